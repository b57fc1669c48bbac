"""Approximating an existing impeller with Casey's patches (Casey 1983: "general enough
to be used ... in approximation of the geometry of existing ones").

- :func:`fit_string`: a C2 cubic Bézier string (a cubic B-spline with simple interior
  knots at the patch junctions) fitted by least squares with parameter correction to
  points of any dimension;
- :func:`fit_channel`: hub and shroud contour tables -> a meridional channel with the same
  number of patches on both walls;
- :func:`trim_lines_to_channel`: straight generating lines clipped to the hub and shroud
  surfaces of revolution;
- :func:`fit_ruled_surface`: trimmed generating lines -> a string of cubic-linear patches
  whose hub and shroud curves are C2 cubic splines fitted together (each line gives one
  6-D point, its hub end and shroud end), so the fitted rulings follow the data rulings.
"""
from __future__ import annotations

import numpy as np
from scipy.interpolate import make_lsq_spline

from ..errors import GeometryError
from ..nurbs import BSplineCurve, bezier_segments
from .bezier import BezierCurve, BezierString, PatchString
from .channel import MeridionalChannel

#: Parameter-correction sweeps and their stopping tolerance (parameter units).
CORRECTION_ITERATIONS = 50
CORRECTION_TOLERANCE = 1e-12
#: Relative weight that holds the end points of a fit on the data.
END_WEIGHT = 1e6
#: Newton tolerance for line/contour intersections (length units of the data).
INTERSECTION_TOLERANCE = 1e-12


def fit_string(points, n_patches: int | None = None, params=None, interior_knots=None,
               iterations: int = CORRECTION_ITERATIONS) -> tuple[BezierString, np.ndarray, np.ndarray]:
    """Least-squares C2 cubic spline through ``points`` (N, dim), ends held, parameters
    corrected by Newton steps on the foot-point equation C'(t)·(C(t) - Q) = 0 (Hoschek
    1988; The NURBS Book 2e §9.4.1 and Eq. 6.3), returned as a string of cubic Bézier
    patches (one per knot span; patch junctions at the knots).

    params: initial parameters (default chord length), mapped to [0, 1]. interior_knots:
    junction parameters in (0, 1); default ``n_patches`` equal spans. Returns
    (string, params, knots). Each span becomes one unit interval of the string's U, so the
    string is C2 in the fitting parameter and G2 (slope and curvature continuous) in U.
    """
    Q = np.asarray(points, dtype=float)
    if params is None:
        params = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(Q, axis=0), axis=1))]
    t = np.asarray(params, dtype=float)
    t = (t - t[0]) / (t[-1] - t[0])
    if interior_knots is None:
        interior_knots = np.arange(1, n_patches) / n_patches
    inner = np.sort(np.asarray(interior_knots, dtype=float))
    if Q.shape[0] < inner.size + 4:
        raise GeometryError(f"{Q.shape[0]} points cannot determine {inner.size + 1} cubic patches")
    knots = np.r_[np.zeros(4), inner, np.ones(4)]
    w = np.ones(len(Q))
    w[[0, -1]] = END_WEIGHT
    spl = make_lsq_spline(t, Q, knots, k=3, w=w)
    for _ in range(iterations):
        C, C1, C2 = spl(t), spl(t, 1), spl(t, 2)
        r = C - Q
        f = np.sum(C1 * r, axis=1)
        fp = np.sum(C2 * r, axis=1) + np.sum(C1 * C1, axis=1)
        step = np.where(fp > 0, f / fp, 0.0)
        step[[0, -1]] = 0.0
        t_new = np.clip(t - step, 0.0, 1.0)
        t_new = np.maximum.accumulate(t_new)
        moved = np.max(np.abs(t_new - t))
        t = t_new
        try:
            spl = make_lsq_spline(t, Q, knots, k=3, w=w)
        except (ValueError, np.linalg.LinAlgError) as exc:
            raise GeometryError(f"least-squares fit failed: {exc}") from None
        if moved < CORRECTION_TOLERANCE:
            break
    curve = BSplineCurve(3, spl.t, spl.c)
    string = BezierString(tuple(BezierCurve(s.control_points) for s in bezier_segments(curve)))
    return string, t, knots


def fit_string_adaptive(points, tolerance: float, error=None, max_patches: int = 64, params=None,
                        start_patches: int = 1) -> tuple[BezierString, np.ndarray, np.ndarray]:
    """:func:`fit_string` with knots added until ``error(points, fitted)`` (default: the
    Euclidean residual at the corrected parameters) is at most ``tolerance``: each round
    splits the span holding the worst point at that point's parameter (knot insertion
    driven by the residual, as in The NURBS Book 2e §9.4.1's remarks on knot placement)."""
    Q = np.asarray(points, dtype=float)
    inner = np.arange(1, start_patches) / start_patches
    while True:
        string, t, knots = fit_string(Q, params=params, interior_knots=inner)
        U = _string_parameter(t, knots)
        res = np.linalg.norm(string.evaluate(U) - Q, axis=1) if error is None else error(string, U)
        worst = int(np.argmax(res))
        if res[worst] <= tolerance or inner.size + 1 >= max_patches:
            return string, U, knots
        k = np.searchsorted(knots, t[worst], side="right") - 1
        a, b = knots[k], knots[k + 1]
        new = t[worst] if 0.2 < (t[worst] - a) / (b - a) < 0.8 else 0.5 * (a + b)
        inner = np.sort(np.r_[inner, new])


