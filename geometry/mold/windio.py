"""Wind-turbine blades from windIO turbine files (IEA Wind Task 37 ontology, YAML).

windIO keeps a blade as distributions over the non-dimensional span s in [0, 1], each on
its own grid, and the airfoils as coordinate lists. Versions name some fields differently:

=====================  ======================================  ========================================
quantity               windIO 1.x (``outer_shape_bem``)        windIO 2.x (``outer_shape``)
=====================  ======================================  ========================================
version                no ``windIO_version`` key               ``windIO_version: '2.0'`` (a string)
chord (m)              ``chord``                                ``chord``
twist                  ``twist``, radians                       ``twist``, degrees
pitch axis             ``pitch_axis``, chord fraction from LE   ``section_offset_y``, m from the LE
reference axis (m)     ``outer_shape_bem.reference_axis``       ``blade.reference_axis``
airfoil positions      ``airfoil_position {grid, labels}``      ``airfoils[] {name, spanwise_position}``
=====================  ======================================  ========================================

Both have ``airfoils[] {name, coordinates {x, y}}`` at the top level (Selig order) and
``components.hub.diameter``. The reference axis is read as: ``x`` the prebend (flapwise,
positive toward the suction side, the +y of :mod:`.sections`), ``y`` the sweep (edgewise,
toward the trailing edge), ``z`` the span from the blade root, so r = hub radius + z.

Stations: the union of the chord grid and the airfoil positions (the grid the file's
author chose for the planform, and every place an airfoil is given exactly). Twist, pitch
axis and the reference axis are interpolated onto them with ``PchipInterpolator`` (as
WISDEM does). Between two positions with different airfoils the section is a blend,
linear in s, of the two airfoils' upper and lower sides resampled at one cosine-spaced
chordwise grid (thickness and camber of :func:`~..sections.airfoil_file.thickness_and_camber`).
The ``circular`` root airfoil becomes Bladesmith's exact ``circle``, and the stations
before the first airfoil that is neither a circle nor a blend with one form the
structural zone of the root transition (Hosseini & Moetakef-Imani 2016, §5.1).

The result is a definition dictionary in the TOML layout of :mod:`.definition`, validated
by the same :func:`~.definition.blade_from_dict` as a TOML file. Its airfoils are named
``<file>#<airfoil>`` or ``<file>#<A>|<B>@<w>`` (the blend with weight w of B), which
:func:`airfoil_from_spec` resolves, so a saved definition reads the airfoils from the
windIO file again.
"""
from __future__ import annotations

import math
import pathlib

import numpy as np

from ..errors import DefinitionError
from ..sections.airfoil_file import Airfoil, airfoil_from_outline
from . import yaml_subset

#: Airfoil names windIO uses for the cylindrical root section.
CIRCLE_NAMES = ("circular", "circle", "Cylinder", "cylinder")
#: Stations closer than this in non-dimensional span are one station.
SPAN_MERGE_TOL = 1e-6
#: A chord grid point closer than this span fraction to an airfoil position is left out
#: (the position is the station; two stations 0.05 m apart would make the skinning stiff).
GRID_MERGE = 0.005
#: An end segment of an airfoil outline this steep to the chord line (degrees) closes a
#: flatback trailing edge (:func:`open_flatback`).
FLATBACK_ANGLE_DEG = 60.0
#: Points per side of a blended airfoil (cosine spaced).
BLEND_POINTS = 121
#: Parsed files kept (live edits resolve airfoils again): key (path, mtime, size).
CACHE_SIZE = 4
_CACHE: dict = {}

WINDIO_SUFFIXES = (".yaml", ".yml")


def is_windio_path(path) -> bool:
    return pathlib.Path(str(path)).suffix.lower() in WINDIO_SUFFIXES


def load_document(path) -> dict:
    """The parsed windIO file (cached while it is unchanged)."""
    path = pathlib.Path(path)
    try:
        st = path.stat()
    except FileNotFoundError:
        raise DefinitionError("windIO file not found", path=str(path)) from None
    key = (str(path.resolve()), st.st_mtime_ns, st.st_size)
    if key not in _CACHE:
        doc = yaml_subset.load(path)
        if not isinstance(doc, dict):
            raise DefinitionError("expected a mapping at the top level", path=str(path))
        while len(_CACHE) >= CACHE_SIZE:
            _CACHE.pop(next(iter(_CACHE)))
        _CACHE[key] = doc
    return _CACHE[key]


def windio_version(doc: dict) -> int:
    """The major windIO version: 2 when ``windIO_version`` says 2.x, else 1."""
    v = doc.get("windIO_version")
    if v is None:
        return 1
    major = str(v).split(".")[0]
    if major not in ("1", "2"):
        raise DefinitionError(f"unsupported windIO_version {v!r} (1.x and 2.x are read)", field="windIO_version")
    return int(major)


