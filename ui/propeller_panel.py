"""The propeller panel (3D viewport sidebar, "Bladesmith" tab) and its property groups.

``Object.bladesmith_propeller`` (:class:`BLADESMITH_PG_propeller`) lives on a propeller's
root Empty and holds every value of the definition (the radial table as a collection
shown with a UIList, rows added and removed with ``bladesmith.propeller_row_add`` /
``_remove``), the tip-smoothing settings and the display tolerance. Every value has an
``update`` callback that regenerates the propeller's objects in place
(:func:`..operators.propeller.on_settings_edited`); an invalid value keeps the last good
geometry and shows the message in the panel.
"""
import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)

from ..geometry.propeller.definition import RADIAL_FIELDS
from ..operators import propeller as ops


def _edited(self, context):
    ops.on_settings_edited(self.id_data)


def _float(name, description, default=0.0, *, unit="NONE", precision=5, step=1.0, **limits):
    # no hard limits: an out-of-range value is refused by the validation, with a message
    return FloatProperty(name=name, description=description, default=default, unit=unit, precision=precision,
                         step=step, update=_edited, **limits)


class BLADESMITH_PG_radial_station(bpy.types.PropertyGroup):
    """One row of the radial table (the [radial] arrays of the definition)."""

    r_R: _float("r/R", "Radius / tip radius (strictly increasing, last row = 1)", 0.5, soft_min=0.0, soft_max=1.0, step=0.1)
    c_D: _float("c/D", "Chord / diameter (> 0; 0 allowed at the tip)", 0.3, soft_min=0.0, soft_max=1.0, step=0.1)
    P_D: _float("P/D", "Pitch / diameter (> 0)", 1.0, soft_min=0.1, soft_max=3.0, step=0.1)
    skew_deg: _float("Skew", "Skew angle of the mid-chord point, degrees, positive = skew back", 0.0,
                     soft_min=-90.0, soft_max=90.0, precision=3, step=10.0)
    rake_D: _float("Rake/D", "Generator-line rake / diameter, positive downstream", 0.0, soft_min=-0.5, soft_max=0.5, step=0.1)
    t_c: _float("t/c", "Maximum thickness / chord (> 0)", 0.05, soft_min=0.0, soft_max=0.5, step=0.1)
    f_c: _float("f/c", "Maximum camber / chord", 0.02, soft_min=-0.2, soft_max=0.2, step=0.1)


class BLADESMITH_PG_table_point(bpy.types.PropertyGroup):
    """A point (x/c, value) of a thickness or mean-line table."""

    x_c: _float("x/c", "Chordwise position / chord, from the leading edge", 0.5, soft_min=0.0, soft_max=1.0, step=0.1)
    value: _float("Value", "T/T0 (thickness table) or f/f0 (mean-line table)", 0.5, soft_min=-1.0, soft_max=1.5, step=0.1)


_THICKNESS_ITEMS = [
    ("NACA66MOD", "NACA 66 mod", "NACA 66 (DTRC modified) thickness form"),
    ("NACA4", "NACA 4-digit", "NACA 4-digit thickness form"),
    ("ELLIPTIC", "Elliptic", "Elliptic thickness form"),
    ("TABLE", "Table", "Thickness table T/T0 against x/c"),
    (ops.THICKNESS_FILE, "Airfoil File", "Thickness of an airfoil .dat file"),
]
_MEANLINE_ITEMS = [
    ("A08", "a=0.8", "NACA a=0.8 mean line (formula)"),
    ("A08MOD", "a=0.8 mod", "NACA a=0.8 (modified) mean line (table)"),
    ("PARABOLIC", "Parabolic", "Parabolic mean line"),
    ("NACA4", "NACA 4-digit", "NACA 4-digit mean line (maximum at 0.4 c)"),
    ("NONE", "None", "No camber"),
    ("TABLE", "Table", "Mean-line table f/f0 against x/c"),
    ("AIRFOIL", "Airfoil File", "Mean line of the airfoil file given as thickness"),
]
_SHAPE_ITEMS = [
    ("ELLIPSE", "Ellipse", "Quarter ellipse"),
    ("CONE", "Cone", "Straight cone"),
    ("FLAT", "Flat", "Flat end"),
]
_HAND_ITEMS = [("RIGHT", "Right", "Right-handed (clockwise seen from astern)"), ("LEFT", "Left", "Left-handed")]


