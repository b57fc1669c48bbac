"""Wind-turbine blade molds in Blender: ``bpy.ops.bladesmith.add_wind_blade`` and live editing.

Objects
-------
A wind blade is a root Empty named after the definition, holding the definition and the
settings in ``Object.bladesmith_wind_blade`` (the property group of
:mod:`..ui.wind_blade_panel`), with children tagged ``bladesmith_mold_part``:

- mold halves (``mold_halves=True``): the SURFACE objects ``upper``, ``lower``, the root
  transitions ``transition_upper`` / ``transition_lower`` (when the definition has
  structural-zone stations), and the ruled bases ``trailing_edge`` /
  ``transition_trailing_edge`` of a blunt trailing edge; the parting lines as CURVE objects
  (``leading_edge``, ``trailing_edge_upper``, ``trailing_edge_lower`` and their ``root_``
  counterparts). These are :attr:`BladeMolds.surfaces` and :attr:`BladeMolds.parting_lines`
  of ``geometry.mold.build_blade`` (Hosseini & Moetakef-Imani 2016).
- traditional (``mold_halves=False``): the single lofted surface ``single`` only, over the
  aerodynamic stations (the root transition and the parting lines belong to the halves).

Every object shows its float64 B-spline exactly and keeps it as a custom property
(:mod:`.nurbs_objects`).

Live editing
------------
Every value of the property group regenerates the children in place through its
``update`` callback (:func:`on_settings_edited`); an invalid value (a station whose r does
not increase, a zero chord, an airfoil that cannot be read, a mold direction without a
silhouette point) keeps the last good geometry and shows the message, which names the
station, in the panel. Two choices keep an edit fast:

- fairness (MVS and strain energy, Hosseini Eq. 6) is computed only on demand
  (``bladesmith.wind_blade_fairness``) or on every edit when ``live_fairness`` is on; it is
  a third to a half of a build. After an edit without it the shown figures are marked stale.
- the fit starts from the control-point count of the shown geometry
  (``fitted_control_points``), so the raise-until-within-tolerance loop of ``build_blade``
  does not repeat its failed attempts on every edit. Editing ``control_points`` or
  ``tolerance`` (or ``bladesmith.regenerate_wind_blade``) starts again from the set count.

The definition of the last good geometry is kept as TOML text (``definition_toml``) with
the folder relative airfoil paths are read from (``base_dir``).
"""
import math
import pathlib
import time
import tomllib
from contextlib import contextmanager

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

from ..geometry.errors import BladesmithError, DefinitionError, GeometryError
from ..geometry.mold import (
    BladeDefinition,
    BladeMolds,
    blade_from_dict,
    build_blade,
    control_point_sweep,
    format_sweep,
    load_blade,
    preset_files,
)
from ..geometry.mold.definition import save_blade
from ..iges.mold import write_molds
from ..geometry.nurbs import BSplineCurve
from ..geometry.propeller import dumps_toml
from ..iges import surface_from_geometry, write_iges
from . import nurbs_objects
from .progress import progress_callback
from .nurbs_objects import remove_object, write_curve, write_surface
from .values import typed
from .scene_guard import unchanged_on_refusal

#: Custom property naming a child's part (a key of BladeMolds.surfaces / parting_lines, or "single").
PART_KEY = "bladesmith_mold_part"
#: Blender's evaluated points per control point of the Bezier nets (three per knot span).
SURFACE_RESOLUTION = 2
CURVE_RESOLUTION = 4
#: The smallest control-point count per half the definition format accepts.
MIN_CONTROL_POINTS = 5

STATION_FIELDS = ("r", "chord", "twist_deg", "pitch_axis", "prebend", "sweep")


def _preset_label(path: pathlib.Path) -> str:
    try:
        with open(path, "rb") as fh:
            return str(tomllib.load(fh).get("name", path.stem))
    except (OSError, tomllib.TOMLDecodeError):
        return path.stem


#: EnumProperty items, built once (Blender needs the list to stay alive).
PRESET_ITEMS = [(key, _preset_label(path), f"Preset {path.name}") for key, path in preset_files().items()] or [
    ("NONE", "No presets", "data/blades holds no .toml file")
]


