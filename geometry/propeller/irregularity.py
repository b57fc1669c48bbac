"""A measure of tip irregularity: how much the curvature of the curves near the tip
wanders beyond what a single rounded edge needs (issue 15; the irregularities of Hally
2013 §1 that tip smoothing, §7, exists to remove).

Definition. For one curve around an edge (a blade cut, Hally §6) take its signed in-plane
curvature κ(t) on the part within d_e of its edge point x_1 (the window where Eq. 30
lets the filter act), and

    E = TV(κ) - |κ_pk - κ_a| - |κ_pk - κ_b|,      TV(κ) = ∫ |dκ/dt| dt,

κ_a, κ_b the curvature at the two ends of the window and κ_pk the curvature of largest
magnitude in it. A fair rounded edge (curvature rising to one peak at the edge and
falling again) has E = 0; every extra wiggle of amplitude A adds 2A. E does not depend on
the direction of travel or the sign convention of κ. The tip irregularity of a blade is
the sum of E·R (R the radius: dimensionless) over every curve whose edge point lies
within d_t of the tip along c_LETE (Hally Eq. 30, the cuts that are smoothed).

Both sides use the same window and the same evaluation: the curve (the plain cut b(p(t))
or the smoothed one, b(p(t)) plus its displacement, Hally §7) at WINDOW_SAMPLES parameters
evenly spread over the part of the plain cut within d_e of x_1, interpolated by a cubic
spline in t whose curvature is taken at those parameters. The measure is taken on the
curves, not on the §9 rows fitted to them: near the tip the edge radius of the last cuts
is below the fitting tolerance, so the rows' curvature there reflects the fit.
"""
from __future__ import annotations

import numpy as np
from scipy.interpolate import make_interp_spline

from .corners import blade_points

#: Parameters per window at which a curve's curvature is measured.
WINDOW_SAMPLES = 1201
#: Parameters at which the plain cut is scanned for its window.
WINDOW_SCAN = 2001
#: Every this many scan parameters are evaluated first (:func:`measure_windows`).
WINDOW_COARSE = 10


def excess_curvature_variation(kappa) -> float:
    """E of the module docstring for a sampled curvature κ_1..κ_n (1/m): the total
    variation beyond one rise to the peak and one fall from it (>= 0)."""
    k = np.asarray(kappa, dtype=np.float64)
    k = k[np.isfinite(k)]
    if k.size < 3:
        return 0.0
    tv = float(np.sum(np.abs(np.diff(k))))
    pk = k[np.argmax(np.abs(k))]
    return max(0.0, tv - abs(pk - k[0]) - abs(pk - k[-1]))


def measure_window(blade, cut, d_e: float) -> np.ndarray:
    """WINDOW_SAMPLES parameters spread evenly over the part of the plain cut within d_e
    (m) of its edge point x_1 (the window of Hally Eq. 30)."""
    t = np.linspace(0.0, 1.0, WINDOW_SCAN)
    X = blade_points(blade, cut.curve.parameters(t))
    inside = np.flatnonzero(np.linalg.norm(X - cut.points[1], axis=1) < d_e)
    lo, hi = t[max(inside[0] - 1, 0)], t[min(inside[-1] + 1, t.size - 1)]
    return np.linspace(lo, hi, WINDOW_SAMPLES)


def curve_excess(t, X) -> float:
    """E (1/m) of the curve through the points X (n, 3) at parameters t (n,): the
    cubic interpolating spline's curvature (in the plane of its mean binormal) at t."""
    S = make_interp_spline(t, X, k=3)
    d1, d2 = S(t, 1), S(t, 2)
    c = np.cross(d1, d2)
    n = np.sum(c, axis=0)
    nn = np.linalg.norm(n)
    if nn == 0.0:
        return 0.0
    return excess_curvature_variation((c @ (n / nn)) / np.linalg.norm(d1, axis=1) ** 3)


def curve_excess_many(t, X) -> np.ndarray:
    """:func:`curve_excess` of several curves sampled at the same t: X (m, n, 3) -> (m,),
    with one interpolating spline for all of them (the same spline per curve)."""
    X = np.asarray(X, dtype=np.float64)
    S = make_interp_spline(t, np.moveaxis(X, 0, 1), k=3)
    d1, d2 = np.moveaxis(S(t, 1), 1, 0), np.moveaxis(S(t, 2), 1, 0)
    out = np.zeros(len(X))
    for i in range(len(X)):
        c = np.cross(d1[i], d2[i])
        n = np.sum(c, axis=0)
        nn = np.linalg.norm(n)
        if nn > 0.0:
            out[i] = excess_curvature_variation((c @ (n / nn)) / np.linalg.norm(d1[i], axis=1) ** 3)
    return out


