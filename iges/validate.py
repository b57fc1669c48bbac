"""Consistency checks of records, and the flags derived from their data.

The writer runs :func:`validate_entity` on every entity (and :func:`validate_loop` on
every trimming loop) before it writes a single byte, so it never produces a file a
reader would reject or repair. The reader runs :func:`check_structure`, the part that
any conforming file satisfies (counts, monotone knots, positive weights, pointer
targets of the right kind).

Flags (IGES 5.3 §4.23 PROP1-4 of 126, §4.24 PROP1-5 of 128) are derived here from the
data, so they are always truthful.
"""
from __future__ import annotations

import math

import numpy as np

from ..geometry.errors import IgesError
from .convert import (
    bspline_curve,
    bspline_surface,
    curve_ends,
    curve_points,
    curve_range,
    surface_points,
    surface_range,
)
from .records import (
    CURVE_TYPES,
    SURFACE_TYPES,
    BSplineCurve126,
    BSplineSurface128,
    CircularArc,
    CompositeCurve,
    CurveOnSurface,
    Entity,
    GenericEntity,
    Line,
    ParametricSpline,
    ParametricSplineSurface,
    SurfaceOfRevolution,
    TransformationMatrix,
    TrimmedSurface,
)

#: Largest degree written or read. OpenCASCADE's Geom_BSplineCurve/Surface stop at 25.
MAX_DEGREE = 25
#: Parameter values may exceed a domain by this fraction of the domain's width
#: (floating-point slack when a trimming curve touches the domain boundary).
PARAMETER_TOLERANCE = 1e-9
#: Derivatives at the two ends of a closed curve/surface count as equal (periodic) within
#: this fraction of their magnitude.
DERIVATIVE_TOLERANCE = 1e-9
#: Samples per knot span (or per segment) when checking that a trimming curve stays in the domain.
SAMPLES_PER_SPAN = 16
#: Largest permitted deviation of an orthonormal 124 rotation from R^T R = I.
ORTHONORMAL_TOLERANCE = 1e-9


def _fail(entity: Entity, message: str):
    raise IgesError(f"{entity.describe()}: {message}")


def _finite(entity: Entity, array: np.ndarray, what: str):
    if array.size and not np.all(np.isfinite(array)):
        idx = tuple(int(i) for i in np.argwhere(~np.isfinite(array))[0])
        _fail(entity, f"{what}{list(idx)} is not finite ({array[idx]!r})")


def _kind(entity: Entity, value, types, what: str, optional: bool = False):
    if value is None and optional:
        return
    if not isinstance(value, types):
        got = value.describe() if isinstance(value, Entity) else repr(value)[:60]
        names = ", ".join(f"{t.__name__} ({t.type_number})" for t in types)
        _fail(entity, f"{what} must be one of {names}; got {got}")


def _range_in_domain(entity: Entity, rng, domain, what: str):
    a, b = rng
    lo, hi = domain
    if not (math.isfinite(a) and math.isfinite(b)):
        _fail(entity, f"{what} ({a!r}, {b!r}) is not finite")
    if not a < b:
        _fail(entity, f"{what} ({a!r}, {b!r}) is empty: start must be < end")
    slack = PARAMETER_TOLERANCE * (hi - lo)
    if a < lo - slack or b > hi + slack:
        _fail(entity, f"{what} ({a!r}, {b!r}) is outside the knot domain [{lo!r}, {hi!r}]")


def _check_degree(entity, degree, what):
    if not 1 <= degree <= MAX_DEGREE:
        _fail(entity, f"{what} must be in 1..{MAX_DEGREE}, got {degree}")


