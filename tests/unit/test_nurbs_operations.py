"""Knot insertion, refinement, clamping, Bezier form, degree elevation, reversal, splitting,
reparametrisation and compatibility (geometry/nurbs/operations.py) as invariants on seeded
random curves and surfaces: clamped and unclamped, rational and not, degrees 1-5, non-uniform
knots with repeated interior knots.

Tolerances are relative: positions to the control net's size (``.size()``), first
derivatives to the largest first derivative sampled. The worst error of each invariant is
collected in ``MAX_ERRORS`` and printed at the end of the module (run with ``-s``).
"""
import numpy as np
import pytest

from bladesmith.geometry.errors import GeometryError
from bladesmith.geometry.nurbs import BSplineCurve, BSplineSurface
from bladesmith.geometry.nurbs.operations import (
    KNOT_TOL,
    bezier_segments,
    clamp,
    clamp_surface,
    elevate_degree,
    elevate_degree_surface,
    insert_knot,
    insert_knot_surface,
    make_compatible,
    merge_knot_vectors,
    refine_knots,
    refine_knots_surface,
    reparametrize,
    reverse,
    reverse_surface,
    split,
    surface_to_bezier_form,
    to_bezier_form,
)

REL = 1e-12
N_PARAMS = 120
MAX_ERRORS: dict[str, float] = {}


@pytest.fixture(scope="module", autouse=True)
def report_max_errors():
    yield
    if MAX_ERRORS:
        print("\nworst relative errors per invariant:")
        for name in sorted(MAX_ERRORS):
            print(f"  {name:28s} {MAX_ERRORS[name]:.2e}")


def check(name: str, error: float, tol: float = REL) -> None:
    MAX_ERRORS[name] = max(MAX_ERRORS.get(name, 0.0), float(error))
    assert error <= tol, f"{name}: relative error {error:.3e} > {tol:.0e}"


# ---------------------------------------------------------------------------------------
# random data
# ---------------------------------------------------------------------------------------
def random_knots(rng, degree: int, n_control: int, kind: str, domain=None) -> np.ndarray:
    """Non-uniform knots over a random domain; interior knots repeated up to the degree.

    kind: 'clamped'; 'unclamped' (distinct knots outside the domain, as Blender's uniform
    mode); 'mixed' (clamped at the start, unclamped at the end with the end value doubled
    when the degree allows).
    """
    p = degree
    n_interior = n_control - p - 1
    mults = []
    while sum(mults) < n_interior:
        mults.append(int(min(rng.integers(1, p + 1) if rng.random() < 0.35 else 1, n_interior - sum(mults))))
    gaps = rng.uniform(0.25, 1.0, len(mults) + 1)
    values = np.cumsum(gaps)[:-1] / gaps.sum()
    interior = np.repeat(values, mults)
    if domain is None:
        start = rng.uniform(-3.0, 3.0)
        domain = (start, start + rng.uniform(0.5, 5.0))
    a, b = domain
    outside = rng.uniform(0.1, 0.4, 2 * p)
    left = -np.cumsum(outside[:p])[::-1]
    right = 1.0 + np.cumsum(outside[p:])
    if kind == "clamped":
        U = np.concatenate([np.zeros(p + 1), interior, np.ones(p + 1)])
    elif kind == "unclamped":
        U = np.concatenate([left, [0.0], interior, [1.0], right])
    elif kind == "mixed":
        end = [1.0, 1.0] if p >= 2 else [1.0]
        U = np.concatenate([np.zeros(p + 1), interior, end, right[: p + 1 - len(end)]])
    else:  # pragma: no cover
        raise ValueError(kind)
    scaled = a + U * (b - a)
    scaled[U == 0.0] = a  # the domain ends exactly, whatever the rounding
    scaled[U == 1.0] = b
    return np.maximum.accumulate(scaled)


