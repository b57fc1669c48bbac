"""Entities other CAD systems write that Bladesmith does not write, read for import only:

* 108 plane, 122 tabulated cylinder, 140 offset surface (IGES 5.3 entity types) as
  bases of 142/144;
* 141 boundary and 143 bounded surface (model-space curves with optional
  parameter-space curves over a surface);
* 308 subfigure definition and 408 singular subfigure instance;
* 402 groups (forms 1, 7, 14, 15) and 104 conic arcs;
* 186 manifold solid B-rep with its 502/504/508/510/514 topology: each face is imported
  as a trimmed face, also on the analytic surfaces 190-198 (:mod:`.analytic`), whose
  loops are mapped from the edges' model-space curves by the surfaces' closed-form
  inverses.

Also the lenient builders the reader uses with ``strict=False`` (:data:`LENIENT_BUILDERS`)
and their structure checks (:func:`check_lenient`), which accept these surfaces under
142 and 144 and repair what real files get slightly wrong (reversed or empty parameter
ranges, interior knots of multiplicity degree + 1 between coincident control points).

Exact NURBS where one exists: 122 over a B-spline, line or arc directrix is a ruled
(degree 1 in v) B-spline surface; a 108 becomes a bilinear patch over its trim loops'
bounding box when it is trimmed. A 140 has no NURBS form and is shown as a mesh only.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from ..geometry.errors import BladesmithError, IgesError
from ..geometry.nurbs import BSplineCurve, BSplineSurface
from .convert import _transform, curve_geometry, curve_points, curve_range, surface_geometry, surface_points, surface_range
from .records import (
    CURVE_TYPES,
    SURFACE_TYPES,
    BSplineCurve126,
    BSplineSurface128,
    CircularArc,
    CompositeCurve,
    CurveOnSurface,
    Entity,
    GenericEntity,
    Line,
    ParametricSpline,
    ParametricSplineSurface,
    SurfaceOfRevolution,
    TransformationMatrix,
    TrimmedSurface,
)
from .analytic import AnalyticSurface, analytic_points, analytic_uv, lenient_builders as _analytic_builders, unwrap_loop
from .validate import check_structure

#: Coincident control points across a knot of multiplicity degree + 1 (a C0 curve written
#: with one knot too many) within this fraction of the control net's size are merged.
MERGE_TOLERANCE = 1e-9
#: Margin of the bilinear patch that stands for a trimmed 108 plane, as a fraction of the
#: loops' bounding box (the loops must lie strictly inside the patch's domain).
PLANE_MARGIN = 0.01
#: Step of the finite differences giving a 140's base-surface normal, as a fraction of the
#: parameter range.
NORMAL_STEP = 1e-6


# -- records ----------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Plane108(Entity):
    """Plane, type 108: A x + B y + C z = D; ``boundary`` a closed curve or None."""

    type_number: ClassVar[int] = 108
    coefficients: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0, 0.0]))
    boundary: Entity | None = None
    plane_form: int = 0

    @property
    def form(self):
        return self.plane_form

    def references(self):
        return () if self.boundary is None else (self.boundary,)


@dataclass(frozen=True, eq=False)
class TabulatedCylinder122(Entity):
    """Tabulated cylinder, type 122: S(u, v) = C(t0 + u (t1 - t0)) + v (L - C(t0))."""

    type_number: ClassVar[int] = 122
    directrix: Entity = None
    end: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def references(self):
        return (self.directrix,)


@dataclass(frozen=True, eq=False)
class OffsetSurface140(Entity):
    """Offset surface, type 140: S(u, v) = B(u, v) + d N(u, v), N the unit normal of B."""

    type_number: ClassVar[int] = 140
    indicator: np.ndarray = field(default_factory=lambda: np.zeros(3))
    distance: float = 0.0
    surface: Entity = None

    def references(self):
        return (self.surface,)


@dataclass(frozen=True, eq=False)
class Boundary141(Entity):
    """Boundary, type 141: model-space curves (with sense) and their parameter-space curves."""

    type_number: ClassVar[int] = 141
    surface: Entity = None
    curves: tuple = ()  # (model curve, sense, tuple of parameter curves)

    def references(self):
        out = [self.surface]
        for c, _, ps in self.curves:
            out.append(c)
            out.extend(ps)
        return tuple(out)


@dataclass(frozen=True, eq=False)
class BoundedSurface143(Entity):
    """Bounded surface, type 143: a surface and 141 boundaries (one outer, others holes)."""

    type_number: ClassVar[int] = 143
    surface: Entity = None
    boundaries: tuple = ()

    def references(self):
        return (self.surface,) + self.boundaries


@dataclass(frozen=True, eq=False)
class SubfigureDefinition308(Entity):
    """Subfigure definition, type 308: a named group of entities."""

    type_number: ClassVar[int] = 308
    depth: int = 0
    name: str = ""
    members: tuple = ()

    def references(self):
        return self.members


@dataclass(frozen=True, eq=False)
class SubfigureInstance408(Entity):
    """Singular subfigure instance, type 408: definition scaled by S, then moved by (X, Y, Z)."""

    type_number: ClassVar[int] = 408
    definition: Entity = None
    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    scale: float = 1.0

    def references(self):
        return (self.definition,)


@dataclass(frozen=True, eq=False)
class VertexList502(Entity):
    type_number: ClassVar[int] = 502
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))


@dataclass(frozen=True, eq=False)
class EdgeList504(Entity):
    type_number: ClassVar[int] = 504
    curves: tuple = ()
    vertex_lists: tuple = ()

    def references(self):
        return self.curves + self.vertex_lists


@dataclass(frozen=True, eq=False)
class Loop508(Entity):
    """Loop, type 508: edges (edge list, index, orientation, parameter curves)."""

    type_number: ClassVar[int] = 508
    edges: tuple = ()  # (edge list 504, 0-based index, same sense?, tuple of parameter curves)
    # vertex "edges" (TYPE 1, a pole or apex): (number of edges before it, its vertex list,
    # its parameter curves), which say how a loop crosses a pole in parameter space
    vertex_edges: tuple = ()

    def references(self):
        out = []
        for e, _, _, ps in self.edges:
            out.append(e)
            out.extend(ps)
        for _, v, ps in self.vertex_edges:
            out.append(v)
            out.extend(ps)
        return tuple(out)


@dataclass(frozen=True, eq=False)
class Face510(Entity):
    type_number: ClassVar[int] = 510
    surface: Entity = None
    loops: tuple = ()
    outer_first: bool = True

    def references(self):
        return (self.surface,) + self.loops


@dataclass(frozen=True, eq=False)
class Shell514(Entity):
    type_number: ClassVar[int] = 514
    faces: tuple = ()

    def references(self):
        return self.faces


@dataclass(frozen=True, eq=False)
class Solid186(Entity):
    type_number: ClassVar[int] = 186
    shells: tuple = ()

    def references(self):
        return self.shells


@dataclass(frozen=True, eq=False)
class Group402(Entity):
    """Associativity instance, type 402, group forms 1, 7, 14, 15: its members."""

    type_number: ClassVar[int] = 402
    members: tuple = ()
    group_form: int = 7

    @property
    def form(self):
        return self.group_form

    def references(self):
        return self.members


@dataclass(frozen=True, eq=False)
class Conic104(Entity):
    """Conic arc, type 104: A x^2 + B xy + C y^2 + D x + E y + F = 0 at z = ZT, from
    (X1, Y1) to (X2, Y2) (counterclockwise for an ellipse); form 1 ellipse, 2 hyperbola,
    3 parabola."""

    type_number: ClassVar[int] = 104
    coefficients: np.ndarray = field(default_factory=lambda: np.zeros(6))
    z: float = 0.0
    start: np.ndarray = field(default_factory=lambda: np.zeros(2))
    end: np.ndarray = field(default_factory=lambda: np.zeros(2))
    conic_form: int = 0

    @property
    def form(self):
        return self.conic_form


FOREIGN_TYPES = (Group402, Conic104, Plane108, TabulatedCylinder122, OffsetSurface140, Boundary141, BoundedSurface143,
                 SubfigureDefinition308, SubfigureInstance408, Solid186, Shell514, Face510, Loop508,
                 EdgeList504, VertexList502)
#: Surfaces accepted under 142, 144 and 143 when reading leniently.
LENIENT_SURFACES = SURFACE_TYPES + (Plane108, TabulatedCylinder122, OffsetSurface140, AnalyticSurface)


# -- lenient builders ----------------------------------------------------------------------
def _merge_repeated_knots(knots: np.ndarray, P: np.ndarray, w: np.ndarray, p: int, axis: int, what: str):
    """Interior knots of multiplicity p + 1 between coincident control points (same weight)
    lose one copy and one of the two points: the same curve, now C0 there. Different points
    mean a discontinuous curve, which is refused."""
    k = np.asarray(knots, dtype=np.float64)
    Pm = np.moveaxis(P, axis, 0)
    wm = np.moveaxis(w, axis, 0)
    size = float(np.abs(Pm).max()) if Pm.size else 1.0
    j = p + 1
    while j < len(k) - p - 1:
        if k[j] == k[j + p] and k[j] > k[p] and k[j] < k[len(k) - p - 1]:
            left, right = Pm[j - 1], Pm[j]
            if (np.abs(left - right).max() > MERGE_TOLERANCE * max(size, 1e-300)
                    or np.abs(wm[j - 1] - wm[j]).max() > MERGE_TOLERANCE * float(np.abs(wm).max())):
                raise IgesError(f"{what}: knot {k[j]!r} has multiplicity {p + 1} between different "
                                f"control points: the curve is discontinuous there")
            k = np.delete(k, j)
            Pm = np.delete(Pm, j, axis=0)
            wm = np.delete(wm, j, axis=0)
            continue
        j += 1
    return k, np.moveaxis(Pm, 0, axis), np.moveaxis(wm, 0, axis)


def _fix_range(rng, lo, hi):
    a, b = rng
    if not (math.isfinite(a) and math.isfinite(b)) or not a < b or a < lo - 1e-9 * (hi - lo) or b > hi + 1e-9 * (hi - lo):
        if math.isfinite(a) and math.isfinite(b) and b < a and lo - 1e-9 * (hi - lo) <= b and a <= hi + 1e-9 * (hi - lo):
            return (b, a)  # reversed: the same piece
        return (lo, hi)  # empty or outside: the whole curve, as OpenCASCADE does
    return (max(a, lo), min(b, hi))


def _lb126(p, r, form):
    from .reader import _b126

    d = _b126(p, r, form)
    k, P, w = _merge_repeated_knots(d["knots"], d["control_points"], d["weights"], d["degree"], 0, p.where)
    n = len(P)
    m = d["degree"]
    d.update(knots=k, control_points=P, weights=w)
    d["start"], d["end"] = _fix_range((d["start"], d["end"]), k[m], k[n])
    return d


def _lb128(p, r, form):
    from .reader import _b128

    d = _b128(p, r, form)
    ku, P, w = _merge_repeated_knots(d["knots_u"], d["control_points"], d["weights"], d["degree_u"], 0, p.where)
    kv, P, w = _merge_repeated_knots(d["knots_v"], P, w, d["degree_v"], 1, p.where)
    d.update(knots_u=ku, knots_v=kv, control_points=P, weights=w)
    d["u_range"] = _fix_range(d["u_range"], ku[d["degree_u"]], ku[P.shape[0]])
    d["v_range"] = _fix_range(d["v_range"], kv[d["degree_v"]], kv[P.shape[1]])
    return d


def _optional(p, r, what):
    j = p.pointer(what, optional=True)
    if j is None:
        return None
    try:
        return r(j, what)
    except IgesError:
        return None  # an optional reference that cannot be read is dropped, not fatal


def _lb142(p, r, form):
    crtn = p.int("CRTN", default=0)
    s = r(p.pointer("SPTR (surface)"), "surface")
    b = _optional(p, r, "BPTR (parameter curve)")
    c = _optional(p, r, "CPTR (model curve)")
    pref = p.int("PREF", default=0)
    return dict(surface=s, parameter_curve=b, model_curve=c, creation=crtn if 0 <= crtn <= 3 else 0,
                preferred=pref if 0 <= pref <= 3 else 0)


def _lb144(p, r, form):
    s = r(p.pointer("PTS (surface)"), "surface")
    n1 = p.int("N1", default=0, lo=0, hi=1)
    n2 = p.count("N2 (number of holes)", 1, lo=0, offset=1)
    pto = p.pointer("PTO (outer boundary)", optional=True)
    inner = tuple(r(p.pointer(f"PTI({k + 1})"), "inner boundary") for k in range(n2))
    outer = None if (pto is None or n1 == 0) else r(pto, "outer boundary")
    return dict(surface=s, outer=outer, inner=inner)


def _lb110(p, r, form):
    return dict(start=p.reals(3, "start point"), end=p.reals(3, "end point"), line_form=form if form in (0, 1, 2) else 0)


def _b108(p, r, form):
    c = p.reals(4, "A, B, C, D")
    j = p.pointer("PTR (bounding curve)", optional=True)
    bound = None if j is None else r(j, "bounding curve")
    return dict(coefficients=c, boundary=bound, plane_form=form)


def _b122(p, r, form):
    return dict(directrix=r(p.pointer("DE (directrix)"), "directrix"), end=p.reals(3, "LX, LY, LZ"))


def _b140(p, r, form):
    ind = p.reals(3, "NX, NY, NZ")
    d = p.real("D (distance)")
    return dict(indicator=ind, distance=d, surface=r(p.pointer("DE (surface)"), "surface"))


def _b141(p, r, form):
    p.int("TYPE", default=0)
    p.int("PREF", default=0)
    s = r(p.pointer("SPTR (surface)"), "surface")
    n = p.count("N (number of curves)", 3, lo=1)
    curves = []
    for k in range(n):
        c = r(p.pointer(f"CRVPT({k + 1})"), "model curve")
        sense = p.int(f"SENSE({k + 1})", default=1)
        m = p.count(f"K({k + 1})", 1)
        ps = []
        for q in range(m):
            j = p.pointer(f"PSCPT({k + 1}, {q + 1})", optional=True)
            if j is not None:
                ps.append(r(j, "parameter curve"))
        curves.append((c, sense != 2, tuple(ps)))
    return dict(surface=s, curves=tuple(curves))


def _b143(p, r, form):
    p.int("TYPE", default=0)
    s = r(p.pointer("SPTR (surface)"), "surface")
    n = p.count("N (number of boundaries)", 1, lo=1)
    return dict(surface=s, boundaries=tuple(r(p.pointer(f"BDPT({k + 1})"), "boundary") for k in range(n)))


def _b308(p, r, form):
    depth = p.int("DEPTH", default=0)
    name = p.string("NAME")
    n = p.count("N (number of entities)", 1, lo=0)
    return dict(depth=depth, name=name, members=tuple(r(p.pointer(f"DE({k + 1})"), "member") for k in range(n)))


def _b408(p, r, form):
    d = r(p.pointer("DE (subfigure definition)"), "subfigure definition")
    xyz = np.array([p.real("X", 0.0), p.real("Y", 0.0), p.real("Z", 0.0)])
    s = p.real("S (scale)", 1.0)
    return dict(definition=d, translation=xyz, scale=s)


def _b502(p, r, form):
    n = p.count("N (number of vertices)", 3, lo=1)
    return dict(points=p.reals(3 * n, "vertices").reshape(n, 3))


def _b504(p, r, form):
    n = p.count("N (number of edges)", 5, lo=1)
    curves, lists = [], {}
    for k in range(n):
        curves.append(r(p.pointer(f"CURV({k + 1})"), "edge curve"))
        for what in ("SVP", "TVP"):
            j = p.pointer(f"{what}({k + 1})")
            if j not in lists:  # a vertex list is a child, not an independent entity
                try:
                    lists[j] = r(j, "vertex list")
                except IgesError:
                    lists[j] = None  # vertices are not used: a bad list is not fatal
            p.int(f"{what[0]}V({k + 1})")
    return dict(curves=tuple(curves), vertex_lists=tuple(v for v in lists.values() if v is not None))


def _b508(p, r, form):
    n = p.count("N (number of edges)", 5, lo=1)
    edges, vertex_edges = [], []
    for k in range(n):
        kind = p.int(f"TYPE({k + 1})", lo=0, hi=1)
        e = r(p.pointer(f"EDGE({k + 1})"), "edge list")
        ndx = p.int(f"NDX({k + 1})", lo=1)
        sense = p.int(f"OF({k + 1})", default=1)
        m = p.count(f"K({k + 1})", 2)
        ps = []
        for q in range(m):
            p.int(f"ISOP({k + 1}, {q + 1})", default=0)
            ps.append(r(p.pointer(f"CURV({k + 1}, {q + 1})"), "parameter curve"))
        if kind == 0:
            edges.append((e, ndx - 1, sense != 0, tuple(ps)))
        else:
            vertex_edges.append((len(edges), e, tuple(ps)))
    return dict(edges=tuple(edges), vertex_edges=tuple(vertex_edges))


def _b510(p, r, form):
    s = r(p.pointer("SURF (surface)"), "surface")
    n = p.count("N (number of loops)", 1, lo=1, offset=1)
    of = p.int("OF (outer loop flag)", default=1)
    loops = tuple(r(p.pointer(f"LOOP({k + 1})"), "loop") for k in range(n))
    return dict(surface=s, loops=loops, outer_first=of == 1)


def _b514(p, r, form):
    n = p.count("N (number of faces)", 2, lo=1)
    faces = []
    for k in range(n):
        faces.append(r(p.pointer(f"FACE({k + 1})"), "face"))
        p.int(f"OF({k + 1})", default=1)
    return dict(faces=tuple(faces))


def _b186(p, r, form):
    shell = r(p.pointer("SHELL"), "shell")
    p.int("SOF", default=1)
    n = p.count("N (void shells)", 2, lo=0)
    shells = [shell]
    for k in range(n):
        shells.append(r(p.pointer(f"VOID({k + 1})"), "void shell"))
        p.int(f"VOF({k + 1})", default=1)
    return dict(shells=tuple(shells))


def _b402(p, r, form):
    if form not in (1, 7, 14, 15):
        raise IgesError(f"{p.where}: associativity form {form} carries no geometry to import")
    n = p.count("N (number of members)", 1, lo=0)
    members = []
    for k in range(n):
        j = p.pointer(f"DE({k + 1})", optional=True)
        if j is None:
            continue
        try:
            members.append(r(j, "member"))
        except IgesError:
            pass  # a member that cannot be read is reported as skipped on its own
    return dict(members=tuple(members), group_form=form)


def _b104(p, r, form):
    c = p.reals(6, "A, B, C, D, E, F")
    z = p.real("ZT", 0.0)
    return dict(coefficients=c, z=z, start=p.reals(2, "X1, Y1"), end=p.reals(2, "X2, Y2"), conic_form=form)


def _lenient_builders():
    from .reader import BUILDERS

    return {
        110: (Line, _lb110), 126: (BUILDERS[126][0], _lb126), 128: (BUILDERS[128][0], _lb128),
        142: (CurveOnSurface, _lb142), 144: (TrimmedSurface, _lb144),
        108: (Plane108, _b108), 122: (TabulatedCylinder122, _b122), 140: (OffsetSurface140, _b140),
        141: (Boundary141, _b141), 143: (BoundedSurface143, _b143), 308: (SubfigureDefinition308, _b308),
        408: (SubfigureInstance408, _b408), 502: (VertexList502, _b502), 504: (EdgeList504, _b504),
        508: (Loop508, _b508), 510: (Face510, _b510), 514: (Shell514, _b514), 186: (Solid186, _b186),
        402: (Group402, _b402), 104: (Conic104, _b104), **_analytic_builders(),
    }


LENIENT_CURVES = CURVE_TYPES + (Conic104,)


def _kind(entity, value, types, what, optional=False):
    if value is None and optional:
        return
    if not isinstance(value, types):
        got = value.describe() if isinstance(value, Entity) else repr(value)[:60]
        raise IgesError(f"{entity.describe()}: {what} must be one of types "
                        f"{', '.join(str(t.type_number) for t in types)}; got {got}")


def check_lenient(entity: Entity) -> None:
    """Structure checks for lenient reading: the strict ones, with 142/144 accepting the
    foreign surfaces, and checks of the foreign records."""
    if isinstance(entity, CurveOnSurface):
        _kind(entity, entity.surface, LENIENT_SURFACES, "surface")
        _kind(entity, entity.parameter_curve, LENIENT_CURVES, "parameter curve", optional=True)
        if not isinstance(entity.model_curve, LENIENT_CURVES):
            object.__setattr__(entity, "model_curve", None)
        if entity.parameter_curve is None and entity.model_curve is None:
            raise IgesError(f"{entity.describe()}: neither a parameter-space nor a model-space curve is usable")
    elif isinstance(entity, TrimmedSurface):
        _kind(entity, entity.surface, LENIENT_SURFACES, "surface")
        for c in ((entity.outer,) if entity.outer is not None else ()) + entity.inner:
            _kind(entity, c, (CurveOnSurface,), "boundary")
    elif isinstance(entity, AnalyticSurface):
        pass  # checked as it is built
    elif isinstance(entity, Plane108):
        a = entity.coefficients
        if not np.all(np.isfinite(a)) or not np.any(a[:3] != 0):
            raise IgesError(f"{entity.describe()}: (A, B, C) = {a[:3].tolist()} is not a plane normal")
        _kind(entity, entity.boundary, LENIENT_CURVES, "bounding curve", optional=True)
    elif isinstance(entity, TabulatedCylinder122):
        _kind(entity, entity.directrix, LENIENT_CURVES, "directrix")
        if not np.all(np.isfinite(entity.end)):
            raise IgesError(f"{entity.describe()}: the generatrix end is not finite")
    elif isinstance(entity, OffsetSurface140):
        _kind(entity, entity.surface, LENIENT_SURFACES, "base surface")
    elif isinstance(entity, Boundary141):
        _kind(entity, entity.surface, LENIENT_SURFACES, "surface")
        for c, _, ps in entity.curves:
            _kind(entity, c, LENIENT_CURVES, "model curve")
            for q in ps:
                _kind(entity, q, LENIENT_CURVES, "parameter curve")
    elif isinstance(entity, BoundedSurface143):
        _kind(entity, entity.surface, LENIENT_SURFACES, "surface")
        for b in entity.boundaries:
            _kind(entity, b, (Boundary141,), "boundary")
            if b.surface is not entity.surface:
                raise IgesError(f"{entity.describe()}: a boundary lies on another surface")
    elif isinstance(entity, SubfigureInstance408):
        _kind(entity, entity.definition, (SubfigureDefinition308,), "definition")
        if not (math.isfinite(entity.scale) and entity.scale > 0) or not np.all(np.isfinite(entity.translation)):
            raise IgesError(f"{entity.describe()}: scale {entity.scale!r} must be a finite number > 0")
    elif isinstance(entity, (SubfigureDefinition308, VertexList502, Group402)):
        pass
    elif isinstance(entity, Conic104):
        conic_curve(entity)  # refuses what is not a conic arc
    elif isinstance(entity, SurfaceOfRevolution):
        # as written by real systems: any finite increasing angle range (OpenCASCADE takes
        # spans past 2 pi too); the trimming loops decide what is shown
        _kind(entity, entity.axis, (Line,), "axis")
        _kind(entity, entity.generatrix, LENIENT_CURVES, "generatrix")
        a, b = entity.start_angle, entity.end_angle
        if not (math.isfinite(a) and math.isfinite(b) and a < b):
            raise IgesError(f"{entity.describe()}: need finite start angle < end angle, got ({a!r}, {b!r})")
    elif isinstance(entity, EdgeList504):
        for c in entity.curves:
            _kind(entity, c, LENIENT_CURVES, "edge curve")
    elif isinstance(entity, Loop508):
        for e, ndx, _, ps in entity.edges:
            _kind(entity, e, (EdgeList504,), "edge list")
            if not 0 <= ndx < len(e.curves):
                raise IgesError(f"{entity.describe()}: edge index {ndx + 1} outside 1..{len(e.curves)}")
    elif isinstance(entity, Face510):
        _kind(entity, entity.surface, LENIENT_SURFACES, "surface")
        for q in entity.loops:
            _kind(entity, q, (Loop508,), "loop")
    elif isinstance(entity, Shell514):
        for f in entity.faces:
            _kind(entity, f, (Face510,), "face")
    elif isinstance(entity, Solid186):
        for s in entity.shells:
            _kind(entity, s, (Shell514,), "shell")
    elif isinstance(entity, CompositeCurve):
        if not entity.curves:
            raise IgesError(f"{entity.describe()}: a composite curve needs at least one constituent")
        for c in entity.curves:
            _kind(entity, c, LENIENT_CURVES, "constituent")
    else:
        check_structure(entity)
        return
    if entity.transform is not None:
        _kind(entity, entity.transform, (TransformationMatrix,), "transform")


# -- evaluation of the foreign surfaces -------------------------------------------------------
def _plane_frame(plane: Plane108):
    """(origin, e1, e2, normal) of a 108 (before its transform)."""
    a = plane.coefficients
    n = a[:3] / np.linalg.norm(a[:3])
    origin = n * a[3] / np.linalg.norm(a[:3])
    helper = np.eye(3)[int(np.argmin(np.abs(n)))]
    e1 = np.cross(n, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    return origin, e1, e2, n


def _tabulated(record: TabulatedCylinder122):
    c = record.directrix
    if isinstance(c, CompositeCurve):
        raise IgesError(f"{record.describe()}: a composite directrix is not supported")
    t0, t1 = curve_range(c)
    C0 = curve_points(c, np.array([t0]))[0]
    return c, t0, t1, C0


def surface_evaluator(surface: Entity):
    """(evaluate(u, v) -> (..., 3) with the surface's own transform, (u0, u1), (v0, v1)) in
    the surface's IGES parameter space, for every surface a 142/144/143/510 may lie on."""
    if isinstance(surface, (BSplineSurface128, ParametricSplineSurface, SurfaceOfRevolution)):
        return (lambda u, v: surface_points(surface, u, v)), *surface_range(surface)
    if isinstance(surface, TabulatedCylinder122):
        c, t0, t1, C0 = _tabulated(surface)
        g = np.asarray(surface.end) - C0

        def ev(u, v):
            u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
            P = curve_points(c, t0 + u * (t1 - t0)) + v[..., None] * g
            return _transform(surface, P)

        return ev, (0.0, 1.0), (0.0, 1.0)
    if isinstance(surface, OffsetSurface140):
        base, (u0, u1), (v0, v1) = surface_evaluator(surface.surface)
        hu, hv = NORMAL_STEP * (u1 - u0), NORMAL_STEP * (v1 - v0)

        def ev(u, v):
            u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
            ua, ub = np.clip(u - hu, u0, u1), np.clip(u + hu, u0, u1)
            va, vb = np.clip(v - hv, v0, v1), np.clip(v + hv, v0, v1)
            Su = base(ub, v) - base(ua, v)
            Sv = base(u, vb) - base(u, va)
            N = np.cross(Su, Sv)
            N /= np.linalg.norm(N, axis=-1, keepdims=True)
            return _transform(surface, base(u, v) + surface.distance * N)

        return ev, (u0, u1), (v0, v1)
    if isinstance(surface, AnalyticSurface):
        def ev(u, v):
            return _transform(surface, analytic_points(surface, u, v))

        big = 1e300
        t = surface.surface_type
        # angles are unwrapped along the loops, so they may leave (-pi, pi]
        return ev, (-big, big), ((-0.5 * math.pi, 0.5 * math.pi) if t == 196 else (-big, big))
    if isinstance(surface, Plane108):
        origin, e1, e2, _ = _plane_frame(surface)

        def ev(u, v):
            u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
            return _transform(surface, origin + u[..., None] * e1 + v[..., None] * e2)

        big = 1e300
        return ev, (-big, big), (-big, big)
    raise IgesError(f"{surface.describe()}: not a surface")


def plane_uv(plane: Plane108, points: np.ndarray) -> np.ndarray:
    """(u, v) in the plane frame of model points (transform of the plane undone)."""
    origin, e1, e2, _ = _plane_frame(plane)
    if plane.transform is not None:
        from .importer import _chain_matrix

        A, b = _chain_matrix(plane.transform)
        points = np.linalg.solve(A, (points - b).T).T
    x = points - origin
    return np.stack([x @ e1, x @ e2], axis=-1)


def exact_surface(surface: Entity) -> BSplineSurface | None:
    """The exact NURBS of an untrimmed foreign surface, or None when there is none."""
    if isinstance(surface, TabulatedCylinder122):
        c, t0, t1, C0 = _tabulated(surface)
        g = np.asarray(surface.end) - C0
        cg = curve_geometry(c) if not isinstance(c, Line) else BSplineCurve(1, [0, 0, 1, 1], np.stack([c.start, c.end]))
        if isinstance(c, BSplineCurve126):
            a, b = cg.domain
            if (t0, t1) != (a, b):
                from ..geometry.nurbs.operations import split_curve

                if t0 > a:
                    cg = split_curve(cg, t0)[1]
                if t1 < b:
                    cg = split_curve(cg, t1)[0]
        P = cg.control_points
        if P.shape[1] == 2:
            P = np.c_[P, np.zeros(len(P))]
        net = np.stack([P, P + g], axis=1)
        w = None if cg.weights is None else np.stack([cg.weights, cg.weights], axis=1)
        s = BSplineSurface(cg.degree, 1, cg.knots, [0.0, 0.0, 1.0, 1.0], net, w)
        if surface.transform is None:
            return s
        return BSplineSurface(s.degree_u, 1, s.knots_u, s.knots_v, _transform(surface, s.control_points), s.weights)
    return None


# -- import of the foreign roots ----------------------------------------------------------------
def _loops_143(imp, record: BoundedSurface143):
    """Closed uv polylines of a 143's boundaries (parameter curves when given, else model
    curves mapped onto the surface)."""
    loops = []
    for b in record.boundaries:
        pts = []
        for c, same, ps in b.curves:
            if ps:
                seg = np.concatenate([np.concatenate(list(imp._param_points(q, 0)))[:, :2] for q in ps])
            else:
                seg = _model_to_uv(imp, record.surface, c)
            pts.append(seg if same else seg[::-1])
        loops.append(np.concatenate(pts))
    return _order_loops(loops)


def _model_to_uv_points(surface: AnalyticSurface, X: np.ndarray) -> np.ndarray:
    """(u, v) of model points on an analytic surface (its own 124 undone)."""
    if surface.transform is not None:
        A, b = _chain_matrix_of(surface)
        X = np.linalg.solve(A, (X - b).T).T
    return analytic_uv(surface, X)


def _model_to_uv(imp, surface, curve) -> np.ndarray:
    X = np.concatenate(list(imp._model_points(curve)))
    if isinstance(surface, AnalyticSurface):
        return _model_to_uv_points(surface, X)
    if isinstance(surface, Plane108):
        return plane_uv(surface, X)
    if isinstance(surface, BSplineSurface128) and surface.transform is None:
        from ..geometry.nurbs.projection import closest_point_surface

        from .convert import bspline_surface

        u, v, _ = closest_point_surface(bspline_surface(surface), X)
        return np.stack([u, v], axis=-1)
    raise IgesError(f"{surface.describe()}: boundary given in model space only; only planes and untransformed "
                    "128 surfaces take model-space boundaries")


def _order_loops(loops: list) -> list:
    """The loop of largest area first (the outer one), then the holes."""
    def area(L):
        x, y = L[:, 0], L[:, 1]
        return abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))) / 2

    return sorted(loops, key=area, reverse=True)


