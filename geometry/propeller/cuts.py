"""Planar blade cuts (Hally 2013 §6, Eqs. 15–24).

A cut is the intersection of the blade with the plane through x_0 (pressure or first
side), x_1 (on the leading or trailing edge) and x_2 (the other side), normal
n = (x_1 - x_0) × (x_1 - x_2) (Eq. 15). A blade point b(ξ, η) is on it when
(b - x_0)·n̂ = 0 (Eq. 16).

Tip chart (deviation from Hally, who works in (ξ, η)): cuts are marched and splined in
(X, Y) = w (cos 2πξ, sin 2πξ), w = sqrt(1 - η) (:func:`~.corners.to_tip_chart`). The
blade is regular in this chart at the tip point, where (ξ, η) is singular; near-tip cuts
of skewed blades that pass over the tip cap are smooth curves there instead of curves
that run along η = 1. Eqs. 18–22 are applied with (X, Y) in place of (ξ, η); the edge
lines ξ = 0 and ξ = 1/2 are the rays Y = 0, X > 0 and X < 0; a_i of Eq. 24 is the
arclength in the chart. Eq. 21 (ξ alone at fixed η) is a search along the circle of
radius w.

Speed: the march runs on a cached bicubic Hermite surrogate of b (:class:`BladeCache`);
every node is then moved onto the exact b ∩ plane in one vectorised pass (Newton along
the Eq. 20 perpendicular, with the Eq. 21 and Eq. 22 fallbacks, counted per cut).

Marching (all cuts and both halves at once, vectorised): each cut is traced from x_0 to
x_1 and, separately, from x_2 to x_1, so the edge point is a node of the cut exactly.
From a point on the cut the parameter-space tangent is t = (-b_η·n̂, b_ξ·n̂) (Eq. 18); the
predictor is p + α t̂ (Eq. 19); it is corrected by Newton on s along the perpendicular
line ξ(s) = ξ + sΔη, η(s) = η - sΔξ (Eqs. 16, 20). Where that fails, a Newton search in
ξ alone at η_i + Δη (Eq. 21) is tried, then bisection on s between points on either
side of the plane (Eq. 22). If every attempt fails a GeometryError names the cut and
the (ξ, η) where it stopped.

Step length (Eq. 23): α = α_max (1 - (1 - r) ρ) with ρ = |b - x_start|/|x_1 - x_start|, so
the steps shrink towards the edge point where the blade curvature is high. Hally uses
α_max = 3·10⁻³ and r = 10⁻³ (thousands of steps); here α_max = min(MARCH_MAX_STEP,
|p_1 - p_start| / MARCH_MIN_STEPS) and r = MARCH_MIN_RATIO, with a turning-angle limit
(MARCH_MAX_TURN per step) that keeps the parameter curve resolved where it bends. The
nodes are only used through the cubic spline of step 3 below, which is what these
constants are chosen for (see tests); the cut stays exactly on the blade whatever the
node spacing, as Hally notes.

Parameterisation (Eq. 24): with a_i the parameter-space arclength and m the index of the
edge point, t_i = (a_i/a_N)[1 + (a_N - a_i)(a_N - 2a_m) / (2 a_m (a_N - a_m))] puts the
edge point at t = 1/2. This quadratic is monotone only for 0.293 < a_m/a_N < 0.707; outside
that range (very unequal halves) each half is scaled linearly instead (documented
deviation). A cubic spline through (t_i, ξ_i) and (t_i, η_i) is the parameter curve.

Trailing-edge cuts run on the periodic blade: their suction-side ξ is written as ξ - 1,
so the cut crosses ξ = 0 continuously (Hally §6, last paragraph).
"""
from __future__ import annotations

import weakref
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import make_interp_spline

from ..errors import GeometryError
from .corners import ETA_TIP_GUARD, SplineCurve, blade_derivatives, blade_points, from_tip_chart, to_tip_chart

