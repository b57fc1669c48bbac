"""bladesmith.import_airfoil and bladesmith.smooth_curve in background Blender."""
import pathlib

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

AIRFOILS = pathlib.Path(__file__).resolve().parents[3] / "shared" / "data" / "airfoils"


def _poly_object(points3, name="profile", cyclic=False):
    data = bpy.data.curves.new(name, "CURVE")
    data.dimensions = "3D"
    spline = data.splines.new("POLY")
    spline.use_cyclic_u = cyclic
    spline.points.add(len(points3) - 1)
    rows = np.ones((len(points3), 4))
    rows[:, :3] = points3
    spline.points.foreach_set("co", rows.astype(np.float32).ravel())
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    return obj


def test_import_airfoil_scale(scene):
    assert bpy.ops.bladesmith.import_airfoil(filepath=str(AIRFOILS / "fx66s196.dat"), chord=2.0) == {"FINISHED"}
    obj = bpy.context.active_object
    assert obj.type == "CURVE" and obj.name == "fx66s196"
    xs = [p.co[0] for p in obj.data.splines[0].points]
    assert max(xs) == pytest.approx(2.0, abs=1e-4) and min(xs) == pytest.approx(0.0, abs=1e-3)


def test_import_airfoil_bad_file(scene, tmp_path):
    bad = tmp_path / "bad.dat"
    bad.write_text("bad\n1 0\n0.5 0.1\n0.5 0.1\n0 0\n0.5 -0.1\n1 0\n")
    with pytest.raises(RuntimeError, match="duplicates"):
        bpy.ops.bladesmith.import_airfoil(filepath=str(bad))
    assert len(bpy.data.objects) == 0


def test_smooth_imported_airfoil(scene, tmp_path):
    bpy.ops.bladesmith.import_airfoil(filepath=str(AIRFOILS / "fx66s196.dat"))
    out = tmp_path / "smooth.dat"
    result = bpy.ops.bladesmith.smooth_curve(centre=0.509, output_points=150, filepath=str(out))
    assert result == {"FINISHED"}
    names = {o.name for o in bpy.data.objects}
    for suffix in ("smoothed", "curvature before", "curvature after", "comb", "deviation"):
        assert f"fx66s196 {suffix}" in names
    report = bpy.data.objects["fx66s196 smoothed"]["bladesmith_fairing"]
    assert report["converged"] and report["kind"] == "smoothfoil"
    assert report["kappa_after"][0] > report["kappa_before"][0]
    lines = out.read_text().splitlines()
    assert int(lines[0]) == 150 and len(lines) == 151


def test_smooth_tilted_poly_curve(scene):
    """A noisy planar polyline in a tilted plane: smoothed (smooth2D) in its own plane."""
    t = np.linspace(0, np.pi / 2, 40)
    rng = np.random.default_rng(0)
    xy = np.stack([2 * np.cos(t), np.sin(t)], 1) + rng.uniform(-5e-4, 5e-4, (40, 2))
    e1, e2 = np.array([1.0, 0, 0]), np.array([0, np.cos(0.6), np.sin(0.6)])
    pts = xy[:, :1] * e1 + xy[:, 1:] * e2
    _poly_object(pts)
    assert bpy.ops.bladesmith.smooth_curve(kind="CURVE", alpha=100.0, smoothing_points=60, smoother="least_squares", smoothing_type=1) == {"FINISHED"}
    smoothed = bpy.data.objects["profile smoothed"]
    co = np.array([p.co[:3] for p in smoothed.data.splines[0].points])
    normal = np.cross(e1, e2)
    assert np.abs(co @ normal).max() < 1e-5  # stays in the curve's plane


def test_smooth_cyclic_poly_curve(scene):
    """A cyclic (closed) noisy ellipse: smoothed as a periodic curve, the result closed."""
    t = np.linspace(0, 2 * np.pi, 121)[:-1]
    rng = np.random.default_rng(2)
    xy = np.stack([2 * np.cos(t), np.sin(t)], 1) + rng.uniform(-5e-4, 5e-4, (120, 2))
    _poly_object(np.column_stack([xy, np.zeros(120)]), "loop", cyclic=True)
    assert bpy.ops.bladesmith.smooth_curve(
        kind="CURVE", alpha=100.0, smoothing_points=120, smoother="least_squares", smoothing_weight=1.0, smoothing_type=1
    ) == {"FINISHED"}
    smoothed = bpy.data.objects["loop smoothed"]
    assert smoothed["bladesmith_fairing"]["converged"]
    co = np.array([p.co[:3] for p in smoothed.data.splines[0].points])
    assert np.allclose(co[0], co[-1], atol=1e-6)  # closed (Bezier form: first = last)
    assert np.abs(np.hypot(co[:, 0] / 2, co[:, 1]) - 1).max() < 0.05  # still the ellipse


def test_non_convergence_leaves_scene_unchanged(scene):
    x = np.linspace(0, 1, 80)
    pts = np.stack([x + 0.03 * np.sin(9 * np.pi * x), 0.15 * np.sin(5 * np.pi * x) + 0.04 * np.sin(17 * np.pi * x), 0 * x], 1)
    _poly_object(pts, "face")
    before = {o.name for o in bpy.data.objects}
    curves_before = len(bpy.data.curves)
    with pytest.raises(RuntimeError, match="did not converge") as info:
        bpy.ops.bladesmith.smooth_curve(kind="CURVE", alpha=1.0, smoothing_points=120, passes=20, smoothing_type=1)
    assert "residual" in str(info.value)
    assert {o.name for o in bpy.data.objects} == before
    assert len(bpy.data.curves) == curves_before and len(bpy.data.collections) == 0


def test_poll_needs_a_curve(scene):
    assert not bpy.ops.bladesmith.smooth_curve.poll()
