"""B-spline and NURBS curves.

Evaluation and derivatives follow Piegl & Tiller, The NURBS Book 2e: Alg. A3.1/A3.2
(non-rational point and derivatives), A4.1/A4.2 (rational point and derivatives from
the homogeneous ones). Everything is float64 and vectorised over parameters.

As for surfaces (see ``surface.py``), many points per knot span (projection, dense
sampling) go through a cached table of each span's Taylor coefficients about its
midpoint, one gather and a small contraction per point; few points use the basis
functions of A2.2/A2.3 directly. Both give the same numbers to round-off.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from math import comb

import numpy as np

from ..errors import GeometryError
from .basis import (
    basis_function_derivatives,
    basis_functions,
    check_parameters,
    domain_of,
    find_span,
    monomial_derivatives,
    taylor_matrices,
    validate_degree,
    validate_knots,
)


#: The span table is used when there are at least this many points per knot span.
TABLE_MIN_POINTS_PER_SPAN = 4


def _readonly(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


def validate_weights(weights, shape: tuple, what: str = "weights") -> np.ndarray:
    """Finite, strictly positive weights of the given shape, as a read-only float64 copy."""
    w = np.array(weights, dtype=np.float64)
    if w.shape != shape:
        raise GeometryError(f"{what}: expected shape {shape}, got {w.shape}")
    if not np.all(np.isfinite(w)):
        raise GeometryError(f"{what} contain a non-finite value ({w[~np.isfinite(w)].flat[0]!r})")
    if np.any(w <= 0):
        raise GeometryError(f"{what} must be > 0, got {w[w <= 0].flat[0]!r}")
    return _readonly(w)


def validate_points(points, what: str = "control_points") -> np.ndarray:
    """Finite float64 copy of a point array (read-only)."""
    P = np.array(points, dtype=np.float64)
    if P.size and not np.all(np.isfinite(P)):
        idx = tuple(int(i) for i in np.argwhere(~np.isfinite(P))[0])
        raise GeometryError(f"{what}{list(idx)} is not finite ({P[idx]!r})")
    return _readonly(P)


def rational_derivatives(Aders: np.ndarray, wders: np.ndarray) -> np.ndarray:
    """Derivatives of C = A/w from those of A = wC and w (NURBS Book Alg. A4.2).

    ``Aders``: S + (d+1, dim), ``wders``: S + (d+1,). Returns S + (d+1, dim).
    """
    d = Aders.shape[-2] - 1
    CK = np.empty_like(Aders)
    w0 = wders[..., 0:1]
    for k in range(d + 1):
        v = Aders[..., k, :].copy()
        for i in range(1, k + 1):
            v -= comb(k, i) * wders[..., i : i + 1] * CK[..., k - i, :]
        CK[..., k, :] = v / w0
    return CK


@dataclass(frozen=True, eq=False)
class BSplineCurve:
    """A B-spline curve, rational when ``weights`` is given.

    degree: p >= 1.
    knots: (n+p+2,) non-decreasing; clamped or not.
    control_points: (n+1, dim) Euclidean points (not pre-multiplied by the weights).
    weights: (n+1,) positive, or None for a non-rational curve.
    """

    degree: int
    knots: np.ndarray
    control_points: np.ndarray
    weights: np.ndarray | None = None

    def __post_init__(self):
        p = validate_degree(self.degree)
        P = validate_points(self.control_points)
        if P.ndim != 2 or P.shape[1] < 1:
            raise GeometryError(f"control_points: expected shape (n+1, dim), got {P.shape}")
        if P.shape[0] < p + 1:
            raise GeometryError(
                f"control_points: degree {p} needs at least {p + 1} control points, got {P.shape[0]}"
            )
        U = validate_knots(self.knots, p, P.shape[0])
        object.__setattr__(self, "degree", p)
        object.__setattr__(self, "control_points", P)
        object.__setattr__(self, "knots", U)
        if self.weights is not None:
            object.__setattr__(self, "weights", validate_weights(self.weights, (P.shape[0],)))

    # -- properties ---------------------------------------------------------------
    @property
    def dim(self) -> int:
        return self.control_points.shape[1]

    @property
    def n_control(self) -> int:
        return self.control_points.shape[0]

    @property
    def is_rational(self) -> bool:
        return self.weights is not None

    @property
    def domain(self) -> tuple[float, float]:
        return domain_of(self.knots, self.degree)

    @property
    def homogeneous(self) -> np.ndarray:
        """Control points in homogeneous form (w*P, w): shape (n+1, dim+1)."""
        w = np.ones(self.n_control) if self.weights is None else self.weights
        return np.concatenate([self.control_points * w[:, None], w[:, None]], axis=1)

    @classmethod
    def from_homogeneous(cls, degree: int, knots, Pw: np.ndarray, rational: bool | None = None):
        """Build from homogeneous points (w*P, w). ``rational=None`` keeps weights only if not all 1."""
        Pw = np.asarray(Pw, dtype=np.float64)
        w = Pw[:, -1]
        if np.any(w <= 0) or not np.all(np.isfinite(w)):
            raise GeometryError("homogeneous control points have non-positive or non-finite weights")
        P = Pw[:, :-1] / w[:, None]
        if rational is None:
            rational = not np.all(w == 1.0)
        return cls(degree, knots, P, w if rational else None)

    def with_control_points(self, control_points, weights="keep") -> "BSplineCurve":
        """Same degree and knots, new control points (and weights unless kept)."""
        w = self.weights if isinstance(weights, str) and weights == "keep" else weights
        return BSplineCurve(self.degree, self.knots, control_points, w)

    def size(self) -> float:
        """Diagonal of the control polygon's bounding box: the length scale for tolerances."""
        P = self.control_points
        return float(np.linalg.norm(P.max(axis=0) - P.min(axis=0)))

    # -- evaluation ---------------------------------------------------------------
    @cached_property
    def _span_table(self):
        """(span midpoints, Taylor coefficients (n_spans, p+1, dim')) of the homogeneous
        curve: on span i, Cw(u) = sum_a (u - m_i)^a table[i, a]."""
        p = self.degree
        Pw = self.homogeneous if self.is_rational else self.control_points
        mid, T = taylor_matrices(self.knots, p, self.n_control)
        windows = np.lib.stride_tricks.sliding_window_view(Pw, p + 1, axis=0)  # (spans, dim', p+1)
        table = np.einsum("iac,idc->iad", T, windows)
        table.flags.writeable = False
        return mid, table

    def _homogeneous_derivatives(self, u: np.ndarray, order: int) -> np.ndarray:
        p = self.degree
        if u.size >= TABLE_MIN_POINTS_PER_SPAN * (self.n_control - p):
            mid, table = self._span_table
            flat = u.ravel()
            i = find_span(self.knots, p, flat) - p
            M = monomial_derivatives(flat - mid[i], p, order)  # (order+1, N, p+1)
            out = np.matmul(M.transpose(1, 0, 2), table[i])
            return out.reshape(u.shape + out.shape[1:])
        span = find_span(self.knots, p, u)
        Pw = self.homogeneous if self.is_rational else self.control_points
        idx = span[..., None] - p + np.arange(p + 1)
        if order == 0:
            N = basis_functions(self.knots, p, u, span)
            return np.einsum("...j,...jd->...d", N, Pw[idx])[..., None, :]
        ders = basis_function_derivatives(self.knots, p, u, span, order)
        return np.einsum("...kj,...jd->...kd", ders, Pw[idx])

    def derivatives(self, u, order: int = 1) -> np.ndarray:
        """C and its derivatives up to ``order`` at ``u``: shape u.shape + (order+1, dim).

        NURBS Book Alg. A3.2, and A4.2 for rational curves.
        """
        if order < 0:
            raise GeometryError(f"derivative order must be >= 0, got {order}")
        u = check_parameters(u, self.knots, self.degree)
        H = self._homogeneous_derivatives(u, order)
        if not self.is_rational:
            return H
        return rational_derivatives(H[..., :-1], H[..., -1])

    def evaluate(self, u) -> np.ndarray:
        """Points C(u): shape u.shape + (dim,) (NURBS Book Alg. A3.1 / A4.1)."""
        u = check_parameters(u, self.knots, self.degree)
        H = self._homogeneous_derivatives(u, 0)[..., 0, :]
        if not self.is_rational:
            return H
        return H[..., :-1] / H[..., -1:]

    __call__ = evaluate

    def tangent(self, u) -> np.ndarray:
        """Unit tangent C'/|C'|."""
        d = self.derivatives(u, 1)[..., 1, :]
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    def curvature(self, u) -> np.ndarray:
        """Curvature at ``u``. Signed (x'y'' - y'x'')/|C'|^3 for planar (dim 2) curves,
        |C' x C''|/|C'|^3 otherwise."""
        D = self.derivatives(u, 2)
        d1, d2 = D[..., 1, :], D[..., 2, :]
        speed = np.linalg.norm(d1, axis=-1)
        if self.dim == 2:
            num = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]
        else:
            d1_3 = np.zeros(d1.shape[:-1] + (3,))
            d2_3 = np.zeros(d2.shape[:-1] + (3,))
            d1_3[..., : self.dim] = d1[..., :3]
            d2_3[..., : self.dim] = d2[..., :3]
            num = np.linalg.norm(np.cross(d1_3, d2_3), axis=-1)
        return num / speed**3

    def sample(self, count: int) -> np.ndarray:
        """``count`` points at parameters uniformly spaced over the domain."""
        a, b = self.domain
        return self.evaluate(np.linspace(a, b, count))