def random_curve(rng, degree: int, kind: str, rational: bool, dim: int = 3, n_control=None, domain=None):
    n = n_control if n_control is not None else degree + 1 + int(rng.integers(0, 8))
    U = random_knots(rng, degree, n, kind, domain)
    P = rng.uniform(-1.0, 1.0, (n, dim))
    w = rng.uniform(0.4, 2.5, n) if rational else None
    return BSplineCurve(degree, U, P, w)


def random_surface(rng, degree_u: int, degree_v: int, kind_u: str, kind_v: str, rational: bool):
    nu = degree_u + 1 + int(rng.integers(0, 5))
    nv = degree_v + 1 + int(rng.integers(0, 5))
    Uu = random_knots(rng, degree_u, nu, kind_u)
    Uv = random_knots(rng, degree_v, nv, kind_v)
    P = rng.uniform(-1.0, 1.0, (nu, nv, 3))
    w = rng.uniform(0.4, 2.5, (nu, nv)) if rational else None
    return BSplineSurface(degree_u, degree_v, Uu, Uv, P, w)


def params(rng, curve: BSplineCurve, count: int = N_PARAMS) -> np.ndarray:
    """Random parameters plus the domain start, the end when evaluable, and the knots."""
    a, b = curve.domain
    inner = curve.knots[(curve.knots > a) & (curve.knots < b)]
    u = np.concatenate([rng.uniform(a, b, count), inner, [a, b]])
    return u


def surface_params(rng, surface: BSplineSurface, count: int = N_PARAMS):
    (a, b), (c, d) = surface.domain_u, surface.domain_v
    return rng.uniform(a, b, count), rng.uniform(c, d, count)


def pos_err(curve, other, u, u_other=None) -> float:
    u_other = u if u_other is None else u_other
    return np.abs(other.evaluate(u_other) - curve.evaluate(u)).max() / curve.size()


def der_err(curve, other, u, u_other=None, scale_other=1.0) -> float:
    u_other = u if u_other is None else u_other
    d = curve.derivatives(u, 1)[..., 1, :]
    e = other.derivatives(u_other, 1)[..., 1, :] * scale_other
    return np.abs(e - d).max() / np.abs(d).max()


def surf_err(surface, other, u, v, u_other=None, v_other=None) -> float:
    u_other = u if u_other is None else u_other
    v_other = v if v_other is None else v_other
    return np.abs(other.evaluate(u_other, v_other) - surface.evaluate(u, v)).max() / surface.size()


def multiplicity(knots, value) -> int:
    return int(np.count_nonzero(np.asarray(knots) == value))


KINDS = ("clamped", "unclamped", "mixed")
CURVE_CASES = [
    (degree, kind, rational, seed)
    for degree in range(1, 6)
    for kind in KINDS
    for rational in (False, True)
    for seed in range(2)
]


def case_id(case):
    degree, kind, rational, seed = case
    return f"p{degree}-{kind}-{'rat' if rational else 'poly'}-{seed}"


@pytest.fixture(params=CURVE_CASES, ids=case_id)
def case(request):
    degree, kind, rational, seed = request.param
    rng = np.random.default_rng([degree, KINDS.index(kind), rational, seed])
    return rng, random_curve(rng, degree, kind, rational, dim=int(rng.integers(2, 4)))


# ---------------------------------------------------------------------------------------
# curves
# ---------------------------------------------------------------------------------------
def test_insert_knot_keeps_geometry(case):
    rng, c = case
    p, (a, b) = c.degree, c.domain
    u = params(rng, c)
    # a new knot, and an existing interior knot when one has room
    targets = [rng.uniform(a, b)]
    inner = np.unique(c.knots[(c.knots > a) & (c.knots < b)])
    room = [k for k in inner if multiplicity(c.knots, k) < p]
    if room:
        targets.append(room[0])
    for x in targets:
        s = multiplicity(c.knots, x)
        times = int(rng.integers(1, p - s + 1))
        d = insert_knot(c, x, times)
        assert d.n_control == c.n_control + times
        assert multiplicity(d.knots, x) == s + times
        assert d.is_rational == c.is_rational and d.domain == c.domain
        check("insert_knot position", pos_err(c, d, u))
        check("insert_knot derivative", der_err(c, d, u))
    # the domain ends of an unclamped vector take up to p copies
    sa = multiplicity(c.knots, a)
    if sa < p:
        d = insert_knot(c, a, p - sa)
        assert multiplicity(d.knots, a) == p
        check("insert_knot position", pos_err(c, d, u))
        check("insert_knot derivative", der_err(c, d, u))
    sb = multiplicity(c.knots, b)
    if sb < p:
        d = insert_knot(c, b, p - sb)
        assert multiplicity(d.knots, b) == p
        u = u[u < b]
        check("insert_knot position", pos_err(c, d, u))
        check("insert_knot derivative", der_err(c, d, u))


