"""bpy.ops.bladesmith.add_propeller, the propeller panel's live regeneration, the TOML
load/save operators, and what survives saving a .blend file."""
import math
import pathlib
import tomllib
from dataclasses import replace

import bpy
import numpy as np
import pytest

from bladesmith.geometry.nurbs import BSplineSurface
from bladesmith.geometry.propeller import Propeller, dumps_toml
from bladesmith.geometry.propeller.definition import SMOOTHING_KEYS
from bladesmith.geometry.propeller.display import blade_display_surface, hub_surface
from bladesmith.operators import propeller as ops
from bladesmith.operators.nurbs_objects import PROPERTY_KEY, stored_geometry

PRESETS = pathlib.Path(__file__).resolve().parents[2] / "data" / "propellers"


def snapshot():
    """What a refused operator must leave untouched."""
    return {
        kind: {item.name for item in getattr(bpy.data, kind)}
        for kind in ("objects", "meshes", "curves", "collections")
    }


def roots():
    return [obj for obj in bpy.data.objects if ops.find_root(obj) is obj]


def parts(root):
    return ops.propeller_parts(root)


def blade_surface(root) -> BSplineSurface:
    (surface,) = stored_geometry(parts(root)[("blade", 0, 0)])
    return surface


def preset_dict(name="dtmb4119"):
    with open(PRESETS / f"{name}.toml", "rb") as fh:
        return tomllib.load(fh)


def write_definition(tmp_path, data, name="bad.toml"):
    path = tmp_path / name
    path.write_text(dumps_toml(data))
    return path


# -- the operator ---------------------------------------------------------------------------
def test_add_propeller_builds_root_blade_copies_and_hub(scene):
    assert bpy.ops.bladesmith.add_propeller(preset="DTMB4119") == {"FINISHED"}
    (root,) = roots()
    assert root.type == "EMPTY" and root.name == "DTMB 4119"
    p = parts(root)
    assert set(p) == {("blade", 0, 0), ("blade", 0, 1), ("blade", 0, 2), ("hub", 0, 0)}
    reference = p[("blade", 0, 0)]
    model = Propeller.from_toml(PRESETS / "dtmb4119.toml").build()
    for k in (1, 2):
        copy = p[("blade", 0, k)]
        assert copy.data == reference.data, "copies are linked duplicates"
        assert copy.parent == root
        # the copy's world transform is the model's blade rotation
        rotation = np.array(copy.matrix_world.to_3x3())
        assert np.allclose(rotation, model.blade_rotation(k), atol=1e-6)
    assert all(obj.type == "SURFACE" for obj in p.values())
    # the stored float64 surfaces are the display fit and the exact hub
    tol = ops.DISPLAY_TOLERANCE_FRACTION * model.definition.diameter
    expected = blade_display_surface(model.blade, tol).surface
    got = blade_surface(root)
    assert np.array_equal(got.control_points, expected.control_points)
    (hub,) = stored_geometry(p[("hub", 0, 0)])
    exact = hub_surface(model.hub)
    assert np.array_equal(hub.control_points, exact.control_points) and np.array_equal(hub.weights, exact.weights)
    s = root.bladesmith_propeller
    assert not s.status_is_error and 0 <= s.display_deviation <= tol
    assert Propeller.from_dict(tomllib.loads(s.definition_toml)) == model.definition


