"""Curvature-based smoothing of plane cubic B-spline curves: smooth2D and smoothfoil.

Hvid, S. L. (1993), *Curvature based smoothing of plane cubic B-spline curves*, DTU
Department of Fluid Mechanics, AFM 93-08.

The algorithm (§3.2, steps 1–5), on N = n+1 points r_0..r_n redistributed along the input
curve (§3.2 "Conditioning the algorithm", distributions of §3.3):

1. Interpolate r_i by the cubic B-spline with knots at their parameters u_i (Eq. 2.1;
   control points d_{-1}..d_{n+1}, here P_0..P_{n+2}; d_{-1} = r_0, d_{n+1} = r_n; the
   end tangents from finite differences of order ``end_derivative_order`` — the jobcard's
   "iorder", §3.4). Curvature κ_i at the knots (Eq. 2.10) from the spline's own first and
   second derivatives, which are linear in the control points: no finite differences.
2. Smooth κ_i into the target κ*_i: the ad hoc smoother κ*_i = (κ_{i−1} + κ_i + κ_{i+1})/3
   over ``passes`` passes, or a linear least-squares spline fit (§3.2); smoothing type 2
   keeps the maximum (the leading-edge value of an airfoil, jobcard "smttype", §3.4).
3. J_ij = ∂κ_i/∂(ε n_j): displacement of d_j along the curve normal n_j at r_j, by finite
   differences. Moving d_j changes κ only at u_{j−1}, u_j, u_{j+1} (§2, local control), so
   J is tridiagonal; the three diagonals come from three perturbed evaluations (every
   third vertex moved at once).
4. Solve J δ = κ* − κ with ``scipy.linalg.solve_banded`` (cyclic on closed curves).
5. d_j ← d_j + δ_j n_j; repeat 3–5 (a secant method, §3.2) until Σ|κ − κ*| <= tolf or
   Σ|δ| <= tolx (the jobcard's "tolf"/"tolx"; iteration printout of §3.4), at most
   ``max_iterations`` ("ntrial") times.

Closed curves (smooth2D) are smoothed as periodic ones, with no seam: the cubic through
the N redistributed points is periodic (knots wrap around by the period, the last three
of N + 3 control points repeat the first three, :func:`periodic_spline_through`), the
curvature smoother wraps around, every control point moves and the Jacobian is cyclic
tridiagonal (Sherman–Morrison on ``solve_banded``, :func:`solve_cyclic_tridiagonal`).
Because nothing is pinned, κ* is corrected to keep ∮κ ds and closure (:func:`_keep_turning`) and the
result is moved back by the best rigid motion (:func:`_rigid_align`).

smoothfoil (§3.3 "Airfoil preparation", §3.2.1) works at unit chord with a sharp trailing
edge: blunt trailing edges are extended along the end tangents to a point, scaled to unit
chord, smoothed, scaled back and cut at the original trailing-edge ends. The smoothed
airfoil is rescaled to the original chord (§3.2 last paragraph). smooth2D uses the
curvature-weighted distribution (§3.3) and works at unit reference length (the bounding-box
diagonal), so tolerances mean the same for every curve.

Deviation is reported as Hvid's ds (§3.2.1: distance at equal parameters, an upper bound)
and as the true distance between the curves (closest points, both ways), and as the
distance of the input data points from the smoothed curve.
"""
from __future__ import annotations

import pathlib
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy.interpolate import make_smoothing_spline
from scipy.linalg import solve_banded

from ..files import atomic_write
from ..errors import DefinitionError, GeometryError
from ..nurbs import BSplineCurve, closest_point_curve, split
from ..nurbs.basis import basis_function_derivatives, basis_functions, find_span
from ..nurbs.local_projection import closest_points_near
from .curvature import arclength_table, curvature_at, derivatives, params_at_arclength, span_samples
from .distributions import DistributionReport, PolynomialDistribution, curvature_fractions, distribution_report

# -- named tolerances and defaults (jobcard of Hvid 1993, Appendix) ---------------------
#: Finite-difference displacement ε of step 3, relative to the reference length (unit
#: chord): small against the 1e-4 c scale of the corrections, large against round-off.
JACOBIAN_STEP = 1e-7

#: A Newton step whose largest displacement exceeds this fraction of the reference length,
#: or a residual that grows by more than :data:`DIVERGENCE_FACTOR` over the first one,
#: counts as divergence: the iteration stops and reports it.
MAX_STEP = 0.05
DIVERGENCE_FACTOR = 1e3

#: smooth2D treats a curve as closed when its two ends are this close (relative to the
#: bounding-box diagonal): float32 coordinates (Blender) round at ~6e-8.
CLOSED_TOL = 1e-6

#: The iteration is stationary, and counts as converged, when Σ|κ − κ*| changes by less
#: than STATIONARY_CHANGE of itself between iterations and is below STATIONARY_FRACTION of
#: the first residual (e.g. a noisy cylinder read as a closed curve, α = 1: 32.4 → 0.257, then
#: constant to 7 digits with steps of 4e-10, just above tolx = 1e-10).
STATIONARY_CHANGE = 1e-3
STATIONARY_FRACTION = 5e-2

#: Ends that meet at an angle larger than this (degrees) make a corner, not a closed
#: curve: a sharp airfoil trailing edge read by smooth2D is an open curve whose ends
#: coincide. Smoothed as a periodic cubic its corner would become a curvature spike of
#: ~1e4 that no smoothing can follow.
CORNER_ANGLE_DEG = 5.0
CORNER_TURN_RATIO = 3.0

#: Trailing-edge gap (fraction of chord) below which an airfoil counts as sharp.
SHARP_TE_TOL = 1e-9

#: The leading edge must lie inside the outline by this many points from either end.
MIN_POINTS_PER_SIDE = 3

#: Extension length L of a blunt trailing edge: TE_EXTENSION_GAPS × the trailing-edge gap,
#: clipped to [MIN_TE_EXTENSION, MAX_TE_FALLBACK] chord. The ends are extended to where
#: their tangents meet (Hvid 1993 §3.3 step 1) when that is within TE_MEET_FACTOR × L;
#: otherwise (tangents parallel, diverging, or meeting far behind, e.g. DU 30 at 0.37 c,
#: whose long straight extension would take a third of the smoothing points) by L and
#: bent gently onto a common apex.
TE_EXTENSION_GAPS = 10.0
TE_MEET_FACTOR = 2.0
MIN_TE_EXTENSION = 0.02
MAX_TE_FALLBACK = 0.2
#: |det| of the two unit end tangents below which they count as parallel.
PARALLEL_TANGENT_TOL = 1e-12

#: Samples per knot span when measuring the true deviation between curves and extremes
#: of curvature.
DEVIATION_SAMPLES_PER_SPAN = 4
#: Bracketing samples per knot span of the projections behind the true deviation.
DEVIATION_BRACKET_SAMPLES = 4

#: Smoothing type 2 keeps the largest |κ| only when it is a peak that survives
#: smoothing: after PEAK_PROBE_PASSES ad hoc passes the largest |κ| is still PEAK_RATIO
#: times the median |κ| or more. Measured on the shipped airfoils at 180 points: 4.7
#: (DU 40) to 70 (fx66-s-196); the NREL cylinders 1.5 (their largest raw value, 3.8 times
#: the median, is one noisy point near the leading edge).
PEAK_RATIO = 3.0
PEAK_PROBE_PASSES = 4

#: Weight of the kept maximum in the least-squares smoother of smoothing type 2 (relative
#: to 1 for every other point): large enough to pin the fit to the value.
KEEP_MAX_WEIGHT = 1e6

#: Points over which the least-squares curvature smoother's weights taper at each end of
#: an open curve (w_i = ((i + 1)/LS_END_TAPER)², i counted from the nearer end). κ at
#: the first knots of a clamped spline is set by the finite-difference end tangent
#: (iorder) as much as by the points, and its noise does not cancel the way the
#: interior's does: κ_i is a second difference of the position noise, whose sum over a
#: window telescopes to two tangent errors, but at an end one of them is the end-tangent
#: error. A natural smoothing spline then extrapolates the end values linearly: on the
#: noisy NACA 0012 (±1e-4 c, 180 points) its trailing-edge κ* scatters by 0.14 about the
#: true 0.18 (a spurious inflection in 3 of 20 sections). Tapered over 6 points the
#: scatter is 0.03 and the interior is unchanged (60 seeds); with the first-moment
#: correction of :func:`_end_moment_correction` no section of 20 keeps an inflection and
#: the deviation does not grow (max 1.5e-4 c against 1.9e-4 c untapered).
LS_END_TAPER = 6

#: Values wrapped around beyond each end of a closed curve before the least-squares
#: curvature fit: the fit's influence decays over ~λ^(1/4) indices, so 24 values leave
#: the result periodic to round-off for λ up to ~10^4.
LS_END_PAD = 24

#: Newton steps used to locate the leading edge (farthest point from the trailing edge).
LEADING_EDGE_NEWTON_STEPS = 8

SMOOTHERS = ("ad_hoc", "least_squares")
SMOOTHING_TYPES = (1, 2)