def test_refine_knots_matches_repeated_insertion(case):
    rng, c = case
    p, (a, b) = c.degree, c.domain
    u = params(rng, c)
    # new values, a repeated one, and the domain ends (which only unclamped ends accept)
    X = np.sort(np.concatenate([rng.uniform(a, b, int(rng.integers(1, 7))), [0.5 * (a + b)] * min(p, 2), [a, b]]))
    X = X[[multiplicity(c.knots, x) + np.count_nonzero(X == x) <= p for x in X]]
    d = refine_knots(c, X)
    assert d.n_control == c.n_control + X.size
    np.testing.assert_array_equal(d.knots, np.sort(np.concatenate([c.knots, X])))
    check("refine_knots position", pos_err(c, d, u))
    check("refine_knots derivative", der_err(c, d, u))
    one_by_one = c
    for x in X:
        one_by_one = insert_knot(one_by_one, x)
    check(
        "refine_knots vs A5.1 points",
        np.abs(one_by_one.control_points - d.control_points).max() / c.size(),
    )
    empty = refine_knots(c, [])
    np.testing.assert_array_equal(empty.knots, c.knots)
    np.testing.assert_array_equal(empty.control_points, c.control_points)


def test_clamp_keeps_geometry_and_domain(case):
    rng, c = case
    p = c.degree
    u = params(rng, c)
    d = clamp(c)
    a, b = c.domain
    assert d.domain == (a, b)
    assert np.all(d.knots[: p + 1] == a) and np.all(d.knots[-p - 1 :] == b)
    check("clamp position", pos_err(c, d, u))
    check("clamp derivative", der_err(c, d, u))
    # interior knots are kept as they are
    inner = c.knots[(c.knots > a) & (c.knots < b)]
    np.testing.assert_array_equal(d.knots[p + 1 : -p - 1], inner)
    again = clamp(d)
    np.testing.assert_array_equal(again.knots, d.knots)
    np.testing.assert_array_equal(again.control_points, d.control_points)


def test_clamp_blender_uniform_cubic():
    # Blender's uniform mode for order 4 and 7 points: knots 0, 1, ..., 10, domain [3, 7]
    rng = np.random.default_rng(7)
    c = BSplineCurve(3, np.arange(11.0), rng.uniform(-1, 1, (7, 3)))
    d = clamp(c)
    np.testing.assert_array_equal(d.knots, [3, 3, 3, 3, 4, 5, 6, 7, 7, 7, 7])
    u = np.linspace(3.0, 7.0, 101)
    check("clamp position", pos_err(c, d, u))
    # uniform cubic: the clamped end point is (P0 + 4 P1 + P2) / 6
    np.testing.assert_allclose(d.control_points[0], (c.control_points[:3] * [[1], [4], [1]]).sum(0) / 6, atol=1e-15)