def _get(tree, keys: str, path: str, prefix: str = ""):
    node = tree
    done = [prefix] if prefix else []
    for k in keys.split("."):
        done.append(k)
        if not isinstance(node, dict) or k not in node:
            raise DefinitionError("missing in the windIO file", path=path, field=".".join(done))
        node = node[k]
    return node


def _distribution(node, path: str, field: str) -> tuple[np.ndarray, np.ndarray]:
    if not isinstance(node, dict) or "grid" not in node or "values" not in node:
        raise DefinitionError("expected {grid, values}", path=path, field=field)
    try:
        grid = np.asarray(node["grid"], dtype=np.float64)
        values = np.asarray(node["values"], dtype=np.float64)
    except (TypeError, ValueError):
        raise DefinitionError("expected numbers in grid and values", path=path, field=field) from None
    if grid.ndim != 1 or grid.shape != values.shape or grid.size < 2:
        raise DefinitionError(f"expected grid and values of one length >= 2, got {grid.shape} and {values.shape}",
                              path=path, field=field)
    if not (np.all(np.isfinite(grid)) and np.all(np.isfinite(values))):
        raise DefinitionError("grid and values must be finite", path=path, field=field)
    if np.any(np.diff(grid) <= 0):
        k = int(np.flatnonzero(np.diff(grid) <= 0)[0]) + 1
        raise DefinitionError(f"grid[{k}] = {grid[k]!r} does not increase", path=path, field=f"{field}.grid")
    return grid, values


def _interp(dist, s: np.ndarray) -> np.ndarray:
    from scipy.interpolate import PchipInterpolator

    grid, values = dist
    return PchipInterpolator(grid, values, extrapolate=True)(s)


def _blade_fields(doc: dict, path: str) -> dict:
    """The version-specific fields as distributions and positions."""
    version = windio_version(doc)
    blade = _get(doc, "components.blade", path)
    if version == 1:
        shape = _get(blade, "outer_shape_bem", path, "components.blade")
        base = "components.blade.outer_shape_bem"
        pos = _get(shape, "airfoil_position", path, base)
        grid, labels = pos.get("grid"), pos.get("labels")
        twist = _distribution(_get(shape, "twist", path, base), path, f"{base}.twist")
        twist = (twist[0], np.degrees(twist[1]))
        pitch = ("fraction", _distribution(_get(shape, "pitch_axis", path, base), path, f"{base}.pitch_axis"))
        axis = _get(shape, "reference_axis", path, base)
        axis_field = f"{base}.reference_axis"
    else:
        shape = _get(blade, "outer_shape", path, "components.blade")
        base = "components.blade.outer_shape"
        foils = _get(shape, "airfoils", path, base)
        if not isinstance(foils, list):
            raise DefinitionError("expected a list", path=path, field=f"{base}.airfoils")
        grid = [f.get("spanwise_position") if isinstance(f, dict) else None for f in foils]
        labels = [f.get("name") if isinstance(f, dict) else None for f in foils]
        twist = _distribution(_get(shape, "twist", path, base), path, f"{base}.twist")
        pitch = ("offset", _distribution(_get(shape, "section_offset_y", path, base), path, f"{base}.section_offset_y"))
        axis = _get(blade, "reference_axis", path, "components.blade")
        axis_field = "components.blade.reference_axis"
    chord = _distribution(_get(shape, "chord", path, base), path, f"{base}.chord")
    if not isinstance(grid, list) or not isinstance(labels, list) or len(grid) != len(labels) or len(grid) < 2:
        raise DefinitionError("expected the airfoil positions and names as lists of one length >= 2", path=path,
                              field=f"{base}.{'airfoil_position' if version == 1 else 'airfoils'}")
    try:
        positions = np.asarray(grid, dtype=np.float64)
    except (TypeError, ValueError):
        raise DefinitionError(f"expected numbers, got {grid!r:.80}", path=path, field=f"{base} airfoil positions") from None
    if np.any(np.diff(positions) < 0) or not np.all(np.isfinite(positions)):
        raise DefinitionError("airfoil positions must be finite and non-decreasing", path=path,
                              field=f"{base} airfoil positions")
    for k, name in enumerate(labels):
        if not isinstance(name, str) or not name:
            raise DefinitionError(f"airfoil {k}: expected a name, got {name!r}", path=path, field=f"{base} airfoil names")
    axes = {a: _distribution(_get(axis, a, path, axis_field), path, f"{axis_field}.{a}") for a in "xyz"}
    hub = doc.get("components", {}).get("hub", {})
    diameter = hub.get("diameter", hub.get("outer_shape_bem", {}).get("diameter") if isinstance(hub, dict) else None) \
        if isinstance(hub, dict) else None
    if isinstance(diameter, bool) or not isinstance(diameter, (int, float)) or not math.isfinite(diameter) or diameter < 0:
        raise DefinitionError(f"expected the hub diameter in m, got {diameter!r}", path=path, field="components.hub.diameter")
    return {"version": version, "chord": chord, "twist": twist, "pitch": pitch, "axis": axes,
            "positions": positions, "labels": labels, "hub_radius": 0.5 * float(diameter),
            "name": str(doc.get("name", pathlib.Path(path).stem))}


