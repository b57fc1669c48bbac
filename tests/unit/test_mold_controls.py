"""Hosseini's controls in the user's hands (issue 19, item 5): the tangent magnitude at S
by hand or by SQP, the degrees p and q, a tolerance per station, the control-point sweep;
the new definition keys are checked like the others."""
from __future__ import annotations

import pathlib

import numpy as np
import pytest

from bladesmith.geometry.errors import DefinitionError, GeometryError
from bladesmith.geometry.mold import blade_from_dict, build_blade, control_point_sweep, format_sweep, load_preset
from bladesmith.geometry.mold.definition import STATION_KEYS, TOP_LEVEL_KEYS

BASE = pathlib.Path(__file__).resolve().parents[2] / "data" / "blades"
N = 14  # control points per half: fast, not within 1e-4 (the tests say adapt=False)


@pytest.fixture(scope="module")
def s823():
    return load_preset("S823_SMALL")


def _build(defn, **kw):
    return build_blade(defn, control_points=N, tolerance=float("inf"), adapt=False, single=False, fairness=False,
                       **kw)


def test_tangent_magnitude_by_hand_is_used_and_keeps_g1(s823):
    sqp = _build(s823)
    hand = _build(s823, tangent_magnitudes=(1.3, 1.0))
    for rep, st in zip(hand.stations, s823.stations):
        assert rep.magnitude_upper == pytest.approx(1.3 * st.chord) and rep.magnitude_lower == pytest.approx(st.chord)
    assert hand.ratio == pytest.approx(1.3)
    assert hand.continuity["le_angle_deg"] < 0.01
    # SQP minimises the least-squares error (Eq. 3): a hand value cannot beat it
    lsq = lambda m: sum(r.lsq_two_part for r in m.stations if r.index >= s823.first_aerodynamic_station)  # noqa: E731
    assert lsq(sqp) < lsq(hand)


def test_degrees_p_and_q(s823):
    m = _build(s823, degree=4, degree_v=2)
    assert m.upper.degree_u == 4 and m.upper.degree_v == 2 and m.transition_upper.degree_u == 4
    assert m.continuity["le_angle_deg"] < 0.01 and m.continuity["root_angle_deg"] < 0.01


def test_per_station_tolerance_is_the_one_that_refuses(s823):
    data = s823.to_dict()
    tols = [1e-2] * len(s823.stations)
    tols[5] = 1e-7
    data["stations"]["tolerance"] = tols
    defn = blade_from_dict(data, "t.toml", BASE)
    assert defn.station_tolerances[5] == 1e-7
    with pytest.raises(GeometryError, match=r"station 5 \(r = 1\.8 m.*its tolerance 1e-07 chord"):
        build_blade(defn, control_points=N, adapt=False, single=False, fairness=False)
    tols[5] = 1e-2
    data["stations"]["tolerance"] = tols
    m = build_blade(blade_from_dict(data, "t.toml", BASE), control_points=N, adapt=False, single=False,
                    fairness=False)
    assert np.all(m.tolerances == 1e-2)


@pytest.mark.parametrize("key, value, words", [
    ("tangent_magnitude", "fast", "sqp"),
    ("tangent_magnitude", [1.0, -1.0], "two positive numbers"),
    ("section_degree", 1, r"\[2, 5\]"),
    ("span_degree", 9, r"\[1, 5\]"),
    ("span_degree", True, r"\[1, 5\]"),
])
def test_new_keys_are_checked(s823, key, value, words):
    data = s823.to_dict()
    data[key] = value
    with pytest.raises(DefinitionError, match=rf"t\.toml: field '{key}': .*{words}"):
        blade_from_dict(data, "t.toml", BASE)


def test_station_tolerance_must_be_positive(s823):
    data = s823.to_dict()
    data["stations"]["tolerance"] = [1e-4] * 8 + [0.0]
    with pytest.raises(DefinitionError, match=r"field 'stations.tolerance\[8\]'"):
        blade_from_dict(data, "t.toml", BASE)


def test_new_keys_are_declared_for_the_strict_key_check(s823):
    data = s823.to_dict()
    assert set(data) <= set(TOP_LEVEL_KEYS)
    assert set(data["stations"]) <= set(STATION_KEYS) and "tolerance" in STATION_KEYS


def test_sweep_tabulates_both_approaches_at_equal_totals(s823):
    rows = control_point_sweep(s823, [8, 12], quadrature_points=4)
    assert [r.n for r in rows] == [8, 12]
    assert rows[1].lsq_two_part < rows[0].lsq_two_part and rows[1].lsq_single < rows[0].lsq_single
    assert all(r.mvs_two_part > 0 and r.strain_energy_single > 0 for r in rows)
    table = format_sweep(rows)
    assert table.count("\n") == 3 and "| 12 |" in table
