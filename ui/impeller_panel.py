"""Impeller panel: edit the skeletal data, β and δ of a Casey impeller live.

``Object.bladesmith_impeller`` holds the channel corner radii and axial positions, the
Bernstein coefficients of β(m̄) and δ(m̄) on hub and shroud, the four blade U values and
the standardisation factors (Casey 1983, Fig. 11: the master impeller trimmed to a channel
whose shroud, or hub, is moved by that fraction of the width; 1 = no cut).
Every edit calls :func:`on_edit`: the definition is rebuilt from the root's TOML with the
edited values, validated, and the children are regenerated
(:func:`..operators.impeller.regenerate`). Invalid values (crossing hub and shroud, LE
after TE, negative thickness, a factor whose new wall the blade rulings cannot reach)
leave the last good geometry and show the message, which names the field, in the panel.
A standardised impeller also shows the largest measured distance of the trimmed blade
edges from the new walls and the knot counts of the trimmed surfaces.
"""
import bpy
from bpy.props import BoolProperty, CollectionProperty, FloatProperty, PointerProperty, StringProperty

from ..operators.values import typed

from ..geometry.errors import BladesmithError

#: Lists edited in the panel: (property name, TOML section, TOML key).
LISTS = (
    ("hub_r", "channel", "hub_r"), ("hub_z", "channel", "hub_z"),
    ("shroud_r", "channel", "shroud_r"), ("shroud_z", "channel", "shroud_z"),
    ("beta_hub", "blade", "beta_hub"), ("beta_shroud", "blade", "beta_shroud"),
    ("thickness_hub", "blade", "thickness_hub"), ("thickness_shroud", "blade", "thickness_shroud"),
)
SCALARS = ("leading_edge_hub", "leading_edge_shroud", "trailing_edge_hub", "trailing_edge_shroud")
#: Standardisation factors: property name = key of the [standardisation] table.
FACTORS = ("shroud_factor", "hub_factor")


def standardisation_table(settings) -> dict:
    """The [standardisation] table of the panel's factors (keys at 1.0 left out)."""
    return {key: typed(getattr(settings, key)) for key in FACTORS if typed(getattr(settings, key)) != 1.0}


def on_edit(self, context):
    root = self.id_data  # the Object owning the group (items and the group alike)
    if root is None or not root.get("bladesmith_impeller_root"):
        return
    settings = root.bladesmith_impeller
    if settings.loading:
        return
    from ..operators.impeller import definition_from_root, regenerate

    data = definition_from_root(root)
    for name, section, key in LISTS:
        data[section][key] = [typed(item.value) for item in getattr(settings, name)]
    for key in SCALARS:
        data["blade"][key] = typed(getattr(settings, key))
    table = standardisation_table(settings)
    if table:
        data["standardisation"] = table
    else:
        data.pop("standardisation", None)
    try:
        model = regenerate(root, data, settings.full_wheel)
        settings.status = ""
        settings.standardisation_report = "" if model.standardisation is None else model.standardisation.summary()
    except BladesmithError as exc:
        settings.status = str(exc)


class BladesmithImpellerValue(bpy.types.PropertyGroup):
    value: FloatProperty(name="Value", update=on_edit, precision=5)


class BladesmithImpellerSettings(bpy.types.PropertyGroup):
    hub_r: CollectionProperty(type=BladesmithImpellerValue)
    hub_z: CollectionProperty(type=BladesmithImpellerValue)
    shroud_r: CollectionProperty(type=BladesmithImpellerValue)
    shroud_z: CollectionProperty(type=BladesmithImpellerValue)
    beta_hub: CollectionProperty(type=BladesmithImpellerValue)
    beta_shroud: CollectionProperty(type=BladesmithImpellerValue)
    thickness_hub: CollectionProperty(type=BladesmithImpellerValue)
    thickness_shroud: CollectionProperty(type=BladesmithImpellerValue)
    leading_edge_hub: FloatProperty(name="LE hub U", update=on_edit)
    leading_edge_shroud: FloatProperty(name="LE shroud U", update=on_edit)
    trailing_edge_hub: FloatProperty(name="TE hub U", update=on_edit)
    trailing_edge_shroud: FloatProperty(name="TE shroud U", update=on_edit)
    shroud_factor: FloatProperty(
        name="Shroud factor", default=1.0, min=0.0, max=2.0, soft_min=0.5, soft_max=1.2, step=1, precision=3,
        description="Standardisation (Casey 1983): trim the blades to a channel whose shroud is at this fraction "
                    "of the width from the hub (0.8 = a 20 % shroud cut, > 1 wider; 1 = the master)",
        update=on_edit)
    hub_factor: FloatProperty(
        name="Hub factor", default=1.0, min=0.0, max=2.0, soft_min=0.5, soft_max=1.2, step=1, precision=3,
        description="Standardisation (Casey 1983): trim the blades to a channel whose hub is at this fraction "
                    "of the width from the shroud (< 1 a hub cut; 1 = the master)",
        update=on_edit)
    standardisation_report: StringProperty(name="Standardisation", default="")
    full_wheel: BoolProperty(name="Full Wheel", default=True)
    loading: BoolProperty(default=False)
    status: StringProperty(name="Status", default="")

    def load(self, definition, full_wheel: bool, report: str = "") -> None:
        """Fill the group from a definition without triggering regeneration."""
        self.loading = True
        try:
            d = definition.to_dict()
            for name, section, key in LISTS:
                coll = getattr(self, name)
                coll.clear()
                for v in d[section][key]:
                    coll.add().value = float(v)
            for key in SCALARS:
                setattr(self, key, float(d["blade"][key]))
            for key in FACTORS:
                setattr(self, key, float(d.get("standardisation", {}).get(key, 1.0)))
            self.full_wheel = full_wheel
            self.status = ""
            self.standardisation_report = report
        finally:
            self.loading = False


class BLADESMITH_PT_impeller(bpy.types.Panel):
    bl_label = "Impeller (Casey)"
    bl_idname = "BLADESMITH_PT_impeller"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Bladesmith"

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and bool(obj.get("bladesmith_impeller_root"))

    def draw(self, context):
        settings = context.active_object.bladesmith_impeller
        layout = self.layout
        if settings.status:
            layout.label(text=settings.status, icon="ERROR")
        for name, _, _ in LISTS:
            box = layout.box()
            box.label(text=name.replace("_", " "))
            row = box.row(align=True)
            for item in getattr(settings, name):
                row.prop(item, "value", text="")
        col = layout.column(align=True)
        for key in SCALARS:
            col.prop(settings, key)
        box = layout.box()
        box.label(text="Standardisation")
        col = box.column(align=True)
        for key in FACTORS:
            col.prop(settings, key)
        if settings.standardisation_report:
            box.label(text=settings.standardisation_report, icon="INFO")


_classes = (BladesmithImpellerValue, BladesmithImpellerSettings, BLADESMITH_PT_impeller)
_register, _unregister = bpy.utils.register_classes_factory(_classes)


def register():
    _register()
    bpy.types.Object.bladesmith_impeller = PointerProperty(type=BladesmithImpellerSettings)


def unregister():
    del bpy.types.Object.bladesmith_impeller
    _unregister()
