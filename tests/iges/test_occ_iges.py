"""Files we write, read by OpenCASCADE's IGESControl_Reader (OCP = cadquery-ocp-novtk).

Zero fail and zero warning messages in the load check list and in the transfer check
list; every face valid (BRepCheck_Analyzer); trimmed faces also pass BRepAlgoAPI_Check and
have the analytic area; OCC's evaluation of the file matches our float64 evaluation.
OCC converts lengths to millimetres, so metres come back multiplied by 1000.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("OCP")

from occ_support import algo_check, face_area, is_valid, read_with_occ, wires_of  # noqa: E402

from bladesmith.iges import curve_from_geometry, surface_from_geometry, write_iges  # noqa: E402
from bladesmith.iges.convert import curve_points, surface_points  # noqa: E402
from bladesmith.iges.examples import (  # noqa: E402
    bicubic_spline_114,
    cubic_spline_112,
    random_curve,
    random_surface,
    trimmed_cylinder_band,
    trimmed_plane_with_hole,
)

#: Length factor from our units to OCC's millimetres.
TO_MM = {"m": 1000.0, "mm": 1.0, "inch": 25.4}
#: Acceptance: OCC's evaluation matches ours to this, relative to the geometry's size.
EVALUATION_TOLERANCE = 1e-12
#: Acceptance: areas of trimmed faces within this relative error of the analytic value.
AREA_TOLERANCE = 1e-9


def clean_read(path):
    res = read_with_occ(path)
    assert res.load_messages == [], res.load_messages
    assert res.transfer_messages == [], res.transfer_messages
    assert res.faces or not res.shape.IsNull()
    for f in res.faces:
        assert is_valid(f)
    return res


def occ_surface_points(face, u, v):
    from OCP.BRep import BRep_Tool

    S = BRep_Tool.Surface_s(face)
    return np.array([[(p := S.Value(a, b)).X(), p.Y(), p.Z()] for a, b in zip(u, v)])


def occ_edges(shape):
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    out = []
    exp = TopExp_Explorer(shape, TopAbs_EDGE)
    while exp.More():
        out.append(BRepAdaptor_Curve(TopoDS.Edge(exp.Current())))
        exp.Next()
    return out


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("units", ["m", "mm"])
def test_random_rational_surfaces_evaluate_identically(seed, units, tmp_path):
    rng = np.random.default_rng(seed)
    shape = tuple(rng.integers(4, 12, 2))
    degrees = tuple(rng.integers(2, 6, 2))  # C1 or better: OCC rightly warns on C0
    s = random_surface(rng, shape=shape, degrees=degrees, rational=seed % 3 != 2, scale=10.0 ** rng.uniform(-2, 2))
    path = tmp_path / "s.igs"
    write_iges(path, [surface_from_geometry(s)], units=units)
    res = clean_read(path)
    assert len(res.faces) == 1
    u = rng.uniform(*s.domain_u, 200)
    v = rng.uniform(*s.domain_v, 200)
    theirs = occ_surface_points(res.faces[0], u, v) / TO_MM[units]
    err = np.max(np.linalg.norm(theirs - s.evaluate(u, v), axis=1)) / s.size()
    print(f"surface seed {seed} {units}: max OCC - ours = {err:.2e} of the size")
    assert err <= EVALUATION_TOLERANCE


@pytest.mark.parametrize("seed", range(6))
def test_random_rational_curves_evaluate_identically(seed, tmp_path):
    rng = np.random.default_rng(100 + seed)
    c = random_curve(rng, n_control=int(rng.integers(4, 15)), degree=int(rng.integers(2, 6)),
                     rational=seed % 3 != 2, scale=10.0 ** rng.uniform(-2, 2))
    path = tmp_path / "c.igs"
    write_iges(path, [curve_from_geometry(c)])
    res = clean_read(path)
    (edge,) = occ_edges(res.shape)
    a, b = c.domain
    assert (edge.FirstParameter(), edge.LastParameter()) == pytest.approx((a, b), abs=1e-12)
    t = rng.uniform(a, b, 200)
    theirs = np.array([[(p := edge.Value(x)).X(), p.Y(), p.Z()] for x in t]) / 1000.0
    err = np.max(np.linalg.norm(theirs - c.evaluate(t), axis=1)) / c.size()
    print(f"curve seed {seed}: max OCC - ours = {err:.2e} of the size")
    assert err <= EVALUATION_TOLERANCE


@pytest.mark.parametrize("preferred", [1, 3])
def test_trimmed_surface_of_revolution(preferred, tmp_path):
    trimmed, area = trimmed_cylinder_band(preferred=preferred)
    path = tmp_path / "band.igs"
    write_iges(path, [trimmed])
    res = clean_read(path)
    assert len(res.faces) == 1
    face = res.faces[0]
    assert len(wires_of(face)) == 2
    assert algo_check(face)
    occ_area = face_area(face) / 1000.0**2
    print(f"trimmed surface of revolution: area {occ_area!r}, exact {area!r}, "
          f"relative error {abs(occ_area - area) / area:.2e}")
    assert abs(occ_area - area) <= AREA_TOLERANCE * area


@pytest.mark.parametrize("units", ["m", "mm", "inch"])
def test_trimmed_bspline_surface_with_hole(units, tmp_path):
    trimmed, area = trimmed_plane_with_hole()
    path = tmp_path / "plane.igs"
    write_iges(path, [trimmed], units=units)
    res = clean_read(path)
    assert len(res.faces) == 1
    face = res.faces[0]
    assert len(wires_of(face)) == 2 and algo_check(face)
    occ_area = face_area(face) / TO_MM[units] ** 2
    assert abs(occ_area - area) <= AREA_TOLERANCE * area


def test_several_trimmed_surfaces_in_one_file(tmp_path):
    band, a1 = trimmed_cylinder_band()
    plane, a2 = trimmed_plane_with_hole()
    path = tmp_path / "two.igs"
    write_iges(path, [band, plane])
    res = clean_read(path)
    assert len(res.faces) == 2
    areas = sorted(face_area(f) / 1e6 for f in res.faces)
    assert areas == pytest.approx(sorted([a1, a2]), rel=AREA_TOLERANCE)
    assert all(algo_check(f) for f in res.faces)


def test_parametric_splines_and_arcs_read_identically(tmp_path):
    from bladesmith.iges import CircularArc

    rng = np.random.default_rng(7)
    spline = cubic_spline_112(rng)
    path = tmp_path / "112.igs"
    write_iges(path, [spline])
    res = clean_read(path)
    edges = occ_edges(res.shape)
    for e in edges:
        t = np.linspace(e.FirstParameter(), e.LastParameter(), 9)
        theirs = np.array([[(p := e.Value(x)).X(), p.Y(), p.Z()] for x in t]) / 1000.0
        assert np.allclose(theirs, curve_points(spline, t), atol=1e-12 * 10)
    sps = bicubic_spline_114(rng)
    path = tmp_path / "114.igs"
    write_iges(path, [sps])
    res = clean_read(path)
    u, v = rng.uniform(0, 1.2, 50), rng.uniform(0, 1.0, 50)
    theirs = occ_surface_points(res.faces[0], u, v) / 1000.0
    assert np.allclose(theirs, surface_points(sps, u, v), atol=1e-11)
    arc = CircularArc([1.0, 2.0], [3.0, 2.0], [1.0, 4.0], z=0.5)
    path = tmp_path / "100.igs"
    write_iges(path, [arc])
    res = clean_read(path)
    (e,) = occ_edges(res.shape)
    t = np.linspace(e.FirstParameter(), e.LastParameter(), 9)
    P = np.array([[(p := e.Value(x)).X(), p.Y(), p.Z()] for x in t]) / 1000.0
    assert np.allclose(np.hypot(P[:, 0] - 1.0, P[:, 1] - 2.0), 2.0, atol=1e-12) and np.allclose(P[:, 2], 0.5)
    assert e.FirstParameter() == pytest.approx(0.0) and e.LastParameter() == pytest.approx(math.pi / 2)
