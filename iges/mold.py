"""IGES records of the mold halves: surfaces as entity 128, parting lines as entity 126
(Hosseini & Moetakef-Imani 2016 §5: the molds are exchanged as IGES)."""
from __future__ import annotations

from ..geometry.mold.blade import BladeMolds
from .convert import curve_from_geometry, surface_from_geometry
from .records import METRES_PER_UNIT
from .writer import write_iges


#: IGES entity labels (at most 8 characters) of the mold surfaces and parting lines.
LABELS = {
    "upper": "UPPER", "lower": "LOWER", "transition_upper": "ROOTUP", "transition_lower": "ROOTLO",
    "trailing_edge": "TEBASE", "transition_trailing_edge": "ROOTTE", "leading_edge": "LEPART",
    "trailing_edge_upper": "TEPARTU", "trailing_edge_lower": "TEPARTL", "root_leading_edge": "RLEPART",
    "root_trailing_edge_upper": "RTEPARTU", "root_trailing_edge_lower": "RTEPARTL",
}


def mold_records(molds: BladeMolds, parting_lines: bool = True, units: str = "m") -> list:
    """128 records of every mold surface (labelled with its name) and 126 records of the
    parting lines, with coordinates in ``units`` (the model is in metres)."""
    scale = 1.0 / METRES_PER_UNIT[units.lower()]
    out = [surface_from_geometry(s, scale=scale, label=LABELS.get(name, "")) for name, s in molds.surfaces.items()]
    if parting_lines:
        out += [curve_from_geometry(c, scale=scale, label=LABELS.get(name, ""))
                for name, c in molds.parting_lines.items()]
    return out


def write_molds(path, molds: BladeMolds, units: str = "m", parting_lines: bool = True) -> str:
    """Write the molds to an IGES file atomically, coordinates in ``units``; returns the path."""
    return write_iges(path, mold_records(molds, parting_lines, units), units=units)
