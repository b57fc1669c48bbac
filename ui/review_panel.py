"""The curvature review panel (3D View > Sidebar > Bladesmith): run the review and read
its numbers per surface: principal curvature range, total MVS, strain energy and the sign
changes along iso lines, the lines with extra ones shown in red (``alert``)."""
import json

import bpy

#: The review collection and the property names (kept in step with
#: :mod:`..operators.curvature_review`, which owns them).
REVIEW_COLLECTION = "Bladesmith Review"
NUMBERS_KEY = "bladesmith_review"
SETTINGS_KEY = "bladesmith_review_settings"


class BLADESMITH_PT_curvature_review(bpy.types.Panel):
    bl_label = "Curvature Review"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Bladesmith"

    def draw(self, context):
        layout = self.layout
        row = layout.row(align=True)
        row.operator("bladesmith.curvature_review", icon="SHADING_RENDERED")
        row.operator("bladesmith.clear_curvature_review", text="", icon="TRASH")
        coll = bpy.data.collections.get(REVIEW_COLLECTION)
        if coll is None:
            layout.label(text="No review yet: select curves, surfaces or a propeller")
            return
        settings = json.loads(coll.get(SETTINGS_KEY, "{}"))
        if settings:
            lo, hi = settings["limits"]
            layout.label(text=f"{settings['quantity']}: limits [{lo:.3g}, {hi:.3g}], {100 * settings.get('clipped', 0):.1f}% clipped")
            if settings.get("sign_convention"):
                layout.label(text=settings["sign_convention"])
            if settings.get("excluded_from_limits"):
                layout.label(text="not in the limits: " + ", ".join(settings["excluded_from_limits"]))
            if settings.get("hub_limits"):
                lo, hi = settings["hub_limits"]
                layout.label(text=f"hub on its own limits [{lo:.3g}, {hi:.3g}]")
        for obj in sorted(coll.objects, key=lambda o: o.name):
            text = obj.get(NUMBERS_KEY)
            if not text:
                continue
            numbers = json.loads(text)
            if not numbers:
                continue
            box = layout.box()
            box.label(text=numbers["name"], icon="SURFACE_DATA")
            col = box.column(align=True)
            col.label(text=f"κ min {numbers['k_min']:.4g}  max {numbers['k_max']:.4g} 1/m")
            col.label(text=f"MVS {numbers['mvs']:.4g} 1/m²   strain energy {numbers['strain_energy']:.4g}")
            for family in numbers["iso_lines"]:
                row = col.row(align=True)
                row.label(text=f"{family['direction']} lines:")
                for count, extra in zip(family["counts"], family["extra"]):
                    cell = row.row(align=True)
                    cell.alert = extra > 0
                    cell.label(text=str(count))


_classes = (BLADESMITH_PT_curvature_review,)
register, unregister = bpy.utils.register_classes_factory(_classes)
