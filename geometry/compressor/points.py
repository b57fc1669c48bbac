"""Impellers from published point data, fitted in Casey's (1983) representation.

Casey (1983, "Blade Surfaces", and "The shapes produced are general enough to be used ...
in approximation of the geometry of existing ones"): the meridional channel M is a string
of Bézier patches and each blade surface a string of cubic-linear patches. Designers have
existing impellers as points (NASA and DLR publish them so); this module reads such points
and fits M and the blades with :mod:`.fitting` to a tolerance, reporting the achieved
deviation per surface.

Point file (TOML; README "Impeller point data")::

    name = "DLR SRV2-O"
    units = "mm"                  # "m" or "mm": all lengths of the data files
    coordinates = "cartesian"     # or "cylindrical": columns (axial, r, r_theta)
    axis = "x"                    # cartesian only: the data coordinate along the machine axis
    blades = 13                   # Z

    [hub]                         # meridional contour points (axial, radius), inlet to outlet
    file = "contours.csv"         # CSV with a header row; lines starting with # are ignored;
    axial = "XH"                  # path relative to this file
    radius = "RH"
    axial_min = -75.0             # optional filters (data units) keeping the impeller part
    radius_max = 112.0

    [shroud]
    file = "contours.csv"
    axial = "XS"
    radius = "RS"

    [[blade]]                     # one table per blade (main, splitter)
    name = "main"
    pressure = "main_PS.csv"      # generating lines of the pressure side: each row a shroud-
    suction = "main_SS.csv"       # side and a hub-side point (ruled, flank-milled blades)
    shroud_point = ["XS", "YS", "ZS"]   # column names; cylindrical: (axial, r, r_theta)
    hub_point = ["XH", "YH", "ZH"]
    radius_max = 112.0            # optional: lines trimmed to this radius as well

Blade sections instead of lines (``kind = "sections"``): the sections in order from hub
to shroud, either as one closed loop per file (``loops = ["s0.csv", ...]``, split into
the pressure and suction sides at the two points farthest apart, the LE and TE; the side
at larger φ is the pressure side, the convention of :mod:`.blade`) or as side lists
(``pressure_sections`` and ``suction_sections``), with ``point = [c1, c2, c3]`` naming the
columns. Each side's first and last sections are joined into straight lines (Casey's
rulings), which are then treated as the generating lines above: with ``pairing = "index"``
point k of the first section to point k of the last (sections written at common blade
parameters); with ``pairing = "length"`` (default) at equal fractions of length on the
first and at σ(s) on the last, σ a sine series chosen to bring the lines closest to the
intermediate sections (:func:`_ruling_lines`, a heuristic: on the test blade it leaves
0.4-0.5 mm where index pairing gives 0.017 mm). The deviation is measured against every
section point, so a blade that is not exactly ruled shows how far the best ruled surface
is from it.

The lines are trimmed to the fitted channel walls (and to ``radius_max``), then each side
is fitted by the best ruled surface (:func:`.fitting.fit_ruled_surface`). Cartesian data
with the axis along data coordinate a are mapped to the right-handed (x, y, z) of
Bladesmith by the cyclic permutation that puts a on z.
"""
from __future__ import annotations

import csv
import math
import pathlib
import tomllib
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from ..errors import DefinitionError, GeometryError
from ..nurbs import closest_point_curve, closest_point_surface
from .channel import MeridionalChannel
from .blade import WALL_TOLERANCE
from .fitting import (EXTENSION_MARGIN, edges_on_walls, extend_channel, fit_channel, fit_general_surface,
                      fit_ruled_surface, trim_lines_to_channel)

