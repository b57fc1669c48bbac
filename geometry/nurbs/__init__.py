"""B-spline and NURBS curves and surfaces (Piegl & Tiller, The NURBS Book 2e)."""
from .basis import (
    basis_function_derivatives,
    basis_functions,
    bezier_knots,
    clamped_uniform_knots,
    find_span,
    validate_knots,
)
from .curve import BSplineCurve
from .surface import BSplineSurface

__all__ = [
    "BSplineCurve",
    "BSplineSurface",
    "basis_function_derivatives",
    "basis_functions",
    "bezier_knots",
    "clamped_uniform_knots",
    "find_span",
    "validate_knots",
]
