"""Propellers in Blender: ``bpy.ops.bladesmith.add_propeller`` and live regeneration.

Objects
-------
A propeller is a root Empty named after the definition, holding every definition value
and the tip-smoothing settings in ``Object.bladesmith_propeller`` (the property group of
:mod:`..ui.propeller_panel`), and as children:

- ``<name> blade``: the reference blade (at +y), a SURFACE object showing the cubic
  display surface of :func:`~..geometry.propeller.display.blade_display_surface` exactly
  (Bezier form, see :mod:`.nurbs_objects`), with the float64 surface stored on it;
- ``<name> blade 2`` ... ``<name> blade Z``: linked copies (the same curve data) turned by
  2π(k-1)/Z about the axis in the sense of θ (:meth:`PropellerModel.blade_rotation`);
- ``<name> hub``: the exact rational surface of revolution (:func:`hub_surface`).

Children carry ``bladesmith_part`` ("blade" or "hub"), ``bladesmith_patch`` (the surface
index of a blade made of several patches, 0 for the unsmoothed blade) and
``bladesmith_blade`` (0 for the reference blade, k for copy k).

Regeneration
------------
Every value of the property group has an ``update`` callback that calls
:func:`on_settings_edited`: the definition is rebuilt from the properties and validated,
the display surfaces are recomputed, and the children are rewritten in place (the same
objects and curve data-blocks; only the control points change when the net keeps its
size). While editing, the blade's previous knot vectors seed the display fit, so the net
keeps its size as long as those knots still meet the display tolerance and Blender's data
is rewritten without entering edit mode. An invalid value leaves the last good geometry
and shows the message (naming the field and the value) in the panel's status line.
The definition of the last good geometry is kept on the root as TOML text
(``definition_toml``), so it survives saving and reopening the .blend file.

Tip smoothing
-------------
With ``smooth_tip`` the blade surfaces come from
``geometry.propeller.smoothing.smooth_blade(model, settings, progress=...)`` (settings:
:func:`smoothing_settings`, lengths in metres), and :func:`show_result` shows each of the
five surfaces as a blade patch with its own Z - 1 linked copies. Smoothing runs on every
edit while ``smooth_tip`` is on (about 0.33 s for DTMB 4119 on a quiet 2-core machine,
``bench/bench_propeller_pipeline.py``), so live editing is meant for the unsmoothed blade.

Units of the operator and panel settings: ``delta_c`` (Δc), ``tip_smoothing_distance``
(d_t), ``edge_smoothing_distance`` (d_e), ``tolerance``, ``sample_spacing`` (d) and
``display_tolerance`` are fractions of the diameter D; :func:`smoothing_settings` converts
them to metres. ``edge_spacing_ratio`` is h/d; ``xi_ll`` ... ``eta_te`` are the six
defining points of Hally §4 in blade parameters.

Definition files may carry a [smoothing] table (lengths in metres,
:data:`~..geometry.propeller.definition.SMOOTHING_KEYS`): ``add_propeller`` takes from it
every setting the call does not set, Load takes all of it, and Save writes every
smoothing setting of the panel into it (:func:`smoothing_table`).
"""
import hashlib
import math
import pathlib
import time
import tomllib
from contextlib import contextmanager
from copy import deepcopy
from dataclasses import dataclass

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

from ..geometry.errors import BladesmithError, DefinitionError, GeometryError
from ..geometry.nurbs import BSplineSurface
from ..geometry.propeller import BladeSurface, Hub, Propeller, PropellerModel, dumps_toml, smooth_blade
from ..geometry.propeller.corners import DefiningPoints
from ..geometry.propeller.definition import DEFINING_POINT_KEYS, RADIAL_FIELDS, SMOOTHING_KEYS
from ..geometry.propeller.display import DISPLAY_TOLERANCE_FRACTION, blade_display_surface, hub_surface
from .progress import progress_callback
from .nurbs_objects import PROPERTY_KEY, remove_object, write_surface
from .values import typed
from .scene_guard import unchanged_on_refusal

#: The extension package (``bladesmith`` from a checkout, ``bl_ext.<repo>.bladesmith``
#: when installed).
PRESET_DIR = pathlib.Path(__file__).resolve().parent.parent / "data" / "propellers"

#: Custom properties naming a child's part (see the module docstring).
PART_KEY = "bladesmith_part"
PATCH_KEY = "bladesmith_patch"
BLADE_KEY = "bladesmith_blade"

#: Blender evaluates ``resolution`` points per control point and direction. The blade's
#: Bezier net has three control points per knot span, the hub's two per arc.
BLADE_RESOLUTION = 2
HUB_RESOLUTION = 6
#: The smoothed blade's five patches carry nets about seven times as dense as the
#: unsmoothed display fit (31 control points along each of about 40 cuts, 118 x 118 in
#: Bezier form): one evaluated point per Bezier control point shows them as finely as the
#: unsmoothed blade at BLADE_RESOLUTION, and Blender's evaluation of the 5 Z patch objects
#: after a live edit costs a quarter of what it costs at 2 (the display only: the surfaces
#: stored on the objects and exported are exact either way).
SMOOTHED_BLADE_RESOLUTION = 1

# -- the settings, with their defaults ---------------------------------------------------
#: Default tip-smoothing settings (Hally 2013 §§6–9), the defaults of
#: ``geometry.propeller.smoothing.SmoothingSettings`` (which counts lengths in R).
#: Lengths here are fractions of the diameter D.
DEFAULT_DELTA_C = 0.01
DEFAULT_TIP_SMOOTHING_DISTANCE = 0.05
DEFAULT_EDGE_SMOOTHING_DISTANCE = 0.025
DEFAULT_TRANSITION_S = 0.75
DEFAULT_FILTER_STRENGTH = 0.5
DEFAULT_FILTER_ITERATIONS = 100
DEFAULT_TOLERANCE = 1e-5
#: d of Hally Eqs. 27-28 (the largest spacing of a cut's samples) and h/d of Eq. 28.
DEFAULT_SAMPLE_SPACING = 0.005
DEFAULT_EDGE_SPACING_RATIO = 0.01
#: Above this, Eq. 29's fourth-difference filter amplifies the shortest wave
#: (1 - 16β/6 < -1 for β > 0.75).
MAX_FILTER_STRENGTH = 0.75

