"""Curvature of plane curves: values at parameters, curvature plots, fairness numbers.

Hvid (1993) §2, Eq. 2.10 (signed curvature of a plane curve, numerator ẋÿ − ẏẍ, see the
typo note in shared/papers/README.md) and §3.1.1 (the curvature plot: curvature against
normalised arc length). Fairness numbers used by the acceptance tests of issue 6:
the number of curvature sign changes (inflection points, §3.1) and the total variation
of curvature along the curve.

All functions take a 2-D :class:`~bladesmith.geometry.nurbs.BSplineCurve` and are
vectorised over parameters.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..errors import GeometryError
from ..nurbs import BSplineCurve

#: Gauss–Legendre nodes per knot span used for arc length: exact for polynomial speed up
#: to degree 2*6-1 and far below 1e-12 relative error for the smooth cubic speeds here.
ARCLENGTH_GAUSS_NODES = 6

#: Default number of sub-intervals per knot span of the arc-length table.
ARCLENGTH_SUBDIVISIONS = 2

#: Default samples per knot span for curvature plots and fairness numbers.
PLOT_SAMPLES_PER_SPAN = 16

#: Curvature values with |κ| below this fraction of max |κ| are treated as zero when sign
#: changes are counted, so round-off around a straight stretch is not an inflection.
SIGN_CHANGE_RELATIVE_TOL = 1e-6


def _require_planar(curve: BSplineCurve) -> BSplineCurve:
    if not isinstance(curve, BSplineCurve):
        raise GeometryError(f"expected a BSplineCurve, got {type(curve).__name__}")
    if curve.dim != 2:
        raise GeometryError(f"expected a plane (2-D) curve, got dimension {curve.dim}")
    return curve


def derivatives(curve: BSplineCurve, params, order: int) -> list[np.ndarray]:
    """[C, C', ..., C^(order)] at ``params``, each params.shape + (dim,).

    Non-rational curves go through ``scipy.interpolate.BSpline`` (compiled de Boor), which
    is several times faster than the general NURBS evaluator for the dense samples
    taken here; rational curves use :meth:`BSplineCurve.derivatives`.
    """
    u = np.asarray(params, dtype=np.float64)
    if curve.is_rational:
        D = curve.derivatives(u, order)
        return [D[..., k, :] for k in range(order + 1)]
    a, b = curve.domain
    u = np.clip(u, a, b)
    spline = _scipy_spline(curve)
    return [spline(u, nu=k) for k in range(order + 1)]


def derivative(curve: BSplineCurve, params, order: int) -> np.ndarray:
    """C^(order) alone at ``params`` (the entry ``order`` of :func:`derivatives`, the same
    numbers, without evaluating the lower orders)."""
    if curve.is_rational:
        return derivatives(curve, params, order)[order]
    a, b = curve.domain
    return _scipy_spline(curve)(np.clip(np.asarray(params, dtype=np.float64), a, b), nu=order)


def _scipy_spline(curve: BSplineCurve):
    """The curve as a ``scipy.interpolate.BSpline`` (no extrapolation), made once per
    curve (curves are immutable) without re-checking the already validated knots: the
    smoothing evaluates each curve many times at a few points, where building it was most
    of the cost."""
    spline = curve.__dict__.get("_fairing_bspline")
    if spline is None:
        from scipy.interpolate import BSpline

        spline = BSpline.construct_fast(curve.knots, np.ascontiguousarray(curve.control_points), curve.degree,
                                        extrapolate=False)
        curve.__dict__["_fairing_bspline"] = spline
    return spline


@lru_cache(maxsize=None)
def _gauss_legendre(count: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights on [-1, 1] (``numpy.polynomial.legendre.leggauss``),
    computed once per count (read-only)."""
    x, w = np.polynomial.legendre.leggauss(count)
    x.flags.writeable = False
    w.flags.writeable = False
    return x, w


def curvature_at(curve: BSplineCurve, params) -> np.ndarray:
    """Signed curvature κ = (ẋÿ − ẏẍ)/(ẋ² + ẏ²)^{3/2} at ``params`` (Hvid 1993 Eq. 2.10):
    positive where the curve turns left (anticlockwise). Shape of ``params``."""
    _require_planar(curve)
    d1, d2 = derivative(curve, params, 1), derivative(curve, params, 2)
    return (d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]) / np.hypot(d1[..., 0], d1[..., 1]) ** 3


def breakpoints(curve: BSplineCurve) -> np.ndarray:
    """Distinct knot values inside the domain, ends included."""
    br = curve.__dict__.get("_fairing_breakpoints")  # curves are immutable: once per curve
    if br is None:
        a, b = curve.domain
        U = np.unique(curve.knots)
        br = U[(U >= a) & (U <= b)]
        br.flags.writeable = False
        curve.__dict__["_fairing_breakpoints"] = br
    return br


def span_samples(curve: BSplineCurve, per_span: int = PLOT_SAMPLES_PER_SPAN) -> np.ndarray:
    """``per_span`` uniform parameters per knot span, both domain ends included."""
    br = breakpoints(curve)
    local = np.arange(per_span) / per_span
    t = (br[:-1, None] + np.diff(br)[:, None] * local[None, :]).ravel()
    return np.concatenate([t, br[-1:]])


