"""Issue 20: bad input through the operators is refused (ERROR report, CANCELLED) with the
file, field and value named, and the scene is exactly as before: the same objects, data
blocks and collections. A requested tolerance that is missed is a warning with figures."""
import math
import pathlib
import tomllib

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

from bladesmith.geometry.propeller import Propeller  # noqa: E402
from bladesmith.geometry.propeller.definition import dumps_toml  # noqa: E402
from bladesmith.geometry.nurbs import BSplineSurface, clamped_uniform_knots  # noqa: E402
from bladesmith.operators import curvature_review as cr  # noqa: E402
from bladesmith.operators import propeller as prop_op  # noqa: E402
from bladesmith.operators.import_airfoil import AIRFOIL_KEY  # noqa: E402
from bladesmith.operators.nurbs_objects import surface_to_object  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared" / "data"
PROPELLER = ROOT / "data" / "propellers" / "dtmb4119.toml"
WIND = ROOT / "data" / "blades" / "s823_small.toml"
IMPELLER = ROOT / "data" / "impellers" / "high_flow.toml"
KINDS = ("objects", "curves", "meshes", "collections", "materials", "images", "scenes", "cameras", "worlds")

ADD = {
    "propeller": lambda path: bpy.ops.bladesmith.add_propeller(definition=str(path)),
    "wind": lambda path: bpy.ops.bladesmith.add_wind_blade(definition=str(path)),
    "impeller": lambda path: bpy.ops.bladesmith.add_impeller(definition=str(path)),
}


def state():
    """Every data-block by kind, with what a refusal must not change."""
    out = {kind: sorted(b.name for b in getattr(bpy.data, kind)) for kind in KINDS}
    out["links"] = sorted((c.name, o.name) for c in bpy.data.collections for o in c.objects)
    out["scene"] = sorted(o.name for o in bpy.context.scene.collection.objects)
    return out


def refused(call, *words):
    """``call()`` is refused with every one of ``words`` in the message and the scene
    unchanged."""
    before = state()
    with pytest.raises(RuntimeError) as err:  # an ERROR report and CANCELLED
        call()
    for word in words:
        assert str(word) in str(err.value), str(err.value)
    assert state() == before
    return str(err.value)


def _write(tmp_path, name, data):
    path = tmp_path / name
    path.write_text(dumps_toml(data))
    return path


def _changed(tmp_path, source, **changes):
    data = tomllib.loads(source.read_text())
    for key, value in changes.items():
        if "__" in key:
            table, field = key.split("__")
            data[table][field] = value
        else:
            data[key] = value
    path = tmp_path / source.name
    if source is WIND:
        import shutil

        shutil.copytree(source.parent / "airfoils", tmp_path / "airfoils", dirs_exist_ok=True)
    path.write_text(dumps_toml(data))
    return path


def _existing_objects():
    """Something in the scene that a refusal must leave alone."""
    bpy.ops.mesh.primitive_cube_add()
    data = bpy.data.curves.new("keep", "CURVE")
    bpy.context.scene.collection.objects.link(bpy.data.objects.new("keep", data))


# -- definitions through the add operators -----------------------------------------------------
@pytest.mark.parametrize("kind", sorted(ADD))
def test_invalid_utf8_definition(scene, tmp_path, kind):
    _existing_objects()
    bad = tmp_path / "latin1.toml"
    bad.write_bytes('name = "h\xe9lice"\n'.encode("latin-1"))
    refused(lambda: ADD[kind](bad), "latin1.toml", "not UTF-8", "0xe9")


@pytest.mark.parametrize("kind", sorted(ADD))
def test_directory_as_definition(scene, tmp_path, kind):
    refused(lambda: ADD[kind](tmp_path), str(tmp_path), "is a directory")


def test_directory_and_binary_radial_table(scene, tmp_path):
    (tmp_path / "folder").mkdir()
    (tmp_path / "binary.csv").write_bytes(bytes(range(256)))
    data = tomllib.loads(PROPELLER.read_text())
    del data["radial"]
    for table, words in (("folder", ("is a directory",)), ("binary.csv", ("binary data", "NUL byte"))):
        data["radial_table"] = table
        path = _write(tmp_path, "p.toml", data)
        refused(lambda: ADD["propeller"](path), "p.toml", "radial_table", table, *words)


