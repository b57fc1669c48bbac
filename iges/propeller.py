"""The propeller as IGES records (Hally 2013 §11): the reference blade's surfaces and its
trimmed hub sector.

Entities (IGES 5.3 §4):

* each blade surface as a Rational B-Spline Surface (128). Hally writes C2 surfaces as 128
  and the others as Parametric Spline Surfaces (114); a 128 represents every B-spline
  surface exactly whatever its continuity, and the surfaces of the smoothing pipeline are
  C2 cubics anyway (:func:`surface_continuity` reports it), so 128 is always written.
* the hub as a Surface of Revolution (120): the spine as an exact rational quadratic
  B-spline (126) with simple knots (:func:`~bladesmith.geometry.propeller.hub_sector.c1_spine`,
  C1 as a B-spline, so readers see a C1 surface; Hally writes 126 when the spine is C2,
  else 112 — a 126 is exact for any spline), laid in the plane x = 0 as (0, ρ, z) and
  turned about the axis Line (110) from (0, 0, 0) to (0, 0, -1) (θ is a right-hand
  rotation about -z, see
  :mod:`bladesmith.geometry.propeller.hub`), over the sector's angular range (inside
  [-π, π], narrower than 2π so the 120 stays an open surface). Its parameter space
  (u = spine parameter s, v = angle) is the hub parameter space (ξ, θ) of Hally §10.
* the sector as a Trimmed Surface (144) over the 120 with
  - an outer Curve on a Parametric Surface (142) whose parameter-space curve is a
    Composite Curve (102) of the two sector edges (126, cubic, exact) and the two end
    lines (110), counter-clockwise in (u, v);
  - one inner 142 along the blade footprint (a closed cubic 126), clockwise.
  The 142s carry the parameter-space curve only (PREF = 1, S∘B preferred): the end lines
  lie on the poles of the hub, whose model-space images are points that no 110 or 126 can
  hold, and OpenCASCADE builds the edges from S∘B (3-D curves by BRepLib) without a
  message. ``model_curves=True`` adds 3-D approximations (a composite of the two sector
  edges, which meet at the poles, and the footprint) with PREF = 3.
"""
from __future__ import annotations

import os

import numpy as np

from ..geometry.errors import GeometryError, IgesError
from ..geometry.nurbs import BSplineCurve, BSplineSurface, reverse, split
from .convert import curve_from_geometry, surface_from_geometry
from .records import METRES_PER_UNIT, UNITS, CompositeCurve, CurveOnSurface, Line, SurfaceOfRevolution, TrimmedSurface
from .writer import DEFAULT_RESOLUTION, write_iges

#: The five blade surfaces of Hally (2013) §4 / Fig. 2, in the order written, with labels.
BLADE_SURFACES = (
    ("pressure_central", "PRESSURE"),
    ("suction_central", "SUCTION"),
    ("leading_edge", "LEADEDGE"),
    ("trailing_edge", "TRAILEDG"),
    ("tip", "TIP"),
)
HUB_LABEL = "HUB"
#: The blade surfaces that wrap round an edge of the blade, by label, with the parameter
#: direction that runs along Hally's cuts round that edge: the leading- and trailing-edge
#: surfaces (u) and the tip surface (v) (:mod:`~bladesmith.geometry.propeller.blade_surfaces`).
#: Every cut passes through its edge point at the middle of its parameter range (Hally 2013
#: §8, Eqs. 38-40; :mod:`~bladesmith.geometry.propeller.edge_curves`), where the surface
#: turns through about 180 degrees within the edge radius (1e-4 to 1e-6 D).
WRAPPED_SURFACES = {"LEADEDGE": "u", "TRAILEDG": "u", "TIP": "v"}
#: Metres per file unit for the unit names ``write_iges`` accepts.
#: A blade surface's boundary is "on the hub" when it comes this close to it, as a fraction
#: of the diameter (only used to refuse blade surfaces that do not belong to this hub).
ROOT_CHECK_FRACTION = 1e-2
#: Samples per direction of each blade surface for that check.
RANGE_CHECK_SAMPLES = 41


def surface_continuity(surface: BSplineSurface) -> int:
    """The parametric continuity C^k of a B-spline surface at its interior knots
    (k = degree - the largest interior multiplicity, the lesser of the two directions)."""
    ks = []
    for p, U in ((surface.degree_u, surface.knots_u), (surface.degree_v, surface.knots_v)):
        inner = U[p + 1 : U.size - p - 1]
        mult = max((int(np.sum(inner == k)) for k in np.unique(inner)), default=0)
        ks.append(p - mult if mult else p + 100)
    return min(ks)


