"""File > Export > IGES and File > Import > IGES in Blender."""
import os
import pathlib

import bpy
import numpy as np
import pytest

from bladesmith.geometry.nurbs import BSplineCurve, BSplineSurface
from bladesmith.geometry.nurbs.projection import closest_point_surface
from bladesmith.iges import read_iges
from bladesmith.operators.nurbs_objects import curve_to_object, object_to_geometry, surface_to_object

FLOAT32 = 2e-6  # relative: the float32 precision of Blender coordinates, with margin
ROOT = pathlib.Path(__file__).resolve().parents[2]


def random_surface(rng, rational):
    nu, nv = 7, 6
    ku = np.r_[[0] * 4, np.sort(rng.uniform(0.1, 0.9, nu - 4)), [1] * 4]
    kv = np.r_[[0] * 4, np.sort(rng.uniform(0.1, 0.9, nv - 4)), [1] * 4]
    x, y = np.meshgrid(np.linspace(0, 1, nu), np.linspace(0, 1, nv), indexing="ij")
    net = np.stack([x, y, 0.2 * rng.normal(size=x.shape)], axis=-1)
    w = rng.uniform(0.5, 2.0, (nu, nv)) if rational else None
    return BSplineSurface(3, 3, ku, kv, net, w)


def scene_snapshot():
    return {
        "objects": set(bpy.data.objects.keys()),
        "curves": set(bpy.data.curves.keys()),
        "meshes": set(bpy.data.meshes.keys()),
    }


def test_export_writes_exact_float64_data(scene, tmp_path):
    rng = np.random.default_rng(1)
    surfaces = [random_surface(rng, r) for r in (False, True)]
    for i, s in enumerate(surfaces):
        surface_to_object(s, f"S{i}")
    curve = BSplineCurve(3, [0, 0, 0, 0, 0.4, 1, 1, 1, 1], rng.normal(size=(5, 3)), rng.uniform(0.5, 2, 5))
    curve_to_object(curve, "C")
    path = tmp_path / "out.igs"
    assert bpy.ops.export_scene.iges(filepath=str(path)) == {"FINISHED"}
    model = read_iges(path)
    geometry = [g for _, g in model.to_geometry()]
    got_surfaces = [g for g in geometry if isinstance(g, BSplineSurface)]
    got_curves = [g for g in geometry if isinstance(g, BSplineCurve)]
    assert len(got_surfaces) == 2 and len(got_curves) == 1
    for s in surfaces:
        match = [g for g in got_surfaces if g.shape == s.shape and g.is_rational == s.is_rational]
        assert match and np.array_equal(match[0].control_points, s.control_points)  # bitwise: float64 data
    assert np.array_equal(got_curves[0].weights, curve.weights)


def test_export_units_and_selection(scene, tmp_path):
    rng = np.random.default_rng(2)
    a = surface_to_object(random_surface(rng, False), "A")
    b = surface_to_object(random_surface(rng, False), "B")
    for obj in scene.objects:
        obj.select_set(obj is a)
    path = tmp_path / "mm.igs"
    assert bpy.ops.export_scene.iges(filepath=str(path), use_selection=True, units="MM") == {"FINISHED"}
    model = read_iges(path)
    assert model.header.unit_flag == 2 and model.header.unit_name == "MM"
    (record, g), = model.to_geometry()
    original = object_to_geometry(a)[0]
    assert np.allclose(g.control_points, 1000.0 * original.control_points, rtol=1e-15, atol=0)
    assert b.name not in {r.label for r, _ in model.to_geometry()}


def test_export_applies_object_transforms(scene, tmp_path):
    rng = np.random.default_rng(3)
    s = random_surface(rng, True)
    obj = surface_to_object(s, "Moved")
    obj.location = (1.0, -2.0, 0.5)
    obj.rotation_euler = (0.3, 0.0, 1.1)
    bpy.context.view_layer.update()
    path = tmp_path / "moved.igs"
    assert bpy.ops.export_scene.iges(filepath=str(path)) == {"FINISHED"}
    (_, g), = read_iges(path).to_geometry()
    M = np.array(obj.matrix_world, dtype=np.float64)
    uv = rng.uniform(0, 1, (200, 2))
    expected = s.evaluate(uv[:, 0], uv[:, 1]) @ M[:3, :3].T + M[:3, 3]
    assert np.abs(g.evaluate(uv[:, 0], uv[:, 1]) - expected).max() < 1e-12 * s.size() * 10


