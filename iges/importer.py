"""From a leniently read IGES model to what an importer shows: exact curves and surfaces in
metres, where they belong, meshes of trimmed faces, and a report of everything skipped.

bpy-free; the import operator only turns :class:`ImportItem` objects into Blender objects.

* Units (IGES 5.3 §2.2.4.3.14-15, Table 3): the unit flag rules; flag 3 names the unit in
  field 15; a defaulted flag means inches (1) unless field 15 names a unit; the model
  space scale (field 13) divides model coordinates (real = model / scale); a scale <= 0
  and an unknown unit are refused.
* Placement: every entity's own 124 chain (curves, surfaces, 102 and its constituents,
  142/144 and the surface under them), then the placement of the 408 singular subfigure
  instances that bring it in (308/408: scale S, then translation, then the 408's own
  124), then the unit factor.
* Resilience: an entity that cannot be converted is skipped with its reason; the report
  counts every skipped type. Only a file with nothing importable, units that cannot be
  known, or work beyond the size budget is refused.
* Bounded work: curves, objects and points made are limited in proportion to the file
  size (:class:`Budget`), so a small file cannot expand into millions of objects.
* Display range: coordinates beyond :data:`MAX_DISPLAY_COORDINATE` metres are refused per
  entity before anything reaches Blender (Blender computes in float32 and hangs on
  coordinates near 1e19 m).
"""
from __future__ import annotations

import math
import os
from collections import defaultdict
from dataclasses import dataclass, field, replace
from dataclasses import fields as fields_of

import numpy as np