def _blade_surfaces(blade) -> list[tuple[str, BSplineSurface]]:
    """(label, surface) for a SmoothedBlade-like object, a mapping, or a sequence."""
    if isinstance(blade, BSplineSurface):
        blade = [blade]
    if isinstance(blade, dict):
        items = [(label, blade[name]) for name, label in BLADE_SURFACES if name in blade]
        extra = set(blade) - {n for n, _ in BLADE_SURFACES}
        if extra:
            raise GeometryError(f"unknown blade surface names {sorted(extra)}; expected "
                                f"{[n for n, _ in BLADE_SURFACES]}")
    elif all(hasattr(blade, name) for name, _ in BLADE_SURFACES):
        items = [(label, getattr(blade, name)) for name, label in BLADE_SURFACES]
    else:
        try:
            seq = list(blade)
        except TypeError:
            raise GeometryError(f"blade surfaces: expected a SmoothedBlade, a dict or a sequence of "
                                f"BSplineSurface, got {type(blade).__name__}") from None
        items = [(f"BLADE{i + 1}", s) for i, s in enumerate(seq)]
    if not items:
        raise GeometryError("no blade surfaces given")
    for label, s in items:
        if not isinstance(s, BSplineSurface):
            raise GeometryError(f"blade surface {label}: expected a BSplineSurface, got {type(s).__name__}")
        if s.dim != 3:
            raise GeometryError(f"blade surface {label}: expected 3-D control points, got dimension {s.dim}")
        if not np.all(np.isfinite(s.control_points)):
            raise GeometryError(f"blade surface {label}: control points are not finite")
    return items


def _check_consistency(model, blade_items, sector) -> None:
    """Refuse data that cannot belong together (before any record is made)."""
    if sector.hub is not model.hub:
        raise GeometryError("the hub sector was built for a different propeller model")
    if sector.blades != model.blades:
        raise GeometryError(f"the hub sector is for {sector.blades} blades, the model has {model.blades}")
    a0, a1 = sector.angle_range
    for loop in sector.loops:
        for c in loop:
            P = c.control_points
            if P.shape[1] != 2:
                raise GeometryError("hub sector loops must be 2-D curves in (ξ_h, θ)")
            if (P[:, 0].min() < sector.xi_lo - 1e-12 or P[:, 0].max() > sector.xi_hi + 1e-12
                    or P[:, 1].min() < a0 - 1e-12 or P[:, 1].max() > a1 + 1e-12):
                raise GeometryError("a hub sector loop leaves the hub's parameter range")
    D = 2.0 * float(model.blade.radius)
    R_hub = float(model.hub.radius)
    reach = ROOT_CHECK_FRACTION * D
    for label, s in blade_items:
        # the surface itself, not its control net: a finite tip chord is closed by a tip
        # surface whose control points reach beyond R while the surface stays inside
        # (Propeller definition: MAX_TIP_CHORD_RATIO)
        (u0, u1), (v0, v1) = s.domain_u, s.domain_v
        X = s.evaluate_grid(np.linspace(u0, u1, RANGE_CHECK_SAMPLES), np.linspace(v0, v1, RANGE_CHECK_SAMPLES))
        r = np.hypot(X[..., 0], X[..., 1])
        if r.max() < R_hub - reach or r.max() > 0.5 * D * (1.0 + ROOT_CHECK_FRACTION):
            raise GeometryError(f"blade surface {label} does not lie between the hub (r = {R_hub:.6g} m) "
                                f"and the tip (r = {0.5 * D:.6g} m) of this propeller")


def _hub_surface(sector, angle_range, scale: float) -> SurfaceOfRevolution:
    axis = Line(start=[0.0, 0.0, 0.0], end=[0.0, 0.0, -1.0])
    spine = curve_from_geometry(sector.generatrix, scale=scale, label="SPINE")
    a0, a1 = map(float, angle_range)
    return SurfaceOfRevolution(axis=axis, generatrix=spine, start_angle=a0, end_angle=a1)


