"""Bézier toolkit of Casey (1983): Bernstein curves, Eq. 9, elevation, Fig. 3a, Eq. 10."""
import numpy as np
import pytest

from bladesmith.geometry.compressor.bezier import (
    BezierCurve, BezierString, PatchString, RuledPatch, bernstein, third_point_for_end_curvature,
)
from bladesmith.geometry.errors import GeometryError

RNG = np.random.default_rng(8)
TOL = 1e-12


@pytest.mark.parametrize("n", [1, 2, 3, 5, 9])
def test_partition_of_unity_and_ends(n):
    u = RNG.random(50)
    assert np.allclose(bernstein(n, u).sum(axis=-1), 1.0, atol=TOL)
    c = BezierCurve(RNG.random((n + 1, 3)))
    assert np.allclose(c.evaluate(0.0), c.control_points[0]) and np.allclose(c.evaluate(1.0), c.control_points[-1])


def test_cubic_matches_eq6():
    P = RNG.random((4, 2))
    u = RNG.random(20)[:, None]
    R = (1 - u) ** 3 * P[0] + 3 * u * (1 - u) ** 2 * P[1] + 3 * u**2 * (1 - u) * P[2] + u**3 * P[3]
    assert np.allclose(BezierCurve(P).evaluate(u[:, 0]), R, atol=TOL)


@pytest.mark.parametrize("n", [2, 4, 7])
def test_derivatives_eq9_against_bspline(n):
    c = BezierCurve(RNG.random((n + 1, 3)))
    u = RNG.random(30)
    ours = c.derivatives(u, 3)
    theirs = c.to_bspline().derivatives(u, 3)
    assert np.allclose(np.moveaxis(ours, 0, 1), theirs, atol=1e-10)
    # finite difference check of the first derivative
    h = 1e-6
    fd = (c.evaluate(u + h) - c.evaluate(u - h)) / (2 * h)
    assert np.allclose(ours[1], fd, atol=1e-6)


def test_elevation_keeps_shape():
    c = BezierCurve(RNG.random((4, 3)))
    e = c.elevate(3)
    u = np.linspace(0, 1, 41)
    assert e.degree == 6 and np.max(np.abs(e.evaluate(u) - c.evaluate(u))) < TOL


def test_end_curvature_construction_fig3a():
    for n in (3, 4, 6):
        p0, p1 = np.array([0.0, 0.0]), np.array([0.3, 0.1])
        for kappa in (0.0, 0.7, 5.0):
            p2 = third_point_for_end_curvature(p0, p1, [0.0, 1.0], kappa, n, along=0.4)
            rest = RNG.random((n - 2, 2)) + 1.0
            c = BezierCurve(np.vstack([p0, p1, p2, rest]))
            assert abs(c.curvature(0.0) - kappa) < 1e-10
            assert abs(c.end_curvature(0) - kappa) < 1e-10


def test_split_and_string_to_bspline():
    c = BezierCurve(RNG.random((5, 2)))
    a, b = c.split(0.5)
    s = BezierString((a, b))
    bs = s.to_bspline()
    U = np.linspace(0, 2, 51)
    assert np.allclose(bs.evaluate(U), s.evaluate(U), atol=TOL)
    assert np.allclose(s.evaluate(np.linspace(0, 1, 11)), c.evaluate(np.linspace(0, 0.5, 11)), atol=TOL)
    assert np.max(s.junction_jumps(3)) < 1e-10  # halves of one polynomial: C-infinity


def test_strings_must_meet():
    with pytest.raises(GeometryError):
        BezierString((BezierCurve([[0, 0], [1, 0]]), BezierCurve([[2, 0], [3, 0]])))


def test_ruled_patch_eq10_and_bspline():
    lo, up = BezierCurve(RNG.random((4, 3))), BezierCurve(RNG.random((3, 3)))
    p = RuledPatch(lo, up)
    u, v = RNG.random(25), RNG.random(25)
    ref = (1 - v)[:, None] * lo.evaluate(u) + v[:, None] * up.evaluate(u)
    assert np.allclose(p.evaluate(u, v), ref, atol=TOL)
    assert np.allclose(p.to_bspline().evaluate(u, v), ref, atol=TOL)
    ps = PatchString.from_patches([p, RuledPatch(BezierCurve(np.vstack([lo.control_points[-1], RNG.random((3, 3))])),
                                                 BezierCurve(np.vstack([p.upper.control_points[-1], RNG.random((3, 3))])))])
    U, V = RNG.random(30) * 2, RNG.random(30) * 1.4 - 0.2
    assert np.allclose(ps.to_bspline().evaluate(U, np.clip(V, 0, 1)), ps.evaluate(U, np.clip(V, 0, 1)), atol=TOL)
    ext = ps.extended(-0.2, 1.2)
    assert np.allclose(ext.evaluate(U, (V + 0.2) / 1.4), ps.evaluate(U, V), atol=TOL)
