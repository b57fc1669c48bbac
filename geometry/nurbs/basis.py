"""Knot vectors and B-spline basis functions, vectorised over parameters.

Piegl & Tiller, The NURBS Book 2e (1997): Alg. A2.1 (FindSpan), A2.2 (BasisFuns),
A2.3 (DersBasisFuns). Every function here takes arrays of parameters of any shape
and works on all of them at once; loops run only over the degree.
"""
from __future__ import annotations

from math import factorial

import numpy as np

from ..errors import GeometryError

#: Relative slack (of the parameter domain's length) within which a parameter just
#: outside the domain is taken as the end value instead of refused. Round-off in
#: callers that compute parameters (arclength, projections) lands here.
DOMAIN_SLACK = 1e-10


def validate_degree(degree, what: str = "degree") -> int:
    """Return ``degree`` as an int, refusing anything that is not an integer >= 1."""
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)):
        raise GeometryError(f"{what} must be an integer >= 1, got {degree!r}")
    if degree < 1:
        raise GeometryError(f"{what} must be >= 1, got {degree}")
    return int(degree)


def validate_knots(knots, degree: int, n_control: int, what: str = "knots") -> np.ndarray:
    """Check a knot vector against a degree and a control-point count.

    Requires ``len(knots) == n_control + degree + 1``, finite non-decreasing values,
    interior multiplicity <= degree, and a domain ``[U[p], U[n+1]]`` of positive
    length. Unclamped (e.g. Blender's uniform) vectors are allowed.
    Returns a read-only float64 copy.
    """
    U = np.array(knots, dtype=np.float64)
    if U.ndim != 1:
        raise GeometryError(f"{what} must be a 1-D sequence, got an array of shape {U.shape}")
    expected = n_control + degree + 1
    if U.size != expected:
        raise GeometryError(
            f"{what}: expected {expected} knots for {n_control} control points of degree "
            f"{degree} (n + p + 2), got {U.size}"
        )
    if not np.all(np.isfinite(U)):
        bad = int(np.flatnonzero(~np.isfinite(U))[0])
        raise GeometryError(f"{what}[{bad}] is not finite ({U[bad]!r})")
    steps = np.diff(U)
    if np.any(steps < 0):
        bad = int(np.flatnonzero(steps < 0)[0])
        raise GeometryError(
            f"{what} must be non-decreasing: {what}[{bad}] = {U[bad]!r} > {what}[{bad + 1}] = {U[bad + 1]!r}"
        )
    p = degree
    a, b = U[p], U[n_control]
    if not b > a:
        raise GeometryError(f"{what}: the parameter domain [U[{p}], U[{n_control}]] = [{a}, {b}] is empty")
    values, counts = np.unique(U, return_counts=True)
    if counts.max() > p + 1:
        v = values[np.argmax(counts)]
        raise GeometryError(
            f"{what}: knot {v!r} has multiplicity {counts.max()}, more than degree + 1 = {p + 1}"
        )
    inside = (values > a) & (values < b) & (counts > p)
    if inside.any():
        v, c = values[inside][0], counts[inside][0]
        raise GeometryError(f"{what}: interior knot {v!r} has multiplicity {c}, more than the degree {p}")
    U.flags.writeable = False
    return U


def clamped_uniform_knots(n_control: int, degree: int, domain=(0.0, 1.0)) -> np.ndarray:
    """Clamped (open) knot vector with uniformly spaced interior knots."""
    p = validate_degree(degree)
    if n_control < p + 1:
        raise GeometryError(f"need at least {p + 1} control points for degree {p}, got {n_control}")
    a, b = map(float, domain)
    interior = np.linspace(a, b, n_control - p + 1)[1:-1]
    return np.concatenate([np.full(p + 1, a), interior, np.full(p + 1, b)])


