"""bpy.ops.bladesmith.add_impeller: presets, definition files, bad data, live panel edits."""
import importlib
import sys

import bpy
import numpy as np
import pytest


@pytest.fixture(scope="module")
def impeller_modules(addon):
    """operators.impeller and ui.impeller_panel (registered with the add-on)."""
    pkg = sys.modules["bladesmith"].__name__
    return [importlib.import_module(f"{pkg}.operators.impeller"), importlib.import_module(f"{pkg}.ui.impeller_panel")]


def test_add_preset_full_wheel(impeller_modules, scene):
    assert bpy.ops.bladesmith.add_impeller(preset="high_flow", full_wheel=True, blade_net=True) == {"FINISHED"}
    root = bpy.context.active_object
    parts = [c["bladesmith_part"] for c in root.children]
    assert sum(p.startswith("blade ") and p.endswith(" S") for p in parts) == 15
    assert "net B" in parts and sum(p.startswith("hub") for p in parts) == 4
    assert root.bladesmith_impeller.beta_hub[0].value == pytest.approx(-35.0)


def test_splitters_and_definition_file(impeller_modules, scene, tmp_path):
    ops = impeller_modules[0]
    path = tmp_path / "imp.toml"
    path.write_text((ops.PRESET_DIR / "intermediate_flow.toml").read_text())
    assert bpy.ops.bladesmith.add_impeller(definition=str(path), full_wheel=False) == {"FINISHED"}
    parts = [c["bladesmith_part"] for c in bpy.context.active_object.children]
    assert "splitter 1 S" in parts and "blade 2 S" not in parts


def test_bad_data_cancelled_scene_unchanged(impeller_modules, scene, tmp_path):
    ops = impeller_modules[0]
    text = (ops.PRESET_DIR / "high_flow.toml").read_text().replace(
        "thickness_hub = [0.004,", "thickness_hub = [-0.004,")
    path = tmp_path / "bad.toml"
    path.write_text(text)
    before = len(bpy.data.objects)
    with pytest.raises(RuntimeError, match="blade.thickness_hub"):
        bpy.ops.bladesmith.add_impeller(definition=str(path))
    assert len(bpy.data.objects) == before


def test_panel_edit_regenerates_and_refuses_bad_values(impeller_modules, scene):
    bpy.ops.bladesmith.add_impeller(preset="high_flow", full_wheel=False)
    root = bpy.context.active_object
    s = root.bladesmith_impeller
    name = f"{root.name} blade 1 S"
    before = np.array([p.co[:] for p in bpy.data.objects[name].data.splines[0].points])
    s.beta_hub[1].value = -20.0
    assert s.status == ""
    after = np.array([p.co[:] for p in bpy.data.objects[name].data.splines[0].points])
    assert np.max(np.abs(after - before)) > 1e-4
    s.leading_edge_hub = 3.5  # after the TE
    assert "blade.leading_edge_hub" in s.status
    assert name in bpy.data.objects  # last good geometry kept
