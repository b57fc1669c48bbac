"""Propeller definition files (TOML, lengths in metres), validated once.

Format (every field is checked; messages name the file, the field and the value)::

    name = "DTMB 4119"
    blades = 3                    # Z
    diameter = 0.3048             # D, m
    hub_diameter_ratio = 0.2      # hub diameter / D (the cylindrical part of the hub)
    hand = "right"                # "right" or "left"
    # radial_table = "file.csv"   # instead of [radial]: CSV with the [radial] column names

    [section]
    thickness = "naca66mod"       # "naca66mod", "naca4", "elliptic", "table", or an airfoil .dat
                                  # path relative to this file
    meanline = "a=0.8"            # "a=0.8", "a=0.8mod", "parabolic", "naca4", "none", "table",
                                  # "airfoil" (the mean line of the .dat file)
    # thickness_x_c = [...]; thickness_t = [...]   (thickness = "table": x/c and T/T0)
    # meanline_x_c = [...];  meanline_f = [...]    (meanline = "table": x/c and f/f0)
    # smooth_airfoil = true       # airfoil .dat thickness only, default false: smooth the file's
                                  # outline first (Hvid 1993 smoothfoil, default jobcard)
    # smooth_passes = 4           # passes of its ad hoc curvature smoother (1-50, default 4)

    [hub]                         # spine: nose, cylinder of the hub radius, tail (Hally §10)
    upstream_length = 0.1067      # m, from the propeller plane z = 0 to the nose tip (upstream)
    downstream_length = 0.1372    # m, from z = 0 to the tail end (downstream)
    nose_shape = "ellipse"        # "ellipse", "cone" or "flat"
    nose_length = 0.0457          # m, axial length of the nose shape (0 for "flat")
    tail_shape = "ellipse"
    tail_length = 0.0610

    [radial]                      # arrays of equal length, stations from root to tip (r/R = 1)
    r_R = [...]                   # r/R, strictly increasing, last = 1
    c_D = [...]                   # chord / D (> 0; 0 allowed at the tip only; a finite tip
                                  # chord at most MAX_TIP_CHORD_RATIO of the largest)
    P_D = [...]                   # pitch / D (> 0)
    skew_deg = [...]              # skew angle of the mid-chord point, degrees, positive = skew back
    rake_D = [...]                # generator-line rake / D, positive downstream (aft)
    t_c = [...]                   # maximum thickness / chord (> 0)
    f_c = [...]                   # maximum camber / chord (towards the suction side)

    [smoothing]                   # optional: Hally (2013) tip smoothing, every key optional
    smooth_tip = true             # the operator's default when the call does not set it
    delta_c = 0.003048            # m, Δc (Eqs. 31, 49)
    tip_smoothing_distance = 0.01524   # m, d_t (Eq. 30)
    edge_smoothing_distance = 0.00762  # m, d_e (Eq. 30)
    transition_s = 0.75           # s_j (Eq. 48), fractional arclength along c_LETE
    filter_strength = 0.5         # α (Eq. 30), in (0, 0.75]
    filter_iterations = 100       # n (Eq. 29)
    tolerance = 3.048e-6          # m, spline accuracy (§9)
    sample_spacing = 0.001524     # m, d, largest spacing of the cut samples (Eqs. 27-28)
    edge_spacing_ratio = 0.01     # h/d (Eq. 28)
    xi_ll = 0.1                   # the six defining points of §4 (Fig. 4) in blade parameters:
    xi_lr = 0.4                   #   xi_ll, xi_lr on the hub; (xi_ul, eta_ul), (xi_ur, eta_ur)
    xi_ul = 0.1                   #   the upper corners of the pressure-side central surface;
    eta_ul = 0.9                  #   eta_le, eta_te of x_LE = b(1/2, eta_le), x_TE = b(0, eta_te)
    xi_ur = 0.4
    eta_ur = 0.9
    eta_le = 0.9
    eta_te = 0.9

A CSV radial table has a header line with those column names ('#' lines are comments;
``t0_c`` and ``f0_c`` are accepted for ``t_c`` and ``f_c``).

Every key is checked against the table's list of keys below (``_TOP_KEYS``,
``_SECTION_KEYS``, ``_HUB_KEYS``, ``RADIAL_FIELDS``, ``SMOOTHING_KEYS``: the one place to
add a key); an
unknown key is refused with the nearest valid name. Counts and sizes are bounded by the
``MAX_*`` constants below (README "Limits of definitions"), named in the refusal.
"""
from __future__ import annotations

