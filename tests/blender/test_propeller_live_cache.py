"""The propeller panel's live path with tip smoothing on reuses what an edit leaves as it
is: the smoothed blade (same model, same smoothing settings), the overlay splines (same
polylines), and shows the smoothed patches at their own display resolution. Every input
of the smoothed blade must invalidate the reuse (a stale blade is never shown)."""
from dataclasses import replace

import bpy
import numpy as np
import pytest

from bladesmith.operators import propeller as ops


class Counting:
    """ops.smooth_blade replaced by a recorder of its calls (the real one underneath)."""

    def __init__(self, monkeypatch, fake: bool = False):
        self.calls = 0
        self.fake = fake
        self.real = ops.smooth_blade
        monkeypatch.setattr(ops, "smooth_blade", self)

    def __call__(self, model, settings, **kwargs):
        self.calls += 1
        if self.fake:
            return object()
        return self.real(model, settings, **kwargs)


def _values():
    """Panel smoothing values (fractions of D) of the defaults, valid for DTMB 4119."""
    return {
        "delta_c": ops.DEFAULT_DELTA_C, "tip_smoothing_distance": ops.DEFAULT_TIP_SMOOTHING_DISTANCE,
        "edge_smoothing_distance": ops.DEFAULT_EDGE_SMOOTHING_DISTANCE, "transition_s": ops.DEFAULT_TRANSITION_S,
        "filter_strength": ops.DEFAULT_FILTER_STRENGTH, "filter_iterations": ops.DEFAULT_FILTER_ITERATIONS,
        "tolerance": ops.DEFAULT_TOLERANCE, "sample_spacing": 0.005, "edge_spacing_ratio": 0.025,
        "xi_ll": 0.1, "xi_lr": 0.4, "xi_ul": 0.1, "eta_ul": 0.9, "xi_ur": 0.4, "eta_ur": 0.9,
        "eta_le": 0.9, "eta_te": 0.9,
    }


def test_smoothed_blade_is_reused_only_for_the_same_model_and_settings(monkeypatch):
    """An edit of any one smoothing setting, or a new model, smooths again; the same
    inputs reuse the last result; measuring (the operators) always smooths."""
    counter = Counting(monkeypatch, fake=True)
    ops._LAST_SMOOTHED.clear()
    propeller = ops.load_definition("", "DTMB4119")
    model = ops.build_model(propeller)
    values = _values()
    assert set(values) == set(ops.SMOOTHING_FIELDS)
    settings = ops.smoothing_settings(values, propeller.diameter)
    first = ops.smoothed_blade(model, settings)
    assert counter.calls == 1
    assert ops.smoothed_blade(model, ops.smoothing_settings(dict(values), propeller.diameter)) is first
    assert counter.calls == 1
    for name in ops.SMOOTHING_FIELDS:
        edited = dict(values)
        edited[name] = values[name] + 1 if name == "filter_iterations" else values[name] * 1.01
        calls = counter.calls
        ops.smoothed_blade(model, ops.smoothing_settings(edited, propeller.diameter))
        assert counter.calls == calls + 1, name
        ops.smoothed_blade(model, settings)  # back to the first settings: smoothed again
        assert counter.calls == calls + 2, name
    # a settings dict changed in place after the call does not alias the cached key
    mutable = ops.smoothing_settings(values, propeller.diameter)
    again = ops.smoothed_blade(model, mutable)
    mutable["defining_points"]["eta_te"] = 0.91
    calls = counter.calls
    assert ops.smoothed_blade(model, mutable) is not again and counter.calls == calls + 1
    # another model (an edited definition builds a new one) smooths again
    other = ops.build_model(replace(propeller, blades=4))
    assert other is not model
    calls = counter.calls
    ops.smoothed_blade(other, settings)
    assert counter.calls == calls + 1
    # measuring never reuses
    ops.smoothed_blade(other, settings, measure=True)
    assert counter.calls == calls + 2
    ops._LAST_SMOOTHED.clear()


@pytest.fixture
def smoothed_root(scene):
    ops._LAST_SMOOTHED.clear()
    assert bpy.ops.bladesmith.add_propeller(preset="dtmb4119", smooth_tip=True, show_overlay=True) == {"FINISHED"}
    (root,) = [obj for obj in bpy.data.objects if ops.find_root(obj) is obj]
    yield root
    ops._LAST_SMOOTHED.clear()


def _blade_points(root):
    return [np.array(obj[ops.PROPERTY_KEY]["control_points"]) for key, obj in sorted(ops.propeller_parts(root).items())
            if key[0] == "blade" and key[2] == 0]


def test_panel_edits_reuse_or_redo_the_smoothing(smoothed_root, monkeypatch):
    """Display and overlay edits reuse the smoothed blade (and leave the patches as they
    are); a smoothing-setting edit and a definition edit smooth again and change them."""
    root = smoothed_root
    s = root.bladesmith_propeller
    s.display_tolerance = s.display_tolerance  # the first live edit after the operator
    counter = Counting(monkeypatch)
    before = _blade_points(root)
    s.display_tolerance = 2.0 * s.display_tolerance
    s.show_overlay = False
    s.show_overlay = True
    assert not s.status_is_error, s.status
    assert counter.calls == 0
    assert all(np.array_equal(a, b) for a, b in zip(before, _blade_points(root)))
    s.delta_c = 1.2 * s.delta_c
    assert not s.status_is_error, s.status
    assert counter.calls == 1
    after_delta = _blade_points(root)
    assert not all(a.shape == b.shape and np.array_equal(a, b) for a, b in zip(before, after_delta))
    s.radial[5].P_D = 1.01 * s.radial[5].P_D
    assert not s.status_is_error, s.status
    assert counter.calls == 2
    assert not all(a.shape == b.shape and np.array_equal(a, b) for a, b in zip(after_delta, _blade_points(root)))


def test_overlay_splines_are_rebuilt_only_when_the_polylines_change(smoothed_root):
    root = smoothed_root
    s = root.bladesmith_propeller
    cuts = ops.propeller_parts(root)[("overlay", 0, 0)].data
    marker = (9.0, 9.0, 9.0, 1.0)
    cuts.splines[0].points[0].co = marker  # stands for "the splines were not rebuilt"
    s.display_tolerance = 2.0 * s.display_tolerance  # the same smoothed blade: same polylines
    assert tuple(cuts.splines[0].points[0].co) == marker
    s.delta_c = 1.2 * s.delta_c  # other cuts
    assert not s.status_is_error, s.status
    assert tuple(cuts.splines[0].points[0].co) != marker


def test_smoothed_patches_at_their_own_display_resolution(smoothed_root):
    root = smoothed_root
    blades = [obj for key, obj in ops.propeller_parts(root).items() if key[0] == "blade"]
    assert len(blades) == 15
    res = ops.SMOOTHED_BLADE_RESOLUTION
    assert all((o.data.splines[0].resolution_u, o.data.splines[0].resolution_v) == (res, res) for o in blades)
    root.bladesmith_propeller.smooth_tip = False
    blade = ops.propeller_parts(root)[("blade", 0, 0)]
    assert (blade.data.splines[0].resolution_u, blade.data.splines[0].resolution_v) == (ops.BLADE_RESOLUTION,) * 2
