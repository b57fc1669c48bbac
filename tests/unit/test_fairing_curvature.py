"""Curvature utilities (Hvid 1993 Eq. 2.10, §3.1.1)."""
import numpy as np
import pytest

from bladesmith.geometry.errors import GeometryError
from bladesmith.geometry.fairing import (
    arclength,
    count_sign_changes,
    curvature_at,
    curvature_comb,
    curvature_plot,
    curve_sign_changes,
    curve_total_variation,
    params_at_arclength,
    total_variation,
)
from bladesmith.geometry.fairing.hvid import spline_through
from bladesmith.geometry.nurbs import BSplineCurve, interpolate


def circle(radius=2.0, count=200, turn=np.pi):
    t = np.linspace(0.0, turn, count)
    return spline_through(radius * np.stack([np.cos(t), np.sin(t)], axis=1), 3)[0]


def test_circle_curvature_sign_and_value():
    c = circle()
    u = np.linspace(0.1, 0.9, 50)
    assert np.allclose(curvature_at(c, u), 0.5, atol=1e-5)  # anticlockwise: positive
    reversed_ = c.with_control_points(c.control_points * [1.0, -1.0])
    assert np.allclose(curvature_at(reversed_, u), -0.5, atol=1e-5)


def test_curvature_matches_core_evaluator():
    rng = np.random.default_rng(0)
    c = interpolate(rng.normal(size=(12, 2)), 3)
    u = np.linspace(*c.domain, 77)
    assert np.allclose(curvature_at(c, u), c.curvature(u), rtol=1e-10, atol=1e-10)


def test_arclength_and_inverse():
    c = circle(radius=2.0)
    assert arclength(c) == pytest.approx(2.0 * np.pi, rel=1e-7)
    f = np.linspace(0, 1, 11)
    pts = c.evaluate(params_at_arclength(c, f))
    angles = np.arctan2(pts[:, 1], pts[:, 0])
    assert np.allclose(angles, np.pi * f, atol=1e-6)


def test_curvature_plot_axes():
    s, k = curvature_plot(circle())
    assert s[0] == 0 and s[-1] == pytest.approx(1.0) and np.all(np.diff(s) > 0)
    assert np.allclose(k, 0.5, atol=5e-4)  # end-tangent finite differences disturb the ends slightly


def test_sign_changes_and_total_variation():
    assert count_sign_changes([1, 2, -1, -2, 3]) == 2
    assert count_sign_changes([1.0, 1e-12, 1.0]) == 0  # touching zero is not a crossing
    assert total_variation([0, 1, 0, 2]) == 4
    x = np.linspace(0, 1, 60)
    wave = spline_through(np.stack([x, 0.05 * np.sin(2 * np.pi * x)], axis=1), 3)[0]
    assert curve_sign_changes(wave) == 1
    assert curve_total_variation(circle()) < 0.02  # finite-difference end tangents: tiny end ripples


def test_comb_points_outward_on_convex_curve():
    c = circle(radius=1.0)
    base, tip = curvature_comb(c, scale=0.5)
    assert np.allclose(np.linalg.norm(tip, axis=1), 1.5, atol=1e-3)
    assert np.allclose(np.linalg.norm(base, axis=1), 1.0, atol=1e-6)


def test_refuses_3d_curve():
    c = BSplineCurve(1, [0, 0, 1, 1], [[0, 0, 0], [1, 1, 1]])
    with pytest.raises(GeometryError, match="2-D"):
        curvature_plot(c)
