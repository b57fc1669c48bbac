"""Sections for mold design: Eq. 5, the silhouette point, the two-part fit with G1 at S."""
import numpy as np
import pytest

from bladesmith.geometry.errors import DefinitionError, GeometryError
from bladesmith.geometry.mold import blade_from_dict, circle_airfoil, fit_two_part, section_points, split_section
from bladesmith.geometry.mold.sections import _AffineHalf
from bladesmith.geometry.sections.airfoil_file import read_airfoil
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[2]

S823 = ROOT / "data" / "blades" / "airfoils" / "s823.dat"


@pytest.fixture(scope="module")
def s823():
    return read_airfoil(S823)


def test_eq5_wrap_is_an_isometry_onto_the_cylinder(s823):
    xy = s823.outline
    r = 3.0
    Q = section_points(xy, r, 1.2, 10.0, 0.3, prebend=0.1, sweep=0.05, wrap=True)
    F = section_points(xy, r, 1.2, 10.0, 0.3, prebend=0.1, sweep=0.05, wrap=False)
    assert np.allclose(np.hypot(Q[:, 0], Q[:, 2]), r, rtol=0, atol=1e-14)
    assert np.allclose(Q[:, 1], F[:, 1], atol=1e-15)
    assert np.allclose(r * np.arctan2(Q[:, 0], Q[:, 2]), F[:, 0], atol=1e-13)  # arc length = flat x
    # scale and twist about the pitch axis: chord length kept
    le, te = F[np.argmin(xy[:, 0])], 0.5 * (F[0] + F[-1])
    assert np.linalg.norm(te - le) == pytest.approx(1.2, rel=1e-12)


@pytest.mark.parametrize("twist, wrap", [(0.0, False), (12.0, False), (12.0, True)])
def test_silhouette_tangent_is_parallel_to_the_mold_direction(s823, twist, wrap):
    xy = s823.outline
    Q = section_points(xy, 2.0, 0.5, twist, 0.3, wrap=wrap)
    sp = split_section(Q, xy[:, 0], 0.5, (0.0, 1.0, 0.0), wrap)
    n = sp.silhouette / np.linalg.norm(sp.silhouette * [1, 0, 1]) * [1, 0, 1] if wrap else np.array([0, 0, 1.0])
    # tangent has no component across the mold direction within the carrier surface
    assert abs(np.dot(np.cross(sp.tangent, [0, 1.0, 0]), n)) < 1e-12
    assert np.allclose(sp.upper[-1], sp.lower[0])


def test_two_part_fit_is_g1_at_s_and_c0_at_te(s823):
    xy = s823.outline
    Q = section_points(xy, 1.0, 1.0, 8.0, 0.25, wrap=False)
    sp = split_section(Q, xy[:, 0], 1.0, (0, 1.0, 0), False)
    f = fit_two_part(sp, n_control=10)
    du = f.upper.derivatives(np.array([1.0]), 1)[0]
    dl = f.lower.derivatives(np.array([0.0]), 1)[0]
    assert np.array_equal(du[0], dl[0])
    assert np.allclose(du[1], f.magnitude_upper * sp.tangent, atol=1e-12)
    assert np.allclose(dl[1], f.magnitude_lower * sp.tangent, atol=1e-12)
    assert np.array_equal(f.upper.evaluate(np.array([0.0]))[0], Q[0])
    assert np.array_equal(f.lower.evaluate(np.array([1.0]))[0], Q[-1])


def test_slsqp_finds_the_exact_minimiser_of_the_quadratic(s823):
    xy = s823.outline
    Q = section_points(xy, 1.0, 1.0, 0.0, 0.0, wrap=False)
    sp = split_section(Q, xy[:, 0], 1.0, (0, 1.0, 0), False)
    f = fit_two_part(sp, n_control=9)
    from bladesmith.geometry.mold.sections import default_knots
    up = _AffineHalf(sp.upper, default_knots(sp.upper, 9), 3, sp.tangent, at_start=False)
    lo = _AffineHalf(sp.lower, default_knots(sp.lower, 9), 3, sp.tangent, at_start=True)
    assert f.magnitude_upper == pytest.approx(up.best(), rel=1e-6)
    assert f.magnitude_lower == pytest.approx(lo.best(), rel=1e-6)
    # and the ratio constraint holds when imposed
    g = fit_two_part(sp, n_control=9, ratio=1.0)
    assert g.magnitude_upper == pytest.approx(g.magnitude_lower, rel=1e-10)
    assert g.lsq_error >= f.lsq_error