import csv
import io
import math
import os
import pathlib
from dataclasses import dataclass, field, fields, replace

import numpy as np

from ..files import atomic_write
from ..errors import DefinitionError
from ..validation import (MAX_LENGTH, MIN_LENGTH, check_count, check_keys, number, read_text, read_toml, string,
                          table)
from ..sections.shape import DEFAULT_SMOOTH_PASSES, check_smooth_passes

RADIAL_FIELDS = ("r_R", "c_D", "P_D", "skew_deg", "rake_D", "t_c", "f_c")
CSV_ALIASES = {"t0_c": "t_c", "f0_c": "f_c"}
HANDS = ("right", "left")
HUB_SHAPES = ("ellipse", "cone", "flat")
#: Tolerance on the tip station r/R = 1.
TIP_TOL = 1e-9
#: A finite chord at r/R = 1 is closed by Hally's tip surface (2013 §§6–9), which then
#: rounds the tip off inside r <= R (1 + TIP_CLOSURE_ALLOWANCE); measured on the presets it
#: works up to ~0.35 of the largest chord and fails beyond, so tip chords above this
#: fraction of the largest chord are refused when the definition is read.
MAX_TIP_CHORD_RATIO = 0.3

_TOP_KEYS = {"name", "blades", "diameter", "hub_diameter_ratio", "hand", "radial_table", "section", "hub", "radial",
             "smoothing"}
#: [smoothing]: lengths (metres in the file), dimensionless settings, and the six defining
#: points of Hally (2013) §4 (blade parameters); the names of
#: :class:`~.smoothing.SmoothingSettings` and :class:`~.corners.DefiningPoints`.
SMOOTHING_LENGTH_KEYS = ("delta_c", "tip_smoothing_distance", "edge_smoothing_distance", "tolerance", "sample_spacing")
SMOOTHING_RATIO_KEYS = ("transition_s", "filter_strength", "edge_spacing_ratio")
DEFINING_POINT_KEYS = ("xi_ll", "xi_lr", "xi_ul", "eta_ul", "xi_ur", "eta_ur", "eta_le", "eta_te")
SMOOTHING_KEYS = ("smooth_tip", *SMOOTHING_LENGTH_KEYS, *SMOOTHING_RATIO_KEYS, "filter_iterations",
                  *DEFINING_POINT_KEYS)
#: Iterations n of the smoothing filter a file may ask for (the filter's cost grows with
#: log n, see cut_smoothing.fourth_difference_filter; beyond this nothing changes).
MAX_FILTER_ITERATIONS = 1_000_000
_SECTION_KEYS = {"thickness", "meanline", "thickness_x_c", "thickness_t", "meanline_x_c", "meanline_f", "smooth_airfoil",
                 "smooth_passes"}
#: Thickness names that are not airfoil files.
_THICKNESS_FORMS = ("naca66mod", "naca4", "elliptic", "table")
_HUB_KEYS = {"upstream_length", "downstream_length", "nose_shape", "nose_length", "tail_shape", "tail_length"}

# Upper bounds (README "Limits of definitions"); each is named in its refusal.
#: Blades Z: marine and air propellers and fans have 2-12.
MAX_BLADES = 32
#: Radial stations (rows of [radial] or of the CSV table): published tables have 10-30.
MAX_RADIAL_STATIONS = 500
#: Points of a section thickness or mean-line table.
MAX_SECTION_TABLE_POINTS = 1000
#: |skew angle| (degrees): a blade skewed further would wrap into its neighbours.
MAX_SKEW_DEG = 180.0
#: |rake| / D, pitch / D and chord / D.
MAX_RAKE_D = 10.0
MAX_PITCH_D = 100.0
MAX_CHORD_D = 10.0
#: |camber| / chord.
MAX_CAMBER_C = 0.5
#: Hub lengths as multiples of D.
MAX_HUB_LENGTH_D = 10.0


