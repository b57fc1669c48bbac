"""Wind-turbine blade mold halves (Hosseini & Moetakef-Imani 2016, J. Mechanics).

``definition``: the blade TOML format and its validation (bad stations named).
``sections``: Eq. 5 (2-D -> 3-D), the silhouette point S, the two-part constrained fit
with G1 at S and SLSQP tangent magnitudes (§2, §4), the single-curve fit for comparison.
``blade``: common knots by averaging, skinning of the halves and of the single surface,
root transition (§5.1), tolerance, continuity and fairness figures (§3, §5).
(The molds as IGES records: ``bladesmith.iges.mold``.)
"""
from .blade import BladeMolds, StationReport, build_blade, common_knots, parting_line_continuity, root_transition
from .definition import BladeDefinition, Station, blade_from_dict, circle_airfoil, load_blade, load_preset, preset_files
from .sections import (
    SingleFit,
    SplitSection,
    TwoPartFit,
    find_silhouette,
    fit_single,
    fit_two_part,
    section_points,
    split_section,
)

__all__ = [
    "BladeDefinition", "BladeMolds", "SingleFit", "SplitSection", "Station", "StationReport", "TwoPartFit",
    "blade_from_dict", "build_blade", "circle_airfoil", "common_knots", "find_silhouette", "fit_single",
    "fit_two_part", "load_blade", "load_preset", "parting_line_continuity", "preset_files", "root_transition",
    "section_points", "split_section",
]