#: Largest parameter-space step α_max (Hally Eq. 23 uses 0.003).
MARCH_MAX_STEP = 0.04
#: At least this many steps from the start to the edge point.
MARCH_MIN_STEPS = 12
#: Smallest step as a fraction of α_max, reached at the edge point (Hally: 0.001).
MARCH_MIN_RATIO = 0.1
#: Largest turning angle of the parameter curve per step (radians).
MARCH_MAX_TURN = 0.12
#: Cells of the cached surrogate of b used for marching (ξ and w = sqrt(1 - η)).
CACHE_XI_CELLS = 256
CACHE_W_CELLS = 48
#: Extra cell rows built beyond the farthest one reached (:class:`BladeCache`).
CACHE_ROW_MARGIN = 2
#: The ξ-search of Eq. 21 must stay this close (in ξ) to the predictor.
XI_SEARCH_MAX_SHIFT = 0.25
#: A half-cut that reaches the edge line ξ = ξ_1 farther than this fraction of its
#: parameter length from x_1 has met the edge elsewhere (error).
EDGE_ARRIVAL_TOL = 0.05
#: Cap on the number of steps of one half cut.
MARCH_MAX_STEPS = 4000
#: A point is on the plane when |(b - x_0)·n̂| is below this fraction of R.
PLANE_TOL = 1e-11
#: Newton iterations of the corrector (Eqs. 20, 21).
NEWTON_MAX_ITERATIONS = 8
#: Bisection (Eq. 22) stops when the bracket is this short in parameter space.
BISECTION_TOL = 1e-13
#: Bracket search of the bisection: samples of s in [-BRACKET_SPAN, BRACKET_SPAN].
BRACKET_SPAN = 2.0
BRACKET_SAMPLES = 41


@dataclass(frozen=True, eq=False)
class BladeCut:
    """One planar cut (Hally §6).

    params: (N, 2) nodes (ξ, η) from x_0 through x_1 to x_2; edge_index: m, the node on
    the edge; t: (N,) spline parameters of Eq. 24 (t[m] = 1/2); curve: the parameter
    spline (:class:`~.corners.SplineCurve`); normal: n̂ (3,); points: x_0, x_1, x_2
    (3, 3); fallbacks: how many nodes needed Eq. 21 or Eq. 22; label: where it came from.
    """

    params: np.ndarray
    edge_index: int
    t: np.ndarray
    curve: SplineCurve
    normal: np.ndarray
    points: np.ndarray
    fallbacks: dict = field(default_factory=dict)
    label: str = ""

    def plane_residual(self, blade, t) -> np.ndarray:
        """|(b(p(t)) - x_0)·n̂| in metres: how far the splined cut leaves its plane."""
        X = self.curve.points(blade, t)
        return np.abs((X - self.points[0]) @ self.normal)


def cut_parameters(a: np.ndarray, m: int) -> np.ndarray:
    """Spline parameters t_i of Hally Eq. 24 from the cumulative arclengths a_i, with
    t_m = 1/2 exactly; linear scaling of each half where Eq. 24 is not monotone."""
    aN, am = a[-1], a[m]
    x = am / aN
    lo, hi = 1.0 - np.sqrt(0.5), np.sqrt(0.5)
    if lo < x < hi:
        t = (a / aN) * (1.0 + (aN - a) * (aN - 2.0 * am) / (2.0 * am * (aN - am)))
    else:
        t = np.where(a <= am, 0.5 * a / am, 0.5 + 0.5 * (a - am) / (aN - am))
    t[0], t[m], t[-1] = 0.0, 0.5, 1.0
    return t


def _fail(label, p, what):
    return GeometryError(
        f"blade cut {label}: {what} at ξ = {p[0]:.6g}, η = {p[1]:.6g} "
        "(Hally 2013 §6: Newton, ξ-search and bisection all failed)"
    )