def _setting_annotations() -> dict:
    length = dict(unit="LENGTH", precision=5, step=0.1)
    out = {
        "is_propeller": BoolProperty(name="Is Propeller", default=False, options={"HIDDEN"}),
        "definition_name": StringProperty(name="Name", description="Name of the propeller", default="Propeller", update=_edited),
        "blades": IntProperty(name="Blades", description="Number of blades Z", default=3, min=1, soft_max=12, update=_edited),
        "diameter": _float("Diameter", "Propeller diameter D", 1.0, soft_min=0.01, soft_max=20.0, **length),
        "hub_diameter_ratio": _float("Hub Ratio", "Hub diameter / D (below the tip radius ratio)", 0.2, soft_min=0.0, soft_max=0.9, step=0.1),
        "hand": EnumProperty(name="Hand", items=_HAND_ITEMS, default="RIGHT", update=_edited),
        "thickness_kind": EnumProperty(name="Thickness", items=_THICKNESS_ITEMS, default="NACA66MOD", update=_edited),
        "thickness_file": StringProperty(name="Airfoil File", description="Airfoil .dat file of the thickness form",
                                         subtype="FILE_PATH", update=_edited),
        "meanline": EnumProperty(name="Mean Line", items=_MEANLINE_ITEMS, default="A08", update=_edited),
        "smooth_airfoil": BoolProperty(
            name="Smooth airfoil (Hvid)", description="Smooth the airfoil file's outline before taking its "
            "thickness and mean line: curvature-based smoothing of Hvid (1993) smoothfoil with its default "
            "settings (airfoil files only)", default=False, update=_edited,
        ),
        "smooth_passes": IntProperty(
            name="Smoothing Passes", description="Passes of Hvid's ad hoc curvature smoother (the paper uses 4); "
            "fewer keep the section closer to the file, the status line gives the deviation",
            default=4, min=1, max=50, update=_edited,
        ),
        "thickness_table": CollectionProperty(type=BLADESMITH_PG_table_point),
        "thickness_index": IntProperty(default=0, options={"HIDDEN"}),
        "meanline_table": CollectionProperty(type=BLADESMITH_PG_table_point),
        "meanline_index": IntProperty(default=0, options={"HIDDEN"}),
        "hub_upstream_length": _float("Upstream Length", "From the propeller plane to the nose tip", 0.35, soft_min=0.0, **length),
        "hub_downstream_length": _float("Downstream Length", "From the propeller plane to the tail end", 0.45, soft_min=0.0, **length),
        "hub_nose_shape": EnumProperty(name="Nose", items=_SHAPE_ITEMS, default="ELLIPSE", update=_edited),
        "hub_nose_length": _float("Nose Length", "Axial length of the nose shape", 0.15, soft_min=0.0, **length),
        "hub_tail_shape": EnumProperty(name="Tail", items=_SHAPE_ITEMS, default="ELLIPSE", update=_edited),
        "hub_tail_length": _float("Tail Length", "Axial length of the tail shape", 0.2, soft_min=0.0, **length),
        "radial": CollectionProperty(type=BLADESMITH_PG_radial_station),
        "radial_index": IntProperty(default=0, options={"HIDDEN"}),
        "display_tolerance": ops.display_tolerance_property(update=_edited),
        # what the panel reports; written by the regeneration, no callbacks
        "status": StringProperty(name="Status", default=""),
        "status_is_error": BoolProperty(default=False),
        "display_deviation": FloatProperty(name="Deviation", default=-1.0, unit="LENGTH", precision=7),
        "regeneration_time": FloatProperty(name="Regeneration Time", default=0.0, unit="TIME_ABSOLUTE"),
        "definition_toml": StringProperty(name="Definition", description="TOML text of the shown definition", default=""),
        "source_path": StringProperty(name="Source", description="The file the definition was loaded from", subtype="FILE_PATH"),
    }
    out.update(ops.smoothing_properties(update=_edited))
    return out


