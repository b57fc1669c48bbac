"""The wind-blade panel (3D viewport sidebar, "Bladesmith" tab) and its property groups.

``Object.bladesmith_wind_blade`` (:class:`BLADESMITH_PG_wind_blade`) lives on a wind
blade's root Empty and holds the definition (the stations as a collection edited in a
UIList: r, chord, twist, pitch axis, airfoil; prebend and sweep of the active station
below the list), the fit settings, and what the last build measured: the least-squares
error of the two-part and the single fit per station and in total, and the MVS and
strain energy of both approaches (Hosseini & Moetakef-Imani 2016, Eqs. 3 and 6), shown
side by side. Every definition value regenerates the molds in place
(:func:`..operators.wind_blade.on_settings_edited`); fairness is computed on demand
("Compute Fairness") unless ``live_fairness`` is on.
"""
import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)

from ..operators import wind_blade as ops


def _edited(self, context):
    ops.on_settings_edited(self.id_data)


def _fit_edited(self, context):
    ops.on_fit_settings_edited(self.id_data)


def _float(name, description, default=0.0, *, unit="NONE", precision=4, step=1.0, **limits):
    # no hard limits: an out-of-range value is refused by the validation, with the station named
    return FloatProperty(name=name, description=description, default=default, unit=unit, precision=precision,
                         step=step, update=_edited, **limits)


def _result(name, description, default=0.0, precision=6):
    return FloatProperty(name=name, description=description, default=default, precision=precision)


class BLADESMITH_PG_wind_blade_station(bpy.types.PropertyGroup):
    """One station of the blade (the [stations] arrays of the definition) and its fit figures."""

    r: _float("r", "Radius of the station from the rotor axis (strictly increasing)", 1.0, unit="LENGTH",
              soft_min=0.0, step=10.0)
    chord: _float("Chord", "Chord length (> 0)", 0.3, unit="LENGTH", soft_min=0.0, step=1.0)
    twist_deg: _float("Twist", "Twist angle, degrees", 0.0, soft_min=-30.0, soft_max=30.0, precision=3, step=10.0)
    pitch_axis: _float("Pitch Axis", "Pitch axis as a chord fraction from the leading edge", 0.3,
                       soft_min=0.0, soft_max=1.0, step=1.0)
    prebend: _float("Prebend", "Flapwise offset of the section", 0.0, unit="LENGTH", step=1.0)
    sweep: _float("Sweep", "Edgewise offset of the section", 0.0, unit="LENGTH", step=1.0)
    airfoil: StringProperty(
        name="Airfoil",
        description="A shipped airfoil name, \"circle\", or a .dat path (relative paths from the definition's folder)",
        default="circle", update=_edited,
    )
    tolerance: _float("Tolerance", "This station's tolerance as a chord fraction; 0 = the blade's", 0.0,
                      soft_min=0.0, soft_max=1e-2, precision=6, step=0.001)
    lsq_two_part: _result("LSQ Two-Part", "Least-squares error of the two-part fit (Hosseini Eq. 3), m²", -1.0, 9)
    lsq_single: _result("LSQ Single", "Least-squares error of the single fit (Hosseini Eq. 3), m²; "
                        "-1 for the root-transition stations", -1.0, 9)
    deviation: _result("Deviation", "Largest closest-point distance of the station's points from the mold "
                       "surfaces, as a fraction of the chord", -1.0, 9)


