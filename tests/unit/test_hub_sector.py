"""The trimmed hub sector (Hally 2013 §10, Eqs. 51–58) and its area."""
from __future__ import annotations

import pathlib

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from bladesmith.geometry.errors import GeometryError
from bladesmith.geometry.nurbs import closest_point_curve, split
from bladesmith.geometry.propeller import Propeller
from bladesmith.geometry.propeller import hub_sector as hs
from bladesmith.geometry.propeller.hub_sector import (
    area_primitive,
    c1_spine,
    hermite_boundary,
    hub_sector,
    nurbs_v_of_theta,
    revolve_points,
    signed_parameter_area,
    trimmed_area,
)

ROOT = pathlib.Path(__file__).resolve().parents[2]
PRESETS = ("dtmb4119", "skewed_demo", "raked_demo")
JOIN_TOL = 1e-12
_MODELS: dict = {}


def sector_of(name):
    if name not in _MODELS:
        model = Propeller.from_toml(ROOT / "data" / "propellers" / f"{name}.toml").build()
        _MODELS[name] = (model, hub_sector(model))
    return _MODELS[name]


@pytest.fixture(params=PRESETS)
def built(request):
    return sector_of(request.param)


# -- the spine -------------------------------------------------------------------------------------------
def test_c1_spine_is_the_hub_spine_with_simple_knots(built):
    model, sector = built
    spine = sector.spine
    inner = spine.knots[3:-3]
    assert np.all(np.diff(inner) > 0), "interior knots must be simple (C1 as a B-spline)"
    s = np.linspace(0.0, 1.0, 801)
    pts = spine.evaluate(s)
    # distance to each of the hub's three Bézier pieces (nose, cylinder, tail), the least
    k1, k2 = model.hub.spine.knots[[3, 5]]
    nose, rest = split(model.hub.spine, k1)
    pieces = (nose,) + split(rest, k2)
    dist = np.min([closest_point_curve(c, pts)[1] for c in pieces], axis=0)
    assert dist.max() < 1e-12 * model.blade.radius
    np.testing.assert_allclose(spine.evaluate([0.0, 1.0]), model.hub.spine.evaluate([0.0, 1.0]), atol=1e-15)
    # on the inner cylinder spans s equals the hub's ξ_h (z linear in s on both)
    k = spine.knots
    s_mid = np.linspace(k[5], k[-6], 11)  # the spans not touched by Ca, Cb
    np.testing.assert_allclose(spine.evaluate(s_mid), model.hub.spine.evaluate(s_mid), atol=1e-14)


def test_c1_spine_has_continuous_derivative_at_its_knots(built):
    _, sector = built
    spine = sector.spine
    eps = 1e-9
    for k in np.unique(spine.knots)[1:-1]:
        d_left = spine.derivatives(k - eps, 1)[1]
        d_right = spine.derivatives(k + eps, 1)[1]
        scale = max(1.0, np.linalg.norm(d_left))
        assert np.linalg.norm(d_left - d_right) < 1e-6 * scale


def test_revolved_nurbs_surface_is_the_hub(built):
    model, sector = built
    S = sector.surface
    s = np.linspace(0.0, 1.0, 23)[:, None]
    th = np.linspace(*sector.angle_range, 31)[None, :]
    exact = revolve_points(sector.spine, s, th)
    np.testing.assert_allclose(S.evaluate(s, nurbs_v_of_theta(th, sector.angle_range)), exact, atol=1e-14)
    # and the same surface as the Hub's own h(ξ_h, θ) at the same points
    k = model.hub.spine.knots
    xi_h = np.linspace(k[3], k[5], 9)[1:-1]  # on the cylinder (a flat end has no unique z -> s)
    p = sector.hub_parameters(xi_h, 0.3)
    np.testing.assert_allclose(sector.evaluate(p[:, 0], p[:, 1]), model.hub.evaluate(xi_h, 0.3), atol=1e-14)


