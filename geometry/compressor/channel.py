"""The meridional channel M (Casey 1983, "The Meridional Channel (M)", Figs. 4b, 5, 7).

A string of patches linear in v in the (z, r) plane: v = 0 is the hub contour, v = 1 the
shroud contour, and the global parameter U runs over [0, n_patches] from inlet to outlet.
Rotating it about the z axis gives the hub and shroud surfaces of revolution.

Skeletal data (Casey's items a–c): the patch-corner defining points (radii and axial
positions), the wall direction at each corner, and for every curved patch two fractions
that place its interior polygon points along the sides of its polygon. Two patch kinds:

- ``degree = 1``: a straight wall (inlet pipe, vaneless diffuser, return passage);
- ``degree = 4``: a bend. Its polygon is P_0, P_1, C, P_3, P_4 where C is the intersection
  of the wall tangents at the two corners, P_1 = P_0 + f_a (C - P_0) and
  P_3 = P_4 + f_b (C - P_4). P_0, P_1, C are collinear and so are C, P_3, P_4, so the
  curvature is zero at both ends (Casey 1983 property c, Fig. 3a with b = 0), as it is on
  a straight patch: slope and curvature are continuous across every junction by
  construction, and the fractions change the fullness of each bend (Casey's "fractions of
  the length of the sides of the polygon").

Wall angles are degrees from the +z direction towards +r (0 axial, 90 radially outwards,
-90 radially inwards, 180 axially backwards).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DefinitionError, GeometryError
from ..nurbs import BSplineCurve, BSplineSurface
from .bezier import BezierCurve, BezierString, PatchString

#: Wall angles given next to a straight patch must match its direction to this (deg).
ANGLE_MATCH_TOLERANCE_DEG = 1e-6
#: Samples per patch when checking that hub and shroud do not cross.
CROSSING_SAMPLES_PER_PATCH = 64
#: Tangent lines closer to parallel than this (sine of the angle) do not define a bend.
PARALLEL_SINE_TOLERANCE = 1e-9


def full_circle():
    """Knots, unit-circle points (9, 2) and weights of the exact rational quadratic full
    circle of four 90-degree arcs (The NURBS Book 2e §7.5, Ex. 7.2)."""
    w = np.sqrt(0.5)
    pts = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]], dtype=float)
    weights = np.array([1, w, 1, w, 1, w, 1, w, 1])
    knots = np.array([0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1]) * 2.0 * np.pi
    return knots, pts, weights


def surface_of_revolution(contour: BSplineCurve) -> BSplineSurface:
    """Rotate a (z, r) contour about the z axis: an exact rational surface of degree
    (p, 2), u along the contour, v the angle φ in [0, 2π] (The NURBS Book 2e §8.5)."""
    if contour.dim != 2:
        raise GeometryError(f"a meridional contour is a (z, r) curve, got dimension {contour.dim}")
    knots_v, circle, w_circle = full_circle()
    z, r = contour.control_points[:, 0], contour.control_points[:, 1]
    w = contour.weights if contour.weights is not None else np.ones(len(z))
    P = np.empty((len(z), len(circle), 3))
    P[..., 0] = r[:, None] * circle[None, :, 0]
    P[..., 1] = r[:, None] * circle[None, :, 1]
    P[..., 2] = z[:, None]
    return BSplineSurface(contour.degree, 2, contour.knots, knots_v, P, w[:, None] * w_circle[None, :])


@dataclass(frozen=True, eq=False)
class MeridionalChannel:
    """Casey's M: ``patches`` is a 2-D :class:`PatchString` in (z, r); lower = hub,
    upper = shroud; U in [0, count]."""

    patches: PatchString

    @property
    def count(self) -> int:
        return self.patches.count

    @property
    def hub(self) -> BezierString:
        return self.patches.lower

    @property
    def shroud(self) -> BezierString:
        return self.patches.upper

    def wall(self, which: str) -> BezierString:
        if which == "hub":
            return self.hub
        if which == "shroud":
            return self.shroud
        raise GeometryError(f"wall must be 'hub' or 'shroud', got {which!r}")

    def evaluate(self, U, v) -> np.ndarray:
        """(z, r) at (U, v)."""
        return self.patches.evaluate(U, v)

    def hub_surface(self) -> BSplineSurface:
        return surface_of_revolution(self.hub.to_bspline())

    def shroud_surface(self) -> BSplineSurface:
        return surface_of_revolution(self.shroud.to_bspline())

    def junction_report(self) -> dict:
        """Slope-angle and curvature jumps at the patch junctions of each wall (rad, 1/m):
        {"hub": (angles, curvatures), "shroud": ...}; both zero for a valid channel."""
        out = {}
        for which in ("hub", "shroud"):
            s = self.wall(which)
            angles, curvs = [], []
            for j in range(s.count - 1):
                a, b = s.segments[j], s.segments[j + 1]
                ta = a.hodograph().evaluate(1.0)
                tb = b.hodograph().evaluate(0.0)
                angles.append(abs(np.arctan2(ta[0] * tb[1] - ta[1] * tb[0], ta @ tb)))
                curvs.append(abs(_signed_curvature(a, 1.0) - _signed_curvature(b, 0.0)))
            out[which] = (np.array(angles), np.array(curvs))
        return out

    def check(self, path: str | None = None) -> None:
        """Refuse a channel whose hub and shroud contours touch or cross, or that reaches
        r < 0: the (U, v) -> (z, r) map must keep one orientation everywhere."""
        U = np.linspace(0.0, self.count, self.count * CROSSING_SAMPLES_PER_PATCH + 1)
        H = self.hub.derivatives(U, 1)
        T = self.shroud.derivatives(U, 1)
        width = T[0] - H[0]
        for v in (0.0, 0.5, 1.0):
            dU = (1 - v) * H[1] + v * T[1]
            jac = dU[:, 0] * width[:, 1] - dU[:, 1] * width[:, 0]
            sign = np.sign(np.median(jac))
            bad = np.nonzero(jac * sign <= 0.0)[0]
            if sign == 0 or bad.size:
                j = int(U[bad[0]]) if bad.size else 0
                raise DefinitionError(
                    f"hub and shroud contours cross or touch in patch {min(j, self.count - 1)} "
                    f"(near U = {U[bad[0]] if bad.size else 0:.3f})",
                    path=path, field="channel.shroud_r",
                )
        # a crossing between non-corresponding points: the polylines must not intersect
        if _polylines_intersect(H[0], T[0]):
            raise DefinitionError("hub and shroud contours cross", path=path, field="channel.shroud_r")
        for which, P in (("hub", H[0]), ("shroud", T[0])):
            if np.any(P[:, 1] < 0.0):
                raise DefinitionError(f"the {which} contour reaches r < 0", path=path, field=f"channel.{which}_r")


def _signed_curvature(curve: BezierCurve, u: float) -> float:
    d = curve.derivatives(u, 2)
    return float((d[1, 0] * d[2, 1] - d[1, 1] * d[2, 0]) / np.linalg.norm(d[1]) ** 3)


def _polylines_intersect(A: np.ndarray, B: np.ndarray) -> bool:
    """Whether two 2-D polylines have a proper crossing (vectorised segment test)."""
    a0, a1 = A[:-1, None, :], A[1:, None, :]
    b0, b1 = B[None, :-1, :], B[None, 1:, :]

    def orient(p, q, r):
        return (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0])

    d1, d2 = orient(b0, b1, a0), orient(b0, b1, a1)
    d3, d4 = orient(a0, a1, b0), orient(a0, a1, b1)
    return bool(np.any((d1 * d2 < 0) & (d3 * d4 < 0)))


# -- skeletal data --------------------------------------------------------------------------
@dataclass(frozen=True)
class WallSkeleton:
    """One wall's skeletal data: corners (n+1, 2) as (z, r); angles (n+1,) in degrees with
    NaN for "take it from the adjacent straight patch"; fractions (n, 2) (f_a, f_b) of
    each bend."""

    corners: np.ndarray
    angles: np.ndarray
    fractions: np.ndarray


def _unit(angle_deg: float) -> np.ndarray:
    a = np.radians(angle_deg)
    return np.array([np.cos(a), np.sin(a)])


def _wall_string(wall: WallSkeleton, degrees, which: str, path: str | None) -> BezierString:
    C = np.asarray(wall.corners, dtype=float)
    angles = np.array(wall.angles, dtype=float)
    # angles of straight patches fix the corner angles next to them
    for j, deg in enumerate(degrees):
        if deg != 1:
            continue
        chord = C[j + 1] - C[j]
        if np.linalg.norm(chord) == 0.0:
            raise DefinitionError(f"straight patch {j} has zero length", path=path, field=f"channel.{which}_z")
        a = np.degrees(np.arctan2(chord[1], chord[0]))
        for k in (j, j + 1):
            if np.isnan(angles[k]):
                angles[k] = a
            elif abs((angles[k] - a + 180.0) % 360.0 - 180.0) > ANGLE_MATCH_TOLERANCE_DEG:
                raise DefinitionError(
                    f"corner {k} angle {wall.angles[k]} deg does not match the straight patch {j} ({a:.6g} deg)",
                    path=path, field=f"channel.{which}_angle",
                )
    segs = []
    for j, deg in enumerate(degrees):
        P0, P4 = C[j], C[j + 1]
        if deg == 1:
            segs.append(BezierCurve(np.array([P0, P4])))
            continue
        for k in (j, j + 1):
            if np.isnan(angles[k]):
                raise DefinitionError(
                    f"corner {k} needs a wall angle (it is not next to a straight patch)",
                    path=path, field=f"channel.{which}_angle",
                )
        t0, t1 = _unit(angles[j]), _unit(angles[j + 1])
        # P0 + s t0 = P4 - w t1
        M = np.column_stack([t0, t1])
        if abs(np.linalg.det(M)) < PARALLEL_SINE_TOLERANCE:
            raise DefinitionError(
                f"patch {j}: the wall directions at corners {j} and {j + 1} are parallel; add a corner",
                path=path, field=f"channel.{which}_angle",
            )
        s, w = np.linalg.solve(M, P4 - P0)
        if s <= 0.0 or w <= 0.0:
            raise DefinitionError(
                f"patch {j}: the wall tangents at corners {j} and {j + 1} do not meet ahead of the bend",
                path=path, field=f"channel.{which}_angle",
            )
        corner = P0 + s * t0
        fa, fb = wall.fractions[j]
        segs.append(BezierCurve(np.array([P0, P0 + fa * (corner - P0), corner, P4 + fb * (corner - P4), P4])))
    return BezierString(tuple(segs))


def channel_from_skeleton(degrees, hub: WallSkeleton, shroud: WallSkeleton, path: str | None = None) -> MeridionalChannel:
    """Build and check the channel from skeletal data (module docstring)."""
    degrees = [int(d) for d in degrees]
    for j, d in enumerate(degrees):
        if d not in (1, 4):
            raise DefinitionError(f"patch {j}: degree must be 1 (straight) or 4 (bend), got {d}", path=path, field="channel.degrees")
    n = len(degrees)
    for which, wall in (("hub", hub), ("shroud", shroud)):
        if np.shape(wall.corners) != (n + 1, 2):
            raise DefinitionError(
                f"{n} patches need {n + 1} corners, got {np.shape(wall.corners)[0]}", path=path, field=f"channel.{which}_z"
            )
        if np.shape(wall.angles) != (n + 1,):
            raise DefinitionError(f"expected {n + 1} angles", path=path, field=f"channel.{which}_angle")
        fr = np.asarray(wall.fractions, dtype=float)
        if fr.shape != (n, 2):
            raise DefinitionError(f"expected {n} pairs of fractions", path=path, field=f"channel.{which}_fractions")
        if np.any((fr <= 0.0) | (fr >= 1.0)):
            raise DefinitionError("fractions must lie in (0, 1)", path=path, field=f"channel.{which}_fractions")
        if np.any(np.asarray(wall.corners)[:, 1] < 0.0):
            raise DefinitionError("radii must be >= 0", path=path, field=f"channel.{which}_r")
    channel = MeridionalChannel(
        PatchString(_wall_string(hub, degrees, "hub", path), _wall_string(shroud, degrees, "shroud", path))
    )
    channel.check(path)
    return channel
