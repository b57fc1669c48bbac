"""The float64 curve and surface types against scipy.interpolate, on random non-uniform data.

Tolerances are relative: positions to the control net's size, derivatives of order k to
the largest k-th derivative sampled (the natural scale of that derivative).
"""
import numpy as np
import pytest
from scipy.interpolate import BSpline, NdBSpline

from bladesmith.geometry.errors import BladesmithError, GeometryError
from bladesmith.geometry.nurbs import BSplineCurve, BSplineSurface
from bladesmith.geometry.nurbs import surface as surface_module

REL = 1e-12


def random_knots(rng, n_control, degree, clamped=True):
    """Non-uniform knots with no span shorter than a fifth of the average."""
    n_spans = n_control - degree
    gaps = rng.uniform(0.2, 1.0, n_spans)
    interior = np.cumsum(gaps)[:-1] / gaps.sum()
    if clamped:
        return np.concatenate([np.zeros(degree + 1), interior, np.ones(degree + 1)])
    outside = rng.uniform(0.05, 0.3, 2 * degree)
    left = -np.cumsum(outside[:degree])[::-1]
    right = 1 + np.cumsum(outside[degree:])
    return np.concatenate([left, [0.0], interior, [1.0], right])


def rel_err(ours, ref):
    scale = max(np.abs(ref).max(), 1e-300)
    return np.abs(ours - ref).max() / scale


@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
@pytest.mark.parametrize("clamped", [True, False])
def test_curve_matches_scipy(degree, clamped):
    rng = np.random.default_rng(degree + 10 * clamped)
    n = degree + 1 + rng.integers(0, 12)
    U = random_knots(rng, n, degree, clamped)
    P = rng.normal(size=(n, 3))
    curve = BSplineCurve(degree, U, P)
    ref = BSpline(U, P, degree)
    u = rng.uniform(*curve.domain, 2000)
    u[:2] = curve.domain  # the ends belong to the domain
    D = curve.derivatives(u, 2)
    assert rel_err(curve.evaluate(u), ref(u)) < REL
    for k in range(min(degree, 2) + 1):
        assert rel_err(D[:, k], ref(u, nu=k)) < REL, k


def test_domain_end_on_a_repeated_unclamped_knot():
    """The end of the domain belongs to the last non-empty span even when the end knot
    is repeated inside an unclamped vector (Blender's Bezier mode without endpoint)."""
    U = [0, 0, 0, 1, 2, 2, 2, 3, 3]  # degree 2, 6 points: domain [0, 2], U[5] = U[4] = 2
    P = np.random.default_rng(8).normal(size=(6, 2))
    curve = BSplineCurve(2, U, P)
    ref = BSpline(np.asarray(U, float), P, 2)
    u = np.array([0.0, 0.5, 1.0, 1.999999, 2.0])
    assert np.all(np.isfinite(curve.evaluate(u)))
    assert rel_err(curve.evaluate(u[:-1]), ref(u[:-1])) < REL
    assert np.allclose(curve.evaluate(2.0), curve.evaluate(2.0 - 1e-12), atol=1e-9)


@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
def test_rational_curve_quotient_rule(degree):
    """C = A/w with A, w evaluated independently by scipy; derivatives by the quotient rule."""
    rng = np.random.default_rng(100 + degree)
    n = degree + 1 + rng.integers(0, 10)
    U = random_knots(rng, n, degree)
    P = rng.normal(size=(n, 2))
    w = rng.uniform(0.3, 3.0, n)
    curve = BSplineCurve(degree, U, P, w)
    A = BSpline(U, P * w[:, None], degree)
    W = BSpline(U, w, degree)
    u = rng.uniform(0, 1, 1500)
    a0, a1, a2 = (A(u, nu=k) for k in range(3))
    w0, w1, w2 = (W(u, nu=k)[:, None] for k in range(3))
    c0 = a0 / w0
    c1 = (a1 - w1 * c0) / w0
    c2 = (a2 - 2 * w1 * c1 - w2 * c0) / w0
    D = curve.derivatives(u, 2)
    assert rel_err(D[:, 0], c0) < REL
    assert rel_err(D[:, 1], c1) < REL
    if degree >= 2:
        assert rel_err(D[:, 2], c2) < 1e-11


