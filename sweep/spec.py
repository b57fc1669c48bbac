"""The sweep file (TOML): a base definition, named parameters and a design.

Format (paths relative to the sweep file)::

    base = "../data/propellers/skewed_demo.toml"   # a propeller, wind-blade or impeller definition
    # kind = "propeller"       # optional: "propeller", "wind_blade" or "impeller" (else from the base's tables)
    output = "skewed_sweep"    # optional: the sweep folder (default: <sweep file stem>_out)

    [settings]                 # optional: build settings every variant starts from (see SETTINGS)
    delta_c = 0.02

    [parameters]               # one table per named parameter
    pitch_scale = { field = "radial.P_D", action = "scale", range = [0.9, 1.1] }
    skew_scale  = { field = "radial.skew_deg", action = "scale", range = [0.5, 1.5] }
    d_t         = { field = "settings.tip_smoothing_distance", range = [0.03, 0.08] }
    blades      = { field = "blades", values = [3, 4, 5] }
    beta_le     = { field = "blade.beta_shroud", action = "offset", index = 0, range = [-3.0, 3.0] }

    [design]
    type = "lhs"               # "grid", "lhs" (Latin hypercube) or "csv"
    samples = 200              # lhs: number of variants
    seed = 7                   # lhs: the seed (same seed, same variants)
    # levels = 3               # grid: levels of each `range` parameter (its `values` otherwise)
    # file = "variants.csv"    # csv: a header naming parameters, one variant per line

A parameter's ``field`` is a dotted path into the definition as its TOML is laid out
(``diameter``, ``hub.nose_length``, ``radial.P_D``, ``stations.chord``,
``blade.beta_hub``) or ``settings.<name>``. ``action``: ``"set"`` (default) puts the value
there; ``"scale"`` multiplies and ``"offset"`` adds to it, every entry of a tabulated
column (or only entry ``index``). ``range = [lo, hi]`` or ``values = [...]`` gives what
it takes; ``integer = true`` rounds a sampled value.

Each variant is its full definition and settings; its key is a hash of both
(:func:`variant_key`), so the same variant gets the same folder in every run, whatever
the order or the design it came from. Errors in the sweep file itself are refused before
anything runs (:class:`DefinitionError` naming the file and field); a variant whose values
make an invalid definition is not an error of the sweep file: it is built, fails, and its
error is recorded with the field it names.
"""
from __future__ import annotations

import copy
import csv
import hashlib
import json
import math
import pathlib
import tomllib
from dataclasses import dataclass, field

import numpy as np

from ..geometry.errors import DefinitionError

KINDS = ("propeller", "wind_blade", "impeller")
ACTIONS = ("set", "scale", "offset")
DESIGNS = ("grid", "lhs", "csv")
#: The sweep format; part of every key, so a change of what a variant means changes keys.
FORMAT_VERSION = 1
#: Hex digits of the key (64 bits: no collision in any sweep a designer will run).
KEY_LENGTH = 16
#: The largest number of variants a sweep file may make (a grid multiplies quickly).
MAX_VARIANTS = 1_000_000

#: Build settings of each kind, with their defaults.
#: propeller: add_propeller's smoothing settings (lengths as fractions of the diameter D,
#: as in the operator and the panel) and the IGES units;
#: wind_blade: build_blade's single surface and the parting lines in the IGES file;
#: impeller: the number of blades written (the walls are always written).
SETTINGS = {
    "propeller": {
        "delta_c": 0.01, "tip_smoothing_distance": 0.05, "edge_smoothing_distance": 0.025, "transition_s": 0.75,
        "filter_strength": 0.5, "filter_iterations": 50, "tolerance": 1e-5, "units": "m",
    },
    "wind_blade": {"single_surface": False, "parting_lines": True, "units": "m"},
    "impeller": {"blades": 1, "units": "m"},
}


@dataclass(frozen=True)
class Parameter:
    """One named parameter (see the module docstring)."""

    name: str
    field: str
    action: str = "set"
    range: tuple | None = None
    values: tuple | None = None
    index: int | None = None
    integer: bool = False

    def levels(self, count: int | None) -> list:
        """The grid levels: ``values``, or ``count`` points spread over ``range``."""
        if self.values is not None:
            return list(self.values)
        lo, hi = self.range
        n = 1 if count is None else count
        pts = [lo] if n == 1 else list(np.linspace(lo, hi, n))
        return [self.cast(p) for p in pts]

    def from_unit(self, u: float):
        """The value at u in [0, 1) of a Latin-hypercube coordinate."""
        if self.values is not None:
            return self.values[min(int(u * len(self.values)), len(self.values) - 1)]
        lo, hi = self.range
        return self.cast(lo + u * (hi - lo))

    def cast(self, v):
        if self.integer:
            return int(round(float(v)))
        return float(v) if isinstance(v, (int, float, np.floating, np.integer)) and not isinstance(v, bool) else v


