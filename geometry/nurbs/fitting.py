"""Curve fitting: parameterisation, knot placement, interpolation, least squares and
adaptive approximation of arbitrary parametric curves with one common knot vector.

Sources:
- Piegl & Tiller, The NURBS Book 2e (1997), Ch. 9: Eqs. 9.4–9.6 (parameters), Eq. 9.8
  (averaged knots), Alg. A9.1 (global interpolation), §9.2.2 (interpolation with end
  derivatives, knots by Eq. 9.22), §9.4.1 (least squares with end points interpolated,
  Eqs. 9.63–9.67), Eqs. 9.68–9.69 (approximation knots), §9.4.2 (weighted and
  constrained least squares).
- Piegl & Tiller (2000), "Least-squares B-spline curve approximation with arbitrary end
  derivatives", Engineering with Computers 16: end control points from the derivatives.
- Hally (2013), DRDC Atlantic TM 2013-178, §9: spline approximation of a curve by knot
  insertion that keeps the initial knots as a subset of the final ones, and one common
  knot sequence for a family of curves.

Fitted curves are non-rational, clamped, float64.
"""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np
from scipy.linalg import lstsq, solve_banded

from ..errors import GeometryError
from .basis import basis_function_derivatives, basis_functions, find_span, validate_degree, validate_knots
from .curve import BSplineCurve

#: Consecutive data points closer than this (relative to the bounding-box diagonal of the
#: data) are refused as coincident: chord-length parameters would repeat.
COINCIDENT_TOL = 1e-12

#: A span passes when its measured deviation is at most (1 - DEVIATION_MARGIN) times the
#: tolerance: a small allowance for a maximum that the sampling and parabolic refinement
#: slightly underestimate.
DEVIATION_MARGIN = 1e-3

#: Default number of deviation samples per knot span in :func:`approximate`.
DEFAULT_SAMPLES_PER_SPAN = 16

#: Default cap on the length of the knot vector built by :func:`approximate`.
DEFAULT_MAX_KNOTS = 2000

#: Default cap on the refit rounds of :func:`approximate_common`.
DEFAULT_MAX_ROUNDS = 20

PARAMETERIZATION_METHODS = ("chord", "centripetal", "uniform")


# ---------------------------------------------------------------------------------------
# validation helpers
# ---------------------------------------------------------------------------------------
def _as_points(points, what: str = "points", minimum: int = 2) -> np.ndarray:
    Q = np.array(points, dtype=np.float64)
    if Q.ndim == 1:
        Q = Q[:, None]
    if Q.ndim != 2 or Q.shape[1] < 1:
        raise GeometryError(f"{what}: expected an array of shape (count, dim), got shape {Q.shape}")
    if Q.shape[0] < minimum:
        raise GeometryError(f"{what}: need at least {minimum} points, got {Q.shape[0]}")
    if not np.all(np.isfinite(Q)):
        k = int(np.argwhere(~np.isfinite(Q))[0, 0])
        raise GeometryError(f"{what}[{k}] is not finite ({Q[k].tolist()!r})")
    return Q


def _as_vector(vec, dim: int, what: str) -> np.ndarray | None:
    if vec is None:
        return None
    d = np.array(vec, dtype=np.float64).reshape(-1)
    if d.shape != (dim,):
        raise GeometryError(f"{what}: expected a vector of {dim} components, got shape {np.shape(vec)}")
    if not np.all(np.isfinite(d)):
        raise GeometryError(f"{what} is not finite ({d.tolist()!r})")
    return d


def _as_params(params, count: int) -> np.ndarray:
    t = np.array(params, dtype=np.float64)
    if t.shape != (count,):
        raise GeometryError(f"params: expected {count} values (one per point), got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        raise GeometryError(f"params[{int(np.flatnonzero(~np.isfinite(t))[0])}] is not finite")
    steps = np.diff(t)
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0])
        raise GeometryError(
            f"params must be strictly increasing: params[{k}] = {t[k]!r} >= params[{k + 1}] = {t[k + 1]!r}"
        )
    return t


def _clamped(a: float, interior: np.ndarray, b: float, degree: int) -> np.ndarray:
    return np.concatenate([np.full(degree + 1, a), np.asarray(interior, dtype=np.float64), np.full(degree + 1, b)])


