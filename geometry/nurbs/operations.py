"""Exact operations on B-spline and NURBS curves and surfaces.

Knot insertion and refinement, clamping, Bezier decomposition, degree elevation,
reversal, splitting, linear reparametrisation and making curves compatible, after
Piegl & Tiller, The NURBS Book 2e (1997), chapter 5:

- Alg. A5.1 (CurveKnotIns) for one knot inserted ``times`` times;
- Alg. A5.3 / A5.5 (surface knot insertion / refinement), done here as the curve
  algorithms A5.1 / A5.4 applied to every row or column of the net at once;
- Alg. A5.4 (RefineKnotVectCurve) for knot refinement;
- Alg. A5.6 (DecomposeCurve) in effect: Bezier decomposition is a refinement that
  raises every interior knot to multiplicity p;
- Alg. A5.9 (DegreeElevateCurve) for degree elevation.

Everything works on homogeneous control points (w*P, w), so rational curves and
surfaces are handled exactly; a non-rational input stays non-rational. The private
``_*_net`` kernels take a net whose first axis runs along the knot vector and any
trailing axes (the other surface direction and the coordinates), so one kernel serves
curves and both directions of surfaces, vectorised over the trailing axes.

Unclamped knot vectors (Blender's uniform mode) are accepted everywhere. Operations that
need a clamped vector (degree elevation, splitting, Bezier form) clamp first, so their
output is clamped over the same domain.
"""
from __future__ import annotations

from math import comb
from numbers import Integral

import numpy as np

from ..errors import GeometryError
from .basis import find_span, validate_degree
from .curve import BSplineCurve
from .surface import BSplineSurface

#: Two knot values closer than KNOT_TOL times the length of the parameter domain are the
#: same knot: a parameter given for insertion or splitting is snapped onto an existing
#: knot within this distance, and :func:`merge_knot_vectors` merges values within it.
KNOT_TOL = 1e-12

__all__ = [
    "KNOT_TOL",
    "bezier_segments",
    "clamp",
    "clamp_surface",
    "elevate_degree",
    "elevate_degree_surface",
    "insert_knot",
    "insert_knot_surface",
    "make_compatible",
    "merge_knot_vectors",
    "refine_knots",
    "refine_knots_surface",
    "reparametrize",
    "reverse",
    "reverse_surface",
    "split",
    "surface_to_bezier_form",
    "to_bezier_form",
]


# ---------------------------------------------------------------------------------------
# argument checks and conversions
# ---------------------------------------------------------------------------------------
def _require_curve(curve, what: str = "curve") -> BSplineCurve:
    if not isinstance(curve, BSplineCurve):
        raise GeometryError(f"{what}: expected a BSplineCurve, got {type(curve).__name__}")
    return curve


def _require_surface(surface, what: str = "surface") -> BSplineSurface:
    if not isinstance(surface, BSplineSurface):
        raise GeometryError(f"{what}: expected a BSplineSurface, got {type(surface).__name__}")
    return surface


def _check_times(times, what: str = "times") -> int:
    if isinstance(times, bool) or not isinstance(times, Integral):
        raise GeometryError(f"{what} must be an integer >= 0, got {times!r}")
    if times < 0:
        raise GeometryError(f"{what} must be >= 0, got {times}")
    return int(times)


def _axis(direction) -> int:
    if isinstance(direction, str) and direction in ("u", "v"):
        return 0 if direction == "u" else 1
    raise GeometryError(f"direction must be 'u' or 'v', got {direction!r}")


def _domain(U: np.ndarray, p: int) -> tuple[float, float]:
    return float(U[p]), float(U[len(U) - p - 1])


def _snap(U: np.ndarray, p: int, u: float) -> float:
    """``u`` moved onto the nearest knot when within KNOT_TOL of the domain length."""
    a, b = _domain(U, p)
    i = int(np.argmin(np.abs(U - u)))
    return float(U[i]) if abs(U[i] - u) <= KNOT_TOL * (b - a) else u


def _knot_value(U: np.ndarray, p: int, u, what: str) -> float:
    """A finite parameter inside the closed domain, snapped onto a nearby knot."""
    try:
        u = float(u)
    except (TypeError, ValueError):
        raise GeometryError(f"{what}: expected a real number, got {u!r}") from None
    if not np.isfinite(u):
        raise GeometryError(f"{what}: expected a finite number, got {u!r}")
    a, b = _domain(U, p)
    u = _snap(U, p, u)
    if not a <= u <= b:
        raise GeometryError(f"{what} {float(u)!r} is outside the domain [{float(a)!r}, {float(b)!r}]")
    return u


def _curve_net(curve: BSplineCurve) -> np.ndarray:
    return curve.homogeneous if curve.is_rational else np.array(curve.control_points)


