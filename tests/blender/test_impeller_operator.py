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
    assert len(written) == 8 + 15 * 4 + 15 * 4 + 2  # walls, S P LE TE of blades and splitters, B of blade 1 and splitter 1
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


# -- channel walls: corner angles and bend fractions -----------------------------------------------
def _all_surfaces(root) -> dict:
    """Control points of every child surface the panel regenerates (full_wheel=False)."""
    from bladesmith.operators.nurbs_objects import object_to_geometry

    out = {}
    for child in root.children:
        if child.type == "SURFACE":
            (surface,) = object_to_geometry(child)
            out[child["bladesmith_part"]] = np.array(surface.control_points)
    return out


def _same(a: dict, b: dict) -> bool:
    return a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)


def _toml_line(root, key: str) -> str:
    (line,) = [x for x in root["definition_toml"].splitlines() if x.startswith(f"{key} = ")]
    return line


def _matches_reference(root) -> bool:
    """The children are the independent build of the stored definition, bit for bit."""
    _, reference = _standardised_reference(root)
    stored = _all_surfaces(root)
    return _same(stored, {k: np.array(v.control_points) for k, v in reference.items() if k in stored})


@pytest.mark.parametrize("preset", ["high_flow", "return_channel"])
def test_panel_walls_load_from_the_definition(impeller_modules, scene, preset):
    from bladesmith.geometry.compressor import ImpellerDefinition

    ops, panel = impeller_modules
    bpy.ops.bladesmith.add_impeller(preset=preset, full_wheel=False)
    s = bpy.context.active_object.bladesmith_impeller
    channel = ImpellerDefinition.from_toml(ops.PRESET_DIR / f"{preset}.toml").to_dict()["channel"]
    degrees = channel["degrees"]
    for wall in ("hub", "shroud"):
        corners, patches = getattr(s, f"{wall}_angle"), getattr(s, f"{wall}_fractions")
        assert len(corners) == len(degrees) + 1 and len(patches) == len(degrees)
        z, r = np.array(channel[f"{wall}_z"]), np.array(channel[f"{wall}_r"])
        for k, (corner, angle) in enumerate(zip(corners, channel[f"{wall}_angle"])):
            assert corner.auto == (angle == "auto")
            if angle == "auto":  # the direction of the adjacent straight patch, computed here independently
                j = k - 1 if k > 0 and degrees[k - 1] == 1 else k
                expected = np.degrees(np.arctan2(r[j + 1] - r[j], z[j + 1] - z[j]))
            else:
                expected = angle
            assert corner.angle == np.float32(expected), (wall, k)
        for patch, degree, pair in zip(patches, degrees, channel[f"{wall}_fractions"]):
            assert patch.bend == (degree == 4)
            assert tuple(patch.fractions) == tuple(np.float32(pair))
    assert s.hub_angle[2].auto is False and s.hub_angle[1].auto is True


def test_panel_wall_angle_edit_regenerates_and_restores(impeller_modules, scene):
    bpy.ops.bladesmith.add_impeller(preset="high_flow", full_wheel=False)
    root = bpy.context.active_object
    s = root.bladesmith_impeller
    original, toml = _all_surfaces(root), root["definition_toml"]
    s.hub_angle[2].angle = 45.0  # a corner between the two bends
    assert s.status == ""
    assert _toml_line(root, "hub_angle") == 'hub_angle = ["auto", "auto", 45.0, "auto", "auto"]'
    edited = _all_surfaces(root)
    assert np.max(np.abs(edited["hub 1"] - original["hub 1"])) > 1e-4
    assert np.array_equal(edited["shroud 1"], original["shroud 1"])
    assert _matches_reference(root)
    s.hub_angle[2].angle = 50.0
    assert s.status == "" and root["definition_toml"] == toml and _same(_all_surfaces(root), original)
    # Auto off at a corner next to the straight inlet, then on again: nothing moves
    s.hub_angle[1].auto = False
    assert s.status == "" and _toml_line(root, "hub_angle") == 'hub_angle = ["auto", 0.0, 50.0, "auto", "auto"]'
    assert _same(_all_surfaces(root), original)
    s.hub_angle[1].auto = True
    assert s.status == "" and root["definition_toml"] == toml and _same(_all_surfaces(root), original)


def test_panel_bend_fraction_edit_regenerates(impeller_modules, scene):
    bpy.ops.bladesmith.add_impeller(preset="high_flow", full_wheel=False)
    root = bpy.context.active_object
    s = root.bladesmith_impeller
    original = _all_surfaces(root)
    s.hub_fractions[1].fractions[0] = 0.7
    assert s.status == ""
    assert _toml_line(root, "hub_fractions") == "hub_fractions = [[0.5, 0.5], [0.7, 0.5], [0.5, 0.6], [0.5, 0.5]]"
    edited = _all_surfaces(root)
    assert np.max(np.abs(edited["hub 1"] - original["hub 1"])) > 1e-4
    assert np.array_equal(edited["shroud 1"], original["shroud 1"])
    assert _matches_reference(root)
    s.shroud_fractions[2].fractions = (0.4, 0.7)
    assert s.status == "" and _toml_line(root, "shroud_fractions").endswith("[0.4, 0.7], [0.5, 0.5]]")
    assert np.max(np.abs(_all_surfaces(root)["shroud 1"] - original["shroud 1"])) > 1e-4


