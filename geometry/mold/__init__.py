"""Wind-turbine blade mold halves (Hosseini & Moetakef-Imani 2016, J. Mechanics).

``definition``: the blade TOML format and its validation (bad stations named).
``sections``: Eq. 5 (2-D -> 3-D), the silhouette point S, the two-part constrained fit
with G1 at S and SLSQP tangent magnitudes (§2, §4), the single-curve fit for comparison.
``windio``: blades from windIO turbine files (read by ``yaml_subset``, a strict reader of
the YAML windIO uses).
``blade``: common knots by averaging, skinning of the halves and of the single surface,
root transition (§5.1), tolerance, continuity and fairness figures (§3, §5).
(The molds as IGES records: ``bladesmith.iges.mold``.)
"""
from .blade import (
    BladeMolds,
    StationReport,
    SweepRow,
    build_blade,
    common_knots,
    control_point_sweep,
    format_sweep,
    parting_line_continuity,
    root_transition,
)
from .windio import load_windio_blade
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
    "BladeDefinition", "BladeMolds", "SingleFit", "SplitSection", "Station", "StationReport", "SweepRow", "TwoPartFit",
    "blade_from_dict", "build_blade", "control_point_sweep", "format_sweep", "load_windio_blade", "circle_airfoil", "common_knots", "find_silhouette", "fit_single",
    "fit_two_part", "load_blade", "load_preset", "parting_line_continuity", "preset_files", "root_transition",
    "section_points", "split_section",
]