def _fmt(value) -> str:
    return repr(value) if isinstance(value, str) else f"{value}"


def _number(value, field_name: str, path, *, positive=False, minimum=None, integer=False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise DefinitionError(f"expected a number, got {_fmt(value)}", path=path, field=field_name)
    if integer and (not float(value).is_integer()):
        raise DefinitionError(f"expected an integer, got {value}", path=path, field=field_name)
    if not math.isfinite(value):
        raise DefinitionError(f"value {value} is not finite", path=path, field=field_name)
    if positive and value <= 0:
        raise DefinitionError(f"must be positive, got {value}", path=path, field=field_name)
    if minimum is not None and value < minimum:
        raise DefinitionError(f"must be at least {minimum}, got {value}", path=path, field=field_name)
    return int(value) if integer else float(value)


def _array(value, field_name: str, path) -> tuple[float, ...]:
    if not isinstance(value, (list, tuple, np.ndarray)):
        raise DefinitionError(f"expected an array of numbers, got {_fmt(value)}", path=path, field=field_name)
    out = []
    for i, v in enumerate(value):
        if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)):
            raise DefinitionError(f"entry {i} is {_fmt(v)}, not a number", path=path, field=field_name)
        if not math.isfinite(float(v)):
            raise DefinitionError(f"entry {i} is {float(v)} (NaN or infinite)", path=path, field=field_name)
        out.append(float(v))
    return tuple(out)


@dataclass(frozen=True)
class RadialDistribution:
    """The table of sections: equal-length tuples, root to tip (see the module docstring)."""

    r_R: tuple
    c_D: tuple
    P_D: tuple
    skew_deg: tuple
    rake_D: tuple
    t_c: tuple
    f_c: tuple

    def as_arrays(self) -> dict[str, np.ndarray]:
        return {name: np.asarray(getattr(self, name), dtype=np.float64) for name in RADIAL_FIELDS}


@dataclass(frozen=True)
class SectionDefinition:
    thickness: str = "naca66mod"
    meanline: str = "a=0.8"
    thickness_x_c: tuple | None = None
    thickness_t: tuple | None = None
    meanline_x_c: tuple | None = None
    meanline_f: tuple | None = None
    #: Smooth the airfoil file's outline first (Hvid 1993 smoothfoil); airfoil files only.
    smooth_airfoil: bool = False
    #: Passes of the ad hoc curvature smoother (Hvid §3.2; the paper's jobcard uses 4).
    smooth_passes: int = 4

    def shape(self, base_dir=None, source=None):
        """The :class:`~bladesmith.geometry.sections.SectionShape` this names (errors name
        ``source``)."""
        from ..sections.shape import SectionShape

        return SectionShape.from_spec(
            self.thickness,
            self.meanline,
            base_dir=base_dir,
            thickness_table=(self.thickness_x_c, self.thickness_t) if self.thickness_x_c is not None else None,
            meanline_table=(self.meanline_x_c, self.meanline_f) if self.meanline_x_c is not None else None,
            source=source,
            smooth_airfoil=self.smooth_airfoil,
            smooth_passes=self.smooth_passes,
        )


@dataclass(frozen=True)
class HubDefinition:
    """Hub spine (Hally 2013 §10): lengths in metres from the propeller plane z = 0."""

    upstream_length: float
    downstream_length: float
    nose_shape: str = "ellipse"
    nose_length: float = 0.0
    tail_shape: str = "ellipse"
    tail_length: float = 0.0

    @classmethod
    def default_for(cls, diameter: float) -> "HubDefinition":
        """Hub used when a definition has no [hub] table: 0.35 D upstream with a 0.15 D
        elliptic nose, 0.45 D downstream with a 0.2 D elliptic tail."""
        return cls(0.35 * diameter, 0.45 * diameter, "ellipse", 0.15 * diameter, "ellipse", 0.2 * diameter)