def test_hand_edited_native_nurbs_export_from_blender_data(scene, tmp_path):
    bpy.ops.surface.primitive_nurbs_surface_torus_add()
    torus = bpy.context.active_object
    path = tmp_path / "torus.igs"
    assert bpy.ops.export_scene.iges(filepath=str(path)) == {"FINISHED"}
    pieces = [g for _, g in read_iges(path).to_geometry()]
    # Blender's torus is 4 x 4 rational Bezier patches (Bezier knot mode): C0 across every
    # joint, so surface_pieces writes each patch as its own surface
    assert len(pieces) == 16
    mesh = torus.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    V = np.array([v.co[:] for v in mesh.vertices], dtype=np.float64) @ np.array(torus.matrix_world)[:3, :3].T
    torus.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh_clear()
    V += np.array(torus.matrix_world)[:3, 3]
    d = np.min([closest_point_surface(g, V)[2] for g in pieces], axis=0)
    size = max(g.size() for g in pieces)
    assert d.max() < FLOAT32 * size


def test_import_then_export_reproduces_surfaces(scene, tmp_path):
    rng = np.random.default_rng(4)
    surfaces = [random_surface(rng, r) for r in (False, True)]
    from bladesmith.iges import surface_from_geometry, write_iges

    source = tmp_path / "source.igs"
    write_iges(source, [surface_from_geometry(s, label=f"S{i}") for i, s in enumerate(surfaces)])
    assert bpy.ops.import_scene.iges(filepath=str(source)) == {"FINISHED"}
    assert {o.name for o in scene.objects} == {"S0", "S1"}
    # the imported objects are exact; edit nothing and export again
    again = tmp_path / "again.igs"
    assert bpy.ops.export_scene.iges(filepath=str(again)) == {"FINISHED"}
    back = {r.label: g for r, g in read_iges(again).to_geometry()}
    uv = rng.uniform(0, 1, (500, 2))
    for i, s in enumerate(surfaces):
        err = np.abs(back[f"S{i}"].evaluate(uv[:, 0], uv[:, 1]) - s.evaluate(uv[:, 0], uv[:, 1])).max()
        assert err < FLOAT32 * s.size(), err


def _mesh_area(obj) -> float:
    V = np.array([v.co[:] for v in obj.data.vertices], dtype=np.float64)
    F = np.array([p.vertices[:] for p in obj.data.polygons])
    return 0.5 * float(np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1).sum())


def test_trimmed_face_is_shown_trimmed_and_keeps_its_exact_entity(scene, tmp_path):
    from bladesmith.iges import examples, write_iges
    from bladesmith.operators.iges_io import EXACT_KEY

    path = tmp_path / "trimmed.igs"
    trimmed, area = examples.trimmed_cylinder_band()
    write_iges(path, [trimmed])
    assert bpy.ops.import_scene.iges(filepath=str(path)) == {"FINISHED"}
    (band,) = list(scene.objects)
    assert band.type == "MESH" and EXACT_KEY in band
    # the band is the cylinder x^2 + y^2 = 2^2, 0 <= z <= 3 between angles 0.25 and 2.75,
    # with a hole of radius 0.3 about (t, angle) = (0.5, 1.5): no vertex inside the hole
    V = np.array([v.co[:] for v in band.data.vertices], dtype=np.float64)
    assert np.abs(np.hypot(V[:, 0], V[:, 1]) - 2.0).max() < FLOAT32 * 4
    t, angle = V[:, 2] / 3.0, np.arctan2(V[:, 1], V[:, 0])
    assert np.hypot(t - 0.5, angle - 1.5).min() > 0.3 - 1e-6
    assert angle.min() > 0.25 - 1e-6 and angle.max() < 2.75 + 1e-6
    # the mesh is the trimmed face within the display tolerance (1e-3 of its size)
    assert abs(_mesh_area(band) / area - 1.0) < 2e-3


@pytest.mark.parametrize("case", ["plane with hole", "hub sector"])
def test_trimmed_face_round_trip_through_opencascade(scene, tmp_path, case):
    """import -> export of a trimmed face: OCC reads the result with 0 messages and the
    same area as the original file to 1e-9 (the exact 144 is written back)."""
    from bladesmith.iges import examples, write_iges

    occ = _occ_support()
    path = tmp_path / "source.igs"
    if case == "plane with hole":
        trimmed, _ = examples.trimmed_plane_with_hole()
        write_iges(path, [trimmed], units="mm")
    else:
        assert bpy.ops.bladesmith.add_propeller(preset="skewed_demo", smooth_tip=True) == {"FINISHED"}
        assert bpy.ops.export_scene.iges(filepath=str(path), units="MM") == {"FINISHED"}
        for obj in list(scene.objects):
            bpy.data.objects.remove(obj, do_unlink=True)
    assert bpy.ops.import_scene.iges(filepath=str(path)) == {"FINISHED"}
    meshes = [o for o in scene.objects if o.type == "MESH"]
    assert len(meshes) == 1
    again = tmp_path / "again.igs"
    assert bpy.ops.export_scene.iges(filepath=str(again), units="MM") == {"FINISHED"}
    first, second = occ.read_with_occ(path), occ.read_with_occ(again)
    assert second.load_messages == [] and second.transfer_messages == []
    a1 = sum(occ.face_area(f) for f in first.faces)
    a2 = sum(occ.face_area(f) for f in second.faces)
    print(f"{case}: OCC area {a1!r} before, {a2!r} after import -> export ({abs(a2 / a1 - 1.0):.1e}); "
          f"messages {second.load_messages + second.transfer_messages}")
    assert len(first.faces) == len(second.faces)
    assert abs(a2 / a1 - 1.0) < 1e-9, (a1, a2)


