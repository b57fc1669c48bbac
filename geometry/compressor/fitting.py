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
  6-D point, its hub end and shroud end), so the fitted rulings follow the data rulings;
- :func:`extend_channel`: the end patches of the walls continued (the same polynomials)
  so that the walls hold every blade edge;
- :func:`edges_on_walls`: the fitted surface rebuilt with its hub and shroud edges on the
  channel walls (Casey 1983: the ruled patches are bounded by curves on the walls; the
  edges are constructed on the walls and the surface ruled between them);
- :func:`fit_general_surface`: the fallback for a blade the best ruled surface misses, a
  surface cubic in v whose hub and shroud edges are the ruled surface's.
"""
from __future__ import annotations

import numpy as np
from scipy.interpolate import make_interp_spline, make_lsq_spline

from ..errors import GeometryError
from ..nurbs import BSplineCurve, BSplineSurface, bezier_segments
from .bezier import BezierCurve, BezierString, PatchString, bernstein
from .blade import CHECK_SAMPLES, FOOT_ITERATIONS, PATCH_MARGIN, _guess, wall_foot
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


#: How far (in contour parameter) a line may meet a wall beyond the contour's ends: the
#: end patches are continued (:func:`extend_channel`) to hold such a blade.
EXTRAPOLATION_LIMIT = 0.5


def _line_contour_intersection(A, B, contour: BezierString, t0: float) -> tuple[float, float]:
    """(t, s): the point A + t (B - A) whose meridional trace (z, r) lies on the contour
    at parameter s (z = third coordinate, r = |(x, y)|): Newton on (t, s) from a sampled
    start. The contour's end patches are continued up to EXTRAPOLATION_LIMIT beyond its
    ends, so a line that reaches past the contour data still meets its wall."""
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
        s = float(np.clip(s - step[1], -EXTRAPOLATION_LIMIT, contour.count + EXTRAPOLATION_LIMIT))
        if np.max(np.abs(step)) < INTERSECTION_TOLERANCE:
            break
    return t, s


def trim_lines_to_channel(lines, channel: MeridionalChannel, parameters: bool = False):
    """Generating lines (K, 2, 3) as (shroud-side point, hub-side point), axis z, clipped
    to the channel: returns (K, 2, 3) with [:, 0] on the hub surface and [:, 1] on the
    shroud surface of revolution; with ``parameters``, also the wall parameters (K, 2) of
    the ends (outside [0, count] where a line meets a wall beyond the contour data)."""
    L = np.asarray(lines, dtype=float)
    out = np.empty_like(L)
    U = np.empty((len(L), 2))
    for k, (S, H) in enumerate(L):
        th, U[k, 0] = _line_contour_intersection(S, H, channel.hub, 1.0)
        ts, U[k, 1] = _line_contour_intersection(S, H, channel.shroud, 0.0)
        out[k, 0] = S + th * (H - S)
        out[k, 1] = S + ts * (H - S)
    return (out, U) if parameters else out


def _extended_string(string: BezierString, U0: float, U1: float) -> BezierString:
    """``string`` with its first patch continued back to U0 < 0 and its last on to
    U1 > count (de Casteljau at a parameter outside [0, 1]: the same polynomial, so the
    wall is unchanged where it was and stays C2 at the junctions); the other patches
    are kept."""
    segs = list(string.segments)
    if U0 < 0.0:
        segs[0] = segs[0].split(U0)[1]
    if U1 > string.count:
        segs[-1] = segs[-1].split(1.0 + U1 - string.count)[0]
    return BezierString(tuple(segs))


def extend_channel(channel: MeridionalChannel, hub_range, shroud_range) -> MeridionalChannel:
    """The channel whose hub (shroud) contour covers the parameter range ``hub_range``
    (``shroud_range``) of the given channel, end patches continued where the range
    reaches past [0, count] (:func:`_extended_string`); the patch counts are kept."""
    lo = _extended_string(channel.hub, *hub_range)
    up = _extended_string(channel.shroud, *shroud_range)
    return MeridionalChannel(PatchString(lo, up))


def fit_ruled_surface(hub_points, shroud_points, tolerance: float, max_patches: int = 64, knots: bool = False):
    """A string of cubic-linear patches fitted to ruling end points: hub_points and
    shroud_points (K, 3), line k joining hub_points[k] to shroud_points[k]. The hub and
    shroud curves are fitted together as one 6-D C2 cubic string, so line k corresponds to
    one parameter u_k on both; knots are added (:func:`fit_string_adaptive`) until every
    line end lies within ``tolerance`` of its fitted ruling. Returns (surface, u_k), and
    with ``knots`` also the fitting parameters of the patch junctions (n + 1 values)."""
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

    six, u, fit_knots = fit_string_adaptive(np.hstack([H, T]), tolerance, error=off_ruling, max_patches=max_patches,
                                            params=d)
    lower = BezierString(tuple(BezierCurve(s.control_points[:, :3]) for s in six.segments))
    upper = BezierString(tuple(BezierCurve(s.control_points[:, 3:]) for s in six.segments))
    if knots:
        return PatchString(lower, upper), u, np.unique(fit_knots)
    return PatchString(lower, upper), u


#: Margin (wall parameter) by which an extended wall reaches past the blade's last edge point.
EXTENSION_MARGIN = 1e-3
#: Most patches per fitted blade surface once its edges are put on the walls.
MAX_EDGE_PATCHES = 512


def _on_wall(surface: PatchString, wall: BezierString, u, v0: float):
    """Points and u-derivatives of the curve in which the ruled ``surface`` meets the wall
    of revolution (:func:`_isocurves_on_wall` on its rulings): the rulings are kept, so
    the surface is only trimmed or continued along them. Returns (points, du-derivatives, v)."""
    A, dA = surface.lower.derivatives(u, 1)
    B, dB = surface.upper.derivatives(u, 1)
    return _isocurves_on_wall(np.stack([A, B], axis=1), np.stack([dA, dB], axis=1), wall, v0)


def _isocurves_on_wall(Q, dQ, wall: BezierString, v0: float):
    """Where the curves C_k(v) = Σ_i B_i(v) Q[k, i] (Bézier in v, extended beyond [0, 1] as
    polynomials) meet the wall of revolution: the v whose meridional trace (z, r) lies on
    the wall contour C(U), by Newton on (v, U) from v = ``v0``; and the derivative of that
    point along u (Q's u-derivatives dQ), from differentiating trace(C(u, v)) = C(U).
    Returns (points, du-derivatives, v)."""
    Q, dQ = np.asarray(Q, dtype=float), np.asarray(dQ, dtype=float)
    degree = Q.shape[1] - 1
    hodograph = degree * np.diff(Q, axis=1)

    def curve(v):
        return np.einsum("ki,kid->kd", bernstein(degree, v), Q), np.einsum("ki,kid->kd", bernstein(degree - 1, v),
                                                                           hodograph)

    v = np.full(len(Q), float(v0))
    P, _ = curve(v)
    zr = np.stack([P[:, 2], np.hypot(P[:, 0], P[:, 1])], axis=-1)
    U, _ = wall_foot(wall, zr, _guess(wall, zr))
    for _ in range(FOOT_ITERATIONS):
        P, d = curve(v)
        r = np.hypot(P[:, 0], P[:, 1])
        C, C1 = wall.derivatives(U, 1)
        F = np.stack([P[:, 2] - C[:, 0], r - C[:, 1]], axis=-1)
        a, b = d[:, 2], (P[:, 0] * d[:, 0] + P[:, 1] * d[:, 1]) / r
        det = -a * C1[:, 1] + C1[:, 0] * b
        dv = (-C1[:, 1] * F[:, 0] + C1[:, 0] * F[:, 1]) / det
        dU = (a * F[:, 1] - b * F[:, 0]) / det
        v -= dv
        U = np.clip(U - dU, 0.0, wall.count)
        if max(np.max(np.abs(dv)), np.max(np.abs(dU))) < INTERSECTION_TOLERANCE:
            break
    P, d = curve(v)
    r = np.hypot(P[:, 0], P[:, 1])
    C1 = wall.derivatives(U, 1)[1]
    Lu = np.einsum("ki,kid->kd", bernstein(degree, v), dQ)
    a, b = d[:, 2], (P[:, 0] * d[:, 0] + P[:, 1] * d[:, 1]) / r
    gz, gr = Lu[:, 2], (P[:, 0] * Lu[:, 0] + P[:, 1] * Lu[:, 1]) / r
    det = -a * C1[:, 1] + C1[:, 0] * b
    dv = (C1[:, 1] * gz - C1[:, 0] * gr) / det
    return P, Lu + dv[:, None] * d, v


def _wall_gap(string: BezierString, wall: BezierString) -> float:
    t = (np.arange(string.count)[:, None] + (np.arange(CHECK_SAMPLES + 1) / CHECK_SAMPLES)[None, :]).ravel()
    X = string.evaluate(t)
    zr = np.stack([X[:, 2], np.hypot(X[:, 0], X[:, 1])], axis=-1)
    return float(wall_foot(wall, zr, _guess(wall, zr))[1].max())


def edges_on_walls(surface: PatchString, channel: MeridionalChannel, wall_tolerance: float, knots=None,
                   max_patches: int = MAX_EDGE_PATCHES) -> tuple[PatchString, float]:
    """``surface`` (lower edge near the hub, upper near the shroud) rebuilt with both
    edges on the channel walls: each edge is the C2 cubic spline through the curve in
    which the surface meets the wall (:func:`_on_wall`, points on the surface's own
    rulings) at common nodes, with that curve's end derivatives (Casey 1983 Eqs. A1–A4 on
    non-uniform nodes), returned as a string of cubic patches (one per node interval);
    the new rulings join equal parameters on both edges, so they are the old rulings
    trimmed or continued to the walls.

    knots: the surface's fitting parameters of its patch junctions (n + 1 values in
    [0, 1], from :func:`fit_ruled_surface`), in which the edges are C2 (each patch spans a
    unit of U, so in U they are only G2); default uniform. The nodes are N + 1 equally
    spaced fitting parameters plus these junctions; N starts at the surface's count and
    is raised (the h^4 convergence of the cubic spline predicts by how much) until both
    edges lie on their walls within ``wall_tolerance``. Returns (surface, largest
    edge-to-wall distance)."""
    n = surface.count
    breaks = np.linspace(0.0, 1.0, n + 1) if knots is None else np.unique(np.asarray(knots, dtype=float))
    if breaks.size != n + 1:
        raise GeometryError(f"{breaks.size} junction parameters for a surface of {n} patches")

    def isocurves(tau):
        k = np.clip(np.searchsorted(breaks, tau, side="right") - 1, 0, n - 1)
        width = breaks[k + 1] - breaks[k]
        U = k + (tau - breaks[k]) / width
        A, dA = surface.lower.derivatives(U, 1)
        B, dB = surface.upper.derivatives(U, 1)
        return np.stack([A, B], axis=1), np.stack([dA, dB], axis=1) / width[:, None, None]

    return _edges_from_isocurves(isocurves, breaks, channel, wall_tolerance, max_patches)


def _edges_from_isocurves(isocurves, breaks, channel: MeridionalChannel, wall_tolerance: float,
                          max_patches: int) -> tuple[PatchString, float]:
    """Hub and shroud edges where the v-curves of a surface meet the walls
    (:func:`_isocurves_on_wall`), interpolated at common nodes over τ in [0, 1] (the
    ``breaks`` plus N + 1 equally spaced values, N raised until both edges lie on their
    walls within ``wall_tolerance``), as the ruled surface between them. ``isocurves(τ)``:
    the Bézier polygons in v of the v-curves at τ and their τ-derivatives."""
    N = len(breaks) - 1
    while True:
        grid = np.linspace(0.0, 1.0, N + 1)
        near = np.min(np.abs(grid[:, None] - breaks[None, :]), axis=1) < 0.25 / N
        nodes = np.union1d(grid[~near], breaks)
        Q, dQ = isocurves(nodes)
        edges, gap = [], 0.0
        for v0, wall in ((0.0, channel.hub), (1.0, channel.shroud)):
            W, dW, _ = _isocurves_on_wall(Q, dQ, wall, v0)
            spline = make_interp_spline(nodes, W, k=3, bc_type=([(1, dW[0])], [(1, dW[-1])]))
            edge = BezierString(tuple(BezierCurve(s.control_points)
                                      for s in bezier_segments(BSplineCurve(3, spline.t, spline.c))))
            gap = max(gap, _wall_gap(edge, wall))
            edges.append(edge)
        if gap <= wall_tolerance or N >= max_patches:
            return PatchString(*edges), gap
        N = min(max_patches, max(N + 1, int(np.ceil(N * (gap / wall_tolerance) ** 0.25 * PATCH_MARGIN))))


#: General-surface fallback: parameter-correction rounds, and the weight of the smoothing
#: term (second differences of the correction rows along u, relative to the data term) that
#: keeps the rows tame where the data leave them free.
GENERAL_ROUNDS = 3
GENERAL_FOOT_ITERATIONS = 6
GENERAL_SMOOTHING = 1e-6


def fit_general_surface(surface: PatchString, points, channel: MeridionalChannel, wall_tolerance: float,
                        max_patches: int = MAX_EDGE_PATCHES) -> tuple[BSplineSurface, float, float]:
    """A general (non-ruled) B-spline surface through ``points`` (K, 3) for a blade the
    best ruled surface misses (issue 18: "optionally by a general B-spline surface"),
    with its hub and shroud edges on the walls.

    ``surface``: the fitted ruled surface (edges on the walls). 1. Raised to degree 3 in v
    exactly (rows P0, (2P0 + P1)/3, (P0 + 2P1)/3, P1), all four rows are corrected by
    least squares to the points (:func:`_fit_rows`): a ruled fit's edges are wrong for a
    non-ruled blade (its rulings extend the data linearly to the walls). 2. The edges are
    rebuilt where this surface's v-curves meet the walls (:func:`_edges_from_isocurves`).
    3. Between them the two inner rows are fitted again, the edge rows held, so the edges
    stay on the walls. Returns (surface, largest distance of the points from it, largest
    edge-to-wall distance)."""
    from scipy.interpolate import BSpline

    from .export import ruled_bspline

    first, (u, v) = _fit_rows(ruled_bspline(surface), points, (0, 1, 2, 3))
    p, t = first.degree_u, first.knots_u
    a, b = float(t[p]), float(t[-p - 1])
    rows = BSpline(t, first.control_points.reshape(len(first.control_points), -1), p)
    slope = rows.derivative()

    def isocurves(tau):
        u = a + np.asarray(tau) * (b - a)
        return rows(u).reshape(-1, 4, 3), slope(u).reshape(-1, 4, 3) * (b - a)

    breaks = (np.unique(t[p:len(t) - p]) - a) / (b - a)
    walls, gap = _edges_from_isocurves(isocurves, breaks, channel, wall_tolerance, max_patches)
    # the new edges follow τ on [0, 1] as the first surface's u did (linearly, when their
    # knot spans are the node spacings; Newton corrects the rest)
    between = ruled_bspline(walls)
    a2, b2 = between.domain_u
    final, _ = _fit_rows(between, points, (1, 2), start=(a2 + (u - a) / (b - a) * (b2 - a2), v))
    from ..nurbs import closest_point_surface

    return final, float(closest_point_surface(final, np.asarray(points, dtype=float))[2].max()), gap


def _foot_newton(surface: BSplineSurface, X, u, v, iterations: int = GENERAL_FOOT_ITERATIONS):
    """Parameter correction: Newton on (S - X)·S_u = (S - X)·S_v = 0 from (u, v) (The
    NURBS Book 2e Eqs. 6.6–6.8), parameters kept in the domain."""
    (a, b), (c, d) = surface.domain_u, surface.domain_v
    for _ in range(iterations):
        D = surface.derivatives(u, v, 2)
        r = D[:, 0, 0] - X
        Su, Sv = D[:, 1, 0], D[:, 0, 1]
        f, g = np.sum(r * Su, axis=1), np.sum(r * Sv, axis=1)
        J11 = np.sum(Su * Su, axis=1) + np.sum(r * D[:, 2, 0], axis=1)
        J12 = np.sum(Su * Sv, axis=1) + np.sum(r * D[:, 1, 1], axis=1)
        J22 = np.sum(Sv * Sv, axis=1) + np.sum(r * D[:, 0, 2], axis=1)
        det = J11 * J22 - J12 * J12
        ok = np.abs(det) > 0.0
        du = np.where(ok, (J22 * f - J12 * g) / np.where(ok, det, 1.0), 0.0)
        dv = np.where(ok, (J11 * g - J12 * f) / np.where(ok, det, 1.0), 0.0)
        u = np.clip(u - du, a, b)
        v = np.clip(v - dv, c, d)
    return u, v


def _fit_rows(ruled: BSplineSurface, points, free: tuple, rounds: int = GENERAL_ROUNDS, start=None):
    """``ruled`` (degree (p, 1), non-rational) raised to degree 3 in v, its control rows
    ``free`` corrected by linear least squares to the points' residuals at their foot
    parameters (closest points first, or ``start``; then Newton parameter correction on
    each new surface, The NURBS Book 2e §9.4.1 and §6.1) with a small smoothing term on
    the rows' second differences along u. Returns (surface, (u, v))."""
    from scipy.interpolate import BSpline
    from scipy.sparse import diags, hstack
    from scipy.sparse.linalg import spsolve

    from ..nurbs import closest_point_surface

    if ruled.degree_v != 1 or ruled.weights is not None:
        raise GeometryError("the general-surface fallback starts from a non-rational ruled surface (degree 1 in v)")
    X = np.asarray(points, dtype=float)
    P0, P1 = ruled.control_points[:, 0], ruled.control_points[:, 1]
    base = np.stack([P0, (2.0 * P0 + P1) / 3.0, (P0 + 2.0 * P1) / 3.0, P1], axis=1)
    knots_v = np.array([0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0])
    p, t = ruled.degree_u, ruled.knots_u
    nu, m = base.shape[0], len(free)
    D = diags([np.ones(nu - 2), -2.0 * np.ones(nu - 2), np.ones(nu - 2)], [0, 1, 2], shape=(nu - 2, nu))
    smooth = _block_diagonal(D, m)
    surface = BSplineSurface(p, 3, t, knots_v, base)
    if start is None:
        u, v, _ = closest_point_surface(surface, X)
    else:
        u, v = _foot_newton(surface, X, *start)
    cp = base
    for _ in range(rounds):
        N = BSpline.design_matrix(np.clip(u, t[p], t[-p - 1]), t, p)
        Bv = bernstein(3, np.clip(v, 0.0, 1.0))
        A = hstack([diags(Bv[:, i]) @ N for i in free])
        residual = X - BSplineSurface(p, 3, t, knots_v, base).evaluate(u, v)
        # normal equations of the data and smoothing terms: sparse and banded in u
        A = A.tocsr()
        normal = (A.T @ A + (GENERAL_SMOOTHING * A.shape[0] / nu) * (smooth.T @ smooth)).tocsc()
        c = spsolve(normal, np.asarray(A.T @ residual))
        cp = base.copy()
        for k, row in enumerate(free):
            cp[:, row] += c[k * nu:(k + 1) * nu]
        surface = BSplineSurface(p, 3, t, knots_v, cp)
        u, v = _foot_newton(surface, X, u, v)
    return surface, (u, v)


def _block_diagonal(D, count: int):
    from scipy.sparse import block_diag

    return block_diag([D] * count).tocsr()
