"""The trimmed hub sector of the reference blade (Hally 2013 §10, with §11 for its IGES form).

Hub parameters. Hally parameterises the hub by p_h = (ξ, θ), ξ from ξ_lo at the upstream
end to ξ_hi at the downstream end, θ the angle about the axis. Here ξ is the parameter s
of :func:`c1_spine`, an exact rational reparameterisation of :attr:`Hub.spine` (same
point set, s in [0, 1] from the upstream pole to the downstream pole) whose interior knots
are simple, so the B-spline is C1: the hub's spine has double knots (C0 as a B-spline)
where the nose and tail meet the cylinder, and a C0 generatrix makes readers (OpenCASCADE)
report a C0 surface. Where the spine is tangent-continuous (elliptic ends) the weights are
chosen so that the homogeneous curve is C1 (The NURBS Book 2e §7.3, reparameterisation of
rational Bézier pieces); where it has a real crease (conical or flat ends) the two Bézier
points next to the crease are put on it, so the curve passes the crease with zero speed
(still C1 as a B-spline, the same point set). θ is the angle of :class:`~.hub.Hub`
(a right-hand rotation about -z, θ = 0 on +y). (s, θ) are exactly the (u, v) parameters
of the IGES Surface of Revolution (entity 120, IGES 5.3 §4.18) whose generatrix is the
C1 spine laid in the plane x = 0 as (0, ρ, z) and whose axis runs from (0, 0, 0) to
(0, 0, -1). Blade–hub intersection parameters (ξ_h of the Hub, θ) convert to (s, θ) through
the axial coordinate z, which increases strictly along the spine.

Construction of the sector (Hally 2013 §10; ξ below is the hub parameter s):

1. p_le = p_b(1/2), p_te = p_b(0): the hub parameters where the blade's leading and
   trailing edges meet the hub (p_b(u), u ≡ blade ξ, from :class:`BladeHubIntersection`).
2. Eqs. 51–53: m = (θ_te - θ_le)/(ξ_te - ξ_le); θ_lo = max(θ_min, θ_le - m(ξ_le - ξ_lo)/2),
   θ_hi = min(θ_max, θ_te + m(ξ_hi - ξ_te)/2), with [θ_min, θ_max] = [-π, π] as in the paper
   (the paper clamps one side each because its θ turns the other way; both bounds are
   applied here). The 120's angular range is the sector's extent plus a margin, inside
   [-π, π]: a range of 2π would make readers turn the 120 into a closed, periodic
   surface, which a sector does not need. The factor 1/2 makes each end piece of the Hermite
   spline below an exact parabola with slope 0 at the pole and m at the blade edge when the
   clamp is inactive.
3. p_h(ξ): the C1 piecewise-cubic Hermite spline through (ξ_lo, θ_lo), (ξ_le, θ_le),
   (ξ_te, θ_te), (ξ_hi, θ_hi) with slopes 0, m, m, 0 (the middle piece is the straight
   line). It is held exactly as a 2-D cubic B-spline u -> (ξ, θ) with double interior
   knots, ξ linear in u: u = (ξ - ξ_lo)/(ξ_hi - ξ_lo) (Eq. 55 as corrected in the
   papers' README: u runs 0 -> 1 from ξ_lo to ξ_hi).
4. Eq. 54: p_h1(u) = p_h(ξ(u)) + (0, π/Z).  Eq. 56: p_h3(u) = p_h1(1 - u) - (0, 2π/Z).
5. Eqs. 57–58: the straight lines p_h2 (at ξ_lo, from p_h1(0) to p_h3(1)) and p_h4 (at
   ξ_hi, from p_h3(0) to p_h1(1)). On this hub both lie on the poles, where the surface
   degenerates: their model-space images are points.

As printed, Eqs. 54, 56 run the sector edges clockwise in the (ξ, θ) plane while Eqs. 57,
58 run the end lines counter-clockwise, so the four do not chain head to tail in the order
h1, h2, h3, h4. The outer loop here is the counter-clockwise chain
[reverse(p_h3), p_h4, reverse(p_h1), p_h2] (the same point sets), the inner loop (the blade
footprint, Hally §10 and §11: c_h0 = h(p_b(u))) is clockwise: the trimmed face lies to
the left of every loop in (u, v) with the surface normal h_ξ × h_θ, which points out of
the hub (IGES 5.3 §4.20 and the convention OpenCASCADE follows).

The footprint p_b(u) is not a spline; it is approximated by a closed cubic B-spline in hub
parameter space by adaptive knot insertion (Hally 2013 §9/§11, :func:`approximate`) in
coordinates scaled to metres, to a tolerance consistent with the blade surfaces, and its
deviation from the exact intersection is measured in 3-D.

The area of the trimmed sector is integrated with Green's theorem: the area element of the
hub is g(ξ) dξ dθ with g = ρ |C'(ξ)| (independent of θ), so with G(ξ) = ∫_0^ξ g,
area = Σ_loops ∮ G(ξ(u)) θ'(u) du, each line integral by Gauss–Legendre quadrature on
pieces where the integrand is smooth (split at the knots of the loop curve and where ξ(u)
crosses a knot of the spine where g is less smooth, :func:`area_breaks`), G by
Gauss–Legendre on the spine's spans. The end lines lie at G(ξ_lo) = 0 and G(ξ_hi), so the
outer loop alone gives G(ξ_hi) 2π/Z, the hub's area over Z, whatever p_h is.
"""
from __future__ import annotations

from dataclasses import dataclass, field
import functools
from functools import cached_property

import numpy as np
from scipy.optimize import brentq

from ..errors import GeometryError
from ..nurbs import BSplineCurve, BSplineSurface, approximate, reverse

#: Default footprint tolerance as a fraction of the propeller diameter (metres / D): the
#: distance on the hub between the splined and the exact blade–hub intersection.
FOOTPRINT_TOLERANCE_FRACTION = 1e-6
#: Gauss–Legendre points per integration piece (area primitives and loop integrals).
GAUSS_POINTS = 24
#: Each spine span is cut into this many equal parts before quadrature (G(ξ)).
GAUSS_SUBDIVISIONS = 4
#: Loop integrals: Gauss points per piece, and the least number of pieces per curve (long
#: pieces, as in the Hermite edges, are cut until there are this many).
LOOP_GAUSS_POINTS = 16
LOOP_MIN_PIECES = 32
#: Samples per knot span when the footprint's 3-D deviation is measured after fitting.
DEVIATION_SAMPLES_PER_SPAN = 16
#: The loops may leave the clamp range by this much (radians) before it is moved (rounding).
ANGLE_RANGE_TOL = 1e-12
#: The 120's angular range reaches this far (radians) beyond the sector's extent.
ANGLE_MARGIN = 1e-2
#: Initial number of uniform knot spans for the footprint approximation.
FOOTPRINT_INITIAL_SPANS = 8
#: Equal spans of the cylinder in :func:`c1_spine` (the parameterisation differs from the
#: hub's only in the first and last of them and on the nose and tail).
CYLINDER_SPANS = 16
#: Size of the table that starts the inversion z -> s, and Newton's iteration cap.
Z_TABLE_SIZE = 257
MAX_NEWTON_ITERATIONS = 60
#: A rational quadratic arc spans at most this angle (The NURBS Book §7.5).
MAX_ARC_ANGLE = 0.5 * np.pi