class BLADESMITH_PG_propeller(bpy.types.PropertyGroup):
    """A propeller's definition, smoothing settings and status (on its root Empty)."""

    __annotations__ = _setting_annotations()


class BLADESMITH_UL_radial(bpy.types.UIList):
    """The radial table: one editable row per station."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_property, index=0, flt_flag=0):
        row = layout.row(align=True)
        for name in RADIAL_FIELDS:
            row.prop(item, name, text="", emboss=True)


class BLADESMITH_UL_table_points(bpy.types.UIList):
    """A thickness or mean-line table: (x/c, value) rows."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_property, index=0, flt_flag=0):
        row = layout.row(align=True)
        row.prop(item, "x_c", text="")
        row.prop(item, "value", text="")


def _root(context):
    return ops.find_root(context.active_object)


class _PropellerPanel:
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Bladesmith"


class BLADESMITH_PT_propeller(_PropellerPanel, bpy.types.Panel):
    bl_label = "Propeller"

    def draw(self, context):
        layout = self.layout
        root = _root(context)
        row = layout.row(align=True)
        row.operator_menu_enum("bladesmith.add_propeller", "preset_choice", text="Add Propeller", icon="ADD")
        row.operator("bladesmith.load_propeller_definition", text="", icon="FILE_FOLDER")
        if root is None:
            layout.label(text="Select a propeller to edit it")
            return
        s = root.bladesmith_propeller
        row = layout.row(align=True)
        row.operator("bladesmith.regenerate_propeller", text="Regenerate", icon="FILE_REFRESH")
        row.operator("bladesmith.save_propeller_definition", text="Save", icon="FILE_TICK")
        box = layout.box()
        box.alert = s.status_is_error
        for line in _wrap(s.status or "not generated yet", 48):
            box.label(text=line, icon="ERROR" if s.status_is_error else "NONE")
        col = layout.column()
        col.use_property_split = True
        col.prop(s, "definition_name")
        col.prop(s, "blades")
        col.prop(s, "diameter")
        col.prop(s, "hub_diameter_ratio")
        col.prop(s, "hand")


def _wrap(text: str, width: int) -> list[str]:
    words, lines, line = text.split(), [], ""
    for word in words:
        if line and len(line) + 1 + len(word) > width:
            lines.append(line)
            line = word
        else:
            line = f"{line} {word}" if line else word
    return lines + ([line] if line else [])


class _Sub(_PropellerPanel):
    bl_parent_id = "BLADESMITH_PT_propeller"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context):
        return _root(context) is not None


def _table_buttons(layout, table: str):
    col = layout.column(align=True)
    col.operator("bladesmith.propeller_row_add", text="", icon="ADD").table = table
    col.operator("bladesmith.propeller_row_remove", text="", icon="REMOVE").table = table


class BLADESMITH_PT_propeller_radial(_Sub, bpy.types.Panel):
    bl_label = "Radial Table"
    bl_options = set()

    def draw(self, context):
        s = _root(context).bladesmith_propeller
        header = self.layout.row(align=True)
        for label in ("r/R", "c/D", "P/D", "skew°", "rake/D", "t/c", "f/c"):
            header.label(text=label)
        row = self.layout.row()
        row.template_list("BLADESMITH_UL_radial", "", s, "radial", s, "radial_index", rows=6)
        _table_buttons(row, "RADIAL")


class BLADESMITH_PT_propeller_section(_Sub, bpy.types.Panel):
    bl_label = "Section"

    def draw(self, context):
        s = _root(context).bladesmith_propeller
        col = self.layout.column()
        col.use_property_split = True
        col.prop(s, "thickness_kind")
        if s.thickness_kind == ops.THICKNESS_FILE:
            col.prop(s, "thickness_file")
        row = col.row()
        row.enabled = s.thickness_kind == ops.THICKNESS_FILE  # only an airfoil file is smoothed
        row.prop(s, "smooth_airfoil")
        row = col.row()
        row.enabled = s.thickness_kind == ops.THICKNESS_FILE and s.smooth_airfoil
        row.prop(s, "smooth_passes")
        col.prop(s, "meanline")
        for kind, label, collection, index in (
            (s.thickness_kind == "TABLE", "Thickness table (x/c, T/T0)", "thickness_table", "thickness_index"),
            (s.meanline == "TABLE", "Mean-line table (x/c, f/f0)", "meanline_table", "meanline_index"),
        ):
            if kind:
                self.layout.label(text=label)
                row = self.layout.row()
                row.template_list("BLADESMITH_UL_table_points", collection, s, collection, s, index, rows=4)
                _table_buttons(row, "THICKNESS" if collection == "thickness_table" else "MEANLINE")