def _curve_from_net(degree: int, knots, net: np.ndarray, rational: bool) -> BSplineCurve:
    if rational:
        return BSplineCurve.from_homogeneous(degree, knots, net, rational=True)
    return BSplineCurve(degree, knots, net)


def _surface_net(surface: BSplineSurface, axis: int) -> np.ndarray:
    """Homogeneous (rational) or plain net with the ``axis`` direction first."""
    net = surface.homogeneous if surface.is_rational else np.array(surface.control_points)
    return net if axis == 0 else net.transpose(1, 0, 2)


def _surface_with(surface: BSplineSurface, axis: int, degree: int, knots, net) -> BSplineSurface:
    """``surface`` with the ``axis`` direction replaced by (degree, knots, net)."""
    if axis == 1:
        net = net.transpose(1, 0, 2)
        dims = (surface.degree_u, degree, surface.knots_u, knots)
    else:
        dims = (degree, surface.degree_v, knots, surface.knots_v)
    if surface.is_rational:
        return BSplineSurface.from_homogeneous(*dims, net, rational=True)
    return BSplineSurface(*dims, net)


def _surface_parts(surface: BSplineSurface, axis: int) -> tuple[int, np.ndarray]:
    if axis == 0:
        return surface.degree_u, surface.knots_u
    return surface.degree_v, surface.knots_v


def _multiplicity(U: np.ndarray, u: float) -> int:
    return int(np.count_nonzero(U == u))


def _check_insertions(U: np.ndarray, p: int, X: np.ndarray, what: str) -> None:
    """Refuse insertions that would leave a knot with multiplicity above the degree."""
    if X.size == 0:
        return
    values, added = np.unique(X, return_counts=True)
    for value, count in zip(values, added):
        s = _multiplicity(U, value)
        if s + count > p:
            raise GeometryError(
                f"{what}: inserting knot {value!r} {count} time(s) where it already has "
                f"multiplicity {s} would give multiplicity {s + count}; expected at most the "
                f"degree {p}"
            )


def _is_clamped(U: np.ndarray, p: int) -> bool:
    return bool(np.all(U[: p + 1] == U[0]) and np.all(U[-p - 1 :] == U[-1]))


def _is_bezier_form(U: np.ndarray, p: int) -> bool:
    if not _is_clamped(U, p):
        return False
    _, counts = np.unique(U[p + 1 : -p - 1], return_counts=True)
    return bool(np.all(counts == p))


# ---------------------------------------------------------------------------------------
# kernels on nets: first axis along the knot vector, any trailing axes
# ---------------------------------------------------------------------------------------
def _column(x: np.ndarray, ndim: int) -> np.ndarray:
    """Coefficient vector shaped to broadcast against a net slice with ``ndim`` axes."""
    return x.reshape(x.shape + (1,) * (ndim - 1))


def _insert_knot_net(U: np.ndarray, p: int, net: np.ndarray, u: float, r: int):
    """Insert ``u`` ``r`` times (NURBS Book Alg. A5.1). Assumes s + r <= p.

    ``k`` is the index of the last knot <= u (not clipped to n, so that a knot equal to
    the domain end of an unclamped vector is handled with the right span).
    """
    if r == 0:
        return U.copy(), net.copy()
    n = net.shape[0] - 1
    k = int(np.searchsorted(U, u, side="right")) - 1
    s = _multiplicity(U, u)
    UQ = np.concatenate([U[: k + 1], np.full(r, u), U[k + 1 :]])
    Q = np.empty((n + 1 + r,) + net.shape[1:])
    Q[: k - p + 1] = net[: k - p + 1]
    Q[k - s + r :] = net[k - s :]
    R = net[k - p : k - s + 1].copy()  # the p - s + 1 points the new knots blend
    for j in range(1, r + 1):
        L = k - p + j
        i = np.arange(p - j - s + 1)
        alpha = _column((u - U[L + i]) / (U[i + k + 1] - U[L + i]), net.ndim)
        R[: p - j - s + 1] = alpha * R[1 : p - j - s + 2] + (1.0 - alpha) * R[: p - j - s + 1]
        Q[L] = R[0]
        Q[k + r - j - s] = R[p - j - s]
    Q[L + 1 : k - s] = R[1 : k - s - L]
    return UQ, Q


