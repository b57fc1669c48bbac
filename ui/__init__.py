"""Panels, property groups, menus and viewport overlays.

Submodules are listed in registration order; each exposes ``register``/``unregister``.
"""
import importlib

_SUBMODULES = ("dependencies", "propeller_panel", "wind_blade_panel", "impeller_panel", "review_panel", "hvid_panel", "sweep_panel")


def _modules():
    return [importlib.import_module(f".{name}", __package__) for name in _SUBMODULES]


def register():
    for module in _modules():
        module.register()


def unregister():
    for module in reversed(_modules()):
        module.unregister()