def _chain_gap(pts: list) -> float:
    """Sum of the jumps from each piece's end to the next piece's start, around the loop."""
    return sum(float(np.linalg.norm(pts[k][-1] - pts[(k + 1) % len(pts)][0])) for k in range(len(pts)))


def _orient_parameter_curves(pts: list, flip: list) -> list:
    """The 508 pieces with the parameter-space curves of the edges used against their
    model-space curve (OF = 0) run the way the loop goes. Writers differ: OpenCASCADE writes
    (and reads) them in the loop's direction already, others (Bladesmith's propeller solid)
    along the edge's curve, to be reversed. Of the two readings, the one whose pieces join
    up (smaller sum of the gaps between consecutive pieces) is taken; OpenCASCADE's on a tie."""
    other = list(pts)
    for k in flip:
        other[k] = pts[k][::-1]
    return other if _chain_gap(other) < _chain_gap(pts) else pts


def _face_loops(imp, face: Face510) -> list:
    loops = []
    analytic = isinstance(face.surface, AnalyticSurface)
    for loop in face.loops:
        pts = []
        jumps = {}
        if analytic:
            for k, _, ps in loop.vertex_edges:
                if ps:  # the sign of the parameter-space step across the pole
                    q = np.concatenate([np.concatenate(list(imp._param_points(c, 0)))[:, :2] for c in ps])
                    jumps[k] = float(q[-1, 0] - q[0, 0])
        # vertex edges (a pole or a degenerate side) with parameter curves: their uv
        # steps are part of the loop in parameter space on other surfaces
        steps = {} if analytic else {k: ps for k, _, ps in loop.vertex_edges if ps}
        flip = []  # indices in pts of parameter-space curves of edges used against their curve
        for j, (e, ndx, same, ps) in enumerate(loop.edges):
            if j in steps:
                pts.append(np.concatenate([np.concatenate(list(imp._param_points(q, 0)))[:, :2]
                                           for q in steps.pop(j)]))
            if analytic:
                # the model-space edge, whatever convention the writer used for its
                # parameter-space curves (degrees or radians, swapped or shifted)
                seg = _model_to_uv(imp, face.surface, e.curves[ndx])
            elif ps:
                seg = np.concatenate([np.concatenate(list(imp._param_points(q, 0)))[:, :2] for q in ps])
                if not same:
                    flip.append(len(pts))
                pts.append(seg)
                continue
            else:
                seg = _model_to_uv(imp, face.surface, e.curves[ndx])
            pts.append(seg if same else seg[::-1])
        for ps in steps.values():  # after the last edge
            pts.append(np.concatenate([np.concatenate(list(imp._param_points(q, 0)))[:, :2] for q in ps]))
        if flip:
            pts = _orient_parameter_curves(pts, flip)
        loops.append(unwrap_loop(face.surface, pts, jumps) if analytic else np.concatenate(pts))
    return loops if face.outer_first else _order_loops(loops)


