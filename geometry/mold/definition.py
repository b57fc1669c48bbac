"""Wind-turbine blade definition files (TOML, metres) for the mold-halves pipeline.

Format (every array of ``[stations]`` has one value per station, root to tip)::

    name = "NREL 5-MW"
    hub_radius = 1.5
    mold_direction = [0.0, 1.0, 0.0]   # optional; the parting direction, default flapwise (+y)
    wrap = true                        # optional; Hosseini Eq. 5 cylinder wrap, false = flat sections
    first_aerodynamic_station = 4      # optional; stations before it form the root transition (§5.1)
    control_points = 14                # optional; per half and section, raised until the tolerance holds
    tolerance = 1e-4                   # optional; fraction of the local chord
    smooth_airfoils = false            # optional; smooth the aerodynamic stations' airfoils first
                                       # (Hvid 1993 smoothfoil, default jobcard)
    smooth_passes = 4                  # optional; passes of its ad hoc curvature smoother (1-50)
    min_trailing_edge_thickness = 0.004  # optional, m; thinner trailing edges are opened to it

    [stations]
    r = [...]           # m, strictly increasing
    chord = [...]       # m, > 0
    twist_deg = [...]
    pitch_axis = [...]  # chord fraction from the LE
    prebend = [...]     # optional, m (flapwise offset)
    sweep = [...]       # optional, m (edgewise offset)
    airfoil = [...]     # a .dat path (relative to the TOML file) or a shipped name, or "circle"

Errors are :class:`DefinitionError` naming the file, the field and the station. Keys are
checked against ``TOP_KEYS`` and ``REQUIRED`` + ``OPTIONAL`` (the one place to add a key);
an unknown key is refused with the nearest valid name. Counts and sizes are bounded by the
``MAX_*`` constants below (README "Limits of definitions"), named in the refusal.

``smooth_airfoils``: every airfoil of an aerodynamic station (from
``first_aerodynamic_station`` on; "circle" excepted) is replaced by its outline smoothed
with Hvid's smoothfoil (Hvid 1993, DTU AFM 93-08; default jobcard), each file once per
load (and once per process while it is unchanged). The structural-zone stations keep
their sections: they are the root circle the flange is machined to.
"""
from __future__ import annotations

import math
import pathlib
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import BladesmithError, DefinitionError
from ..validation import MAX_LENGTH, MIN_LENGTH, check_count, check_keys, read_toml, string
from ..sections.airfoil_file import Airfoil, read_airfoil, smoothed_airfoil
from ..sections.shape import DEFAULT_SMOOTH_PASSES, check_smooth_passes

#: Points per half of the built-in "circle" section (cosine spaced, dense at the ends).
CIRCLE_POINTS = 101

#: Default control points per half and section (raised until the tolerance holds).
DEFAULT_CONTROL_POINTS = 12

#: Default fitting tolerance as a fraction of the local chord (issue 7).
DEFAULT_TOLERANCE = 1e-4

DATA_DIR = pathlib.Path(__file__).resolve().parent.parent.parent / "data"
BLADES_DIR = DATA_DIR / "blades"

#: Smoothed airfoils kept between loads (live edits reload the definition): key
#: (path, modification time, size) of the file.
SMOOTHED_CACHE_SIZE = 16
_SMOOTHED: dict = {}

#: Degrees of the section curves (p) and across the sections (q): the defaults, and the
#: accepted ranges (p >= 2: the fit prescribes an end derivative at S).
DEFAULT_SECTION_DEGREE = 3
DEFAULT_SPAN_DEGREE = 3
SECTION_DEGREES = (2, 5)
SPAN_DEGREES = (1, 5)

