"""The lenient IGES import (iges/importer.py): units, placement, per-entity resilience,
bounded work, trimmed faces as meshes. No bpy."""
from __future__ import annotations

import importlib.util
import math
import pathlib
import sys

import numpy as np
import pytest

from bladesmith.geometry.errors import IgesError
from bladesmith.iges import BSplineSurface128, parse_iges, to_string
from bladesmith.iges.importer import MAX_DISPLAY_COORDINATE, import_model, records_from_json, units_of
from bladesmith.iges.tessellate import inside

HERE = pathlib.Path(__file__).resolve().parent


def _cases():
    if "import_cases" not in sys.modules:
        spec = importlib.util.spec_from_file_location("import_cases", HERE / "import_cases.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules["import_cases"] = module
        spec.loader.exec_module(module)
    return sys.modules["import_cases"]


C = _cases()


def run(text, tolerance=1e-3):
    return import_model(parse_iges(text, strict=False), len(text), tolerance)


def curve_ends(report):
    return np.array([[it.geometry.evaluate(np.array(it.geometry.domain))] for it in report.items
                     if it.kind == "curve"]).reshape(-1, 3)


def mesh_area(item) -> float:
    V, F = item.mesh.vertices, item.mesh.triangles
    return 0.5 * float(np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1).sum())


# -- units ------------------------------------------------------------------------------------
@pytest.mark.parametrize("case", sorted(C.UNIT_CASES))
def test_units_flag_name_and_defaults(case):
    changes, metres = C.UNIT_CASES[case]
    text = C.set_global(C.line_file(1000.0), **changes)
    report = run(text)
    (curve,) = [it.geometry for it in report.items]
    assert np.isclose(curve.evaluate(1.0)[0], 1000.0 * metres, rtol=1e-15), case


def test_model_space_scale_divides_and_bad_scales_are_refused():
    text = C.set_global(C.line_file(1000.0), unit_flag=2, unit_name="MM", model_scale=0.5)
    (item,) = run(text).items
    assert np.isclose(item.geometry.evaluate(1.0)[0], 2.0, rtol=1e-15)  # 1000 mm at 1:2 scale
    for bad in (0.0, -1.0):
        with pytest.raises(IgesError, match=r"model space scale"):
            run(C.set_global(C.line_file(), model_scale=bad))
    with pytest.raises(IgesError, match=r"units flag\) = 3 .* unknown"):
        run(C.set_global(C.line_file(), unit_flag=3, unit_name="FURLONG"))


# -- placement --------------------------------------------------------------------------------
def test_composite_curve_transform_is_applied():
    text, expected = C.composite_with_transform()
    got = curve_ends(run(text))
    assert np.abs(got - expected).max() < 1e-12


def test_nested_composites_apply_every_transform():
    text, expected = C.nested_composites(3)
    got = curve_ends(run(text))
    assert np.abs(got - expected).max() < 1e-12


def test_subfigure_instance_scale_translation_and_transform():
    text, expected = C.subfigure_instance()
    report = run(text)
    assert report.counts == {"curve": 1}
    assert np.abs(curve_ends(report) - expected).max() < 1e-12


def test_trimmed_surface_and_its_surface_transforms_are_applied():
    text, area = C.trimmed_with_transforms()
    (item,) = run(text).items
    base_text, _ = C.plane_with_hole_mm()
    (base,) = run(base_text).items
    V0 = base.mesh.vertices * 1000.0  # the untransformed face, in the file's millimetres
    expected = (V0 @ C.R2.T + C.T2) @ C.R1.T + C.T1
    # same loops, same tessellation algorithm: the placed mesh is the moved mesh
    lo, hi = expected.min(axis=0), expected.max(axis=0)
    assert np.abs(item.mesh.vertices.min(axis=0) - lo).max() < 1e-9
    assert np.abs(item.mesh.vertices.max(axis=0) - hi).max() < 1e-9
    assert abs(mesh_area(item) / area - 1) < 2e-3


# -- trimmed faces -------------------------------------------------------------------------------
def test_trimmed_face_mesh_stays_inside_its_loops_and_keeps_the_exact_entity():
    text, area = C.plane_with_hole_mm()
    (item,) = run(text).items
    assert item.kind == "mesh" and item.trimmed
    assert abs(mesh_area(item) / (area * 1e-6) - 1) < 2e-3
    # the exact data is the 144 itself, which the writer takes as it is
    exact = parse_iges(to_string([records_from_json(item.exact)]))
    assert [e.type_number for e in exact.roots] == [144]


def test_plane_108_face_bounded_by_model_space_loops():
    text, area = C.plane_face_with_hole()
    report = run(text)
    (item,) = report.items
    assert abs(mesh_area(item) - area) < 1e-9 * area
    assert np.allclose(item.mesh.vertices[:, 2], 1.0)
    assert not report.skipped


