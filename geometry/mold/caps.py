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
within ``tol`` (relative to its size) is refused: such a blade needs a rounded cap, which
this module does not make.
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


def blade_caps(molds, kind: str = "ruled") -> tuple:
    """(root cap, tip cap) of :class:`~.blade.BladeMolds`: the root over the transitions'
    (or, without them, the halves') v = 0 rows, the tip over the halves' v = 1 rows (with
    the trailing-edge base's row when the trailing edge is blunt). kind: "ruled"
    (:func:`ruled_cap`, BSplineSurface, any section) or "planar" (:func:`planar_cap`, a
    :class:`Cap`, only for planar end sections)."""
    s = molds.surfaces
    root = [s[n] for n in ("transition_upper", "transition_lower", "transition_trailing_edge") if n in s]
    if not root:
        root = [s[n] for n in ("upper", "lower", "trailing_edge") if n in s]
    tip = [s[n] for n in ("upper", "lower", "trailing_edge") if n in s]
    span = tip[0].evaluate(0.5, 1.0) - root[0].evaluate(0.5, 0.0)
    if kind == "planar":
        return planar_cap(root, False, span, "root"), planar_cap(tip, True, -span, "tip")
    if kind != "ruled":
        raise GeometryError(f"unknown cap kind {kind!r}; expected 'ruled' or 'planar'")
    return ruled_cap(root[0], root[1], False, span), ruled_cap(tip[0], tip[1], True, -span)
