"""Fitting: parameters, knots, interpolation (NURBS Book Alg. A9.1, §9.2.2), least squares
(§9.4.1) and adaptive approximation with a common knot vector (Hally 2013 §9)."""
import numpy as np
import pytest

from bladesmith.geometry.errors import GeometryError
from bladesmith.geometry.nurbs.fitting import (
    DEFAULT_SAMPLES_PER_SPAN,
    approximate,
    approximate_common,
    approximation_knots,
    average_knots,
    fit_least_squares,
    interpolate,
    parameterize,
)

REL = 1e-12  # interpolation / end-condition accuracy relative to the data size


def _size(Q):
    return float(np.linalg.norm(Q.max(axis=0) - Q.min(axis=0)))


def _random_points(rng, count, dim=3):
    return np.cumsum(rng.normal(size=(count, dim)), axis=0)


def _dense_deviation(curve, func, samples_per_span):
    """Max |func(t) - C(t)| on 10x as many samples per knot span as the fit used."""
    breaks = np.unique(curve.knots)
    local = np.linspace(0.0, 1.0, 10 * samples_per_span + 1)
    t = (breaks[:-1, None] + np.diff(breaks)[:, None] * local).ravel()
    return float(np.linalg.norm(func(t) - curve.evaluate(t), axis=1).max())


def _is_sub_multiset(small, big, tol=0.0):
    big = list(np.sort(big))
    for x in np.sort(small):
        hit = [i for i, y in enumerate(big) if abs(y - x) <= tol]
        if not hit:
            return False
        big.pop(hit[0])
    return True


# -- parameters and knots -----------------------------------------------------------------
@pytest.mark.parametrize("method", ["chord", "centripetal", "uniform"])
def test_parameterize_runs_from_0_to_1_increasing(method):
    Q = _random_points(np.random.default_rng(0), 15)
    t = parameterize(Q, method)
    assert t[0] == 0.0 and t[-1] == 1.0
    assert np.all(np.diff(t) > 0)


def test_parameterize_chord_is_proportional_to_chord_length():
    Q = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 3.0], [1.0, 4.0]])
    np.testing.assert_allclose(parameterize(Q, "chord"), [0, 0.2, 0.8, 1.0], atol=1e-15)
    np.testing.assert_allclose(parameterize(Q, "centripetal"), np.array([0, 1, 1 + 3**0.5, 2 + 3**0.5]) / (2 + 3**0.5))
    np.testing.assert_allclose(parameterize(Q, "uniform"), [0, 1 / 3, 2 / 3, 1])


def test_parameterize_refuses_coincident_points_naming_the_index():
    Q = np.array([[0.0, 0], [1, 0], [2, 1], [2, 1], [3, 0]])
    with pytest.raises(GeometryError, match=r"points\[3\] coincides with points\[2\]"):
        parameterize(Q)


def test_parameterize_refuses_nan_and_unknown_method():
    with pytest.raises(GeometryError, match=r"points\[1\] is not finite"):
        parameterize([[0.0, 0], [np.nan, 1], [2, 2]])
    with pytest.raises(GeometryError, match="method"):
        parameterize([[0.0, 0], [1, 1]], "arc")


def test_average_knots_eq_9_8():
    t = np.array([0.0, 0.1, 0.3, 0.6, 0.8, 1.0])
    U = average_knots(t, 3)
    expected = [0, 0, 0, 0, (0.1 + 0.3 + 0.6) / 3, (0.3 + 0.6 + 0.8) / 3, 1, 1, 1, 1]
    np.testing.assert_allclose(U, expected, atol=1e-15)


def test_approximation_knots_put_a_parameter_in_every_span():
    rng = np.random.default_rng(1)
    t = np.sort(np.concatenate([[0, 1], rng.uniform(0, 1, 60)]))
    for n_control in (4, 10, 30, 62):
        U = approximation_knots(t, n_control, 3)
        assert len(U) == n_control + 4
        spans = np.unique(U)
        counts = np.histogram(t, bins=spans)[0]
        assert np.all(counts >= 1)


# -- interpolation ---------------------------------------------------------------------------
@pytest.mark.parametrize("degree", [1, 2, 3, 5])
@pytest.mark.parametrize("method", ["chord", "centripetal", "uniform"])
def test_interpolation_passes_through_its_points(degree, method):
    rng = np.random.default_rng(10 + degree)
    Q = _random_points(rng, 17)
    c = interpolate(Q, degree, method=method)
    t = parameterize(Q, method)
    err = np.abs(c.evaluate(t) - Q).max() / _size(Q)
    assert err <= REL
    assert c.degree == degree and c.n_control == len(Q)