def check_structure(entity: Entity) -> None:
    """Counts, monotonicity, positivity, finiteness and pointer kinds of one record."""
    if isinstance(entity, BSplineCurve126):
        p, P, U, w = entity.degree, entity.control_points, entity.knots, entity.weights
        _check_degree(entity, p, "degree")
        n = P.shape[0]
        if n < p + 1:
            _fail(entity, f"degree {p} needs at least {p + 1} control points, got {n}")
        if U.size != n + p + 1:
            _fail(entity, f"expected {n + p + 1} knots for {n} control points of degree {p} (K+M+2), got {U.size}")
        if w.shape != (n,):
            _fail(entity, f"expected {n} weights, got {w.shape[0] if w.ndim else 0}")
        _finite(entity, P, "control_points")
        _finite(entity, w, "weights")
        if np.any(w <= 0):
            _fail(entity, f"weights must be > 0, got {w[w <= 0][0]!r}")
        bspline_curve(entity)  # knot vector: finite, non-decreasing, multiplicities
        _range_in_domain(entity, entity.parameter_range, (U[p], U[n]), "parameter range (V0, V1)")
    elif isinstance(entity, BSplineSurface128):
        p, q = entity.degree_u, entity.degree_v
        _check_degree(entity, p, "degree_u")
        _check_degree(entity, q, "degree_v")
        P, w = entity.control_points, entity.weights
        nu, nv = P.shape[:2]
        if nu < p + 1 or nv < q + 1:
            _fail(entity, f"degrees ({p}, {q}) need at least ({p + 1}, {q + 1}) control points, got ({nu}, {nv})")
        for U, deg, n, d in ((entity.knots_u, p, nu, "u"), (entity.knots_v, q, nv, "v")):
            if U.size != n + deg + 1:
                _fail(entity, f"expected {n + deg + 1} {d} knots for {n} control points of degree {deg}, got {U.size}")
        if w.shape != (nu, nv):
            _fail(entity, f"weights: expected shape ({nu}, {nv}), got {w.shape}")
        _finite(entity, P, "control_points")
        _finite(entity, w, "weights")
        if np.any(w <= 0):
            _fail(entity, f"weights must be > 0, got {w[w <= 0][0]!r}")
        bspline_surface(entity)
        _range_in_domain(entity, entity.parameter_range_u, (entity.knots_u[p], entity.knots_u[nu]), "u range")
        _range_in_domain(entity, entity.parameter_range_v, (entity.knots_v[q], entity.knots_v[nv]), "v range")
    elif isinstance(entity, Line):
        _finite(entity, entity.start, "start")
        _finite(entity, entity.end, "end")
        if entity.line_form not in (0, 1, 2):
            _fail(entity, f"form must be 0, 1 or 2, got {entity.line_form}")
    elif isinstance(entity, CircularArc):
        for name in ("center", "start", "end"):
            _finite(entity, getattr(entity, name), name)
        if not math.isfinite(entity.z):
            _fail(entity, f"z is not finite ({entity.z!r})")
        if not entity.radius > 0:
            _fail(entity, "radius is zero: the start point is the center")
    elif isinstance(entity, CompositeCurve):
        if not entity.curves:
            _fail(entity, "a composite curve needs at least one constituent")
        for i, c in enumerate(entity.curves):
            _kind(entity, c, CURVE_TYPES, f"constituent {i}")
    elif isinstance(entity, ParametricSpline):
        T, C, TP = entity.breakpoints, entity.coefficients, entity.terminal
        if entity.spline_type not in range(1, 7):
            _fail(entity, f"spline type CTYPE must be 1..6, got {entity.spline_type}")
        if entity.ndim not in (2, 3):
            _fail(entity, f"NDIM must be 2 or 3, got {entity.ndim}")
        N = T.size - 1
        if N < 1:
            _fail(entity, "needs at least one segment (two breakpoints)")
        if C.shape != (N, 3, 4):
            _fail(entity, f"coefficients: expected shape ({N}, 3, 4), got {C.shape}")
        if TP.shape != (3, 4):
            _fail(entity, f"terminal values: expected shape (3, 4), got {TP.shape}")
        for a, what in ((T, "breakpoints"), (C, "coefficients"), (TP, "terminal")):
            _finite(entity, a, what)
        if np.any(np.diff(T) <= 0):
            _fail(entity, "breakpoints must increase strictly")
    elif isinstance(entity, ParametricSplineSurface):
        TU, TV, C = entity.breakpoints_u, entity.breakpoints_v, entity.coefficients
        if entity.spline_type not in range(1, 7):
            _fail(entity, f"spline type CTYPE must be 1..6, got {entity.spline_type}")
        M, N = TU.size - 1, TV.size - 1
        if M < 1 or N < 1:
            _fail(entity, "needs at least one segment in u and in v")
        if C.shape != (M, N, 3, 16):
            _fail(entity, f"coefficients: expected shape ({M}, {N}, 3, 16), got {C.shape}")
        for a, what in ((TU, "breakpoints_u"), (TV, "breakpoints_v"), (C, "coefficients")):
            _finite(entity, a, what)
        if np.any(np.diff(TU) <= 0) or np.any(np.diff(TV) <= 0):
            _fail(entity, "breakpoints must increase strictly")
    elif isinstance(entity, SurfaceOfRevolution):
        _kind(entity, entity.axis, (Line,), "axis")
        _kind(entity, entity.generatrix, CURVE_TYPES, "generatrix")
        a, b = entity.start_angle, entity.end_angle
        if not (math.isfinite(a) and math.isfinite(b)):
            _fail(entity, f"angles ({a!r}, {b!r}) are not finite")
        if not a < b or b - a > 2.0 * math.pi * (1.0 + PARAMETER_TOLERANCE):
            _fail(entity, f"need start angle < end angle <= start + 2 pi, got ({a!r}, {b!r})")
    elif isinstance(entity, TransformationMatrix):
        R, T = entity.rotation, entity.translation
        if R.shape != (3, 3) or T.shape != (3,):
            _fail(entity, f"expected a (3, 3) rotation and (3,) translation, got {R.shape} and {T.shape}")
        _finite(entity, R, "rotation")
        _finite(entity, T, "translation")
        if entity.matrix_form not in (0, 1, 10, 11, 12):
            _fail(entity, f"form must be 0, 1, 10, 11 or 12, got {entity.matrix_form}")
    elif isinstance(entity, CurveOnSurface):
        _kind(entity, entity.surface, SURFACE_TYPES, "surface")
        _kind(entity, entity.parameter_curve, CURVE_TYPES, "parameter_curve", optional=True)
        _kind(entity, entity.model_curve, CURVE_TYPES, "model_curve", optional=True)
        if entity.parameter_curve is None and entity.model_curve is None:
            _fail(entity, "needs a parameter-space curve, a model-space curve or both")
        if entity.creation not in range(4):
            _fail(entity, f"creation flag CRTN must be 0..3, got {entity.creation}")
        if entity.preferred not in range(4):
            _fail(entity, f"preferred representation PREF must be 0..3, got {entity.preferred}")
    elif isinstance(entity, TrimmedSurface):
        _kind(entity, entity.surface, SURFACE_TYPES, "surface")
        _kind(entity, entity.outer, (CurveOnSurface,), "outer boundary", optional=True)
        for i, c in enumerate(entity.inner):
            _kind(entity, c, (CurveOnSurface,), f"inner boundary {i}")
        for i, c in enumerate(((entity.outer,) if entity.outer is not None else ()) + entity.inner):
            if c.surface is not entity.surface:
                _fail(entity, f"boundary {i} lies on a different surface than the trimmed surface")
    elif isinstance(entity, GenericEntity):
        pass
    else:
        raise IgesError(f"not an IGES record: {type(entity).__name__}")
    if entity.transform is not None:
        _kind(entity, entity.transform, (TransformationMatrix,), "transform")


