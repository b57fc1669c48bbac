"""The impeller CFD set as IGES records (Casey 1983 walls and blades; the trimmed walls
written as the propeller hub sector is, Hally 2013 §11).

* each blade surface (S, P, LE and TE caps; B only when asked) as a 128;
* each wall sector as a Trimmed Surface (144) over a Surface of Revolution (120): the
  wall's C1 contour as a 126 laid in the plane y = 0 as (r, 0, z), turned about the axis
  Line (110) from (0, 0, 0) to (0, 0, 1) over the sector's angle range;
  - the outer boundary a 142 with a Composite Curve (102) of parameter-space curves
    (126 and 110) and no model-space curve (PREF = 1, S∘B exact);
  - one 142 per blade footprint with both curves: the parameter-space composite and the
    model-space composite of the blade's own wall edges (the control rows of the exported
    blade surfaces), PREF = 2, so the wall face and the blade face share the same edge
    curve and sew.
"""
from __future__ import annotations

import os

import numpy as np

from ..geometry.errors import IgesError
from ..geometry.nurbs import BSplineCurve
from .convert import curve_from_geometry, surface_from_geometry
from .records import METRES_PER_UNIT, UNITS, CompositeCurve, CurveOnSurface, Line, SurfaceOfRevolution, TrimmedSurface
from .writer import DEFAULT_RESOLUTION, write_iges


def _param_piece(c: BSplineCurve):
    if c.degree == 1 and c.n_control == 2:
        return Line(start=[*c.control_points[0], 0.0], end=[*c.control_points[1], 0.0])
    return curve_from_geometry(c)


def wall_record(sector, *, scale: float = 1.0) -> TrimmedSurface:
    """One :class:`~bladesmith.geometry.compressor.cfd.WallSector` as a 144 over a 120."""
    c = sector.contour.curve
    P = np.column_stack([c.control_points[:, 1], np.zeros(c.n_control), c.control_points[:, 0]])
    generatrix = curve_from_geometry(BSplineCurve(c.degree, c.knots, P, c.weights), scale=scale,
                                     label=f"{sector.which.upper()[:6]}C")
    axis = Line(start=[0.0, 0.0, 0.0], end=[0.0, 0.0, 1.0])
    a0, a1 = map(float, sector.angle_range)
    surface = SurfaceOfRevolution(axis=axis, generatrix=generatrix, start_angle=a0, end_angle=a1)
    outer = CurveOnSurface(surface=surface, parameter_curve=CompositeCurve(curves=[_param_piece(p) for p in
                                                                                   sector.outer.parameter]),
                           model_curve=None, creation=0, preferred=1)
    inner = []
    for hole in sector.holes:
        param = CompositeCurve(curves=[_param_piece(p) for p in hole.parameter])
        model = CompositeCurve(curves=[curve_from_geometry(m, scale=scale) for m in hole.model])
        inner.append(CurveOnSurface(surface=surface, parameter_curve=param, model_curve=model, creation=2,
                                    preferred=2))
    return TrimmedSurface(surface=surface, outer=outer, inner=tuple(inner), label=sector.which.upper()[:8])


def cfd_records(cfd, units: str = "m") -> list:
    """Root records of a :class:`~bladesmith.geometry.compressor.cfd.CfdSet`: the 144 wall
    sectors, then the blade 128s."""
    key = units.lower() if isinstance(units, str) else units
    if key not in UNITS or key not in METRES_PER_UNIT:
        raise IgesError(f"unknown units {units!r}; expected one of {sorted(UNITS)}")
    scale = 1.0 / METRES_PER_UNIT[key]
    records = [wall_record(w, scale=scale) for w in cfd.walls]
    records += [surface_from_geometry(s, scale=scale, label=name.replace(" ", "")[:8].upper()) for name, s in cfd.blades]
    return records


def write_cfd_iges(path, cfd, units: str = "m", **options) -> str:
    """Write the CFD set atomically (validated by :func:`write_iges`); returns the path."""
    options.setdefault("resolution", DEFAULT_RESOLUTION / METRES_PER_UNIT[units.lower()])
    return write_iges(os.fspath(path), cfd_records(cfd, units), units=units, **options)