@pytest.mark.parametrize("ends", ["start", "end", "both"])
@pytest.mark.parametrize("degree", [2, 3, 4])
def test_interpolation_with_end_derivatives(ends, degree):
    rng = np.random.default_rng(20 + degree)
    Q = _random_points(rng, 12)
    D0 = rng.normal(size=3) * 10 if ends in ("start", "both") else None
    Dm = rng.normal(size=3) * 10 if ends in ("end", "both") else None
    c = interpolate(Q, degree, start_derivative=D0, end_derivative=Dm)
    t = parameterize(Q)
    scale = _size(Q)
    assert np.abs(c.evaluate(t) - Q).max() <= REL * scale
    d = c.derivatives(np.array([0.0, 1.0]), 1)[:, 1]
    if D0 is not None:
        assert np.abs(d[0] - D0).max() <= REL * max(scale, np.abs(D0).max())
    if Dm is not None:
        assert np.abs(d[1] - Dm).max() <= REL * max(scale, np.abs(Dm).max())
    assert c.n_control == len(Q) + (D0 is not None) + (Dm is not None)


def test_interpolation_with_given_params_and_two_points_hermite():
    Q = np.array([[0.0, 0.0], [1.0, 0.0]])
    c = interpolate(Q, 3, params=[2.0, 5.0], start_derivative=[0.0, 1.0], end_derivative=[0.0, -1.0])
    assert c.domain == (2.0, 5.0)
    np.testing.assert_allclose(c.evaluate([2.0, 5.0]), Q, atol=1e-15)
    np.testing.assert_allclose(c.derivatives(np.array([2.0, 5.0]), 1)[:, 1], [[0, 1], [0, -1]], atol=1e-14)


def test_interpolation_errors():
    with pytest.raises(GeometryError, match="too few points"):
        interpolate([[0.0, 0], [1, 1], [2, 0]], 3)
    with pytest.raises(GeometryError, match="not finite"):
        interpolate([[0.0, 0], [1, np.inf], [2, 0], [3, 1]], 3)
    with pytest.raises(GeometryError, match=r"points\[2\] coincides"):
        interpolate([[0.0, 0], [1, 1], [1, 1], [3, 1], [4, 0]], 3)
    with pytest.raises(GeometryError, match="at least 2 points"):
        interpolate([[0.0, 0]], 1)
    with pytest.raises(GeometryError, match="strictly increasing"):
        interpolate([[0.0, 0], [1, 1], [2, 0], [3, 1]], 3, params=[0, 0.5, 0.5, 1])
    with pytest.raises(GeometryError, match="start_derivative"):
        interpolate([[0.0, 0], [1, 1], [2, 0], [3, 1]], 3, start_derivative=[1, 2, 3])


# -- least squares ---------------------------------------------------------------------------
def _noisy_curve_points(rng, count=200):
    t = np.linspace(0, 1, count)
    return np.stack([np.cos(4 * t), np.sin(3 * t), t**2], axis=1) + rng.normal(scale=1e-3, size=(count, 3))


@pytest.mark.parametrize("n_control", [4, 9, 25])
def test_least_squares_interpolates_the_end_points_and_is_optimal(n_control):
    rng = np.random.default_rng(30)
    Q = _noisy_curve_points(rng)
    c = fit_least_squares(Q, n_control, 3)
    t = parameterize(Q)
    scale = _size(Q)
    assert np.abs(c.evaluate([0.0, 1.0]) - Q[[0, -1]]).max() <= REL * scale
    # optimality: the residual is orthogonal to every free basis function (normal equations)
    from bladesmith.geometry.nurbs.fitting import _collocation_matrix

    N = _collocation_matrix(c.knots, 3, n_control, t[1:-1])[:, 1:-1]
    residual = Q[1:-1] - c.evaluate(t[1:-1])
    assert np.abs(N.T @ residual).max() <= 1e-10 * scale


def test_least_squares_end_derivatives_are_exact():
    rng = np.random.default_rng(31)
    Q = _noisy_curve_points(rng)
    D0, Dm = np.array([0.5, 3.0, -1.0]), np.array([-4.0, -2.0, 2.5])
    c = fit_least_squares(Q, 12, 3, start_derivative=D0, end_derivative=Dm)
    scale = _size(Q)
    assert np.abs(c.evaluate([0.0, 1.0]) - Q[[0, -1]]).max() <= REL * scale
    d = c.derivatives(np.array([0.0, 1.0]), 1)[:, 1]
    assert np.abs(d[0] - D0).max() <= REL * 4
    assert np.abs(d[1] - Dm).max() <= REL * 4