# -- Eqs. 51–58 ----------------------------------------------------------------------------------------
def test_boundary_passes_the_blade_edges_with_slope_m_and_meets_the_ends_orthogonally(built):
    model, sector = built
    p_h = sector.boundary
    (s_le, t_le), (s_te, t_te) = sector.leading_edge, sector.trailing_edge
    m = sector.slope
    assert m == pytest.approx((t_te - t_le) / (s_te - s_le), rel=1e-15)  # Eq. 53
    for s0, t0 in ((s_le, t_le), (s_te, t_te)):
        u0 = (s0 - sector.xi_lo) / (sector.xi_hi - sector.xi_lo)  # Eq. 55 (corrected)
        P, dP = p_h.derivatives(u0, 1)
        assert P == pytest.approx([s0, t0], abs=1e-14)
        assert dP[1] / dP[0] == pytest.approx(m, rel=1e-12)
    # end tangents are along ξ: orthogonal to the lines ξ = ξ_lo, ξ_hi (zero slope)
    for u in (0.0, 1.0):
        d = p_h.derivatives(u, 1)[1]
        assert d[0] > 0 and abs(d[1]) <= 1e-14 * abs(d[0])
    # ξ is linear in u (Eq. 55): u runs 0 -> 1 from ξ_lo to ξ_hi
    u = np.linspace(0.0, 1.0, 17)
    np.testing.assert_allclose(p_h.evaluate(u)[:, 0], sector.xi_lo + u * (sector.xi_hi - sector.xi_lo), atol=1e-15)
    # the middle piece is the straight line through the edges
    u_mid = np.linspace(s_le, s_te, 9)
    np.testing.assert_allclose(p_h.evaluate(u_mid)[:, 1], t_le + m * (u_mid - s_le), atol=1e-13)


def test_end_points_are_extrapolated_and_clamped(built):
    _, sector = built
    lo, hi = sector.clamp_range
    assert lo <= sector.theta_lo <= hi and lo <= sector.theta_hi <= hi
    assert sector.clamp_range == (-np.pi, np.pi)
    (s1, t1), (s2, t2) = sorted([sector.leading_edge, sector.trailing_edge])
    m = sector.slope
    assert sector.theta_lo == pytest.approx(np.clip(t1 - 0.5 * m * (s1 - sector.xi_lo), lo, hi), abs=1e-15)  # Eq. 51
    assert sector.theta_hi == pytest.approx(np.clip(t2 + 0.5 * m * (sector.xi_hi - s2), lo, hi), abs=1e-15)  # Eq. 52
    # unclamped, each end piece is the parabola θ_end + (m / 2Δξ)(ξ - ξ_end)²
    u = np.linspace(0.0, s1, 9)
    th = sector.boundary.evaluate(u)[:, 1]
    parabola = sector.theta_lo + m / (2 * (s1 - sector.xi_lo)) * (u - sector.xi_lo) ** 2
    np.testing.assert_allclose(th, parabola, atol=1e-13)


def test_clamp_limits_theta_lo_and_theta_hi():
    m, th_lo, th_hi, p_h, *_ = hs._sector_curves(0.0, 1.0, (0.3, 1.0), (0.6, -1.0), 3, (-1.5, 1.5))
    assert th_lo == 1.5 and th_hi == -1.5  # extrapolations 1.0 + 1/3*... > 1.5 and < -1.5 are clamped
    P = p_h.evaluate([0.0, 1.0])
    assert P[0, 1] == 1.5 and P[1, 1] == -1.5


def test_offsets_are_plus_minus_pi_over_z_and_the_loop_closes(built):
    model, sector = built
    Z = model.blades
    u = np.linspace(0.0, 1.0, 41)
    base = sector.boundary.evaluate(u)
    np.testing.assert_allclose(sector.p_h1.evaluate(u) - base, np.tile([0.0, np.pi / Z], (u.size, 1)),
                               atol=4e-16 * np.pi, rtol=0)  # Eq. 54
    np.testing.assert_allclose(sector.p_h3.evaluate(u), sector.p_h1.evaluate(1.0 - u) - [0.0, 2 * np.pi / Z],
                               atol=1e-15, rtol=0)  # Eq. 56
    np.testing.assert_allclose(sector.p_h3.evaluate(1.0 - u) - base, np.tile([0.0, -np.pi / Z], (u.size, 1)),
                               atol=1e-15, rtol=0)
    # Eqs. 57-58: the end lines join the ends of p_h1 and p_h3 at ξ_lo and ξ_hi
    assert np.all(sector.p_h2.control_points[:, 0] == sector.xi_lo)
    assert np.all(sector.p_h4.control_points[:, 0] == sector.xi_hi)
    np.testing.assert_allclose(sector.p_h2.evaluate([0.0, 1.0]), [sector.p_h1.evaluate(0.0), sector.p_h3.evaluate(1.0)],
                               atol=JOIN_TOL)
    np.testing.assert_allclose(sector.p_h4.evaluate([0.0, 1.0]), [sector.p_h3.evaluate(0.0), sector.p_h1.evaluate(1.0)],
                               atol=JOIN_TOL)
    # the outer loop chains head to tail and closes, in parameter space
    loop = sector.outer_loop
    for a, b in zip(loop, loop[1:] + loop[:1]):
        assert np.max(np.abs(a.evaluate(a.domain[1]) - b.evaluate(b.domain[0]))) <= JOIN_TOL
    fp = sector.footprint
    assert np.array_equal(fp.evaluate(fp.domain[0]), fp.evaluate(fp.domain[1]))