def test_import_reports_skipped_entities_and_keeps_the_rest(scene, tmp_path):
    from bladesmith.iges import Line, to_string

    text = to_string([Line([0, 0, 0], [1, 0, 0]), Line([0, 0, 0], [0, 1, 0])])
    # the second line becomes a type 116 point, which is not imported
    lines = text.split("\n")
    d = [i for i, ln in enumerate(lines) if ln[72:73] == "D"][2:4]
    p = [i for i, ln in enumerate(lines) if ln[72:73] == "P" and ln.startswith("110,")][1]
    for i in d:
        lines[i] = lines[i].replace("     110", "     116", 1)
    lines[p] = lines[p].replace("110,", "116,", 1)
    path = tmp_path / "mixed.igs"
    path.write_text("\n".join(lines))
    from bladesmith.operators.iges_io import import_file

    counts = import_file(str(path), scene.collection)
    assert counts["curves"] == 1
    assert counts["report"].skipped == {116: [1, "entity type not supported"]}


def test_failed_import_leaves_the_scene_unchanged(scene, tmp_path):
    rng = np.random.default_rng(5)
    surface_to_object(random_surface(rng, False), "Existing")
    before = scene_snapshot()
    bad = tmp_path / "bad.igs"
    bad.write_text("this is not an IGES file\n")
    with pytest.raises(RuntimeError, match="IGES|line"):
        bpy.ops.import_scene.iges(filepath=str(bad))
    missing = tmp_path / "missing.igs"
    with pytest.raises(RuntimeError):
        bpy.ops.import_scene.iges(filepath=str(missing))
    assert scene_snapshot() == before


def test_failed_export_keeps_the_previous_file(scene, tmp_path, monkeypatch):
    rng = np.random.default_rng(6)
    surface_to_object(random_surface(rng, False), "S")
    path = tmp_path / "keep.igs"
    assert bpy.ops.export_scene.iges(filepath=str(path)) == {"FINISHED"}
    good = path.read_bytes()
    # a surface Blender shows but IGES cannot hold: nothing may be written
    from bladesmith.operators import iges_io

    def broken(*args, **kwargs):
        raise iges_io.BladesmithError("simulated failure halfway")

    monkeypatch.setattr(iges_io, "curve_from_geometry", broken)
    curve_to_object(BSplineCurve(1, [0, 0, 1, 1], [[0, 0, 0], [1, 1, 1]]), "C")
    with pytest.raises(RuntimeError, match="simulated failure"):
        bpy.ops.export_scene.iges(filepath=str(path))
    assert path.read_bytes() == good
    assert not [p for p in os.listdir(tmp_path) if p.endswith(".tmp")]


def test_nothing_to_export_is_an_error(scene, tmp_path):
    with pytest.raises(RuntimeError, match="nothing to export"):
        bpy.ops.export_scene.iges(filepath=str(tmp_path / "empty.igs"))
    assert not (tmp_path / "empty.igs").exists()


def test_menus_are_registered(addon):
    from bladesmith.operators import iges_io

    assert iges_io._menu_export in bpy.types.TOPBAR_MT_file_export._dyn_ui_initialize()
    assert iges_io._menu_import in bpy.types.TOPBAR_MT_file_import._dyn_ui_initialize()