from ..geometry.errors import BladesmithError, IgesError
from ..geometry.nurbs import BSplineCurve, BSplineSurface
from .convert import (
    _transform,
    curve_geometry,
    curve_points,
    curve_range,
    surface_geometry,
    surface_points,
    surface_range,
)
from .reader import IgesModel, SkippedEntity, parse_iges
from .records import (
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
from .tessellate import TrimmedMesh, tessellate

#: Metres per unit for IGES 5.3 unit flags 1..11 (3: the name in field 15 rules).
METRES_PER_FLAG = {1: 0.0254, 2: 1e-3, 4: 0.3048, 5: 1609.344, 6: 1.0, 7: 1e3, 8: 2.54e-5,
                   9: 1e-6, 10: 1e-2, 11: 2.54e-8}
#: Unit names as CAD systems spell them in Global field 15, to unit flags.
UNIT_NAME_FLAGS = {
    "IN": 1, "INCH": 1, "INCHES": 1, "MM": 2, "MILLIMETER": 2, "MILLIMETRE": 2, "MILLIMETERS": 2,
    "MILLIMETRES": 2, "FT": 4, "FOOT": 4, "FEET": 4, "MI": 5, "MILE": 5, "MILES": 5, "M": 6,
    "METER": 6, "METRE": 6, "METERS": 6, "METRES": 6, "KM": 7, "KILOMETER": 7, "KILOMETRE": 7,
    "KILOMETERS": 7, "KILOMETRES": 7, "MIL": 8, "MILS": 8, "UM": 9, "MICRON": 9, "MICRONS": 9,
    "MICROMETER": 9, "MICROMETRE": 9, "MICROMETERS": 9, "MICROMETRES": 9, "CM": 10,
    "CENTIMETER": 10, "CENTIMETRE": 10, "CENTIMETERS": 10, "CENTIMETRES": 10, "UIN": 11,
    "MICROINCH": 11, "MICROINCHES": 11,
}
#: Largest |coordinate| in metres sent to Blender. Blender evaluates in float32, and its
#: curve operators hang on coordinates near 1e19 m; 1e12 m keeps squared distances
#: (1e24 m^2) far inside float32's range (3.4e38).
MAX_DISPLAY_COORDINATE = 1e12
#: Display tolerance of trimmed-face meshes, as a fraction of the face's size.
DISPLAY_TOLERANCE = 1e-3
#: Budget per byte of file: curves, objects and points made (see :class:`Budget`).
CURVES_PER_BYTE = 1 / 8
OBJECTS_PER_BYTE = 1 / 16
POINTS_PER_BYTE = 64
#: Floors of the budget, so small hand-written files are not starved.
MIN_CURVES, MIN_OBJECTS, MIN_POINTS = 1000, 200, 200_000
#: 308/408 subfigures nested deeper than this are refused per entity.
MAX_SUBFIGURE_DEPTH = 16
#: Samples per knot span (or per segment) of a trimming curve when it is turned into a polyline.
LOOP_SAMPLES_PER_SPAN = 24
#: Samples of a circular arc trimming curve per radian.
ARC_SAMPLES_PER_RADIAN = 24
#: Blender shows NURBS of degree <= 5 (order 6); higher degrees are meshed for display.
MAX_DISPLAY_DEGREE = 5
#: Entity types that carry no geometry to show (annotation, properties, views ...).
NO_GEOMETRY_TYPES = {0, 123, 124, 502, 202, 206, 210, 212, 214, 216, 218, 220, 222, 228, 230, 302, 304, 306,
                     310, 312, 314, 316, 320, 322, 402, 404, 406, 410, 412, 414, 416, 418, 420, 422,
                     430}


@dataclass(frozen=True)
class Units:
    metres_per_unit: float
    name: str
    model_scale: float

    @property
    def factor(self) -> float:
        """Metres per model-space coordinate (unit / model scale)."""
        return self.metres_per_unit / self.model_scale


def units_of(model: IgesModel) -> Units:
    """The length unit of a model (IGES 5.3 §2.2.4.3.13-15). IgesError when the unit cannot
    be known or the model space scale is not positive."""
    h = model.header
    where = f"{model.path}: " if model.path else ""
    scale = 1.0 if "model_scale" in model.defaulted else float(h.model_scale)
    if not (math.isfinite(scale) and scale > 0.0):
        raise IgesError(f"{where}Global field 13 (model space scale) = {scale!r}: must be > 0", path=None)
    name = "" if "unit_name" in model.defaulted else (h.unit_name or "").strip().upper()
    named = UNIT_NAME_FLAGS.get(name.replace(" ", "").rstrip("."))
    flag = None if "unit_flag" in model.defaulted else int(h.unit_flag)
    if flag is None:
        flag = named if named is not None else 1  # the standard's default is inches
    elif flag == 3 or flag not in METRES_PER_FLAG:
        if named is None:
            raise IgesError(f"{where}Global field 14 (units flag) = {flag} with field 15 (units name) "
                            f"= {h.unit_name!r}: the unit is unknown")
        flag = named
    return Units(METRES_PER_FLAG[flag], {v: k for k, v in UNIT_NAME_FLAGS.items() if len(k) <= 3}.get(flag, name),
                 scale)


class Budget:
    """Counts of what an import makes, limited in proportion to the file size."""

    def __init__(self, file_bytes: int):
        self.file_bytes = int(file_bytes)
        self.limits = {
            "curves": max(MIN_CURVES, int(file_bytes * CURVES_PER_BYTE)),
            "objects": max(MIN_OBJECTS, int(file_bytes * OBJECTS_PER_BYTE)),
            "points": max(MIN_POINTS, int(file_bytes * POINTS_PER_BYTE)),
        }
        self.used = dict.fromkeys(self.limits, 0)

    def spend(self, what: str, count: int = 1):
        self.used[what] += int(count)
        if self.used[what] > self.limits[what]:
            raise _BudgetExceeded(
                f"the file ({self.file_bytes} bytes) expands to more than {self.limits[what]} {what}, the "
                f"limit for its size; refused (nested composite curves or subfigure instances that "
                f"multiply their contents?)"
            )

    def left(self, what: str) -> int:
        return self.limits[what] - self.used[what]


class _BudgetExceeded(IgesError):
    """Raised through per-entity handlers: the whole file is refused."""


# -- placement ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Placement:
    """x -> factor * (A x + b): a 408 chain then the unit factor (A includes 408 scales)."""

    A: np.ndarray = field(default_factory=lambda: np.eye(3))
    b: np.ndarray = field(default_factory=lambda: np.zeros(3))
    factor: float = 1.0

    def apply(self, P: np.ndarray) -> np.ndarray:
        P = np.asarray(P, dtype=np.float64)
        return self.factor * (P @ self.A.T + self.b)

    def then(self, A, b) -> "Placement":
        """First this placement's affine map, then (A, b) (before the unit factor)."""
        A = np.asarray(A, dtype=np.float64)
        return Placement(A @ self.A, A @ self.b + np.asarray(b, dtype=np.float64), self.factor)


def _chain_matrix(t: TransformationMatrix | None) -> tuple[np.ndarray, np.ndarray]:
    """(R, T) of a 124 chain as one affine map."""
    A, b = np.eye(3), np.zeros(3)
    depth = 0
    while t is not None:
        A, b = t.rotation @ A, t.rotation @ b + t.translation
        t = t.transform
        depth += 1
        if depth > 32:
            raise IgesError("transformation chain longer than 32")
    return A, b


def _placed_curve(c: BSplineCurve, place: Placement) -> BSplineCurve:
    P = c.control_points
    if P.shape[1] == 2:
        P = np.c_[P, np.zeros(len(P))]
    return BSplineCurve(c.degree, c.knots, place.apply(P), c.weights)


def _placed_surface(s: BSplineSurface, place: Placement) -> BSplineSurface:
    return BSplineSurface(s.degree_u, s.degree_v, s.knots_u, s.knots_v, place.apply(s.control_points), s.weights)


# -- what comes out ----------------------------------------------------------------------
@dataclass
class ImportItem:
    """One object to make.

    kind: "curve" or "surface" (``geometry`` exact, metres), or "mesh" (``mesh``, metres,
    with ``exact`` the IGES text of the exact entity in metres, for export).
    """

    name: str
    kind: str
    geometry: object = None
    mesh: TrimmedMesh | None = None
    exact: str | None = None
    note: str = ""
    trimmed: bool = True  # a mesh item: a trimmed face (else a surface Blender cannot show)


@dataclass
class ImportReport:
    items: list
    units: Units
    skipped: dict  # entity type -> [count, example reason]
    notes: list
    counts: dict

    def skipped_summary(self) -> str:
        """'3 x type 108 (reason), 1 x type 116 (reason)' for every type skipped."""
        parts = []
        for t in sorted(self.skipped):
            n, why = self.skipped[t]
            parts.append(f"{n} x type {t} ({why})")
        return ", ".join(parts)


class _Importer:
    def __init__(self, model: IgesModel, budget: Budget, tolerance: float):
        self.model = model
        self.budget = budget
        self.tolerance = tolerance
        self.items: list[ImportItem] = []
        self.skipped = defaultdict(lambda: [0, ""])
        self.notes: list[str] = list(model.notes)
        self.base = os.path.splitext(os.path.basename(model.path or "iges"))[0]
        prefix = f"{model.path}, " if model.path else None
        for s in model.skipped:
            self.skip_type(s.entity_type, _short(s.reason.replace(prefix, "") if prefix else s.reason))

    def skip_type(self, etype: int, why: str):
        entry = self.skipped[etype]
        entry[0] += 1
        if not entry[1]:
            entry[1] = why

    def skip(self, record: Entity, why: str):
        self.skip_type(_type_of(record), why)

    # -- item makers ------------------------------------------------------------------
    def _check_range(self, P: np.ndarray, record: Entity):
        m = float(np.abs(P).max()) if P.size else 0.0
        if not math.isfinite(m) or m > MAX_DISPLAY_COORDINATE:
            raise IgesError(f"{record.describe()}: coordinate {m:.3g} m is beyond the display limit "
                            f"{MAX_DISPLAY_COORDINATE:.0e} m (Blender works in float32)")

    def add_curve(self, record: Entity, c: BSplineCurve, name: str, note: str = ""):
        self._check_range(c.control_points, record)
        self.budget.spend("curves")
        self.budget.spend("objects")
        self.budget.spend("points", c.control_points.shape[0])
        if c.degree > MAX_DISPLAY_DEGREE:
            from ..geometry.nurbs.fitting import approximate

            c = approximate(c.evaluate, self.tolerance * max(c.size(), 1e-300), degree=3, domain=c.domain)
            note = f"degree above {MAX_DISPLAY_DEGREE} shown as a cubic approximation"
        self.items.append(ImportItem(name, "curve", geometry=c, note=note))

    def add_surface(self, record: Entity, s: BSplineSurface, name: str, exact_record=None, place=None):
        self._check_range(s.control_points, record)
        self.budget.spend("objects")
        self.budget.spend("points", s.control_points.shape[0] * s.control_points.shape[1])
        if max(s.degree_u, s.degree_v) <= MAX_DISPLAY_DEGREE:
            self.items.append(ImportItem(name, "surface", geometry=s))
            return
        item = surface_as_mesh(s, name, self.tolerance, self.budget.left("points"))
        self.budget.spend("points", len(item.mesh.vertices))
        item.note = f"degree above {MAX_DISPLAY_DEGREE} shown as a mesh ({item.note})"
        self.items.append(item)

    # -- conversion of roots ----------------------------------------------------------
    def name_of(self, record: Entity) -> str:
        return (record.label or f"{self.base}.{_type_of(record)}").strip() or self.base

    def root(self, record: Entity, place: Placement, depth: int = 0):
        if isinstance(record, TransformationMatrix):
            return
        t = _type_of(record)
        try:
            with np.errstate(all="ignore"):
                self._root(record, place, depth)
        except _BudgetExceeded:
            raise
        except IgesError as exc:
            self.skip(record, _short(str(exc)))
        except BladesmithError as exc:
            self.skip(record, _short(f"{record.describe()}: {exc}"))
        except RecursionError:
            self.skip_type(t, "references nested too deeply")

    def _root(self, record: Entity, place: Placement, depth: int):
        from . import foreign

        name = self.name_of(record)
        if isinstance(record, (BSplineCurve126, CircularArc, ParametricSpline)):
            self.add_curve(record, _placed_curve(curve_geometry(record), place), name)
        elif isinstance(record, Line):
            self.add_curve(record, _placed_curve(_line_curve(record), place), name,
                           note="" if record.form == 0 else "unbounded line shown between its two points")
        elif isinstance(record, CompositeCurve):
            for c in self.composite_leaves(record, 0):
                self.add_curve(record, _placed_curve(c, place), name)
        elif isinstance(record, (BSplineSurface128, ParametricSplineSurface, SurfaceOfRevolution)):
            self.add_surface(record, _placed_surface(surface_geometry(record), place), name)
        elif isinstance(record, TrimmedSurface):
            self.trimmed(record, place, name)
        elif isinstance(record, CurveOnSurface):
            if record.model_curve is None:
                raise IgesError(f"{record.describe()}: a curve on a surface with no model-space curve")
            A, b = _chain_matrix(record.transform)
            for c in self.model_curves(record.model_curve):
                self.add_curve(record, _placed_curve(c, place.then(A, b)), name)
        elif isinstance(record, foreign.FOREIGN_TYPES):
            foreign.import_root(self, record, place, depth)
        elif isinstance(record, GenericEntity):
            if record.entity_type in NO_GEOMETRY_TYPES:
                self.skip(record, "no geometry to import (annotation, property or structure)")
            else:
                self.skip(record, "entity type not supported")
        else:
            self.skip(record, "entity type not supported")

    def model_curves(self, record: Entity) -> list[BSplineCurve]:
        if isinstance(record, CompositeCurve):
            return self.composite_leaves(record, 0)
        return [_curve_of(record)]

    def composite_leaves(self, record: CompositeCurve, depth: int) -> list[BSplineCurve]:
        """Constituents of a 102 as curves, nested 102s expanded, each 102's own 124 chain
        applied to what it contains (IGES 5.3 §4.4)."""
        if depth > 64:
            raise IgesError(f"{record.describe()}: composite curves nested deeper than 64")
        out = []
        for c in record.curves:
            self.budget.spend("curves")
            if isinstance(c, CompositeCurve):
                out.extend(self.composite_leaves(c, depth + 1))
            else:
                out.append(_curve_of(c))
        if record.transform is not None:
            A, b = _chain_matrix(record.transform)
            out = [BSplineCurve(c.degree, c.knots, _pad3(c.control_points) @ A.T + b, c.weights) for c in out]
        return out

    # -- trimmed surfaces -------------------------------------------------------------
    def loop_polyline(self, cos: CurveOnSurface) -> np.ndarray:
        """A 142 boundary as a closed polyline in the IGES parameter space of its surface
        (from its parameter-space curve, or else its model-space curve mapped onto the
        surface: planes and untransformed 128 surfaces)."""
        from . import foreign

        if isinstance(cos.surface, foreign.AnalyticSurface):
            # writers differ on the units of parameter curves over 190-198 (degrees or
            # radians, shifted, swapped): the model-space curve, mapped by the surface's
            # closed-form inverse, is unambiguous
            if cos.model_curve is None:
                raise IgesError(f"{cos.describe()}: a boundary on an analytic surface (type "
                                f"{cos.surface.surface_type}) without a model-space curve")
            edges = [foreign._model_to_uv_points(cos.surface, _pad3(X)) for X in self._model_points(cos.model_curve)]
            P = foreign.unwrap_loop(cos.surface, edges)
        elif cos.parameter_curve is not None and not isinstance(cos.surface, foreign.Plane108):
            P = np.concatenate(list(self._param_points(cos.parameter_curve, 0)))[:, :2]
            if cos.model_curve is not None and not np.all(np.ptp(P, axis=0) > 0):
                # a parameter-space loop with no area (freecad-common's SOD_323.igs: two
                # whose u stays at -0.01) beside a model-space one: OCC builds the face from
                # the model-space curve, and so do we, where it can be mapped onto the surface
                try:
                    P = foreign._model_to_uv(self, cos.surface, cos.model_curve)
                except IgesError:
                    pass
        elif cos.model_curve is not None:
            P = foreign._model_to_uv(self, cos.surface, cos.model_curve)
        else:
            raise IgesError(f"{cos.describe()}: no usable boundary curve")
        self.budget.spend("points", len(P))
        if not np.all(np.isfinite(P)):
            raise IgesError(f"{cos.describe()}: the parameter-space curve is not finite")
        keep = np.ones(len(P), bool)
        keep[1:] = np.any(P[1:] != P[:-1], axis=1)
        P = P[keep]
        if len(P) > 1 and np.array_equal(P[0], P[-1]):
            P = P[:-1]
        return P

    def _param_points(self, curve: Entity, depth: int):
        if depth > 64:
            raise IgesError(f"{curve.describe()}: composite curves nested deeper than 64")
        if isinstance(curve, CompositeCurve):
            for c in curve.curves:
                self.budget.spend("curves")
                for P in self._param_points(c, depth + 1):
                    yield _transform(curve, P) if curve.transform is not None else P
            return
        from .foreign import Conic104, conic_curve

        if isinstance(curve, Conic104):
            c = conic_curve(curve)
            t = np.linspace(*c.domain, 4 * LOOP_SAMPLES_PER_SPAN + 1)
            self.budget.spend("points", len(t))
            yield c.evaluate(t)
            return
        a, b = curve_range(curve)
        if isinstance(curve, BSplineCurve126):
            U = np.unique(np.clip(curve.knots, a, b))
            t = (U[:-1, None] + np.linspace(0, 1, LOOP_SAMPLES_PER_SPAN, endpoint=False)[None, :]
                 * np.diff(U)[:, None]).ravel()
            t = np.append(t, b)
        elif isinstance(curve, ParametricSpline):
            U = curve.breakpoints
            t = np.append((U[:-1, None] + np.linspace(0, 1, LOOP_SAMPLES_PER_SPAN, endpoint=False)[None, :]
                           * np.diff(U)[:, None]).ravel(), U[-1])
        elif isinstance(curve, CircularArc):
            t = np.linspace(a, b, max(3, int(ARC_SAMPLES_PER_RADIAN * abs(b - a)) + 1))
        else:
            t = np.array([a, b])
        self.budget.spend("points", len(t))
        yield curve_points(curve, t)

    def _model_points(self, curve: Entity, depth: int = 0):
        """Model-space points along a curve record (own transforms applied), for mapping a
        model-space boundary onto its surface."""
        if isinstance(curve, CompositeCurve):
            if depth > 64:
                raise IgesError(f"{curve.describe()}: composite curves nested deeper than 64")
            for c in curve.curves:
                self.budget.spend("curves")
                for P in self._model_points(c, depth + 1):
                    yield _transform(curve, _pad3(P)) if curve.transform is not None else _pad3(P)
            return
        for P in self._param_points(curve, depth):
            yield _pad3(P)

    def trimmed(self, record: TrimmedSurface, place: Placement, name: str):
        """A 144 as a mesh inside its loops, with the exact 144 kept for export."""
        from . import foreign

        surf = record.surface
        if record.outer is None:
            if isinstance(surf, foreign.Plane108):
                raise IgesError(f"{record.describe()}: a plane with no outer boundary is unbounded")
            _, (u0, u1), (v0, v1) = foreign.surface_evaluator(surf)
            if isinstance(surf, foreign.AnalyticSurface):
                if surf.surface_type not in (196, 198):
                    raise IgesError(f"{record.describe()}: an analytic surface of type {surf.surface_type} "
                                    "with no outer boundary is unbounded")
                # the whole sphere or torus
                (u0, u1), (v0, v1) = (-math.pi, math.pi), ((v0, v1) if surf.surface_type == 196 else (-math.pi, math.pi))
            outer = np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1]])
        else:
            outer = self.loop_polyline(record.outer)
        loops = [outer] + [self.loop_polyline(c) for c in record.inner]
        exact, why = exact_text(record, place, name)
        if exact is None:
            self.notes.append(f"{name}: shown trimmed, but cannot be exported exactly ({why})")
        foreign._mesh_face(self, record, surf, loops, place, name, exact=exact)