# ---------------------------------------------------------------------------------------
# Every key a wind-blade definition may hold: the one place a strict-key check reads
# (issue 20). Top level, and the arrays of [stations].
# ---------------------------------------------------------------------------------------
REQUIRED = ("r", "chord", "twist_deg", "pitch_axis", "airfoil")
#: "tolerance": per station, a chord fraction overriding the top-level one (issue 19).
OPTIONAL = ("prebend", "sweep", "tolerance")
STATION_KEYS = REQUIRED + OPTIONAL
TOP_LEVEL_KEYS = (
    "name", "hub_radius", "mold_direction", "wrap", "first_aerodynamic_station", "control_points", "tolerance",
    "smooth_airfoils", "smooth_passes", "stations",
    "min_trailing_edge_thickness",  # m: every station's trailing edge at least this thick (issue 16)
    # issue 19: the paper's controls
    "section_degree",     # p of the section curves (Hosseini Eq. 1), 2..5, default 3
    "span_degree",        # q across the sections (Eq. 4), 1..5, default 3
    "tangent_magnitude",  # "sqp" (default: optimised, §4 Fig. 7b) or [upper, lower] by hand (Fig. 7a)
)
#: The keys of the top level ([stations] takes REQUIRED + OPTIONAL).
TOP_KEYS = TOP_LEVEL_KEYS

# Upper bounds (README "Limits of definitions"); each is named in its refusal.
#: Stations: real blades have 10-60 (windIO grids about 50).
MAX_STATIONS = 300
#: Control points per half and section (the fit raises the count up to
#: mold.blade.MAX_CONTROL_POINTS; a start above it is refused here).
MAX_START_CONTROL_POINTS = 60
#: Fewest stations from first_aerodynamic_station on (the skinning is cubic across the span).
MIN_AERODYNAMIC_STATIONS = 4
#: |twist| (degrees).
MAX_TWIST_DEG = 180.0
#: The smallest fitting tolerance (fraction of the chord): below, float64 rounding of the
#: fit is as large as the tolerance.
MIN_TOLERANCE = 1e-9
MAX_TOLERANCE = 0.1
#: min_trailing_edge_thickness may be at most this fraction of the smallest chord.
MAX_TE_THICKNESS_CHORDS = 0.05
#: The trailing edge is opened over this aft fraction of the chord (:func:`opened_trailing_edge`).
TE_OPENING_BLEND = 0.2


def circle_airfoil() -> Airfoil:
    """A unit-diameter circle as an airfoil (LE at (0, 0), TE at (1, 0)): the blade root."""
    th = np.pi * (1.0 - np.cos(np.linspace(0.0, np.pi, CIRCLE_POINTS))) / 2.0  # 0..π
    x = 0.5 - 0.5 * np.cos(th)
    y = 0.5 * np.sin(th)
    upper = np.column_stack([x, y])
    lower = np.column_stack([x, -y])
    upper[-1, 1] = lower[-1, 1] = 0.0
    return Airfoil("circle", upper, lower, "builtin", "")


def shipped_airfoils() -> dict[str, pathlib.Path]:
    """Names of the airfoils shipped in data/blades/airfoils and data/airfoils."""
    out = {}
    for folder in (DATA_DIR / "airfoils", BLADES_DIR / "airfoils"):
        if folder.is_dir():
            out.update({p.stem: p for p in sorted(folder.glob("*.dat"))})
    return out


def resolve_airfoil(spec: str, base: pathlib.Path | None) -> Airfoil:
    """An airfoil from a station's ``airfoil`` entry: "circle", a shipped name, or a path."""
    if spec == "circle":
        return circle_airfoil()
    head = spec.partition("#")[0]
    if "#" in spec and head.lower().endswith((".yaml", ".yml")):
        from .windio import airfoil_from_spec  # windio imports this module

        return airfoil_from_spec(spec, base)
    shipped = shipped_airfoils()
    if spec in shipped:
        return read_airfoil(shipped[spec])
    path = pathlib.Path(spec)
    if not path.is_absolute() and base is not None:
        path = base / path
    return read_airfoil(path)


@dataclass(frozen=True, eq=False)
class Station:
    r: float
    chord: float
    twist_deg: float
    pitch_axis: float
    airfoil: Airfoil
    prebend: float = 0.0
    sweep: float = 0.0
    airfoil_name: str = ""


