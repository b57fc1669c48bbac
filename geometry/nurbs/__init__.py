"""B-spline and NURBS curves and surfaces (Piegl & Tiller, The NURBS Book 2e).

Types and evaluation (``curve``, ``surface``, ``basis``); knot insertion, refinement,
Bezier decomposition, degree elevation, reversal, splitting and compatibility
(``operations``); interpolation, least squares and adaptive approximation (``fitting``);
skinning, Coons and transfinite interpolation (``skinning``); closest points
(``projection``).
"""
from .basis import (
    basis_function_derivatives,
    basis_functions,
    bezier_knots,
    clamped_uniform_knots,
    find_span,
    validate_knots,
)
from .curve import BSplineCurve
from .fitting import approximate, approximate_common, fit_least_squares, interpolate, parameterize
from .operations import (
    bezier_segments,
    clamp,
    elevate_degree,
    insert_knot,
    make_compatible,
    merge_knot_vectors,
    refine_knots,
    reparametrize,
    reverse,
    split,
    surface_to_bezier_form,
    to_bezier_form,
)
from .projection import closest_point_curve, closest_point_surface
from .skinning import coons_surface, skin, transfinite_interpolation
from .surface import BSplineSurface

__all__ = [
    "BSplineCurve",
    "BSplineSurface",
    "approximate",
    "approximate_common",
    "basis_function_derivatives",
    "basis_functions",
    "bezier_knots",
    "bezier_segments",
    "clamp",
    "clamped_uniform_knots",
    "closest_point_curve",
    "closest_point_surface",
    "coons_surface",
    "elevate_degree",
    "find_span",
    "fit_least_squares",
    "insert_knot",
    "interpolate",
    "make_compatible",
    "merge_knot_vectors",
    "parameterize",
    "refine_knots",
    "reparametrize",
    "reverse",
    "skin",
    "split",
    "surface_to_bezier_form",
    "to_bezier_form",
    "transfinite_interpolation",
    "validate_knots",
]
