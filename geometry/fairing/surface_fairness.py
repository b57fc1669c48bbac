"""Fairness integrals of any B-spline/NURBS surface: the Minimum Variation Surface (MVS)
functional and the strain (bending) energy (Hosseini & Moetakef-Imani 2016, §5 Eq. 6,
after Moreton & Séquin 1992):

    MVS = ∫ ( (∂κ1/∂e1)² + (∂κ2/∂e2)² ) dA,    strain energy = ∫ (κ1² + κ2²) dA.

κ1 >= κ2 are the principal curvatures and e1, e2 the principal directions, from the first
fundamental form I = [[E, F], [F, G]] and the second II = [[L, M], [M, N]] (do Carmo §3.3):
κ solves det(II - κ I) = 0 and e = a S_u + b S_v with (II - κ I)(a, b)ᵀ = 0. The directional
derivative ∂κ/∂e = a κ_u + b κ_v, with κ_u, κ_v from the derivative of a simple generalised
eigenvalue: κ_x = eᵀ(II_x - κ I_x)e / eᵀ I e (e normalised so eᵀ I e = 1, i.e. a unit
tangent vector), which needs the surface's third derivatives and the derivative of the
unit normal n_x = (N_x - n (n·N_x)) / |N| for N = S_u × S_v.

Integration: Gauss–Legendre with ``quadrature_points`` nodes per knot span in u and in v,
dA = |S_u × S_v| du dv. At umbilics (κ1 = κ2) the directions are undefined; there
κ_x = eᵀ(II_x - κ I_x)e is used with e the eigenvector numpy returns, which is exact where
the surface is umbilic in a neighbourhood (II = κ I, as on a sphere) and a bounded
approximation at isolated umbilics.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError
from ..nurbs import BSplineSurface

#: Default Gauss–Legendre nodes per knot span and direction: exact for the area of a
#: bicubic patch's polynomial parts and ample for the smooth integrands here.
DEFAULT_QUADRATURE_POINTS = 6

#: A surface point whose |S_u × S_v| is below this (relative to the squared size of the
#: surface) is degenerate; the integrands are taken as zero there.
DEGENERATE_TOL = 1e-14


@dataclass(frozen=True)
class Fairness:
    """MVS and strain energy of a surface (Eq. 6), and its area."""

    mvs: float
    strain_energy: float
    area: float


def _gauss_nodes(knots: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(count)
    br = np.unique(knots)
    a, h = br[:-1, None], np.diff(br)[:, None]
    return (a + 0.5 * h * (x + 1.0)).ravel(), (0.5 * h * w).ravel()


def principal_curvatures(surface: BSplineSurface, u, v) -> dict:
    """κ1 >= κ2, unit principal directions e1, e2 (3-D), their directional derivatives
    ∂κ1/∂e1 and ∂κ2/∂e2, and the area element |S_u × S_v|, at broadcast (u, v).

    Returns a dict of arrays: ``k1``, ``k2`` (shape B), ``e1``, ``e2`` (B + (3,)),
    ``dk1_de1``, ``dk2_de2``, ``dA`` (B)."""
    if surface.dim != 3:
        raise GeometryError(f"fairness needs a 3-D surface, got dim {surface.dim}")
    D = surface.derivatives(u, v, 3)
    Su, Sv = D[..., 1, 0, :], D[..., 0, 1, :]
    Suu, Suv, Svv = D[..., 2, 0, :], D[..., 1, 1, :], D[..., 0, 2, :]
    Suuu, Suuv, Suvv, Svvv = D[..., 3, 0, :], D[..., 2, 1, :], D[..., 1, 2, :], D[..., 0, 3, :]
    dot = lambda a, b: np.einsum("...i,...i->...", a, b)  # noqa: E731
    Nv = np.cross(Su, Sv)
    area = np.linalg.norm(Nv, axis=-1)
    bad = area <= DEGENERATE_TOL * max(surface.size(), 1e-300) ** 2
    safe = np.where(bad, 1.0, area)
    n = Nv / safe[..., None]
    # derivatives of the unnormalised and unit normal
    N_u = np.cross(Suu, Sv) + np.cross(Su, Suv)
    N_v = np.cross(Suv, Sv) + np.cross(Su, Svv)
    n_u = (N_u - n * dot(n, N_u)[..., None]) / safe[..., None]
    n_v = (N_v - n * dot(n, N_v)[..., None]) / safe[..., None]
    # fundamental forms and their derivatives
    E, F, G = dot(Su, Su), dot(Su, Sv), dot(Sv, Sv)
    L, M, N = dot(Suu, n), dot(Suv, n), dot(Svv, n)
    E_u, E_v = 2 * dot(Suu, Su), 2 * dot(Suv, Su)
    F_u, F_v = dot(Suu, Sv) + dot(Su, Suv), dot(Suv, Sv) + dot(Su, Svv)
    G_u, G_v = 2 * dot(Suv, Sv), 2 * dot(Svv, Sv)
    L_u, L_v = dot(Suuu, n) + dot(Suu, n_u), dot(Suuv, n) + dot(Suu, n_v)
    M_u, M_v = dot(Suuv, n) + dot(Suv, n_u), dot(Suvv, n) + dot(Suv, n_v)
    N_u2, N_v2 = dot(Suvv, n) + dot(Svv, n_u), dot(Svvv, n) + dot(Svv, n_v)
    Iform = np.stack([np.stack([E, F], -1), np.stack([F, G], -1)], -2)
    IIform = np.stack([np.stack([L, M], -1), np.stack([M, N], -1)], -2)
    Iform = np.where(bad[..., None, None], np.eye(2), Iform)
    # generalised symmetric eigenproblem II e = κ I e via the Cholesky factor of I
    C = np.linalg.cholesky(Iform)
    Ci = np.linalg.inv(C)  # 2x2 triangular per point
    A = Ci @ IIform @ np.swapaxes(Ci, -1, -2)
    k, y = np.linalg.eigh(A)  # ascending
    vecs = np.swapaxes(Ci, -1, -2) @ y  # columns: (a, b) with eᵀ I e = 1
    out = {}
    dI_u = np.stack([np.stack([E_u, F_u], -1), np.stack([F_u, G_u], -1)], -2)
    dI_v = np.stack([np.stack([E_v, F_v], -1), np.stack([F_v, G_v], -1)], -2)
    dII_u = np.stack([np.stack([L_u, M_u], -1), np.stack([M_u, N_u2], -1)], -2)
    dII_v = np.stack([np.stack([L_v, M_v], -1), np.stack([M_v, N_v2], -1)], -2)
    for name, col in (("1", 1), ("2", 0)):
        kap = k[..., col]
        ab = vecs[..., :, col]
        quad = lambda X: np.einsum("...i,...ij,...j->...", ab, X, ab)  # noqa: E731
        k_u = quad(dII_u) - kap * quad(dI_u)
        k_v = quad(dII_v) - kap * quad(dI_v)
        e = ab[..., 0:1] * Su + ab[..., 1:2] * Sv
        deriv = ab[..., 0] * k_u + ab[..., 1] * k_v
        out["k" + name] = np.where(bad, 0.0, kap)
        out["e" + name] = e
        out[f"dk{name}_de{name}"] = np.where(bad, 0.0, deriv)
    out["dA"] = area
    return out


def surface_fairness(surface: BSplineSurface, quadrature_points: int | None = None) -> Fairness:
    """MVS and strain energy (Hosseini 2016 Eq. 6) of ``surface`` by Gauss–Legendre
    quadrature per knot span (``quadrature_points`` nodes per span and direction).

    The integrands come from :func:`.surface_curvature.surface_curvature_grid`, the same
    formulas as :func:`principal_curvatures` with the 2x2 pencil solved in closed form
    (at an umbilic it takes e1 along S_u, exact where II = κ I in a neighbourhood)."""
    if not isinstance(surface, BSplineSurface):
        raise GeometryError(f"surface_fairness needs a BSplineSurface, got {type(surface).__name__}")
    g = DEFAULT_QUADRATURE_POINTS if quadrature_points is None else int(quadrature_points)
    if g < 1:
        raise GeometryError(f"quadrature_points must be >= 1, got {quadrature_points!r}")
    if surface.dim != 3:
        raise GeometryError(f"fairness needs a 3-D surface, got dim {surface.dim}")
    from .surface_curvature import surface_curvature_grid

    us, wu = _gauss_nodes(surface.knots_u, g)
    vs, wv = _gauss_nodes(surface.knots_v, g)
    # The nodes form a tensor grid: derivatives by one matrix product per (k, l) and the
    # 2x2 eigenproblems in closed form (surface_curvature), not per point through LAPACK.
    c = surface_curvature_grid(surface, us, vs, fairness=True)
    W = wu[:, None] * wv[None, :] * c.area_element
    mvs = float(np.sum(W * c.mvs_density))
    se = float(np.sum(W * c.strain_energy_density))
    return Fairness(mvs, se, float(W.sum()))


@dataclass(frozen=True)
class CurveFairness:
    """The curve analogues of Eq. 6: curvature variation ∫ (dκ/ds)² ds, bending energy
    ∫ κ² ds, and the arc length."""

    curvature_variation: float
    bending_energy: float
    length: float


def curve_fairness(curve, quadrature_points: int | None = None) -> CurveFairness:
    """Eq. 6 of Hosseini & Moetakef-Imani (2016) reduced to a curve (a section of a blade
    surface): ∫ (dκ/ds)² ds and ∫ κ² ds by Gauss–Legendre quadrature per knot span.

    With a = C', b = C'', c = C''' and w = a × b (curves of any dimension are embedded in
    3-D): κ = |w| / |a|³ and dκ/ds = ((w · (a × c)) / |w| − 3 |w| (a · b) / |a|²) / |a|⁴,
    the chain rule on the Frenet curvature (do Carmo §1.5); at a straight point (w = 0)
    the derivative is taken as zero. ds = |a| du.
    """
    from ..nurbs import BSplineCurve

    if not isinstance(curve, BSplineCurve):
        raise GeometryError(f"curve_fairness needs a BSplineCurve, got {type(curve).__name__}")
    g = DEFAULT_QUADRATURE_POINTS if quadrature_points is None else int(quadrature_points)
    if g < 1:
        raise GeometryError(f"quadrature_points must be >= 1, got {quadrature_points!r}")
    u, w_q = _gauss_nodes(curve.knots[curve.degree: len(curve.knots) - curve.degree], g)
    D = curve.derivatives(u, 3)
    pad = lambda X: np.pad(X, ((0, 0), (0, 3 - X.shape[1]))) if X.shape[1] < 3 else X  # noqa: E731
    a, b, c = pad(D[:, 1]), pad(D[:, 2]), pad(D[:, 3])
    speed = np.linalg.norm(a, axis=1)
    if np.any(speed <= DEGENERATE_TOL * max(curve.size(), 1e-300)):
        raise GeometryError("curve_fairness: the curve has a zero derivative (a cusp or a degenerate span)")
    w = np.cross(a, b)
    wn = np.linalg.norm(w, axis=1)
    kappa = wn / speed**3
    safe = np.where(wn > 0.0, wn, 1.0)
    dk = np.where(wn > 0.0, (np.einsum("ij,ij->i", w, np.cross(a, c)) / safe
                             - 3.0 * wn * np.einsum("ij,ij->i", a, b) / speed**2) / speed**4, 0.0)
    ds = w_q * speed
    return CurveFairness(float(ds @ dk**2), float(ds @ kappa**2), float(ds.sum()))