SMOOTHING_FIELDS = (
    "delta_c",
    "tip_smoothing_distance",
    "edge_smoothing_distance",
    "transition_s",
    "filter_strength",
    "filter_iterations",
    "tolerance",
    "sample_spacing",
    "edge_spacing_ratio",
    *DEFINING_POINT_KEYS,
)
#: Smoothing settings given as fractions of D (converted to metres for geometry/).
LENGTH_FRACTIONS = ("delta_c", "tip_smoothing_distance", "edge_smoothing_distance", "tolerance", "sample_spacing")
#: What the six defining points of Hally (2013) §4 (Fig. 4) are, for their tooltips.
DEFINING_POINT_TEXT = {
    "xi_ll": ("ξ_LL", "ξ of the lower-left corner of the pressure-side central surface, on the hub "
              "(trailing-edge side), in (0, 0.25)"),
    "xi_lr": ("ξ_LR", "ξ of the lower-right corner of the pressure-side central surface, on the hub "
              "(leading-edge side), in (0.25, 0.5)"),
    "xi_ul": ("ξ_UL", "ξ of the upper-left corner of the pressure-side central surface, in (0, 0.25)"),
    "eta_ul": ("η_UL", "η (= r/R) of the upper-left corner of the pressure-side central surface"),
    "xi_ur": ("ξ_UR", "ξ of the upper-right corner of the pressure-side central surface, in (0.25, 0.5)"),
    "eta_ur": ("η_UR", "η (= r/R) of the upper-right corner of the pressure-side central surface"),
    "eta_le": ("η_LE", "η (= r/R) of x_LE on the leading edge, where the tip surface begins"),
    "eta_te": ("η_TE", "η (= r/R) of x_TE on the trailing edge, where the tip surface begins"),
}

#: Section names of the definition format and the panel's enum identifiers.
THICKNESS_FORMS = {"NACA66MOD": "naca66mod", "NACA4": "naca4", "ELLIPTIC": "elliptic", "TABLE": "table"}
THICKNESS_FILE = "FILE"
MEANLINES = {
    "A08": "a=0.8",
    "A08MOD": "a=0.8mod",
    "PARABOLIC": "parabolic",
    "NACA4": "naca4",
    "NONE": "none",
    "TABLE": "table",
    "AIRFOIL": "airfoil",
}


def smoothing_properties(smooth_default: bool = False, update=None) -> dict:
    """The smoothing settings as bpy properties (shared by the operator and the property
    group, so both document the same units and defaults); ``update``: the callback of
    every property, or None."""
    extra = {} if update is None else {"update": update}
    return {
        "smooth_tip": BoolProperty(
            name="Smooth Tip",
            description="Replace the blade by Hally's five smoothed spline surfaces with exactly matching edges "
            "(Hally 2013 §§4-9)",
            default=smooth_default,
            **extra,
        ),
        "show_overlay": BoolProperty(
            name="Show Cuts",
            description="Show the blade cuts, the c_LETE curve and the transition cut j as curve objects "
            "(tip smoothing only)",
            default=False,
            **extra,
        ),
        "delta_c": FloatProperty(
            name="Δc / D",
            description="Δc: largest spacing of the blade cuts along the leading and trailing edges, "
            "as a fraction of the diameter (Hally 2013 §8, Eq. 31)",
            default=DEFAULT_DELTA_C, soft_min=1e-4, soft_max=0.1, precision=4, step=0.1, **extra,
        ),
        "tip_smoothing_distance": FloatProperty(
            name="d_t / D",
            description="d_t: arclength along the edges from the tip over which cuts are smoothed, "
            "as a fraction of the diameter (Hally 2013 Eq. 30)",
            default=DEFAULT_TIP_SMOOTHING_DISTANCE, soft_min=1e-3, soft_max=0.5, precision=4, step=0.1, **extra,
        ),
        "edge_smoothing_distance": FloatProperty(
            name="d_e / D",
            description="d_e: distance from the leading or trailing edge within which a cut is smoothed, "
            "as a fraction of the diameter (Hally 2013 Eq. 30)",
            default=DEFAULT_EDGE_SMOOTHING_DISTANCE, soft_min=1e-3, soft_max=0.5, precision=4, step=0.1, **extra,
        ),
        "transition_s": FloatProperty(
            name="s_j",
            description="s_j: edge parameter of the transition cut, in (0, 1) (Hally 2013 Eq. 48)",
            default=DEFAULT_TRANSITION_S, soft_min=0.05, soft_max=0.95, precision=3, **extra,
        ),
        "filter_strength": FloatProperty(
            name="α",
            description=f"α: strength of the Laplace filter, in (0, {MAX_FILTER_STRENGTH}] (Hally 2013 Eqs. 29-30)",
            default=DEFAULT_FILTER_STRENGTH, soft_min=0.01, soft_max=MAX_FILTER_STRENGTH, precision=3, **extra,
        ),
        "filter_iterations": IntProperty(
            name="Iterations",
            description="n: iterations of the smoothing filter (Hally 2013 Eq. 29)",
            default=DEFAULT_FILTER_ITERATIONS, min=0, soft_max=500, **extra,
        ),
        "tolerance": FloatProperty(
            name="Tolerance / D",
            description="Spline approximation tolerance of the smoothed surfaces, as a fraction of the diameter",
            default=DEFAULT_TOLERANCE, soft_min=1e-7, soft_max=1e-3, precision=7, step=0.001, **extra,
        ),
        "sample_spacing": FloatProperty(
            name="d / D",
            description="d: largest spacing of the points sampled on a cut for the smoothing filter, as a fraction "
            "of the diameter (Hally 2013 Eqs. 27-28)",
            default=DEFAULT_SAMPLE_SPACING, soft_min=1e-4, soft_max=0.05, precision=5, step=0.01, **extra,
        ),
        "edge_spacing_ratio": FloatProperty(
            name="h / d",
            description="h/d: spacing of the cut samples at the leading or trailing edge over their largest "
            "spacing d, in (0, 1) (Hally 2013 Eq. 28; Hally uses 1/100)",
            default=DEFAULT_EDGE_SPACING_RATIO, soft_min=1e-3, soft_max=0.5, precision=4, step=0.01, **extra,
        ),
        **{key: FloatProperty(
            name=label,
            description=f"{text} (Hally 2013 §4, Fig. 4: the points that split the blade into five surfaces)",
            default=getattr(DefiningPoints(), key), soft_min=0.0, soft_max=1.0, precision=4, step=0.1, **extra,
        ) for key, (label, text) in DEFINING_POINT_TEXT.items()},
    }


