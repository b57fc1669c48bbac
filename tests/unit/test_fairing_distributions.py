"""Distributions of Hvid (1993) §3.2–3.3."""
import numpy as np
import pytest

from bladesmith.geometry.errors import DefinitionError
from bladesmith.geometry.fairing import PolynomialDistribution, curvature_fractions, distribution_report
from bladesmith.geometry.fairing.hvid import spline_through
from bladesmith.geometry.sections.airfoil_file import read_airfoil

FX66 = __import__("pathlib").Path(__file__).resolve().parents[3] / "shared" / "data" / "airfoils" / "fx66s196.dat"


@pytest.fixture(scope="module")
def fx66():
    return read_airfoil(FX66)


@pytest.mark.parametrize("args", [(0.5, 0.5, 0.491, 0.1), (0.15, 0.15, 0.25, 0.5), (1.0, 2.0, 0.4, 0.3)])
def test_polynomial_conditions(args):
    f = PolynomialDistribution(*args)
    e0, e1, c, cg = args
    second = np.polynomial.Polynomial(f.coefficients).deriv(2)
    assert f(0.0) == pytest.approx(0.0, abs=1e-14) and f(1.0) == pytest.approx(1.0)
    assert f.derivative(0.0) == pytest.approx(e0) and f.derivative(1.0) == pytest.approx(e1)
    assert f(0.5) == pytest.approx(c) and f.derivative(0.5) == pytest.approx(cg)
    assert second(0.0) == pytest.approx(0.0, abs=1e-12) and second(1.0) == pytest.approx(0.0, abs=1e-10)
    fr = f.fractions(101)
    assert np.all(np.diff(fr) > 0)


def test_non_monotone_refused_with_values():
    with pytest.raises(DefinitionError, match="non-monotone") as info:
        PolynomialDistribution(0.5, 0.5, 0.9, 0.1)
    assert "f(1/2)=0.9" in str(info.value) and "distribution" in str(info.value)


def test_report_of_paper_choice_on_fx66(fx66):
    """§3.4 prints TE segments .006977/.006978 and max ratio 1.142 for np = 150 (paper's table)."""
    from bladesmith.geometry.fairing.curvature import params_at_arclength

    pts = np.concatenate([fx66.lower[::-1], fx66.upper[1:]])
    c, _ = spline_through(pts, 2)
    f = PolynomialDistribution(0.5, 0.5, 0.491, 0.1)
    rep = distribution_report(c.evaluate(params_at_arclength(c, f.fractions(150))))
    assert rep.first_segment == pytest.approx(0.006977, rel=0.03)
    assert rep.last_segment == pytest.approx(0.006978, rel=0.03)
    assert rep.max_ratio == pytest.approx(1.142, rel=0.01)


def test_curvature_fractions_alpha():
    t = np.linspace(0, np.pi / 2, 80)
    c, _ = spline_through(np.stack([2 * np.cos(t), np.sin(t)], axis=1), 3)
    dense = np.diff(curvature_fractions(c, 50, 0.0))
    uniform = np.diff(curvature_fractions(c, 50, 1e6))
    assert np.ptp(uniform) < 1e-4  # α → ∞: uniform in arc length
    assert dense[0] < dense[-1]  # more points where κ is large (κ = 2 at the start, 0.25 at the end)
    with pytest.raises(DefinitionError, match="alpha"):
        curvature_fractions(c, 50, -1.0)