def test_loop_orientation_outer_ccw_inner_cw(built):
    _, sector = built
    pts = np.concatenate([c.evaluate(np.linspace(*c.domain, 400)) for c in sector.outer_loop])
    x, y = pts[:, 0], pts[:, 1]
    assert 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) > 0
    assert signed_parameter_area(sector.footprint) < 0


def test_sector_lies_inside_the_120_range_which_lies_inside_minus_pi_pi(built):
    _, sector = built
    a0, a1 = sector.angle_range
    assert -np.pi <= a0 < a1 <= np.pi
    for c in sector.outer_loop + sector.inner_loop:
        th = c.evaluate(np.linspace(*c.domain, 500))[:, 1]
        assert th.min() >= a0 and th.max() <= a1


def test_footprint_lies_on_the_blade_hub_intersection(built):
    model, sector = built
    assert sector.footprint_deviation <= sector.tolerance
    u = np.linspace(0.0, 1.0, 1001)
    fitted = sector.footprint.evaluate(u)
    on_hub = sector.evaluate(fitted[:, 0], fitted[:, 1])
    exact = sector.exact_footprint(u)
    d = np.linalg.norm(on_hub - sector.evaluate(exact[:, 0], exact[:, 1]), axis=-1)
    assert d.max() <= sector.tolerance
    # and the exact footprint is on the blade: b(ξ, η_h(ξ)) at the same ξ
    I = model.blade_hub_intersection
    xi = 1.0 - u if sector.footprint_reversed else u
    blade_pts = model.blade.evaluate(xi, I.eta_h(xi))
    assert np.linalg.norm(on_hub - blade_pts, axis=-1).max() <= sector.tolerance


def test_model_space_loops_follow_the_surface(built):
    _, sector = built
    outer, inner = sector.model_loops()
    assert len(outer) == 2  # the end lines lie on the poles: points, left out
    for curve3, curve2 in zip(outer, (sector.outer_loop[0], sector.outer_loop[2])):
        u = np.linspace(0.0, 1.0, 301)
        assert np.linalg.norm(curve3.evaluate(u) - sector.model_points(curve2, u), axis=-1).max() <= sector.tolerance
    # the two sector edges meet at the poles
    np.testing.assert_allclose(outer[0].evaluate(1.0), outer[1].evaluate(0.0), atol=1e-15)


# -- area ------------------------------------------------------------------------------------------------
def _half_prolate_spheroid_area(a, c):
    """Area of half a spheroid with equatorial radius a and polar semi-axis c > a."""
    e = np.sqrt(1.0 - (a / c) ** 2)
    return np.pi * a * a + np.pi * a * c * np.arcsin(e) / e


def test_outer_loop_area_is_the_hub_area_over_z_in_closed_form():
    model, sector = sector_of("dtmb4119")
    d = model.definition.hub
    R = model.hub.radius
    z0, z1 = -d.upstream_length + d.nose_length, d.downstream_length - d.tail_length
    total = (2 * np.pi * R * (z1 - z0) + _half_prolate_spheroid_area(R, d.nose_length)
             + _half_prolate_spheroid_area(R, d.tail_length))
    outer = trimmed_area(sector.spine, (sector.outer_loop,))
    assert outer == pytest.approx(total / model.blades, rel=1e-12)
    assert 2 * np.pi * area_primitive(sector.spine, 1.0) == pytest.approx(total, rel=1e-13)