def display_tolerance_property(update=None):
    extra = {} if update is None else {"update": update}
    return FloatProperty(
        name="Display Tolerance / D",
        description="Largest distance of the displayed unsmoothed blade from the model b(ξ, η), "
        "as a fraction of the diameter",
        default=DISPLAY_TOLERANCE_FRACTION, soft_min=1e-6, soft_max=1e-2, precision=6, step=0.001, **extra,
    )


def check_smoothing(values: dict) -> None:
    """Refuse smoothing settings outside their ranges (DefinitionError naming the field)."""
    for name in SMOOTHING_FIELDS:
        value = values[name]
        if not math.isfinite(value):
            raise DefinitionError(f"value {value} is not finite", field=name)
    for name in ("delta_c", "tip_smoothing_distance", "edge_smoothing_distance", "tolerance"):
        if values[name] <= 0:
            raise DefinitionError(f"must be a positive fraction of the diameter, got {values[name]}", field=name)
    if not 0.0 < values["transition_s"] < 1.0:
        raise DefinitionError(f"s_j must lie in (0, 1), got {values['transition_s']}", field="transition_s")
    if not 0.0 < values["filter_strength"] <= MAX_FILTER_STRENGTH:
        raise DefinitionError(
            f"α must lie in (0, {MAX_FILTER_STRENGTH}], got {values['filter_strength']}", field="filter_strength"
        )
    if values["filter_iterations"] < 0:
        raise DefinitionError(f"must not be negative, got {values['filter_iterations']}", field="filter_iterations")
    if values["sample_spacing"] <= 0:
        raise DefinitionError(f"d must be a positive fraction of the diameter, got {values['sample_spacing']}",
                              field="sample_spacing")
    if not 0.0 < values["edge_spacing_ratio"] < 1.0:
        raise DefinitionError(f"h/d must lie in (0, 1), got {values['edge_spacing_ratio']}", field="edge_spacing_ratio")
    DefiningPoints(**{key: values[key] for key in DEFINING_POINT_KEYS}).validate()


def check_display_tolerance(value: float) -> float:
    if not (math.isfinite(value) and value > 0):
        raise DefinitionError(f"must be a positive fraction of the diameter, got {value}", field="display_tolerance")
    return value


def smoothing_settings(values: dict, diameter: float) -> dict:
    """Smoothing settings for geometry/ (lengths in metres): a plain dict keyed like the
    operator's properties."""
    # Blender keeps float32: take the decimal the user typed (0.1, not 0.10000000149), so
    # the settings of the panel give the same geometry as the same settings given in R
    out = {name: typed(values[name]) for name in SMOOTHING_FIELDS if name not in DEFINING_POINT_KEYS}
    for name in LENGTH_FRACTIONS:
        out[name] = typed(values[name]) * diameter
    out["filter_iterations"] = int(values["filter_iterations"])
    out["defining_points"] = {key: typed(values[key]) for key in DEFINING_POINT_KEYS}
    return out


def smoothing_table(values: dict, diameter: float) -> dict:
    """The [smoothing] table of a definition file (lengths in metres) from operator or
    panel values (lengths as fractions of D; ``smooth_tip`` included when given)."""
    out = {}
    for name in SMOOTHING_KEYS:
        if name not in values:
            continue
        value = values[name]
        if name == "smooth_tip":
            out[name] = bool(value)
        elif name == "filter_iterations":
            out[name] = int(value)
        elif name in LENGTH_FRACTIONS:
            out[name] = typed(value) * diameter
        else:
            out[name] = typed(value)
    return out


def file_smoothing_values(propeller: Propeller) -> dict:
    """The [smoothing] table of a definition as operator values (lengths as fractions
    of D): only the keys the file gives."""
    out = {}
    for name, value in (propeller.smoothing or {}).items():
        out[name] = value / propeller.diameter if name in LENGTH_FRACTIONS else value
    return out


# -- presets ----------------------------------------------------------------------------
def preset_files() -> dict[str, pathlib.Path]:
    """Preset name (the file stem in capitals, e.g. "DTMB4119") -> definition file."""
    return {path.stem.upper(): path for path in sorted(PRESET_DIR.glob("*.toml"))}


def preset_path(name: str) -> pathlib.Path:
    """The definition file of a preset, matched without regard to case (also accepts the
    file name with its .toml suffix)."""
    key = str(name).strip().upper()
    if key.endswith(".TOML"):
        key = key[: -len(".TOML")]
    files = preset_files()
    if key not in files:
        raise DefinitionError(f"unknown preset {name!r}; known presets: {', '.join(files)}", field="preset")
    return files[key]


def _preset_label(path: pathlib.Path) -> str:
    try:
        with open(path, "rb") as fh:
            return str(tomllib.load(fh).get("name", path.stem))
    except (OSError, tomllib.TOMLDecodeError):
        return path.stem


#: EnumProperty items, built once (Blender needs the list to stay alive).
PRESET_ITEMS = [(key, _preset_label(path), f"Preset {path.name}") for key, path in preset_files().items()] or [
    ("NONE", "No presets", "data/propellers holds no .toml file")
]


# -- settings <-> definition --------------------------------------------------------------
_suspended = 0


@contextmanager
def suspended_updates():
    """Property writes inside this block do not regenerate (the update callbacks return)."""
    global _suspended
    _suspended += 1
    try:
        yield
    finally:
        _suspended -= 1


def updates_suspended() -> bool:
    return _suspended > 0


