"""Review-image helpers without Blender (issue 21): sequential colours, zebra stripes,
scale bars, blade landmarks and span segments."""
import numpy as np
import pytest

from bladesmith.geometry.errors import GeometryError
from bladesmith.geometry.fairing.review_display import (
    blade_landmarks,
    length_label,
    nice_length,
    segment_count,
    sequential_colours,
    sign_convention,
    span_segments,
    upper_limit,
    zebra_values,
)
from bladesmith.geometry.sections.naca import naca4_thickness


def test_sequential_colours_darken_monotonically():
    rgb = sequential_colours(np.linspace(0, 1, 50), (0.0, 1.0))[:, :3]
    lightness = rgb @ [0.2126, 0.7152, 0.0722]
    assert np.all(np.diff(lightness) < 0)
    assert np.allclose(sequential_colours([-5.0, 9.0], (0.0, 1.0))[:, :3], rgb[[0, -1]])  # clipped
    with pytest.raises(GeometryError):
        sequential_colours([1.0], (1.0, 1.0))


def test_upper_limit_is_a_percentile_from_zero():
    v = np.concatenate([np.linspace(0, 1, 99), [1000.0]])
    lo, hi = upper_limit(v, 98.0)
    assert lo == 0.0 and 0.9 < hi <= 1.0


def test_zebra_values_ignore_the_normal_sign_and_stripe():
    th = np.linspace(-1.2, 1.2, 400)
    n = np.stack([np.sin(th), np.zeros_like(th), np.cos(th)], -1)  # normals turning about y
    z = zebra_values(n, np.array([0, 0, -1.0]), np.array([1.0, 0, 0]))
    assert np.allclose(z, zebra_values(-n, np.array([0, 0, -1.0]), np.array([1.0, 0, 0])))
    assert z.min() == 0.0 and z.max() == 1.0
    assert np.count_nonzero(np.diff(z > 0.5)) >= 6  # several stripes


def test_scale_bar_lengths():
    assert [nice_length(x) for x in (0.07, 0.3, 2.4, 12.0)] == [0.05, 0.2, 2.0, 10.0]
    assert length_label(0.02) == "20 mm" and length_label(5.0) == "5 m"


def test_sign_conventions_are_stated():
    assert "convex" in sign_convention("mean", True) and "concave" in sign_convention("mean", False)
    assert "never negative" in sign_convention("strain_energy")
    assert "outside" in sign_convention("deviation")


def blade(le_at_low_x: bool):
    """A straight extruded NACA 0012 blade, span along z, chord along x, 1 m chord."""
    x = 0.5 * (1 - np.cos(np.linspace(0, np.pi, 60)))
    y = 0.06 * naca4_thickness(x, True)
    if not le_at_low_x:
        x = 1.0 - x
    ring = np.concatenate([np.stack([x, y], 1), np.stack([x, -y], 1)])
    return np.concatenate([np.column_stack([ring, np.full(len(ring), z)]) for z in np.linspace(0, 5, 21)])


@pytest.mark.parametrize("le_at_low_x", [True, False])
def test_blade_landmarks_find_the_rounded_edge(le_at_low_x):
    P = blade(le_at_low_x)
    marks = blade_landmarks(P, np.array([0, 0, 1.0]), np.array([0, 1.0, 0]))
    assert marks["root"][2] == pytest.approx(0.0, abs=0.3) and marks["tip"][2] == pytest.approx(5.0, abs=0.3)
    assert (marks["LE"][0] < marks["TE"][0]) == le_at_low_x


def test_long_blades_are_cut_into_segments():
    assert segment_count(61.5, 4.7) == 4  # NREL 5-MW
    assert segment_count(0.15, 0.14) == 1  # a propeller blade
    P = np.column_stack([np.zeros(11), np.zeros(11), np.linspace(0, 10, 11)])
    segs = span_segments(P, np.array([0, 0, 1.0]), 4)
    assert len(segs) == 4 and segs[0][0] < 0 and segs[-1][1] > 10
    assert all(a < b for a, b in segs)
