"""Skinning (NURBS Book §10.3), Coons patches and transfinite interpolation."""
import numpy as np
import pytest

from bladesmith.geometry.errors import GeometryError
from bladesmith.geometry.nurbs import BSplineCurve
from bladesmith.geometry.nurbs.fitting import interpolate
from bladesmith.geometry.nurbs.skinning import coons_surface, skin, skin_parameters, transfinite_interpolation

REL = 1e-12
DENSE = np.linspace(0.0, 1.0, 1001)


def _random_section(rng, k, rational=False):
    """A section curve of random degree, knots and domain at height ~k."""
    p = int(rng.integers(2, 5))
    n = int(rng.integers(p + 1, p + 8))
    a = float(rng.uniform(-2, 2))
    interior = np.sort(rng.uniform(0, 1, n - p - 1))
    U = a + 3.0 * np.concatenate([np.zeros(p + 1), interior, np.ones(p + 1)])
    P = np.stack([np.linspace(0, 1, n) + rng.normal(0, 0.02, n), rng.normal(0, 0.1, n),
                  np.full(n, 0.5 * k) + rng.normal(0, 0.05, n)], axis=1)
    W = rng.uniform(0.8, 1.25, n) if rational else None
    return BSplineCurve(p, U, P, W)


def _section_error(S, curves, v):
    worst = 0.0
    for k, c in enumerate(curves):
        a, b = c.domain
        err = np.abs(S.evaluate(DENSE, v[k]) - c.evaluate(a + (b - a) * DENSE)).max()
        worst = max(worst, err / c.size())
    return worst


@pytest.mark.parametrize("method", ["chord", "centripetal", "uniform"])
@pytest.mark.parametrize("degree_v", [1, 2, 3])
def test_skin_interpolates_every_section(method, degree_v):
    rng = np.random.default_rng(100 + degree_v)
    curves = [_random_section(rng, k) for k in range(7)]
    S = skin(curves, degree_v, method=method)
    v = skin_parameters(curves, method)
    assert S.degree_v == degree_v and S.degree_u == max(c.degree for c in curves)
    assert S.domain_v == (0.0, 1.0) and S.domain_u == (0.0, 1.0)
    assert _section_error(S, curves, v) <= REL


def test_skin_rational_sections_in_homogeneous_space():
    rng = np.random.default_rng(110)
    curves = [_random_section(rng, k, rational=bool(k % 2)) for k in range(6)]
    S = skin(curves, 3)
    assert S.is_rational
    assert _section_error(S, curves, skin_parameters(curves)) <= REL


def test_skin_with_given_params():
    rng = np.random.default_rng(120)
    curves = [_random_section(rng, k) for k in range(5)]
    v = [0.0, 0.1, 0.5, 0.6, 2.0]
    S = skin(curves, 3, params=v)
    assert S.domain_v == (0.0, 2.0)
    assert _section_error(S, curves, v) <= REL


def test_skin_parameters_average_the_columns():
    # parallel straight sections at heights 0, 1, 3: chord parameters 0, 1/3, 1
    curves = [BSplineCurve(1, [0, 0, 1, 1], [[0, 0, z], [1, 0, z]]) for z in (0.0, 1.0, 3.0)]
    np.testing.assert_allclose(skin_parameters(curves), [0, 1 / 3, 1], atol=1e-15)


def test_skin_errors():
    rng = np.random.default_rng(130)
    curves = [_random_section(rng, k) for k in range(3)]
    with pytest.raises(GeometryError, match="at least 4 section curves"):
        skin(curves, 3)
    with pytest.raises(GeometryError, match="section curve 2 coincides with section curve 1"):
        skin([curves[0], curves[1], curves[1], curves[2]], 2)
    with pytest.raises(GeometryError, match="BSplineCurve"):
        skin([curves[0], "not a curve"], 1)


def _coons_boundaries(rng):
    c0 = interpolate(rng.normal(size=(6, 3)), 3)
    d0 = interpolate(np.concatenate([c0.evaluate([0.0]), rng.normal(size=(4, 3))]), 2)
    d1 = interpolate(np.concatenate([c0.evaluate([1.0]), rng.normal(size=(5, 3))]), 4)
    c1 = interpolate(np.concatenate([d0.evaluate([1.0]), rng.normal(size=(3, 3)), d1.evaluate([1.0])]), 3)
    return c0, c1, d0, d1


def test_coons_surface_reproduces_its_four_boundaries():
    c0, c1, d0, d1 = _coons_boundaries(np.random.default_rng(140))
    S = coons_surface(c0, c1, d0, d1)
    scale = max(c.size() for c in (c0, c1, d0, d1))
    errs = [
        np.abs(S.evaluate(DENSE, 0.0) - c0.evaluate(DENSE)).max(),
        np.abs(S.evaluate(DENSE, 1.0) - c1.evaluate(DENSE)).max(),
        np.abs(S.evaluate(0.0, DENSE) - d0.evaluate(DENSE)).max(),
        np.abs(S.evaluate(1.0, DENSE) - d1.evaluate(DENSE)).max(),
    ]
    assert max(errs) <= REL * scale
    assert (S.degree_u, S.degree_v) == (3, 4)