def test_to_bezier_form_and_segments(case):
    rng, c = case
    p, (a, b) = c.degree, c.domain
    u = params(rng, c)
    d = to_bezier_form(c)
    inner = np.unique(c.knots[(c.knots > a) & (c.knots < b)])
    expected = np.concatenate([[a] * (p + 1), np.repeat(inner, p), [b] * (p + 1)])
    np.testing.assert_array_equal(d.knots, expected)
    assert d.n_control == p * (inner.size + 1) + 1
    check("bezier form position", pos_err(c, d, u))
    check("bezier form derivative", der_err(c, d, u))
    segments = bezier_segments(c)
    breaks = np.unique(np.concatenate([[a, b], c.knots[(c.knots > a) & (c.knots < b)]]))
    assert len(segments) == breaks.size - 1
    for seg, lo, hi in zip(segments, breaks[:-1], breaks[1:]):
        assert seg.degree == p and seg.n_control == p + 1 and seg.is_rational == c.is_rational
        np.testing.assert_array_equal(seg.knots, [lo] * (p + 1) + [hi] * (p + 1))
        u = np.concatenate([rng.uniform(lo, hi, 40), [lo, hi]])
        check("bezier segments position", pos_err(c, seg, u))
    # neighbouring segments share their end points exactly
    for left, right in zip(segments[:-1], segments[1:]):
        np.testing.assert_array_equal(left.control_points[-1], right.control_points[0])


def test_elevate_degree(case):
    rng, c = case
    p = c.degree
    u = params(rng, c)
    values, counts = np.unique(clamp(c).knots, return_counts=True)
    for times in (1, 2, 3):
        d = elevate_degree(c, times)
        assert d.degree == p + times and d.domain == c.domain and d.is_rational == c.is_rational
        np.testing.assert_array_equal(d.knots, np.repeat(values, counts + times))
        check("elevate_degree position", pos_err(c, d, u))
        check("elevate_degree derivative", der_err(c, d, u))


def test_calls_that_change_nothing_return_the_input(case):
    _, c = case
    a, b = c.domain
    assert insert_knot(c, 0.5 * (a + b), 0) is c
    assert refine_knots(c, []) is c
    k = clamp(c)
    assert clamp(k) is k and elevate_degree(k, 0) is k
    bz = to_bezier_form(c)
    assert to_bezier_form(bz) is bz


def test_reverse(case):
    rng, c = case
    a, b = c.domain
    u = params(rng, c)
    r = reverse(c)
    assert r.domain == (a, b)
    check("reverse position", pos_err(c, r, u, a + b - u))
    # off the knots: at a knot the evaluator gives the derivative from the right, which
    # is the one from the left of the reversed curve
    u = u[~np.isin(u, c.knots)]
    d = c.derivatives(u, 1)[..., 1, :]
    e = r.derivatives(a + b - u, 1)[..., 1, :]
    check("reverse derivative", np.abs(e + d).max() / np.abs(d).max())
    twice = reverse(r)
    np.testing.assert_array_equal(twice.control_points, c.control_points)
    np.testing.assert_allclose(twice.knots, c.knots, rtol=0, atol=4 * np.finfo(float).eps * np.abs(c.knots).max())