PAPER_ANGLE_RANGE = (-np.pi, np.pi)

#: The blade surfaces whose v = 0 rows form the blade root edge (Hally 2013 Eqs. 2–5: c_1
#: round the trailing edge, c_2 on the pressure side, c_3 round the leading edge, c_4 on
#: the suction side; a right-hand blade chains them in this order, a left-hand one the
#: other way round).
ROOT_SURFACES = ("trailing_edge", "pressure_central", "leading_edge", "suction_central")
#: The parameter-space image of the root edge is fitted to this fraction of D (3-D distance
#: on the hub): far below the sewing tolerance of 1e-7 D a CFD user works with.
ROOT_PCURVE_FRACTION = 1e-9
#: A root edge farther than this (fraction of D) from the hub belongs to another hub:
#: refused. Between the sector tolerance and this the sector carries a warning.
ROOT_ON_HUB_REFUSAL_FRACTION = 1e-3


# -- exact Hermite boundary --------------------------------------------------------------------
def hermite_boundary(xi, theta, slopes) -> BSplineCurve:
    """The C1 cubic Hermite spline θ(ξ) through the points (xi[k], theta[k]) with slopes
    dθ/dξ = slopes[k], as an exact 2-D cubic B-spline u -> (ξ, θ) on u in [0, 1] with
    ξ = ξ_0 + u(ξ_K - ξ_0) (Hally 2013 §10 step 3, Eq. 55 as corrected).

    Each piece k has the Bézier points (ξ_k, θ_k), (ξ_k + h/3, θ_k + s_k h/3),
    (ξ_{k+1} - h/3, θ_{k+1} - s_{k+1} h/3), (ξ_{k+1}, θ_{k+1}), h = ξ_{k+1} - ξ_k; the joint
    points are the (h-weighted) averages of their neighbours, so one copy of each interior
    knot is removed and the spline has double interior knots (C1).
    """
    xi = np.asarray(xi, dtype=np.float64)
    theta = np.asarray(theta, dtype=np.float64)
    s = np.asarray(slopes, dtype=np.float64)
    if not (xi.ndim == 1 and xi.shape == theta.shape == s.shape and xi.size >= 2):
        raise GeometryError(f"hermite_boundary: expected equal 1-D arrays of >= 2 values, got {xi.shape}, "
                            f"{theta.shape}, {s.shape}")
    h = np.diff(xi)
    if np.any(~(h > 0)):
        raise GeometryError(f"hermite_boundary: the ξ values must increase strictly, got {xi.tolist()}")
    pts = [(xi[0], theta[0])]
    for k in range(xi.size - 1):
        pts.append((xi[k] + h[k] / 3.0, theta[k] + s[k] * h[k] / 3.0))
        pts.append((xi[k + 1] - h[k] / 3.0, theta[k + 1] - s[k + 1] * h[k] / 3.0))
    pts.append((xi[-1], theta[-1]))
    u = (xi - xi[0]) / (xi[-1] - xi[0])
    u[-1] = 1.0
    knots = np.concatenate([[0.0] * 4, np.repeat(u[1:-1], 2), [1.0] * 4])
    return BSplineCurve(3, knots, np.array(pts))


def _shifted(curve: BSplineCurve, dtheta: float) -> BSplineCurve:
    """The 2-D curve moved by (0, dθ) (B-splines are affinely invariant)."""
    return curve.with_control_points(curve.control_points + np.array([0.0, dtheta]))


def _line(p0, p1) -> BSplineCurve:
    return BSplineCurve(1, np.array([0.0, 0.0, 1.0, 1.0]), np.array([p0, p1], dtype=np.float64))


# -- exact NURBS surface of revolution ---------------------------------------------------------
def _arcs(angle0: float, angle1: float):
    """(knots, angles, radius factors, weights) of the rational quadratic arcs covering
    [angle0, angle1] in pieces of at most 90° (The NURBS Book 2e, Alg. A7.1). The knots are
    the angles of the arc joints, so the v parameter equals θ at every knot."""
    span = angle1 - angle0
    n = max(1, int(np.ceil(span / MAX_ARC_ANGLE - 1e-12)))
    d = span / n
    w = np.cos(0.5 * d)
    angles, factors, weights = [angle0], [1.0], [1.0]
    for k in range(n):
        a = angle0 + k * d
        angles += [a + 0.5 * d, a + d]
        factors += [1.0 / w, 1.0]
        weights += [w, 1.0]
    joints = angle0 + d * np.arange(1, n)
    knots = np.concatenate([[angle0] * 3, np.repeat(joints, 2), [angle1] * 3])
    knots[-3:] = angle1
    return knots, np.array(angles), np.array(factors), np.array(weights), d


def revolve_spine(spine: BSplineCurve, angle_range=PAPER_ANGLE_RANGE) -> BSplineSurface:
    """The hub h(ξ_h, θ) = (ρ sin θ, ρ cos θ, z) as an exact NURBS surface: the rational
    quadratic spine (ρ, z) times rational quadratic circular arcs over ``angle_range``
    (The NURBS Book 2e, Alg. A8.1). u = ξ_h exactly; v equals θ at the arc joints (the knots)
    and in between is related to θ by :func:`nurbs_v_of_theta`."""
    a0, a1 = map(float, angle_range)
    knots_v, angles, f, wa, _ = _arcs(a0, a1)
    C = spine.control_points
    wg = np.ones(C.shape[0]) if spine.weights is None else spine.weights
    rho, z = C[:, 0], C[:, 1]
    P = np.empty((C.shape[0], angles.size, 3))
    P[..., 0] = rho[:, None] * f[None, :] * np.sin(angles)[None, :]
    P[..., 1] = rho[:, None] * f[None, :] * np.cos(angles)[None, :]
    P[..., 2] = z[:, None]
    W = wg[:, None] * wa[None, :]
    return BSplineSurface(spine.degree, 2, spine.knots, knots_v, P, W)