class BladeCache:
    """A cached bicubic Hermite surrogate of b(ξ, w) with w = sqrt(1 - η), used to march
    the cuts cheaply; the nodes are then refined on the exact blade (:func:`march_cuts`).

    b, b_ξ, b_w and b_ξw are taken from the exact blade on a uniform grid of
    ``n_xi`` x ``n_w`` cells (ξ periodic on [0, 1], w on [0, sqrt(1 - eta_min)]); in w the
    closing tip chord c ~ sqrt(1 - η) is smooth, so the surrogate is accurate up to the
    tip. Evaluation is a gather of per-cell power-basis coefficients (a few numpy
    operations whatever the number of points)."""

    _H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [-3.0, 3.0, -2.0, -1.0], [2.0, -2.0, 1.0, 1.0]])

    def __init__(self, blade, n_xi: int = CACHE_XI_CELLS, n_w: int = CACHE_W_CELLS):
        self.blade = blade
        self.n_xi, self.n_w = n_xi, n_w
        self.w_max = float(np.sqrt(1.0 - blade.eta_min))
        self.hx = 1.0 / n_xi
        self.hw = self.w_max / n_w
        self._xg = np.arange(n_xi + 1) * self.hx
        wg = np.arange(n_w + 1) * self.hw
        self._wg_eval = np.maximum(wg, np.sqrt(ETA_TIP_GUARD))
        self._eta = np.clip(1.0 - self._wg_eval**2, blade.eta_min, 1.0 - ETA_TIP_GUARD)
        self.coef = np.empty((n_xi, n_w, 4, 4, 3))
        #: cell rows (in w, from the tip) whose coefficients are filled: the cuts near the
        #: tip visit about half of them, so rows are built when first reached
        self.rows = 0

    def _build_rows(self, rows: int) -> None:
        """Fill the coefficients of the cell rows self.rows .. rows - 1 (each cell from
        the exact b and its derivatives at its corners, as if the whole grid were built)."""
        rows = min(int(rows), self.n_w)
        a = self.rows
        if rows <= a:
            return
        xg, wg_eval, eta = self._xg, self._wg_eval[a : rows + 1], self._eta[a : rows + 1]
        D = self.blade.mixed_derivatives(xg[:-1, None], eta[None, :])  # (n_xi, rows-a+1, 3, 3, 3)
        D = np.concatenate([D, D[:1]], axis=0)
        dw = -2.0 * wg_eval[None, :, None]  # dη/dw
        F = D[..., 0, 0, :]
        Fx = D[..., 1, 0, :] * self.hx
        Fw = D[..., 0, 1, :] * dw * self.hw
        Fxw = D[..., 1, 1, :] * dw * self.hx * self.hw
        # Hermite data per cell corner: G[a, b] for the 4x4 geometry matrix
        def corners(A):
            return np.stack([A[:-1, :-1], A[1:, :-1], A[:-1, 1:], A[1:, 1:]], axis=0)

        f, fx, fw, fxw = corners(F), corners(Fx), corners(Fw), corners(Fxw)
        G = np.empty((4, 4) + f.shape[1:])
        # rows: value at x=0, x=1, d/dx at 0, 1; cols: same in w
        G[0, 0], G[1, 0], G[0, 1], G[1, 1] = f[0], f[1], f[2], f[3]
        G[2, 0], G[3, 0], G[2, 1], G[3, 1] = fx[0], fx[1], fx[2], fx[3]
        G[0, 2], G[1, 2], G[0, 3], G[1, 3] = fw[0], fw[1], fw[2], fw[3]
        G[2, 2], G[3, 2], G[2, 3], G[3, 3] = fxw[0], fxw[1], fxw[2], fxw[3]
        self.coef[:, a:rows] = np.einsum("ai,ijxyk,bj->xyabk", self._H, G, self._H)
        self.rows = rows

    def derivatives(self, p, order: int = 1) -> np.ndarray:
        """b, b_ξ, b_η of the surrogate at p (n, 2), in the layout of
        ``BladeSurface.derivatives(order=1)``: (n, 2, 2, 3)."""
        xi = np.mod(p[:, 0], 1.0)
        w = np.sqrt(np.maximum(1.0 - p[:, 1], ETA_TIP_GUARD))
        x = xi / self.hx
        i = np.minimum(x.astype(np.intp), self.n_xi - 1)
        y = np.minimum(w, self.w_max) / self.hw
        j = np.minimum(y.astype(np.intp), self.n_w - 1)
        if j.size and j.max() >= self.rows:
            self._build_rows(j.max() + 1 + CACHE_ROW_MARGIN)
        C = self.coef[i, j]
        # the power bases (1, s, s², s³) and (0, 1, 2s, 3s²) for s (ξ) and r (w), both at once
        sr = np.empty((2, len(p)))
        np.subtract(x, i, out=sr[0])
        np.subtract(y, j, out=sr[1])
        P = np.empty((2, len(p), 4))
        P[..., 0] = 1.0
        P[..., 1] = sr
        P[..., 2] = sr * sr
        P[..., 3] = P[..., 2] * sr
        Pd = np.empty((2, len(p), 4))
        Pd[..., 0] = 0.0
        Pd[..., 1] = 1.0
        Pd[..., 2] = 2 * sr
        Pd[..., 3] = 3 * sr * sr
        S, dS, Rr, dR = P[0], Pd[0], P[1], Pd[1]
        out = np.zeros((len(p), order + 1, order + 1, 3))
        CR = np.einsum("nabk,nb->nak", C, Rr)
        out[:, 0, 0] = np.einsum("na,nak->nk", S, CR)
        if order:
            out[:, 1, 0] = np.einsum("na,nak->nk", dS, CR) / self.hx
            dw_deta = -0.5 / w
            out[:, 0, 1] = np.einsum("na,nabk,nb->nk", S, C, dR) * (dw_deta / self.hw)[:, None]
        return out


