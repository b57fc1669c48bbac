"""Records <-> ``geometry.nurbs`` objects, and point evaluation of records.

* 126 <-> :class:`BSplineCurve`, 128 <-> :class:`BSplineSurface` (exact).
* 110, 100, 112 -> :class:`BSplineCurve`; 114, 120 -> :class:`BSplineSurface` (exact:
  power-basis pieces become Bezier pieces, arcs and revolutions become rational
  quadratic arcs, Piegl & Tiller, The NURBS Book 2e, Alg. A7.1 and A8.1).
* 102 -> a list of curves; 142 and 144 -> :class:`TrimmedSurfaceGeometry`.

Evaluation (``curve_points``, ``surface_points``) follows each entity's own IGES 5.3
parameterisation, which the writer's validation needs (trimming curves lie in the
surface's IGES parameter space; IGES 5.3 §4.19, §4.20).
"""
from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from ..geometry.errors import BladesmithError, GeometryError, IgesError
from ..geometry.nurbs import BSplineCurve, BSplineSurface
from ..geometry.nurbs.operations import split_surface
from .records import (
    BSplineCurve126,
    BSplineSurface128,
    CircularArc,
    CompositeCurve,
    CurveOnSurface,
    Entity,
    Line,
    ParametricSpline,
    ParametricSplineSurface,
    SurfaceOfRevolution,
    TransformationMatrix,
    TrimmedSurface,
)

#: Pieces of 112/114 splines must meet within this fraction of the coefficients' size.
CONTINUITY_TOLERANCE = 1e-9
#: Transformation chains (124 pointing to 124 ...) longer than this are refused.
MAX_TRANSFORM_DEPTH = 32


# -- records -> points -----------------------------------------------------------------
def _transform(entity: Entity, points: np.ndarray) -> np.ndarray:
    t = entity.transform
    depth = 0
    while t is not None:
        if not isinstance(t, TransformationMatrix):
            raise IgesError(f"{entity.describe()}: transform is not a type 124 entity")
        points = t.apply(points)
        t = t.transform
        depth += 1
        if depth > MAX_TRANSFORM_DEPTH:
            raise IgesError(f"{entity.describe()}: transformation chain longer than {MAX_TRANSFORM_DEPTH}")
    return points


def curve_range(curve: Entity) -> tuple[float, float]:
    """The IGES parameter range of a curve record (IGES 5.3 §4.3, §4.13, §4.14, §4.23)."""
    if isinstance(curve, Line):
        return 0.0, 1.0
    if isinstance(curve, CircularArc):
        return curve.angles
    if isinstance(curve, ParametricSpline):
        T = curve.breakpoints
        return float(T[0]), float(T[-1])
    if isinstance(curve, BSplineCurve126):
        return curve.parameter_range
    if isinstance(curve, CompositeCurve):
        raise IgesError("a composite curve (102) has no single parameter range; use its constituents")
    raise IgesError(f"{curve.describe() if isinstance(curve, Entity) else curve!r}: not a curve entity")


def curve_points(curve: Entity, t) -> np.ndarray:
    """Points of a curve record at IGES parameters ``t``: shape t.shape + (3,)."""
    t = np.asarray(t, dtype=np.float64)
    if isinstance(curve, Line):
        P = curve.start + t[..., None] * (curve.end - curve.start)
    elif isinstance(curve, CircularArc):
        r = curve.radius
        P = np.stack(
            [curve.center[0] + r * np.cos(t), curve.center[1] + r * np.sin(t), np.full(t.shape, curve.z)],
            axis=-1,
        )
    elif isinstance(curve, ParametricSpline):
        T = curve.breakpoints
        i = np.clip(np.searchsorted(T, t, side="right") - 1, 0, T.size - 2)
        s = (t - T[i])[..., None]
        c = curve.coefficients[i]  # t.shape + (3, 4)
        P = c[..., 0] + s * (c[..., 1] + s * (c[..., 2] + s * c[..., 3]))
    elif isinstance(curve, BSplineCurve126):
        P = bspline_curve(curve).evaluate(t)
    else:
        raise IgesError(f"{curve.describe()}: cannot evaluate points of this entity")
    return _transform(curve, P)


def curve_ends(curve: Entity) -> tuple[np.ndarray, np.ndarray]:
    """(start point, end point) of a curve record, composite curves included."""
    if isinstance(curve, CompositeCurve):
        if not curve.curves:
            raise IgesError("composite curve (102) with no constituents")
        p0 = curve_ends(curve.curves[0])[0]
        p1 = curve_ends(curve.curves[-1])[1]
        return _transform(curve, p0), _transform(curve, p1)
    a, b = curve_range(curve)
    P = curve_points(curve, np.array([a, b]))
    return P[0], P[1]


