"""Closest points on B-spline curves from a good parameter guess, many curves in one
vectorised pass, certified global, with the general search
(:func:`.projection.closest_point_curve`) only where the certificate fails.

For the deviation measurements (a smoothed curve against its original, the fitted
sections of a mold against their data) every query point already has a parameter close
to its foot: the parameter it was sampled at on a curve with the same knots, or the one it
was fitted at. The general search spends its time finding starts (adaptive samples,
brackets, several Newton starts per point), one curve per call; here each point gets the
bracketed Newton iteration of the general search (NURBS Book §6.1, Eqs. 6.3–6.5) on the
window of three knot spans around its guess, all points of all curves at once, and two
bounds make the answer the global closest point. Per knot span, from the span's Taylor
expansion C(u) = Σ_a (u - m)^a T_a about its midpoint m (the curve's span table), with h
half the span's length: a disc of centre T_0 and radius ρ = Σ_{a>=1} |T_a| h^a holds the
span, |C'| >= |T_1| - Σ_{a>=2} a |T_a| h^(a-1) and |C''| <= Σ_{a>=2} a (a-1) |T_a| h^(a-2).

1. One minimum in the window: with f = C'·(C - P), f' = |C'|² + C''·(C - P) > 0 on every
   span of the window when |C'|² > |C''| (|P - T_0| + ρ) there; then f increases across
   the window, and the window's minimum is the root of f (bracketed by the sign change
   of f at the window's ends) or the end where f has the sign of a minimum. Where this
   fails on the whole window, its spans are cut into pieces with their own bounds
   (:func:`_window_pieces`).
2. Nothing nearer elsewhere: every span outside the window has |P - T_0| - ρ >= d, d the
   window's distance (tested through anchor points, :func:`_others_farther`); where a
   span does not, the window around it is solved as well and the least distance kept.

Points that fail are given to :func:`.projection.closest_point_curve` unchanged, and so
are all points of rational curves or curves of degree < 2."""
from __future__ import annotations

from math import factorial

import numpy as np

from .basis import find_span, monomial_derivatives, taylor_matrices
from .curve import BSplineCurve
from .projection import COSINE_TOL, MAX_ITERATIONS, POINT_TOL, _query_points, closest_point_curve

#: Pieces per knot span of the finer test of :func:`_window_pieces`.
WINDOW_PIECES = 8
#: Knot spans per group of :func:`_others_farther` (one anchor point per group).
GROUP_SPANS = 4
#: Relative slack of the bounds (round-off of the span table and of the sums).
BOUND_SLACK = 1e-9


def _norm(x: np.ndarray) -> np.ndarray:
    """Euclidean norms over the last (short) axis, for the bounds."""
    return np.sqrt(np.einsum("...d,...d->...", x, x))


