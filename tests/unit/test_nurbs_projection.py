"""Closest points on curves and surfaces (NURBS Book §6.1, Eqs. 6.3–6.8)."""
import numpy as np
import pytest
from scipy.spatial import cKDTree

from bladesmith.geometry.errors import GeometryError
from bladesmith.geometry.nurbs import BSplineCurve, BSplineSurface, clamped_uniform_knots
from bladesmith.geometry.nurbs.projection import closest_point_curve, closest_point_surface

PARAM_TOL = 1e-10  # parameters recovered to this (absolute)
DIST_TOL = 1e-14  # distances to this, relative to the size: a 1e-9 gap is measured to ~1e-5 of itself


def _random_surface(rng, rational=False, nu=8, nv=7):
    X, Y = np.meshgrid(np.linspace(0, 1, nu), np.linspace(0, 1.2, nv), indexing="ij")
    Z = 0.15 * rng.normal(size=(nu, nv))
    W = rng.uniform(0.7, 1.4, (nu, nv)) if rational else None
    Uu = np.concatenate([np.zeros(4), np.sort(rng.uniform(0, 1, nu - 4)), np.ones(4)])
    return BSplineSurface(3, 3, Uu, clamped_uniform_knots(nv, 3, (0.0, 2.0)), np.stack([X, Y, Z], -1), W)


def _random_planar_curve(rng, n=12):
    P = np.stack([np.linspace(0, 3, n), 0.3 * rng.normal(size=n)], axis=1)
    return BSplineCurve(3, clamped_uniform_knots(n, 3), P)


@pytest.mark.parametrize("rational", [False, True])
@pytest.mark.parametrize("offset", [0.0, 1e-9, 1e-3])
def test_surface_point_at_normal_offset_returns_its_foot_and_distance(rational, offset):
    rng = np.random.default_rng(200 + int(rational))
    S = _random_surface(rng, rational)
    u0 = rng.uniform(0.02, 0.98, 400)
    v0 = rng.uniform(0.04, 1.96, 400)
    h = offset * rng.choice([-1.0, 1.0], 400)
    P = S.evaluate(u0, v0) + h[:, None] * S.normal(u0, v0)
    u, v, d = closest_point_surface(S, P)
    assert np.abs(u - u0).max() <= PARAM_TOL
    assert np.abs(v - v0).max() <= PARAM_TOL
    assert np.abs(d - np.abs(h)).max() <= DIST_TOL * S.size()


def test_surface_projection_is_never_worse_than_dense_sampling():
    rng = np.random.default_rng(210)
    S = _random_surface(rng)
    P = rng.uniform([-0.3, -0.3, -0.4], [1.3, 1.5, 0.4], size=(300, 3))
    u, v, d = closest_point_surface(S, P)
    us, vs = np.linspace(0, 1, 401), np.linspace(0, 2, 401)
    dense, _ = cKDTree(S.evaluate_grid(us, vs).reshape(-1, 3)).query(P)
    assert np.all(d <= dense + 1e-12)
    # the reported distance is the distance to the reported point
    np.testing.assert_allclose(np.linalg.norm(S.evaluate(u, v) - P, axis=1), d, rtol=0, atol=1e-15)
    # points beyond an edge land on the edge (clamping, Eq. 6.8)
    assert np.any(u == 0.0) and np.any(u == 1.0) and np.any(v == 0.0) and np.any(v == 2.0)


def test_surface_projection_keeps_the_shape_of_the_points():
    S = _random_surface(np.random.default_rng(220))
    P = np.random.default_rng(221).uniform(0, 1, size=(4, 5, 3))
    u, v, d = closest_point_surface(S, P)
    assert u.shape == v.shape == d.shape == (4, 5)


def test_curve_point_at_normal_offset_returns_its_foot_and_distance():
    rng = np.random.default_rng(230)
    c = _random_planar_curve(rng)
    t0 = rng.uniform(0.0, 1.0, 500)
    t0[:2] = [0.0, 1.0]
    T = c.tangent(t0)
    normal = np.stack([-T[:, 1], T[:, 0]], axis=1)
    for offset in (0.0, 1e-9, 1e-3):
        h = offset * rng.choice([-1.0, 1.0], 500)
        t, d = closest_point_curve(c, c.evaluate(t0) + h[:, None] * normal)
        assert np.abs(t - t0).max() <= PARAM_TOL
        assert np.abs(d - np.abs(h)).max() <= DIST_TOL * c.size()


def test_curve_projection_is_never_worse_than_dense_sampling_and_clamps():
    rng = np.random.default_rng(240)
    c = BSplineCurve(3, clamped_uniform_knots(10, 3), np.cumsum(rng.normal(size=(10, 3)), axis=0))
    lo, hi = c.control_points.min(axis=0) - 1, c.control_points.max(axis=0) + 1
    P = rng.uniform(lo, hi, size=(500, 3))
    t, d = closest_point_curve(c, P)
    dense, _ = cKDTree(c.evaluate(np.linspace(0, 1, 200001))).query(P)
    assert np.all(d <= dense + 1e-12)
    # a point beyond the start along the reversed tangent projects onto the end point
    beyond = c.evaluate(0.0) - 0.5 * c.tangent(0.0)
    t_end, d_end = closest_point_curve(c, beyond)
    assert t_end == 0.0 and abs(d_end - 0.5) <= 1e-14


