"""Section forms: NACA tables and formulas, closed round trailing edge, airfoil files."""
import numpy as np
import pytest

from bladesmith.geometry.errors import DefinitionError
from bladesmith.geometry.sections import (
    SectionShape,
    a_series_meanline,
    naca4_thickness,
    polygon_self_intersections,
    polygons_are_simple,
    read_airfoil,
    thickness_and_camber,
)
from bladesmith.geometry.sections import tables
import pathlib

SHARED_DATA = pathlib.Path(__file__).resolve().parents[3] / "shared" / "data"

AIRFOILS = SHARED_DATA / "airfoils"


def test_a08_formula_reproduces_table():
    f = a_series_meanline(tables.A08_X, 0.8)
    # the table is given to 0.001 % of chord
    assert np.max(np.abs(f - tables.A08_F)) < 1e-5
    assert a_series_meanline(0.5) == pytest.approx(0.06790, abs=5e-6)


def test_naca4_thickness_normalised():
    assert naca4_thickness(0.3) == pytest.approx(1.0, abs=1e-3)
    assert naca4_thickness(1.0, closed_trailing_edge=True) == pytest.approx(0.0, abs=1e-4)


@pytest.mark.parametrize("thickness", ["naca66mod", "naca4", "elliptic"])
@pytest.mark.parametrize("meanline", ["a=0.8", "a=0.8mod", "parabolic", "naca4", "none"])
def test_shape_normalised_and_closed(thickness, meanline):
    s = SectionShape.from_spec(thickness, meanline)
    x = np.linspace(0.0, 1.0, 200001)
    T = s.thickness_at(x)
    assert T.max() == pytest.approx(1.0, abs=1e-9)
    assert T[0] == 0.0 and abs(T[-1]) < 1e-15  # closed LE and TE
    assert np.all(T[1:-1] > 0)
    if meanline != "none":
        F = s.camber(x)
        assert F.max() == pytest.approx(1.0, abs=1e-9)
        assert F[0] == pytest.approx(0.0, abs=1e-15) and F[-1] == pytest.approx(0.0, abs=1e-12)


def test_naca66_table_points_kept_except_closed_te():
    s = SectionShape.from_spec("naca66mod", "none")
    T = s.thickness_at(tables.NACA66MOD_X)
    # the spline's maximum is renormalised to 1: the table points move by that factor only
    scale = T[10] / tables.NACA66MOD_T[10]
    assert abs(scale - 1.0) < 1e-4
    assert np.allclose(T[:-1], scale * tables.NACA66MOD_T[:-1], atol=1e-12)
    assert T[-1] == 0.0


def test_meanline_slope_matches_tables():
    for name, table, slope in (("a=0.8mod", tables.A08MOD_F, tables.A08MOD_DFDX), ("a=0.8", tables.A08_F, tables.A08_DFDX)):
        s = SectionShape.from_spec("naca66mod", name)
        f0 = table.max()
        err = np.abs(s.camber(tables.A08_X, 1) * f0 - slope)
        # away from the singular leading edge and the TE extrapolations
        assert np.max(err[2:-3]) < 5e-3, name


def test_round_edges_are_smooth_in_psi():
    """The closed trailing edge is blunt: the outline's tangent is continuous through the
    TE (ψ = 0) and the LE (ψ = π)."""
    s = SectionShape.from_spec("naca66mod", "a=0.8")
    for psi0 in (0.0, np.pi):
        gaps = []
        for eps in (1e-5, 1e-6):
            a = s.points(np.array([psi0 - eps, psi0]), 0.1, 0.02)
            b = s.points(np.array([psi0, psi0 + eps]), 0.1, 0.02)
            ta, tb = a[1] - a[0], b[1] - b[0]
            gaps.append(np.linalg.norm(ta / np.linalg.norm(ta) - tb / np.linalg.norm(tb)))
        # one-sided chords differ by O(eps): a corner would leave a gap that does not shrink
        assert gaps[1] < 1e-4 and gaps[1] < 0.2 * gaps[0]


def test_thickness_table_that_self_intersects_is_refused():
    x = [0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0]
    t = [0.0, 0.6, 1.0, -0.2, 0.5, 0.3, 0.0]
    with pytest.raises(DefinitionError, match="self-intersect"):
        SectionShape.from_spec("table", "none", thickness_table=(x, t))


def test_polygon_self_intersection():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    bowtie = np.array([[0, 0], [1, 1], [1, 0], [0, 1]], float)
    assert len(polygon_self_intersections(square)) == 0
    assert len(polygon_self_intersections(bowtie)) == 1
    assert list(polygons_are_simple(np.stack([square, bowtie]))) == [True, False]