@pytest.mark.parametrize("changes, words", [
    ({"channel__degrees": ["x"]}, ("channel.degrees", "'x'")),
    ({"channel__degrees": 5}, ("channel.degrees", "5")),
    ({"channel__degrees": [math.nan, 4, 4, 1]}, ("channel.degrees", "nan")),
    ({"channel__degrees": [1.5, 4, 4, 1]}, ("channel.degrees", "1.5")),
    ({"channel__degrees": ["1", "4", "4", "1"]}, ("channel.degrees", "'1'")),
    ({"channel__hub_angle": 5}, ("channel.hub_angle", "5")),
    ({"splitter": 5}, ("splitter", "expected a table")),
    ({"blade__count": 1000}, ("blade.count", "MAX_BLADES", "1000")),
    ({"blade__patches": 100000}, ("blade.patches", "MAX_BLADE_PATCHES", "100000")),
    ({"blade__beta_hub": [-30.0] * 1_000_000}, ("MAX_FILE_BYTES",)),  # 7 MB: refused before parsing
    ({"blade__beta_hub": [-30.0] * 100_000}, ("blade.beta_hub", "MAX_COEFFICIENTS", "100000")),
    ({"blade__paches": 6}, ("blade.paches", "did you mean 'patches'")),
])
def test_bad_impeller(scene, tmp_path, changes, words):
    path = _changed(tmp_path, IMPELLER, **changes)
    refused(lambda: ADD["impeller"](path), "high_flow.toml", *words)


@pytest.mark.parametrize("changes, words", [
    ({"section": 5}, ("section", "expected a table")),
    ({"diameter": 1e308}, ("diameter", "1e+308")),
    ({"diameter": 1e20}, ("diameter", "1e+20")),  # used to hang curve.make_segment
    ({"blades": 1000}, ("blades", "MAX_BLADES")),
    ({"diamter": 0.3}, ("diamter", "did you mean 'diameter'")),
])
def test_bad_propeller(scene, tmp_path, changes, words):
    path = _changed(tmp_path, PROPELLER, **changes)
    refused(lambda: ADD["propeller"](path), "dtmb4119.toml", *words)


def test_propeller_skew_1e6(scene, tmp_path):
    data = tomllib.loads(PROPELLER.read_text())
    data["radial"]["skew_deg"][3] = 1e6
    path = _write(tmp_path, "p.toml", data)
    refused(lambda: ADD["propeller"](path), "radial.skew_deg", "MAX_SKEW_DEG", "1000000.0")


@pytest.mark.parametrize("changes, words", [
    ({"hub_radius": -5.0}, ("hub_radius", "-5.0")),
    ({"stations__pitch_axis": [0.5, 0.5, 50.0, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3]}, ("stations.pitch_axis[2]", "50.0")),
    ({"stations__twist_deg": [18.0, 18.0, 1e300, 12.0, 8.5, 6.0, 4.0, 3.0, 2.5]}, ("stations.twist_deg[2]",
                                                                                     "1e+300")),
    ({"control_points": 1_000_000}, ("control_points", "MAX_START_CONTROL_POINTS")),
    ({"stations__prebnd": [0.0] * 9}, ("stations.prebnd", "did you mean 'prebend'")),
])
def test_bad_wind_blade(scene, tmp_path, changes, words):
    path = _changed(tmp_path, WIND, **changes)
    refused(lambda: ADD["wind"](path), "s823_small.toml", *words)


def test_wind_operator_control_points_bounded(scene):
    refused(lambda: bpy.ops.bladesmith.add_wind_blade(preset="S823_SMALL", control_points=1_000_000),
            "control_points", "MAX_START_CONTROL_POINTS")


# -- tolerances: a miss is a warning with figures ---------------------------------------------
def test_missed_propeller_tolerance_is_reported_with_figures(scene):
    propeller = Propeller.from_toml(PROPELLER)
    rna = bpy.ops.bladesmith.add_propeller.get_rna_type().properties
    smoothing = {name: rna[name].default for name in prop_op.SMOOTHING_FIELDS}
    smoothing["tolerance"] = 1e-7
    result = prop_op.compute_display(propeller, display_tolerance=prop_op.DISPLAY_TOLERANCE_FRACTION,
                                     smooth_tip=True, smoothing=smoothing, measure=True)
    misses = prop_op.tolerance_misses(result)
    assert misses and "more than the tolerance 3.05e-08 m" in misses[0], misses
    # within tolerance: nothing to warn about
    smoothing["tolerance"] = 1e-5
    result = prop_op.compute_display(propeller, display_tolerance=prop_op.DISPLAY_TOLERANCE_FRACTION,
                                     smooth_tip=True, smoothing=smoothing, measure=True)
    assert prop_op.tolerance_misses(result) == []


def test_add_propeller_warns_when_the_tolerance_is_missed(scene, capfd):
    """tolerance=1e-7 D: FINISHED, with a WARNING report giving the deviation and the
    tolerance (Blender prints reports of background runs)."""
    assert bpy.ops.bladesmith.add_propeller(preset="DTMB4119", smooth_tip=True, tolerance=1e-7) == {"FINISHED"}
    out = capfd.readouterr()
    text = out.out + out.err
    assert "Warning" in text and "more than the tolerance 3.05e-08 m" in text, text[-2000:]


