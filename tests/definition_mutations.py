"""Hypothesis strategies that mutate a definition dictionary (issue 20, Deliver 4).

A case is a valid base definition (a shipped preset) with 1-3 mutations, each one of:

- ``replace``: any value (entry, array or table) by a wild value: NaN, ±inf, huge and tiny
  floats, big integers, strings, booleans, lists, tables;
- ``scale``: a number times a factor in [-4, 4] or an extreme one (near-valid designs,
  so that many cases build);
- ``delete``: a key or a list entry;
- ``unknown``: a new key in a table (a typo of an existing key, or random text);
- ``resize``: a list truncated, extended by repeats, or blown up a thousandfold.

Each mutation records the names it touched; a refusal must name one of them (or, for a
mutation that makes the definition inconsistent, the field the check is attached to, which
is a key of the same format: :func:`names_a_field`).

The number of examples is ``BLADESMITH_PROPERTY_EXAMPLES`` (default a few hundred per format,
so the suite stays fast); the report's 2,000+ runs set it (README "Property tests").
"""
from __future__ import annotations

import copy
import math
import os
import re

from hypothesis import strategies as st

#: Examples per format in the default suite; BLADESMITH_PROPERTY_EXAMPLES overrides.
DEFAULT_EXAMPLES = 100


def examples(default: int = DEFAULT_EXAMPLES) -> int:
    return int(os.environ.get("BLADESMITH_PROPERTY_EXAMPLES", default))


def measuring() -> bool:
    """True in the measured runs (the env var set): then per-case times are bounded."""
    return "BLADESMITH_PROPERTY_EXAMPLES" in os.environ


def save_counts(level: str, counts: dict) -> None:
    """With BLADESMITH_PROPERTY_REPORT=DIR, keep the running counts in DIR/<level>.json
    (so a long measured run can be read while it goes)."""
    folder = os.environ.get("BLADESMITH_PROPERTY_REPORT")
    if folder:
        import json

        with open(os.path.join(folder, f"{level}-{os.getpid()}.json"), "w") as fh:
            json.dump(counts, fh)


WILD = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.text(max_size=12),
    st.booleans(),
    st.lists(st.floats(min_value=-1e3, max_value=1e3), max_size=8),
    st.dictionaries(st.text(max_size=6), st.integers(-5, 5), max_size=2),
    st.sampled_from([0, -1, 1, 2, 0.5, 1e-300, 1e300, 1e6, 10**6, 1e20, math.nan, "auto", "circle", "", [], {},
                     [1], [[0.5, 0.5]]]),
)
#: Mostly gentle factors (designs near the preset, many of which build), some wild ones.
FACTORS = st.one_of(st.floats(min_value=0.8, max_value=1.25), st.floats(min_value=0.9, max_value=1.1),
                    st.floats(min_value=-4.0, max_value=4.0), st.sampled_from([0.0, 1e-6, 0.999, 1.001, 1e6]))


def paths(data, prefix=()):
    """Every addressable value: keys of tables, entries of lists (and of nested lists)."""
    out = []
    if isinstance(data, dict):
        items = list(data.items())
    elif isinstance(data, list):
        items = list(enumerate(data))
    else:
        return out
    for key, value in items:
        p = prefix + (key,)
        out.append(p)
        if isinstance(value, (dict, list)) and len(value) <= 64:
            out.extend(paths(value, p))
    return out


def tables(data, prefix=()):
    out = [prefix] if isinstance(data, dict) else []
    if isinstance(data, dict):
        for key, value in data.items():
            if isinstance(value, dict):
                out.extend(tables(value, prefix + (key,)))
    return out


def _get(data, path):
    for key in path:
        data = data[key]
    return data


def names(path) -> set[str]:
    return {str(k) for k in path if isinstance(k, str)}


@st.composite
def mutated(draw, base: dict):
    """(definition, [(operation, path, names)]) from ``base`` with 1-3 mutations."""
    data = copy.deepcopy(base)
    log = []
    for _ in range(draw(st.sampled_from([1, 1, 1, 2, 3]))):
        op = draw(st.sampled_from(["replace", "replace", "scale", "scale", "scale", "scale", "scale", "delete",
                                   "unknown", "resize"]))
        if op == "unknown":
            where = draw(st.sampled_from(tables(data)))
            table = _get(data, where)
            if table:
                near = draw(st.sampled_from(sorted(table)))
                key = draw(st.one_of(st.just(near[:-1] + "x"), st.just(near + "s"), st.text(min_size=1, max_size=8)))
            else:
                key = draw(st.text(min_size=1, max_size=8))
            if key in table:
                continue
            table[key] = draw(WILD)
            log.append((op, where + (key,), names(where) | {key}))
            continue
        candidates = paths(data)
        if not candidates:
            break
        path = draw(st.sampled_from(candidates))
        parent, key = _get(data, path[:-1]), path[-1]
        value = parent[key]
        if op == "scale":
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                op = "replace"
            else:
                new = value * draw(FACTORS)
                parent[key] = int(new) if isinstance(value, int) and math.isfinite(new) and abs(new) < 2**62 else new
        if op == "replace":
            parent[key] = draw(WILD)
        elif op == "delete":
            del parent[key]
        elif op == "resize":
            if not isinstance(value, list) or not value:
                parent[key] = draw(WILD)
                op = "replace"
            else:
                how = draw(st.sampled_from(["truncate", "extend", "blow_up"]))
                if how == "truncate":
                    parent[key] = value[: draw(st.integers(0, len(value) - 1))]
                elif how == "extend":
                    parent[key] = value + [value[-1]] * draw(st.integers(1, 5))
                else:
                    parent[key] = value * 1000
        log.append((op, path, names(path)))
    return data, log


def _named(name: str, message: str) -> bool:
    """``name`` appears as a field: quoted, dotted or indexed, or (a long or compound key
    such as mold_direction) as a whole word."""
    if f"'{name}" in message or f".{name}" in message or f"{name}'" in message or f"{name}[" in message:
        return True
    return ("_" in name or len(name) >= 6) and re.search(rf"\b{re.escape(name)}\b", message) is not None


def names_a_field(message: str, log, vocabulary) -> bool:
    """The refusal names a mutated key, or (for an inconsistency) a key of the format."""
    touched = set().union(*(n for _, _, n in log)) if log else set()
    if any(_named(n, message) for n in touched):
        return True
    return any(_named(n, message) for n in vocabulary)