def surface_as_mesh(s: BSplineSurface, name: str, tolerance: float = DISPLAY_TOLERANCE,
                    max_points: int = MIN_POINTS) -> ImportItem:
    """A mesh item of an untrimmed surface Blender cannot show as NURBS, keeping the exact
    surface (:func:`records_to_json`, metres) for export."""
    from .convert import surface_from_geometry

    (a, b), (c, d) = s.domain_u, s.domain_v
    box = np.array([[a, c], [b, c], [b, d], [a, d]])
    mesh = tessellate(s.evaluate, [box], tolerance * s.size(), max_points)
    exact = records_to_json(surface_from_geometry(s, label=name[:8]))
    return ImportItem(name, "mesh", mesh=mesh, exact=exact, trimmed=False,
                      note=f"deviation {mesh.deviation:.2g} m; exact surface kept for export")


def _pad3(P: np.ndarray) -> np.ndarray:
    return P if P.shape[1] == 3 else np.c_[P, np.zeros((len(P), 3 - P.shape[1]))]


def _curve_of(record: Entity) -> BSplineCurve:
    """Any single curve record as an exact B-spline (own 124 chain applied)."""
    from .foreign import Conic104, conic_curve

    if isinstance(record, Line):
        return _line_curve(record)
    if isinstance(record, Conic104):
        return conic_curve(record)
    return curve_geometry(record)


