"""Standardised impellers as B-spline surfaces (Casey 1983, "Standardisation of
Impellers", items a–d and Fig. 11; Piegl & Tiller, The NURBS Book 2e).

Casey's standardisation: one master impeller (channel M', blade surfaces B, S and P) is
used in several new meridional channels M, narrower (a shroud cut or a hub cut) or wider
(the blade extrapolated linearly in v); the new flow channel is the intersection of M
with the blade surfaces, and the (u, v) net is modified so that it is confined to M.
:func:`.uses.scaled_channel` makes M from M' (new shroud = hub + f_s (shroud - hub), new
hub = shroud + f_h (hub - shroud)) and :class:`.uses.StandardisedSurface` evaluates the
trimmed surface: on the ruling at U it runs from R(U, v_hub(U)) on the new hub wall to
R(U, v_shroud(U)) on the new shroud wall.

The trimmed surface is still ruled, but its two edges are no longer polynomial in U
(v_hub and v_shroud come from intersecting each ruling's meridional trace with a wall).
Here they are approximated, for display and IGES:

- both edges with ONE common knot vector (:func:`..nurbs.fitting.approximate_common`:
  Hally 2013 §9, interpolation at the Greville abscissae, The NURBS Book 2e Alg. A9.1
  with prescribed knots), starting from INITIAL_SPANS equal spans per master patch (so
  the patch junctions, where the master strings' third derivatives jump, are knots),
  knots inserted until |C(U) - R(U, v(U))| <= tolerance in the same parameter U;
- the surface is the degree (3, 1) B-spline ruled between them (The NURBS Book 2e §8.2:
  both boundary curves on one knot vector, a control net of two rows), so its rulings are
  the master's rulings at the same U and it deviates from the exact trimmed surface by at
  most what its edges do.

The rounded LE/TE end patches are ruled as well (one cubic-linear patch each) and are
trimmed the same way; an end patch and the S or P surface it joins share their end
ruling, so the trimmed edges meet (the curves interpolate their end points).

Tolerance: a fraction (default :data:`DEFAULT_TOLERANCE`) of the impeller size, the
diagonal of the (z, r) box of the master channel's polygons. The edges' distance from the
new walls is measured in the meridional plane (foot points on the wall's Bézier string by
Newton on C'(s)·(C(s) - X) = 0, The NURBS Book 2e Eqs. 6.3–6.4) at dense samples; the exact
edges lie on the walls to round-off, so it is at most the fit deviation.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError
from ..nurbs import BSplineSurface
from ..nurbs.fitting import approximate_common
from .bezier import BezierString
from .blade import BladeSurfaces
from .channel import MeridionalChannel
from .uses import CutError, StandardisedSurface, _power, standardise

#: Edge tolerance as a fraction of the impeller size (:func:`impeller_size`).
DEFAULT_TOLERANCE = 1e-7
#: Initial knot spans per master patch (the patch junctions are knots from the start;
#: fewer only means more rounds of knot insertion, the final knots are about the same).
INITIAL_SPANS = 4
#: ... for a master of up to this many patches; an adaptive master with more patches starts
#: from its patch junctions alone (its patches are already short).
INITIAL_SPANS_PATCHES = 8
#: Samples per knot span when measuring the edges' distance from the walls.
WALL_CHECK_SAMPLES_PER_SPAN = 8
#: Foot-point Newton: iterations and step tolerance (in the wall parameter).
FOOT_MAX_ITERATIONS = 20
FOOT_TOLERANCE = 1e-14

#: The knots each trimmed surface got last time (key: name, patches, tolerance), tried
#: first on the next trim: a live edit usually moves the edges too little to need others,
#: and one fit replaces the knot-insertion rounds (see ``approximate_common(seed_knots)``).
LAST_KNOTS_SIZE = 64
_LAST_KNOTS: dict = {}

#: Blade parts in the order of :func:`.export.blade_surfaces`.
PARTS = ("S", "P", "LE", "TE")


def impeller_size(channel: MeridionalChannel) -> float:
    """Diagonal of the (z, r) box of the channel's wall polygons: the length scale of the
    standardisation tolerance."""
    P = np.concatenate([seg.control_points for wall in (channel.hub, channel.shroud) for seg in wall.segments])
    return float(np.linalg.norm(P.max(axis=0) - P.min(axis=0)))


def wall_distance(contour: BezierString, zr, s0) -> tuple[np.ndarray, np.ndarray]:
    """Distances (and foot parameters) of meridional points ``zr`` (k, 2) from the wall
    ``contour``, by Newton on f(s) = C'(s)·(C(s) - X) from ``s0`` near the foot
    (The NURBS Book 2e Eqs. 6.3–6.4; s kept on the wall, Eq. 6.5)."""
    X = np.asarray(zr, dtype=float)
    s = np.array(s0, dtype=float)
    n = contour.count
    form = _power(contour)
    for _ in range(FOOT_MAX_ITERATIONS):
        C = form.derivatives(s, 2)
        r = C[0] - X
        f = np.sum(C[1] * r, axis=1)
        fp = np.sum(C[2] * r, axis=1) + np.sum(C[1] * C[1], axis=1)
        step = f / fp
        s = np.minimum(np.maximum(s - step, 0.0), n)
        if np.max(np.abs(step), initial=0.0) < FOOT_TOLERANCE * n:
            break
    return np.linalg.norm(form.derivatives(s)[0] - X, axis=1), s


@dataclass(frozen=True, eq=False)
class TrimmedSurface:
    """One trimmed blade surface: the degree (3, 1) B-spline ``surface`` (U over the
    master's range, v = 0 on the new hub, 1 on the new shroud), the ``exact`` evaluator it
    approximates, the largest edge deviation measured by the fit (hub, shroud), the
    largest meridional distance of its edges from the new walls (hub, shroud) and the
    length of its knot vector in U."""

    name: str
    surface: BSplineSurface
    exact: StandardisedSurface
    fit_deviation: tuple
    wall_deviation: tuple
    n_knots: int


def trim_surface(surface, channel: MeridionalChannel, tolerance: float, name: str = "") -> TrimmedSurface:
    """The ruled ``surface`` (a patch string or an end patch) trimmed to ``channel`` as a
    degree (3, 1) B-spline whose edges are within ``tolerance`` (absolute) of the exact
    cut (module docstring). Raises :class:`.uses.CutError` when the rulings do not meet a
    wall, :class:`GeometryError` when the tolerance cannot be met."""
    exact = standardise(surface, channel)
    n = exact.surface.count
    report = {}
    key = (name, n, float(tolerance))
    try:
        hub, shroud = approximate_common(
            [_remembered(exact, "hub"), _remembered(exact, "shroud")],
            tolerance, degree=3, domain=(0.0, float(n)), initial_knots=np.arange(1, _spans(n) * n) / _spans(n),
            report=report, seed_knots=_LAST_KNOTS.get(key))
    except CutError as exc:
        raise CutError(f"{name}: {exc}" if name else str(exc), exc.wall, exc.U) from None
    except GeometryError as exc:
        raise GeometryError(f"{name}: {exc}" if name else str(exc)) from None
    if key not in _LAST_KNOTS and len(_LAST_KNOTS) >= LAST_KNOTS_SIZE:
        _LAST_KNOTS.pop(next(iter(_LAST_KNOTS)))
    _LAST_KNOTS[key] = hub.knots
    P = np.stack([hub.control_points, shroud.control_points], axis=1)
    trimmed = BSplineSurface(3, 1, hub.knots, np.array([0.0, 0.0, 1.0, 1.0]), P)
    return TrimmedSurface(name, trimmed, exact, tuple(report["max_deviation"]),
                          edge_wall_deviation(trimmed, exact), len(hub.knots))


def _spans(n: int) -> int:
    return max(1, (INITIAL_SPANS * INITIAL_SPANS_PATCHES) // max(n, INITIAL_SPANS_PATCHES) if n > INITIAL_SPANS_PATCHES
               else INITIAL_SPANS)


def _remembered(exact: StandardisedSurface, which: str):
    """The edge function of one wall, remembering its last few results: the common-knot
    refit samples a curve on a knot vector it has usually just been sampled on."""
    memory = {}

    def edge(U):
        key = np.asarray(U, dtype=float).tobytes()
        found = memory.get(key)
        if found is None:
            found = exact.edge(U, which)
            if len(memory) >= 8:
                memory.pop(next(iter(memory)))
            memory[key] = found
        return found

    return edge


def edge_wall_deviation(surface: BSplineSurface, exact: StandardisedSurface,
                        samples_per_span: int = WALL_CHECK_SAMPLES_PER_SPAN) -> tuple[float, float]:
    """Largest meridional distance of the hub (v = 0) and shroud (v = 1) edges of
    ``surface`` from the walls of ``exact.channel``, at ``samples_per_span`` + 1 points
    per knot span of U (foot points from the exact cut's table, then :func:`wall_distance`)."""
    breaks = np.unique(surface.knots_u)
    t = np.linspace(0.0, 1.0, samples_per_span + 1)
    U = np.unique((breaks[:-1, None] + np.diff(breaks)[:, None] * t[None, :]).ravel())
    out = []
    for v, which in ((0.0, "hub"), (1.0, "shroud")):
        X = surface.evaluate(U, np.full_like(U, v))
        zr = np.stack([X[:, 2], np.hypot(X[:, 0], X[:, 1])], axis=1)
        table = exact._tables[which]
        dist, _ = wall_distance(exact.channel.wall(which), zr, table.start(U)[1])
        out.append(float(dist.max()))
    return tuple(out)


class Standardisation:
    """The trimmed blades of a standardised impeller (Casey 1983, Fig. 11).

    ``master_channel`` is M', ``channel`` the new M; ``blades`` maps "blade" (and
    "splitter") to the master :class:`.blade.BladeSurfaces`. S, P and the end patches are
    trimmed on construction (so an impossible cut is refused at once); the camber surface
    B on first request (:meth:`surfaces` with ``include_camber``)."""

    def __init__(self, master_channel: MeridionalChannel, channel: MeridionalChannel, shroud_factor: float,
                 hub_factor: float, blades: dict, tolerance: float | None = None):
        self.master_channel = master_channel
        self.channel = channel
        self.shroud_factor = float(shroud_factor)
        self.hub_factor = float(hub_factor)
        self.size = impeller_size(master_channel)
        self.relative_tolerance = DEFAULT_TOLERANCE if tolerance is None else float(tolerance)
        self.tolerance = self.relative_tolerance * self.size
        self.blades = dict(blades)
        self.parts: dict[str, dict[str, TrimmedSurface]] = {}
        for label, blade in self.blades.items():
            self.parts[label] = {}
            for part in PARTS:
                master = _master_part(blade, part)
                if master is not None:
                    self.parts[label][part] = trim_surface(master, channel, self.tolerance, f"{label} {part}")

    def trimmed(self, label: str, part: str) -> TrimmedSurface:
        """One trimmed surface ("blade"/"splitter", "S"/"P"/"LE"/"TE"/"B")."""
        found = self.parts[label].get(part)
        if found is None and part == "B":
            found = trim_surface(self.blades[label].camber, self.channel, self.tolerance, f"{label} B")
            self.parts[label]["B"] = found
        if found is None:
            raise GeometryError(f"the {label} has no part {part!r}")
        return found

    def surfaces(self, label: str, include_camber: bool = False) -> list[tuple[str, BSplineSurface]]:
        """(part, surface) pairs of one blade in the order of :func:`.export.blade_surfaces`."""
        out = [(part, t.surface) for part, t in self.parts[label].items() if part in PARTS]
        if include_camber:
            out.append(("B", self.trimmed(label, "B").surface))
        return out

    def all_trimmed(self) -> list[TrimmedSurface]:
        return [t for parts in self.parts.values() for t in parts.values()]

    @property
    def max_wall_deviation(self) -> float:
        """Largest measured distance of any trimmed edge from its new wall (metres)."""
        return max(max(t.wall_deviation) for t in self.all_trimmed())

    @property
    def max_fit_deviation(self) -> float:
        return max(max(t.fit_deviation) for t in self.all_trimmed())

    def knot_counts(self) -> dict[str, int]:
        return {t.name: t.n_knots for t in self.all_trimmed()}

    def summary(self) -> str:
        """One line for the Blender report and panel."""
        knots = self.knot_counts()
        factors = f"shroud factor {self.shroud_factor:g}"
        if self.hub_factor != 1.0:
            factors += f", hub factor {self.hub_factor:g}"
        return (f"standardised ({factors}): edges within {self.max_wall_deviation:.2g} m of the new walls "
                f"(tolerance {self.tolerance:.2g} m), {min(knots.values())}–{max(knots.values())} knots per surface")


def _master_part(blade: BladeSurfaces, part: str):
    return {"S": blade.suction, "P": blade.pressure, "LE": blade.leading_edge, "TE": blade.trailing_edge,
            "B": blade.camber}[part]
