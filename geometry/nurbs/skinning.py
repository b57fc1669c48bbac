"""Surfaces through curves: skinning, bilinearly blended Coons patches, and
transfinite interpolation of sampled boundaries.

Sources:
- Piegl & Tiller, The NURBS Book 2e (1997): §10.3 (skinned surfaces), Eq. 9.5/9.6 and
  Eq. 9.8 (parameters and averaged knots, used across the sections), Ch. 10 Coons
  surfaces (§10.5–10.6: the bilinearly blended Coons patch as two ruled surfaces minus a
  bilinear surface, all brought to a common degree and knot vectors).
- Hally (2013), DRDC Atlantic TM 2013-178, §8 Eq. 41 and §9 step 4: transfinite
  interpolation between four sampled boundary curves.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from ..errors import GeometryError
from .basis import validate_degree
from .curve import BSplineCurve
from .fitting import PARAMETERIZATION_METHODS, _as_params, _collocation_entries, _solve_banded_rows, average_knots, greville_abscissae
from .operations import make_compatible
from .surface import BSplineSurface

#: Boundary corners of a Coons patch or a transfinite interpolation must meet within this
#: distance, relative to the size of the boundary data, unless an explicit tol is given.
CORNER_TOL = 1e-9

#: A skinning column (control points of one index across the sections) shorter than this,
#: relative to the size of the sections, carries no parameter information and is skipped.
DEGENERATE_COLUMN_TOL = 1e-12


def _require_curves(curves, what: str) -> list[BSplineCurve]:
    try:
        curves = list(curves)
    except TypeError:
        raise GeometryError(f"{what}: expected a sequence of BSplineCurve, got {type(curves).__name__}") from None
    for i, c in enumerate(curves):
        if not isinstance(c, BSplineCurve):
            raise GeometryError(f"{what}[{i}]: expected a BSplineCurve, got {type(c).__name__}")
    return curves


def _section_parameters(columns: np.ndarray, method: str, scale: float) -> np.ndarray:
    """v̄_k for K sections: each column i of points across the sections is parameterised
    (Eq. 9.4/9.5/9.6) and the parameters are averaged over the columns (NURBS Book §10.3)."""
    K = columns.shape[1]
    if method == "uniform":
        return np.arange(K) / (K - 1)
    steps = np.linalg.norm(np.diff(columns, axis=1), axis=2)  # (n+1, K-1)
    if method == "centripetal":
        steps = np.sqrt(steps)
    total = steps.sum(axis=1)
    floor = DEGENERATE_COLUMN_TOL * scale
    if method == "centripetal":
        floor = np.sqrt(floor)
    useful = total > floor
    if not np.any(useful):
        raise GeometryError("skin: all section curves coincide; there is nothing to skin")
    fractions = np.cumsum(steps[useful], axis=1) / total[useful, None]
    mean_steps = np.diff(np.concatenate([[0.0], fractions.mean(axis=0)]))
    if np.any(mean_steps <= 0):
        k = int(np.flatnonzero(mean_steps <= 0)[0]) + 1
        raise GeometryError(f"skin: section curve {k} coincides with section curve {k - 1}")
    v = np.concatenate([[0.0], fractions.mean(axis=0)])
    v[-1] = 1.0
    return v


def skin_parameters(curves: Sequence[BSplineCurve], method: str = "chord") -> np.ndarray:
    """The section parameters v̄_k that :func:`skin` uses when none are given: the curves
    are made compatible, each column of control points across the sections is
    parameterised with ``method`` (NURBS Book Eqs. 9.4–9.6) and the columns' parameters
    are averaged (§10.3). Columns of coincident points (a section collapsed to the same
    point everywhere) are skipped. Returns (K,) from 0 to 1."""
    curves = _require_curves(curves, "curves")
    if len(curves) < 2:
        raise GeometryError(f"need at least 2 section curves, got {len(curves)}")
    if method not in PARAMETERIZATION_METHODS:
        raise GeometryError(f"method must be one of {PARAMETERIZATION_METHODS}, got {method!r}")
    sections = make_compatible(curves)
    return _parameters_of(sections, method)


def _parameters_of(sections: list[BSplineCurve], method: str) -> np.ndarray:
    euclid = np.stack([c.control_points for c in sections], axis=1)  # (n+1, K, dim)
    return _section_parameters(euclid, method, max(c.size() for c in sections))


def skin(
    curves: Sequence[BSplineCurve],
    degree_v: int = 3,
    params=None,
    method: str = "chord",
) -> BSplineSurface:
    """Skinned (lofted) surface through section curves (NURBS Book §10.3).

    curves: K >= degree_v + 1 section curves C_k(u), any degrees, knots and domains; they
    become the u-direction and v runs across the sections. The curves are made compatible
    (one degree, one clamped knot vector, u in [0, 1]) with
    :func:`~.operations.make_compatible`. params: the section parameters v̄_k (K strictly
    increasing values; the v domain is [params[0], params[-1]]), or None for
    :func:`skin_parameters`: the ``method`` parameterisation ("chord", "centripetal" or
    "uniform") of every column of control points across the sections, averaged. The v knots are averaged (Eq. 9.8) and every
    column is interpolated with the same banded system (Alg. A9.1). Rational sections are
    skinned in homogeneous space (w P, w), so S(u, v̄_k) = C_k(u) exactly for them too.

    Returns a BSplineSurface with S(u, v̄_k) equal to section k (reparametrised to [0, 1]).
    """
    curves = _require_curves(curves, "curves")
    q = validate_degree(degree_v, "degree_v")
    K = len(curves)
    if K < 2:
        raise GeometryError(f"skin needs at least 2 section curves, got {K}")
    if K < q + 1:
        raise GeometryError(f"skin: degree_v {q} needs at least {q + 1} section curves, got {K}")
    if method not in PARAMETERIZATION_METHODS:
        raise GeometryError(f"method must be one of {PARAMETERIZATION_METHODS}, got {method!r}")
    sections = make_compatible(curves)
    rational = sections[0].is_rational
    if params is None:
        v = _parameters_of(sections, method)
    else:
        v = _as_params(params, K)
    V = average_knots(v, q)
    net = np.stack([c.homogeneous if rational else c.control_points for c in sections], axis=1)
    n1, _, dimh = net.shape
    cols, vals = _collocation_entries(V, q, v)
    # one banded system, all columns (and coordinates) as right-hand sides
    rhs = net.transpose(1, 0, 2).reshape(K, n1 * dimh)
    Q = _solve_banded_rows(cols, vals, rhs).reshape(K, n1, dimh).transpose(1, 0, 2)
    U = sections[0].knots
    p = sections[0].degree
    if not rational:
        return BSplineSurface(p, q, U, V, Q)
    if np.any(Q[..., -1] <= 0):
        raise GeometryError(
            "skin: interpolating the section weights gave non-positive weights; "
            "use sections with more similar weights or uniform parameters"
        )
    return BSplineSurface.from_homogeneous(p, q, U, V, Q, rational=True)


def _corner_check(pairs, names, tol: float) -> None:
    for (a, b), name in zip(pairs, names):
        gap = float(np.linalg.norm(np.asarray(a) - np.asarray(b)))
        if not gap <= tol:
            raise GeometryError(f"the boundaries do not meet at the {name} corner: gap {gap:.3g} > tolerance {tol:.3g}")


def coons_surface(
    c0: BSplineCurve,
    c1: BSplineCurve,
    d0: BSplineCurve,
    d1: BSplineCurve,
    tol: float | None = None,
) -> BSplineSurface:
    """Bilinearly blended Coons patch from four boundary curves, as an exact B-spline
    (NURBS Book 2e, Ch. 10, Coons surfaces).

    c0(u): boundary at v = 0, c1(u): at v = 1, d0(v): at u = 0, d1(v): at u = 1, each
    taken over its own domain mapped onto [0, 1]. The corners must meet:
    c0(0)=d0(0), c0(1)=d1(0), c1(0)=d0(1), c1(1)=d1(1) within ``tol`` (absolute; default
    :data:`CORNER_TOL` times the size of the curves), else :class:`GeometryError`.

    S(u, v) = R_c(u, v) + R_d(u, v) - T(u, v) with the ruled surfaces
    R_c = (1-v) c0(u) + v c1(u), R_d = (1-u) d0(v) + u d1(v) and the bilinear T through
    the corners. c0, c1 are made compatible (degree p, knots U) and so are d0, d1
    (degree q, knots V); by the linear precision of B-splines (Σ ξ_i N_i(u) = u with the
    Greville abscissae ξ_i), every term is written exactly on the (p, U) x (q, V) basis,
    so the control net is (1-η_j) A_i + η_j B_i + (1-ξ_i) C_j + ξ_i D_j - bilinear(ξ_i, η_j).
    Boundary curves must be non-rational (the blend of different denominators is not
    a tensor-product NURBS). The surface reproduces the four boundaries.
    """
    named = {"c0": c0, "c1": c1, "d0": d0, "d1": d1}
    for name, c in named.items():
        if not isinstance(c, BSplineCurve):
            raise GeometryError(f"{name}: expected a BSplineCurve, got {type(c).__name__}")
        if c.is_rational:
            raise GeometryError(f"{name} is rational; coons_surface needs non-rational boundary curves")
    if len({c.dim for c in named.values()}) != 1:
        raise GeometryError(f"the boundary curves have different dimensions: {[c.dim for c in named.values()]}")
    a0, a1 = make_compatible([c0, c1])
    b0, b1 = make_compatible([d0, d1])
    A, B = a0.control_points, a1.control_points  # clamped: end control points are the ends
    C, D = b0.control_points, b1.control_points
    scale = max(c.size() for c in (a0, a1, b0, b1))
    limit = CORNER_TOL * scale if tol is None else float(tol)
    _corner_check(
        [(A[0], C[0]), (A[-1], D[0]), (B[0], C[-1]), (B[-1], D[-1])],
        ["(u, v) = (0, 0)", "(1, 0)", "(0, 1)", "(1, 1)"],
        limit,
    )
    P00, P10 = 0.5 * (A[0] + C[0]), 0.5 * (A[-1] + D[0])
    P01, P11 = 0.5 * (B[0] + C[-1]), 0.5 * (B[-1] + D[-1])
    p, U = a0.degree, a0.knots
    q, V = b0.degree, b0.knots
    xi = greville_abscissae(U, p)[:, None, None]  # (nu, 1, 1)
    eta = greville_abscissae(V, q)[None, :, None]  # (1, nv, 1)
    ruled_c = (1 - eta) * A[:, None, :] + eta * B[:, None, :]
    ruled_d = (1 - xi) * C[None, :, :] + xi * D[None, :, :]
    bilinear = (1 - xi) * (1 - eta) * P00 + xi * (1 - eta) * P10 + (1 - xi) * eta * P01 + xi * eta * P11
    return BSplineSurface(p, q, U, V, ruled_c + ruled_d - bilinear)


def transfinite_interpolation(
    bottom,
    top,
    left,
    right,
    u=None,
    v=None,
    tol: float | None = None,
) -> np.ndarray:
    """Bilinearly blended transfinite interpolation of four sampled boundaries
    (Coons; Hally 2013 §8 Eq. 41 and §9 step 4, where it runs in blade parameter space).

    bottom: (nu, dim) samples at v = 0, top: (nu, dim) at v = 1, left: (nv, dim) at u = 0,
    right: (nv, dim) at u = 1, with bottom[0]~left[0], bottom[-1]~right[0],
    top[0]~left[-1], top[-1]~right[-1] within ``tol`` (absolute; default
    :data:`CORNER_TOL` times the data size). u: (nu,) parameters of the bottom/top
    samples, v: (nv,) of the left/right samples (increasing; normalised to [0, 1];
    default uniform).

    Returns the grid X (nu, nv, dim):
    X_ij = (1-v_j) bottom_i + v_j top_i + (1-u_i) left_j + u_i right_j
           - [(1-u_i)(1-v_j) X_00 + u_i (1-v_j) X_10 + (1-u_i) v_j X_01 + u_i v_j X_11],
    whose boundary rows and columns are exactly the given samples.
    """
    B = np.array(bottom, dtype=np.float64)
    T = np.array(top, dtype=np.float64)
    L = np.array(left, dtype=np.float64)
    R = np.array(right, dtype=np.float64)
    for name, X in (("bottom", B), ("top", T), ("left", L), ("right", R)):
        if X.ndim != 2 or X.shape[0] < 2:
            raise GeometryError(f"{name}: expected an array of shape (count >= 2, dim), got {X.shape}")
        if not np.all(np.isfinite(X)):
            raise GeometryError(f"{name} contains a non-finite value")
    if B.shape != T.shape:
        raise GeometryError(f"bottom and top must have the same shape, got {B.shape} and {T.shape}")
    if L.shape != R.shape:
        raise GeometryError(f"left and right must have the same shape, got {L.shape} and {R.shape}")
    if B.shape[1] != L.shape[1]:
        raise GeometryError(f"the boundaries have different dimensions ({B.shape[1]} and {L.shape[1]})")
    nu, nv = B.shape[0], L.shape[0]

    def unit(params, count, what):
        if params is None:
            return np.linspace(0.0, 1.0, count)
        t = _as_params(params, count) if np.size(params) == count else None
        if t is None:
            raise GeometryError(f"{what}: expected {count} values, got {np.size(params)}")
        s = (t - t[0]) / (t[-1] - t[0])
        s[-1] = 1.0
        return s

    s = unit(u, nu, "u")[:, None, None]
    t = unit(v, nv, "v")[None, :, None]
    allpts = np.concatenate([B, T, L, R])
    scale = float(np.linalg.norm(allpts.max(axis=0) - allpts.min(axis=0)))
    limit = CORNER_TOL * scale if tol is None else float(tol)
    _corner_check(
        [(B[0], L[0]), (B[-1], R[0]), (T[0], L[-1]), (T[-1], R[-1])],
        ["bottom-left", "bottom-right", "top-left", "top-right"],
        limit,
    )
    X00, X10, X01, X11 = B[0], B[-1], T[0], T[-1]
    X = (
        (1 - t) * B[:, None, :] + t * T[:, None, :]
        + (1 - s) * L[None, :, :] + s * R[None, :, :]
        - ((1 - s) * (1 - t) * X00 + s * (1 - t) * X10 + (1 - s) * t * X01 + s * t * X11)
    )
    X[:, 0], X[:, -1], X[0, :], X[-1, :] = B, T, L, R
    X[0, 0], X[-1, 0], X[0, -1], X[-1, -1] = X00, X10, X01, X11
    return X
