"""Known-answer IGES models: used by the tests against third-party readers and by demos.

Each builder returns records (and, where useful, the exact area), so a reader's result
can be compared with an analytic value.
"""
from __future__ import annotations

import math

import numpy as np

from ..geometry.nurbs import BSplineCurve, BSplineSurface
from .records import (
    BSplineCurve126,
    BSplineSurface128,
    CompositeCurve,
    CurveOnSurface,
    Line,
    SurfaceOfRevolution,
    TrimmedSurface,
)


def arc126(center, radius: float, angle0: float, angle1: float, z: float | None = None) -> BSplineCurve126:
    """A circular arc as one exact rational quadratic Bezier segment (|angle1 - angle0| < pi):
    The NURBS Book 2e §7.3, weight cos(half angle) on the middle point."""
    half = 0.5 * (angle1 - angle0)
    mid = 0.5 * (angle0 + angle1)
    c = np.asarray(center, dtype=np.float64)
    pts = np.array([
        c + radius * np.array([math.cos(angle0), math.sin(angle0)]),
        c + radius / math.cos(half) * np.array([math.cos(mid), math.sin(mid)]),
        c + radius * np.array([math.cos(angle1), math.sin(angle1)]),
    ])
    if z is not None:
        pts = np.c_[pts, np.full(3, z)]
    return BSplineCurve126(2, [0, 0, 0, 1, 1, 1], pts, [1.0, math.cos(half), 1.0])


def circle_loop(center, radius: float, clockwise: bool = False) -> CompositeCurve:
    """A full circle as four exact quarter arcs (102 of four 126); no C0 knots anywhere."""
    s = -1.0 if clockwise else 1.0
    q = 0.5 * math.pi
    return CompositeCurve([arc126(center, radius, s * k * q, s * (k + 1) * q) for k in range(4)])