def test_blender_shows_the_blade_within_the_display_tolerance(scene):
    bpy.ops.bladesmith.add_propeller(preset="dtmb4119")
    (root,) = roots()
    blade = parts(root)[("blade", 0, 0)]
    evaluated = blade.evaluated_get(bpy.context.evaluated_depsgraph_get())
    mesh = evaluated.to_mesh()
    try:
        verts = np.array([v.co for v in mesh.vertices])
    finally:
        evaluated.to_mesh_clear()
    model = Propeller.from_toml(PRESETS / "dtmb4119.toml").build()
    R = model.blade.radius
    r = np.hypot(verts[:, 0], verts[:, 1])
    tol = ops.DISPLAY_TOLERANCE_FRACTION * model.definition.diameter + 1e-6 * R
    # every shown point lies on a cylinder r = ηR of the blade span, near the blade's section there
    assert r.min() >= model.blade.hub_ratio * R - tol and r.max() <= R + tol
    dense = model.blade.sample(400, 200)
    lo, hi = dense.reshape(-1, 3).min(axis=0), dense.reshape(-1, 3).max(axis=0)
    assert np.all(verts.min(axis=0) >= lo - tol) and np.all(verts.max(axis=0) <= hi + tol)


@pytest.mark.parametrize("name", ["dtmb4119", "DTMB4119", "Skewed_Demo", "raked_demo.toml"])
def test_preset_names_are_case_insensitive(scene, name):
    assert bpy.ops.bladesmith.add_propeller(preset=name) == {"FINISHED"}
    assert len(roots()) == 1


def test_preset_enum_lists_the_shipped_files():
    keys = {item[0] for item in ops.PRESET_ITEMS}
    assert keys == {path.stem.upper() for path in PRESETS.glob("*.toml")}
    assert "DTMB4119" in keys


def test_definition_file_and_left_hand(scene, tmp_path):
    data = preset_dict("skewed_demo")
    data["hand"] = "left"
    data["blades"] = 5
    path = write_definition(tmp_path, data, "left.toml")
    assert bpy.ops.bladesmith.add_propeller(definition=str(path)) == {"FINISHED"}
    (root,) = roots()
    assert len([key for key in parts(root) if key[0] == "blade"]) == 5
    assert root.bladesmith_propeller.hand == "LEFT"


def _bad(key, value):
    def change(data):
        if "." in key:
            table, field = key.split(".")
            entry = data.setdefault(table, {})
            if isinstance(value, tuple):  # (index, value) in an array
                entry[field][value[0]] = value[1]
            else:
                entry[field] = value
        else:
            data[key] = value
        return data

    return change


def _thickness_table(data):
    data["section"] = {
        "thickness": "table",
        "meanline": "a=0.8",
        "thickness_x_c": [0.0, 0.25, 0.5, 0.75, 1.0],
        "thickness_t": [0.0, 0.8, -0.2, 0.6, 0.0],
    }
    return data


INVALID = {
    # case: (change, field named, value named)
    "non-increasing r_R": (_bad("radial.r_R", (3, 0.4)), "radial.r_R", "0.4"),
    "negative chord": (_bad("radial.c_D", (2, -0.1)), "radial.c_D", "-0.1"),
    "NaN": (_bad("radial.P_D", (4, float("nan"))), "radial.P_D", "nan"),
    "self-intersecting thickness table": (_thickness_table, "section.thickness_t", "-0.2"),
    "missing airfoil file": (_bad("section.thickness", "no_such_airfoil.dat"), "section.thickness", "no_such_airfoil.dat"),
    "hub radius >= tip radius": (_bad("hub_diameter_ratio", 1.0), "hub_diameter_ratio", "1.0"),
}


@pytest.mark.parametrize("case", list(INVALID))
def test_invalid_definitions_are_refused_and_nothing_is_created(scene, tmp_path, case):
    change, field, value = INVALID[case]
    path = write_definition(tmp_path, change(preset_dict()))
    bpy.ops.bladesmith.add_propeller(preset="dtmb4119")  # something already in the scene
    before = snapshot()
    with pytest.raises(RuntimeError) as info:
        bpy.ops.bladesmith.add_propeller(definition=str(path))
    message = str(info.value)
    assert field in message and value in message, message
    assert snapshot() == before