def settings_to_dict(settings, with_smoothing: bool = False) -> dict:
    """The definition (TOML layout) of a property group; ``with_smoothing``: with the
    [smoothing] table of all the smoothing settings (what Save writes)."""
    kind = settings.thickness_kind
    if kind == THICKNESS_FILE:
        thickness = bpy.path.abspath(settings.thickness_file) if settings.thickness_file else ""
    else:
        thickness = THICKNESS_FORMS[kind]
    section = {"thickness": thickness, "meanline": MEANLINES[settings.meanline]}
    if kind == THICKNESS_FILE and settings.smooth_airfoil:  # only an airfoil file is smoothed
        section["smooth_airfoil"] = True
        section["smooth_passes"] = int(settings.smooth_passes)
    if kind == "TABLE":
        section["thickness_x_c"] = [typed(row.x_c) for row in settings.thickness_table]
        section["thickness_t"] = [typed(row.value) for row in settings.thickness_table]
    if settings.meanline == "TABLE":
        section["meanline_x_c"] = [typed(row.x_c) for row in settings.meanline_table]
        section["meanline_f"] = [typed(row.value) for row in settings.meanline_table]
    out = {
        "name": settings.definition_name,
        "blades": int(settings.blades),
        "diameter": typed(settings.diameter),
        "hub_diameter_ratio": typed(settings.hub_diameter_ratio),
        "hand": settings.hand.lower(),
        "section": section,
        "hub": {
            "upstream_length": typed(settings.hub_upstream_length),
            "downstream_length": typed(settings.hub_downstream_length),
            "nose_shape": settings.hub_nose_shape.lower(),
            "nose_length": typed(settings.hub_nose_length),
            "tail_shape": settings.hub_tail_shape.lower(),
            "tail_length": typed(settings.hub_tail_length),
        },
        "radial": {name: [typed(getattr(row, name)) for row in settings.radial] for name in RADIAL_FIELDS},
    }
    if with_smoothing:
        values = smoothing_values(settings)
        values["smooth_tip"] = settings.smooth_tip
        out["smoothing"] = smoothing_table(values, out["diameter"])
    return out


def settings_to_definition(settings, with_smoothing: bool = False) -> Propeller:
    """The validated definition of a property group (DefinitionError names the field)."""
    return Propeller.from_dict(settings_to_dict(settings, with_smoothing))


def smoothing_values(source) -> dict:
    """The smoothing settings of an operator or property group, as plain numbers."""
    return {name: getattr(source, name) for name in SMOOTHING_FIELDS}


def definition_to_settings(settings, propeller: Propeller, smoothing: dict | None = None,
                           display_tolerance: float | None = None) -> None:
    """Write a definition (and optionally the smoothing settings) into a property group,
    without regenerating."""
    with suspended_updates():
        settings.is_propeller = True
        settings.definition_name = propeller.name
        settings.blades = propeller.blades
        settings.diameter = propeller.diameter
        settings.hub_diameter_ratio = propeller.hub_diameter_ratio
        settings.hand = propeller.hand.upper()
        sec = propeller.section
        kinds = {v: k for k, v in THICKNESS_FORMS.items()}
        if sec.thickness in kinds:
            settings.thickness_kind = kinds[sec.thickness]
            settings.thickness_file = ""
        else:
            path = pathlib.Path(sec.thickness)
            if propeller.base_dir is not None and not path.is_absolute():
                path = propeller.base_dir / path
            settings.thickness_kind = THICKNESS_FILE
            settings.thickness_file = str(path.resolve())
        settings.meanline = {v: k for k, v in MEANLINES.items()}[sec.meanline]
        settings.smooth_airfoil = sec.smooth_airfoil
        settings.smooth_passes = sec.smooth_passes
        for table, xs, ys in (
            (settings.thickness_table, sec.thickness_x_c, sec.thickness_t),
            (settings.meanline_table, sec.meanline_x_c, sec.meanline_f),
        ):
            table.clear()
            for x, y in zip(xs or (), ys or ()):
                row = table.add()
                row.x_c, row.value = x, y
        hub = propeller.hub
        settings.hub_upstream_length = hub.upstream_length
        settings.hub_downstream_length = hub.downstream_length
        settings.hub_nose_shape = hub.nose_shape.upper()
        settings.hub_nose_length = hub.nose_length
        settings.hub_tail_shape = hub.tail_shape.upper()
        settings.hub_tail_length = hub.tail_length
        settings.radial.clear()
        columns = [getattr(propeller.radial, name) for name in RADIAL_FIELDS]
        for values in zip(*columns):
            row = settings.radial.add()
            for name, value in zip(RADIAL_FIELDS, values):
                setattr(row, name, value)
        settings.radial_index = min(settings.radial_index, len(settings.radial) - 1)
        if smoothing is not None:
            for name in ("smooth_tip", "show_overlay") + SMOOTHING_FIELDS:
                if name in smoothing:
                    setattr(settings, name, smoothing[name])
        if display_tolerance is not None:
            settings.display_tolerance = display_tolerance
        settings.source_path = str(propeller.source or "")


# -- the model -> display surfaces ------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class DisplayResult:
    """What the objects of one propeller show: the blade as one or more surfaces
    (one unsmoothed, several after tip smoothing), the hub, and how well they follow the
    model (``deviation`` is None when not measured)."""

    propeller: Propeller
    model: object
    blade_surfaces: list
    hub: BSplineSurface
    deviation: float | None
    tolerance: float
    smoothed: bool
    #: the SmoothedBlade of Hally's pipeline (its report and overlay polylines), when smoothed
    smoothing: object = None


_SECTION_CACHE: dict = {}
#: Section shapes kept between regenerations (a live edit rarely changes the section).
SECTION_CACHE_SIZE = 4


def _section_key(propeller: Propeller):
    sec = propeller.section
    key = (sec.thickness, sec.meanline, sec.thickness_x_c, sec.thickness_t, sec.meanline_x_c, sec.meanline_f,
           sec.smooth_airfoil, sec.smooth_passes, str(propeller.base_dir))
    path = pathlib.Path(sec.thickness)
    if propeller.base_dir is not None and not path.is_absolute():
        path = propeller.base_dir / path
    try:
        stamp = path.stat().st_mtime_ns if path.suffix else None  # an airfoil file: re-read when it changes
    except OSError:
        stamp = None
    return key + (stamp,)


#: The last model built, with its definition and section key: an edit that leaves the
#: definition as it is (a smoothing or display setting) reuses it, and with it what was
#: computed on it (the blade–hub intersection, the marching surrogate of the cuts).
_LAST_MODEL: list = []


def build_model(propeller: Propeller) -> PropellerModel:
    """``propeller.build()``, reusing the section shape of a recent regeneration with the
    same [section] (building it costs about as much as the rest of the model), and the
    whole model when the definition is unchanged."""
    key = _section_key(propeller)
    if _LAST_MODEL and _LAST_MODEL[0] == propeller and _LAST_MODEL[1] == key:
        return _LAST_MODEL[2]
    section = _SECTION_CACHE.get(key)
    if section is None:
        section = propeller.section.shape(propeller.base_dir, propeller.source)
        while len(_SECTION_CACHE) >= SECTION_CACHE_SIZE:
            _SECTION_CACHE.pop(next(iter(_SECTION_CACHE)))
        _SECTION_CACHE[key] = section
    blade = BladeSurface.from_definition(propeller, section=section)
    model = PropellerModel(definition=propeller, blade=blade, hub=Hub.from_definition(propeller))
    _LAST_MODEL[:] = [propeller, key, model]
    return model