@pytest.mark.parametrize("item, name, value, field", [
    ("hub_fractions", 1, (1.0, 0.5), "channel.hub_fractions"),  # outside (0, 1)
    ("shroud_fractions", 2, (0.5, 0.0), "channel.shroud_fractions"),
    ("hub_angle", 2, -30.0, "channel.hub_angle"),  # the corner tangents do not meet ahead of the bend
    ("hub_angle", 2, True, "channel.hub_angle"),  # Auto between two bends: no straight patch to take it from
    ("shroud_angle", 1, 5.0, "channel.shroud_angle"),  # does not match the straight inlet
])
def test_panel_refuses_bad_wall_values(impeller_modules, scene, item, name, value, field):
    bpy.ops.bladesmith.add_impeller(preset="high_flow", full_wheel=False)
    root = bpy.context.active_object
    s = root.bladesmith_impeller
    target = getattr(s, item)[name]
    if item.endswith("_angle") and not isinstance(value, bool):
        target.auto = False  # valid: the shown direction
        assert s.status == ""
    original, toml = _all_surfaces(root), root["definition_toml"]
    prop = "fractions" if item.endswith("_fractions") else "auto" if isinstance(value, bool) else "angle"
    setattr(target, prop, value)
    assert field in s.status
    assert root["definition_toml"] == toml and _same(_all_surfaces(root), original)  # the last good geometry


def test_panel_auto_off_keeps_the_geometry(impeller_modules, scene):
    """Turning Auto off writes the direction the channel used: on the presets' axial and
    radial patches 0.0 / 90.0 as shown; on inclined straight patches the float32 field
    cannot hold the direction to the definition's 1e-6 deg (93.57633 would be refused),
    so the shown value is written as the direction itself and the geometry is unchanged
    bit for bit."""
    bpy.ops.bladesmith.add_impeller(preset="high_flow", full_wheel=False)
    root = bpy.context.active_object
    s = root.bladesmith_impeller
    original = _all_surfaces(root)
    for wall in ("hub", "shroud"):
        for corner in getattr(s, f"{wall}_angle"):
            corner.auto = False
            assert s.status == ""
    assert _toml_line(root, "hub_angle") == "hub_angle = [0.0, 0.0, 50.0, 90.0, 90.0]"
    assert _same(_all_surfaces(root), original)
    for wall in ("hub", "shroud"):
        for k in (0, 1, 3, 4):
            getattr(s, f"{wall}_angle")[k].auto = True
    s.hub_r[0].value = 0.0  # the inlet hub becomes a cone at atan(0.04 / 0.06) = 33.69 deg
    s.shroud_z[4].value = -0.025  # the diffuser shroud leans back: 93.58 deg
    assert s.status == ""
    assert s.hub_angle[1].angle == pytest.approx(np.degrees(np.arctan2(0.04, 0.06)), abs=1e-5)  # the shown direction follows
    assert s.shroud_angle[3].angle == pytest.approx(np.degrees(np.arctan2(0.08, -0.005)), abs=1e-5)
    auto = _all_surfaces(root)
    s.hub_angle[1].auto = False
    s.shroud_angle[3].auto = False
    assert s.status == ""
    assert _same(_all_surfaces(root), auto)
    angles = __import__("tomllib").loads(root["definition_toml"])["channel"]
    assert angles["hub_angle"][1] == pytest.approx(33.69006752598, abs=1e-9)
    assert angles["shroud_angle"][3] == pytest.approx(93.576334375, abs=1e-8)
    assert _matches_reference(root)


def test_panel_walls_draws_bends_only(impeller_modules, scene):
    from types import SimpleNamespace

    panel = impeller_modules[1]

    class Layout:
        def __init__(self, parent=None, log=None):
            self.parent, self.enabled, self.log = parent, True, log if log is not None else []

        def _child(self, *args, **kwargs):
            return Layout(self, self.log)

        box = row = column = _child

        def label(self, text="", icon="NONE"):
            self.log.append(("label", text))

        def prop(self, data, name, **kwargs):
            assert name in data.bl_rna.properties, name
            on, node = True, self
            while node is not None:
                on, node = on and node.enabled, node.parent
            self.log.append(("prop", data.path_from_id(name), on))

    bpy.ops.bladesmith.add_impeller(preset="high_flow", full_wheel=False)
    context = SimpleNamespace(active_object=bpy.context.active_object)
    assert panel.BLADESMITH_PT_impeller_walls.poll(context)
    assert panel.BLADESMITH_PT_impeller_walls.bl_parent_id == panel.BLADESMITH_PT_impeller.bl_idname
    layout = Layout()
    panel.BLADESMITH_PT_impeller_walls.draw(SimpleNamespace(layout=layout), context)
    props = {path: on for kind, path, *on in layout.log if kind == "prop" for on in on}
    assert ("label", "Hub wall") in layout.log and ("label", "Shroud wall") in layout.log
    assert props["bladesmith_impeller.hub_angle[2].angle"] is True  # explicit: editable
    assert props["bladesmith_impeller.hub_angle[1].angle"] is False  # auto: shown, disabled
    assert props["bladesmith_impeller.hub_angle[1].auto"] is True
    fractions = sorted(p for p in props if p.endswith(".fractions"))
    assert fractions == [f"bladesmith_impeller.{w}_fractions[{j}].fractions" for w in ("hub", "shroud") for j in (1, 2)]


