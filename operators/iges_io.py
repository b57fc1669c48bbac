"""File > Export > IGES and File > Import > IGES.

Export writes every selected (or every) NURBS surface and curve object: Bladesmith objects
from their exact float64 data, hand-edited or native Blender NURBS, poly and Bezier curves
from their Blender data with the knot vectors Blender really uses
(:func:`..operators.nurbs_objects.object_to_geometry`). Object transforms are applied to
the control points (NURBS are affine invariant, so this is exact up to the float32
matrix Blender stores; identity transforms are skipped and cost nothing). Surfaces that
are closed, or only C0 across a knot, are written in exact pieces
(:func:`..iges.convert.surface_pieces`): OpenCASCADE would otherwise repair them and warn.

A tip-smoothed propeller (any of its objects selected, or all) is written the way
Hally (2013) §11 prescribes instead of object by object: the five surfaces of the
reference blade as 128 and the hub sector trimmed by the blade footprint as a 144 over a
120, in the propeller's own coordinates, the hub trimmed by the blade root edge itself (the
blade surfaces' root rows as the trimming loop's 3-D curves). With ``full_propeller=True``
all Z blades and the whole hub (one trimmed full-turn 120 with Z root holes) are written,
faces that sew into one closed shell.

Import creates exact NURBS objects for 126/128 (and 100, 110, 112, 114, 120 converted to
B-splines); a trimmed surface (144) comes in as its untrimmed surface plus its trimming
curves, and the report says so. A failure leaves the scene as it was.
"""
from __future__ import annotations

import os

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from ..geometry.errors import BladesmithError
from ..geometry.nurbs import BSplineCurve, BSplineSurface
from ..geometry.nurbs.fitting import approximate
from ..iges import (
    METRES_PER_UNIT,
    TrimmedSurfaceGeometry,
    curve_from_geometry,
    read_iges,
    surface_from_geometry,
    write_iges,
)
from ..iges.convert import surface_pieces, surface_points, surface_range
from .nurbs_objects import curve_to_object, object_to_geometry, remove_object, surface_to_object
from .progress import progress_callback

#: Trimming curves of an imported 144 are approximated on the surface to this fraction of
#: the surface's size (they have no exact model-space form when the file gives none).
TRIM_CURVE_TOL = 1e-6

EXPORTABLE_TYPES = {"SURFACE", "CURVE"}


def _world_geometry(obj) -> list:
    """The object's curves and surfaces in world coordinates, float64."""
    pieces = object_to_geometry(obj)
    M = np.array(obj.matrix_world, dtype=np.float64)
    if np.array_equal(M, np.eye(4)):
        return pieces
    out = []
    for g in pieces:
        P = g.control_points
        P3 = np.zeros(P.shape[:-1] + (3,))
        P3[..., : P.shape[-1]] = P
        moved = P3 @ M[:3, :3].T + M[:3, 3]
        if isinstance(g, BSplineSurface):
            out.append(BSplineSurface(g.degree_u, g.degree_v, g.knots_u, g.knots_v, moved, g.weights))
        else:
            out.append(BSplineCurve(g.degree, g.knots, moved, g.weights))
    return out


def _smoothed_propeller_roots(objects) -> list:
    """The tip-smoothed propellers that any of ``objects`` belongs to."""
    from . import propeller

    roots = []
    for obj in objects:
        root = propeller.find_root(obj)
        if root is not None and root.bladesmith_propeller.smooth_tip and root not in roots:
            roots.append(root)
    return roots


def _propeller_records(root, units: str, full_propeller: bool = False) -> list:
    """Hally §11 records of a smoothed propeller: the reference blade's five surfaces (from
    their stored float64 data) and the hub sector of the model the root's definition makes,
    trimmed by the blade root edge itself. ``full_propeller``: all Z blades and the whole
    hub instead (:func:`..iges.propeller.full_propeller_iges_entities`), one closed shell;
    ``"SOLID"``: the same faces as one IGES 186 manifold solid B-rep."""
    from ..geometry.propeller.hub_sector import hub_sector
    from ..geometry.propeller.smoothing import SURFACE_NAMES
    from ..iges.propeller import full_propeller_brep_entities, full_propeller_iges_entities, propeller_iges_entities
    from . import propeller

    settings = root.bladesmith_propeller
    model = propeller.build_model(propeller.settings_to_definition(settings))
    parts = propeller.propeller_parts(root)
    patches = sorted((patch, obj) for (part, patch, blade), obj in parts.items() if part == "blade" and blade == 0)
    if len(patches) != len(SURFACE_NAMES):
        raise BladesmithError(
            f"propeller '{root.name}': expected {len(SURFACE_NAMES)} blade surfaces, found {len(patches)}; "
            "regenerate it"
        )
    surfaces = {}
    for name, (_, obj) in zip(SURFACE_NAMES, patches):
        (surface,) = object_to_geometry(obj)
        surfaces[name] = surface
    tolerance = propeller.smoothing_settings(propeller.smoothing_values(settings), model.definition.diameter)["tolerance"]
    sector = hub_sector(model, tolerance=tolerance, blade=surfaces)
    if full_propeller == "SOLID":
        return full_propeller_brep_entities(model, surfaces, sector, units.lower()), sector.warnings
    if full_propeller:
        return full_propeller_iges_entities(model, surfaces, sector, units.lower()), sector.warnings
    return propeller_iges_entities(model, surfaces, sector, units.lower()), sector.warnings


