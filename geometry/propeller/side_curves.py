"""The side edges c_5 ... c_8 of the central surfaces (Hally 2013 §5, Eqs. 8–14).

Each side curve keeps a distance from the leading (c_6, c_7) or trailing (c_5, c_8) edge
that varies linearly along it, so the edge surfaces have a nearly constant width:

- p_1(u): the straight parameter line from the lower to the upper corner, re-parameterised
  by the fractional arclength of b(p_1) (Eq. 8);
- p_2(u): the edge itself from the hub to x_LE (or x_TE), likewise (Eq. 9);
- d(u) = d_L + u (d_U - d_L) with the end distances of Eq. 10 (Eq. 11);
- x_m(u): the point at distance d(u) from b(p_2(u)) towards b(p_1(u)) (Eq. 12);
- the blade point on the line through x_m along the unit normal at p_1(u), by Newton on
  the three components of b(p_m) = x_m + t n̂ for (ξ, η, t) (Eq. 13);
- a cubic spline through the parameters gives p(u), and c(u) = b(p(u)) (Eq. 14).

Newton is vectorised over all u at once; x_m(0) and x_m(1) are the corners exactly.
"""
from __future__ import annotations

import numpy as np
from scipy.interpolate import make_interp_spline

from ..errors import GeometryError
from .corners import Corners, SplineCurve, blade_derivatives, blade_points

#: Number of u values solved by Newton per side curve (the N of Hally §5).
SIDE_CURVE_SAMPLES = 33
#: Samples of the straight lines used to build the arclength distributions a_1, a_2.
ARCLENGTH_SAMPLES = 257
#: Newton on Eq. 13 stops when the correction is below this (parameter units)...
NEWTON_TOL = 1e-13
#: ...within this many iterations.
NEWTON_MAX_ITERATIONS = 30


def arclength_lines(blade, starts, ends, samples: int = ARCLENGTH_SAMPLES):
    """u -> p(u) on straight parameter lines from ``starts`` (K, 2) to ``ends`` (K, 2)
    with u the fractional arclength of b(p) (the arclength distributions a_1, a_2 of
    Hally Eqs. 8–9), all lines in one evaluation of b. Returns a function mapping u (n,)
    to parameters (K, n, 2)."""
    starts, ends = np.asarray(starts, float), np.asarray(ends, float)
    w = np.linspace(0.0, 1.0, samples)
    X = blade_points(blade, starts[:, None] + w[None, :, None] * (ends - starts)[:, None])
    s = np.concatenate([np.zeros((len(starts), 1)), np.cumsum(np.linalg.norm(np.diff(X, axis=1), axis=2), axis=1)],
                       axis=1)
    if np.any(s[:, -1] <= 0):
        raise GeometryError("degenerate side line (Hally §5, Eqs. 8–9)")
    s /= s[:, -1:]
    inverse = [make_interp_spline(sk, w, k=3) for sk in s]

    def lines(u):
        a = np.clip(np.stack([f(np.asarray(u, float)) for f in inverse]), 0.0, 1.0)
        return starts[:, None] + a[..., None] * (ends - starts)[:, None]

    return lines


def side_curves(blade, corners: Corners, samples: int = SIDE_CURVE_SAMPLES) -> dict[str, SplineCurve]:
    """c_5 (x_LL -> x_UL, from the TE), c_6 (x_LR -> x_UR, from the LE), c_7
    (x_LL^(s) -> x_UL^(s), from the LE) and c_8 (x_LR^(s) -> x_UR^(s), from the TE)
    (Hally §4 items 5–8, §5), all four solved together. The suction-side TE curve c_8 is
    written with ξ - 1 (the periodic blade) so the trailing-edge curves run continuously
    through ξ = 0."""
    c = corners
    shift = np.array([1.0, 0.0])
    names = ("c5", "c6", "c7", "c8")
    lower = np.stack([c.ll, c.lr, c.ll_s, c.lr_s - shift])
    upper = np.stack([c.ul, c.ur, c.ul_s, c.ur_s - shift])
    e_low = np.stack([c.te_hub, c.le_hub, c.le_hub, c.te_hub])
    e_up = np.stack([c.te, c.le, c.le, c.te])
    K = len(names)
    lines = arclength_lines(blade, np.concatenate([lower, e_low]), np.concatenate([upper, e_up]))
    u = np.linspace(0.0, 1.0, samples)
    L = lines(u)
    P1 = L[:K]  # Eq. 8; L[K:] are the edge lines p_2(u) of Eq. 9
    B = blade_points(blade, L)
    B1, B2 = B[:K], B[K:]
    gap = B1 - B2
    dist = np.linalg.norm(gap, axis=2)
    if np.any(dist <= 0):
        raise GeometryError("a side line touches the edge (Hally §5, Eq. 10)")
    d = dist[:, :1] + u[None, :] * (dist[:, -1:] - dist[:, :1])  # Eqs. 10–11
    xm = (B2 + d[..., None] * gap / dist[..., None]).reshape(-1, 3)  # Eq. 12
    p1 = P1.reshape(-1, 2)
    D = blade_derivatives(blade, p1, 1)
    n = np.cross(D[:, 1, 0], D[:, 0, 1])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    # Newton on b(p) - x_m - t n = 0 for (ξ, η, t) (Eq. 13), from p = p_1(u), t = 0
    p = p1.copy()
    t = np.zeros(len(p))
    for _ in range(NEWTON_MAX_ITERATIONS):
        D = blade_derivatives(blade, p, 1)
        F = D[:, 0, 0] - xm - t[:, None] * n
        J = np.stack([D[:, 1, 0], D[:, 0, 1], -n], axis=-1)
        delta = np.linalg.solve(J, -F[..., None])[..., 0]
        p += delta[:, :2]
        t += delta[:, 2]
        if np.max(np.abs(delta[:, :2])) < NEWTON_TOL:
            break
    else:
        k = int(np.argmax(np.abs(delta[:, :2]).max(axis=1)))
        raise GeometryError(
            f"{names[k // samples]}: Newton projection of Hally Eq. 13 did not converge at u = {u[k % samples]:.4g} "
            f"(ξ = {p[k, 0]:.6g}, η = {p[k, 1]:.6g})"
        )
    p = p.reshape(K, samples, 2)
    p[:, 0], p[:, -1] = P1[:, 0], P1[:, -1]  # x_m(0), x_m(1) are the corners exactly
    if np.any(p[..., 1] > 1.0) or np.any(p[..., 1] < blade.eta_min):
        raise GeometryError("a projected side curve leaves the blade (η outside [eta_min, 1]; Hally §5)")
    return {name: SplineCurve(make_interp_spline(u, p[k], k=3)) for k, name in enumerate(names)}  # Eq. 14