def _line_curve(record: Line) -> BSplineCurve:
    """A line of any form as the segment between its two points (forms 1 and 2 are
    unbounded; the segment is what the file defines), its 124 chain applied."""
    P = np.stack([record.start, record.end])
    if not np.any(P[0] != P[1]):
        raise IgesError(f"{record.describe()}: the two points coincide")
    return BSplineCurve(1, [0.0, 0.0, 1.0, 1.0], _transform(record, P))


def _type_of(record) -> int:
    if isinstance(record, GenericEntity):
        return record.entity_type
    if isinstance(record, SkippedEntity):
        return record.entity_type
    return record.type_number


def _short(reason: str, limit: int = 200) -> str:
    reason = " ".join(str(reason).split())
    return reason if len(reason) <= limit else reason[: limit - 3] + "..."


# -- exact data of shown-as-mesh faces ---------------------------------------------------
def scale_record(record: Entity, k: float, memo: dict | None = None, parameter_space: bool = False):
    """A copy of ``record`` (and what it references) with model-space coordinates and 124
    translations times ``k``; parameter-space curves (142 B, 144 loops' B) are unchanged,
    so trimming stays exact. Entities shared in the graph stay shared."""
    memo = {} if memo is None else memo
    key = (id(record), parameter_space)
    if key in memo:
        return memo[key]
    s = 1.0 if parameter_space else k
    tr = record.transform
    new_tr = None if tr is None else scale_record(tr, k, memo, parameter_space)
    if isinstance(record, TransformationMatrix):
        out = replace(record, translation=record.translation * s, transform=new_tr)
    elif isinstance(record, Line):
        out = replace(record, start=record.start * s, end=record.end * s, transform=new_tr)
    elif isinstance(record, CircularArc):
        out = replace(record, center=record.center * s, start=record.start * s, end=record.end * s,
                      z=record.z * s, transform=new_tr)
    elif isinstance(record, (BSplineCurve126, BSplineSurface128)):
        out = replace(record, control_points=record.control_points * s, transform=new_tr)
    elif isinstance(record, ParametricSpline):
        out = replace(record, coefficients=record.coefficients * s, terminal=record.terminal * s, transform=new_tr)
    elif isinstance(record, ParametricSplineSurface):
        out = replace(record, coefficients=record.coefficients * s, transform=new_tr)
    elif isinstance(record, CompositeCurve):
        out = replace(record, curves=tuple(scale_record(c, k, memo, parameter_space) for c in record.curves),
                      transform=new_tr)
    elif isinstance(record, SurfaceOfRevolution):
        out = replace(record, axis=scale_record(record.axis, k, memo), generatrix=scale_record(record.generatrix, k, memo),
                      transform=new_tr)
    elif isinstance(record, CurveOnSurface):
        out = replace(
            record, surface=scale_record(record.surface, k, memo),
            parameter_curve=None if record.parameter_curve is None else scale_record(record.parameter_curve, k, memo, True),
            model_curve=None if record.model_curve is None else scale_record(record.model_curve, k, memo),
            transform=new_tr,
        )
    elif isinstance(record, TrimmedSurface):
        surface = scale_record(record.surface, k, memo)
        memo[(id(record.surface), False)] = surface
        out = replace(
            record, surface=surface,
            outer=None if record.outer is None else scale_record(record.outer, k, memo),
            inner=tuple(scale_record(c, k, memo) for c in record.inner), transform=new_tr,
        )
    else:
        raise IgesError(f"{record.describe()}: cannot be rewritten")
    object.__setattr__(out, "directory", None)
    memo[key] = out
    return out