# ---- airfoil files ------------------------------------------------------------------
def test_selig_file():
    a = read_airfoil(AIRFOILS / "s823.dat")
    assert a.format == "selig"
    assert np.allclose(a.upper[0], 0) and np.allclose(a.lower[0], 0)
    assert a.upper[-1, 0] == pytest.approx(1.0, abs=1e-12)
    t, _ = thickness_and_camber(a, np.linspace(0, 1, 2001))
    assert t.max() == pytest.approx(0.21, abs=3e-3)


def test_reverse_selig_file():
    a = read_airfoil(AIRFOILS / "nrel5mw_DU25_A17.dat")
    assert a.format == "reverse-selig"
    assert np.mean(a.upper[:, 1]) > np.mean(a.lower[:, 1])
    t, _ = thickness_and_camber(a, np.linspace(0, 1, 2001))
    assert t.max() == pytest.approx(0.25, abs=3e-3)
    assert a.trailing_edge_thickness > 0


def _write_lednicer(path, upper, lower):
    lines = ["NACA 0012 (Lednicer)", f"{len(upper)}.  {len(lower)}.", ""]
    lines += [f"{x:.7f} {y:.7f}" for x, y in upper] + [""]
    lines += [f"{x:.7f} {y:.7f}" for x, y in lower]
    path.write_text("\n".join(lines) + "\n")


def test_lednicer_file(tmp_path):
    x = 0.5 * (1 - np.cos(np.linspace(0, np.pi, 41)))
    yt = 0.06 * naca4_thickness(x)
    f = tmp_path / "naca0012.dat"
    _write_lednicer(f, np.c_[x, yt], np.c_[x, -yt])
    a = read_airfoil(f)
    assert a.format == "lednicer"
    assert np.allclose(a.upper, np.c_[x, yt], atol=1e-7)
    # the same section written as Selig reads back identically
    g = tmp_path / "naca0012_selig.dat"
    pts = np.concatenate([np.c_[x, yt][::-1], np.c_[x, -yt][1:]])
    g.write_text("NACA 0012\n" + "\n".join(f"{p:.7f} {q:.7f}" for p, q in pts) + "\n")
    b = read_airfoil(g)
    assert b.format == "selig"
    assert np.allclose(b.upper, a.upper, atol=1e-12) and np.allclose(b.lower, a.lower, atol=1e-12)


def test_airfoil_normalised_to_unit_chord(tmp_path):
    x = 0.5 * (1 - np.cos(np.linspace(0, np.pi, 41)))
    yt = 0.06 * naca4_thickness(x)
    pts = np.concatenate([np.c_[x, yt][::-1], np.c_[x, -yt][1:]])
    ang = np.radians(10)
    rot = np.array([[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]])
    moved = 2.5 * pts @ rot.T + [3.0, -1.0]
    f = tmp_path / "moved.dat"
    f.write_text("moved\n" + "\n".join(f"{p:.12f} {q:.12f}" for p, q in moved) + "\n")
    a = read_airfoil(f)
    assert np.allclose(a.outline, pts, atol=1e-9)


def test_airfoil_duplicate_point_reported_with_line(tmp_path):
    f = tmp_path / "dup.dat"
    f.write_text("dup\n1.0 0.0\n0.5 0.05\n0.5 0.05\n0.0 0.0\n0.5 -0.05\n1.0 0.0\n")
    with pytest.raises(DefinitionError, match=r"dup\.dat.*line 4.*duplicates the point on line 3"):
        read_airfoil(f)


def test_airfoil_nan_reported_with_line(tmp_path):
    f = tmp_path / "nan.dat"
    f.write_text("# comment\nnan airfoil\n1.0 0.0\n0.5 0.05\n0.0 nan\n0.5 -0.05\n1.0 0.0\n")
    with pytest.raises(DefinitionError, match=r"nan\.dat.*line 5.*NaN"):
        read_airfoil(f)


def test_airfoil_missing_file(tmp_path):
    with pytest.raises(DefinitionError, match="not found"):
        read_airfoil(tmp_path / "nothing.dat")


@pytest.mark.parametrize("name", ["s823.dat", "fx66s196.dat", "nrel5mw_DU25_A17.dat", "nrel5mw_NACA64_A17.dat"])
def test_airfoil_as_propeller_section(name):
    s = SectionShape.from_spec(str(AIRFOILS / name), "airfoil")
    x = np.linspace(0, 1, 20001)
    assert s.thickness_at(x).max() == pytest.approx(1.0, abs=1e-8)
    assert s.thickness_at(1.0) == pytest.approx(0.0, abs=1e-15)
    assert polygons_are_simple(s.outline(200, 0.2, 0.03))