#: The last smoothed blade of a live edit: (model, settings in metres, SmoothedBlade). An
#: edit that leaves the model (the same object from :func:`build_model`, which returns the
#: cached one exactly when the definition and its section are unchanged) and every
#: smoothing setting as they are (a display or overlay setting) reuses it. The operators
#: measure (``measure=True``) and always smooth afresh.
_LAST_SMOOTHED: list = []


def smoothed_blade(model: PropellerModel, settings: dict, progress=None, measure: bool = False):
    """``smooth_blade(model, settings, ...)``, reusing the last live edit's result when the
    model and the settings are the same (the whole input of :func:`smooth_blade`: the model
    is immutable once built, the settings a plain dict of numbers). ``measure=True`` always
    smooths afresh."""
    if not measure and _LAST_SMOOTHED and _LAST_SMOOTHED[0] is model and _LAST_SMOOTHED[1] == settings:
        return _LAST_SMOOTHED[2]
    smoothed = smooth_blade(model, settings, progress=progress, measure=measure)
    _LAST_SMOOTHED[:] = [model, deepcopy(settings), smoothed]
    return smoothed


def compute_display(propeller: Propeller, *, display_tolerance: float, smooth_tip: bool = False,
                    smoothing: dict | None = None, knots=None, progress=None, measure: bool = False) -> DisplayResult:
    """Build the model and the surfaces to show (bpy-free work; raises BladesmithError).

    display_tolerance: fraction of D. smoothing: :func:`smoothing_values` (fractions of D).
    knots: (knots_u, knots_v) to seed the unsmoothed display fit. measure: also measure the
    smoothed blade's deviation from the unsmoothed one (about 0.4 s for DTMB 4119: done
    for the operators, not on every live edit)."""
    model = build_model(propeller)
    tolerance = check_display_tolerance(display_tolerance) * propeller.diameter
    smoothed = None
    if smooth_tip:
        settings = smoothing_settings(smoothing, propeller.diameter)
        smoothed = smoothed_blade(model, settings, progress=progress, measure=measure)
        surfaces, deviation = list(smoothed.surfaces), None
    else:
        try:
            display = blade_display_surface(model.blade, tolerance, knots=knots, progress=progress)
        except GeometryError as exc:  # name the definition and the setting that cannot be met
            raise DefinitionError(f"{exc} (display_tolerance = {display_tolerance:g} D)", path=propeller.source,
                                  field="display_tolerance") from None
        surfaces, deviation = [display.surface], display.max_deviation
    return DisplayResult(propeller, model, surfaces, hub_surface(model.hub), deviation, tolerance, smooth_tip, smoothed)


def smoothing_summary(smoothed) -> str:
    """One line a user reads after tip smoothing: cuts, knots and, when measured, the
    deviation from the unsmoothed blade inside and outside the smoothing zone."""
    report = smoothed.report
    cuts, knots = report["cuts"], report["knots"]
    text = (f"smoothed blade: 5 surfaces from {cuts['tip']} tip, {cuts['leading_edge']} LE and "
            f"{cuts['trailing_edge']} TE curves ({cuts['smoothed']} smoothed, transition cut j = "
            f"{report['transition_index'] + 1}), {knots['n_control']} control points per curve on one knot vector")
    dev = report.get("deviation_m")
    if dev is not None:
        text += (f"; deviation from the unsmoothed blade {dev['max_outside']:.2e} m outside the smoothing zone "
                 f"(tolerance {report['tolerance_m']:.2e} m), {dev['max_inside']:.2e} m inside "
                 f"(bound {report['deviation_bound_inside_m']:.2e} m)")
    ti = report.get("tip_irregularity")
    if ti is not None and ti["curves"]:
        text += (f"; tip irregularity {ti['unsmoothed']:.4g} unsmoothed -> {ti['smoothed']:.4g} smoothed "
                 f"(x{ti['ratio']:.3f}, excess curvature variation x R over {ti['curves']} curves)")
    return text


def tolerance_misses(result: DisplayResult) -> list[str]:
    """A sentence with the figures for every requested tolerance or bound the shown
    blade does not meet (empty when all are met): the operator warns with them rather
    than reporting a silent success."""
    out = []
    if result.deviation is not None and result.deviation > result.tolerance:
        out.append(f"the displayed blade deviates {result.deviation:.3g} m from the model, more than the display "
                   f"tolerance {result.tolerance:.3g} m")
    report = result.smoothing.report if result.smoothing is not None else {}
    dev = report.get("deviation_m")
    if dev is not None:
        if dev["max_outside"] > report["tolerance_m"]:
            out.append(f"the smoothed blade deviates {dev['max_outside']:.3g} m from the unsmoothed one outside the "
                       f"smoothing zone, more than the tolerance {report['tolerance_m']:.3g} m")
        bound = report.get("deviation_bound_inside_m")
        if bound is not None and dev["max_inside"] > bound:
            out.append(f"inside the smoothing zone it deviates {dev['max_inside']:.3g} m, more than the bound "
                       f"{bound:.3g} m")
    return out


# -- writing surfaces into objects ----------------------------------------------------------
def _part(obj) -> tuple[str, int, int] | None:
    if obj.get(PART_KEY) is None:
        return None
    return str(obj[PART_KEY]), int(obj.get(PATCH_KEY, 0)), int(obj.get(BLADE_KEY, 0))


def _tag(obj, part: str, patch: int = 0, blade: int = 0) -> None:
    obj[PART_KEY], obj[PATCH_KEY], obj[BLADE_KEY] = part, patch, blade


def propeller_parts(root) -> dict:
    """Children of a root by (part, patch, blade)."""
    return {key: child for child in root.children if (key := _part(child)) is not None}


def _collections_of(root):
    return list(root.users_collection) or [bpy.context.scene.collection]


def _new_child(root, obj, part: str, patch: int, blade: int):
    for collection in _collections_of(root):
        if obj.name not in collection.objects:
            collection.objects.link(obj)
    obj.parent = root
    _tag(obj, part, patch, blade)
    return obj