def test_trimmed_area_against_an_independent_integral(built):
    """Slice the footprint along s instead of integrating around it: its area is
    ∫ g(s) w(s) ds, w the θ-width of the footprint at s (the two branches of the spline
    between its extreme s, inverted by bisection), g = ρ|C'|, with s = c - h cos φ to
    smooth the square-root ends, by composite Gauss–Legendre in φ."""
    model, sector = built
    spine, fp = sector.spine, sector.footprint
    u_dense = np.linspace(0.0, 1.0, 4001)
    s_dense = fp.evaluate(u_dense)[:, 0]

    def extreme(i, sign):
        a, b = u_dense[max(i - 1, 0)], u_dense[min(i + 1, u_dense.size - 1)]
        r = minimize_scalar(lambda u: sign * fp.evaluate(u)[0], bounds=(a, b), method="bounded",
                            options={"xatol": 1e-14})
        return r.x, fp.evaluate(r.x)[0]

    u_lo, s_lo = extreme(int(np.argmin(s_dense)), 1.0)
    u_hi, s_hi = extreme(int(np.argmax(s_dense)), -1.0)
    a, b = sorted([u_lo, u_hi])

    def branch_theta(s0, u_of_w):
        """θ where the branch w -> fp(u_of_w(w)), w in [0, 1], reaches s0 (bisection)."""
        lo, hi = np.zeros_like(s0), np.ones_like(s0)
        rising = fp.evaluate(u_of_w(1.0))[0] > fp.evaluate(u_of_w(0.0))[0]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            above = fp.evaluate(u_of_w(mid))[:, 0] > s0
            go_left = above if rising else ~above
            hi, lo = np.where(go_left, mid, hi), np.where(go_left, lo, mid)
        return fp.evaluate(u_of_w(0.5 * (lo + hi)))[:, 1]

    c, h = 0.5 * (s_lo + s_hi), 0.5 * (s_hi - s_lo)
    kinks = [np.arccos((c - k) / h) for k in np.unique(spine.knots) if s_lo < k < s_hi]
    breaks = np.unique(np.concatenate([[0.0, np.pi], kinks]))
    x, w = np.polynomial.legendre.leggauss(20)
    edges = np.unique(np.concatenate([np.linspace(p0, p1, 161) for p0, p1 in zip(breaks[:-1], breaks[1:])]))
    half = 0.5 * np.diff(edges)
    phi = ((edges[:-1] + half)[:, None] + half[:, None] * x[None, :]).ravel()
    weights = (half[:, None] * w[None, :]).ravel()
    s0 = c - h * np.cos(phi)
    t1 = branch_theta(s0, lambda v: a + v * (b - a))
    t2 = branch_theta(s0, lambda v: np.mod(b + v * (1.0 - b + a), 1.0))
    D = spine.derivatives(s0, 1)
    g = D[:, 0, 0] * np.linalg.norm(D[:, 1, :], axis=-1)
    footprint_area = float(np.sum(g * np.abs(t1 - t2) * h * np.sin(phi) * weights))
    outer = trimmed_area(spine, (sector.outer_loop,))
    assert sector.area == pytest.approx(outer - footprint_area, rel=1e-9)


def test_errors():
    model, _ = sector_of("dtmb4119")
    with pytest.raises(GeometryError, match="tolerance"):
        hub_sector(model, tolerance=0.0)
    with pytest.raises(GeometryError, match="increase"):
        hermite_boundary([0.0, 0.5, 0.4, 1.0], [0, 0, 0, 0], [0, 0, 0, 0])
    with pytest.raises(GeometryError, match="outside"):
        hub_sector(model, clamp_range=(-0.5, 0.5))
    with pytest.raises(GeometryError, match="same axial"):
        hs._sector_curves(0.0, 1.0, (0.4, 0.2), (0.4, -0.2), 3, (-np.pi, np.pi))


def test_c1_spine_keeps_creases_exact():
    """skewed_demo has a conical tail and raked_demo a flat one: the crease is passed with
    zero speed, and the spine still lies on the hub's spine."""
    for name in ("skewed_demo", "raked_demo"):
        model, sector = sector_of(name)
        spine = c1_spine(model.hub)
        J2 = model.hub.spine.control_points[4]
        s = spine.knots[-4]  # k2: the cylinder's downstream end
        assert np.allclose(spine.evaluate(s), J2, atol=1e-14)
        assert np.linalg.norm(spine.derivatives(s, 1)[1]) < 1e-6


# -- the junction: the blade root edge itself as the inner loop -----------------------------------------
_BLADES: dict = {}


def sector_from_blade(name):
    if name not in _BLADES:
        from bladesmith.geometry.propeller import smooth_blade

        model, _ = sector_of(name)
        blade = smooth_blade(model, measure=False)
        _BLADES[name] = (model, blade, hub_sector(model, blade=blade))
    return _BLADES[name]