UNITS = {"m": 1.0, "mm": 1e-3}
#: Default fit tolerance as a fraction of the largest radius of the data.
DEFAULT_TOLERANCE_FRACTION = 5e-5
#: Samples per generating line when the blade deviation is measured.
SAMPLES_PER_LINE = 21
KEYS = {"name", "units", "coordinates", "axis", "blades", "hub", "shroud", "blade"}
#: Keys of a [[blade]] table.
BLADE_KEYS = {"name", "kind", "pressure", "suction", "shroud_point", "hub_point", "radius_max", "loops",
              "pressure_sections", "suction_sections", "point", "pairing"}


def _csv_columns(path: pathlib.Path, columns, source: str, field_name: str) -> np.ndarray:
    try:
        with open(path, newline="") as fh:
            rows = list(csv.DictReader(line for line in fh if line.strip() and not line.startswith("#")))
    except OSError as exc:
        raise DefinitionError(f"cannot read {path}: {exc.strerror}", path=source, field=field_name) from None
    if not rows:
        raise DefinitionError(f"{path.name} has no data rows", path=source, field=field_name)
    missing = [c for c in columns if c not in rows[0]]
    if missing:
        raise DefinitionError(f"{path.name} has no column {missing[0]!r}; it has {', '.join(rows[0])}",
                              path=source, field=field_name)
    out = []
    for k, r in enumerate(rows):
        if any(r[c] in (None, "") for c in columns):
            continue  # a shorter column (blank cells) ends there
        try:
            out.append([float(r[c]) for c in columns])
        except ValueError:
            raise DefinitionError(f"{path.name} row {k + 1}: not a number in {columns}", path=source,
                                  field=field_name) from None
    return np.array(out)


@dataclass(frozen=True)
class FittedImpeller:
    """Channel, blades {name: {"S": PatchString, "P": PatchString}}, blade count and the
    deviations (m) of each fitted surface from its points."""

    name: str
    channel: MeridionalChannel
    blades: dict
    count: int
    deviation: dict = field(default_factory=dict)
    tolerance: float = 0.0
    wall_gap: dict = field(default_factory=dict)  # {"<blade> S|P": largest edge-to-wall distance (m)}
    wall_tolerance: float = 0.0
    patches: dict = field(default_factory=dict)  # {"<blade> S|P": cubic-linear patches}
    extended: bool = False  # the walls' end patches were continued to hold the blades
    general: dict = field(default_factory=dict)  # {"<blade> S|P": BSplineSurface} where the ruled fit missed
    ruled_deviation: dict = field(default_factory=dict)  # {"<blade> S|P": the ruled fit's deviation} for those

    @property
    def met(self) -> bool:
        """Whether every surface lies within the tolerance of its points and every blade
        edge on its wall within the wall tolerance."""
        return (all(v <= self.tolerance for v in self.deviation.values())
                and all(g <= self.wall_tolerance for g in self.wall_gap.values()))

    def summary(self) -> str:
        parts = [f"{k} {v * 1e3:.4f} mm" for k, v in self.deviation.items()]
        head = "" if self.met else "tolerance NOT met: "
        text = f"{head}{self.name}: fitted to {self.tolerance * 1e3:.4g} mm; deviation " + ", ".join(parts)
        if self.wall_gap:
            text += (f"; edges on the walls within {max(self.wall_gap.values()) * 1e3:.2g} mm "
                     f"(tolerance {self.wall_tolerance * 1e3:.2g} mm); patches "
                     + ", ".join(f"{k} {v}" for k, v in self.patches.items()))
        if self.general:
            text += "; general B-spline surfaces for " + ", ".join(
                f"{k} (ruled fit {self.ruled_deviation[k] * 1e3:.4f} mm)" for k in self.general)
        return text