def _refine_net(U: np.ndarray, p: int, net: np.ndarray, X: np.ndarray):
    """Insert the sorted knots ``X`` all at once (NURBS Book Alg. A5.4).

    ``find_span`` returns n at the domain end b, as FindSpan (A2.1) does; that is also
    right when X holds b of an unclamped vector, because the loop below moves every knot
    >= x (with the control points only they support) and blends with alpha = 0 across
    knots equal to x.
    """
    if X.size == 0:
        return U.copy(), net.copy()
    n = net.shape[0] - 1
    m = n + p + 1
    r = X.size - 1
    a = int(find_span(U, p, np.float64(X[0])))
    b = int(find_span(U, p, np.float64(X[-1]))) + 1
    Ubar = np.empty(m + r + 2)
    Q = np.empty((n + r + 2,) + net.shape[1:])
    Q[: a - p + 1] = net[: a - p + 1]
    Q[b + r : n + r + 2] = net[b - 1 : n + 1]
    Ubar[: a + 1] = U[: a + 1]
    Ubar[b + p + r + 1 :] = U[b + p :]
    i = b + p - 1
    k = b + p + r
    for j in range(r, -1, -1):
        x = X[j]
        # knots >= x move right unchanged, with the control points they alone support
        while x <= U[i] and i > a:
            Q[k - p - 1] = net[i - p - 1]
            Ubar[k] = U[i]
            k -= 1
            i -= 1
        Q[k - p - 1] = Q[k - p]
        for l in range(1, p + 1):
            ind = k - p + l
            alpha = Ubar[k + l] - x
            if alpha == 0.0:
                Q[ind - 1] = Q[ind]
            else:
                alpha /= Ubar[k + l] - U[i - p + l]
                Q[ind - 1] = alpha * Q[ind - 1] + (1.0 - alpha) * Q[ind]
        Ubar[k] = x
        k -= 1
    return Ubar, Q


def _clamp_net(U: np.ndarray, p: int, net: np.ndarray):
    """Equivalent clamped representation over the same domain (identity if clamped).

    The domain ends a = U[p] and b = U[n+1] are raised to multiplicity p by
    refinement (A5.4); the curve then passes through the control point next to each
    p-fold end knot, and the basis functions of the points beyond it vanish on the
    domain, so those points and the knots outside the domain are dropped and one more
    copy of each end value completes the clamped vector.
    """
    if _is_clamped(U, p):
        return U.copy(), net.copy()
    n = net.shape[0] - 1
    a, b = float(U[p]), float(U[n + 1])
    extra = [a] * max(0, p - _multiplicity(U, a)) + [b] * max(0, p - _multiplicity(U, b))
    U, net = _refine_net(U, p, net, np.array(extra, dtype=np.float64))
    lo = int(np.searchsorted(U, a, side="right")) - p  # first of the last p copies of a
    lo_b = int(np.searchsorted(U, b, side="left"))  # first copy of b
    knots = np.concatenate([[a], U[lo : lo_b + p], [b]])
    return knots, net[lo - 1 : lo_b].copy()


def _bezier_net(U: np.ndarray, p: int, net: np.ndarray):
    """Clamp, then raise every interior knot to multiplicity p (Alg. A5.6 as a refinement)."""
    U, net = _clamp_net(U, p, net)
    values, counts = np.unique(U[p + 1 : -p - 1], return_counts=True)
    X = np.repeat(values, p - counts)
    return _refine_net(U, p, net, X)


def _bezier_elevation_matrix(p: int, t: int) -> np.ndarray:
    """Coefficients of degree elevation of one Bezier segment from p to p+t:
    ``Q_i = sum_j C(p,j) C(t,i-j) / C(p+t,i) P_j`` (NURBS Book §5.5, the ``bezalfs``
    of Alg. A5.9)."""
    ph = p + t
    M = np.zeros((ph + 1, p + 1))
    for i in range(ph + 1):
        for j in range(max(0, i - t), min(p, i) + 1):
            M[i, j] = comb(p, j) * comb(t, i - j) / comb(ph, i)
    return M


