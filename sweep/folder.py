"""Reading a sweep folder (no Dask, no pyarrow): what Blender's "Load Sweep Variant"
needs to find one variant's definition and settings.

The folder's ``sweep.json`` lists the variants (index, key, parameter values) and their
kind; ``variants/<key>/definition.toml`` is the definition each was built from and
``variants/<key>/variant.json`` its record (status, settings, metrics or error).
"""
from __future__ import annotations

import json
import pathlib
from dataclasses import dataclass

from ..geometry.errors import DefinitionError

INDEX_FILE = "sweep.json"


@dataclass(frozen=True)
class VariantEntry:
    """One variant of a sweep folder: kind, design index, key, parameter values, the
    path of its definition file, its settings and its record's status and error."""

    kind: str
    index: int
    key: str
    values: dict
    definition: pathlib.Path
    settings: dict
    status: str
    error: str


def read_index(folder) -> dict:
    path = pathlib.Path(folder) / INDEX_FILE
    try:
        index = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DefinitionError("not a sweep folder (no sweep.json); run the sweep command first", path=str(path)) from None
    except (OSError, ValueError) as exc:
        raise DefinitionError(f"cannot read the sweep index: {exc}", path=str(path)) from None
    if not isinstance(index, dict) or not isinstance(index.get("variants"), list) or "kind" not in index:
        raise DefinitionError("not a sweep index (expected kind and variants)", path=str(path))
    return index


def find_variant(folder, variant: int | None = None, key: str = "") -> VariantEntry:
    """The variant with design index ``variant`` or with ``key`` (a unique prefix will do)."""
    folder = pathlib.Path(folder)
    index = read_index(folder)
    entries = index["variants"]
    if key:
        found = [e for e in entries if str(e.get("key", "")).startswith(key)]
        if len({e["key"] for e in found}) != 1:
            what = "no variant has" if not found else "more than one variant has"
            raise DefinitionError(f"{what} a key starting {key!r}", path=str(folder / INDEX_FILE), field="key")
        entry = found[0]
    else:
        if variant is None or not 0 <= variant < len(entries):
            raise DefinitionError(f"variant {variant} is not in the sweep (0 to {len(entries) - 1})",
                                  path=str(folder / INDEX_FILE), field="variant")
        entry = next((e for e in entries if e.get("variant") == variant), entries[variant])
    vdir = folder / "variants" / entry["key"]
    definition = vdir / "definition.toml"
    if not definition.is_file():
        raise DefinitionError(f"variant {entry['variant']} ({entry['key']}) has not been built yet: "
                              f"{str(definition)!r} does not exist", path=str(folder / INDEX_FILE), field="variant")
    try:
        record = json.loads((vdir / "variant.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        record = {}
    return VariantEntry(index["kind"], int(entry["variant"]), entry["key"], dict(entry.get("values", {})), definition,
                        dict(record.get("settings", index.get("settings", {}))), record.get("status", "unknown"),
                        record.get("error", ""))