def _mesh_face(imp, record, surface, loops, place, name, exact=None):
    from .importer import ImportItem
    from .tessellate import tessellate

    ev, (u0, u1), (v0, v1) = surface_evaluator(surface)
    A, b = _chain_matrix_of(record)
    full = place.then(A, b)

    def evaluate(u, v):
        return full.apply(ev(np.clip(u, u0, u1), np.clip(v, v0, v1)))

    L = np.concatenate(loops)
    lo, hi = L.min(axis=0), L.max(axis=0)
    corners = evaluate(np.array([lo[0], hi[0], lo[0], hi[0]]), np.array([lo[1], lo[1], hi[1], hi[1]]))
    imp._check_range(corners, record)
    size = float(np.linalg.norm(np.ptp(corners, axis=0))) or 1.0
    mesh = tessellate(evaluate, loops, imp.tolerance * size, max(16, imp.budget.left("points")))
    imp._check_range(mesh.vertices, record)
    imp.budget.spend("points", len(mesh.vertices))
    imp.budget.spend("objects")
    note = "" if exact is not None else "shown trimmed; no exact export for this face"
    if mesh.deviation > imp.tolerance * size:
        note = (f"mesh deviates {mesh.deviation:.3g} m from the surface, more than the display "
                f"tolerance {imp.tolerance * size:.3g} m (refinement stopped: {mesh.stopped or 'budget'})")
        imp.notes.append(f"{name}: {note}")
    imp.items.append(ImportItem(name, "mesh", mesh=mesh, exact=exact, note=note))


