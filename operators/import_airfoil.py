"""``bpy.ops.bladesmith.import_airfoil``: an airfoil .dat file as a curve object.

Selig, reverse-Selig and Lednicer files are detected by
:func:`bladesmith.geometry.sections.airfoil_file.read_airfoil` (duplicates and NaN are
refused with the file and line). The outline is normalised to unit chord, scaled by
``chord`` and shown as the cubic B-spline through the points (chord-length parameters,
NURBS Book Alg. A9.1) or as a polyline. The normalised points are kept on the object as
the custom property ``bladesmith_airfoil`` so ``bladesmith.smooth_curve`` smooths the
tabulated data itself (Hvid 1993 §3.2.1) rather than a sampling of the display curve.
"""

import pathlib

import bpy
import numpy as np
from bpy.props import BoolProperty, FloatProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

from ..geometry.errors import BladesmithError
from ..geometry.nurbs import interpolate
from ..geometry.sections.airfoil_file import read_airfoil
from .hvid_properties import JOBCARD, HvidProperties, draw_jobcard
from .nurbs_objects import curve_to_object, remove_object
from .scene_guard import unchanged_on_refusal

#: Custom property holding the tabulated, unit-chord airfoil on imported objects.
AIRFOIL_KEY = "bladesmith_airfoil"


def airfoil_to_object(airfoil, chord: float = 1.0, as_polyline: bool = False, collection=None):
    """A CURVE object of ``airfoil`` (Selig order: TE, upper side, LE, lower side, TE) at
    ``chord`` metres in the XY plane, with the unit-chord points stored (``AIRFOIL_KEY``)."""
    points = airfoil.outline
    name = pathlib.Path(airfoil.path).stem or airfoil.name.strip()[:60]
    if as_polyline:
        data = bpy.data.curves.new(name, "CURVE")
        data.dimensions = "3D"
        spline = data.splines.new("POLY")
        spline.points.add(len(points) - 1)
        rows = np.zeros((len(points), 4))
        rows[:, :2] = chord * points
        rows[:, 3] = 1.0
        spline.points.foreach_set("co", rows.astype(np.float32).ravel())
        obj = bpy.data.objects.new(name, data)
        (collection or bpy.context.scene.collection).objects.link(obj)
    else:
        obj = curve_to_object(interpolate(chord * points, 3), name, collection)
    obj[AIRFOIL_KEY] = {
        "name": airfoil.name,
        "format": airfoil.format,
        "path": str(airfoil.path),
        "chord": float(chord),
        "points": [float(v) for v in points.ravel()],
    }
    return obj


def stored_airfoil(obj) -> tuple[np.ndarray, float] | None:
    """(unit-chord outline (m, 2), chord) stored by :func:`airfoil_to_object`, or None."""
    record = obj.get(AIRFOIL_KEY) if obj is not None else None
    if record is None:
        return None
    points = np.array(record["points"], dtype=np.float64).reshape(-1, 2)
    return points, float(record["chord"])


class BLADESMITH_OT_import_airfoil(bpy.types.Operator, ImportHelper, HvidProperties):
    """Import an airfoil coordinate file (Selig, reverse Selig or Lednicer .dat) as a curve at unit chord"""

    bl_idname = "bladesmith.import_airfoil"
    bl_label = "Import Airfoil (.dat)"
    bl_options = {"REGISTER", "UNDO"}

    filename_ext = ".dat"
    filter_glob: StringProperty(default="*.dat;*.txt", options={"HIDDEN"})
    chord: FloatProperty(
        name="Chord", description="Chord length of the curve (the file is normalised to unit chord first)",
        default=1.0, min=1e-6, soft_max=100.0, unit="LENGTH",
    )
    as_polyline: BoolProperty(
        name="Polyline", description="Show the tabulated points as a polyline instead of the cubic through them",
        default=False,
    )

    smooth: BoolProperty(
        name="Smooth (Hvid)",
        description="Smooth the imported airfoil with Hvid's smoothfoil (the settings below), as Smooth Curve (Hvid) does",
        default=False,
    )

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "chord")
        layout.prop(self, "as_polyline")
        layout.prop(self, "smooth")
        if self.smooth:
            draw_jobcard(layout.box(), self, "AIRFOIL", show_kind=False)

    @unchanged_on_refusal
    def execute(self, context):
        try:
            airfoil = read_airfoil(self.filepath)
            obj = airfoil_to_object(airfoil, self.chord, self.as_polyline, context.collection)
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        selected = list(context.selected_objects)
        for other in selected:
            other.select_set(False)
        obj.select_set(True)
        context.view_layer.objects.active = obj
        if self.smooth:
            jobcard = {name: getattr(self, name) for name in JOBCARD if name != "kind"}
            try:
                bpy.ops.bladesmith.smooth_curve(kind="AIRFOIL", **jobcard)
            except RuntimeError as exc:  # the smoother's own refusal, reported as an error
                remove_object(obj)
                for other in selected:
                    other.select_set(True)
                self.report({"ERROR"}, f"{self.filepath}: not imported, the smoothing failed: {exc}")
                return {"CANCELLED"}
        te = airfoil.trailing_edge_thickness
        self.report(
            {"INFO"},
            f"Imported {airfoil.name!r} ({airfoil.format}, {len(airfoil.outline)} points, "
            f"{'sharp' if airfoil.sharp_trailing_edge else f'blunt {te:.4g} c'} trailing edge)",
        )
        return {"FINISHED"}


def _menu_import(self, context):
    self.layout.operator(BLADESMITH_OT_import_airfoil.bl_idname, text="Airfoil (.dat)")


_register, _unregister = bpy.utils.register_classes_factory((BLADESMITH_OT_import_airfoil,))


def register():
    _register()
    bpy.types.TOPBAR_MT_file_import.append(_menu_import)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(_menu_import)
    _unregister()