def test_unknown_preset_and_bad_settings_are_refused(scene):
    before = snapshot()
    with pytest.raises(RuntimeError, match="preset.*'NoSuchProp'"):
        bpy.ops.bladesmith.add_propeller(preset="NoSuchProp")
    with pytest.raises(RuntimeError, match="transition_s.*1.5"):
        bpy.ops.bladesmith.add_propeller(preset="dtmb4119", transition_s=1.5)
    with pytest.raises(RuntimeError, match="display_tolerance"):
        bpy.ops.bladesmith.add_propeller(preset="dtmb4119", display_tolerance=0.0)
    assert snapshot() == before


def test_smoothed_result_plugs_in_as_patches_with_copies(scene, monkeypatch):
    """The smoothed path: the five surfaces become one object per patch, each with its
    Z - 1 linked copies; the settings reach the pipeline in metres (the operator's
    lengths are fractions of D); switching smoothing off leaves one blade patch."""
    seen = {}
    real = ops.smooth_blade

    def recording(model, settings, **kwargs):
        seen.update(settings)
        return real(model, settings, **kwargs)

    monkeypatch.setattr(ops, "smooth_blade", recording)
    assert bpy.ops.bladesmith.add_propeller(preset="dtmb4119", smooth_tip=True, delta_c=0.02) == {"FINISHED"}
    (root,) = roots()
    keys = set(parts(root))
    assert {("blade", patch, k) for patch in range(5) for k in range(3)} <= keys
    assert parts(root)[("blade", 1, 2)].data == parts(root)[("blade", 1, 0)].data
    assert seen["delta_c"] == pytest.approx(0.02 * 0.3048)
    before_curves = len(bpy.data.curves)
    root.bladesmith_propeller.smooth_tip = False
    assert not root.bladesmith_propeller.status_is_error
    assert not any(key[1] >= 1 for key in parts(root) if key[0] == "blade")
    assert len(bpy.data.curves) == before_curves - 4


def test_smooth_tip_with_the_real_smoothing(scene):
    assert bpy.ops.bladesmith.add_propeller(preset="dtmb4119", smooth_tip=True) == {"FINISHED"}
    (root,) = roots()
    patches = {key[1] for key in parts(root) if key[0] == "blade"}
    assert len(patches) >= 2
    assert all(("blade", patch, k) in parts(root) for patch in patches for k in range(3))


def test_operators_that_change_data_support_undo():
    for op in (
        bpy.ops.bladesmith.add_propeller,
        bpy.ops.bladesmith.regenerate_propeller,
        bpy.ops.bladesmith.load_propeller_definition,
        bpy.ops.bladesmith.propeller_row_add,
        bpy.ops.bladesmith.propeller_row_remove,
    ):
        assert {"REGISTER", "UNDO"} <= set(op.bl_options), op


# -- the panel: live regeneration ----------------------------------------------------------
@pytest.fixture
def root(scene):
    bpy.ops.bladesmith.add_propeller(preset="dtmb4119")
    (obj,) = roots()
    return obj


def _ids(root):
    return {key: (obj.as_pointer(), obj.data.as_pointer()) for key, obj in parts(root).items()}


def test_editing_a_value_regenerates_in_place(root):
    s = root.bladesmith_propeller
    ids = _ids(root)
    before = blade_surface(root).control_points
    s.radial[5].P_D = 1.2
    assert not s.status_is_error, s.status
    after = blade_surface(root).control_points
    assert before.shape != after.shape or not np.allclose(before, after)
    assert _ids(root) == ids, "the same objects and curve data-blocks are reused"
    # the shown blade is the display fit of the edited definition
    edited = ops.settings_to_definition(s)
    assert edited.radial.P_D[5] == 1.2
    xi, v = np.random.default_rng(1).random((2, 4000))
    S = blade_surface(root)
    tol = s.display_tolerance * edited.diameter
    model = edited.build()
    from bladesmith.geometry.propeller.display import eta_of_v

    dev = np.linalg.norm(S.evaluate(xi, v) - model.blade.evaluate(xi, eta_of_v(v, model.blade.hub_ratio, True)), axis=-1)
    assert dev.max() <= tol
    # the stored definition follows
    assert tomllib.loads(s.definition_toml)["radial"]["P_D"][5] == 1.2