@pytest.mark.parametrize("name", PRESETS)
def test_inner_loop_is_the_blade_root_edge_itself(name):
    """The inner loop's 3-D curves are the four root rows of the blade surfaces, the same
    float64 control points (reversed as a whole when the loop runs against +ξ); the root
    footprint distance is 0 (<= 1e-12 D); the parameter-space loop maps onto them within
    the root's distance from the hub, which is within the sector tolerance."""
    from bladesmith.geometry.propeller.hub_sector import ROOT_SURFACES, blade_root_edges, root_footprint_distance

    model, blade, sector = sector_from_blade(name)
    D = 2.0 * model.blade.radius
    rows = [getattr(blade, n).control_points[:, 0] for n in ROOT_SURFACES]
    assert len(sector.root_edges) == 4
    for c in sector.root_edges:
        assert any(np.array_equal(c.control_points, r) or np.array_equal(c.control_points[::-1], r) for r in rows)
    assert root_footprint_distance(sector, blade) <= 1e-12 * D
    assert sector.root_hub_distance <= sector.tolerance and sector.warnings == ()
    # chained head to tail, closed, clockwise in (s, θ) like the footprint spline
    loop = sector.inner_loop
    for a, b in zip(loop, loop[1:] + loop[:1]):
        np.testing.assert_array_equal(sector.evaluate(*a.evaluate(a.domain[1])), sector.evaluate(*b.evaluate(b.domain[0])))
    P = np.concatenate([c.evaluate(np.linspace(0, 1, 201)) for c in loop])
    assert 0.5 * np.sum(P[:-1, 0] * P[1:, 1] - P[1:, 0] * P[:-1, 1]) < 0
    # h(p(u)) follows the root edge at the same u
    for p, r in zip(loop, sector.root_edges):
        u = np.linspace(0, 1, 301)
        q = p.evaluate(u)
        assert np.linalg.norm(sector.evaluate(q[:, 0], q[:, 1]) - r.evaluate(u), axis=-1).max() <= sector.tolerance
    # the same trimmed area as the sector trimmed by the exact intersection
    _, plain = sector_of(name)
    assert sector.area == pytest.approx(plain.area, rel=1e-6)
    # and the curves are those of blade_root_edges (a copy, not a refit)
    assert sum(c.n_control for c in blade_root_edges(blade)) == sum(c.n_control for c in sector.root_edges)


def test_root_edges_that_do_not_meet_or_miss_the_hub_are_refused():
    from bladesmith.geometry.nurbs import BSplineSurface

    model, blade, _ = sector_from_blade("dtmb4119")
    surfaces = {n: getattr(blade, n) for n in ("pressure_central", "suction_central", "leading_edge",
                                               "trailing_edge", "tip")}
    moved = dict(surfaces)
    s = surfaces["leading_edge"]
    moved["leading_edge"] = BSplineSurface(s.degree_u, s.degree_v, s.knots_u, s.knots_v,
                                           s.control_points + np.array([0.0, 0.0, 1e-9]))
    with pytest.raises(GeometryError, match="share their corners"):
        hub_sector(model, blade=moved)
    lifted = {n: BSplineSurface(t.degree_u, t.degree_v, t.knots_u, t.knots_v, t.control_points * 1.05)
              for n, t in surfaces.items()}
    with pytest.raises(GeometryError, match="from the hub"):
        hub_sector(model, blade=lifted)


@pytest.mark.parametrize("name", PRESETS)
def test_edges_of_neighbouring_copies_coincide(name):
    """The -π/Z edge of copy k+1 (turned by 2π/Z) and the +π/Z edge of copy k are the same
    control points up to the rounding of one rotation, and both lie on the hub."""
    model, sector = sector_of(name)
    D = 2.0 * model.blade.radius
    c3r, c1r = sector.edge_model_curves()
    turned = c3r.control_points @ model.blade_rotation(1).T
    assert np.abs(turned - c1r.control_points[::-1]).max() <= 1e-15 * D
    u = np.linspace(0.0, 1.0, 201)
    # each follows its edge on the hub at the same parameter (outer loop order and sense)
    for curve, edge in ((c3r, sector.outer_loop[0]), (c1r, sector.outer_loop[2])):
        assert np.linalg.norm(curve.evaluate(u) - sector.model_points(edge, u), axis=-1).max() <= sector.tolerance


def test_full_turn_range_holds_every_footprint():
    from bladesmith.geometry.propeller.hub_sector import full_hub_angle_range, turned_pcurves

    for name in PRESETS:
        model, _, sector = sector_from_blade(name)
        a0, a1 = full_hub_angle_range(sector)
        assert a1 - a0 == pytest.approx(2 * np.pi, abs=1e-15)
        for k in range(model.blades):
            th = np.concatenate([c.control_points[:, 1] for c in turned_pcurves(sector, k)])
            assert a0 < th.min() and th.max() < a1