def export_objects(objects, filepath: str, units: str = "M", progress=None, full_propeller: bool = False) -> dict:
    """Write the NURBS of ``objects`` to ``filepath`` (atomically). Returns counts (and
    ``warnings``, a list of messages with figures).

    full_propeller: smoothed propellers go out whole (Z blades and the whole hub, one closed
    shell) instead of as Hally's reference blade and hub sector; "SOLID": as one IGES 186
    manifold solid B-rep.

    Raises :class:`BladesmithError` (nothing is written then) when an object cannot be
    expressed exactly or the data is inconsistent.
    """
    from . import propeller

    scale = 1.0 / METRES_PER_UNIT[units.lower()]
    records, counts = [], {"surfaces": 0, "curves": 0, "objects": 0, "propellers": 0, "trimmed": 0, "warnings": []}
    roots = _smoothed_propeller_roots(objects)
    for root in roots:
        found, warnings = _propeller_records(root, units, full_propeller)
        counts["warnings"] += [f"propeller '{root.name}': {w}" for w in warnings]
        records.extend(found)
        counts["propellers"] += 1
        faces = found[0].shell.faces if full_propeller == "SOLID" else found
        counts["surfaces"] += len(faces) - 1
        counts["trimmed"] += 1
    objects = [o for o in objects if o.type in EXPORTABLE_TYPES and propeller.find_root(o) not in roots]
    for i, obj in enumerate(objects):
        try:
            pieces = _world_geometry(obj)
        except BladesmithError as exc:
            raise type(exc)(f"object '{obj.name}': {exc}") from None
        # closed or C0 surfaces go out in pieces, which readers take without repair
        pieces = [q for g in pieces for q in (surface_pieces(g) if isinstance(g, BSplineSurface) else [g])]
        for k, g in enumerate(pieces):
            label = obj.name if len(pieces) == 1 else f"{obj.name}.{k}"
            if isinstance(g, BSplineSurface):
                records.append(surface_from_geometry(g, scale=scale, label=label[:8]))
                counts["surfaces"] += 1
            else:
                records.append(curve_from_geometry(g, scale=scale, label=label[:8]))
                counts["curves"] += 1
        counts["objects"] += 1
        if progress:
            progress((i + 1) / len(objects))
    if not records:
        raise BladesmithError("nothing to export: no NURBS surface or curve objects")
    write_iges(filepath, records, units=units.lower())
    return counts


def _trim_curve_on_surface(surface_record, curve: BSplineCurve, size: float) -> BSplineCurve:
    """A model-space B-spline of S(c(t)) within :data:`TRIM_CURVE_TOL` of ``size``.

    The loop ``c`` is in the IGES parameter space of the basis surface record (for a 120,
    v is the rotation angle), so S is evaluated through the record, not through its
    NURBS conversion, whose parameterisation differs."""
    a, b = curve.domain
    (u0, u1), (v0, v1) = surface_range(surface_record)

    def on_surface(t):
        uv = curve.evaluate(t)
        return surface_points(surface_record, np.clip(uv[..., 0], u0, u1), np.clip(uv[..., 1], v0, v1))

    return approximate(on_surface, TRIM_CURVE_TOL * size, degree=3, domain=(a, b))


def import_file(filepath: str, collection, progress=None) -> dict:
    """Create objects for the curves and surfaces of an IGES file in ``collection``.

    Returns counts; on any :class:`BladesmithError` the objects made so far are removed
    and the error propagates, so the scene is unchanged.
    """
    model = read_iges(filepath)
    unit = model.header.unit_name.upper() if model.header.unit_name else "M"
    factor = METRES_PER_UNIT.get(unit.lower(), 1.0) / (model.header.model_scale or 1.0)
    items = model.to_geometry()
    created = []
    counts = {"surfaces": 0, "curves": 0, "trimmed": 0, "trim_curves": 0}
    base = os.path.splitext(os.path.basename(filepath))[0]

    def scaled(g):
        P = np.asarray(g.control_points) * factor
        if isinstance(g, BSplineSurface):
            return BSplineSurface(g.degree_u, g.degree_v, g.knots_u, g.knots_v, P, g.weights)
        return BSplineCurve(g.degree, g.knots, P, g.weights)

    try:
        for i, (record, geometry) in enumerate(items):
            name = (record.label or f"{base}.{record.type_number}").strip() or base
            if isinstance(geometry, TrimmedSurfaceGeometry):
                created.append(surface_to_object(scaled(geometry.surface), name, collection))
                counts["trimmed"] += 1
                for loop in ([geometry.outer] if geometry.outer else []) + list(geometry.inner):
                    for c in loop:
                        trim = _trim_curve_on_surface(record.surface, c, geometry.surface.size())
                        created.append(curve_to_object(scaled(trim), f"{name}.trim", collection))
                        counts["trim_curves"] += 1
            elif isinstance(geometry, BSplineSurface):
                created.append(surface_to_object(scaled(geometry), name, collection))
                counts["surfaces"] += 1
            else:
                for c in geometry if isinstance(geometry, list) else [geometry]:
                    for piece in c if isinstance(c, list) else [c]:
                        created.append(curve_to_object(scaled(piece), name, collection))
                        counts["curves"] += 1
            if progress:
                progress((i + 1) / len(items))
    except BladesmithError:
        for obj in created:
            remove_object(obj)
        raise
    counts["objects"] = created
    return counts