@pytest.mark.parametrize(
    "edit, field, value",
    [
        (lambda s: setattr(s.radial[3], "r_R", 0.3), "radial.r_R", "0.3"),
        (lambda s: setattr(s.radial[2], "c_D", -0.1), "radial.c_D", "-0.1"),
        (lambda s: setattr(s.radial[4], "t_c", float("nan")), "radial.t_c", "nan"),
        (lambda s: setattr(s, "hub_diameter_ratio", 1.0), "hub_diameter_ratio", "1.0"),
        (lambda s: setattr(s, "thickness_kind", "FILE"), "section.thickness", "''"),
        (lambda s: setattr(s, "transition_s", 0.0), "transition_s", "0.0"),
    ],
)
def test_invalid_panel_edit_keeps_the_geometry_and_reports(root, edit, field, value):
    s = root.bladesmith_propeller
    before_points = blade_surface(root).control_points.copy()
    before = snapshot()
    edit(s)
    assert s.status_is_error
    assert field in s.status and value in s.status, s.status
    assert np.array_equal(blade_surface(root).control_points, before_points)
    assert snapshot() == before


def test_panel_recovers_after_an_invalid_edit(root):
    s = root.bladesmith_propeller
    s.radial[2].c_D = -0.1
    assert s.status_is_error
    s.radial[2].c_D = 0.41
    assert not s.status_is_error
    assert ops.settings_to_definition(s).radial.c_D[2] == 0.41


def test_blade_count_adds_and_removes_linked_copies(root):
    s = root.bladesmith_propeller
    curves = len(bpy.data.curves)
    s.blades = 5
    assert sorted(k for part, _, k in parts(root) if part == "blade") == [0, 1, 2, 3, 4]
    copy = parts(root)[("blade", 0, 4)]
    assert copy.rotation_euler.z == pytest.approx(-2 * math.pi * 4 / 5)
    s.blades = 2
    assert sorted(k for part, _, k in parts(root) if part == "blade") == [0, 1]
    assert len(bpy.data.curves) == curves
    assert len(bpy.data.objects) == 1 + 2 + 1


def test_radial_rows_add_and_remove(root):
    s = root.bladesmith_propeller
    bpy.context.view_layer.objects.active = root
    s.radial_index = 5
    r5, r6 = s.radial[5].r_R, s.radial[6].r_R
    assert bpy.ops.bladesmith.propeller_row_add(table="RADIAL") == {"FINISHED"}
    assert len(s.radial) == 11 and s.radial_index == 6
    assert s.radial[6].r_R == pytest.approx(0.5 * (r5 + r6))
    assert not s.status_is_error, s.status
    for _ in range(8):
        s.radial_index = 1  # interior rows: root and tip stay
        bpy.ops.bladesmith.propeller_row_remove(table="RADIAL")
    assert len(s.radial) == 3 and not s.status_is_error, s.status
    s.radial_index = 0
    bpy.ops.bladesmith.propeller_row_remove(table="RADIAL")
    assert s.status_is_error and "radial.r_R" in s.status and "2" in s.status


def test_hub_and_section_edits(root):
    s = root.bladesmith_propeller
    (hub_before,) = stored_geometry(parts(root)[("hub", 0, 0)])
    s.hub_nose_shape = "CONE"
    assert not s.status_is_error, s.status
    (hub_after,) = stored_geometry(parts(root)[("hub", 0, 0)])
    assert not np.allclose(hub_before.control_points, hub_after.control_points)
    s.meanline = "PARABOLIC"
    assert not s.status_is_error, s.status
    bpy.context.view_layer.objects.active = root
    s.thickness_kind = "TABLE"  # an empty table
    assert s.status_is_error and "section.thickness" in s.status
    for _ in range(5):
        bpy.ops.bladesmith.propeller_row_add(table="THICKNESS")
    for row, (x, t) in zip(s.thickness_table, [(0.0, 0.0), (0.2, 0.8), (0.45, 1.0), (0.8, 0.5), (1.0, 0.0)]):
        row.x_c, row.value = x, t
    assert not s.status_is_error, s.status