def _new_surface_child(root, surface, name, part, patch, resolution):
    data = bpy.data.curves.new(name, type="SURFACE")
    data.dimensions = "3D"
    obj = bpy.data.objects.new(name, data)
    try:
        _new_child(root, obj, part, patch, 0)
        write_surface(obj, surface, resolution)
    except BaseException:
        remove_object(obj)
        raise
    return obj


def blade_name(root_name: str, patch: int, blade: int) -> str:
    name = f"{root_name} blade" + (f" {blade + 1}" if blade else "")
    return name + (f" patch {patch + 1}" if patch else "")


def show_result(root, result: DisplayResult) -> dict:
    """Make the children of ``root`` show ``result``: blade patches, their Z - 1 linked
    rotated copies and the hub, reusing existing objects and curve data. Objects no longer
    needed (fewer blades or patches) are removed. Returns the parts."""
    parts = propeller_parts(root)
    base = root.name
    Z = result.propeller.blades
    surfaces = result.blade_surfaces
    resolution = SMOOTHED_BLADE_RESOLUTION if result.smoothed else BLADE_RESOLUTION
    for patch, surface in enumerate(surfaces):
        reference = parts.get(("blade", patch, 0))
        if reference is None:
            reference = _new_surface_child(root, surface, blade_name(base, patch, 0), "blade", patch, resolution)
            parts[("blade", patch, 0)] = reference
        else:
            write_surface(reference, surface, resolution)
        record = reference[PROPERTY_KEY].to_dict()
        for k in range(1, Z):
            copy = parts.get(("blade", patch, k))
            if copy is None:
                copy = bpy.data.objects.new(blade_name(base, patch, k), reference.data)
                parts[("blade", patch, k)] = _new_child(root, copy, "blade", patch, k)
            elif copy.data is not reference.data:
                copy.data = reference.data
            # blade_rotation(k) turns (x, y) by 2πk/Z from +y towards +x: -2πk/Z about +z
            copy.rotation_euler = (0.0, 0.0, -2.0 * math.pi * k / Z)
            copy[PROPERTY_KEY] = record
    # copies before their reference, so the reference's curve data is freed with it
    surplus = sorted((key for key in parts if key[0] == "blade" and (key[1] >= len(surfaces) or key[2] >= Z)),
                     key=lambda key: -key[2])
    for key in surplus:
        remove_object(parts.pop(key))
    hub = parts.get(("hub", 0, 0))
    if hub is None:
        parts[("hub", 0, 0)] = _new_surface_child(root, result.hub, f"{base} hub", "hub", 0, HUB_RESOLUTION)
    else:
        write_surface(hub, result.hub, HUB_RESOLUTION)
    show = result.smoothing is not None and root.bladesmith_propeller.show_overlay
    _show_overlay(root, parts, result.smoothing if show else None)
    root.empty_display_size = 0.5 * result.propeller.diameter
    return parts


def overlay_polylines(smoothed) -> dict:
    """The overlay of Hally's pipeline as polylines (metres), by overlay index: 0 the tip,
    leading- and trailing-edge curves (§8), 1 the curve c_LETE along the edges, 2 the
    transition cut j on the leading and on the trailing edge (Eq. 48)."""
    overlays, curves = smoothed.overlays, smoothed.curves
    cuts, j = overlays["cuts"], overlays["transition"]
    n_tip, n_le = len(curves.tip), len(curves.leading)
    return {
        0: ("cuts", list(cuts)),
        1: ("c_LETE", [overlays["lete"]]),
        2: ("transition cut j", [cuts[n_tip + j], cuts[n_tip + n_le + j]]),
    }


#: Custom property of an overlay's curve data: a digest of the polylines it shows, so an
#: edit that leaves them as they are does not rebuild the splines (nor make Blender
#: evaluate the curve again).
OVERLAY_DIGEST_KEY = "bladesmith_overlay_digest"


def _write_polylines(data, polylines) -> None:
    co = []
    for P in polylines:
        c = np.ones((len(P), 4), dtype=np.float32)
        c[:, :3] = P
        co.append(c)
    digest = hashlib.blake2b(b"".join(np.int64(len(c)).tobytes() + c.tobytes() for c in co),
                             digest_size=16).hexdigest()
    if data.get(OVERLAY_DIGEST_KEY) == digest and len(data.splines) == len(co):
        return
    data.splines.clear()
    for c in co:
        spline = data.splines.new("POLY")
        spline.points.add(len(c) - 1)
        spline.points.foreach_set("co", c.ravel())
    data[OVERLAY_DIGEST_KEY] = digest


def _show_overlay(root, parts: dict, smoothed) -> None:
    """Make the overlay children match ``smoothed`` (None: remove them). They are curve
    objects drawn in front and never rendered or exported."""
    wanted = {} if smoothed is None else overlay_polylines(smoothed)
    for key in [k for k in parts if k[0] == "overlay" and k[1] not in wanted]:
        remove_object(parts.pop(key))
    for index, (label, polylines) in wanted.items():
        obj = parts.get(("overlay", index, 0))
        if obj is None:
            data = bpy.data.curves.new(f"{root.name} {label}", "CURVE")
            data.dimensions = "3D"
            obj = bpy.data.objects.new(f"{root.name} {label}", data)
            parts[("overlay", index, 0)] = _new_child(root, obj, "overlay", index, 0)
            obj.hide_render = True
            obj.show_in_front = True
        _write_polylines(obj.data, polylines)


def store_status(settings, result: DisplayResult, seconds: float) -> None:
    """Record the definition of the shown geometry and a status line on the root."""
    settings.definition_toml = dumps_toml(result.propeller.to_dict())
    shape = result.blade_surfaces[0].shape
    if result.deviation is not None:
        settings.display_deviation = result.deviation
        detail = f"blade {shape[0]} x {shape[1]} control points, deviation {result.deviation:.2e} m " \
                 f"(tolerance {result.tolerance:.2e} m)"
    else:
        settings.display_deviation = -1.0
        detail = smoothing_summary(result.smoothing)
    deviation = result.model.blade.section.smoothing_deviation
    if deviation is not None:
        detail += f"; airfoil smoothed (Hvid), deviation {deviation:.2e} chord"
    settings.status = f"{detail}; {seconds * 1e3:.0f} ms"
    settings.status_is_error = False
    settings.regeneration_time = seconds