def _elevate_net(U: np.ndarray, p: int, net: np.ndarray, t: int):
    """Raise the degree by ``t`` (NURBS Book Alg. A5.9). Needs a clamped knot vector.

    The curve is cut into Bezier segments on the fly (knot insertion), every segment is
    elevated (:func:`_bezier_elevation_matrix`) and the knots inserted are removed again, so each distinct knot
    keeps its multiplicity plus t.
    """
    if t == 0:
        return U.copy(), net.copy()
    n = net.shape[0] - 1
    m = n + p + 1
    ph = p + t
    tail = net.shape[1:]
    bezalfs = _bezier_elevation_matrix(p, t)
    n_distinct = np.unique(U).size
    n_knots = m + 1 + t * n_distinct
    Uh = np.empty(n_knots)
    Qw = np.zeros((n_knots - ph - 1,) + tail)
    bpts = net[: p + 1].copy()
    ebpts = np.zeros((ph + 1,) + tail)
    next_bpts = np.zeros((max(p - 1, 1),) + tail)
    alfs = np.zeros(max(p - 1, 1))
    kind = ph + 1
    r = -1
    a, b = p, p + 1
    cind = 1
    ua = U[0]
    Qw[0] = net[0]
    Uh[: ph + 1] = ua
    while b < m:
        i = b
        while b < m and U[b] == U[b + 1]:
            b += 1
        mul = b - i + 1
        ub = U[b]
        oldr, r = r, p - mul
        lbz = (oldr + 2) // 2 if oldr > 0 else 1
        rbz = ph - (r + 1) // 2 if r > 0 else ph
        if r > 0:
            # insert ub r times into the current segment to make it a Bezier segment
            numer = ub - ua
            for kk in range(p, mul, -1):
                alfs[kk - mul - 1] = numer / (U[a + kk] - ua)
            for j in range(1, r + 1):
                s = mul + j
                al = _column(alfs[: p - s + 1], net.ndim)
                bpts[s : p + 1] = al * bpts[s : p + 1] + (1.0 - al) * bpts[s - 1 : p]
                next_bpts[r - j] = bpts[p]
        ebpts[lbz:] = np.tensordot(bezalfs[lbz:], bpts, axes=(1, 0))
        if oldr > 1:
            # remove the knot ua oldr times (it was inserted for the previous segment)
            first, last = kind - 2, kind
            den = ub - ua
            bet = (ub - Uh[kind - 1]) / den
            for tr in range(1, oldr):
                i, j = first, last
                kj = j - kind + 1
                while j - i > tr:
                    if i < cind:
                        alf = (ub - Uh[i]) / (ua - Uh[i])
                        Qw[i] = alf * Qw[i] + (1.0 - alf) * Qw[i - 1]
                    if j >= lbz:
                        if j - tr <= kind - ph + oldr:
                            gam = (ub - Uh[j - tr]) / den
                            ebpts[kj] = gam * ebpts[kj] + (1.0 - gam) * ebpts[kj + 1]
                        else:
                            ebpts[kj] = bet * ebpts[kj] + (1.0 - bet) * ebpts[kj + 1]
                    i += 1
                    j -= 1
                    kj -= 1
                first -= 1
                last += 1
        if a != p:
            Uh[kind : kind + ph - oldr] = ua
            kind += ph - oldr
        Qw[cind : cind + rbz - lbz + 1] = ebpts[lbz : rbz + 1]
        cind += rbz - lbz + 1
        if b < m:
            bpts[:r] = next_bpts[:r]
            bpts[max(r, 0) :] = net[b - p + max(r, 0) : b + 1]
            a, b, ua = b, b + 1, ub
        else:
            Uh[kind : kind + ph + 1] = ub
            kind += ph + 1
    if kind != n_knots or cind != Qw.shape[0]:  # pragma: no cover - would be a bug here
        raise GeometryError(
            f"degree elevation produced {kind} knots and {cind} control points, "
            f"expected {n_knots} and {Qw.shape[0]}"
        )
    return Uh, Qw


# ---------------------------------------------------------------------------------------
# curves
# ---------------------------------------------------------------------------------------
def insert_knot(curve: BSplineCurve, u: float, times: int = 1) -> BSplineCurve:
    """Insert the knot ``u`` ``times`` times; the curve is unchanged.

    Piegl & Tiller, The NURBS Book 2e, Alg. A5.1 (on homogeneous points for NURBS).
    ``u`` must lie in the closed domain [a, b] (the ends only make sense for unclamped
    knot vectors) and is snapped onto an existing knot within :data:`KNOT_TOL`; the
    resulting multiplicity may not exceed the degree. ``times=0`` returns the input.
    """
    curve = _require_curve(curve)
    r = _check_times(times)
    p, U = curve.degree, curve.knots
    u = _knot_value(U, p, u, "knot")
    _check_insertions(U, p, np.full(r, u), "insert_knot")
    if r == 0:
        return curve
    UQ, Q = _insert_knot_net(U, p, _curve_net(curve), u, r)
    return _curve_from_net(p, UQ, Q, curve.is_rational)


def _knot_list(U: np.ndarray, p: int, new_knots, what: str) -> np.ndarray:
    """``new_knots`` as a sorted float64 array inside the domain, snapped onto knots."""
    X = np.array(new_knots, dtype=np.float64).ravel()
    if X.size == 0:
        return X
    if not np.all(np.isfinite(X)):
        bad = int(np.flatnonzero(~np.isfinite(X))[0])
        raise GeometryError(f"{what}[{bad}] is not finite ({X[bad]!r})")
    steps = np.diff(X)
    if np.any(steps < 0):
        bad = int(np.flatnonzero(steps < 0)[0])
        raise GeometryError(
            f"{what} must be sorted (non-decreasing): {what}[{bad}] = {X[bad]!r} > "
            f"{what}[{bad + 1}] = {X[bad + 1]!r}"
        )
    a, b = _domain(U, p)
    X = np.array([_snap(U, p, x) for x in X])
    outside = (X < a) | (X > b)
    if outside.any():
        bad = int(np.flatnonzero(outside)[0])
        raise GeometryError(f"{what}[{bad}] = {float(X[bad])!r} is outside the domain [{float(a)!r}, {float(b)!r}]")
    return np.sort(X)  # snapping can swap values closer than KNOT_TOL