@dataclass(frozen=True, eq=False)
class BladeDefinition:
    """A validated blade: stations root to tip, with their airfoils read."""

    name: str
    hub_radius: float
    stations: tuple
    mold_direction: np.ndarray = field(default_factory=lambda: np.array([0.0, 1.0, 0.0]))
    wrap: bool = True
    first_aerodynamic_station: int = 0
    control_points: int = DEFAULT_CONTROL_POINTS
    tolerance: float = DEFAULT_TOLERANCE
    path: str = ""
    #: The aerodynamic stations' airfoils are smoothed (Hvid 1993 smoothfoil)...
    smooth_airfoils: bool = False
    #: ...with this many passes of the ad hoc curvature smoother (the paper's jobcard: 4).
    smooth_passes: int = DEFAULT_SMOOTH_PASSES
    #: p of the section curves and q across the sections (Hosseini Eqs. 1 and 4).
    section_degree: int = DEFAULT_SECTION_DEGREE
    span_degree: int = DEFAULT_SPAN_DEGREE
    #: (λ_upper, λ_lower): the tangent magnitudes at S by hand (Hosseini Fig. 7a), or None
    #: for SQP (§4).
    tangent_magnitudes: tuple | None = None
    #: Per station: the tolerance (chord fraction), or None for ``tolerance`` everywhere.
    station_tolerances: tuple | None = None
    #: m: stations with a thinner trailing edge (sharp ones among them) were opened to it
    #: (:func:`opened_trailing_edge`); 0 keeps every airfoil as read.
    min_trailing_edge_thickness: float = 0.0

    def to_dict(self) -> dict:
        """The definition as TOML-ready values (airfoils by name or path)."""
        st = self.stations
        return {
            "name": self.name, "hub_radius": self.hub_radius, "mold_direction": self.mold_direction.tolist(),
            "wrap": self.wrap, "first_aerodynamic_station": self.first_aerodynamic_station,
            "control_points": self.control_points, "tolerance": self.tolerance,
            "smooth_airfoils": self.smooth_airfoils, "smooth_passes": self.smooth_passes,
            "section_degree": self.section_degree, "span_degree": self.span_degree,
            "tangent_magnitude": "sqp" if self.tangent_magnitudes is None else list(self.tangent_magnitudes),
            "min_trailing_edge_thickness": self.min_trailing_edge_thickness,
            "stations": {
                "r": [s.r for s in st], "chord": [s.chord for s in st], "twist_deg": [s.twist_deg for s in st],
                "pitch_axis": [s.pitch_axis for s in st], "prebend": [s.prebend for s in st],
                "sweep": [s.sweep for s in st], "airfoil": [s.airfoil_name for s in st],
                **({} if self.station_tolerances is None else {"tolerance": list(self.station_tolerances)}),
            },
        }


def _number(value, path, fld) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise DefinitionError(f"expected a finite number, got {value!r}", path=path, field=fld)
    return float(value)


