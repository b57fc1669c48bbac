"""Bladesmith: exact NURBS blades for Blender, written to IGES that meshers accept.

This file only registers the submodules, in order. It imports nothing from Blender at
module level, so ``geometry`` and ``iges`` stay importable without ``bpy``.
"""
import importlib

#: Registered in this order, unregistered in reverse.
_SUBMODULES = ("operators", "ui")


def _modules():
    return [importlib.import_module(f".{name}", __package__) for name in _SUBMODULES]


def register():
    for module in _modules():
        module.register()


def unregister():
    for module in reversed(_modules()):
        module.unregister()