def place_record(record: Entity, R: np.ndarray, t: np.ndarray, k: float) -> Entity:
    """``record`` scaled by ``k`` (:func:`scale_record`) then moved by the rigid map
    x -> R x + t (R orthogonal), as one 124 on the root composed with its own chain."""
    out = scale_record(record, k)
    A, b = _chain_matrix(out.transform)
    R = np.asarray(R, dtype=np.float64)
    A2, b2 = R @ A, R @ b + np.asarray(t, dtype=np.float64)
    if np.allclose(A2, np.eye(3), rtol=0, atol=1e-15) and not np.any(b2):
        return replace(out, transform=None)
    form = 0 if np.linalg.det(A2) > 0 else 1
    return replace(out, transform=TransformationMatrix(A2, b2, form))


def rigid_part(A: np.ndarray) -> tuple[np.ndarray, float]:
    """(R, s) with A = s R, R orthogonal, s > 0; IgesError when A is not a similarity."""
    A = np.asarray(A, dtype=np.float64)
    d = float(np.linalg.det(A))
    if not (math.isfinite(d) and d != 0.0):
        raise IgesError("the placement is singular")
    s = abs(d) ** (1.0 / 3.0)
    R = A / s
    if np.abs(R.T @ R - np.eye(3)).max() > 1e-9:
        raise IgesError("the placement scales unevenly (non-uniform scale or shear); a trimmed IGES face "
                        "cannot carry it exactly")
    return R, s