def nurbs_v_of_theta(theta, angle_range=PAPER_ANGLE_RANGE) -> np.ndarray:
    """The v parameter of :func:`revolve_spine`'s surface at the angle θ.

    On a symmetric rational quadratic arc of opening φ (middle weight cos(φ/2)) the point at
    t in [0, 1] lies at the angle ψ from the arc's middle with tan(ψ/2) = tan(φ/4)(2t - 1)
    (the arc is a stereographic image of the line), so t = (1 + tan(ψ/2)/tan(φ/4))/2.
    """
    a0, a1 = map(float, angle_range)
    _, _, _, _, d = _arcs(a0, a1)
    th = np.asarray(theta, dtype=np.float64)
    k = np.clip(np.floor((th - a0) / d), 0, max(0, round((a1 - a0) / d) - 1))
    start = a0 + k * d
    psi = th - (start + 0.5 * d)
    t = 0.5 * (1.0 + np.tan(0.5 * psi) / np.tan(0.25 * d))
    return start + t * d


# -- quadrature ----------------------------------------------------------------------------------
_GL_X, _GL_W = np.polynomial.legendre.leggauss(GAUSS_POINTS)


@functools.lru_cache(maxsize=8)
def _leggauss(points: int):
    """Gauss–Legendre nodes and weights, computed once per order (an eigenvalue solve)."""
    x, w = np.polynomial.legendre.leggauss(points)
    x.flags.writeable = False
    w.flags.writeable = False
    return x, w


def _piece_edges(breaks, subdivisions: int) -> np.ndarray:
    b = np.unique(np.asarray(breaks, dtype=np.float64))
    t = np.linspace(0.0, 1.0, subdivisions + 1)
    return np.unique(np.concatenate([b[:-1, None] + t[None, :] * np.diff(b)[:, None], b[-1:, None]], axis=None))


def _gauss_pieces(breaks, subdivisions: int = GAUSS_SUBDIVISIONS, points: int = GAUSS_POINTS):
    """Nodes (n, N) and weights (n, N) of composite Gauss–Legendre (N = ``points``) on the
    pieces between ``breaks``, each cut into ``subdivisions`` equal parts."""
    x, w = (_GL_X, _GL_W) if points == GAUSS_POINTS else _leggauss(points)
    edges = _piece_edges(breaks, subdivisions)
    lo, hi = edges[:-1], edges[1:]
    half = 0.5 * (hi - lo)
    nodes = 0.5 * (hi + lo)[:, None] + half[:, None] * x[None, :]
    return nodes, half[:, None] * w[None, :]


# -- the C1 spine -----------------------------------------------------------------------------------
def _is_corner(before, joint, after, tol: float) -> bool:
    """Whether the control polygon turns at ``joint`` (no common tangent)."""
    a, b = joint - before, after - joint
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    if na <= tol or nb <= tol:
        return True
    return abs(a[0] * b[1] - a[1] * b[0]) > tol * max(na, nb) or float(a @ b) <= 0.0


def _end_weight(k: float, h_end: float, h_cyl: float) -> float:
    """Weight α of the end piece's middle point so that the end piece keeps its conic shape
    factor k = w²/(w0 w2) when its last point becomes the implied joint of a single knot:
    α² = k w_J, w_J = (h_cyl α + h_end)/(h_end + h_cyl) (positive root)."""
    a = h_end + h_cyl
    return (k * h_cyl + np.sqrt((k * h_cyl) ** 2 + 4.0 * a * k * h_end)) / (2.0 * a)


def c1_spine(hub, cylinder_spans: int = CYLINDER_SPANS) -> BSplineCurve:
    """The hub's spine (ρ, z) as a rational quadratic B-spline with simple interior knots.

    The hub's spine is three rational quadratic Bézier pieces (nose, cylinder, tail) joined
    with double knots at k1, k2. Here the knots are (0,0,0, k1, c_1..c_{n-1}, k2, 1,1,1),
    the cylinder cut into n = ``cylinder_spans`` equal spans, and the control points are
    N0, N1, Ca, G_3..G_n, Cb, T1, T2 (n + 4 points): the G_i are the cylinder's points at the Greville
    abscissae, so z is linear in the parameter over the inner cylinder spans, as on the hub
    (s = ξ_h there). Each join point is implied by its neighbours,
    J = (h_r w_l P_l + h_l w_r P_r)/(h_r w_l + h_l w_r). At a tangent join the end piece's
    middle weight keeps its conic's shape factor (:func:`_end_weight`) and Ca (Cb) puts J on
    the join point; at a crease N1 = Ca = J (T1 = Cb = J), which keeps the straight end
    piece straight and passes the crease with zero speed. Every point of the result lies on
    the hub's spine (exact); only the parameterisation of the end pieces and of the first
    and last cylinder spans differs.
    """
    S = hub.spine
    P = np.asarray(S.control_points, dtype=np.float64)
    W = np.ones(P.shape[0]) if S.weights is None else np.asarray(S.weights, dtype=np.float64)
    U = S.knots
    if P.shape[0] != 7 or S.degree != 2:
        raise GeometryError("c1_spine expects the hub's three-piece rational quadratic spine")
    if np.any(np.abs(W[[0, 2, 4, 6]] - 1.0) > 1e-15):
        raise GeometryError("c1_spine expects the hub's spine in standard form (join weights 1)")
    n = int(cylinder_spans)
    if n < 2:
        raise GeometryError(f"cylinder_spans must be at least 2, got {cylinder_spans}")
    k1, k2 = float(U[3]), float(U[5])
    h1, h3 = k1 - float(U[0]), float(U[-1]) - k2
    cyl = k1 + (k2 - k1) * np.arange(n + 1) / n
    cyl[-1] = k2
    hc = cyl[1] - cyl[0]
    knots = np.concatenate([[0.0] * 3, cyl, [1.0] * 3])
    tol = 1e-12 * max(1.0, float(np.abs(P).max()))
    N0, N1, J1, J2, T1, T2 = P[0], P[1], P[2], P[4], P[5], P[6]
    greville = 0.5 * (knots[1:-2] + knots[2:-1])  # one per control point
    t = (greville[2 : n + 2] - k1) / (k2 - k1)
    cylinder = J1[None, :] + t[:, None] * (J2 - J1)[None, :]
    if _is_corner(N1, J1, J2, tol):
        if abs(W[1] - 1.0) > 1e-15 and _is_corner(N0, N1, J1, tol):
            raise GeometryError("the hub's nose is curved and meets the cylinder in a crease: no C1 spine")
        alpha, N1n, Ca = 1.0, J1.copy(), J1.copy()
    else:
        alpha = _end_weight(W[1] ** 2, h1, hc)
        N1n, Ca = N1, (J1 * (hc * alpha + h1) - hc * alpha * N1) / h1
    if _is_corner(J1, J2, T1, tol):
        if abs(W[5] - 1.0) > 1e-15 and _is_corner(J2, T1, T2, tol):
            raise GeometryError("the hub's tail is curved and meets the cylinder in a crease: no C1 spine")
        beta, T1n, Cb = 1.0, J2.copy(), J2.copy()
    else:
        beta = _end_weight(W[5] ** 2, h3, hc)
        T1n, Cb = T1, (J2 * (hc * beta + h3) - hc * beta * T1) / h3
    cylinder[0], cylinder[-1] = Ca, Cb
    if np.any(np.diff(cylinder[:, 1]) < 0):
        raise GeometryError("c1_spine: the cylinder's control points are out of order")
    pts = np.concatenate([[N0, N1n], cylinder, [T1n, T2]])
    weights = np.concatenate([[1.0, alpha], np.ones(n), [beta, 1.0]])
    return BSplineCurve(2, knots, pts, weights)