def test_smoothed_propeller_exports_as_reference_blade_and_hub_sector(scene, tmp_path):
    """Hally (2013) §11 (``split_edges=False``): the five reference-blade surfaces (exact, as
    smoothed) and the hub sector as a trimmed surface, however many rotated copies the scene
    shows."""
    from bladesmith.geometry.propeller import Propeller, smooth_blade
    from bladesmith.iges import BSplineSurface128, TrimmedSurface

    assert bpy.ops.bladesmith.add_propeller(preset="dtmb4119", smooth_tip=True) == {"FINISHED"}
    rng = np.random.default_rng(9)
    surface_to_object(random_surface(rng, False), "Other")
    path = tmp_path / "prop.igs"
    assert bpy.ops.export_scene.iges(filepath=str(path), split_edges=False) == {"FINISHED"}
    model = read_iges(path)
    roots = model.roots
    assert sum(isinstance(r, TrimmedSurface) for r in roots) == 1
    blades = [r for r in roots if isinstance(r, BSplineSurface128) and r.label != "Other"]
    assert len(blades) == 5 and sum(isinstance(r, BSplineSurface128) for r in roots) == 6
    # the file holds exactly the float64 surfaces the blade objects show
    shown = [object_to_geometry(o)[0] for o in scene.objects
             if o.get("bladesmith_part") == "blade" and o.get("bladesmith_blade", 0) == 0]
    assert sorted(np.asarray(r.control_points).tobytes() for r in blades) == sorted(
        s.control_points.tobytes() for s in shown)
    # and they are the Hally surfaces: an independent run with the same settings, given as
    # fractions of R rather than of D, agrees to the round-off the pipeline amplifies
    definition = Propeller.from_toml(ROOT / "data" / "propellers" / "dtmb4119.toml")
    reference = smooth_blade(definition.build(), measure=False)
    for r, s in zip(blades, reference.surfaces):
        assert np.abs(np.asarray(r.control_points) - s.control_points).max() < 1e-9 * definition.diameter


def test_reference_export_splits_the_edge_surfaces_by_default(scene, tmp_path):
    """The default export writes the LE, TE and tip surfaces as two faces each, cut along
    the blade's edge (8 blade faces and the hub sector): each half is its shown surface
    exactly over its half of the domain, and OpenCASCADE reads the file cleanly."""
    from bladesmith.geometry.nurbs import BSplineSurface
    from bladesmith.iges import BSplineSurface128, TrimmedSurface

    occ = _occ_support()
    assert bpy.ops.bladesmith.add_propeller(preset="dtmb4119", smooth_tip=True) == {"FINISHED"}
    path = tmp_path / "split.igs"
    assert bpy.ops.export_scene.iges(filepath=str(path)) == {"FINISHED"}
    roots = read_iges(path).roots
    assert sum(isinstance(r, TrimmedSurface) for r in roots) == 1
    blades = [r for r in roots if isinstance(r, BSplineSurface128)]
    assert sorted(r.label for r in blades) == sorted(
        ["PRESSURE", "SUCTION", "LEADEDGP", "LEADEDGS", "TRAILEDP", "TRAILEDS", "TIPP", "TIPS"])
    shown = {o["bladesmith_patch"]: object_to_geometry(o)[0] for o in scene.objects
             if o.get("bladesmith_part") == "blade" and o.get("bladesmith_blade", 0) == 0}
    wrapped = [shown[k] for k in sorted(shown)][2:]  # LE, TE, tip (smoothing.SURFACE_NAMES order)
    t = np.linspace(0.0, 1.0, 21)[:, None]
    s = np.linspace(0.0, 1.0, 17)[None, :]
    # DTMB 4119 is right-handed: the first half along the cuts is the LE's and tip's pressure
    # side and the TE's suction side (the TE surface runs suction -> pressure)
    pairs = (("LEADEDGP", "LEADEDGS", "u"), ("TRAILEDS", "TRAILEDP", "u"), ("TIPP", "TIPS", "v"))
    for whole, (first, second, direction) in zip(wrapped, pairs):
        for label, offset in ((first, 0.0), (second, 0.5)):
            (r,) = [r for r in blades if r.label == label]
            half = BSplineSurface(r.degree_u, r.degree_v, np.asarray(r.knots_u), np.asarray(r.knots_v),
                                  np.asarray(r.control_points))
            u, v = (offset + 0.5 * t, s) if direction == "u" else (s.T, offset + 0.5 * t.T)
            h = half.evaluate(t, s) if direction == "u" else half.evaluate(s.T, t.T)
            assert np.abs(h - whole.evaluate(u, v)).max() < 1e-12 * 0.3048, label
    r = occ.read_with_occ(path)
    assert r.load_messages == [] and r.transfer_messages == [] and len(r.faces) == 9