UNIT_ITEMS = [
    ("M", "Metres", "Write coordinates in metres (IGES unit flag 6)"),
    ("MM", "Millimetres", "Write coordinates in millimetres (IGES unit flag 2)"),
    ("IN", "Inches", "Write coordinates in inches (IGES unit flag 1)"),
]


class EXPORT_SCENE_OT_iges(bpy.types.Operator, ExportHelper):
    """Write NURBS surfaces and curves to an IGES 5.3 file"""

    bl_idname = "export_scene.iges"
    bl_label = "Export IGES"
    bl_options = {"PRESET"}

    filename_ext = ".igs"
    filter_glob: StringProperty(default="*.igs;*.iges", options={"HIDDEN"})
    use_selection: BoolProperty(name="Selected Only", description="Export the selected objects only", default=False)
    units: EnumProperty(name="Units", items=UNIT_ITEMS, default="M")
    full_propeller: BoolProperty(
        name="Full Propeller",
        description="Write smoothed propellers whole: all blades and the whole hub, faces that sew into one "
                    "closed shell (otherwise Hally's reference blade and hub sector)",
        default=False,
    )
    brep_solid: BoolProperty(
        name="As Solid (186)",
        description="With Full Propeller: write the faces as one IGES 186 manifold solid B-rep "
                    "(vertices, edges, loops, faces, shell) instead of loose faces",
        default=False,
    )

    def execute(self, context):
        objects = context.selected_objects if self.use_selection else context.scene.objects
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            counts = export_objects(objects, self.filepath, self.units, progress_callback(wm),
                                    full_propeller="SOLID" if self.full_propeller and self.brep_solid
                                    else self.full_propeller)
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        message = f"Wrote {counts['surfaces']} surfaces, {counts['trimmed']} trimmed surfaces and {counts['curves']} curves"
        if counts["propellers"] and self.full_propeller:
            message += f" ({counts['propellers']} smoothed propeller(s) whole: all blades and the whole hub"
            message += ", as one 186 solid)" if self.brep_solid else ")"
        elif counts["propellers"]:
            message += (
                f" ({counts['propellers']} smoothed propeller(s) as reference blade and trimmed hub sector, "
                "Hally 2013 §11)"
            )
        for warning in counts["warnings"]:
            self.report({"WARNING"}, warning)
        self.report({"INFO"}, f"{message} to {self.filepath} ({self.units.lower()})")
        return {"FINISHED"}


class IMPORT_SCENE_OT_iges(bpy.types.Operator, ImportHelper):
    """Read the curves and surfaces of an IGES file as exact NURBS objects"""

    bl_idname = "import_scene.iges"
    bl_label = "Import IGES"
    bl_options = {"REGISTER", "UNDO"}

    filename_ext = ".igs"
    filter_glob: StringProperty(default="*.igs;*.iges", options={"HIDDEN"})

    def execute(self, context):
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            counts = import_file(self.filepath, context.collection, progress_callback(wm))
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        message = f"Imported {counts['surfaces']} surfaces and {counts['curves']} curves"
        if counts["trimmed"]:
            message += (
                f"; {counts['trimmed']} trimmed surfaces came in untrimmed, with their "
                f"{counts['trim_curves']} trimming curves as separate curve objects"
            )
        self.report({"INFO"}, message)
        return {"FINISHED"}


def _menu_export(self, context):
    self.layout.operator(EXPORT_SCENE_OT_iges.bl_idname, text="IGES (.igs/.iges)")


def _menu_import(self, context):
    self.layout.operator(IMPORT_SCENE_OT_iges.bl_idname, text="IGES (.igs/.iges)")


_register, _unregister = bpy.utils.register_classes_factory((EXPORT_SCENE_OT_iges, IMPORT_SCENE_OT_iges))


def register():
    _register()
    bpy.types.TOPBAR_MT_file_export.append(_menu_export)
    bpy.types.TOPBAR_MT_file_import.append(_menu_import)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(_menu_import)
    bpy.types.TOPBAR_MT_file_export.remove(_menu_export)
    _unregister()