Progress = Callable[[int, int], None]


class SmoothingNotConverged(GeometryError):
    """The Newton/secant iteration of Hvid (1993) §3.2 did not meet tolx/tolf.

    ``history``: tuple of (Σ|κ − κ*|, Σ|δ|) per iteration; ``reason``: why it stopped.
    The message carries the residual history.
    """

    def __init__(self, message: str, history, reason: str):
        self.history = tuple(history)
        self.reason = reason
        lines = [message, f"stopped: {reason}"]
        lines += [f"iteration {k}: residual {f:.6e}  step {x:.6e}" for k, (f, x) in enumerate(self.history, 1)]
        super().__init__("\n".join(lines))


# Upper bounds of the jobcard's counts (README "Limits of definitions"): the work of one
# smoothing grows with them; each is named in its refusal.
MAX_SMOOTHING_POINTS = 5000
MAX_OUTPUT_POINTS = 10000
MAX_ITERATIONS = 200
MAX_PASSES = 10000


@dataclass(frozen=True)
class SmoothingSettings:
    """Parameters of the smoother, named after Hvid's jobcard (1993, Appendix and §3.4).

    smoothing_points: nsmooth, points (knots) of the smoothing spline.
    output_points: np, points of the final layout written out.
    max_iterations: ntrial. tolx: tolerance on Σ|δ| between iterations (reference length 1).
    tolf: tolerance on Σ|κ − κ*| (curvature at reference length 1).
    smoothing_type: smttype, 1 smooths every point, 2 keeps the maximum |κ| value.
    smoother: "ad_hoc" (3-point mean, §3.2) or "least_squares" (cubic spline fit).
    passes: passes of the ad hoc smoother (the paper's fx66 run uses 4, §3.2.1).
    end_derivative_order: iorder, 2 or 3: order of the finite-difference end tangents.
    smoothing_weight: λ of the least-squares smoother (penalised cubic spline in the
    point index, scipy ``make_smoothing_spline``); 0 chooses λ by generalised
    cross-validation.
    """

    smoothing_points: int = 180
    output_points: int = 150
    max_iterations: int = 10
    tolx: float = 1e-10
    tolf: float = 1e-9
    smoothing_type: int = 2
    smoother: str = "ad_hoc"
    passes: int = 4
    end_derivative_order: int = 2
    smoothing_weight: float = 10.0

    def __post_init__(self):
        def need(ok: bool, name: str, what: str):
            if not ok:
                raise DefinitionError(f"{what}, got {getattr(self, name)!r}", field=name)

        for name in ("smoothing_points", "output_points", "max_iterations", "passes", "smoothing_type",
                     "end_derivative_order"):
            value = getattr(self, name)
            need(not isinstance(value, bool) and isinstance(value, (int, np.integer)), name, "expected an integer")
        need(8 <= self.smoothing_points <= MAX_SMOOTHING_POINTS, "smoothing_points",
             f"nsmooth must lie in [8, MAX_SMOOTHING_POINTS = {MAX_SMOOTHING_POINTS}]")
        need(4 <= self.output_points <= MAX_OUTPUT_POINTS, "output_points",
             f"np must lie in [4, MAX_OUTPUT_POINTS = {MAX_OUTPUT_POINTS}]")
        need(1 <= self.max_iterations <= MAX_ITERATIONS, "max_iterations",
             f"ntrial must lie in [1, MAX_ITERATIONS = {MAX_ITERATIONS}]")
        need(int(self.passes) <= MAX_PASSES, "passes", f"passes must be <= MAX_PASSES = {MAX_PASSES}")
        need(np.isfinite(self.tolx) and self.tolx >= 0, "tolx", "tolx must be >= 0")
        need(np.isfinite(self.tolf) and self.tolf >= 0, "tolf", "tolf must be >= 0")
        need(self.smoothing_type in SMOOTHING_TYPES, "smoothing_type", f"smoothing type must be one of {SMOOTHING_TYPES}")
        need(self.smoother in SMOOTHERS, "smoother", f"smoother must be one of {SMOOTHERS}")
        need(int(self.passes) >= 0, "passes", "passes must be >= 0")
        need(self.end_derivative_order in (2, 3), "end_derivative_order", "iorder must be 2 or 3")
        need(np.isfinite(self.smoothing_weight) and self.smoothing_weight >= 0, "smoothing_weight", "smoothing_weight must be >= 0")


# =======================================================================================
# step 1: interpolation with knots at the data parameters, curvature at the knots
# =======================================================================================
def end_derivative(params: np.ndarray, points: np.ndarray, order: int, at_end: bool = False) -> np.ndarray:
    """dr/du at the first (or last) point from the polynomial through ``order`` + 1 end
    points: a one-sided finite difference of order ``order`` (Hvid's iorder, §3.4)."""
    k = order + 1
    if at_end:
        x, y = params[::-1][:k], points[::-1][:k]
    else:
        x, y = params[:k], points[:k]
    x0 = x[0]
    w = np.empty(k)
    w[0] = np.sum(1.0 / (x0 - x[1:]))
    for j in range(1, k):
        others = np.delete(np.arange(k), j)
        num = np.prod(x0 - x[others[others != 0]])
        den = np.prod(x[j] - x[others])
        w[j] = num / den
    return w @ y


def interpolate_at_knots(points, params, start_derivative, end_derivative_) -> BSplineCurve:
    """Cubic B-spline through r_i at u_i with knots at the u_i (Hvid 1993 Eq. 2.1) and the
    end derivatives prescribed: knots u_0^4, u_1..u_{n−1}, u_n^4; n+3 control points with
    P_0 = r_0 and P_{n+2} = r_n. The system is banded (solve_banded)."""
    Q = np.asarray(points, dtype=np.float64)
    u = np.asarray(params, dtype=np.float64)
    n = Q.shape[0] - 1
    U = np.concatenate([np.full(4, u[0]), u[1:-1], np.full(4, u[-1])])
    span = find_span(U, 3, u)
    N = basis_functions(U, 3, u, span)
    ends = np.array([u[0], u[-1]])
    ends_span = find_span(U, 3, ends)
    D = basis_function_derivatives(U, 3, ends, ends_span, 1)[:, 1, :]
    cols = np.concatenate([span[:1, None], ends_span[:1, None], span[1:-1, None], ends_span[1:, None], span[-1:, None]]) - 3
    cols = cols + np.arange(4)
    vals = np.concatenate([N[:1], D[:1], N[1:-1], D[1:], N[-1:]])
    rhs = np.concatenate([Q[:1], np.asarray(start_derivative)[None], Q[1:-1], np.asarray(end_derivative_)[None], Q[-1:]])
    rows = np.broadcast_to(np.arange(n + 3)[:, None], cols.shape)
    nz = vals != 0.0
    offsets = (cols - rows)[nz]
    upper, lower = max(int(offsets.max()), 0), max(int(-offsets.min()), 0)
    ab = np.zeros((lower + upper + 1, n + 3))
    ab[(upper + rows - cols)[nz], cols[nz]] = vals[nz]
    try:
        P = solve_banded((lower, upper), ab, rhs)
    except np.linalg.LinAlgError as exc:
        raise GeometryError(f"the interpolation at the knots is singular ({exc})") from None
    return BSplineCurve(3, U, P)


def spline_through(points: np.ndarray, end_derivative_order: int, params=None) -> tuple[BSplineCurve, np.ndarray]:
    """Chord-length parameters (normalised to [0, 1]) and the cubic through the points with
    knots at them and finite-difference end tangents (§3.2 step 1)."""
    Q = np.asarray(points, dtype=np.float64)
    if params is None:
        chords = np.linalg.norm(np.diff(Q, axis=0), axis=1)
        if np.any(chords <= 0.0):
            k = int(np.flatnonzero(chords <= 0.0)[0]) + 1
            raise GeometryError(f"point {k} repeats point {k - 1} ({Q[k].tolist()}); remove duplicates")
        params = np.concatenate([[0.0], np.cumsum(chords)])
        params /= params[-1]
    d0 = end_derivative(params, Q, end_derivative_order)
    dn = end_derivative(params, Q, end_derivative_order, at_end=True)
    return interpolate_at_knots(Q, params, d0, dn), params