# -- TOML and .blend ---------------------------------------------------------------------------
def test_save_and_load_definition(root, tmp_path):
    bpy.context.view_layer.objects.active = root
    path = tmp_path / "saved.toml"
    assert bpy.ops.bladesmith.save_propeller_definition(filepath=str(path)) == {"FINISHED"}
    saved = Propeller.from_toml(path)
    # float32 panel values come back as the decimals of the file; Save adds [smoothing]
    assert set(saved.smoothing) == set(SMOOTHING_KEYS)
    assert replace(saved, smoothing=None) == Propeller.from_toml(PRESETS / "dtmb4119.toml")
    ids = _ids(root)
    assert bpy.ops.bladesmith.load_propeller_definition(filepath=str(PRESETS / "raked_demo.toml")) == {"FINISHED"}
    s = root.bladesmith_propeller
    assert s.definition_name == Propeller.from_toml(PRESETS / "raked_demo.toml").name
    assert ("hub", 0, 0) in parts(root) and _ids(root)[("hub", 0, 0)] == ids[("hub", 0, 0)]
    # a bad file changes nothing
    bad = tmp_path / "bad.toml"
    bad.write_text("name = 'x'\nblades = 3\n")
    before = (snapshot(), s.definition_toml)
    with pytest.raises(RuntimeError, match="diameter"):
        bpy.ops.bladesmith.load_propeller_definition(filepath=str(bad))
    assert (snapshot(), s.definition_toml) == before


#: A value for every smoothing setting of the panel, none its default, valid for DTMB 4119
#: (lengths as fractions of D).
SMOOTHING_EDITS = {
    "smooth_tip": True, "delta_c": 0.012, "tip_smoothing_distance": 0.045, "edge_smoothing_distance": 0.03,
    "transition_s": 0.8, "filter_strength": 0.4, "filter_iterations": 80, "tolerance": 2e-5,
    "sample_spacing": 0.004, "edge_spacing_ratio": 0.02, "xi_ll": 0.12, "xi_lr": 0.38, "xi_ul": 0.11,
    "eta_ul": 0.88, "xi_ur": 0.39, "eta_ur": 0.89, "eta_le": 0.91, "eta_te": 0.92,
}


def _smoothing_of(settings) -> dict:
    return {name: getattr(settings, name) for name in SMOOTHING_EDITS}


def _same(a: dict, b: dict):
    for name in SMOOTHING_EDITS:
        assert a[name] == pytest.approx(b[name], rel=1e-6), (name, a[name], b[name])