@pytest.fixture(params=["gather", "table"])
def evaluation_path(request, monkeypatch):
    """Forces one of the two surface evaluation paths."""
    monkeypatch.setattr(surface_module, "TABLE_MIN_POINTS_PER_PATCH", 10**9 if request.param == "gather" else 0)
    return request.param


@pytest.mark.parametrize("degrees", [(1, 1), (2, 3), (3, 3), (4, 2), (5, 5), (1, 4)])
def test_surface_matches_ndbspline(degrees, evaluation_path):
    p, q = degrees
    n_points = 3000
    rng = np.random.default_rng(p * 7 + q)
    nu, nv = p + 1 + rng.integers(0, 9), q + 1 + rng.integers(0, 9)
    Uu, Uv = random_knots(rng, nu, p), random_knots(rng, nv, q)
    P = rng.normal(size=(nu, nv, 3))
    surface = BSplineSurface(p, q, Uu, Uv, P)
    assert surface._use_patch_table(n_points) == (evaluation_path == "table")
    ref = NdBSpline((Uu, Uv), P, (p, q))
    uv = rng.uniform(0, 1, (n_points, 2))
    uv[0] = (1.0, 1.0)
    uv[1] = (0.0, 1.0)
    assert rel_err(surface.evaluate(uv[:, 0], uv[:, 1]), ref(uv)) < REL
    D = surface.derivatives(uv[:, 0], uv[:, 1], 2)
    for k in range(3):
        for l in range(3 - k):
            if k > p or l > q:
                assert np.all(D[:, k, l] == 0)
                continue
            assert rel_err(D[:, k, l], ref(uv, nu=(k, l))) < REL, (k, l)


def test_rational_surface_quotient_rule(evaluation_path):
    n_points = 2000
    rng = np.random.default_rng(7)
    p, q, nu, nv = 3, 2, 8, 6
    Uu, Uv = random_knots(rng, nu, p), random_knots(rng, nv, q)
    P = rng.normal(size=(nu, nv, 3))
    w = rng.uniform(0.4, 2.5, (nu, nv))
    surface = BSplineSurface(p, q, Uu, Uv, P, w)
    A = NdBSpline((Uu, Uv), P * w[..., None], (p, q))
    W = NdBSpline((Uu, Uv), w, (p, q))
    uv = rng.uniform(0, 1, (n_points, 2))
    a = {kl: A(uv, nu=kl) for kl in [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]}
    ww = {kl: W(uv, nu=kl)[:, None] for kl in a}
    s00 = a[0, 0] / ww[0, 0]
    s10 = (a[1, 0] - ww[1, 0] * s00) / ww[0, 0]
    s01 = (a[0, 1] - ww[0, 1] * s00) / ww[0, 0]
    s11 = (a[1, 1] - ww[1, 1] * s00 - ww[1, 0] * s01 - ww[0, 1] * s10) / ww[0, 0]
    s20 = (a[2, 0] - 2 * ww[1, 0] * s10 - ww[2, 0] * s00) / ww[0, 0]
    s02 = (a[0, 2] - 2 * ww[0, 1] * s01 - ww[0, 2] * s00) / ww[0, 0]
    D = surface.derivatives(uv[:, 0], uv[:, 1], 2)
    assert rel_err(surface.evaluate(uv[:, 0], uv[:, 1]), s00) < REL
    for (k, l), ref in {(0, 0): s00, (1, 0): s10, (0, 1): s01, (1, 1): s11, (2, 0): s20, (0, 2): s02}.items():
        assert rel_err(D[:, k, l], ref) < 1e-11, (k, l)


