"""The CFD set of an impeller: hub and shroud walls trimmed at the blade footprints.

Casey (1983) bounds every blade surface by curves on the channel walls ("Blade Surfaces",
steps a–f; :mod:`.blade` builds the edges on the walls). A CFD mesher needs the walls with
the blades cut out, so that walls and blades sew into one shell. Here each wall is
trimmed the way the propeller hub sector is (Hally 2013 §10–11, IGES 144 over a 120):

- the wall is a surface of revolution: the C1 (z, r) contour of the channel wall
  (:func:`wall_contour`, the same reduced contour as :func:`.export.channel_wall_quarters`)
  turned about +z; its parameter space is (u, φ), u along the contour, φ the angle
  (IGES 120 with the contour laid in the plane y = 0 as (r, 0, z) and the axis from
  (0, 0, 0) to (0, 0, 1): a right-hand turn about +z, the convention of :mod:`.blade`);
- one passage sector per blade (one blade pitch 2π/Z): its sides follow the blade,
  φ_side(u) = φ_B(U) + a 2π/Z on the wall's camber line, held constant upstream of the LE
  and downstream of the TE, with a = -1/2 (between two blades) or, with splitters at
  pitch fraction f, a = (f - 1)/2 (between the previous splitter and the blade); the
  other side is the same curve shifted by one pitch, so neighbouring sectors share their
  sides exactly (the same control points plus k 2π/Z);
- the holes are the blade footprints, one per blade and splitter, each the closed chain
  of the blade's wall edges S, TE cap, P (reversed), LE cap: the model-space curves ARE
  the edges of the exported blade surfaces (their v = 0 or v = 1 control rows, copied),
  and the parameter-space curves are approximations of their (u, φ) images
  (:func:`..nurbs.approximate`), so the 142s prefer the model-space curve.

A standardised impeller (Casey 1983, Fig. 11) has the walls of its new channel and the
blades trimmed to it (:mod:`.standardisation`, edges on the new walls), footprints and
sector sides taken from the trimmed surfaces.

A single passage is one sector of hub and shroud with the reference blade (and splitter):
after sewing, its only free edges are the inlet, the outlet and the periodic sides. The
full wheel is Z sectors and Z blades: its free edges are the inlet and outlet circles.
The camber surface B is left out unless asked for (it is not a wall of the flow).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError
from ..nurbs import BSplineCurve, BSplineSurface, approximate, interpolate, reverse
from ..nurbs.fitting import greville_abscissae, interpolate_at
from .bezier import BezierString
from .blade import wall_foot
from .definition import ImpellerModel
from .export import blade_surfaces, reduced_contour

#: Parameter-space trim curves: tolerance (u and φ units) of their approximation.
PCURVE_TOLERANCE = 1e-9
#: Samples of the camber line for the sector sides.
SIDE_POINTS = 33
#: The 120's angular range reaches this far beyond the sector (radians).
ANGLE_MARGIN = 1e-2


@dataclass(frozen=True)
class WallContour:
    """A wall's C1 contour (z, r) over u and the map from the channel parameter U to u
    (linear on each channel patch: u = breaks[j] + (U - j) spans[j])."""

    curve: BSplineCurve
    breaks: np.ndarray
    string: BezierString

    def u_of_U(self, U) -> np.ndarray:
        U = np.asarray(U, dtype=float)
        n = len(self.breaks) - 1
        j = np.clip(np.floor(U).astype(int), 0, n - 1)
        return self.breaks[j] + (U - j) * (self.breaks[j + 1] - self.breaks[j])


def wall_contour(string: BezierString) -> WallContour:
    curve, breaks = reduced_contour(string)
    return WallContour(curve, breaks, string)


@dataclass(frozen=True)
class Trim:
    """One trim loop: 2-D parameter curves (u, φ) and, per piece, the 3-D model curve
    (None: the 142 carries the parameter curve only)."""

    parameter: tuple
    model: tuple


@dataclass(frozen=True)
class WallSector:
    """A trimmed wall face: the wall (``which``), its contour, the 120's angle range, the
    outer loop (counter-clockwise in (u, φ)) and the holes (clockwise)."""

    which: str
    contour: WallContour
    angle_range: tuple
    outer: Trim
    holes: tuple


def _edge_curve(surface: BSplineSurface, v: float) -> BSplineCurve:
    """The v = 0 or v = 1 edge of a degree (p, 1) blade surface: its control row, copied."""
    row = 0 if v == 0.0 else -1
    w = None if surface.weights is None else surface.weights[:, row].copy()
    return BSplineCurve(surface.degree_u, surface.knots_u.copy(), surface.control_points[:, row].copy(), w)


def _pcurve(contour: WallContour, wall: BezierString, model: BSplineCurve, U_guess) -> BSplineCurve:
    """(u, φ) of the wall foot points of ``model`` (φ continuous), approximated on the model
    curve's own parameter and knots."""
    a, b = model.domain

    def func(t):
        X = model.evaluate(t)
        zr = np.stack([X[:, 2], np.hypot(X[:, 0], X[:, 1])], axis=1)
        U, _ = wall_foot(wall, zr, U_guess(t))
        phi = np.unwrap(np.arctan2(X[:, 1], X[:, 0]))
        return np.stack([contour.u_of_U(U), phi], axis=1)

    inner = np.unique(model.knots[(model.knots > a) & (model.knots < b)])
    try:
        return approximate(func, PCURVE_TOLERANCE, degree=3, domain=(a, b), initial_knots=inner)
    except GeometryError:
        # a trimmed (standardised) edge's knots can be too uneven for the adaptive
        # approximation (it met a singular interpolation system): interpolate at the
        # Greville abscissae of uniform knots, doubled until the tolerance is met
        return _uniform_pcurve(func, a, b)