def refine_knots(curve: BSplineCurve, new_knots) -> BSplineCurve:
    """Insert all of ``new_knots`` (a sorted sequence, possibly empty, repeats allowed).

    Piegl & Tiller, The NURBS Book 2e, Alg. A5.4 (knot refinement). Every resulting
    multiplicity must stay <= the degree. The curve is unchanged.
    """
    curve = _require_curve(curve)
    p, U = curve.degree, curve.knots
    X = _knot_list(U, p, new_knots, "new_knots")
    _check_insertions(U, p, X, "refine_knots")
    if X.size == 0:
        return curve
    Ubar, Q = _refine_net(U, p, _curve_net(curve), X)
    return _curve_from_net(p, Ubar, Q, curve.is_rational)


def clamp(curve: BSplineCurve) -> BSplineCurve:
    """The same curve over the same domain with a clamped (open) knot vector.

    For an unclamped vector (e.g. Blender's uniform knots) the domain ends are inserted
    until they have multiplicity p (NURBS Book Alg. A5.4), then the knots outside the
    domain and the control points that only they support are dropped. Returns the
    input itself when it is clamped already (the types are immutable).
    """
    curve = _require_curve(curve)
    if _is_clamped(curve.knots, curve.degree):
        return curve
    U, Q = _clamp_net(curve.knots, curve.degree, _curve_net(curve))
    return _curve_from_net(curve.degree, U, Q, curve.is_rational)


def to_bezier_form(curve: BSplineCurve) -> BSplineCurve:
    """Bezier decomposition as one B-spline: clamped, every interior knot of multiplicity p.

    The knot vector is [a]*(p+1), each distinct interior knot p times, [b]*(p+1); control
    points i*p .. i*p+p are the Bezier points of span i. Piegl & Tiller, The NURBS Book
    2e, Alg. A5.6 (done as a refinement, Alg. A5.4).
    """
    curve = _require_curve(curve)
    if _is_bezier_form(curve.knots, curve.degree):
        return curve
    U, Q = _bezier_net(curve.knots, curve.degree, _curve_net(curve))
    return _curve_from_net(curve.degree, U, Q, curve.is_rational)


def bezier_segments(curve: BSplineCurve) -> list[BSplineCurve]:
    """The Bezier segments of the curve, one per non-empty knot span, in order.

    Each is a BSplineCurve of the same degree (rational if the input is) with knots
    [u_i]*(p+1) + [u_{i+1}]*(p+1) over its own span. NURBS Book Alg. A5.6.
    """
    curve = _require_curve(curve)
    p = curve.degree
    U, Q = _bezier_net(curve.knots, p, _curve_net(curve))
    breaks = np.unique(U)
    segments = []
    for i in range(breaks.size - 1):
        knots = np.concatenate([np.full(p + 1, breaks[i]), np.full(p + 1, breaks[i + 1])])
        segments.append(_curve_from_net(p, knots, Q[i * p : i * p + p + 1], curve.is_rational))
    return segments


def elevate_degree(curve: BSplineCurve, times: int = 1) -> BSplineCurve:
    """The same curve with its degree raised by ``times`` (NURBS Book Alg. A5.9).

    Each distinct knot's multiplicity grows by ``times``. Unclamped input is clamped
    first (the output is clamped over the same domain). ``times=0`` returns
    :func:`clamp` of the input.
    """
    curve = _require_curve(curve)
    t = _check_times(times)
    p = curve.degree
    if t == 0:
        return clamp(curve)
    U, net = _clamp_net(curve.knots, p, _curve_net(curve))
    Uh, Q = _elevate_net(U, p, net, t)
    return _curve_from_net(p + t, Uh, Q, curve.is_rational)


def reverse(curve: BSplineCurve) -> BSplineCurve:
    """The curve traversed backwards over the same domain: R(u) = C(a + b - u).

    Knots u_i -> a + b - u_{m-i}, control points (and weights) in reverse order.
    """
    curve = _require_curve(curve)
    p, U = curve.degree, curve.knots
    a, b = curve.domain
    V = _exact_end_copies((a + b) - U[::-1], U, p)
    w = None if curve.weights is None else curve.weights[::-1]
    return BSplineCurve(p, V, curve.control_points[::-1], w)


def _exact_end_copies(U_new: np.ndarray, U_old: np.ndarray, p: int) -> np.ndarray:
    """Give knots that equal a domain end in the reversed vector exactly that end value.

    a + b - b == a can fail by one ulp in floating point; the copies of the domain ends
    must stay exactly equal or a clamped vector would stop being clamped.
    """
    a, b = _domain(U_old, p)
    rev_old = U_old[::-1]
    U_new = U_new.copy()
    U_new[rev_old == b] = a
    U_new[rev_old == a] = b
    return np.maximum.accumulate(U_new)