def test_face_whose_parameter_loop_has_no_area_takes_its_model_space_loop():
    """A 144 over a 128 (the plane z = 0 over [0, 4] x [0, 3]) whose 142 has a parameter
    curve stuck on u = 0 (no area, as two faces of freecad-common's SOD_323.igs) and a
    model-space rectangle [0.5, 3.5] x [0.5, 2.5]: the face comes from the model-space
    curve, as OpenCASCADE makes it, not refused."""
    surface = (128, [1, 1, 1, 1, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 1, 1, 1, 1, 1,
                     0, 0, 0, 4, 0, 0, 0, 3, 0, 4, 3, 0, 0, 1, 0, 1], 0, 0, "01")
    ents = [surface]
    first = len(ents) + 1
    for a, b in (((0, 0), (0, 1)), ((0, 1), (0, 0))):  # the stuck parameter curve
        ents.append((110, [a[0], a[1], 0.0, b[0], b[1], 0.0], 0, 0, "01"))
    ents.append((102, [2, f"@{first}", f"@{first + 1}"], 0, 0, "01"))
    param = len(ents)
    sq = [(0.5, 0.5), (3.5, 0.5), (3.5, 2.5), (0.5, 2.5)]
    first = len(ents) + 1
    for a, b in zip(sq, sq[1:] + sq[:1]):
        ents.append((110, [a[0], a[1], 0.0, b[0], b[1], 0.0], 0, 0, "01"))
    ents.append((102, [4] + [f"@{first + i}" for i in range(4)], 0, 0, "01"))
    ents.append((142, [0, "@1", f"@{param}", f"@{len(ents)}", 1], 0, 0, "01"))
    ents.append((144, ["@1", 1, 0, f"@{len(ents)}"], 0, 0, "00"))
    report = run(C.raw_file(ents))
    (item,) = report.items
    assert not report.skipped, report.skipped_summary()
    assert abs(mesh_area(item) - 6.0) < 1e-9 * 6.0
    box = np.array([item.mesh.vertices.min(axis=0), item.mesh.vertices.max(axis=0)])
    assert np.abs(box - [[0.5, 0.5, 0.0], [3.5, 2.5, 0.0]]).max() < 1e-9


def test_tabulated_cylinder_face_with_hole():
    text, quarter = C.tabulated_cylinder_face()
    (item,) = run(text).items
    r = np.hypot(item.mesh.vertices[:, 0], item.mesh.vertices[:, 1])
    assert np.abs(r - 2.0).max() < 1e-9
    assert 0.8 * quarter < mesh_area(item) < quarter


def test_inside_is_the_even_odd_rule():
    rng = np.random.default_rng(0)
    th = np.linspace(0, 2 * np.pi, 300, endpoint=False)
    outer = np.c_[np.cos(th), np.sin(th)] * (1 + 0.3 * np.sin(5 * th))[:, None]
    hole = 0.3 * np.c_[np.cos(th), np.sin(th)]
    P = rng.uniform(-1.4, 1.4, (5000, 2))
    got = inside(P, [outer, hole])
    r, a = np.hypot(P[:, 0], P[:, 1]), np.arctan2(P[:, 1], P[:, 0])
    # away from the polygon edges the answer is the analytic one
    R = 1 + 0.3 * np.sin(5 * a)
    clear = (np.abs(r - R) > 0.02) & (np.abs(r - 0.3) > 0.02)
    assert np.array_equal(got[clear], ((r < R) & (r > 0.3))[clear])


# -- resilience -----------------------------------------------------------------------------------
def _with_entity_replaced(text, old_type, new_type):
    lines = text.split("\n")
    for i, ln in enumerate(lines):
        if ln[72:73] == "D" and ln.startswith(f"{old_type:8d}"):
            lines[i] = f"{new_type:8d}" + ln[8:]
        elif ln[72:73] == "P" and ln.startswith(f"{old_type},"):
            lines[i] = (f"{new_type}," + ln[len(str(old_type)) + 1:64]).ljust(64)[:64] + ln[64:]
    return "\n".join(lines)


def test_one_bad_entity_is_skipped_and_reported_not_the_file():
    rng = np.random.default_rng(2)
    from bladesmith.iges import Line, curve_from_geometry
    from bladesmith.iges.examples import random_curve

    good = curve_from_geometry(random_curve(rng, n_control=5))
    text = to_string([good, Line([0, 0, 0], [1, 1, 1])])
    text = _with_entity_replaced(text, 110, 116)  # a point: not imported
    report = run(text)
    assert report.counts == {"curve": 1}
    assert report.skipped == {116: [1, "entity type not supported"]}
    assert "1 x type 116" in report.skipped_summary()


