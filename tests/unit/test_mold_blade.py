"""NREL 5-MW mold halves: parting-line continuity, root-transition G1, tolerance by
closest-point distance (issue 7 acceptance). Figures printed with ``pytest -s``."""
import numpy as np
import pytest

from bladesmith.geometry.mold import build_blade, load_preset

#: Acceptance (issue 7).
GAP_TOL = 1e-10  # m
ANGLE_TOL = 0.01  # degrees


@pytest.fixture(scope="module")
def nrel():
    return build_blade(load_preset("NREL5MW"))


def test_nineteen_stations(nrel):
    assert len(nrel.stations) == 19


def test_le_parting_line_is_g1(nrel):
    c = nrel.continuity
    print(f"\nNREL 5-MW: LE gap {c['le_gap']:.2e} m, normal angle {c['le_angle_deg']:.2e} deg; "
          f"root transition gap {c['root_gap']:.2e} m angle {c['root_angle_deg']:.2e} deg; "
          f"transition LE gap {c['root_le_gap']:.2e} angle {c['root_le_angle_deg']:.2e}")
    assert c["le_gap"] < GAP_TOL and c["le_angle_deg"] < ANGLE_TOL
    assert c["root_le_gap"] < GAP_TOL and c["root_le_angle_deg"] < ANGLE_TOL


def test_root_transition_meets_the_aero_surface_g1(nrel):
    c = nrel.continuity
    assert c["root_gap"] < GAP_TOL and c["root_angle_deg"] < ANGLE_TOL


def test_every_section_within_tolerance(nrel):
    dev = np.array([s.deviation_two_part for s in nrel.stations])
    print("\nmax closest-point deviation / chord per station:", np.array2string(dev, precision=2))
    assert np.all(dev <= nrel.definition.tolerance)


def test_parting_lines_lie_on_both_halves(nrel):
    le = nrel.parting_lines["leading_edge"]
    v = np.linspace(0, 1, 11)
    assert np.allclose(le.evaluate(v), nrel.lower.evaluate(0.0, v), atol=1e-12, rtol=0)


def test_section_rows_are_the_fitted_sections(nrel):
    # the root transition ends on the first aerodynamic section exactly
    assert np.array_equal(nrel.transition_upper.control_points[:, -1], nrel.upper.control_points[:, 0])
