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

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline
from scipy.optimize import brentq

from ..errors import GeometryError
from .corners import SplineCurve, blade_points

#: Largest filter strength α for which the explicit fourth-difference filter is stable.
MAX_STABLE_FILTER_STRENGTH = 0.75
#: Documented bound on the deviation inside the smoothing zone, as a fraction of R.
SMOOTHING_ZONE_BOUND = 5e-3
#: Share of that bound the filter's own displacement may use (the rest is left for the
#: spline surfaces of §9 between the cuts).
GUARD_BOUND_FRACTION = 0.8
#: β tapers to 0 over this fraction of the shorter half of a cut next to its ends.
END_TAPER_FRACTION = 0.5
#: Changes of a cut's excess curvature variation below this fraction of its unsmoothed
#: value (plus this fraction of 1/d_e) are rounding, not a rise.
GUARD_RELATIVE_SLACK = 1e-9
#: The guard looks at the filter after 1, r, r², ... and n sweeps (r this ratio).
GUARD_CHECKPOINT_RATIO = 4
#: Power iterations that estimate the filter's largest mode, and the margin on the
#: estimate (power iteration approaches the spectral radius from below).
STABILITY_POWER_ITERATIONS = 200
STABILITY_MARGIN = 1.02
#: Parameters of a cut's smoothing window at which the guard measures the curvature.
GUARD_WINDOW_SAMPLES = 1201
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


def fourth_difference_filter(Y: np.ndarray, beta: np.ndarray, iterations: int, spacing=None) -> np.ndarray:
    """Hally Eq. 29: ``iterations`` Jacobi sweeps of y_i += β_i/6 (-y_{i-2} + 4y_{i-1}
    - 6y_i + 4y_{i+1} - y_{i+2}) on the interior samples 2..N-3 (β_i = 0 keeps a sample
    fixed). Y: (N, dim); beta: (N,). With ``spacing`` (the samples' arclength s, (N,))
    the fourth difference is taken in s (:func:`filter_matrix`), not in the index."""
    Y = np.array(Y, dtype=np.float64)
    if spacing is not None:
        M = filter_matrix(spacing, beta)
        return np.linalg.matrix_power(M, int(iterations)) @ Y
    b = (np.asarray(beta, dtype=np.float64)[2:-2] / 6.0)[:, None]
    if not np.any(b):
        return Y
    for _ in range(int(iterations)):
        Y[2:-2] += b * (-Y[:-4] + 4.0 * Y[1:-3] - 6.0 * Y[2:-2] + 4.0 * Y[3:-1] - Y[4:])
    return Y


def fourth_difference_weights(s: np.ndarray) -> np.ndarray:
    """Weights W (N, N) with (W y)_i = -h_i^4 y^(4)(s_i) for the interior samples
    2..N-3 (rows of the others are 0): y^(4) = 24 y[s_{i-2}, ..., s_{i+2}] (the fourth
    divided difference), h_i = (s_{i+2} - s_{i-2})/4 the local spacing. On uniform
    spacing a row is (-1, 4, -6, 4, -1), the stencil of Hally Eq. 29."""
    s = np.asarray(s, dtype=np.float64)
    N = s.size
    W = np.zeros((N, N))
    if N < 5:
        return W
    i = np.arange(2, N - 2)
    cols = i[:, None] + np.arange(-2, 3)[None, :]
    nodes = s[cols]  # (m, 5)
    diff = nodes[:, :, None] - nodes[:, None, :]
    diff[:, np.arange(5), np.arange(5)] = 1.0
    w = 1.0 / np.prod(diff, axis=2)  # divided-difference weights
    h = (nodes[:, 4] - nodes[:, 0]) / 4.0
    W[i[:, None], cols] = -24.0 * h[:, None] ** 4 * w
    return W