def _root_loop(surface, pcurves, edges, scale: float) -> CurveOnSurface:
    """A 142 along a blade root: B = the composite of the root's images in (s, θ), C = the
    composite of the root edges themselves (the blade surfaces' v = 0 rows, as 126 with the
    same control points), PREF = 2: C is the curve both faces share."""
    param = CompositeCurve(curves=[curve_from_geometry(c) for c in pcurves])
    model = CompositeCurve(curves=[curve_from_geometry(c, scale=scale) for c in edges])
    return CurveOnSurface(surface=surface, parameter_curve=param, model_curve=model, creation=2, preferred=2)


def hub_records(sector, *, scale: float = 1.0, model_curves: bool = False) -> TrimmedSurface:
    """The hub sector as a 144 over a 120 (see the module docstring); 3-D coordinates times
    ``scale`` (file units per metre); parameter-space curves are in (ξ_h, θ) as they are.
    A sector built from the blade (``hub_sector(..., blade=...)``) is trimmed by the blade
    root edge itself (:func:`_root_loop`)."""
    surface = _hub_surface(sector, sector.angle_range, scale)

    pieces = []
    for c in sector.outer_loop:
        if c.degree == 1 and c.n_control == 2:
            pieces.append(Line(start=c.control_points[0], end=c.control_points[1]))
        else:
            pieces.append(curve_from_geometry(c))
    outer_param = CompositeCurve(curves=pieces)
    inner_param = curve_from_geometry(sector.footprint)
    outer_model = inner_model = None
    pref = 1
    if model_curves:
        outer3, inner3 = sector.model_loops()
        outer_model = CompositeCurve(curves=[curve_from_geometry(c, scale=scale) for c in outer3])
        inner_model = curve_from_geometry(inner3[0], scale=scale)
        pref = 3
    outer = CurveOnSurface(surface=surface, parameter_curve=outer_param, model_curve=outer_model,
                           creation=0, preferred=pref)
    if sector.root_edges is not None:
        inner = _root_loop(surface, sector.inner_loop, sector.root_edges, scale)
    else:
        inner = CurveOnSurface(surface=surface, parameter_curve=inner_param, model_curve=inner_model,
                               creation=2, preferred=pref)
    return TrimmedSurface(surface=surface, outer=outer, inner=(inner,), label=HUB_LABEL)


def turned_blade(items, rotation) -> list:
    """(label, surface) of a blade turned by the 3x3 ``rotation``: every control net times
    the matrix once (B-splines are affinely invariant), so a turned surface's edge rows are
    the turned rows of the reference surface, the same numbers wherever they are used."""
    R = np.asarray(rotation, dtype=np.float64)
    out = []
    for label, s in items:
        out.append((label, BSplineSurface(s.degree_u, s.degree_v, s.knots_u, s.knots_v,
                                          s.control_points @ R.T, s.weights)))
    return out


def split_at_edges(items, hand: int = 1) -> list:
    """(label, surface) with every wrapped surface (:data:`WRAPPED_SURFACES`) replaced by its
    two halves, in the order they follow each other along the cuts, both under the wrapped
    surface's label and each over its own half of the surface's domain (so a half takes the
    whole's parameters). The halves are those of
    :func:`~bladesmith.geometry.propeller.blade_surfaces.split_at_edges`: cut at the edge
    points (t = 1/2, Hally 2013 §8 Eqs. 38-40) by knot insertion, every row they share with
    each other or a neighbour copied from one array, never recomputed. ``hand``: +1
    right-handed, -1 left-handed (only names the halves there; the order here is found
    from the rows themselves).

    Why: each wrapped surface turns through ~180 degrees round an edge whose radius
    (1e-4 D at a trailing edge, 1e-6 D on the smoothed tip) is far below any coarse mesh
    size. A mesher that meshes the surface whole makes triangles that straddle the edge,
    fold over (gmsh: "elements remain invalid", Delaunay falling back to MeshAdapt) and
    give slivers or "PLC Error: A segment and a facet intersect" in 3-D. With an edge along
    the blade's edge the mesher puts its nodes on it, and no triangle crosses it."""
    from ..geometry.propeller.blade_surfaces import split_at_edges as split_blade

    names = {label: name for name, label in BLADE_SURFACES}
    if sorted(label for label, _ in items) != sorted(names):
        raise GeometryError("split_edges needs the five blade surfaces of the smoothing pipeline "
                            f"({[n for n, _ in BLADE_SURFACES]}), got {[label for label, _ in items]}")
    halves = split_blade({names[label]: s for label, s in items}, hand)
    out = []
    for label, whole in items:
        name, direction = names[label], WRAPPED_SURFACES.get(label)
        if direction is None:
            out.append((label, halves[name]))
            continue
        if (whole.domain_u if direction == "u" else whole.domain_v) != (0.0, 1.0):
            raise GeometryError(f"blade surface {label}: split_edges needs the domain [0, 1] along the cuts")
        start = (lambda S: S.control_points[0]) if direction == "u" else (lambda S: S.control_points[:, 0])
        pair = [halves[f"{name}_pressure"], halves[f"{name}_suction"]]
        if not np.array_equal(start(pair[0]), start(whole)):
            pair.reverse()
        if not np.array_equal(start(pair[0]), start(whole)):
            raise GeometryError(f"blade surface {label}: neither half starts where the surface does")
        out += [(label, _on_half(pair[0], direction, 0.0)), (label, _on_half(pair[1], direction, 0.5))]
    return out