def test_evaluation_shapes_broadcast():
    rng = np.random.default_rng(3)
    surface = BSplineSurface(3, 3, random_knots(rng, 6, 3), random_knots(rng, 5, 3), rng.normal(size=(6, 5, 3)))
    u = rng.uniform(0, 1, (4, 1))
    v = rng.uniform(0, 1, (1, 7))
    assert surface.evaluate(u, v).shape == (4, 7, 3)
    assert surface.derivatives(u, v, 2).shape == (4, 7, 3, 3, 3)
    assert surface.evaluate(0.5, 0.5).shape == (3,)
    curve = BSplineCurve(2, random_knots(rng, 5, 2), rng.normal(size=(5, 2)))
    assert curve.evaluate(np.zeros((2, 3))).shape == (2, 3, 2)
    assert curve.derivatives(0.3, 2).shape == (3, 2)


def test_grid_and_iso_curves_agree_with_pointwise():
    rng = np.random.default_rng(4)
    p, q = 3, 2
    Uu, Uv = random_knots(rng, 9, p), random_knots(rng, 7, q)
    surface = BSplineSurface(p, q, Uu, Uv, rng.normal(size=(9, 7, 3)), rng.uniform(0.5, 2, (9, 7)))
    us, vs = np.linspace(0, 1, 13), np.linspace(0, 1, 11)
    grid = surface.evaluate_grid(us, vs)
    pointwise = surface.evaluate(us[:, None], vs[None, :])
    assert rel_err(grid, pointwise) < REL
    iso_u = surface.iso_curve("u", 0.37)
    assert rel_err(iso_u.evaluate(vs), surface.evaluate(0.37, vs)) < REL
    iso_v = surface.iso_curve("v", 0.81)
    assert rel_err(iso_v.evaluate(us), surface.evaluate(us, 0.81)) < REL


def test_table_path_is_cached_and_read_only():
    rng = np.random.default_rng(5)
    surface = BSplineSurface(3, 3, random_knots(rng, 6, 3), random_knots(rng, 6, 3), rng.normal(size=(6, 6, 3)))
    first = surface._patch_table
    assert surface._patch_table is first
    with pytest.raises(ValueError):
        first[2][0, 0, 0] = 1.0
    with pytest.raises(ValueError):
        surface.control_points[0, 0, 0] = 1.0


def test_table_path_switches_off_for_huge_tables(monkeypatch):
    rng = np.random.default_rng(6)
    surface = BSplineSurface(3, 3, random_knots(rng, 8, 3), random_knots(rng, 8, 3), rng.normal(size=(8, 8, 3)))
    assert surface._use_patch_table(10**6)
    monkeypatch.setattr(surface_module, "TABLE_MAX_BYTES", 100)
    assert not surface._use_patch_table(10**6)


# -- bad input -------------------------------------------------------------------------

GOOD_KNOTS = [0, 0, 0, 0, 0.5, 1, 1, 1, 1]
GOOD_POINTS = np.arange(15.0).reshape(5, 3)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(knots=[0, 0, 0, 0, 0.6, 0.5, 1, 1, 1]), "non-decreasing"),
        (dict(knots=[0, 0, 0, 0, 1, 1, 1, 1]), "expected 9 knots"),
        (dict(knots=[0, 0, 0, 0, np.nan, 1, 1, 1, 1]), "not finite"),
        (dict(control_points=np.where(np.eye(5, 3) > 0, np.nan, GOOD_POINTS)), "not finite"),
        (dict(weights=[1, 1, 0, 1, 1]), "must be > 0"),
        (dict(weights=[1, 1, -2, 1, 1]), "must be > 0"),
        (dict(weights=[1, 1, 1, 1]), "expected shape (5,)"),
        (dict(weights=[1, np.inf, 1, 1, 1]), "non-finite"),
        (dict(degree=0, knots=[0, 0, 0.25, 0.5, 0.75, 1]), "degree must be >= 1"),
        (dict(degree=2.5), "integer"),
        (dict(control_points=np.zeros((2, 3)), knots=[0, 0, 0, 0, 1, 1]), "at least 4 control points"),
        (dict(knots=[0, 0, 0, 0, 0, 1, 1, 1, 1]), "multiplicity 5, more than degree + 1"),
        (dict(knots=[0, 0, 0, 1, 1, 1, 1, 1, 1]), "domain"),
    ],
)
def test_curve_refuses_bad_input(kwargs, message):
    args = dict(degree=3, knots=GOOD_KNOTS, control_points=GOOD_POINTS, weights=None)
    args.update(kwargs)
    with pytest.raises(GeometryError) as info:
        BSplineCurve(**args)
    assert message in str(info.value)
    assert isinstance(info.value, BladesmithError) and isinstance(info.value, ValueError)