class BLADESMITH_PT_propeller_hub(_Sub, bpy.types.Panel):
    bl_label = "Hub"

    def draw(self, context):
        s = _root(context).bladesmith_propeller
        col = self.layout.column()
        col.use_property_split = True
        for name in ("hub_upstream_length", "hub_downstream_length", "hub_nose_shape", "hub_nose_length",
                     "hub_tail_shape", "hub_tail_length"):
            col.prop(s, name)


class BLADESMITH_PT_propeller_smoothing(_Sub, bpy.types.Panel):
    bl_label = "Tip Smoothing"

    def draw_header(self, context):
        self.layout.prop(_root(context).bladesmith_propeller, "smooth_tip", text="")

    def draw(self, context):
        s = _root(context).bladesmith_propeller
        col = self.layout.column()
        col.use_property_split = True
        col.active = s.smooth_tip
        for name in SMOOTHING_UP_FRONT:
            col.prop(s, name)
        col.prop(s, "show_overlay")


#: The settings a user tunes (Hally's Δc, d_t, s_j and α); the rest are folded away.
SMOOTHING_UP_FRONT = ("delta_c", "tip_smoothing_distance", "transition_s", "filter_strength")


class BLADESMITH_PT_propeller_smoothing_advanced(_Sub, bpy.types.Panel):
    bl_label = "Advanced"
    bl_parent_id = "BLADESMITH_PT_propeller_smoothing"

    def draw(self, context):
        s = _root(context).bladesmith_propeller
        col = self.layout.column()
        col.use_property_split = True
        col.active = s.smooth_tip
        for name in ops.SMOOTHING_FIELDS:
            if name not in SMOOTHING_UP_FRONT and name not in ops.DEFINING_POINT_KEYS:
                col.prop(s, name)
        # the six defining points of Hally (2013) §4, Fig. 4 (blade parameters ξ, η = r/R)
        col.label(text="Defining points (Hally Fig. 4)")
        for row_keys in (("xi_ll", "xi_lr"), ("xi_ul", "eta_ul"), ("xi_ur", "eta_ur"), ("eta_le", "eta_te")):
            row = col.row(align=True)
            for name in row_keys:
                row.prop(s, name)


class BLADESMITH_PT_propeller_display(_Sub, bpy.types.Panel):
    bl_label = "Display"

    def draw(self, context):
        s = _root(context).bladesmith_propeller
        col = self.layout.column()
        col.use_property_split = True
        col.prop(s, "display_tolerance")
        if s.display_deviation >= 0.0:
            col.label(text=f"Measured deviation: {s.display_deviation:.3g} m")
        col.label(text=f"Last regeneration: {s.regeneration_time * 1e3:.0f} ms")
        if s.source_path:
            col.label(text=f"Loaded from: {bpy.path.basename(s.source_path)}")


_classes = (
    BLADESMITH_PG_radial_station,
    BLADESMITH_PG_table_point,
    BLADESMITH_PG_propeller,
    BLADESMITH_UL_radial,
    BLADESMITH_UL_table_points,
    BLADESMITH_PT_propeller,
    BLADESMITH_PT_propeller_radial,
    BLADESMITH_PT_propeller_section,
    BLADESMITH_PT_propeller_hub,
    BLADESMITH_PT_propeller_smoothing,
    BLADESMITH_PT_propeller_smoothing_advanced,
    BLADESMITH_PT_propeller_display,
)
_register, _unregister = bpy.utils.register_classes_factory(_classes)


def register():
    _register()
    bpy.types.Object.bladesmith_propeller = PointerProperty(type=BLADESMITH_PG_propeller)


def unregister():
    del bpy.types.Object.bladesmith_propeller
    _unregister()