def load_definition(definition: str, preset: str) -> BladeDefinition:
    """A validated definition from a file path (Blender's // prefix allowed) or a preset
    name (case-insensitive, e.g. "NREL5MW"; the ``.toml`` suffix is accepted)."""
    if definition:
        return load_blade(bpy.path.abspath(definition))
    key = str(preset).strip().upper()
    if key.endswith(".TOML"):
        key = key[: -len(".TOML")]
    files = preset_files()
    if key not in files:
        raise DefinitionError(f"unknown blade preset {preset!r}; known presets: {', '.join(files)}", field="preset")
    return load_blade(files[key])


def check_fit_settings(control_points: int, tolerance: float) -> None:
    """Refuse a control-point count or tolerance the fit cannot use (0 = the definition's)."""
    if control_points != 0 and control_points < MIN_CONTROL_POINTS:
        raise DefinitionError(f"expected 0 (the definition's) or an integer >= {MIN_CONTROL_POINTS}, "
                              f"got {control_points}", field="control_points")
    if not (math.isfinite(tolerance) and tolerance >= 0.0):
        raise DefinitionError(f"expected 0 (the definition's) or a positive chord fraction, got {tolerance}",
                              field="tolerance")


def compute_molds(defn: BladeDefinition, *, control_points: int = 0, tolerance: float = 0.0,
                  fairness: bool = True, progress=None) -> BladeMolds:
    """The molds of ``defn`` (bpy-free work; raises BladesmithError). Both approaches are
    always built, so the panel can compare them."""
    check_fit_settings(control_points, tolerance)
    return build_blade(defn, control_points=control_points or None, tolerance=tolerance or None,
                       single=True, fairness=fairness, progress=progress)


# -- settings <-> definition ------------------------------------------------------------------
_suspended = 0


@contextmanager
def suspended_updates():
    """Property writes inside this block do not regenerate."""
    global _suspended
    _suspended += 1
    try:
        yield
    finally:
        _suspended -= 1


def settings_to_dict(settings) -> dict:
    """The definition (TOML layout of ``geometry.mold.definition``) of a property group."""
    rows = settings.stations
    return {
        "name": settings.definition_name,
        "hub_radius": typed(settings.hub_radius),
        "mold_direction": [typed(x) for x in settings.mold_direction],
        "wrap": bool(settings.wrap),
        "first_aerodynamic_station": int(settings.first_aerodynamic_station),
        "control_points": int(settings.control_points),
        "tolerance": typed(settings.tolerance),
        "smooth_airfoils": bool(settings.smooth_airfoils),
        "smooth_passes": int(settings.smooth_passes),
        "min_trailing_edge_thickness": typed(settings.min_trailing_edge_thickness),
        "section_degree": int(settings.section_degree),
        "span_degree": int(settings.span_degree),
        "tangent_magnitude": ("sqp" if settings.tangent_mode == "SQP"
                              else [typed(settings.tangent_upper), typed(settings.tangent_lower)]),
        "stations": {
            **{name: [typed(getattr(row, name)) for row in rows] for name in STATION_FIELDS},
            "airfoil": [row.airfoil.strip() for row in rows],
            # a row's tolerance 0 means the blade's; any row set gives the per-station array
            **({"tolerance": [typed(row.tolerance) or typed(settings.tolerance) for row in rows]}
               if any(row.tolerance > 0 for row in rows) else {}),
        },
    }


def settings_to_definition(settings) -> BladeDefinition:
    """The validated definition of a property group (DefinitionError names the station)."""
    base = pathlib.Path(bpy.path.abspath(settings.base_dir)) if settings.base_dir else None
    return blade_from_dict(settings_to_dict(settings), "", base)