def surface_range(surface: Entity) -> tuple[tuple[float, float], tuple[float, float]]:
    """((u0, u1), (v0, v1)): the IGES parameter domain of a surface record."""
    if isinstance(surface, BSplineSurface128):
        return surface.parameter_range_u, surface.parameter_range_v
    if isinstance(surface, SurfaceOfRevolution):
        return curve_range(surface.generatrix), (surface.start_angle, surface.end_angle)
    if isinstance(surface, ParametricSplineSurface):
        U, V = surface.breakpoints_u, surface.breakpoints_v
        return (float(U[0]), float(U[-1])), (float(V[0]), float(V[-1]))
    raise IgesError(f"{surface.describe() if isinstance(surface, Entity) else surface!r}: not a parametric surface")


def _rotate(points: np.ndarray, origin, axis, angle) -> np.ndarray:
    """Rotate ``points`` right-handedly by ``angle`` about the line (origin, unit axis) (Rodrigues)."""
    x = points - origin
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    along = (x @ axis)[..., None] * axis
    return origin + x * c + np.cross(axis, x) * s + along * (1.0 - c)


def axis_of(surface: SurfaceOfRevolution) -> tuple[np.ndarray, np.ndarray]:
    """(origin, unit direction) of a 120's axis line, transforms applied."""
    p0, p1 = curve_ends(surface.axis)
    d = p1 - p0
    n = float(np.linalg.norm(d))
    if not n > 0.0 or not math.isfinite(n):
        raise IgesError(f"{surface.describe()}: the axis of revolution has zero or non-finite length")
    return p0, d / n


