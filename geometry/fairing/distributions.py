"""Point distributions along a curve for the Hvid smoother (Hvid 1993, §3.2 "Conditioning
the algorithm" and §3.3 "User input").

A distribution maps the index parameter t = i/(N−1) of the i-th of N points to a fraction
f(t) of the total arc length (Hvid's u, normalised arc length, u ∈ [0, 1]).

- smooth2D (:func:`curvature_fractions`): f is the integrated and normalised curvature
  (§3.3, footnote 2), damped by α: more points where the curve bends, uniform as α → ∞.
- smoothfoil (:class:`PolynomialDistribution`): the 7th-order polynomial with
  f(0) = 0, f(1) = 1, f''(0) = f''(1) = 0 and the user's f'(0), f'(1), f(½), f'(½)
  (§3.3, Fig. 3.9). It must be monotone (§3.3: "must be monotone"); a non-monotone choice
  is refused with :class:`~bladesmith.geometry.errors.DefinitionError`.

:func:`distribution_report` gives the numbers Hvid prints for each choice (§3.3, §3.4):
the largest ratio between adjacent segments and the lengths of the two trailing-edge
(end) segments.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DefinitionError, GeometryError
from ..nurbs import BSplineCurve
from .curvature import arclength_table

#: f'(t) must exceed this everywhere on [0, 1] for the polynomial to count as monotone
#: (a zero slope would put two points on top of each other).
MIN_DISTRIBUTION_SLOPE = 1e-9

#: Samples per knot span of the curvature integrated by :func:`curvature_fractions`.
CURVATURE_SAMPLES_PER_SPAN = 16

#: Relative floor of the curvature weight, so a straight curve with α = 0 still gets a
#: (uniform) distribution instead of a division by zero.
CURVATURE_WEIGHT_FLOOR = 1e-12


@dataclass(frozen=True)
class PolynomialDistribution:
    """Hvid (1993) §3.3 airfoil distribution: f(t) = Σ_{k=0}^{7} a_k t^k.

    end0, end1: f'(0) and f'(1) (Hvid's "end0", "end1": trailing-edge spacing).
    centre, centre_slope: f(½) and f'(½) (Hvid's "cen", "cengrad": where the leading edge
    sits in arc length and how dense points are there).
    Fixed: f(0) = 0, f(1) = 1, f''(0) = f''(1) = 0.
    The paper's fx66-s-196 session (§3.4) uses 0.5, 0.5, 0.491, 0.1.
    """

    end0: float = 0.5
    end1: float = 0.5
    centre: float = 0.5
    centre_slope: float = 0.1

    def __post_init__(self):
        for field in ("end0", "end1", "centre", "centre_slope"):
            value = getattr(self, field)
            if not np.isfinite(value):
                raise DefinitionError(f"distribution value is not finite: {value!r}", field=field)
        coefficients = self.coefficients
        slope = np.polynomial.Polynomial(coefficients).deriv()
        candidates = np.concatenate([[0.0, 1.0], _real_roots_in_unit(slope.deriv())])
        values = slope(candidates)
        k = int(np.argmin(values))
        if values[k] <= MIN_DISTRIBUTION_SLOPE:
            raise DefinitionError(
                f"f'(0)={self.end0:g}, f'(1)={self.end1:g}, f(1/2)={self.centre:g}, f'(1/2)={self.centre_slope:g} "
                f"give a non-monotone distribution: f'({candidates[k]:.4f}) = {values[k]:.4g} "
                f"(must be > {MIN_DISTRIBUTION_SLOPE:g} on [0, 1]; Hvid 1993 §3.3)",
                field="distribution",
            )

    @property
    def coefficients(self) -> np.ndarray:
        """a_0..a_7 from the eight conditions (a dense 8×8 solve, once)."""
        h = 0.5
        k = np.arange(8)
        rows = [
            (k == 0).astype(float),  # f(0)
            (k == 1).astype(float),  # f'(0)
            2.0 * (k == 2),  # f''(0)
            np.ones(8),  # f(1)
            k.astype(float),  # f'(1)
            k * (k - 1.0),  # f''(1)
            h**k,  # f(1/2)
            k * h ** np.maximum(k - 1, 0),  # f'(1/2)
        ]
        rhs = [0.0, self.end0, 0.0, 1.0, self.end1, 0.0, self.centre, self.centre_slope]
        return np.linalg.solve(np.array(rows), np.array(rhs))

    def __call__(self, t) -> np.ndarray:
        return np.polynomial.polynomial.polyval(np.asarray(t, dtype=np.float64), self.coefficients)

    def derivative(self, t) -> np.ndarray:
        return np.polynomial.Polynomial(self.coefficients).deriv()(np.asarray(t, dtype=np.float64))

    def fractions(self, count: int) -> np.ndarray:
        """f(i/(count−1)), i = 0..count−1: arc-length fractions of ``count`` points."""
        f = self(np.linspace(0.0, 1.0, _count(count)))
        f[0], f[-1] = 0.0, 1.0
        return f


def _real_roots_in_unit(poly: np.polynomial.Polynomial) -> np.ndarray:
    r = poly.roots()
    r = r.real[np.abs(r.imag) <= 1e-12]
    return r[(r >= 0.0) & (r <= 1.0)]


def _count(count: int) -> int:
    count = int(count)
    if count < 4:
        raise DefinitionError(f"need at least 4 points, got {count}", field="count")
    return count


def curvature_fractions(curve: BSplineCurve, count: int, alpha: float) -> np.ndarray:
    """Hvid (1993) §3.3 smooth2D distribution: arc-length fractions of ``count`` points
    spaced evenly in F(s) = ∫_0^s (|κ| + α κ̄) ds / ∫_0^L (|κ| + α κ̄) ds.

    κ̄ = (1/L)∫|κ| ds is the mean absolute curvature, so α is dimensionless: α = 0 is the
    purely curvature-weighted distribution ("integrated and normalized curvature",
    footnote 2), α = 1 gives equal shares to curvature and arc length, and α → ∞ a
    uniform distribution (§3.3: large α more uniform). Point density is ∝ |κ| + α κ̄.
    """
    if not np.isfinite(alpha) or alpha < 0:
        raise DefinitionError(f"alpha must be >= 0 (Hvid 1993 §3.3), got {alpha!r}", field="alpha")
    count = _count(count)
    t, s = arclength_table(curve, CURVATURE_SAMPLES_PER_SPAN)
    kappa = np.abs(curve.curvature(t))
    length = s[-1]
    ds = np.diff(s)
    mean = float(np.sum(0.5 * (kappa[1:] + kappa[:-1]) * ds)) / length
    weight = kappa + alpha * mean + CURVATURE_WEIGHT_FLOOR * max(mean, 1.0 / length)
    F = np.concatenate([[0.0], np.cumsum(0.5 * (weight[1:] + weight[:-1]) * ds)])
    F /= F[-1]
    fractions = np.interp(np.linspace(0.0, 1.0, count), F, s / length)
    fractions[0], fractions[-1] = 0.0, 1.0
    return fractions


@dataclass(frozen=True)
class DistributionReport:
    """What Hvid (1993) §3.3/§3.4 prints for a distribution choice.

    max_ratio: largest ratio between the lengths of two adjacent segments (≥ 1).
    first_segment, last_segment: lengths of the two end (trailing-edge) segments, in the
    units of the points (fractions of chord for a unit-chord airfoil).
    """

    max_ratio: float
    first_segment: float
    last_segment: float
    count: int

    def lines(self) -> list[str]:
        return [
            f"Trailing edge: length of first segment: {self.first_segment:.9f}",
            f"               length of last segment : {self.last_segment:.9f}",
            f"Max. ratio between panels: {self.max_ratio:.9f}",
        ]


def distribution_report(points) -> DistributionReport:
    """:class:`DistributionReport` of a polyline (N, dim) of distributed points."""
    P = np.asarray(points, dtype=np.float64)
    seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
    if np.any(seg <= 0):
        raise GeometryError(f"distributed points {int(np.flatnonzero(seg <= 0)[0])} and the next coincide")
    ratio = seg[1:] / seg[:-1]
    return DistributionReport(
        max_ratio=float(np.max(np.maximum(ratio, 1.0 / ratio))),
        first_segment=float(seg[0]),
        last_segment=float(seg[-1]),
        count=int(P.shape[0]),
    )


__all__ = [
    "DistributionReport",
    "PolynomialDistribution",
    "curvature_fractions",
    "distribution_report",
]