def definition_to_settings(settings, defn: BladeDefinition, base_dir: str = "") -> None:
    """Write a definition into a property group without regenerating."""
    with suspended_updates():
        settings.is_wind_blade = True
        settings.definition_name = defn.name
        settings.hub_radius = defn.hub_radius
        settings.mold_direction = [float(x) for x in defn.mold_direction]
        settings.wrap = defn.wrap
        settings.first_aerodynamic_station = defn.first_aerodynamic_station
        settings.control_points = defn.control_points
        settings.tolerance = defn.tolerance
        settings.smooth_airfoils = defn.smooth_airfoils
        settings.smooth_passes = defn.smooth_passes
        settings.min_trailing_edge_thickness = defn.min_trailing_edge_thickness
        settings.section_degree = defn.section_degree
        settings.span_degree = defn.span_degree
        settings.tangent_mode = "SQP" if defn.tangent_magnitudes is None else "HAND"
        if defn.tangent_magnitudes is not None:
            settings.tangent_upper, settings.tangent_lower = defn.tangent_magnitudes
        settings.base_dir = base_dir
        settings.source_path = defn.path
        settings.stations.clear()
        for st in defn.stations:
            row = settings.stations.add()
            for name in STATION_FIELDS:
                setattr(row, name, getattr(st, name))
            row.airfoil = st.airfoil_name
        for row, tol in zip(settings.stations, defn.station_tolerances or ()):
            row.tolerance = tol
        settings.stations_index = min(max(settings.stations_index, 0), len(settings.stations) - 1)
        settings.fitted_control_points = 0


def _base_dir(defn: BladeDefinition) -> str:
    return str(pathlib.Path(defn.path).resolve().parent) if defn.path else ""


# -- writing the molds into objects -----------------------------------------------------------
def mold_parts(root) -> dict:
    """Children of a wind-blade root by part name."""
    return {str(child[PART_KEY]): child for child in root.children if child.get(PART_KEY) is not None}


def displayed_entities(molds: BladeMolds, mold_halves: bool) -> dict:
    """Part name -> surface or curve shown for ``molds``."""
    if not mold_halves:
        return {"single": molds.single}
    return {**molds.surfaces, **molds.parting_lines}


def part_label(name: str) -> str:
    return name.replace("_", " ")


def _new_child(root, entity, name: str, part: str):
    collections = list(root.users_collection) or [bpy.context.scene.collection]
    if isinstance(entity, BSplineCurve):
        obj = nurbs_objects.curve_to_object(entity, name, collections[0], resolution=CURVE_RESOLUTION)
    else:
        obj = nurbs_objects.surface_to_object(entity, name, collections[0], resolution=SURFACE_RESOLUTION)
    try:
        for collection in collections[1:]:
            collection.objects.link(obj)
        obj.parent = root
        obj[PART_KEY] = part
    except BaseException:
        remove_object(obj)
        raise
    return obj


def show_molds(root, molds: BladeMolds, mold_halves: bool) -> dict:
    """Make the children of ``root`` show ``molds``, rewriting existing objects in place;
    parts no longer shown are removed. Returns the parts."""
    parts = mold_parts(root)
    wanted = displayed_entities(molds, mold_halves)
    for name in [n for n in parts if n not in wanted]:
        remove_object(parts.pop(name))
    for name, entity in wanted.items():
        obj = parts.get(name)
        is_curve = isinstance(entity, BSplineCurve)
        if obj is not None and obj.type != ("CURVE" if is_curve else "SURFACE"):
            remove_object(parts.pop(name))
            obj = None
        if obj is None:
            parts[name] = _new_child(root, entity, f"{root.name} {part_label(name)}", name)
        elif is_curve:
            write_curve(obj, entity, CURVE_RESOLUTION)
        else:
            write_surface(obj, entity, SURFACE_RESOLUTION)
    root.empty_display_size = 0.1 * molds.definition.stations[-1].r
    return parts