def _check_model_curve(entity: Entity, resolution: float):
    """A composite in model space must be connected within the resolution (IGES 5.3 §4.4)."""
    if isinstance(entity, CompositeCurve):
        _check_connected(entity, resolution, lambda p: p, "model space")


def _check_connected(composite: CompositeCurve, resolution: float, to_model, space: str):
    ends = [curve_ends(c) for c in composite.curves]
    for i in range(len(ends) - 1):
        a = to_model(ends[i][1])
        b = to_model(ends[i + 1][0])
        gap = float(np.linalg.norm(a - b))
        if not gap <= resolution:
            _fail(composite, f"constituents {i} and {i + 1} do not meet ({space}): gap {gap:.3g} "
                             f"exceeds the resolution {resolution:.3g}")


def validate_entity(entity: Entity, resolution: float) -> None:
    """Everything the writer requires of one record (see module docstring)."""
    if isinstance(entity, GenericEntity):
        _fail(entity, "entities of unsupported types are read-only and cannot be written")
    check_structure(entity)
    if isinstance(entity, Line) and entity.line_form == 0:
        if not np.linalg.norm(entity.end - entity.start) > 0:
            _fail(entity, "a bounded line needs distinct start and end points")
    if isinstance(entity, CircularArc):
        r0 = entity.radius
        r1 = float(np.hypot(*(entity.end - entity.center)))
        if abs(r1 - r0) > resolution:
            _fail(entity, f"start and end are at different distances from the center ({r0!r}, {r1!r})")
    if isinstance(entity, SurfaceOfRevolution):
        from .convert import axis_of
        axis_of(entity)
    if isinstance(entity, CurveOnSurface):
        # PREF must name a representation the entity has (IGES 5.3 §4.19)
        has_b, has_c = entity.parameter_curve is not None, entity.model_curve is not None
        if (entity.preferred == 1 and not has_b) or (entity.preferred == 2 and not has_c) or (
                entity.preferred == 3 and not (has_b and has_c)):
            _fail(entity, f"preferred representation PREF = {entity.preferred} names a curve the entity "
                          f"does not have (parameter curve: {has_b}, model curve: {has_c})")
        if has_b:
            check_in_domain(entity, resolution)