def straight126(a, b, degree: int = 3) -> BSplineCurve126:
    """A straight segment as a 126 of the given degree with linear parameterisation."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    P = a + np.linspace(0.0, 1.0, degree + 1)[:, None] * (b - a)
    return BSplineCurve126(degree, [0.0] * (degree + 1) + [1.0] * (degree + 1), P)


def trimmed_cylinder_band(radius: float = 2.0, height: float = 3.0, start_angle: float = 0.25,
                          end_angle: float = 2.75, hole_radius: float = 0.3, preferred: int = 3):
    """A band of a cylinder with a circular hole, as a trimmed surface of revolution.

    120: axis a 110 (the z axis), generatrix a 126 (the straight line x = radius,
    0 <= z <= height, parameter t = z / height), angles [start_angle, end_angle]
    (< pi apart, so each model-space arc is one rational Bezier segment).
    Outer loop (142): in parameter space a 102 of two 110 lines and two 126 segments;
    in model space a 102 of two 110 lines (along the generatrix) and two 126 arcs
    (top and bottom rims). Hole (142): a circle of ``hole_radius`` in (t, angle)
    parameter space, a 102 of four exact rational arcs, clockwise.

    On the surface dA = radius * height dt dangle, so the exact area is
    radius * height * ((end - start) - pi * hole_radius^2). Returns (trimmed, area).
    """
    R, H, SA, TA, r = radius, height, start_angle, end_angle, hole_radius
    axis = Line([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    generatrix = BSplineCurve126(1, [0, 0, 1, 1], [[R, 0.0, 0.0], [R, 0.0, H]])
    surface = SurfaceOfRevolution(axis, generatrix, SA, TA)
    outer_b = CompositeCurve([
        Line([0.0, SA], [1.0, SA]), straight126([1.0, SA], [1.0, TA]),
        Line([1.0, TA], [0.0, TA]), straight126([0.0, TA], [0.0, SA]),
    ])
    ca, sa, ct, st = math.cos(SA), math.sin(SA), math.cos(TA), math.sin(TA)
    outer_c = CompositeCurve([
        Line([R * ca, R * sa, 0.0], [R * ca, R * sa, H]), arc126([0.0, 0.0], R, SA, TA, z=H),
        Line([R * ct, R * st, H], [R * ct, R * st, 0.0]), arc126([0.0, 0.0], R, TA, SA, z=0.0),
    ])
    outer = CurveOnSurface(surface, outer_b, outer_c, creation=0, preferred=preferred)
    hole = CurveOnSurface(surface, circle_loop([0.5, 0.5 * (SA + TA)], r, clockwise=True), None, preferred=1)
    area = R * H * ((TA - SA) - math.pi * r * r)
    return TrimmedSurface(surface, outer, [hole]), area


def trimmed_plane_with_hole(width: float = 2.0, depth: float = 1.5, hole_radius: float = 0.4,
                            degree: int = 3, count: int = 6):
    """A flat rectangle as a non-uniform bicubic 128 (a planar net, so its area is known),
    trimmed by its domain boundary (N1 = 0) with a circular hole in parameter space.

    The net maps (u, v) in [0, 1]^2 affinely onto [0, width] x [0, depth] (control points at
    the Greville abscissae), so the hole of radius ``hole_radius`` in the (u, v) square is an
    ellipse of area pi * r^2 * width * depth. Returns (trimmed, area).
    """
    knots = np.r_[[0.0] * (degree + 1), [0.2, 0.45], [1.0] * (degree + 1)]
    n = len(knots) - degree - 1
    greville = np.array([knots[i + 1 : i + degree + 1].mean() for i in range(n)])
    U, V = np.meshgrid(greville, greville, indexing="ij")
    P = np.stack([width * U, depth * V, np.full(U.shape, 0.5)], axis=-1)
    surface = BSplineSurface128(degree, degree, knots, knots, P)
    hole = CurveOnSurface(surface, circle_loop([0.5, 0.5], hole_radius, clockwise=True), None, preferred=1)
    area = width * depth * (1.0 - math.pi * hole_radius**2)
    return TrimmedSurface(surface, None, [hole]), area


def random_knots(rng, n_control: int, degree: int, domain=(0.0, 1.0)) -> np.ndarray:
    """Clamped, non-uniform, with simple interior knots (so the spline is C^(degree-1))."""
    a, b = domain
    gaps = rng.uniform(0.3, 1.7, n_control - degree)
    inner = a + (b - a) * np.cumsum(gaps)[:-1] / gaps.sum()
    return np.r_[[a] * (degree + 1), inner, [b] * (degree + 1)]


def random_surface(rng, shape=(7, 6), degrees=(3, 2), rational: bool = True, scale: float = 1.0) -> BSplineSurface:
    """A random non-uniform (rational) B-spline surface over a wavy grid of size ``scale``."""
    nu, nv = shape
    p, q = degrees
    ku = random_knots(rng, nu, p, (0.0, rng.uniform(0.5, 3.0)))
    kv = random_knots(rng, nv, q, (-1.0, rng.uniform(0.0, 2.0)))
    U, V = np.meshgrid(np.linspace(0, 1, nu), np.linspace(0, 1, nv), indexing="ij")
    P = np.stack([U, V, 0.2 * rng.normal(size=U.shape)], axis=-1) + 0.05 * rng.normal(size=(nu, nv, 3))
    W = rng.uniform(0.5, 2.0, size=(nu, nv)) if rational else None
    return BSplineSurface(p, q, ku, kv, scale * P, W)


def random_curve(rng, n_control: int = 8, degree: int = 3, rational: bool = True, scale: float = 1.0) -> BSplineCurve:
    """A random non-uniform (rational) 3-D B-spline curve of size ``scale``."""
    knots = random_knots(rng, n_control, degree, (rng.uniform(-1.0, 0.0), rng.uniform(1.0, 4.0)))
    t = np.linspace(0, 1, n_control)
    P = np.stack([t, np.sin(3 * t), 0.3 * t**2], axis=-1) + 0.1 * rng.normal(size=(n_control, 3))
    W = rng.uniform(0.5, 2.0, size=n_control) if rational else None
    return BSplineCurve(degree, knots, scale * P, W)


def cubic_spline_112(rng, segments: int = 3):
    """A C2 parametric spline curve (112, CTYPE 3) with truthful terminal values."""
    from .records import ParametricSpline

    T = np.cumsum(np.r_[0.0, rng.uniform(0.5, 1.5, segments)])
    C = np.zeros((segments, 3, 4))
    C[0] = rng.normal(size=(3, 4))
    for i in range(1, segments):
        h = T[i] - T[i - 1]
        a, b, c, d = C[i - 1].T
        C[i, :, 0] = a + b * h + c * h * h + d * h**3
        C[i, :, 1] = b + 2 * c * h + 3 * d * h * h
        C[i, :, 2] = c + 3 * d * h
        C[i, :, 3] = rng.normal(size=3)
    h = T[-1] - T[-2]
    a, b, c, d = C[-1].T
    terminal = np.stack([a + b * h + c * h * h + d * h**3, b + 2 * c * h + 3 * d * h * h, c + 3 * d * h, d], axis=1)
    return ParametricSpline(3, 2, 3, T, C, terminal)


def bicubic_spline_114(rng, breakpoints_u=(0.0, 0.5, 1.2), breakpoints_v=(0.0, 0.4, 1.0)):
    """A parametric spline surface (114) whose patches are one global bicubic polynomial,
    re-expanded about each patch corner (so the patches join smoothly)."""
    from math import comb

    from .records import ParametricSplineSurface

    TU, TV = np.asarray(breakpoints_u, float), np.asarray(breakpoints_v, float)
    c = rng.normal(size=(3, 4, 4))  # coordinate, u power, v power
    c[0, 1, 0] += 1.0
    c[1, 0, 1] += 1.0
    M, N = len(TU) - 1, len(TV) - 1
    out = np.zeros((M, N, 3, 16))
    for i in range(M):
        for j in range(N):
            for a in range(4):
                for b in range(4):
                    val = sum(c[:, a2, b2] * comb(a2, a) * comb(b2, b) * TU[i] ** (a2 - a) * TV[j] ** (b2 - b)
                              for a2 in range(a, 4) for b2 in range(b, 4))
                    out[i, j, :, 4 * b + a] = val
    return ParametricSplineSurface(3, 1, TU, TV, out)