def store_results(settings, molds: BladeMolds, seconds: float) -> None:
    """Record the shown definition, the comparison figures and a status line on the root."""
    defn = molds.definition
    aero = [rep for rep in molds.stations if rep.index >= defn.first_aerodynamic_station]
    with suspended_updates():
        settings.definition_toml = dumps_toml(defn.to_dict())
        settings.fitted_control_points = molds.control_points
        settings.lsq_two_part = float(sum(rep.lsq_two_part for rep in aero))
        settings.lsq_single = float(sum(rep.lsq_single for rep in aero))
        settings.max_deviation = float(max(rep.deviation_two_part for rep in molds.stations))
        settings.le_angle_deg = float(molds.continuity.get("le_angle_deg", 0.0))
        for row, rep in zip(settings.stations, molds.stations):
            row.lsq_two_part = rep.lsq_two_part
            row.lsq_single = rep.lsq_single if math.isfinite(rep.lsq_single) else -1.0
            row.deviation = rep.deviation_two_part
        fair = molds.fairness
        settings.fairness_valid = "two_part" in fair and "single" in fair
        if settings.fairness_valid:
            settings.mvs_two_part = fair["two_part"]["mvs"]
            settings.mvs_single = fair["single"]["mvs"]
            settings.strain_energy_two_part = fair["two_part"]["strain_energy"]
            settings.strain_energy_single = fair["single"]["strain_energy"]
        settings.regeneration_time = seconds
        settings.fitted_ratio = float(molds.ratio)
        settings.aligned_parameters = bool(molds.aligned_parameters)
        smoothed = [st.airfoil.smoothing_deviation for st in defn.stations if st.airfoil.smoothing_deviation is not None]
        note = f"; airfoils smoothed (Hvid), worst deviation {max(smoothed):.2e} chord" if smoothed else ""
        aligned = "; aligned parameters (the chord-length ones missed)" if molds.aligned_parameters else ""
        if getattr(molds, "densified", False):
            aligned = ("; densified fit (the data could not carry the control points the tolerance needs: each "
                       "section's interpolant fitted, deviation at the data points)")
        if settings.fairness_valid:  # both approaches are always built: the numbers in either mode
            shown = "mold halves" if settings.mold_halves else "single surface"
            note += (f"; fairness (Hosseini Eq. 6, shown: {shown}): MVS two-part {settings.mvs_two_part:.4g}, "
                     f"single {settings.mvs_single:.4g}; strain energy two-part "
                     f"{settings.strain_energy_two_part:.4g}, single {settings.strain_energy_single:.4g}")
        settings.status = (f"{molds.control_points} control points per half, worst section "
                           f"{settings.max_deviation:.2e} chord{note}{aligned}; {seconds * 1e3:.0f} ms")
        settings.status_is_error = False


def regenerate(root, *, fresh: bool = False, fairness: bool | None = None, progress=None) -> bool:
    """Rebuild the molds from the root's settings and update its children in place.

    fresh: start the fit from the set control-point count, not the shown one. fairness:
    compute MVS and strain energy (default the ``live_fairness`` setting). An invalid value
    leaves the geometry as it is and puts the message in ``status``. Returns success."""
    settings = root.bladesmith_wind_blade
    start = time.perf_counter()
    try:
        defn = settings_to_definition(settings)
        n = defn.control_points
        if not fresh and settings.fitted_control_points > n:
            n = settings.fitted_control_points
        molds = compute_molds(defn, control_points=n, tolerance=0.0,
                              fairness=settings.live_fairness if fairness is None else fairness, progress=progress)
    except BladesmithError as exc:
        with suspended_updates():
            settings.status = str(exc)
            settings.status_is_error = True
        return False
    show_molds(root, molds, settings.mold_halves)
    store_results(settings, molds, time.perf_counter() - start)
    return True


def on_settings_edited(root) -> None:
    """The properties' update callback: regenerate unless updates are suspended."""
    if _suspended or root is None or not root.bladesmith_wind_blade.is_wind_blade:
        return
    regenerate(root)


def on_fit_settings_edited(root) -> None:
    """control_points / tolerance edited: the fit starts again from the set count."""
    if _suspended or root is None or not root.bladesmith_wind_blade.is_wind_blade:
        return
    regenerate(root, fresh=True)


def find_root(obj):
    """The wind-blade root of ``obj`` (itself or its parent), or None."""
    for candidate in (obj, getattr(obj, "parent", None)):
        settings = getattr(candidate, "bladesmith_wind_blade", None) if candidate is not None else None
        if settings is not None and settings.is_wind_blade:
            return candidate
    return None