#: Uniform-knot fallback of :func:`_pcurve`: first and largest number of spans.
UNIFORM_PCURVE_SPANS = (32, 4096)


def _uniform_pcurve(func, a: float, b: float) -> BSplineCurve:
    """Cubic interpolant of ``func`` at the Greville abscissae of uniform knots on [a, b]
    (The NURBS Book 2e §9.2.1), the span count doubled until the largest deviation at the
    span midpoints is within PCURVE_TOLERANCE; the last one tried is returned otherwise."""
    n, most = UNIFORM_PCURVE_SPANS
    while True:
        knots = np.r_[np.full(4, a), np.linspace(a, b, n + 1)[1:-1], np.full(4, b)]
        curve = interpolate_at(knots, 3, greville_abscissae(knots, 3), func(greville_abscissae(knots, 3)))
        t = np.linspace(a, b, 4 * n + 1)
        if np.max(np.abs(curve.evaluate(t) - func(t))) <= PCURVE_TOLERANCE or n >= most:
            return curve
        n *= 2


def _signed_area(curves) -> float:
    area = 0.0
    for c in curves:
        t = np.linspace(*c.domain, 401)
        P = c.evaluate(t)
        area += 0.5 * float(np.sum(P[:-1, 0] * P[1:, 1] - P[1:, 0] * P[:-1, 1]))
    return area