_BLADE_CACHES: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def blade_cache(blade) -> BladeCache:
    """The :class:`BladeCache` of ``blade`` (default cells), built once per blade object:
    a blade is immutable, and an edit of the smoothing settings marches new cuts on the
    same blade (the operator reuses the model when the definition did not change)."""
    cache = _BLADE_CACHES.get(blade)
    if cache is None:
        cache = _BLADE_CACHES[blade] = BladeCache(blade)
    return cache


def chart_derivatives(deriv, eta_min):
    """Wrap an evaluator of b and its (ξ, η) derivatives (layout of
    ``BladeSurface.derivatives(order=1)``) into one in the tip chart (X, Y)
    (:func:`~.corners.to_tip_chart`): [0, 0] = b, [1, 0] = b_X, [0, 1] = b_Y, by the chain
    rule ξ_X = -Y/(2πr²), ξ_Y = X/(2πr²), η_X = -2X, η_Y = -2Y."""
    r_max2 = 1.0 - eta_min

    def evaluate(c, order=1):
        c = np.array(c, dtype=np.float64)
        r2 = np.sum(c * c, axis=1)
        big = r2 > r_max2
        if big.any():
            c[big] *= np.sqrt(r_max2 / r2[big])[:, None]
        r2 = np.maximum(np.minimum(r2, r_max2), ETA_TIP_GUARD)
        # from_tip_chart(c) (ξ_ref = 0), written out: the same operations, fewer calls
        p = np.empty_like(c)
        p[:, 0] = np.mod(np.arctan2(c[:, 1], c[:, 0]) / (2.0 * np.pi) + 0.5, 1.0) - 0.5
        p[:, 1] = 1.0 - (c[:, 0] ** 2 + c[:, 1] ** 2)
        D = deriv(p, 1)
        X, Y = c[:, 0:1], c[:, 1:2]
        bxi, beta = D[:, 1, 0], D[:, 0, 1]
        k = 1.0 / (2.0 * np.pi * r2[:, None])
        b_X = -Y * k * bxi - 2.0 * X * beta
        b_Y = X * k * bxi - 2.0 * Y * beta
        D[:, 1, 0] = b_X
        D[:, 0, 1] = b_Y
        D[:, 1, 1] = 0.0
        return D

    return evaluate