def create_wind_blade(context, molds: BladeMolds, mold_halves: bool, seconds: float):
    """A new root Empty with children showing ``molds``; on any failure everything made so
    far is removed again, so the scene is unchanged."""
    defn = molds.definition
    root = bpy.data.objects.new(defn.name, None)
    try:
        root.empty_display_type = "PLAIN_AXES"
        root.location = context.scene.cursor.location
        context.collection.objects.link(root)
        settings = root.bladesmith_wind_blade
        definition_to_settings(settings, defn, _base_dir(defn))
        with suspended_updates():
            settings.mold_halves = mold_halves
        show_molds(root, molds, mold_halves)
        store_results(settings, molds, seconds)
        for obj in context.view_layer.objects:
            obj.select_set(False)
        root.select_set(True)
        context.view_layer.objects.active = root
    except BaseException:
        for child in list(root.children):
            remove_object(child)
        bpy.data.objects.remove(root, do_unlink=True)
        raise
    return root


def _override(defn: BladeDefinition, control_points: int, tolerance: float) -> BladeDefinition:
    """``defn`` with the operator's control-point count and tolerance (0 = keep)."""
    if not control_points and not tolerance:
        return defn
    data = defn.to_dict()
    if control_points:
        data["control_points"] = int(control_points)
    if tolerance:
        data["tolerance"] = float(tolerance)
    # the stations' airfoils are already read; re-reading by name resolves relative paths
    base = pathlib.Path(defn.path).parent if defn.path else None
    return blade_from_dict(data, defn.path, base)


# -- operators ------------------------------------------------------------------------------
class BLADESMITH_OT_add_wind_blade(bpy.types.Operator):
    """Add wind-turbine blade molds from a definition file or a preset: upper and lower mold halves, root transitions and parting lines (Hosseini & Moetakef-Imani 2016)"""

    bl_idname = "bladesmith.add_wind_blade"
    bl_label = "Add Wind Blade"
    bl_options = {"REGISTER", "UNDO"}

    definition: StringProperty(
        name="Definition", description="Blade definition file (.toml, or a windIO turbine .yaml); when empty, "
        "the preset is used",
        subtype="FILE_PATH", default="",
    )
    preset: StringProperty(
        name="Preset", description="Preset name, the file stem in data/blades (case-insensitive), e.g. NREL5MW",
        default=PRESET_ITEMS[0][0],
    )
    preset_choice: EnumProperty(name="Preset", description="Preset definition", items=PRESET_ITEMS)
    mold_halves: BoolProperty(
        name="Mold Halves",
        description="Upper and lower mold surfaces split at the silhouette (G1 at the leading-edge parting line), "
        "root transitions and parting lines; off: the single traditional lofted surface",
        default=True,
    )
    control_points: IntProperty(
        name="Control Points",
        description="Control points per half and section to start from (raised until the tolerance holds); "
        "0 = the definition's",
        default=0, soft_min=0, soft_max=60,
    )
    tolerance: FloatProperty(
        name="Tolerance",
        description="Largest distance of a section from its airfoil points, as a fraction of the local chord; "
        "0 = the definition's (1e-4 by default)",
        default=0.0, soft_min=0.0, soft_max=1e-2, precision=6, step=0.001,
    )
    fairness: BoolProperty(
        name="Fairness", description="Compute MVS and strain energy of both approaches (Hosseini Eq. 6)",
        default=True,
    )

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT"

    def _preset_name(self) -> str:
        if self.properties.is_property_set("preset") or not self.properties.is_property_set("preset_choice"):
            return self.preset
        return self.preset_choice

    @unchanged_on_refusal
    def execute(self, context):
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            start = time.perf_counter()
            tolerance = typed(self.tolerance)  # the float32 property as typed
            check_fit_settings(self.control_points, tolerance)
            defn = _override(load_definition(self.definition, self._preset_name()), self.control_points, tolerance)
            try:
                molds = compute_molds(defn, fairness=self.fairness, progress=progress_callback(wm))
            except GeometryError as exc:  # the station and cause are in the message; name the file
                raise DefinitionError(str(exc), path=defn.path or None) from None
            root = create_wind_blade(context, molds, self.mold_halves, time.perf_counter() - start)
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        self.report({"INFO"}, f"{root.name}: {root.bladesmith_wind_blade.status}")
        return {"FINISHED"}


