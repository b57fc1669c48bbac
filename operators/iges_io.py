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

Import (:func:`import_file`) reads leniently through :mod:`..iges.importer`: exact NURBS
objects at the file's units and placement, trimmed faces as meshes inside their loops
that keep the exact 144 as ``bladesmith_iges_exact`` (export writes it back exactly, moved
with the object), and a report of every entity type skipped and why. A refusal leaves
the scene as it was.
"""
from __future__ import annotations

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from ..geometry.errors import BladesmithError
from ..geometry.nurbs import BSplineCurve, BSplineSurface
from ..iges import (
    METRES_PER_UNIT,
    curve_from_geometry,
    surface_from_geometry,
    write_iges,
)
from ..iges.convert import surface_pieces
from .nurbs_objects import curve_to_object, object_to_geometry, remove_object, surface_to_object
from .progress import progress_callback

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


def _propeller_records(root, units: str, full_propeller: bool = False, split_edges: bool = True) -> list:
    """Hally §11 records of a smoothed propeller: the reference blade's five surfaces (from
    their stored float64 data) and the hub sector of the model the root's definition makes,
    trimmed by the blade root edge itself. ``full_propeller``: all Z blades and the whole
    hub instead (:func:`..iges.propeller.full_propeller_iges_entities`), one closed shell;
    ``"SOLID"``: the same faces as one IGES 186 manifold solid B-rep. ``split_edges``: the
    leading-edge, trailing-edge and tip surfaces as two faces each, cut exactly along the
    blade's edge (:func:`..geometry.propeller.blade_surfaces.split_at_edges`), so that a
    mesher puts nodes on the edge instead of folding triangles across its tiny radius."""
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
        return (full_propeller_brep_entities(model, surfaces, sector, units.lower(), split_edges=split_edges),
                sector.warnings)
    if full_propeller:
        return (full_propeller_iges_entities(model, surfaces, sector, units.lower(), split_edges=split_edges),
                sector.warnings)
    return propeller_iges_entities(model, surfaces, sector, units.lower(), split_edges=split_edges), sector.warnings


def export_objects(objects, filepath: str, units: str = "M", progress=None, full_propeller: bool = False,
                   split_edges: bool = True) -> dict:
    """Write the NURBS of ``objects`` to ``filepath`` (atomically). Returns counts (and
    ``warnings``, a list of messages with figures).

    full_propeller: smoothed propellers go out whole (Z blades and the whole hub, one closed
    shell) instead of as Hally's reference blade and hub sector; "SOLID": as one IGES 186
    manifold solid B-rep. split_edges: their leading-edge, trailing-edge and tip surfaces
    go out as two faces each, cut along the blade's edge (False: Hally's five surfaces).

    Raises :class:`BladesmithError` (nothing is written then) when an object cannot be
    expressed exactly or the data is inconsistent.
    """
    from . import propeller

    scale = 1.0 / METRES_PER_UNIT[units.lower()]
    records, counts = [], {"surfaces": 0, "curves": 0, "objects": 0, "propellers": 0, "trimmed": 0, "warnings": []}
    roots = _smoothed_propeller_roots(objects)
    for root in roots:
        found, warnings = _propeller_records(root, units, full_propeller, split_edges)
        counts["warnings"] += [f"propeller '{root.name}': {w}" for w in warnings]
        records.extend(found)
        counts["propellers"] += 1
        faces = found[0].shell.faces if full_propeller == "SOLID" else found
        counts["surfaces"] += len(faces) - 1
        counts["trimmed"] += 1
    objects = [o for o in objects if (o.type in EXPORTABLE_TYPES or o.get(EXACT_KEY) is not None)
               and propeller.find_root(o) not in roots]
    for i, obj in enumerate(objects):
        if obj.get(EXACT_KEY) is not None:
            # an imported trimmed face (or surface shown as a mesh): its exact entity
            from ..iges.importer import placed_exact_records

            try:
                found = placed_exact_records(str(obj[EXACT_KEY]), np.array(obj.matrix_world), scale)
            except BladesmithError as exc:
                raise type(exc)(f"object '{obj.name}': {exc}") from None
            records.extend(found)
            counts["trimmed" if any(r.type_number == 144 for r in found) else "surfaces"] += len(found)
            counts["objects"] += 1
            continue
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


#: Custom property of an imported mesh that stands for an exact entity (a trimmed face, or
#: a surface Blender cannot show): the IGES text of that entity in metres, for export.
EXACT_KEY = "bladesmith_iges_exact"


def _mesh_to_object(item, collection):
    """A MESH object of an import item's triangles, its exact entity stored on it."""
    mesh = bpy.data.meshes.new(item.name)
    obj = None
    try:
        V = np.asarray(item.mesh.vertices, dtype=np.float64)
        F = np.asarray(item.mesh.triangles, dtype=np.int64)
        mesh.vertices.add(len(V))
        mesh.vertices.foreach_set("co", V.astype(np.float32).ravel())
        mesh.loops.add(3 * len(F))
        mesh.loops.foreach_set("vertex_index", F.astype(np.int32).ravel())
        mesh.polygons.add(len(F))
        mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * len(F), 3, dtype=np.int32))
        mesh.polygons.foreach_set("loop_total", np.full(len(F), 3, dtype=np.int32))
        mesh.update(calc_edges=True)
        mesh.validate()
        obj = bpy.data.objects.new(item.name, mesh)
        if item.exact is not None:
            obj[EXACT_KEY] = item.exact
        (collection or bpy.context.scene.collection).objects.link(obj)
    except BaseException:
        if obj is not None:
            bpy.data.objects.remove(obj, do_unlink=True)
        if mesh.users == 0:
            bpy.data.meshes.remove(mesh)
        raise
    return obj