def _footprint(surfaces: dict, which: str, contour: WallContour, wall: BezierString, corner_U) -> Trim:
    """The closed chain S, TE, P reversed, LE of a blade's edges on wall ``which``,
    clockwise in (u, φ)."""
    v = 0.0 if which == "hub" else 1.0
    U0, U1 = float(corner_U[0]), float(corner_U[-1])
    if not (np.isfinite(U0) and np.isfinite(U1)):
        U0, U1 = 0.0, float(wall.count)  # axial elements: no shroud corners, guess from a search below

    def guess_along(curve: BSplineCurve, forward: bool):
        a, b = curve.domain
        if np.isfinite(corner_U).all():
            return lambda t: np.interp(t, np.linspace(a, b, len(corner_U)), corner_U if forward else corner_U[::-1])
        return lambda t: _search_guess(wall, curve.evaluate(t))

    def at_end(end: float):
        return lambda t: np.full(np.shape(t), end)

    pieces = []
    S = _edge_curve(surfaces["S"], v)
    P = _edge_curve(surfaces["P"], v)
    pieces.append((S, guess_along(S, True)))
    if "TE" in surfaces:
        T = _edge_curve(surfaces["TE"], v)
        pieces.append((T, at_end(U1) if np.isfinite(corner_U).all() else (lambda t, c=T: _search_guess(wall, c.evaluate(t)))))
    Pr = reverse(P)
    pieces.append((Pr, guess_along(Pr, False)))
    if "LE" in surfaces:
        L = _edge_curve(surfaces["LE"], v)
        pieces.append((L, at_end(U0) if np.isfinite(corner_U).all() else (lambda t, c=L: _search_guess(wall, c.evaluate(t)))))
    models = tuple(c for c, _ in pieces)
    params = [_pcurve(contour, wall, c, g) for c, g in pieces]
    # φ continuous along the chain (each piece was unwrapped on its own)
    for k in range(1, len(params)):
        jump = params[k].control_points[0, 1] - params[k - 1].control_points[-1, 1]
        shift = 2.0 * math.pi * round(jump / (2.0 * math.pi))
        if shift:
            cp = params[k].control_points.copy()
            cp[:, 1] -= shift
            params[k] = BSplineCurve(3, params[k].knots, cp)
    if _signed_area(params) > 0.0:  # holes run clockwise
        params = [reverse(c) for c in reversed(params)]
        models = tuple(reverse(c) for c in reversed(models))
    return Trim(tuple(params), models)


def _search_guess(wall: BezierString, X) -> np.ndarray:
    zr = np.stack([X[:, 2], np.hypot(X[:, 0], X[:, 1])], axis=1)
    Us = np.linspace(0.0, wall.count, 64 * wall.count + 1)
    W = wall.evaluate(Us)
    return Us[np.argmin(np.linalg.norm(W[None] - zr[:, None], axis=-1), axis=1)]


def _line(p0, p1) -> BSplineCurve:
    return BSplineCurve(1, np.array([0.0, 0.0, 1.0, 1.0]), np.array([p0, p1], dtype=float))


def _side(model: ImpellerModel, which: str, contour: WallContour, offset: float, B: BSplineSurface,
          corners) -> list:
    """The lower periodic side of the passage sector on wall ``which``: a straight piece at
    the LE angle from the inlet, the camber line φ_B(U) + offset between LE and TE (a cubic
    interpolating it; B the camber surface whose edges lie on the walls, ``corners`` its
    corner parameters or NaN), a straight piece at the TE angle to the outlet; in (u, φ)."""
    v = 0.0 if which == "hub" else 1.0
    wall = model.channel.wall(which)
    edge = _edge_curve(B, v)
    t = np.linspace(*edge.domain, SIDE_POINTS)
    corner_U = corners[0 if which == "hub" else 1]
    if np.isfinite(corner_U).all():
        guess = np.interp(t, np.linspace(*edge.domain, len(corner_U)), corner_U)
    else:
        guess = _search_guess(wall, edge.evaluate(t))
    X = edge.evaluate(t)
    U, _ = wall_foot(wall, np.stack([X[:, 2], np.hypot(X[:, 0], X[:, 1])], axis=1), guess)
    uphi = np.stack([contour.u_of_U(U), np.unwrap(np.arctan2(X[:, 1], X[:, 0])) + offset], axis=1)
    middle = interpolate(uphi, 3)
    u_in, u_out = float(contour.breaks[0]), float(contour.breaks[-1])
    start, end = middle.control_points[0], middle.control_points[-1]
    pieces = []
    if start[0] > u_in:
        pieces.append(_line((u_in, start[1]), start))
    pieces.append(middle)
    if end[0] < u_out:
        pieces.append(_line(end, (u_out, end[1])))
    return pieces


def _shifted(curve: BSplineCurve, dphi: float) -> BSplineCurve:
    cp = curve.control_points.copy()
    cp[:, 1] += dphi
    return BSplineCurve(curve.degree, curve.knots, cp, curve.weights)


def _rotated(surface: BSplineSurface, angle: float) -> BSplineSurface:
    c, s = math.cos(angle), math.sin(angle)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return BSplineSurface(surface.degree_u, surface.degree_v, surface.knots_u, surface.knots_v,
                          surface.control_points @ R.T, surface.weights)