def _chain_matrix_of(record):
    from .importer import _chain_matrix

    return _chain_matrix(record.transform)


def import_root(imp, record: Entity, place, depth: int):
    """Import one independent foreign entity through the importer ``imp``."""
    from .importer import MAX_SUBFIGURE_DEPTH

    name = imp.name_of(record)
    if isinstance(record, SubfigureInstance408):
        if depth > MAX_SUBFIGURE_DEPTH:
            raise IgesError(f"{record.describe()}: subfigures nested deeper than {MAX_SUBFIGURE_DEPTH}")
        A, b = _chain_matrix_of(record)
        defn = record.definition
        Ad, bd = _chain_matrix_of(defn)
        # IGES 5.3, type 408: members scaled by S about the origin, moved by (X, Y, Z), then
        # the 408's own 124
        inner = _compose(place, A, b, record.scale, record.translation, Ad, bd)
        for m in defn.members:
            imp.root(m, inner, depth + 1)
    elif isinstance(record, SubfigureDefinition308):
        return  # a definition shows only through its instances
    elif isinstance(record, Group402):
        if depth > MAX_SUBFIGURE_DEPTH:
            raise IgesError(f"{record.describe()}: groups nested deeper than {MAX_SUBFIGURE_DEPTH}")
        for m in record.members:
            imp.root(m, place, depth + 1)
    elif isinstance(record, Conic104):
        from .importer import _placed_curve

        imp.add_curve(record, _placed_curve(conic_curve(record), place), name)
    elif isinstance(record, BoundedSurface143):
        loops = _loops_143(imp, record)
        _mesh_face(imp, record, record.surface, loops, place, name)
    elif isinstance(record, (Solid186, Shell514)):
        shells = record.shells if isinstance(record, Solid186) else (record,)
        A, b = _chain_matrix_of(record)
        inner = place.then(A, b)
        for k, shell in enumerate(shells):
            for i, face in enumerate(shell.faces):
                imp.root(face, inner, depth + 1)
    elif isinstance(record, Face510):
        _mesh_face(imp, record, record.surface, _face_loops(imp, record), place, name)
    elif isinstance(record, TabulatedCylinder122):
        s = exact_surface(record)
        from .importer import _placed_surface

        imp.add_surface(record, _placed_surface(s, place), name)
    elif isinstance(record, OffsetSurface140):
        ev, (u0, u1), (v0, v1) = surface_evaluator(record)
        box = np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1]])
        _mesh_face(imp, record, record, [box], place, name)
    elif isinstance(record, Plane108):
        if record.boundary is None:
            imp.skip(record, "unbounded plane: nothing to show")
            return
        X = np.concatenate(list(imp._model_points(record.boundary)))
        uv = plane_uv(record, X)
        _mesh_face(imp, record, record, [uv], place, name)
    else:
        imp.skip(record, "not an independent geometric entity")