def _on_half(surface: BSplineSurface, direction: str, offset: float) -> BSplineSurface:
    """A half of :func:`~bladesmith.geometry.propeller.blade_surfaces.split_at_edges`
    (knots over [0, 1] along ``direction``) put back over [offset, offset + 1/2], the
    part of the whole surface's domain it is: U/2 + offset, exact in floating point (the
    inverse of that function's 2U and 2(U - 1/2)); the net is the same array."""
    U, V = surface.knots_u, surface.knots_v
    if direction == "u":
        U = 0.5 * U + offset
    else:
        V = 0.5 * V + offset
    return BSplineSurface(surface.degree_u, surface.degree_v, U, V, surface.control_points, surface.weights)


def _root_row(surface: BSplineSurface) -> BSplineCurve:
    """The v = 0 boundary of a blade surface: its first control row (a copy)."""
    return BSplineCurve(surface.degree_u, surface.knots_u, np.array(surface.control_points[:, 0]),
                        None if surface.weights is None else np.array(surface.weights[:, 0]))


def _split_hole(pcurves, edges, whole, halves) -> tuple:
    """The hole (pcurves, edges) with every root edge that is the v = 0 row of a split
    surface (``whole[i]``, halves ``halves[i]``, both turned alike) replaced by the halves'
    own v = 0 rows, and its parameter-space image cut at the same parameter (the image has
    the root edge's parameter, :func:`~bladesmith.geometry.propeller.hub_sector.root_pcurves`)."""
    out_p, out_e = [], []
    for pc, edge in zip(pcurves, edges):
        P = edge.control_points
        for s, (first, second) in zip(whole, halves):
            row = s.control_points[:, 0]
            if np.array_equal(P, row):
                cut = first.domain_u[1]
                out_p += list(split(pc, cut))
                out_e += [_root_row(first), _root_row(second)]
                break
            if np.array_equal(P[::-1], row):
                a, b = edge.domain
                out_p += list(split(pc, a + b - first.domain_u[1]))
                out_e += [reverse(_root_row(second)), reverse(_root_row(first))]
                break
        else:
            out_p.append(pc)
            out_e.append(edge)
    return tuple(out_p), tuple(out_e)


def full_propeller_geometry(model, blade, sector, *, split_edges: bool = True):
    """The whole propeller as plain geometry: (blades, holes, angle_range).

    blades: Z lists of (label, surface), blade k the reference blade turned by 2πk/Z
    (:meth:`PropellerModel.blade_rotation`). holes: Z pairs (pcurves, root edges) trimming
    the whole hub, blade k's footprint the reference loop moved by 2πk/Z in θ and its 3-D
    curves the root rows of turned blade k. angle_range: a full turn with the seam between
    two blades (:func:`~bladesmith.geometry.propeller.hub_sector.full_hub_angle_range`).
    split_edges: the leading-edge, trailing-edge and tip surfaces each as two halves cut
    along the blade's edge (:func:`split_at_edges`), so 8 faces a blade instead of 5; the
    root edges of the split surfaces are split alike.
    The sector must have been built from ``blade`` (its inner loop is the root edge)."""
    from ..geometry.propeller.hub_sector import full_hub_angle_range, oriented_root_edges, turned_pcurves

    if sector.root_edges is None:
        raise GeometryError("a full propeller needs the hub sector built from the blade surfaces "
                            "(hub_sector(model, blade=...)), so the hub is trimmed by the blade root edge itself")
    items = _blade_surfaces(blade)
    _check_consistency(model, items, sector)
    pieces = split_at_edges(items, int(np.sign(model.blade.hand))) if split_edges else items
    wrapped = [label for label, _ in items if label in WRAPPED_SURFACES]
    names = dict((label, name) for name, label in BLADE_SURFACES)
    blades, holes = [], []
    for k in range(model.blades):
        turned = items if k == 0 else turned_blade(items, model.blade_rotation(k))
        by_name = {names[label]: surface for label, surface in turned if label in names}
        pcs, edges = turned_pcurves(sector, k), oriented_root_edges(sector, by_name)
        if split_edges:
            turned_pieces = pieces if k == 0 else turned_blade(pieces, model.blade_rotation(k))
            whole = [s for (label, s) in turned if label in WRAPPED_SURFACES]
            turned_halves = [[s for lab, s in turned_pieces if lab == label] for label in wrapped]
            pcs, edges = _split_hole(pcs, edges, whole, turned_halves)
            turned = turned_pieces
        blades.append(turned)
        holes.append((pcs, edges))
    return blades, holes, full_hub_angle_range(sector)