def test_what_real_files_get_wrong_is_tolerated():
    text = C.line_file(1.0)
    # no newlines at all; a blank line after the T section; CRLF
    for variant in (text.replace("\n", ""), text + "\n   \n", text.replace("\n", "\r\n")):
        (item,) = run(variant).items
        assert np.isclose(item.geometry.evaluate(1.0)[0], 1.0)
    # a line of form 1 (semi-bounded): shown between its two points, and said so
    f1 = C.raw_file([(110, [0, 0, 0, 2, 0, 0], 1)])
    (item,) = run(f1).items
    assert "unbounded" in item.note
    # reversed parameter range and a knot of multiplicity degree + 1 between equal points
    pts = [[0, 0, 0], [1, 1, 0], [2, 0, 0], [2, 0, 0], [3, 1, 0], [4, 0, 0]]
    knots = [0, 0, 0, 1, 1, 1, 2, 2, 2]
    f2 = C.raw_file([(126, [5, 2, 0, 0, 0, 0, *knots, *[1] * 6, *np.ravel(pts), 2.0, 0.0])])
    with pytest.raises(IgesError):
        parse_iges(f2)  # the strict reader refuses it
    (item,) = run(f2).items
    assert np.allclose(item.geometry.evaluate(np.array(item.geometry.domain)), [[0, 0, 0], [4, 0, 0]])


def test_degree_above_five_is_meshed_and_kept_exact():
    from bladesmith.geometry.nurbs import BSplineSurface
    from bladesmith.iges import surface_from_geometry

    x, y = np.meshgrid(np.linspace(0, 1, 7), np.linspace(0, 1, 4), indexing="ij")
    net = np.stack([x, y, 0.1 * np.sin(3 * x) * y], axis=-1)
    s = BSplineSurface(6, 3, [0] * 7 + [1] * 7, [0] * 4 + [1] * 4, net)
    (item,) = run(to_string([surface_from_geometry(s)])).items
    assert item.kind == "mesh" and not item.trimmed and "degree above 5" in item.note
    assert item.mesh.deviation <= 1e-3 * s.size()
    back = records_from_json(item.exact)
    assert isinstance(back, BSplineSurface128) and np.array_equal(back.control_points, net)


# -- bounded work -----------------------------------------------------------------------------------
def test_exploding_composites_are_refused_by_the_size_budget():
    text = C.exploding_composites()
    assert len(text) < 10_000
    with pytest.raises(IgesError, match=r"expands to more than \d+ curves"):
        run(text)


def test_coordinates_beyond_float32_display_range_never_reach_blender():
    big = C.raw_file([(110, [0, 0, 0, 2e19, 0, 0]), (110, [0, 0, 0, 1, 0, 0])])
    report = run(big)
    assert report.counts == {"curve": 1}
    assert "display limit" in report.skipped[110][1]
    only = C.raw_file([(110, [0, 0, 0, 2e19, 0, 0])])
    with pytest.raises(IgesError, match=r"nothing to import.*display limit"):
        run(only)
    assert MAX_DISPLAY_COORDINATE < np.finfo(np.float32).max ** 0.5


def test_units_of_default_is_inches():
    text = C.set_global(C.line_file(), unit_flag=None, unit_name=None)
    assert units_of(parse_iges(text, strict=False)).metres_per_unit == 0.0254
    assert math.isclose(units_of(parse_iges(C.line_file(), strict=False)).factor, 1.0)


def test_dense_trimming_loop_is_thinned_within_the_tolerance():
    """A hole loop sampled 5000 times on a cylinder keeps a few dozen points, and every
    dropped point lies within the thinning tolerance of the mesh's boundary chord."""
    from bladesmith.iges.tessellate import _thin

    R = 0.05

    def evaluate(u, v):
        u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
        return np.stack([R * np.cos(u), R * np.sin(u), v], axis=-1)

    t = np.linspace(0.0, 2.0 * np.pi, 5000, endpoint=False)
    uv = np.stack([np.pi + 0.5 * np.cos(t), 0.05 + 0.02 * np.sin(t)], axis=1)
    X = evaluate(uv[:, 0], uv[:, 1])
    tol = 1e-5
    keep = _thin(evaluate, uv, X, tol)
    assert 8 < len(keep) < 300, len(keep)
    # every dropped point within tol of the chord between its kept neighbours
    k = np.r_[keep, keep[0] + len(X)]
    Xc = np.concatenate([X, X])
    for a, b in zip(k[:-1], k[1:]):
        A, B = Xc[a], Xc[b]
        P = Xc[a + 1:b]
        s = np.clip((P - A) @ (B - A) / ((B - A) @ (B - A)), 0.0, 1.0)
        assert np.linalg.norm(P - A - s[:, None] * (B - A), axis=1).max(initial=0.0) <= tol
