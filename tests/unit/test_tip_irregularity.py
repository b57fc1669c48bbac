"""Issue 15: tip smoothing that removes tip irregularities (Hally 2013 §7) and never adds
them. The measure (geometry/propeller/irregularity.py), the arclength filter, the guard,
and the irregular-tip fixtures of tests/data/irregular_tips."""
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.propeller import Propeller
from bladesmith.geometry.propeller.cut_smoothing import (
    SMOOTHING_ZONE_BOUND,
    edge_distribution,
    filter_matrix,
    fourth_difference_filter,
    fourth_difference_weights,
)
from bladesmith.geometry.propeller.irregularity import excess_curvature_variation
from bladesmith.geometry.propeller.smoothing import SmoothingSettings, smooth_blade

HERE = pathlib.Path(__file__).resolve().parents[1]
IRREGULAR = HERE / "data" / "irregular_tips"
PRESETS = HERE.parent / "data" / "propellers"
#: Several-fold: the default settings must at least divide the measure by this on the
#: steep, coarse irregular tip.
SEVERAL_FOLD = 3.0


def test_excess_curvature_variation():
    rise_fall = np.concatenate([np.full(20, 1.0), np.linspace(1, 50, 40), np.linspace(50, 2, 40)])
    assert excess_curvature_variation(rise_fall) == pytest.approx(0.0, abs=1e-9)
    assert excess_curvature_variation(-rise_fall) == pytest.approx(0.0, abs=1e-9)
    wiggle = rise_fall.copy()
    wiggle[10] += 3.0  # one bump of 3 where the curvature is flat adds 2 * 3
    assert excess_curvature_variation(wiggle) == pytest.approx(6.0)


def test_arclength_filter_is_eq29_on_uniform_samples():
    rng = np.random.default_rng(3)
    Y = rng.standard_normal((30, 3))
    beta = np.full(30, 0.5)
    beta[[0, 1, -2, -1]] = 0.0
    s = np.arange(30) * 0.01
    assert np.allclose(fourth_difference_filter(Y, beta, 7, spacing=s), fourth_difference_filter(Y, beta, 7))


def test_arclength_filter_keeps_cubics_the_index_stencil_does_not():
    """The root of the roughening: on tanh-clustered samples the index-space stencil of
    Eq. 29 moves a curve that is a cubic in arclength; the arclength stencil does not."""
    t = edge_distribution(1.0, 1.0, 0.05, 0.0005)
    s = 2.0 * t - 1.0
    y = s**3 - 0.3 * s**2 + s
    W = fourth_difference_weights(s)
    assert np.max(np.abs(W @ y)) < 1e-9
    index = np.abs(-y[:-4] + 4 * y[1:-3] - 6 * y[2:-2] + 4 * y[3:-1] - y[4:])
    assert index.max() > 1e-6


def test_filter_matrix_is_stable():
    t = edge_distribution(0.3, 0.2, 0.01, 0.0001)
    s = np.cumsum(np.r_[0.0, np.diff(t)])
    beta = np.full(t.size, 0.75)
    beta[[0, 1, -2, -1]] = 0.0
    M = filter_matrix(s, beta)
    assert np.max(np.abs(np.linalg.eigvals(M))) <= 1.0 + 1e-9


@pytest.fixture(scope="module")
def steep():
    return Propeller.from_toml(IRREGULAR / "steep_coarse.toml").build()


@pytest.fixture(scope="module")
def steep_default(steep):
    return smooth_blade(steep, measure=False)


def test_defaults_reduce_the_irregularity_several_fold(steep, steep_default):
    ti = steep_default.report["tip_irregularity"]
    assert ti["curves"] > 0
    assert ti["unsmoothed"] > 0
    assert ti["smoothed"] * SEVERAL_FOLD <= ti["unsmoothed"], ti["ratio"]
    R = steep.blade.radius
    assert steep_default.report["max_smoothing_displacement_m"] <= SMOOTHING_ZONE_BOUND * R


def test_no_iterations_changes_nothing(steep):
    sb = smooth_blade(steep, SmoothingSettings(filter_iterations=0), measure=False)
    ti = sb.report["tip_irregularity"]
    assert ti["smoothed"] == pytest.approx(ti["unsmoothed"], rel=1e-12)
    assert sb.report["max_smoothing_displacement_m"] == 0.0


@pytest.fixture(scope="module")
def steep_strong(steep):
    return smooth_blade(steep, SmoothingSettings(filter_strength=0.75, filter_iterations=10000), measure=False)


def test_strong_settings_never_roughen_nor_break_the_bound(steep, steep_default, steep_strong):
    """10,000 sweeps at the largest α never leave the tip rougher than the defaults, nor
    any cut rougher than unsmoothed, nor move a cut beyond the bound."""
    ti = steep_strong.report["tip_irregularity"]
    assert ti["smoothed"] <= steep_default.report["tip_irregularity"]["smoothed"]
    assert steep_strong.report["max_smoothing_displacement_m"] <= SMOOTHING_ZONE_BOUND * steep.blade.radius
    for pc in ti["per_curve"]:
        assert pc["smoothed"] <= pc["unsmoothed"] * (1 + 1e-9) + 1e-9, pc


def test_guard_reports_a_stop_with_figures(steep_strong):
    stops = [s.stopped for s in steep_strong.curves.smoothing.values() if s.stopped]
    assert stops and all("of 10000 sweeps" in s and "1/m" in s or "bound" in s for s in stops)
    assert steep_strong.report["smoothing_stops"] == stops


def test_skewed_irregular_tip_is_not_made_rougher():
    model = Propeller.from_toml(IRREGULAR / "skewed_fast.toml").build()
    sb = smooth_blade(model, measure=False)
    ti = sb.report["tip_irregularity"]
    assert ti["smoothed"] < ti["unsmoothed"]
    for pc in ti["per_curve"]:
        assert pc["smoothed"] <= pc["unsmoothed"] * (1 + 1e-9) + 1e-9, pc
