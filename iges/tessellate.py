"""Triangle meshes of trimmed surfaces, for display only (Blender has no trimmed NURBS).

A trimmed face is tessellated in its parameter plane: the trimming loops become closed
polylines (uv), a regular grid fills the inside, points too near a loop are dropped, the
lot is Delaunay-triangulated (scipy.spatial.Delaunay) and triangles whose centroid lies
outside the region (even-odd rule: inside the outer loop, outside every hole) are
removed. The parameter plane is first stretched by the mean speeds |S_u| and |S_v| so
that triangles are roughly isotropic on the surface.

The mesh is refined until the largest chordal deviation, measured at triangle centroids
and edge midpoints against the exact surface, is within the display tolerance (each
failing probe point becomes a vertex), or until the point budget or the rounds are spent; the achieved deviation is returned so that a miss is reported,
never hidden.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import Delaunay, QhullError, cKDTree

from ..geometry.errors import IgesError

#: Refinement rounds (each adds the failing probe points as vertices) before giving up.
MAX_ROUNDS = 8
#: First grid: this many cells across the larger side of the loop's bounding box.
START_CELLS = 16
#: Refinement adds no vertex nearer than this fraction of the face's larger side to another.
MIN_SPACING = 1e-4
#: Triangles of less (doubled) area than this fraction of the face's larger side squared are dropped.
SLIVER_AREA = 1e-12
#: Least stretch of one parameter direction relative to the other.
MIN_STRETCH = 1e-3
#: Most vertices of one face's display mesh (a tolerance missed at this size is reported).
MAX_FACE_POINTS = 20_000
#: Points are moved by at most this fraction of a grid cell for Qhull only (see tessellate).
JITTER = 1e-9
#: (point, edge) crossings formed at once by the point-in-polygon test (bounds its memory).
PAIR_CHUNK = 1 << 20


@dataclass(frozen=True)
class TrimmedMesh:
    """vertices (n, 3) float64 on the surface; triangles (m, 3) int; uv (n, 2) parameters;
    deviation: largest measured distance between the mesh and the surface."""

    vertices: np.ndarray
    triangles: np.ndarray
    uv: np.ndarray
    deviation: float
    #: why refinement stopped short of the tolerance ("" when it did not)
    stopped: str = ""


def inside(points: np.ndarray, loops: list) -> np.ndarray:
    """Even-odd rule: True where ``points`` (k, 2) lie inside the region bounded by the
    closed polylines ``loops`` (each (m, 2), last point joined to the first).

    A point lies inside when an odd number of edges cross the ray from it in +x: edges with
    ylo <= y < yhi whose crossing abscissa is beyond the point. With the points sorted by y,
    each edge finds the points of its y-range by binary search, so only the (point, edge)
    pairs that do cross are formed (in chunks of :data:`PAIR_CHUNK`): the work is the
    number of crossings, not points x edges."""
    points = np.asarray(points, dtype=np.float64)
    odd = np.zeros(len(points), dtype=bool)
    if not len(points):
        return odd
    A = np.concatenate(loops)
    B = np.concatenate([np.roll(l, -1, axis=0) for l in loops])
    ylo, yhi = np.minimum(A[:, 1], B[:, 1]), np.maximum(A[:, 1], B[:, 1])
    keep = yhi > ylo  # horizontal edges never cross a horizontal ray
    A, B, ylo, yhi = A[keep], B[keep], ylo[keep], yhi[keep]
    if not len(A):
        return odd
    slope = (B[:, 0] - A[:, 0]) / (B[:, 1] - A[:, 1])
    py = points[:, 1]
    order = np.argsort(py, kind="stable")
    ys = py[order]
    first = np.searchsorted(ys, ylo, side="left")  # points with ylo <= y < yhi
    count = np.searchsorted(ys, yhi, side="left") - first
    ends = np.cumsum(count)
    parity = np.zeros(len(points), dtype=np.int64)
    e0 = 0
    while e0 < len(A):
        # the edges e0..e1-1 make at most PAIR_CHUNK pairs (at least one edge)
        base = ends[e0 - 1] if e0 else 0
        e1 = max(e0 + 1, int(np.searchsorted(ends, base + PAIR_CHUNK, side="right")))
        c = count[e0:e1]
        n = int(c.sum())
        if n:
            edge = np.repeat(np.arange(e0, e1), c)
            rank = np.repeat(first[e0:e1] - (np.cumsum(c) - c), c) + np.arange(n)
            pt = order[rank]
            xint = A[edge, 0] + (py[pt] - A[edge, 1]) * slope[edge]
            parity += np.bincount(pt[points[pt, 0] < xint], minlength=len(points))
        e0 = e1
    odd[:] = parity % 2 == 1
    return odd


def _flipped(P: np.ndarray, Q: np.ndarray, tri: np.ndarray, sliver: float) -> np.ndarray:
    """Triangles ``tri`` whose orientation differs between the vertex sets P and Q, among
    those of (doubled) area above ``sliver`` in P."""

    def doubled_area(X):
        e1, e2 = X[tri[:, 1]] - X[tri[:, 0]], X[tri[:, 2]] - X[tri[:, 0]]
        return e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]

    a = doubled_area(P)
    return (np.abs(a) > sliver) & (np.sign(a) != np.sign(doubled_area(Q)))


def _resample(loop: np.ndarray, step: float, max_points: int) -> np.ndarray:
    """The closed polyline ``loop`` with every segment longer than ``step`` subdivided."""
    b = np.roll(loop, -1, axis=0)
    seg = np.linalg.norm(b - loop, axis=1)
    k = np.maximum(1, np.ceil(np.minimum(seg / step, max_points)).astype(np.int64))
    if int(k.sum()) > max_points:
        raise IgesError(f"meshing the trimmed face needs more than the budget of {max_points} points")
    # segment i gives loop[i] + (b[i] - loop[i]) * j / k[i], j = 0 .. k[i] - 1 (all at once)
    seg_of = np.repeat(np.arange(len(loop)), k)
    j = np.arange(len(seg_of)) - np.repeat(np.cumsum(k) - k, k)
    return loop[seg_of] + (b - loop)[seg_of] * (j / k[seg_of])[:, None]


#: Loop points are thinned to this fraction of the display tolerance (:func:`_thin`).
THIN_FRACTION = 0.1
#: Rounds of :func:`_thin` before every point still off its chord is kept.
THIN_ROUNDS = 64


def _thin(evaluate, uv: np.ndarray, points: np.ndarray, tol: float) -> np.ndarray:
    """Indices (ascending) of the points of a closed trimming loop to keep: ``uv`` (m, 2) in
    the parameter plane, ``points`` (m, 3) = S(uv). Douglas–Peucker (Ramer 1972; Douglas &
    Peucker 1973), run on all chords at once, each round adding the farthest point of every
    chord that misses. A dropped point misses when it lies farther than ``tol`` from the 3-D
    chord AB between the kept points on either side, or when the surface at the (u, v)
    chord's point a + s (b - a) lies farther than ``tol`` from A + s (B - A), s being the
    point's place between the two by index (so that the surface is probed all along the
    chord even where the dropped points gather in 3-D, as on an edge collapsed to a pole):
    the mesh's boundary edge must be near both the loop and the surface next to it.

    A trimming loop sampled per knot span of long, many-span curves (a blade root edge) can
    hold thousands of points within the display tolerance of a few chords; as mesh
    vertices they spent the face's point budget before the inside was refined."""
    m = len(points)
    if m <= 8 or not tol > 0:
        return np.arange(m)
    P = np.concatenate([points, points[:1]])  # closed: point m is point 0
    UV = np.concatenate([uv, uv[:1]])
    keep = np.zeros(m + 1, dtype=bool)
    keep[[0, m // 3, (2 * m) // 3, m]] = True
    at = np.arange(m + 1)
    for _ in range(THIN_ROUNDS):
        idx = np.nonzero(keep)[0]
        seg = np.minimum(np.searchsorted(idx, at, side="right") - 1, len(idx) - 2)
        a, b = P[idx[seg]], P[idx[seg + 1]]
        ab = b - a
        L2 = np.einsum("ij,ij->i", ab, ab)
        t = np.clip(np.einsum("ij,ij->i", P - a, ab) / np.where(L2 > 0, L2, 1.0), 0.0, 1.0)
        foot = a + t[:, None] * ab
        d = np.linalg.norm(P - foot, axis=1)
        free = ~keep
        i0, i1 = idx[seg[free]], idx[seg[free] + 1]
        s_ = ((at[free] - i0) / (i1 - i0))[:, None]  # by index: spread along the chord
        w = UV[i0] + s_ * (UV[i1] - UV[i0])
        on_surface = evaluate(w[:, 0], w[:, 1])
        d[free] = np.maximum(d[free], np.linalg.norm(on_surface - (P[i0] + s_ * (P[i1] - P[i0])), axis=1))
        d[~np.isfinite(d)] = np.inf
        d[keep] = 0.0
        far = d > tol
        if not far.any():
            return np.nonzero(keep[:m])[0]
        order = np.lexsort((-d, seg))  # by chord, farthest first
        first = order[np.r_[True, seg[order][1:] != seg[order][:-1]]]
        keep[first[far[first]]] = True
    keep[:m] |= far[:m]  # rounds spent: keep every point still off its chord
    return np.nonzero(keep[:m])[0]


def tessellate(evaluate, loops_uv: list, tolerance: float, max_points: int) -> TrimmedMesh:
    """Mesh of the region of the surface ``evaluate(u, v) -> (..., 3)`` bounded by
    ``loops_uv`` (first the outer loop, then holes; each a closed polyline (m, 2) in the
    surface's parameter space), with chordal deviation within ``tolerance`` if the budget
    of ``max_points`` vertices allows (see :class:`TrimmedMesh`.deviation).
    IgesError when the loops bound no area."""
    max_points = min(int(max_points), MAX_FACE_POINTS)
    loops_uv = [np.asarray(l, dtype=np.float64) for l in loops_uv if len(l) >= 3]
    if not loops_uv:
        raise IgesError("the trimming loops bound no area")
    # loops hold the points needed within THIN_FRACTION of the tolerance, no more
    thinned = []
    for l in loops_uv:
        Xl = evaluate(l[:, 0], l[:, 1])
        if np.all(np.isfinite(Xl)):
            l = l[_thin(evaluate, l, Xl, THIN_FRACTION * tolerance)]
        thinned.append(l)
    loops_uv = thinned
    outer = loops_uv[0]
    lo, hi = outer.min(axis=0), outer.max(axis=0)
    span = hi - lo
    if not np.all(span > 0) or not np.all(np.isfinite(span)):
        raise IgesError(f"the outer trimming loop spans {span.tolist()} in (u, v): no area")
    # metric stretch: mean speeds of S along u and v over the loop's box
    g = np.linspace(0.0, 1.0, 9)
    U, V = np.meshgrid(lo[0] + g * span[0], lo[1] + g * span[1], indexing="ij")
    X = evaluate(U, V)
    su = float(np.mean(np.linalg.norm(np.diff(X, axis=0), axis=-1))) / (span[0] / 8) + 1e-300
    sv = float(np.mean(np.linalg.norm(np.diff(X, axis=1), axis=-1))) / (span[1] / 8) + 1e-300
    scale = np.array([su, sv])
    # a direction in which the surface hardly moves (a pole, a degenerate patch) still gets
    # points: its stretch is floored at a fraction of the other's
    scale = np.maximum(scale, MIN_STRETCH * scale.max())
    if not np.all(np.isfinite(scale)):
        raise IgesError("the surface is not finite over its trimming loops")
    mloops = [(l - lo) * scale for l in loops_uv]
    width = span * scale
    h = float(width.max()) / START_CELLS
    best = None
    B = np.concatenate([_resample(l, h, max_points) for l in mloops])
    nx, ny = (np.ceil(width / h).astype(int) + 1).tolist()
    gx = np.linspace(0.0, width[0], nx)
    gy = np.linspace(0.0, width[1], ny)
    G = np.stack(np.meshgrid(gx, gy, indexing="ij"), axis=-1).reshape(-1, 2)
    d, _ = cKDTree(B).query(G)
    G = G[(d > 0.5 * h)]
    if len(G):
        G = G[inside(G, mloops)]
    P = np.unique(np.concatenate([B, G]), axis=0)
    if len(P) < 3:
        raise IgesError("the trimming loops bound no area")
    if len(P) > max_points:
        raise IgesError(f"meshing the trimmed face needs more than the budget of {max_points} points")
    X = evaluate(*(P / scale + lo).T)
    floor = MIN_SPACING * h * START_CELLS
    # Qhull is given the points moved by a fixed pseudo-random fraction JITTER of a cell:
    # the regular grid's four co-circular points per cell make it merge and re-triangulate
    # facets (two to three times slower). The triangles are a valid mesh of the unmoved
    # points when none of non-negligible area changes orientation; loop points closer
    # together than the jitter can make one flip, and that round is triangulated unmoved.
    jitter = np.random.default_rng(0).uniform(-JITTER * h, JITTER * h, size=P.shape)
    sliver = SLIVER_AREA * float(width.max()) ** 2
    for _ in range(MAX_ROUNDS):
        try:
            tri = Delaunay(P + jitter).simplices
            if np.any(_flipped(P, P + jitter, tri, sliver)):
                tri = Delaunay(P).simplices
        except QhullError:  # degenerate: all loop points on a line
            raise IgesError("the trimming loops are degenerate (all points on a line)") from None
        centroids = P[tri].mean(axis=1)
        kept = inside(centroids, mloops)
        tri, centroids = tri[kept], centroids[kept]
        # Qhull leaves slivers of (almost) zero area along straight runs of loop points:
        # they show nothing and their chords are not part of the surface
        e1, e2 = P[tri[:, 1]] - P[tri[:, 0]], P[tri[:, 2]] - P[tri[:, 0]]
        big = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) > sliver
        tri, centroids = tri[big], centroids[big]
        if not len(tri):
            raise IgesError("the trimming loops bound no area")
        if not np.all(np.isfinite(X)):
            raise IgesError("the surface is not finite over its trimming loops")
        # chordal deviation at centroids (inside the region: the triangles were kept for
        # it) and at the midpoint of every edge, each edge once although two triangles share it
        edges = np.sort(tri[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
        edges = edges[np.unique(edges[:, 0] * len(P) + edges[:, 1], return_index=True)[1]]
        mids = 0.5 * (P[edges[:, 0]] + P[edges[:, 1]])
        probes = np.concatenate([centroids, mids])
        linear = np.concatenate([X[tri].mean(axis=1), 0.5 * (X[edges[:, 0]] + X[edges[:, 1]])])
        Xp = evaluate(*(probes / scale + lo).T)
        dev = np.linalg.norm(Xp - linear, axis=1)
        # midpoints outside the region (edges of triangles over a concave part of a loop)
        # evaluate the surface where the face is not: they do not count
        dev[len(centroids):][~inside(mids, mloops)] = 0.0
        deviation = float(dev.max()) if dev.size else 0.0
        best = TrimmedMesh(X, tri.astype(np.int64), P / scale + lo, deviation, f"{MAX_ROUNDS} refinement rounds")
        bad = dev > tolerance
        if not bad.any():
            best = TrimmedMesh(X, tri.astype(np.int64), P / scale + lo, deviation)
            break
        # refine where the mesh misses: the failing probe points become vertices, but not
        # nearer than ``floor`` to a vertex (nearly coincident points stall Qhull, and a
        # miss that survives at that spacing is a singular spot, reported by ``deviation``)
        cand, cx = probes[bad], Xp[bad]
        # a failing triangle long in one direction (near a pole, or across a thinned loop)
        # is split at the midpoint of its longest edge, not at its centroid: the centroid's
        # three triangles keep that edge, and the next centroid creeps towards it
        tb = np.nonzero(bad[:len(centroids)])[0]
        if len(tb):
            corners3 = P[tri[tb]]
            lengths = np.linalg.norm(corners3[:, [1, 2, 0]] - corners3, axis=2)
            k = np.argmax(lengths, axis=1)
            mid = 0.5 * (corners3[np.arange(len(tb)), k] + corners3[np.arange(len(tb)), (k + 1) % 3])
            ok = inside(mid, mloops)
            if ok.any():
                mid = mid[ok]
                cand = np.concatenate([cand, mid])
                cx = np.concatenate([cx, evaluate(*(mid / scale + lo).T)])
        keep = cKDTree(P).query(cand)[0] > floor
        cand, cx = cand[keep], cx[keep]
        _, k = np.unique(np.round(cand / floor), axis=0, return_index=True)
        cand, cx = cand[k], cx[k]
        if not len(cand) or len(P) + len(cand) > max_points:
            why = (f"point budget of {max_points}" if len(cand) else
                   "no point to add farther than the minimum spacing from the others")
            best = TrimmedMesh(best.vertices, best.triangles, best.uv, best.deviation, why)
            break
        P = np.concatenate([P, cand])
        X = np.concatenate([X, cx])
        jitter = np.concatenate([jitter, np.random.default_rng(len(P)).uniform(-JITTER * h, JITTER * h, size=cand.shape)])
    if best is None:
        raise IgesError(f"meshing the trimmed face within budget of {max_points} points is not possible")
    return best