@dataclass(frozen=True)
class Variant:
    """One design point: its parameter values, full definition and settings, and key."""

    index: int
    values: dict
    definition: dict
    settings: dict
    key: str


@dataclass
class SweepSpec:
    """A validated sweep file."""

    path: pathlib.Path
    kind: str
    base: pathlib.Path
    base_definition: dict
    settings: dict
    parameters: list
    design: dict
    output: pathlib.Path
    raw: dict = field(default_factory=dict)

    def variants(self) -> list[Variant]:
        """Every variant of the design, in design order (index 0, 1, ...)."""
        rows = design_rows(self)
        out = []
        for i, values in enumerate(rows):
            definition, settings = apply_values(self, values)
            out.append(Variant(i, values, definition, settings, variant_key(self.kind, definition, settings)))
        return out


# -- reading ---------------------------------------------------------------------------
def infer_kind(data: dict) -> str | None:
    if "radial" in data or "radial_table" in data:
        return "propeller"
    if "stations" in data:
        return "wind_blade"
    if "channel" in data:
        return "impeller"
    return None


def load_base(kind: str, path: pathlib.Path) -> dict:
    """The base definition, validated, as its full TOML layout (defaults filled in,
    a radial_table CSV read into [radial]), with file paths as written in the base."""
    if kind == "propeller":
        from ..geometry.propeller import Propeller

        data = Propeller.from_toml(path).to_dict()
        # keep the airfoil path as written (relative to the base file): keys must not
        # depend on where the checkout lies
        with open(path, "rb") as fh:
            raw = tomllib.load(fh)
        if isinstance(raw.get("section"), dict) and "thickness" in raw["section"]:
            data["section"]["thickness"] = raw["section"]["thickness"]
        return data
    if kind == "wind_blade":
        from ..geometry.mold import load_blade

        return load_blade(path).to_dict()
    from ..geometry.compressor import ImpellerDefinition

    return ImpellerDefinition.from_toml(path).to_dict()


def load_spec(path, output=None) -> SweepSpec:
    """Read and validate a sweep file; ``output`` (a folder) overrides its ``output``."""
    path = pathlib.Path(path).resolve()
    p = str(path)
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except FileNotFoundError:
        raise DefinitionError("sweep file not found", path=p) from None
    except tomllib.TOMLDecodeError as exc:
        raise DefinitionError(f"not valid TOML: {exc}", path=p) from None
    unknown = set(data) - {"base", "kind", "output", "settings", "parameters", "design"}
    if unknown:
        raise DefinitionError(f"unknown field(s) {sorted(unknown)}", path=p, field=sorted(unknown)[0])
    if not isinstance(data.get("base"), str):
        raise DefinitionError(f"expected the path of a definition file, got {data.get('base')!r}", path=p, field="base")
    base = (path.parent / data["base"]).resolve()
    if not base.is_file():
        raise DefinitionError(f"base definition {str(base)!r} not found", path=p, field="base")
    with open(base, "rb") as fh:
        try:
            base_raw = tomllib.load(fh)
        except tomllib.TOMLDecodeError as exc:
            raise DefinitionError(f"not valid TOML: {exc}", path=str(base)) from None
    kind = data.get("kind", infer_kind(base_raw))
    if kind not in KINDS:
        raise DefinitionError(f"expected one of {', '.join(KINDS)} (or a base whose tables say), got {kind!r}",
                              path=p, field="kind")
    base_definition = load_base(kind, base)
    settings = dict(SETTINGS[kind])
    given = data.get("settings", {})
    if not isinstance(given, dict):
        raise DefinitionError("expected a table", path=p, field="settings")
    for k, v in given.items():
        if k not in settings:
            raise DefinitionError(f"unknown {kind} setting; expected one of {sorted(settings)}", path=p,
                                  field=f"settings.{k}")
        settings[k] = v
    parameters = _parameters(data.get("parameters"), p, kind, base_definition, settings)
    design = _design(data.get("design"), p, parameters, path.parent)
    if output is None:
        out = data.get("output", f"{path.stem}_out")
        if not isinstance(out, str) or not out:
            raise DefinitionError(f"expected a folder name, got {out!r}", path=p, field="output")
        output = path.parent / out
    spec = SweepSpec(path, kind, base, base_definition, settings, parameters, design,
                     pathlib.Path(output).resolve(), data)
    return spec