class _PlaneSolver:
    """Points of the blade on the cut planes (Eqs. 16, 20–22) in the tip chart, for one
    evaluator of b (the exact blade or the :class:`BladeCache`)."""

    def __init__(self, deriv, x0, normal, eta_min, radius):
        self.deriv = chart_derivatives(deriv, eta_min)
        self.x0 = x0
        self.n = normal
        self.eta_min = eta_min
        self.r_max2 = 1.0 - eta_min
        self.tol = PLANE_TOL * radius
        #: (b_X·n̂, b_Y·n̂) at the points of the last :meth:`solve` where known (NaN elsewhere)
        self.gradient = None
        self.last_gradient = None

    def residual(self, p, idx, order=1):
        """f = (b(p) - x_0)·n̂ (Eq. 16), its chart gradient (b_X·n̂, b_Y·n̂), and the
        derivatives."""
        D = self.deriv(p, 1)
        n = self.n[idx]
        f = np.einsum("ij,ij->i", D[:, 0, 0] - self.x0[idx], n)
        g = np.empty((len(f), 2))
        g[:, 0] = np.einsum("ij,ij->i", D[:, 1, 0], n)
        g[:, 1] = np.einsum("ij,ij->i", D[:, 0, 1], n)
        return f, g, D

    def newton_line(self, trial, m, idx):
        """Newton for s on Eq. 20: p(s) = trial + s m. Returns (p, ok)."""
        s = np.zeros(len(idx))
        ok = np.zeros(len(idx), dtype=bool)
        p = trial.copy()
        grad = np.full((len(idx), 2), np.nan)  # (b_X·n̂, b_Y·n̂) where converged
        todo = np.arange(len(idx))
        for _ in range(NEWTON_MAX_ITERATIONS):
            if todo.size == 0:
                break
            pt = trial[todo] + s[todo, None] * m[todo]
            f, g, _ = self.residual(pt, idx[todo])
            p[todo] = pt
            conv = np.abs(f) < self.tol
            ok[todo[conv]] = True
            grad[todo[conv]] = g[conv]
            todo, f, g = todo[~conv], f[~conv], g[~conv]
            fp = np.einsum("ij,ij->i", g, m[todo])
            with np.errstate(divide="ignore", invalid="ignore"):
                ds = -f / fp
            bad = ~np.isfinite(ds) | (np.abs(s[todo] + ds) > 1.5)
            s[todo] += np.where(bad, 0.0, ds)
            todo = todo[~bad]
        ok &= np.sum(p * p, axis=1) <= self.r_max2
        self.last_gradient = grad
        return p, ok

    def xi_search(self, trial, idx):
        """Newton for ξ at fixed η = η_i + Δη (Eq. 21): in the chart, along the circle
        of radius w through the predictor. Returns (p, ok)."""
        w = np.linalg.norm(trial, axis=1)
        xi0 = np.arctan2(trial[:, 1], trial[:, 0]) / (2.0 * np.pi)
        xi = xi0.copy()
        ok = np.zeros(len(idx), dtype=bool)
        p = trial.copy()
        for _ in range(2 * NEWTON_MAX_ITERATIONS):
            a = 2.0 * np.pi * xi
            p = np.stack([w * np.cos(a), w * np.sin(a)], axis=1)
            f, g, _ = self.residual(p, idx)
            ok = np.abs(f) < self.tol
            if np.all(ok):
                break
            fp = 2.0 * np.pi * (-p[:, 1] * g[:, 0] + p[:, 0] * g[:, 1])
            with np.errstate(divide="ignore", invalid="ignore"):
                dxi = np.where(ok, 0.0, -f / fp)
            xi += np.clip(np.where(np.isfinite(dxi), dxi, 0.0), -0.05, 0.05)
        self.last_gradient = g  # at the p returned (the last evaluation)
        return p, ok & (np.abs(xi - xi0) < XI_SEARCH_MAX_SHIFT)

    def bisection(self, trial, m, idx):
        """Bisection on s along Eq. 20 from a bracket s_1, s_2 with f(s_1) < 0 < f(s_2)
        (Eq. 22). Returns (p, ok)."""
        S = np.linspace(-BRACKET_SPAN, BRACKET_SPAN, BRACKET_SAMPLES)
        k = len(idx)
        P = trial[:, None, :] + S[None, :, None] * m[:, None, :]
        f, _, _ = self.residual(P.reshape(-1, 2), np.repeat(idx, S.size), order=0)
        f = f.reshape(k, S.size)
        ok = np.zeros(k, dtype=bool)
        s1, s2 = np.zeros(k), np.zeros(k)
        for r in range(k):
            change = np.flatnonzero(np.sign(f[r, :-1]) != np.sign(f[r, 1:]))
            if change.size:
                j = change[np.argmin(np.abs(S[change] + S[change + 1]))]
                ok[r] = True
                s1[r], s2[r] = (S[j], S[j + 1]) if f[r, j] < 0 else (S[j + 1], S[j])
        mlen = np.linalg.norm(m, axis=1)
        for _ in range(200):
            s3 = 0.5 * (s1 + s2)
            f3, _, _ = self.residual(trial + s3[:, None] * m, idx, order=0)
            neg = f3 < 0
            s1, s2 = np.where(neg, s3, s1), np.where(neg, s2, s3)
            if np.all(np.abs(s1 - s2) * mlen < BISECTION_TOL):
                break
        p = trial + 0.5 * (s1 + s2)[:, None] * m
        return p, ok

    def solve(self, trial, m, idx, labels, counts, per_item=None):
        """Newton (Eq. 20), then the ξ-search (Eq. 21), then bisection (Eq. 22).
        ``self.gradient``: (b_X·n̂, b_Y·n̂) at the returned points where the search that
        found them evaluated it there (NaN elsewhere)."""
        self.last_gradient = None
        p, ok = self.newton_line(trial, m, idx)
        grad = self.last_gradient
        self.gradient = grad = np.full((len(idx), 2), np.nan) if grad is None else grad
        if np.all(ok):
            return p
        grad[~ok] = np.nan
        bad = np.flatnonzero(~ok)
        self.last_gradient = None
        pb, okb = self.xi_search(trial[bad], idx[bad])
        if self.last_gradient is not None:
            grad[bad[okb]] = self.last_gradient[okb]
        p[bad[okb]] = pb[okb]
        counts["xi_search"] += int(okb.sum())
        if per_item is not None:
            np.add.at(per_item[:, 0], idx[bad[okb]], 1)
        bad = bad[~okb]
        if bad.size:
            pc, okc = self.bisection(trial[bad], m[bad], idx[bad])
            if not np.all(okc):
                k = bad[int(np.argmin(okc))]
                raise _fail(labels[idx[k]], trial[k], "no point of the plane found")
            p[bad] = pc
            counts["bisection"] += bad.size
            if per_item is not None:
                np.add.at(per_item[:, 1], idx[bad], 1)
        return p


