"""Impeller definition files (TOML) and the impeller model built from them.

Format (lengths in metres, angles in degrees; see README "Impeller definition")::

    name = "Intermediate flow coefficient impeller"

    [channel]                      # Casey (1983) Fig. 5 skeletal data, inlet to outlet
    degrees = [1, 4, 4, 1]         # per patch: 1 straight wall, 4 bend (see channel.py)
    hub_z = [...]                  # patch-corner axial positions, n+1 values
    hub_r = [...]                  # patch-corner radii
    hub_angle = ["auto", ...]      # wall direction at each corner, deg from +z towards +r;
                                   # "auto" next to a straight patch takes its direction
    hub_fractions = [[fa, fb], ...]  # per patch, placing P_1 and P_3 of a bend
    shroud_z = [...]; shroud_r = [...]; shroud_angle = [...]; shroud_fractions = [...]

    [blade]
    count = 15                     # Z
    leading_edge_hub = 1.0         # channel parameter U of the four blade corners
    leading_edge_shroud = 1.0      # (Casey 1983 step b); U in [0, patches of the channel]
    trailing_edge_hub = 3.0
    trailing_edge_shroud = 3.0
    beta_hub = [b0, ..., bk]       # Bernstein coefficients of β(m̄) (deg), m̄ in [0, 1]:
    beta_shroud = [...]            # the first and last are the LE and TE angles
    thickness_hub = [...]          # Bernstein coefficients of δ(m̄) (m), all >= 0
    thickness_shroud = [...]
    patches = 6                    # cubic-linear patches per surface
    lean_hub = 0.0                 # φ of the camber LE on hub and shroud (deg)
    lean_shroud = 0.0
    elements = "arbitrary"         # or "axial" (Casey's axial-element blades)
    leading_edge_ratio = 3.0       # rounded LE: ellipse semi-axes ratio; 0 = cut off (flat closing face)
    trailing_edge_ratio = 0.0
    tolerance = 1e-6               # camber/thickness tolerance, fraction of the outer diameter;
                                   # the patch count is raised from `patches` to meet it (0: fixed)
    patch_spacing = "meridional"   # or "blade": corners equidistant along the blade (Casey step e)

    [splitter]                     # optional: a shortened copy of the main camber line
    leading_edge_hub = 1.6
    leading_edge_shroud = 1.5
    thickness_hub = [...]
    thickness_shroud = [...]
    pitch_fraction = 0.5           # φ offset in blade pitches 2π/Z
    patches = 4

    [standardisation]              # optional (Casey 1983, Fig. 11): trim to a new channel
    shroud_factor = 0.8            # new shroud = hub + 0.8 (shroud - hub): a 20 % shroud cut
    hub_factor = 1.0               # new hub = shroud + f (hub - shroud): < 1 a hub cut

See :class:`StandardisationDefinition` for why the factors have a table of their own.

Keys are checked against ``TOP_KEYS``, ``CHANNEL_KEYS``, ``BLADE_KEYS``, ``SPLITTER_KEYS``
and ``STANDARDISATION_KEYS`` (the one place to add a key); an unknown key is refused with
the nearest valid name. Counts and sizes are bounded by the ``MAX_*`` constants below
(README "Limits of definitions"), named in the refusal.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import DefinitionError, GeometryError
from ..validation import MAX_LENGTH, MIN_LENGTH, check_count, check_keys, number, number_list, read_toml, string, table
from .blade import (DEFAULT_TOLERANCE, MAX_BETA_DEG, PATCH_SPACINGS, WALL_TOLERANCE, BladeSurfaces, WallBlade,
                    WallCamber, blade_step, blade_strings, build_blade, outer_diameter)
from .memo import MEMORY
from .channel import MeridionalChannel, WallSkeleton, channel_from_skeleton
from .standardisation import Standardisation
from .uses import CutError, scaled_channel

WALLS = ("hub", "shroud")

#: The keys of each table (the one place to add a key).
TOP_KEYS = ("name", "channel", "blade", "splitter", "standardisation")
CHANNEL_KEYS = ("degrees", "hub_z", "hub_r", "hub_angle", "hub_fractions", "shroud_z", "shroud_r", "shroud_angle",
                "shroud_fractions")
BLADE_KEYS = ("count", "leading_edge_hub", "leading_edge_shroud", "trailing_edge_hub", "trailing_edge_shroud",
              "beta_hub", "beta_shroud", "thickness_hub", "thickness_shroud", "patches", "lean_hub", "lean_shroud",
              "elements", "leading_edge_ratio", "trailing_edge_ratio", "tolerance", "patch_spacing")
SPLITTER_KEYS = ("leading_edge_hub", "leading_edge_shroud", "thickness_hub", "thickness_shroud", "pitch_fraction",
                 "patches", "leading_edge_ratio")

# Upper bounds (README "Limits of definitions"); each is named in its refusal.
#: Blades Z (main blades; splitters double the count): real impellers have 7-30.
MAX_BLADES = 64
#: Patches of the meridional channel (Casey's skeleton has 3-6).
MAX_CHANNEL_PATCHES = 20
#: Cubic-linear patches per blade surface (Casey uses 4-8; the adaptive count that holds
#: the wall and camber tolerances reaches 65-74 on the shipped presets).
MAX_BLADE_PATCHES = 200
#: Bernstein coefficients of β(m̄) and δ(m̄) per wall (degree + 1; Casey uses 3-6).
MAX_COEFFICIENTS = 30
#: |wall angle| and |lean| (degrees).
MAX_ANGLE_DEG = 180.0
#: The fractions placing P_1 and P_3 of a bend lie in [MIN_FRACTION, 1 - MIN_FRACTION]:
#: nearer the ends, a leg of the bend's polygon degenerates (a zero end tangent).
MIN_FRACTION = 0.05
#: Rounded-edge ellipse semi-axes ratio.
MAX_EDGE_RATIO = 20.0


def _floats(data: dict, key: str, section: str, path, length: int | None = None, *, maximum: int = MAX_COEFFICIENTS,
            bound_name: str = "MAX_COEFFICIENTS", lo=-MAX_LENGTH, hi=MAX_LENGTH) -> tuple:
    name = f"{section}.{key}"
    if key not in data:
        raise DefinitionError("missing", path=path, field=name)
    value = data[key]
    out = number_list(value, path, name, maximum=maximum, bound_name=bound_name, lo=lo, hi=hi)
    if length is not None and len(out) != length:
        raise DefinitionError(f"expected {length} values, got {len(out)}", path=path, field=name)
    return out


def _number(data: dict, key: str, section: str, path, default=None, lo=None, hi=None) -> float:
    name = f"{section}.{key}"
    if key not in data:
        if default is None:
            raise DefinitionError("missing", path=path, field=name)
        return float(default)
    return number(data[key], path, name, lo=lo, hi=hi)


@dataclass(frozen=True)
class ChannelDefinition:
    degrees: tuple
    hub_z: tuple
    hub_r: tuple
    hub_angle: tuple  # NaN = "auto"
    hub_fractions: tuple
    shroud_z: tuple
    shroud_r: tuple
    shroud_angle: tuple
    shroud_fractions: tuple

    @classmethod
    def from_dict(cls, data: dict, path=None) -> "ChannelDefinition":
        check_keys(table(data, path, "channel"), CHANNEL_KEYS, path, "channel")
        if "degrees" not in data:
            raise DefinitionError("missing", path=path, field="channel.degrees")
        raw_degrees = data["degrees"]
        if not isinstance(raw_degrees, list) or not raw_degrees:
            raise DefinitionError(f"expected a list of patch degrees (1 or 4), got {raw_degrees!r}", path=path,
                                  field="channel.degrees")
        check_count(len(raw_degrees), MAX_CHANNEL_PATCHES, "MAX_CHANNEL_PATCHES", path, "channel.degrees", "patches")
        degrees = []
        for j, d in enumerate(raw_degrees):
            d = number(d, path, "channel.degrees", integer=True, entry=f"patch {j}: ")
            if d not in (1, 4):
                raise DefinitionError(f"patch {j}: degree must be 1 (straight) or 4 (bend), got {d}", path=path,
                                      field="channel.degrees")
            degrees.append(d)
        degrees = tuple(degrees)
        n = len(degrees)
        values = {"degrees": degrees}
        for w in WALLS:
            values[f"{w}_z"] = _floats(data, f"{w}_z", "channel", path, n + 1, maximum=MAX_CHANNEL_PATCHES + 1,
                                       bound_name="MAX_CHANNEL_PATCHES + 1")
            values[f"{w}_r"] = _floats(data, f"{w}_r", "channel", path, n + 1, maximum=MAX_CHANNEL_PATCHES + 1,
                                       bound_name="MAX_CHANNEL_PATCHES + 1", lo=0.0)
            raw = data.get(f"{w}_angle", ["auto"] * (n + 1))
            if not isinstance(raw, list) or len(raw) != n + 1:
                raise DefinitionError(f"expected a list of {n + 1} angles or \"auto\", got {raw!r}", path=path,
                                      field=f"channel.{w}_angle")
            angles = []
            for i, a in enumerate(raw):
                if a == "auto":
                    angles.append(math.nan)
                elif isinstance(a, (int, float)) and not isinstance(a, bool):
                    angles.append(number(a, path, f"channel.{w}_angle", lo=-MAX_ANGLE_DEG, hi=MAX_ANGLE_DEG,
                                         entry=f"corner {i}: "))
                else:
                    raise DefinitionError(f"corner {i}: expected a number or \"auto\", got {a!r}", path=path,
                                          field=f"channel.{w}_angle")
            values[f"{w}_angle"] = tuple(angles)
            fr = data.get(f"{w}_fractions", [[0.5, 0.5]] * n)
            if not isinstance(fr, list) or len(fr) != n or not all(isinstance(q, list) and len(q) == 2 for q in fr):
                raise DefinitionError(f"expected {n} pairs [fa, fb], got {fr!r}", path=path,
                                      field=f"channel.{w}_fractions")
            fr = np.array([[number(v, path, f"channel.{w}_fractions", lo=MIN_FRACTION, hi=1.0 - MIN_FRACTION,
                                   entry=f"pair {j}: ") for v in q] for j, q in enumerate(fr)], dtype=float).reshape(n, 2)
            if fr.shape != (n, 2):
                raise DefinitionError(f"expected {n} pairs, got shape {fr.shape}", path=path, field=f"channel.{w}_fractions")
            values[f"{w}_fractions"] = tuple(map(tuple, fr.tolist()))
        size = max(np.ptp(values[f"{w}_{c}"] + values[f"{v}_{c}"]) for w in WALLS for v in WALLS for c in "zr")
        if size < MIN_LENGTH:
            raise DefinitionError(f"the channel spans {size!r} m, less than MIN_LENGTH = {MIN_LENGTH:g} m (the "
                                  "float32 display would lose it)", path=path, field="channel.hub_z")
        return cls(**values)

    def to_dict(self) -> dict:
        out = {"degrees": list(self.degrees)}
        for w in WALLS:
            out[f"{w}_z"] = list(getattr(self, f"{w}_z"))
            out[f"{w}_r"] = list(getattr(self, f"{w}_r"))
            out[f"{w}_angle"] = ["auto" if math.isnan(a) else a for a in getattr(self, f"{w}_angle")]
            out[f"{w}_fractions"] = [list(p) for p in getattr(self, f"{w}_fractions")]
        return out

    def build(self, path=None) -> MeridionalChannel:
        walls = {}
        for w in WALLS:
            walls[w] = WallSkeleton(
                np.column_stack([getattr(self, f"{w}_z"), getattr(self, f"{w}_r")]),
                np.array(getattr(self, f"{w}_angle"), dtype=float),
                np.array(getattr(self, f"{w}_fractions"), dtype=float),
            )
        return channel_from_skeleton(self.degrees, walls["hub"], walls["shroud"], path)


BLADE_SCALARS = {
    "leading_edge_hub": None, "leading_edge_shroud": None, "trailing_edge_hub": None, "trailing_edge_shroud": None,
    "lean_hub": 0.0, "lean_shroud": 0.0, "leading_edge_ratio": 3.0, "trailing_edge_ratio": 0.0,
    "tolerance": DEFAULT_TOLERANCE,
}
#: [blade] keys added by issue 18 (adaptive patch count, Casey's two patch spacings):
#: "tolerance" (in BLADE_SCALARS, a fraction of the outer diameter, >= 0) and
#: "patch_spacing" (one of PATCH_SPACINGS).
BLADE_CHOICES = {"elements": ("arbitrary", "axial"), "patch_spacing": PATCH_SPACINGS}


@dataclass(frozen=True)
class BladeDefinition:
    count: int
    leading_edge_hub: float
    leading_edge_shroud: float
    trailing_edge_hub: float
    trailing_edge_shroud: float
    beta_hub: tuple
    beta_shroud: tuple
    thickness_hub: tuple
    thickness_shroud: tuple
    patches: int = 6
    lean_hub: float = 0.0
    lean_shroud: float = 0.0
    elements: str = "arbitrary"
    leading_edge_ratio: float = 3.0
    trailing_edge_ratio: float = 0.0
    tolerance: float = DEFAULT_TOLERANCE
    patch_spacing: str = "meridional"

    @classmethod
    def from_dict(cls, data: dict, path=None) -> "BladeDefinition":
        s = "blade"
        check_keys(table(data, path, "blade"), BLADE_KEYS, path, "blade")
        count = data.get("count")
        if isinstance(count, bool) or not isinstance(count, int) or count < 1:
            raise DefinitionError(f"expected a positive integer, got {count!r}", path=path, field="blade.count")
        check_count(count, MAX_BLADES, "MAX_BLADES", path, "blade.count", "blades")
        patches = data.get("patches", 6)
        if isinstance(patches, bool) or not isinstance(patches, int) or patches < 1:
            raise DefinitionError(f"expected a positive integer, got {patches!r}", path=path, field="blade.patches")
        check_count(patches, MAX_BLADE_PATCHES, "MAX_BLADE_PATCHES", path, "blade.patches", "patches")
        choices = {}
        for key, allowed in BLADE_CHOICES.items():
            choices[key] = data.get(key, allowed[0])
            if choices[key] not in allowed:
                raise DefinitionError(f"expected one of {', '.join(map(repr, allowed))}, got {choices[key]!r}",
                                      path=path, field=f"blade.{key}")
        values = {k: _number(data, k, s, path, d) for k, d in BLADE_SCALARS.items()}
        if values["tolerance"] < 0.0:
            raise DefinitionError(f"expected a number >= 0, got {values['tolerance']!r}", path=path, field="blade.tolerance")
        for w in WALLS:
            values[f"lean_{w}"] = _number(data, f"lean_{w}", s, path, 0.0, -MAX_ANGLE_DEG, MAX_ANGLE_DEG)
            values[f"beta_{w}"] = _floats(data, f"beta_{w}", s, path, lo=-MAX_BETA_DEG, hi=MAX_BETA_DEG)
            if len(values[f"beta_{w}"]) < 2:
                raise DefinitionError("expected at least 2 coefficients (the leading- and trailing-edge angles)",
                                      path=path, field=f"blade.beta_{w}")
            values[f"thickness_{w}"] = _floats(data, f"thickness_{w}", s, path, lo=0.0)
        for key in ("leading_edge_ratio", "trailing_edge_ratio"):
            values[key] = _number(data, key, s, path, BLADE_SCALARS[key], 0.0, MAX_EDGE_RATIO)
        return cls(count=count, patches=patches, **choices, **values)

    def to_dict(self) -> dict:
        out = {}
        for k, v in self.__dict__.items():
            out[k] = list(v) if isinstance(v, tuple) else v
        return out


@dataclass(frozen=True)
class SplitterDefinition:
    leading_edge_hub: float
    leading_edge_shroud: float
    thickness_hub: tuple
    thickness_shroud: tuple
    pitch_fraction: float = 0.5
    patches: int = 4
    leading_edge_ratio: float = 3.0

    @classmethod
    def from_dict(cls, data: dict, path=None) -> "SplitterDefinition":
        s = "splitter"
        check_keys(table(data, path, "splitter"), SPLITTER_KEYS, path, "splitter")
        patches = data.get("patches", 4)
        if isinstance(patches, bool) or not isinstance(patches, int) or patches < 1:
            raise DefinitionError(f"expected a positive integer, got {patches!r}", path=path, field="splitter.patches")
        check_count(patches, MAX_BLADE_PATCHES, "MAX_BLADE_PATCHES", path, "splitter.patches", "patches")
        return cls(
            leading_edge_hub=_number(data, "leading_edge_hub", s, path),
            leading_edge_shroud=_number(data, "leading_edge_shroud", s, path),
            thickness_hub=_floats(data, "thickness_hub", s, path, lo=0.0),
            thickness_shroud=_floats(data, "thickness_shroud", s, path, lo=0.0),
            pitch_fraction=_number(data, "pitch_fraction", s, path, 0.5, 0.0, 1.0),
            patches=patches,
            leading_edge_ratio=_number(data, "leading_edge_ratio", s, path, 3.0, 0.0, MAX_EDGE_RATIO),
        )

    def to_dict(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.__dict__.items()}


#: Each standardisation factor must lie in (FACTOR_MIN, FACTOR_MAX].
FACTOR_MIN = 0.3
FACTOR_MAX = 1.5
#: The new channel keeps at least this fraction of the master's width:
#: shroud_factor + hub_factor - 1 >= MIN_WIDTH_FRACTION.
MIN_WIDTH_FRACTION = 0.3
STANDARDISATION_KEYS = ("shroud_factor", "hub_factor")


@dataclass(frozen=True)
class StandardisationDefinition:
    """Casey's (1983) standardisation, items a–d and Fig. 11: the master impeller (the
    [channel] and [blade] tables, Casey's M') is trimmed to a new meridional channel M
    made by :func:`.uses.scaled_channel`, new shroud = hub + shroud_factor (shroud - hub)
    and new hub = shroud + hub_factor (hub - shroud), both along the master channel's
    straight v lines; the blade surfaces are cut by the new walls along their rulings
    (extrapolated linearly in v where M is wider).

    The factors have a table of their own rather than living in [channel] because they do
    not describe a channel: [channel] stays the master's skeletal data, which the panel
    edits and from which the blades are built, and the standardisation is an operation
    applied afterwards to the finished master impeller (Casey uses one master blade for a
    family of channels). Removing the table restores the master exactly, and the same
    master data serve every member of the family.

    Both default to 1 (no cut); each must lie in (FACTOR_MIN, FACTOR_MAX] and together they
    must leave MIN_WIDTH_FRACTION of the master channel's width."""

    shroud_factor: float = 1.0
    hub_factor: float = 1.0

    @classmethod
    def from_dict(cls, data, path=None) -> "StandardisationDefinition":
        if not isinstance(data, dict):
            raise DefinitionError(f"expected a table, got {data!r}", path=path, field="standardisation")
        unknown = sorted(set(data) - set(STANDARDISATION_KEYS))
        if unknown:
            raise DefinitionError(f"unknown key {unknown[0]!r}; expected {', '.join(STANDARDISATION_KEYS)}",
                                  path=path, field=f"standardisation.{unknown[0]}")
        values = {k: _number(data, k, "standardisation", path, 1.0) for k in STANDARDISATION_KEYS}
        out = cls(**values)
        out.check(path)
        return out

    def check(self, path=None) -> None:
        for key in STANDARDISATION_KEYS:
            value = getattr(self, key)
            if not (math.isfinite(value) and FACTOR_MIN < value <= FACTOR_MAX):
                raise DefinitionError(f"must lie in ({FACTOR_MIN}, {FACTOR_MAX}], got {value!r}",
                                      path=path, field=f"standardisation.{key}")
        width = self.shroud_factor + self.hub_factor - 1.0
        if width < MIN_WIDTH_FRACTION:
            key = "hub_factor" if self.hub_factor != 1.0 else "shroud_factor"
            raise DefinitionError(
                f"shroud_factor {self.shroud_factor!r} and hub_factor {self.hub_factor!r} leave {width:.3g} of the "
                f"channel width; at least {MIN_WIDTH_FRACTION} is needed", path=path, field=f"standardisation.{key}")

    @property
    def is_identity(self) -> bool:
        return self.shroud_factor == 1.0 and self.hub_factor == 1.0

    def to_dict(self) -> dict:
        """The table, keys at 1.0 omitted (empty for no standardisation)."""
        return {k: getattr(self, k) for k in STANDARDISATION_KEYS if getattr(self, k) != 1.0}


