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


# -- standardisation (Casey 1983, Fig. 11) ---------------------------------------------------------
def _stored(root, part):
    from bladesmith.operators.nurbs_objects import object_to_geometry

    (surface,) = object_to_geometry(bpy.data.objects[f"{root.name} {part}"])
    return surface


def _standardised_reference(source, **table):
    """An independent build: ``source`` is a preset name or a root (whose stored
    definition holds the panel's values as typed)."""
    import tomllib

    from bladesmith.geometry.compressor import ImpellerDefinition
    from bladesmith.geometry.compressor.export import impeller_surfaces

    ops = sys.modules["bladesmith.operators.impeller"]
    if isinstance(source, str):
        data = ImpellerDefinition.from_toml(ops.PRESET_DIR / f"{source}.toml").to_dict()
    else:
        data = tomllib.loads(source["definition_toml"])  # the panel's factors included
    if table:
        data["standardisation"] = table
    model = ImpellerDefinition.from_dict(data).build()
    return model, dict(impeller_surfaces(model, 1, include_camber=True))


def test_standardised_definition_file(impeller_modules, scene, tmp_path):
    ops = impeller_modules[0]
    path = tmp_path / "cut.toml"
    text = (ops.PRESET_DIR / "intermediate_flow.toml").read_text()
    path.write_text(text + "\n[standardisation]\nshroud_factor = 0.8\n")
    assert bpy.ops.bladesmith.add_impeller(definition=str(path), full_wheel=False) == {"FINISHED"}
    root = bpy.context.active_object
    s = root.bladesmith_impeller
    assert s.shroud_factor == pytest.approx(0.8) and s.hub_factor == 1.0
    assert s.standardisation_report.startswith("standardised (shroud factor 0.8): edges within")
    assert "knots per surface" in s.standardisation_report
    assert "[standardisation]" in root["definition_toml"]
    model, reference = _standardised_reference("intermediate_flow", shroud_factor=0.8)
    for part in ("blade 1 S", "blade 1 LE", "splitter 1 P", "blade 1 B", "shroud 2"):
        assert np.array_equal(_stored(root, part).control_points, reference[part].control_points), part


def test_panel_standardisation_regenerates_live(impeller_modules, scene):
    bpy.ops.bladesmith.add_impeller(preset="high_flow", full_wheel=False)
    root = bpy.context.active_object
    s = root.bladesmith_impeller
    assert s.standardisation_report == ""
    s.shroud_factor = 0.8
    assert s.status == "" and s.standardisation_report.startswith("standardised")
    assert "shroud_factor = 0.8\n" in root["definition_toml"]  # as typed, not float32 0.800000011920929
    _, reference = _standardised_reference(root)
    for part in ("blade 1 S", "blade 1 P", "blade 1 LE", "blade 1 B", "shroud 1", "hub 1"):
        assert np.array_equal(_stored(root, part).control_points, reference[part].control_points), part
    s.hub_factor = 0.9
    assert s.status == "" and "hub factor 0.9" in s.standardisation_report
    model, both = _standardised_reference(root)
    assert model.standardisation.hub_factor == pytest.approx(0.9)
    assert np.array_equal(_stored(root, "blade 1 S").control_points, both["blade 1 S"].control_points)
    s.hub_factor = 0.25  # refused: the last good geometry stays
    assert "standardisation.hub_factor" in s.status and "0.25" in s.status
    assert np.array_equal(_stored(root, "blade 1 S").control_points, both["blade 1 S"].control_points)
    s.hub_factor = 1.0
    s.shroud_factor = 1.0  # back to the master, bit for bit
    assert s.status == "" and s.standardisation_report == ""
    assert "standardisation" not in root["definition_toml"]
    _, master = _standardised_reference(root)
    for part in ("blade 1 S", "blade 1 LE", "shroud 1"):
        assert np.array_equal(_stored(root, part).control_points, master[part].control_points), part


def test_panel_refuses_a_factor_the_rulings_cannot_reach(impeller_modules, scene):
    bpy.ops.bladesmith.add_impeller(preset="intermediate_flow", full_wheel=False)
    s = bpy.context.active_object.bladesmith_impeller
    s.shroud_factor = 1.1
    assert "standardisation.shroud_factor" in s.status and "shroud wall" in s.status


def test_standardised_impeller_exports_to_iges(impeller_modules, scene, tmp_path):
    """File > Export > IGES writes the trimmed blades; OpenCASCADE reads the file with no
    fail or warning message and valid faces, gmsh meshes it."""
    import importlib.util
    import pathlib

    from bladesmith.iges import read_iges

    pytest.importorskip("OCP")
    if "occ_support" not in sys.modules:  # as in test_iges_operators
        occ_path = pathlib.Path(__file__).resolve().parents[1] / "iges" / "occ_support.py"
        spec = importlib.util.spec_from_file_location("occ_support", occ_path)
        module = importlib.util.module_from_spec(spec)
        sys.modules["occ_support"] = module
        spec.loader.exec_module(module)
    occ = sys.modules["occ_support"]
    bpy.ops.bladesmith.add_impeller(preset="intermediate_flow", full_wheel=True)
    root = bpy.context.active_object
    root.bladesmith_impeller.shroud_factor = 0.8
    assert root.bladesmith_impeller.status == ""
    path = tmp_path / "standardised.igs"
    assert bpy.ops.export_scene.iges(filepath=str(path), units="MM") == {"FINISHED"}
    _, reference = _standardised_reference(root)
    written = [g for _, g in read_iges(path).to_geometry()]
    assert len(written) == 8 + 15 * 3 + 15 * 3 + 2  # walls, S P LE of blades and splitters, B of blade 1 and splitter 1
    S = reference["blade 1 S"]
    assert any(g.shape == S.shape and np.array_equal(g.control_points, 1000.0 * S.control_points) for g in written)
    result = occ.read_with_occ(path)
    assert result.load_messages == [] and result.transfer_messages == []
    assert len(result.faces) == len(written) and all(occ.is_valid(f) for f in result.faces)
    gmsh = pytest.importorskip("gmsh")
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.logger.start()
        gmsh.model.add("standardised")
        gmsh.model.occ.importShapes(str(path))
        gmsh.model.occ.synchronize()
        assert len(gmsh.model.getEntities(2)) == len(written)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 10.0)  # mm
        gmsh.model.mesh.generate(2)
        complaints = [line for line in gmsh.logger.get() if line.startswith(("Error", "Warning"))]
        assert complaints == [], complaints
    finally:
        gmsh.logger.stop()
        gmsh.finalize()