def evaluate_splines(knots, coefficients, degree: int, t) -> np.ndarray:
    """K non-rational splines of one degree, each with its own knots, at the same
    parameters: knots a sequence of K vectors (n_k + p + 1,), coefficients of K arrays
    (n_k, dim), t (n,) inside every domain. Returns (K, n, dim).

    One call instead of K: the knot vectors and coefficients are concatenated, each
    curve's spans (NURBS Book Alg. A2.1) are shifted by its offset into the
    concatenation, and the basis functions (Alg. A2.2) and the sums (Alg. A3.1) run over
    all curves and parameters at once. The cost of evaluating many short splines at a
    few points each is per-call overhead, which this removes."""
    p = validate_degree(degree)
    t = np.asarray(t, dtype=np.float64)
    K = len(knots)
    if K != len(coefficients):
        raise GeometryError(f"evaluate_splines: {K} knot vectors for {len(coefficients)} coefficient arrays")
    if K == 0:
        return np.empty((0, t.size, 0))
    U = [np.asarray(k, dtype=np.float64) for k in knots]
    C = [np.asarray(c, dtype=np.float64).reshape(len(c), -1) for c in coefficients]
    for k, (Uk, Ck) in enumerate(zip(U, C)):
        if len(Uk) != len(Ck) + p + 1:
            raise GeometryError(f"evaluate_splines: curve {k} has {len(Uk)} knots for {len(Ck)} coefficients "
                                f"of degree {p}")
    knot_offset = np.cumsum([0] + [len(Uk) for Uk in U[:-1]])
    coef_offset = np.cumsum([0] + [len(Ck) for Ck in C[:-1]])
    spans = np.stack([find_span(Uk, p, t) for Uk in U])  # (K, n), each in its own vector
    flat_knots = np.concatenate(U)
    flat_coefs = np.concatenate(C)
    N = basis_functions(flat_knots, p, np.broadcast_to(t, spans.shape), spans + knot_offset[:, None])
    rows = (spans - p + coef_offset[:, None])[..., None] + np.arange(p + 1)
    return np.einsum("kna,knad->knd", N, flat_coefs[rows])