@dataclass(frozen=True, eq=False)
class ImpellerModel:
    """The float64 model: channel M, the reference blade (B, S, P at φ as defined), the
    splitter (or None) and the blade count Z. Blade k is the reference turned by 2πk/Z.

    Standardised (Casey 1983, Fig. 11): ``channel`` is the new channel M, ``blade`` and
    ``splitter`` stay the master's surfaces (built in the master channel,
    ``standardisation.master_channel``), and ``standardisation`` holds their trimmed
    B-spline surfaces (:class:`.standardisation.Standardisation`), which
    :func:`.export.impeller_surfaces` shows and exports. None when not standardised."""

    name: str
    channel: MeridionalChannel
    blade: BladeSurfaces
    splitter: BladeSurfaces | None
    count: int
    standardisation: Standardisation | None = None

    def blade_angle(self, k: int) -> float:
        return 2.0 * math.pi * k / self.count

    @property
    def master_channel(self) -> MeridionalChannel:
        """The channel the blades were designed in (M'; ``channel`` when not standardised)."""
        return self.channel if self.standardisation is None else self.standardisation.master_channel


@dataclass(frozen=True)
class ImpellerDefinition:
    name: str
    channel: ChannelDefinition
    blade: BladeDefinition
    splitter: SplitterDefinition | None = None
    path: str | None = field(default=None, compare=False)
    standardisation: StandardisationDefinition | None = None  # None: the master itself
    #: Take pieces built before from the same values from :data:`.memo.MEMORY` (False: build all).
    memoise: bool = field(default=True, compare=False)

    @classmethod
    def from_dict(cls, data: dict, path=None) -> "ImpellerDefinition":
        path = None if path is None else str(path)
        table(data, path, "definition")
        check_keys(data, TOP_KEYS, path)
        if not isinstance(data.get("channel"), dict):
            raise DefinitionError("missing [channel] table", path=path, field="channel")
        if not isinstance(data.get("blade"), dict):
            raise DefinitionError("missing [blade] table", path=path, field="blade")
        splitter = data.get("splitter")
        standardisation = None
        if "standardisation" in data:
            standardisation = StandardisationDefinition.from_dict(data["standardisation"], path)
            if standardisation.is_identity:
                standardisation = None
        return cls(
            name=string(data.get("name", "Impeller"), path, "name"),
            channel=ChannelDefinition.from_dict(data["channel"], path),
            blade=BladeDefinition.from_dict(data["blade"], path),
            splitter=None if splitter is None else SplitterDefinition.from_dict(splitter, path),
            path=path,
            standardisation=standardisation,
        )

    @classmethod
    def from_toml(cls, path) -> "ImpellerDefinition":
        return cls.from_dict(read_toml(path), path)

    def to_dict(self) -> dict:
        out = {"name": self.name, "channel": self.channel.to_dict(), "blade": self.blade.to_dict()}
        if self.splitter is not None:
            out["splitter"] = self.splitter.to_dict()
        if self.standardisation is not None and not self.standardisation.is_identity:
            out["standardisation"] = self.standardisation.to_dict()
        return out

    def with_values(self, **changes) -> "ImpellerDefinition":
        return replace(self, **changes)

    # -- validation and building ---------------------------------------------------------
    def _check_blade(self, n: int) -> None:
        b, p = self.blade, self.path
        for w in WALLS:
            le, te = getattr(b, f"leading_edge_{w}"), getattr(b, f"trailing_edge_{w}")
            for key, val in ((f"leading_edge_{w}", le), (f"trailing_edge_{w}", te)):
                if not 0.0 <= val <= n:
                    raise DefinitionError(f"U = {val} lies outside the channel [0, {n}]", path=p, field=f"blade.{key}")
            if le >= te:
                raise DefinitionError(
                    f"the leading edge (U = {le}) must lie before the trailing edge (U = {te})",
                    path=p, field=f"blade.leading_edge_{w}",
                )
            th = np.asarray(getattr(b, f"thickness_{w}"))
            if np.any(th < 0.0):
                raise DefinitionError(f"thickness must be >= 0, got {th.min()}", path=p, field=f"blade.thickness_{w}")
            beta = np.asarray(getattr(b, f"beta_{w}"))
            if np.any(np.abs(beta) >= MAX_BETA_DEG):
                raise DefinitionError(f"|β| must stay below {MAX_BETA_DEG} deg", path=p, field=f"blade.beta_{w}")
        if b.leading_edge_ratio < 0 or b.trailing_edge_ratio < 0:
            raise DefinitionError("edge ratios must be >= 0", path=p, field="blade.leading_edge_ratio")
        s = self.splitter
        if s is not None:
            for w in WALLS:
                le = getattr(s, f"leading_edge_{w}")
                if not getattr(b, f"leading_edge_{w}") < le < getattr(b, f"trailing_edge_{w}"):
                    raise DefinitionError(
                        "the splitter leading edge must lie between the main blade's leading and trailing edges",
                        path=p, field=f"splitter.leading_edge_{w}",
                    )
                th = np.asarray(getattr(s, f"thickness_{w}"))
                if np.any(th < 0.0):
                    raise DefinitionError(f"thickness must be >= 0, got {th.min()}", path=p, field=f"splitter.thickness_{w}")

    def build(self) -> ImpellerModel:
        """Validate and build the float64 model (channel, blade, splitter); a refusal names
        the definition's file."""
        try:
            return self._build()
        except DefinitionError as exc:
            if exc.path or not self.path:
                raise
            raise exc.with_path(self.path) from None

    def _build(self) -> ImpellerModel:
        """The model, its pieces taken from :data:`.memo.MEMORY` when built before from the
        same values (a panel edit rebuilds only what it changes)."""
        memory = MEMORY if self.memoise else None

        def kept(key, build):
            return build() if memory is None else memory.get(key, build)

        channel_key = repr(self.channel.to_dict())
        channel = kept(("channel", channel_key), lambda: self.channel.build(self.path))
        self._check_blade(channel.count)
        b = self.blade
        camber_keys = {
            w: (channel_key, w, getattr(b, f"leading_edge_{w}"), getattr(b, f"trailing_edge_{w}"),
                tuple(getattr(b, f"beta_{w}")), getattr(b, f"lean_{w}"))
            for w in WALLS
        }
        cambers = {
            w: kept(("camber",) + camber_keys[w], lambda w=w: WallCamber(
                channel.wall(w), getattr(b, f"leading_edge_{w}"), getattr(b, f"trailing_edge_{w}"),
                getattr(b, f"beta_{w}"), math.radians(getattr(b, f"lean_{w}"))))
            for w in WALLS
        }
        axial = b.elements == "axial"
        walls = {
            w: WallBlade(cambers[w], cambers[w].U0, cambers[w].U1, np.asarray(getattr(b, f"thickness_{w}")))
            for w in WALLS
        }
        size = outer_diameter(walls["hub"], walls["shroud"])
        tol = b.tolerance * size
        wall_tol = min(b.tolerance, WALL_TOLERANCE) * size if b.tolerance > 0.0 else None

        def one_blade(label, wb, thickness_key, patches, le_ratio):
            base = (label, camber_keys["hub"], camber_keys["shroud"], thickness_key, axial, b.patch_spacing)

            def step(n):
                return kept(("step",) + base + (n,),
                            lambda: blade_step(channel, wb["hub"], wb["shroud"], n, axial, b.patch_spacing))

            strings_key = base + (patches, tol, wall_tol)
            strings = kept(("strings",) + strings_key, lambda: blade_strings(
                channel, wb["hub"], wb["shroud"], patches, axial, tol, wall_tol, b.patch_spacing, step))
            caps = kept(("caps",) + strings_key, dict)
            return kept(("blade",) + strings_key + (le_ratio, b.trailing_edge_ratio), lambda: build_blade(
                channel, wb["hub"], wb["shroud"], patches, axial, le_ratio, b.trailing_edge_ratio, tol, wall_tol,
                b.patch_spacing, strings=strings, caps=caps if memory is not None else None))

        blade = one_blade("blade", walls, (tuple(b.thickness_hub), tuple(b.thickness_shroud)), b.patches,
                          b.leading_edge_ratio)
        splitter = None
        s = self.splitter
        if s is not None:
            offset = 2.0 * math.pi * s.pitch_fraction / b.count
            swalls = {
                w: WallBlade(cambers[w], getattr(s, f"leading_edge_{w}"), cambers[w].U1,
                             np.asarray(getattr(s, f"thickness_{w}")), offset)
                for w in WALLS
            }
            splitter = one_blade(("splitter", s.leading_edge_hub, s.leading_edge_shroud, offset), swalls,
                                 (tuple(s.thickness_hub), tuple(s.thickness_shroud)), s.patches, s.leading_edge_ratio)
        st = self.standardisation
        if st is None or st.is_identity:
            return ImpellerModel(self.name, channel, blade, splitter, b.count)
        new_channel = kept(("scaled channel", channel_key, st.shroud_factor, st.hub_factor),
                           lambda: scaled_channel(channel, st.shroud_factor, st.hub_factor))
        standardisation = kept(("standardisation", id(blade), id(splitter), id(new_channel)),
                               lambda: self._standardise(channel, blade, splitter, new_channel))
        return ImpellerModel(self.name, standardisation.channel, blade, splitter, b.count, standardisation)

    def _standardise(self, master: MeridionalChannel, blade: BladeSurfaces, splitter,
                     channel: MeridionalChannel | None = None) -> Standardisation:
        """The new channel and the trimmed blades (Casey 1983, Fig. 11); failures are
        reported against the factor of the wall concerned."""
        st, p = self.standardisation, self.path
        st.check(p)

        def field_of(wall: str) -> str:
            if wall == "hub" and st.hub_factor != 1.0:
                return "standardisation.hub_factor"
            if wall == "shroud" and st.shroud_factor != 1.0:
                return "standardisation.shroud_factor"
            # the wall concerned did not move: the factor that did is to blame
            return "standardisation.shroud_factor" if st.shroud_factor != 1.0 else "standardisation.hub_factor"

        if channel is None:
            channel = scaled_channel(master, st.shroud_factor, st.hub_factor)
        try:
            channel.check(p)
        except DefinitionError as exc:
            raise DefinitionError(f"the new channel is invalid: {str(exc).rsplit(chr(39) + ': ', 1)[-1]}", path=p,
                                  field=field_of("shroud")) from None
        blades = {"blade": blade} if splitter is None else {"blade": blade, "splitter": splitter}
        values = f"shroud_factor = {st.shroud_factor!r}"
        if st.hub_factor != 1.0:
            values += f", hub_factor = {st.hub_factor!r}"
        try:
            return Standardisation(master, channel, st.shroud_factor, st.hub_factor, blades)
        except CutError as exc:
            raise DefinitionError(f"cannot standardise with {values}: {exc}", path=p,
                                  field=field_of(exc.wall)) from None
        except GeometryError as exc:
            raise DefinitionError(f"cannot standardise with {values}: {exc}", path=p,
                                  field=field_of("shroud")) from None


def dumps_toml(data: dict, header: str = "") -> str:
    """TOML text of a definition dictionary (flat tables of numbers, strings and lists)."""

    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, float):
            return repr(float(v))  # numpy 2's float64 repr is 'np.float64(...)'
        return str(v)

    lines = [header.rstrip()] if header else []
    for k, v in data.items():
        if not isinstance(v, dict):
            lines.append(f"{k} = {value(v)}")
    for k, v in data.items():
        if isinstance(v, dict):
            lines.append(f"\n[{k}]")
            lines.extend(f"{kk} = {value(vv)}" for kk, vv in v.items())
    return "\n".join(lines) + "\n"
