"""Bladesmith: exact NURBS blades for Blender, written to IGES that meshers accept.

This file only registers the submodules, in order. It imports nothing from Blender at
module level, so ``geometry`` and ``iges`` stay importable without ``bpy``.
"""
import importlib

#: Registered in this order, unregistered in reverse.
_SUBMODULES = ("operators", "ui")

#: Registered instead when scipy cannot be imported: preferences and a panel that say so,
#: and the operators as disabled stand-ins (ui/dependencies.py).
_WITHOUT_SCIPY = ("ui.dependencies",)

_registered = []


def _modules(names=_SUBMODULES):
    return [importlib.import_module(f".{name}", __package__) for name in names]


def register():
    from .ui.dependencies import scipy_problem

    modules = _modules(_SUBMODULES if scipy_problem() is None else _WITHOUT_SCIPY)
    for module in modules:
        module.register()
    _registered[:] = modules


def unregister():
    for module in reversed(_registered or _modules()):
        module.unregister()
    _registered.clear()
