"""Closest points on B-spline curves and surfaces (point inversion and projection).

Piegl & Tiller, The NURBS Book 2e, §6.1: a coarse search gives the start, then Newton
iteration on f(u) = C'(u)·(C(u) - P) (Eqs. 6.3–6.4) for curves and on
f = S_u·r, g = S_v·r (Eqs. 6.6–6.7) for surfaces, keeping parameters in the domain
(Eqs. 6.5 and 6.8), and stopping on point coincidence, zero cosine or a vanishing step.
Everything is vectorised over many query points.

Two safeguards keep the answer the true closest point: the curve iteration keeps a
bracket around the best sample and bisects when a Newton step would leave it, and the
surface iteration only accepts steps that reduce the distance (halving them otherwise),
falling back to the Gauss–Newton matrix where the Hessian is not positive definite.
Parameters held at a domain boundary by a gradient pointing outwards are fixed and the
search continues along the boundary.
"""
from __future__ import annotations

import itertools

import numpy as np

from ..errors import GeometryError
from .curve import BSplineCurve
from .surface import BSplineSurface

#: Point-coincidence tolerance ε1 of NURBS Book Eq. 6.4, relative to the size of the
#: curve or surface (control-polygon bounding-box diagonal). Also bounds the last step.
POINT_TOL = 1e-15

#: Zero-cosine tolerance ε2 of NURBS Book Eq. 6.4: |C'·r| <= ε2 |C'| |r|.
COSINE_TOL = 1e-13

#: Coarse samples per non-empty knot span for the curve start search.
CURVE_SAMPLES_PER_SPAN = 8

#: Coarse grid samples per non-empty knot span (each direction) for surfaces.
SURFACE_SAMPLES_PER_SPAN = 8

#: Minimum number of coarse samples per parameter direction.
MIN_SAMPLES = 16

#: Newton starts per query point: the samples that are discrete local minima of the
#: distance over the coarse samples (each a separate basin), the nearest first; the best
#: result is kept. Several guard against the nearest sample lying in the basin of a
#: local, not the global, minimum.
CANDIDATES = 4

#: Curve samples are bisected until consecutive ones are at most this fraction of the
#: curve's size apart...
CURVE_SAMPLE_CHORD = 1.0 / 64
#: ...and the tangent turns by at most this angle (radians) between them, so that each
#: sample interval holds at most one local minimum of the distance to any point.
CURVE_SAMPLE_TURN = np.radians(20.0)
#: Intervals next to a knot shorter than this fraction of the domain are not split for
#: turning: at a C0 knot the tangent jumps and no bisection resolves it.
CORNER_SPAN = 1e-3
#: Bisection rounds of the adaptive curve sampling (each at most doubles the samples).
CURVE_SAMPLE_ROUNDS = 12

#: The adaptive surface start grid stops growing at this many points.
SURFACE_GRID_MAX = 1 << 18

#: Query points times coarse samples handled per block when ranking the samples.
BLOCK_ENTRIES = 1 << 22

#: Above this many (point, sample) pairs the curve brackets are built from the samples
#: near each point only (a k-d tree query), not from the dense point × sample table.
SPARSE_BRACKET_PAIRS = 1 << 17


#: Newton iterations before giving up improving (the best point so far is returned).
MAX_ITERATIONS = 100

#: Round-off of an evaluated point, relative to the size of the surface. Near the minimum
#: the distance is flat to round-off (and the point and derivative evaluations round
#: differently), so the line search accepts a step that increases |r| by no more than this.
ROUNDOFF = 1e-13

#: Step halvings tried by the surface line search before the point is left as it is.
MAX_HALVINGS = 40


def _query_points(points, dim: int) -> tuple[np.ndarray, tuple]:
    P = np.asarray(points, dtype=np.float64)
    if P.ndim == 0 or P.shape[-1] != dim:
        raise GeometryError(f"points: expected shape (..., {dim}) to match the geometry, got {P.shape}")
    if not np.all(np.isfinite(P)):
        raise GeometryError("points contain a non-finite value")
    return P.reshape(-1, dim), P.shape[:-1]