def spine_parameter_of_z(spine: BSplineCurve, z, tol: float = 4e-16) -> np.ndarray:
    """The parameter s of the spine point at axial position z (z increases strictly along
    the spine): Newton's method from a tabulated inverse, safeguarded by a shrinking
    bracket, vectorised. Converges to ``tol`` times the spine's axial length."""
    z = np.asarray(z, dtype=np.float64)
    shape = z.shape
    z = z.ravel()
    a, b = spine.domain
    table_s = np.linspace(a, b, Z_TABLE_SIZE)
    table_z = spine.evaluate(table_s)[:, 1]
    za, zb = table_z[0], table_z[-1]
    scale = abs(zb - za)
    if np.any(z < za - 1e-12 * scale) or np.any(z > zb + 1e-12 * scale):
        raise GeometryError(f"axial positions outside the hub [{za:.6g}, {zb:.6g}]")
    k = np.clip(np.searchsorted(table_z, z), 1, Z_TABLE_SIZE - 1)
    lo, hi = table_s[k - 1], table_s[k]
    s = np.interp(z, table_z, table_s)
    for _ in range(MAX_NEWTON_ITERATIONS):
        D = spine.derivatives(s, 1)
        f = D[:, 0, 1] - z
        if np.max(np.abs(f)) <= tol * scale:
            break
        lo = np.where(f < 0, s, lo)
        hi = np.where(f > 0, s, hi)
        with np.errstate(divide="ignore", invalid="ignore"):
            step = s - f / D[:, 1, 1]
        s = np.where((step > lo) & (step < hi), step, 0.5 * (lo + hi))
    return s.reshape(shape)


def revolve_points(spine: BSplineCurve, s, theta) -> np.ndarray:
    """h(s, θ) = (ρ sin θ, ρ cos θ, z) for the spine (ρ(s), z(s)): broadcast shape + (3,)."""
    s, theta = np.broadcast_arrays(np.asarray(s, dtype=np.float64), np.asarray(theta, dtype=np.float64))
    a, b = spine.domain
    C = spine.evaluate(np.clip(s, a, b))
    return np.stack([C[..., 0] * np.sin(theta), C[..., 0] * np.cos(theta), C[..., 1]], axis=-1)