class _OnRoot:
    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT" and find_root(context.active_object) is not None

    def _regenerate(self, context, **options):
        """Regenerate the active wind blade with progress; report a failure."""
        root = find_root(context.active_object)
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            ok = regenerate(root, progress=progress_callback(wm), **options)
        finally:
            wm.progress_end()
        if not ok:
            self.report({"ERROR"}, root.bladesmith_wind_blade.status)
            return {"CANCELLED"}
        return {"FINISHED"}


class BLADESMITH_OT_regenerate_wind_blade(_OnRoot, bpy.types.Operator):
    """Rebuild the active wind blade from its settings, starting the fit from the set control-point count"""

    bl_idname = "bladesmith.regenerate_wind_blade"
    bl_label = "Regenerate Wind Blade"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        return self._regenerate(context, fresh=True)


class BLADESMITH_OT_wind_blade_fairness(_OnRoot, bpy.types.Operator):
    """Compute MVS and strain energy of the two-part and the single surface (Hosseini Eq. 6)"""

    bl_idname = "bladesmith.wind_blade_fairness"
    bl_label = "Compute Fairness"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        return self._regenerate(context, fairness=True)


class BLADESMITH_OT_wind_blade_station_add(_OnRoot, bpy.types.Operator):
    """Insert a station after the active one (midway to the next, same airfoil)"""

    bl_idname = "bladesmith.wind_blade_station_add"
    bl_label = "Add Station"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        root = find_root(context.active_object)
        settings = root.bladesmith_wind_blade
        rows = settings.stations
        with suspended_updates():
            if len(rows) == 0:
                rows.add().airfoil = "circle"
                settings.stations_index = 0
            else:
                i = min(max(settings.stations_index, 0), len(rows) - 1)
                here = rows[i]
                there = rows[i + 1] if i + 1 < len(rows) else None
                row = rows.add()
                for name in STATION_FIELDS:
                    a = getattr(here, name)
                    b = getattr(there, name) if there is not None else a
                    setattr(row, name, 0.5 * (a + b))
                if there is None:  # beyond the tip: one more step of the last spacing
                    row.r = here.r + (here.r - rows[i - 1].r if i > 0 else 0.1 * here.r)
                row.airfoil = here.airfoil
                rows.move(len(rows) - 1, i + 1)
                settings.stations_index = i + 1
        regenerate(root)
        return {"FINISHED"}


class BLADESMITH_OT_wind_blade_station_remove(_OnRoot, bpy.types.Operator):
    """Remove the active station"""

    bl_idname = "bladesmith.wind_blade_station_remove"
    bl_label = "Remove Station"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        root = find_root(context.active_object)
        settings = root.bladesmith_wind_blade
        i = settings.stations_index
        if not 0 <= i < len(settings.stations):
            self.report({"ERROR"}, "no active station to remove")
            return {"CANCELLED"}
        with suspended_updates():
            settings.stations.remove(i)
            settings.stations_index = max(0, min(i, len(settings.stations) - 1))
        regenerate(root)
        return {"FINISHED"}


def export_molds(settings, filepath: str, progress=None, caps: str = "NONE") -> str:
    """Write the shown molds (rebuilt from the last good definition, with the shown
    control-point count, so IGES comes from the float64 model) to ``filepath`` in metres:
    the surfaces as 128, the parting lines as 126; the single surface alone when the
    halves are off. caps "RULED", "PLANAR" or "ROUNDED": the closed blade instead, the mold surfaces
    with root and tip caps (:func:`..iges.mold.write_closed_blade`)."""
    if not settings.definition_toml:
        raise DefinitionError("the wind blade has no generated geometry to export")
    base = pathlib.Path(bpy.path.abspath(settings.base_dir)) if settings.base_dir else None
    defn = blade_from_dict(tomllib.loads(settings.definition_toml), "", base)
    n = max(defn.control_points, settings.fitted_control_points)
    molds = compute_molds(defn, control_points=n, tolerance=0.0, fairness=False, progress=progress)
    if caps != "NONE":
        from ..iges.mold import write_closed_blade

        return write_closed_blade(filepath, molds, units="m", caps=caps.lower())
    if settings.mold_halves:
        return write_molds(filepath, molds, units="m")
    return write_iges(filepath, [surface_from_geometry(molds.single, label="SINGLE")], units="m")