def _lookup(tree: dict, dotted: str):
    node = tree
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            raise KeyError(part)
        node = node[part]
    return node


def _parameters(table, p, kind, base_definition, settings) -> list[Parameter]:
    if not isinstance(table, dict) or not table:
        raise DefinitionError("expected a [parameters] table with at least one parameter", path=p, field="parameters")
    out = []
    for name, entry in table.items():
        where = f"parameters.{name}"
        if not isinstance(entry, dict):
            raise DefinitionError(f"expected a table, got {entry!r}", path=p, field=where)
        unknown = set(entry) - {"field", "action", "range", "values", "index", "integer"}
        if unknown:
            raise DefinitionError(f"unknown key(s) {sorted(unknown)}", path=p, field=where)
        target = entry.get("field")
        if not isinstance(target, str) or not target:
            raise DefinitionError(f"expected a definition field such as 'radial.P_D', got {target!r}", path=p,
                                  field=f"{where}.field")
        tree = {"settings": settings, **base_definition}
        try:
            current = _lookup(tree, target)
        except KeyError:
            raise DefinitionError(f"{target!r} is not a field of the {kind} definition (nor settings.<name>)",
                                  path=p, field=f"{where}.field") from None
        if isinstance(current, dict):
            raise DefinitionError(f"{target!r} is a table, not a field", path=p, field=f"{where}.field")
        action = entry.get("action", "set")
        if action not in ACTIONS:
            raise DefinitionError(f"expected one of {', '.join(ACTIONS)}, got {action!r}", path=p, field=f"{where}.action")
        index = entry.get("index")
        if index is not None:
            if not isinstance(current, list):
                raise DefinitionError(f"index given but {target!r} is not a tabulated column", path=p,
                                      field=f"{where}.index")
            if isinstance(index, bool) or not isinstance(index, int) or not -len(current) <= index < len(current):
                raise DefinitionError(f"expected an entry of the {len(current)}-entry column, got {index!r}", path=p,
                                      field=f"{where}.index")
        elif isinstance(current, list) and action == "set":
            raise DefinitionError(f"{target!r} is a tabulated column: scale or offset it, or set one entry (index)",
                                  path=p, field=f"{where}.action")
        rng, values = entry.get("range"), entry.get("values")
        if (rng is None) == (values is None):
            raise DefinitionError("give either range = [lo, hi] or values = [...]", path=p, field=where)
        if rng is not None:
            if (not isinstance(rng, list) or len(rng) != 2
                    or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in rng)
                    or rng[0] > rng[1]):
                raise DefinitionError(f"expected [lo, hi] with lo <= hi, got {rng!r}", path=p, field=f"{where}.range")
            rng = (float(rng[0]), float(rng[1]))
        if values is not None:
            if not isinstance(values, list) or not values:
                raise DefinitionError(f"expected a non-empty list, got {values!r}", path=p, field=f"{where}.values")
            if action != "set" and not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
                raise DefinitionError(f"{action} needs numbers, got {values!r}", path=p, field=f"{where}.values")
            values = tuple(values)
        integer = entry.get("integer", False)
        if not isinstance(integer, bool):
            raise DefinitionError(f"expected true or false, got {integer!r}", path=p, field=f"{where}.integer")
        out.append(Parameter(name, target, action, rng, values, index, integer))
    return out


def _design(table, p, parameters, folder) -> dict:
    if not isinstance(table, dict):
        raise DefinitionError("expected a [design] table", path=p, field="design")
    kind = table.get("type")
    if kind not in DESIGNS:
        raise DefinitionError(f"expected one of {', '.join(DESIGNS)}, got {kind!r}", path=p, field="design.type")
    allowed = {"grid": {"type", "levels"}, "lhs": {"type", "samples", "seed"}, "csv": {"type", "file"}}[kind]
    unknown = set(table) - allowed
    if unknown:
        raise DefinitionError(f"unknown key(s) {sorted(unknown)} for a {kind} design", path=p,
                              field=f"design.{sorted(unknown)[0]}")
    design = dict(table)
    if kind == "grid":
        levels = table.get("levels")
        if levels is not None and (isinstance(levels, bool) or not isinstance(levels, int) or levels < 1):
            raise DefinitionError(f"expected an integer >= 1, got {levels!r}", path=p, field="design.levels")
        if levels is None and any(q.values is None for q in parameters):
            raise DefinitionError("a grid over a range needs design.levels", path=p, field="design.levels")
        total = math.prod(len(q.levels(levels)) for q in parameters)
        if total > MAX_VARIANTS:
            raise DefinitionError(f"the grid has {total} variants, more than {MAX_VARIANTS}", path=p,
                                  field="design.levels")
    elif kind == "lhs":
        n, seed = table.get("samples"), table.get("seed")
        if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_VARIANTS:
            raise DefinitionError(f"expected an integer in [1, {MAX_VARIANTS}], got {n!r}", path=p,
                                  field="design.samples")
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise DefinitionError(f"expected an integer >= 0 (the same seed gives the same variants), got {seed!r}",
                                  path=p, field="design.seed")
    else:
        name = table.get("file")
        if not isinstance(name, str):
            raise DefinitionError(f"expected a CSV file name, got {name!r}", path=p, field="design.file")
        design["rows"] = _read_csv(folder / name, parameters)
    return design