class PointFile:
    """A parsed point file (module docstring); lengths converted to metres, (x, y, z)."""

    def __init__(self, path):
        self.path = pathlib.Path(path)
        src = str(self.path)
        try:
            with open(self.path, "rb") as fh:
                data = tomllib.load(fh)
        except OSError as exc:
            raise DefinitionError(f"cannot read: {exc.strerror}", path=src) from None
        except tomllib.TOMLDecodeError as exc:
            raise DefinitionError(f"not valid TOML: {exc}", path=src) from None
        unknown = sorted(set(data) - KEYS)
        if unknown:
            raise DefinitionError(f"unknown key {unknown[0]!r}", path=src, field=unknown[0])
        self.name = str(data.get("name", self.path.stem))
        units = data.get("units")
        if units not in UNITS:
            raise DefinitionError(f"expected one of {sorted(UNITS)}, got {units!r}", path=src, field="units")
        self.scale = UNITS[units]
        self.coordinates = data.get("coordinates", "cartesian")
        if self.coordinates not in ("cartesian", "cylindrical"):
            raise DefinitionError(f"expected \"cartesian\" or \"cylindrical\", got {self.coordinates!r}", path=src,
                                  field="coordinates")
        self.axis = data.get("axis", "z")
        if self.axis not in ("x", "y", "z"):
            raise DefinitionError(f"expected \"x\", \"y\" or \"z\", got {self.axis!r}", path=src, field="axis")
        count = data.get("blades")
        if isinstance(count, bool) or not isinstance(count, int) or count < 1:
            raise DefinitionError(f"expected a positive integer, got {count!r}", path=src, field="blades")
        self.count = count
        self.walls = {w: self._wall(data, w) for w in ("hub", "shroud")}
        blades = data.get("blade")
        if not isinstance(blades, list) or not blades:
            raise DefinitionError("expected at least one [[blade]] table", path=src, field="blade")
        self.blades = [self._blade(b, k) for k, b in enumerate(blades)]

    def _filter(self, pts, table, section):
        for key, col, op in (("axial_min", 0, np.greater_equal), ("axial_max", 0, np.less_equal),
                             ("radius_max", 1, np.less_equal), ("radius_min", 1, np.greater_equal)):
            if key in table:
                value = table[key]
                if isinstance(value, bool) or not isinstance(value, (int, float)):
                    raise DefinitionError(f"expected a number, got {value!r}", path=str(self.path),
                                          field=f"{section}.{key}")
                pts = pts[op(pts[:, col], float(value))]
        return pts

    def _wall(self, data, which):
        table = data.get(which)
        if not isinstance(table, dict):
            raise DefinitionError(f"missing [{which}] table", path=str(self.path), field=which)
        for key in ("file", "axial", "radius"):
            if key not in table:
                raise DefinitionError("missing", path=str(self.path), field=f"{which}.{key}")
        pts = _csv_columns(self.path.parent / table["file"], [table["axial"], table["radius"]], str(self.path),
                           f"{which}.file")
        pts = self._filter(pts, table, which)
        if len(pts) < 4:
            raise DefinitionError(f"{len(pts)} points left after the filters; at least 4 are needed",
                                  path=str(self.path), field=which)
        return pts * self.scale

    def _to_xyz(self, P):
        if self.coordinates == "cylindrical":
            axial, r, rtheta = P[:, 0], P[:, 1], P[:, 2]
            theta = rtheta / r
            return np.column_stack([r * np.cos(theta), r * np.sin(theta), axial])
        a = "xyz".index(self.axis)
        return P[:, [(a + 1) % 3, (a + 2) % 3, a]]

    def _sections(self, b, section):
        """(lines by side, all section points by side) of a blade given as sections."""
        if "point" not in b:
            raise DefinitionError("missing", path=str(self.path), field=f"{section}.point")
        cols = list(b["point"])
        pairing = b.get("pairing", "length")
        if pairing not in ("length", "index"):
            raise DefinitionError(f"expected \"length\" or \"index\", got {pairing!r}", path=str(self.path),
                                  field=f"{section}.pairing")

        def read(name, key):
            pts = _csv_columns(self.path.parent / name, cols, str(self.path), f"{section}.{key}")
            return self._to_xyz(pts * self.scale)

        if "loops" in b:
            sides = {"P": [], "S": []}
            for f in b["loops"]:
                loop = read(f, "loops")
                P, S = _split_loop(loop)
                sides["P"].append(P)
                sides["S"].append(S)
        else:
            for key in ("pressure_sections", "suction_sections"):
                if key not in b:
                    raise DefinitionError("missing (or give loops)", path=str(self.path), field=f"{section}.{key}")
            sides = {"P": [read(f, "pressure_sections") for f in b["pressure_sections"]],
                     "S": [read(f, "suction_sections") for f in b["suction_sections"]]}
        lines, points = {}, {}
        for side, secs in sides.items():
            if len(secs) < 2:
                raise DefinitionError("at least two sections (hub and shroud side) are needed",
                                      path=str(self.path), field=section)
            if pairing == "index":
                if len(secs[0]) != len(secs[-1]):
                    raise DefinitionError(f"pairing \"index\" needs end sections of equal length, got {len(secs[0])} "
                                          f"and {len(secs[-1])} points", path=str(self.path), field=f"{section}.pairing")
                lines[side] = np.stack([secs[-1], secs[0]], axis=1)
            else:
                lines[side] = _ruling_lines(secs)
            points[side] = np.concatenate(secs)
        return lines, points

    def _blade(self, b, k):
        section = f"blade[{k}]"
        if not isinstance(b, dict):
            raise DefinitionError("expected a table", path=str(self.path), field=section)
        unknown = sorted(set(b) - BLADE_KEYS)
        if unknown:
            raise DefinitionError(f"unknown key {unknown[0]!r}", path=str(self.path), field=f"{section}.{unknown[0]}")
        kind = b.get("kind", "lines")
        if kind not in ("lines", "sections"):
            raise DefinitionError(f"expected \"lines\" or \"sections\", got {kind!r}", path=str(self.path),
                                  field=f"{section}.kind")
        radius_max = b.get("radius_max")
        if kind == "sections":
            lines, points = self._sections(b, section)
            return {"name": str(b.get("name", f"blade {k + 1}")), "lines": lines, "points": points,
                    "radius_max": None if radius_max is None else float(radius_max) * self.scale}
        for key in ("pressure", "suction", "shroud_point", "hub_point"):
            if key not in b:
                raise DefinitionError("missing", path=str(self.path), field=f"{section}.{key}")
        lines = {}
        for side, key in (("P", "pressure"), ("S", "suction")):
            cols = list(b["shroud_point"]) + list(b["hub_point"])
            A = _csv_columns(self.path.parent / b[key], cols, str(self.path), f"{section}.{key}") * self.scale
            lines[side] = np.stack([self._to_xyz(A[:, :3]), self._to_xyz(A[:, 3:])], axis=1)  # shroud, hub
        return {"name": str(b.get("name", f"blade {k + 1}")), "lines": lines, "points": None,
                "radius_max": None if radius_max is None else float(radius_max) * self.scale}