# ---------------------------------------------------------------------------------------
# parameters and knots
# ---------------------------------------------------------------------------------------
def parameterize(points, method: str = "chord") -> np.ndarray:
    """Parameters ū_k in [0, 1] for data points Q_k (NURBS Book Eqs. 9.4–9.6).

    points: (m+1, dim). method: ``"uniform"`` (Eq. 9.4, ū_k = k/m), ``"chord"`` (Eq. 9.5,
    cumulative chord length) or ``"centripetal"`` (Eq. 9.6, cumulative square roots of
    chord lengths). Returns (m+1,) with ū_0 = 0 and ū_m = 1.

    Consecutive points closer than :data:`COINCIDENT_TOL` times the data size are refused
    with a :class:`GeometryError` naming the index, whatever the method.
    """
    if method not in PARAMETERIZATION_METHODS:
        raise GeometryError(f"method must be one of {PARAMETERIZATION_METHODS}, got {method!r}")
    Q = _as_points(points)
    chords = np.linalg.norm(np.diff(Q, axis=0), axis=1)
    scale = float(np.linalg.norm(Q.max(axis=0) - Q.min(axis=0)))
    close = chords <= COINCIDENT_TOL * scale
    if np.any(close):
        k = int(np.flatnonzero(close)[0]) + 1
        raise GeometryError(
            f"points[{k}] coincides with points[{k - 1}] (distance {chords[k - 1]:.3g}); "
            "remove repeated points before fitting"
        )
    m = Q.shape[0] - 1
    if method == "uniform":
        return np.arange(m + 1) / m
    steps = chords if method == "chord" else np.sqrt(chords)
    t = np.concatenate([[0.0], np.cumsum(steps)])
    t /= t[-1]
    t[-1] = 1.0
    return t


def _window_means(values: np.ndarray, width: int) -> np.ndarray:
    """Means of every run of ``width`` consecutive values (empty if there are none)."""
    if values.size < width:
        return np.empty(0)
    c = np.concatenate([[0.0], np.cumsum(values)])
    return (c[width:] - c[:-width]) / width


def average_knots(params, degree: int) -> np.ndarray:
    """Clamped knots for interpolation by averaging (NURBS Book Eq. 9.8).

    params: (m+1,) increasing. Returns m+p+2 knots: p+1 copies of ū_0 and of ū_m, and
    u_{j+p} = (1/p) Σ_{i=j}^{j+p-1} ū_i for j = 1..m-p.
    """
    p = validate_degree(degree)
    t = _as_params(params, np.size(params))
    if t.size < p + 1:
        raise GeometryError(f"degree {p} needs at least {p + 1} parameters, got {t.size}")
    return _clamped(t[0], _window_means(t[1:-1], p), t[-1], p)


def approximation_knots(params, n_control: int, degree: int) -> np.ndarray:
    """Clamped knots for least-squares approximation (NURBS Book Eqs. 9.68–9.69).

    params: (m+1,) increasing; n_control = n+1 with p+1 <= n+1 <= m+1. With
    d = (m+1)/(n-p+1), i = int(j d) and α = j d - i, the interior knots are
    u_{p+j} = (1-α) ū_{i-1} + α ū_i for j = 1..n-p, so every knot span holds a parameter.
    """
    p = validate_degree(degree)
    t = _as_params(params, np.size(params))
    m = t.size - 1
    if n_control < p + 1:
        raise GeometryError(f"n_control must be at least degree + 1 = {p + 1}, got {n_control}")
    if n_control > m + 1:
        raise GeometryError(f"n_control ({n_control}) must not exceed the number of parameters ({m + 1})")
    n = n_control - 1
    d = (m + 1) / (n - p + 1)
    jd = np.arange(1, n - p + 1) * d
    i = np.floor(jd).astype(int)
    alpha = jd - i
    interior = (1.0 - alpha) * t[i - 1] + alpha * t[np.minimum(i, m)]
    return _clamped(t[0], interior, t[-1], p)


def greville_abscissae(knots, degree: int) -> np.ndarray:
    """Greville abscissae ξ_i = (u_{i+1} + ... + u_{i+p}) / p: shape (n+1,)."""
    U = np.asarray(knots, dtype=np.float64)
    return _window_means(U[1:-1], degree)