def test_no_silhouette_for_a_spanwise_mold_direction(s823):
    xy = s823.outline
    Q = section_points(xy, 1.0, 1.0, 0.0, 0.0, wrap=False)
    with pytest.raises(GeometryError, match="no silhouette"):
        split_section(Q, xy[:, 0], 1.0, (0, 0, 1.0), False)


def test_circle_silhouette_is_its_extreme_point():
    c = circle_airfoil()
    xy = c.outline
    Q = section_points(xy, 1.0, 2.0, 30.0, 0.5, wrap=False)
    sp = split_section(Q, xy[:, 0], 2.0, (0, 1.0, 0), False)
    assert sp.silhouette[0] == pytest.approx(-1.0, abs=1e-7)  # radius 1 about the pitch axis


# -- definitions: bad stations are refused with the station named --------------------------
def _definition(**changes):
    st = {"r": [1.0, 2.0, 3.0, 4.0], "chord": [0.5, 0.5, 0.4, 0.3], "twist_deg": [5.0, 4, 3, 2],
          "pitch_axis": [0.3] * 4, "airfoil": [str(S823)] * 4}
    st.update(changes)
    return {"name": "t", "hub_radius": 0.5, "stations": st}


def test_decreasing_r_names_the_station():
    with pytest.raises(DefinitionError, match=r"station 2: r = 1.5 m does not increase"):
        blade_from_dict(_definition(r=[1.0, 2.0, 1.5, 4.0]))


def test_zero_chord_names_the_station():
    with pytest.raises(DefinitionError, match=r"station 1: chord must be > 0"):
        blade_from_dict(_definition(chord=[0.5, 0.0, 0.4, 0.3]))


def test_unreadable_airfoil_names_the_station(tmp_path):
    bad = tmp_path / "bad.dat"
    bad.write_text("bad\n1 0\n0.5 x\n")
    with pytest.raises(DefinitionError, match=r"station 3: cannot read airfoil"):
        blade_from_dict(_definition(airfoil=[str(S823)] * 3 + [str(bad)]))


def test_mold_direction_without_silhouette_names_the_station():
    from bladesmith.geometry.mold import build_blade
    d = _definition()
    d["mold_direction"] = [0.0, 0.0, 1.0]
    with pytest.raises(GeometryError, match=r"station 0 \(r = 1 m.*no silhouette"):
        build_blade(blade_from_dict(d))


def test_densified_halves_carry_more_control_points_than_data(s823):
    """Issue 19 (IEA 15 MW): a half with fewer data points than the tolerance needs control
    points is fitted to samples of the section's interpolant. The samples include every
    data point (marks) and both ends bit for bit; a count above the number of data points,
    ill-posed on the data, is well posed on the samples, and its errors are measured at
    the data points only."""
    from bladesmith.geometry.mold.blade import section_deviation
    from bladesmith.geometry.mold.sections import DENSE_SAMPLES, densified

    xy = s823.outline[::4]  # a coarse section: ~40 points a side
    Q = section_points(xy, 2.0, 0.5, 8.0, 0.3, wrap=True)
    sp = split_section(Q, xy[:, 0], 0.5, (0.0, 1.0, 0.0), True)
    dn = densified(sp)
    assert np.array_equal(dn.upper[0], sp.upper[0]) and np.array_equal(dn.upper[-1], sp.silhouette)
    assert np.array_equal(dn.lower[0], sp.silhouette) and np.array_equal(dn.lower[-1], sp.lower[-1])
    assert len(dn.upper) == DENSE_SAMPLES * (len(sp.upper) - 1) + 1
    assert np.abs(dn.upper[dn.upper_marks] - Q[sp.upper_data]).max() < 1e-13
    assert np.abs(dn.lower[dn.lower_marks] - Q[sp.lower_data]).max() < 1e-13
    n = len(sp.upper) + 10
    with pytest.raises(GeometryError):
        fit_two_part(sp, n_control=n)
    fit = fit_two_part(dn, n_control=n)
    dev = section_deviation(dn, fit)
    assert dev * sp.chord <= fit.max_residual + 1e-15  # the residual at the data bounds the distance
    assert dev < 1e-4  # the default tolerance, with more control points than data