def import_file(filepath: str, collection, progress=None) -> dict:
    """Create objects for the curves and surfaces of an IGES file in ``collection``.

    The file is read leniently (:func:`..iges.importer.import_path`): units and placement
    applied, unsupported or malformed entities skipped and reported, trimmed faces as
    meshes inside their loops that keep the exact 144 for export. Returns counts and the
    report; on any error the objects made so far are removed and the error propagates, so
    the scene is unchanged.
    """
    from ..iges.importer import import_path, surface_as_mesh

    report = import_path(filepath)
    created = []
    counts = {"surfaces": 0, "curves": 0, "trimmed": 0, "meshed": 0, "notes": list(report.notes)}
    try:
        for i, item in enumerate(report.items):
            if item.kind == "surface":
                try:
                    created.append(surface_to_object(item.geometry, item.name, collection))
                    counts["surfaces"] += 1
                except BladesmithError as exc:
                    # Blender cannot show this one as NURBS: show a mesh, keep it exact
                    mesh_item = surface_as_mesh(item.geometry, item.name)
                    created.append(_mesh_to_object(mesh_item, collection))
                    counts["meshed"] += 1
                    counts["notes"].append(f"{item.name}: shown as a mesh ({exc})")
            elif item.kind == "curve":
                created.append(curve_to_object(item.geometry, item.name, collection))
                counts["curves"] += 1
            else:
                created.append(_mesh_to_object(item, collection))
                counts["trimmed" if item.trimmed else "meshed"] += 1
            if item.note:
                counts["notes"].append(f"{item.name}: {item.note}")
            if progress:
                progress((i + 1) / len(report.items))
    except BaseException:
        for obj in created:
            remove_object(obj)
        raise
    counts["objects"] = created
    counts["report"] = report
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
    split_edges: BoolProperty(
        name="Split Edge Surfaces",
        description="Write each smoothed propeller blade's leading-edge, trailing-edge and tip surfaces as two "
                    "faces, cut exactly along the blade's edge, so that meshers put nodes on the edge instead of "
                    "folding triangles across its tiny radius near the tip (off: Hally's five surfaces)",
        default=True,
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
                                    else self.full_propeller, split_edges=self.split_edges)
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
        report = counts["report"]
        u = report.units
        message = (f"Imported {counts['surfaces']} surfaces, {counts['trimmed']} trimmed faces (meshes inside "
                   f"their trim loops, exact data kept) and {counts['curves']} curves; units {u.name} "
                   f"(x {u.factor:g} m)")
        if counts["meshed"]:
            message += f"; {counts['meshed']} surfaces shown as meshes"
        if report.skipped:
            message += f"; skipped {report.skipped_summary()}"
        self.report({"WARNING"} if report.skipped else {"INFO"}, message)
        for note in counts["notes"]:
            self.report({"INFO"}, note)
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