class BLADESMITH_OT_export_wind_blade_iges(_OnRoot, bpy.types.Operator):
    """Export the active wind blade's molds as IGES (surfaces as entity 128, parting lines as 126, metres)"""

    bl_idname = "bladesmith.export_wind_blade_iges"
    bl_label = "Export Molds (IGES)"
    bl_options = {"REGISTER"}

    filepath: StringProperty(name="File Path", subtype="FILE_PATH")
    filter_glob: StringProperty(default="*.igs;*.iges", options={"HIDDEN"})
    check_existing: BoolProperty(default=True, options={"HIDDEN"})
    caps: EnumProperty(
        name="Caps",
        description="Close the blade with root and tip caps (one closed shell for CFD or FE), or write the open "
                    "mold halves",
        items=[("NONE", "Mold halves (open)", "The mold surfaces and parting lines, open at root and tip"),
               ("RULED", "Closed, ruled caps", "Caps ruled between the halves' end sections (any section)"),
               ("PLANAR", "Closed, planar caps", "Trimmed planes over the end sections (only planar sections)"),
               ("ROUNDED", "Closed, rounded tip", "A planar root (the flange face) and a rounded tip tangent to the "
                "mold halves")],
        default="NONE",
    )

    def invoke(self, context, event):
        if not self.filepath:
            name = find_root(context.active_object).bladesmith_wind_blade.definition_name
            self.filepath = (bpy.path.clean_name(name) or "blade").lower() + "_molds.igs"
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        root = find_root(context.active_object)
        path = bpy.path.abspath(self.filepath)
        if not path:
            self.report({"ERROR"}, "no file path given")
            return {"CANCELLED"}
        if pathlib.Path(path).suffix.lower() not in (".igs", ".iges"):
            path += ".igs"
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            export_molds(root.bladesmith_wind_blade, path, progress=progress_callback(wm), caps=self.caps)
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        except OSError as exc:
            self.report({"ERROR"}, f"{path}: cannot write ({exc.strerror or exc})")
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        self.report({"INFO"}, f"Exported {path}")
        return {"FINISHED"}


class BLADESMITH_OT_save_wind_blade_definition(_OnRoot, bpy.types.Operator):
    """Save the active wind blade's definition as TOML (airfoil paths rewritten for the new folder)"""

    bl_idname = "bladesmith.save_wind_blade_definition"
    bl_label = "Save Wind Blade Definition"
    bl_options = {"REGISTER"}

    filepath: StringProperty(name="File Path", subtype="FILE_PATH")
    filter_glob: StringProperty(default="*.toml", options={"HIDDEN"})
    check_existing: BoolProperty(default=True, options={"HIDDEN"})

    def invoke(self, context, event):
        if not self.filepath:
            name = find_root(context.active_object).bladesmith_wind_blade.definition_name
            self.filepath = (bpy.path.clean_name(name) or "blade").lower() + ".toml"
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        settings = find_root(context.active_object).bladesmith_wind_blade
        path = bpy.path.abspath(self.filepath)
        if not path:
            self.report({"ERROR"}, "no file path given")
            return {"CANCELLED"}
        if pathlib.Path(path).suffix.lower() != ".toml":
            path += ".toml"
        base = pathlib.Path(bpy.path.abspath(settings.base_dir)) if settings.base_dir else None
        try:
            save_blade(settings_to_dict(settings), path, base)
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        except OSError as exc:
            self.report({"ERROR"}, f"{path}: cannot write ({exc.strerror or exc})")
            return {"CANCELLED"}
        self.report({"INFO"}, f"Saved {path}")
        return {"FINISHED"}