def _march(solver, blade, start, end, labels, counts):
    """March every half-cut from ``start`` towards ``end`` (Eqs. 18–19, 23). Returns a
    list of node arrays, each from its start to its end point exactly."""
    H = len(start)
    cur = start.copy()
    nodes = np.empty((H, MARCH_MAX_STEPS + 2, 2))
    count = np.ones(H, dtype=np.intp)
    nodes[:, 0] = start
    Lp = np.linalg.norm(end - start, axis=1)
    amax = np.minimum(MARCH_MAX_STEP, Lp / MARCH_MIN_STEPS)
    turn = np.ones(H)
    prev_dir = np.zeros((H, 2))
    active = np.arange(H)
    f, g, D = solver.residual(cur, active)
    for _ in range(MARCH_MAX_STEPS):
        t = np.stack([-g[:, 1], g[:, 0]], axis=1)  # Eq. 18
        tn = np.linalg.norm(t, axis=1)
        if np.any(tn == 0):
            h = int(active[np.argmin(tn)])
            raise _fail(labels[h], cur[h], "the plane is tangent to the blade")
        t /= tn[:, None]
        pd = prev_dir[active]
        ref = np.where((np.abs(pd).sum(axis=1) > 0)[:, None], pd, end[active] - cur[active])
        t *= np.where(np.einsum("ij,ij->i", t, ref) < 0, -1.0, 1.0)[:, None]
        dist_end = np.linalg.norm(end[active] - cur[active], axis=1)
        rho = np.clip(1.0 - dist_end / Lp[active], 0.0, 1.0)
        alpha = amax[active] * (1.0 - (1.0 - MARCH_MIN_RATIO) * rho) * turn[active]  # Eq. 23
        finishing = dist_end <= 1.5 * alpha
        if np.any(finishing):
            hf = active[finishing]
            nodes[hf, count[hf]] = end[hf]
            count[hf] += 1
        go = ~finishing
        idx = active[go]
        if idx.size == 0:
            break
        step = alpha[go, None] * t[go]  # (Δξ, Δη), Eq. 19
        trial = cur[idx] + step
        m = np.stack([step[:, 1], -step[:, 0]], axis=1)  # Eq. 20
        p = solver.solve(trial, m, idx, labels, counts)
        d = p - cur[idx]
        dn = np.linalg.norm(d, axis=1)
        new_dir = d / np.where(dn > 0, dn, 1.0)[:, None]
        had = np.abs(prev_dir[idx]).sum(axis=1) > 0
        ang = np.where(had, np.arccos(np.clip(np.einsum("ij,ij->i", new_dir, prev_dir[idx]), -1.0, 1.0)), 0.0)
        with np.errstate(divide="ignore"):
            turn[idx] = np.clip(turn[idx] * np.where(ang > 0, MARCH_MAX_TURN / ang, 2.0), 0.05, 1.0)
        # the half-cut ends where it reaches the edge line ξ = ξ_1: at x_1, or else the
        # plane meets the edge elsewhere first and the cut is not an arc around the edge
        side0 = cur[idx, 1] - end[idx, 1]
        side1 = p[:, 1] - end[idx, 1]
        crossed = (side0 * side1 <= 0) & (np.abs(side0) > 0)
        if np.any(crossed):
            w = side0[crossed] / (side0[crossed] - side1[crossed])
            x_x = cur[idx[crossed], 0] + w * (p[crossed, 0] - cur[idx[crossed], 0])
            far = np.abs(x_x - end[idx[crossed], 0]) > EDGE_ARRIVAL_TOL * Lp[idx[crossed]]
            if np.any(far):
                k = int(np.flatnonzero(far)[0])
                h = int(idx[crossed][k])
                eta_x = 1.0 - x_x[k] ** 2
                raise GeometryError(
                    f"blade cut {labels[h]}: its plane meets an edge at η = {eta_x:.5g} before reaching the "
                    f"edge point at η = {1.0 - end[h, 0] ** 2:.5g} (Hally 2013 §6 assumes one arc around the "
                    "edge); move the defining points or the transition cut"
                )
        passed = crossed | (np.einsum("ij,ij->i", end[idx] - p, new_dir) <= 0)
        nodes[idx, count[idx]] = np.where(passed[:, None], end[idx], p)
        count[idx] += 1
        prev_dir[idx] = new_dir
        cur[idx] = p
        active = idx[~passed]
        if active.size == 0:
            break
        # the gradient at the new points: the corrector evaluated it there already
        g = solver.gradient[~passed]
        redo = np.flatnonzero(np.isnan(g[:, 0]))
        if redo.size:
            g[redo] = solver.residual(cur[active[redo]], active[redo])[1]
    else:
        h = int(active[0])
        raise _fail(labels[h], cur[h], f"no arrival at the edge point after {MARCH_MAX_STEPS} steps")
    return [nodes[h, : count[h]] for h in range(H)]