def _face_labels(turned, k: int) -> list:
    """IGES labels (8 characters at most) of blade k's faces: Hally's names for the
    reference blade, the first six letters and the blade number for the others; the halves
    of a split surface end in 1 and 2 before the blade number."""
    counts = {}
    for label, _ in turned:
        counts[label] = counts.get(label, 0) + 1
    out, seen = [], {}
    for label, _ in turned:
        stem = label[:6] if k else label
        if counts[label] > 1:
            seen[label] = seen.get(label, 0) + 1
            stem = f"{label[:5]}{seen[label]}" if k else f"{label[:7]}{seen[label]}"
        out.append(f"{stem}{k + 1:02d}"[-8:] if k else stem)
    return out


def faces_per_blade(split_edges: bool = True) -> int:
    """Faces of one blade in the full-propeller export: Hally's five surfaces, or eight when
    the wrapped surfaces are split along the blade's edges (:func:`split_at_edges`)."""
    return len(BLADE_SURFACES) + (len(WRAPPED_SURFACES) if split_edges else 0)


def _iso_uses(surface: BSplineSurface) -> list:
    """The boundary of an untrimmed surface as one loop of edge uses (3-D curve, 2-D curve,
    isoparametric) counter-clockwise in (u, v): v = v0 forwards, u = u1 forwards, v = v1
    backwards, u = u0 backwards. The 3-D curves are the control rows of the net (the
    surface's own boundary curves, exactly); each 2-D curve is the straight line in (u, v)
    with the 3-D curve's parameter (so both run together)."""
    from ..geometry.nurbs import BSplineCurve, reverse

    (u0, u1), (v0, v1) = surface.domain_u, surface.domain_v
    P, W = surface.control_points, surface.weights
    Ku, Kv, p, q = surface.knots_u, surface.knots_v, surface.degree_u, surface.degree_v

    def row(deg, knots, pts, w):
        return BSplineCurve(deg, knots, np.array(pts), None if w is None else np.array(w))

    def line(a, b, t0, t1):
        return BSplineCurve(1, np.array([t0, t0, t1, t1]), np.array([a, b], dtype=np.float64))

    bottom = (row(p, Ku, P[:, 0], None if W is None else W[:, 0]), line((u0, v0), (u1, v0), u0, u1))
    right = (row(q, Kv, P[-1, :], None if W is None else W[-1, :]), line((u1, v0), (u1, v1), v0, v1))
    top = (row(p, Ku, P[:, -1], None if W is None else W[:, -1]), line((u0, v1), (u1, v1), u0, u1))
    left = (row(q, Kv, P[0, :], None if W is None else W[0, :]), line((u0, v0), (u0, v1), v0, v1))
    return [(bottom[0], bottom[1], True), (right[0], right[1], True),
            (reverse(top[0]), reverse(top[1]), True), (reverse(left[0]), reverse(left[1]), True)]


