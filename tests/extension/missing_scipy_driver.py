"""Run in a fresh Python with bpy: register the checkout with scipy made unimportable.

    python missing_scipy_driver.py RESULT.json

``sys.modules["scipy"] = None`` makes every ``import scipy`` raise ImportError, as on a
Blender where the wheel is missing. Writes what registration did to RESULT.json.
"""
import importlib.util
import json
import pathlib
import sys

sys.modules["scipy"] = None

import bpy  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
RESULT = pathlib.Path(sys.argv[1])


class Layout:
    """Records what a draw() puts on a layout."""

    def __init__(self, lines):
        self.lines = lines

    def box(self):
        return self

    def column(self, **_):
        return self

    def row(self, **_):
        return self

    def label(self, text="", icon="NONE"):
        self.lines.append([icon, text])


def bladesmith_types():
    return sorted(n for n in dir(bpy.types) if "BLADESMITH" in n.upper() or n.endswith("_OT_iges"))


spec = importlib.util.spec_from_file_location("bladesmith", ROOT / "__init__.py", submodule_search_locations=[str(ROOT)])
addon = importlib.util.module_from_spec(spec)
sys.modules["bladesmith"] = addon
spec.loader.exec_module(addon)

result = {}
try:
    addon.register()
    result["registered"] = True
except Exception as exc:  # the failure this test exists to catch
    result["registered"] = False
    result["error"] = f"{type(exc).__name__}: {exc}"
    RESULT.write_text(json.dumps(result, indent=1))
    sys.exit(0)

deps = sys.modules["bladesmith.ui.dependencies"]
result["types"] = bladesmith_types()
result["preferences_registered"] = deps.BladesmithPreferences.is_registered
result["preferences_idname"] = deps.BladesmithPreferences.bl_idname
result["panel_category"] = getattr(bpy.types, "BLADESMITH_PT_dependencies").bl_category
for name, cls in (("panel", deps.BLADESMITH_PT_dependencies), ("preferences", deps.BladesmithPreferences)):
    lines = []
    cls.draw(type("Self", (), {"layout": Layout(lines)})(), bpy.context)
    result[f"{name}_lines"] = lines

polls, calls = {}, {}
for idname in deps.SCIPY_OPERATORS:
    group, name = idname.split(".")
    op = getattr(getattr(bpy.ops, group), name)
    polls[idname] = op.poll()
    try:
        op()
        calls[idname] = "ran"
    except RuntimeError as exc:
        calls[idname] = str(exc)
result["polls"] = polls
result["calls"] = calls
result["scipy_loaded"] = "scipy.interpolate" in sys.modules

addon.unregister()
result["types_after_unregister"] = bladesmith_types()
addon.register()
addon.unregister()
result["types_after_second_cycle"] = bladesmith_types()
RESULT.write_text(json.dumps(result, indent=1))