def _local_minimum_starts(P: np.ndarray, G: np.ndarray, grid_shape: tuple, k: int) -> np.ndarray:
    """Indices (len(P), k) into the flattened samples G: the k nearest samples that are
    discrete local minima of |G - P| over the sample grid (neighbours along each axis and
    diagonals), padded with the nearest sample when there are fewer than k."""
    out = np.empty((P.shape[0], k), dtype=int)
    g2 = np.einsum("gd,gd->g", G, G)
    block = max(1, BLOCK_ENTRIES // G.shape[0])
    for s in range(0, P.shape[0], block):
        Pb = P[s : s + block]
        D = (g2[None, :] - 2.0 * Pb @ G.T).reshape((Pb.shape[0],) + grid_shape)
        pad = np.pad(D, [(0, 0)] + [(1, 1)] * len(grid_shape), constant_values=np.inf)
        is_min = np.ones(D.shape, dtype=bool)
        for offs in np.ndindex(*(3,) * len(grid_shape)):
            if all(o == 1 for o in offs):
                continue
            sl = (slice(None),) + tuple(slice(o, o + n) for o, n in zip(offs, grid_shape))
            is_min &= D <= pad[sl]
        score = np.where(is_min, D, np.inf).reshape(Pb.shape[0], -1)
        flat = D.reshape(Pb.shape[0], -1)
        kk = min(k, score.shape[1])
        part = np.argpartition(score, kk - 1, axis=1)[:, :kk]
        order = np.argsort(np.take_along_axis(score, part, axis=1), axis=1)
        part = np.take_along_axis(part, order, axis=1)
        best = np.argmin(flat, axis=1)
        finite = np.isfinite(np.take_along_axis(score, part, axis=1))
        part = np.where(finite, part, best[:, None])
        if kk < k:
            part = np.concatenate([part, np.repeat(best[:, None], k - kk, axis=1)], axis=1)
        out[s : s + block] = part
    return out


def _span_samples(knots: np.ndarray, degree: int, per_span: int) -> np.ndarray:
    n_control = len(knots) - degree - 1
    breaks = np.unique(knots[degree : n_control + 1])
    per_span = max(per_span, int(np.ceil((MIN_SAMPLES - 1) / (breaks.size - 1))))
    local = np.arange(per_span) / per_span
    t = (breaks[:-1, None] + np.diff(breaks)[:, None] * local[None, :]).ravel()
    return np.concatenate([t, breaks[-1:]])


def closest_point_curve(
    curve: BSplineCurve,
    points,
    tol: float | None = None,
    cos_tol: float = COSINE_TOL,
    samples_per_span: int = CURVE_SAMPLES_PER_SPAN,
    candidates: int = CANDIDATES,
    max_iterations: int = MAX_ITERATIONS,
) -> tuple[np.ndarray, np.ndarray]:
    """Parameters and distances of the closest points of ``curve`` to ``points``.

    points: shape S + (dim,). Returns (params, distances), each of shape S.
    tol: point-coincidence tolerance ε1 (absolute length; default :data:`POINT_TOL`
    times ``curve.size()``). cos_tol: zero-cosine tolerance ε2.

    Starts: up to ``candidates`` sample intervals (of ``samples_per_span`` samples per knot
    span) over which f changes sign from negative to positive, or domain ends where the
    distance increases inwards, the ones nearest P first (see :func:`_curve_brackets`),
    each refined, the best kept. Newton on
    f(u) = C'(u)·(C(u) - P), u ← u - f/f' with f' = C''·(C - P) + |C'|² (NURBS Book
    Eqs. 6.3–6.4), safeguarded by the bracket between the neighbouring samples (which
    also keeps u in the domain, Eq. 6.5): a step leaving the bracket or with f' <= 0 is
    replaced by bisection on the sign of f.
    """
    if not isinstance(curve, BSplineCurve):
        raise GeometryError(f"closest_point_curve needs a BSplineCurve, got {type(curve).__name__}")
    P, shape = _query_points(points, curve.dim)
    eps1 = POINT_TOL * max(curve.size(), 1e-300) if tol is None else float(tol)
    ts, C0, C1 = _adaptive_curve_samples(curve, _span_samples(curve.knots, curve.degree, samples_per_span))
    k = max(1, int(candidates))
    lo, hi, start = _curve_brackets(P, ts, C0, C1, k)
    # a point with fewer than k brackets has its best one repeated: refine each once
    repeat = np.zeros(lo.shape, dtype=bool)
    for j in range(1, k):
        repeat[:, j] = np.any((lo[:, :j] == lo[:, j: j + 1]) & (hi[:, :j] == hi[:, j: j + 1]), axis=1)
    todo = ~repeat.reshape(-1)
    Pk = np.repeat(P, k, axis=0)
    u = start.reshape(-1).copy()
    u[todo] = _newton_curve(curve, Pk[todo], u[todo], lo.reshape(-1)[todo], hi.reshape(-1)[todo], eps1, cos_tol,
                            max_iterations)
    dist = np.full(u.shape, np.inf)
    dist[todo] = np.linalg.norm(curve.evaluate(u[todo]) - Pk[todo], axis=1)
    rows = np.arange(P.shape[0]) * k + np.argmin(dist.reshape(-1, k), axis=1)
    return u[rows].reshape(shape), dist[rows].reshape(shape)


def _adaptive_curve_samples(curve: BSplineCurve, ts: np.ndarray):
    """Samples, points and first derivatives, with intervals bisected until each is short
    (:data:`CURVE_SAMPLE_CHORD`) and turns little (:data:`CURVE_SAMPLE_TURN`): rational
    curves with large weight ratios can sweep a long way within a small parameter step."""
    limit = CURVE_SAMPLE_CHORD * max(curve.size(), 1e-300)
    cos_turn = np.cos(CURVE_SAMPLE_TURN)
    for round_ in range(CURVE_SAMPLE_ROUNDS + 1):
        D = curve.derivatives(ts, 1)
        C0, C1 = D[:, 0], D[:, 1]
        if round_ == CURVE_SAMPLE_ROUNDS:
            break
        chord = np.linalg.norm(np.diff(C0, axis=0), axis=1)
        norms = np.linalg.norm(C1, axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            cos = np.einsum("sd,sd->s", C1[:-1], C1[1:]) / (norms[:-1] * norms[1:])
        # a tangent that jumps at a knot of full multiplicity is a corner, not a turn to resolve
        at_corner = np.isin(ts[1:], curve.knots) | np.isin(ts[:-1], curve.knots)
        split = (chord > limit) | (~(cos >= cos_turn) & ~(at_corner & (np.diff(ts) < CORNER_SPAN * np.ptp(ts))))
        if not split.any():
            break
        ts = np.sort(np.concatenate([ts, 0.5 * (ts[:-1][split] + ts[1:][split])]))
    return ts, C0, C1


def _curve_brackets(P, ts, C0, C1, k):
    """Brackets [lo, hi] and starts, shape (len(P), k), for the curve's Newton iteration.

    Every local minimum of |C(u) - P| inside the domain is a root of f = C'·(C - P) where
    f changes sign from negative to positive, so each sample interval with f(t_j) < 0 <=
    f(t_j+1) brackets one; the domain ends are minima when f(a) >= 0 or f(b) <= 0. The k
    brackets whose nearer end is closest to P are kept (the interval around the nearest
    sample pads the list when there are fewer), so a minimum lying between two far
    samples on a fast-moving stretch of the curve is still found.
    """
    M = ts.size
    if P.shape[0] * M > SPARSE_BRACKET_PAIRS and M > 2:
        return _curve_brackets_near(P, ts, C0, C1, k)
    cc = np.einsum("sd,sd->s", C1, C0)
    g2 = np.einsum("sd,sd->s", C0, C0)
    lo = np.empty((P.shape[0], k))
    hi = np.empty((P.shape[0], k))
    start = np.empty((P.shape[0], k))
    block = max(1, BLOCK_ENTRIES // M)
    left, right = np.r_[ts[:-1], ts[0], ts[-1]], np.r_[ts[1:], ts[0], ts[-1]]
    for s in range(0, P.shape[0], block):
        Pb = P[s : s + block]
        F = cc[None, :] - Pb @ C1.T  # f at the samples
        Q = g2[None, :] - 2.0 * Pb @ C0.T  # squared distance less |P|^2
        nearer = np.minimum(Q[:, :-1], Q[:, 1:])
        interior = (F[:, :-1] < 0) & (F[:, 1:] >= 0)
        score = np.concatenate(
            [np.where(interior, nearer, np.inf),
             np.where(F[:, :1] >= 0, Q[:, :1], np.inf),
             np.where(F[:, -1:] <= 0, Q[:, -1:], np.inf)],
            axis=1,
        )
        kk = min(k, score.shape[1])
        pick = np.argpartition(score, kk - 1, axis=1)[:, :kk]
        if kk < k:
            pick = np.concatenate([pick, np.repeat(pick[:, :1], k - kk, axis=1)], axis=1)
        found = np.isfinite(np.take_along_axis(score, pick, axis=1))
        # fallback (f changes sign twice inside one interval): around the nearest sample
        j = np.argmin(Q, axis=1)
        fb_lo, fb_hi = ts[np.maximum(j - 1, 0)], ts[np.minimum(j + 1, M - 1)]
        a, b = left[pick], right[pick]
        closer_left = np.take_along_axis(np.c_[Q[:, :-1], Q[:, :1], Q[:, -1:]], pick, axis=1) <= np.take_along_axis(
            np.c_[Q[:, 1:], Q[:, :1], Q[:, -1:]], pick, axis=1
        )
        st = np.where(closer_left, a, b)
        lo[s : s + block] = np.where(found, a, fb_lo[:, None])
        hi[s : s + block] = np.where(found, b, fb_hi[:, None])
        start[s : s + block] = np.where(found, st, ts[j][:, None])
    return lo, hi, start


def _curve_brackets_near(P, ts, C0, C1, k):
    """:func:`_curve_brackets` restricted to the sample intervals near each point, with the
    same result. Let C(u*) be the closest point, d* its distance, d0 the distance to the
    nearest sample and h the longest sample chord. The end of u*'s interval nearer to u*
    along the curve is within half the interval's arc of C(u*), so within d* + h/2 (1.07)
    of P (the samples turn by at most :data:`CURVE_SAMPLE_TURN`: an interval's arc is at
    most 1/cos 20° of its chord); every interval ranked above it has an end nearer still.
    So the k best brackets are among the intervals with an end in the ball of radius
    d0 + h (twice the margin needed), found with a k-d tree (``scipy.spatial.cKDTree``)."""
    from scipy.spatial import cKDTree

    M, nP = ts.size, P.shape[0]
    tree = cKDTree(C0)
    d0, j = tree.query(P)
    h = float(np.max(np.linalg.norm(np.diff(C0, axis=0), axis=1)))
    balls = tree.query_ball_point(P, d0 + h, return_sorted=True)
    lens = np.fromiter(map(len, balls), dtype=np.int64, count=nP)
    pid = np.repeat(np.arange(nP), lens)
    sid = np.fromiter(itertools.chain.from_iterable(balls), dtype=np.int64, count=int(lens.sum()))
    # intervals with an end in the ball (interval i joins samples i and i + 1), each once:
    # i = s - 1 for every sample s, and i = s when s + 1 is not the next sample listed
    nxt = np.r_[sid[1:], -1]
    same = np.r_[pid[1:] == pid[:-1], False]
    last = ~(same & (nxt == sid + 1))
    iv = np.concatenate([sid - 1, sid[last]])
    pv = np.concatenate([pid, pid[last]])
    keep = (iv >= 0) & (iv <= M - 2)
    pv, iv = pv[keep], iv[keep]
    cc = np.einsum("sd,sd->s", C1, C0)
    g2 = np.einsum("sd,sd->s", C0, C0)
    Pp = P[pv]
    Fl = cc[iv] - np.einsum("sd,sd->s", Pp, C1[iv])
    Fr = cc[iv + 1] - np.einsum("sd,sd->s", Pp, C1[iv + 1])
    Ql = g2[iv] - 2.0 * np.einsum("sd,sd->s", Pp, C0[iv])
    Qr = g2[iv + 1] - 2.0 * np.einsum("sd,sd->s", Pp, C0[iv + 1])
    interior = (Fl < 0) & (Fr >= 0)
    # domain ends (dense: two samples per point)
    F0 = cc[0] - P @ C1[0]
    Fe = cc[-1] - P @ C1[-1]
    Q0 = g2[0] - 2.0 * P @ C0[0]
    Qe = g2[-1] - 2.0 * P @ C0[-1]
    ar = np.arange(nP)
    cand_p = np.concatenate([pv[interior], ar, ar])
    cand_s = np.concatenate([np.minimum(Ql, Qr)[interior], np.where(F0 >= 0, Q0, np.inf), np.where(Fe <= 0, Qe, np.inf)])
    cand_a = np.concatenate([ts[iv][interior], np.full(nP, ts[0]), np.full(nP, ts[-1])])
    cand_b = np.concatenate([ts[iv + 1][interior], np.full(nP, ts[0]), np.full(nP, ts[-1])])
    cand_st = np.concatenate([np.where(Ql <= Qr, ts[iv], ts[iv + 1])[interior], np.full(nP, ts[0]), np.full(nP, ts[-1])])
    order = np.lexsort((cand_s, cand_p))
    cand_p, cand_s, cand_a, cand_b, cand_st = (x[order] for x in (cand_p, cand_s, cand_a, cand_b, cand_st))
    first = np.searchsorted(cand_p, ar)
    count = np.diff(np.r_[first, cand_p.size])  # >= 2 (the two ends)
    rank = np.minimum(np.arange(k)[None, :], count[:, None] - 1)  # pad with the best one
    idx = first[:, None] + rank
    found = np.isfinite(cand_s[idx])
    fb_lo, fb_hi = ts[np.maximum(j - 1, 0)], ts[np.minimum(j + 1, M - 1)]
    lo = np.where(found, cand_a[idx], fb_lo[:, None])
    hi = np.where(found, cand_b[idx], fb_hi[:, None])
    start = np.where(found, cand_st[idx], ts[j][:, None])
    return lo, hi, start


def _newton_curve(curve, P, u, lo, hi, eps1, cos_tol, max_iterations) -> np.ndarray:
    """Bracketed Newton iteration of :func:`closest_point_curve` from the starts ``u``
    inside the brackets [lo, hi] (all arrays of one length, updated in place)."""
    active = np.arange(P.shape[0])
    for _ in range(max_iterations):
        if active.size == 0:
            break
        ua = u[active]
        D = curve.derivatives(ua, 2)
        r = D[:, 0] - P[active]
        d1, d2 = D[:, 1], D[:, 2]
        dist = np.linalg.norm(r, axis=1)
        speed = np.linalg.norm(d1, axis=1)
        f = np.einsum("nd,nd->n", d1, r)
        fp = np.einsum("nd,nd->n", d2, r) + speed**2
        done = (dist <= eps1) | (np.abs(f) <= cos_tol * speed * dist)
        # the minimum lies on the side where f changes sign to positive
        neg = f < 0
        lo[active[neg]] = ua[neg]
        hi[active[~neg]] = ua[~neg]
        la, ha = lo[active], hi[active]
        with np.errstate(divide="ignore", invalid="ignore"):
            un = ua - f / fp
        bad = ~(fp > 0) | ~(un >= la) | ~(un <= ha)
        un = np.where(bad, 0.5 * (la + ha), un)
        done |= np.abs(un - ua) * speed <= eps1
        keep = ~done
        u[active[keep]] = un[keep]
        active = active[keep]
    return u


def _grid_params(knots, degree, grid, which: int) -> np.ndarray:
    if grid is None:
        return _span_samples(knots, degree, SURFACE_SAMPLES_PER_SPAN)
    count = grid if np.isscalar(grid) else grid[which]
    count = int(count)
    if count < 2:
        raise GeometryError(f"grid: need at least 2 samples per direction, got {count}")
    n_control = len(knots) - degree - 1
    breaks = np.unique(knots[degree : n_control + 1])
    # keep the knots in the grid so every span is sampled
    return np.unique(np.concatenate([np.linspace(breaks[0], breaks[-1], count), breaks]))


def closest_point_surface(
    surface: BSplineSurface,
    points,
    tol: float | None = None,
    grid=None,
    cos_tol: float = COSINE_TOL,
    candidates: int = CANDIDATES,
    max_iterations: int = MAX_ITERATIONS,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Parameters and distances of the closest points of ``surface`` to ``points``.

    points: shape S + (dim,). Returns (u, v, distances), each of shape S.
    tol: point-coincidence tolerance ε1 (absolute; default :data:`POINT_TOL` times
    ``surface.size()``). grid: coarse start grid, None for
    :data:`SURFACE_SAMPLES_PER_SPAN` samples per knot span, an int, or (count_u, count_v).

    Starts: up to ``candidates`` points of the grid (``surface.evaluate_grid``) that are
    discrete local minima of the distance over the grid, nearest first, each refined,
    the best kept. Newton on f = S_u·r, g = S_v·r with r = S - P (NURBS Book
    Eqs. 6.6–6.7), the Jacobian [[|S_u|² + r·S_uu, S_u·S_v + r·S_uv], [., |S_v|² + r·S_vv]]
    (Gauss–Newton's [[|S_u|², S_u·S_v], [., |S_v|²]] where that is not positive definite),
    parameters clamped to the domain (Eq. 6.8) and a parameter held at a boundary where
    the gradient points out of the domain. Steps that do not reduce |r| are halved.
    Stops on point coincidence, zero cosines in both directions or a vanishing step.

    The answer is the global closest point when its basin of attraction is resolved by
    the start grid, which is refined adaptively (:func:`_adaptive_surface_grid`); that
    holds for points near a surface that does not fold back within a grid spacing of
    itself (blade, hub and channel surfaces do not). For points far away (distance
    comparable to the size of the surface's undulations), or folded surfaces, raise
    ``grid`` to be sure.
    """
    if not isinstance(surface, BSplineSurface):
        raise GeometryError(f"closest_point_surface needs a BSplineSurface, got {type(surface).__name__}")
    P, shape = _query_points(points, surface.dim)
    eps1 = POINT_TOL * max(surface.size(), 1e-300) if tol is None else float(tol)
    us = _grid_params(surface.knots_u, surface.degree_u, grid, 0)
    vs = _grid_params(surface.knots_v, surface.degree_v, grid, 1)
    if grid is None:
        us, vs = _adaptive_surface_grid(surface, us, vs)
    G = surface.evaluate_grid(us, vs)
    k = max(1, int(candidates))
    idx = _local_minimum_starts(P, G.reshape(-1, surface.dim), G.shape[:2], k).reshape(-1)
    Pk = np.repeat(P, k, axis=0)
    u, v = _newton_surface(surface, Pk, us[idx // vs.size], vs[idx % vs.size], eps1, cos_tol, max_iterations)
    dist = np.linalg.norm(surface.evaluate(u, v) - Pk, axis=1)
    rows = np.arange(P.shape[0]) * k + np.argmin(dist.reshape(-1, k), axis=1)
    return u[rows].reshape(shape), v[rows].reshape(shape), dist[rows].reshape(shape)


def _adaptive_surface_grid(surface: BSplineSurface, us: np.ndarray, vs: np.ndarray):
    """Start-grid parameters with grid lines added (by bisection, per direction) where
    neighbouring lines are far apart (:data:`CURVE_SAMPLE_CHORD` of the size) or the
    tangent across them turns by more than :data:`CURVE_SAMPLE_TURN`, up to
    :data:`SURFACE_GRID_MAX` points: the surface analogue of the adaptive curve samples."""
    limit = CURVE_SAMPLE_CHORD * max(surface.size(), 1e-300)
    cos_turn = np.cos(CURVE_SAMPLE_TURN)

    def to_split(G, T, axis):
        chord = np.linalg.norm(np.diff(G, axis=axis), axis=-1).max(axis=1 - axis)
        a = T[:-1] if axis == 0 else T[:, :-1]
        b = T[1:] if axis == 0 else T[:, 1:]
        with np.errstate(divide="ignore", invalid="ignore"):
            cos = np.einsum("...d,...d->...", a, b) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1))
        turn = ~(cos >= cos_turn)
        return (chord > limit) | turn.any(axis=1 - axis)

    for _ in range(CURVE_SAMPLE_ROUNDS):
        D = surface.derivatives(us[:, None], vs[None, :], 1)
        G = D[..., 0, 0, :]
        split_u = to_split(G, D[..., 1, 0, :], 0)
        split_v = to_split(G, D[..., 0, 1, :], 1)
        new_u = 0.5 * (us[:-1][split_u] + us[1:][split_u])
        new_v = 0.5 * (vs[:-1][split_v] + vs[1:][split_v])
        if new_u.size + new_v.size == 0 or (us.size + new_u.size) * (vs.size + new_v.size) > SURFACE_GRID_MAX:
            break
        us, vs = np.sort(np.r_[us, new_u]), np.sort(np.r_[vs, new_v])
    return us, vs


def _newton_surface(surface, P, u, v, eps1, cos_tol, max_iterations):
    """Safeguarded Newton iteration of :func:`closest_point_surface` from (u, v)."""
    u, v = u.copy(), v.copy()
    (ua_, ub_), (va_, vb_) = surface.domain_u, surface.domain_v
    noise = ROUNDOFF * surface.size()
    active = np.arange(P.shape[0])
    for _ in range(max_iterations):
        if active.size == 0:
            break
        uu, vv, Pa = u[active], v[active], P[active]
        D = surface.derivatives(uu, vv, 2)
        r = D[:, 0, 0] - Pa
        Su, Sv = D[:, 1, 0], D[:, 0, 1]
        Suu, Suv, Svv = D[:, 2, 0], D[:, 1, 1], D[:, 0, 2]
        dot = lambda a, b: np.einsum("nd,nd->n", a, b)  # noqa: E731
        d2 = dot(r, r)
        dist = np.sqrt(d2)
        f, g = dot(Su, r), dot(Sv, r)
        nu_, nv_ = np.sqrt(dot(Su, Su)), np.sqrt(dot(Sv, Sv))
        # a parameter at a boundary whose descent direction (-gradient) points outwards is held
        hold_u = ((uu <= ua_) & (f > 0)) | ((uu >= ub_) & (f < 0))
        hold_v = ((vv <= va_) & (g > 0)) | ((vv >= vb_) & (g < 0))
        zero_u = hold_u | (np.abs(f) <= cos_tol * nu_ * dist)
        zero_v = hold_v | (np.abs(g) <= cos_tol * nv_ * dist)
        done = (dist <= eps1) | (zero_u & zero_v)
        # Newton matrix, Gauss–Newton where the Hessian is not positive definite
        Guu, Guv, Gvv = nu_**2, dot(Su, Sv), nv_**2
        Huu, Huv, Hvv = Guu + dot(r, Suu), Guv + dot(r, Suv), Gvv + dot(r, Svv)
        pd = (Huu > 0) & (Hvv > 0) & (Huu * Hvv - Huv**2 > 0)
        Auu, Auv, Avv = np.where(pd, Huu, Guu), np.where(pd, Huv, Guv), np.where(pd, Hvv, Gvv)
        det = Auu * Avv - Auv**2
        with np.errstate(divide="ignore", invalid="ignore"):
            du = np.where(hold_v, -f / Auu, (-f * Avv + g * Auv) / det)
            dv = np.where(hold_u, -g / Avv, (-g * Auu + f * Auv) / det)
        du = np.where(hold_u, 0.0, du)
        dv = np.where(hold_v, 0.0, dv)
        singular = ~np.isfinite(du) | ~np.isfinite(dv)
        # singular matrix (degenerate derivatives): steepest descent scaled to a small move
        du = np.where(singular, -f / np.maximum(Guu + Gvv, 1e-300), du)
        dv = np.where(singular, -g / np.maximum(Guu + Gvv, 1e-300), dv)
        du = np.where(singular & hold_u, 0.0, du)
        dv = np.where(singular & hold_v, 0.0, dv)
        # line search: halve steps that do not reduce the distance beyond evaluation round-off
        slack = 2.0 * dist * noise + noise**2
        todo = np.flatnonzero(~done)
        un, vn = uu.copy(), vv.copy()
        accepted = np.zeros(active.size, dtype=bool)
        scale = 1.0
        for _h in range(MAX_HALVINGS):
            if todo.size == 0:
                break
            cu = np.clip(uu[todo] + scale * du[todo], ua_, ub_)
            cv = np.clip(vv[todo] + scale * dv[todo], va_, vb_)
            dn = surface.evaluate(cu, cv) - Pa[todo]
            better = np.einsum("nd,nd->n", dn, dn) <= d2[todo] + slack[todo]
            ok = todo[better]
            un[ok], vn[ok] = cu[better], cv[better]
            accepted[ok] = True
            todo = todo[~better]
            scale *= 0.5
        # no reducing step at all: the start is as good as this iteration can make it
        done |= ~accepted
        move = np.sqrt(
            np.einsum("nd,nd->n", (un - uu)[:, None] * Su + (vn - vv)[:, None] * Sv,
                      (un - uu)[:, None] * Su + (vn - vv)[:, None] * Sv)
        )
        u[active], v[active] = np.where(done, uu, un), np.where(done, vv, vn)
        done |= move <= eps1
        active = active[~done]
    return u, v


def refine_closest_points(surface: BSplineSurface, points, u, v, tol: float | None = None,
                          cos_tol: float = COSINE_TOL, max_iterations: int = MAX_ITERATIONS):
    """The safeguarded Newton iteration of :func:`closest_point_surface` (NURBS Book
    Eqs. 6.6–6.8) from given start parameters, without the start grid: for callers that
    already hold good starts (e.g. the nearest point of a dense tessellation).
    points (n, dim), u, v (n,). Returns (u, v, distances), each (n,)."""
    P, shape = _query_points(points, surface.dim)
    eps1 = POINT_TOL * max(surface.size(), 1e-300) if tol is None else float(tol)
    u, v = _newton_surface(surface, P, np.asarray(u, dtype=np.float64).ravel().copy(),
                           np.asarray(v, dtype=np.float64).ravel().copy(), eps1, cos_tol, max_iterations)
    dist = np.linalg.norm(surface.evaluate(u, v) - P, axis=1)
    return u.reshape(shape), v.reshape(shape), dist.reshape(shape)