def _refine_exact(solver, paths, labels, counts, per_item):
    """Move the interior nodes of every marched path onto the exact blade ∩ plane, all at
    once: Newton along the perpendicular of Eq. 20 with the exact b, then the fallbacks of
    Eqs. 21–22."""
    idx, trial, m = [], [], []
    for h, P in enumerate(paths):
        if len(P) < 3:
            continue
        tang = P[2:] - P[:-2]
        step = 0.5 * tang
        idx.append(np.full(len(P) - 2, h))
        trial.append(P[1:-1])
        m.append(np.stack([step[:, 1], -step[:, 0]], axis=1))
    if not idx:
        return paths
    idx, trial, m = np.concatenate(idx), np.concatenate(trial), np.concatenate(m)
    p = solver.solve(trial, m, idx, labels, counts, per_item)
    out, k = [], 0
    for h, P in enumerate(paths):
        if len(P) < 3:
            out.append(P)
            continue
        Q = P.copy()
        Q[1:-1] = p[k : k + len(P) - 2]
        k += len(P) - 2
        out.append(Q)
    return out


def march_cuts(blade, p0, p1, p2, labels=None, cache=None) -> list[BladeCut]:
    """The cuts through the planes (b(p0_k), b(p1_k), b(p2_k)) for k = 1..K, all marched
    at once (Hally §6). p0, p1, p2: (K, 2) blade parameters; p1 on the edge (ξ = 1/2 or
    0), p0 and p2 on either side, written on the periodic blade so that the cut is
    continuous in ξ. Returns K :class:`BladeCut`, each running x_0 -> x_1 -> x_2."""
    p0, p1, p2 = (np.atleast_2d(np.asarray(a, dtype=np.float64)) for a in (p0, p1, p2))
    K = len(p0)
    labels = [str(k) for k in range(K)] if labels is None else list(labels)
    X = blade_points(blade, np.stack([p0, p1, p2], axis=1))  # (K, 3, 3)
    n = np.cross(X[:, 1] - X[:, 0], X[:, 1] - X[:, 2])  # Eq. 15
    nn = np.linalg.norm(n, axis=1)
    scale = np.linalg.norm(X[:, 1] - X[:, 0], axis=1) * np.linalg.norm(X[:, 1] - X[:, 2], axis=1)
    if np.any(nn <= 1e-12 * scale):
        k = int(np.argmin(nn / scale))
        raise GeometryError(f"blade cut {labels[k]}: the three points are collinear (Hally Eq. 15)")
    n /= nn[:, None]
    xi_ref = p1[:, 0].copy()
    c0, c1, c2 = to_tip_chart(p0), to_tip_chart(p1), to_tip_chart(p2)
    c1[:, 1] = 0.0  # the edge rays: Y = 0 exactly
    start = np.concatenate([c0, c2])
    end = np.concatenate([c1, c1])
    x0 = np.concatenate([X[:, 0], X[:, 0]])
    normal = np.concatenate([n, n])
    labels2 = labels + labels
    counts = {"xi_search": 0, "bisection": 0}
    cache = BladeCache(blade) if cache is None else cache
    rough = _PlaneSolver(cache.derivatives, x0, normal, blade.eta_min, blade.radius)
    paths = _march(rough, blade, start, end, labels2, {"xi_search": 0, "bisection": 0})
    exact = _PlaneSolver(lambda p, order: blade_derivatives(blade, p, order), x0, normal, blade.eta_min, blade.radius)
    fb = np.zeros((2 * K, 2), dtype=int)
    paths = _refine_exact(exact, paths, labels2, counts, fb)
    cuts = []
    for k in range(K):
        first, second = paths[k], paths[K + k]
        nodes = np.concatenate([first, second[::-1][1:]])
        m = len(first) - 1
        a = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(nodes, axis=0), axis=1))])
        if np.any(np.diff(a) <= 0):
            raise GeometryError(f"blade cut {labels[k]}: repeated nodes (Hally §6)")
        t = cut_parameters(a, m)
        spline = make_interp_spline(t, nodes, k=3)
        nodes = from_tip_chart(nodes, xi_ref[k])
        cuts.append(
            BladeCut(
                params=nodes, edge_index=m, t=t, curve=SplineCurve(spline, xi_ref=float(xi_ref[k])), normal=n[k],
                points=X[k],
                fallbacks={"xi_search": int(fb[k, 0] + fb[K + k, 0]), "bisection": int(fb[k, 1] + fb[K + k, 1])},
                label=labels[k],
            )
        )
    return cuts


def march_statistics(cuts) -> dict:
    """Totals over cuts: nodes and fallbacks (Hally §6 Eqs. 21–22)."""
    return {
        "cuts": len(cuts),
        "nodes": int(sum(len(c.params) for c in cuts)),
        "xi_search": int(sum(c.fallbacks.get("xi_search", 0) for c in cuts)),
        "bisection": int(sum(c.fallbacks.get("bisection", 0) for c in cuts)),
    }