def split(curve: BSplineCurve, u: float) -> tuple[BSplineCurve, BSplineCurve]:
    """Cut the curve at the interior parameter ``u`` into (left, right).

    The curve is clamped, ``u`` is inserted up to multiplicity p (NURBS Book Alg. A5.1)
    and the control polygon is cut at the point C(u); both halves are clamped, over
    [a, u] and [u, b]. ``u`` within KNOT_TOL of a knot is snapped onto it.
    """
    curve = _require_curve(curve)
    p = curve.degree
    U, net = _clamp_net(curve.knots, p, _curve_net(curve))
    a, b = _domain(U, p)
    u = _knot_value(U, p, u, "split parameter")
    if not a < u < b:
        raise GeometryError(f"split parameter {u!r} must be strictly inside the domain ({a!r}, {b!r})")
    U, net = _insert_knot_net(U, p, net, u, p - _multiplicity(U, u))
    lo = int(np.searchsorted(U, u, side="left"))  # the p copies of u are U[lo:lo+p]
    left = _curve_from_net(p, np.concatenate([U[: lo + p], [u]]), net[:lo], curve.is_rational)
    right = _curve_from_net(p, np.concatenate([[u], U[lo:]]), net[lo - 1 :], curve.is_rational)
    return left, right


def split_surface(surface: BSplineSurface, direction: str, value: float) -> tuple[BSplineSurface, BSplineSurface]:
    """Cut ``surface`` at ``value`` of ``direction`` ('u' or 'v') into two surfaces, as
    :func:`split` cuts a curve (NURBS Book Alg. A5.1 on every row of the net at once);
    both pieces are clamped in that direction, over [a, value] and [value, b]."""
    surface = _require_surface(surface)
    axis = _axis(direction)
    p, U = _surface_parts(surface, axis)
    U, net = _clamp_net(U, p, _surface_net(surface, axis))
    a, b = _domain(U, p)
    u = _knot_value(U, p, value, "split parameter")
    if not a < u < b:
        raise GeometryError(f"split parameter {u!r} must be strictly inside the domain ({a!r}, {b!r})")
    U, net = _insert_knot_net(U, p, net, u, p - _multiplicity(U, u))
    lo = int(np.searchsorted(U, u, side="left"))  # the p copies of u are U[lo:lo+p]
    left = _surface_with(surface, axis, p, np.concatenate([U[: lo + p], [u]]), net[:lo])
    right = _surface_with(surface, axis, p, np.concatenate([[u], U[lo:]]), net[lo - 1 :])
    return left, right


def _map_knots(U: np.ndarray, p: int, domain) -> np.ndarray:
    try:
        c, d = (float(x) for x in domain)
    except (TypeError, ValueError):
        raise GeometryError(f"domain: expected a pair (start, end), got {domain!r}") from None
    if not (np.isfinite(c) and np.isfinite(d) and d > c):
        raise GeometryError(f"domain: expected finite start < end, got ({c!r}, {d!r})")
    a, b = _domain(U, p)
    t = (U - a) / (b - a)
    # the lerp form maps a and b to c and d exactly
    V = c * (1.0 - t) + d * t
    V[U == a] = c
    V[U == b] = d
    return np.maximum.accumulate(V)


def reparametrize(curve: BSplineCurve, domain=(0.0, 1.0)) -> BSplineCurve:
    """The same curve over ``domain`` = (c, d) by the linear map of the knot vector
    u -> c + (u - a)(d - c)/(b - a). Derivatives scale by (b - a)/(d - c)."""
    curve = _require_curve(curve)
    V = _map_knots(curve.knots, curve.degree, domain)
    return BSplineCurve(curve.degree, V, curve.control_points, curve.weights)


# ---------------------------------------------------------------------------------------
# surfaces: the curve kernels on every row or column of the net at once
# ---------------------------------------------------------------------------------------
def insert_knot_surface(surface: BSplineSurface, direction: str, value: float, times: int = 1) -> BSplineSurface:
    """Insert the knot ``value`` ``times`` times in the ``direction`` ('u' or 'v') knot
    vector. Piegl & Tiller, The NURBS Book 2e, Alg. A5.3 (as A5.1 on all rows at once)."""
    surface = _require_surface(surface)
    axis = _axis(direction)
    r = _check_times(times)
    p, U = _surface_parts(surface, axis)
    value = _knot_value(U, p, value, f"knot ({direction})")
    _check_insertions(U, p, np.full(r, value), f"insert_knot_surface ({direction})")
    if r == 0:
        return surface
    UQ, Q = _insert_knot_net(U, p, _surface_net(surface, axis), value, r)
    return _surface_with(surface, axis, p, UQ, Q)