def exact_text(record: Entity, place: Placement, name: str) -> tuple[str | None, str]:
    """The exact data (:func:`records_to_json`, metres) of ``record`` placed by ``place``,
    or (None, reason). Not validated here: the writer validates it when it is exported."""
    try:
        R, s = rigid_part(place.A)
        # x -> f (s R y + b) = R (f s y) + f b for the record's own coordinates y
        placed = place_record(record, R, place.factor * place.b, place.factor * s)
        return records_to_json(replace(placed, label=name[:8])), ""
    except BladesmithError as exc:
        return None, _short(str(exc))


#: Records the exact data may hold, by class name.
_EXACT_CLASSES = {cls.__name__: cls for cls in (
    TransformationMatrix, Line, CircularArc, BSplineCurve126, BSplineSurface128, ParametricSpline,
    ParametricSplineSurface, CompositeCurve, SurfaceOfRevolution, CurveOnSurface, TrimmedSurface)}


def records_to_json(root: Entity) -> str:
    """A record graph as JSON: one entry per record (class, fields; arrays as exact float
    lists, references as indices of earlier entries), the root last. Floats round-trip
    exactly (Python writes the shortest repr)."""
    import json

    index: dict = {}
    table: list = []

    def enc(value):
        if isinstance(value, Entity):
            return {"ref": add(value)}
        if isinstance(value, np.ndarray):
            return {"array": [float(x) for x in value.ravel()], "shape": list(value.shape)}
        if isinstance(value, tuple):
            return {"tuple": [enc(v) for v in value]}
        if isinstance(value, np.generic):
            return value.item()
        if isinstance(value, (float, int, str)) or value is None:
            return value
        raise IgesError(f"cannot keep a {type(value).__name__} as exact data")

    def add(rec):
        if id(rec) in index:
            return index[id(rec)]
        if type(rec).__name__ not in _EXACT_CLASSES:
            raise IgesError(f"{rec.describe()}: no exact export for this entity type")
        fields = {}
        for f in fields_of(rec):
            if f.name == "directory" or not f.init:
                continue
            fields[f.name] = enc(getattr(rec, f.name))
        index[id(rec)] = len(table)
        table.append({"class": type(rec).__name__, "fields": fields})
        return index[id(rec)]

    add(root)
    return json.dumps({"bladesmith_exact": 1, "records": table, "root": index[id(root)]})


