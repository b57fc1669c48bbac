"""The Sweep panel (View3D > Sidebar > Bladesmith): pick a sweep folder and a variant,
and load that variant's definition into the scene (``bladesmith.load_sweep_variant``)."""
import bpy
from bpy.props import IntProperty, StringProperty


class BLADESMITH_PT_sweep(bpy.types.Panel):
    bl_label = "Design Sweep"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Bladesmith"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        scene = context.scene
        col = self.layout.column()
        col.prop(scene, "bladesmith_sweep_folder", text="Folder")
        col.prop(scene, "bladesmith_sweep_variant", text="Variant")
        op = col.operator("bladesmith.load_sweep_variant", text="Load Variant", icon="IMPORT")
        op.directory = scene.bladesmith_sweep_folder
        op.variant = scene.bladesmith_sweep_variant


_classes = (BLADESMITH_PT_sweep,)
_register, _unregister = bpy.utils.register_classes_factory(_classes)


def register():
    bpy.types.Scene.bladesmith_sweep_folder = StringProperty(
        name="Sweep Folder", description="Folder written by the sweep command (holds sweep.json)", subtype="DIR_PATH")
    bpy.types.Scene.bladesmith_sweep_variant = IntProperty(
        name="Variant", description="Design index of the variant (the metrics table's 'variant' column)", min=0)
    _register()


def unregister():
    _unregister()
    del bpy.types.Scene.bladesmith_sweep_variant
    del bpy.types.Scene.bladesmith_sweep_folder