# -- airfoils -----------------------------------------------------------------------------------
def test_import_airfoil_name_and_refusals(scene, tmp_path):
    assert bpy.ops.bladesmith.import_airfoil(filepath=str(SHARED / "airfoils" / "s823.dat")) == {"FINISHED"}
    assert bpy.context.active_object[AIRFOIL_KEY]["name"] == "s823"  # not the header 'x_c y_c'
    flat = tmp_path / "flat.dat"
    flat.write_text("flat\n1 0\n0.75 0\n0.5 0\n0.25 0\n0 0\n0.3 0\n0.6 0\n0.9 0\n")
    refused(lambda: bpy.ops.bladesmith.import_airfoil(filepath=str(flat)), "flat.dat", "zero thickness")
    refused(lambda: bpy.ops.bladesmith.import_airfoil(filepath=str(tmp_path)), "is a directory")


# -- smooth_curve -------------------------------------------------------------------------------
def _poly(points, name="profile"):
    data = bpy.data.curves.new(name, "CURVE")
    data.dimensions = "3D"
    spline = data.splines.new("POLY")
    spline.points.add(len(points) - 1)
    rows = np.ones((len(points), 4))
    rows[:, :3] = points
    spline.points.foreach_set("co", rows.astype(np.float32).ravel())
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    return obj


def _arc(n=40):
    t = np.linspace(0, np.pi / 2, n)
    return np.stack([np.cos(t), np.sin(t), 0 * t], -1)


def test_smooth_two_point_curve(scene):
    _poly(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]))
    refused(lambda: bpy.ops.bladesmith.smooth_curve(kind="CURVE"), "2 points")


@pytest.mark.parametrize("n", [3, 4, 5, 6])
@pytest.mark.parametrize("kind", ["CURVE", "AIRFOIL"])
def test_smooth_short_curves_finish_or_refuse_cleanly(scene, n, kind):
    _poly(_arc(n))
    before = state()
    try:
        assert bpy.ops.bladesmith.smooth_curve(kind=kind) == {"FINISHED"}
    except RuntimeError as exc:
        assert "Traceback" not in str(exc), str(exc)
        assert state() == before


def test_smooth_default_bezier_curve_finishes_or_refuses_cleanly(scene):
    bpy.ops.curve.primitive_bezier_curve_add()
    before = state()
    try:
        assert bpy.ops.bladesmith.smooth_curve() == {"FINISHED"}
    except RuntimeError as exc:
        assert "Traceback" not in str(exc), str(exc)
        assert state() == before


def test_smooth_counts_bounded(scene):
    _poly(_arc())
    refused(lambda: bpy.ops.bladesmith.smooth_curve(kind="CURVE", smoothing_points=1_000_000),
            "smoothing_points", "MAX_SMOOTHING_POINTS")
    refused(lambda: bpy.ops.bladesmith.smooth_curve(kind="CURVE", max_iterations=1_000_000, tolx=0.0, tolf=0.0),
            "max_iterations", "MAX_ITERATIONS")
    refused(lambda: bpy.ops.bladesmith.smooth_curve(kind="CURVE", smoothing_type=5), "smoothing_type", "5")


def test_smoothing_type_is_an_integer(scene):
    _poly(_arc())
    assert bpy.ops.bladesmith.smooth_curve(kind="CURVE", smoothing_type=2, make_plots=False) == {"FINISHED"}


@pytest.mark.parametrize("target", ["missing/dir/out.dat", "/proc/out.dat"])
def test_smooth_curve_unwritable_file(scene, tmp_path, target):
    _poly(_arc())
    path = target if target.startswith("/") else str(tmp_path / target)
    refused(lambda: bpy.ops.bladesmith.smooth_curve(kind="CURVE", filepath=path), "filepath", path)


# -- curvature_review ---------------------------------------------------------------------------
def _surface():
    n = 6
    x = np.linspace(0.0, 1.0, n)
    P = np.zeros((n, n, 3))
    P[..., 0], P[..., 1] = np.meshgrid(x, x, indexing="ij")
    P[..., 2] = 0.05 * np.outer(np.sin(np.pi * x), np.sin(np.pi * x))
    k = clamped_uniform_knots(n, 3)
    obj = surface_to_object(BSplineSurface(3, 3, k, k, P), "Bump")
    obj.select_set(True)
    return obj


def test_review_image_of_curves_only_is_refused_before_any_change(scene, tmp_path):
    _poly(_arc())
    refused(lambda: bpy.ops.bladesmith.curvature_review(filepath=str(tmp_path / "r.png")), "no surfaces")
    assert cr.REVIEW_COLLECTION not in bpy.data.collections


@pytest.mark.parametrize("target", ["missing/dir/r.png", "/proc/r.png"])
def test_review_image_into_unwritable_folder(scene, tmp_path, target):
    _surface()
    _poly(_arc())
    path = target if target.startswith("/") else str(tmp_path / target)
    refused(lambda: bpy.ops.bladesmith.curvature_review(filepath=path, comb_lines=0), path)
    assert cr.REVIEW_COLLECTION not in bpy.data.collections
