"""The impeller as a list of named exact surfaces, for the Blender display and IGES.

Channel walls: rational surfaces of revolution of degree (p, 2) (IGES 128); blades: the
S and P patch strings and the rounded end patches as degree (3, 1) B-splines (IGES 128,
Casey's cubic-linear patches), blade k turned by 2πk/Z (exact rotation of the polygons).
A standardised impeller has the walls of its new channel and the trimmed blades of
:mod:`.standardisation` (degree (3, 1) B-splines too).
"""
from __future__ import annotations

import weakref

import numpy as np

from ..nurbs import BSplineSurface
from ..nurbs.fitting import greville_abscissae, interpolate_at
from .bezier import BezierString, PatchString
from .channel import full_circle
from .definition import ImpellerModel

#: A knot-reduced form is used only if it reproduces the Bézier form to this (relative).
REDUCTION_TOLERANCE = 1e-12
#: Samples per patch at which a knot-reduced form is compared with the Bézier form (a
#: string that is not smooth enough differs all along the patches next to the junction).
REDUCTION_SAMPLES = 10


def _reduced_string(string: BezierString, multiplicity: int, spans=None):
    """The string as a B-spline with interior knots of lower ``multiplicity`` (knot
    removal done as exact interpolation at the Greville abscissae, The NURBS Book 2e
    §9.2.1: the string lies in the smaller spline space, so the interpolant is the string),
    or None when the string is not smooth enough for it. ``spans``: knot-span lengths
    (default 1 per patch)."""
    n, p = string.count, string.max_degree
    h = np.ones(n) if spans is None else np.asarray(spans, float)
    breaks = np.r_[0.0, np.cumsum(h)]
    knots = np.r_[np.zeros(p + 1), np.repeat(breaks[1:-1], multiplicity), np.full(p + 1, breaks[-1])]
    g = greville_abscissae(knots, p)
    k = np.clip(np.searchsorted(breaks, g, side="right") - 1, 0, n - 1)
    U = k + (g - breaks[k]) / h[k]
    curve = interpolate_at(knots, p, g, string.elevated_to(p).evaluate(U))
    test = np.linspace(0.0, breaks[-1], REDUCTION_SAMPLES * n + 1)
    kt = np.clip(np.searchsorted(breaks, test, side="right") - 1, 0, n - 1)
    ref = string.evaluate(kt + (test - breaks[kt]) / h[kt])
    scale = max(1.0, float(np.abs(ref).max()))
    if np.max(np.abs(curve.evaluate(test) - ref)) > REDUCTION_TOLERANCE * scale:
        return None
    return curve


#: The B-spline forms already made of patch strings and wall contours (the model objects
#: are immutable and shared by every model built from the same values, :mod:`.memo`, so a
#: panel edit converts only what it changed); dropped with the object they belong to.
_CONVERTED = weakref.WeakKeyDictionary()


def _converted(obj, make):
    try:
        return _CONVERTED[obj]
    except KeyError:
        value = _CONVERTED[obj] = make(obj)
        return value


def ruled_bspline(surface: PatchString) -> BSplineSurface:
    """A cubic-linear patch string as a degree (3, 1) B-spline with simple interior knots
    when it is C2 (Casey's blades), else in Bézier form (made once per string)."""
    return _converted(surface, _ruled_bspline)


def _ruled_bspline(surface: PatchString) -> BSplineSurface:
    lo = _reduced_string(surface.lower, 1)
    up = _reduced_string(surface.upper, 1)
    if lo is None or up is None:
        # a fitted string (:mod:`.fitting`) is C2 in its own knot spans, not in unit spans
        # per patch: take the spans from the polygon legs at the junctions (C1 matching)
        h = _spans(surface.lower)
        lo = _reduced_string(surface.lower, 1, spans=h) if h is not None else None
        up = _reduced_string(surface.upper, 1, spans=h) if h is not None else None
        if lo is None or up is None:
            return surface.to_bspline()
    P = np.stack([lo.control_points, up.control_points], axis=1)
    return BSplineSurface(lo.degree, 1, lo.knots, np.array([0.0, 0, 1, 1]), P)


def _spans(string: BezierString):
    """Knot spans that make the string's first derivatives match at the junctions, or None."""
    h = [1.0]
    for a, b in zip(string.segments[:-1], string.segments[1:]):
        da = np.linalg.norm(a.control_points[-1] - a.control_points[-2])
        db = np.linalg.norm(b.control_points[1] - b.control_points[0])
        if not (da > 0.0 and db > 0.0):
            return None
        h.append(h[-1] * db / da)
    return h