def _is_circle(name: str) -> bool:
    return name in CIRCLE_NAMES


def windio_airfoil(doc: dict, name: str, path: str) -> Airfoil:
    """The airfoil ``name`` of the file's top-level ``airfoils`` list (Selig order)."""
    foils = doc.get("airfoils")
    if not isinstance(foils, list):
        raise DefinitionError("missing airfoils list", path=path, field="airfoils")
    for k, foil in enumerate(foils):
        if isinstance(foil, dict) and foil.get("name") == name:
            coords = foil.get("coordinates")
            field = f"airfoils[{k}].coordinates"
            if not isinstance(coords, dict) or "x" not in coords or "y" not in coords:
                raise DefinitionError("expected {x, y}", path=path, field=field)
            try:
                xy = np.column_stack([np.asarray(coords["x"], dtype=np.float64),
                                      np.asarray(coords["y"], dtype=np.float64)])
            except (TypeError, ValueError):
                raise DefinitionError("expected two lists of numbers of one length", path=path, field=field) from None
            if len(xy) < 5 or not np.all(np.isfinite(xy)):
                raise DefinitionError(f"expected at least 5 finite points, got {len(xy)}", path=path, field=field)
            keep = np.concatenate([[True], np.linalg.norm(np.diff(xy, axis=0), axis=1) > 0])
            return airfoil_from_outline(open_flatback(xy[keep]), name, "windio", path)
    names = [f.get("name") for f in foils if isinstance(f, dict)]
    raise DefinitionError(f"no airfoil named {name!r}; the file has {names}", path=path, field="airfoils")


def _outline_spline(foil: Airfoil):
    """The outline (TE upper -> LE -> TE lower) as a C2 cubic interpolant over its
    normalised chord-length parameter (``scipy.interpolate.make_interp_spline``)."""
    from scipy.interpolate import make_interp_spline

    P = foil.outline
    t = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
    return make_interp_spline(t / t[-1], P, k=3, axis=0)


def open_flatback(xy: np.ndarray) -> np.ndarray:
    """The outline without the points that close a blunt (flatback) trailing edge.

    windIO files close a flatback airfoil: the list starts and ends at the chord's end
    (1, 0) and steps across the base to the suction and pressure sides (SNL-FFA-W3-500 of
    the IEA 15 MW). The two base segments meet the sides at corners that no smooth section
    curve fits; the sides' ends are the blunt trailing edge, which the mold's ruled
    trailing-edge base closes. An end segment steeper than :data:`FLATBACK_ANGLE_DEG` to
    the chord line is such a base step."""
    P = np.asarray(xy, dtype=np.float64)
    chord = P[np.argmax(np.linalg.norm(P - 0.5 * (P[0] + P[-1]), axis=1))] - 0.5 * (P[0] + P[-1])
    c = chord / np.linalg.norm(chord)

    def steep(a, b):
        d = b - a
        return abs(d @ c) < np.cos(np.radians(FLATBACK_ANGLE_DEG)) * np.linalg.norm(d)

    lo, hi = 0, len(P)
    if steep(P[0], P[1]):
        lo = 1
    if steep(P[-1], P[-2]):
        hi = len(P) - 1
    return P[lo:hi]


def blend_airfoils(a: Airfoil, b: Airfoil, weight: float, name: str = "", path: str = "") -> Airfoil:
    """(1 - weight) a + weight b: both outlines at the same normalised chord-length
    parameters (denser near the trailing edges and the leading edge), point by point,
    renormalised to unit chord. Blending C2 outlines at one parameter gives a C2 outline;
    blending ordinates at one chordwise x would inherit the kinks of a per-side
    interpolation and the square-root slope of a round nose."""
    u = np.linspace(0.0, 1.0, 2 * BLEND_POINTS - 1)
    t = u - np.sin(4.0 * np.pi * u) / (4.0 * np.pi)  # dense at 0, 1/2, 1
    P = (1.0 - weight) * _outline_spline(a)(t) + weight * _outline_spline(b)(t)
    return airfoil_from_outline(P, name or f"{a.name}|{b.name}@{weight:g}", "windio-blend", path)


