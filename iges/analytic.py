"""The analytic surfaces of IGES 5.3 that B-rep writers use under 510 faces (and 144/142):
plane surface 190, right circular cylindrical surface 192, right circular conical surface
194, spherical surface 196 and toroidal surface 198 (IGES 5.3 §4.24-4.28 of the B-rep
entities, forms 0 unparameterised and 1 parameterised).

Each is read from its location point (116), axis and reference directions (123) and
radii; the frame is (X, Y, A) with A the axis (the normal of a plane), X the reference
direction made perpendicular to A (any perpendicular when form 0 gives none) and
Y = A x X. Surface points, with u and v in radians where they are angles:

* 190: S(u, v) = L + u X + v Y
* 192: S(u, v) = L + R (cos u X + sin u Y) + v A
* 194: S(u, v) = L + (R + v tan a) (cos u X + sin u Y) + v A   (a the semi-angle)
* 196: S(u, v) = C + R (cos v (cos u X + sin u Y) + sin v A),   v in [-pi/2, pi/2]
* 198: S(u, v) = C + (R + r cos v) (cos u X + sin u Y) + r sin v A

:func:`analytic_uv` inverts these in closed form, so a face's trimming loops can be
mapped from its model-space edges whatever convention a writer used for its
parameter-space curves. :func:`analytic_nurbs` gives the exact rational NURBS of a patch
[u0, u1] x [v0, v1] (circular arcs as rational quadratics, The NURBS Book 2e §7.5 and
Alg. A7.1; lines as degree 1; the tensor product of an arc net and a line or of two arc
nets, §8.5 surfaces of revolution). Every analytic surface has one.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..geometry.errors import IgesError
from ..geometry.nurbs import BSplineSurface
from .records import Entity, GenericEntity

#: A point of a loop this close to the axis (as a fraction of the surface's size) has no
#: angle of its own (a cone's apex, a sphere's pole): it takes its neighbour's.
AXIS_FRACTION = 1e-9


@dataclass(frozen=True, eq=False)
class AnalyticSurface(Entity):
    """Types 190-198 as one record: ``kind`` names the surface; ``location`` the point L or
    centre C; ``axis`` A (unit); ``reference`` X (unit, perpendicular to A); ``radius``
    R (major radius of a torus); ``minor_radius`` r (torus); ``semi_angle`` a in radians
    (cone)."""

    type_number: ClassVar[int] = 190
    surface_type: int = 190
    surface_form: int = 0
    location: np.ndarray = field(default_factory=lambda: np.zeros(3))
    axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    reference: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))
    radius: float = 0.0
    minor_radius: float = 0.0
    semi_angle: float = 0.0
    sources: tuple = ()  # the 116 point and 123 directions it was read from

    @property
    def form(self):
        return self.surface_form

    def references(self):
        return self.sources

    def describe(self) -> str:
        seq = self.directory.sequence if self.directory is not None else "?"
        return f"{type(self).__name__} (type {self.surface_type}) at DE {seq}"


NAMES = {190: "plane surface", 192: "cylindrical surface", 194: "conical surface", 196: "spherical surface",
         198: "toroidal surface"}


def _point(e, what: str) -> np.ndarray:
    """Coordinates of a 116 point (its own 124 applied)."""
    from .convert import _transform
    from .reader import _parse_real

    if not isinstance(e, GenericEntity) or e.entity_type != 116 or len(e.parameters) < 3:
        raise IgesError(f"{what} must be a type 116 point; got {e.describe() if isinstance(e, Entity) else e!r}")
    xyz = np.array([_parse_real(t, None if k < 2 else 0.0) for k, t in enumerate(e.parameters[:3])], dtype=object)
    if any(x is None for x in xyz):
        raise IgesError(f"{what}: the point's coordinates are not reals: {list(e.parameters[:3])}")
    P = np.array(xyz, dtype=np.float64)
    return _transform(e, P[None])[0] if e.transform is not None else P


def _direction(e, what: str) -> np.ndarray:
    """A 123 direction, unit length (only the rotation of its own 124 applies)."""
    from .importer import _chain_matrix
    from .reader import _parse_real

    if not isinstance(e, GenericEntity) or e.entity_type != 123 or len(e.parameters) < 3:
        raise IgesError(f"{what} must be a type 123 direction; got {e.describe() if isinstance(e, Entity) else e!r}")
    d = [_parse_real(t) for t in e.parameters[:3]]
    if any(x is None for x in d):
        raise IgesError(f"{what}: the direction's components are not reals: {list(e.parameters[:3])}")
    d = np.array(d, dtype=np.float64)
    if e.transform is not None:
        d = _chain_matrix(e.transform)[0] @ d
    n = float(np.linalg.norm(d))
    if not (math.isfinite(n) and n > 0):
        raise IgesError(f"{what}: zero direction {d.tolist()}")
    return d / n


def _frame(axis: np.ndarray, ref: np.ndarray | None, what: str) -> np.ndarray:
    """X: ``ref`` made perpendicular to ``axis`` (or any perpendicular)."""
    if ref is not None:
        x = ref - (ref @ axis) * axis
        n = float(np.linalg.norm(x))
        if n > 1e-12:
            return x / n
    helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
    x = np.cross(axis, helper)
    return x / np.linalg.norm(x)


def _builder(surface_type: int):
    def build(p, r, form):
        what = f"{p.where} ({NAMES[surface_type]})"
        sources = []

        def r(j, role, _resolve=r):
            sources.append(_resolve(j, role))
            return sources[-1]

        L = _point(r(p.pointer("DELOC/DECENT (point)"), "location"), f"{what}: location")
        radius, minor, angle, axis, ref = 0.0, 0.0, 0.0, np.array([0.0, 0.0, 1.0]), None
        if surface_type == 190:
            axis = _direction(r(p.pointer("DENRML (normal)"), "normal"), f"{what}: normal")
        elif surface_type in (192, 194):
            axis = _direction(r(p.pointer("DEAXIS (axis)"), "axis"), f"{what}: axis")
            radius = p.real("RADIUS")
            if surface_type == 194:
                angle = math.radians(p.real("SANGLE (semi-angle, degrees)"))
                if not 0.0 < angle < 0.5 * math.pi:
                    raise IgesError(f"{what}: semi-angle {math.degrees(angle)!r} degrees outside (0, 90)")
        elif surface_type == 196:
            radius = p.real("RADIUS")
            if form == 1:
                axis = _direction(r(p.pointer("DEAXIS (axis)"), "axis"), f"{what}: axis")
        else:
            axis = _direction(r(p.pointer("DEAXIS (axis)"), "axis"), f"{what}: axis")
            radius = p.real("MAJRAD (major radius)")
            minor = p.real("MINRAD (minor radius)")
            if not 0.0 < minor:
                raise IgesError(f"{what}: minor radius {minor!r} must be > 0")
        if form == 1:
            ref = _direction(r(p.pointer("DEREFD (reference direction)"), "reference direction"),
                             f"{what}: reference direction")
        if surface_type in (192, 196, 198) and not (math.isfinite(radius) and radius > 0):
            raise IgesError(f"{what}: radius {radius!r} must be > 0")
        if surface_type == 194 and not (math.isfinite(radius) and radius >= 0):
            raise IgesError(f"{what}: radius {radius!r} must be >= 0")
        return dict(surface_type=surface_type, surface_form=form, location=L, axis=axis,
                    reference=_frame(axis, ref, what), radius=float(radius), minor_radius=float(minor),
                    semi_angle=float(angle), sources=tuple(sources))

    return build


def lenient_builders() -> dict:
    return {t: (AnalyticSurface, _builder(t)) for t in NAMES}


# -- evaluation and inversion -------------------------------------------------------------
def _axes(s: AnalyticSurface):
    X = np.asarray(s.reference, float)
    A = np.asarray(s.axis, float)
    return X, np.cross(A, X), A


def analytic_points(s: AnalyticSurface, u, v) -> np.ndarray:
    """S(u, v) of the module docstring, shape broadcast(u, v) + (3,), without the surface's
    own 124 (the caller applies it)."""
    u, v = np.broadcast_arrays(np.asarray(u, np.float64), np.asarray(v, np.float64))
    X, Y, A = _axes(s)
    L = np.asarray(s.location, float)
    cu, su = np.cos(u)[..., None], np.sin(u)[..., None]
    radial = cu * X + su * Y
    t = s.surface_type
    if t == 190:
        return L + u[..., None] * X + v[..., None] * Y
    if t == 192:
        return L + s.radius * radial + v[..., None] * A
    if t == 194:
        return L + (s.radius + v * math.tan(s.semi_angle))[..., None] * radial + v[..., None] * A
    if t == 196:
        cv, sv = np.cos(v)[..., None], np.sin(v)[..., None]
        return L + s.radius * (cv * radial + sv * A)
    cv, sv = np.cos(v)[..., None], np.sin(v)[..., None]
    return L + (s.radius + s.minor_radius * cv) * radial + s.minor_radius * sv * A


def size_of(s: AnalyticSurface) -> float:
    return float(max(s.radius + s.minor_radius, np.abs(s.location).max(), 1e-300))


def analytic_uv(s: AnalyticSurface, P: np.ndarray) -> np.ndarray:
    """(u, v) of model points P (n, 3) on the surface (its own 124 already undone), u in
    (-pi, pi]. Points on the axis (no angle) get NaN for u."""
    X, Y, A = _axes(s)
    d = np.asarray(P, np.float64) - np.asarray(s.location, float)
    x, y, z = d @ X, d @ Y, d @ A
    t = s.surface_type
    if t == 190:
        return np.stack([x, y], axis=-1)
    rho = np.hypot(x, y)
    u = np.arctan2(y, x)
    u[rho <= AXIS_FRACTION * size_of(s)] = np.nan
    if t in (192, 194):
        v = z
    elif t == 196:
        v = np.arctan2(z, rho)
    else:
        v = np.arctan2(z, rho - s.radius)
    return np.stack([u, v], axis=-1)


def unwrap_loop(s: AnalyticSurface, edges: list, jumps: dict | None = None) -> np.ndarray:
    """A closed uv polyline from the uv polylines of a loop's edges in order (from
    :func:`analytic_uv`): each edge's angles continue from the previous edge's end
    without 2 pi jumps, and points on the axis take their neighbour's angle along the same
    edge. ``jumps``: {number of edges before it: step} for the loop's pole crossings (a
    vertex edge whose parameter curve steps u by ``step``): the loop moves on by a full
    turn in u, in the step's sign (360 degrees or 2 pi, whatever the writer's unit)."""
    jumps = jumps or {}
    out, last = [], None
    angular_v = s.surface_type == 198
    for k, e in enumerate(edges):
        e = np.array(e, dtype=np.float64)
        if last is not None and abs(jumps.get(k, 0.0)) > 1e-9 and s.surface_type != 190:
            last = last + np.array([math.copysign(2 * math.pi, jumps[k]), 0.0])
        if s.surface_type != 190:
            u = e[:, 0]
            ok = np.isfinite(u)
            if not ok.any():
                continue  # an edge along the axis only (degenerate): no angle to give
            idx = np.where(ok, np.arange(len(u)), -1)
            np.maximum.accumulate(idx, out=idx)  # the previous point off the axis
            idx[idx < 0] = int(np.argmax(ok))
            e[:, 0] = np.unwrap(u[idx])
            if angular_v:
                e[:, 1] = np.unwrap(e[:, 1])
            if last is not None:  # continue from the previous edge's end
                e[:, 0] += 2 * math.pi * np.round((last[0] - e[0, 0]) / (2 * math.pi))
                if angular_v:
                    e[:, 1] += 2 * math.pi * np.round((last[1] - e[0, 1]) / (2 * math.pi))
        out.append(e)
        last = e[-1]
    if not out:
        raise IgesError("the loop has no edge off the axis")
    return np.concatenate(out)


# -- exact NURBS -----------------------------------------------------------------------------
def _arc(t0: float, t1: float):
    """Knots, (cos, sin) directions, radius factors and weights of a unit arc t0..t1."""
    from .convert import _arc_net

    return _arc_net(t0, t1)


def analytic_nurbs(s: AnalyticSurface, u_range, v_range) -> BSplineSurface:
    """The exact rational NURBS of the patch [u0, u1] x [v0, v1] of ``s`` (its own 124 not
    applied). The NURBS parameters are not the angles (rational arcs are not arc-length
    parameterised); its points are the same set."""
    (u0, u1), (v0, v1) = (float(a) for a in u_range), (float(b) for b in v_range)
    if not (u1 > u0 and v1 > v0):
        raise IgesError(f"{s.describe()}: empty patch u {u0}..{u1}, v {v0}..{v1}")
    X, Y, A = _axes(s)
    L = np.asarray(s.location, float)
    t = s.surface_type
    line = np.array([0.0, 0.0, 1.0, 1.0])
    if t == 190:
        P = np.array([[L + a * X + b * Y for b in (v0, v1)] for a in (u0, u1)])
        return BSplineSurface(1, 1, line, line, P)
    ku, cs, f, wu = _arc(u0, u1)
    radial = f[:, None] * (cs[:, :1] * X + cs[:, 1:] * Y)  # (m, 3), with the arc's radius factors
    if t in (192, 194):
        k = 0.0 if t == 192 else math.tan(s.semi_angle)
        rows = [L + (s.radius + k * v) * radial + v * A for v in (v0, v1)]
        P = np.stack(rows, axis=1)
        W = np.stack([wu, wu], axis=1)
        return BSplineSurface(2, 1, ku, line, P, W)
    if t == 196:
        v0, v1 = max(v0, -0.5 * math.pi), min(v1, 0.5 * math.pi)
    kv, csv, fv, wv = _arc(v0, v1)
    # the meridian circle (radius r around the tube centre R, or the sphere's great circle)
    R, r = (0.0, s.radius) if t == 196 else (s.radius, s.minor_radius)
    rho = R + r * fv * csv[:, 0]  # distances from the axis of the meridian's control points
    z = r * fv * csv[:, 1]
    # The NURBS Book §8.5: control point (i, j) = the meridian's point j turned by arc i
    P = L + rho[None, :, None] * radial[:, None, :] + z[None, :, None] * A
    W = wu[:, None] * wv[None, :]
    return BSplineSurface(2, 2, ku, kv, P, W)