def _hub_outer_uses(sector, angle_range) -> list:
    """The outer boundary of the full-turn hub in (s, θ), counter-clockwise: the seam (the
    spine turned to the start angle, exact: same knots and weights, s its parameter) from
    the upstream to the downstream pole, the downstream pole (a degenerate edge), the seam
    again backwards at the end angle (the same edge), the upstream pole."""
    from ..geometry.nurbs import BSplineCurve, reverse

    a0, a1 = map(float, angle_range)
    S = sector.spine
    rho, z = S.control_points[:, 0], S.control_points[:, 1]
    seam = BSplineCurve(S.degree, S.knots, np.column_stack([rho * np.sin(a0), rho * np.cos(a0), z]), S.weights)
    s0, s1 = map(float, S.domain)

    def line(a, b, t0=0.0, t1=1.0):
        return BSplineCurve(1, np.array([t0, t0, t1, t1]), np.array([a, b], dtype=np.float64))

    up, down = seam.control_points[0], seam.control_points[-1]
    return [(seam, line((s0, a0), (s1, a0), s0, s1), True),
            (down.copy(), line((s1, a0), (s1, a1)), True),
            (reverse(seam), reverse(line((s0, a1), (s1, a1), s0, s1)), True),
            (up.copy(), line((s0, a1), (s0, a0)), True)]


def full_propeller_brep_entities(model, blade, hub_sector, units: str = "m", *, split_edges: bool = True) -> list:
    """The whole propeller as ONE IGES 186 manifold solid B-rep (with 502/504/508/510/514,
    :mod:`.brep`): the faces of :func:`full_propeller_iges_entities` (8Z, or 5Z without
    ``split_edges``, untrimmed 128s
    bounded by their own boundary curves, the full-turn 120 with the Z blade root edges as
    its loops and its own boundary as the outer one), every edge written once and used by
    two faces, all face normals pointing out of the propeller (blade S_u × S_v, hub
    h_ξ × h_θ)."""
    from .brep import FaceSpec, solid_from_faces

    key = units.lower() if isinstance(units, str) else units
    if key not in UNITS or key not in METRES_PER_UNIT:
        raise IgesError(f"unknown units {units!r}; expected one of {sorted(UNITS)}")
    scale = 1.0 / METRES_PER_UNIT[key]
    blades, holes, angle_range = full_propeller_geometry(model, blade, hub_sector, split_edges=split_edges)
    faces = []
    for k, turned in enumerate(blades):
        for name, (label, s) in zip(_face_labels(turned, k), turned):
            record = surface_from_geometry(s, scale=scale, label=name)
            faces.append(FaceSpec(surface=record, loops=[_iso_uses(s)], outer=True))
    hub = _hub_surface(hub_sector, angle_range, scale)
    loops = [_hub_outer_uses(hub_sector, angle_range)]
    loops += [[(edge, pc, False) for pc, edge in zip(pcs, edges)] for pcs, edges in holes]
    faces.append(FaceSpec(surface=hub, loops=loops, outer=True))
    return [solid_from_faces(faces, scale=scale, label="PROPELLR")]


def full_propeller_iges_entities(model, blade, hub_sector, units: str = "m", *, split_edges: bool = True) -> list:
    """IGES records of the whole propeller: Z blades of eight 128 each (Hally's five, the
    leading-edge, trailing-edge and tip surfaces each split along the blade's edge,
    :func:`split_at_edges`; five with ``split_edges=False``), and the whole hub as
    one 144 over a 120 turned a full turn, whose outer boundary is the boundary of its
    parameter domain (N1 = 0; the poles and the seam are the surface's own) and whose Z
    inner loops are the blade root edges (:func:`_root_loop`). Every blade face and the hub
    face share their junction curve, so the faces sew into one closed shell at any
    tolerance; no sector edges are written. See :func:`full_propeller_geometry`."""
    key = units.lower() if isinstance(units, str) else units
    if key not in UNITS or key not in METRES_PER_UNIT:
        raise IgesError(f"unknown units {units!r}; expected one of {sorted(UNITS)}")
    scale = 1.0 / METRES_PER_UNIT[key]
    blades, holes, angle_range = full_propeller_geometry(model, blade, hub_sector, split_edges=split_edges)
    records = []
    for k, turned in enumerate(blades):
        records += [surface_from_geometry(s, scale=scale, label=name)
                    for name, (label, s) in zip(_face_labels(turned, k), turned)]
    surface = _hub_surface(hub_sector, angle_range, scale)
    inner = [_root_loop(surface, pc, edges, scale) for pc, edges in holes]
    records.append(TrimmedSurface(surface=surface, outer=None, inner=inner, label=HUB_LABEL))
    return records