def _annotations() -> dict:
    return {
        "is_wind_blade": BoolProperty(name="Is Wind Blade", default=False, options={"HIDDEN"}),
        "definition_name": StringProperty(name="Name", description="Name of the blade", default="Blade",
                                          update=_edited),
        "hub_radius": _float("Hub Radius", "Hub radius", 1.0, unit="LENGTH", soft_min=0.0, step=10.0),
        "mold_direction": FloatVectorProperty(
            name="Mold Direction", description="Parting (draw) direction of the molds; default flapwise +y",
            size=3, default=(0.0, 1.0, 0.0), subtype="XYZ", update=_edited,
        ),
        "wrap": BoolProperty(name="Wrap Sections", description="Wrap the aerodynamic sections onto their "
                             "cylinders of radius r (Hosseini Eq. 5); off: flat sections", default=True,
                             update=_edited),
        "smooth_airfoils": BoolProperty(
            name="Smooth airfoils (Hvid)", description="Smooth the airfoils of the aerodynamic stations first: "
            "curvature-based smoothing of Hvid (1993) smoothfoil with its default settings (\"circle\" and the "
            "root-transition stations are kept as they are)", default=False, update=_edited,
        ),
        "smooth_passes": IntProperty(
            name="Smoothing Passes", description="Passes of Hvid's ad hoc curvature smoother (the paper uses 4); "
            "fewer keep the sections closer to the files, the status line gives the deviation",
            default=4, min=1, max=50, update=_edited,
        ),
        "min_trailing_edge_thickness": _float(
            "Min TE Thickness", "Every station's trailing edge at least this thick (sharp ones are opened over "
            "the aft 20 % of the chord); 0 keeps the airfoils as read", 0.0, unit="LENGTH", soft_min=0.0,
            precision=4, step=0.01),
        "first_aerodynamic_station": IntProperty(
            name="First Airfoil Station", description="Index of the first aerodynamic station; the stations "
            "before it form the root transition (Hosseini §5.1)", default=0, soft_min=0, update=_edited,
        ),
        "control_points": IntProperty(
            name="Control Points", description="Control points per half and section to start from "
            "(raised until the tolerance holds)", default=12, soft_min=5, soft_max=60, update=_fit_edited,
        ),
        "tolerance": FloatProperty(
            name="Tolerance", description="Largest distance of a section from its airfoil points, as a "
            "fraction of the local chord", default=1e-4, soft_min=1e-6, soft_max=1e-2, precision=6,
            step=0.001, update=_fit_edited,
        ),
        "section_degree": IntProperty(
            name="Section Degree p", description="Degree of the section curves (Hosseini Eq. 1)", default=3,
            min=2, max=5, update=_fit_edited,
        ),
        "span_degree": IntProperty(
            name="Span Degree q", description="Degree across the sections (skinning, Hosseini Eq. 4)", default=3,
            min=1, max=5, update=_fit_edited,
        ),
        "tangent_mode": EnumProperty(
            name="Tangent at S", description="Magnitude of the tangent at the silhouette point S (Hosseini Fig. 7)",
            items=[("SQP", "Optimised (SQP)", "Minimise the least-squares error (Hosseini §4)"),
                   ("HAND", "By Hand", "Upper and lower magnitudes in chords, one ratio for the whole blade")],
            default="SQP", update=_fit_edited,
        ),
        "tangent_upper": FloatProperty(
            name="Upper Magnitude", description="|C'(1)| of the upper half at S, in chords", default=1.0,
            soft_min=0.05, soft_max=5.0, precision=4, step=1.0, update=_fit_edited,
        ),
        "tangent_lower": FloatProperty(
            name="Lower Magnitude", description="|C'(0)| of the lower half at S, in chords", default=1.0,
            soft_min=0.05, soft_max=5.0, precision=4, step=1.0, update=_fit_edited,
        ),
        "fitted_ratio": _result("Tangent Ratio", "Upper / lower tangent magnitude at S of the shown molds", 1.0),
        "aligned_parameters": BoolProperty(default=False),
        "mold_halves": BoolProperty(
            name="Mold Halves", description="Show the upper and lower mold halves, root transitions and parting "
            "lines; off: the single traditional surface", default=True, update=_edited,
        ),
        "live_fairness": BoolProperty(
            name="Live Fairness", description="Compute MVS and strain energy on every edit (slower)",
            default=False, update=_edited,
        ),
        "stations": CollectionProperty(type=BLADESMITH_PG_wind_blade_station),
        "stations_index": IntProperty(default=0, options={"HIDDEN"}),
        "base_dir": StringProperty(name="Airfoil Folder", description="Folder relative airfoil paths are read "
                                   "from (the definition file's folder)", subtype="DIR_PATH", update=_edited),
        "source_path": StringProperty(name="Source", description="The file the definition was loaded from",
                                      subtype="FILE_PATH"),
        # written by the regeneration, no callbacks
        "status": StringProperty(name="Status", default=""),
        "status_is_error": BoolProperty(default=False),
        "definition_toml": StringProperty(name="Definition", description="TOML text of the shown definition"),
        "fitted_control_points": IntProperty(name="Fitted Control Points", default=0),
        "regeneration_time": FloatProperty(name="Regeneration Time", default=0.0, unit="TIME_ABSOLUTE"),
        "lsq_two_part": _result("LSQ Two-Part", "Sum over the aerodynamic stations of the two-part fits' "
                                "least-squares errors, m²", 0.0, 9),
        "lsq_single": _result("LSQ Single", "Sum over the aerodynamic stations of the single fits' "
                              "least-squares errors, m²", 0.0, 9),
        "max_deviation": _result("Worst Section", "Largest section deviation, chord fraction", 0.0, 9),
        "le_angle_deg": _result("LE Normal Angle", "Largest normal angle across the leading-edge parting "
                                "line, degrees", 0.0, 9),
        "fairness_valid": BoolProperty(default=False),
        "mvs_two_part": _result("MVS Two-Part", "Minimum variation surface integral of both halves"),
        "mvs_single": _result("MVS Single", "Minimum variation surface integral of the single surface"),
        "strain_energy_two_part": _result("Strain Energy Two-Part", "Strain energy integral of both halves"),
        "strain_energy_single": _result("Strain Energy Single", "Strain energy integral of the single surface"),
    }


