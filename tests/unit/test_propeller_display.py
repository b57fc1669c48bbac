"""Display surfaces: the blade approximation stays within its tolerance of b(ξ, η) (checked
on independent random samples, not the fit's own check grid), closes at the trailing edge
and the tip, starts on the hub cylinder; the hub surface of revolution is exact."""
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.errors import GeometryError
from bladesmith.geometry.nurbs import BSplineSurface
from bladesmith.geometry.propeller import Propeller
from bladesmith.geometry.propeller.display import (
    DISPLAY_TOLERANCE_FRACTION,
    blade_display_surface,
    display_deviation,
    eta_of_v,
    full_circle,
    hub_surface,
)

PRESETS = pathlib.Path(__file__).resolve().parents[2] / "data" / "propellers"
NAMES = ["dtmb4119", "skewed_demo", "raked_demo"]


@pytest.fixture(scope="module", params=NAMES)
def model(request):
    return Propeller.from_toml(PRESETS / f"{request.param}.toml").build()


def _random_parameters(count=60000, seed=7):
    """Uniform samples plus samples crowded at the trailing edge, the root and the tip,
    where the error of a spline fit peaks."""
    rng = np.random.default_rng(seed)
    xi, v = rng.random(count), rng.random(count)
    k = count // 8
    xi[:k] *= 0.03
    xi[k : 2 * k] = 1.0 - 0.03 * xi[k : 2 * k]
    v[2 * k : 3 * k] *= 0.03
    v[3 * k : 4 * k] = 1.0 - 0.03 * v[3 * k : 4 * k]
    return xi, v


@pytest.mark.parametrize("fraction", [1e-3, DISPLAY_TOLERANCE_FRACTION])
def test_blade_display_within_tolerance(model, fraction):
    tol = fraction * model.definition.diameter
    display = blade_display_surface(model.blade, tol)
    assert display.max_deviation <= tol
    dev = display_deviation(display, model.blade, *_random_parameters())
    assert dev.max() <= tol, f"independent samples deviate {dev.max():.3g} > {tol:.3g}"
    assert display.surface.degree_u == display.surface.degree_v == 3
    assert display.surface.weights is None


def test_blade_display_closes_and_starts_on_the_hub(model):
    blade = model.blade
    tol = 1e-3 * model.definition.diameter
    display = blade_display_surface(blade, tol)
    S = display.surface
    v = np.linspace(0.0, 1.0, 57)
    # trailing edge: ξ = 0 and ξ = 1 are the same line
    assert np.abs(S.evaluate(0.0, v) - S.evaluate(1.0, v)).max() <= 1e-12 * blade.radius
    xi = np.linspace(0.0, 1.0, 101)
    # root edge on the hub cylinder (r = η_s R with η_s the hub radius ratio), within tol
    root = S.evaluate(xi, 0.0)
    assert np.abs(np.hypot(root[:, 0], root[:, 1]) - blade.hub_ratio * blade.radius).max() <= tol
    # tip: a closed tip collapses to the tip point of b
    tip = S.evaluate(xi, 1.0)
    if display.closed_tip:
        assert np.abs(tip - blade.evaluate(0.5, 1.0)).max() <= 1e-12 * blade.radius


def test_eta_map_is_onto_the_blade_span():
    v = np.linspace(0.0, 1.0, 11)
    for closed in (True, False):
        eta = eta_of_v(v, 0.2, closed)
        assert eta[0] == 0.2 and eta[-1] == 1.0
        assert np.all(np.diff(eta) > 0)


def test_seeded_knots_keep_the_net_when_they_suffice():
    prop = Propeller.from_toml(PRESETS / "dtmb4119.toml")
    tol = DISPLAY_TOLERANCE_FRACTION * prop.diameter
    first = blade_display_surface(prop.build().blade, tol)
    edited = prop.with_values(radial_P_D=tuple(p * 1.01 for p in prop.radial.P_D)).build()
    knots = (first.surface.knots_u, first.surface.knots_v)
    again = blade_display_surface(edited.blade, tol, knots=knots)
    assert again.surface.shape == first.surface.shape
    assert np.array_equal(again.surface.knots_u, first.surface.knots_u)
    assert display_deviation(again, edited.blade, *_random_parameters(20000)).max() <= tol


def test_bad_arguments_are_refused(model):
    with pytest.raises(GeometryError, match="tolerance"):
        blade_display_surface(model.blade, 0.0)
    with pytest.raises(GeometryError, match="knots_u"):
        blade_display_surface(model.blade, 1e-3, knots=(np.array([0.0, 0.5, 1.0]), np.linspace(0, 1, 8)))


def test_left_hand_blade_display():
    prop = Propeller.from_toml(PRESETS / "skewed_demo.toml").with_values(hand="left")
    model = prop.build()
    tol = 1e-3 * prop.diameter
    display = blade_display_surface(model.blade, tol)
    assert display_deviation(display, model.blade, *_random_parameters(20000)).max() <= tol


# -- hub ------------------------------------------------------------------------------------
def test_full_circle_is_a_unit_circle():
    knots, points, weights = full_circle()
    from bladesmith.geometry.nurbs import BSplineCurve

    circle = BSplineCurve(2, knots, points, weights)
    P = circle.evaluate(np.linspace(0.0, 1.0, 1001))
    assert np.abs(np.hypot(P[:, 0], P[:, 1]) - 1.0).max() <= 1e-14
    # starts at +y (θ = 0) and turns towards +x first
    assert np.allclose(P[0], (0.0, 1.0)) and P[10, 0] > 0


def test_hub_surface_is_the_exact_revolution_of_the_spine(model):
    hub = model.hub
    S = hub_surface(hub)
    assert isinstance(S, BSplineSurface) and S.degree_u == S.degree_v == 2 and S.weights is not None
    us, vs = np.linspace(0.0, 1.0, 301), np.linspace(0.0, 1.0, 203)
    X = S.evaluate_grid(us, vs)
    C = hub.spine.evaluate(us)  # same u parameter: the spine's weights carry over
    scale = hub.radius + np.abs(C[:, 1]).max()
    assert np.abs(np.hypot(X[..., 0], X[..., 1]) - C[:, None, 0]).max() <= 1e-14 * scale
    assert np.abs(X[..., 2] - C[:, None, 1]).max() <= 1e-14 * scale
    # the circle covers every angle
    theta = np.arctan2(X[150, :, 0], X[150, :, 1])
    assert np.ptp(np.unwrap(theta)) == pytest.approx(2 * np.pi, abs=1e-12)


def test_hub_surface_normal_points_out(model):
    S = hub_surface(model.hub)
    a, b = model.hub._cylinder_params
    u = np.linspace(a, b, 7)[1:-1]
    v = np.linspace(0.0, 1.0, 13)[:-1] + 0.01
    U, V = np.meshgrid(u, v, indexing="ij")
    n = S.normal(U, V)
    P = S.evaluate(U, V)
    radial = P.copy()
    radial[..., 2] = 0.0
    assert np.all(np.sum(n * radial, axis=-1) > 0)