def _curve_samples(curve: Entity) -> np.ndarray:
    """IGES parameters densely covering a (non-composite) curve."""
    a, b = curve_range(curve)
    if isinstance(curve, BSplineCurve126):
        U = np.unique(np.clip(curve.knots, a, b))
    elif isinstance(curve, ParametricSpline):
        U = np.unique(np.clip(curve.breakpoints, a, b))
    else:
        U = np.array([a, b])
    t = (U[:-1, None] + np.linspace(0.0, 1.0, SAMPLES_PER_SPAN + 1)[None, :] * np.diff(U)[:, None]).ravel()
    return np.clip(t, a, b)


def _leaves(curve: Entity, depth: int = 0):
    if isinstance(curve, CompositeCurve):
        if depth > 64:
            raise IgesError(f"{curve.describe()}: composite curves nested too deeply")
        for c in curve.curves:
            yield from _leaves(c, depth + 1)
    else:
        yield curve


def check_in_domain(cos: CurveOnSurface, resolution: float) -> None:
    """The parameter-space curve B of a 142 lies inside its surface's parameter domain."""
    (u0, u1), (v0, v1) = surface_range(cos.surface)
    su, sv = PARAMETER_TOLERANCE * (u1 - u0), PARAMETER_TOLERANCE * (v1 - v0)

    def outside(P):
        return (P[..., 0] < u0 - su) | (P[..., 0] > u1 + su) | (P[..., 1] < v0 - sv) | (P[..., 1] > v1 + sv)

    for leaf in _leaves(cos.parameter_curve):
        if isinstance(leaf, BSplineCurve126) and leaf.transform is None:
            a, b = leaf.parameter_range
            if a == leaf.knots[leaf.degree] and b == leaf.knots[leaf.control_points.shape[0]]:
                if not outside(leaf.control_points).any():
                    continue  # convex hull inside the domain
        P = curve_points(leaf, _curve_samples(leaf))
        bad = outside(P)
        if bad.any():
            u, v = P[bad][0, :2]
            _fail(cos, f"the parameter-space curve leaves the surface's parameter domain "
                       f"[{u0!r}, {u1!r}] x [{v0!r}, {v1!r}] at (u, v) = ({u!r}, {v!r}) "
                       f"(in {leaf.describe()})")