@dataclass(frozen=True)
class Propeller:
    """A validated propeller definition (see the module docstring for the format).

    source: the file it was read from (for messages and relative paths), or None.
    """

    name: str
    blades: int
    diameter: float
    hub_diameter_ratio: float
    hand: str
    section: SectionDefinition
    hub: HubDefinition
    radial: RadialDistribution
    source: str | None = field(default=None, compare=False)
    #: The [smoothing] table (keys of SMOOTHING_KEYS, lengths in metres), or None.
    smoothing: dict | None = field(default=None, hash=False)

    def __post_init__(self):
        p = self.source
        string(self.name, p, "name")
        object.__setattr__(self, "blades", number(self.blades, p, "blades", lo=1, integer=True))
        check_count(self.blades, MAX_BLADES, "MAX_BLADES", p, "blades", "blades")
        # the float32 display keeps the geometry only between MIN_LENGTH and MAX_LENGTH
        object.__setattr__(self, "diameter", number(self.diameter, p, "diameter", lo=MIN_LENGTH, hi=MAX_LENGTH))
        h = number(self.hub_diameter_ratio, p, "hub_diameter_ratio", lo=0.0, hi=1.0, lo_open=True, hi_open=True)
        object.__setattr__(self, "hub_diameter_ratio", h)
        if not isinstance(self.hand, str) or self.hand not in HANDS:
            raise DefinitionError(f"expected 'right' or 'left', got {_fmt(self.hand)}", path=p, field="hand")
        self._validate_radial()
        tip = self.radial.r_R[-1]
        if h >= tip:
            raise DefinitionError(
                f"hub radius ratio {h} is not below the tip radius ratio r_R = {tip} "
                f"(hub radius {0.5 * h * self.diameter:g} m >= tip radius {0.5 * tip * self.diameter:g} m)",
                path=p,
                field="hub_diameter_ratio",
            )
        self._validate_section()
        self._validate_hub()
        self._validate_smoothing()

    # -- validation -------------------------------------------------------------------
    def _validate_radial(self):
        p, rad = self.source, self.radial
        arrays = {}
        for name in RADIAL_FIELDS:
            value = getattr(rad, name)
            if isinstance(value, (list, tuple, np.ndarray)):
                check_count(len(value), MAX_RADIAL_STATIONS, "MAX_RADIAL_STATIONS", p, f"radial.{name}", "stations")
            arrays[name] = _array(value, f"radial.{name}", p)
        n = len(arrays["r_R"])
        if n < 3:
            raise DefinitionError(f"need at least 3 stations, got {n}", path=p, field="radial.r_R")
        for name, a in arrays.items():
            if len(a) != n:
                raise DefinitionError(f"has {len(a)} entries, r_R has {n}", path=p, field=f"radial.{name}")
        object.__setattr__(self, "radial", RadialDistribution(**arrays))
        r = np.asarray(arrays["r_R"])
        bad = np.nonzero(np.diff(r) <= 0)[0]
        if bad.size:
            i = bad[0]
            raise DefinitionError(
                f"must increase strictly: entry {i + 1} is {r[i + 1]} after {r[i]}", path=p, field="radial.r_R"
            )
        if r[0] <= 0:
            raise DefinitionError(f"entry 0 is {r[0]}; radii must be positive", path=p, field="radial.r_R")
        if abs(r[-1] - 1.0) > TIP_TOL:
            raise DefinitionError(f"the last station must be the tip r_R = 1, got {r[-1]}", path=p, field="radial.r_R")
        c = np.asarray(arrays["c_D"])
        for i, v in enumerate(c):
            if v < 0 or (v == 0 and i != n - 1):
                what = "negative" if v < 0 else "zero (only the tip chord may be zero)"
                raise DefinitionError(f"entry {i} (r_R = {r[i]}) is {v}: chord is {what}", path=p, field="radial.c_D")
        if c[-1] > MAX_TIP_CHORD_RATIO * c.max():
            raise DefinitionError(
                f"the tip chord (entry {n - 1}, r_R = 1) is {c[-1]}, {c[-1] / c.max():.3g} of the largest chord "
                f"{c.max()}: the tip closure (Hally's tip surface rounding off a finite tip) supports at most "
                f"{MAX_TIP_CHORD_RATIO} of it. Lower the tip chord to <= {MAX_TIP_CHORD_RATIO * c.max():.4g}, "
                f"or extend the table with stations that taper the chord to 0 at r_R = 1", path=p, field="radial.c_D")
        for name in ("P_D", "t_c"):
            a = np.asarray(arrays[name])
            bad = np.nonzero(a <= 0)[0]
            if bad.size:
                i = bad[0]
                raise DefinitionError(f"entry {i} (r_R = {r[i]}) is {a[i]}; must be positive", path=p, field=f"radial.{name}")
        t = np.asarray(arrays["t_c"])
        if np.any(t >= 1.0):
            i = int(np.argmax(t >= 1.0))
            raise DefinitionError(f"entry {i} (r_R = {r[i]}) is {t[i]}; thickness must be below the chord", path=p, field="radial.t_c")
        for name, bound, bound_name in (("c_D", MAX_CHORD_D, "MAX_CHORD_D"), ("P_D", MAX_PITCH_D, "MAX_PITCH_D"),
                                        ("skew_deg", MAX_SKEW_DEG, "MAX_SKEW_DEG"), ("rake_D", MAX_RAKE_D, "MAX_RAKE_D"),
                                        ("f_c", MAX_CAMBER_C, "MAX_CAMBER_C")):
            a = np.abs(np.asarray(arrays[name]))
            if np.any(a > bound):
                i = int(np.argmax(a > bound))
                raise DefinitionError(f"entry {i} (r_R = {r[i]}) is {arrays[name][i]!r}; |{name}| is limited to "
                                      f"{bound_name} = {bound:g}", path=p, field=f"radial.{name}")

    def _validate_section(self):
        p, s = self.source, self.section
        for name in ("thickness", "meanline"):
            if not isinstance(getattr(s, name), str):
                raise DefinitionError(f"expected a string, got {_fmt(getattr(s, name))}", path=p, field=f"section.{name}")
        for name in ("thickness_x_c", "thickness_t", "meanline_x_c", "meanline_f"):
            v = getattr(s, name)
            if v is not None:
                if isinstance(v, (list, tuple, np.ndarray)):
                    check_count(len(v), MAX_SECTION_TABLE_POINTS, "MAX_SECTION_TABLE_POINTS", p, f"section.{name}",
                                "points")
                object.__setattr__(s, name, _array(v, f"section.{name}", p))
        if not isinstance(s.smooth_airfoil, bool):
            raise DefinitionError(f"expected true or false, got {_fmt(s.smooth_airfoil)}", path=p,
                                  field="section.smooth_airfoil")
        check_smooth_passes(s.smooth_passes, p, "section.smooth_passes")
        if s.smooth_airfoil and s.thickness in _THICKNESS_FORMS:
            raise DefinitionError(
                f"smooth_airfoil = true needs an airfoil .dat file as thickness (it smooths the file's outline, "
                f"Hvid 1993), got thickness = {_fmt(s.thickness)}",
                path=p,
                field="section.smooth_airfoil",
            )
        if s.thickness not in _THICKNESS_FORMS:
            f = pathlib.Path(s.thickness)
            if self.base_dir is not None and not f.is_absolute():
                f = self.base_dir / f
            if not f.is_file():
                raise DefinitionError(
                    f"{s.thickness!r} is neither naca66mod, naca4, elliptic nor table, and the airfoil file "
                    f"{str(f)!r} does not exist",
                    path=p,
                    field="section.thickness",
                )
        if s.meanline == "none" and any(v != 0 for v in self.radial.f_c):
            raise DefinitionError("meanline is 'none' but radial.f_c is not zero", path=p, field="section.meanline")
        if s.thickness == "table":
            x, t = s.thickness_x_c, s.thickness_t
            if x is None or t is None or len(x) != len(t):
                raise DefinitionError("thickness = 'table' needs thickness_x_c and thickness_t of equal length",
                                      path=p, field="section.thickness_t")
            for i, (xi, ti) in enumerate(zip(x, t)):
                if ti < 0 or (ti == 0 and 0 < xi < 1):
                    raise DefinitionError(
                        f"entry {i} (x/c = {xi}) is {ti}: the section would self-intersect",
                        path=p, field="section.thickness_t",
                    )

    def _validate_hub(self):
        p, hub = self.source, self.hub
        longest = MAX_HUB_LENGTH_D * self.diameter
        for name in ("upstream_length", "downstream_length"):
            object.__setattr__(hub, name, _number(getattr(hub, name), f"hub.{name}", p, positive=True))
            if getattr(hub, name) > longest:
                raise DefinitionError(f"{getattr(hub, name)!r} m is more than MAX_HUB_LENGTH_D = {MAX_HUB_LENGTH_D:g} "
                                      f"diameters ({longest:g} m)", path=p, field=f"hub.{name}")
        for end in ("nose", "tail"):
            shape = getattr(hub, f"{end}_shape")
            if not isinstance(shape, str) or shape not in HUB_SHAPES:
                raise DefinitionError(f"expected one of {', '.join(HUB_SHAPES)}, got {_fmt(shape)}", path=p, field=f"hub.{end}_shape")
            length = _number(getattr(hub, f"{end}_length"), f"hub.{end}_length", p, minimum=0.0)
            object.__setattr__(hub, f"{end}_length", length)
            if shape != "flat" and length <= 0:
                raise DefinitionError(f"a {shape} {end} needs a positive length, got {length}", path=p, field=f"hub.{end}_length")
            total = getattr(hub, "upstream_length" if end == "nose" else "downstream_length")
            if length >= total:
                raise DefinitionError(
                    f"{end} length {length} m must be shorter than the hub's {'upstream' if end == 'nose' else 'downstream'} length {total} m",
                    path=p, field=f"hub.{end}_length",
                )

    def _validate_smoothing(self):
        """[smoothing]: known keys and types here, ranges by :class:`SmoothingSettings`
        (the one place they are defined), every refusal naming ``smoothing.<key>``."""
        if self.smoothing is None:
            return
        p = self.source
        sm = dict(table(self.smoothing, p, "smoothing"))
        check_keys(sm, SMOOTHING_KEYS, p, "smoothing")
        if "smooth_tip" in sm and not isinstance(sm["smooth_tip"], bool):
            raise DefinitionError(f"expected true or false, got {_fmt(sm['smooth_tip'])}", path=p,
                                  field="smoothing.smooth_tip")
        for key in SMOOTHING_LENGTH_KEYS + SMOOTHING_RATIO_KEYS + DEFINING_POINT_KEYS:
            if key in sm:
                sm[key] = number(sm[key], p, f"smoothing.{key}")
        if "filter_iterations" in sm:
            sm["filter_iterations"] = number(sm["filter_iterations"], p, "smoothing.filter_iterations", lo=0,
                                             hi=MAX_FILTER_ITERATIONS, integer=True)
        object.__setattr__(self, "smoothing", sm)
        self.smoothing_settings()  # the ranges

    def smoothing_settings(self):
        """The :class:`~.smoothing.SmoothingSettings` of the [smoothing] table (lengths
        as fractions of R, defaults for keys not given); a bad value is a
        DefinitionError naming ``smoothing.<key>`` and the file."""
        from .corners import DefiningPoints
        from .smoothing import SmoothingSettings

        sm = self.smoothing or {}
        values = {k: sm[k] for k in SMOOTHING_LENGTH_KEYS + SMOOTHING_RATIO_KEYS + ("filter_iterations",) if k in sm}
        points = {k: sm[k] for k in DEFINING_POINT_KEYS if k in sm}
        try:
            values["defining_points"] = DefiningPoints(**points)
            # the η of the points must lie above the hub (the blade's hub ratio is D's)
            values["defining_points"].validate(_HubRatio(self.hub_diameter_ratio), "defining_points.")
            return SmoothingSettings.from_metres(values, self.radius)
        except DefinitionError as exc:
            name = (exc.field or "").rsplit(".", 1)[-1]
            message = exc.message
            if name in SMOOTHING_LENGTH_KEYS:  # the settings count in R; the file in metres
                bound = message.split(", got")[0]
                message = f"{sm[name]!r} m is {sm[name] / self.radius:.4g} R, but it {bound} R (R = {self.radius:g} m)"
            raise DefinitionError(message, path=self.source, field=f"smoothing.{name}" if name else "smoothing") from None

    # -- properties -----------------------------------------------------------------
    @property
    def base_dir(self) -> pathlib.Path | None:
        return pathlib.Path(self.source).parent if self.source else None

    @property
    def radius(self) -> float:
        return 0.5 * self.diameter

    @property
    def hub_radius(self) -> float:
        return 0.5 * self.hub_diameter_ratio * self.diameter

    def with_values(self, **changes) -> "Propeller":
        """A copy with top-level fields replaced (validated again); ``radial_<name>=array``,
        ``section_<name>=...`` and ``hub_<name>=...`` replace one nested field."""
        nested = {"radial": {}, "section": {}, "hub": {}}
        top = {}
        for key, value in changes.items():
            for prefix in nested:
                if key.startswith(prefix + "_") and key[len(prefix) + 1 :] in {f.name for f in fields(getattr(self, prefix))}:
                    nested[prefix][key[len(prefix) + 1 :]] = value
                    break
            else:
                top[key] = value
        for prefix, vals in nested.items():
            if vals:
                top[prefix] = replace(getattr(self, prefix), **vals)
        return replace(self, **top)

    def build(self):
        """The float64 model: blade b(ξ, η) and hub (see :class:`~.model.PropellerModel`)."""
        from .model import PropellerModel

        return PropellerModel.from_definition(self)

    # -- TOML -------------------------------------------------------------------------
    @classmethod
    def from_dict(cls, data: dict, source=None) -> "Propeller":
        p = str(source) if source is not None else None
        table(data, p, "definition")
        check_keys(data, _TOP_KEYS, p)
        for key in ("name", "blades", "diameter", "hub_diameter_ratio", "hand"):
            if key not in data:
                raise DefinitionError("missing", path=p, field=key)
        sec = table(data.get("section", {}), p, "section")
        check_keys(sec, _SECTION_KEYS, p, "section")
        hub = data.get("hub")
        if hub is None:
            diameter = number(data["diameter"], p, "diameter", lo=MIN_LENGTH, hi=MAX_LENGTH)
            hub_def = HubDefinition.default_for(float(diameter))
        else:
            check_keys(table(hub, p, "hub"), _HUB_KEYS, p, "hub")
            for key in ("upstream_length", "downstream_length"):
                if key not in hub:
                    raise DefinitionError("missing", path=p, field=f"hub.{key}")
            hub_def = HubDefinition(**hub)
        if "radial_table" in data:
            if "radial" in data:
                raise DefinitionError("give either [radial] or radial_table, not both", path=p, field="radial_table")
            radial = read_radial_csv(data["radial_table"], base_dir=pathlib.Path(p).parent if p else None, source=p)
        else:
            rad = data.get("radial")
            if not isinstance(rad, dict):
                raise DefinitionError("missing [radial] table (or radial_table = \"file.csv\")", path=p, field="radial")
            check_keys(rad, RADIAL_FIELDS, p, "radial")
            missing = [k for k in RADIAL_FIELDS if k not in rad]
            if missing:
                raise DefinitionError("missing", path=p, field=f"radial.{missing[0]}")
            radial = RadialDistribution(**{k: rad[k] for k in RADIAL_FIELDS})
        return cls(
            name=data["name"],
            blades=data["blades"],
            diameter=data["diameter"],
            hub_diameter_ratio=data["hub_diameter_ratio"],
            hand=data["hand"],
            section=SectionDefinition(**sec),
            hub=hub_def,
            radial=radial,
            source=p,
            smoothing=data.get("smoothing"),
        )

    @classmethod
    def from_toml(cls, path) -> "Propeller":
        """Read and validate a definition file (tomllib)."""
        path = pathlib.Path(path)
        data = read_toml(path)
        return cls.from_dict(data, source=path.resolve())

    def to_dict(self, relative_to=None) -> dict:
        """Plain data (the TOML layout). An airfoil-file thickness path is rewritten
        relative to ``relative_to`` (a folder) when given."""
        # smooth_airfoil is written only when set (off by default)
        sec = {k: v for k, v in vars(self.section).items() if v is not None and not (k == "smooth_airfoil" and not v)}
        if not self.section.smooth_airfoil or self.section.smooth_passes == DEFAULT_SMOOTH_PASSES:
            sec.pop("smooth_passes", None)  # written only when it matters
        thickness = self.section.thickness
        if self.base_dir is not None and relative_to is not None and thickness not in _THICKNESS_FORMS:
            absolute = (self.base_dir / thickness).resolve()
            sec["thickness"] = os.path.relpath(absolute, relative_to).replace(os.sep, "/")
        sec = {k: list(v) if isinstance(v, tuple) else v for k, v in sec.items()}
        out = {
            "name": self.name,
            "blades": self.blades,
            "diameter": self.diameter,
            "hub_diameter_ratio": self.hub_diameter_ratio,
            "hand": self.hand,
            "section": sec,
            "hub": dict(vars(self.hub)),
            "radial": {k: list(getattr(self.radial, k)) for k in RADIAL_FIELDS},
        }
        if self.smoothing is not None:
            out["smoothing"] = {k: self.smoothing[k] for k in SMOOTHING_KEYS if k in self.smoothing}
        return out

    def to_toml(self, path, header: str = "") -> None:
        """Write the definition (atomically: temporary file, then os.replace)."""
        path = pathlib.Path(path)
        text = dumps_toml(self.to_dict(relative_to=path.resolve().parent), header)
        try:
            atomic_write(path, text)
        except OSError as exc:
            raise DefinitionError(f"cannot write the definition: {exc}", path=str(path)) from exc


