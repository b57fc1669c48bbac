"""Hub h(ξ_h, θ) and the blade–hub intersection (Hally 2013 §10)."""
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.propeller import Propeller, blade_hub_intersection

PRESETS = pathlib.Path(__file__).resolve().parents[2] / "data" / "propellers"
NAMES = ["dtmb4119", "skewed_demo", "raked_demo"]


@pytest.fixture(scope="module", params=NAMES)
def model(request):
    return Propeller.from_toml(PRESETS / f"{request.param}.toml").build()


def test_spine_closes_on_the_axis_and_runs_downstream(model):
    hub, d = model.hub, model.definition
    ends = hub.spine.evaluate(np.array([0.0, 1.0]))
    assert np.allclose(ends[:, 0], 0.0, atol=1e-15)
    assert ends[0, 1] == pytest.approx(-d.hub.upstream_length) and ends[1, 1] == pytest.approx(d.hub.downstream_length)
    z = hub.spine.evaluate(np.linspace(0, 1, 200))[:, 1]
    assert np.all(np.diff(z) >= -1e-15)
    # the cylindrical part has the hub radius
    a, b = hub._cylinder_params
    assert np.allclose(hub.spine.evaluate(np.linspace(a, b, 20))[:, 0], d.hub_radius, rtol=1e-14)


def test_hub_derivatives_and_outward_normal(model):
    hub = model.hub
    rng = np.random.default_rng(3)
    xh, th = rng.uniform(0.02, 0.98, 300), rng.uniform(-np.pi, np.pi, 300)
    # stay off the C0 joins of the spine pieces
    U = hub.spine.knots
    keep = np.min(np.abs(xh[:, None] - np.unique(U)[None, :]), axis=1) > 1e-3
    xh, th = xh[keep], th[keep]
    D = hub.derivatives(xh, th, 2)
    h = 1e-6
    for (k, l), (dx, dt) in {(1, 0): (h, 0), (0, 1): (0, h)}.items():
        fd = (hub.evaluate(xh + dx, th + dt) - hub.evaluate(xh - dx, th - dt)) / (2 * h)
        assert np.allclose(fd, D[:, k, l], atol=1e-7 * np.abs(D[:, k, l]).max())
        fd2 = (hub.derivatives(xh + dx, th + dt, 1) - hub.derivatives(xh - dx, th - dt, 1)) / (2 * h)
        assert np.allclose(fd2[:, 1, 0], D[:, 1 + k, l], atol=1e-6 * np.abs(D[:, 1 + k, l]).max() + 1e-12)
    p = hub.evaluate(xh, th)
    n = hub.normal(xh, th)
    radial = p.copy()
    radial[:, 2] = 0
    assert np.all(np.einsum("ij,ij->i", n, radial) > -1e-12)


def test_intersection_points_lie_on_the_hub(model):
    inter = model.intersection(257)
    assert inter.max_residual < 1e-12
    hub, blade = model.hub, model.blade
    # independently: radius of each intersection point equals the spine radius at its z
    rho = np.hypot(inter.points[:, 0], inter.points[:, 1])
    spine = hub.spine.evaluate(inter.xi_h)
    assert np.max(np.abs(rho - spine[:, 0])) < 1e-12
    assert np.max(np.abs(inter.points[:, 2] - spine[:, 1])) < 1e-12
    # the two parameterizations give the same points
    assert np.max(np.abs(hub.evaluate(inter.xi_h, inter.theta) - blade.evaluate(inter.xi, inter.eta))) < 1e-12
    # and evaluation anywhere (η_h(ξ), p_b(u)) agrees with the sampled curve
    xi = np.array([0.0, 0.123, 0.5, 0.77, 1.0])
    eta = inter.eta_h(xi)
    pb = inter.hub_parameters(xi)
    assert np.max(np.abs(hub.evaluate(pb[:, 0], pb[:, 1]) - blade.evaluate(xi, eta))) < 1e-12
    assert np.all(np.abs(pb[:, 1]) <= np.pi)


def test_cylindrical_hub_gives_constant_eta(model):
    inter = model.blade_hub_intersection
    assert np.allclose(inter.eta, model.definition.hub_diameter_ratio, atol=1e-14)


def test_intersection_on_a_tapered_hub():
    """A nose reaching into the blade root: the intersection follows the taper."""
    p = Propeller.from_toml(PRESETS / "dtmb4119.toml")
    q = p.with_values(hub_upstream_length=0.07, hub_nose_length=0.04, hub_nose_shape="cone")
    model = q.build()
    inter = model.intersection(201)
    assert inter.max_residual < 1e-12
    assert inter.eta.min() < q.hub_diameter_ratio - 1e-3  # part of the root lies on the cone


def test_left_hand_intersection_is_mirrored():
    p = Propeller.from_toml(PRESETS / "skewed_demo.toml")
    right = p.with_values(hand="right").build()
    left = p.with_values(hand="left").build()
    xi = np.linspace(0, 1, 65)
    ir = blade_hub_intersection(right.blade, right.hub, 65)
    il = blade_hub_intersection(left.blade, left.hub, 65)
    assert np.allclose(il.eta, ir.eta[::-1], atol=1e-13)
    assert np.allclose(il.theta, -ir.theta[::-1], atol=1e-12)
    assert np.allclose(il.xi_h, ir.xi_h[::-1], atol=1e-13)
    assert xi.shape == il.xi.shape