def test_full_propeller_option_writes_all_blades_and_the_whole_hub(scene, tmp_path):
    """export_scene.iges(full_propeller=True): Z blades of eight surfaces (Hally's five, the
    LE, TE and tip surfaces split along the blade's edge) and one trimmed hub with Z holes;
    OpenCASCADE reads it cleanly and its faces sew at 1e-7 D with no free edge."""
    from bladesmith.iges import BSplineSurface128, TrimmedSurface

    occ = _occ_support()
    assert bpy.ops.bladesmith.add_propeller(preset="dtmb4119", smooth_tip=True) == {"FINISHED"}
    path = tmp_path / "whole.igs"
    assert bpy.ops.export_scene.iges(filepath=str(path), full_propeller=True) == {"FINISHED"}
    roots = read_iges(path).roots
    hubs = [r for r in roots if isinstance(r, TrimmedSurface)]
    assert len(hubs) == 1 and len(hubs[0].inner) == 3 and hubs[0].outer is None
    assert sum(isinstance(r, BSplineSurface128) for r in roots) == 24
    r = occ.read_with_occ(path)
    assert r.load_messages == [] and r.transfer_messages == []
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing

    sewing = BRepBuilderAPI_Sewing(1e-7 * 0.3048 * 1000.0)
    for face in r.faces:
        sewing.Add(face)
    sewing.Perform()
    assert len(r.faces) == 25 and sewing.NbFreeEdges() == 0
    # and as one 186 solid
    solid_path = tmp_path / "solid.igs"
    assert bpy.ops.export_scene.iges(filepath=str(solid_path), full_propeller=True, brep_solid=True) == {"FINISHED"}
    r = occ.read_with_occ(solid_path)
    assert r.load_messages == [] and r.transfer_messages == [] and len(r.faces) == 25
    assert occ.is_valid(r.shape) and r.shape.ShapeType().name == "TopAbs_SOLID"


def _occ_support():
    pytest.importorskip("OCP")
    import importlib.util

    import sys

    if "occ_support" not in sys.modules:
        spec = importlib.util.spec_from_file_location("occ_support", ROOT / "tests" / "iges" / "occ_support.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules["occ_support"] = module
        spec.loader.exec_module(module)
    return sys.modules["occ_support"]


@pytest.mark.parametrize("case", ["torus", "sphere", "propeller", "smoothed propeller", "random surfaces"])
def test_exported_files_read_cleanly_in_opencascade(scene, tmp_path, case):
    """Every file the export operator writes: zero fail and warning messages in
    OpenCASCADE, every face valid. Closed and C0 surfaces (Blender's cyclic primitives,
    the unsmoothed blade closed at its trailing edge, the hub) go out in pieces."""
    occ = _occ_support()
    if case == "torus":
        bpy.ops.surface.primitive_nurbs_surface_torus_add()
    elif case == "sphere":
        bpy.ops.surface.primitive_nurbs_surface_sphere_add()
    elif case == "propeller":
        assert bpy.ops.bladesmith.add_propeller(preset="dtmb4119") == {"FINISHED"}
    elif case == "smoothed propeller":
        assert bpy.ops.bladesmith.add_propeller(preset="skewed_demo", smooth_tip=True) == {"FINISHED"}
    else:
        rng = np.random.default_rng(12)
        for i in range(3):
            surface_to_object(random_surface(rng, bool(i % 2)), f"R{i}")
    path = tmp_path / "exported.igs"
    assert bpy.ops.export_scene.iges(filepath=str(path), units="MM") == {"FINISHED"}
    result = occ.read_with_occ(path)
    assert result.load_messages == [] and result.transfer_messages == []
    assert result.faces and all(occ.is_valid(face) for face in result.faces)


@pytest.mark.parametrize("scale", [-2.0, 0.0])
def test_model_space_scale_that_mirrors_or_vanishes_is_refused_through_the_operator(scene, tmp_path, scale):
    """Issue 20: a model scale of -2 used to mirror silently and 0 was taken as 1; the
    import operator refuses both, naming the field and value, and changes nothing."""
    import importlib.util
    import sys

    cases_path = pathlib.Path(__file__).resolve().parents[1] / "unit" / "import_cases.py"
    if "import_cases" not in sys.modules:
        spec = importlib.util.spec_from_file_location("import_cases", cases_path)
        module = importlib.util.module_from_spec(spec)
        sys.modules["import_cases"] = module
        spec.loader.exec_module(module)
    cases = sys.modules["import_cases"]
    path = tmp_path / "scaled.igs"
    path.write_text(cases.set_global(cases.line_file(), model_scale=scale))
    rng = np.random.default_rng(20)
    surface_to_object(random_surface(rng, False), "Existing")
    before = scene_snapshot()
    with pytest.raises(RuntimeError, match=r"Global field 13 \(model space scale\) = " + str(scale).replace(".", r"\.")):
        bpy.ops.import_scene.iges(filepath=str(path))
    assert scene_snapshot() == before
