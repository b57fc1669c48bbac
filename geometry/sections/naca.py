"""Analytic section families on the unit chord (x/c from the leading edge, 0 <= x <= 1).

- NACA a-series mean line (Abbott & von Doenhoff 1959, §4.3; formula as given in MIT
  OpenProp ``GeometryFoil2D.m``), for a = 0.8 the "NACA a=0.8" mean line.
- NACA 4-digit thickness (Abbott & von Doenhoff 1959, §6.4, Eq. 6.2) and the 4-digit
  two-parabola mean line; a parabolic-arc mean line; an elliptic thickness form.

All return plain float64 arrays of the shape of ``x``.
"""
from __future__ import annotations

import numpy as np

#: NACA 4-digit half-thickness coefficients (open trailing edge, Abbott & von Doenhoff Eq. 6.2).
NACA4_COEFFICIENTS = (0.2969, -0.1260, -0.3516, 0.2843, -0.1015)


def _xlogx(x: np.ndarray) -> np.ndarray:
    """x ln|x| with its limit 0 at x = 0."""
    x = np.asarray(x, dtype=np.float64)
    ax = np.abs(x)
    out = np.zeros_like(x)
    nz = ax > 0
    out[nz] = x[nz] * np.log(ax[nz])
    return out


def _x2logx(x: np.ndarray) -> np.ndarray:
    """x^2 ln|x| with its limit 0 at x = 0."""
    return np.asarray(x, dtype=np.float64) * _xlogx(x)


def a_series_meanline(x, a: float = 0.8, cli: float = 1.0) -> np.ndarray:
    """Ordinate f/c of the NACA a-series mean line for design lift coefficient ``cli``
    (without the ideal-angle rotation): Abbott & von Doenhoff (1959) §4.3."""
    x = np.asarray(x, dtype=np.float64)
    if not 0.0 < a < 1.0:
        raise ValueError(f"a-series mean line: a must lie in (0, 1), got {a}")
    b = 1.0 - a
    g = -(a * a * (np.log(a) / 2.0 - 0.25) + 0.25) / b
    h = (b * b * np.log(b) / 2.0 - b * b / 4.0) / b + g
    one_minus = 1.0 - x
    bracket = (
        (_x2logx(a - x) / 2.0 - _x2logx(one_minus) / 2.0 + (one_minus**2 - (a - x) ** 2) / 4.0) / b
        - _xlogx(x)
        + g
        - h * x
    )
    return cli / (2.0 * np.pi * (a + 1.0)) * bracket


def naca4_thickness(x, closed_trailing_edge: bool = False) -> np.ndarray:
    """Thickness T(x)/T0 of the NACA 4-digit family normalised to maximum 1 at x = 0.3
    (full thickness, both sides). Abbott & von Doenhoff (1959) Eq. 6.2 with the last
    coefficient -0.1036 when ``closed_trailing_edge``."""
    x = np.clip(np.asarray(x, dtype=np.float64), 0.0, 1.0)
    a0, a1, a2, a3, a4 = NACA4_COEFFICIENTS
    if closed_trailing_edge:
        a4 = -0.1036
    # 5 t (...) is the half thickness for thickness ratio t: full thickness is 10 t (...);
    # at x = 0.3 the bracket is 0.1 (to 4 digits), so T/T0 = 10 * bracket.
    return 10.0 * (a0 * np.sqrt(x) + x * (a1 + x * (a2 + x * (a3 + x * a4))))


def naca4_meanline(x, position: float = 0.4) -> np.ndarray:
    """NACA 4-digit mean line normalised to maximum camber 1 at x = ``position``
    (two parabolas meeting with zero slope; Abbott & von Doenhoff §6.4)."""
    x = np.asarray(x, dtype=np.float64)
    p = float(position)
    return np.where(x <= p, (2.0 * p * x - x * x) / (p * p), ((1.0 - 2.0 * p) + 2.0 * p * x - x * x) / (1.0 - p) ** 2)


def parabolic_meanline(x) -> np.ndarray:
    """Parabolic-arc mean line 4x(1 - x): maximum 1 at mid-chord."""
    x = np.asarray(x, dtype=np.float64)
    return 4.0 * x * (1.0 - x)


def elliptic_thickness(x) -> np.ndarray:
    """Elliptic thickness form 2 sqrt(x(1 - x)): maximum 1 at mid-chord, round at both edges."""
    x = np.clip(np.asarray(x, dtype=np.float64), 0.0, 1.0)
    return 2.0 * np.sqrt(x * (1.0 - x))