def write_full_propeller_iges(path, model, blade, hub_sector, units: str = "m", *, resolution: float | None = None,
                              brep: bool = False, split_edges: bool = True, **options) -> str:
    """Write the whole propeller (:func:`full_propeller_iges_entities`, or with ``brep=True``
    the 186 solid of :func:`full_propeller_brep_entities`) to ``path`` atomically. Returns
    the path. split_edges: see :func:`split_at_edges`."""
    if brep:
        records = full_propeller_brep_entities(model, blade, hub_sector, units, split_edges=split_edges)
    else:
        records = full_propeller_iges_entities(model, blade, hub_sector, units, split_edges=split_edges)
    if resolution is None:
        resolution = DEFAULT_RESOLUTION / METRES_PER_UNIT[units.lower()]
    return write_iges(os.fspath(path), records, units=units, resolution=resolution, **options)


#: IGES labels of the eight surfaces when the wrap-around surfaces are split at the edges
#: (:func:`bladesmith.geometry.propeller.blade_surfaces.split_at_edges`).
SPLIT_LABELS = {
    "pressure_central": "PRESSURE", "suction_central": "SUCTION",
    "leading_edge_pressure": "LEADEDGP", "leading_edge_suction": "LEADEDGS",
    "trailing_edge_pressure": "TRAILEDP", "trailing_edge_suction": "TRAILEDS",
    "tip_pressure": "TIPP", "tip_suction": "TIPS",
}


def _split_items(model, items) -> list:
    """The five (label, surface) items as eight, split along the blade edges."""
    from ..geometry.propeller.blade_surfaces import SPLIT_SURFACE_NAMES, split_at_edges

    by_label = dict(items)
    names = {label: name for name, label in BLADE_SURFACES}
    if set(by_label) != set(names):
        raise GeometryError("split_edges needs the five blade surfaces of the smoothing pipeline "
                            f"({[n for n, _ in BLADE_SURFACES]})")
    halves = split_at_edges({names[k]: v for k, v in by_label.items()}, int(np.sign(model.blade.hand)))
    return [(SPLIT_LABELS[n], halves[n]) for n in SPLIT_SURFACE_NAMES]


def propeller_iges_entities(model, blade, hub_sector, units: str = "m", *, model_curves: bool = False,
                            split_edges: bool = False) -> list:
    """IGES records of the reference blade and its trimmed hub sector (Hally 2013 §11).

    model: the :class:`~bladesmith.geometry.propeller.PropellerModel`. blade: a
    ``SmoothedBlade`` (attributes pressure_central, suction_central, leading_edge,
    trailing_edge, tip), a dict with those keys, or a sequence of BSplineSurface.
    hub_sector: the :class:`~bladesmith.geometry.propeller.hub_sector.HubSector` of
    ``model``. units: the file's length unit; geometry (metres) is scaled to it.
    split_edges: write the leading-edge, trailing-edge and tip surfaces as two surfaces
    each, cut exactly along the blade edge, so the edge is a face boundary (meshers then
    put nodes on it instead of folding triangles across its tiny radius near the tip;
    see :func:`~bladesmith.geometry.propeller.blade_surfaces.split_at_edges`).
    Returns the root records: one 128 per blade surface, then the 144.
    Raises GeometryError/IgesError for inconsistent data.
    """
    key = units.lower() if isinstance(units, str) else units
    if key not in UNITS or key not in METRES_PER_UNIT:
        raise IgesError(f"unknown units {units!r}; expected one of {sorted(UNITS)}")
    scale = 1.0 / METRES_PER_UNIT[key]
    items = _blade_surfaces(blade)
    if split_edges:
        items = _split_items(model, items)
    _check_consistency(model, items, hub_sector)
    records = [surface_from_geometry(s, scale=scale, label=label) for label, s in items]
    records.append(hub_records(hub_sector, scale=scale, model_curves=model_curves))
    return records


def write_propeller_iges(path, model, blade, hub_sector, units: str = "m", *, resolution: float | None = None,
                         model_curves: bool = False, split_edges: bool = False, **options) -> str:
    """Write the propeller's reference blade and hub sector to ``path`` (atomically, via
    :func:`bladesmith.iges.write_iges`, which validates every record first). resolution:
    Global field 19 in file units (default DEFAULT_RESOLUTION metres converted). Returns
    the path."""
    records = propeller_iges_entities(model, blade, hub_sector, units, model_curves=model_curves,
                                      split_edges=split_edges)
    if resolution is None:
        resolution = DEFAULT_RESOLUTION / METRES_PER_UNIT[units.lower()]
    return write_iges(os.fspath(path), records, units=units, resolution=resolution, **options)