def reduced_contour(string: BezierString):
    """The wall contour as a C1 B-spline (interior knots of multiplicity p - 1, knot spans
    chosen so that the first derivatives match at the junctions: the channel is G2), or
    the Bézier form when that fails; and the parameter breaks of the channel patches
    (patch j covers [breaks[j], breaks[j+1]], linearly in U)."""
    p = string.max_degree
    s = string.elevated_to(p)
    h = [1.0]
    for a, b in zip(s.segments[:-1], s.segments[1:]):
        da = np.linalg.norm(a.control_points[-1] - a.control_points[-2])
        db = np.linalg.norm(b.control_points[1] - b.control_points[0])
        h.append(h[-1] * db / da)
    contour = _reduced_string(s, p - 1, spans=h) if p > 1 else None
    if contour is None:
        return string.to_bspline(), np.arange(string.count + 1, dtype=float)
    return contour, np.r_[0.0, np.cumsum(h)]


def channel_wall_quarters(string: BezierString) -> list[BSplineSurface]:
    """A wall of revolution as four quarter surfaces (φ in [qπ/2, (q+1)π/2]), each one
    exact rational quadratic arc in v, so that none is closed and none has a C0 knot in v, with the contour made C1 by choosing the knot spans so that the first
    derivatives match at the junctions (the channel is G2; interior knots of
    multiplicity p - 1), falling back to the Bézier form (made once per string)."""
    return list(_converted(string, _channel_wall_quarters))


def _channel_wall_quarters(string: BezierString) -> tuple:
    contour, _ = reduced_contour(string)
    knots_c, circle, w_circle = full_circle()
    out = []
    for q in range(4):
        half = slice(2 * q, 2 * q + 3)
        c, w = circle[half], w_circle[half]
        z, r = contour.control_points[:, 0], contour.control_points[:, 1]
        P = np.empty((len(z), 3, 3))
        P[..., 0] = r[:, None] * c[None, :, 0]
        P[..., 1] = r[:, None] * c[None, :, 1]
        P[..., 2] = z[:, None]
        kv = np.array([0.0, 0, 0, 1, 1, 1]) * 0.5 * np.pi + 0.5 * np.pi * q
        out.append(BSplineSurface(contour.degree, 2, contour.knots, kv, P, np.ones(len(z))[:, None] * w[None, :]))
    return tuple(out)


def blade_surfaces(blade, include_camber: bool = False) -> list[tuple[str, BSplineSurface]]:
    out = [("S", ruled_bspline(blade.suction)), ("P", ruled_bspline(blade.pressure))]
    if blade.leading_edge is not None:
        out.append(("LE", ruled_bspline(blade.leading_edge)))
    if blade.trailing_edge is not None:
        out.append(("TE", ruled_bspline(blade.trailing_edge)))
    if include_camber:
        out.append(("B", ruled_bspline(blade.camber)))
    return out


def impeller_surfaces(model: ImpellerModel, blades: int | None = None, include_camber: bool = False
                      ) -> list[tuple[str, BSplineSurface]]:
    """(name, surface) pairs: "hub 1".."hub 4", "shroud 1".."shroud 4" (quarter
    walls, see :func:`channel_wall_quarters`), then "blade k S" ... for k = 1..blades (default all Z)
    and "splitter k S" ... when the model has splitters.

    A standardised model (Casey 1983, Fig. 11) gives the walls of its new channel and the
    blades trimmed to it (:mod:`.standardisation`: degree (3, 1) B-splines whose edges lie
    on the new walls to the standardisation tolerance), under the same names."""
    out = []
    for wall in ("hub", "shroud"):
        for i, surface in enumerate(channel_wall_quarters(model.channel.wall(wall))):
            out.append((f"{wall} {i + 1}", surface))
    count = model.count if blades is None else int(blades)
    st = model.standardisation
    reference = {label: blade_surfaces(blade, include_camber) if st is None else st.surfaces(label, include_camber)
                 for label, blade in (("blade", model.blade), ("splitter", model.splitter)) if blade is not None}
    for k in range(count):
        c, s = np.cos(model.blade_angle(k)), np.sin(model.blade_angle(k))
        R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        for label, parts in reference.items():
            for part, surface in parts:
                if part == "B" and k:
                    continue
                turned = surface if k == 0 else BSplineSurface(
                    surface.degree_u, surface.degree_v, surface.knots_u, surface.knots_v,
                    surface.control_points @ R.T, surface.weights)
                out.append((f"{label} {k + 1} {part}", turned))
    return out


def construction_summary(model: ImpellerModel) -> tuple[str, bool]:
    """One line on the adaptive construction of the blades (:func:`.blade.build_blade`):
    patches chosen, the largest edge-to-wall distance and the camber and thickness errors
    (metres); and whether every tolerance was met."""
    parts, met = [], True
    for label, blade in (("blade", model.blade), ("splitter", model.splitter)):
        if blade is None or not blade.report:
            continue
        r = blade.report
        met = met and bool(r.get("met", True))
        parts.append(f"{label} {r['patches']} patches ({r['spacing']}), wall {r['wall_gap']:.2g} m, "
                     f"camber {r['camber']:.2g} m, thickness {r['thickness']:.2g} m")
    text = "; ".join(parts)
    if not met:
        text = "tolerance NOT met: " + text
    return text, met