def records_from_json(text: str) -> Entity:
    """The root record of :func:`records_to_json` output. IgesError when damaged."""
    import json

    try:
        data = json.loads(text)
        table = data["records"]
        built: list = [None] * len(table)

        def dec(value):
            if isinstance(value, dict):
                if "ref" in value:
                    k = int(value["ref"])
                    if not 0 <= k < len(table) or built[k] is None:
                        raise IgesError("damaged exact data: a reference to a later record")
                    return built[k]
                if "array" in value:
                    return np.array(value["array"], dtype=np.float64).reshape(value["shape"])
                if "tuple" in value:
                    return tuple(dec(v) for v in value["tuple"])
                raise IgesError("damaged exact data: unknown value")
            return value

        for k, entry in enumerate(table):
            cls = _EXACT_CLASSES[entry["class"]]
            built[k] = cls(**{name: dec(v) for name, v in entry["fields"].items()})
        return built[int(data["root"])]
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise IgesError(f"damaged exact data on the object: {exc}") from None


def placed_exact_records(text: str, matrix, scale: float) -> list:
    """The exact record of ``text`` (:func:`records_to_json`) moved by the 4x4 object
    ``matrix`` (a similarity: rotation, uniform scale, translation) and scaled by ``scale``
    (metres to file units)."""
    M = np.asarray(matrix, dtype=np.float64)
    R, s = rigid_part(M[:3, :3])
    return [place_record(records_from_json(text), R, scale * M[:3, 3], scale * s)]