def _string_parameter(t, knots) -> np.ndarray:
    """Fitting parameter t -> string parameter U (span k of the knots -> [k, k+1])."""
    breaks = np.unique(knots)
    k = np.clip(np.searchsorted(breaks, t, side="right") - 1, 0, breaks.size - 2)
    return k + (t - breaks[k]) / (breaks[k + 1] - breaks[k])


def fit_channel(hub_points, shroud_points, tolerance: float, max_patches: int = 64) -> MeridionalChannel:
    """A meridional channel (z, r) fitted to hub and shroud contour tables (N, 2) within
    ``tolerance`` (residual at the corrected foot points), with the same patch count on
    both walls (Casey's patches span hub and shroud): the wall that needs more patches
    sets the count, and the other wall gets that many equal spans."""
    hub, _, kh = fit_string_adaptive(hub_points, tolerance, max_patches=max_patches)
    shroud, _, ks = fit_string_adaptive(shroud_points, tolerance, max_patches=max_patches)
    for _ in range(max_patches):
        n = max(hub.count, shroud.count)
        if hub.count == shroud.count:
            break
        if hub.count < n:
            hub, _, _ = fit_string_adaptive(hub_points, tolerance, max_patches=max_patches, start_patches=n)
        if shroud.count < n:
            shroud, _, _ = fit_string_adaptive(shroud_points, tolerance, max_patches=max_patches, start_patches=n)
    if hub.count != shroud.count:
        raise GeometryError(f"hub and shroud fits ended with {hub.count} and {shroud.count} patches")
    return MeridionalChannel(PatchString(hub, shroud))


def _line_contour_intersection(A, B, contour: BezierString, t0: float) -> float:
    """Parameter t of the point A + t (B - A) whose meridional trace (z, r) lies on the
    contour (z = third coordinate, r = |(x, y)|): Newton on (t, s) from a sampled start."""
    s_grid = np.linspace(0.0, contour.count, contour.count * 400 + 1)
    C = contour.evaluate(s_grid)
    t = t0
    P = A + t * (B - A)
    zr = np.array([P[2], np.hypot(P[0], P[1])])
    s = s_grid[np.argmin(np.linalg.norm(C - zr, axis=1))]
    d = B - A
    for _ in range(50):
        P = A + t * d
        r = np.hypot(P[0], P[1])
        F = np.array([P[2], r]) - contour.evaluate(s)
        dz_dt = d[2]
        dr_dt = (P[0] * d[0] + P[1] * d[1]) / r
        dC = contour.derivatives(s, 1)[1]
        J = np.array([[dz_dt, -dC[0]], [dr_dt, -dC[1]]])
        step = np.linalg.solve(J, F)
        t -= step[0]
        s = float(np.clip(s - step[1], 0.0, contour.count))
        if np.max(np.abs(step)) < INTERSECTION_TOLERANCE:
            break
    return t


def trim_lines_to_channel(lines, channel: MeridionalChannel) -> np.ndarray:
    """Generating lines (K, 2, 3) as (shroud-side point, hub-side point), axis z, clipped
    to the channel: returns (K, 2, 3) with [:, 0] on the hub surface and [:, 1] on the
    shroud surface of revolution."""
    L = np.asarray(lines, dtype=float)
    out = np.empty_like(L)
    for k, (S, H) in enumerate(L):
        th = _line_contour_intersection(S, H, channel.hub, 1.0)
        ts = _line_contour_intersection(S, H, channel.shroud, 0.0)
        out[k, 0] = S + th * (H - S)
        out[k, 1] = S + ts * (H - S)
    return out


def fit_ruled_surface(hub_points, shroud_points, tolerance: float, max_patches: int = 64) -> tuple[PatchString, np.ndarray]:
    """A string of cubic-linear patches fitted to ruling end points: hub_points and
    shroud_points (K, 3), line k joining hub_points[k] to shroud_points[k]. The hub and
    shroud curves are fitted together as one 6-D C2 cubic string, so line k corresponds to
    one parameter u_k on both; knots are added (:func:`fit_string_adaptive`) until every
    line end lies within ``tolerance`` of its fitted ruling. Returns (surface, u_k)."""
    H = np.asarray(hub_points, dtype=float)
    T = np.asarray(shroud_points, dtype=float)
    mid = 0.5 * (H + T)
    d = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(mid, axis=0), axis=1))]

    def off_ruling(st: BezierString, U: np.ndarray) -> np.ndarray:
        # distance of both data ends from the fitted ruling line at u_k: moving an end
        # along its own line does not move the line, so only this part is an error
        F = st.evaluate(U)
        a, b = F[:, :3], F[:, 3:]
        e = (b - a) / np.linalg.norm(b - a, axis=1, keepdims=True)
        out = []
        for P in (H, T):
            w = P - a
            out.append(np.linalg.norm(w - np.sum(w * e, axis=1, keepdims=True) * e, axis=1))
        return np.maximum(*out)

    six, u, _ = fit_string_adaptive(np.hstack([H, T]), tolerance, error=off_ruling, max_patches=max_patches, params=d)
    lower = BezierString(tuple(BezierCurve(s.control_points[:, :3]) for s in six.segments))
    upper = BezierString(tuple(BezierCurve(s.control_points[:, 3:]) for s in six.segments))
    return PatchString(lower, upper), u