@pytest.mark.parametrize("name", ["HIGH_FLOW", "High_Flow", "high_flow.toml"])
def test_presets_are_matched_without_regard_to_case(impeller_modules, scene, name):
    # as the propeller and wind-blade presets are (issue 14)
    assert bpy.ops.bladesmith.add_impeller(preset=name, full_wheel=False) == {"FINISHED"}


def test_unknown_preset_is_refused_by_name(impeller_modules, scene):
    before = len(bpy.data.objects)
    with pytest.raises(RuntimeError, match="unknown preset 'no_such_wheel'"):
        bpy.ops.bladesmith.add_impeller(preset="no_such_wheel")
    assert len(bpy.data.objects) == before


def test_panel_splitter_edits_reuse_the_nets_of_sizes_shown_before(impeller_modules, scene, monkeypatch):
    """A splitter LE edit changes the splitter's patch count, so its nets change size, which
    Blender allows only through edit mode (make_segment). Going back to a size shown
    before takes the curve data kept for it: no edit-mode rebuild, and every child still
    shows the independent build exactly (stored data valid), the linked copies of the full
    wheel included. A part that changes to a size not shown before copies the data of a
    part just rebuilt to it (S, P and B share the patch count)."""
    from bladesmith.operators import nurbs_objects

    ops = impeller_modules[0]
    bpy.ops.bladesmith.add_impeller(preset="high_flow", full_wheel=True)
    root = bpy.context.active_object
    s = root.bladesmith_impeller
    s.splitter = True
    rebuilds = []
    editing = nurbs_objects._editing
    monkeypatch.setattr(nurbs_objects, "_editing", lambda obj: rebuilds.append(obj.name) or editing(obj))
    sizes = {}
    for round_ in range(2):
        for value in (1.6, 1.55):
            rebuilds.clear()
            s.splitter_leading_edge_hub = value
            assert s.status == ""
            children = {c["bladesmith_part"]: c for c in root.children}
            _, reference = _standardised_reference(root)
            for name, surface in reference.items():
                (shown,) = nurbs_objects.stored_geometry(children[name])
                assert np.array_equal(shown.control_points, surface.control_points), name
            first = children["splitter 1 S"]
            assert all(children[f"splitter {k} S"].data is first.data for k in range(2, s.blade_count + 1))
            sizes.setdefault(value, set()).add(ops._net_of(first.data))
            # first round: one net rebuilt, the other parts of that size copy it; then none
            assert len(rebuilds) <= (0 if round_ else 1), rebuilds
    assert len(sizes[1.6]) == len(sizes[1.55]) == 1 and sizes[1.6] != sizes[1.55]


def test_blades_display_their_rulings_walls_their_arcs(impeller_modules, scene):
    """Blade parts (one linear segment in v: S, P, B, caps) are evaluated by Blender with
    resolution 1 along v: three rows of points (v = 0, 1/2, 1 of the net with its midpoint
    column), on the straight rulings, which are the surface's own; a full wheel's Z linked
    copies tessellate a third of the rows of resolution 3. Walls keep SURFACE_RESOLUTION
    both ways."""
    from bladesmith.operators.nurbs_objects import stored_geometry

    ops = impeller_modules[0]
    bpy.ops.bladesmith.add_impeller(preset="high_flow", full_wheel=False)
    root = bpy.context.active_object
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for child in root.children:
        if child.type != "SURFACE":
            continue
        spline = child.data.splines[0]
        part = child["bladesmith_part"]
        if part.startswith(("hub", "shroud")):
            assert (spline.resolution_u, spline.resolution_v) == (ops.SURFACE_RESOLUTION,) * 2, part
            continue
        assert (spline.resolution_u, spline.resolution_v) == (ops.SURFACE_RESOLUTION, 1), part
        (surface,) = stored_geometry(child)
        u = np.linspace(*surface.knots_u[[0, -1]], 4001)
        edges = [surface.evaluate(u, np.full_like(u, v)) for v in (0.0, 0.5, 1.0)]
        mesh = child.evaluated_get(depsgraph).to_mesh()
        X = np.array([v.co[:] for v in mesh.vertices])
        child.evaluated_get(depsgraph).to_mesh_clear()
        near = np.min([np.min(np.linalg.norm(X[:, None] - E[None, ::8], axis=-1), axis=1) for E in edges], axis=0)
        assert near.max() < 1e-3, part  # every drawn point on one of the rows (to the sample spacing)