def _previous_knots(root):
    """The knot vectors of the shown unsmoothed blade, to seed the next display fit."""
    blade = propeller_parts(root).get(("blade", 0, 0))
    record = blade.get(PROPERTY_KEY) if blade is not None else None
    if record is None or record.get("kind") != "surface":
        return None
    if int(record.get("degree_u", 0)) != 3 or int(record.get("degree_v", 0)) != 3:
        return None
    return np.asarray(record["knots_u"], dtype=np.float64), np.asarray(record["knots_v"], dtype=np.float64)


def regenerate(root, *, fresh: bool = False) -> bool:
    """Rebuild the definition from the root's properties and update its children.

    fresh: start the display fit from uniform knots instead of the shown blade's knots.
    Invalid values leave the geometry as it is and put the message in ``status``
    (``status_is_error``). Returns whether the geometry was regenerated.
    """
    settings = root.bladesmith_propeller
    start = time.perf_counter()
    try:
        propeller = settings_to_definition(settings)
        smoothing = smoothing_values(settings)
        check_smoothing(smoothing)
        knots = None if (fresh or settings.smooth_tip) else _previous_knots(root)
        result = compute_display(
            propeller,
            display_tolerance=settings.display_tolerance,
            smooth_tip=settings.smooth_tip,
            smoothing=smoothing,
            knots=knots,
            measure=fresh,
        )
    except BladesmithError as exc:
        settings.status = str(exc)
        settings.status_is_error = True
        return False
    show_result(root, result)
    store_status(settings, result, time.perf_counter() - start)
    return True


def on_settings_edited(root) -> None:
    """The properties' update callback: regenerate unless updates are suspended."""
    if updates_suspended() or root is None or not root.bladesmith_propeller.is_propeller:
        return
    regenerate(root)


def find_root(obj):
    """The propeller root of ``obj`` (itself or its parent), or None."""
    for candidate in (obj, getattr(obj, "parent", None)):
        settings = getattr(candidate, "bladesmith_propeller", None) if candidate is not None else None
        if settings is not None and settings.is_propeller:
            return candidate
    return None


def create_propeller(context, result: DisplayResult, smoothing: dict, display_tolerance: float):
    """A new root Empty with its children showing ``result``; on any failure everything
    made so far is removed again, so the scene is unchanged."""
    propeller = result.propeller
    root = bpy.data.objects.new(propeller.name, None)
    created = [root]
    try:
        root.empty_display_type = "ARROWS"
        root.location = context.scene.cursor.location
        context.collection.objects.link(root)
        definition_to_settings(root.bladesmith_propeller, propeller, smoothing, display_tolerance)
        show_result(root, result)
        created.extend(root.children)
        for obj in context.view_layer.objects:
            obj.select_set(False)
        root.select_set(True)
        context.view_layer.objects.active = root
    except BaseException:
        created.extend(child for child in root.children if child not in created)
        for obj in reversed(created):
            remove_object(obj)
        raise
    return root


def load_definition(operator_definition: str, preset: str) -> Propeller:
    """The validated definition of a file path (Blender's // prefix allowed) or a preset."""
    if operator_definition:
        return Propeller.from_toml(bpy.path.abspath(operator_definition))
    return Propeller.from_toml(preset_path(preset))


# -- operators ------------------------------------------------------------------------------
class BLADESMITH_OT_add_propeller(bpy.types.Operator):
    """Add a propeller from a definition file or a preset: the unsmoothed blade (or the tip-smoothed blade), its linked copies and the hub"""

    bl_idname = "bladesmith.add_propeller"
    bl_label = "Add Propeller"
    bl_options = {"REGISTER", "UNDO"}

    definition: StringProperty(
        name="Definition",
        description="Propeller definition file (.toml); when empty, the preset is used",
        subtype="FILE_PATH",
        default="",
    )
    preset: StringProperty(
        name="Preset",
        description="Preset name, the file stem in data/propellers (case-insensitive), e.g. DTMB4119",
        default=PRESET_ITEMS[0][0],
    )
    preset_choice: EnumProperty(
        name="Preset",
        description="Preset definition (used when neither definition nor preset is given)",
        items=PRESET_ITEMS,
    )
    display_tolerance: display_tolerance_property()
    __annotations__.update(smoothing_properties(smooth_default=False))

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
            propeller = load_definition(self.definition, self._preset_name())
            smoothing = smoothing_values(self)
            smoothing["smooth_tip"] = self.smooth_tip
            smoothing["show_overlay"] = self.show_overlay
            # the file's [smoothing] gives what this call does not set
            for name, value in file_smoothing_values(propeller).items():
                if not self.properties.is_property_set(name):
                    smoothing[name] = value
            check_smoothing(smoothing)
            result = compute_display(
                propeller,
                display_tolerance=self.display_tolerance,
                smooth_tip=smoothing["smooth_tip"],
                smoothing=smoothing,
                progress=progress_callback(wm),
                measure=True,
            )
            start = time.perf_counter()
            root = create_propeller(context, result, smoothing, self.display_tolerance)
            store_status(root.bladesmith_propeller, result, time.perf_counter() - start)
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        self.report({"INFO"}, f"{root.name}: {root.bladesmith_propeller.status}")
        if result.smoothing is not None:
            for warning in result.smoothing.report.get("warnings", []):
                self.report({"WARNING"}, warning)
        for miss in tolerance_misses(result):
            self.report({"WARNING"}, f"{root.name}: {miss}")
        return {"FINISHED"}


class BLADESMITH_OT_regenerate_propeller(bpy.types.Operator):
    """Regenerate the active propeller from its settings, starting the display fit afresh"""

    bl_idname = "bladesmith.regenerate_propeller"
    bl_label = "Regenerate Propeller"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT" and find_root(context.active_object) is not None

    def execute(self, context):
        root = find_root(context.active_object)
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            ok = regenerate(root, fresh=True)
        finally:
            wm.progress_end()
        if not ok:
            self.report({"ERROR"}, root.bladesmith_propeller.status)
            return {"CANCELLED"}
        return {"FINISHED"}


_TABLES = [
    ("RADIAL", "Radial", "The radial table of sections"),
    ("THICKNESS", "Thickness", "The thickness table (thickness = table)"),
    ("MEANLINE", "Mean Line", "The mean-line table (meanline = table)"),
]