def test_save_writes_all_smoothing_settings_and_they_come_back(root, tmp_path):
    """Issue 15: Save writes every smoothing setting (Δc, d_t, d_e, s_j, α, n, tolerance,
    d, h/d, the six defining points of Hally Fig. 4, smooth_tip) into [smoothing], lengths
    in metres; add_propeller(definition=...) and Load read all of them back."""
    assert set(SMOOTHING_EDITS) == set(ops.SMOOTHING_FIELDS) | {"smooth_tip"}
    s = root.bladesmith_propeller
    with ops.suspended_updates():
        for name, value in SMOOTHING_EDITS.items():
            setattr(s, name, value)
    bpy.context.view_layer.objects.active = root
    path = tmp_path / "smoothing.toml"
    assert bpy.ops.bladesmith.save_propeller_definition(filepath=str(path)) == {"FINISHED"}
    table = tomllib.loads(path.read_text())["smoothing"]
    assert set(table) == set(SMOOTHING_KEYS)
    D = 0.3048
    assert table["delta_c"] == pytest.approx(0.012 * D) and table["sample_spacing"] == pytest.approx(0.004 * D)
    assert table["smooth_tip"] is True and table["filter_iterations"] == 80 and table["eta_te"] == 0.92
    # a new propeller from the file: every setting as saved, and the pipeline ran with them
    assert bpy.ops.bladesmith.add_propeller(definition=str(path)) == {"FINISHED"}
    new = bpy.context.view_layer.objects.active
    assert new != root and new.bladesmith_propeller.smooth_tip
    _same(_smoothing_of(new.bladesmith_propeller), SMOOTHING_EDITS)
    assert len({key[1] for key in parts(new) if key[0] == "blade"}) == 5
    # what the call sets wins over the file
    assert bpy.ops.bladesmith.add_propeller(definition=str(path), smooth_tip=False, xi_ll=0.13) == {"FINISHED"}
    third = bpy.context.view_layer.objects.active.bladesmith_propeller
    assert not third.smooth_tip and third.xi_ll == pytest.approx(0.13) and third.xi_lr == pytest.approx(0.38)
    # Load into a propeller with other settings: the file's settings replace them
    with ops.suspended_updates():
        for name in SMOOTHING_EDITS:
            root.bladesmith_propeller.property_unset(name)
    assert root.bladesmith_propeller.xi_ll == pytest.approx(0.1)
    bpy.context.view_layer.objects.active = root
    assert bpy.ops.bladesmith.load_propeller_definition(filepath=str(path)) == {"FINISHED"}
    _same(_smoothing_of(root.bladesmith_propeller), SMOOTHING_EDITS)


def test_bad_smoothing_values_in_a_file_are_refused(scene, tmp_path):
    data = preset_dict()
    data["smoothing"] = {"xi_lr": 0.6}
    path = write_definition(tmp_path, data)
    before = snapshot()
    with pytest.raises(RuntimeError, match=r"bad.toml.*smoothing.xi_lr.*0.6"):
        bpy.ops.bladesmith.add_propeller(definition=str(path))
    assert snapshot() == before
    with pytest.raises(RuntimeError, match=r"field 'edge_spacing_ratio'.*1.5"):
        bpy.ops.bladesmith.add_propeller(preset="dtmb4119", edge_spacing_ratio=1.5)
    with pytest.raises(RuntimeError, match=r"field 'eta_le'.*1.2"):
        bpy.ops.bladesmith.add_propeller(preset="dtmb4119", eta_le=1.2)
    assert snapshot() == before


def test_load_without_a_propeller_adds_one(scene):
    assert bpy.ops.bladesmith.load_propeller_definition(filepath=str(PRESETS / "skewed_demo.toml")) == {"FINISHED"}
    assert len(roots()) == 1


def test_blend_file_keeps_the_definition(root, tmp_path):
    s = root.bladesmith_propeller
    s.radial[5].P_D = 1.15
    surface = blade_surface(root)
    toml_text = s.definition_toml
    path = tmp_path / "prop.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))
    (reopened,) = roots()
    r = reopened.bladesmith_propeller
    assert r.definition_toml == toml_text and r.radial[5].P_D == pytest.approx(1.15)
    again = blade_surface(reopened)
    assert np.array_equal(again.control_points, surface.control_points)
    copy = ops.propeller_parts(reopened)[("blade", 0, 1)]
    assert copy.get(PROPERTY_KEY) is not None and stored_geometry(copy) is not None
    # and it keeps regenerating
    r.radial[5].P_D = 1.1
    assert not r.status_is_error, r.status