def blade_from_dict(data: dict, path: str = "", base: pathlib.Path | None = None) -> BladeDefinition:
    """Validate a parsed definition. Bad stations are refused with the station named."""
    if not isinstance(data, dict):
        raise DefinitionError("expected a table", path=path)
    check_keys(data, TOP_KEYS, path)
    name = string(data.get("name", pathlib.Path(path).stem if path else "blade"), path, "name")
    hub = _number(data.get("hub_radius", 0.0), path, "hub_radius")
    st = data.get("stations")
    if not isinstance(st, dict):
        raise DefinitionError("missing [stations] table", path=path, field="stations")
    check_keys(st, REQUIRED + OPTIONAL, path, "stations")
    for key in REQUIRED:
        if key not in st:
            raise DefinitionError("missing array", path=path, field=f"stations.{key}")
    count = len(st["r"]) if isinstance(st["r"], list) else -1
    check_count(count, MAX_STATIONS, "MAX_STATIONS", path, "stations.r", "stations")
    if count < 2:
        raise DefinitionError(f"expected an array of at least 2 stations, got {st['r']!r}", path=path, field="stations.r")
    for key in REQUIRED + OPTIONAL:
        if key in st and (not isinstance(st[key], list) or len(st[key]) != count):
            raise DefinitionError(f"expected {count} values (one per station)", path=path, field=f"stations.{key}")
    stations = []
    for k in range(count):
        vals = {key: _number(st[key][k], path, f"stations.{key}[{k}]") for key in REQUIRED[:-1]}
        extra = {key: _number(st[key][k], path, f"stations.{key}[{k}]") for key in ("prebend", "sweep") if key in st}
        if k and vals["r"] <= stations[-1].r:
            raise DefinitionError(
                f"station {k}: r = {vals['r']!r} m does not increase (station {k - 1} has r = {stations[-1].r!r} m)",
                path=path, field=f"stations.r[{k}]")
        if not 0 < vals["r"] <= MAX_LENGTH:
            raise DefinitionError(f"station {k}: r must lie in (0, MAX_LENGTH = {MAX_LENGTH:g}] m, got {vals['r']!r}",
                                  path=path, field=f"stations.r[{k}]")
        if vals["chord"] <= 0:
            raise DefinitionError(f"station {k}: chord must be > 0, got {vals['chord']!r}", path=path,
                                  field=f"stations.chord[{k}]")
        if not MIN_LENGTH <= vals["chord"] <= MAX_LENGTH:
            raise DefinitionError(f"station {k}: chord must lie in [MIN_LENGTH = {MIN_LENGTH:g}, MAX_LENGTH = "
                                  f"{MAX_LENGTH:g}] m, got {vals['chord']!r}", path=path, field=f"stations.chord[{k}]")
        if abs(vals["twist_deg"]) > MAX_TWIST_DEG:
            raise DefinitionError(f"station {k}: |twist| is limited to MAX_TWIST_DEG = {MAX_TWIST_DEG:g} deg, got "
                                  f"{vals['twist_deg']!r}", path=path, field=f"stations.twist_deg[{k}]")
        if not 0.0 <= vals["pitch_axis"] <= 1.0:
            raise DefinitionError(f"station {k}: the pitch axis is a chord fraction from the leading edge in [0, 1], "
                                  f"got {vals['pitch_axis']!r}", path=path, field=f"stations.pitch_axis[{k}]")
        for key, value in extra.items():
            if abs(value) > MAX_LENGTH:
                raise DefinitionError(f"station {k}: |{key}| must not exceed MAX_LENGTH = {MAX_LENGTH:g} m, got "
                                      f"{value!r}", path=path, field=f"stations.{key}[{k}]")
        spec = st["airfoil"][k]
        if not isinstance(spec, str) or not spec or len(spec) > 4096:
            raise DefinitionError(f"station {k}: expected an airfoil name or path, got {spec!r}", path=path,
                                  field=f"stations.airfoil[{k}]")
        try:
            foil = resolve_airfoil(spec, base)
        except BladesmithError as exc:
            raise DefinitionError(f"station {k}: cannot read airfoil {spec!r}: {exc}", path=path,
                                  field=f"stations.airfoil[{k}]") from None
        stations.append(Station(vals["r"], vals["chord"], vals["twist_deg"], vals["pitch_axis"], foil,
                                extra.get("prebend", 0.0), extra.get("sweep", 0.0), spec))
    if not 0.0 <= hub <= stations[0].r:
        raise DefinitionError(f"must lie in [0, r of station 0 = {stations[0].r!r}] m, got {hub!r}", path=path,
                              field="hub_radius")
    for key in ("prebend", "sweep"):
        if key in st:
            span = stations[-1].r
            worst = max(abs(getattr(s, key)) for s in stations)
            if worst > span:
                k = max(range(count), key=lambda i: abs(getattr(stations[i], key)))
                raise DefinitionError(f"station {k}: |{key}| = {worst!r} m is more than the tip radius {span!r} m",
                                      path=path, field=f"stations.{key}[{k}]")
    direction = data.get("mold_direction", [0.0, 1.0, 0.0])
    if not isinstance(direction, list) or len(direction) != 3:
        raise DefinitionError(f"expected [x, y, z], got {direction!r}", path=path, field="mold_direction")
    d = np.array([_number(v, path, "mold_direction") for v in direction])
    if np.linalg.norm(d) == 0:
        raise DefinitionError("the mold direction is the zero vector", path=path, field="mold_direction")
    first = data.get("first_aerodynamic_station", 0)
    if isinstance(first, bool) or not isinstance(first, int) or not 0 <= first <= count - 2:
        raise DefinitionError(f"expected an integer in [0, {count - 2}], got {first!r}", path=path,
                              field="first_aerodynamic_station")
    if count - first < MIN_AERODYNAMIC_STATIONS:
        raise DefinitionError(
            f"the aerodynamic zone (stations {first} to {count - 1}) has {count - first} stations; skinning them "
            f"(degree 3 across the span) needs at least {MIN_AERODYNAMIC_STATIONS}", path=path,
            field="first_aerodynamic_station" if first else "stations.r")
    n = data.get("control_points", DEFAULT_CONTROL_POINTS)
    if isinstance(n, bool) or not isinstance(n, int) or n < 5:
        raise DefinitionError(f"expected an integer >= 5, got {n!r}", path=path, field="control_points")
    check_count(n, MAX_START_CONTROL_POINTS, "MAX_START_CONTROL_POINTS", path, "control_points",
                "control points per half")
    tol = _number(data.get("tolerance", DEFAULT_TOLERANCE), path, "tolerance")
    if not MIN_TOLERANCE <= tol <= MAX_TOLERANCE:
        raise DefinitionError(f"expected a chord fraction in [MIN_TOLERANCE = {MIN_TOLERANCE:g}, "
                              f"MAX_TOLERANCE = {MAX_TOLERANCE:g}], got {tol!r}", path=path, field="tolerance")
    wrap = data.get("wrap", True)
    if not isinstance(wrap, bool):
        raise DefinitionError(f"expected true or false, got {wrap!r}", path=path, field="wrap")
    smooth = data.get("smooth_airfoils", False)
    if not isinstance(smooth, bool):
        raise DefinitionError(f"expected true or false, got {smooth!r}", path=path, field="smooth_airfoils")
    passes = check_smooth_passes(data.get("smooth_passes", DEFAULT_SMOOTH_PASSES), path, "smooth_passes")
    p = _degree(data.get("section_degree", DEFAULT_SECTION_DEGREE), SECTION_DEGREES, path, "section_degree")
    q = _degree(data.get("span_degree", DEFAULT_SPAN_DEGREE), SPAN_DEGREES, path, "span_degree")
    if q > count - first - 1:
        raise DefinitionError(f"span_degree {q} needs at least {q + 1} aerodynamic stations, the blade has "
                              f"{count - first}", path=path, field="span_degree")
    magnitudes = _tangent_magnitudes(data.get("tangent_magnitude", "sqp"), path)
    station_tols = None
    if "tolerance" in st:
        station_tols = tuple(_number(v, path, f"stations.tolerance[{k}]") for k, v in enumerate(st["tolerance"]))
        for k, v in enumerate(station_tols):
            if v <= 0:
                raise DefinitionError(f"station {k}: expected a positive chord fraction, got {v!r}", path=path,
                                      field=f"stations.tolerance[{k}]")
    if smooth:
        stations = _smoothed_stations(stations, first, path, passes)
    te_min = _number(data.get("min_trailing_edge_thickness", 0.0), path, "min_trailing_edge_thickness")
    smallest = min(s.chord for s in stations)
    if not 0.0 <= te_min <= MAX_TE_THICKNESS_CHORDS * smallest:
        raise DefinitionError(f"expected a thickness in [0, MAX_TE_THICKNESS_CHORDS = {MAX_TE_THICKNESS_CHORDS:g} x "
                              f"the smallest chord = {MAX_TE_THICKNESS_CHORDS * smallest:g}] m, got {te_min!r}",
                              path=path, field="min_trailing_edge_thickness")
    if te_min > 0:
        stations = [replace(s, airfoil=opened_trailing_edge(s.airfoil, te_min / s.chord)) for s in stations]
    return BladeDefinition(name, hub, tuple(stations), d / np.linalg.norm(d), wrap, first, n, tol, path, smooth,
                           passes, p, q, magnitudes, station_tols, te_min)