@dataclass(frozen=True)
class _HubRatio:
    """What DefiningPoints.validate needs of a blade: its hub radius ratio."""

    hub_ratio: float


def read_radial_csv(name, base_dir=None, source=None) -> RadialDistribution:
    """A radial table from CSV: a header line with the [radial] column names; '#' lines skipped."""
    if not isinstance(name, str):
        raise DefinitionError(f"expected a file name, got {_fmt(name)}", path=source, field="radial_table")
    path = pathlib.Path(name)
    if base_dir is not None and not path.is_absolute():
        path = pathlib.Path(base_dir) / path
    text = read_text(path, what="radial table file", source=str(path) if source is None else source,
                     field="radial_table")
    lines = [(i, ln) for i, ln in enumerate(text.splitlines(), start=1) if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise DefinitionError("empty radial table", path=str(path), field="radial_table")
    check_count(len(lines) - 1, MAX_RADIAL_STATIONS, "MAX_RADIAL_STATIONS", str(path), "radial_table", "stations")
    reader = csv.reader(io.StringIO("\n".join(ln for _, ln in lines)))
    rows = list(reader)
    header = [CSV_ALIASES.get(h.strip(), h.strip()) for h in rows[0]]
    missing = [k for k in RADIAL_FIELDS if k not in header]
    if missing:
        raise DefinitionError(f"missing column {missing[0]!r} (header {rows[0]})", path=str(path), field=missing[0])
    cols = {k: [] for k in RADIAL_FIELDS}
    for (lineno, _), row in zip(lines[1:], rows[1:]):
        if len(row) != len(header):
            raise DefinitionError(f"line {lineno}: {len(row)} values, header has {len(header)}", path=str(path))
        for k in RADIAL_FIELDS:
            cell = row[header.index(k)].strip()
            try:
                v = float(cell)
            except ValueError:
                raise DefinitionError(f"line {lineno}: {cell!r} is not a number", path=str(path), field=k) from None
            if not math.isfinite(v):
                raise DefinitionError(f"line {lineno}: value {cell} is NaN or infinite", path=str(path), field=k)
            cols[k].append(v)
    return RadialDistribution(**{k: tuple(v) for k, v in cols.items()})


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(float(v))  # numpy 2's float64 repr is 'np.float64(...)'
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def dumps_toml(data: dict, header: str = "") -> str:
    """TOML text for a dict of scalars, arrays and one level of tables."""
    out = [("# " + line).rstrip() for line in header.splitlines()] if header else []
    for k, v in data.items():
        if not isinstance(v, dict):
            out.append(f"{k} = {_toml_value(v)}")
    for k, v in data.items():
        if isinstance(v, dict):
            out.append("")
            out.append(f"[{k}]")
            for kk, vv in v.items():
                out.append(f"{kk} = {_toml_value(vv)}")
    return "\n".join(out) + "\n"