def test_least_squares_with_knots_weights_and_params():
    rng = np.random.default_rng(32)
    Q = _noisy_curve_points(rng, 80)
    U = np.array([0, 0, 0, 0, 0.2, 0.5, 0.7, 1, 1, 1, 1.0]) * 3.0
    t = 3.0 * parameterize(Q)
    c = fit_least_squares(Q, 7, 3, params=t, knots=U)
    np.testing.assert_array_equal(c.knots, U)
    # a heavy weight pulls the curve onto that point
    w = np.ones(len(Q))
    w[40] = 1e8
    cw = fit_least_squares(Q, 7, 3, params=t, knots=U, point_weights=w)
    assert np.linalg.norm(cw.evaluate(t[40]) - Q[40]) < 1e-6 < np.linalg.norm(c.evaluate(t[40]) - Q[40])


def test_least_squares_errors():
    Q = _noisy_curve_points(np.random.default_rng(33), 20)
    with pytest.raises(GeometryError, match="n_control too small"):
        fit_least_squares(Q, 3, 3)
    with pytest.raises(GeometryError, match="n_control too small"):
        fit_least_squares(Q, 3, 2, start_derivative=[1, 0, 0], end_derivative=[1, 0, 0])
    with pytest.raises(GeometryError, match="too few points"):
        fit_least_squares(Q, 21, 3)
    with pytest.raises(GeometryError, match="not finite"):
        bad = Q.copy()
        bad[5, 1] = np.nan
        fit_least_squares(bad, 6, 3)
    with pytest.raises(GeometryError, match="point_weights"):
        fit_least_squares(Q, 6, 3, point_weights=-np.ones(20))
    with pytest.raises(GeometryError, match="domain"):
        fit_least_squares(Q, 6, 3, params=np.linspace(0, 1, 20), knots=[0, 0, 0, 0, 0.5, 1, 2, 2, 2, 2])


# -- adaptive approximation (Hally 2013 §9) --------------------------------------------------
def _helix(t):
    return np.stack([np.cos(6 * t), np.sin(6 * t), 0.3 * t], axis=1)


def _airfoil_like(t):
    # sharp curvature near t = 0.5 (a leading edge), gentle elsewhere
    s = 2 * t - 1
    return np.stack([np.abs(s) ** 1.5 + 0.02 * s**2, 0.1 * np.sin(np.pi * s) + 0.03 * s], axis=1)


@pytest.mark.parametrize("func", [_helix, _airfoil_like])
@pytest.mark.parametrize("fit", ["interpolate", "least_squares"])
def test_approximate_meets_tolerance_on_denser_samples(func, fit):
    tol = 1e-6
    report = {}
    c = approximate(func, tol, fit=fit, report=report)
    dev = _dense_deviation(c, func, DEFAULT_SAMPLES_PER_SPAN)
    assert dev <= tol
    assert report["max_deviation"] <= tol and report["n_knots"] == len(c.knots)
    assert c.domain == (0.0, 1.0) and c.degree == 3


def test_approximate_keeps_the_initial_knots_and_the_domain():
    initial = [0.0, 0.0, 0.0, 0.0, 0.13, 0.5, 0.5, 0.77, 2.0, 2.0, 2.0, 2.0]
    f = lambda t: _helix(t / 2.0)  # noqa: E731
    c = approximate(f, 1e-7, domain=(0.0, 2.0), initial_knots=initial)
    assert _is_sub_multiset(initial, c.knots)
    assert c.domain == (0.0, 2.0)
    assert _dense_deviation(c, f, DEFAULT_SAMPLES_PER_SPAN) <= 1e-7


def test_approximate_reports_failure_when_the_knot_budget_is_exceeded():
    step = lambda t: np.stack([t, (t > 0.3).astype(float)], axis=1)  # noqa: E731
    with pytest.raises(GeometryError, match="did not reach the tolerance"):
        approximate(step, 1e-6, max_knots=60)


def test_approximate_refuses_bad_functions_and_arguments():
    with pytest.raises(GeometryError, match="not finite"), np.errstate(invalid="ignore", divide="ignore"):
        approximate(lambda t: np.stack([t, np.log(t - 0.5)], axis=1), 1e-3)
    with pytest.raises(GeometryError, match="shape"):
        approximate(lambda t: np.zeros((3, 2)), 1e-3)
    with pytest.raises(GeometryError, match="tolerance"):
        approximate(_helix, 0.0)
    with pytest.raises(GeometryError, match="outside the domain"):
        approximate(_helix, 1e-3, initial_knots=[0.5, 1.5])


def _random_smooth_curve(rng):
    """A random smooth space curve: a few random Fourier modes per coordinate."""
    k = rng.integers(1, 5, size=(3, 3))
    a = rng.normal(size=(3, 3)) / k
    phase = rng.uniform(0, 2 * np.pi, size=(3, 3))

    def f(t):
        t = np.asarray(t)[:, None, None]
        return np.sum(a * np.sin(2 * np.pi * k * t / 2 + phase), axis=2)

    return f