def arclength_table(curve: BSplineCurve, subdivisions: int = ARCLENGTH_SUBDIVISIONS) -> tuple[np.ndarray, np.ndarray]:
    """Parameters t_k and cumulative arc lengths s(t_k), both (K,), s_0 = 0.

    Each knot span is cut into ``subdivisions`` pieces integrated with
    :data:`ARCLENGTH_GAUSS_NODES`-point Gauss–Legendre quadrature of |C'(u)|.
    """
    t = span_samples(curve, subdivisions)
    x, w = _gauss_legendre(ARCLENGTH_GAUSS_NODES)
    half = 0.5 * np.diff(t)
    mid = 0.5 * (t[:-1] + t[1:])
    u = mid[:, None] + half[:, None] * x[None, :]
    speed = np.linalg.norm(derivative(curve, u, 1), axis=-1)
    pieces = half * (speed @ w)
    return t, np.concatenate([[0.0], np.cumsum(pieces)])


def arclength(curve: BSplineCurve) -> float:
    """Total arc length of the curve."""
    return float(arclength_table(curve)[1][-1])


def params_at_arclength(curve: BSplineCurve, fractions, table=None) -> np.ndarray:
    """Parameters at the given fractions (0..1) of the total arc length.

    Inverts :func:`arclength_table` with the cubic Hermite interpolant of u(s), whose
    slopes du/ds = 1/|C'(u)| are known at the table points (error O(h⁴) per piece).
    """
    t, s = arclength_table(curve) if table is None else table
    speed = np.linalg.norm(derivative(curve, t, 1), axis=-1)
    target = np.clip(np.asarray(fractions, dtype=np.float64), 0.0, 1.0) * s[-1]
    u = _hermite(s, t, 1.0 / np.maximum(speed, 1e-300))(target)
    a, b = curve.domain
    return np.clip(u, a, b)


def _hermite(x: np.ndarray, y: np.ndarray, dydx: np.ndarray):
    """``scipy.interpolate.CubicHermiteSpline(x, y, dydx)`` for 1-D float64 data: its
    piecewise-polynomial coefficients, the same arithmetic, given to ``PPoly`` without
    the input checks when x increases strictly (the class itself, which refuses the data
    with its own message, otherwise)."""
    from scipy.interpolate import CubicHermiteSpline, PPoly

    dx = np.diff(x)
    if not (x.ndim == 1 and x.size >= 2 and np.all(dx > 0) and np.all(np.isfinite(x))
            and np.all(np.isfinite(y)) and np.all(np.isfinite(dydx))):
        return CubicHermiteSpline(x, y, dydx)
    slope = np.diff(y, axis=0) / dx
    t = (dydx[:-1] + dydx[1:] - 2 * slope) / dx
    c = np.empty((4, len(x) - 1), dtype=t.dtype)
    c[0] = t / dx
    c[1] = (slope - dydx[:-1]) / dx - t
    c[2] = dydx[:-1]
    c[3] = y[:-1]
    return PPoly.construct_fast(c, x, extrapolate=True)


def curvature_plot(curve: BSplineCurve, per_span: int = PLOT_SAMPLES_PER_SPAN) -> tuple[np.ndarray, np.ndarray]:
    """The curvature plot of Hvid (1993) §3.1.1: (normalised arc length s/L, κ), each (K,).

    Samples ``per_span`` parameters per knot span; the arc length of each sample comes
    from the Gauss–Legendre table of :func:`arclength_table`.
    """
    curve = _require_planar(curve)
    t, s = arclength_table(curve, per_span)  # t: per_span parameters per knot span
    return s / s[-1], curvature_at(curve, t)


def count_sign_changes(kappa, tol: float | None = None) -> int:
    """Number of sign changes (inflection points, Hvid 1993 §3.1) in a curvature sequence.

    Values with |κ| <= tol (default :data:`SIGN_CHANGE_RELATIVE_TOL` × max |κ|) are
    skipped, so a run that touches zero without crossing is not counted.
    """
    k = np.asarray(kappa, dtype=np.float64).ravel()
    if k.size == 0:
        return 0
    if tol is None:
        tol = SIGN_CHANGE_RELATIVE_TOL * float(np.max(np.abs(k)))
    signs = np.sign(k[np.abs(k) > tol])
    return int(np.count_nonzero(signs[1:] != signs[:-1]))


def total_variation(kappa) -> float:
    """Total variation Σ|κ_{k+1} − κ_k| of a sampled curvature sequence."""
    k = np.asarray(kappa, dtype=np.float64).ravel()
    return float(np.sum(np.abs(np.diff(k))))


def curve_sign_changes(curve: BSplineCurve, per_span: int = PLOT_SAMPLES_PER_SPAN, tol: float | None = None) -> int:
    """:func:`count_sign_changes` of the curvature sampled ``per_span`` times per knot span."""
    return count_sign_changes(curvature_at(curve, span_samples(curve, per_span)), tol)


def curve_total_variation(curve: BSplineCurve, per_span: int = PLOT_SAMPLES_PER_SPAN) -> float:
    """:func:`total_variation` of the curvature sampled ``per_span`` times per knot span
    (a lower bound of the exact total variation that converges as ``per_span`` grows)."""
    return total_variation(curvature_at(curve, span_samples(curve, per_span)))


def curvature_comb(curve: BSplineCurve, scale: float, per_span: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Base points and tips of a curvature comb: tip = C(u) − scale κ(u) N(u), with N the
    left unit normal, so teeth stand outside convex (κ > 0) stretches. Both (K, 2)."""
    curve = _require_planar(curve)
    u = span_samples(curve, per_span)
    c, d1, d2 = derivatives(curve, u, 2)
    speed = np.linalg.norm(d1, axis=1)
    kappa = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / speed**3
    normal = np.stack([-d1[:, 1], d1[:, 0]], axis=1) / speed[:, None]
    return c, c - scale * kappa[:, None] * normal