def refine_knots_surface(surface: BSplineSurface, direction: str, new_knots) -> BSplineSurface:
    """Insert the sorted knots ``new_knots`` in the ``direction`` knot vector.
    Piegl & Tiller, The NURBS Book 2e, Alg. A5.5 (as A5.4 on all rows at once)."""
    surface = _require_surface(surface)
    axis = _axis(direction)
    p, U = _surface_parts(surface, axis)
    X = _knot_list(U, p, new_knots, f"new_knots ({direction})")
    _check_insertions(U, p, X, f"refine_knots_surface ({direction})")
    if X.size == 0:
        return surface
    Ubar, Q = _refine_net(U, p, _surface_net(surface, axis), X)
    return _surface_with(surface, axis, p, Ubar, Q)


def _clamp_direction(surface: BSplineSurface, axis: int) -> BSplineSurface:
    p, U = _surface_parts(surface, axis)
    if _is_clamped(U, p):
        return surface
    Uc, Q = _clamp_net(U, p, _surface_net(surface, axis))
    return _surface_with(surface, axis, p, Uc, Q)


def clamp_surface(surface: BSplineSurface) -> BSplineSurface:
    """The same surface with clamped knot vectors in u and v (see :func:`clamp`);
    the input itself when both are clamped already."""
    surface = _require_surface(surface)
    return _clamp_direction(_clamp_direction(surface, 0), 1)


def surface_to_bezier_form(surface: BSplineSurface) -> BSplineSurface:
    """Bezier decomposition in both directions (see :func:`to_bezier_form`): every
    interior knot of multiplicity p (in u) and q (in v), clamped ends. NURBS Book Alg. A5.7
    in effect (done as refinement, Alg. A5.5)."""
    surface = _require_surface(surface)
    for axis in (0, 1):
        p, U = _surface_parts(surface, axis)
        if _is_bezier_form(U, p):
            continue
        Ub, Q = _bezier_net(U, p, _surface_net(surface, axis))
        surface = _surface_with(surface, axis, p, Ub, Q)
    return surface


def elevate_degree_surface(surface: BSplineSurface, direction: str, times: int = 1) -> BSplineSurface:
    """Raise the degree in ``direction`` by ``times`` (NURBS Book Alg. A5.10, done as
    A5.9 on all rows at once). That direction is clamped first."""
    surface = _require_surface(surface)
    axis = _axis(direction)
    t = _check_times(times)
    if t == 0:
        return _clamp_direction(surface, axis)
    p, U = _surface_parts(surface, axis)
    U, net = _clamp_net(U, p, _surface_net(surface, axis))
    Uh, Q = _elevate_net(U, p, net, t)
    return _surface_with(surface, axis, p + t, Uh, Q)


def reverse_surface(surface: BSplineSurface, direction: str) -> BSplineSurface:
    """The surface with ``direction`` reversed over the same domain:
    S'(u, v) = S(a + b - u, v) for 'u' (likewise for 'v')."""
    surface = _require_surface(surface)
    axis = _axis(direction)
    p, U = _surface_parts(surface, axis)
    a, b = _domain(U, p)
    V = _exact_end_copies((a + b) - U[::-1], U, p)
    P = np.flip(surface.control_points, axis)
    w = None if surface.weights is None else np.flip(surface.weights, axis)
    if axis == 0:
        return BSplineSurface(p, surface.degree_v, V, surface.knots_v, P, w)
    return BSplineSurface(surface.degree_u, p, surface.knots_u, V, P, w)


# ---------------------------------------------------------------------------------------
# compatibility
# ---------------------------------------------------------------------------------------
def _clusters(values: np.ndarray, tol: float) -> np.ndarray:
    """Start indices (into sorted ``values``) of groups of values within ``tol`` of the
    group's first value."""
    starts = [0]
    for i in range(1, values.size):
        if values[i] - values[starts[-1]] > tol:
            starts.append(i)
    return np.array(starts)