def test_interior_multiplicity_above_degree_is_refused():
    with pytest.raises(GeometryError, match="multiplicity 3, more than the degree 2"):
        BSplineCurve(2, [0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1], np.zeros((6, 2)))


def test_surface_refuses_bad_input():
    P = np.zeros((5, 4, 3))
    with pytest.raises(GeometryError, match="knots_v: expected 7 knots"):
        BSplineSurface(3, 2, GOOD_KNOTS, [0, 0, 0, 1, 1, 1], P)
    with pytest.raises(GeometryError, match="degree_v must be >= 1"):
        BSplineSurface(3, 0, GOOD_KNOTS, [0, 0.3, 0.6, 1], P)
    with pytest.raises(GeometryError, match=r"weights: expected shape \(5, 4\)"):
        BSplineSurface(3, 2, GOOD_KNOTS, [0, 0, 0, 0.5, 1, 1, 1], P, np.ones((4, 5)))
    with pytest.raises(GeometryError, match="must be > 0"):
        BSplineSurface(3, 2, GOOD_KNOTS, [0, 0, 0, 0.5, 1, 1, 1], P, np.zeros((5, 4)))
    with pytest.raises(GeometryError, match=r"expected shape \(nu, nv, dim\)"):
        BSplineSurface(3, 2, GOOD_KNOTS, [0, 0, 0, 0.5, 1, 1, 1], np.zeros((5, 4)))


def test_parameters_outside_the_domain_are_refused():
    curve = BSplineCurve(3, GOOD_KNOTS, GOOD_POINTS)
    with pytest.raises(GeometryError, match="outside the domain"):
        curve.evaluate([0.5, 1.2])
    with pytest.raises(GeometryError, match="NaN"):
        curve.evaluate([np.nan])
    # round-off just past the end is taken as the end
    assert np.allclose(curve.evaluate(1 + 1e-13), GOOD_POINTS[-1])


@pytest.mark.parametrize("rational", [False, True])
def test_curve_span_table_and_basis_paths_agree(rational):
    """Many parameters go through the cached Taylor table of the spans, few through the
    basis functions (NURBS Book A2.3); both give the same values and derivatives."""
    from bladesmith.geometry.nurbs import curve as curve_module

    rng = np.random.default_rng(11 + rational)
    for degree in (1, 2, 3, 5):
        n = degree + 8
        knots = np.concatenate([np.zeros(degree + 1), np.sort(rng.uniform(0, 2, n - degree - 1)), np.full(degree + 1, 2.0)])
        c = BSplineCurve(degree, knots, rng.normal(size=(n, 3)) * 10, rng.uniform(0.5, 2.0, n) if rational else None)
        u = np.concatenate([rng.uniform(0, 2, 400), knots[degree:-degree]])
        assert u.size >= curve_module.TABLE_MIN_POINTS_PER_SPAN * (n - degree)
        many = c.derivatives(u, 3)
        few = np.stack([c.derivatives(u[i: i + 1], 3)[0] for i in range(u.size)])
        scale = np.abs(few).max(axis=0, keepdims=True) + 1.0
        assert np.max(np.abs(many - few) / scale) < 1e-13, degree
