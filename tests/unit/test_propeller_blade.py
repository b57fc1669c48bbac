"""The blade b(ξ, η): closed blunt TE, orientation, mirror symmetry, analytic derivatives,
cylindrical sections, C2 across stations, skewed and raked blades."""
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.errors import GeometryError
from bladesmith.geometry.propeller import Propeller

PRESETS = pathlib.Path(__file__).resolve().parents[2] / "data" / "propellers"
MIRROR = np.diag([-1.0, 1.0, 1.0])


@pytest.fixture(scope="module")
def dtmb():
    return Propeller.from_toml(PRESETS / "dtmb4119.toml")


@pytest.fixture(scope="module")
def blade(dtmb):
    return dtmb.build().blade


def _params(blade, n=2000, seed=7, tip_margin=0.0):
    rng = np.random.default_rng(seed)
    return rng.uniform(0, 1, n), rng.uniform(blade.eta_min, 1.0 - tip_margin, n)


def test_closed_trailing_edge_and_equal_normals(blade):
    eta = np.linspace(blade.eta_min, 0.999, 400)
    assert np.max(np.abs(blade.evaluate(0.0, eta) - blade.evaluate(1.0, eta))) <= 1e-15
    assert np.max(np.abs(blade.normal(0.0, eta) - blade.normal(1.0, eta))) < 1e-9


def test_trailing_edge_is_blunt(blade):
    """One-sided tangents b_ξ just before and after the TE agree (no corner): the
    normals at ξ = ±ε converge to one another linearly in ε."""
    eta = np.linspace(blade.eta_min, 0.99, 50)
    gaps = [np.max(np.linalg.norm(blade.normal(eps, eta) - blade.normal(1.0 - eps, eta), axis=-1)) for eps in (1e-4, 1e-5)]
    assert gaps[1] < 0.2 * gaps[0]
    # and b_ξ itself is continuous through the TE (periodic C2 in ξ)
    D0, D1 = blade.derivatives(0.0, eta), blade.derivatives(1.0, eta)
    assert np.allclose(D0[..., :, :, :], D1[..., :, :, :], rtol=0, atol=1e-12 * np.abs(D0).max())


def test_periodic_in_xi(blade):
    xi, eta = _params(blade, 200)
    assert np.allclose(blade.evaluate(xi - 1.0, eta), blade.evaluate(xi, eta), atol=1e-15)
    assert np.allclose(blade.derivatives(xi + 1.0, eta), blade.derivatives(xi, eta), rtol=1e-12, atol=1e-12)


def test_normal_points_outward(blade):
    xi = np.linspace(0.0, 1.0, 400, endpoint=False)[:, None]
    for eta in (0.25, 0.5, 0.8, 0.97):
        pts = blade.evaluate(xi, eta)
        nrm = blade.normal(xi, eta)
        centre = pts.mean(axis=0)
        assert np.all(np.einsum("...k,...k->...", pts - centre, nrm) > 0)


def test_pressure_side_first_and_leading_edge_upstream(blade):
    """ξ in (0, 0.5) is the pressure side (facing downstream, +z) and the LE (ξ = 0.5) is
    upstream of the TE; the LE leads in the rotation (towards +x at the reference line)."""
    eta = 0.7
    le, te = blade.evaluate(0.5, eta), blade.evaluate(0.0, eta)
    assert le[2] < te[2] and le[0] > te[0]
    assert blade.normal(0.3, eta)[2] > 0 and blade.normal(0.7, eta)[2] < 0


def test_points_lie_on_cylinders(blade):
    xi, eta = _params(blade)
    p = blade.evaluate(xi, eta)
    assert np.allclose(np.hypot(p[:, 0], p[:, 1]), blade.radius * eta, rtol=1e-14, atol=1e-15)


@pytest.mark.parametrize("preset", ["dtmb4119", "skewed_demo", "raked_demo"])
def test_left_hand_is_mirror_image(preset):
    p = Propeller.from_toml(PRESETS / f"{preset}.toml")
    right = p.with_values(hand="right").build().blade
    left = p.with_values(hand="left").build().blade
    xi, eta = _params(right)
    assert np.max(np.abs(left.evaluate(xi, eta) - right.evaluate(1.0 - xi, eta) @ MIRROR)) < 1e-12
    # derivatives: ξ reversed, x mirrored
    DL, DR = left.derivatives(xi, eta), right.derivatives(1.0 - xi, eta) @ MIRROR
    sign = np.array([1.0, -1.0, 1.0])[:, None, None]  # (-1)^k for ∂^k/∂ξ^k
    assert np.max(np.abs(DL - sign * DR)) < 1e-12 * np.max(np.abs(DR[np.isfinite(DR)]))
    # both normals point outwards
    assert np.allclose(left.normal(xi, eta), right.normal(1.0 - xi, eta) @ MIRROR, atol=1e-10)


