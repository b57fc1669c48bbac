"""A refused operator leaves the scene exactly as it was (ARCHITECTURE.md, house style 6).

:func:`unchanged_on_refusal` wraps an operator's ``execute``: it records the data-blocks
that exist before (objects, curves, meshes, collections, materials, images, scenes, ...)
and, when ``execute`` returns CANCELLED or raises, removes every data-block made since, so
neither objects nor orphan data nor collections are left behind.

:func:`check_output_file` refuses an output path whose folder is missing or read-only
before any work is done, so the refusal names the file and the field.
"""
from __future__ import annotations

import functools
import os

import bpy

from ..geometry.errors import DefinitionError

#: bpy.data collections a Bladesmith operator can add to, removed in this order (objects
#: first, so their data have no users left when they go).
_KINDS = ("objects", "collections", "scenes", "curves", "meshes", "materials", "images", "cameras", "worlds",
          "lights", "textures", "node_groups")


def snapshot() -> dict[str, set[int]]:
    """The data-blocks of each kind, by pointer (names may be reused)."""
    return {kind: {block.as_pointer() for block in getattr(bpy.data, kind)} for kind in _KINDS}


def remove_new(before: dict[str, set[int]]) -> int:
    """Remove every data-block not in ``before``; returns how many were removed."""
    removed = 0
    for kind in _KINDS:
        blocks = getattr(bpy.data, kind)
        for block in [b for b in blocks if b.as_pointer() not in before[kind]]:
            if kind == "scenes" and len(bpy.data.scenes) <= 1:
                continue
            blocks.remove(block)
            removed += 1
    return removed


def unchanged_on_refusal(execute):
    """Decorator of ``Operator.execute``: on CANCELLED (or an exception) every data-block
    the call made is removed again."""

    @functools.wraps(execute)
    def wrapper(self, context):
        before = snapshot()
        try:
            result = execute(self, context)
        except BaseException:
            remove_new(before)
            raise
        if "CANCELLED" in result:
            remove_new(before)
        return result

    return wrapper


def check_output_file(path: str, field: str = "filepath") -> str:
    """``path`` (Blender's // resolved) when its folder exists and is writable and it is
    not a folder itself, else a DefinitionError naming the file and ``field``."""
    path = bpy.path.abspath(path)
    folder = os.path.dirname(os.path.abspath(path)) or "."
    if os.path.isdir(path):
        raise DefinitionError(f"{path!r} is a folder, not a file", field=field)
    if not os.path.isdir(folder):
        raise DefinitionError(f"cannot write {path!r}: the folder {folder!r} does not exist", field=field)
    if not os.access(folder, os.W_OK | os.X_OK):
        raise DefinitionError(f"cannot write {path!r}: the folder {folder!r} is read-only", field=field)
    return path