def test_split(case):
    rng, c = case
    p, (a, b) = c.degree, c.domain
    inner = np.unique(c.knots[(c.knots > a) & (c.knots < b)])
    cuts = [a + rng.uniform(0.05, 0.95) * (b - a)] + ([inner[len(inner) // 2]] if inner.size else [])
    for x in cuts:
        left, right = split(c, x)
        assert left.domain == (a, x) and right.domain == (x, b)
        for half in (left, right):
            assert np.all(half.knots[: p + 1] == half.knots[0]) and np.all(half.knots[-p - 1 :] == half.knots[-1])
            assert half.is_rational == c.is_rational
        ul = np.concatenate([rng.uniform(a, x, N_PARAMS // 2), [a, x]])
        ur = np.concatenate([rng.uniform(x, b, N_PARAMS // 2), [x, b]])
        check("split position", max(pos_err(c, left, ul), pos_err(c, right, ur)))
        check("split derivative", max(der_err(c, left, ul[:-1]), der_err(c, right, ur[1:])))
        np.testing.assert_array_equal(left.control_points[-1], right.control_points[0])


def test_reparametrize(case):
    rng, c = case
    a, b = c.domain
    u = params(rng, c)
    for domain in [(0.0, 1.0), (-2.5, 7.25)]:
        lo, hi = domain
        d = reparametrize(c, domain)
        assert d.domain == domain
        s = lo + (u - a) * (hi - lo) / (b - a)
        s = np.clip(s, lo, hi)
        check("reparametrize position", pos_err(c, d, u, s))
        # off the knots, where a mapped parameter may land on the other side of a jump in C'
        off = ~np.isin(u, c.knots)
        check("reparametrize derivative", der_err(c, d, u[off], s[off], scale_other=(hi - lo) / (b - a)))


# ---------------------------------------------------------------------------------------
# merging and compatibility
# ---------------------------------------------------------------------------------------
def test_merge_knot_vectors_takes_max_multiplicity():
    U1 = [0, 0, 0, 0, 0.25, 0.5, 0.5, 1, 1, 1, 1]
    U2 = [0, 0, 0, 0, 0.5, 0.75, 0.75, 0.75, 1, 1, 1, 1]
    U3 = [0, 0, 0, 0, 0.25, 0.25, 0.5 + 1e-14, 1, 1, 1, 1]  # 0.5 + 1e-14 is 0.5
    merged = merge_knot_vectors([U1, U2, U3], 3)
    np.testing.assert_array_equal(merged, [0] * 4 + [0.25] * 2 + [0.5] * 2 + [0.75] * 3 + [1] * 4)
    # every input is a sub-multiset of the result
    for U in (U1, U2):
        values, counts = np.unique(U, return_counts=True)
        for v, k in zip(values, counts):
            assert multiplicity(merged, v) >= k
    # with tol 0 the near-duplicate is its own knot
    strict = merge_knot_vectors([U1, U3], 3, tol=0.0)
    assert 0.5 + 1e-14 in strict and multiplicity(strict, 0.5) == 2


def test_merge_knot_vectors_random():
    rng = np.random.default_rng(11)
    for _ in range(20):
        p = int(rng.integers(1, 5))
        vectors = [random_knots(rng, p, p + 1 + int(rng.integers(0, 7)), "clamped", (0.0, 1.0)) for _ in range(3)]
        merged = merge_knot_vectors(vectors, p)
        values = np.unique(np.concatenate(vectors))
        np.testing.assert_array_equal(np.unique(merged), values)
        for v in values:
            assert multiplicity(merged, v) == max(multiplicity(U, v) for U in vectors)


def test_merge_knot_vectors_errors():
    with pytest.raises(GeometryError, match="not clamped for degree 2"):
        merge_knot_vectors([[0, 0, 0, 1, 1, 1], [-1, 0, 0.5, 1, 1, 2]], 2)
    with pytest.raises(GeometryError, match=r"expected the domain of knot_vectors\[0\]"):
        merge_knot_vectors([[0, 0, 1, 1], [0, 0, 2, 2]], 1)
    with pytest.raises(GeometryError, match="at least one knot vector"):
        merge_knot_vectors([], 2)
    with pytest.raises(GeometryError, match="degree must be"):
        merge_knot_vectors([[0, 0, 1, 1]], 0)


@pytest.mark.parametrize("seed", range(8))
def test_make_compatible(seed):
    rng = np.random.default_rng(100 + seed)
    count = int(rng.integers(2, 5))
    curves = [
        random_curve(rng, int(rng.integers(1, 6)), str(rng.choice(KINDS)), bool(rng.random() < 0.4), dim=3)
        for _ in range(count)
    ]
    if seed == 0:  # one curve rational, the others not
        curves = [c if i else random_curve(rng, 2, "clamped", True) for i, c in enumerate(curves)]
        curves[1:] = [BSplineCurve(c.degree, c.knots, c.control_points) for c in curves[1:]]
    out = make_compatible(curves)
    assert len(out) == len(curves)
    p = max(c.degree for c in curves)
    rational = any(c.is_rational for c in curves)
    for o in out:
        assert o.degree == p and o.domain == (0.0, 1.0) and o.is_rational == rational
        np.testing.assert_array_equal(o.knots, out[0].knots)
    assert np.all(out[0].knots[: p + 1] == 0.0) and np.all(out[0].knots[-p - 1 :] == 1.0)
    t = np.concatenate([rng.uniform(0, 1, N_PARAMS), [0.0]])
    for c, o in zip(curves, out):
        a, b = c.domain
        check("make_compatible position", pos_err(c, o, a + t * (b - a), t))
        d = c.derivatives(a + t * (b - a), 1)[:, 1]
        e = o.derivatives(t, 1)[:, 1] / (b - a)  # d/dt = (b - a) d/du
        check("make_compatible derivative", np.abs(e - d).max() / np.abs(d).max())


def test_make_compatible_snaps_near_equal_knots():
    P = np.array([[0.0, 0.0], [1.0, 2.0], [2.0, -1.0], [3.0, 0.5]])
    c1 = BSplineCurve(2, [0, 0, 0, 0.5, 1, 1, 1], P)
    c2 = BSplineCurve(2, [0, 0, 0, 0.5 + 1e-14, 1, 1, 1], P[::-1])
    o1, o2 = make_compatible([c1, c2])
    np.testing.assert_array_equal(o1.knots, [0, 0, 0, 0.5, 1, 1, 1])
    np.testing.assert_array_equal(o2.knots, o1.knots)
    t = np.linspace(0, 1, 101)
    check("make_compatible position", pos_err(c2, o2, t))


def test_make_compatible_errors():
    c2 = BSplineCurve(1, [0, 0, 1, 1], [[0.0, 0.0], [1.0, 1.0]])
    c3 = BSplineCurve(1, [0, 0, 1, 1], [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])
    with pytest.raises(GeometryError, match=r"one dimension for all curves, got \[2, 3\]"):
        make_compatible([c2, c3])
    with pytest.raises(GeometryError, match="at least one curve"):
        make_compatible([])
    with pytest.raises(GeometryError, match=r"curves\[1\]: expected a BSplineCurve, got list"):
        make_compatible([c2, [0, 1]])


# ---------------------------------------------------------------------------------------
# curve error cases
# ---------------------------------------------------------------------------------------
@pytest.fixture
def cubic():
    return BSplineCurve(3, [0, 0, 0, 0, 0.4, 0.4, 0.7, 1, 1, 1, 1], np.arange(21.0).reshape(7, 3) ** 0.5)


def test_insert_knot_errors(cubic):
    with pytest.raises(GeometryError, match=r"multiplicity 2 would give multiplicity 4; expected at most the degree 3"):
        insert_knot(cubic, 0.4, 2)
    with pytest.raises(GeometryError, match=r"already has multiplicity 4 would give multiplicity 5"):
        insert_knot(cubic, 0.0)  # the clamped end already has p + 1
    with pytest.raises(GeometryError, match=r"knot 1.5 is outside the domain \[0.0, 1.0\]"):
        insert_knot(cubic, 1.5)
    with pytest.raises(GeometryError, match="finite"):
        insert_knot(cubic, float("nan"))
    with pytest.raises(GeometryError, match="times must be >= 0, got -1"):
        insert_knot(cubic, 0.5, -1)
    with pytest.raises(GeometryError, match="times must be an integer"):
        insert_knot(cubic, 0.5, 1.5)
    with pytest.raises(GeometryError, match="expected a BSplineCurve, got ndarray"):
        insert_knot(np.zeros((4, 3)), 0.5)
    # within KNOT_TOL of an existing knot means that knot
    d = insert_knot(cubic, 0.4 + 0.1 * KNOT_TOL)
    assert multiplicity(d.knots, 0.4) == 3


def test_refine_knots_errors(cubic):
    with pytest.raises(GeometryError, match=r"sorted \(non-decreasing\)"):
        refine_knots(cubic, [0.5, 0.2])
    with pytest.raises(GeometryError, match=r"new_knots\[1\] = 1.5 is outside the domain \[0.0, 1.0\]"):
        refine_knots(cubic, [0.2, 1.5])
    with pytest.raises(GeometryError, match="inserting knot 0.7 3 time.*would give multiplicity 4"):
        refine_knots(cubic, [0.7, 0.7, 0.7])
    with pytest.raises(GeometryError, match="not finite"):
        refine_knots(cubic, [0.2, np.inf])


def test_split_and_reparametrize_errors(cubic):
    for u in (0.0, 1.0, 1.0 + 0.1 * KNOT_TOL):
        with pytest.raises(GeometryError, match="strictly inside the domain"):
            split(cubic, u)
    with pytest.raises(GeometryError, match="outside the domain"):
        split(cubic, -0.3)
    with pytest.raises(GeometryError, match=r"expected finite start < end, got \(1.0, 0.0\)"):
        reparametrize(cubic, (1.0, 0.0))
    with pytest.raises(GeometryError, match="expected a pair"):
        reparametrize(cubic, 3.0)


# ---------------------------------------------------------------------------------------
# surfaces
# ---------------------------------------------------------------------------------------
SURFACE_CASES = [
    (p, q, kind_u, kind_v, rational)
    for (p, q) in [(1, 3), (2, 2), (3, 1), (4, 2), (3, 5)]
    for (kind_u, kind_v) in [("clamped", "unclamped"), ("unclamped", "mixed")]
    for rational in (False, True)
]


@pytest.fixture(params=SURFACE_CASES, ids=lambda c: f"p{c[0]}q{c[1]}-{c[2]}-{c[3]}-{'rat' if c[4] else 'poly'}")
def surface_case(request):
    p, q, kind_u, kind_v, rational = request.param
    rng = np.random.default_rng([p, q, KINDS.index(kind_u), KINDS.index(kind_v), rational])
    return rng, random_surface(rng, p, q, kind_u, kind_v, rational)


def _direction_data(surface, direction):
    if direction == "u":
        return surface.degree_u, surface.knots_u, surface.domain_u
    return surface.degree_v, surface.knots_v, surface.domain_v


@pytest.mark.parametrize("direction", ["u", "v"])
def test_surface_knot_insertion_and_refinement(surface_case, direction):
    rng, s = surface_case
    u, v = surface_params(rng, s)
    p, U, (a, b) = _direction_data(s, direction)
    x = rng.uniform(a, b)
    d = insert_knot_surface(s, direction, x, p)
    assert multiplicity(_direction_data(d, direction)[1], x) == p
    check("surface insert position", surf_err(s, d, u, v))
    D0, D1 = s.derivatives(u, v, 1), d.derivatives(u, v, 1)
    check("surface insert derivative", np.abs(D1[:, 1, 0] - D0[:, 1, 0]).max() / np.abs(D0[:, 1, 0]).max())
    check("surface insert derivative", np.abs(D1[:, 0, 1] - D0[:, 0, 1]).max() / np.abs(D0[:, 0, 1]).max())
    X = np.sort(rng.uniform(a, b, 4))
    r = refine_knots_surface(s, direction, X)
    np.testing.assert_array_equal(_direction_data(r, direction)[1], np.sort(np.concatenate([U, X])))
    other = "v" if direction == "u" else "u"
    np.testing.assert_array_equal(_direction_data(r, other)[1], _direction_data(s, other)[1])
    check("surface refine position", surf_err(s, r, u, v))
    # every iso-curve of the refined surface is the refined iso-curve
    t = _direction_data(s, other)[2][0]
    iso = s.iso_curve(other, t)
    np.testing.assert_allclose(
        r.iso_curve(other, t).control_points, refine_knots(iso, X).control_points, rtol=0, atol=1e-14 * s.size()
    )


def test_surface_clamp_and_bezier_form(surface_case):
    rng, s = surface_case
    u, v = surface_params(rng, s)
    c = clamp_surface(s)
    assert c.domain_u == s.domain_u and c.domain_v == s.domain_v
    for p, U in ((c.degree_u, c.knots_u), (c.degree_v, c.knots_v)):
        assert np.all(U[: p + 1] == U[0]) and np.all(U[-p - 1 :] == U[-1])
    check("surface clamp position", surf_err(s, c, u, v))
    assert clamp_surface(c) is c
    bz = surface_to_bezier_form(s)
    for p, U in ((bz.degree_u, bz.knots_u), (bz.degree_v, bz.knots_v)):
        values, counts = np.unique(U, return_counts=True)
        assert counts[0] == counts[-1] == p + 1 and np.all(counts[1:-1] == p)
    check("surface bezier form position", surf_err(s, bz, u, v))


@pytest.mark.parametrize("direction", ["u", "v"])
def test_surface_elevate_and_reverse(surface_case, direction):
    rng, s = surface_case
    u, v = surface_params(rng, s)
    p, _, (a, b) = _direction_data(s, direction)
    e = elevate_degree_surface(s, direction, 2)
    assert _direction_data(e, direction)[0] == p + 2
    check("surface elevate position", surf_err(s, e, u, v))
    r = reverse_surface(s, direction)
    assert _direction_data(r, direction)[2] == (a, b)
    if direction == "u":
        check("surface reverse position", surf_err(s, r, u, v, a + b - u, v))
    else:
        check("surface reverse position", surf_err(s, r, u, v, u, a + b - v))


def test_surface_direction_errors():
    rng = np.random.default_rng(3)
    s = random_surface(rng, 2, 3, "clamped", "clamped", False)
    for call in (
        lambda: insert_knot_surface(s, "w", 0.5),
        lambda: refine_knots_surface(s, "U", [0.5]),
        lambda: elevate_degree_surface(s, 0),
        lambda: reverse_surface(s, "uv"),
    ):
        with pytest.raises(GeometryError, match="direction must be 'u' or 'v', got"):
            call()
    (a, b) = s.domain_v
    with pytest.raises(GeometryError, match=r"knot \(v\) .* is outside the domain"):
        insert_knot_surface(s, "v", b + 1.0)
    with pytest.raises(GeometryError, match="would give multiplicity 4; expected at most the degree 2"):
        insert_knot_surface(s, "u", s.knots_u[0])
    with pytest.raises(GeometryError, match="expected a BSplineSurface, got BSplineCurve"):
        clamp_surface(random_curve(rng, 2, "clamped", False))


# ---------------------------------------------------------------------------------------
# regression: the end of an unclamped domain on a repeated knot (found while writing these)
# ---------------------------------------------------------------------------------------
def test_core_evaluates_end_of_unclamped_curve_with_multiple_end_knot():
    c = BSplineCurve(3, [0, 1, 2, 3, 5, 5, 6, 7, 8], np.arange(10.0).reshape(5, 2))
    with np.errstate(all="ignore"):
        end = c.evaluate(5.0)
    np.testing.assert_allclose(end, clamp(c).control_points[-1], rtol=0, atol=1e-12)


@pytest.mark.parametrize("direction", ["u", "v"])
@pytest.mark.parametrize("rational", [False, True])
def test_split_surface_reproduces_the_surface(direction, rational):
    from bladesmith.geometry.nurbs.operations import split_surface

    rng = np.random.default_rng(61 + rational)
    for kind in ("clamped", "unclamped"):
        s = random_surface(rng, 3, 2, kind, kind, rational)
        (a, b), (c, d) = s.domain_u, s.domain_v
        lo, hi = (a, b) if direction == "u" else (c, d)
        x = lo + 0.37 * (hi - lo)
        first, second = split_surface(s, direction, x)
        t = rng.uniform(0, 1, 400)
        for piece, (p0, p1) in ((first, (lo, x)), (second, (x, hi))):
            w = p0 + t * (p1 - p0)
            other = (c + rng.uniform(0, 1, 400) * (d - c)) if direction == "u" else (a + rng.uniform(0, 1, 400) * (b - a))
            uu, vv = (w, other) if direction == "u" else (other, w)
            assert np.abs(piece.evaluate(uu, vv) - s.evaluate(uu, vv)).max() < 1e-12 * s.size()
        # the pieces share their boundary row of control points exactly
        axis = 0 if direction == "u" else 1
        assert np.array_equal(np.take(first.control_points, -1, axis), np.take(second.control_points, 0, axis))
