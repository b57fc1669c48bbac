"""Hally (2013) tip smoothing, §§3–9, measured on DTMB 4119 and the 45°-skewed demo at
default settings (issue 5 acceptance): shared edges, normals, accuracy, the smoothing
zone, fairness of the tip cuts, orientation."""
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.propeller import Propeller
from bladesmith.geometry.propeller.smoothing import (
    SMOOTHING_ZONE_BOUND,
    SURFACE_NAMES,
    SmoothingSettings,
    deviation_report,
    project_to_blade,
    shared_edge_report,
    smooth_blade,
    tip_cut_fairness,
)

PRESETS = pathlib.Path(__file__).resolve().parents[2] / "data" / "propellers"


@pytest.fixture(scope="module", params=["dtmb4119", "skewed_demo"])
def case(request):
    model = Propeller.from_toml(PRESETS / f"{request.param}.toml").build()
    smoothed = smooth_blade(model)
    return request.param, model, smoothed


def test_five_surfaces_are_cubic_splines(case):
    _, _, sb = case
    assert set(sb.named_surfaces) == set(SURFACE_NAMES)
    for s in sb.named_surfaces.values():
        assert s.degree_u == 3 and s.degree_v == 3 and not s.is_rational


def test_shared_edges_coincide(case):
    """Every pair of adjacent surfaces meets to 1e-12 D at 200 points per edge."""
    _, model, sb = case
    D = 2.0 * model.blade.radius
    for e in shared_edge_report(sb.named_surfaces, samples=200):
        assert e["max_gap"] <= 1e-12 * D, e["edge"]


def test_shared_control_points_are_identical(case):
    _, _, sb = case
    P = {k: s.control_points for k, s in sb.named_surfaces.items()}
    assert np.array_equal(P["pressure_central"][-1], P["leading_edge"][0])
    assert np.array_equal(P["pressure_central"][0], P["trailing_edge"][-1])
    assert np.array_equal(P["suction_central"][0], P["leading_edge"][-1])
    assert np.array_equal(P["suction_central"][-1], P["trailing_edge"][0])
    assert np.array_equal(P["pressure_central"][:, -1], P["tip"][:, 0])
    assert np.array_equal(P["suction_central"][:, -1], P["tip"][::-1, -1])
    assert np.array_equal(P["leading_edge"][:, -1], P["tip"][-1])
    assert np.array_equal(P["trailing_edge"][::-1, -1], P["tip"][0])


def test_normals_continuous_across_edges(case):
    """Below 1° across every shared edge (away from the tip surface's 180° corners)."""
    _, _, sb = case
    for e in shared_edge_report(sb.named_surfaces):
        assert e["max_normal_angle_deg"] < 1.0, e["edge"]


def test_accuracy_outside_and_inside_smoothing_zone(case):
    """Within the tolerance outside the zone and the bound inside, or a warning with the
    figure (issue 15: the tip surface of the skewed demo departs from the blade between
    its cuts at the trailing edge near the tip by about 1.8e-4 D, which the earlier
    report, projecting from the nearest cut only, did not see)."""
    name, model, sb = case
    R = model.blade.radius
    dev = sb.report["deviation_m"]
    warnings = " ".join(sb.report["warnings"])
    if name == "dtmb4119":
        assert dev["max_outside"] <= sb.settings.tolerance * R
    if dev["max_outside"] > sb.settings.tolerance * R:
        assert f"{dev['max_outside']:.3g} m" in warnings and "tolerance" in warnings
    assert dev["max_inside"] <= SMOOTHING_ZONE_BOUND * R


def test_deviation_measured_independently(case):
    """Random points of the central surfaces project onto b within the tolerance."""
    _, model, sb = case
    rng = np.random.default_rng(5)
    u, v = rng.uniform(0, 1, 300), rng.uniform(0, 1, 300)
    for name in ("pressure_central", "suction_central", "leading_edge", "trailing_edge"):
        X = sb.named_surfaces[name].evaluate(u, v)
        d, _ = project_to_blade(model.blade, X, sb.parameter_surfaces[name].evaluate(u, v))
        assert d.max() <= sb.settings.tolerance * model.blade.radius, name


def test_outward_normals(case):
    _, model, sb = case
    t = np.array([0.25, 0.5, 0.75])
    for name in ("pressure_central", "suction_central", "leading_edge", "trailing_edge"):
        n = sb.named_surfaces[name].normal(t, t)
        p = sb.parameter_surfaces[name].evaluate(t, t)
        nb = model.blade.normal(p[:, 0], p[:, 1])
        assert np.all(np.einsum("ij,ij->i", n, nb) > 0.99), name
    # tip: compare with the pressure central surface across their shared edge
    a = sb.tip.normal(t, np.zeros(3))
    b = sb.pressure_central.normal(t, np.ones(3))
    assert np.all(np.einsum("ij,ij->i", a, b) > 0.99)


def test_edge_curves_pass_through_edge_points(case):
    """Every curve around the LE/TE meets the edge at t = 1/2 (Hally Eqs. 24, 47)."""
    _, model, sb = case
    c = sb.curves
    for fam, s_edge in ((c.leading, c.s_le_curves), (c.trailing, c.s_te_curves)):
        P = np.stack([crv.parameters(np.array([0.5]))[0] for crv in fam])
        expect = c.lete.parameters(s_edge)
        assert np.allclose(P[:, 1], expect[:, 1], atol=1e-9)
        assert np.allclose(np.mod(P[:, 0] - expect[:, 0] + 0.5, 1.0) - 0.5, 0.0, atol=1e-9)


def test_tip_cut_fairness(case):
    """Smoothing adds no curvature sign change to any tip cut."""
    _, model, sb = case
    for r in tip_cut_fairness(model.blade, sb.curves, sb.tip):
        assert r["sign_changes_smoothed"] <= r["sign_changes_unsmoothed"], r
        assert r["sign_changes_surface"] <= r["sign_changes_unsmoothed"], r


def test_settings_in_metres_match_fractions_of_r(case):
    _, model, sb = case
    R = model.blade.radius
    s = SmoothingSettings.from_metres({"delta_c": 0.02 * R, "tolerance": 2e-5 * R, "transition_s": 0.75}, R)
    assert np.isclose(s.delta_c, 0.02) and np.isclose(s.tolerance, 2e-5) and s.transition_s == 0.75


def test_report_contents(case):
    _, _, sb = case
    r = sb.report
    assert r["cuts"]["tip"] >= 4 and r["cuts"]["smoothed"] > 0
    assert r["knots"]["n_knots"] == len(sb.tip.knots_v)
    assert set(r["newton_fallbacks"]) == {"xi_search", "bisection"}
    assert 0 < r["transition_index"] < r["cuts"]["leading_edge"]
    assert len(sb.overlays["cuts"]) == r["cuts"]["tip"] + r["cuts"]["leading_edge"] + r["cuts"]["trailing_edge"]
    assert sb.overlays["lete"].shape[1] == 3