class BLADESMITH_OT_wind_blade_sweep(_OnRoot, bpy.types.Operator):
    """Tabulate LSQ error, MVS and strain energy of the two-part molds and the single surface at each control-point count (Hosseini Figs. 5, 8, 10, 11) into a text block"""

    bl_idname = "bladesmith.wind_blade_sweep"
    bl_label = "Control-Point Sweep"
    bl_options = {"REGISTER"}

    counts: StringProperty(name="Counts", description="Control points per half, separated by spaces or commas",
                           default="8 12 16 20")

    def execute(self, context):
        root = find_root(context.active_object)
        settings = root.bladesmith_wind_blade
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            try:
                counts = [int(c) for c in self.counts.replace(",", " ").split()]
            except ValueError:
                raise DefinitionError(f"expected integers, got {self.counts!r}", field="counts") from None
            rows = control_point_sweep(settings_to_definition(settings), counts, progress=progress_callback(wm))
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        name = f"{settings.definition_name} sweep"
        text = bpy.data.texts.get(name) or bpy.data.texts.new(name)
        text.from_string(f"{settings.definition_name}: control-point sweep (equal total control points)\n\n"
                         + format_sweep(rows) + "\n")
        self.report({"INFO"}, f"Sweep of {len(rows)} counts in the text block {name!r}")
        return {"FINISHED"}


class BLADESMITH_OT_import_windio_blade(bpy.types.Operator):
    """Import the blade of a windIO turbine file (YAML, windIO 1.x or 2.x) as wind-blade molds"""

    bl_idname = "bladesmith.import_windio_blade"
    bl_label = "Import windIO Blade"
    bl_options = {"REGISTER", "UNDO"}

    filepath: StringProperty(name="File Path", subtype="FILE_PATH")
    filter_glob: StringProperty(default="*.yaml;*.yml", options={"HIDDEN"})
    mold_halves: BoolProperty(name="Mold Halves", description="Mold halves; off: the single surface", default=True)
    control_points: IntProperty(name="Control Points", description="Control points per half to start from; "
                                "0 = the default", default=0, soft_min=0, soft_max=60)
    tolerance: FloatProperty(name="Tolerance", description="Largest section deviation as a chord fraction; "
                             "0 = the default (1e-4)", default=0.0, soft_min=0.0, soft_max=1e-2, precision=6,
                             step=0.001)
    fairness: BoolProperty(name="Fairness", description="Compute MVS and strain energy", default=False)

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT"

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        return bpy.ops.bladesmith.add_wind_blade(
            definition=self.filepath, mold_halves=self.mold_halves, control_points=self.control_points,
            tolerance=self.tolerance, fairness=self.fairness)


def menu_import_windio(self, context):
    self.layout.operator(BLADESMITH_OT_import_windio_blade.bl_idname, text="windIO Wind Blade (.yaml)")


def menu_add_wind_blade(self, context):
    self.layout.operator_menu_enum(BLADESMITH_OT_add_wind_blade.bl_idname, "preset_choice", text="Wind Blade",
                                   icon="MOD_SIMPLEDEFORM")


_classes = (
    BLADESMITH_OT_add_wind_blade,
    BLADESMITH_OT_regenerate_wind_blade,
    BLADESMITH_OT_wind_blade_fairness,
    BLADESMITH_OT_wind_blade_station_add,
    BLADESMITH_OT_wind_blade_station_remove,
    BLADESMITH_OT_export_wind_blade_iges,
    BLADESMITH_OT_save_wind_blade_definition,
    BLADESMITH_OT_wind_blade_sweep,
    BLADESMITH_OT_import_windio_blade,
)
_register, _unregister = bpy.utils.register_classes_factory(_classes)


def register():
    _register()
    bpy.types.VIEW3D_MT_add.append(menu_add_wind_blade)
    bpy.types.TOPBAR_MT_file_import.append(menu_import_windio)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(menu_import_windio)
    bpy.types.VIEW3D_MT_add.remove(menu_add_wind_blade)
    _unregister()