#: Lines made from the end sections of a blade given as sections.
SECTION_LINES = 41


def _resample(P: np.ndarray, count: int) -> np.ndarray:
    """``count`` points at equal fractions of the polyline's length."""
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))]
    t = np.linspace(0.0, s[-1], count)
    return np.stack([np.interp(t, s, P[:, i]) for i in range(P.shape[1])], axis=1)


#: Terms of the sine series of the pairing σ(s) between the end sections.
PAIRING_TERMS = 4


def _ruling_lines(secs) -> np.ndarray:
    """Straight lines (shroud point, hub point) between the first (hub-side) and last
    section: hub point at length fraction s, shroud point at σ(s) = s + Σ a_k sin(kπ s),
    the a_k chosen (Nelder–Mead) so that the lines pass as close as possible to the
    intermediate sections (a ruled surface is fixed by which points its rulings join)."""
    hub_poly, shroud_poly = secs[0], secs[-1]
    s = np.linspace(0.0, 1.0, SECTION_LINES)
    H = _resample(hub_poly, SECTION_LINES)
    middle = np.concatenate(secs[1:-1]) if len(secs) > 2 else None
    fine = _resample(shroud_poly, 1001)

    def shroud_points(a):
        sigma = s + sum(a[k] * np.sin((k + 1) * np.pi * s) for k in range(len(a)))
        sigma = np.clip(sigma, 0.0, 1.0)
        return np.stack([np.interp(sigma, np.linspace(0, 1, 1001), fine[:, i]) for i in range(3)], axis=1)

    def cost(a):
        T = shroud_points(a)
        d = T - H
        # distance of each middle point to each line segment, the nearest line taken
        w = middle[:, None, :] - H[None]
        t = np.clip(np.sum(w * d[None], axis=-1) / np.sum(d * d, axis=-1)[None], 0.0, 1.0)
        dist = np.linalg.norm(w - t[..., None] * d[None], axis=-1).min(axis=1)
        return float(np.sum(dist ** 2))

    a = np.zeros(PAIRING_TERMS)
    if middle is not None:
        a = minimize(cost, a, method="Nelder-Mead", options={"xatol": 1e-7, "fatol": 1e-16, "maxiter": 4000}).x
    return np.stack([shroud_points(a), H], axis=1)