def merge_knot_vectors(knot_vectors, degree: int, tol: float = KNOT_TOL) -> np.ndarray:
    """Union of clamped knot vectors of one degree over one domain, each distinct value
    with the largest multiplicity it has in any input.

    Values closer than ``tol`` times the domain length are one value, represented by the
    smallest of them (the domain ends by those of the first vector). Every input is then a
    sub-multiset of the result (up to that snapping), so the result is a common refinement
    (Piegl & Tiller, The NURBS Book 2e, §10.3, compatible curves for skinning).
    """
    p = validate_degree(degree)
    try:
        vectors = [np.array(k, dtype=np.float64) for k in knot_vectors]
    except (TypeError, ValueError) as exc:
        raise GeometryError(f"knot_vectors: expected a sequence of 1-D number sequences ({exc})") from None
    if not vectors:
        raise GeometryError("knot_vectors: expected at least one knot vector, got none")
    try:
        tol = float(tol)
    except (TypeError, ValueError):
        raise GeometryError(f"tol: expected a number >= 0, got {tol!r}") from None
    if not (np.isfinite(tol) and tol >= 0):
        raise GeometryError(f"tol: expected a finite number >= 0, got {tol!r}")
    for i, U in enumerate(vectors):
        what = f"knot_vectors[{i}]"
        if U.ndim != 1 or U.size < 2 * p + 2:
            raise GeometryError(
                f"{what}: expected a 1-D vector of at least {2 * p + 2} knots for degree {p}, "
                f"got shape {U.shape}"
            )
        if not np.all(np.isfinite(U)) or np.any(np.diff(U) < 0):
            raise GeometryError(f"{what}: expected finite non-decreasing knots, got {U.tolist()}")
        if not _is_clamped(U, p):
            raise GeometryError(
                f"{what} is not clamped for degree {p} (expected {p + 1} equal knots at each end, "
                f"got {U[: p + 1].tolist()} ... {U[-p - 1:].tolist()}); clamp() the curve first"
            )
    a, b = vectors[0][0], vectors[0][-1]
    if not b > a:
        raise GeometryError(f"knot_vectors[0]: the domain [{a!r}, {b!r}] is empty")
    abs_tol = tol * (b - a)
    for i, U in enumerate(vectors[1:], start=1):
        if abs(U[0] - a) > abs_tol or abs(U[-1] - b) > abs_tol:
            raise GeometryError(
                f"knot_vectors[{i}] is over [{U[0]!r}, {U[-1]!r}], expected the domain of "
                f"knot_vectors[0], [{a!r}, {b!r}]; reparametrize() first"
            )
    allv = np.sort(np.concatenate(vectors))
    starts = _clusters(allv, abs_tol)
    reps = allv[starts].copy()
    reps[0], reps[-1] = a, b
    mult = np.zeros(reps.size, dtype=int)
    for U in vectors:
        idx = np.searchsorted(allv[starts], U, side="right") - 1
        mult = np.maximum(mult, np.bincount(idx, minlength=reps.size))
    if reps.size < 2 or mult[0] != p + 1 or mult[-1] != p + 1:
        raise GeometryError(
            f"knot_vectors: knots closer than tol = {tol!r} (relative) to a domain end merge with it; "
            f"expected multiplicity {p + 1} at the ends, got {mult[0]} and {mult[-1]}"
        )
    if np.any(mult[1:-1] > p):
        i = 1 + int(np.argmax(mult[1:-1]))
        raise GeometryError(
            f"knot_vectors: merged knot {reps[i]!r} has multiplicity {mult[i]}, more than the "
            f"degree {p} (knots closer than tol = {tol!r} counted as one)"
        )
    return np.repeat(reps, mult)


def make_compatible(curves) -> list[BSplineCurve]:
    """Curves with one degree, one clamped knot vector over [0, 1] and one rationality.

    Each curve is clamped, degree-elevated to the largest degree (Alg. A5.9),
    reparametrised linearly to [0, 1], made rational (weights 1) if any curve is, and
    refined (Alg. A5.4) with the knots of :func:`merge_knot_vectors` it lacks. Knots
    within KNOT_TOL of a merged value are moved onto it (a change of the curve of that
    order); otherwise every output is its input up to the linear reparametrisation.
    Piegl & Tiller, The NURBS Book 2e, §10.3 (compatible curves for skinned surfaces).
    """
    try:
        curves = list(curves)
    except TypeError:
        raise GeometryError(f"curves: expected a sequence of BSplineCurve, got {type(curves).__name__}") from None
    if not curves:
        raise GeometryError("curves: expected at least one curve, got none")
    for i, c in enumerate(curves):
        _require_curve(c, f"curves[{i}]")
    dims = {c.dim for c in curves}
    if len(dims) > 1:
        raise GeometryError(f"curves: expected one dimension for all curves, got {sorted(dims)}")
    p = max(c.degree for c in curves)
    rational = any(c.is_rational for c in curves)
    nets, vectors = [], []
    for c in curves:
        U, net = _clamp_net(c.knots, c.degree, c.homogeneous if rational else np.array(c.control_points))
        U, net = _elevate_net(U, c.degree, net, p - c.degree)
        U = _map_knots(U, p, (0.0, 1.0))
        nets.append(net)
        vectors.append(U)
    merged = merge_knot_vectors(vectors, p)
    values, counts = np.unique(merged, return_counts=True)
    out = []
    for U, net in zip(vectors, nets):
        # snap onto the merged values (all within KNOT_TOL by construction)
        nearest = np.clip(np.searchsorted(values, U), 1, values.size - 1)
        nearest = np.where(np.abs(values[nearest - 1] - U) <= np.abs(values[nearest] - U), nearest - 1, nearest)
        U = values[nearest]
        have = np.bincount(nearest, minlength=values.size)
        X = np.repeat(values, counts - have)
        Ubar, Q = _refine_net(U, p, net, X)
        if not np.array_equal(Ubar, merged):  # pragma: no cover - would be a bug here
            raise GeometryError("make_compatible: a refined knot vector differs from the merged one")
        out.append(_curve_from_net(p, merged, Q, rational))
    return out
