"""Pieces of Hally (2013) tip smoothing: settings validation, the tanh distribution and
its sinh Δ/Δ solve, the B-spline modulation, the fourth-difference filter, Eq. 24, the
tip chart, side curves and cuts, refusal of settings that cannot work, left hands."""
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.errors import DefinitionError, GeometryError
from bladesmith.geometry.propeller import Propeller
from bladesmith.geometry.propeller.corners import DefiningPoints, corner_points, from_tip_chart, to_tip_chart
from bladesmith.geometry.propeller.cut_smoothing import (
    bump,
    curvature_sign_changes,
    edge_distribution,
    fourth_difference_filter,
    solve_stretching,
)
from bladesmith.geometry.propeller.cuts import cut_parameters, march_cuts
from bladesmith.geometry.propeller.side_curves import side_curves
from bladesmith.geometry.propeller.smoothing import SmoothingSettings, smooth_blade

PRESETS = pathlib.Path(__file__).resolve().parents[2] / "data" / "propellers"


@pytest.fixture(scope="module")
def dtmb():
    return Propeller.from_toml(PRESETS / "dtmb4119.toml").build()


def test_bump_is_the_scaled_cubic_bspline():
    x = np.linspace(-1.2, 1.2, 241)
    f = bump(x)
    assert bump(0.0) == 1.0 and bump(0.5) == 0.25 and bump(1.0) == 0.0
    assert np.all(f >= 0) and np.all(f[np.abs(x) >= 1] == 0)
    # C2: second differences continuous at ±1/2
    h = 1e-4
    for a in (0.5, -0.5):
        d2 = lambda y: (bump(y + h) - 2 * bump(y) + bump(y - h)) / h**2  # noqa: E731
        assert abs(d2(a - 3 * h) - d2(a + 3 * h)) < 1e-2


@pytest.mark.parametrize("B", [1.0 + 1e-9, 1.0001, 1.5, 10.0, 1e4, 1e12])
def test_solve_stretching(B):
    d = solve_stretching(B)
    if d > 0:
        assert np.isclose(np.sinh(d) / d, B, rtol=1e-10)
    assert solve_stretching(0.5) == 0.0


def test_edge_distribution_spacings():
    L, d, h = 0.2, 0.01, 1e-4
    t = edge_distribution(L, L, d, h)
    n = len(t)
    assert n % 2 == 1 and t[(n - 1) // 2] == 0.5 and t[0] == 0 and t[-1] == 1
    dt = np.diff(t)
    assert np.all(dt > 0)
    # in units of the half length: end spacing ~ d, edge spacing ~ h
    assert np.isclose(2 * L * dt[0], d, rtol=0.2)
    assert np.isclose(2 * L * dt[(n - 1) // 2], h, rtol=0.2)
    ratio = dt[1:(n - 1) // 2] / dt[: (n - 1) // 2 - 1]
    assert ratio.max() / ratio.min() < 1.2  # nearly geometric


def test_fourth_difference_filter_keeps_planes_and_lines():
    rng = np.random.default_rng(1)
    t = np.linspace(0, 1, 40)
    line = np.stack([t, 2 * t, -t], axis=1)
    beta = np.full(40, 0.5)
    assert np.allclose(fourth_difference_filter(line, beta, 30), line)
    noisy = np.stack([t, np.sin(3 * t) + 1e-3 * rng.standard_normal(40), np.zeros(40)], axis=1)
    beta[[0, 1, 20, -2, -1]] = 0.0
    out = fourth_difference_filter(noisy, beta, 30)
    assert np.all(out[:, 2] == 0.0)
    assert np.array_equal(out[[0, 1, 20, -2, -1]], noisy[[0, 1, 20, -2, -1]])
    rough = lambda Y: np.abs(np.diff(Y[:, 1], 4)).sum()  # noqa: E731
    assert rough(out) < 0.5 * rough(noisy)


def test_cut_parameters_eq24():
    a = np.cumsum(np.r_[0, np.full(10, 0.1), np.full(7, 0.13)])
    t = cut_parameters(a, 10)
    assert t[0] == 0 and t[10] == 0.5 and t[-1] == 1 and np.all(np.diff(t) > 0)
    a = np.cumsum(np.r_[0, np.full(10, 0.1), np.full(2, 0.01)])  # very unequal halves
    t = cut_parameters(a, 10)
    assert t[10] == 0.5 and np.all(np.diff(t) > 0)


def test_tip_chart_roundtrip():
    rng = np.random.default_rng(2)
    p = np.stack([rng.uniform(-0.4, 0.9, 100), rng.uniform(0.2, 1.0, 100)], axis=1)
    q = from_tip_chart(to_tip_chart(p), 0.25)
    assert np.allclose(q[:, 1], p[:, 1], atol=1e-12)
    assert np.allclose(np.mod(q[:, 0] - p[:, 0] + 0.5, 1) - 0.5, 0, atol=1e-12)


def test_curvature_sign_changes():
    assert curvature_sign_changes(np.r_[np.ones(5), -np.ones(5), np.ones(3)]) == 2
    assert curvature_sign_changes(np.r_[np.ones(5), 1e-9 * np.array([-1, 1, -1]), np.ones(3)]) == 0


def test_side_curves_keep_linear_distance_from_edge(dtmb):
    b = dtmb.blade
    c = corner_points(b, dtmb.blade_hub_intersection, DefiningPoints())
    sides = side_curves(b, c)
    u = np.linspace(0, 1, 9)
    p6 = sides["c6"].parameters(u)
    assert np.allclose(p6[0], c.lr) and np.allclose(p6[-1], c.ur)
    assert np.all(p6[:, 0] < 0.5) and np.all(np.diff(p6[:, 1]) > 0)
    p8 = sides["c8"].parameters(u)
    assert np.allclose(p8[0], c.lr_s - [1, 0])


def test_cuts_lie_on_their_planes(dtmb):
    b = dtmb.blade
    p0 = np.array([[0.4, 0.6], [0.1, 0.6], [0.3, 0.9]])
    p1 = np.array([[0.5, 0.6], [0.0, 0.6], [0.0, 0.999]])
    p2 = np.array([[0.6, 0.6], [-0.1, 0.6], [-0.3, 0.9]])
    for cut in march_cuts(b, p0, p1, p2):
        t = np.linspace(0, 1, 1001)
        # between the nodes the spline leaves the plane slightly (it stays on the blade)
        assert cut.plane_residual(b, t).max() < 1e-5 * b.radius
        X = cut.curve.points(b, np.array([0.0, 0.5, 1.0]))
        assert np.allclose(X, cut.points, atol=1e-12 * b.radius)
        # nodes are exactly on the plane
        Xn = b.evaluate(cut.params[:, 0], cut.params[:, 1])
        assert np.abs((Xn - cut.points[0]) @ cut.normal).max() < 1e-10 * b.radius


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"delta_c": 0.0}, "delta_c"),
        ({"delta_c": -0.1}, "delta_c"),
        ({"filter_strength": 0.9}, "filter_strength"),
        ({"tolerance": 0.0}, "tolerance"),
        ({"filter_iterations": -1}, "filter_iterations"),
        ({"transition_s": 1.0}, "transition_s"),
    ],
)
def test_settings_refused(kwargs, field):
    with pytest.raises(DefinitionError, match=field):
        SmoothingSettings(**kwargs)


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"transition_s": 0.55}, "transition_s"),  # inside the smoothing range (Eq. 48)
        ({"tip_smoothing_distance": 1.9}, "tip_smoothing_distance"),  # longer than an edge
        ({"delta_c": 0.9}, "delta_c"),  # too few curves
        ({"defining_points": DefiningPoints(xi_ll=0.3)}, "xi_ll"),
    ],
)
def test_settings_that_cannot_work_are_refused(dtmb, kwargs, field):
    with pytest.raises(DefinitionError, match=field):
        smooth_blade(dtmb, SmoothingSettings(**kwargs), measure=False)