def bezier_knots(degree: int, domain=(0.0, 1.0)) -> np.ndarray:
    """Knot vector of a single Bezier segment of the given degree."""
    a, b = map(float, domain)
    return np.concatenate([np.full(degree + 1, a), np.full(degree + 1, b)])


def domain_of(knots: np.ndarray, degree: int) -> tuple[float, float]:
    """Parameter domain ``(U[p], U[m-p])`` of a knot vector."""
    return float(knots[degree]), float(knots[len(knots) - degree - 1])


def check_parameters(u, knots: np.ndarray, degree: int, what: str = "parameter") -> np.ndarray:
    """Return ``u`` as float64, clipped into the domain when within :data:`DOMAIN_SLACK`.

    Raises :class:`GeometryError` for NaN or for parameters clearly outside the domain.
    """
    u = np.asarray(u, dtype=np.float64)
    a, b = domain_of(knots, degree)
    slack = DOMAIN_SLACK * (b - a)
    if u.size:
        if np.isnan(u).any():
            raise GeometryError(f"{what} contains NaN")
        lo, hi = u.min(), u.max()
        if lo < a - slack or hi > b + slack:
            bad = lo if lo < a - slack else hi
            raise GeometryError(f"{what} {float(bad)!r} is outside the domain [{float(a)!r}, {float(b)!r}]")
    return np.clip(u, a, b)


def find_span(knots: np.ndarray, degree: int, u: np.ndarray) -> np.ndarray:
    """Knot span index i with ``U[i] <= u < U[i+1]``, vectorised (NURBS Book Alg. A2.1).

    The end of the domain belongs to the last non-empty span, as in A2.1; on unclamped
    vectors whose end knot U[n+1] is repeated below index n+1 that span lies below n.
    """
    n = len(knots) - degree - 2
    last = np.searchsorted(knots, knots[n + 1], side="left") - 1  # last i with U[i] < U[n+1]
    span = np.searchsorted(knots, u, side="right") - 1
    return np.clip(span, degree, last)


def basis_functions(knots: np.ndarray, degree: int, u: np.ndarray, span: np.ndarray) -> np.ndarray:
    """Non-vanishing basis functions N_{span-p..span, p}(u) (NURBS Book Alg. A2.2).

    ``u`` and ``span`` have shape S; the result has shape S + (p+1,).
    """
    p = degree
    u = np.asarray(u, dtype=np.float64)
    N = np.zeros(u.shape + (p + 1,))
    N[..., 0] = 1.0
    left = np.empty(u.shape + (p + 1,))
    right = np.empty(u.shape + (p + 1,))
    for j in range(1, p + 1):
        left[..., j] = u - knots[span + 1 - j]
        right[..., j] = knots[span + j] - u
        saved = np.zeros(u.shape)
        for r in range(j):
            temp = N[..., r] / (right[..., r + 1] + left[..., j - r])
            N[..., r] = saved + right[..., r + 1] * temp
            saved = left[..., j - r] * temp
        N[..., j] = saved
    _snap_single_basis(N)
    return N


def _snap_single_basis(N: np.ndarray) -> None:
    """Where only one basis function is non-zero (a clamped end, a knot of multiplicity
    p), it is 1 by the partition of unity (NURBS Book P2.4); Alg. A2.2 computes it as
    right · (N / right), which may round to 1 ± 1 ulp. Snap it, so that an end row of
    a collocation or evaluation copies its control point bit for bit on every CPU."""
    single = np.count_nonzero(N, axis=-1) == 1
    if single.any():
        N[single] = N[single] != 0.0