def _read_csv(path: pathlib.Path, parameters) -> list[dict]:
    """Variants from CSV: a header naming parameters (all of them), then one line each;
    numbers are read as numbers, anything else as text."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise DefinitionError(f"design file {str(path)!r} not found", field="design.file") from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    rows = list(csv.reader(lines))
    if not rows:
        raise DefinitionError("empty design file", path=str(path), field="design.file")
    header = [h.strip() for h in rows[0]]
    names = {q.name: q for q in parameters}
    for h in header:
        if h not in names:
            raise DefinitionError(f"column {h!r} is not a parameter; parameters: {sorted(names)}", path=str(path),
                                  field=h)
    missing = [n for n in names if n not in header]
    if missing:
        raise DefinitionError(f"no column for parameter {missing[0]!r}", path=str(path), field=missing[0])
    out = []
    for lineno, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise DefinitionError(f"line {lineno}: {len(row)} values, header has {len(header)}", path=str(path))
        values = {}
        for h, cell in zip(header, row):
            cell = cell.strip()
            try:
                v = float(cell)
                v = names[h].cast(v)
            except ValueError:
                if names[h].action != "set":
                    raise DefinitionError(f"line {lineno}: {cell!r} is not a number", path=str(path), field=h) from None
                v = cell
            values[h] = v
        out.append(values)
    if len(out) > MAX_VARIANTS:
        raise DefinitionError(f"{len(out)} variants, more than {MAX_VARIANTS}", path=str(path), field="design.file")
    return out


# -- the design ------------------------------------------------------------------------
def design_rows(spec: SweepSpec) -> list[dict]:
    """Parameter values of every variant: {parameter name: value}."""
    params, d = spec.parameters, spec.design
    if d["type"] == "grid":
        import itertools

        levels = [q.levels(d.get("levels")) for q in params]
        return [{q.name: v for q, v in zip(params, combo)} for combo in itertools.product(*levels)]
    if d["type"] == "lhs":
        from scipy.stats import qmc

        U = qmc.LatinHypercube(d=len(params), seed=np.random.default_rng(d["seed"])).random(d["samples"])
        return [{q.name: q.from_unit(u) for q, u in zip(params, row)} for row in U]
    return [dict(r) for r in d["rows"]]


def _modify(current, action: str, value, index):
    def one(x):
        if action == "set":
            return value
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            return None  # reported by the caller
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            return None
        return x * value if action == "scale" else x + value

    if isinstance(current, list):
        new = list(current)
        targets = range(len(new)) if index is None else [index]
        for i in targets:
            new[i] = one(new[i])
        return new
    return one(current)


def apply_values(spec: SweepSpec, values: dict) -> tuple[dict, dict]:
    """The variant's definition and settings: the base's, with each parameter applied in
    the order the sweep file lists them. Values are not validated here (the build does,
    and records what it refuses)."""
    definition = copy.deepcopy(spec.base_definition)
    settings = dict(spec.settings)
    tree = {"settings": settings, **definition}
    for q in spec.parameters:
        v = values[q.name]
        parts = q.field.split(".")
        node = tree
        for part in parts[:-1]:
            node = node[part]
        new = _modify(node[parts[-1]], q.action, v, q.index)
        if new is None or (isinstance(new, list) and any(x is None for x in new)):
            raise DefinitionError(f"cannot {q.action} {node[parts[-1]]!r} by {v!r}", path=str(spec.path),
                                  field=f"parameters.{q.name}")
        node[parts[-1]] = new
    definition = {k: v for k, v in tree.items() if k != "settings"}
    return definition, settings


def canonical_json(data) -> str:
    """The JSON text a key is computed from: sorted keys, floats by repr (exact)."""
    return json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=True)


def variant_key(kind: str, definition: dict, settings: dict) -> str:
    """A hash of what a variant is (kind, full definition, settings, format version)."""
    text = canonical_json({"format": FORMAT_VERSION, "kind": kind, "definition": definition, "settings": settings})
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:KEY_LENGTH]