def zone_cuts(curves) -> list[tuple[str, int, object, object]]:
    """(family, index, plain cut, smoothed curve) for every curve of the smoothing zone."""
    out = []
    for i, flag in enumerate(curves.smoothed_tip):
        if flag:
            out.append(("tip", i, curves.cuts["tip"][i], curves.tip[i]))
    for fam, flags, smooth in (("leading", curves.smoothed_leading, curves.leading),
                               ("trailing", curves.smoothed_trailing, curves.trailing)):
        for i, cut in curves.cuts[fam].items():
            if flags[i]:
                out.append((fam, i, cut, smooth[i]))
    return out


def tip_irregularity(blade, curves, d_e: float) -> dict:
    """The tip irregularity (module docstring) before and after smoothing:
    {"unsmoothed": ΣE·R, "smoothed": ΣE·R, "ratio": smoothed/unsmoothed, "curves": n,
    "per_curve": [{"curve": "tip 12", "unsmoothed": E·R, "smoothed": E·R}, ...]}.
    d_e in metres."""
    R = blade.radius
    per = []
    for fam, i, cut, smooth in zone_cuts(curves):
        done = curves.smoothing.get((fam, i))
        if done is not None and len(done.irregularity) == 2:
            # the guard of the filter measured this cut already, with this definition
            per.append({"curve": f"{fam} {i + 1}", "unsmoothed": done.irregularity[0] * R,
                        "smoothed": done.irregularity[1] * R})
            continue
        tw = measure_window(blade, cut, d_e)
        X0 = blade_points(blade, cut.curve.parameters(tw))
        off = smooth.displacement(tw)
        X1 = X0 if off is None else blade_points(blade, smooth.parameters(tw)) + off
        per.append({"curve": f"{fam} {i + 1}", "unsmoothed": curve_excess(tw, X0) * R,
                    "smoothed": curve_excess(tw, X1) * R})
    before = float(sum(p["unsmoothed"] for p in per))
    after = float(sum(p["smoothed"] for p in per))
    return {"unsmoothed": before, "smoothed": after, "ratio": after / before if before > 0 else 1.0,
            "curves": len(per), "per_curve": per}


def measure_windows(blade, cuts, d_e: float) -> list[np.ndarray]:
    """:func:`measure_window` of several cuts with one evaluation of b.

    The window only needs the first and last of the WINDOW_SCAN parameters within d_e of
    x_1. Scanned every WINDOW_COARSE-th parameter first; where the coarse distances fall
    monotonically to their minimum and rise after it (a cut that runs round its edge
    once), only the parameters next to the two coarse crossings are evaluated, which gives
    the same first and last parameters; otherwise the whole scan (as before)."""
    t = np.linspace(0.0, 1.0, WINDOW_SCAN)
    coarse = t[::WINDOW_COARSE]
    x1 = np.stack([c.points[1] for c in cuts])
    P = np.stack([c.curve.parameters(coarse) for c in cuts])
    dist = np.linalg.norm(blade_points(blade, P) - x1[:, None], axis=2)
    out = [None] * len(cuts)
    fine_t, fine_k, full = [], [], []
    for k, d in enumerate(dist):
        m = int(np.argmin(d))
        inside = np.flatnonzero(d < d_e)
        fall, rise = np.diff(d[: m + 1]), np.diff(d[m:])
        if inside.size == 0 or not (np.all(fall < 0) and np.all(rise > 0)):
            full.append(k)
            continue
        # the fine parameters between the coarse samples around each crossing
        a, b = inside[0], inside[-1]
        lo = np.arange(max(a - 1, 0) * WINDOW_COARSE, a * WINDOW_COARSE + 1)
        hi = np.arange(b * WINDOW_COARSE, min((b + 1) * WINDOW_COARSE, t.size - 1) + 1)
        fine_t.append(np.concatenate([lo, hi]))
        fine_k.append(k)
    if fine_k:
        idx = fine_t
        pts = [cuts[k].curve.parameters(t[i]) for k, i in zip(fine_k, idx)]
        X = blade_points(blade, np.concatenate(pts))
        off = 0
        for k, i in zip(fine_k, idx):
            d = np.linalg.norm(X[off : off + i.size] - x1[k], axis=1)
            off += i.size
            inside = i[d < d_e]
            lo, hi = t[max(inside[0] - 1, 0)], t[min(inside[-1] + 1, t.size - 1)]
            out[k] = np.linspace(lo, hi, WINDOW_SAMPLES)
    for k in full:
        out[k] = measure_window(blade, cuts[k], d_e)
    return out