class _Spans:
    """The non-empty knot spans of several non-rational curves of one degree and
    dimension, numbered consecutively curve after curve (global span g): span table rows,
    ends, owning curve, and the bounds of the module docstring."""

    def __init__(self, curves):
        p = curves[0].degree
        self.p = p
        mids, tables, lo, hi, owner = [], [], [], [], []
        self.size = np.array([max(c.size(), 1e-300) for c in curves])
        start = 0
        self.first = np.empty(len(curves), dtype=np.intp)
        self.count = np.empty(len(curves), dtype=np.intp)
        shared = {}  # Taylor matrices per knot vector (a blade's sections share theirs)
        for k, c in enumerate(curves):
            U, n = c.knots, c.n_control
            if "_span_table" in c.__dict__:
                mid, table = c._span_table
            else:  # the curve's span table (BSplineCurve._span_table), its matrices shared
                key = (U.tobytes(), n)
                if key not in shared:
                    shared[key] = taylor_matrices(U, p, n)
                mid, T = shared[key]
                windows = np.lib.stride_tricks.sliding_window_view(c.control_points, p + 1, axis=0)
                table = np.einsum("iac,idc->iad", T, windows)
            br = np.unique(U[p: n + 1])
            i = find_span(U, p, 0.5 * (br[:-1] + br[1:])) - p
            mids.append(mid[i])
            tables.append(table[i])
            lo.append(br[:-1])
            hi.append(br[1:])
            owner.append(np.full(br.size - 1, k))
            self.first[k], self.count[k] = start, br.size - 1
            start += br.size - 1
        self.mid = np.concatenate(mids)
        self.table = np.concatenate(tables)  # (spans, p+1, dim)
        self.lo, self.hi = np.concatenate(lo), np.concatenate(hi)
        self.owner = np.concatenate(owner)
        # span search over all curves at once: curve k's span ends shifted by k * shift
        reach = float(np.max(np.abs(np.r_[self.lo, self.hi]))) if self.hi.size else 1.0
        self.shift = float(2.0 ** np.ceil(np.log2(4.0 * max(reach, 1.0))))  # > any domain's width
        self.keys = self.lo + self.owner * self.shift
        norms = _norm(self.table)  # (spans, p+1)
        h = 0.5 * (self.hi - self.lo)
        a = np.arange(p + 1)
        hp = h[:, None] ** a
        slack = 1.0 + BOUND_SLACK
        self.centre = self.table[:, 0]
        self.radius = slack * np.sum(norms[:, 1:] * hp[:, 1:], axis=1)
        speed = norms[:, 1] - slack * np.sum(a[2:] * norms[:, 2:] * hp[:, 1:-1], axis=1)
        self.speed = np.where(speed > 0, speed, 0.0)
        self.bend = slack * np.sum(a[2:] * (a[2:] - 1) * norms[:, 2:] * hp[:, :-2], axis=1)

    def span(self, k: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Global span of parameter u on curve k (the span find_span picks)."""
        g = np.searchsorted(self.keys, u + k * self.shift, side="right") - 1
        return np.clip(g, self.first[k], self.first[k] + self.count[k] - 1)

    def derivatives(self, g: np.ndarray, u: np.ndarray, order: int) -> np.ndarray:
        """C and its derivatives up to ``order`` at u on global spans g: (n, order+1, dim),
        the arithmetic of :meth:`BSplineCurve.derivatives` for many points per span."""
        M = monomial_derivatives(u - self.mid[g], self.p, order)
        return np.matmul(M.transpose(1, 0, 2), self.table[g])

    def horner(self, g: np.ndarray, u: np.ndarray, order: int) -> list[np.ndarray]:
        """[C, C', ...] up to ``order`` (<= 2) at u on spans g by Horner's rule on the span
        table: fewer operations than :meth:`derivatives` (the Newton steps), equal to
        rounding."""
        T = self.table[g]
        t = (u - self.mid[g])[:, None]
        p = self.p
        c = T[:, p]
        for a in range(p - 1, -1, -1):
            c = c * t + T[:, a]
        out = [c]
        if order >= 1:
            c = p * T[:, p]
            for a in range(p - 1, 0, -1):
                c = c * t + a * T[:, a]
            out.append(c)
        if order >= 2:
            c = (p * (p - 1)) * T[:, p]
            for a in range(p - 1, 1, -1):
                c = c * t + (a * (a - 1)) * T[:, a]
            out.append(c)
        return out

    def same(self, g: np.ndarray, k: np.ndarray) -> np.ndarray:
        """Is g a span (index in range) of curve k?"""
        return (g >= self.first[k]) & (g < self.first[k] + self.count[k])


def closest_points_near(curves, points, guess, which=None, tol: float | None = None,
                        cos_tol: float = COSINE_TOL, max_iterations: int = MAX_ITERATIONS,
                        stats: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Parameters and distances of the closest points of ``curves[which[i]]`` to
    ``points[i]`` (n, dim), given a parameter ``guess[i]`` near each foot (one curve:
    ``curves`` may be a curve and ``which`` None). The same answer as
    :func:`.projection.closest_point_curve` per curve (the global closest point, to its
    tolerances: ``tol`` absolute or :data:`.projection.POINT_TOL` times each curve's size),
    see the module docstring. ``stats``: if a dict, gets ``fallback``, the number of points
    given to the general search. Returns (params, distances), each (n,)."""
    if isinstance(curves, BSplineCurve):
        curves = [curves]
    curves = list(curves)
    dim = curves[0].dim
    P, _ = _query_points(points, dim)
    n = P.shape[0]
    k = np.zeros(n, dtype=np.intp) if which is None else np.asarray(which, dtype=np.intp).reshape(-1)
    u0 = np.asarray(guess, dtype=np.float64).reshape(-1)
    if u0.size != n or k.size != n:
        raise ValueError(f"guess and which: expected {n} entries, got {u0.size} and {k.size}")
    u = np.empty(n)
    dist = np.empty(n)
    fast = [not c.is_rational and c.degree >= 2 and c.degree == curves[0].degree and c.dim == dim for c in curves]
    ok = np.zeros(n, dtype=bool)
    if n and all(fast):
        S = _spans(curves)
        eps = S.size * POINT_TOL if tol is None else np.full(len(curves), float(tol))
        eps1 = eps[k]
        a, b = S.lo[S.first[k]], S.hi[S.first[k] + S.count[k] - 1]
        u0 = np.clip(np.where(np.isfinite(u0), u0, a), a, b)
        g = S.span(k, u0)
        ur, d, ok = _solve_windows(S, P, k, g, u0, eps1, cos_tol, max_iterations)
        clear, cand_p, cand_g = _others_farther(S, P, k, d, g, ok)
        if cand_p.size:
            uc, dc, okc = _solve_windows(S, P[cand_p], k[cand_p], cand_g, None, eps1[cand_p], cos_tol, max_iterations)
            failed = np.unique(cand_p[~okc])
            better = okc & (dc < d[cand_p])
            order = np.argsort(-dc[better], kind="stable")  # the least last: it wins the assignment
            bp = cand_p[better][order]
            ur[bp], d[bp] = uc[better][order], dc[better][order]
            clear[np.unique(cand_p)] = True
            clear[failed] = False
        ok &= clear
        u[ok], dist[ok] = ur[ok], d[ok]
    fb = ~ok
    if stats is not None:
        stats["fallback"] = int(np.count_nonzero(fb))
    for c in np.unique(k[fb]):
        rows = np.flatnonzero(fb & (k == c))
        u[rows], dist[rows] = closest_point_curve(curves[c], P[rows], tol=tol, cos_tol=cos_tol,
                                                  max_iterations=max_iterations)
    return u, dist


def closest_point_curve_near(curve: BSplineCurve, points, guess, tol: float | None = None,
                             cos_tol: float = COSINE_TOL, max_iterations: int = MAX_ITERATIONS,
                             stats: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`closest_points_near` for one curve; points S + (dim,), guess S; returns
    (params, distances) of shape S."""
    P, shape = _query_points(points, curve.dim)
    u, d = closest_points_near([curve], P, np.asarray(guess, dtype=np.float64).reshape(-1), None, tol, cos_tol,
                               max_iterations, stats)
    return u.reshape(shape), d.reshape(shape)


def _spans(curves) -> _Spans:
    if len(curves) == 1:  # cached on the (frozen) curve, like its span table
        c = curves[0]
        s = c.__dict__.get("_near_spans")
        if s is None:
            s = c.__dict__["_near_spans"] = _Spans(curves)
        return s
    return _Spans(curves)


def _newton(S: _Spans, P, k, u, lo, hi, eps1, cos_tol, max_iterations) -> np.ndarray:
    """The bracketed Newton iteration of :func:`.projection.closest_point_curve` (NURBS
    Book Eqs. 6.3–6.5; bisection when a step leaves the bracket [lo, hi] or f' <= 0), on
    the span tables; u, lo, hi are updated in place."""
    active = np.arange(P.shape[0])
    for _ in range(max_iterations):
        if active.size == 0:
            break
        ua, ka = u[active], k[active]
        c0, d1, d2 = S.horner(S.span(ka, ua), ua, 2)
        r = c0 - P[active]
        dist = np.sqrt(np.einsum("nd,nd->n", r, r))
        speed2 = np.einsum("nd,nd->n", d1, d1)
        speed = np.sqrt(speed2)
        f = np.einsum("nd,nd->n", d1, r)
        fp = np.einsum("nd,nd->n", d2, r) + speed2
        ea = eps1[active]
        done = (dist <= ea) | (np.abs(f) <= cos_tol * speed * dist)
        neg = f < 0
        lo[active[neg]] = ua[neg]
        hi[active[~neg]] = ua[~neg]
        la, ha = lo[active], hi[active]
        with np.errstate(divide="ignore", invalid="ignore"):
            un = ua - f / fp
        bad = ~(fp > 0) | ~(un >= la) | ~(un <= ha)
        un = np.where(bad, 0.5 * (la + ha), un)
        done |= np.abs(un - ua) * speed <= ea
        keep = ~done
        u[active[keep]] = un[keep]
        active = active[keep]
    return u


def _solve_windows(S, P, k, g, u0, eps1, cos_tol, max_iterations):
    """(u, d, ok) of :func:`_window_minimum`, with :func:`_window_pieces` where it fails."""
    u, d, ok = _window_minimum(S, P, k, g, u0, eps1, cos_tol, max_iterations)
    if not ok.all():
        fine = np.flatnonzero(~ok)
        u[fine], d[fine], ok[fine] = _window_pieces(S, P[fine], k[fine], g[fine], eps1[fine], cos_tol, max_iterations)
    return u, d, ok


def _window_spans(S, k, g):
    """Spans g-1, g, g+1 (clipped to the curve) and which of them are the curve's."""
    raw = g[:, None] + np.arange(-1, 2)
    inside = S.same(raw, k[:, None])
    return np.where(inside, raw, g[:, None]), inside


def _window_minimum(S, P, k, g, u0, eps1, cos_tol, max_iterations):
    """The closest point of the window of spans g-1..g+1 to each P, and whether it is
    certified (bound 1 of the module docstring): (u, d, ok), d = inf where not ok.
    u0 None: start where the chord of f between the window's ends crosses zero."""
    w, inside = _window_spans(S, k, g)
    glo, ghi = w[:, 0], w[:, 2]
    lo, hi = S.lo[glo], S.hi[ghi]
    m = P.shape[0]
    c0, c1 = S.horner(np.concatenate([glo, ghi]), np.concatenate([lo, hi]), 1)
    f = np.einsum("nd,nd->n", c1, c0 - np.concatenate([P, P]))
    f_lo, f_hi = f[:m], f[m:]
    far = _norm(S.centre[w] - P[:, None]) + S.radius[w]
    unique = np.all(~inside | (S.speed[w] ** 2 > S.bend[w] * far), axis=1)
    root = unique & (f_lo < 0) & (f_hi > 0)
    at_lo = unique & (f_lo >= 0)
    at_hi = unique & ~at_lo & (f_hi <= 0)
    if u0 is None:
        with np.errstate(divide="ignore", invalid="ignore"):
            u0 = np.where(root, lo - f_lo * (hi - lo) / (f_hi - f_lo), 0.5 * (lo + hi))
    u = np.where(at_lo, lo, np.where(at_hi, hi, np.clip(u0, lo, hi)))
    r = np.flatnonzero(root)
    if r.size:
        u[r] = _newton(S, P[r], k[r], u[r], lo[r].copy(), hi[r].copy(), eps1[r], cos_tol, max_iterations)
    ok = root | at_lo | at_hi
    d = np.full(m, np.inf)
    if ok.any():
        i = np.flatnonzero(ok)
        d[i] = np.linalg.norm(S.derivatives(S.span(k[i], u[i]), u[i], 0)[:, 0] - P[i], axis=1)
    return u, d, ok


def _window_pieces(S, P, k, g, eps1, cos_tol, max_iterations):
    """:func:`_window_minimum` for the points whose window fails bound 1 as a whole (a
    tightly curved stretch, e.g. next to a sharp trailing edge): each span of the window
    cut into :data:`WINDOW_PIECES` pieces, each with the bounds of the module docstring
    from its own Taylor expansion. A piece whose disc lies no nearer than the nearest
    piece end is left out; every other piece must have f increasing (else the point is not
    certified), and holds a minimum only where f changes sign from - to + across it
    (found by the bracketed Newton iteration). The least of those minima and of the piece
    ends is the window's minimum. Returns (u, d, ok)."""
    p, m, K = S.p, P.shape[0], WINDOW_PIECES
    w, valid = _window_spans(S, k, g)  # (m, 3)
    frac = np.arange(K + 1) / K
    ends = S.lo[w][..., None] + (S.hi[w] - S.lo[w])[..., None] * frac  # (m, 3, K+1)
    a_, b_ = ends[..., :-1], ends[..., 1:]
    mids, h = 0.5 * (a_ + b_), 0.5 * (b_ - a_)
    gw = np.broadcast_to(w[..., None], mids.shape)
    D = S.derivatives(gw.ravel(), mids.ravel(), p).reshape(m, 3, K, p + 1, -1)
    T = D / np.array([factorial(j) for j in range(p + 1)])[:, None]
    norms = _norm(T)  # (m, 3, K, p+1)
    j = np.arange(p + 1)
    hp = h[..., None] ** j
    slack = 1.0 + BOUND_SLACK
    radius = slack * np.sum(norms[..., 1:] * hp[..., 1:], axis=-1)
    speed = norms[..., 1] - slack * np.sum(j[2:] * norms[..., 2:] * hp[..., 1:-1], axis=-1)
    bend = slack * np.sum(j[2:] * (j[2:] - 1) * norms[..., 2:] * hp[..., :-2], axis=-1)
    centre_gap = _norm(T[..., 0, :] - P[:, None, None])
    ge = np.broadcast_to(w[..., None], ends.shape)
    E = S.derivatives(ge.ravel(), ends.ravel(), 1).reshape(m, 3, K + 1, 2, -1)
    r = E[..., 0, :] - P[:, None, None]
    f = np.einsum("...d,...d->...", E[..., 1, :], r)  # (m, 3, K+1)
    dist_ends = np.where(valid[..., None], np.linalg.norm(r, axis=-1), np.inf)
    flat = dist_ends.reshape(m, -1)
    best_end = np.argmin(flat, axis=1)
    d_ub = flat[np.arange(m), best_end]
    u = ends.reshape(m, -1)[np.arange(m), best_end]
    excluded = ~valid[..., None] | (centre_gap - radius >= d_ub[:, None, None])
    mono = (speed > 0) & (speed**2 > bend * (centre_gap + radius))
    ok = np.all(excluded | mono, axis=(1, 2))
    d = np.where(ok, d_ub, np.inf)
    pick = ok[:, None, None] & ~excluded & mono & (f[..., :-1] < 0) & (f[..., 1:] > 0)
    pi, si, ki = np.nonzero(pick)
    if pi.size:
        lo, hi = a_[pi, si, ki], b_[pi, si, ki]
        fl, fh = f[pi, si, ki], f[pi, si, ki + 1]
        start = np.clip(lo - fl * (hi - lo) / (fh - fl), lo, hi)
        uc = _newton(S, P[pi], k[pi], start, lo.copy(), hi.copy(), eps1[pi], cos_tol, max_iterations)
        dc = np.linalg.norm(S.derivatives(S.span(k[pi], uc), uc, 0)[:, 0] - P[pi], axis=1)
        order = np.argsort(-dc, kind="stable")  # the least last: it wins the assignment
        pi, uc, dc = pi[order], uc[order], dc[order]
        better = dc < d[pi]
        d[pi[better]], u[pi[better]] = dc[better], uc[better]
    return u, d, ok


def _padded_spans(S, k, centre_g=None, half=None):
    """Spans of each point's curve k, (n, max count), and which entries are real; with
    ``centre_g`` and ``half``: only the spans within ``half`` of centre_g."""
    if centre_g is None:
        width = int(S.count.max())
        g = S.first[k][:, None] + np.arange(width)
    else:
        g = centre_g[:, None] + np.arange(-half, half + 1)
    valid = S.same(g, k[:, None])
    return np.where(valid, g, S.first[k][:, None]), valid


def _others_farther(S, P, k, d, g, ok):
    """For the points with ``ok``: is every span t of the point's curve outside its window
    g-1..g+1 at least d away by its disc, |P - c_t| - ρ_t >= d? The points are grouped by
    curve and g // G (G = :data:`GROUP_SPANS`), each group with one anchor point A (its
    middle one by span): the spans farther than G from the anchor's span are tested once
    for A and for a member P by |P - c_t| - ρ_t >= |A - c_t| - ρ_t - |P - A| (triangle
    inequality), the 2G + 1 spans around the anchor's directly. The points this does not
    clear get the disc test against every span of their curve. Returns (clear, point
    index, span) with the (point, span) pairs the disc test leaves open."""
    clear = np.zeros(P.shape[0], dtype=bool)
    none = np.empty(0, dtype=np.intp)
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        return clear, none, none
    G = GROUP_SPANS
    gi, Pi, di, ki = g[idx], P[idx], d[idx], k[idx]
    order = np.argsort(gi, kind="stable")  # global spans: grouped by curve too
    group = gi[order] // G
    starts = np.flatnonzero(np.r_[True, (group[1:] != group[:-1]) | (ki[order][1:] != ki[order][:-1])])
    counts = np.diff(np.r_[starts, group.size])
    first = order[starts + counts // 2]  # each group's anchor
    member = np.empty(gi.size, dtype=np.intp)
    member[order] = np.repeat(np.arange(starts.size), counts)
    anchor = first[member]
    ga, ka = gi[first], ki[first]
    t, valid = _padded_spans(S, ka)
    gaps = _norm(S.centre[t] - Pi[first][:, None]) - S.radius[t]
    gaps[~valid | (np.abs(t - ga[:, None]) <= G)] = np.inf
    beyond = gaps.min(axis=1)[member] - _norm(Pi - Pi[anchor])
    band, bvalid = _padded_spans(S, ki, ga[member], G)
    near = _norm(S.centre[band] - Pi[:, None]) - S.radius[band]
    near[~bvalid | (np.abs(band - gi[:, None]) <= 1)] = np.inf
    near_ok = near.min(axis=1) >= di
    done = (beyond >= di) & near_ok
    clear[idx[done]] = True
    if done.all():
        return clear, none, none
    # the rest: the spans beyond the band that the anchor's bound leaves open, and every
    # span of the band, get the disc test
    r = np.flatnonzero(~done)
    t, valid = _padded_spans(S, ka[member[r]])
    maybe = gaps[member[r]] - _norm(Pi[r] - Pi[anchor[r]])[:, None] < di[r][:, None]  # beyond the band
    maybe |= valid & (np.abs(t - ga[member[r]][:, None]) <= G)  # the band
    maybe &= np.abs(t - gi[r][:, None]) > 1
    i, j = np.nonzero(maybe)
    tt = t[i, j]
    rows = idx[r[i]]
    gap = _norm(S.centre[tt] - P[rows]) - S.radius[tt]
    open_ = gap < d[rows]
    clear[idx[r]] = True
    clear[rows[open_]] = False
    return clear, rows[open_], tt[open_]