def validate_loop(cos: CurveOnSurface, resolution: float) -> None:
    """A trimming loop (142 inside a 144) is closed within the resolution, in model space.

    Parameter-space gaps are measured where they matter, on the surface: |S(B(a)) - S(B(b))|.
    When both B and C are given, C must start where S(B) starts.
    """
    S = cos.surface

    def on_surface(p):
        return surface_points(S, p[0], p[1])

    if cos.parameter_curve is not None:
        B = cos.parameter_curve
        if isinstance(B, CompositeCurve):
            _check_connected(B, resolution, on_surface, "on the surface")
        b0, b1 = curve_ends(B)
        s0, s1 = on_surface(b0), on_surface(b1)
        gap = float(np.linalg.norm(s1 - s0))
        if not gap <= resolution:
            _fail(cos, f"trimming loop is not closed: its parameter-space curve ends {gap:.3g} "
                       f"(on the surface) from its start; resolution {resolution:.3g}")
    if cos.model_curve is not None:
        C = cos.model_curve
        _check_model_curve(C, resolution)
        c0, c1 = curve_ends(C)
        gap = float(np.linalg.norm(c1 - c0))
        if not gap <= resolution:
            _fail(cos, f"trimming loop is not closed: its model-space curve ends {gap:.3g} from "
                       f"its start; resolution {resolution:.3g}")
        if cos.parameter_curve is not None:
            d = float(np.linalg.norm(c0 - s0))
            if not d <= resolution:
                _fail(cos, f"model-space curve starts {d:.3g} away from the parameter-space curve's "
                           f"start on the surface; resolution {resolution:.3g}")


# -- derived flags ----------------------------------------------------------------------------
def plane_of(points: np.ndarray, resolution: float) -> np.ndarray | None:
    """Unit normal of a plane containing ``points`` within ``resolution``, or None."""
    P = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if np.all(P[:, 2] == 0.0):
        return np.array([0.0, 0.0, 1.0])
    c = P.mean(axis=0)
    _, _, vt = np.linalg.svd(P - c, full_matrices=True)
    n = vt[-1]
    if np.max(np.abs((P - c) @ n)) > resolution:
        return None
    k = int(np.argmax(np.abs(n)))
    return n if n[k] > 0 else -n


def curve_flags(curve: BSplineCurve126, resolution: float) -> tuple[int, int, int, int, np.ndarray]:
    """(PROP1 planar, PROP2 closed, PROP3 polynomial, PROP4 periodic, unit normal) of a 126."""
    normal = plane_of(curve.control_points, resolution)
    planar = normal is not None
    a, b = curve.parameter_range
    C = bspline_curve(curve)
    p = curve.degree
    D = C.derivatives(np.array([a, b]), max(p - 1, 0))  # (2, p, dim)
    closed = bool(np.linalg.norm(D[1, 0] - D[0, 0]) <= resolution)
    periodic = closed and p > 1 and all(
        np.linalg.norm(D[1, k] - D[0, k]) <= DERIVATIVE_TOLERANCE * max(1.0, np.linalg.norm(D[0, k]))
        for k in range(1, p)
    )
    return int(planar), int(closed), int(curve.is_polynomial), int(periodic), (normal if planar else np.zeros(3))


