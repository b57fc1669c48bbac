"""The add-on registers, unregisters without leftovers, and registers again; the manifest
passes the validator that ships inside the bpy wheel."""
import pathlib
import subprocess
import sys

import bpy

ROOT = pathlib.Path(__file__).resolve().parents[2]


def bladesmith_types():
    return {name for name in dir(bpy.types) if "BLADESMITH" in name.upper() or name.startswith("IMPORT_SCENE_OT_iges") or name.startswith("EXPORT_SCENE_OT_iges")}


def test_register_unregister_register(addon):
    registered = bladesmith_types()
    addon.unregister()
    assert bladesmith_types() == set(), "left registered after unregister"
    assert not hasattr(bpy.types.Scene, "bladesmith")
    addon.register()
    assert bladesmith_types() == registered
    addon.unregister()
    addon.register()
    assert bladesmith_types() == registered


def test_manifest_passes_the_bundled_validator():
    cli = pathlib.Path(bpy.utils.system_resource("SCRIPTS")) / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"
    assert cli.exists(), cli
    result = subprocess.run([sys.executable, str(cli), "validate", str(ROOT)], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Success" in result.stdout