def basis_function_derivatives(
    knots: np.ndarray, degree: int, u: np.ndarray, span: np.ndarray, order: int
) -> np.ndarray:
    """Basis functions and their derivatives up to ``order`` (NURBS Book Alg. A2.3).

    Returns shape S + (order+1, p+1): ``ders[..., k, j]`` is the k-th derivative of
    N_{span-p+j, p}(u). Derivatives above the degree are zero.
    """
    p = degree
    u = np.asarray(u, dtype=np.float64)
    S = u.shape
    ndu = np.zeros(S + (p + 1, p + 1))
    ndu[..., 0, 0] = 1.0
    left = np.empty(S + (p + 1,))
    right = np.empty(S + (p + 1,))
    for j in range(1, p + 1):
        left[..., j] = u - knots[span + 1 - j]
        right[..., j] = knots[span + j] - u
        saved = np.zeros(S)
        for r in range(j):
            # lower triangle holds knot differences, upper the basis functions
            ndu[..., j, r] = right[..., r + 1] + left[..., j - r]
            temp = ndu[..., r, j - 1] / ndu[..., j, r]
            ndu[..., r, j] = saved + right[..., r + 1] * temp
            saved = left[..., j - r] * temp
        ndu[..., j, j] = saved
    ders = np.zeros(S + (order + 1, p + 1))
    ders[..., 0, :] = ndu[..., :, p]
    _snap_single_basis(ders[..., 0, :])
    top = min(order, p)
    for r in range(p + 1):
        a = np.zeros(S + (2, p + 1))
        a[..., 0, 0] = 1.0
        s1, s2 = 0, 1
        for k in range(1, top + 1):
            d = np.zeros(S)
            rk, pk = r - k, p - k
            if r >= k:
                a[..., s2, 0] = a[..., s1, 0] / ndu[..., pk + 1, rk]
                d = a[..., s2, 0] * ndu[..., rk, pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = k - 1 if r - 1 <= pk else p - r
            for j in range(j1, j2 + 1):
                a[..., s2, j] = (a[..., s1, j] - a[..., s1, j - 1]) / ndu[..., pk + 1, rk + j]
                d = d + a[..., s2, j] * ndu[..., rk + j, pk]
            if r <= pk:
                a[..., s2, k] = -a[..., s1, k - 1] / ndu[..., pk + 1, r]
                d = d + a[..., s2, k] * ndu[..., r, pk]
            ders[..., k, r] = d
            s1, s2 = s2, s1
    factor = float(p)
    for k in range(1, top + 1):
        ders[..., k, :] *= factor
        factor *= p - k
    return ders


def taylor_matrices(knots: np.ndarray, degree: int, n_control: int):
    """Per knot span i (p <= i <= n): the span midpoint m_i and the matrix T_i with
    ``T_i[k, c] = N^(k)_{i-p+c}(m_i) / k!``, so that on span i
    ``sum_c N_{i-p+c}(u) P_c = sum_k (u - m_i)^k (T_i P)_k`` (Taylor expansion of the
    basis, exact for polynomials of degree p; derivatives from NURBS Book Alg. A2.3).
    Empty spans get zero matrices; they are never selected by :func:`find_span`."""
    spans = np.arange(degree, n_control)
    lo, hi = knots[spans], knots[spans + 1]
    mid = 0.5 * (lo + hi)
    with np.errstate(divide="ignore", invalid="ignore"):
        T = basis_function_derivatives(knots, degree, mid, spans, degree)
    T /= np.array([factorial(k) for k in range(degree + 1)])[:, None]
    T[hi <= lo] = 0.0
    return mid, T


def monomial_derivatives(t: np.ndarray, degree: int, order: int) -> np.ndarray:
    """``out[k, n, a] = d^k/dt^k t^a`` at t[n], for k <= order: shape (order+1, N, degree+1)."""
    powers = np.empty((t.size, degree + 1))
    powers[:, 0] = 1.0
    for a in range(1, degree + 1):
        np.multiply(powers[:, a - 1], t, out=powers[:, a])
    if order == 0:
        return powers[None]
    out = np.zeros((order + 1, t.size, degree + 1))
    out[0] = powers
    for k in range(1, order + 1):
        for a in range(k, degree + 1):
            out[k, :, a] = (factorial(a) // factorial(a - k)) * powers[:, a - k]
    return out
