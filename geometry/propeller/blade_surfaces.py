"""Spline surfaces from the curves around the edges and the tip (Hally 2013 §9).

1. One knot sequence for all curves (Hally §9, after his Ref. 6 §11): knots are only
   ever inserted (at the midpoints of spans where some curve misses the tolerance), so
   the initial knots stay a subset and the final sequence serves every curve. Hally
   approximates the curves one after another; here all curves are fitted at once on the
   current knots (one banded solve with every curve as right-hand side) and a span is
   split when any curve fails on it, which yields the same kind of sequence in a few
   vectorised rounds. The sequence is kept symmetric (t <-> 1 - t, with 1/2 a knot), so a
   curve shared by two surfaces in opposite directions (c_11) has the same knots both ways.
   Each curve is interpolated at the Greville abscissae of the knots (§9 step 2 samples
   the curves on the knot sequence).
2. The leading-edge, trailing-edge and tip surfaces interpolate their curves: the control
   rows of the curves are interpolated across the curves at v_j = (j - 1)/(N - 1) (Eq. 50).
3.–5. The central surfaces: the blade parameters of their edges are sampled where the
   curves end (c_5, c_6 at the ends of the edge curves, c_9, c_10 at the ends of the tip
   cuts, c_2, c_4 at as many points), a grid is made by transfinite interpolation in the
   blade parameter space (N_LE = N_TE is needed here), mapped by b, and interpolated.

Shared edges: the edge control rows of the central surfaces are then replaced by the
rows of the neighbouring edge or tip surfaces (they interpolate the same points at the
same parameters with the same knots, so this changes them only by round-off), which
makes the control points of adjacent surfaces identical along every shared edge.

Orientation (outward normals S_u × S_v, like b_ξ × b_η of Hally Eq. 1): edge surfaces
have u along the curves in the +ξ sense and v from the hub up; the tip surface has u
across the cuts (from c_11 to c_12) and v along the cuts (pressure -> suction); central
surfaces have u along +ξ and v from the hub up.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError
from ..nurbs import BSplineSurface
from ..nurbs.basis import basis_functions, find_span
from ..nurbs.fitting import average_knots, greville_abscissae, interpolate_at
from ..nurbs.skinning import transfinite_interpolation
from .batch import curve_displacement, curve_parameters
from .corners import blade_points

DEGREE = 3
#: Deviation samples per knot span when building the common knot sequence.
SAMPLES_PER_SPAN = 8
#: Initial interior knots of the common sequence (uniform, with 1/2 = the edge point of
#: every curve); typical blades need 25–35 control points per curve at the default tolerance.
INITIAL_KNOTS = tuple(np.arange(1, 16) / 16)
#: Cap on the common knot sequence.
MAX_KNOTS = 4000


def evaluate_curves(blade, curves, t) -> tuple[np.ndarray, np.ndarray]:
    """Points (K, n, 3) and blade parameters (K, n, 2) of K curves at the same t (n,),
    with one evaluation of b for all of them (and the curves' parameters in batches,
    :mod:`.batch`)."""
    t = np.asarray(t, dtype=np.float64)
    P = curve_parameters(curves, t)
    X = blade_points(blade, P)
    for k, c in enumerate(curves):
        d = curve_displacement(c, t, X[k])
        if d is not None:
            X[k] += d
    return X, P


def _clamped(interior) -> np.ndarray:
    return np.concatenate([np.zeros(DEGREE + 1), np.sort(interior), np.ones(DEGREE + 1)])


def _symmetric(interior: np.ndarray) -> np.ndarray:
    """Interior knots closed under t -> 1 - t, exactly symmetric in floating point."""
    half = np.unique(np.concatenate([interior[interior < 0.5], 1.0 - interior[interior > 0.5]]))
    mid = [0.5] if np.any(np.isclose(interior, 0.5, rtol=0, atol=1e-15)) else []
    return np.concatenate([half, mid, (1.0 - half)[::-1]])


def _collocation(U, t):
    span = find_span(U, DEGREE, t)
    N = basis_functions(U, DEGREE, t, span)
    M = np.zeros((t.size, len(U) - DEGREE - 1))
    M[np.arange(t.size)[:, None], span[:, None] - DEGREE + np.arange(DEGREE + 1)] = N
    return M


def fit_rows(U, X):
    """Interpolate every curve (K, n, dim) at the Greville abscissae of U: control points
    (K, n, dim)."""
    g = greville_abscissae(U, DEGREE)
    K, n, dim = X.shape
    flat = np.moveaxis(X, 0, 1).reshape(n, K * dim)
    C = interpolate_at(U, DEGREE, g, flat).control_points
    return np.moveaxis(C.reshape(n, K, dim), 1, 0)


def common_knots(blade, curves, tolerance: float, report: dict | None = None):
    """The common knot vector of Hally §9 (see the module docstring) for ``curves``, and
    the control points (K, n, 3) and blade parameters at the Greville abscissae (K, n, 2)
    of every curve. tolerance: metres."""
    interior = _symmetric(np.array(INITIAL_KNOTS))
    cache_t = np.empty(0)
    cache_X = np.empty((len(curves), 0, 3))
    rounds = 0
    while True:
        rounds += 1
        U = _clamped(interior)
        g = greville_abscissae(U, DEGREE)
        breaks = np.unique(U)
        local = (np.arange(1, SAMPLES_PER_SPAN) / SAMPLES_PER_SPAN)
        ts = (breaks[:-1, None] + np.diff(breaks)[:, None] * local[None, :]).ravel()
        new = ~np.isin(ts, cache_t)
        # one evaluation of the curves per round: the Greville abscissae and the new samples
        Xa, Pa = evaluate_curves(blade, curves, np.concatenate([g, ts[new]]))
        Xg, Pg = Xa[:, : g.size], Pa[:, : g.size]
        C = fit_rows(U, Xg)
        if np.any(new):
            cache_t = np.concatenate([cache_t, ts[new]])
            cache_X = np.concatenate([cache_X, Xa[:, g.size :]], axis=1)
        order = np.argsort(cache_t)
        cache_t, cache_X = cache_t[order], cache_X[:, order]
        F = cache_X[:, np.searchsorted(cache_t, ts)]
        M = _collocation(U, ts)
        S = np.einsum("tn,knd->ktd", M, C)
        dev = np.linalg.norm(F - S, axis=2).max(axis=0).reshape(len(breaks) - 1, SAMPLES_PER_SPAN - 1).max(axis=1)
        failing = dev > tolerance
        if not np.any(failing):
            break
        mids = 0.5 * (breaks[:-1] + breaks[1:])[failing]
        interior = _symmetric(np.concatenate([interior, mids]))
        if len(interior) + 2 * (DEGREE + 1) > MAX_KNOTS:
            raise GeometryError(
                f"no common knot sequence within {MAX_KNOTS} knots meets the tolerance {tolerance:.3g} m "
                f"(largest deviation {dev.max():.3g} m; Hally 2013 §9)"
            )
    if report is not None:
        report.update(rounds=rounds, n_knots=len(U), n_control=len(U) - DEGREE - 1,
                      max_curve_deviation=float(dev.max()), curves=len(curves))
    return U, C, Pg


def across_knots(count: int) -> tuple[np.ndarray, np.ndarray]:
    """Parameters v_j = (j - 1)/(N - 1) (Hally Eq. 50) and their averaged interpolation
    knots (NURBS Book Eq. 9.8), made exactly symmetric."""
    v = np.arange(count) / (count - 1)
    V = average_knots(v, DEGREE)
    V = 0.5 * (V + (1.0 - V[::-1]))
    return v, V


def interpolate_rows(rows: np.ndarray, v: np.ndarray, V: np.ndarray) -> np.ndarray:
    """Interpolate rows (N, n, dim) across the first axis at v with knots V: (N, n, dim)."""
    N, n, dim = rows.shape
    C = interpolate_at(V, DEGREE, v, rows.reshape(N, n * dim)).control_points
    return np.array(C).reshape(N, n, dim)


@dataclass(frozen=True, eq=False)
class SurfacePair:
    """A blade surface and its companion in blade parameter space (same knots; its
    "points" are approximate blade parameters (ξ, η) of the surface, used to start
    closest-point searches)."""

    surface: BSplineSurface
    parameters: BSplineSurface


def edge_surface(U, C, Pg, along_u: bool = True) -> SurfacePair:
    """Surface through curve control rows C (K, n, 3): u along the curves and v across
    them (``along_u``), or the transpose (the tip surface)."""
    K = C.shape[0]
    v, V = across_knots(K)
    net = interpolate_rows(C, v, V)
    net[0], net[-1] = C[0], C[-1]
    pnet = interpolate_rows(fit_rows(U, Pg), v, V)
    if along_u:
        return SurfacePair(BSplineSurface(DEGREE, DEGREE, U, V, np.swapaxes(net, 0, 1)),
                           BSplineSurface(DEGREE, DEGREE, U, V, np.swapaxes(pnet, 0, 1)))
    return SurfacePair(BSplineSurface(DEGREE, DEGREE, V, U, net), BSplineSurface(DEGREE, DEGREE, V, U, pnet))


def central_surface(blade, bottom, top, left, right, knots_u, knots_v, edges) -> SurfacePair:
    """A central surface (Hally §9 steps 3–5): TFI grid in blade parameters from the
    sampled edges bottom/top (nu, 2) and left/right (nv, 2), mapped by b and interpolated
    on the given knots; then the edge rows ``edges`` (dict side -> control row) of the
    neighbours are copied in."""
    G = transfinite_interpolation(bottom, top, left, right)
    X = blade_points(blade, G)
    nu, nv = G.shape[:2]
    u, _ = across_knots(nu)
    v, _ = across_knots(nv)
    net = interpolate_rows(np.swapaxes(interpolate_rows(np.swapaxes(X, 0, 1), v, knots_v), 0, 1), u, knots_u)
    pnet = interpolate_rows(np.swapaxes(interpolate_rows(np.swapaxes(G, 0, 1), v, knots_v), 0, 1), u, knots_u)
    for side, row in edges.items():
        if side == "u0":
            net[0] = row
        elif side == "u1":
            net[-1] = row
        elif side == "v0":
            net[:, 0] = row
        elif side == "v1":
            net[:, -1] = row
    return SurfacePair(BSplineSurface(DEGREE, DEGREE, knots_u, knots_v, net),
                       BSplineSurface(DEGREE, DEGREE, knots_u, knots_v, pnet))