def airfoil_from_spec(spec: str, base: pathlib.Path | None) -> Airfoil:
    """An airfoil named ``<file>#<name>`` or ``<file>#<A>|<B>@<w>`` (a blend) from a windIO file."""
    from .definition import circle_airfoil

    file, _, rest = spec.partition("#")
    path = pathlib.Path(file)
    if not path.is_absolute() and base is not None:
        path = base / path
    doc = load_document(path)

    def one(name):
        return circle_airfoil() if _is_circle(name) else windio_airfoil(doc, name, str(path))

    if "|" not in rest:
        return one(rest)
    pair, _, w = rest.rpartition("@")
    first, _, second = pair.partition("|")
    try:
        weight = float(w)
    except ValueError:
        raise DefinitionError(f"expected <A>|<B>@<weight>, got {rest!r}", path=str(path)) from None
    if not 0.0 <= weight <= 1.0:
        raise DefinitionError(f"blend weight {weight!r} outside [0, 1]", path=str(path))
    return blend_airfoils(one(first), one(second), weight, rest, str(path))


def _stations(fields: dict) -> np.ndarray:
    """Span positions of the stations: every airfoil position, and the chord grid points
    between two positions whose airfoils are not the root circle (from the circle to the
    first airfoil the root transition of Hosseini §5.1 joins the sections; a thickness
    blend of a circle and an airfoil has a square-root slope at the trailing edge that no
    cubic section fits within 1e-4 chord)."""
    pos, labels = fields["positions"], fields["labels"]
    grid = fields["chord"][0]
    keep = []
    for x in grid:
        j = int(np.searchsorted(pos, x, side="right")) - 1
        if j < 0 or j >= len(pos) - 1:
            continue
        near = np.min(np.abs(pos - x)) <= GRID_MERGE * (pos[-1] - pos[0])
        if not near and not (_is_circle(labels[j]) or _is_circle(labels[j + 1])):
            keep.append(x)
    s = np.union1d(np.asarray(keep), pos)
    return s[np.concatenate([[True], np.diff(s) > SPAN_MERGE_TOL])]


def _station_airfoil(s: float, positions, labels, file: str) -> tuple[str, bool]:
    """(spec, structural) of the station at span s: the airfoil or blend there, and whether
    it is a circle or a blend with one."""
    j = int(np.searchsorted(positions, s, side="right")) - 1
    j = min(max(j, 0), len(positions) - 1)
    if abs(s - positions[j]) <= SPAN_MERGE_TOL or j == len(positions) - 1:
        name = labels[j]
        return ("circle" if _is_circle(name) else f"{file}#{name}"), _is_circle(name)
    a, b = labels[j], labels[j + 1]
    if a == b:
        return ("circle" if _is_circle(a) else f"{file}#{a}"), _is_circle(a)
    w = (s - positions[j]) / (positions[j + 1] - positions[j])
    return f"{file}#{a}|{b}@{w:.9g}", _is_circle(a) or _is_circle(b)


def windio_blade_dict(path) -> dict:
    """The blade of a windIO file as a definition dictionary (TOML layout of :mod:`.definition`)."""
    path = pathlib.Path(path)
    doc = load_document(path)
    fields = _blade_fields(doc, str(path))
    s = _stations(fields)
    chord = _interp(fields["chord"], s)
    kind, pitch = fields["pitch"]
    pitch_axis = _interp(pitch, s) if kind == "fraction" else _interp(pitch, s) / chord
    ax = fields["axis"]
    specs, structural = zip(*(_station_airfoil(x, fields["positions"], fields["labels"], path.name) for x in s))
    first = next((k for k, st in enumerate(structural) if not st), 0)
    z = _interp(ax["z"], s)
    return {
        "name": fields["name"],
        "hub_radius": fields["hub_radius"],
        "first_aerodynamic_station": int(first),
        "stations": {
            "r": (fields["hub_radius"] + z).tolist(),
            "chord": chord.tolist(),
            "twist_deg": _interp(fields["twist"], s).tolist(),
            "pitch_axis": pitch_axis.tolist(),
            "prebend": _interp(ax["x"], s).tolist(),
            "sweep": _interp(ax["y"], s).tolist(),
            "airfoil": list(specs),
        },
        "source": {"windio_file": path.name, "windio_version": fields["version"], "span": s.tolist()},
    }


def load_windio_blade(path, **overrides):
    """A validated :class:`~.definition.BladeDefinition` from a windIO file: the same checks
    as a TOML definition (:func:`~.definition.blade_from_dict`). ``overrides``: top-level
    definition keys (control_points, tolerance, ...) set on top of the file's blade."""
    from .definition import blade_from_dict

    path = pathlib.Path(path)
    data = windio_blade_dict(path)
    data.pop("source")
    data.update(overrides)
    return blade_from_dict(data, str(path), path.parent)