def _compose(place, A, b, s, t, Ad, bd):
    """Placement of a 308's members: the 308's own 124, then scale s and translation t of
    the 408, then the 408's own 124 (A, b), then ``place``."""
    # member point y -> Ad y + bd -> s (.) + t -> A (.) + b
    M = A @ (s * Ad)
    c = A @ (s * bd + t) + b
    return place.then(M, c)


# -- conics ---------------------------------------------------------------------------------------
def conic_curve(record: Conic104) -> BSplineCurve:
    """A 104 as an exact rational quadratic B-spline in 3-D (z = ZT, its 124 chain applied).

    Ellipse: the affine image of a circular arc about its centre and principal axes (any
    span up to a full turn, counterclockwise from start to end). Parabola
    and hyperbola: one rational Bezier segment (The NURBS Book 2e §7.2-7.3): P1 where the
    end tangents meet, the weight from the conic's point on the line from the chord's
    midpoint to P1."""
    A, B, C, D, E, F = (float(x) for x in record.coefficients)
    p0, p2 = np.asarray(record.start, float), np.asarray(record.end, float)
    what = record.describe()
    Q = np.array([[A, B / 2], [B / 2, C]])
    if not np.all(np.isfinite(record.coefficients)) or not np.any(Q):
        raise IgesError(f"{what}: not a conic (A = B = C = 0)")
    if record.conic_form == 1 or (record.conic_form == 0 and np.linalg.det(Q) > 0):
        try:
            c = np.linalg.solve(Q, -0.5 * np.array([D, E]))
        except np.linalg.LinAlgError:
            raise IgesError(f"{what}: an ellipse with no centre") from None
        Fc = A * c[0] ** 2 + B * c[0] * c[1] + C * c[1] ** 2 + D * c[0] + E * c[1] + F
        lam, V = np.linalg.eigh(Q)
        if not (np.all(lam * Fc < 0)):
            raise IgesError(f"{what}: the coefficients are not a real ellipse")
        axes = np.sqrt(-Fc / lam)
        local = lambda p: (V.T @ (p - c)) / axes  # noqa: E731
        q0, q2 = local(p0), local(p2)
        t0 = math.atan2(q0[1], q0[0])
        t1 = math.atan2(q2[1], q2[0])
        if t1 <= t0 + 1e-14:
            t1 += 2 * math.pi
        from .convert import _arc_net

        knots, cs, f, w = _arc_net(t0, t1)
        P2 = c + ((f[:, None] * cs) * axes) @ V.T
    else:
        def grad(p):
            return np.array([2 * A * p[0] + B * p[1] + D, B * p[0] + 2 * C * p[1] + E])

        g0, g2 = grad(p0), grad(p2)
        M = np.array([g0, g2])
        if abs(np.linalg.det(M)) <= 1e-14 * (np.linalg.norm(g0) * np.linalg.norm(g2) + 1e-300):
            raise IgesError(f"{what}: the end tangents are parallel; not one conic arc segment")
        p1 = np.linalg.solve(M, np.array([g0 @ p0, g2 @ p2]))
        m = 0.5 * (p0 + p2)
        d = p1 - m
        # conic(m + s d) = a s^2 + b s + k: the root in (0, 1)
        def conic(p):
            return A * p[0] ** 2 + B * p[0] * p[1] + C * p[1] ** 2 + D * p[0] + E * p[1] + F

        k = conic(m)
        a = A * d[0] ** 2 + B * d[0] * d[1] + C * d[1] ** 2
        b = conic(m + d) - a - k
        roots = np.roots([a, b, k]) if abs(a) > 0 else np.array([-k / b]) if b else np.array([])
        roots = [float(r.real) for r in np.atleast_1d(roots) if abs(r.imag) < 1e-12 and 0 < r.real < 1]
        if not roots:
            raise IgesError(f"{what}: the arc between its end points is not on the conic")
        s_ = min(roots)
        w1 = s_ / (1 - s_)  # shoulder point S = m + s (p1 - m), w = |m S| / |S p1|
        knots, w = np.array([0, 0, 0, 1, 1, 1.0]), np.array([1.0, w1, 1.0])
        P2 = np.array([p0, p1, p2])
    P = np.c_[P2, np.full(len(P2), record.z)]
    try:
        curve = BSplineCurve(2, knots, P, w)
    except BladesmithError as exc:
        raise IgesError(f"{what}: {exc}") from None
    if record.transform is None:
        return curve
    return curve.with_control_points(_transform(record, curve.control_points))