# -- the sector ------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class HubSector:
    """The hub sector of the reference blade with its footprint removed (Hally 2013 §10).

    All 2-D curves are in hub parameter space (s, θ) = the (u, v) space of the IGES 120
    (see the module docstring); each runs over its own parameter in [0, 1].

    hub: the :class:`~.hub.Hub`. spine: :func:`c1_spine` of it, (ρ, z) over s in [0, 1].
    blades: Z. clamp_range: [θ_min, θ_max] of Eqs. 51–52 ([-π, π] as in the paper unless
    the sector does not fit it, then centred on the sector). angle_range: (start, end) angles
    of the 120: the sector's angular extent plus ANGLE_MARGIN each side, inside clamp_range
    (a range of 2π would make the 120 a closed, periodic surface, which a sector does not
    need). xi_lo, xi_hi: the ends of s. leading_edge, trailing_edge: (s_le, θ_le),
    (s_te, θ_te). slope: m of Eq. 53. theta_lo, theta_hi: Eqs. 51–52. boundary: p_h (§10
    step 3). p_h1..p_h4: Eqs. 54, 57, 56, 58. outer_loop: the counter-clockwise chain of
    four curves (reverse(p_h3), p_h4, reverse(p_h1), p_h2). footprint: the closed spline
    approximating p_b(u) in (s, θ), oriented clockwise (the inner loop). footprint_deviation:
    largest 3-D distance between h(footprint(u)) and the exact intersection at the same u
    (m). tolerance: the footprint tolerance asked for (m). area: of the trimmed sector (m²).
    root_pcurves, root_edges: when built from the blade (``hub_sector(..., blade=...)``), the
    inner loop in (s, θ) and in 3-D (the blade root edge itself, see :func:`blade_root_edges`),
    clockwise; root_reversed: whether they run against +ξ. root_hub_distance: largest
    distance between the root edge and its image on the hub (m). warnings: missed tolerances,
    with figures.
    """

    hub: object
    spine: BSplineCurve
    blades: int
    clamp_range: tuple
    angle_range: tuple
    xi_lo: float
    xi_hi: float
    leading_edge: tuple
    trailing_edge: tuple
    slope: float
    theta_lo: float
    theta_hi: float
    boundary: BSplineCurve
    p_h1: BSplineCurve
    p_h2: BSplineCurve
    p_h3: BSplineCurve
    p_h4: BSplineCurve
    outer_loop: tuple
    footprint: BSplineCurve
    footprint_reversed: bool
    footprint_deviation: float
    tolerance: float
    area: float
    intersection: object = field(repr=False, default=None)
    root_pcurves: tuple | None = None
    root_edges: tuple | None = None
    root_hub_distance: float | None = None
    root_reversed: bool = False
    warnings: tuple = ()

    @property
    def inner_loop(self) -> tuple:
        """The inner trimming loop in (s, θ): the parameter-space images of the blade root
        edges when the sector was built from the blade surfaces, else the footprint spline."""
        return self.root_pcurves if self.root_pcurves is not None else (self.footprint,)

    @property
    def inner_model_curves(self) -> tuple | None:
        """The inner loop in 3-D when built from the blade: the blade root edges themselves
        (the surfaces' v = 0 control rows, copied; reversed where the loop runs against +ξ),
        in the order and sense of :attr:`inner_loop`. None for the footprint spline."""
        return self.root_edges

    def edge_model_curves(self, tolerance: float | None = None) -> tuple:
        """3-D curves of the sector's ±π/Z edges as (reverse(p_h3), reverse(p_h1)), the
        order of :attr:`outer_loop`. The first is the second's points turned by -2π/Z
        (reverse(p_h3)(u) = p_h1(u) - (0, 2π/Z), Eq. 56) and reversed, both from ONE fitted
        array, so in Z turned copies the +π/Z edge of one copy and the -π/Z edge of the next
        are the same control points up to the rounding of one rotation (no refit)."""
        c1 = self.model_curve(self.p_h1, tolerance)
        if c1 is None:
            raise GeometryError("the hub sector's edge p_h1 has no extent in 3-D")
        a = -2.0 * np.pi / self.blades
        sn, cs = np.sin(a), np.cos(a)
        # θ -> θ + a with (ρ sin θ, ρ cos θ, z): the rotation of :meth:`PropellerModel.blade_rotation`
        M = np.array([[cs, sn, 0.0], [-sn, cs, 0.0], [0.0, 0.0, 1.0]])
        c3r = c1.with_control_points(c1.control_points @ M.T)
        return c3r, reverse(c1)

    @property
    def loops(self) -> tuple:
        """(outer loop, inner loop), each a tuple of 2-D curves chained head to tail."""
        return self.outer_loop, self.inner_loop

    def evaluate(self, s, theta) -> np.ndarray:
        """h(s, θ) on the hub: broadcast shape + (3,)."""
        return revolve_points(self.spine, s, theta)

    @cached_property
    def surface(self) -> BSplineSurface:
        """The untrimmed hub over angle_range as an exact NURBS surface (u = s; v see
        :func:`nurbs_v_of_theta`)."""
        return revolve_spine(self.spine, self.angle_range)

    @property
    def generatrix(self) -> BSplineCurve:
        """The C1 spine in the plane x = 0 as the 3-D curve (0, ρ, z): the 120's generatrix."""
        S = self.spine
        P = np.column_stack([np.zeros(S.n_control), S.control_points[:, 0], S.control_points[:, 1]])
        return BSplineCurve(S.degree, S.knots, P, S.weights)

    def hub_parameters(self, xi_h, theta) -> np.ndarray:
        """(s, θ) of the hub point with :class:`Hub` parameters (ξ_h, θ): shape + (2,).
        Through z, so not on a flat end (all of it at one z); the blade footprint and the
        blade edges lie on the cylinder or on curved ends."""
        z = self.hub.spine.evaluate(np.asarray(xi_h, dtype=np.float64))[..., 1]
        return np.stack(np.broadcast_arrays(spine_parameter_of_z(self.spine, z), theta), axis=-1)

    def exact_footprint(self, u) -> np.ndarray:
        """p_b at the footprint's parameter u (its orientation), exactly, in (s, θ)."""
        u = np.asarray(u, dtype=np.float64)
        pb = self.intersection.hub_parameters(1.0 - u if self.footprint_reversed else u)
        return self.hub_parameters(pb[..., 0], pb[..., 1])

    # -- 3-D images of the parameter-space curves
    def model_points(self, curve: BSplineCurve, u) -> np.ndarray:
        """Points h(p(u)) of a hub-parameter-space curve: u.shape + (3,)."""
        p = curve.evaluate(np.asarray(u, dtype=np.float64))
        return self.evaluate(p[..., 0], p[..., 1])

    def model_curve(self, curve: BSplineCurve, tolerance: float | None = None) -> BSplineCurve | None:
        """A cubic B-spline within ``tolerance`` (default: the sector's) of h(p(u)) with the
        same parameter, or None when the image is a point (the end lines on the poles)."""
        tol = self.tolerance if tolerance is None else float(tolerance)
        pts = self.model_points(curve, np.linspace(*curve.domain, 9))
        if np.max(np.linalg.norm(pts - pts[0], axis=-1)) <= tol:
            return None
        a, b = curve.domain
        inner = np.unique(curve.knots[(curve.knots > a) & (curve.knots < b)])
        return approximate(lambda u: self.model_points(curve, u), tol, degree=3, domain=(a, b),
                           initial_knots=inner)

    def model_loops(self, tolerance: float | None = None) -> tuple:
        """(outer, inner) loops in 3-D. Outer: the ±π/Z edges of :meth:`edge_model_curves`
        (the end lines p_h2, p_h4 lie on the poles, points, and are left out). Inner: the
        blade root edges when the sector was built from the blade, else a fit of the
        footprint spline on the hub (:meth:`model_curve`)."""
        c3r, c1r = self.edge_model_curves(tolerance)
        out = (c3r, c1r)  # p_h4 and p_h2 lie on the poles: points, left out
        if self.root_edges is not None:
            return out, tuple(self.root_edges)
        return out, (self.model_curve(self.footprint, tolerance),)


# -- area -------------------------------------------------------------------------------------------
def area_primitive(spine: BSplineCurve, s) -> np.ndarray:
    """G(s) = ∫_0^s ρ |C'| ds', the hub area between the upstream pole and s per unit angle
    (composite Gauss–Legendre on the spine's spans, where the integrand is analytic)."""
    s = np.asarray(s, dtype=np.float64)
    lo_d, hi_d = spine.domain
    breaks = np.unique(spine.knots)

    def g(x):
        D = spine.derivatives(x, 1)
        return D[..., 0, 0] * np.linalg.norm(D[..., 1, :], axis=-1)

    nodes, weights = _gauss_pieces(breaks)
    edges = _piece_edges(breaks, GAUSS_SUBDIVISIONS)
    piece_lo = edges[:-1]
    cum = np.concatenate([[0.0], np.cumsum(np.sum(g(nodes) * weights, axis=1))])
    x = np.clip(s, lo_d, hi_d).ravel()
    k = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, piece_lo.size - 1)
    a = piece_lo[k]
    half = 0.5 * (x - a)
    nodes_x = (a + half)[:, None] + half[:, None] * _GL_X[None, :]
    partial = np.sum(g(nodes_x) * _GL_W[None, :], axis=1) * half
    return (cum[k] + partial).reshape(s.shape)


def area_breaks(spine: BSplineCurve) -> np.ndarray:
    """Interior knots of the spine where ρ|C'| may be less smooth than within a span. For a
    :func:`c1_spine` the inner cylinder spans (those not touched by Ca, Cb) are linear in s
    (ρ|C'| constant across their knots), so only the three knots at each end of the
    cylinder count; otherwise every knot."""
    U = np.unique(spine.knots)[1:-1]
    if U.size >= 6 and spine.degree == 2:
        P = spine.control_points[2:-2]
        w = np.ones(spine.n_control) if spine.weights is None else spine.weights
        d = np.diff(P, axis=0)
        if P.shape[0] > 3 and np.allclose(w[2:-2], 1.0, rtol=0, atol=1e-15) and \
                np.allclose(d[1:-1], d[1], rtol=1e-12, atol=0) and np.allclose(np.diff(U[1:-1]), U[2] - U[1]):
            return U[[0, 1, 2, -3, -2, -1]]
    return U


