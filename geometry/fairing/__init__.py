"""Curvature of curves and Hvid smoothing (Hvid 1993, DTU AFM 93-08).

``curvature``: curvature at parameters, curvature plots against normalised arc length,
sign changes and total variation of curvature, curvature combs.
``distributions``: the point distributions of Hvid §3.2–3.3 (curvature-weighted with
damping α; the 7th-order airfoil polynomial) and their report.
``hvid``: smooth2D and smoothfoil (§3.2–3.4), the section pre-processing hook
:func:`smooth_airfoil_points`, and full-precision output of the np points.
"""
from .curvature import (
    arclength,
    arclength_table,
    count_sign_changes,
    curvature_at,
    curvature_comb,
    curvature_plot,
    curve_sign_changes,
    curve_total_variation,
    params_at_arclength,
    total_variation,
)
from .distributions import DistributionReport, PolynomialDistribution, curvature_fractions, distribution_report
from .hvid import (
    SmoothingNotConverged,
    SmoothingResult,
    SmoothingSettings,
    smooth2d,
    smooth_airfoil_points,
    smooth_airfoil_result,
    smooth_curvature,
    smoothfoil,
    write_points,
)

__all__ = [
    "DistributionReport",
    "PolynomialDistribution",
    "SmoothingNotConverged",
    "SmoothingResult",
    "SmoothingSettings",
    "arclength",
    "arclength_table",
    "count_sign_changes",
    "curvature_at",
    "curvature_comb",
    "curvature_fractions",
    "curvature_plot",
    "curve_sign_changes",
    "curve_total_variation",
    "distribution_report",
    "params_at_arclength",
    "smooth2d",
    "smooth_airfoil_points",
    "smooth_airfoil_result",
    "smooth_curvature",
    "smoothfoil",
    "total_variation",
    "write_points",
]