def solve_cyclic_tridiagonal(lower: np.ndarray, diag: np.ndarray, upper: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """x with A x = rhs for the cyclic tridiagonal A: A[i, i−1] = lower[i], A[i, i] = diag[i],
    A[i, i+1] = upper[i], indices mod N (so lower[0] = A[0, N−1] and upper[N−1] = A[N−1, 0]
    are the corners). Sherman–Morrison on top of ``solve_banded``: A = B + u vᵀ with B
    tridiagonal, u = (γ, 0, …, 0, A[N−1, 0]), v = (1, 0, …, 0, A[0, N−1]/γ), γ = −diag[0]
    (Press et al., Numerical Recipes §2.7). ``rhs``: (N,) or (N, m)."""
    lower, diag, upper = (np.asarray(a, dtype=np.float64) for a in (lower, diag, upper))
    N = diag.size
    b = np.asarray(rhs, dtype=np.float64)
    B = b.reshape(N, -1)
    top_right, bottom_left = lower[0], upper[-1]
    gamma = -diag[0] if diag[0] != 0.0 else -1.0
    ab = np.zeros((3, N))
    ab[0, 1:] = upper[:-1]
    ab[1] = diag
    ab[2, :-1] = lower[1:]
    ab[1, 0] -= gamma
    ab[1, -1] -= bottom_left * top_right / gamma
    u = np.zeros(N)
    u[0], u[-1] = gamma, bottom_left
    Y = solve_banded((1, 1), ab, np.column_stack([B, u]))
    y, z = Y[:, :-1], Y[:, -1]
    vz = z[0] + top_right / gamma * z[-1]
    vy = y[0] + top_right / gamma * y[-1]
    x = y - np.outer(z, vy / (1.0 + vz))
    return x.reshape(b.shape)


def periodic_knots(params: np.ndarray) -> np.ndarray:
    """Knot vector of the closed cubic with breakpoints u_0..u_N (u_N closes the loop):
    the three knots beyond each end are those of the other end shifted by the period, so
    the N + 3 control points P_k = P_{k mod N} make the curve C² everywhere, seam included."""
    u = np.asarray(params, dtype=np.float64)
    T = u[-1] - u[0]
    return np.concatenate([u[-4:-1] - T, u, u[1:4] + T])


def periodic_spline_through(points: np.ndarray, params=None) -> tuple[BSplineCurve, np.ndarray]:
    """Closed counterpart of :func:`spline_through` (§3.2 step 1 without end conditions):
    the periodic cubic through N distinct points (the loop closes back to the first; do
    not repeat it) with knots at their chord-length parameters u_0..u_{N−1} (u_N = 1 closes
    the loop). At a knot only three basis functions are non-zero, so the system is cyclic
    tridiagonal (:func:`solve_cyclic_tridiagonal`). Returns the curve (N + 3 control points,
    the last three repeating the first three) and u_0..u_{N−1}."""
    Q = np.asarray(points, dtype=np.float64)
    N = Q.shape[0]
    if N < 4:
        raise GeometryError(f"a closed curve needs at least 4 distinct points, got {N}")
    if params is None:
        chords = np.linalg.norm(np.diff(np.concatenate([Q, Q[:1]]), axis=0), axis=1)
        if np.any(chords <= 0.0):
            k = int(np.flatnonzero(chords <= 0.0)[0])
            raise GeometryError(f"point {(k + 1) % N} repeats point {k} ({Q[k].tolist()}); remove duplicates")
        params = np.concatenate([[0.0], np.cumsum(chords)])
        params /= params[-1]
    u = np.asarray(params, dtype=np.float64)
    U = periodic_knots(u)
    span = np.arange(N) + 3  # U[i + 3] = u_i
    Nb = basis_functions(U, 3, u[:-1], span)  # P_i, P_{i+1}, P_{i+2} (the fourth is 0 at the knot)
    # unknown j is P_{(j+1) mod N}: row i sees unknowns i−1, i, i+1 (cyclic tridiagonal)
    X = solve_cyclic_tridiagonal(Nb[:, 0], Nb[:, 1], Nb[:, 2], Q)
    F = np.roll(X, 1, axis=0)
    return BSplineCurve(3, U, F[np.arange(N + 3) % N]), u[:-1]


@dataclass(frozen=True)
class _KnotCurvature:
    """C'(u_i) and C''(u_i) as fixed linear maps of the control points (knots never move):
    four columns per knot, so κ_i of any control net costs two small gathers."""

    cols: np.ndarray  # (N, 4)
    d1: np.ndarray  # (N, 4)
    d2: np.ndarray  # (N, 4)
    d0: np.ndarray  # (N, 4)

    @classmethod
    def of(cls, curve: BSplineCurve, params: np.ndarray, closed: bool = False) -> "_KnotCurvature":
        """closed: ``curve`` is periodic (:func:`periodic_spline_through`); the columns then
        index its N distinct control points (P_k = P_{k mod N})."""
        span = find_span(curve.knots, 3, params)
        ders = basis_function_derivatives(curve.knots, 3, params, span, 2)
        cols = span[:, None] - 3 + np.arange(4)
        if closed:
            cols = cols % (curve.n_control - 3)
        return cls(cols, ders[:, 1, :], ders[:, 2, :], ders[:, 0, :])

    def derivatives(self, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        G = P[self.cols]
        return np.einsum("nk,nkd->nd", self.d1, G), np.einsum("nk,nkd->nd", self.d2, G)

    def points(self, P: np.ndarray) -> np.ndarray:
        return np.einsum("nk,nkd->nd", self.d0, P[self.cols])

    def curvature(self, P: np.ndarray) -> np.ndarray:
        """κ_i of Hvid (1993) Eq. 2.10 with numerator ẋÿ − ẏẍ."""
        a, b = self.derivatives(P)
        return (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) / np.hypot(a[:, 0], a[:, 1]) ** 3

    def normals(self, P: np.ndarray) -> np.ndarray:
        a, _ = self.derivatives(P)
        return np.stack([-a[:, 1], a[:, 0]], axis=1) / np.hypot(a[:, 0], a[:, 1])[:, None]

    def curvature_and_normals(self, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`curvature` and :meth:`normals` from one evaluation of the derivatives."""
        a, b = self.derivatives(P)
        speed = np.hypot(a[:, 0], a[:, 1])
        return ((a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) / speed**3,
                np.stack([-a[:, 1], a[:, 0]], axis=1) / speed[:, None])


# =======================================================================================
# step 2: the smoothed curvature target
# =======================================================================================
def _extend(k: np.ndarray, pad: int, closed: bool) -> np.ndarray:
    """``k`` with ``pad`` values added at each end: wrapped around for a closed curve,
    mirrored about the half-index beyond each end (…, κ_1, κ_0 | κ_0, κ_1, …) for an open one."""
    if pad == 0:
        return k
    if closed:
        reps = -(-pad // k.size)
        ring = np.tile(k, 2 * reps + 1)
        mid = reps * k.size
        return ring[mid - pad : mid + k.size + pad]
    pad = min(pad, k.size)
    return np.concatenate([k[pad - 1 :: -1], k, k[: -pad - 1 : -1]])


def _end_moment_correction(change: np.ndarray) -> np.ndarray:
    """Correction c to a change Δκ* near the ends of an open curve such that, for each end,
    Σ s_i (Δκ*_i + c_i) = 0 over that end's half, s_i = index distance from the end.

    Why: the Newton step turns κ* − κ into a normal displacement d with d'' ≈ δκ, the end
    point fixed and the end tangent free. A change of κ* near an end with a non-zero
    first moment about that end bends the whole rest of the curve (far from the end,
    d = −∫ s δκ ds); with zero first moment the displacement stays local. The correction
    is c = a ψ with ψ = (s/S)(1 − s/S) on s < S = 2 :data:`LS_END_TAPER` (zero at the end
    point itself, so the end values that the taper fixed are left alone)."""
    n = change.size
    x = np.arange(n, dtype=np.float64)
    end = np.minimum(x, x[::-1])
    span = 2.0 * LS_END_TAPER
    psi = np.where(end < span, (end / span) * (1.0 - end / span), 0.0)
    out = np.zeros(n)
    for side in (x < 0.5 * (n - 1), x >= 0.5 * (n - 1)):
        s = end[side]
        out[side] = -np.sum(s * change[side]) / np.sum(s * psi[side]) * psi[side]
    return out


def has_peak(kappa, closed: bool = False) -> bool:
    """Does κ have a peak for smoothing type 2 to keep (:data:`PEAK_RATIO`)?"""
    k = np.asarray(kappa, dtype=np.float64)
    probe = k
    for _ in range(PEAK_PROBE_PASSES):
        padded = _extend(probe, 1, closed)
        probe = (padded[:-2] + padded[1:-1] + padded[2:]) / 3.0
    return float(np.max(np.abs(probe))) >= PEAK_RATIO * float(np.median(np.abs(k)))


def smooth_curvature(
    kappa,
    smoother: str = "ad_hoc",
    passes: int = 4,
    smoothing_type: int = 2,
    weight: float = 10.0,
    closed: bool = False,
) -> np.ndarray:
    """Target curvature κ* from κ at the knots (Hvid 1993 §3.2 step 2).

    ``"ad_hoc"``: ``passes`` passes of κ*_i = (κ_{i−1} + κ_i + κ_{i+1})/3; at the two ends
    of an open curve the missing neighbour is replaced by the end value itself,
    (2κ_0 + κ_1)/3; on a closed curve the mean wraps around (κ_{−1} = κ_{N−1}).
    ``"least_squares"``: the penalised least-squares cubic spline in the point index i,
    minimising Σ w_i (κ_i − g(i))² + λ ∫ g''² di (scipy ``make_smoothing_spline``) with
    λ = ``weight`` (0: generalised cross-validation). Unlike the 3-point mean it leaves
    a smooth curvature (the leading-edge peak) nearly untouched while removing
    point-to-point noise, so it moves the curve far less (issue 6 acceptance, NACA 0012).
    Open curves: natural spline ends (g'' = 0), with the weights w_i tapered to
    ((i + 1)/:data:`LS_END_TAPER`)² over the last :data:`LS_END_TAPER` points at each end,
    so the end values follow the interior trend instead of the end points' own κ (see
    :data:`LS_END_TAPER` for why those are the least trustworthy); the change this makes
    near each end is then corrected to zero first moment about that end
    (:func:`_end_moment_correction`), so it does not bend the rest of the curve. Closed
    curves: the sequence is fitted with
    :data:`LS_END_PAD` values wrapped around beyond each end, so the fit is periodic to
    round-off and the seam leaves no trace.
    smoothing_type 2 keeps κ at the point of largest |κ| (the airfoil's leading edge,
    §3.4 "smttype") when it is a peak (:data:`PEAK_RATIO`); type 1 smooths every point.
    """
    k = np.array(kappa, dtype=np.float64)
    n = k.size
    keep = int(np.argmax(np.abs(k)))
    kept = k[keep]
    if smoothing_type == 2 and not has_peak(k, closed):
        # no peak to keep (a cylinder section: the largest value is one noisy point, and
        # keeping it bent the circle by 2.4e-2 c): smooth every point
        smoothing_type = 1
    if smoother == "ad_hoc":
        for _ in range(int(passes)):
            padded = _extend(k, 1, closed)
            k = (padded[:-2] + padded[1:-1] + padded[2:]) / 3.0
            if smoothing_type == 2:
                k[keep] = kept
    elif smoother == "least_squares":
        w = np.ones(n)
        if smoothing_type == 2:
            w[keep] = KEEP_MAX_WEIGHT
        lam = float(weight) if weight else None
        if closed:
            pad = LS_END_PAD
            kk, ww = _extend(k, pad, True), _extend(w, pad, True)
            x = np.arange(kk.size, dtype=np.float64)
            k = make_smoothing_spline(x, kk, w=ww, lam=lam)(x)[pad : pad + n]
        else:
            x = np.arange(n, dtype=np.float64)
            natural = make_smoothing_spline(x, k, w=w, lam=lam)(x)
            if LS_END_TAPER > 0 and n >= 4 * LS_END_TAPER:
                end = np.minimum(x, x[::-1])
                taper = np.minimum(1.0, (end + 1.0) / LS_END_TAPER) ** 2
                tapered = make_smoothing_spline(x, k, w=w * taper, lam=lam)(x)
                k = tapered + _end_moment_correction(tapered - natural)
            else:
                k = natural
        if smoothing_type == 2:
            k[keep] = kept
    else:
        raise DefinitionError(f"smoother must be one of {SMOOTHERS}, got {smoother!r}", field="smoother")
    return k


# =======================================================================================
# steps 3-5: the Newton/secant iteration
# =======================================================================================
def _jacobian_plan(N: int, closed: bool = False) -> list:
    """The colouring of :func:`_jacobian_bands` for N vertices: per colour the moved
    vertices, and where each band entry comes from (flat indices into the bands and into
    the colours' curvature changes: entry (1 + o, i) from the colour of vertex i + o). It
    depends on N only, so one Newton run computes it once."""
    colour = np.arange(N) % 3
    if closed and N % 3:
        colour[N - N % 3 :] = 3 + np.arange(N % 3)
    i = np.arange(N)
    moved_sets, dst, src = [], [], []
    for c in range(int(colour.max()) + 1):
        moved = colour == c
        for o in (-1, 0, 1):
            j = i + o
            ok = np.ones(N, dtype=bool) if closed else (j >= 0) & (j < N)
            j = j % N
            ok &= moved[j]
            dst.append((1 + o) * N + i[ok])  # bands[1 + o, i] (flat)
            src.append(c * N + i[ok])  # ∂κ_i from the net with colour c moved (flat)
        moved_sets.append(moved)
    return [moved_sets, np.concatenate(dst), np.concatenate(src)]


def _jacobian_bands(op: _KnotCurvature, P: np.ndarray, kappa: np.ndarray, normals: np.ndarray, step: float,
                    rows: np.ndarray, closed: bool = False, plan: list | None = None) -> np.ndarray:
    """Tridiagonal J_ij = ∂κ_i/∂(ε n_j), vertex j ↔ control point ``P[rows[j]]`` (Hvid's
    d_j), as bands[1 + j − i, i] (row i: ∂κ_i/∂d_{i−1}, ∂κ_i/∂d_i, ∂κ_i/∂d_{i+1}; on a
    closed curve the indices wrap, so the corners are bands[0, 0] and bands[2, N−1]).
    Vertices of one colour are moved together, since κ_i only sees d_{i−1}, d_i, d_{i+1}:
    colour j mod 3, and on a closed curve with N not a multiple of 3 the last N mod 3
    vertices get colours of their own so that no two moved vertices are within two of
    each other across the seam (:func:`_jacobian_plan`)."""
    N = kappa.size
    if plan is None:
        plan = _jacobian_plan(N, closed)
    moved_sets, dst, src = plan
    bands = np.zeros((3, N))
    # all colours' perturbed nets at once: κ_i of net c is the same arithmetic as
    # op.curvature on that net alone (the gathers and sums are per net)
    Q = np.repeat(P[None], len(moved_sets), axis=0)
    for c, moved in enumerate(moved_sets):
        Q[c, rows[moved]] += step * normals[moved]
    G = Q[:, op.cols]  # (colours, N, 4, dim)
    a, b = np.einsum("nk,cnkd->cnd", op.d1, G), np.einsum("nk,cnkd->cnd", op.d2, G)
    k = (a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]) / np.hypot(a[..., 0], a[..., 1]) ** 3
    dk = (k - kappa) / step
    bands.reshape(-1)[dst] = dk.reshape(-1)[src]
    return bands


def _solve_jacobian(bands: np.ndarray, rhs: np.ndarray, closed: bool) -> np.ndarray:
    if closed:
        return solve_cyclic_tridiagonal(bands[0], bands[1], bands[2], rhs)
    # A[i, i+1] = bands[2, i], A[i, i−1] = bands[0, i]: LAPACK's tridiagonal ?gtsv, the
    # routine scipy.linalg.solve_banded((1, 1), ...) calls, without its wrapper's work
    return _solve_tridiagonal(bands[0, 1:], bands[1], bands[2, :-1], rhs)


def _solve_tridiagonal(lower: np.ndarray, diag: np.ndarray, upper: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """x with A x = rhs for the tridiagonal A (sub-, main and super-diagonal), by LAPACK
    dgtsv as ``scipy.linalg.solve_banded`` does for one band each side (the same numbers
    and errors: ValueError for non-finite input, LinAlgError when singular)."""
    from scipy.linalg.lapack import dgtsv

    arrays = [np.asarray(a, dtype=np.float64) for a in (lower, diag, upper, rhs)]
    if not all(np.isfinite(a).all() for a in arrays):
        raise ValueError("array must not contain infs or NaNs")
    *_, x, info = dgtsv(*arrays)
    if info > 0:
        raise np.linalg.LinAlgError("singular matrix")
    if info < 0:
        raise ValueError(f"illegal value in {-info}-th argument of internal gtsv")
    return x


def newton_curvature(
    curve: BSplineCurve,
    params: np.ndarray,
    target: np.ndarray,
    max_iterations: int,
    tolx: float,
    tolf: float,
    progress: Progress | None = None,
    closed: bool = False,
    op: "_KnotCurvature | None" = None,
) -> tuple[BSplineCurve, list[tuple[float, float]], bool, str]:
    """Steps 3–5 of Hvid (1993) §3.2 on a cubic with knots at ``params`` (reference length
    1). Returns (curve, history of (Σ|κ−κ*|, Σ|δ|), converged, reason). Open curves: the
    end control points P_0 = r_0 and P_{n+2} = r_n never move. Closed (periodic, from
    :func:`periodic_spline_through`): every control point moves, the Jacobian is cyclic
    tridiagonal, and there is no seam. ``op``: :meth:`_KnotCurvature.of` (curve, params,
    closed) when the caller has it already (the knots never move)."""
    if op is None:
        op = _KnotCurvature.of(curve, params, closed)
    N = target.size
    if closed:
        P = np.array(curve.control_points[:N])
        rows = (np.arange(N) + 1) % N
        wrap = np.arange(N + 3) % N

        def build(P):
            return curve.with_control_points(P[wrap])
    else:
        P = np.array(curve.control_points)
        rows = np.arange(N) + 1

        def build(P):
            return curve.with_control_points(P)

    history: list[tuple[float, float]] = []
    first = None
    target = np.array(target, dtype=np.float64)
    plan = _jacobian_plan(N, closed)
    for iteration in range(1, int(max_iterations) + 1):
        kappa, normals = op.curvature_and_normals(P)
        residual = kappa - target
        errf = float(np.sum(np.abs(residual)))
        if not np.isfinite(errf):
            return build(P), history, False, "the curvature became non-finite"
        if errf <= tolf:
            history.append((errf, 0.0))
            return build(P), history, True, "tolf"
        first = errf if first is None else first
        if history and abs(history[-1][0] - errf) <= STATIONARY_CHANGE * errf and errf <= STATIONARY_FRACTION * first:
            # the curve no longer moves and what is left of κ* − κ is a small part of what
            # was asked: the part of the target no displacement reaches (round-off in the
            # cokernel of J); more iterations would only repeat this one
            history.append((errf, 0.0))
            return build(P), history, True, "stationary"
        if errf > DIVERGENCE_FACTOR * first:
            history.append((errf, float("nan")))
            return build(P), history, False, "the residual diverged"
        bands = _jacobian_bands(op, P, kappa, normals, JACOBIAN_STEP, rows, closed, plan)
        try:
            delta = _solve_jacobian(bands, -residual, closed)
        except np.linalg.LinAlgError:
            history.append((errf, float("nan")))
            return build(P), history, False, "the Jacobian is singular"
        if closed:
            delta = _without_rigid_modes(delta, P[rows], normals)
        if np.max(np.abs(delta)) > MAX_STEP:
            # The step asks for more than the curve can give: κ* − κ has a part along J's
            # weakest direction, which no reasonable displacement produces (ends at one
            # point, e.g. a cylinder read as an airfoil: the turn about that point, which
            # curvature cannot see). Take that part out of κ* (the least change of the
            # target that makes it reachable) and solve again.
            y = _weakest_left_vector(bands, closed)
            shift = y * float(y @ residual)
            target = target + shift
            residual = residual - shift
            delta = _solve_jacobian(bands, -residual, closed)
            if closed:
                delta = _without_rigid_modes(delta, P[rows], normals)
        errx = float(np.sum(np.abs(delta)))
        history.append((errf, errx))
        if not np.all(np.isfinite(delta)) or np.max(np.abs(delta)) > MAX_STEP:
            return build(P), history, False, (
                f"a step of {np.max(np.abs(delta)):.3g} exceeds {MAX_STEP} of the reference length (diverging)"
            )
        P[rows] += delta[:, None] * normals
        if progress is not None:
            progress(iteration, int(max_iterations))
        if errx <= tolx:
            kappa = op.curvature(P)
            history.append((float(np.sum(np.abs(kappa - target))), 0.0))
            return build(P), history, True, "tolx"
    return build(P), history, False, f"ntrial = {max_iterations} iterations reached"


def _weakest_left_vector(bands: np.ndarray, closed: bool = False, iterations: int = 4) -> np.ndarray:
    """Unit left singular vector of the smallest singular value of the (cyclic, when
    ``closed``) tridiagonal J (``bands`` as in :func:`_jacobian_bands`), by inverse
    iteration on Jᵀ: Jᵀ[i, i−1] = J[i−1, i] = bands[2, i−1], Jᵀ[i, i+1] = J[i+1, i] =
    bands[0, i+1]."""
    transposed = np.stack([np.roll(bands[2], 1), bands[1], np.roll(bands[0], -1)])
    y = np.random.default_rng(0).standard_normal(bands.shape[1])
    for _ in range(iterations):
        y = _solve_jacobian(transposed, y, closed)
        y /= np.linalg.norm(y)
    return y


def _without_rigid_modes(delta: np.ndarray, vertices: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """``delta`` less its least-squares component along the normal displacements of the
    rigid motions of a closed curve (the two translations and the turn about the
    centroid). Rigid motions leave every κ_i unchanged, so the cyclic J is (nearly)
    singular along them and round-off in the finite-difference Jacobian (§3.2 step 3)
    grows there from one iteration to the next: on a Blender Bezier circle the residual
    fell to 7e-9 and then rose tenfold per iteration. Removing them changes J δ only to
    first order in the round-off."""
    arm = vertices - vertices.mean(axis=0)
    M = np.stack([normals[:, 0], normals[:, 1], normals[:, 1] * arm[:, 0] - normals[:, 0] * arm[:, 1]], axis=1)
    coef, *_ = np.linalg.lstsq(M, delta, rcond=None)
    return delta - M @ coef


# =======================================================================================
# results
# =======================================================================================
@dataclass(frozen=True)
class Deviation:
    """Deviations between the smoothed curve and its references, in units of the reference
    length (fractions of chord for airfoils).

    same_parameter: Hvid's ds (§3.2.1), |S(u) − C(u)| at equal parameters, max.
    true: Hausdorff distance between the curves (closest points both ways), sampled.
    data: largest distance of the input data points from the smoothed curve.
    profile: (normalised arc length, distance) of the smoothed curve's samples to the
    unsmoothed one, for the plot of Hvid's Fig. 3.4.
    """

    same_parameter: float
    true: float
    data: float
    profile: tuple[np.ndarray, np.ndarray] = field(repr=False, default=(np.empty(0), np.empty(0)))


@dataclass(frozen=True)
class SmoothingResult:
    """What smooth2D / smoothfoil hand back, in the input's coordinates.

    curve: the smoothed cubic B-spline. unsmoothed: the cubic through the redistributed
    points before smoothing (Hvid's "original"). source: the cubic through the input data.
    params: u_i of the knots. kappa_before / kappa_target / kappa_after: κ at the knots
    (input units; airfoils: sign such that convex is positive). history: (Σ|κ−κ*|, Σ|δ|) per
    iteration (reference length 1). reference_length: chord (airfoil) or bounding-box
    diagonal (smooth2D). points: the np output points on the smoothed curve.
    dense_before / dense_after: (min, max) κ over the whole curves (sampled between knots too).
    """

    curve: BSplineCurve
    unsmoothed: BSplineCurve
    source: BSplineCurve
    params: np.ndarray
    kappa_before: np.ndarray
    kappa_target: np.ndarray
    kappa_after: np.ndarray
    history: tuple
    converged: bool
    reason: str
    reference_length: float
    deviation: Deviation
    distribution: DistributionReport
    points: np.ndarray
    dense_before: tuple[float, float]
    dense_after: tuple[float, float]
    kind: str = "smooth2D"
    curvature_sign: float = 1.0
    chord_scale: float = 1.0

    @property
    def iterations(self) -> int:
        return len([h for h in self.history if h[1] != 0.0 or not self.converged])

    def lines(self) -> list[str]:
        """A printout in the manner of Hvid's session (§3.4)."""
        out = [f"{self.kind}: {len(self.params)} smoothing points, reference length {self.reference_length:.9g}"]
        out += self.distribution.lines()
        out.append(f"initial curvature: min {self.kappa_before.min():.6f}  max {self.kappa_before.max():.6f}")
        for k, (f, x) in enumerate(self.history, 1):
            out.append(f"iteration no. {k}: {f:.10f} {x:.10f}")
        out.append(f"{self.reason} criteria" if self.converged else f"NOT CONVERGED: {self.reason}")
        out.append(f"smoothed curvature: min {self.kappa_after.min():.6f}  max {self.kappa_after.max():.6f}")
        out.append(
            f"max deviation / reference length: true {self.deviation.true:.3e}, same parameter "
            f"{self.deviation.same_parameter:.3e}, data points {self.deviation.data:.3e}"
        )
        return out


def write_points(path, points) -> None:
    """Write (x, y) rows at full float64 precision (repr, 17 significant digits), atomically
    (temporary file in the same folder, then os.replace) — Hvid's output step (§3.3
    "Output" warns that formatted writing destroys the smoothing)."""
    path = pathlib.Path(path)
    P = np.asarray(points, dtype=np.float64)
    text = "".join(f"{x!r} {y!r}\n" for x, y in P[:, :2].tolist())
    atomic_write(path, f"{P.shape[0]}\n{text}")


# =======================================================================================
# shared pipeline
# =======================================================================================
def _transform_curve(curve: BSplineCurve, scale: float, rotation: np.ndarray, origin: np.ndarray) -> BSplineCurve:
    """x ↦ origin + scale · (R x): exact on the control points."""
    return curve.with_control_points(origin + scale * (curve.control_points @ rotation.T))


def _dense_extremes(curve: BSplineCurve, sign: float) -> tuple[float, float]:
    k = sign * curvature_at(curve, span_samples(curve, DEVIATION_SAMPLES_PER_SPAN))
    return float(k.min()), float(k.max())


def _deviation(smoothed: BSplineCurve, unsmoothed: BSplineCurve, params: np.ndarray, data: np.ndarray,
               measure: bool = True, data_params: np.ndarray | None = None) -> Deviation:
    """The deviation report. The true distances are closest points (NURBS Book §6.1)
    found from the parameter correspondence (:func:`..nurbs.local_projection.closest_points_near`):
    the smoothed and the unsmoothed curve share their knots and lie close, so each sample's
    own parameter starts its foot's search on the other curve; the data points start at
    ``data_params`` (their parameters on the smoothed curve, approximately) or, when not
    given, at the nearest sample. The closest points are certified global there, and
    found by the general search where they cannot be."""
    same = float(np.max(np.linalg.norm(smoothed.evaluate(params) - unsmoothed.evaluate(params), axis=1)))
    if not measure:
        return Deviation(same, float("nan"), float("nan"))
    us = span_samples(smoothed, DEVIATION_SAMPLES_PER_SPAN)
    same_knots = np.array_equal(smoothed.knots, unsmoothed.knots)
    ss = us if same_knots else span_samples(unsmoothed, DEVIATION_SAMPLES_PER_SPAN)
    on_smoothed = smoothed.evaluate(us)
    if data_params is None:
        from scipy.spatial import cKDTree

        data_params = us[cKDTree(on_smoothed).query(data)[1]]
    # one pass: the smoothed samples onto the unsmoothed curve (0), the unsmoothed samples
    # and the data onto the smoothed one (1)
    n1, n2 = us.size, ss.size
    _, d = closest_points_near([unsmoothed, smoothed], np.concatenate([on_smoothed, unsmoothed.evaluate(ss), data]),
                               np.concatenate([us, ss, np.asarray(data_params, dtype=np.float64)]),
                               np.repeat([0, 1, 1], [n1, n2, len(data)]))
    d1, d2, d3 = d[:n1], d[n1: n1 + n2], d[n1 + n2:]
    t, s = arclength_table(smoothed, DEVIATION_SAMPLES_PER_SPAN)
    return Deviation(same, float(max(d1.max(), d2.max())), float(d3.max()), (s / s[-1], d1))


def _run(
    source: BSplineCurve,
    fractions: np.ndarray,
    output_fractions: np.ndarray,
    settings: SmoothingSettings,
    progress: Progress | None,
    rescale_chord: Callable[[BSplineCurve, BSplineCurve], tuple[BSplineCurve, float]] | None = None,
    closed: bool = False,
):
    """Redistribute, interpolate, smooth the curvature, iterate (reference length 1).
    closed: ``fractions`` run from 0 to 1 with the last point repeating the first; the
    curve is periodic (no end conditions, nothing fixed at the seam)."""
    table = arclength_table(source)
    u_src = params_at_arclength(source, fractions, table)
    r = derivatives(source, u_src, 0)[0]
    report = distribution_report(derivatives(source, params_at_arclength(source, output_fractions, table), 0)[0])
    if closed:
        unsmoothed, params = periodic_spline_through(r[:-1])
    else:
        unsmoothed, params = spline_through(r, settings.end_derivative_order)
    op = _KnotCurvature.of(unsmoothed, params, closed)
    kappa0 = op.curvature(unsmoothed.control_points)
    target = smooth_curvature(
        kappa0, settings.smoother, settings.passes, settings.smoothing_type, settings.smoothing_weight, closed
    )
    if closed:
        target = _keep_turning(target, kappa0, unsmoothed, params)
    curve, history, converged, reason = newton_curvature(
        unsmoothed, params, target, settings.max_iterations, settings.tolx, settings.tolf, progress, closed, op
    )
    if closed:
        curve = _rigid_align(curve, unsmoothed, params)
    chord_scale = 1.0
    if converged and rescale_chord is not None:
        curve, chord_scale = rescale_chord(curve, unsmoothed)
    kappa1 = op.curvature(curve.control_points)
    return unsmoothed, params, curve, kappa0, target, kappa1, history, converged, reason, report, chord_scale, u_src


def _keep_turning(target: np.ndarray, kappa: np.ndarray, curve: BSplineCurve, params: np.ndarray) -> np.ndarray:
    """κ* corrected so that a closed curve can still follow it: it must turn the tangent
    as far as κ does around the loop (∮κ ds = 2π) and bring the curve back to its start.
    To first order a change Δκ of a closed curve's curvature moves its end by
    ∮ Δκ(s) J (r(L) − r(s)) ds, so with ∮Δκ ds = 0 closure asks ∮ Δκ(s) r(s) ds = 0: three
    linear conditions. κ* gets the least correction c(s) = d + a x(s) + b y(s) that meets
    them (trapezoidal rule over the knots, arc lengths of ``curve``). Smoothing in the point
    index meets none of them when the points are not evenly spaced, and type 2's kept
    maximum breaks the symmetry that would otherwise meet the closure ones; a closed
    curve has no free end to absorb the difference and would bend its whole shape."""
    t, s = arclength_table(curve)
    knots_s = np.interp(np.concatenate([params, [curve.domain[1]]]), t, s)
    ds = np.diff(knots_s)
    w = 0.5 * (ds + np.roll(ds, 1))  # trapezoid weights of the periodic knots
    r = curve.evaluate(params)
    B = np.column_stack([np.ones_like(w), r - np.sum(w[:, None] * r, axis=0) / np.sum(w)])
    change = target - kappa
    coef = np.linalg.solve(B.T @ (w[:, None] * B), -B.T @ (w * change))
    return target + B @ coef


def _rigid_align(curve: BSplineCurve, reference: BSplineCurve, params: np.ndarray) -> BSplineCurve:
    """``curve`` moved by the rotation and translation that best map its knot points onto
    ``reference``'s (least squares, Kabsch/Procrustes). A closed curve is held by nothing
    but its curvature, which does not see rigid motions: the Newton steps drift along them
    (near-null vectors of the cyclic Jacobian). Curvature is unchanged by the move."""
    A, B = curve.evaluate(params), reference.evaluate(params)
    ca, cb = A.mean(axis=0), B.mean(axis=0)
    H = (A - ca).T @ (B - cb)
    U, _, Vt = np.linalg.svd(H)
    D = np.diag([1.0, np.sign(np.linalg.det(Vt.T @ U.T))])
    R = Vt.T @ D @ U.T
    return curve.with_control_points(cb + (curve.control_points - ca) @ R.T)


def advice(history, reason: str, settings: "SmoothingSettings | None" = None) -> str:
    """What to change, read from the residual history (Σ|κ − κ*| per iteration) and the
    reason the iteration stopped (Hvid 1993 §3.2.2: a target curvature that asks too much
    does not converge; §3.4: ntrial, tolx, tolf)."""
    f = np.array([h[0] for h in history], dtype=np.float64)
    s = settings or SmoothingSettings()
    if "non-finite" in reason:
        return ("the curvature became infinite: the curve has a cusp, a corner or nearly repeated points; "
                "remove them, or use more smoothing points (nsmooth) so each corner is resolved")
    if "singular" in reason:
        return "the Jacobian is singular: the curve folds back on itself; check the point order"
    if f.size >= 2 and "ntrial" in reason:
        best = int(np.argmin(f))
        if best < f.size - 1 and f[-1] > 2.0 * f[best]:
            return (f"the residual fell to {f[best]:.3g} at iteration {best + 1} and then rose (round-off): "
                    f"set tolf to {10 * f[best]:.2g} or more")
        rate = f[-1] / f[-2] if f[-2] > 0 else 1.0
        if rate < 0.5 and f[-1] > 0:
            more = int(np.ceil(np.log(max(s.tolf, 1e-300) / f[-1]) / np.log(rate))) if s.tolf > 0 else 10
            return (f"the residual still falls (×{rate:.2g} per iteration, now {f[-1]:.3g}): "
                    f"raise max_iterations (ntrial) to about {len(f) + max(more, 1) + 2}")
        return (f"the residual stalls at {f[-1]:.3g}: the target curvature cannot be reached; "
                "smooth less (fewer passes, or the least-squares smoother), use smoothing type 1 "
                f"on a closed curve, or accept it with tolf = {2 * f[-1]:.2g}")
    if "diverg" in reason or "exceeds" in reason:
        return (f"the first residual {f[0]:.3g} asks for more than a small correction: "
                "smooth less (fewer passes, or the least-squares smoother), use more smoothing points "
                "(nsmooth) where the curvature changes fast (smaller α), or check for a corner in the curve"
                if f.size else "smooth less (fewer passes)")
    return "smooth less (fewer passes, or the least-squares smoother), or use more iterations"


def _fail(kind: str, history, reason: str, settings: "SmoothingSettings | None" = None):
    raise SmoothingNotConverged(
        f"{kind}: the smoothing did not converge; the curve was not changed. What to change: "
        f"{advice(history, reason, settings)}",
        history,
        reason,
    )


def _as_points(points, what: str) -> np.ndarray:
    Q = np.array(points, dtype=np.float64)
    if Q.ndim != 2 or Q.shape[1] != 2:
        raise GeometryError(f"{what}: expected (count, 2) points, got shape {Q.shape}")
    if Q.shape[0] < 5:
        raise GeometryError(f"{what}: need at least 5 points, got {Q.shape[0]}")
    if not np.all(np.isfinite(Q)):
        k = int(np.argwhere(~np.isfinite(Q))[0, 0])
        raise GeometryError(f"{what}[{k}] is not finite ({Q[k].tolist()})")
    gaps = np.linalg.norm(np.diff(Q, axis=0), axis=1)
    size = float(np.linalg.norm(np.ptp(Q, axis=0)))
    if np.any(gaps <= 1e-12 * size):
        k = int(np.flatnonzero(gaps <= 1e-12 * size)[0]) + 1
        raise GeometryError(f"{what}[{k}] = {Q[k].tolist()} duplicates point {k - 1}")
    return Q


# =======================================================================================
# smooth2D
# =======================================================================================
def smooth2d(
    data,
    alpha: float = 1.0,
    settings: SmoothingSettings | None = None,
    progress: Progress | None = None,
    raise_on_failure: bool = True,
    measure: bool = True,
    closed: bool | None = None,
) -> SmoothingResult:
    """Hvid's smooth2D (1993 §3.3): smooth any plane curve.

    data: (m, 2) points (interpolated first, §3.2 step 1) or a 2-D BSplineCurve (used as it
    is when its degree is at least 2; a polyline's vertices are interpolated).
    closed: None detects a closed curve (last point, or end, within
    :data:`CLOSED_TOL` of the size from the first). Closed curves are smoothed as periodic
    ones: periodic interpolation of ``smoothing_points`` distinct points, curvature
    smoothed around the loop, every control point free (cyclic tridiagonal Jacobian), so
    the seam is not fixed and leaves no trace. The result is a periodic cubic (unclamped
    knots, last three control points repeating the first three).
    alpha: damping α of the curvature-weighted distribution (:func:`curvature_fractions`).
    Raises :class:`SmoothingNotConverged` (with the residual history) when the iteration
    fails, unless ``raise_on_failure`` is False.
    """
    settings = settings or SmoothingSettings(smoothing_type=1)
    if isinstance(data, BSplineCurve):
        if data.dim != 2:
            raise GeometryError(f"smooth2D needs a plane (2-D) curve, got dimension {data.dim}")
        points = _as_points(data.control_points, "curve control points") if data.degree == 1 else None
        raw = data if data.degree >= 2 else None
    else:
        points, raw = _as_points(data, "points"), None
    sample = raw.evaluate(span_samples(raw, 4)) if raw is not None else points
    lo = sample.min(axis=0)
    ref = float(np.linalg.norm(sample.max(axis=0) - lo))
    if ref <= 0:
        raise GeometryError("smooth2D: the curve has zero extent")
    eye = np.eye(2)
    if closed is None:
        closed = _closed(raw, points, ref)
    if raw is not None:
        source = _transform_curve(raw, 1.0 / ref, eye, -lo / ref)
        data_points = source.evaluate(span_samples(source, 1))
    else:
        data_points = (points - lo) / ref
        if closed:
            if np.linalg.norm(data_points[-1] - data_points[0]) <= CLOSED_TOL:
                data_points = data_points[:-1]
            source, _ = periodic_spline_through(data_points)
        else:
            source, _ = spline_through(data_points, settings.end_derivative_order)
    # closed: one more fraction, the last (= 1) repeating the first point of the loop
    fractions = curvature_fractions(source, settings.smoothing_points + int(closed), alpha)
    output_fractions = curvature_fractions(source, settings.output_points, alpha)
    (unsmoothed, params, curve, k0, target, k1, history, converged, reason, report, _, _) = _run(
        source, fractions, output_fractions, settings, progress, closed=closed
    )
    if not converged and raise_on_failure:
        _fail("smooth2D", history, reason, settings)
    deviation = _deviation(curve, unsmoothed, params, data_points, measure)
    out_fr = curvature_fractions(curve, settings.output_points, alpha)
    out_points = curve.evaluate(params_at_arclength(curve, out_fr))
    back = lambda c: _transform_curve(c, ref, eye, lo)  # noqa: E731
    return SmoothingResult(
        curve=back(curve),
        unsmoothed=back(unsmoothed),
        source=back(source),
        params=params,
        kappa_before=k0 / ref,
        kappa_target=target / ref,
        kappa_after=k1 / ref,
        history=tuple(history),
        converged=converged,
        reason=reason,
        reference_length=ref,
        deviation=deviation,
        distribution=DistributionReport(report.max_ratio, report.first_segment * ref, report.last_segment * ref, report.count),
        points=lo + ref * out_points,
        dense_before=tuple(v / ref for v in _dense_extremes(unsmoothed, 1.0)),
        dense_after=tuple(v / ref for v in _dense_extremes(curve, 1.0)),
        kind="smooth2D",
    )


# =======================================================================================
# smoothfoil
# =======================================================================================
def is_closed(data) -> bool:
    """Would :func:`smooth2d` smooth ``data`` (points (m, 2) or a 2-D BSplineCurve) as a
    closed curve: its ends within :data:`CLOSED_TOL` of its size and meeting without a
    corner (:data:`CORNER_ANGLE_DEG`)?"""
    if isinstance(data, BSplineCurve):
        raw, points = (data, None) if data.degree >= 2 else (None, _as_points(data.control_points, "curve control points"))
    else:
        raw, points = None, _as_points(data, "points")
    sample = raw.evaluate(span_samples(raw, 4)) if raw is not None else points
    return _closed(raw, points, float(np.linalg.norm(np.ptp(sample, axis=0))))


def _closed(raw: BSplineCurve | None, points: np.ndarray | None, size: float) -> bool:
    ends = raw.evaluate(np.array(raw.domain)) if raw is not None else points[[0, -1]]
    return bool(np.linalg.norm(ends[1] - ends[0]) <= CLOSED_TOL * size) and not _corner_at_join(raw, points)


def _corner_at_join(raw: BSplineCurve | None, points: np.ndarray | None) -> bool:
    """Do the two ends of a curve whose ends coincide meet in a corner? A curve's end
    tangents at more than :data:`CORNER_ANGLE_DEG`; points: the turn between the last and
    the first chord both above that angle and more than :data:`CORNER_TURN_RATIO` times the
    turn at either neighbouring point (a closed outline turns by about the same angle at
    every point; a sharp trailing edge turns by much more at the join than next to it)."""
    def turn(a, b):
        na, nb = float(np.linalg.norm(a)), float(np.linalg.norm(b))
        if na == 0.0 or nb == 0.0:
            return np.pi
        return float(np.arccos(np.clip(np.dot(a, b) / (na * nb), -1.0, 1.0)))

    limit = np.radians(CORNER_ANGLE_DEG)
    if raw is not None:
        return turn(raw.derivatives(raw.domain[0], 1)[1], raw.derivatives(raw.domain[1], 1)[1]) > limit
    c = np.diff(points, axis=0)
    at_join = turn(c[-1], c[0])
    beside = max(turn(c[0], c[1]), turn(c[-2], c[-1]))
    return at_join > limit and at_join > CORNER_TURN_RATIO * beside


def _farthest_point(curve: BSplineCurve, origin: np.ndarray) -> float:
    """Parameter of the point of ``curve`` farthest from ``origin`` (the leading edge seen
    from the trailing edge): dense samples, then Newton on (C − T)·C' = 0."""
    u = span_samples(curve, DEVIATION_SAMPLES_PER_SPAN)
    k = int(np.argmax(np.linalg.norm(derivatives(curve, u, 0)[0] - origin, axis=1)))
    t, lo, hi = u[k], u[max(k - 1, 0)], u[min(k + 1, u.size - 1)]
    for _ in range(LEADING_EDGE_NEWTON_STEPS):
        D = derivatives(curve, t, 2)
        g = np.dot(D[0] - origin, D[1])
        h = np.dot(D[1], D[1]) + np.dot(D[0] - origin, D[2])
        if h >= 0:
            break
        step = float(np.clip(t - g / h, lo, hi))
        if step == t:  # a fixed point: the remaining steps would repeat it
            break
        t = step
    return float(t)


def _chord_frame(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    """(LE, TE midpoint, chord, rotation R with R (TE − LE)/chord = (1, 0))."""
    te = 0.5 * (points[0] + points[-1])
    i_le = int(np.argmax(np.linalg.norm(points - te, axis=1)))
    if i_le < MIN_POINTS_PER_SIDE or i_le > points.shape[0] - 1 - MIN_POINTS_PER_SIDE:
        raise GeometryError(
            f"smoothfoil: the leading edge (point {i_le} of {points.shape[0]}, farthest from the trailing edge) "
            f"must have at least {MIN_POINTS_PER_SIDE} points on each side; is the outline ordered TE -> LE -> TE?"
        )
    le = points[i_le]
    chord = float(np.linalg.norm(te - le))
    c, s = (te - le) / chord
    return le, te, chord, np.array([[c, s], [-s, c]])


def _extend_trailing_edge(points: np.ndarray, order: int) -> tuple[np.ndarray, int, int]:
    """Hvid (1993) §3.3 "Airfoil preparation" step 1: extend both trailing-edge ends
    along their end tangents to the point where the tangents meet (when that is behind
    the trailing edge and within :data:`TE_MEET_FACTOR` × L; otherwise along the
    tangents and gently onto a common apex, see below). Returns the new outline (apex
    first and last) and the number of points added at each end."""
    spline, _ = spline_through(points, order)
    t0 = -spline.derivatives(spline.domain[0], 1)[1]
    t1 = spline.derivatives(spline.domain[1], 1)[1]
    t0, t1 = t0 / np.linalg.norm(t0), t1 / np.linalg.norm(t1)
    p0, p1 = points[0], points[-1]
    A = np.stack([t0, -t1], axis=1)
    det = np.linalg.det(A)
    gap = float(np.linalg.norm(p1 - p0))
    a = b = np.inf
    if abs(det) > PARALLEL_TANGENT_TOL:
        a, b = np.linalg.solve(A, p1 - p0)
    h0 = float(np.linalg.norm(points[1] - points[0]))
    h1 = float(np.linalg.norm(points[-1] - points[-2]))
    L = float(np.clip(TE_EXTENSION_GAPS * gap, MIN_TE_EXTENSION, MAX_TE_FALLBACK))
    if 0 < a <= TE_MEET_FACTOR * L and 0 < b <= TE_MEET_FACTOR * L:
        apex = p0 + a * t0
        k0 = max(2, int(np.ceil(a / h0)))
        k1 = max(2, int(np.ceil(b / h1)))
        head = apex + (p0 - apex) * (np.arange(k0) / k0)[:, None]
        tail = p1 + (apex - p1) * (np.arange(1, k1 + 1) / k1)[:, None]
        return np.concatenate([head, points, tail]), k0, k1
    # The tangents are (nearly) parallel or diverge (thick blunt sections such as DU 35):
    # extend each end along its tangent by L and bend it gently onto the common apex
    # m, the mid-point of the two straight extensions: x(s) = p + s t + (s/L)^2 (m - p - L t),
    # s in [0, L], which leaves p with the end tangent t (so the kept part of the outline is
    # not kinked) and with curvature about gap / L^2.
    m = 0.5 * ((p0 + L * t0) + (p1 + L * t1))
    k0 = max(2, int(np.ceil(L / h0)))
    k1 = max(2, int(np.ceil(L / h1)))

    def branch(p, t, k, reverse):
        s = L * (np.arange(1, k + 1) / k)
        pts = p + s[:, None] * t + (s / L)[:, None] ** 2 * (m - p - L * t)
        return pts[::-1] if reverse else pts

    return np.concatenate([branch(p0, t0, k0, True), points, branch(p1, t1, k1, False)]), k0, k1


def smoothfoil(
    data,
    distribution: PolynomialDistribution | None = None,
    settings: SmoothingSettings | None = None,
    progress: Progress | None = None,
    raise_on_failure: bool = True,
    measure: bool = True,
    rescale: bool = True,
    realign: bool = False,
) -> SmoothingResult:
    """Hvid's smoothfoil (1993 §3.2.1, §3.3, §3.4): smooth an airfoil outline.

    data: an ``Airfoil`` of ``sections.airfoil_file`` (taken lower side first, TE → lower → LE → upper → TE, the
    order of the paper's fx66 file, so f(½) = 0.491 puts the leading edge at the middle
    point), or (m, 2) outline points TE → LE → TE in either direction and at any chord,
    position and angle (§3.3: smoothed at unit chord, mapped back).
    distribution: the §3.3 polynomial (default: the paper's 0.5, 0.5, 0.491, 0.1).
    Blunt trailing edges are extended, smoothed and cut back (§3.3 steps 1–4). The smoothed
    airfoil is rescaled to its original chord (§3.2). Curvatures are reported at unit
    chord with convex stretches positive; deviations as fractions of chord.
    """
    settings = settings or SmoothingSettings()
    distribution = distribution or PolynomialDistribution(0.5, 0.5, 0.491, 0.1)
    # an Airfoil (sections/airfoil_file.py) by its sides: importing the class would make
    # the two modules import each other (airfoil_file smooths with this one)
    if hasattr(data, "lower") and hasattr(data, "upper"):
        points = np.concatenate([data.lower[::-1], data.upper[1:]])
    else:
        points = _as_points(data, "airfoil outline")
    le, te, chord, R = _chord_frame(points)
    unit = ((points - le) @ R.T) / chord  # LE at the origin, TE mid-point at (1, 0)
    blunt = float(np.linalg.norm(unit[0] - unit[-1])) > SHARP_TE_TOL
    work, k0, k1 = (_extend_trailing_edge(unit, settings.end_derivative_order) if blunt else (unit, 0, 0))
    if blunt:
        # §3.3 step 2: the extended airfoil at unit chord (apex at (1, 0))
        le2, _, chord2, R2 = _chord_frame(work)
        work = ((work - le2) @ R2.T) / chord2
    else:
        work = work.copy()
        work[-1] = work[0]  # a sharp trailing edge: both ends exactly at the same point
        le2, chord2, R2 = np.zeros(2), 1.0, np.eye(2)
    # area sign: the outline runs clockwise (< 0) or anticlockwise; convex is positive
    x, y = work[:, 0], work[:, 1]
    sign = 1.0 if np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) > 0 else -1.0
    source, work_params = spline_through(work, settings.end_derivative_order)
    apex = work[0].copy()

    def rescale_chord(curve: BSplineCurve, unsmoothed: BSplineCurve) -> tuple[BSplineCurve, float]:
        # §3.2: the smoothed airfoil gets the chord of the original one (leading edge =
        # farthest point from the trailing edge). With ``realign`` the similarity about the
        # trailing edge also puts the leading edge back where it was, undoing the small
        # rotation that a changed trailing-edge tangent gives the whole outline.
        a = curve.evaluate(_farthest_point(curve, apex)) - apex
        b = unsmoothed.evaluate(_farthest_point(unsmoothed, apex)) - apex
        factor = float(np.linalg.norm(b) / np.linalg.norm(a))
        rot = np.eye(2)
        if realign:
            c, s = (a[0] * b[0] + a[1] * b[1]), (a[0] * b[1] - a[1] * b[0])
            rot = np.array([[c, -s], [s, c]]) / float(np.hypot(c, s))
        return curve.with_control_points(apex + factor * ((curve.control_points - apex) @ rot.T)), factor

    fractions = distribution.fractions(settings.smoothing_points)
    output_fractions = distribution.fractions(settings.output_points)
    (unsmoothed, params, curve, k0_, target, k1_, history, converged, reason, report, factor, u_src) = _run(
        source, fractions, output_fractions, settings, progress, rescale_chord if rescale else None
    )
    if not converged and raise_on_failure:
        _fail("smoothfoil", history, reason, settings)
    u_out = params_at_arclength(curve, output_fractions)
    out_points = curve.evaluate(u_out)
    cut = curve
    if blunt:
        # §3.3 step 4: cut back at the original trailing-edge ends
        ends = np.stack([work[k0], work[-1 - k1]])
        (ua, ub), _ = closest_point_curve(curve, ends)
        cut = split(split(curve, float(ua))[1], float(ub))[0]
        inside = (u_out > ua) & (u_out < ub)
        out_points = np.concatenate([cut.evaluate(cut.domain[0])[None], out_points[inside], cut.evaluate(cut.domain[1])[None]])
    # the data's parameters on the smoothed curve, about: source -> knot parameters (same knots as curve)
    deviation = _deviation(curve, unsmoothed, params, work, measure, np.interp(work_params, u_src, params))
    # back to the input frame: x ↦ le + chord · Rᵀ (le2 + chord2 R2ᵀ x)
    Rt, R2t = R.T, R2.T

    def back(c: BSplineCurve) -> BSplineCurve:
        return _transform_curve(c, chord * chord2, Rt @ R2t, le + chord * (le2 @ R))

    def back_points(p: np.ndarray) -> np.ndarray:
        return le + chord * ((le2 + chord2 * (p @ R2)) @ R)

    return SmoothingResult(
        curve=back(cut),
        unsmoothed=back(unsmoothed),
        source=back(source),
        params=params,
        kappa_before=sign * k0_,
        kappa_target=sign * target,
        kappa_after=sign * k1_,
        history=tuple(history),
        converged=converged,
        reason=reason,
        reference_length=chord * chord2,
        deviation=deviation,
        distribution=report,
        points=back_points(out_points),
        dense_before=_dense_extremes(unsmoothed, sign),
        dense_after=_dense_extremes(curve, sign),
        kind="smoothfoil",
        curvature_sign=sign,
        chord_scale=factor,
    )


def smooth_airfoil_result(points, count: int | None = None, **options) -> SmoothingResult:
    """The section pipelines' pre-processing (propeller, wind blade): the outline (m, 2)
    TE → LE → TE smoothed by :func:`smoothfoil`, with its report; ``result.points`` are
    resampled at ``count`` points (default m) in the input's frame and direction.
    ``options``: ``distribution`` and any :class:`SmoothingSettings` field (default: the
    paper's jobcard). Raises :class:`SmoothingNotConverged`."""
    P = _as_points(points, "airfoil outline")
    distribution = options.pop("distribution", None)
    settings = SmoothingSettings(**{"output_points": int(count or P.shape[0]), **options})
    return smoothfoil(P, distribution, settings)


def smooth_airfoil_points(points, count: int | None = None, **options) -> np.ndarray:
    """:func:`smooth_airfoil_result`'s points only."""
    return smooth_airfoil_result(points, count, **options).points
