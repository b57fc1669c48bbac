"""Hvid (1993) §3.2.1 and §3.4: smoothfoil on fx66-s-196 with the paper's jobcard
(nsmooth 180, np 150, ntrial 10, tolx 1e-10, tolf 1e-9, iorder 2, smttype 2, four ad hoc
passes, distribution .5 .5 .491 .1). Our figures beside the paper's:

                                   paper (§3.4)     ours (UIUC fx66s196.dat)
  TE segments (np = 150)           .006977/.006978  .006864/.006977
  max ratio between panels         1.1420           1.1410
  curvature before, min / max      -10.69 / 111.93  -35.87 / 110.91
  curvature after,  min / max      -2.83 / 109.37   -4.27 / 110.81 (knots, after chord rescale)
  iterations (+ final tolx line)   5 (+1)           5 (+1)
  max deviation / chord            ~3.0e-4          2.13e-3 (true distance, both ways)

The paper's table (Appendix, partly printed) is not the UIUC file: printed points differ by
up to 1.2e-3 c (e.g. upper y at x = .40245: .13691 vs .13567), and the UIUC lower surface
has a hook at the trailing edge (y = +.00026 at x = .99039, -.00038 at .99893, 0 at 1)
that the paper's table does not (.00066, .00005, 0). The hook gives the -35.9 minimum and
most of the deviation; with that one point removed the figures become -11.31 / 112.48 ->
-4.27 / 112.38 and 7.8e-4 c (the next test). The rest of the gap is the leading-edge
curvature of the UIUC data, noisier than the paper's: its 3-point smoothing changes the
turning around the nose by 0.09 rad, which the pinned trailing edge turns into a
~8.6e-4 c chord change (rescaled, §3.2). The paper's data are not available to close it.
"""
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.fairing import PolynomialDistribution, SmoothingSettings, curve_sign_changes, smoothfoil
from bladesmith.geometry.sections.airfoil_file import Airfoil, read_airfoil

FX66 = pathlib.Path(__file__).resolve().parents[3] / "shared" / "data" / "airfoils" / "fx66s196.dat"
JOBCARD = SmoothingSettings(
    smoothing_points=180, output_points=150, max_iterations=10, tolx=1e-10, tolf=1e-9,
    smoothing_type=2, smoother="ad_hoc", passes=4, end_derivative_order=2,
)
DISTRIBUTION = PolynomialDistribution(0.5, 0.5, 0.491, 0.1)

PAPER = {"te": (0.006977224, 0.006978219), "ratio": 1.141965713, "kmin": (-10.693326, -2.830055),
         "kmax": (111.926973, 109.367063), "iterations": 5, "deviation": 3.0e-4}


@pytest.fixture(scope="module")
def fx66():
    return read_airfoil(FX66)


@pytest.fixture(scope="module")
def result(fx66):
    return smoothfoil(fx66, DISTRIBUTION, JOBCARD)


def test_distribution_report(result):
    rep = result.distribution
    assert rep.first_segment == pytest.approx(PAPER["te"][0], rel=0.02)
    assert rep.last_segment == pytest.approx(PAPER["te"][1], rel=0.02)
    assert rep.max_ratio == pytest.approx(PAPER["ratio"], rel=0.002)


def test_convergence_like_the_paper(result):
    assert result.converged
    # the paper prints 5 iterations and then "tolx criteria!" on the 6th evaluation
    assert len(result.history) == PAPER["iterations"] + 1
    residuals = [f for f, _ in result.history]
    assert all(b < a for a, b in zip(residuals, residuals[1:]))
    assert residuals[-1] < JOBCARD.tolf or result.history[-1][1] == 0.0


def test_leading_edge_maximum_kept_and_minimum_raised(result):
    before, after = result.kappa_before, result.kappa_after
    # type 2 keeps the LE value at its knot; only the §3.2 chord rescaling changes it
    assert after.max() == pytest.approx(before.max() / result.chord_scale, rel=1e-9)
    assert after.max() == pytest.approx(PAPER["kmax"][0], rel=0.02)
    assert before.min() < -30 and after.min() > -5  # paper: -10.7 -> -2.8 (see module docstring)
    assert curve_sign_changes(result.curve) < curve_sign_changes(result.unsmoothed)


def test_deviation_small_fraction_of_chord(result):
    assert result.deviation.true < 2.5e-3  # paper ~3e-4 on its own table (module docstring)
    assert result.deviation.true <= result.deviation.same_parameter * 1.01


def test_without_the_trailing_edge_hook(fx66):
    fixed = Airfoil(fx66.name, fx66.upper, np.delete(fx66.lower, -2, axis=0), fx66.format)
    r = smoothfoil(fixed, DISTRIBUTION, JOBCARD)
    assert r.kappa_before.min() == pytest.approx(PAPER["kmin"][0], abs=1.0)
    assert r.kappa_before.max() == pytest.approx(PAPER["kmax"][0], rel=0.01)
    assert r.kappa_after.min() > -5
    assert r.deviation.true < 1e-3
    assert len(r.history) == PAPER["iterations"] + 1