def _table(settings, table: str):
    if table == "RADIAL":
        return settings.radial, "radial_index"
    if table == "THICKNESS":
        return settings.thickness_table, "thickness_index"
    return settings.meanline_table, "meanline_index"


def _row_values(row) -> dict:
    return {prop.identifier: getattr(row, prop.identifier) for prop in row.bl_rna.properties if prop.type == "FLOAT"}


class BLADESMITH_OT_propeller_row_add(bpy.types.Operator):
    """Insert a row after the active one (midway to the next row, or a copy of the last)"""

    bl_idname = "bladesmith.propeller_row_add"
    bl_label = "Add Row"
    bl_options = {"REGISTER", "UNDO"}

    table: EnumProperty(name="Table", items=_TABLES, default="RADIAL")

    @classmethod
    def poll(cls, context):
        return find_root(context.active_object) is not None

    def execute(self, context):
        root = find_root(context.active_object)
        settings = root.bladesmith_propeller
        rows, index_name = _table(settings, self.table)
        index = getattr(settings, index_name)
        with suspended_updates():
            if len(rows) == 0:
                rows.add()
                new_index = 0
            else:
                index = min(max(index, 0), len(rows) - 1)
                here = _row_values(rows[index])
                there = _row_values(rows[index + 1]) if index + 1 < len(rows) else here
                row = rows.add()
                for name, value in here.items():
                    setattr(row, name, 0.5 * (value + there[name]))
                rows.move(len(rows) - 1, index + 1)
                new_index = index + 1
            setattr(settings, index_name, new_index)
        regenerate(root)
        return {"FINISHED"}


class BLADESMITH_OT_propeller_row_remove(bpy.types.Operator):
    """Remove the active row"""

    bl_idname = "bladesmith.propeller_row_remove"
    bl_label = "Remove Row"
    bl_options = {"REGISTER", "UNDO"}

    table: EnumProperty(name="Table", items=_TABLES, default="RADIAL")

    @classmethod
    def poll(cls, context):
        return find_root(context.active_object) is not None

    def execute(self, context):
        root = find_root(context.active_object)
        settings = root.bladesmith_propeller
        rows, index_name = _table(settings, self.table)
        index = getattr(settings, index_name)
        if not 0 <= index < len(rows):
            self.report({"ERROR"}, "no active row to remove")
            return {"CANCELLED"}
        with suspended_updates():
            rows.remove(index)
            setattr(settings, index_name, max(0, min(index, len(rows) - 1)))
        regenerate(root)
        return {"FINISHED"}


class BLADESMITH_OT_load_propeller_definition(bpy.types.Operator):
    """Load a propeller definition (.toml) into the active propeller, or add a new propeller"""

    bl_idname = "bladesmith.load_propeller_definition"
    bl_label = "Load Propeller Definition"
    bl_options = {"REGISTER", "UNDO"}

    filepath: StringProperty(name="File Path", subtype="FILE_PATH")
    filter_glob: StringProperty(default="*.toml", options={"HIDDEN"})
    new_propeller: BoolProperty(
        name="New Propeller",
        description="Add a new propeller instead of replacing the active propeller's definition",
        default=False,
    )

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT"

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        root = None if self.new_propeller else find_root(context.active_object)
        if root is None:
            return bpy.ops.bladesmith.add_propeller(definition=self.filepath)
        settings = root.bladesmith_propeller
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            propeller = load_definition(self.filepath, "")
            smoothing = smoothing_values(settings)
            smoothing["smooth_tip"] = settings.smooth_tip
            smoothing.update(file_smoothing_values(propeller))  # the file's [smoothing] wins
            check_smoothing(smoothing)
            result = compute_display(
                propeller,
                display_tolerance=settings.display_tolerance,
                smooth_tip=smoothing["smooth_tip"],
                smoothing=smoothing,
                progress=progress_callback(wm),
            )
            start = time.perf_counter()
            definition_to_settings(settings, propeller, smoothing)
            show_result(root, result)
            store_status(settings, result, time.perf_counter() - start)
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        return {"FINISHED"}


class BLADESMITH_OT_save_propeller_definition(bpy.types.Operator):
    """Save the active propeller's definition as TOML, with all its tip-smoothing settings"""

    bl_idname = "bladesmith.save_propeller_definition"
    bl_label = "Save Propeller Definition"
    bl_options = {"REGISTER"}

    filepath: StringProperty(name="File Path", subtype="FILE_PATH")
    filter_glob: StringProperty(default="*.toml", options={"HIDDEN"})
    check_existing: BoolProperty(default=True, options={"HIDDEN"})

    @classmethod
    def poll(cls, context):
        return find_root(context.active_object) is not None

    def invoke(self, context, event):
        if not self.filepath:
            stem = bpy.path.clean_name(find_root(context.active_object).bladesmith_propeller.definition_name) or "propeller"
            self.filepath = stem.lower() + ".toml"
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        root = find_root(context.active_object)
        path = pathlib.Path(bpy.path.abspath(self.filepath))
        if path.suffix.lower() != ".toml":
            path = path.with_suffix(".toml")
        try:
            # every smoothing setting goes into [smoothing] (lengths in metres)
            propeller = settings_to_definition(root.bladesmith_propeller, with_smoothing=True)
            propeller.to_toml(path, header=f"{propeller.name}: written by Bladesmith")
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        except OSError as exc:
            self.report({"ERROR"}, f"{path}: cannot write ({exc.strerror or exc})")
            return {"CANCELLED"}
        self.report({"INFO"}, f"Saved {path}")
        return {"FINISHED"}


def menu_add_propeller(self, context):
    self.layout.operator_menu_enum(BLADESMITH_OT_add_propeller.bl_idname, "preset_choice", text="Propeller", icon="MESH_CYLINDER")


_classes = (
    BLADESMITH_OT_add_propeller,
    BLADESMITH_OT_regenerate_propeller,
    BLADESMITH_OT_propeller_row_add,
    BLADESMITH_OT_propeller_row_remove,
    BLADESMITH_OT_load_propeller_definition,
    BLADESMITH_OT_save_propeller_definition,
)
_register, _unregister = bpy.utils.register_classes_factory(_classes)


def register():
    _register()
    bpy.types.VIEW3D_MT_add.append(menu_add_propeller)


def unregister():
    bpy.types.VIEW3D_MT_add.remove(menu_add_propeller)
    _unregister()