def _crossings(curve: BSplineCurve, values, U: np.ndarray) -> np.ndarray:
    """Parameters where the first coordinate of ``curve`` crosses one of ``values``."""
    values = np.asarray(values, dtype=np.float64)
    if values.size == 0:
        return np.empty(0)
    us = (U[:-1, None] + np.linspace(0.0, 1.0, 9)[None, :] * np.diff(U)[:, None]).ravel()
    fs = curve.evaluate(us)[:, 0][:, None] - values[None, :]
    out = []
    for i, j in zip(*np.nonzero(fs[:-1] * fs[1:] < 0)):
        kn = values[j]
        out.append(brentq(lambda u: float(curve.evaluate(u)[0]) - kn, us[i], us[i + 1], xtol=1e-15, rtol=1e-15))
    return np.array(out)


def _loop_integral(spine: BSplineCurve, curve: BSplineCurve, breaks=None) -> float:
    """∫ G(s(u)) θ'(u) du along a 2-D hub-parameter curve (Green's theorem term)."""
    a, b = curve.domain
    U = np.unique(np.clip(curve.knots, a, b))
    # where s(u) crosses a knot of the spine, G is less smooth: split there too
    kinks = area_breaks(spine) if breaks is None else breaks
    B = np.unique(np.concatenate([U, _crossings(curve, kinks, U)]))
    sub = max(1, int(np.ceil(LOOP_MIN_PIECES / (B.size - 1))))
    nodes, weights = _gauss_pieces(B, sub, LOOP_GAUSS_POINTS)
    D = curve.derivatives(nodes, 1)
    # G once per distinct s: the end lines p_h2, p_h4 keep s constant over all their nodes
    s_values, where = np.unique(D[..., 0, 0], return_inverse=True)
    G = area_primitive(spine, s_values)[where].reshape(D.shape[:-2])
    return float(np.sum(G * D[..., 1, 1] * weights))


def trimmed_area(spine: BSplineCurve, loops) -> float:
    """Area of the hub region bounded by ``loops`` (outer counter-clockwise, inner
    clockwise in (s, θ)): Green's theorem with the area element ρ|C'| ds dθ."""
    return float(sum(_loop_integral(spine, c) for loop in loops for c in loop))


def signed_parameter_area(curve: BSplineCurve, samples: int = 2001) -> float:
    """Shoelace area of a closed 2-D curve (positive when counter-clockwise)."""
    P = curve.evaluate(np.linspace(*curve.domain, samples))
    x, y = P[:, 0], P[:, 1]
    return 0.5 * float(np.sum(x[:-1] * y[1:] - x[1:] * y[:-1]))


# -- footprint ----------------------------------------------------------------------------------------
def _footprint_spline(intersection, hub, spine: BSplineCurve, tolerance: float):
    """The closed cubic spline through p_b(u) in (s, θ) (Hally 2013 §11), fitted in
    coordinates (s λ_s, θ ρ) scaled to metres so that ``tolerance`` is a distance on the hub;
    returns (curve oriented clockwise, measured 3-D deviation, whether it was reversed)."""
    zs = hub.spine.evaluate(intersection.xi_h)[:, 1]
    s_samples = np.linspace(*spine_parameter_of_z(spine, np.array([zs.min(), zs.max()])), 65)
    D = spine.derivatives(s_samples, 1)
    scale = np.array([float(np.max(np.linalg.norm(D[:, 1, :], axis=-1))), float(np.max(D[:, 0, 0]))])

    def exact(u):
        pb = intersection.hub_parameters(u)
        z = hub.spine.evaluate(pb[:, 0])[:, 1]
        return np.column_stack([spine_parameter_of_z(spine, z), pb[:, 1]])

    init = np.linspace(0.0, 1.0, FOOTPRINT_INITIAL_SPANS + 1)[1:-1]
    fit = approximate(lambda u: exact(u) * scale, tolerance, degree=3, initial_knots=init)
    P = fit.control_points / scale
    P[-1] = P[0]  # p_b(0) = p_b(1): the closed trailing edge (Hally 2013 §2)
    curve = BSplineCurve(3, fit.knots, P)
    reversed_ = signed_parameter_area(curve) > 0.0
    if reversed_:
        curve = reverse(curve)
    U = np.unique(curve.knots)
    u = (U[:-1, None] + np.linspace(0.0, 1.0, DEVIATION_SAMPLES_PER_SPAN + 1)[None, :] * np.diff(U)[:, None]).ravel()
    pb = intersection.hub_parameters(1.0 - u if reversed_ else u)
    fitted = curve.evaluate(u)
    dev = np.linalg.norm(revolve_points(spine, fitted[:, 0], fitted[:, 1]) - hub.evaluate(pb[:, 0], pb[:, 1]), axis=-1)
    return curve, float(dev.max()), reversed_


# -- the blade root edge as the inner loop ---------------------------------------------------------------
def blade_root_edges(blade) -> tuple:
    """The blade root edge: the v = 0 control rows of the four surfaces that reach the hub
    (:data:`ROOT_SURFACES`), chained head to tail from the trailing edge, each as a 3-D cubic B-spline over the surface's u
    knots: the very curves of the surfaces' boundaries (copies of the same float64 rows).
    Raises GeometryError when they do not chain head to tail exactly (a blade whose
    surfaces do not share their corners)."""
    curves = []
    for name in ROOT_SURFACES:
        surface = getattr(blade, name, None) if not isinstance(blade, dict) else blade.get(name)
        if surface is None:
            raise GeometryError(f"the blade root edge needs the blade surface {name!r}")
        curves.append(BSplineCurve(surface.degree_u, surface.knots_u, np.array(surface.control_points[:, 0]),
                                   None if surface.weights is None else np.array(surface.weights[:, 0])))
    # chain head to tail from the trailing edge (a left-hand blade runs the other way round)
    order, left = [0], [1, 2, 3]
    while left:
        end = curves[order[-1]].control_points[-1]
        nxt = [k for k in left if np.array_equal(curves[k].control_points[0], end)]
        if not nxt:
            gap = min(float(np.linalg.norm(curves[k].control_points[0] - end)) for k in left)
            raise GeometryError(f"the root edge of the blade surface {ROOT_SURFACES[order[-1]]} meets no other "
                                f"root edge (nearest gap {gap:.3g} m): the blade surfaces do not share their corners")
        order.append(nxt[0])
        left.remove(nxt[0])
    if not np.array_equal(curves[order[-1]].control_points[-1], curves[0].control_points[0]):
        raise GeometryError("the blade root edge does not close: the blade surfaces do not share their corners")
    curves = [curves[k] for k in order]
    return tuple(curves)