def test_left_handed_blade():
    model = Propeller.from_toml(PRESETS / "raked_demo.toml").build()
    sb = smooth_blade(model, measure=False)
    # the pressure side of a left-handed blade is ξ in (1/2, 1)
    p = sb.parameter_surfaces["pressure_central"].evaluate(np.array([0.5]), np.array([0.5]))
    assert 0.5 < p[0, 0] < 1.0
    for name, s in sb.named_surfaces.items():
        assert np.all(np.isfinite(s.control_points)), name


@pytest.mark.parametrize("fail", ["newton", "newton_and_xi"])
def test_fallbacks_of_eqs_21_22_when_newton_fails(dtmb, monkeypatch, fail):
    """Hally §6: when the Newton search along Eq. 20 fails, the ξ-search of Eq. 21 is
    tried, then the bisection of Eq. 22. Newton (and the ξ-search) are made to fail; the
    cuts are still found, exactly on their planes, and the fallbacks are counted."""
    from bladesmith.geometry.propeller import cuts as cuts_module

    def refuse(self, trial, *args):
        return trial.copy(), np.zeros(len(trial), dtype=bool)

    monkeypatch.setattr(cuts_module._PlaneSolver, "newton_line", refuse)
    if fail == "newton_and_xi":
        monkeypatch.setattr(cuts_module._PlaneSolver, "xi_search", refuse)
    b = dtmb.blade
    p0 = np.array([[0.4, 0.6], [0.3, 0.9]])
    p1 = np.array([[0.5, 0.6], [0.0, 0.999]])
    p2 = np.array([[0.6, 0.6], [-0.3, 0.9]])
    found = march_cuts(b, p0, p1, p2)
    xi = sum(c.fallbacks.get("xi_search", 0) for c in found)
    bis = sum(c.fallbacks.get("bisection", 0) for c in found)
    if fail == "newton":
        assert xi > 0
    else:
        assert xi == 0 and bis > 0
    for cut in found:
        Xn = b.evaluate(cut.params[:, 0], cut.params[:, 1])
        assert np.abs((Xn - cut.points[0]) @ cut.normal).max() < 1e-8 * b.radius
        # between the nodes the spline stays on the blade and near the plane (the fallbacks
        # do not keep the spacing of Eq. 23)
        assert cut.plane_residual(b, np.linspace(0, 1, 501)).max() < 5e-5 * b.radius
