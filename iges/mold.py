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


def cap_record(cap, scale: float, label: str):
    """A planar cap (:func:`~bladesmith.geometry.mold.caps.planar_cap`) as a 144 over its
    plane (a bilinear 128), trimmed by one 142 whose 3-D curve is the composite of the mold
    surfaces' end rows themselves (PREF = 2: the curve the cap shares with the surfaces) and
    whose parameter curve is the composite of their exact (u, v) images."""
    from .records import CompositeCurve, CurveOnSurface, TrimmedSurface

    plane = surface_from_geometry(cap.plane, scale=scale, label=label)
    loop = CurveOnSurface(surface=plane,
                          parameter_curve=CompositeCurve(curves=[curve_from_geometry(c) for c in cap.pcurves]),
                          model_curve=CompositeCurve(curves=[curve_from_geometry(c, scale=scale) for c in cap.edges]),
                          creation=0, preferred=2)
    return TrimmedSurface(surface=plane, outer=loop, inner=(), label=label)


def closed_blade_records(molds: BladeMolds, units: str = "m", caps: str = "ruled") -> list:
    """The mold surfaces (:func:`~bladesmith.geometry.mold.caps.closed_surfaces`: a
    trailing-edge base that runs the whole span is part of the lower face) plus root and
    tip caps (:func:`~bladesmith.geometry.mold.caps.blade_caps`): faces that sew into one
    closed shell. caps: "ruled" (a 128 between the halves' end rows, any section),
    "planar" (a trimmed plane whose loop is the end rows themselves; only where the end
    section is planar) or "rounded" (a planar root, a rounded tip tangent to the mold
    halves)."""
    from ..geometry.mold.caps import blade_caps, closed_surfaces

    scale = 1.0 / METRES_PER_UNIT[units.lower()]
    root, tip = blade_caps(molds, caps)
    out = [surface_from_geometry(s, scale=scale, label=LABELS.get(name, ""))
           for name, s in closed_surfaces(molds).items()]
    from ..geometry.mold.caps import Cap

    if caps in ("planar", "rounded"):
        def record(cap, label):
            return cap_record(cap, scale, label) if isinstance(cap, Cap) else surface_from_geometry(cap, scale=scale,
                                                                                                     label=label)
        return out + [record(root, "ROOTCAP"), record(tip, "TIPCAP")]
    return out + [surface_from_geometry(root, scale=scale, label="ROOTCAP"),
                  surface_from_geometry(tip, scale=scale, label="TIPCAP")]


def write_closed_blade(path, molds: BladeMolds, units: str = "m", caps: str = "ruled") -> str:
    """Write the closed blade (:func:`closed_blade_records`) atomically; returns the path."""
    return write_iges(path, closed_blade_records(molds, units, caps), units=units)