def hub_parameters_of_points(spine: BSplineCurve, points) -> np.ndarray:
    """(s, θ) of the hub point at the same axial position z and angle θ = atan2(x, y) as
    ``points`` (shape + (3,) -> shape + (2,)). On the cylinder this is the closest hub
    point; a blade root lies on the cylinder or on the curved ends (not on a flat end)."""
    P = np.asarray(points, dtype=np.float64)
    return np.stack([spine_parameter_of_z(spine, P[..., 2]), np.arctan2(P[..., 0], P[..., 1])], axis=-1)


def root_pcurves(spine: BSplineCurve, roots, tolerance: float):
    """The root edges' images in the hub parameter space: for each 3-D root curve r(u),
    the 2-D cubic B-spline p(u) ≈ (s, θ)(r(u)) (:func:`hub_parameters_of_points`), by
    adaptive knot insertion from the curve's own interior knots (Hally 2013 §9/§11,
    :func:`approximate`) in coordinates scaled to metres (s |C'|max, θ ρmax), so that
    ``tolerance`` is a distance on the hub. Returns (pcurves, largest 3-D distance between
    r(u) and h(p(u)) over all curves at the same u): the distance of the root edge from the
    hub plus the fit error."""
    s_samples = np.linspace(*spine.domain, 257)
    D = spine.derivatives(s_samples, 1)
    scale = np.array([float(np.max(np.linalg.norm(D[:, 1, :], axis=-1))), float(np.max(D[:, 0, 0]))])
    out, dist = [], 0.0
    for r in roots:
        def image(u, r=r):
            return hub_parameters_of_points(spine, r.evaluate(u)) * scale

        interior = np.unique(r.knots[r.degree + 1 : -r.degree - 1])
        fit = approximate(image, tolerance, degree=3, domain=r.domain, initial_knots=interior)
        p = fit.with_control_points(fit.control_points / scale)
        U = np.unique(p.knots)
        u = (U[:-1, None] + np.linspace(0.0, 1.0, DEVIATION_SAMPLES_PER_SPAN + 1)[None, :] * np.diff(U)[:, None]).ravel()
        q = p.evaluate(u)
        dist = max(dist, float(np.max(np.linalg.norm(revolve_points(spine, q[:, 0], q[:, 1]) - r.evaluate(u), axis=-1))))
        out.append(p)
    return tuple(out), dist


def root_footprint_distance(sector, blade, samples: int = DEVIATION_SAMPLES_PER_SPAN) -> float:
    """Largest 3-D distance between the sector's inner-loop model curves and the blade's
    root edge (:func:`blade_root_edges`) at matching parameters; 0 when the loop is the root
    edge itself. Raises GeometryError when the sector was not built from a blade."""
    if sector.root_edges is None:
        raise GeometryError("the hub sector was built from the blade–hub intersection, not from the blade root edge")
    roots = oriented_root_edges(sector, blade)
    loop = sector.root_edges
    worst = 0.0
    for a, b in zip(roots, loop):  # same order: both chained by blade_root_edges
        U = np.unique(np.concatenate([a.knots, b.knots]))
        u = (U[:-1, None] + np.linspace(0.0, 1.0, samples + 1)[None, :] * np.diff(U)[:, None]).ravel()
        worst = max(worst, float(np.max(np.linalg.norm(a.evaluate(u) - b.evaluate(u), axis=-1))))
    return worst


def full_hub_angle_range(sector) -> tuple[float, float]:
    """(a0, a0 + 2π): the angular range of a hub turned a full turn, with its seam midway
    between the reference blade's root and the root of the blade before it, so the Z
    footprints (the reference one turned by 2πk/Z, k = 0..Z-1) lie strictly inside.
    Raises GeometryError when neighbouring roots overlap on the hub."""
    lo, hi = _theta_extent(sector.inner_loop)  # conservative (control polygons)
    pitch = 2.0 * np.pi / sector.blades
    if not hi - lo < pitch:
        raise GeometryError(f"the blade root spans {hi - lo:.6g} rad of the hub, more than the blade pitch "
                            f"2π/Z = {pitch:.6g} rad: neighbouring blade roots overlap")
    a0 = 0.5 * (lo + hi - pitch)
    return a0, a0 + 2.0 * np.pi


def turned_pcurves(sector, k: int) -> tuple:
    """The inner loop of blade k's footprint in (s, θ): the reference loop moved by
    (0, 2πk/Z) (the hub is axisymmetric, so this is exact)."""
    d = 2.0 * np.pi * k / sector.blades
    return tuple(c.with_control_points(c.control_points + np.array([0.0, d])) for c in sector.inner_loop)


def oriented_root_edges(sector, blade) -> tuple:
    """The root edge of ``blade`` (any turned copy of the blade the sector was built from)
    chained and oriented as the sector's inner loop (:func:`blade_root_edges`, reversed when
    the sector's is)."""
    roots = blade_root_edges(blade)
    if sector.root_reversed:
        roots = tuple(reverse(c) for c in roots[::-1])
    return roots


# -- Eqs. 51-58 ----------------------------------------------------------------------------------------
def _sector_curves(xi_lo, xi_hi, le, te, Z, clamp_range):
    """Eqs. 51–58 for the given clamp range: (m, θ_lo, θ_hi, p_h, p_h1, p_h2, p_h3, p_h4)."""
    (xi_le, th_le), (xi_te, th_te) = le, te
    if xi_te == xi_le:
        raise GeometryError("the blade's leading and trailing edges meet the hub at the same axial position; "
                            "the hub sector of Hally (2013) §10 needs them apart")
    t_min, t_max = clamp_range
    m = (th_te - th_le) / (xi_te - xi_le)  # Eq. 53
    # the four points ordered along the axis (the leading edge normally lies upstream)
    (x1, t1), (x2, t2) = sorted([(xi_le, th_le), (xi_te, th_te)])
    if not xi_lo < x1 < x2 < xi_hi:
        raise GeometryError(f"the blade edges meet the hub at s = {x1:.6g}, {x2:.6g}, not strictly inside "
                            f"the hub's range ({xi_lo:.6g}, {xi_hi:.6g})")
    # Eqs. 51-52, extrapolating from the upstream and the downstream edge; the paper clamps
    # one side each (its θ runs the other way); either bound may apply here
    theta_lo = min(max(t1 - 0.5 * m * (x1 - xi_lo), t_min), t_max)
    theta_hi = min(max(t2 + 0.5 * m * (xi_hi - x2), t_min), t_max)
    p_h = hermite_boundary([xi_lo, x1, x2, xi_hi], [theta_lo, t1, t2, theta_hi], [0.0, m, m, 0.0])
    d = np.pi / Z
    p_h1 = _shifted(p_h, d)  # Eq. 54
    p_h3 = _shifted(reverse(p_h1), -2.0 * d)  # Eq. 56
    P1, P3 = p_h1.control_points, p_h3.control_points
    p_h2 = _line(P1[0], P3[-1])  # Eq. 57
    p_h4 = _line(P3[0], P1[-1])  # Eq. 58
    return m, theta_lo, theta_hi, p_h, p_h1, p_h2, p_h3, p_h4


