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

from ..errors import DefinitionError, GeometryError
from ..nurbs import closest_point_curve, closest_point_surface
from .bezier import PatchString
from .channel import MeridionalChannel
from .fitting import fit_channel, fit_ruled_surface, trim_lines_to_channel

UNITS = {"m": 1.0, "mm": 1e-3}
#: Default fit tolerance as a fraction of the largest radius of the data.
DEFAULT_TOLERANCE_FRACTION = 5e-5
#: Samples per generating line when the blade deviation is measured.
SAMPLES_PER_LINE = 21
KEYS = {"name", "units", "coordinates", "axis", "blades", "hub", "shroud", "blade"}


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

    @property
    def met(self) -> bool:
        """Whether every surface lies within the tolerance of its points."""
        return all(v <= self.tolerance for v in self.deviation.values())

    def summary(self) -> str:
        parts = [f"{k} {v * 1e3:.4f} mm" for k, v in self.deviation.items()]
        head = "" if self.met else "tolerance NOT met: "
        return f"{head}{self.name}: fitted to {self.tolerance * 1e3:.4g} mm; deviation " + ", ".join(parts)


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

    def _blade(self, b, k):
        section = f"blade[{k}]"
        if not isinstance(b, dict):
            raise DefinitionError("expected a table", path=str(self.path), field=section)
        for key in ("pressure", "suction", "shroud_point", "hub_point"):
            if key not in b:
                raise DefinitionError("missing", path=str(self.path), field=f"{section}.{key}")
        lines = {}
        for side, key in (("P", "pressure"), ("S", "suction")):
            cols = list(b["shroud_point"]) + list(b["hub_point"])
            A = _csv_columns(self.path.parent / b[key], cols, str(self.path), f"{section}.{key}") * self.scale
            lines[side] = np.stack([self._to_xyz(A[:, :3]), self._to_xyz(A[:, 3:])], axis=1)  # shroud, hub
        radius_max = b.get("radius_max")
        return {"name": str(b.get("name", f"blade {k + 1}")), "lines": lines,
                "radius_max": None if radius_max is None else float(radius_max) * self.scale}


def fit_impeller(points: PointFile, tolerance: float | None = None) -> FittedImpeller:
    """Fit the channel and every blade side of ``points`` to ``tolerance`` (metres; default
    DEFAULT_TOLERANCE_FRACTION of the largest data radius) and measure each surface's
    largest distance from its points (true closest points, The NURBS Book 2e §6.1)."""
    hub, shroud = points.walls["hub"], points.walls["shroud"]
    size = float(max(hub[:, 1].max(), shroud[:, 1].max()))
    tol = DEFAULT_TOLERANCE_FRACTION * size if tolerance is None else float(tolerance)
    if not tol > 0.0:
        raise DefinitionError(f"the tolerance must be > 0, got {tolerance!r}", field="tolerance")
    channel = fit_channel(hub, shroud, tolerance=tol)
    deviation = {
        "hub": float(closest_point_curve(channel.hub.to_bspline(), hub)[1].max()),
        "shroud": float(closest_point_curve(channel.shroud.to_bspline(), shroud)[1].max()),
    }
    blades = {}
    for b in points.blades:
        sides = {}
        for side, lines in b["lines"].items():
            trimmed = trim_lines_to_channel(lines, channel)
            s = np.linspace(0.0, 1.0, SAMPLES_PER_LINE)
            P = trimmed[:, 0, None] + s[None, :, None] * (trimmed[:, 1] - trimmed[:, 0])[:, None]
            inside = np.ones(P.shape[:2], bool) if b["radius_max"] is None else \
                np.hypot(P[..., 0], P[..., 1]) <= b["radius_max"] * (1.0 + 1e-12)
            used = inside.any(axis=1)
            if used.sum() < 4:
                raise GeometryError(f"blade {b['name']} {side}: {used.sum()} lines inside the channel; need 4")
            surface, _ = fit_ruled_surface(trimmed[used, 0], trimmed[used, 1], tol)
            _, _, dist = closest_point_surface(surface.to_bspline(), P[used][inside[used]])
            sides[side] = surface
            deviation[f"{b['name']} {side}"] = float(dist.max())
        blades[b["name"]] = sides
    return FittedImpeller(points.name, channel, blades, points.count, deviation, tol)


def fitted_surfaces(fitted: FittedImpeller, blades: int | None = None) -> list:
    """(name, BSplineSurface) of the fitted wheel as :func:`.export.impeller_surfaces`
    names them: walls as quarter surfaces of revolution, then "<blade> k S|P"."""
    from .export import channel_wall_quarters, ruled_bspline

    out = []
    for wall in ("hub", "shroud"):
        for i, s in enumerate(channel_wall_quarters(fitted.channel.wall(wall))):
            out.append((f"{wall} {i + 1}", s))
    count = fitted.count if blades is None else int(blades)
    ref = {name: {side: ruled_bspline(ps) for side, ps in sides.items()} for name, sides in fitted.blades.items()}
    from ..nurbs import BSplineSurface
    for k in range(count):
        a = 2.0 * math.pi * k / fitted.count
        R = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0], [0.0, 0.0, 1.0]])
        for name, sides in ref.items():
            for side, s in sides.items():
                out.append((f"{name} {k + 1} {side}", s if k == 0 else BSplineSurface(
                    s.degree_u, s.degree_v, s.knots_u, s.knots_v, s.control_points @ R.T, s.weights)))
    return out
