"""scipy, the one dependency Blender does not bundle: its status, and the add-on without it.

The extension zip carries the scipy wheel for its platform, and Blender installs it when
the extension is installed. If scipy still cannot be imported (a zip for another
platform, a removed ``.local`` folder, a broken wheel), the root ``register()`` registers
only this module, which shows why in the add-on preferences and in a sidebar panel, and
registers every operator id as a disabled stand-in whose poll message says the same, so a
script calling ``bpy.ops.bladesmith.add_propeller()`` gets that message, not an
``AttributeError``. With scipy present this module only adds the preferences status line.
"""
from __future__ import annotations

import importlib

import bpy

#: The add-on's own module name: ``bladesmith`` from a checkout,
#: ``bl_ext.<repo>.bladesmith`` when installed as an extension.
ADDON_PACKAGE = __package__.rpartition(".")[0]

#: The scipy modules geometry/ imports.
SCIPY_MODULES = ("scipy", "scipy.interpolate", "scipy.linalg", "scipy.optimize")

#: Every operator the add-on registers needs geometry/, and geometry/ needs scipy.
SCIPY_OPERATORS = (
    "bladesmith.add_propeller",
    "bladesmith.regenerate_propeller",
    "bladesmith.load_propeller_definition",
    "bladesmith.save_propeller_definition",
    "bladesmith.add_wind_blade",
    "bladesmith.regenerate_wind_blade",
    "bladesmith.export_wind_blade_iges",
    "bladesmith.wind_blade_fairness",
    "bladesmith.add_impeller",
    "bladesmith.import_airfoil",
    "bladesmith.smooth_curve",
    "bladesmith.curvature_review",
    "bladesmith.load_sweep_variant",
    "export_scene.iges",
    "import_scene.iges",
)

MISSING_TITLE = "Bladesmith is disabled: scipy cannot be imported"
MISSING_HELP = (
    "Blender does not bundle scipy; the Bladesmith zip for your platform carries it.",
    "Install the zip built for this platform again (Edit > Preferences > Get Extensions >",
    "Install from Disk), then restart Blender.",
)


def scipy_problem() -> str | None:
    """None when the scipy modules Bladesmith uses import; otherwise the reason they do not."""
    try:
        for name in SCIPY_MODULES:
            importlib.import_module(name)
    except Exception as exc:  # ImportError, or OSError etc. from a broken binary wheel
        return f"{type(exc).__name__}: {exc}"
    return None


def status_lines(problem: str | None) -> list[tuple[str, str]]:
    """(icon, text) lines for the preferences and the panel."""
    if problem is None:
        import scipy

        return [("CHECKMARK", f"scipy {scipy.__version__}: all operators available")]
    return [("ERROR", MISSING_TITLE), ("BLANK1", f"Reason: {problem}")] + [("BLANK1", line) for line in MISSING_HELP]


def _draw_status(layout, problem) -> None:
    box = layout.box()
    col = box.column(align=True)
    for icon, text in status_lines(problem):
        col.label(text=text, icon=icon)


_state = {"problem": None}


class BladesmithPreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON_PACKAGE

    def draw(self, context):
        _draw_status(self.layout, _state["problem"])


class BLADESMITH_PT_dependencies(bpy.types.Panel):
    """Shown instead of the Bladesmith panels when scipy is missing."""

    bl_label = "Bladesmith"
    bl_idname = "BLADESMITH_PT_dependencies"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Bladesmith"

    def draw(self, context):
        _draw_status(self.layout, _state["problem"])


def _disabled_operator(idname: str) -> type:
    """A stand-in for ``idname`` whose poll is always False, with the reason as poll message."""
    group, name = idname.split(".")

    def poll(cls, context):
        cls.poll_message_set(f"{MISSING_TITLE} ({_state['problem']})")
        return False

    return type(
        f"{group.upper()}_OT_{name}",
        (bpy.types.Operator,),
        {
            "bl_idname": idname,
            "bl_label": name.replace("_", " ").title(),
            "bl_description": f"Unavailable: {MISSING_TITLE}",
            "poll": classmethod(poll),
            "execute": lambda self, context: {"CANCELLED"},
        },
    )


_registered: list[type] = []


def register():
    _state["problem"] = scipy_problem()
    classes = [BladesmithPreferences]
    if _state["problem"] is not None:
        classes += [BLADESMITH_PT_dependencies, *(_disabled_operator(i) for i in SCIPY_OPERATORS)]
    for cls in classes:
        bpy.utils.register_class(cls)
    _registered[:] = classes


def unregister():
    for cls in reversed(_registered):
        bpy.utils.unregister_class(cls)
    _registered.clear()