def _theta_extent(curves) -> tuple[float, float]:
    """(min, max) of θ over 2-D B-spline curves, bounded by their control polygons (convex
    hull property): conservative, which is all the range checks need."""
    th = np.concatenate([c.control_points[:, 1] for c in curves])
    return float(th.min()), float(th.max())


def hub_sector(model, tolerance: float | None = None, clamp_range=None, intersection=None, blade=None) -> HubSector:
    """The trimmed hub sector of ``model`` (a :class:`~.model.PropellerModel`), Hally (2013) §10.

    tolerance: footprint tolerance in metres (default FOOTPRINT_TOLERANCE_FRACTION × D; use
    the blade surfaces' tolerance). clamp_range: [θ_min, θ_max] of Eqs. 51–52 (default
    [-π, π] as in the paper; when the sector does not fit it, it is centred on the sector).
    intersection: a :class:`BladeHubIntersection` (default the model's).
    blade: the blade surfaces (a ``SmoothedBlade`` or a dict of the five). When given, the
    inner loop is the blade root edge itself (:func:`blade_root_edges`): its model-space
    curves are the surfaces' v = 0 rows (copied), its parameter-space curves their images on
    the hub (:func:`root_pcurves`, fitted to ROOT_PCURVE_FRACTION × D), so blade and hub share
    one junction curve (Hally 2013 §10: the blade–hub intersection, fillet-free) and sew
    at any tolerance. ``root_hub_distance`` then says how far that curve lies from the
    hub; above ``tolerance`` the sector carries a warning, above
    ROOT_ON_HUB_REFUSAL_FRACTION × D it is refused.
    Raises :class:`GeometryError` when the sector cannot be built.
    """
    hub = model.hub
    Z = int(model.blades)
    if Z < 1:
        raise GeometryError(f"a propeller needs at least one blade, got {Z}")
    D = 2.0 * float(model.blade.radius)
    tol = FOOTPRINT_TOLERANCE_FRACTION * D if tolerance is None else float(tolerance)
    if not tol > 0:
        raise GeometryError(f"tolerance must be positive, got {tolerance!r}")
    I = model.blade_hub_intersection if intersection is None else intersection
    spine = c1_spine(hub)
    xi_lo, xi_hi = map(float, spine.domain)
    pe = I.hub_parameters(np.array([0.5, 0.0]))  # §10 step 1: leading edge ξ = 1/2, trailing edge ξ = 0
    se = spine_parameter_of_z(spine, hub.spine.evaluate(pe[:, 0])[:, 1])
    le, te = (float(se[0]), float(pe[0, 1])), (float(se[1]), float(pe[1, 1]))

    footprint, deviation, reversed_ = _footprint_spline(I, hub, spine, tol)
    fp_lo, fp_hi = _theta_extent([footprint])
    pcurves = roots = root_dist = None
    root_reversed = False
    warnings = []
    if blade is not None:
        roots = blade_root_edges(blade)
        pcurves, root_dist = root_pcurves(spine, roots, ROOT_PCURVE_FRACTION * D)
        if root_dist > ROOT_ON_HUB_REFUSAL_FRACTION * D:
            raise GeometryError(f"the blade root edge lies {root_dist:.3g} m ({root_dist / D:.3g} D) from the hub: "
                                f"these blade surfaces do not end on this propeller's hub")
        if root_dist > tol:
            warnings.append(f"the blade root edge lies up to {root_dist:.3g} m from the hub, more than the "
                            f"footprint tolerance {tol:.3g} m")
        # the inner loop runs clockwise in (s, θ), like the footprint spline
        P = np.concatenate([c.evaluate(np.linspace(*c.domain, 257)) for c in pcurves])
        x, y = P[:, 0], P[:, 1]
        if 0.5 * float(np.sum(x[:-1] * y[1:] - x[1:] * y[:-1])) > 0.0:
            pcurves = tuple(reverse(c) for c in pcurves[::-1])
            roots = tuple(reverse(c) for c in roots[::-1])
            root_reversed = True
        fp_lo, fp_hi = _theta_extent(pcurves)

    requested = clamp_range is not None
    rng = tuple(map(float, PAPER_ANGLE_RANGE if clamp_range is None else clamp_range))
    for attempt in range(2):
        if not (rng[0] < rng[1] <= rng[0] + 2.0 * np.pi + ANGLE_RANGE_TOL):
            raise GeometryError(f"clamp_range must satisfy start < end <= start + 2π, got {rng}")
        m, th_lo, th_hi, p_h, p_h1, p_h2, p_h3, p_h4 = _sector_curves(xi_lo, xi_hi, le, te, Z, rng)
        lo, hi = _theta_extent([p_h1, p_h3])
        lo, hi = min(lo, fp_lo), max(hi, fp_hi)
        if lo >= rng[0] - ANGLE_RANGE_TOL and hi <= rng[1] + ANGLE_RANGE_TOL:
            break
        if requested or attempt:
            raise GeometryError(
                f"the hub sector spans θ in [{lo:.6g}, {hi:.6g}], outside [{rng[0]:.6g}, {rng[1]:.6g}], "
                f"the angular range of the hub surface (Hally 2013 §10, Eqs. 51–52)")
        c = 0.5 * (le[1] + te[1])
        rng = (c - np.pi, c + np.pi)
    angle_range = (max(rng[0], lo - ANGLE_MARGIN), min(rng[1], hi + ANGLE_MARGIN))

    outer = (reverse(p_h3), p_h4, reverse(p_h1), p_h2)
    area = trimmed_area(spine, (outer, pcurves if pcurves is not None else (footprint,)))
    if not area > 0:
        raise GeometryError(f"the trimmed hub sector has non-positive area {area:.6g} m²: the footprint "
                            f"does not lie inside the sector")
    return HubSector(
        hub=hub, spine=spine, blades=Z, clamp_range=rng, angle_range=angle_range, xi_lo=xi_lo, xi_hi=xi_hi,
        leading_edge=le, trailing_edge=te, slope=float(m), theta_lo=float(th_lo), theta_hi=float(th_hi),
        boundary=p_h, p_h1=p_h1, p_h2=p_h2, p_h3=p_h3, p_h4=p_h4, outer_loop=outer, footprint=footprint,
        footprint_reversed=reversed_, footprint_deviation=deviation, tolerance=tol, area=area, intersection=I,
        root_pcurves=pcurves, root_edges=roots, root_hub_distance=root_dist, root_reversed=root_reversed,
        warnings=tuple(warnings),
    )
