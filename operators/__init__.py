"""Thin bpy operators: read properties, call geometry/, write objects.

Submodules are listed in registration order; each exposes ``register``/``unregister``.
"""
import importlib

_SUBMODULES = ("nurbs_objects", "iges_io", "propeller", "wind_blade", "impeller", "impeller_uses", "import_airfoil", "smooth_curve", "curvature_review", "sweep_variant")


def _modules():
    return [importlib.import_module(f".{name}", __package__) for name in _SUBMODULES]


def register():
    for module in _modules():
        module.register()


def unregister():
    for module in reversed(_modules()):
        module.unregister()