# -- the panel's draw code, against a recording layout -------------------------------------
class RecordingLayout:
    """Stands in for UILayout: every property, operator and list the panel draws must exist."""

    def __init__(self, calls):
        self.calls = calls

    def __getattr__(self, name):
        if name in ("row", "column", "box", "split", "column_flow"):
            return lambda *args, **kwargs: RecordingLayout(self.calls)
        return None

    def __setattr__(self, name, value):
        object.__setattr__(self, name, value)

    def prop(self, data, name, **kwargs):
        assert name in data.bl_rna.properties, f"{data} has no property {name!r}"
        self.calls.append(("prop", name))

    def label(self, **kwargs):
        self.calls.append(("label", kwargs.get("text")))

    def operator(self, idname, **kwargs):
        module, name = idname.split(".")
        assert hasattr(getattr(bpy.ops, module), name), idname
        self.calls.append(("operator", idname))
        return type("Properties", (), {})()

    def operator_menu_enum(self, idname, prop, **kwargs):
        module, name = idname.split(".")
        assert prop in getattr(getattr(bpy.ops, module), name).get_rna_type().properties
        self.calls.append(("operator_menu_enum", idname))

    def template_list(self, list_type, list_id, data, collection, active_data, active_prop, **kwargs):
        assert hasattr(bpy.types, list_type), list_type
        assert collection in data.bl_rna.properties and active_prop in active_data.bl_rna.properties
        self.calls.append(("template_list", collection))


def test_panels_draw_existing_properties_and_operators(root):
    from bladesmith.ui import propeller_panel as panel

    bpy.context.view_layer.objects.active = root
    s = root.bladesmith_propeller
    s.thickness_kind = "TABLE"
    s.meanline = "TABLE"
    calls = []
    for cls in (
        panel.BLADESMITH_PT_propeller,
        panel.BLADESMITH_PT_propeller_radial,
        panel.BLADESMITH_PT_propeller_section,
        panel.BLADESMITH_PT_propeller_hub,
        panel.BLADESMITH_PT_propeller_smoothing,
        panel.BLADESMITH_PT_propeller_smoothing_advanced,
        panel.BLADESMITH_PT_propeller_display,
    ):
        fake = type("FakePanel", (), {"layout": RecordingLayout(calls)})()
        if issubclass(cls, panel._Sub):
            assert cls.poll(bpy.context)
        if hasattr(cls, "draw_header"):
            cls.draw_header(fake, bpy.context)
        cls.draw(fake, bpy.context)
    drawn = {name for kind, name in calls if kind == "prop"}
    assert {"blades", "diameter", "hub_diameter_ratio", "hand", "thickness_kind", "meanline",
            "hub_nose_shape", "display_tolerance", "smooth_tip", "show_overlay", *ops.SMOOTHING_FIELDS} <= drawn
    assert {"radial", "thickness_table", "meanline_table"} <= {name for kind, name in calls if kind == "template_list"}
    # the radial list draws every column of a row
    row_calls = []
    panel.BLADESMITH_UL_radial.draw_item(None, bpy.context, RecordingLayout(row_calls), s, s.radial[0], 0, s, "radial_index")
    assert [name for _, name in row_calls] == list(ops.RADIAL_FIELDS)


def test_smoothed_report_and_overlay(scene):
    """The report gives the cuts, the knots and the deviation from the unsmoothed blade;
    the optional overlay shows the cuts, c_LETE and the transition cut j, and goes away
    when switched off."""
    assert bpy.ops.bladesmith.add_propeller(preset="dtmb4119", smooth_tip=True, show_overlay=True) == {"FINISHED"}
    (root,) = roots()
    status = root.bladesmith_propeller.status
    assert "tip" in status and "control points per curve" in status
    assert "deviation from the unsmoothed blade" in status and "outside the smoothing zone" in status
    overlays = {key[1]: obj for key, obj in parts(root).items() if key[0] == "overlay"}
    assert set(overlays) == {0, 1, 2}
    assert len(overlays[0].data.splines) == 42 * 3  # tip, LE and TE curves of DTMB 4119
    assert len(overlays[1].data.splines) == 1 and len(overlays[2].data.splines) == 2
    assert all(o.hide_render for o in overlays.values())
    root.bladesmith_propeller.show_overlay = False
    assert not any(key[0] == "overlay" for key in parts(root))
