"""The concave streak on DTMB 4119's pressure side (issue 15) is in the table.

The review image shows a concave (blue) streak running along the pressure side near the
trailing edge and up to the tip. It comes from the sections themselves: the NACA a=0.8
mean line's second derivative has a logarithmic singularity at x/c = a = 0.8 (Abbott & von
Doenhoff, Theory of Wing Sections, §4.3: the load falls linearly from x = a to the
trailing edge), so there the camber's curvature beats the thickness form's convexity and
the lower (pressure) side of every section turns concave in a band round x/c = 0.8. The
band widens toward the tip where t/c falls faster than f/c, and the 0.8-chord line of the
blade runs into the tip point: the streak. It is therefore kept, not smoothed away.
"""
import pathlib
import tomllib

import numpy as np
import pytest

from bladesmith.geometry.sections import SectionShape

DTMB = pathlib.Path(__file__).resolve().parents[2] / "data" / "propellers" / "dtmb4119.toml"


def _lower_side_curvature(shape: SectionShape, t_c: float, f_c: float):
    """(x, curvature × c) along the lower side of the unit-chord section, positive where
    the outline is convex (bulging away from the section), from a dense outline."""
    P = shape.outline(8001, t_c, f_c)
    x, y = P[:, 0], P[:, 1]
    dx, dy = np.gradient(x), np.gradient(y)
    k = (dx * np.gradient(dy) - dy * np.gradient(dx)) / (dx ** 2 + dy ** 2) ** 1.5
    k *= np.sign(np.median(k))  # the outline is convex over most of its length
    camber = shape.camber(np.clip(x, 0.0, 1.0)) * f_c if f_c else 0.0 * x
    lower = (y < camber) & (x > 0.1) & (x < 0.97)
    return x[lower], k[lower]


def _stations():
    radial = tomllib.loads(DTMB.read_text())["radial"]
    return [(r, t, f) for r, t, f in zip(radial["r_R"], radial["t_c"], radial["f_c"]) if 0.5 <= r < 1.0]


@pytest.mark.parametrize("r_R,t_c,f_c", _stations())
def test_pressure_side_is_concave_round_the_a08_load_break(r_R, t_c, f_c):
    shape = SectionShape.from_spec("naca66mod", "a=0.8")
    x, k = _lower_side_curvature(shape, t_c, f_c)
    assert k.min() < 0.0, f"r/R {r_R}: the pressure side is convex everywhere"
    assert abs(x[np.argmin(k)] - 0.8) < 0.01, f"r/R {r_R}: most concave at x/c {x[np.argmin(k)]:.3f}, not 0.8"
    concave = x[k < 0.0]
    assert concave.min() < 0.78 and concave.max() > 0.82


def _dip_at_08(x, k) -> float:
    """How much more concave the lower side is at x/c = 0.8 than 0.05 chord either side
    (× c; positive for a local dip)."""
    at = lambda v: float(np.interp(v, *zip(*sorted(zip(x, k)))))
    return min(at(0.75), at(0.85)) - at(0.8)


@pytest.mark.parametrize("r_R,t_c,f_c", _stations())
def test_the_dip_at_08_is_the_a08_mean_lines(r_R, t_c, f_c):
    """The a=0.8 sections dip sharply at x/c = 0.8; the same thicknesses and cambers with a
    parabolic mean line (no load break) have no dip there: the band is the mean line's."""
    x, k = _lower_side_curvature(SectionShape.from_spec("naca66mod", "a=0.8"), t_c, f_c)
    xp, kp = _lower_side_curvature(SectionShape.from_spec("naca66mod", "parabolic"), t_c, f_c)
    assert _dip_at_08(x, k) > 0.1
    assert _dip_at_08(xp, kp) < 0.01
