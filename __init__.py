"""Bladesmith: exact NURBS blades for Blender, written to IGES that meshers accept.

This file only registers the submodules, in order. It imports nothing from Blender at
module level, so ``geometry`` and ``iges`` stay importable without ``bpy``.
"""
import atexit
import importlib

#: Registered in this order, unregistered in reverse.
_SUBMODULES = ("operators", "ui")

#: Registered instead when scipy cannot be imported: preferences and a panel that say so,
#: and the operators as disabled stand-ins (ui/dependencies.py).
_WITHOUT_SCIPY = ("ui.dependencies",)

_registered = []
_exit_hook_armed = []


def _modules(names=_SUBMODULES):
    return [importlib.import_module(f".{name}", __package__) for name in names]


def register():
    from .ui.dependencies import scipy_problem

    modules = _modules(_SUBMODULES if scipy_problem() is None else _WITHOUT_SCIPY)
    for module in modules:
        module.register()
    _registered[:] = modules
    _unregister_at_exit_when_a_module()


def unregister():
    for module in reversed(_registered or _modules()):
        module.unregister()
    _registered.clear()


def _unregister_at_exit_when_a_module():
    """In the ``bpy`` module (Blender as a Python module, ``bpy.app.binary_path`` empty),
    interpreter exit with any operator class still registered deadlocks in bpy's own
    teardown (a global-state destructor waits on a condition variable). A script that
    registers the add-on and simply returns must still exit, so unregister at exit there.
    Inside the Blender executable, Blender unregisters add-ons itself."""
    import bpy

    if bpy.app.binary_path == "" and not _exit_hook_armed:
        atexit.register(_unregister_if_registered)
        _exit_hook_armed.append(True)


def _unregister_if_registered():
    if _registered:
        unregister()