@dataclass(frozen=True)
class CfdSet:
    """Faces of the CFD set: ``walls`` (WallSector, trimmed) and ``blades`` (name,
    BSplineSurface); ``diameter`` the outer diameter used for the sewing tolerance."""

    walls: tuple
    blades: tuple
    diameter: float
    passages: int


def cfd_set(model: ImpellerModel, full_wheel: bool = False, include_camber: bool = False) -> CfdSet:
    """The single passage (one sector of hub and shroud, the reference blade and splitter)
    or the full wheel (Z sectors and Z blades), module docstring."""
    Z = model.count
    pitch = 2.0 * math.pi / Z
    a = -0.5
    if model.splitter is not None:
        # the splitter's φ offset, in pitches, from its camber line
        f = _splitter_fraction(model)
        a = 0.5 * (f - 1.0)
    references = [("blade", model.blade)] + ([("splitter", model.splitter)] if model.splitter is not None else [])
    std = model.standardisation
    if std is None:
        ref_surfaces = {label: dict(blade_surfaces(b, include_camber)) for label, b in references}
        corners = {label: b.corner_U for label, b in references}
        camber = dict(blade_surfaces(model.blade, include_camber=True))["B"]
    else:
        # standardised (Casey 1983, Fig. 11): the blades trimmed to the new channel, whose
        # edges lie on its walls; their wall parameters are found by search
        ref_surfaces = {label: dict(std.surfaces(label, include_camber)) for label, _ in references}
        corners = {label: np.full((2, 2), np.nan) for label, _ in references}
        camber = std.trimmed("blade", "B").surface
    walls, blades = [], []
    count = Z if full_wheel else 1
    diameter = 0.0
    for which in ("hub", "shroud"):
        string = model.channel.wall(which)
        contour = wall_contour(string)
        lower = _side(model, which, contour, a * pitch, camber, corners["blade"])
        holes0 = [_footprint(ref_surfaces[label], which, contour, string, corners[label][0 if which == "hub" else 1])
                  for label, _ in references]
        for k in range(count):
            shift = k * pitch
            low = [_shifted(c, shift) for c in lower]
            up = [reverse(_shifted(c, shift + pitch)) for c in reversed(lower)]
            outlet = _line(low[-1].control_points[-1], up[0].control_points[0])
            inlet = _line(up[-1].control_points[-1], low[0].control_points[0])
            outer = tuple(low) + (outlet,) + tuple(up) + (inlet,)
            holes = []
            for h in holes0:
                params = tuple(_shifted(c, shift) for c in h.parameter)
                models = tuple(c if k == 0 else _rotated_curve(c, shift) for c in h.model)
                holes.append(Trim(params, models))
            phis = np.concatenate([c.control_points[:, 1] for c in outer])
            walls.append(WallSector(which, contour, (float(phis.min()) - ANGLE_MARGIN, float(phis.max()) + ANGLE_MARGIN),
                                    Trim(outer, (None,) * len(outer)), tuple(holes)))
            diameter = max(diameter, 2.0 * float(np.max(contour.curve.control_points[:, 1])))
    for k in range(count):
        for label, parts in ref_surfaces.items():
            for part, surface in parts.items():
                if part == "B" and not include_camber:
                    continue
                blades.append((f"{label} {k + 1} {part}", surface if k == 0 else _rotated(surface, k * pitch)))
    return CfdSet(tuple(walls), tuple(blades), diameter, count)


def _rotated_curve(curve: BSplineCurve, angle: float) -> BSplineCurve:
    c, s = math.cos(angle), math.sin(angle)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return BSplineCurve(curve.degree, curve.knots, curve.control_points @ R.T, curve.weights)


def _splitter_fraction(model: ImpellerModel) -> float:
    """The splitter's pitch fraction, from the angle between the B surfaces at the TE hub
    corner (they share the camber line, offset in φ)."""
    b = model.blade.camber.lower.segments[-1].control_points[-1]
    s = model.splitter.camber.lower.segments[-1].control_points[-1]
    d = math.atan2(s[1], s[0]) - math.atan2(b[1], b[0])
    return ((d / (2.0 * math.pi / model.count)) % 1.0)