def _spline_node_derivatives(Y: np.ndarray):
    """First and second derivatives at the nodes of the not-a-knot cubic interpolating
    spline (the spline of ``make_interp_spline(t, Y, k=3)``) through Y (n, ...) at evenly
    spaced parameters, unit spacing: M (second derivatives) from the tridiagonal
    equations M_{i-1} + 4M_i + M_{i+1} = 6 δ²y_i and the not-a-knot ends
    M_0 - 2M_1 + M_2 = 0, M_{n-3} - 2M_{n-2} + M_{n-1} = 0 (one banded solve for all
    columns)."""
    from scipy.linalg import solve_banded

    shape = Y.shape
    n = shape[0]
    Y = Y.reshape(n, -1)
    ab = np.zeros((5, n))
    # ab[2 + i - j, j] = A[i, j]
    ab[2, 1:-1] = 4.0
    ab[1, 2:] = 1.0  # A[i, i+1], i = 1..n-2
    ab[3, :-2] = 1.0  # A[i, i-1], i = 1..n-2
    ab[2, 0], ab[1, 1], ab[0, 2] = 1.0, -2.0, 1.0  # row 0
    ab[4, n - 3], ab[3, n - 2], ab[2, n - 1] = 1.0, -2.0, 1.0  # row n-1
    rhs = np.empty_like(Y)
    rhs[0] = rhs[-1] = 0.0
    np.subtract(Y[:-2], 2.0 * Y[1:-1], out=rhs[1:-1])
    rhs[1:-1] += Y[2:]
    rhs[1:-1] *= 6.0
    M = solve_banded((2, 2), ab, rhs, overwrite_ab=True, overwrite_b=True, check_finite=False)
    d1 = np.empty_like(Y)
    np.subtract(Y[1:], Y[:-1], out=d1[:-1])
    d1[:-1] -= (2.0 * M[:-1] + M[1:]) / 6.0
    d1[-1] = (Y[-1] - Y[-2]) + (M[-2] + 2.0 * M[-1]) / 6.0
    return d1.reshape(shape), M.reshape(shape)


def curve_excess_uniform(X) -> np.ndarray:
    """:func:`curve_excess` of curves sampled at the same evenly spaced parameters, X
    (m, n, 3) -> (m,): the same measure (the curvature of the cubic interpolating spline
    at the samples; it does not depend on the parameter scale), computed for all curves
    at once from the spline's node derivatives (equal to :func:`curve_excess_many` to
    round-off)."""
    X = np.asarray(X, dtype=np.float64)
    m, n, _ = X.shape
    d1, d2 = _spline_node_derivatives(np.ascontiguousarray(np.moveaxis(X, 0, 1)))  # (n, m, 3)
    ax, ay, az = d1[..., 0], d1[..., 1], d1[..., 2]
    bx, by, bz = d2[..., 0], d2[..., 1], d2[..., 2]
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx  # c' x c'', (n, m)
    nx, ny, nz = cx.sum(axis=0), cy.sum(axis=0), cz.sum(axis=0)
    nn = np.sqrt(nx * nx + ny * ny + nz * nz)
    out = np.zeros(m)
    ok = nn > 0.0
    inv = 1.0 / np.where(ok, nn, 1.0)
    speed2 = ax * ax + ay * ay + az * az
    with np.errstate(divide="ignore", invalid="ignore"):
        k = (cx * (nx * inv) + cy * (ny * inv) + cz * (nz * inv)) / (speed2 * np.sqrt(speed2))  # (n, m)
    finite = np.all(np.isfinite(k), axis=0)
    use = ok & finite
    kk = k[:, use]
    if kk.size:
        tv = np.sum(np.abs(np.diff(kk, axis=0)), axis=0)
        pk = kk[np.argmax(np.abs(kk), axis=0), np.arange(kk.shape[1])]
        out[use] = np.maximum(0.0, tv - np.abs(pk - kk[0]) - np.abs(pk - kk[-1]))
    for i in np.flatnonzero(ok & ~finite):
        out[i] = excess_curvature_variation(k[:, i])
    return out