def filter_matrix(s: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """One sweep of the filter as a matrix, M = I + diag(β/6) W (W of
    :func:`fourth_difference_weights`, the fourth difference in arclength s), with β
    already scaled by :func:`stable_strength_scale`.

    Why not the index: on tanh-clustered samples the index-space stencil of Eq. 29 is
    not a fourth derivative (it carries the growth of the spacing), so many sweeps drive
    the points towards a cubic in the index, which is not a smooth curve in space; that
    is why strong settings roughened the tip. In s the fixed point of the sweeps is a
    cubic in arclength."""
    beta = np.asarray(beta, dtype=np.float64)
    W = fourth_difference_weights(s)
    scale = stable_strength_scale(W, beta)
    return np.eye(len(beta)) + scale * (beta / 6.0)[:, None] * W


def stable_strength_scale(W: np.ndarray, beta: np.ndarray) -> float:
    """The factor (<= 1) on β that keeps a sweep y <- (I + B) y, B = diag(β/6) W, from
    growing its largest mode: the spectral radius ρ of B is estimated by power iteration
    (STABILITY_POWER_ITERATIONS products, times STABILITY_MARGIN) and β scaled so that
    ρ <= 2, the limit of the explicit filter (on uniform samples ρ = 16 α/6: α = 3/4 is
    then scaled by 1/1.02; on Hally's nearly geometric samples the factor stays close to 1). The guard of
    :func:`smooth_cut` catches any slower growth (rougher or moved beyond the bound)."""
    active = np.flatnonzero(beta > 0)
    if active.size == 0:
        return 1.0
    B = (beta[active] / 6.0)[:, None] * W[np.ix_(active, active)]
    x = np.random.default_rng(0).standard_normal(active.size)
    rho = 0.0
    for _ in range(STABILITY_POWER_ITERATIONS):
        y = B @ x
        rho = math.sqrt(y.dot(y))  # np.linalg.norm's own formula, without its per-call checks
        if rho == 0.0:
            return 1.0
        x = y / rho
    return min(1.0, 2.0 / (STABILITY_MARGIN * rho))


@dataclass(frozen=True, eq=False)
class SmoothedCut:
    """A cut after Hally §7: ``curve`` (the exact cut blended into the spline of the
    smoothed samples), the samples t (N,), the points before (N, 3) and after (N, 3)
    filtering, β (N,), the largest displacement (m), the sweeps kept (``iterations``:
    fewer than asked when the guard stopped the filter), ``stopped`` (None, or why and
    with which figures the guard stopped early) and ``irregularity`` (the guard's excess
    curvature variation of the cut before and after, 1/m)."""

    curve: SplineCurve
    t: np.ndarray
    before: np.ndarray
    after: np.ndarray
    beta: np.ndarray
    max_displacement: float
    iterations: int = 0
    stopped: str | None = None
    irregularity: tuple = ()


class BlendedOffset:
    """The displacement of a smoothed cut from b(p(t)) (Hally §7). Inside the filter's
    window the smoothed curve is Hally's cubic spline S through the smoothed samples;
    outside it, the exact cut plus the spline of the sample displacements d(t); the
    weight w(t) (the in-cut factor f(|y - x_1|/d_e) of Eq. 30 at the samples, splined)
    blends them:

        c(t) = b(p(t)) + d(t) + w(t) (S(t) - b(p(t)) - d(t)).

    Both curves pass through the smoothed samples, so c does too. Inside the window the
    exact cut's features finer than the sample spacing h are not kept: they are the tip
    irregularities the smoothing is for (with the exact cut plus d(t) alone, the
    filter could never remove them, which is why the defaults changed nothing)."""

    def __init__(self, blade, parameters, spline, disp, weight):
        self.blade, self.parameters, self.spline, self.disp, self.weight = blade, parameters, spline, disp, weight
        #: the three splines as one (columns w, d, S) when they share their knots: one
        #: evaluation gives each column's values of its own spline
        self.joint = None
        if (np.array_equal(spline.t, disp.t) and np.array_equal(spline.t, weight.t)
                and spline.k == disp.k == weight.k and np.ndim(weight.c) == 1):
            self.joint = BSpline.construct_fast(
                spline.t, np.concatenate([np.asarray(weight.c)[:, None], disp.c, spline.c], axis=1), spline.k)

    def __call__(self, t):
        t = np.asarray(t, dtype=np.float64)
        return self.on_exact(t, None)

    def on_exact(self, t, X):
        """The displacement at t; X: the exact cut b(p(t)) there when already known."""
        if self.joint is not None:
            V = self.joint(t)
            w, d, S = np.clip(V[:, 0], 0.0, 1.0), V[:, 1:4], V[:, 4:7]
        else:
            d = self.disp(t)
            w = np.clip(self.weight(t), 0.0, 1.0)
            S = None
        out = np.array(d)
        on = w > 0.0
        if np.any(on):
            Xo = blade_points(self.blade, self.parameters.parameters(t[on])) if X is None else X[on]
            out[on] = d[on] + w[on, None] * ((self.spline(t[on]) if S is None else S[on]) - Xo - d[on])
        return out


def smooth_cut(blade, cut, tip_distance: float, *, d_t: float, d_e: float, strength: float,
               iterations: int, spacing: float, edge_spacing: float, bound: float | None = None) -> SmoothedCut:
    """Sample, filter and re-spline one cut (Hally Eqs. 25–30). ``tip_distance`` is a,
    the distance along the edge from x_1 to the tip (m); d_t, d_e, spacing (d) and
    edge_spacing (h) are in metres.

    The filter runs in arclength (:func:`filter_matrix`). A guard looks at it after 0,
    1, 4, 16, ... (GUARD_CHECKPOINT_RATIO) and n sweeps and keeps the checkpoint whose
    curve (the smoothed cut, see :class:`BlendedOffset`) has the least excess curvature
    variation in the window (:mod:`.irregularity`), among those
    whose largest displacement stays within ``bound`` (m): more sweeps never leave the cut
    rougher than fewer, nor move it beyond the bound. When the guard keeps fewer than n
    sweeps, ``stopped`` says why, with the figures. n = 0 leaves the cut exact.
    (:func:`smooth_cuts` with one cut.)"""
    return smooth_cuts(blade, [cut], [tip_distance], d_t=d_t, d_e=d_e, strength=strength, iterations=iterations,
                       spacing=spacing, edge_spacing=edge_spacing, bound=bound)[0]


def _filter_bands(s: np.ndarray) -> np.ndarray:
    """The non-zero band of :func:`fourth_difference_weights` (rows 2..N-3, columns
    i-2..i+2): (N-4, 5), the same numbers without the dense matrix."""
    N = s.size
    i = np.arange(2, N - 2)
    cols = i[:, None] + np.arange(-2, 3)[None, :]
    nodes = s[cols]  # (m, 5)
    diff = nodes[:, :, None] - nodes[:, None, :]
    diff[:, np.arange(5), np.arange(5)] = 1.0
    w = 1.0 / np.prod(diff, axis=2)
    h = (nodes[:, 4] - nodes[:, 0]) / 4.0
    return -24.0 * h[:, None] ** 4 * w


def _strength_scale(bands: np.ndarray, beta: np.ndarray) -> float:
    """:func:`stable_strength_scale` for the filter of ``bands`` (:func:`_filter_bands`).

    The power iteration there estimates |B x| with |x| = 1, which cannot exceed the 2-norm
    of B, and |B|_2 <= sqrt(|B|_1 |B|_inf). When that bound already keeps the estimate
    below 2/STABILITY_MARGIN the factor is exactly 1 and the iteration is skipped (the
    common case, Hally's nearly geometric samples); otherwise it runs as before."""
    active = beta > 0
    if not np.any(active):
        return 1.0
    N = beta.size
    cols = np.arange(2, N - 2)[:, None] + np.arange(-2, 3)[None, :]
    A = np.abs((beta[2:-2] / 6.0)[:, None] * bands) * (active[2:-2, None] & active[cols])
    row = float(A.sum(axis=1).max())
    col = float(np.bincount(cols.ravel(), weights=A.ravel(), minlength=N).max())
    if math.sqrt(row * col) * STABILITY_MARGIN * (1.0 + 1e-9) < 2.0:
        return 1.0
    W = np.zeros((N, N))
    W[np.arange(2, N - 2)[:, None], cols] = bands
    return stable_strength_scale(W, beta)


def _checkpoints(n: int) -> list[int]:
    levels = int(np.log(n) / np.log(GUARD_CHECKPOINT_RATIO)) + 2
    return sorted({min(GUARD_CHECKPOINT_RATIO**k, n) for k in range(levels)})


def smooth_cuts(blade, cuts, tip_distances, *, d_t: float, d_e: float, strength: float,
                iterations: int, spacing: float, edge_spacing: float, bound: float | None = None) -> list[SmoothedCut]:
    """:func:`smooth_cut` for several cuts at once: the same samples, filter, guard and
    curves, cut by cut, with b evaluated once for all cuts at each stage, the filter
    sweeps of all cuts run on one concatenated array (the samples next to the cuts'
    ends are fixed, so no cut reads another), one interpolation per cut for its
    splines, and the guard's curvature measured for every cut and checkpoint in one
    banded solve (:func:`~.irregularity.curve_excess_uniform`)."""
    from .irregularity import curve_excess_uniform, measure_windows

    K = len(cuts)
    n = int(iterations)
    ts, pars = [], []
    for cut in cuts:
        x0, x1, x2 = cut.points
        t = edge_distribution(float(np.linalg.norm(x1 - x0)), float(np.linalg.norm(x1 - x2)), spacing, edge_spacing)
        ts.append(t)
        pars.append(cut.curve.parameters(t))
    Yall = blade_points(blade, np.concatenate(pars))
    offsets = np.cumsum([0] + [t.size for t in ts])
    results: list = [None] * K
    work = []  # cuts the filter acts on: (k, t, Y0, beta, in_cut, coef, bands)
    for k, (cut, t, a) in enumerate(zip(cuts, ts, tip_distances)):
        x1 = cut.points[1]
        Y0 = Yall[offsets[k] : offsets[k + 1]]
        in_cut = bump(np.linalg.norm(Y0 - x1, axis=1) / d_e)
        # β falls smoothly to 0 towards the ends, which stay on c_9/c_10 (c_5..c_8): a pinned
        # end inside the window would put a kink into the cut next to it
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(Y0, axis=0), axis=1))])
        to_end = np.minimum(s, s[-1] - s)
        taper = 1.0 - bump(to_end / (END_TAPER_FRACTION * min(s[len(t) // 2], s[-1] - s[len(t) // 2])))
        beta = strength * bump(a / d_t) * in_cut * taper  # Eq. 30
        beta[[0, 1, -2, -1]] = 0.0
        if n == 0 or not np.any(beta > 0):
            results[k] = SmoothedCut(curve=cut.curve, t=t, before=Y0, after=Y0, beta=beta, max_displacement=0.0)
            continue
        bands = _filter_bands(s)
        coef = _strength_scale(bands, beta) * beta[2:-2] / 6.0
        work.append((k, t, Y0, beta, in_cut, coef, bands))
    if not work:
        return results
    # --- the sweeps of every cut on one array: y_i += coef_i Σ_k band_ik y_{i-2+k} on the
    # interior samples (Eq. 29 in arclength, the banded form of :func:`filter_matrix`)
    Y0cat = np.concatenate([w[2] for w in work])
    starts = np.cumsum([0] + [len(w[1]) for w in work])
    weights = np.zeros((5, len(Y0cat) - 4, 1))
    for (k, t, Y0, beta, in_cut, coef, bands), o in zip(work, starts):
        for j in range(5):
            weights[j, o : o + len(t) - 4, 0] = coef * bands[:, j]
    Y = np.array(Y0cat)
    done = 0
    kept = [[] for _ in work]  # (checkpoint, Y) per cut
    stop: list = [None] * len(work)
    for c in _checkpoints(n):
        w = weights
        for _ in range(c - done):
            Y[2:-2] += w[0] * Y[:-4] + w[1] * Y[1:-3] + w[2] * Y[2:-2] + w[3] * Y[3:-1] + w[4] * Y[4:]
        done = c
        for i, o in enumerate(starts[:-1]):
            if stop[i] is not None:
                continue
            Yc = Y[o : starts[i + 1]]
            moved = float(np.max(np.linalg.norm(Yc - work[i][2], axis=1)))
            if bound is not None and moved > bound:
                stop[i] = (c, moved)
                weights = weights.copy()
                weights[:, o : starts[i + 1] - 4] = 0.0  # this cut stops here
                continue
            kept[i].append((c, Yc.copy()))
    # --- the guard's measure: every cut's window, its checkpoints' curves, one batch
    windows = measure_windows(blade, [cuts[w[0]] for w in work], d_e)
    Xw_all = blade_points(blade, np.stack([cuts[w[0]].curve.parameters(tw) for w, tw in zip(work, windows)]))
    splines, curves_w = [], []
    for i, (k, t, Y0, beta, in_cut, coef, bands) in enumerate(work):
        tw, Xw = windows[i], Xw_all[i]
        m = len(kept[i])
        curves_w.append(Xw[None])
        if m:
            Yk = np.stack([Yc for _, Yc in kept[i]], axis=1)  # (N, checkpoints, 3)
            rhs = np.concatenate([in_cut[:, None], Yk.reshape(len(t), -1), (Yk - Y0[:, None]).reshape(len(t), -1)],
                                 axis=1)
        else:
            rhs = in_cut[:, None]
        # one interpolation for the weight, the checkpoints' curves and their displacements
        # (LAPACK solves the columns independently: each is the spline of its own call)
        S = make_interp_spline(t, rhs, k=3)
        splines.append(S)
        if m:
            V = S(tw)
            wv = np.clip(V[:, 0], 0.0, 1.0)
            through = np.moveaxis(V[:, 1 : 1 + 3 * m].reshape(-1, m, 3), 1, 0)
            d = np.moveaxis(V[:, 1 + 3 * m :].reshape(-1, m, 3), 1, 0)
            # BlendedOffset.on_exact for every checkpoint at once
            out = np.array(d)
            on = wv > 0.0
            if np.any(on):
                out[:, on] = d[:, on] + wv[on, None] * (through[:, on] - Xw[on] - d[:, on])
            curves_w.append(Xw + out)
    excess_all = curve_excess_uniform(np.concatenate(curves_w))
    sizes = np.cumsum([0] + [1 + len(kept_i) for kept_i in kept])  # the window curve + the checkpoints
    for i, (k, t, Y0, beta, in_cut, coef, bands) in enumerate(work):
        cut = cuts[k]
        excess = excess_all[sizes[i] : sizes[i + 1]]
        first = excess[0]
        slack = GUARD_RELATIVE_SLACK * first + GUARD_RELATIVE_SLACK / d_e
        best_e, best_n, best_Y, best_i = first, 0, Y0, None
        last_e = first
        for j, ((c, Yc), e) in enumerate(zip(kept[i], excess[1:])):
            last_e = e
            if e <= best_e + slack:
                best_e, best_n, best_Y, best_i = e, c, Yc, j
        why = None
        if stop[i] is not None:
            c, moved = stop[i]
            why = (f"kept {best_n} of {n} sweeps: {c} sweeps would move the cut by {moved:.3g} m, "
                   f"beyond the deviation bound {bound:.3g} m")
        elif best_n != n and last_e > best_e + slack:
            why = (f"kept {best_n} of {n} sweeps: more sweeps raise the cut's excess curvature variation "
                   f"({best_e:.4g} 1/m at {best_n} sweeps, {last_e:.4g} 1/m at {n}; unsmoothed {first:.4g} 1/m)")
        if best_n == 0:
            results[k] = SmoothedCut(curve=cut.curve, t=t, before=Y0, after=Y0, beta=beta, max_displacement=0.0,
                                     stopped=why, irregularity=(first, first))
            continue
        S, m = splines[i], len(kept[i])
        C = S.c
        weight = BSpline.construct_fast(S.t, np.ascontiguousarray(C[:, 0]), 3)
        through = BSpline(S.t, C[:, 1 : 1 + 3 * m].reshape(-1, m, 3)[:, best_i], 3)
        disp = BSpline(S.t, C[:, 1 + 3 * m :].reshape(-1, m, 3)[:, best_i], 3)
        off = BlendedOffset(blade, cut.curve, through, disp, weight)
        results[k] = SmoothedCut(
            curve=replace(cut.curve, offset=off), t=t, before=Y0, after=best_Y, beta=beta,
            max_displacement=float(np.max(np.linalg.norm(best_Y - Y0, axis=1))), iterations=best_n, stopped=why,
            irregularity=(first, best_e),
        )
    return results


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
