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

The child panel "Channel walls" edits the wall angles (``[channel] hub_angle`` /
``shroud_angle``, one per corner: "Auto" writes "auto", otherwise the angle in degrees
from +z towards +r) and the bend fractions (``hub_fractions`` / ``shroud_fractions``,
[f_a, f_b] placing P_1 and P_3 of each bend; drawn for bends only). The angle of an Auto
corner shows the direction the built channel has there (:func:`corner_directions`), so
turning Auto off starts from the current shape.
"""
import bpy
import numpy as np
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty, FloatVectorProperty, IntProperty,
                       PointerProperty, StringProperty)

from ..operators.values import typed

from ..geometry.compressor.blade import MAX_PATCHES, PATCH_SPACINGS
from ..geometry.compressor.export import construction_summary
from ..geometry.errors import BladesmithError

#: Lists edited in the panel: (property name, TOML section, TOML key).
LISTS = (
    ("hub_r", "channel", "hub_r"), ("hub_z", "channel", "hub_z"),
    ("shroud_r", "channel", "shroud_r"), ("shroud_z", "channel", "shroud_z"),
    ("beta_hub", "blade", "beta_hub"), ("beta_shroud", "blade", "beta_shroud"),
    ("thickness_hub", "blade", "thickness_hub"), ("thickness_shroud", "blade", "thickness_shroud"),
)
SCALARS = ("leading_edge_hub", "leading_edge_shroud", "trailing_edge_hub", "trailing_edge_shroud")
#: [blade] settings edited in the panel (issue 18): property name = [blade] key.
BLADE_SETTINGS = ("count", "patches", "tolerance", "patch_spacing", "elements", "leading_edge_ratio",
                  "trailing_edge_ratio")
#: [splitter] settings: property "splitter_<key>" edits [splitter] <key>.
SPLITTER_SETTINGS = ("leading_edge_hub", "leading_edge_shroud", "pitch_fraction", "patches", "leading_edge_ratio")
#: Standardisation factors: property name = key of the [standardisation] table.
FACTORS = ("shroud_factor", "hub_factor")
#: Channel walls: the corner-angle and bend-fraction collections are ``{wall}_angle`` and
#: ``{wall}_fractions``, named as the [channel] keys they edit.
WALLS = ("hub", "shroud")
#: Channel patch degree of a bend (1 is a straight patch); see geometry/compressor/channel.py.
BEND_DEGREE = 4


def corner_directions(channel, degrees, wall: str) -> list:
    """The wall direction (deg from +z towards +r, atan2(dr, dz)) of the built channel at
    each corner of ``wall``. Next to a straight patch it is that patch's chord, computed as
    the channel does for an "auto" corner (so the value is the one it uses, bit for bit);
    elsewhere the polygon leg of the adjacent bend at that corner (the tangent the
    definition's angle gives, to rounding)."""
    string = channel.wall(wall)
    n = string.count
    out = []
    for k in range(n + 1):
        sides = [j for j in (k - 1, k) if 0 <= j < n]
        straight = [j for j in sides if int(degrees[j]) == 1]
        j = (straight or sides[-1:])[0]
        P = string.segments[j].control_points
        d = P[1] - P[0] if j == k else P[-1] - P[-2]
        out.append(float(np.degrees(np.arctan2(d[1], d[0]))))
    return out


def _straight_direction(channel: dict, wall: str, k: int):
    """The direction (deg) of a straight patch next to corner k, from the definition's
    corners as the channel computes it (the first such patch), or None."""
    degrees = channel["degrees"]
    z, r = channel[f"{wall}_z"], channel[f"{wall}_r"]
    for j in (k - 1, k):
        if 0 <= j < len(degrees) and int(degrees[j]) == 1 and j + 1 < len(z) and j + 1 < len(r):
            C = np.column_stack([np.asarray(z[j:j + 2], dtype=float), np.asarray(r[j:j + 2], dtype=float)])
            chord = C[1] - C[0]
            return float(np.degrees(np.arctan2(chord[1], chord[0])))
    return None


def wall_angles(settings, channel: dict, wall: str) -> list:
    """The [channel] ``{wall}_angle`` list of the panel: "auto", or the angle as typed.

    An angle next to a straight patch must equal that patch's direction to 1e-6 deg
    (channel.ANGLE_MATCH_TOLERANCE_DEG), finer than a float32 field holds above about 16 deg; a
    value that shows that direction (equal as float32, as after turning Auto off) is
    written as the direction itself, so turning Auto off keeps the shape exactly."""
    out = []
    for k, corner in enumerate(getattr(settings, f"{wall}_angle")):
        if corner.auto:
            out.append("auto")
            continue
        value = typed(corner.angle)
        direction = _straight_direction(channel, wall, k)
        if direction is not None and np.float32(corner.angle) == np.float32(direction):
            value = direction
        out.append(value)
    return out


def sync_auto_angles(settings, channel, degrees) -> None:
    """Show in each Auto corner's angle field the direction the built channel has there."""
    was_loading = settings.loading
    settings.loading = True
    try:
        for wall in WALLS:
            corners = getattr(settings, f"{wall}_angle")
            if len(corners) != channel.count + 1:
                continue
            for corner, angle in zip(corners, corner_directions(channel, degrees, wall)):
                if corner.auto and corner.angle != np.float32(angle):
                    corner.angle = angle
    finally:
        settings.loading = was_loading


def standardisation_table(settings) -> dict:
    """The [standardisation] table of the panel's factors (keys at 1.0 left out)."""
    return {key: typed(getattr(settings, key)) for key in FACTORS if typed(getattr(settings, key)) != 1.0}


def write_blade_settings(settings, data: dict) -> None:
    """The panel's blade and splitter settings into the definition dictionary. Turning the
    splitter on in a wheel that has none starts it halfway along the blade, half a pitch
    off, with the blade's thickness."""
    blade = data["blade"]
    for key in BLADE_SETTINGS:
        value = getattr(settings, key if key != "count" else "blade_count")
        blade[key] = value if isinstance(value, (int, str)) else typed(value)
    if not settings.splitter:
        data.pop("splitter", None)
        return
    splitter = data.setdefault("splitter", {
        "thickness_hub": list(blade["thickness_hub"]), "thickness_shroud": list(blade["thickness_shroud"])})
    for key in SPLITTER_SETTINGS:
        value = getattr(settings, f"splitter_{key}")
        splitter[key] = value if isinstance(value, int) else typed(value)


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
    write_blade_settings(settings, data)
    channel = data["channel"]
    for wall in WALLS:
        if len(getattr(settings, f"{wall}_angle")):  # empty in a root made before the walls were editable
            channel[f"{wall}_angle"] = wall_angles(settings, channel, wall)
        patches = getattr(settings, f"{wall}_fractions")
        if len(patches):
            channel[f"{wall}_fractions"] = [[typed(p.fractions[0]), typed(p.fractions[1])] for p in patches]
    table = standardisation_table(settings)
    if table:
        data["standardisation"] = table
    else:
        data.pop("standardisation", None)
    try:
        model = regenerate(root, data, settings.full_wheel)
        settings.status = ""
        settings.construction_report = construction_summary(model)[0]
        sync_auto_angles(settings, model.master_channel, data["channel"]["degrees"])
        settings.standardisation_report = "" if model.standardisation is None else model.standardisation.summary()
    except BladesmithError as exc:
        settings.status = str(exc)


class BladesmithImpellerValue(bpy.types.PropertyGroup):
    value: FloatProperty(name="Value", update=on_edit, precision=5)


class BladesmithImpellerCorner(bpy.types.PropertyGroup):
    """One corner of a channel wall: its wall angle, or "auto"."""

    auto: BoolProperty(
        name="Auto", default=True, update=on_edit,
        description="Take the direction of the adjacent straight patch (\"auto\" in the definition)")
    angle: FloatProperty(
        name="Angle", default=0.0, soft_min=-180.0, soft_max=180.0, step=100, precision=4, update=on_edit,
        description="Wall direction at this corner, degrees from +z towards +r (0 axial, 90 radially outwards)")


class BladesmithImpellerPatch(bpy.types.PropertyGroup):
    """One patch of a channel wall: the fractions placing P_1 and P_3 of a bend."""

    fractions: FloatVectorProperty(
        name="Fractions", size=2, default=(0.5, 0.5), min=0.0, max=1.0, soft_min=0.05, soft_max=0.95,
        step=1, precision=3, update=on_edit,
        description="f_a, f_b: P_1 = P_0 + f_a (C - P_0) and P_3 = P_4 + f_b (C - P_4), C the meeting point of the "
                    "corner tangents; in (0, 1), larger is a fuller bend")
    bend: BoolProperty(name="Bend", default=False)  # degree 4; fixed by the definition


class BladesmithImpellerSettings(bpy.types.PropertyGroup):
    hub_r: CollectionProperty(type=BladesmithImpellerValue)
    hub_z: CollectionProperty(type=BladesmithImpellerValue)
    shroud_r: CollectionProperty(type=BladesmithImpellerValue)
    shroud_z: CollectionProperty(type=BladesmithImpellerValue)
    beta_hub: CollectionProperty(type=BladesmithImpellerValue)
    beta_shroud: CollectionProperty(type=BladesmithImpellerValue)
    thickness_hub: CollectionProperty(type=BladesmithImpellerValue)
    thickness_shroud: CollectionProperty(type=BladesmithImpellerValue)
    hub_angle: CollectionProperty(type=BladesmithImpellerCorner)
    shroud_angle: CollectionProperty(type=BladesmithImpellerCorner)
    hub_fractions: CollectionProperty(type=BladesmithImpellerPatch)
    shroud_fractions: CollectionProperty(type=BladesmithImpellerPatch)
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
    # blade settings (issue 18)
    blade_count: IntProperty(name="Blades", default=15, min=1, max=200, update=on_edit,
                             description="Number of blades Z")
    patches: IntProperty(name="Patches", default=6, min=1, max=MAX_PATCHES, update=on_edit,
                         description="Cubic-linear patches per blade surface; the least number when a tolerance is set")
    tolerance: FloatProperty(name="Tolerance", default=1e-6, min=0.0, max=1e-2, precision=7, step=1e-5,
                             update=on_edit,
                             description="Camber and thickness tolerance as a fraction of the outer diameter; the "
                                         "patch count is raised to meet it (edges on the walls to 1e-6 D at most); "
                                         "0 keeps the patch count")
    patch_spacing: EnumProperty(name="Spacing", items=[(k, k.capitalize(), f"Patch corners equidistant {t}")
                                                       for k, t in zip(PATCH_SPACINGS, ("in meridional distance",
                                                                                        "along the blade"))],
                                update=on_edit)
    elements: EnumProperty(name="Elements", items=[("arbitrary", "Arbitrary", "Straight line elements roughly normal "
                                                    "to the walls"), ("axial", "Axial", "Axial straight line elements")],
                           update=on_edit)
    leading_edge_ratio: FloatProperty(name="LE rounding", default=3.0, min=0.0, max=20.0, update=on_edit,
                                      description="Elliptic leading edge: semi-axes ratio; 0 = cut off")
    trailing_edge_ratio: FloatProperty(name="TE rounding", default=0.0, min=0.0, max=20.0, update=on_edit,
                                       description="Elliptic trailing edge: semi-axes ratio; 0 = cut off (closed by a "
                                                   "flat face)")
    splitter: BoolProperty(name="Splitter", default=False, update=on_edit)
    splitter_leading_edge_hub: FloatProperty(name="Splitter LE hub U", default=1.5, update=on_edit)
    splitter_leading_edge_shroud: FloatProperty(name="Splitter LE shroud U", default=1.5, update=on_edit)
    splitter_pitch_fraction: FloatProperty(name="Pitch fraction", default=0.5, min=0.01, max=0.99, update=on_edit)
    splitter_patches: IntProperty(name="Splitter patches", default=4, min=1, max=MAX_PATCHES, update=on_edit)
    splitter_leading_edge_ratio: FloatProperty(name="Splitter LE rounding", default=3.0, min=0.0, max=20.0,
                                               update=on_edit)
    construction_report: StringProperty(name="Construction", default="")
    full_wheel: BoolProperty(name="Full Wheel", default=True)
    loading: BoolProperty(default=False)
    status: StringProperty(name="Status", default="")

    def load(self, definition, full_wheel: bool, report: str = "", construction: str = "") -> None:
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
            for key in BLADE_SETTINGS:
                setattr(self, key if key != "count" else "blade_count", d["blade"][key])
            self.splitter = "splitter" in d
            if self.splitter:
                for key in SPLITTER_SETTINGS:
                    setattr(self, f"splitter_{key}", d["splitter"][key])
            else:
                b = d["blade"]
                self.splitter_leading_edge_hub = 0.5 * (b["leading_edge_hub"] + b["trailing_edge_hub"])
                self.splitter_leading_edge_shroud = 0.5 * (b["leading_edge_shroud"] + b["trailing_edge_shroud"])
            degrees = d["channel"]["degrees"]
            for wall in WALLS:
                corners = getattr(self, f"{wall}_angle")
                corners.clear()
                for angle in d["channel"][f"{wall}_angle"]:
                    item = corners.add()
                    item.auto = angle == "auto"
                    item.angle = 0.0 if item.auto else float(angle)
                patches = getattr(self, f"{wall}_fractions")
                patches.clear()
                for degree, pair in zip(degrees, d["channel"][f"{wall}_fractions"]):
                    item = patches.add()
                    item.fractions = (float(pair[0]), float(pair[1]))
                    item.bend = int(degree) == BEND_DEGREE
            try:
                sync_auto_angles(self, definition.channel.build(definition.path), degrees)
            except BladesmithError:
                pass  # an invalid channel has no directions to show; the fields stay at 0
            self.full_wheel = full_wheel
            self.status = ""
            self.standardisation_report = report
            self.construction_report = construction
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
        box.label(text="Blade")
        col = box.column(align=True)
        for key in ("blade_count", "patches", "tolerance", "patch_spacing", "elements", "leading_edge_ratio",
                    "trailing_edge_ratio"):
            col.prop(settings, key)
        if settings.construction_report:
            box.label(text=settings.construction_report, icon="INFO")
        box = layout.box()
        box.prop(settings, "splitter")
        col = box.column(align=True)
        col.enabled = settings.splitter
        for key in SPLITTER_SETTINGS:
            col.prop(settings, f"splitter_{key}")
        row = layout.row(align=True)
        row.operator("bladesmith.save_impeller_definition", icon="FILE_TICK")
        row.operator("bladesmith.export_impeller_cfd", icon="EXPORT")
        row = layout.row(align=True)
        row.operator("bladesmith.impeller_net", icon="MESH_GRID")
        row.operator("bladesmith.impeller_sections", icon="MOD_SLICE")
        box = layout.box()
        box.label(text="Standardisation")
        col = box.column(align=True)
        for key in FACTORS:
            col.prop(settings, key)
        if settings.standardisation_report:
            box.label(text=settings.standardisation_report, icon="INFO")


class BLADESMITH_PT_impeller_walls(bpy.types.Panel):
    """Wall angles at the corners and fractions of the bends, per wall."""

    bl_label = "Channel walls"
    bl_idname = "BLADESMITH_PT_impeller_walls"
    bl_parent_id = "BLADESMITH_PT_impeller"
    bl_options = {"DEFAULT_CLOSED"}
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Bladesmith"

    @classmethod
    def poll(cls, context):
        return BLADESMITH_PT_impeller.poll(context)

    def draw(self, context):
        settings = context.active_object.bladesmith_impeller
        for wall in WALLS:
            box = self.layout.box()
            box.label(text=f"{wall.capitalize()} wall")
            col = box.column(align=True)
            for k, corner in enumerate(getattr(settings, f"{wall}_angle")):
                row = col.row(align=True)
                row.label(text=f"Corner {k}")
                row.prop(corner, "auto", toggle=True)
                sub = row.row(align=True)
                sub.enabled = not corner.auto
                sub.prop(corner, "angle", text="Angle °")
            col = box.column(align=True)
            for j, patch in enumerate(getattr(settings, f"{wall}_fractions")):
                if patch.bend:
                    row = col.row(align=True)
                    row.label(text=f"Bend {j} fractions")
                    row.prop(patch, "fractions", text="")


_classes = (BladesmithImpellerValue, BladesmithImpellerCorner, BladesmithImpellerPatch, BladesmithImpellerSettings,
            BLADESMITH_PT_impeller, BLADESMITH_PT_impeller_walls)
_register, _unregister = bpy.utils.register_classes_factory(_classes)


def register():
    _register()
    bpy.types.Object.bladesmith_impeller = PointerProperty(type=BladesmithImpellerSettings)


def unregister():
    del bpy.types.Object.bladesmith_impeller
    _unregister()
