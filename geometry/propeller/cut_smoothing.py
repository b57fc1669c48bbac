"""Smoothing a blade cut near the tip (Hally 2013 §7, Eqs. 25–30), and the curvature
measures used to judge it.

Sampling (Eqs. 25–28): the cut's parameter curve p(t) (t = 1/2 on the edge, Eq. 24) is
sampled at t_i = f((i-1)/(N-1)), f two tanh distributions spliced at the edge so the
sample spacing grows from h at the edge to d at the ends, nearly geometrically:

    g(x) = u(x) / (A + (1 - A) u(x)),  u(x) = ½[1 + tanh((x - ½)Δ)/tanh(½Δ)],
    A = sqrt(h/d),  sinh Δ / Δ = L / (n sqrt(d h))   (n = (N-1)/2 intervals per half),
    r = (L - h)/(L - d),  N = 1 + 2 round(ln(d/h) / ln r).

Hally's Eq. 25 writes the second half as ½ + ½ g(2x - 1), which would put the fine
spacing at x_2 instead of at the edge; the second half here is the mirror image,
1 - ½ g(2 - 2x), so both halves are fine at the edge (t = 1/2 is sample (N+1)/2). Each
half uses its own length L (|x_1 - x_0| and |x_1 - x_2|) with the N of the longer half.
Eq. 27 is solved for Δ by Brent's method on log(sinh Δ / Δ) = log B (B <= 1 means the
spacings cannot be met: Δ -> 0, uniform spacing).

Filter (Eq. 29): y_i <- y_i + β_i/6 (-y_{i-2} + 4y_{i-1} - 6y_i + 4y_{i+1} - y_{i+2}),
n times, with the edge sample and the two samples at each end fixed (the ends lie on
the neighbouring surfaces' edges). β_i = α f(a/d_t) f(|y_i - x_1|/d_e) (Eq. 30), a the
distance along the edge from x_1 to the tip and f the cubic B-spline with knots
{-1, -½, 0, ½, 1} scaled to f(0) = 1. The explicit filter is stable for α <= 3/4.
The filter is a linear combination with zero-sum weights, so a planar cut stays in its
plane.

The smoothed cut: Hally interpolates the smoothed samples with a cubic spline. Here the
smoothed curve is the exact cut plus a cubic spline through the sample displacements
y_i^n - y_i^0, c(t) = b(p(t)) + d(t): it interpolates the same smoothed points, and where
the filter did not act (d = 0) it is the unsmoothed cut exactly rather than a spline
through samples of it (documented deviation; the sample density then no longer limits
the accuracy away from the edge).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.interpolate import make_interp_spline
from scipy.optimize import brentq

from ..errors import GeometryError
from .corners import SplineCurve, blade_points

#: Largest filter strength α for which the explicit fourth-difference filter is stable.
MAX_STABLE_FILTER_STRENGTH = 0.75
#: Curvature values below this fraction of the largest |κ| along a curve count as zero
#: when sign changes are counted.
CURVATURE_ZERO_FRACTION = 1e-3


def bump(x) -> np.ndarray:
    """The cubic B-spline with knots {-1, -½, 0, ½, 1} scaled so f(0) = 1 (Hally §7,
    Fig. 6): 1 - 6x² + 6|x|³ for |x| <= ½, 2(1 - |x|)³ for ½ <= |x| <= 1, else 0."""
    a = np.abs(np.asarray(x, dtype=np.float64))
    inner = 1.0 - 6.0 * a**2 + 6.0 * a**3
    outer = 2.0 * (1.0 - a) ** 3
    return np.where(a <= 0.5, inner, np.where(a < 1.0, outer, 0.0))


def _log_sinh_ratio(delta: float) -> float:
    """log(sinh Δ / Δ), stable for small and large Δ."""
    if delta < 1e-4:
        return delta * delta / 6.0
    return delta + np.log1p(-np.exp(-2.0 * delta)) - np.log(2.0) - np.log(delta)


def solve_stretching(B: float) -> float:
    """Δ with sinh Δ / Δ = B (Hally Eq. 27; Ref. 5 Annex A.5). B <= 1 gives 0."""
    if not np.isfinite(B):
        raise GeometryError(f"tanh distribution: sinh Δ/Δ = {B!r} is not finite")
    if B <= 1.0 + 1e-12:
        return 0.0
    target = np.log(B)
    hi = max(1.0, 2.0 * (target + np.log(2.0 * max(target, 1.0)) + 1.0))
    while _log_sinh_ratio(hi) < target:
        hi *= 2.0
    return float(brentq(lambda d: _log_sinh_ratio(d) - target, 0.0, hi, xtol=1e-14, rtol=1e-14))


def tanh_half(x, A: float, delta: float) -> np.ndarray:
    """g(x) of Hally Eq. 26 on [0, 1]: spacing ratio g'(1)/g'(0) = A²."""
    x = np.asarray(x, dtype=np.float64)
    if delta <= 0.0:
        u = x
    else:
        u = 0.5 * (1.0 + np.tanh((x - 0.5) * delta) / np.tanh(0.5 * delta))
    return u / (A + (1.0 - A) * u)


def sample_count(L: float, d: float, h: float) -> int:
    """N of Hally Eq. 28 (odd, at least 7)."""
    r = (L - h) / (L - d)
    n = int(np.rint(np.log(d / h) / np.log(r))) if r > 1.0 else 3
    return 1 + 2 * max(n, 3)


def edge_distribution(L_first: float, L_second: float, d: float, h: float) -> np.ndarray:
    """Sample parameters t_i in [0, 1] of Hally Eqs. 25–28, fine (h) at t = 1/2 and coarse
    (d) at the ends; the middle sample is exactly 1/2."""
    L = max(L_first, L_second)
    if not (h > 0 and d > h):
        raise GeometryError(f"tanh distribution: need 0 < h < d, got h = {h!r}, d = {d!r}")
    d = min(d, 0.25 * L)
    h = min(h, 0.01 * d) if h >= d else h
    N = sample_count(L, d, h)
    n = (N - 1) // 2
    A = np.sqrt(h / d)
    x = np.arange(n + 1) / n
    halves = []
    for Lh in (L_first, L_second):
        delta = solve_stretching(Lh / (n * np.sqrt(d * h)))
        halves.append(tanh_half(x, A, delta))
    first = 0.5 * halves[0]
    second = 1.0 - 0.5 * halves[1][::-1]
    t = np.concatenate([first, second[1:]])
    t[0], t[n], t[-1] = 0.0, 0.5, 1.0
    return t


def fourth_difference_filter(Y: np.ndarray, beta: np.ndarray, iterations: int) -> np.ndarray:
    """Hally Eq. 29: ``iterations`` Jacobi sweeps of y_i += β_i/6 (-y_{i-2} + 4y_{i-1}
    - 6y_i + 4y_{i+1} - y_{i+2}) on the interior samples 2..N-3 (β_i = 0 keeps a sample
    fixed). Y: (N, dim); beta: (N,)."""
    Y = np.array(Y, dtype=np.float64)
    b = (np.asarray(beta, dtype=np.float64)[2:-2] / 6.0)[:, None]
    if not np.any(b):
        return Y
    for _ in range(int(iterations)):
        Y[2:-2] += b * (-Y[:-4] + 4.0 * Y[1:-3] - 6.0 * Y[2:-2] + 4.0 * Y[3:-1] - Y[4:])
    return Y


@dataclass(frozen=True, eq=False)
class SmoothedCut:
    """A cut after Hally §7: ``curve`` (the exact cut plus the displacement spline),
    the samples t (N,), the points before (N, 3) and after (N, 3) filtering, β (N,),
    and the largest displacement (m)."""

    curve: SplineCurve
    t: np.ndarray
    before: np.ndarray
    after: np.ndarray
    beta: np.ndarray
    max_displacement: float


def smooth_cut(blade, cut, tip_distance: float, *, d_t: float, d_e: float, strength: float,
               iterations: int, spacing: float, edge_spacing: float) -> SmoothedCut:
    """Sample, filter and re-spline one cut (Hally Eqs. 25–30). ``tip_distance`` is a,
    the distance along the edge from x_1 to the tip (m); d_t, d_e, spacing (d) and
    edge_spacing (h) are in metres."""
    x0, x1, x2 = cut.points
    t = edge_distribution(float(np.linalg.norm(x1 - x0)), float(np.linalg.norm(x1 - x2)), spacing, edge_spacing)
    Y0 = blade_points(blade, cut.curve.parameters(t))
    beta = strength * bump(tip_distance / d_t) * bump(np.linalg.norm(Y0 - x1, axis=1) / d_e)  # Eq. 30
    mid = (len(t) - 1) // 2
    beta[[0, 1, mid, -2, -1]] = 0.0
    Y = fourth_difference_filter(Y0, beta, iterations)
    disp = Y - Y0
    offset = make_interp_spline(t, disp, k=3)
    return SmoothedCut(
        curve=replace(cut.curve, offset=offset), t=t, before=Y0, after=Y, beta=beta,
        max_displacement=float(np.max(np.linalg.norm(disp, axis=1))),
    )


# ---------------------------------------------------------------------------------------
# curvature (fairness of the cuts; reused by the curvature review)
# ---------------------------------------------------------------------------------------
def spline_signed_curvature(curve, t, normal) -> np.ndarray:
    """Signed curvature (1/m) of a B-spline curve (``BSplineCurve``) at t in the plane of
    unit normal n̂ (see :func:`signed_curvature`)."""
    D = curve.derivatives(np.asarray(t, dtype=np.float64), 2)
    return signed_curvature(D[:, 1], D[:, 2], normal)


def signed_curvature(first, second, normal) -> np.ndarray:
    """Signed curvature of a curve in the plane of unit normal n̂:
    κ = ((c' × c'')·n̂) / |c'|³. first, second: (n, 3)."""
    first, second = np.asarray(first, float), np.asarray(second, float)
    num = np.cross(first, second) @ np.asarray(normal, float)
    return num / np.linalg.norm(first, axis=-1) ** 3


def curvature_sign_changes(kappa, zero_fraction: float = CURVATURE_ZERO_FRACTION) -> int:
    """Number of sign changes along a sampled curvature κ_1..κ_n, ignoring values with
    |κ| < zero_fraction · max|κ| (they carry no reliable sign)."""
    k = np.asarray(kappa, dtype=np.float64)
    k = k[np.isfinite(k)]
    if k.size == 0:
        return 0
    limit = zero_fraction * np.max(np.abs(k))
    s = np.sign(k[np.abs(k) >= limit])
    return int(np.count_nonzero(s[1:] != s[:-1]))
