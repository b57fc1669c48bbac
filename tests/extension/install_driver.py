"""Run inside a Python that has a ``bpy`` wheel, in a fresh Blender user directory.

    BLENDER_USER_RESOURCES=<empty dir> python install_driver.py ZIP OUT.igs RESULT.json [no-scipy]

Installs ZIP as a user does (``extensions.package_install_files``, the operator behind
drag-and-drop and Install from Disk), enables it with ``addon_utils``, builds the DTMB 4119
preset propeller, exports IGES and disables the extension. Prints nothing it relies on;
writes what happened to RESULT.json for the test to check.

scipy must come from the wheel bundled in the zip, as on a user's machine: a scipy found
anywhere else on ``sys.path`` (the developer venv) is hidden by a meta-path finder. With
``no-scipy`` every scipy is hidden: the installed extension must still enable, with its
preferences present and its operators disabled.
"""
import importlib.machinery
import json
import os
import pathlib
import sys
import time

ZIP, IGES_PATH, RESULT_PATH = (pathlib.Path(a) for a in sys.argv[1:4])
NO_SCIPY = sys.argv[4:] == ["no-scipy"]
USER_DIR = pathlib.Path(os.environ["BLENDER_USER_RESOURCES"]).resolve()
MODULE = "bl_ext.user_default.bladesmith"


class OnlyBundledScipy:
    """Finds top-level ``scipy`` only below the Blender user directory."""

    def find_spec(self, name, path=None, target=None):
        if name != "scipy":
            return None
        allowed = [p for p in sys.path if p and pathlib.Path(p).resolve().is_relative_to(USER_DIR)]
        if NO_SCIPY:
            allowed = []
        spec = importlib.machinery.PathFinder.find_spec(name, allowed)
        if spec is None:
            raise ModuleNotFoundError("No module named 'scipy' (only the bundled wheel counts here)", name=name)
        return spec


sys.meta_path.insert(0, OnlyBundledScipy())
result = {"steps": []}
clock = time.perf_counter()


def step(name):
    global clock
    now = time.perf_counter()
    result["steps"].append((name, round(now - clock, 3)))
    clock = now


import bpy  # noqa: E402
import addon_utils  # noqa: E402  (importable once bpy is)

result["blender"] = bpy.app.version_string
result["user_dir"] = bpy.utils.resource_path("USER")
step("import bpy")

outcome = bpy.ops.extensions.package_install_files(filepath=str(ZIP), repo="user_default", enable_on_install=False)
result["install"] = sorted(outcome)
result["installed_dir"] = str(USER_DIR / "extensions" / "user_default" / "bladesmith")
step("install")

addon_utils.enable(MODULE, default_set=True, handle_error=None)
result["enabled_after_enable"] = MODULE in bpy.context.preferences.addons
if NO_SCIPY:
    result["preferences"] = type(bpy.context.preferences.addons[MODULE].preferences).__name__
    result["poll"] = bpy.ops.bladesmith.add_propeller.poll()
    try:
        bpy.ops.bladesmith.add_propeller(preset="DTMB4119")
        result["call"] = "ran"
    except RuntimeError as exc:
        result["call"] = str(exc)
    addon_utils.disable(MODULE, default_set=True, handle_error=None)
    result["enabled_after_disable"] = MODULE in bpy.context.preferences.addons
    result["operator_after_disable"] = hasattr(bpy.types, "BLADESMITH_OT_add_propeller")
    RESULT_PATH.write_text(json.dumps(result, indent=1))
    sys.exit(0)
import scipy  # noqa: E402

result["scipy"] = {"version": scipy.__version__, "file": scipy.__file__}
import numpy  # noqa: E402

result["numpy"] = numpy.__version__
result["addon_file"] = sys.modules[MODULE].__file__
step("enable")

bpy.ops.wm.read_factory_settings(use_empty=True)
# read_factory_settings resets preferences in memory; the add-on must still be there.
if MODULE not in bpy.context.preferences.addons:
    addon_utils.enable(MODULE, default_set=True, handle_error=None)
# The tip-smoothed propeller (make demo's job): its IGES is Hally (2013) §11's set.
result["propeller"] = sorted(bpy.ops.bladesmith.add_propeller(preset="DTMB4119", smooth_tip=True))
result["objects"] = sorted(obj.name for obj in bpy.data.objects)
step("add_propeller")

result["export"] = sorted(bpy.ops.export_scene.iges(filepath=str(IGES_PATH)))
step("export")

addon_utils.disable(MODULE, default_set=True, handle_error=None)
result["enabled_after_disable"] = MODULE in bpy.context.preferences.addons
result["operator_after_disable"] = hasattr(bpy.types, "BLADESMITH_OT_add_propeller")
step("disable")

RESULT_PATH.write_text(json.dumps(result, indent=1))
