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
    # every parameter evaluated so far, with the points and blade parameters of all
    # curves there, one row per parameter ((t, curve, xyz): a round appends rows and
    # gathers rows): a round evaluates only the Greville abscissae and samples it has not
    # seen (knot insertion leaves most of them in place)
    K = len(curves)
    cache_t = np.empty(0)
    cache_X = np.empty((0, K, 3))
    cache_P = np.empty((0, K, 2))
    rounds = 0
    while True:
        rounds += 1
        U = _clamped(interior)
        g = greville_abscissae(U, DEGREE)
        breaks = np.unique(U)
        local = (np.arange(1, SAMPLES_PER_SPAN) / SAMPLES_PER_SPAN)
        ts = (breaks[:-1, None] + np.diff(breaks)[:, None] * local[None, :]).ravel()
        wanted = np.concatenate([g, ts])
        new = np.unique(wanted[~np.isin(wanted, cache_t)])
        if new.size:
            Xa, Pa = evaluate_curves(blade, curves, new)
            cache_t = np.concatenate([cache_t, new])
            cache_X = np.concatenate([cache_X, np.swapaxes(Xa, 0, 1)])
            cache_P = np.concatenate([cache_P, np.swapaxes(Pa, 0, 1)])
        order = np.argsort(cache_t)
        sorted_t = cache_t[order]

        def rows(t):
            return order[np.searchsorted(sorted_t, t)]

        ig = rows(g)
        # the fit of every curve at the Greville abscissae (fit_rows, on the same matrix)
        C = interpolate_at(U, DEGREE, g, cache_X[ig].reshape(g.size, K * 3)).control_points
        F = cache_X[rows(ts)]  # (samples, curves, 3)
        # the fitted curves at the samples (only compared with the tolerance)
        S = (_collocation(U, ts) @ C).reshape(ts.size, K, 3)
        dev = np.linalg.norm(F - S, axis=2).max(axis=1).reshape(len(breaks) - 1, SAMPLES_PER_SPAN - 1).max(axis=1)
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
    C = np.moveaxis(np.asarray(C).reshape(g.size, K, 3), 1, 0)
    Pg = np.moveaxis(cache_P[ig], 1, 0)
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


# ---------------------------------------------------------------------------------------
# the wrap-around surfaces split at the edge
# ---------------------------------------------------------------------------------------
#: Names of the eight surfaces of :func:`split_at_edges`, in the order the IGES writer uses.
SPLIT_SURFACE_NAMES = ("pressure_central", "suction_central", "leading_edge_pressure", "leading_edge_suction",
                       "trailing_edge_pressure", "trailing_edge_suction", "tip_pressure", "tip_suction")


def _with_net(surface: BSplineSurface, net: np.ndarray, direction: str) -> BSplineSurface:
    """``surface`` with control net ``net`` and its ``direction`` knots mapped from
    [0, 1/2] or [1/2, 1] to [0, 1] (2u or 2u - 1: exact in floating point)."""
    def unit(U):
        return 2.0 * U if U[-1] <= 0.5 else 2.0 * (U - 0.5)

    U, V = surface.knots_u, surface.knots_v
    U, V = (unit(U), V) if direction == "u" else (U, unit(V))
    return BSplineSurface(surface.degree_u, surface.degree_v, U, V, net)


