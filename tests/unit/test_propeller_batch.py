"""Batched evaluation used for the speed of tip smoothing (issue 22): many splines with
their own knots at once, and the curves of Hally §8 in groups, against the one-by-one
evaluation they replace."""
import pathlib

import numpy as np
import pytest
from scipy.interpolate import make_interp_spline

from bladesmith.geometry.errors import GeometryError
from bladesmith.geometry.nurbs.curve import evaluate_splines
from bladesmith.geometry.propeller import Propeller
from bladesmith.geometry.propeller.batch import curve_displacement, curve_parameters
from bladesmith.geometry.propeller.corners import blade_points, corner_points
from bladesmith.geometry.propeller.edge_curves import build_edge_curves
from bladesmith.geometry.propeller.side_curves import side_curves
from bladesmith.geometry.propeller.smoothing import SmoothingSettings

PRESETS = pathlib.Path(__file__).resolve().parents[2] / "data" / "propellers"


def test_evaluate_splines_matches_each_spline():
    rng = np.random.default_rng(7)
    splines = []
    for k in range(9):
        n = int(rng.integers(5, 40))
        x = np.sort(np.concatenate([[0.0, 1.0], rng.uniform(0.0, 1.0, n - 2)]))
        splines.append(make_interp_spline(x, rng.normal(size=(n, 2)), k=3))
    t = np.concatenate([[0.0, 1.0, 0.5], rng.uniform(0.0, 1.0, 50), splines[3].t[5:9]])
    got = evaluate_splines([s.t for s in splines], [s.c for s in splines], 3, t)
    want = np.stack([s(t) for s in splines])
    assert got.shape == want.shape
    assert np.max(np.abs(got - want)) < 1e-12 * max(1.0, np.abs(want).max())


def test_evaluate_splines_refuses_mismatched_knots():
    s = make_interp_spline(np.linspace(0, 1, 8), np.arange(16.0).reshape(8, 2), k=3)
    with pytest.raises(GeometryError):
        evaluate_splines([s.t[:-1]], [s.c], 3, [0.5])


@pytest.fixture(scope="module")
def dtmb_curves():
    model = Propeller.from_toml(PRESETS / "dtmb4119.toml").build()
    blade = model.blade
    settings = SmoothingSettings()
    corners = corner_points(blade, model.blade_hub_intersection, settings.defining_points)
    curves = build_edge_curves(blade, corners, side_curves(blade, corners), settings)
    return blade, curves


def test_curve_parameters_match_one_by_one(dtmb_curves):
    blade, curves = dtmb_curves
    family = curves.leading + curves.trailing + curves.tip  # TFI curves, cuts, smoothed cuts, a reversed cut
    kinds = {type(c).__name__ for c in family}
    assert {"TFICurve", "SplineCurve", "ReversedCurve"} <= kinds
    t = np.linspace(0.0, 1.0, 37)
    got = curve_parameters(family, t)
    want = np.stack([c.parameters(t) for c in family])
    assert np.max(np.abs(got - want)) < 1e-13
    # the smoothed cuts' displacement given the exact points equals their own
    smoothed = [c for c in family if c.displacement(t) is not None]
    assert smoothed
    for c in smoothed:
        exact = blade_points(blade, c.parameters(t))
        assert np.max(np.abs(curve_displacement(c, t, exact) - c.displacement(t))) < 1e-15 * blade.radius + 1e-15


def _jet_derivatives(blade, xi, eta, order):
    with np.errstate(divide="ignore", invalid="ignore"):
        comps = blade._jets(xi, eta, order)
    out = np.zeros(np.broadcast_shapes(np.shape(xi), np.shape(eta)) + (order + 1, order + 1, 3))
    for k, jet in enumerate(comps):
        jet.stack_into(out, k, order)
    return out


@pytest.mark.parametrize("hand", [1, -1])
@pytest.mark.parametrize("cambered", [True, False])
def test_blade_fast_paths_equal_the_jets(hand, cambered):
    """b and its first derivatives written out (the speed path) give the jets' numbers bit
    for bit, tip points (infinite η-derivatives) included."""
    import dataclasses

    blade = Propeller.from_toml(PRESETS / "dtmb4119.toml").build().blade
    section = blade.section if cambered else dataclasses.replace(blade.section, meanline=None)
    blade = dataclasses.replace(blade, hand=hand, section=section)
    rng = np.random.default_rng(3)
    xi = rng.uniform(-1.0, 2.0, 400)
    eta = rng.uniform(blade.eta_min, 1.0, 400)
    eta[:4] = 1.0
    assert np.array_equal(blade.evaluate(xi, eta), _jet_derivatives(blade, xi, eta, 0)[..., 0, 0, :])
    assert np.array_equal(blade.derivatives(xi, eta, 1), _jet_derivatives(blade, xi, eta, 1), equal_nan=True)
    grid = (xi[:30, None], eta[None, :20])
    assert np.array_equal(blade.derivatives(*grid, 1), _jet_derivatives(blade, *grid, 1), equal_nan=True)


def test_mixed_derivatives_equal_the_full_second_order():
    blade = Propeller.from_toml(PRESETS / "dtmb4119.toml").build().blade
    xi = np.linspace(0.0, 1.0, 64, endpoint=False)[:, None]
    eta = np.linspace(blade.eta_min, 1.0 - 1e-12, 17)[None, :]
    full = blade.derivatives(xi, eta, 2)
    mixed = blade.mixed_derivatives(xi, eta)
    for k, l in ((0, 0), (1, 0), (0, 1), (1, 1)):
        assert np.array_equal(mixed[..., k, l, :], full[..., k, l, :])
    assert not np.any(mixed[..., 2, 0, :]) and not np.any(mixed[..., 0, 2, :])


def test_outline_check_remembered_per_section_and_ratios():
    """The self-intersection check is remembered for a section and its (t/c, f/c) values
    (a pitch edit reuses it), and a change of t/c on the same section is still checked
    and refused."""
    import dataclasses

    from bladesmith.geometry.errors import DefinitionError
    from bladesmith.geometry.propeller.blade import BladeSurface

    propeller = Propeller.from_toml(PRESETS / "dtmb4119.toml")
    section = propeller.section.shape(propeller.base_dir, propeller.source)
    first = BladeSurface.from_definition(propeller, section=section)
    radial = propeller.radial
    pitched = dataclasses.replace(propeller, radial=dataclasses.replace(radial, P_D=tuple(1.01 * p for p in radial.P_D)))
    second = BladeSurface.from_definition(pitched, section=section)  # same sections: the remembered check
    assert np.all(second.evaluate(0.25, 0.6) != first.evaluate(0.25, 0.6))
    t_c, f_c = list(radial.t_c), list(radial.f_c)
    t_c[0], f_c[0] = 0.95, 0.45
    folded = dataclasses.replace(propeller, radial=dataclasses.replace(radial, t_c=tuple(t_c), f_c=tuple(f_c)))
    with pytest.raises(DefinitionError, match="self-intersects"):
        BladeSurface.from_definition(folded, section=section)
    with pytest.raises(DefinitionError, match="self-intersects"):  # and again, from the memory
        BladeSurface.from_definition(folded, section=section)