def opened_trailing_edge(foil: Airfoil, thickness: float, blend: float = TE_OPENING_BLEND) -> Airfoil:
    """``foil`` with its trailing edge at least ``thickness`` (chord fraction) thick.

    Why (issue 16): a blunt trailing edge that turns sharp between two stations (NREL
    5-MW: 12.6 mm at r = 40.45 m, sharp NACA 64-618 from 44.55 m; the sharp root circle
    before the 8.3-11.75 m DU 40) ends its base in a zero-angle cusp, which no mesher
    fills with well-shaped elements; and a laminated blade is never sharp: its trailing
    edge is at least the bond line thick. The missing thickness g = thickness - (the
    airfoil's) is added half to each side, y_upper += g/2 b(x), y_lower -= g/2 b(x), with
    b the C1 smoothstep 3t² - 2t³ of t = (x - (1 - blend)) / blend on the aft ``blend`` of
    the chord (0 ahead of it): the camber line stays, the outline moves at most g/2 (at
    the trailing edge) and keeps its slope at x = 1 - blend. A trailing edge already as
    thick is returned unchanged."""
    g = thickness - foil.trailing_edge_thickness
    if g <= 0:
        return foil

    def lift(xy, sign):
        t = np.clip((xy[:, 0] - (1.0 - blend)) / blend, 0.0, 1.0)
        out = np.array(xy, dtype=np.float64)
        out[:, 1] += sign * 0.5 * g * t * t * (3.0 - 2.0 * t)
        return out

    return replace(foil, upper=lift(foil.upper, 1.0), lower=lift(foil.lower, -1.0))