def _split_loop(loop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A closed section loop split at its two farthest points (LE and TE) into the
    pressure side (larger mean φ) and the suction side, both running LE to TE (the LE
    being the end nearer the axis inlet, smaller axial position)."""
    L = loop[:-1] if np.allclose(loop[0], loop[-1]) else loop
    d = np.linalg.norm(L[:, None] - L[None], axis=-1)
    i, j = np.unravel_index(np.argmax(d), d.shape)
    le, te = (i, j) if L[i, 2] <= L[j, 2] else (j, i)
    n = len(L)
    forward = L[[(le + k) % n for k in range((te - le) % n + 1)]]
    backward = L[[(le - k) % n for k in range((le - te) % n + 1)]]
    phi = [np.mean(np.unwrap(np.arctan2(c[:, 1], c[:, 0]))) for c in (forward, backward)]
    return (forward, backward) if phi[0] > phi[1] else (backward, forward)


def fit_impeller(points: PointFile, tolerance: float | None = None,
                 wall_tolerance: float | None = None, general: bool = False) -> FittedImpeller:
    """Fit the channel and every blade side of ``points`` to ``tolerance`` (metres; default
    DEFAULT_TOLERANCE_FRACTION of the largest data radius) and measure each surface's
    largest distance from its points (true closest points, The NURBS Book 2e §6.1).

    The blade edges are put on the channel walls (:func:`.fitting.edges_on_walls`) within
    ``wall_tolerance`` (default WALL_TOLERANCE × the outer diameter, 2 × the largest data
    radius, as for the presets); where the data lines reach past the contour data, the
    walls' end patches are continued to hold them (:func:`.fitting.extend_channel`).

    general: a side whose best ruled surface misses its points by more than the
    tolerance is fitted again by a general B-spline surface (cubic in v, the same edges on
    the walls; :func:`.fitting.fit_general_surface`); both deviations are reported."""
    hub, shroud = points.walls["hub"], points.walls["shroud"]
    size = float(max(hub[:, 1].max(), shroud[:, 1].max()))
    tol = DEFAULT_TOLERANCE_FRACTION * size if tolerance is None else float(tolerance)
    if not tol > 0.0:
        raise DefinitionError(f"the tolerance must be > 0, got {tolerance!r}", field="tolerance")
    wall_tol = WALL_TOLERANCE * 2.0 * size if wall_tolerance is None else float(wall_tolerance)
    if not wall_tol > 0.0:
        raise DefinitionError(f"the wall tolerance must be > 0, got {wall_tolerance!r}", field="wall_tolerance")
    channel = fit_channel(hub, shroud, tolerance=tol)
    deviation = {
        "hub": float(closest_point_curve(channel.hub.to_bspline(), hub)[1].max()),
        "shroud": float(closest_point_curve(channel.shroud.to_bspline(), shroud)[1].max()),
    }
    # first pass: ruled fits to the trimmed lines, and how far along each wall they reach
    ruled, reach = {}, np.array([[0.0, channel.count], [0.0, channel.count]])
    for b in points.blades:
        for side, lines in b["lines"].items():
            trimmed, U = trim_lines_to_channel(lines, channel, parameters=True)
            s = np.linspace(0.0, 1.0, SAMPLES_PER_LINE)
            P = trimmed[:, 0, None] + s[None, :, None] * (trimmed[:, 1] - trimmed[:, 0])[:, None]
            inside = np.ones(P.shape[:2], bool) if b["radius_max"] is None else \
                np.hypot(P[..., 0], P[..., 1]) <= b["radius_max"] * (1.0 + 1e-12)
            used = inside.any(axis=1)
            if used.sum() < 4:
                raise GeometryError(f"blade {b['name']} {side}: {used.sum()} lines inside the channel; need 4")
            surface, _, knots = fit_ruled_surface(trimmed[used, 0], trimmed[used, 1], tol, knots=True)
            measured = P[used][inside[used]] if b["points"] is None else b["points"][side]
            ruled[(b["name"], side)] = (surface, knots, measured)
            reach[:, 0] = np.minimum(reach[:, 0], U[used].min(axis=0) - EXTENSION_MARGIN)
            reach[:, 1] = np.maximum(reach[:, 1], U[used].max(axis=0) + EXTENSION_MARGIN)
    extended = bool(np.any(reach[:, 0] < 0.0) or np.any(reach[:, 1] > channel.count))
    if extended:
        channel = extend_channel(channel, reach[0], reach[1])
    blades, gaps, patches, general_surfaces, ruled_deviation = {}, {}, {}, {}, {}
    for (name, side), (surface, knots, measured) in ruled.items():
        surface, gap = edges_on_walls(surface, channel, wall_tol, knots)
        _, _, dist = closest_point_surface(surface.to_bspline(), measured)
        blades.setdefault(name, {})[side] = surface
        key = f"{name} {side}"
        deviation[key] = float(dist.max())
        gaps[key] = gap
        patches[key] = surface.count
        if general and deviation[key] > tol:
            general_surfaces[key], g, gaps[key] = fit_general_surface(surface, measured, channel, wall_tol)
            ruled_deviation[key], deviation[key] = deviation[key], g
    return FittedImpeller(points.name, channel, blades, points.count, deviation, tol, gaps, wall_tol, patches,
                          extended, general_surfaces, ruled_deviation)


def fitted_surfaces(fitted: FittedImpeller, blades: int | None = None) -> list:
    """(name, BSplineSurface) of the fitted wheel as :func:`.export.impeller_surfaces`
    names them: walls as quarter surfaces of revolution, then "<blade> k S|P"."""
    from .export import channel_wall_quarters, ruled_bspline

    out = []
    for wall in ("hub", "shroud"):
        for i, s in enumerate(channel_wall_quarters(fitted.channel.wall(wall))):
            out.append((f"{wall} {i + 1}", s))
    count = fitted.count if blades is None else int(blades)
    ref = {name: {side: fitted.general.get(f"{name} {side}") or ruled_bspline(ps) for side, ps in sides.items()}
           for name, sides in fitted.blades.items()}
    from ..nurbs import BSplineSurface
    for k in range(count):
        a = 2.0 * math.pi * k / fitted.count
        R = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0], [0.0, 0.0, 1.0]])
        for name, sides in ref.items():
            for side, s in sides.items():
                out.append((f"{name} {k + 1} {side}", s if k == 0 else BSplineSurface(
                    s.degree_u, s.degree_v, s.knots_u, s.knots_v, s.control_points @ R.T, s.weights)))
    return out