def test_twenty_curves_share_one_knot_vector_meeting_the_tolerance():
    rng = np.random.default_rng(40)
    funcs = [_random_smooth_curve(rng) for _ in range(20)]
    tol = 1e-5
    initial = [0.25, 0.5, 0.75]
    report = {}
    curves = approximate_common(funcs, tol, initial_knots=initial, report=report)
    U = curves[0].knots
    for c in curves:
        np.testing.assert_array_equal(c.knots, U)
    devs = [_dense_deviation(c, f, DEFAULT_SAMPLES_PER_SPAN) for c, f in zip(curves, funcs)]
    print(f"\n20 curves: common knot vector of {len(U)} knots ({report['n_control']} control points), "
          f"{report['rounds']} round(s); max dense deviation {max(devs):.3e} <= tolerance {tol:g}")
    assert max(devs) <= tol
    assert _is_sub_multiset(initial, U)


def test_approximate_common_seed_knots():
    """A seed that still meets the tolerance is used as it is (one fit, rounds 0); one
    that does not changes nothing: the result is the unseeded one, bit for bit."""
    from bladesmith.geometry.nurbs.fitting import approximate_common

    def curves(amplitude):
        return [lambda t, a=amplitude: np.stack([t, a * np.sin(3 * t), np.cos(2 * t)], axis=-1),
                lambda t, a=amplitude: np.stack([t, 0.2 + a * np.cos(3 * t), np.sin(t)], axis=-1)]

    report = {}
    first = approximate_common(curves(0.5), 1e-6, domain=(0.0, 2.0), report=report)
    assert report["rounds"] >= 1
    seed = first[0].knots
    # a small edit: the old knots still hold the tolerance
    rep = {}
    edited = approximate_common(curves(0.501), 1e-6, domain=(0.0, 2.0), report=rep, seed_knots=seed)
    assert rep["rounds"] == 0 and np.array_equal(edited[0].knots, seed)
    assert max(rep["max_deviation"]) <= 1e-6
    # a seed too coarse for the tolerance: the usual procedure, unchanged
    coarse = np.array([0, 0, 0, 0, 1.0, 2, 2, 2, 2])
    a = approximate_common(curves(0.5), 1e-6, domain=(0.0, 2.0), seed_knots=coarse)
    for x, y in zip(a, first):
        assert np.array_equal(x.knots, y.knots) and np.array_equal(x.control_points, y.control_points)
    # a seed that is not a clamped vector on the domain is ignored
    b = approximate_common(curves(0.5), 1e-6, domain=(0.0, 2.0), seed_knots=seed * 2)
    assert np.array_equal(b[0].control_points, first[0].control_points)


def test_interpolation_end_control_points_are_the_end_points_bit_for_bit():
    """Clamped interpolation: P_0 = Q_0 and P_n = Q_m as copies, with or without end
    derivatives, so curves and surfaces that end on a shared point share it exactly on
    every CPU (issue 14)."""
    rng = np.random.default_rng(1414)
    for trial in range(60):
        m = int(rng.integers(4, 30))
        Q = np.cumsum(rng.normal(size=(m, 3)), axis=0) * rng.uniform(1e-3, 1e3)
        t = np.sort(rng.uniform(-5, 5, m))
        if np.any(np.diff(t) <= 1e-9):
            continue
        for kw in ({}, {"end_derivative": rng.normal(size=3)}, {"start_derivative": rng.normal(size=3)},
                   {"start_derivative": rng.normal(size=3), "end_derivative": rng.normal(size=3)}):
            c = interpolate(Q, 3, params=t, **kw)
            assert np.array_equal(c.control_points[0], Q[0]), (trial, kw)
            assert np.array_equal(c.control_points[-1], Q[-1]), (trial, kw)


def test_basis_at_clamped_ends_and_full_multiplicity_knots_is_exactly_one():
    from bladesmith.geometry.nurbs.basis import basis_functions, basis_function_derivatives, find_span

    rng = np.random.default_rng(3)
    for trial in range(100):
        inner = np.sort(rng.uniform(0, 1, int(rng.integers(1, 12))))
        U = np.r_[[0.0] * 4, inner, inner[len(inner) // 2].repeat(2), [1.0] * 4]
        U = np.sort(U)
        u = np.array([0.0, 1.0])
        span = find_span(U, 3, u)
        for N in (basis_functions(U, 3, u, span), basis_function_derivatives(U, 3, u, span, 2)[:, 0]):
            assert np.array_equal(N[0], [1.0, 0, 0, 0]) and np.array_equal(N[1], [0, 0, 0, 1.0]), trial