class BLADESMITH_PG_wind_blade(bpy.types.PropertyGroup):
    """A wind blade's definition, fit settings and figures (on its root Empty)."""

    __annotations__ = _annotations()


class BLADESMITH_UL_wind_blade_stations(bpy.types.UIList):
    """The stations: one editable row each (r, chord, twist, pitch axis, airfoil)."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_property, index=0, flt_flag=0):
        row = layout.row(align=True)
        row.label(text=str(index))
        for name in ("r", "chord", "twist_deg", "pitch_axis"):
            row.prop(item, name, text="", emboss=True)
        row.prop(item, "airfoil", text="")


def _root(context):
    return ops.find_root(context.active_object)


def _wrap(text: str, width: int) -> list[str]:
    lines, line = [], ""
    for word in text.split():
        if line and len(line) + 1 + len(word) > width:
            lines.append(line)
            line = word
        else:
            line = f"{line} {word}" if line else word
    return lines + ([line] if line else [])


class _WindBladePanel:
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Bladesmith"


class BLADESMITH_PT_wind_blade(_WindBladePanel, bpy.types.Panel):
    bl_label = "Wind Blade"

    def draw(self, context):
        layout = self.layout
        layout.operator_menu_enum("bladesmith.add_wind_blade", "preset_choice", text="Add Wind Blade", icon="ADD")
        root = _root(context)
        if root is None:
            layout.label(text="Select a wind blade to edit it")
            return
        s = root.bladesmith_wind_blade
        row = layout.row(align=True)
        row.operator("bladesmith.regenerate_wind_blade", text="Regenerate", icon="FILE_REFRESH")
        row.operator("bladesmith.export_wind_blade_iges", text="Export IGES", icon="EXPORT")
        box = layout.box()
        box.alert = s.status_is_error
        for line in _wrap(s.status or "not generated yet", 48):
            box.label(text=line, icon="ERROR" if s.status_is_error else "NONE")
        col = layout.column()
        col.use_property_split = True
        for name in ("definition_name", "hub_radius", "mold_direction", "wrap", "smooth_airfoils", "smooth_passes",
                     "min_trailing_edge_thickness", "first_aerodynamic_station", "control_points", "tolerance",
                     "section_degree", "span_degree", "tangent_mode", "tangent_upper", "tangent_lower", "mold_halves",
                     "base_dir"):
            row = col.row()
            row.enabled = ((name != "smooth_passes" or s.smooth_airfoils)
                           and (name not in ("tangent_upper", "tangent_lower") or s.tangent_mode == "HAND"))
            row.prop(s, name)
        layout.operator("bladesmith.save_wind_blade_definition", text="Save Wind Blade Definition", icon="FILE_TICK")


class _Sub(_WindBladePanel):
    bl_parent_id = "BLADESMITH_PT_wind_blade"

    @classmethod
    def poll(cls, context):
        return _root(context) is not None


class BLADESMITH_PT_wind_blade_stations(_Sub, bpy.types.Panel):
    bl_label = "Stations"

    def draw(self, context):
        s = _root(context).bladesmith_wind_blade
        layout = self.layout
        header = layout.row(align=True)
        for label in ("#", "r", "chord", "twist°", "pitch ax.", "airfoil"):
            header.label(text=label)
        row = layout.row()
        row.template_list("BLADESMITH_UL_wind_blade_stations", "", s, "stations", s, "stations_index", rows=6)
        buttons = row.column(align=True)
        buttons.operator("bladesmith.wind_blade_station_add", text="", icon="ADD")
        buttons.operator("bladesmith.wind_blade_station_remove", text="", icon="REMOVE")
        if 0 <= s.stations_index < len(s.stations):
            st = s.stations[s.stations_index]
            col = layout.column()
            col.use_property_split = True
            col.prop(st, "prebend")
            col.prop(st, "sweep")
            col.prop(st, "tolerance")
            col.label(text=f"LSQ two-part {st.lsq_two_part:.3e}, single "
                      + (f"{st.lsq_single:.3e}" if st.lsq_single >= 0 else "-"))
            col.label(text=f"Deviation {st.deviation:.2e} chord")


class BLADESMITH_PT_wind_blade_comparison(_Sub, bpy.types.Panel):
    bl_label = "Two-Part vs Single"

    def draw(self, context):
        s = _root(context).bladesmith_wind_blade
        layout = self.layout
        grid = layout.grid_flow(row_major=True, columns=3, even_columns=True, align=True)
        for text in ("", "Two-part", "Single"):
            grid.label(text=text)
        grid.label(text="LSQ error")
        grid.label(text=f"{s.lsq_two_part:.4e}")
        grid.label(text=f"{s.lsq_single:.4e}")
        for label, a, b in (("MVS", s.mvs_two_part, s.mvs_single),
                            ("Strain energy", s.strain_energy_two_part, s.strain_energy_single)):
            grid.label(text=label)
            grid.label(text=f"{a:.4e}" if s.fairness_valid else "-")
            grid.label(text=f"{b:.4e}" if s.fairness_valid else "-")
        row = layout.row(align=True)
        row.operator("bladesmith.wind_blade_fairness", text="Compute Fairness", icon="MOD_SMOOTH")
        layout.operator("bladesmith.wind_blade_sweep", text="Control-Point Sweep", icon="TEXT")
        row.prop(s, "live_fairness", text="Live")
        if not s.fairness_valid:
            layout.label(text="Fairness not computed for the shown molds", icon="INFO")
        layout.label(text=f"{s.fitted_control_points} control points per half; "
                     f"LE normal angle {s.le_angle_deg:.1e}°")
        layout.label(text=f"Last regeneration: {s.regeneration_time * 1e3:.0f} ms")


_classes = (
    BLADESMITH_PG_wind_blade_station,
    BLADESMITH_PG_wind_blade,
    BLADESMITH_UL_wind_blade_stations,
    BLADESMITH_PT_wind_blade,
    BLADESMITH_PT_wind_blade_stations,
    BLADESMITH_PT_wind_blade_comparison,
)
_register, _unregister = bpy.utils.register_classes_factory(_classes)


def register():
    _register()
    bpy.types.Object.bladesmith_wind_blade = PointerProperty(type=BLADESMITH_PG_wind_blade)


def unregister():
    del bpy.types.Object.bladesmith_wind_blade
    _unregister()
