"""Loading one variant of a design sweep into the scene: ``bpy.ops.bladesmith.load_sweep_variant``.

A sweep folder (written by ``scripts/sweep.py``, see README "Design sweeps") keeps every
variant's definition as ``variants/<key>/definition.toml``. This operator finds the
variant by its design index or key (:func:`..sweep.folder.find_variant`) and hands that
file to the kind's own operator, ``add_propeller`` (with the variant's smoothing
settings), ``add_wind_blade`` or ``add_impeller``, which validate it and build the
objects, or report the error and leave the scene unchanged.
"""
import bpy
from bpy.props import IntProperty, StringProperty

from ..geometry.errors import BladesmithError
from ..sweep.folder import find_variant

#: add_propeller properties a propeller sweep records in its settings (fractions of D).
PROPELLER_SETTINGS = ("delta_c", "tip_smoothing_distance", "edge_smoothing_distance", "transition_s",
                      "filter_strength", "filter_iterations", "tolerance")


class BLADESMITH_OT_load_sweep_variant(bpy.types.Operator):
    """Add one variant of a design sweep to the scene, from its definition in the sweep folder"""

    bl_idname = "bladesmith.load_sweep_variant"
    bl_label = "Load Sweep Variant"
    bl_options = {"REGISTER", "UNDO"}

    directory: StringProperty(name="Sweep Folder", description="Folder written by the sweep command (holds sweep.json)",
                              subtype="DIR_PATH", default="")
    variant: IntProperty(name="Variant", description="Design index of the variant (the metrics table's 'variant')",
                         default=0, min=0)
    key: StringProperty(name="Key", description="Key of the variant (or a unique prefix); used instead of the index "
                        "when given", default="")

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT"

    def execute(self, context):
        try:
            entry = find_variant(bpy.path.abspath(self.directory), self.variant, self.key)
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        path = str(entry.definition)
        if entry.kind == "propeller":
            smoothing = {k: entry.settings[k] for k in PROPELLER_SETTINGS if k in entry.settings}
            result = bpy.ops.bladesmith.add_propeller(definition=path, smooth_tip=True, **smoothing)
        elif entry.kind == "wind_blade":
            result = bpy.ops.bladesmith.add_wind_blade(definition=path)
        elif entry.kind == "impeller":
            result = bpy.ops.bladesmith.add_impeller(definition=path)
        else:
            self.report({"ERROR"}, f"{self.directory}: unknown sweep kind {entry.kind!r}")
            return {"CANCELLED"}
        if result != {"FINISHED"}:
            return {"CANCELLED"}
        note = f" (the sweep recorded it as failed: {entry.error})" if entry.status == "failed" else ""
        values = ", ".join(f"{k} = {v:.6g}" if isinstance(v, float) else f"{k} = {v}" for k, v in entry.values.items())
        self.report({"INFO"}, f"sweep variant {entry.index} ({entry.key}): {values}{note}")
        return {"FINISHED"}


_classes = (BLADESMITH_OT_load_sweep_variant,)
_register, _unregister = bpy.utils.register_classes_factory(_classes)


def register():
    _register()


def unregister():
    _unregister()
