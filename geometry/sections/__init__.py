"""Blade sections: NACA 66 (DTRC modified) thickness, NACA a = 0.8 mean lines, NACA
4-digit, elliptic, and airfoil .dat files, as closed round-edged unit-chord shapes."""
from .airfoil_file import Airfoil, airfoil_from_outline, read_airfoil, smoothed_airfoil, thickness_and_camber
from .naca import a_series_meanline, elliptic_thickness, naca4_meanline, naca4_thickness, parabolic_meanline
from .shape import MEANLINE_NAMES, THICKNESS_NAMES, SectionShape, polygon_self_intersections, polygons_are_simple

__all__ = [
    "Airfoil",
    "MEANLINE_NAMES",
    "SectionShape",
    "THICKNESS_NAMES",
    "a_series_meanline",
    "airfoil_from_outline",
    "elliptic_thickness",
    "naca4_meanline",
    "naca4_thickness",
    "parabolic_meanline",
    "polygon_self_intersections",
    "polygons_are_simple",
    "read_airfoil",
    "smoothed_airfoil",
    "thickness_and_camber",
]
