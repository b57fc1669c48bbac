"""Bpy-free IGES 5.3 writer and reader: entities as plain data records.

Write::

    from bladesmith.iges import write_iges, surface_from_geometry
    write_iges("blade.igs", [surface_from_geometry(surface)], units="m")

Read::

    model = read_iges("blade.igs")      # IgesModel: .entities, .header, .roots
    for record, geometry in model.to_geometry(): ...

Entity coverage (IGES 5.3 §4): 100, 102, 110, 112, 114, 120, 124, 126, 128, 142, 144,
written and read; other types are read as :class:`GenericEntity`.
"""
from .convert import (
    TrimmedSurfaceGeometry,
    curve_from_geometry,
    curve_geometry,
    surface_from_geometry,
    surface_geometry,
    to_geometry,
)
from .reader import IgesModel, parse_iges, read_iges
from .records import (
    METRES_PER_UNIT,
    UNITS,
    BSplineCurve126,
    BSplineSurface128,
    CircularArc,
    CompositeCurve,
    CurveOnSurface,
    DirectoryInfo,
    Entity,
    GenericEntity,
    GlobalSection,
    Line,
    ParametricSpline,
    ParametricSplineSurface,
    SurfaceOfRevolution,
    TransformationMatrix,
    TrimmedSurface,
)
from .writer import DEFAULT_RESOLUTION, format_real, make_header, to_string, write_iges

__all__ = [
    "BSplineCurve126", "BSplineSurface128", "CircularArc", "CompositeCurve", "CurveOnSurface",
    "DEFAULT_RESOLUTION", "DirectoryInfo", "METRES_PER_UNIT", "Entity", "GenericEntity", "GlobalSection", "IgesModel",
    "Line", "ParametricSpline", "ParametricSplineSurface", "SurfaceOfRevolution",
    "TransformationMatrix", "TrimmedSurface", "TrimmedSurfaceGeometry", "UNITS",
    "curve_from_geometry", "curve_geometry", "format_real", "make_header", "parse_iges",
    "read_iges", "surface_from_geometry", "surface_geometry", "to_geometry", "to_string",
    "write_iges",
]