def _degree(value, bounds, path, fld) -> int:
    lo, hi = bounds
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        raise DefinitionError(f"expected an integer in [{lo}, {hi}], got {value!r}", path=path, field=fld)
    return value


def _tangent_magnitudes(value, path) -> tuple | None:
    """"sqp" (None) or [λ_upper, λ_lower] > 0: the derivative magnitudes at S (Hosseini
    Fig. 7a), in units of each half's [0, 1] parameter per chord (the halves' lengths)."""
    if isinstance(value, str) and value.lower() == "sqp":
        return None
    if isinstance(value, list) and len(value) == 2:
        lam = tuple(_number(v, path, "tangent_magnitude") for v in value)
        if all(x > 0 for x in lam):
            return lam
    raise DefinitionError(f'expected "sqp" or [upper, lower] (two positive numbers), got {value!r}', path=path,
                          field="tangent_magnitude")


def _smoothed_airfoil(foil: Airfoil, passes: int) -> Airfoil:
    """``foil`` smoothed by Hvid's smoothfoil, from the cache while its file is unchanged."""
    try:
        stat = pathlib.Path(foil.path).stat()
        key = (str(pathlib.Path(foil.path).resolve()), stat.st_mtime_ns, stat.st_size, passes)
    except OSError:
        key = None
    if key is not None and key in _SMOOTHED:
        return _SMOOTHED[key]
    out = smoothed_airfoil(foil, passes=passes)
    if key is not None:
        while len(_SMOOTHED) >= SMOOTHED_CACHE_SIZE:
            _SMOOTHED.pop(next(iter(_SMOOTHED)))
        _SMOOTHED[key] = out
    return out