def test_projection_errors():
    S = _random_surface(np.random.default_rng(250))
    c = _random_planar_curve(np.random.default_rng(251))
    with pytest.raises(GeometryError, match="expected shape"):
        closest_point_surface(S, np.zeros((3, 2)))
    with pytest.raises(GeometryError, match="non-finite"):
        closest_point_curve(c, [[np.nan, 0.0]])
    with pytest.raises(GeometryError, match="BSplineSurface"):
        closest_point_surface(c, np.zeros((1, 2)))


def _strongly_rational_knots(rng, n, p):
    interior = np.sort(rng.uniform(0, 1, n - p - 1))
    return np.concatenate([np.zeros(p + 1), interior, np.ones(p + 1)])


@pytest.mark.parametrize("degree", [2, 3, 4, 5])
def test_points_on_strongly_rational_curves_project_onto_them(degree):
    """Points on the curve have distance 0: with weight ratios up to 25 the curve sweeps
    far within small parameter steps, and more than one local minimum can hide between
    two coarse samples (a case met while measuring Blender's display)."""
    rng = np.random.default_rng(40 + degree)
    worst = 0.0
    for _ in range(15):
        n = degree + 1 + int(rng.integers(0, 6))
        curve = BSplineCurve(degree, _strongly_rational_knots(rng, n, degree), rng.normal(size=(n, 3)),
                             rng.uniform(0.2, 5.0, n))
        u0 = rng.uniform(0, 1, 300)
        params, dist = closest_point_curve(curve, curve.evaluate(u0))
        worst = max(worst, dist.max() / curve.size())
    assert worst < 1e-9, worst


def test_points_on_strongly_rational_surfaces_project_onto_them():
    """Strong weights (ratios up to 25) on surfaces that do not fold back onto themselves,
    as blade surfaces never do (see closest_point_surface on folded surfaces)."""
    rng = np.random.default_rng(77)
    worst = 0.0
    for _ in range(6):
        p, q = int(rng.integers(2, 4)), int(rng.integers(2, 4))
        nu, nv = p + 1 + int(rng.integers(0, 4)), q + 1 + int(rng.integers(0, 4))
        x, y = np.meshgrid(np.linspace(0, 1, nu), np.linspace(0, 1, nv), indexing="ij")
        net = np.stack([x, y, 0.3 * rng.normal(size=x.shape)], axis=-1)
        net[..., :2] += rng.uniform(-0.2, 0.2, (nu, nv, 2)) / max(nu, nv)
        surface = BSplineSurface(p, q, _strongly_rational_knots(rng, nu, p), _strongly_rational_knots(rng, nv, q),
                                 net, rng.uniform(0.2, 5.0, (nu, nv)))
        uv = rng.uniform(0, 1, (400, 2))
        _, _, dist = closest_point_surface(surface, surface.evaluate(uv[:, 0], uv[:, 1]))
        worst = max(worst, dist.max() / surface.size())
    assert worst < 1e-9, worst


@pytest.mark.parametrize("rational", [False, True])
def test_curve_brackets_near_each_point_agree_with_the_dense_table(rational, monkeypatch):
    """Many points (the k-d tree path of ``_curve_brackets``) and few (the dense point ×
    sample table) give the same closest points, including points far from the curve,
    points on it and points near self-approaching stretches."""
    from bladesmith.geometry.nurbs import projection

    rng = np.random.default_rng(7 + rational)
    n = 30
    P = np.cumsum(rng.normal(size=(n, 3)), axis=0)
    P[n // 2:] = P[n // 2 - 1::-1][: n - n // 2] + 0.05 * rng.normal(size=(n - n // 2, 3))  # doubles back
    curve = BSplineCurve(3, _strongly_rational_knots(rng, n, 3), P, rng.uniform(0.3, 3.0, n) if rational else None)
    lo, hi = P.min(axis=0) - 2, P.max(axis=0) + 2
    Q = np.concatenate([rng.uniform(lo, hi, (1500, 3)), curve.evaluate(rng.uniform(0, 1, 500))])
    t_near, d_near = closest_point_curve(curve, Q)
    monkeypatch.setattr(projection, "SPARSE_BRACKET_PAIRS", 1 << 62)
    t_dense, d_dense = closest_point_curve(curve, Q)
    assert np.max(np.abs(d_near - d_dense)) <= 1e-13 * curve.size()
    # same distance; the parameter may differ only where two feet are equally near
    differ = np.abs(t_near - t_dense) > 1e-9
    assert differ.sum() <= 2