# -- entry points ------------------------------------------------------------------------
def import_model(model: IgesModel, file_bytes: int, tolerance: float = DISPLAY_TOLERANCE) -> ImportReport:
    """Items to create for a leniently read model, and the report. IgesError when nothing at
    all can be imported, the units are unknown, or the work exceeds the size budget."""
    units = units_of(model)
    budget = Budget(file_bytes)
    imp = _Importer(model, budget, tolerance)
    place = Placement(factor=units.factor)
    roots = model.roots
    from .foreign import Group402

    if model.dependent and not model.skipped and not any(
            isinstance(r, Group402) or _type_of(r) not in NO_GEOMETRY_TYPES for r in roots):
        # every unreferenced entity is flagged dependent (DE status): the flags are wrong,
        # so go by references alone, as OpenCASCADE does
        roots = replace(model, dependent=frozenset()).roots
    for record in roots:
        imp.root(record, place)
    counts = defaultdict(int)
    for it in imp.items:
        counts[it.kind] += 1
    report = ImportReport(imp.items, units, dict(imp.skipped), imp.notes, dict(counts))
    if not imp.items:
        where = f"{model.path}: " if model.path else ""
        why = report.skipped_summary() or "the file has no entities"
        raise IgesError(f"{where}nothing to import; skipped: {why}")
    return report


def import_path(path, tolerance: float = DISPLAY_TOLERANCE) -> ImportReport:
    """Read ``path`` leniently and convert it (:func:`import_model`)."""
    from .reader import read_iges

    model = read_iges(path, strict=False)
    return import_model(model, os.path.getsize(os.fspath(path)), tolerance)