# ---------------------------------------------------------------------------------------
# linear algebra
# ---------------------------------------------------------------------------------------
def _collocation_entries(knots: np.ndarray, degree: int, params: np.ndarray, order: int = 0):
    """Columns and values of the non-zero basis entries (k-th derivative) at each parameter:
    two arrays of shape (len(params), p+1)."""
    span = find_span(knots, degree, params)
    if order == 0:
        vals = basis_functions(knots, degree, params, span)
    else:
        vals = basis_function_derivatives(knots, degree, params, span, order)[..., order, :]
    cols = span[:, None] - degree + np.arange(degree + 1)
    return cols, vals


def _collocation_matrix(knots: np.ndarray, degree: int, n_control: int, params: np.ndarray) -> np.ndarray:
    cols, vals = _collocation_entries(knots, degree, params)
    M = np.zeros((params.size, n_control))
    M[np.arange(params.size)[:, None], cols] = vals
    return M


def _solve_banded_rows(cols: np.ndarray, vals: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve the square system whose row r has entries ``vals[r]`` in columns ``cols[r]``,
    in LAPACK band storage with ``scipy.linalg.solve_banded`` (never an inverse).

    A row whose only non-zero entry is exactly 1 (a clamped end: N_0(u_0) = N_n(u_m) = 1,
    NURBS Book Eq. 2.5 and §9.2.1) pins its unknown to the right-hand side *bit for bit*:
    the unknown is copied, its column moved to the right-hand side of the other rows, and
    only the remaining unknowns are solved for. Mathematically nothing changes; in floating
    point it makes "the surface's end row is the section's control polygon" an identity
    rather than an accident of the LU rounding, which differs between CPUs and BLAS kernels
    (the red main of issue 14: a root transition's last column against the aero surface's
    first row on an AVX-512 machine).
    """
    n = cols.shape[0]
    rhs = np.asarray(rhs, dtype=np.float64)
    nz = vals != 0.0
    unit = (nz.sum(axis=1) == 1) & np.any(nz & (vals == 1.0), axis=1)
    pin_rows = np.flatnonzero(unit)
    pin_cols = cols[pin_rows][nz[pin_rows]]
    if pin_rows.size == 0 or np.unique(pin_cols).size != pin_cols.size:
        return _solve_band_storage(cols, vals, rhs)
    free_col = np.ones(n, dtype=bool)
    free_col[pin_cols] = False
    flat = rhs.reshape(n, -1)
    known = np.zeros_like(flat)
    known[pin_cols] = flat[pin_rows]
    if free_col.any():
        c, v = cols[~unit], vals[~unit]
        pinned_entry = ~free_col[c]
        reduced_rhs = flat[~unit] - np.einsum("rj,rjk->rk", np.where(pinned_entry, v, 0.0), known[c])
        new_index = np.cumsum(free_col) - 1
        known[free_col] = _solve_band_storage(
            np.maximum(new_index[c], 0), np.where(pinned_entry, 0.0, v), reduced_rhs)
    return known.reshape(rhs.shape)


def _solve_band_storage(cols: np.ndarray, vals: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    n = cols.shape[0]
    rows = np.broadcast_to(np.arange(n)[:, None], cols.shape)
    nz = vals != 0.0
    offsets = (cols - rows)[nz]
    upper = max(int(offsets.max()), 0)
    lower = max(int(-offsets.min()), 0)
    ab = np.zeros((lower + upper + 1, n))
    ab[(upper + rows - cols)[nz], cols[nz]] = vals[nz]
    try:
        return solve_banded((lower, upper), ab, rhs)
    except np.linalg.LinAlgError as exc:  # singular: Schoenberg–Whitney condition violated
        raise GeometryError(f"the interpolation system is singular ({exc})") from None


# ---------------------------------------------------------------------------------------
# interpolation
# ---------------------------------------------------------------------------------------
def interpolate(
    points,
    degree: int = 3,
    params=None,
    method: str = "chord",
    start_derivative=None,
    end_derivative=None,
) -> BSplineCurve:
    """Global B-spline interpolation of points Q_0..Q_m (NURBS Book Alg. A9.1).

    points: (m+1, dim). params: (m+1,) strictly increasing, or None for
    :func:`parameterize` with ``method``. The curve's domain is [params[0], params[-1]]
    and C(ū_k) = Q_k.

    Without derivatives the knots are averaged (Eq. 9.8) and n = m. With prescribed end
    derivatives D_0 = C'(ū_0) and/or D_m = C'(ū_m) (§9.2.2) one control point is added per
    derivative and the derivative conditions become extra rows of the system, placed
    second and second-to-last so it stays banded. With both, the interior knots are
    u_{j+p} = (1/p) Σ_{i=j-1}^{j+p-2} ū_i, j = 1..m-p+2 (Eq. 9.22); with one, the windows
    are widened to p+1 parameters so the count of knots matches. The banded system is
    solved with ``scipy.linalg.solve_banded``.
    """
    p = validate_degree(degree)
    Q = _as_points(points)
    m = Q.shape[0] - 1
    dim = Q.shape[1]
    D0 = _as_vector(start_derivative, dim, "start_derivative")
    Dm = _as_vector(end_derivative, dim, "end_derivative")
    nd = (D0 is not None) + (Dm is not None)
    if m + 1 + nd < p + 1:
        raise GeometryError(
            f"too few points for degree {p}: need at least {p + 1 - nd} points "
            f"with {nd} end derivative(s), got {m + 1}"
        )
    if nd == 2 and p < 2:
        raise GeometryError("both end derivatives need degree >= 2 (Eq. 9.22 averages p >= 2 parameters)")
    t = parameterize(Q, method) if params is None else _as_params(params, m + 1)
    if nd == 0:
        interior = _window_means(t[1:-1], p)
    elif nd == 2:
        interior = _window_means(t, p)  # Eq. 9.22
    else:
        interior = _window_means(t, p + 1)
    U = _clamped(t[0], interior, t[-1], p)

    cols, vals = _collocation_entries(U, p, t)
    rhs = Q
    if D0 is not None:
        dc, dv = _collocation_entries(U, p, t[:1], 1)
        cols = np.concatenate([cols[:1], dc, cols[1:]])
        vals = np.concatenate([vals[:1], dv, vals[1:]])
        rhs = np.concatenate([rhs[:1], D0[None], rhs[1:]])
    if Dm is not None:
        dc, dv = _collocation_entries(U, p, t[-1:], 1)
        cols = np.concatenate([cols[:-1], dc, cols[-1:]])
        vals = np.concatenate([vals[:-1], dv, vals[-1:]])
        rhs = np.concatenate([rhs[:-1], Dm[None], rhs[-1:]])
    P = _solve_banded_rows(cols, vals, rhs)
    return BSplineCurve(p, U, P)


def interpolate_at(knots, degree: int, params, points) -> BSplineCurve:
    """The B-spline with the given knots through ``points`` at ``params`` (one parameter
    per control point; Schoenberg–Whitney must hold, e.g. Greville abscissae). Banded
    solve as in NURBS Book Alg. A9.1, with the knots prescribed instead of averaged."""
    p = validate_degree(degree)
    Q = _as_points(points, minimum=1)
    U = validate_knots(knots, p, Q.shape[0])
    t = np.asarray(params, dtype=np.float64)
    if t.shape != (Q.shape[0],):
        raise GeometryError(f"params: expected {Q.shape[0]} values, got shape {t.shape}")
    cols, vals = _collocation_entries(U, p, t)
    return BSplineCurve(p, U, _solve_banded_rows(cols, vals, Q))


# ---------------------------------------------------------------------------------------
# least squares
# ---------------------------------------------------------------------------------------
def fit_least_squares(
    points,
    n_control: int,
    degree: int = 3,
    params=None,
    knots=None,
    start_derivative=None,
    end_derivative=None,
    point_weights=None,
) -> BSplineCurve:
    """Least-squares B-spline approximation with interpolated end points
    (NURBS Book §9.4.1, Eqs. 9.63–9.67; weighted form §9.4.2).

    points: (m+1, dim) with m+1 >= n_control >= degree+1. params: (m+1,) increasing, or
    None for chord length (Eq. 9.5). knots: a clamped vector of n_control+p+1 knots whose
    domain is [params[0], params[-1]] (when both are given; with knots alone the chord
    parameters are mapped onto the knots' domain), or None for Eqs. 9.68–9.69.

    P_0 = Q_0 and P_n = Q_m exactly. A prescribed start derivative D_0 fixes
    P_1 = P_0 + D_0 (u_{p+1} - u_1)/p, an end derivative D_m fixes
    P_{n-1} = P_n - D_m (u_{n+p} - u_n)/p, so C'(u_0) = D_0 and C'(u_m) = D_m exactly
    (Piegl & Tiller 2000). The remaining interior control points minimise
    Σ_{k=1}^{m-1} w_k |Q_k - C(ū_k)|² (w_k = ``point_weights``, default 1), solved as an
    over-determined residual system with ``scipy.linalg.lstsq``.
    """
    p = validate_degree(degree)
    Q = _as_points(points)
    m = Q.shape[0] - 1
    dim = Q.shape[1]
    D0 = _as_vector(start_derivative, dim, "start_derivative")
    Dm = _as_vector(end_derivative, dim, "end_derivative")
    nd = (D0 is not None) + (Dm is not None)
    if isinstance(n_control, bool) or not isinstance(n_control, (int, np.integer)):
        raise GeometryError(f"n_control must be an integer, got {n_control!r}")
    n_control = int(n_control)
    if n_control < max(p + 1, 2 + nd):
        raise GeometryError(
            f"n_control too small: degree {p} with {nd} end derivative(s) needs at least "
            f"{max(p + 1, 2 + nd)} control points, got {n_control}"
        )
    if n_control > m + 1:
        raise GeometryError(
            f"too few points: {n_control} control points need at least {n_control} data points, got {m + 1}"
        )
    if knots is not None:
        U = validate_knots(knots, p, n_control)
        a, b = float(U[0]), float(U[-1])
        if not (np.all(U[: p + 1] == a) and np.all(U[-p - 1 :] == b)):
            raise GeometryError("knots must be clamped (p+1 equal knots at each end)")
        if params is None:
            t = a + (b - a) * parameterize(Q)
            t[-1] = b
        else:
            t = _as_params(params, m + 1)
            if t[0] != a or t[-1] != b:
                raise GeometryError(
                    f"params run over [{t[0]!r}, {t[-1]!r}] but the knots' domain is [{a!r}, {b!r}]"
                )
    else:
        t = parameterize(Q) if params is None else _as_params(params, m + 1)
        U = approximation_knots(t, n_control, p)
    if point_weights is None:
        w = np.ones(m + 1)
    else:
        w = np.array(point_weights, dtype=np.float64)
        if w.shape != (m + 1,):
            raise GeometryError(f"point_weights: expected {m + 1} values, got shape {w.shape}")
        if not np.all(np.isfinite(w)) or np.any(w <= 0):
            raise GeometryError("point_weights must be finite and > 0")

    n = n_control - 1
    P = np.zeros((n_control, dim))
    fixed = np.zeros(n_control, dtype=bool)
    P[0], P[n] = Q[0], Q[m]
    fixed[[0, n]] = True
    if D0 is not None:
        P[1] = P[0] + D0 * (U[p + 1] - U[1]) / p
        fixed[1] = True
    if Dm is not None:
        P[n - 1] = P[n] - Dm * (U[n + p] - U[n]) / p
        fixed[n - 1] = True
    free = np.flatnonzero(~fixed)
    if free.size:
        N = _collocation_matrix(U, p, n_control, t[1:-1])
        R = Q[1:-1] - N[:, fixed] @ P[fixed]
        sw = np.sqrt(w[1:-1])[:, None]
        A = N[:, free] * sw
        sol, _, rank, _ = lstsq(A, R * sw)
        if rank < free.size:
            raise GeometryError(
                f"the least-squares system is rank deficient ({rank} < {free.size}): some knot span "
                "holds no data parameter (Schoenberg–Whitney); use fewer control points or other knots"
            )
        P[free] = sol
    return BSplineCurve(p, U, P)


# ---------------------------------------------------------------------------------------
# adaptive approximation of callables (Hally 2013, §9)
# ---------------------------------------------------------------------------------------
def _call(func: Callable, t: np.ndarray, dim: int | None = None) -> np.ndarray:
    X = np.asarray(func(t), dtype=np.float64)
    if X.ndim == 1 and X.shape[0] == t.size:
        X = X[:, None]
    if X.ndim != 2 or X.shape[0] != t.size or (dim is not None and X.shape[1] != dim):
        want = f"({t.size}, {dim if dim is not None else 'dim'})"
        raise GeometryError(f"the curve function returned shape {X.shape} for {t.size} parameters; expected {want}")
    if not np.all(np.isfinite(X)):
        k = int(np.argwhere(~np.isfinite(X))[0, 0])
        raise GeometryError(f"the curve function is not finite at t = {t[k]!r}")
    return X


def _interior_knots(initial_knots, degree: int, a: float, b: float) -> np.ndarray:
    """The interior values of an initial knot vector (a full clamped vector or just its
    interior knots), as a sorted array; values at the domain ends are dropped."""
    if initial_knots is None:
        return np.empty(0)
    K = np.sort(np.array(initial_knots, dtype=np.float64).reshape(-1))
    if not np.all(np.isfinite(K)):
        raise GeometryError("initial_knots contain a non-finite value")
    slack = 1e-14 * (b - a)
    if K.size and (K[0] < a - slack or K[-1] > b + slack):
        raise GeometryError(f"initial_knots run over [{K[0]!r}, {K[-1]!r}], outside the domain [{a!r}, {b!r}]")
    interior = K[(K > a + slack) & (K < b - slack)]
    if interior.size:
        values, counts = np.unique(interior, return_counts=True)
        if counts.max() > degree:
            raise GeometryError(
                f"initial_knots: interior knot {values[np.argmax(counts)]!r} has multiplicity "
                f"{counts.max()}, more than the degree {degree}"
            )
    return interior


class _Fit:
    """One fit of a callable on one knot vector, with its measured deviation per span."""

    def __init__(self, curve: BSplineCurve, breaks: np.ndarray, span_deviation: np.ndarray, evaluations: int):
        self.curve = curve
        self.breaks = breaks
        self.span_deviation = span_deviation
        self.evaluations = evaluations

    @property
    def max_deviation(self) -> float:
        return float(self.span_deviation.max())


def _fit_on_knots(func, U: np.ndarray, degree: int, samples_per_span: int, fit: str, dim: int | None) -> _Fit:
    """Fit ``func`` with knot vector U and measure |func(t) - C(t)| span by span.

    The deviation is sampled at ``samples_per_span`` + 1 points per non-empty span; the
    largest sample of each span is then refined by one parabolic step through it and its
    neighbours, so a maximum between samples is not missed.
    """
    p = degree
    breaks = np.unique(U)
    S = samples_per_span
    h = np.diff(breaks)
    local = np.arange(S + 1) / S
    ts = breaks[:-1, None] + h[:, None] * local[None, :]  # (spans, S+1)
    ts[:, -1] = breaks[1:]
    evaluations = 0
    if fit == "interpolate":
        g = greville_abscissae(U, p)
        X = _call(func, g, dim)
        evaluations += g.size
        curve = interpolate_at(U, p, g, X)
        F = _call(func, ts.ravel(), X.shape[1])
        evaluations += ts.size
    else:
        tflat = np.unique(ts.ravel())
        F_unique = _call(func, tflat, dim)
        evaluations += tflat.size
        curve = fit_least_squares(F_unique, len(U) - p - 1, p, params=tflat, knots=U)
        F = F_unique[np.searchsorted(tflat, ts.ravel())]
    dev = np.linalg.norm(F - curve.evaluate(ts.ravel()), axis=1).reshape(ts.shape)
    span_dev = dev.max(axis=1)
    # parabolic refinement around the largest sample of each span
    j = np.argmax(dev, axis=1)
    rows = np.arange(dev.shape[0])
    inner = (j > 0) & (j < S)
    if np.any(inner):
        r, jj = rows[inner], j[inner]
        e_m, e_0, e_p = dev[r, jj - 1], dev[r, jj], dev[r, jj + 1]
        curv = e_m - 2.0 * e_0 + e_p
        ok = curv < 0
        if np.any(ok):
            r, jj = r[ok], jj[ok]
            delta = np.clip(0.5 * (e_m[ok] - e_p[ok]) / curv[ok], -1.0, 1.0)
            tv = ts[r, jj] + delta * h[r] / S
            Fv = _call(func, tv, F.shape[1])
            evaluations += tv.size
            dv = np.linalg.norm(Fv - curve.evaluate(tv), axis=1)
            span_dev[r] = np.maximum(span_dev[r], dv)
    return _Fit(curve, breaks, span_dev, evaluations)


def _check_approximation_args(tolerance, degree, domain, samples_per_span, fit):
    p = validate_degree(degree)
    tol = float(tolerance)
    if not np.isfinite(tol) or tol <= 0:
        raise GeometryError(f"tolerance must be a positive number, got {tolerance!r}")
    a, b = map(float, domain)
    if not (np.isfinite(a) and np.isfinite(b) and b > a):
        raise GeometryError(f"domain must be an interval (a, b) with a < b, got {domain!r}")
    if isinstance(samples_per_span, bool) or not isinstance(samples_per_span, (int, np.integer)) or samples_per_span < 2:
        raise GeometryError(f"samples_per_span must be an integer >= 2, got {samples_per_span!r}")
    if fit not in ("interpolate", "least_squares"):
        raise GeometryError(f"fit must be 'interpolate' or 'least_squares', got {fit!r}")
    if fit == "least_squares" and samples_per_span < p + 1:
        raise GeometryError(f"least-squares fitting needs samples_per_span >= degree + 1 = {p + 1}")
    return p, tol, a, b, int(samples_per_span)


def _approximate_from(func, U, p, tol, a, b, max_knots, samples_per_span, fit, dim, stats):
    """Knot insertion loop of :func:`approximate`, starting from the full knot vector U."""
    while True:
        result = _fit_on_knots(func, U, p, samples_per_span, fit, dim)
        stats["evaluations"] += result.evaluations
        stats["iterations"] += 1
        failing = result.span_deviation > tol * (1.0 - DEVIATION_MARGIN)
        if not np.any(failing):
            return result
        br = result.breaks
        mids = 0.5 * (br[:-1] + br[1:])[failing]
        if len(U) + mids.size > max_knots:
            raise GeometryError(
                f"approximation did not reach the tolerance {tol:.3g} within {max_knots} knots "
                f"(max deviation {result.max_deviation:.3g} on {int(failing.sum())} span(s)); "
                "the curve may be non-smooth or the tolerance too small"
            )
        interior = np.sort(np.concatenate([U[p + 1 : len(U) - p - 1], mids]))
        U = _clamped(a, interior, b, p)


def approximate(
    func: Callable[[np.ndarray], np.ndarray],
    tolerance: float,
    degree: int = 3,
    domain=(0.0, 1.0),
    initial_knots=None,
    max_knots: int = DEFAULT_MAX_KNOTS,
    samples_per_span: int = DEFAULT_SAMPLES_PER_SPAN,
    fit: str = "interpolate",
    report: dict | None = None,
) -> BSplineCurve:
    """Approximate a parametric curve t -> func(t) to within ``tolerance`` by adaptive
    knot insertion (Hally 2013, §9, after the algorithm of his Ref. 6, Sec. 11).

    func: vectorised, takes a 1-D array of parameters in ``domain`` and returns points of
    shape (len(t), dim). The result is a clamped B-spline of ``degree`` on ``domain`` with
    |func(t) - C(t)| <= tolerance (the same parameter t, so the error bound holds for the
    parameterisation, not just the shape).

    Procedure: start from ``initial_knots`` (a full clamped vector or only its interior
    knots; None = a single Bézier span); fit; sample the deviation on
    ``samples_per_span`` + 1 points in every knot span (with one parabolic refinement of
    each span's largest sample); insert a knot at the midpoint of every span whose
    deviation exceeds the tolerance; repeat. Knots are only ever inserted, so the initial
    knots remain a subset of the final knot vector: the property Hally §9 relies on to
    build one knot sequence for many curves (see :func:`approximate_common`).

    The fit (``fit="interpolate"``, default) follows Hally §9 step 2, which samples each
    curve at the knot sequence and interpolates: here the curve is interpolated at the
    Greville abscissae of the knot vector, which for a cubic are the knots themselves
    plus one point inside each end span (NURBS Book Alg. A9.1 with prescribed knots;
    Schoenberg–Whitney holds). ``fit="least_squares"`` fits the span samples instead
    (NURBS Book §9.4.1, end points interpolated).

    report: if a dict is given it receives ``max_deviation``, ``n_knots``,
    ``n_control``, ``iterations`` and ``evaluations``. Raises :class:`GeometryError` if
    more than ``max_knots`` knots would be needed.
    """
    p, tol, a, b, S = _check_approximation_args(tolerance, degree, domain, samples_per_span, fit)
    U = _clamped(a, _interior_knots(initial_knots, p, a, b), b, p)
    stats = {"evaluations": 0, "iterations": 0}
    result = _approximate_from(func, U, p, tol, a, b, max_knots, S, fit, None, stats)
    if report is not None:
        report.update(
            max_deviation=result.max_deviation,
            n_knots=len(result.curve.knots),
            n_control=result.curve.n_control,
            **stats,
        )
    return result.curve


def approximate_common(
    funcs: Sequence[Callable[[np.ndarray], np.ndarray]],
    tolerance: float,
    degree: int = 3,
    domain=(0.0, 1.0),
    initial_knots=None,
    max_knots: int = DEFAULT_MAX_KNOTS,
    samples_per_span: int = DEFAULT_SAMPLES_PER_SPAN,
    fit: str = "interpolate",
    max_rounds: int = DEFAULT_MAX_ROUNDS,
    report: dict | None = None,
    seed_knots=None,
) -> list[BSplineCurve]:
    """Approximate several curves with ONE common knot vector (Hally 2013, §9).

    Hally's procedure: approximate the first curve from the initial knots with
    :func:`approximate`; approximate each following curve starting from the knots of the
    previous approximation; the last knot vector contains all earlier ones. Every curve is
    then refitted with that final knot vector. Hally notes each refit meets the accuracy
    because its knots contain those that sufficed for it; with an interpolating fit
    extra knots usually but not always reduce the error, so the refits are measured
    again and any curve that still fails seeds another round of knot insertion from the
    common vector (at most ``max_rounds`` rounds), until all curves meet ``tolerance``
    with the same knots.

    ``seed_knots``: a full clamped knot vector to try first (e.g. the one found for the same
    curves before a small edit): when every curve fitted on it meets the tolerance, by the
    same measure as the final check below, those fits are returned (``rounds`` 0);
    otherwise the procedure runs from ``initial_knots`` as if no seed were given, so knots
    never accumulate from one edit to the next.

    Returns the curves (same degree, same knots, domain ``domain``). ``report`` receives
    ``max_deviation`` (list per curve), ``n_knots``, ``n_control``, ``rounds`` and
    ``evaluations``.
    """
    p, tol, a, b, S = _check_approximation_args(tolerance, degree, domain, samples_per_span, fit)
    funcs = list(funcs)
    if not funcs:
        raise GeometryError("approximate_common needs at least one curve function")
    stats = {"evaluations": 0, "iterations": 0}
    limit = tol * (1.0 - DEVIATION_MARGIN)
    results, rounds = None, 0
    if seed_knots is not None:
        Us = np.asarray(seed_knots, dtype=np.float64)
        clamped = (Us.ndim == 1 and Us.size >= 2 * p + 2 and np.all(np.diff(Us) >= 0)
                   and np.all(Us[: p + 1] == a) and np.all(Us[-p - 1:] == b))
        if clamped:
            seeded = [_fit_on_knots(f, Us, p, S, fit, None) for f in funcs]
            stats["evaluations"] += sum(r.evaluations for r in seeded)
            if all(r.max_deviation <= limit for r in seeded):
                results, U = seeded, Us
    if results is None:
        U = _clamped(a, _interior_knots(initial_knots, p, a, b), b, p)
        pending = list(range(len(funcs)))
        while True:
            rounds += 1
            for i in pending:
                U = _approximate_from(funcs[i], U, p, tol, a, b, max_knots, S, fit, None, stats).curve.knots
            results = [_fit_on_knots(f, U, p, S, fit, None) for f in funcs]
            stats["evaluations"] += sum(r.evaluations for r in results)
            pending = [i for i, r in enumerate(results) if r.max_deviation > limit]
            if not pending:
                break
            if rounds >= max_rounds:
                raise GeometryError(
                    f"no common knot vector met the tolerance {tol:.3g} within {max_rounds} rounds "
                    f"(curves {pending} still fail)"
                )
    if report is not None:
        report.update(
            max_deviation=[r.max_deviation for r in results],
            n_knots=len(U),
            n_control=len(U) - p - 1,
            rounds=rounds,
            evaluations=stats["evaluations"],
        )
    return [r.curve for r in results]