def test_coons_interior_is_the_bilinear_blend_of_the_boundaries():
    c0, c1, d0, d1 = _coons_boundaries(np.random.default_rng(141))
    S = coons_surface(c0, c1, d0, d1)
    us, vs = np.linspace(0, 1, 41), np.linspace(0, 1, 37)
    grid = transfinite_interpolation(c0.evaluate(us), c1.evaluate(us), d0.evaluate(vs), d1.evaluate(vs), us, vs)
    assert np.abs(S.evaluate_grid(us, vs) - grid).max() <= REL * S.size()


def test_coons_refuses_open_corners_and_rational_curves():
    c0, c1, d0, d1 = _coons_boundaries(np.random.default_rng(142))
    moved = BSplineCurve(c1.degree, c1.knots, c1.control_points + [0.0, 0.0, 1e-3])
    with pytest.raises(GeometryError, match=r"do not meet at the \(0, 1\) corner"):
        coons_surface(c0, moved, d0, d1)
    rational = BSplineCurve(c0.degree, c0.knots, c0.control_points, np.ones(c0.n_control))
    with pytest.raises(GeometryError, match="rational"):
        coons_surface(rational, c1, d0, d1)


def test_transfinite_interpolation_reproduces_a_bilinear_patch_and_its_boundaries():
    corners = np.array([[0.0, 0.0, 0.0], [2.0, 0.1, 0.3], [0.2, 1.5, -0.4], [1.9, 1.7, 1.0]])
    u, v = np.linspace(0, 1, 9) ** 1.5, np.linspace(0, 1, 6)

    def bilinear(s, t):
        s, t = s[..., None], t[..., None]
        return (1 - s) * (1 - t) * corners[0] + s * (1 - t) * corners[1] + (1 - s) * t * corners[2] + s * t * corners[3]

    S, T = np.meshgrid(u, v, indexing="ij")
    exact = bilinear(S, T)
    X = transfinite_interpolation(exact[:, 0], exact[:, -1], exact[0, :], exact[-1, :], u, v)
    assert X.shape == (9, 6, 3)
    assert np.abs(X - exact).max() <= 1e-15 * 10
    rng = np.random.default_rng(150)
    B, Tp = rng.normal(size=(9, 2)), rng.normal(size=(9, 2))
    L = np.concatenate([B[:1], rng.normal(size=(4, 2)), Tp[:1]])
    R = np.concatenate([B[-1:], rng.normal(size=(4, 2)), Tp[-1:]])
    Y = transfinite_interpolation(B, Tp, L, R)
    np.testing.assert_array_equal(Y[:, 0], B)
    np.testing.assert_array_equal(Y[:, -1], Tp)
    np.testing.assert_array_equal(Y[0, 1:-1], L[1:-1])
    np.testing.assert_array_equal(Y[-1, 1:-1], R[1:-1])


def test_transfinite_interpolation_errors():
    B = np.zeros((4, 2))
    T = np.ones((4, 2))
    L = np.stack([np.zeros(3), np.linspace(0, 1, 3)], axis=1)
    R = L + [1.0, 0.0]
    with pytest.raises(GeometryError, match="do not meet at the bottom-right corner"):
        transfinite_interpolation(B, T, L, R)
    with pytest.raises(GeometryError, match="same shape"):
        transfinite_interpolation(B, T[:3], L, R)
    with pytest.raises(GeometryError, match="non-finite"):
        transfinite_interpolation(B, T, L * np.nan, R)


def test_skinned_end_rows_are_the_end_sections_bit_for_bit():
    """The clamped end rows of a skin are its first and last sections' control polygons,
    copied, not solved: equality that holds on every CPU (issue 14). Before the fix the
    basis at v = 0 came out as 1 - 1 ulp on some knot vectors and the end rows were
    solved through it."""
    rng = np.random.default_rng(14)
    for trial in range(40):
        K = int(rng.integers(4, 16))
        base = rng.normal(size=(7, 3)) * 10.0
        sections = [BSplineCurve(3, np.r_[[0.0] * 4, 0.3, 0.55, 0.8, [1.0] * 4][:11], base + rng.normal(size=(7, 3)) * (k + 1))
                    for k in range(K)]
        v = np.sort(rng.uniform(0.0, 1.0, K))
        v[0], v[-1] = rng.uniform(-2.0, 0.0), rng.uniform(1.0, 3.0)
        s = skin(sections, 3, params=v)
        assert np.array_equal(s.control_points[:, 0], sections[0].control_points), trial
        assert np.array_equal(s.control_points[:, -1], sections[-1].control_points), trial