@pytest.mark.parametrize("preset", ["dtmb4119", "skewed_demo", "raked_demo"])
def test_analytic_derivatives_match_finite_differences(preset):
    blade = Propeller.from_toml(PRESETS / f"{preset}.toml").build().blade
    h = 1e-5
    xi, eta = _params(blade, 500, tip_margin=0.02)
    eta = np.clip(eta, blade.eta_min + 2 * h, None)
    D = blade.derivatives(xi, eta, 2)
    Dxp, Dxm = blade.derivatives(xi + h, eta, 1), blade.derivatives(xi - h, eta, 1)
    Dep, Dem = blade.derivatives(xi, eta + h, 1), blade.derivatives(xi, eta - h, 1)

    def close(fd, exact, name):
        scale = np.max(np.abs(exact))
        assert np.max(np.abs(fd - exact)) < 1e-6 * scale, name

    close((Dxp[:, 0, 0] - Dxm[:, 0, 0]) / (2 * h), D[:, 1, 0], "b_xi")
    close((Dep[:, 0, 0] - Dem[:, 0, 0]) / (2 * h), D[:, 0, 1], "b_eta")
    close((Dxp[:, 1, 0] - Dxm[:, 1, 0]) / (2 * h), D[:, 2, 0], "b_xixi")
    close((Dep[:, 1, 0] - Dem[:, 1, 0]) / (2 * h), D[:, 1, 1], "b_xieta")
    close((Dxp[:, 0, 1] - Dxm[:, 0, 1]) / (2 * h), D[:, 1, 1], "b_etaxi")
    close((Dep[:, 0, 1] - Dem[:, 0, 1]) / (2 * h), D[:, 0, 2], "b_etaeta")
    assert np.all(D[:, 1:, 2:] == 0) and np.all(D[:, 2:, 1:] == 0)


def test_c2_in_eta_through_stations(blade, dtmb):
    """b_ηη is continuous through each station (and through the root, where the blade is
    extended below the table)."""
    xi = np.linspace(0.0, 1.0, 33)[:, None]
    for r in dtmb.radial.r_R[:-1]:
        lo, hi = blade.derivatives(xi, r - 1e-9), blade.derivatives(xi, r + 1e-9)
        scale = np.max(np.abs(lo[..., 0, 2, :]))
        assert np.max(np.abs(lo[..., 0, 2, :] - hi[..., 0, 2, :])) < 1e-6 * scale, r


def test_chord_closes_at_tip_like_square_root(blade):
    d = blade.distributions(np.array([1.0 - 1e-4, 1.0 - 1e-6, 1.0]))
    c = d["chord"]
    assert c[2] == 0.0
    assert c[0] / c[1] == pytest.approx(10.0, rel=1e-3)  # c ~ sqrt(1 - η)


def test_eta_outside_the_model_is_refused(blade):
    with pytest.raises(GeometryError, match="eta"):
        blade.evaluate(0.3, 1.01)
    with pytest.raises(GeometryError, match="eta"):
        blade.evaluate(0.3, blade.eta_min - 0.01)


def test_broadcasting_and_grid(blade):
    xs, es = blade.display_parameters(64, 48)
    grid = blade.sample(64, 48)
    assert grid.shape == (64, 48, 3)
    assert np.allclose(grid[5, 7], blade.evaluate(xs[5], es[7]), atol=0)
    assert blade.derivatives(xs[:, None], es[None, :]).shape == (64, 48, 3, 3, 3)


def _measure_all(p, skip_tip=True):
    blade = p.build().blade
    D = p.diameter
    worst = np.zeros(6)
    for r, c, P, sk, rk, tc, fc in zip(*(getattr(p.radial, k) for k in ("r_R", "c_D", "P_D", "skew_deg", "rake_D", "t_c", "f_c"))):
        if r == 1.0 and skip_tip:
            continue
        m = blade.measure_section(r * blade.radius)
        err = [m.chord - c * D, m.pitch - P * D, m.max_thickness - tc * c * D, m.max_camber - fc * c * D,
               np.radians(m.skew_deg - sk) * r * blade.radius, m.rake - rk * D]
        worst = np.maximum(worst, np.abs(err) / D)
    return worst


@pytest.mark.parametrize("preset", ["skewed_demo", "raked_demo"])
def test_skewed_and_raked_presets_reproduce_their_tables(preset):
    worst = _measure_all(Propeller.from_toml(PRESETS / f"{preset}.toml"))
    assert np.all(worst < 1e-6), worst


def test_extreme_skew_and_rake_build():
    p = Propeller.from_toml(PRESETS / "skewed_demo.toml")
    r = np.array(p.radial.r_R)
    skew = 72.0 * ((r - r[0]) / (1 - r[0])) ** 1.5
    rake = 0.05 * (r - r[0]) / (1 - r[0])
    q = p.with_values(radial_skew_deg=tuple(skew), radial_rake_D=tuple(-rake), blades=7)
    model = q.build()
    assert np.all(_measure_all(q) < 1e-6)
    assert model.intersection().max_residual < 1e-12
