"""Bernstein–Bézier curves, patches linear in v, and strings of them (Casey 1983).

Casey (1983), "Bernstein–Bezier Surfaces": a Bézier curve of degree n is
R(u) = Σ_k B_k^n(u) P_k with the Bernstein polynomials B_k^n(u) = C(n,k) u^k (1-u)^(n-k)
(Eqs. 4–8); derivatives by Eq. 9, d/du B_k^n = n (B_{k-1}^{n-1} - B_k^{n-1}); degree
elevation (property e, Forrest); the end curvature depends on the first three polygon
points only (property c, Fig. 3a). A patch linear in v joins two Bézier curves by straight
lines, R(u, v) = Σ_k [(1-v) P_k^0 + v P_k^1] B_k^n(u) (Eq. 10, Fig. 4a); patches are joined
into strings (Fig. 4b) whose global parameter U runs over [0, n_patches], patch j
covering [j, j+1].

Every object converts exactly to the B-spline types of :mod:`..nurbs` (a Bézier curve is a
B-spline with knots 0^(n+1) 1^(n+1); a string has interior knots of multiplicity p, The
NURBS Book 2e §5.4), so the Blender display and IGES take them unchanged.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from math import comb

import numpy as np

from ..errors import GeometryError
from ..nurbs import BSplineCurve, BSplineSurface

#: Two strings/patches are joined only if their shared corner points agree to this
#: (relative to the size of the polygon).
JOIN_TOLERANCE = 1e-12


def bernstein(degree: int, u) -> np.ndarray:
    """Bernstein polynomials B_k^n(u), k = 0..n (Casey 1983, Eq. 7). Shape u.shape + (n+1,)."""
    n = int(degree)
    if n < 0:
        raise GeometryError(f"degree must be >= 0, got {degree}")
    u = np.asarray(u, dtype=float)
    k, binom = _binomials(n)
    if u.size < BERNSTEIN_POWER_SIZE:
        u = u[..., None]
        return binom * u**k * (1.0 - u) ** (n - k)
    # many parameters: powers by repeated products (float powers cost more than products)
    out = np.empty(u.shape + (n + 1,))
    out[..., 0] = 1.0
    for i in range(1, n + 1):
        np.multiply(out[..., i - 1], u, out=out[..., i])
    w = 1.0 - u
    t = np.ones_like(u)
    for i in range(n - 1, -1, -1):
        t *= w
        out[..., i] *= t
    out *= binom
    return out


#: Below this many parameters :func:`bernstein` uses powers (fewer numpy calls).
BERNSTEIN_POWER_SIZE = 256


@lru_cache(maxsize=64)
def _binomials(n: int) -> tuple[np.ndarray, np.ndarray]:
    k = np.arange(n + 1)
    return k, np.array([comb(n, i) for i in range(n + 1)], dtype=float)


def _as_polygon(points, what: str) -> np.ndarray:
    P = np.array(points, dtype=float)
    if P.ndim == 1:
        P = P[:, None]
    if P.ndim != 2 or P.shape[0] < 1:
        raise GeometryError(f"{what}: expected shape (n+1, dim), got {P.shape}")
    if not np.all(np.isfinite(P)):
        raise GeometryError(f"{what}: contains non-finite values")
    P.setflags(write=False)
    return P


def elevation_matrix(degree: int, times: int = 1) -> np.ndarray:
    """Matrix E with Q = E P raising a degree-n polygon to degree n+times.

    One step: Q_i = i/(n+1) P_{i-1} + (1 - i/(n+1)) P_i (Casey 1983 property e, after
    Forrest; The NURBS Book 2e Eq. 5.36).
    """
    E = np.eye(degree + 1)
    n = degree
    for _ in range(int(times)):
        step = np.zeros((n + 2, n + 1))
        for i in range(n + 2):
            a = i / (n + 1)
            if i > 0:
                step[i, i - 1] = a
            if i <= n:
                step[i, i] = 1.0 - a
        E = step @ E
        n += 1
    return E


@dataclass(frozen=True, eq=False)
class BezierCurve:
    """A Bézier curve of any degree (Casey 1983, Eq. 8).

    control_points: (n+1, dim) polygon points P_0..P_n; degree n = len - 1. Parameter
    u in [0, 1] (evaluation outside extrapolates the polynomial).
    """

    control_points: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "control_points", _as_polygon(self.control_points, "control_points"))

    @property
    def degree(self) -> int:
        return self.control_points.shape[0] - 1

    @property
    def dim(self) -> int:
        return self.control_points.shape[1]

    def evaluate(self, u) -> np.ndarray:
        """Points R(u), shape u.shape + (dim,)."""
        return bernstein(self.degree, u) @ self.control_points

    def hodograph(self) -> "BezierCurve":
        """dR/du as a Bézier curve of degree n-1 with points n (P_{k+1} - P_k) (Eq. 9)."""
        P = self.control_points
        if self.degree == 0:
            return BezierCurve(np.zeros_like(P))
        return BezierCurve(self.degree * np.diff(P, axis=0))

    def derivatives(self, u, order: int = 1) -> np.ndarray:
        """R and its derivatives up to ``order``: shape (order+1,) + u.shape + (dim,)."""
        out = []
        curve = self
        for _ in range(int(order) + 1):
            out.append(curve.evaluate(u))
            curve = curve.hodograph()
        return np.stack(out)

    def curvature(self, u) -> np.ndarray:
        """Curvature |R' x R''| / |R'|^3 (2-D or 3-D), shape u.shape."""
        d = self.derivatives(u, 2)
        d1, d2 = d[1], d[2]
        if self.dim == 2:
            cross = np.abs(d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0])
        else:
            cross = np.linalg.norm(np.cross(d1, d2), axis=-1)
        return cross / np.linalg.norm(d1, axis=-1) ** 3

    def elevate(self, times: int = 1) -> "BezierCurve":
        """The same curve at degree n + times (Casey 1983 property e)."""
        return BezierCurve(elevation_matrix(self.degree, times) @ self.control_points)

    def split(self, t: float) -> tuple["BezierCurve", "BezierCurve"]:
        """de Casteljau subdivision at u = t (The NURBS Book 2e §1.4)."""
        P = np.array(self.control_points)
        left, right = [P[0]], [P[-1]]
        while P.shape[0] > 1:
            P = (1.0 - t) * P[:-1] + t * P[1:]
            left.append(P[0])
            right.append(P[-1])
        return BezierCurve(np.array(left)), BezierCurve(np.array(right[::-1]))

    def reversed(self) -> "BezierCurve":
        return BezierCurve(self.control_points[::-1])

    def end_curvature(self, end: int = 0) -> float:
        """Curvature at u = 0 (end 0) or u = 1 (end 1) from the first (last) three polygon
        points only: κ = (n-1)/n · h / a², a = |P_1 - P_0|, h the distance of P_2 from the
        line P_0 P_1 (Casey 1983 property c, Fig. 3a)."""
        P = self.control_points if end == 0 else self.control_points[::-1]
        n = self.degree
        if n < 2:
            return 0.0
        t = P[1] - P[0]
        a = float(np.linalg.norm(t))
        w = P[2] - P[1]
        h = float(np.linalg.norm(w - (w @ t) / (a * a) * t))
        return (n - 1) / n * h / (a * a)

    def to_bspline(self) -> BSplineCurve:
        """The same curve as a clamped B-spline with knots 0^(n+1) 1^(n+1)."""
        n = self.degree
        if n < 1:
            raise GeometryError("a B-spline needs degree >= 1")
        knots = np.r_[np.zeros(n + 1), np.ones(n + 1)]
        return BSplineCurve(n, knots, np.array(self.control_points))


def third_point_for_end_curvature(p0, p1, direction, curvature: float, degree: int, along: float) -> np.ndarray:
    """P_2 giving curvature κ at u = 0 of a degree-n curve starting P_0, P_1 (Fig. 3a).

    P_2 = P_1 + along · a · t + h · d, with t the unit tangent (P_1 - P_0)/a, d the unit
    component of ``direction`` normal to t (the side the curve bends to), and
    h = n/(n-1) · κ a² (inverting :meth:`BezierCurve.end_curvature`). ``along`` is the
    tangential offset of P_2 beyond P_1 as a fraction of a = |P_1 - P_0|. κ = 0 puts the
    three points on a straight line (b = 0 in Casey's Fig. 3a).
    """
    p0, p1, direction = (np.asarray(x, dtype=float) for x in (p0, p1, direction))
    if degree < 2:
        raise GeometryError(f"the end curvature needs degree >= 2, got {degree}")
    t = p1 - p0
    a = float(np.linalg.norm(t))
    if a == 0.0:
        raise GeometryError("P_0 and P_1 coincide: the end tangent is undefined")
    t = t / a
    d = direction - (direction @ t) * t
    nd = float(np.linalg.norm(d))
    if nd == 0.0 and curvature != 0.0:
        raise GeometryError("the bending direction is parallel to the end tangent")
    d = d / nd if nd > 0 else d
    h = degree / (degree - 1) * float(curvature) * a * a
    return p1 + along * a * t + h * d


def bernstein_function(coefficients, u) -> np.ndarray:
    """A scalar Bernstein polynomial Σ c_k B_k^n(u) (used for β(m) and δ(m))."""
    c = np.asarray(coefficients, dtype=float)
    return bernstein(c.size - 1, u) @ c


def bernstein_function_derivative(coefficients, u) -> np.ndarray:
    """d/du Σ c_k B_k^n(u) = n Σ (c_{k+1} - c_k) B_k^{n-1}(u) (Casey 1983, Eq. 9)."""
    c = np.asarray(coefficients, dtype=float)
    if c.size < 2:
        return np.zeros(np.shape(u))
    return bernstein(c.size - 2, u) @ ((c.size - 1) * np.diff(c))


def _split_parameter(U, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Global U in [0, n] -> (patch index j, local u in [0, 1]); outside, the end patches
    extrapolate."""
    U = np.asarray(U, dtype=float)
    # np.minimum/np.maximum: np.clip on these integers, without its wrapper's cost
    j = np.minimum(np.maximum(np.floor(U).astype(int), 0), n - 1)
    return j, U - j


@dataclass(frozen=True, eq=False)
class BezierString:
    """Bézier curves joined end to end (Casey 1983, Fig. 4b along one edge).

    segments: tuple of :class:`BezierCurve` of one dimension; segment j covers the global
    parameter U in [j, j+1], so U runs over [0, len(segments)].
    """

    segments: tuple

    def __post_init__(self):
        segs = tuple(s if isinstance(s, BezierCurve) else BezierCurve(s) for s in self.segments)
        if not segs:
            raise GeometryError("a Bézier string needs at least one segment")
        dims = {s.dim for s in segs}
        if len(dims) != 1:
            raise GeometryError(f"segments of one string must share a dimension, got {sorted(dims)}")
        scale = max(1.0, max(float(np.abs(s.control_points).max()) for s in segs))
        for j in range(len(segs) - 1):
            gap = float(np.linalg.norm(segs[j].control_points[-1] - segs[j + 1].control_points[0]))
            if gap > JOIN_TOLERANCE * scale:
                raise GeometryError(f"segments {j} and {j + 1} do not meet: gap {gap:.3g}")
        object.__setattr__(self, "segments", segs)
        # for vectorised evaluation: the polygons of the successive hodographs (Eq. 9) of all
        # segments at the highest degree (elevation is exact), stacked per order
        p = max(sg.degree for sg in segs)
        P = np.stack([np.asarray(sg.elevate(p - sg.degree).control_points if sg.degree < p else sg.control_points)
                      for sg in segs])
        stacked = [P]
        while P.shape[1] > 1:
            P = (P.shape[1] - 1) * np.diff(P, axis=1)
            stacked.append(P)
        object.__setattr__(self, "_stacked", stacked)

    @property
    def count(self) -> int:
        return len(self.segments)

    @property
    def dim(self) -> int:
        return self.segments[0].dim

    def derivatives(self, U, order: int = 0) -> np.ndarray:
        """Derivatives with respect to U up to ``order``: (order+1,) + U.shape + (dim,).
        At a junction U = j the right-hand patch j is used (the last patch at U = n)."""
        U = np.asarray(U, dtype=float)
        j, u = _split_parameter(U.ravel(), self.count)
        out = np.empty((order + 1, u.size, self.dim))
        stacked = self._stacked
        for d in range(order + 1):
            if d < len(stacked):
                out[d] = np.einsum("ki,kid->kd", bernstein(stacked[d].shape[1] - 1, u), stacked[d][j])
            else:
                out[d] = 0.0
        return out.reshape((order + 1,) + U.shape + (self.dim,))

    def evaluate(self, U) -> np.ndarray:
        return self.derivatives(U, 0)[0]

    def junction_jumps(self, order: int = 2) -> np.ndarray:
        """|R^(k)(j+) - R^(k)(j-)| at each junction j = 1..n-1 for k = 0..order:
        shape (n-1, order+1). Zero rows mean C^order continuity."""
        out = np.zeros((self.count - 1, order + 1))
        for j in range(self.count - 1):
            left = self.segments[j].derivatives(1.0, order)
            right = self.segments[j + 1].derivatives(0.0, order)
            out[j] = np.linalg.norm(right - left, axis=-1)
        return out

    def elevated_to(self, degree: int) -> "BezierString":
        if all(s.degree == degree for s in self.segments):
            return self  # immutable: nothing to elevate
        segs = []
        for s in self.segments:
            if s.degree > degree:
                raise GeometryError(f"cannot lower degree {s.degree} to {degree}")
            segs.append(s.elevate(degree - s.degree))
        return BezierString(tuple(segs))

    @property
    def max_degree(self) -> int:
        return max(s.degree for s in self.segments)

    def to_bspline(self, degree: int | None = None) -> BSplineCurve:
        """The string as one B-spline of degree ``degree`` (default: the highest segment
        degree; lower segments are elevated), interior knots j of multiplicity p.
        The parameter is the global U in [0, n]."""
        p = self.max_degree if degree is None else int(degree)
        string = self.elevated_to(p)
        pts = [string.segments[0].control_points]
        for s in string.segments[1:]:
            pts.append(s.control_points[1:])
        knots = _string_knots(p, self.count)
        return BSplineCurve(p, knots, np.concatenate(pts))


def _string_knots(p: int, n: int) -> np.ndarray:
    return np.r_[np.zeros(p + 1), np.repeat(np.arange(1, n), p), np.full(p + 1, float(n))]


@dataclass(frozen=True, eq=False)
class RuledPatch:
    """A patch linear in v (Casey 1983, Eq. 10, Fig. 4a): the straight lines joining
    points of equal u on ``lower`` (v = 0) and ``upper`` (v = 1). The two curves are
    brought to a common degree by elevation. A cubic ``lower``/``upper`` pair gives the
    cubic-linear patch of the paper."""

    lower: BezierCurve
    upper: BezierCurve

    def __post_init__(self):
        lo, up = self.lower, self.upper
        if not isinstance(lo, BezierCurve):
            lo = BezierCurve(lo)
        if not isinstance(up, BezierCurve):
            up = BezierCurve(up)
        if lo.dim != up.dim:
            raise GeometryError(f"lower and upper curves differ in dimension: {lo.dim} vs {up.dim}")
        n = max(lo.degree, up.degree)
        object.__setattr__(self, "lower", lo.elevate(n - lo.degree))
        object.__setattr__(self, "upper", up.elevate(n - up.degree))

    @property
    def degree(self) -> int:
        return self.lower.degree

    def evaluate(self, u, v) -> np.ndarray:
        """R(u, v) by Eq. 10; u and v broadcast. v outside [0, 1] extrapolates linearly
        along the straight line elements (Casey 1983, standardisation)."""
        u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
        v = v[..., None]
        return (1.0 - v) * self.lower.evaluate(u) + v * self.upper.evaluate(u)

    def to_bspline(self) -> BSplineSurface:
        n = self.degree
        P = np.stack([self.lower.control_points, self.upper.control_points], axis=1)
        return BSplineSurface(n, 1, np.r_[np.zeros(n + 1), np.ones(n + 1)], np.array([0.0, 0, 1, 1]), P)


@dataclass(frozen=True, eq=False)
class PatchString:
    """A string of patches linear in v (Casey 1983, Fig. 4b): ``lower`` (v = 0) and
    ``upper`` (v = 1) are Bézier strings with the same number of segments; patch j is the
    :class:`RuledPatch` of their segments j, over global U in [j, j+1]."""

    lower: BezierString
    upper: BezierString

    def __post_init__(self):
        if self.lower.count != self.upper.count:
            raise GeometryError(
                f"lower and upper strings need the same number of patches, got {self.lower.count} and {self.upper.count}"
            )
        if self.lower.dim != self.upper.dim:
            raise GeometryError("lower and upper strings differ in dimension")

    @classmethod
    def from_patches(cls, patches) -> "PatchString":
        return cls(BezierString(tuple(p.lower for p in patches)), BezierString(tuple(p.upper for p in patches)))

    @property
    def count(self) -> int:
        return self.lower.count

    def patch(self, j: int) -> RuledPatch:
        return RuledPatch(self.lower.segments[j], self.upper.segments[j])

    def evaluate(self, U, v) -> np.ndarray:
        """R(U, v), U in [0, count], v in [0, 1] (linear extrapolation outside)."""
        U, v = np.broadcast_arrays(np.asarray(U, float), np.asarray(v, float))
        w = v[..., None]
        return (1.0 - w) * self.lower.evaluate(U) + w * self.upper.evaluate(U)

    def derivatives_u(self, U, v, order: int = 1) -> np.ndarray:
        """∂^k R/∂U^k for k = 0..order: (order+1,) + shape + (dim,)."""
        U, v = np.broadcast_arrays(np.asarray(U, float), np.asarray(v, float))
        w = v[..., None]
        return (1.0 - w) * self.lower.derivatives(U, order) + w * self.upper.derivatives(U, order)

    def to_bspline(self) -> BSplineSurface:
        """One B-spline surface of degree (p, 1), p the highest patch degree, U in
        [0, count], v in [0, 1]: what IGES writes as a type 128 entity."""
        p = max(self.lower.max_degree, self.upper.max_degree)
        lo = self.lower.to_bspline(p)
        up = self.upper.to_bspline(p)
        P = np.stack([lo.control_points, up.control_points], axis=1)
        return BSplineSurface(p, 1, lo.knots, np.array([0.0, 0, 1, 1]), P)

    def extended(self, v0: float, v1: float) -> "PatchString":
        """The same ruled surface re-parameterised so that new v = 0, 1 are old v0, v1
        (exact: the polygons are affine combinations)."""
        lo = tuple(
            BezierCurve((1 - v0) * a.control_points + v0 * b.control_points)
            for a, b in zip(self.lower.segments, self.upper.segments)
        )
        up = tuple(
            BezierCurve((1 - v1) * a.control_points + v1 * b.control_points)
            for a, b in zip(self.lower.segments, self.upper.segments)
        )
        return PatchString(BezierString(lo), BezierString(up))