def surface_points(surface: Entity, u, v) -> np.ndarray:
    """Points of a surface record at IGES parameters (u, v): broadcast shape + (3,)."""
    u, v = np.broadcast_arrays(np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64))
    if isinstance(surface, BSplineSurface128):
        P = bspline_surface(surface).evaluate(u, v)
    elif isinstance(surface, SurfaceOfRevolution):
        origin, axis = axis_of(surface)
        P = _rotate(curve_points(surface.generatrix, u), origin, axis, v)
    elif isinstance(surface, ParametricSplineSurface):
        TU, TV = surface.breakpoints_u, surface.breakpoints_v
        i = np.clip(np.searchsorted(TU, u, side="right") - 1, 0, TU.size - 2)
        j = np.clip(np.searchsorted(TV, v, side="right") - 1, 0, TV.size - 2)
        s, t = u - TU[i], v - TV[j]
        k = np.arange(16)
        mono = s[..., None] ** (k % 4) * t[..., None] ** (k // 4)  # shape + (16,)
        P = np.einsum("...ck,...k->...c", surface.coefficients[i, j], mono)
    else:
        raise IgesError(f"{surface.describe() if isinstance(surface, Entity) else surface!r}: not a parametric surface")
    return _transform(surface, P)


# -- records -> geometry ------------------------------------------------------------------
def _geometry(fn, what: str, *args):
    try:
        return fn(*args)
    except GeometryError as exc:
        raise IgesError(f"{what}: {exc}") from None


#: Geometry objects of records already converted (records are immutable, so this is safe).
_GEOMETRY_CACHE: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def bspline_curve(record: BSplineCurve126) -> BSplineCurve:
    """The 126's curve over its whole knot domain (transform not applied)."""
    g = _GEOMETRY_CACHE.get(record)
    if g is None:
        w = None if record.is_polynomial else record.weights
        g = _geometry(BSplineCurve, record.describe(), record.degree, record.knots, record.control_points, w)
        _GEOMETRY_CACHE[record] = g
    return g


def bspline_surface(record: BSplineSurface128) -> BSplineSurface:
    """The 128's surface over its whole knot domains (transform not applied)."""
    g = _GEOMETRY_CACHE.get(record)
    if g is None:
        w = None if record.is_polynomial else record.weights
        g = _geometry(
            BSplineSurface, record.describe(), record.degree_u, record.degree_v,
            record.knots_u, record.knots_v, record.control_points, w,
        )
        _GEOMETRY_CACHE[record] = g
    return g


def _transform_curve(record: Entity, curve: BSplineCurve) -> BSplineCurve:
    if record.transform is None:
        return curve
    return curve.with_control_points(_transform(record, curve.control_points))


def _arc_net(angle0: float, angle1: float):
    """Unit-circle rational quadratic arc from angle0 to angle1 (The NURBS Book Alg. A7.1).

    Returns (knots, cos/sin pairs (m, 2) of the control points' directions, radius factors (m,),
    weights (m,)): control point j is center + r * factor_j * (cos, sin)_j.
    """
    span = angle1 - angle0
    narcs = max(1, int(math.ceil(span / (0.5 * math.pi) - 1e-12)))
    d = span / narcs
    w1 = math.cos(0.5 * d)
    angles, factors, weights = [], [], []
    for k in range(narcs):
        a = angle0 + k * d
        if k == 0:
            angles.append(a), factors.append(1.0), weights.append(1.0)
        angles += [a + 0.5 * d, a + d]
        factors += [1.0 / w1, 1.0]
        weights += [w1, 1.0]
    knots = [angle0] * 3
    for k in range(1, narcs):
        knots += [angle0 + k * d] * 2
    knots += [angle1] * 3
    A = np.array(angles)
    return np.array(knots), np.stack([np.cos(A), np.sin(A)], axis=1), np.array(factors), np.array(weights)


def _power_to_bezier(coeffs: np.ndarray, h: float) -> np.ndarray:
    """Cubic power coefficients (..., 4) in s over [0, h] -> Bezier points (..., 4)."""
    a = coeffs * h ** np.arange(4)
    # b_j = sum_k C(j,k)/C(3,k) a_k  (The NURBS Book §6.1, Eq. 6.4 inverse)
    M = np.array([[1, 0, 0, 0], [1, 1 / 3, 0, 0], [1, 2 / 3, 1 / 3, 0], [1, 1, 1, 1]])
    return a @ M.T


def _breakpoint_knots(T: np.ndarray) -> np.ndarray:
    return np.concatenate([[T[0]] * 4, np.repeat(T[1:-1], 3), [T[-1]] * 4])


def curve_geometry(record: Entity) -> BSplineCurve:
    """A single curve record as an exact B-spline curve (3-D; transforms applied)."""
    if isinstance(record, BSplineCurve126):
        return _transform_curve(record, bspline_curve(record))
    if isinstance(record, Line):
        if record.form != 0:
            raise IgesError(f"{record.describe()}: only bounded lines (form 0) convert to curves")
        c = _geometry(BSplineCurve, record.describe(), 1, [0.0, 0.0, 1.0, 1.0], np.stack([record.start, record.end]))
        return _transform_curve(record, c)
    if isinstance(record, CircularArc):
        a0, a1 = record.angles
        knots, cs, f, w = _arc_net(a0, a1)
        r = record.radius
        P = np.empty((len(f), 3))
        P[:, :2] = record.center + r * f[:, None] * cs
        P[:, 2] = record.z
        c = _geometry(BSplineCurve, record.describe(), 2, knots, P, w)
        return _transform_curve(record, c)
    if isinstance(record, ParametricSpline):
        T = record.breakpoints
        h = np.diff(T)
        B = _power_to_bezier(record.coefficients, h[:, None, None])  # (N, 3, 4)
        gaps = np.abs(B[:-1, :, 3] - B[1:, :, 0])
        if gaps.size and gaps.max() > CONTINUITY_TOLERANCE * max(1.0, float(np.abs(B).max())):
            raise IgesError(f"{record.describe()}: segments do not meet; a discontinuous spline has "
                            f"no B-spline form")
        P = np.concatenate([B[0, :, :1].T] + [B[i, :, 1:].T for i in range(len(h))])
        c = _geometry(BSplineCurve, record.describe(), 3, _breakpoint_knots(T), P)
        return _transform_curve(record, c)
    raise IgesError(f"{record.describe()}: not a single curve")


def surface_geometry(record: Entity) -> BSplineSurface:
    """A surface record as an exact B-spline surface (transforms applied).

    For a 120 the v direction becomes rational quadratic arcs whose knots sit at the
    arc-joint angles; between knots v is no longer the angle.
    """
    if isinstance(record, BSplineSurface128):
        s = bspline_surface(record)
    elif isinstance(record, ParametricSplineSurface):
        TU, TV = record.breakpoints_u, record.breakpoints_v
        hu, hv = np.diff(TU), np.diff(TV)
        C = record.coefficients.reshape(record.coefficients.shape[:3] + (4, 4))  # [.., t-power, s-power]
        C = np.swapaxes(C, -1, -2)  # [..., s-power, t-power]
        M, N = len(hu), len(hv)
        P = np.zeros((3 * M + 1, 3 * N + 1, 3))
        for i in range(M):
            for j in range(N):
                c = C[i, j] * (hu[i] ** np.arange(4))[:, None] * (hv[j] ** np.arange(4))[None, :]
                Mb = np.array([[1, 0, 0, 0], [1, 1 / 3, 0, 0], [1, 2 / 3, 1 / 3, 0], [1, 1, 1, 1]])
                B = np.einsum("ak,dkl,bl->abd", Mb, c, Mb)
                if i or j:  # shared boundary rows must agree, else there is no B-spline form
                    old = P[3 * i : 3 * i + 4, 3 * j : 3 * j + 4]
                    mask = np.zeros((4, 4), bool)
                    mask[0, :] = i > 0
                    mask[:, 0] |= j > 0
                    if np.abs(old[mask] - B[mask]).max() > CONTINUITY_TOLERANCE * max(1.0, float(np.abs(B).max())):
                        raise IgesError(f"{record.describe()}: patches ({i}, {j}) and its neighbours do not "
                                        f"meet; a discontinuous spline surface has no B-spline form")
                P[3 * i : 3 * i + 4, 3 * j : 3 * j + 4] = B
        s = _geometry(BSplineSurface, record.describe(), 3, 3, _breakpoint_knots(TU), _breakpoint_knots(TV), P)
    elif isinstance(record, SurfaceOfRevolution):
        s = revolve(curve_geometry(record.generatrix), *axis_of(record), record.start_angle, record.end_angle)
    else:
        raise IgesError(f"{record.describe()}: not a parametric surface")
    if record.transform is None:
        return s
    P = _transform(record, s.control_points)
    return BSplineSurface(s.degree_u, s.degree_v, s.knots_u, s.knots_v, P, s.weights)


def revolve(generatrix: BSplineCurve, origin, axis, angle0: float, angle1: float) -> BSplineSurface:
    """The surface swept by ``generatrix`` rotating about (origin, unit axis) from angle0 to
    angle1, exactly (The NURBS Book Alg. A8.1): u along the generatrix, v around."""
    knots_v, cs, f, wa = _arc_net(angle0, angle1)
    G = generatrix.control_points
    if G.shape[1] != 3:
        G = np.concatenate([G, np.zeros((G.shape[0], 3 - G.shape[1]))], axis=1)
    wg = np.ones(G.shape[0]) if generatrix.weights is None else generatrix.weights
    axis = np.asarray(axis, dtype=np.float64)
    rel = G - origin
    O = origin + (rel @ axis)[:, None] * axis  # foot on the axis
    X = G - O
    r = np.linalg.norm(X, axis=1)
    Xh = np.where(r[:, None] > 0, X / np.where(r > 0, r, 1.0)[:, None], 0.0)
    Yh = np.cross(axis, Xh)
    P = (O[:, None, :] + (r[:, None] * f[None, :])[..., None]
         * (cs[None, :, 0, None] * Xh[:, None, :] + cs[None, :, 1, None] * Yh[:, None, :]))
    # arc angles are absolute: angle 0 is the generatrix itself (Xh), as in IGES 5.3 §4.18
    W = wg[:, None] * wa[None, :]
    return _geometry(BSplineSurface, "surface of revolution", generatrix.degree, 2, generatrix.knots, knots_v, P, W)


@dataclass(frozen=True, eq=False)
class TrimmedSurfaceGeometry:
    """A 144 as geometry: the untrimmed surface and its boundary loops.

    Each loop is a list of 2-D curves in the IGES parameter space of the basis surface
    entity (for a 120: u = generatrix parameter, v = angle). ``outer`` is None when the
    boundary of the parameter domain bounds the surface.
    """

    surface: BSplineSurface
    outer: list | None
    inner: list


def _loop_curves(curve: Entity) -> list:
    if isinstance(curve, CompositeCurve):
        out = []
        for c in curve.curves:
            out.extend(_loop_curves(c))
        return out
    c = curve_geometry(curve)
    return [BSplineCurve(c.degree, c.knots, c.control_points[:, :2], c.weights)]


def _loop(cos: CurveOnSurface) -> list:
    if cos.parameter_curve is None:
        raise IgesError(f"{cos.describe()}: no parameter-space curve; cannot express the loop in (u, v)")
    return _loop_curves(cos.parameter_curve)


def to_geometry(record: Entity):
    """The geometry of one record: a BSplineCurve, a list of them (102), a BSplineSurface,
    or a :class:`TrimmedSurfaceGeometry` (144). 142 gives its model-space curve(s) when it
    has one, else its parameter-space loop. IgesError for entities with no geometry."""
    try:
        with np.errstate(all="ignore"):
            if isinstance(record, CompositeCurve):
                return [to_geometry(c) for c in record.curves]
            if isinstance(record, (BSplineCurve126, Line, CircularArc, ParametricSpline)):
                return curve_geometry(record)
            if isinstance(record, (BSplineSurface128, ParametricSplineSurface, SurfaceOfRevolution)):
                return surface_geometry(record)
            if isinstance(record, CurveOnSurface):
                if record.model_curve is not None:
                    return to_geometry(record.model_curve)
                return _loop(record)
            if isinstance(record, TrimmedSurface):
                outer = None if record.outer is None else _loop(record.outer)
                return TrimmedSurfaceGeometry(
                    surface_geometry(record.surface), outer, [_loop(c) for c in record.inner]
                )
    except RecursionError:
        raise IgesError(f"{record.describe()}: references nested too deeply") from None
    except BladesmithError as exc:
        if isinstance(exc, IgesError):
            raise
        raise IgesError(f"{record.describe()}: {exc}") from None
    raise IgesError(f"{record.describe()}: has no curve or surface geometry")


# -- surfaces as pieces readers take as they are ---------------------------------------------
#: Boundary iso-curves closer than this fraction of the surface's size make it closed.
CLOSED_TOL = 1e-9
#: Points compared along each boundary to decide closedness.
CLOSED_SAMPLES = 33


def _closed(surface: BSplineSurface, direction: str) -> bool:
    (a, b), (c, d) = surface.domain_u, surface.domain_v
    if direction == "u":
        t = np.linspace(c, d, CLOSED_SAMPLES)
        A, B = surface.evaluate(a, t), surface.evaluate(b, t)
    else:
        t = np.linspace(a, b, CLOSED_SAMPLES)
        A, B = surface.evaluate(t, c), surface.evaluate(t, d)
    return float(np.abs(A - B).max()) <= CLOSED_TOL * surface.size()


def surface_pieces(surface: BSplineSurface) -> list[BSplineSurface]:
    """``surface`` as the pieces a reader takes without repair, exactly (knot insertion).

    OpenCASCADE makes a closed surface periodic ("Surface is made periodic") and reports
    a surface that is only C0 across an interior knot ("Resulting Geom_Surface is
    C0-continuous"), both as warnings. So a surface is cut at every interior knot of
    multiplicity >= its degree (degree 2 and up; degree 1 is C0 everywhere) and, where it
    is closed in a direction with no such cut, in the middle of that direction. Returns
    ``[surface]`` when nothing needs cutting.
    """
    pieces = [surface]
    for direction in ("u", "v"):
        out = []
        for piece in pieces:
            p, U = (piece.degree_u, piece.knots_u) if direction == "u" else (piece.degree_v, piece.knots_v)
            a, b = piece.domain_u if direction == "u" else piece.domain_v
            values, counts = np.unique(U[(U > a) & (U < b)], return_counts=True)
            cuts = list(values[counts >= p]) if p >= 2 else []
            if not cuts and _closed(piece, direction):
                cuts = [0.5 * (a + b)]
            rest = piece
            for x in cuts:
                first, rest = split_surface(rest, direction, float(x))
                out.append(first)
            out.append(rest)
        pieces = out
    return pieces


# -- geometry -> records ------------------------------------------------------------------
def curve_from_geometry(curve: BSplineCurve, *, scale: float = 1.0, start=None, end=None,
                        label: str = "") -> BSplineCurve126:
    """A 126 record of a B-spline curve (2-D curves get z = 0), coordinates times ``scale``."""
    if not isinstance(curve, BSplineCurve):
        raise IgesError(f"expected a BSplineCurve, got {type(curve).__name__}")
    P = np.asarray(curve.control_points, dtype=np.float64) * scale
    if P.shape[1] not in (2, 3):
        raise IgesError(f"IGES curves are 2-D or 3-D; this curve has dimension {P.shape[1]}")
    return BSplineCurve126(curve.degree, curve.knots, P, curve.weights, start, end, label=label)


def surface_from_geometry(surface: BSplineSurface, *, scale: float = 1.0, label: str = "") -> BSplineSurface128:
    """A 128 record of a B-spline surface, coordinates times ``scale``."""
    if not isinstance(surface, BSplineSurface):
        raise IgesError(f"expected a BSplineSurface, got {type(surface).__name__}")
    if surface.dim != 3:
        raise IgesError(f"IGES surfaces are 3-D; this surface has dimension {surface.dim}")
    return BSplineSurface128(
        surface.degree_u, surface.degree_v, surface.knots_u, surface.knots_v,
        np.asarray(surface.control_points) * scale, surface.weights, label=label,
    )
