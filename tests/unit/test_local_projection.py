"""Closest points from a parameter guess (geometry/nurbs/local_projection.py): the same
answer as the general search (projection.closest_point_curve), global even where the
guess points at the wrong stretch of the curve, for many curves in one pass."""

import numpy as np
import pytest

from bladesmith.geometry.nurbs import BSplineCurve, closest_point_curve, interpolate
from bladesmith.geometry.nurbs.local_projection import closest_point_curve_near, closest_points_near


def hairpin(count=60):
    """An open cubic that runs out along y = +0.01 and back along y = -0.01 (a sharp
    trailing edge seen from the side): its two legs are 0.02 apart for a length of 1."""
    s = np.linspace(0.0, 1.0, count)
    a = np.linspace(0.0, np.pi, 9)[1:-1]
    out = np.column_stack([s, 0.01 + 0.0 * s])
    turn = np.column_stack([1.0 + 0.01 * np.sin(a), 0.01 * np.cos(a)])
    back = np.column_stack([s[::-1], -0.01 + 0.0 * s])
    return interpolate(np.vstack([out, turn, back]), 3)


def wavy(seed, count=40, dim=2):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 1.0, count)
    P = np.column_stack([t, 0.1 * np.sin(6 * t)] + [0.05 * np.cos(4 * t)] * (dim - 2))
    return interpolate(P + 1e-3 * rng.standard_normal(P.shape), 3)


def test_equals_general_search_near_the_curve():
    for seed in range(4):
        c = wavy(seed)
        rng = np.random.default_rng(10 + seed)
        u = np.sort(rng.uniform(*c.domain, 300))
        normal = np.array([[0.0, -1.0], [1.0, 0.0]]) @ c.derivatives(u, 1)[:, 1].T
        P = c.evaluate(u) + (rng.uniform(-3e-3, 3e-3, u.size) * normal / np.linalg.norm(normal, axis=0)).T
        guess = np.clip(u + rng.uniform(-2e-3, 2e-3, u.size), *c.domain)
        stats = {}
        _, d = closest_point_curve_near(c, P, guess, stats=stats)
        _, ref = closest_point_curve(c, P)
        assert np.max(np.abs(d - ref)) <= 1e-14
        assert stats["fallback"] == 0  # the certificate holds for a gently curved curve


def test_a_guess_on_the_wrong_leg_still_finds_the_nearer_one():
    c = hairpin()
    u = np.linspace(0.02, 0.4, 50)  # on the outgoing leg (y = +0.01; it ends near u = 0.49)
    on_out = c.evaluate(u)
    assert np.allclose(on_out[:, 1], 0.01, atol=1e-4)
    # points between the legs, nearer the return leg (y = -0.01), guessed on the outgoing one
    P = on_out - np.array([0.0, 0.016])
    _, d = closest_point_curve_near(c, P, u)
    _, ref = closest_point_curve(c, P)
    assert np.allclose(ref, 0.004, atol=2e-4)  # the true feet are on the return leg
    assert np.max(np.abs(d - ref)) <= 1e-14


def test_many_curves_in_one_pass_with_their_own_knots():
    curves = [wavy(s, count=20 + 7 * s, dim=3) for s in range(5)]
    rng = np.random.default_rng(3)
    P, guess, which = [], [], []
    for k, c in enumerate(curves):
        u = rng.uniform(*c.domain, 40)
        P.append(c.evaluate(u) + rng.uniform(-1e-3, 1e-3, (u.size, 3)))
        guess.append(u)
        which.append(np.full(u.size, k))
    _, d = closest_points_near(curves, np.concatenate(P), np.concatenate(guess), np.concatenate(which))
    ref = np.concatenate([closest_point_curve(c, p)[1] for c, p in zip(curves, P)])
    assert np.max(np.abs(d - ref)) <= 1e-14


def test_rational_curves_go_to_the_general_search():
    w = np.array([1.0, 0.5, 2.0, 0.7, 1.0])
    c = BSplineCurve(3, np.array([0, 0, 0, 0, 0.5, 1, 1, 1, 1.0]),
                     np.array([[0, 0], [1, 1], [2, -1], [3, 1], [4, 0.0]]), w)
    u = np.linspace(0.0, 1.0, 30)
    P = c.evaluate(u) + 0.01
    stats = {}
    _, d = closest_point_curve_near(c, P, u, stats=stats)
    assert stats["fallback"] == u.size
    assert np.array_equal(d, closest_point_curve(c, P)[1])


def test_bad_guess_count_is_refused():
    c = wavy(0)
    with pytest.raises(ValueError):
        closest_point_curve_near(c, c.evaluate(np.array([0.1, 0.2])), np.array([0.1]))


def test_two_minima_in_one_window_give_the_nearer():
    # a W: two dips within the three spans around the guess; the point below the hump is
    # nearer the right dip, the guess sits on the left one
    c = interpolate(np.array([[0.0, 0.0], [0.5, -1.0], [1.0, 0.5], [1.5, -1.1], [2.0, 0.0]]), 3)
    P = np.array([[1.0, -2.0]])
    u_left = closest_point_curve(c, np.array([[0.5, -1.5]]))[0]
    _, d = closest_point_curve_near(c, P, u_left)
    _, ref = closest_point_curve(c, P)
    assert ref[0] < 1.1  # the right dip
    assert np.max(np.abs(d - ref)) <= 1e-14
