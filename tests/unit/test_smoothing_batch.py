"""Issue 22: the batched parts of Hally (2013) tip smoothing give what the one-by-one
parts give: the cuts smoothed together (§7) bit for bit as each alone, the guard's window
and curvature measure as the per-cut scan and spline, and the marching surrogate built
row by row as the whole grid."""
from __future__ import annotations

import pathlib

import numpy as np
import pytest

from bladesmith.geometry.propeller import Propeller
from bladesmith.geometry.propeller.cut_smoothing import GUARD_BOUND_FRACTION, SMOOTHING_ZONE_BOUND, smooth_cuts
from bladesmith.geometry.propeller.cuts import BladeCache
from bladesmith.geometry.propeller.irregularity import (
    curve_excess_many,
    curve_excess_uniform,
    measure_window,
    measure_windows,
)
from bladesmith.geometry.propeller.smoothing import SmoothingSettings, smooth_blade

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def dtmb():
    model = Propeller.from_toml(ROOT / "data" / "propellers" / "dtmb4119.toml").build()
    return model, smooth_blade(model, measure=False)


def _kw(model, settings=SmoothingSettings()):
    R = model.blade.radius
    return dict(d_t=settings.tip_smoothing_distance * R, d_e=settings.edge_smoothing_distance * R,
                strength=settings.filter_strength, iterations=settings.filter_iterations,
                spacing=settings.sample_spacing * R,
                edge_spacing=settings.sample_spacing * settings.edge_spacing_ratio * R,
                bound=GUARD_BOUND_FRACTION * SMOOTHING_ZONE_BOUND * R)


def test_cuts_smoothed_together_equal_each_alone(dtmb):
    model, sb = dtmb
    keys = [k for k in sb.curves.smoothing if k[0] == "tip"][:4]
    cuts = [sb.curves.cuts["tip"][i] for _, i in keys]
    a = [0.02 * model.blade.radius * (1 + i) for i in range(len(cuts))]  # distances to the tip
    together = smooth_cuts(model.blade, cuts, a, **_kw(model))
    t = np.linspace(0.0, 1.0, 157)
    for cut, ai, joint in zip(cuts, a, together):
        alone = smooth_cuts(model.blade, [cut], [ai], **_kw(model))[0]
        assert joint.iterations == alone.iterations
        assert np.array_equal(joint.after, alone.after)
        assert np.array_equal(joint.curve.points(model.blade, t), alone.curve.points(model.blade, t))
    assert any(j.iterations > 0 for j in together)  # the filter acted


def test_guard_window_and_curvature_match_the_scan(dtmb):
    model, sb = dtmb
    d_e = SmoothingSettings().edge_smoothing_distance * model.blade.radius
    cuts = sb.curves.cuts["tip"][2:-2]
    windows = measure_windows(model.blade, cuts, d_e)
    for cut, tw in zip(cuts, windows):
        assert np.array_equal(tw, measure_window(model.blade, cut, d_e))
    tw = windows[len(cuts) // 2]
    X = np.stack([c.curve.points(model.blade, tw) for c in cuts])
    ref = curve_excess_many(tw, X)
    assert np.count_nonzero(ref > 1.0) > len(cuts) // 2  # irregular curves, not only fair ones
    np.testing.assert_allclose(curve_excess_uniform(X), ref, rtol=1e-7, atol=1e-9 * ref.max())


def test_surrogate_rows_built_on_demand_equal_the_whole_grid(dtmb):
    model, _ = dtmb
    lazy, whole = BladeCache(model.blade), BladeCache(model.blade)
    whole._build_rows(whole.n_w)
    rng = np.random.default_rng(3)
    for eta_lo in (0.99, 0.9, 0.6, model.blade.eta_min):  # rows reached step by step
        p = np.stack([rng.uniform(-0.2, 1.2, 200), rng.uniform(eta_lo, 1.0, 200)], axis=1)
        assert np.array_equal(lazy.derivatives(p), whole.derivatives(p))
    assert lazy.rows == whole.rows == whole.n_w


def test_report_pairs_the_shared_edges_of_a_left_handed_blade():
    """smooth_blade's shared-edge report compares the surfaces that share each edge also
    when the central surfaces are swapped (left hand): gaps at 1e-12 D, as the control
    rows are copies (it reported 0.06 m on the raked demo)."""
    model = Propeller.from_toml(ROOT / "data" / "propellers" / "raked_demo.toml").build()
    assert model.blade.hand < 0
    sb = smooth_blade(model, SmoothingSettings(filter_iterations=0))
    D = 2.0 * model.blade.radius
    assert len(sb.report["shared_edges"]) == 8
    for e in sb.report["shared_edges"]:
        assert e["max_gap"] <= 1e-12 * D, e