def _corners_apart(surface: BSplineSurface128, resolution: float) -> bool:
    """Whether the surface is certainly open in both directions, from its control net
    alone: with knots clamped at the ends of the parameter range the corners are the net's
    corner points (up to rounding in the last bits, far below the margin here), and both
    pairs of opposite sides have a corner pair farther apart than the resolution."""
    p, q = surface.degree_u, surface.degree_v
    U, V = surface.knots_u, surface.knots_v
    (u0, u1), (v0, v1) = surface.parameter_range_u, surface.parameter_range_v
    if not (np.all(U[: p + 1] == u0) and np.all(U[-p - 1 :] == u1)
            and np.all(V[: q + 1] == v0) and np.all(V[-q - 1 :] == v1)):
        return False
    P = surface.control_points
    c00, c10, c01, c11 = P[0, 0], P[-1, 0], P[0, -1], P[-1, -1]
    margin = resolution + 1e-9 * (1.0 + float(np.max(np.abs([c00, c10, c01, c11]))))
    d = np.linalg.norm(np.array([c00 - c10, c01 - c11, c00 - c01, c10 - c11]), axis=-1)
    return bool(max(d[0], d[1]) > margin and max(d[2], d[3]) > margin)


def surface_flags(surface: BSplineSurface128, resolution: float) -> tuple[int, int, int, int, int]:
    """(PROP1 closed u, PROP2 closed v, PROP3 polynomial, PROP4 periodic u, PROP5 periodic v)."""
    if _corners_apart(surface, resolution):  # the usual case, settled without evaluating
        return 0, 0, int(surface.is_polynomial), 0, 0
    S = bspline_surface(surface)
    (u0, u1), (v0, v1) = surface.parameter_range_u, surface.parameter_range_v
    nu, nv = surface.control_points.shape[:2]
    us = np.linspace(u0, u1, 4 * nu + 1)
    vs = np.linspace(v0, v1, 4 * nv + 1)

    def closed_periodic(side_a, side_b, degree, order_index):
        Pa, Pb = side_a[..., 0, :], side_b[..., 0, :]
        closed = bool(np.max(np.linalg.norm(Pa - Pb, axis=-1)) <= resolution)
        if not closed or degree < 2:
            return closed, False
        for k in range(1, degree):
            da, db = side_a[..., k, :], side_b[..., k, :]
            scale = max(1.0, float(np.max(np.linalg.norm(da, axis=-1))))
            if np.max(np.linalg.norm(da - db, axis=-1)) > DERIVATIVE_TOLERANCE * scale:
                return closed, False
        return closed, True

    p, q = surface.degree_u, surface.degree_v
    # corners first: an open surface (the usual case) is settled by four points
    C = S.evaluate_grid([u0, u1], [v0, v1])
    closed_u = closed_v = False
    if np.linalg.norm(C[0, 0] - C[1, 0]) <= resolution and np.linalg.norm(C[0, 1] - C[1, 1]) <= resolution:
        G = S.evaluate_grid([u0, u1], vs)  # (2, len(vs), 3)
        closed_u = bool(np.max(np.linalg.norm(G[0] - G[1], axis=-1)) <= resolution)
    periodic_u = False
    if closed_u and p > 1:
        D = S.derivatives(np.array([u0, u1])[:, None], vs[None, :], p - 1)  # (2, V, p, p, 3)
        Du = D[..., :, 0, :]  # pure u derivatives
        periodic_u = closed_periodic(Du[0], Du[1], p, 0)[1]
    if np.linalg.norm(C[0, 0] - C[0, 1]) <= resolution and np.linalg.norm(C[1, 0] - C[1, 1]) <= resolution:
        H = S.evaluate_grid(us, [v0, v1])  # (len(us), 2, 3)
        closed_v = bool(np.max(np.linalg.norm(H[:, 0] - H[:, 1], axis=-1)) <= resolution)
    periodic_v = False
    if closed_v and q > 1:
        D = S.derivatives(us[:, None], np.array([v0, v1])[None, :], q - 1)  # (U, 2, q, q, 3)
        Dv = D[..., 0, :, :]
        periodic_v = closed_periodic(Dv[:, 0], Dv[:, 1], q, 1)[1]
    return int(closed_u), int(closed_v), int(surface.is_polynomial), int(periodic_u), int(periodic_v)