def split_at_edges(surfaces: dict, hand: int = 1) -> dict:
    """The five blade surfaces with the leading-edge, trailing-edge and tip surfaces each
    cut in two along the blade edge (t = 1/2 of every curve around the edges, Hally Eqs. 24
    and 47; 1/2 is a knot of the common sequence), exactly, by knot insertion
    (:func:`~bladesmith.geometry.nurbs.operations.split_surface`): eight surfaces named
    :data:`SPLIT_SURFACE_NAMES`. ``hand``: +1 right-handed (ξ < 1/2 is the pressure side),
    -1 left-handed.

    Why: the leading and trailing edges near the tip have radii of 1e-5 to 1e-4 D (the
    section's edge radius scales with the vanishing chord). Inside a face such an edge is
    resolved by no practical mesh size, and a mesher's triangles straddle it and fold
    (gmsh: "elements remain invalid", 2-30 per face at curvature-adapted and uniform sizes).
    As a face boundary the edge gets mesh nodes on it and no triangle crosses it.

    Shared edges stay exact: the two halves of a surface share one control row (slices of
    one net), and every row a half shares with a neighbour is copied from one array
    (the central surfaces' rows from the five-surface set, the edge-surface tops from the
    tip halves), never recomputed."""
    from ..nurbs.operations import split_surface

    le_a, le_b = split_surface(surfaces["leading_edge"], "u", 0.5)
    te_a, te_b = split_surface(surfaces["trailing_edge"], "u", 0.5)
    tip_a, tip_b = split_surface(surfaces["tip"], "v", 0.5)
    pc, sc = surfaces["pressure_central"], surfaces["suction_central"]
    if hand < 0:  # the pressure central surface lies at ξ > 1/2 (smoothing.smooth_blade)
        pc, sc = sc, pc
    le, te, tip = surfaces["leading_edge"], surfaces["trailing_edge"], surfaces["tip"]
    joins = {"LE u0 = central u1": (le.control_points[0], pc.control_points[-1]),
             "LE u1 = central u0": (le.control_points[-1], sc.control_points[0]),
             "TE u0 = central u1": (te.control_points[0], sc.control_points[-1]),
             "TE u1 = central u0": (te.control_points[-1], pc.control_points[0]),
             "tip v0 = central v1": (tip.control_points[:, 0], pc.control_points[:, -1]),
             "tip v1 = central v1 reversed": (tip.control_points[:, -1], sc.control_points[::-1, -1])}
    wrong = [k for k, (a, b) in joins.items() if a.shape != b.shape or not np.array_equal(a, b)]
    if wrong:  # the rows copied below must be the shared ones: a wrong hand would swap sides
        raise GeometryError(f"split_at_edges: the five surfaces do not share their edges as a "
                            f"{'right' if hand > 0 else 'left'}-handed blade's do ({', '.join(wrong)})")
    # pc: u0 = TE surface's u1 row, u1 = LE surface's u0 row, v1 = tip's v0 column
    # sc: u0 = LE surface's u1 row, u1 = TE surface's u0 row, v1 = tip's v1 column reversed
    tip_a_net, tip_b_net = tip_a.control_points.copy(), tip_b.control_points.copy()
    tip_a_net[:, 0] = pc.control_points[:, -1]
    tip_b_net[:, -1] = sc.control_points[::-1, -1]
    tip_b_net[:, 0] = tip_a_net[:, -1]
    le_a_net, le_b_net = le_a.control_points.copy(), le_b.control_points.copy()
    te_a_net, te_b_net = te_a.control_points.copy(), te_b.control_points.copy()
    le_a_net[0], le_b_net[-1] = pc.control_points[-1], sc.control_points[0]
    te_a_net[0], te_b_net[-1] = sc.control_points[-1], pc.control_points[0]
    le_b_net[0] = le_a_net[-1]
    te_b_net[0] = te_a_net[-1]
    # tops: the LE surface's v1 row is the tip's u1 row (c_12); the TE surface's v1 row is
    # the tip's u0 row (c_11) reversed; the halves of c_11 swap sides under the reversal
    le_a_net[:, -1], le_b_net[:, -1] = tip_a_net[-1], tip_b_net[-1]
    te_a_net[:, -1], te_b_net[:, -1] = tip_b_net[0][::-1], tip_a_net[0][::-1]
    le_a, le_b = _with_net(le_a, le_a_net, "u"), _with_net(le_b, le_b_net, "u")
    te_a, te_b = _with_net(te_a, te_a_net, "u"), _with_net(te_b, te_b_net, "u")
    tip_a, tip_b = _with_net(tip_a, tip_a_net, "v"), _with_net(tip_b, tip_b_net, "v")
    # first halves (ξ rising) of the LE surface and of the tip are on the pressure side of
    # a right-handed blade; the TE surface runs suction -> pressure (its second half)
    halves = {"leading_edge_pressure": le_a, "leading_edge_suction": le_b,
              "trailing_edge_pressure": te_b, "trailing_edge_suction": te_a,
              "tip_pressure": tip_a, "tip_suction": tip_b}
    if hand < 0:
        halves = {k.replace("pressure", "#").replace("suction", "pressure").replace("#", "suction"): v
                  for k, v in halves.items()}
    out = {"pressure_central": surfaces["pressure_central"], "suction_central": surfaces["suction_central"], **halves}
    return {k: out[k] for k in SPLIT_SURFACE_NAMES}


#: The shared edges of :func:`split_at_edges` for a right-handed blade, as
#: (surface a, side a, surface b, side b, reversed) like smoothing.SHARED_EDGES.
SPLIT_SHARED_EDGES = (
    ("pressure_central", "u1", "leading_edge_pressure", "u0", False),
    ("pressure_central", "u0", "trailing_edge_pressure", "u1", False),
    ("suction_central", "u0", "leading_edge_suction", "u1", False),
    ("suction_central", "u1", "trailing_edge_suction", "u0", False),
    ("pressure_central", "v1", "tip_pressure", "v0", False),
    ("suction_central", "v1", "tip_suction", "v1", True),
    ("leading_edge_pressure", "u1", "leading_edge_suction", "u0", False),
    ("trailing_edge_suction", "u1", "trailing_edge_pressure", "u0", False),
    ("tip_pressure", "v1", "tip_suction", "v0", False),
    ("leading_edge_pressure", "v1", "tip_pressure", "u1", False),
    ("leading_edge_suction", "v1", "tip_suction", "u1", False),
    ("trailing_edge_pressure", "v1", "tip_pressure", "u0", True),
    ("trailing_edge_suction", "v1", "tip_suction", "u0", True),
)


def shared_rows(surface: BSplineSurface, side: str) -> np.ndarray:
    """The control row of a surface along one side ('u0', 'u1', 'v0', 'v1')."""
    P = surface.control_points
    return {"u0": P[0], "u1": P[-1], "v0": P[:, 0], "v1": P[:, -1]}[side]