def _smoothed_stations(stations: list, first: int, path, passes: int = DEFAULT_SMOOTH_PASSES) -> list:
    """The stations with the airfoils of the aerodynamic ones (k >= ``first``, not
    "circle") smoothed, each airfoil file once."""
    done: dict = {}
    out = []
    for k, st in enumerate(stations):
        if k < first or st.airfoil_name == "circle":
            out.append(st)
            continue
        key = st.airfoil.path or st.airfoil_name
        if key not in done:
            try:
                done[key] = _smoothed_airfoil(st.airfoil, passes)
            except BladesmithError as exc:  # SmoothingNotConverged (a GeometryError) among them
                raise DefinitionError(
                    f"station {k}: the airfoil {st.airfoil_name!r} could not be smoothed (Hvid 1993 smoothfoil; "
                    f"smooth_airfoils = false keeps it as read): {exc}",
                    path=path, field=f"stations.airfoil[{k}]") from exc
        out.append(replace(st, airfoil=done[key]))
    return out


def load_blade(path) -> BladeDefinition:
    """Read and validate a blade definition: a TOML file, or a windIO turbine file
    (``.yaml`` / ``.yml``, :mod:`.windio`) through the same checks."""
    path = pathlib.Path(path)
    if path.suffix.lower() in (".yaml", ".yml"):
        from .windio import load_windio_blade

        return load_windio_blade(path)
    data = read_toml(path)
    return blade_from_dict(data, str(path), path.parent)


def preset_files() -> dict[str, pathlib.Path]:
    """Shipped blade definitions by preset name (file stem upper-cased: "NREL5MW")."""
    return {p.stem.upper(): p for p in sorted(BLADES_DIR.glob("*.toml"))}


def load_preset(name: str) -> BladeDefinition:
    presets = preset_files()
    key = name.upper()
    if key not in presets:
        raise DefinitionError(f"unknown blade preset {name!r}; shipped: {sorted(presets)}", field="preset")
    return load_blade(presets[key])


def relocated_airfoil(spec: str, base: pathlib.Path | None, folder: pathlib.Path) -> str:
    """A station's airfoil entry as it must be written in a definition saved in
    ``folder``: "circle" and shipped names unchanged; a path (or the windIO file of a
    ``file.yaml#name`` entry) read from ``base`` made relative to ``folder`` when it can
    be, else absolute."""
    import os

    if spec == "circle" or spec in shipped_airfoils():
        return spec
    head, sep, rest = spec.partition("#")
    if not (sep and head.lower().endswith((".yaml", ".yml"))):
        head, sep, rest = spec, "", ""
    path = pathlib.Path(head)
    if not path.is_absolute() and base is not None:
        path = base / path
    path = path.resolve()
    try:
        head = os.path.relpath(path, folder.resolve())
    except ValueError:  # another drive
        head = str(path)
    return f"{pathlib.Path(head).as_posix()}{sep}{rest}"


def save_blade(data: dict, path, base: pathlib.Path | None = None) -> str:
    """Write the definition ``data`` (TOML layout) to ``path`` atomically, after checking
    it (:func:`blade_from_dict`) and rewriting its airfoil entries for the new folder
    (:func:`relocated_airfoil`). Returns the path. "Save Wind Blade Definition"."""
    from ..files import atomic_write
    from ..propeller import dumps_toml

    path = pathlib.Path(path)
    blade_from_dict(data, str(path), base)  # refuse what could not be read back
    out = dict(data)
    stations = dict(out["stations"])
    stations["airfoil"] = [relocated_airfoil(a, base, path.parent) for a in stations["airfoil"]]
    out["stations"] = stations
    header = (f"# Wind-blade definition saved by Bladesmith (Hosseini & Moetakef-Imani 2016 molds).\n"
              f"# Format: README, 'The wind-blade molds'.\n")
    atomic_write(path, header + dumps_toml(out))
    return str(path)
