"""Planar root and tip caps that close the wind blade's mold halves into one shell.

The mold halves (Hosseini & Moetakef-Imani 2016 §5) are open at the root and the tip by
design: a mold makes the skin. A CFD or FE user needs a closed blade. The end rows of the
mold surfaces (upper, lower and, for a blunt trailing edge, the trailing-edge base; the root
transitions at the root) are the first and last skinned sections, which lie in the
section planes of their stations (Eq. 5 places every section in one plane). Each cap is
that plane, trimmed by exactly those rows:

* the plane as a bilinear B-spline patch S(u, v) = o + u e1 + v e2 (affine, so a curve in
  the plane has its (u, v) image with the affinely mapped control points, exactly up to
  rounding), covering the loop's bounding rectangle with a margin;
* the trimming loop's 3-D curves are the surfaces' end rows themselves (copied), chained
  head to tail; their parameter-space curves the affine images of the same control points.

e1 × e2 points out of the blade (away from the tip at the root, away from the root at the
tip), so the cap's normal is outward like the mold surfaces'. A loop that is not planar
within ``tol`` (relative to its size) is refused (:func:`ruled_cap` or
:func:`rounded_cap` close any end).

The user's choice of ``kind`` in :func:`blade_caps`: "ruled", "planar" or "rounded". The
rounded form rounds the tip (:func:`rounded_cap`, a dome beyond the last station, tangent
to the mold halves) and keeps the root planar: the root of a blade is the flat face of its
root flange (bolted to the pitch bearing), the root circle lies in that plane (the
structural-zone stations are not wrapped, :func:`~.blade.blade_sections`), and a dome
there would lie inside the hub. A root that is not planar (a blade without a root
transition, whose first section is wrapped on its cylinder) gets the ruled cap.

The faces the caps close are :func:`closed_surfaces`: the mold surfaces, with a blunt
trailing-edge base that runs the whole span made part of the lower face
(:func:`lower_with_base`, a C1 face with the corner rounded), so that a coarse mesher
need not fill a 4-32 mm strip with needle triangles (issue 16, NREL 5-MW).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError
from ..nurbs import BSplineCurve, BSplineSurface, reverse

#: The end rows must lie in one plane to this fraction of the loop's size.
PLANARITY_TOL = 1e-9
#: End points of neighbouring rows closer than this (fraction of the loop's size) meet.
CHAIN_TOL = 1e-11
#: The plane patch reaches this fraction of the loop's size beyond the loop.
PLANE_MARGIN = 0.05


@dataclass(frozen=True, eq=False)
class Cap:
    """A planar cap: ``plane`` (bilinear patch, normal e1 × e2 outward), ``edges`` (3-D end
    rows chained head to tail, counter-clockwise in the plane's (u, v)) and ``pcurves``
    (their (u, v) images, same parameters), ``flatness`` (largest distance of the rows'
    control points from the plane, m)."""

    plane: BSplineSurface
    edges: tuple
    pcurves: tuple
    flatness: float


def _row(surface: BSplineSurface, v_end: bool) -> BSplineCurve:
    P = surface.control_points[:, -1 if v_end else 0]
    W = None if surface.weights is None else surface.weights[:, -1 if v_end else 0]
    return BSplineCurve(surface.degree_u, surface.knots_u, np.array(P), None if W is None else np.array(W))


def _chain(curves: list, what: str, tol: float) -> list:
    """Order and orient the curves head to tail (end points within ``tol`` m: the halves'
    shared edges are equal, a sharp trailing edge's two edges agree to SHARP_TE_TOL)."""
    out = [curves[0]]
    left = list(curves[1:])

    def near(a, b):
        return float(np.linalg.norm(a - b)) <= tol

    while left:
        end = out[-1].control_points[-1]
        for k, c in enumerate(left):
            if near(c.control_points[0], end):
                out.append(left.pop(k))
                break
            if near(c.control_points[-1], end):
                out.append(reverse(left.pop(k)))
                break
        else:
            raise GeometryError(f"the {what} edges of the mold surfaces do not chain into a closed loop")
    if not near(out[-1].control_points[-1], out[0].control_points[0]):
        raise GeometryError(f"the {what} edges of the mold surfaces do not close")
    return out


def planar_cap(surfaces: list, v_end: bool, inward, what: str, tol: float = PLANARITY_TOL) -> Cap:
    """The planar cap over the v = 0 (``v_end`` False) or v = 1 rows of ``surfaces``.
    inward: a vector pointing into the blade from this end (the cap's normal is its
    opposite). Raises GeometryError when the rows do not close or are not planar."""
    rows = [_row(s, v_end) for s in surfaces]
    size0 = float(np.ptp(np.concatenate([c.control_points for c in rows]), axis=0).max())
    edges = _chain(rows, what, CHAIN_TOL * size0)
    P = np.concatenate([c.control_points for c in edges])
    o = P.mean(axis=0)
    _, _, Vt = np.linalg.svd(P - o)
    n = Vt[2]
    if float(n @ np.asarray(inward, dtype=np.float64)) > 0:
        n = -n
    size = float(np.ptp(P, axis=0).max())
    flat = float(np.abs((P - o) @ n).max())
    if flat > tol * size:
        raise GeometryError(f"the {what} section of the blade is not planar ({flat:.3g} m off its plane, "
                            f"{flat / size:.3g} of its size): a planar cap cannot close it")
    e1 = Vt[0] - (Vt[0] @ n) * n
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)  # e1 × e2 = n, outward
    uv = np.stack([(P - o) @ e1, (P - o) @ e2], axis=-1)
    lo, hi = uv.min(axis=0) - PLANE_MARGIN * size, uv.max(axis=0) + PLANE_MARGIN * size
    corners = np.array([[o + lo[0] * e1 + lo[1] * e2, o + lo[0] * e1 + hi[1] * e2],
                        [o + hi[0] * e1 + lo[1] * e2, o + hi[0] * e1 + hi[1] * e2]])
    plane = BSplineSurface(1, 1, np.array([lo[0], lo[0], hi[0], hi[0]]), np.array([lo[1], lo[1], hi[1], hi[1]]),
                           corners)
    pcurves = [BSplineCurve(c.degree, c.knots, np.stack([(c.control_points - o) @ e1, (c.control_points - o) @ e2],
                                                        axis=-1), c.weights) for c in edges]
    Q = np.concatenate([c.evaluate(np.linspace(*c.domain, 101)) for c in pcurves])
    if 0.5 * float(np.sum(Q[:-1, 0] * Q[1:, 1] - Q[1:, 0] * Q[:-1, 1])) < 0:  # make it counter-clockwise
        edges = [reverse(c) for c in edges[::-1]]
        pcurves = [reverse(c) for c in pcurves[::-1]]
    return Cap(plane=plane, edges=tuple(edges), pcurves=tuple(pcurves), flatness=flat)


def ruled_cap(upper: BSplineSurface, lower: BSplineSurface, v_end: bool, inward) -> BSplineSurface:
    """A cap for any (also non-planar) end section: the ruled surface between the upper
    half's end row (TE -> S) and the lower half's end row reversed (TE -> S), after both are
    made compatible by knot insertion (exact; NURBS Book §10.3). Its w = 0 and w = 1 edges
    are those rows (the same curves), its u = 0 edge the trailing-edge base's end segment
    (a point for a sharp edge) and its u = 1 edge the point S (degenerate). Oriented with
    S_u × S_w pointing away from ``inward``."""
    from ..nurbs import make_compatible

    a, b = make_compatible([_row(upper, v_end), reverse(_row(lower, v_end))])
    net = np.stack([a.control_points, b.control_points], axis=1)
    # a sharp trailing edge: the halves' TE points agree to SHARP_TE_TOL, not bit for bit;
    # make the cap's short edge there an exact point (a degenerate edge, not a 1e-17 m one)
    size = float(np.ptp(net.reshape(-1, 3), axis=0).max())
    for i in (0, -1):
        if float(np.linalg.norm(net[i, 0] - net[i, 1])) <= CHAIN_TOL * size:
            net[i, 1] = net[i, 0]
    W = None if a.weights is None else np.stack([a.weights, b.weights], axis=1)
    cap = BSplineSurface(a.degree, 1, a.knots, np.array([0.0, 0.0, 1.0, 1.0]), net, W)
    D = cap.derivatives(0.5, 0.5, 1) if hasattr(cap, "derivatives") else None
    if D is not None:
        normal = np.cross(D[1, 0], D[0, 1])
    else:
        h = 1e-6
        normal = np.cross(cap.evaluate(0.5 + h, 0.5) - cap.evaluate(0.5 - h, 0.5),
                          cap.evaluate(0.5, 0.5 + h) - cap.evaluate(0.5, 0.5 - h))
    if float(normal @ np.asarray(inward, dtype=np.float64)) > 0:
        cap = BSplineSurface(a.degree, 1, a.knots, np.array([0.0, 0.0, 1.0, 1.0]), net[:, ::-1],
                             None if W is None else W[:, ::-1])
    return cap


#: Length of the rounded tip beyond the last station, as a fraction of the local distance
#: between the halves' end rows (the thickness): 0.5 gives about a half-round end.
TIP_BULGE = 0.5


def _v_derivative_row(surface: BSplineSurface) -> BSplineCurve:
    """d/dv of the surface at v = 1 as a curve in u: control points
    q / (v_last - v_{last-q}) (P_{i,last} - P_{i,last-1}) (NURBS Book Eq. 3.7 in v)."""
    V, q = surface.knots_v, surface.degree_v
    P = surface.control_points
    D = q / (V[-1] - V[-q - 2]) * (P[:, -1] - P[:, -2])
    return BSplineCurve(surface.degree_u, surface.knots_u, np.array(D))


def rounded_cap(upper: BSplineSurface, lower: BSplineSurface, inward, bulge: float = TIP_BULGE) -> BSplineSurface:
    """A rounded tip: a cubic-in-w surface from the upper half's last row a(u) (TE -> S)
    to the lower half's last row reversed b(u) (TE -> S), bulging beyond the tip along
    the halves' own span tangents. Rows (w control points) a_i, a_i + ℓ_i t^a_i,
    b_i + ℓ_i t^b_i, b_i with t_i the unit v-derivative control vectors of each half at
    v = 1 and ℓ_i = ``bulge`` × |a_i - b_i| (0 at the TE end, u = 0, so that edge is the
    trailing-edge base's end segment or the sharp TE point; 0 at S where a = b). Where ℓ
    is one multiple of the derivative, the cap's w-derivative 3 ℓ t is parallel to the
    halves' S_v: tangent to them across the tip edge (G1; exactly so for constant ℓ/|D|,
    nearly so elsewhere). Its w = 0 and w = 1 edges are the halves' rows themselves
    (after exact knot insertion, NURBS Book §10.3), as for :func:`ruled_cap`. Oriented
    with S_u × S_w pointing away from ``inward``."""
    from ..nurbs import make_compatible

    if not (np.isfinite(bulge) and bulge > 0):
        raise GeometryError(f"the tip bulge must be a positive fraction of the thickness, got {bulge!r}")
    if upper.weights is not None or lower.weights is not None:
        raise GeometryError("a rounded cap needs non-rational mold halves")
    a, da, b, db = make_compatible([_row(upper, True), _v_derivative_row(upper),
                                    reverse(_row(lower, True)), reverse(_v_derivative_row(lower))])
    A, B = a.control_points, b.control_points
    size = float(np.ptp(np.vstack([A, B]), axis=0).max())
    ell = bulge * np.linalg.norm(A - B, axis=1)
    ell[0] = 0.0
    ell[np.linalg.norm(A - B, axis=1) <= CHAIN_TOL * size] = 0.0

    def unit(D):
        n = np.linalg.norm(D, axis=1, keepdims=True)
        return np.divide(D, n, out=np.zeros_like(D), where=n > 0)

    net = np.stack([A, A + ell[:, None] * unit(da.control_points), B + ell[:, None] * unit(db.control_points), B],
                   axis=1)
    for i in (0, -1):  # a sharp TE (and S): one point, not two 1e-17 m apart
        if float(np.linalg.norm(net[i, 0] - net[i, 3])) <= CHAIN_TOL * size:
            net[i, :] = net[i, 0]
    W = np.array([0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0])
    cap = BSplineSurface(a.degree, 3, a.knots, W, net)
    D = cap.derivatives(0.5, 0.5, 1)
    if float(np.cross(D[1, 0], D[0, 1]) @ np.asarray(inward, dtype=np.float64)) > 0:
        cap = BSplineSurface(a.degree, 3, a.knots, W, net[:, ::-1])
    return cap


def closed_surfaces(molds) -> dict:
    """The faces of the closed blade besides its caps: the mold surfaces
    (:attr:`~.blade.BladeMolds.surfaces`), with each trailing-edge base that runs the
    whole span of its zone (root to joint, joint to tip: a trailing edge blunt everywhere,
    e.g. by ``min_trailing_edge_thickness``) made part of its lower face
    (:func:`lower_with_base`, one corner blend for both zones, so the root joint row is
    the same and is copied). When a base ends inside its zone (the trailing edge turns
    sharp there: IEA 15 MW's root circle) every base stays a face of its own: a merged
    face's rounded corner would not meet the neighbouring zone's sharp one."""
    out = dict(molds.surfaces)
    pairs = []
    for lower, prefix in (("lower", "trailing_edge"), ("transition_lower", "transition_trailing_edge")):
        pieces = [k for k in out if k == prefix or k.startswith(prefix + "_")]
        if lower not in out or not pieces:
            continue
        base, lo = out[pieces[0]], out[lower]
        if len(pieces) != 1 or base.knots_v[0] != lo.knots_v[0] or base.knots_v[-1] != lo.knots_v[-1]:
            return out  # a base ends inside its zone: every base stays a face (the joint row must match)
        pairs.append((lower, pieces[0]))
    if not pairs:
        return out
    # one corner for both zones: the joint row (the transition's w = 1, the aero half's v = 0)
    # is then made by the same arithmetic from the same rows, and is copied besides
    corner = corner_parameters(out[pairs[0][0]], out[pairs[0][1]])
    for lower, prefix in pairs:
        out[lower] = lower_with_base(out[lower], out.pop(prefix), corner=corner)
    if len(pairs) == 2:
        aero, root = out["lower"], out["transition_lower"]
        net = root.control_points.copy()
        size = max(aero.size(), root.size())
        if np.abs(net[:, -1] - aero.control_points[:, 0]).max() > 1e-12 * size:
            raise GeometryError("the merged lower faces do not meet on the root joint")
        net[:, -1] = aero.control_points[:, 0]
        out["transition_lower"] = BSplineSurface(root.degree_u, root.degree_v, root.knots_u, root.knots_v, net)
    return out


def blade_caps(molds, kind: str = "ruled") -> tuple:
    """(root cap, tip cap) of :class:`~.blade.BladeMolds`: the root over the transitions'
    (or, without them, the halves') v = 0 rows, the tip over the halves' v = 1 rows (with
    the trailing-edge base's row when the trailing edge is blunt), of the faces of
    :func:`closed_surfaces`. kind: "ruled" (:func:`ruled_cap`, BSplineSurface, any
    section) or "planar" (:func:`planar_cap`, a :class:`Cap`, only for planar end
    sections)."""
    s = closed_surfaces(molds)

    def end(halves, prefix, v_end):
        """The halves and the trailing-edge bases (``prefix``, ``prefix_2``, ...) that reach
        this end: a base ends where the trailing edge turns sharp (NREL 5-MW at 44.55 m)."""
        up, lo = s[halves[0]], s[halves[1]]
        size = max(up.size(), lo.size())
        ends = (_row(up, v_end).control_points[0], _row(lo, v_end).control_points[-1])
        out = [up, lo]
        for name, surface in s.items():
            if name == prefix or name.startswith(prefix + "_"):
                P = _row(surface, v_end).control_points
                if all(min(np.linalg.norm(P[i] - e) for e in ends) <= CHAIN_TOL * size for i in (0, -1)):
                    out.append(surface)
        return out

    if "transition_upper" in s:
        root = end(("transition_upper", "transition_lower"), "transition_trailing_edge", False)
    else:
        root = end(("upper", "lower"), "trailing_edge", False)
    tip = end(("upper", "lower"), "trailing_edge", True)
    span = tip[0].evaluate(0.5, 1.0) - root[0].evaluate(0.5, 0.0)
    if kind == "planar":
        return planar_cap(root, False, span, "root"), planar_cap(tip, True, -span, "tip")
    if kind == "rounded":
        try:
            root_cap = planar_cap(root, False, span, "root")
        except GeometryError:
            root_cap = ruled_cap(root[0], root[1], False, span)
        return root_cap, rounded_cap(tip[0], tip[1], -span)
    if kind != "ruled":
        raise GeometryError(f"unknown cap kind {kind!r}; expected 'ruled', 'planar' or 'rounded'")
    return ruled_cap(root[0], root[1], False, span), ruled_cap(tip[0], tip[1], True, -span)


# ---------------------------------------------------------------------------------------
# the trailing-edge base as part of the lower face (closed blade only; the molds keep it apart)
# ---------------------------------------------------------------------------------------
#: The rounded corner where the lower face turns onto the trailing-edge base reaches this
#: fraction of the base's width along the base, and as far (from the mean width) along the
#: lower half (:func:`lower_with_base`; NREL 5-MW: the corner moves at most 1.03 mm).
CORNER_BLEND = 0.1


def corner_parameters(lower: BSplineSurface, base: BSplineSurface, blend: float = CORNER_BLEND) -> tuple:
    """(s, e1, e2) of :func:`lower_with_base`: s the lower half's share of the mean row
    length (control polygon), e2 = ``blend`` (1 - s), e1 such that the lower side of the
    corner blend is as long in 3-D as the base side (mean over the rows; |S_u(1-)| of the
    lower half is p |P_n-1 - P_n-2| / (1 - u_last), NURBS Book Eq. 3.7, / s after the
    join), at most half the lower half's last knot span."""
    p, P = lower.degree_u, lower.control_points
    width = np.linalg.norm(base.control_points[1] - base.control_points[0], axis=1)
    row = np.linalg.norm(np.diff(P, axis=0), axis=2).sum(axis=0)
    s = float(row.mean() / (row.mean() + width.mean()))
    u_last = float(lower.knots_u[P.shape[0] - 1])
    speed = p * np.linalg.norm(P[-1] - P[-2], axis=1).mean() / ((1.0 - u_last) * s)
    return s, float(min(blend * width.mean() / speed, 0.5 * (s - u_last * s))), blend * (1.0 - s)


def lower_with_base(lower: BSplineSurface, base: BSplineSurface, blend: float = CORNER_BLEND,
                    corner: tuple | None = None) -> BSplineSurface:
    """The lower half and a blunt trailing-edge base (ruled, lower(1, v) -> upper(0, v), the
    same v knots) as one C1 surface: the lower face turns round the trailing-edge corner
    onto the base and ends on the upper half's trailing edge.

    Why: a base 4-32 mm wide on a 61 m blade is a face a coarse mesher (0.3 m elements)
    can only fill with needle triangles, whose tetrahedra are slivers (NREL 5-MW, min SICN
    0.003 along the whole span). As part of the lower face it needs no mesh edge of its own.

    Construction, exact except at the corner (NURBS Book §5.2 knot insertion and §5.4
    removal): the base is degree-elevated to p in u (control points a + i (b - a) / p) and
    joined to the lower half at u = s (knot of multiplicity p, C0). Knots s - e1 and
    s + e2 are inserted p times ((s, e1, e2) of :func:`corner_parameters`, or ``corner``:
    faces that share a row use the same, so the row comes out the same). The two Bezier
    pieces that meet at the corner are replaced by one cubic segment on [s - e1, s + e2]
    whose inner control points continue the neighbouring legs with the derivative of each
    side (B1 = P_A + (P_A - P_A-) (e1 + e2) / (s - e1 - u_prev), likewise B2), so the
    curve is C1 there, and one copy of s - e1 and of s + e2 is removed (their control
    points P_A, P_B lie on those legs: removal is exact). Outside (s - e1, s + e2) the
    surface is the lower half (u < s - e1) and the base (u > s + e2) unchanged; its u = 1
    edge is the upper half's trailing-edge column and its u = 0 edge the LE parting line,
    copied."""
    from ..nurbs.operations import refine_knots_surface

    p, q = lower.degree_u, lower.degree_v
    if base.degree_v != q or not np.array_equal(base.knots_v, lower.knots_v):
        raise GeometryError("the trailing-edge base and the lower half do not share their span knots")
    if lower.weights is not None or base.weights is not None:
        raise GeometryError("the trailing-edge base can join only non-rational mold halves")
    if p != 3:
        raise GeometryError(f"the trailing-edge corner blend is cubic; the lower half is of degree {p} across")
    P = lower.control_points
    a, b = base.control_points[0], base.control_points[1]
    if not np.array_equal(a, P[-1]):
        raise GeometryError("the trailing-edge base does not start on the lower half's trailing edge")
    if np.linalg.norm(b - a, axis=1).min() <= 0:
        raise GeometryError("the trailing-edge base closes to a point; it cannot be part of the lower face")
    s, e1, e2 = corner_parameters(lower, base, blend) if corner is None else corner
    n = P.shape[0]
    U = np.concatenate([lower.knots_u[:n] * s, [s] * p, [1.0] * (p + 1)])
    ext = [a + (b - a) * (i / p) for i in range(1, p)] + [np.array(b)]
    joined = BSplineSurface(p, q, U, lower.knots_v, np.concatenate([P, np.stack(ext)], axis=0))
    ua, ub = s - e1, s + e2
    R = refine_knots_surface(joined, "u", [ua] * p + [ub] * p)
    K, N = R.knots_u, R.control_points.copy()
    # the control points at C(ua) and C(ub): a knot run of multiplicity p ending at index k
    # holds the curve point P_(k - p)
    ia = int(np.nonzero(np.isclose(K, ua, rtol=0, atol=1e-15))[0][-1]) - p
    ib = int(np.nonzero(np.isclose(K, ub, rtol=0, atol=1e-15))[0][-1]) - p
    u_prev = float(K[ia])  # the knot before the ua run
    u_next = 1.0
    PA, PB = N[ia], N[ib]
    B1 = PA + (PA - N[ia - 1]) * (ub - ua) / (ua - u_prev)
    B2 = PB - (N[ib + 1] - PB) * (ub - ua) / (u_next - ub)
    net = np.concatenate([N[:ia], B1[None], B2[None], N[ib + 1:]], axis=0)
    knots = np.concatenate([K[:ia + 1], [ua] * (p - 1), [ub] * (p - 1), K[ib + p + 1:]])
    net[-1] = b  # the upper half's trailing-edge column, copied
    net[0] = P[0]  # the leading-edge parting line, copied
    return BSplineSurface(p, q, knots, lower.knots_v, net)
