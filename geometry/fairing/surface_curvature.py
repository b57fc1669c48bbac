"""Curvature of B-spline/NURBS surfaces and curves for visual review, from the float64 model.

Differential geometry (do Carmo, Differential Geometry of Curves and Surfaces, §3.2–3.3):
with S_u, S_v, S_uu, S_uv, S_vv the partial derivatives and n = σ S_u × S_v / |S_u × S_v|
(σ = ``sign``, +1 for the surface's own normal),

    first fundamental form   I  = [[E, F], [F, G]],  E = S_u·S_u, F = S_u·S_v, G = S_v·S_v,
    second fundamental form  II = [[L, M], [M, N]],  L = S_uu·n, M = S_uv·n, N = S_vv·n,
    Gaussian K = (LN - M²)/(EG - F²),  mean H = (EN - 2FM + GL) / (2(EG - F²)),
    principal κ1,2 = H ± sqrt(H² - K)  (κ1 >= κ2),

so a curvature is positive where the surface bends towards n (a sphere with inward n has
κ = +1/r). The principal direction e1 = a S_u + b S_v solves (II - κ1 I)(a, b)ᵀ = 0 and
e2 = n × e1. Hosseini & Moetakef-Imani (2016) Eq. 6 (after Moreton & Séquin 1992) give the
fairness densities

    MVS density = (∂κ1/∂e1)² + (∂κ2/∂e2)²,    strain-energy density = κ1² + κ2²,

with ∂κ/∂e = a κ_u + b κ_v and κ_x = eᵀ(II_x - κ I_x)e / eᵀIe, the derivative of a simple
eigenvalue of the pencil II - κ I (needs the third derivatives of S and n_x = (N_x -
n(n·N_x))/|N| for N = σ S_u × S_v). At umbilics (κ1 = κ2) the directions are undefined;
e1 is then S_u/|S_u| and the formula gives the derivative along it.

On a parameter grid the derivatives come from dense collocation matrices of the basis
derivatives (NURBS Book Alg. A2.3) contracted with the net row-then-column, and from
Alg. A4.4 for rational surfaces: far cheaper than evaluating the pairs one by one, which is
what lets a review at display resolution run interactively.

Also here: signed curvature of curves (in their plane, or normal curvature on a surface),
curvature combs with an envelope, sign changes along isoparametric lines, robust symmetric
limits (percentile clipping), a diverging colour-blind-safe colour map, and fairness
integrals by Gauss–Legendre quadrature per knot span.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError
from ..nurbs import BSplineCurve, BSplineSurface
from ..nurbs.basis import basis_function_derivatives, check_parameters, find_span
from ..propeller.cut_smoothing import CURVATURE_ZERO_FRACTION, curvature_sign_changes

#: |S_u × S_v| below this times the squared surface size marks a degenerate point (a
#: collapsed edge); curvature is reported as 0 there rather than inf/nan.
DEGENERATE_TOL = 1e-14
#: Default percentile of |value| used as the symmetric colour limit (robust clipping:
#: tips and edges carry curvatures orders of magnitude above the rest).
DEFAULT_PERCENTILE = 98.0
#: Gauss–Legendre nodes per knot span and direction for the fairness integrals.
DEFAULT_QUADRATURE_POINTS = 6
#: Default samples per knot span along an isoparametric line when counting sign changes.
ISO_SAMPLES_PER_SPAN = 16
#: A curve whose points deviate from their best-fit plane by less than this fraction of
#: its size is treated as planar (its curvature is then signed in that plane).
PLANARITY_TOL = 1e-6
#: Default comb length: the robust (percentile) tooth is this fraction of the curve's size.
DEFAULT_COMB_FRACTION = 0.15

#: Names of the scalar quantities a :class:`SurfaceCurvature` provides.
QUANTITIES = ("mean", "gaussian", "k1", "k2", "max_abs", "mvs", "strain_energy")

#: Control colours (sRGB, 0..1) of the diverging map at -1, -2/3, ..., +1: blue to near
#: white to orange, a pair told apart by the common colour-vision deficiencies
#: (deuteranopia, protanopia, tritanopia), lightness falling monotonically away from 0.
DIVERGING_CONTROL_COLOURS = np.array([
    [0.122, 0.306, 0.549],
    [0.290, 0.525, 0.773],
    [0.663, 0.796, 0.910],
    [0.969, 0.969, 0.969],
    [0.965, 0.753, 0.561],
    [0.878, 0.471, 0.184],
    [0.612, 0.239, 0.043],
])


# ---------------------------------------------------------------------------------------
# derivatives on grids
# ---------------------------------------------------------------------------------------
def _derivative_matrices(knots: np.ndarray, degree: int, n_control: int, params: np.ndarray, order: int):
    """(order+1, len(params), n_control): row k holds d^k N_i/du^k at the params."""
    span = find_span(knots, degree, params)
    ders = basis_function_derivatives(knots, degree, params, span, order)  # (n, order+1, p+1)
    M = np.zeros((order + 1, params.size, n_control))
    cols = span[:, None] - degree + np.arange(degree + 1)
    rows = np.arange(params.size)[:, None]
    for k in range(order + 1):
        M[k, rows, cols] = ders[:, k, :]
    return M


def _rational_fields(A: dict, order: int) -> dict:
    """NURBS Book Alg. A4.4 on component-first fields: A[(k, l)] = (dim+1, ...) holds the
    derivatives of (wS, w); returns those of S, (dim, ...) each."""
    from math import comb

    w = {key: value[-1] for key, value in A.items()}
    S = {}
    for k in range(order + 1):
        for l in range(order + 1 - k):
            v = A[(k, l)][:-1].copy()
            for j in range(1, l + 1):
                v -= comb(l, j) * w[(0, j)] * S[(k, l - j)]
            for i in range(1, k + 1):
                v -= comb(k, i) * w[(i, 0)] * S[(k - i, l)]
                for j in range(1, l + 1):
                    v -= comb(k, i) * comb(l, j) * w[(i, j)] * S[(k - i, l - j)]
            S[(k, l)] = v / w[(0, 0)]
    return S


def grid_derivative_fields(surface: BSplineSurface, us, vs, order: int = 2) -> dict:
    """Partial derivatives on the grid us x vs as a dict {(k, l): (dim, len(us), len(vs))}
    (component-first, contiguous) for k + l <= order: one batched matrix product
    D_u^(k) · P · D_v^(l)ᵀ per entry, then Alg. A4.4 for rational surfaces."""
    us = check_parameters(np.ravel(us), surface.knots_u, surface.degree_u, "u")
    vs = check_parameters(np.ravel(vs), surface.knots_v, surface.degree_v, "v")
    if order < 0:
        raise GeometryError(f"derivative order must be >= 0, got {order}")
    net = surface.homogeneous if surface.is_rational else surface.control_points
    net = np.ascontiguousarray(net.transpose(2, 0, 1))  # (dim', nu, nv)
    Du = _derivative_matrices(surface.knots_u, surface.degree_u, surface.shape[0], us, order)
    Dv = _derivative_matrices(surface.knots_v, surface.degree_v, surface.shape[1], vs, order)
    fields = {}
    for k in range(order + 1):
        rows = np.matmul(Du[k], net)  # (dim', len(us), nv)
        for l in range(order + 1 - k):
            fields[(k, l)] = np.matmul(rows, Dv[l].T)
    if surface.is_rational:
        fields = _rational_fields(fields, order)
    return fields


def grid_derivatives(surface: BSplineSurface, us, vs, order: int = 2) -> np.ndarray:
    """Partial derivatives on the grid us x vs: (len(us), len(vs), order+1, order+1, dim),
    entry [..., k, l, :] = d^(k+l)S/du^k dv^l for k + l <= order (zero above).
    NURBS Book Alg. A2.3 (basis derivatives) and A4.4 (rational surfaces)."""
    fields = grid_derivative_fields(surface, us, vs, order)
    f0 = fields[(0, 0)]
    H = np.zeros(f0.shape[1:] + (order + 1, order + 1, f0.shape[0]))
    for (k, l), value in fields.items():
        H[:, :, k, l] = np.moveaxis(value, 0, -1)
    return H


# ---------------------------------------------------------------------------------------
# surface curvature
# ---------------------------------------------------------------------------------------
def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


@dataclass(frozen=True, eq=False)
class SurfaceCurvature:
    """Curvature of a 3-D surface at parameters (arrays of the broadcast shape B).

    points, normal: B + (3,); first_form (E, F, G) and second_form (L, M, N): each B;
    gaussian (1/m²), mean, k1 >= k2 (1/m); e1, e2: unit principal directions B + (3,);
    area_element |S_u × S_v|; dk1_de1, dk2_de2 (1/m²): None unless computed with
    ``fairness=True``. ``degenerate``: bool B, points where the normal is undefined."""

    points: np.ndarray
    normal: np.ndarray
    first_form: tuple
    second_form: tuple
    gaussian: np.ndarray
    mean: np.ndarray
    k1: np.ndarray
    k2: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    area_element: np.ndarray
    degenerate: np.ndarray
    dk1_de1: np.ndarray | None = None
    dk2_de2: np.ndarray | None = None

    @property
    def strain_energy_density(self) -> np.ndarray:
        """κ1² + κ2² (1/m²), Hosseini (2016) Eq. 6."""
        return self.k1**2 + self.k2**2

    @property
    def mvs_density(self) -> np.ndarray:
        """(∂κ1/∂e1)² + (∂κ2/∂e2)² (1/m⁴), Hosseini (2016) Eq. 6."""
        if self.dk1_de1 is None:
            raise GeometryError("the MVS density needs third derivatives: compute with fairness=True")
        return self.dk1_de1**2 + self.dk2_de2**2

    @property
    def max_abs(self) -> np.ndarray:
        """The principal curvature of larger magnitude, with its sign (1/m)."""
        return np.where(np.abs(self.k1) >= np.abs(self.k2), self.k1, self.k2)

    def quantity(self, name: str) -> np.ndarray:
        """One of :data:`QUANTITIES` by name."""
        if name == "strain_energy":
            return self.strain_energy_density
        if name == "mvs":
            return self.mvs_density
        if name in QUANTITIES:
            return getattr(self, name)
        raise GeometryError(f"unknown curvature quantity {name!r}; expected one of {', '.join(QUANTITIES)}")


def _cross(a, b):
    return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _dotc(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _fields_from_array(D: np.ndarray) -> dict:
    d = D.shape[-2] - 1
    return {(k, l): np.ascontiguousarray(np.moveaxis(D[..., k, l, :], -1, 0))
            for k in range(d + 1) for l in range(d + 1 - k)}


def curvature_from_derivatives(D, *, sign: float = 1.0, fairness: bool = False,
                               size: float = 1.0) -> SurfaceCurvature:
    """:class:`SurfaceCurvature` from partial derivatives: an array B + (d+1, d+1, 3) with
    d >= 2 (d >= 3 for ``fairness``), or the dict of :func:`grid_derivative_fields`.
    ``sign``: +1 measures curvature against S_u × S_v, -1 against the opposite normal.
    ``size``: the surface's length scale (degeneracy test)."""
    F_ = D if isinstance(D, dict) else _fields_from_array(np.asarray(D, dtype=np.float64))
    if F_[(0, 0)].shape[0] != 3:
        raise GeometryError(f"surface curvature needs a 3-D surface, got dimension {F_[(0, 0)].shape[0]}")
    need = 3 if fairness else 2
    if (need, 0) not in F_:
        raise GeometryError(f"curvature needs derivatives of order {need}")
    sign = 1.0 if sign >= 0 else -1.0
    Su, Sv = F_[(1, 0)], F_[(0, 1)]
    Suu, Suv, Svv = F_[(2, 0)], F_[(1, 1)], F_[(0, 2)]
    Nvec = _cross(Su, Sv)
    if sign < 0:
        Nvec = -Nvec
    area = np.sqrt(_dotc(Nvec, Nvec))
    degenerate = area <= DEGENERATE_TOL * max(size, 1e-300) ** 2
    safe = np.where(degenerate, 1.0, area)
    n = Nvec / safe
    E, F, G = _dotc(Su, Su), _dotc(Su, Sv), _dotc(Sv, Sv)
    L, M, N = _dotc(Suu, n), _dotc(Suv, n), _dotc(Svv, n)
    det_I = np.where(degenerate, 1.0, E * G - F * F)
    E_safe = np.where(degenerate | (E <= 0), 1.0, E)
    # symmetric form of the pencil II - κ I: A = C⁻¹ II C⁻ᵀ with I = C Cᵀ (Cholesky), so
    # H² - K = ((A11 - A22)/2)² + A12² is a sum of squares and stays accurate at umbilics
    c11 = np.sqrt(E_safe)
    c22 = np.sqrt(det_I / E_safe)
    r21, r22 = -F / (E_safe * c22), 1.0 / c22  # second row of C⁻¹ (first is (1/c11, 0))
    A11 = L / E_safe
    A12 = (L * r21 + M * r22) / c11
    A22 = L * r21 * r21 + 2.0 * M * r21 * r22 + N * r22 * r22
    H = np.where(degenerate, 0.0, 0.5 * (A11 + A22))
    disc = np.where(degenerate, 0.0, np.hypot(0.5 * (A11 - A22), A12))
    K = np.where(degenerate, 0.0, (L * N - M * M) / det_I)
    k1, k2 = H + disc, H - disc
    # eigenvector y of A for k1 from the better-conditioned row, then (a, b) = C⁻ᵀ y
    pick = np.abs(k1 - A11) >= np.abs(k1 - A22)
    y0 = np.where(pick, A12, k1 - A22)
    y1 = np.where(pick, k1 - A11, A12)
    a = y0 / c11 + r21 * y1
    b = r22 * y1
    e1 = a * Su + b * Sv
    length = np.sqrt(_dotc(e1, e1))
    # umbilic (or degenerate): any tangent direction is principal; take S_u
    umbilic = np.hypot(y0, y1) <= 1e-9 * np.maximum(np.abs(k1) + np.abs(k2), 1e-300)
    umbilic |= length == 0.0
    e1 = np.where(umbilic, Su / c11, e1 / np.where(length > 0, length, 1.0))
    e2 = _cross(n, e1)
    last = lambda x: np.moveaxis(x, 0, -1)  # noqa: E731
    result = dict(
        points=last(F_[(0, 0)]), normal=last(n), first_form=(E, F, G), second_form=(L, M, N),
        gaussian=K, mean=H, k1=k1, k2=k2, e1=last(e1), e2=last(e2), area_element=area,
        degenerate=degenerate,
    )
    if fairness:
        Suuu, Suuv, Suvv, Svvv = F_[(3, 0)], F_[(2, 1)], F_[(1, 2)], F_[(0, 3)]
        N_u = _cross(Suu, Sv) + _cross(Su, Suv)
        N_v = _cross(Suv, Sv) + _cross(Su, Svv)
        if sign < 0:
            N_u, N_v = -N_u, -N_v
        n_u = (N_u - n * _dotc(n, N_u)) / safe
        n_v = (N_v - n * _dotc(n, N_v)) / safe
        dE = (2 * _dotc(Suu, Su), 2 * _dotc(Suv, Su))
        dF = (_dotc(Suu, Sv) + _dotc(Su, Suv), _dotc(Suv, Sv) + _dotc(Su, Svv))
        dG = (2 * _dotc(Suv, Sv), 2 * _dotc(Svv, Sv))
        dL = (_dotc(Suuu, n) + _dotc(Suu, n_u), _dotc(Suuv, n) + _dotc(Suu, n_v))
        dM = (_dotc(Suuv, n) + _dotc(Suv, n_u), _dotc(Suvv, n) + _dotc(Suv, n_v))
        dN = (_dotc(Suvv, n) + _dotc(Svv, n_u), _dotc(Svvv, n) + _dotc(Svv, n_v))

        def directional(kappa, e):
            # (a, b) of the unit tangent e = a S_u + b S_v: I (a, b)ᵀ = (e·S_u, e·S_v)ᵀ
            p, q = _dotc(e, Su), _dotc(e, Sv)
            a = (G * p - F * q) / det_I
            b = (E * q - F * p) / det_I
            k_x = []
            for x in (0, 1):
                quad_II = a * a * dL[x] + 2 * a * b * dM[x] + b * b * dN[x]
                quad_I = a * a * dE[x] + 2 * a * b * dF[x] + b * b * dG[x]
                k_x.append(quad_II - kappa * quad_I)  # e is unit, so eᵀIe = 1
            return np.where(degenerate, 0.0, a * k_x[0] + b * k_x[1])

        result["dk1_de1"] = directional(k1, e1)
        result["dk2_de2"] = directional(k2, e2)
    return SurfaceCurvature(**result)


def _require_3d_surface(surface) -> BSplineSurface:
    if not isinstance(surface, BSplineSurface):
        raise GeometryError(f"expected a BSplineSurface, got {type(surface).__name__}")
    if surface.dim != 3:
        raise GeometryError(f"surface curvature needs a 3-D surface, got dimension {surface.dim}")
    return surface


def surface_curvature(surface: BSplineSurface, u, v, *, sign: float = 1.0, fairness: bool = False) -> SurfaceCurvature:
    """Curvature at broadcast parameter arrays u, v (shape B); see the module docstring."""
    _require_3d_surface(surface)
    D = surface.derivatives(u, v, 3 if fairness else 2)
    return curvature_from_derivatives(D, sign=sign, fairness=fairness, size=surface.size())


def surface_curvature_grid(surface: BSplineSurface, us, vs, *, sign: float = 1.0, fairness: bool = False) -> SurfaceCurvature:
    """Curvature on the grid us x vs (arrays of shape (len(us), len(vs)))."""
    _require_3d_surface(surface)
    D = grid_derivative_fields(surface, us, vs, 3 if fairness else 2)
    return curvature_from_derivatives(D, sign=sign, fairness=fairness, size=surface.size())


def span_parameters(knots: np.ndarray, degree: int, per_span: int) -> np.ndarray:
    """``per_span`` uniform intervals in every non-empty knot span of the domain, ends
    included (``per_span * spans + 1`` parameters): the tessellation of the review maps."""
    a, b = knots[degree], knots[-degree - 1]
    br = np.unique(knots[(knots >= a) & (knots <= b)])
    per_span = max(int(per_span), 1)
    t = np.linspace(0.0, 1.0, per_span + 1)[:-1]
    out = (br[:-1, None] + np.diff(br)[:, None] * t).ravel()
    return np.append(out, b)


def _gauss_nodes(knots: np.ndarray, degree: int, count: int):
    x, w = np.polynomial.legendre.leggauss(count)
    a, b = knots[degree], knots[-degree - 1]
    br = np.unique(knots[(knots >= a) & (knots <= b)])
    lo, h = br[:-1, None], np.diff(br)[:, None]
    return (lo + 0.5 * h * (x + 1.0)).ravel(), (0.5 * h * w).ravel()


@dataclass(frozen=True)
class FairnessIntegrals:
    """∫ MVS density dA (1/m²), ∫ (κ1² + κ2²) dA (dimensionless) and the area (m²)."""

    mvs: float
    strain_energy: float
    area: float


def fairness_integrals(surface: BSplineSurface, quadrature_points: int = DEFAULT_QUADRATURE_POINTS) -> FairnessIntegrals:
    """Total MVS and strain energy (Hosseini 2016 Eq. 6) by Gauss–Legendre quadrature with
    ``quadrature_points`` nodes per knot span and direction, dA = |S_u × S_v| du dv. The
    nodes form a tensor grid, so the derivatives come from :func:`grid_derivatives`."""
    _require_3d_surface(surface)
    g = int(quadrature_points)
    if g < 1:
        raise GeometryError(f"quadrature_points must be >= 1, got {quadrature_points!r}")
    us, wu = _gauss_nodes(surface.knots_u, surface.degree_u, g)
    vs, wv = _gauss_nodes(surface.knots_v, surface.degree_v, g)
    c = surface_curvature_grid(surface, us, vs, fairness=True)
    W = wu[:, None] * wv[None, :] * c.area_element
    return FairnessIntegrals(
        mvs=float(np.sum(W * c.mvs_density)),
        strain_energy=float(np.sum(W * c.strain_energy_density)),
        area=float(W.sum()),
    )


# ---------------------------------------------------------------------------------------
# isoparametric lines
# ---------------------------------------------------------------------------------------
def iso_line_parameters(surface: BSplineSurface, direction: str, per_span: int = ISO_SAMPLES_PER_SPAN) -> np.ndarray:
    """Sample parameters along an iso line: u = const lines run in v (``direction='u'``)."""
    if direction == "u":
        return span_parameters(surface.knots_v, surface.degree_v, per_span)
    if direction == "v":
        return span_parameters(surface.knots_u, surface.degree_u, per_span)
    raise GeometryError(f"direction must be 'u' or 'v', got {direction!r}")


def iso_line_normal_curvature(surface: BSplineSurface, direction: str, values, *, sign: float = 1.0,
                              per_span: int = ISO_SAMPLES_PER_SPAN) -> tuple[np.ndarray, np.ndarray]:
    """Normal curvature of the surface along its iso lines (1/m): for u = const lines
    (``direction='u'``) κ_n = N/G, for v = const lines κ_n = L/E (do Carmo §3.2: II/I in
    the line's direction); its sign changes are the surface's inflections along the line.
    Returns (line parameters t (n,), κ_n (len(values), n))."""
    _require_3d_surface(surface)
    values = np.atleast_1d(np.asarray(values, dtype=np.float64))
    t = iso_line_parameters(surface, direction, per_span)
    if direction == "u":
        D = grid_derivative_fields(surface, values, t, 2)
    else:
        D = {key: value.swapaxes(1, 2) for key, value in grid_derivative_fields(surface, t, values, 2).items()}
    c = curvature_from_derivatives(D, sign=sign, size=surface.size())
    E, _, G = c.first_form
    L, _, N = c.second_form
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = np.where(c.degenerate, 0.0, (N / G) if direction == "u" else (L / E))
    return t, kappa


def iso_line_sign_changes(surface: BSplineSurface, direction: str, values, *, per_span: int = ISO_SAMPLES_PER_SPAN,
                          zero_fraction: float = CURVATURE_ZERO_FRACTION) -> np.ndarray:
    """Number of sign changes of the normal curvature along each iso line (int array), by
    :func:`~..propeller.cut_smoothing.curvature_sign_changes` (values below
    ``zero_fraction`` of the line's largest |κ| carry no sign)."""
    _, kappa = iso_line_normal_curvature(surface, direction, values, per_span=per_span)
    return np.array([curvature_sign_changes(k, zero_fraction) for k in kappa], dtype=int)


def extra_sign_changes(counts) -> np.ndarray:
    """Sign changes beyond the family's baseline: the median count over the lines of one
    family (rounded down) is what the shape itself has (e.g. a cambered section's
    inflection); a line with more has extra ones — a bump or a ragged stretch."""
    c = np.asarray(counts, dtype=int)
    if c.size == 0:
        return c
    baseline = int(np.floor(np.median(c)))
    return np.maximum(c - baseline, 0)


# ---------------------------------------------------------------------------------------
# curves: signed curvature and combs
# ---------------------------------------------------------------------------------------
def plane_normal(points, tol: float = PLANARITY_TOL) -> np.ndarray | None:
    """Unit normal of the best-fit plane of (n, 3) points when they lie in it within
    ``tol`` times their size, else None. The normal's orientation is made deterministic
    (largest component positive)."""
    P = np.asarray(points, dtype=np.float64)
    size = float(np.linalg.norm(P.max(axis=0) - P.min(axis=0)))
    if P.shape[0] < 3 or size == 0.0:
        return None
    Q = P - P.mean(axis=0)
    _, s, Vt = np.linalg.svd(Q, full_matrices=False)
    if s[1] <= tol * size:  # collinear: no plane
        return None
    m = Vt[2]
    if np.max(np.abs(Q @ m)) > tol * size:
        return None
    return m if m[np.argmax(np.abs(m))] > 0 else -m


def curvature_vector(first, second) -> np.ndarray:
    """κ N = (C'' - (C''·T)T)/|C'|², pointing to the centre of curvature (any dimension)."""
    first, second = np.asarray(first, float), np.asarray(second, float)
    speed2 = _dot(first, first)
    tangential = (_dot(second, first) / speed2)[..., None] * first
    return (second - tangential) / speed2[..., None]


@dataclass(frozen=True, eq=False)
class CurvatureComb:
    """A curvature comb (porcupine plot): ``points`` (n, 3) on the curve at ``parameters``,
    signed ``curvature`` (n,) (1/m) against ``reference`` (n, 3) unit vectors, ``teeth``
    (n, 3) the tooth ends points - sign·scale·κ·reference, and ``scale`` (m per 1/m).
    The envelope is the polyline through the tooth ends. With sign = +1 (the CAD
    convention) teeth stand on the convex side, away from the centre of curvature."""

    parameters: np.ndarray
    points: np.ndarray
    curvature: np.ndarray
    reference: np.ndarray
    teeth: np.ndarray
    scale: float
    sign: float

    @property
    def envelope(self) -> np.ndarray:
        return self.teeth

    def sign_changes(self, zero_fraction: float = CURVATURE_ZERO_FRACTION) -> int:
        return curvature_sign_changes(self.curvature, zero_fraction)


def comb_scale(curvatures, size: float, fraction: float = DEFAULT_COMB_FRACTION,
               percentile: float = DEFAULT_PERCENTILE) -> float:
    """Scale (m per 1/m) making the ``percentile`` tooth ``fraction`` of ``size`` long, so
    combs of several curves drawn with one scale compare directly."""
    k = np.abs(np.concatenate([np.ravel(c) for c in curvatures])) if len(curvatures) else np.zeros(1)
    k = k[np.isfinite(k)]
    top = float(np.percentile(k, percentile)) if k.size else 0.0
    return fraction * size / top if top > 0 else 0.0


def _arclength_parameters(curve: BSplineCurve, count: int) -> np.ndarray:
    a, b = curve.domain
    dense = np.linspace(a, b, 8 * count + 1)
    P = curve.evaluate(dense)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
    if s[-1] == 0.0:
        return np.linspace(a, b, count)
    return np.interp(np.linspace(0.0, s[-1], count), s, dense)


def curve_curvature(curve: BSplineCurve, t, *, normal="auto", surface: BSplineSurface | None = None,
                    surface_parameters=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Signed curvature (1/m) of a 2-D or 3-D curve at t with its reference directions.

    - ``surface`` and ``surface_parameters`` ((u, v) arrays at t): the normal curvature
      κ_n = κN·n against the surface normal n (Meusnier), for lines on a surface;
    - else a plane normal m (given, or found when ``normal='auto'`` and the curve is
      planar): κ = κN·(m × T), signed in the plane (section cuts, Hvid curves);
    - else the unsigned curvature |κN| along the principal normal N.
    Returns (points (n, 3), κ (n,), reference unit vectors (n, 3))."""
    if not isinstance(curve, BSplineCurve):
        raise GeometryError(f"expected a BSplineCurve, got {type(curve).__name__}")
    if curve.dim not in (2, 3):
        raise GeometryError(f"combs need a 2-D or 3-D curve, got dimension {curve.dim}")
    t = np.asarray(t, dtype=np.float64)
    D = curve.derivatives(t, 2)
    if curve.dim == 2:
        D = np.concatenate([D, np.zeros(D.shape[:-1] + (1,))], axis=-1)
        if isinstance(normal, str):
            normal = np.array([0.0, 0.0, 1.0])
    C, d1, d2 = D[..., 0, :], D[..., 1, :], D[..., 2, :]
    kvec = curvature_vector(d1, d2)
    if surface is not None:
        u, v = surface_parameters
        ref = surface.normal(u, v)
    else:
        if isinstance(normal, str):
            if normal != "auto":
                raise GeometryError(f"normal must be 'auto', None or a vector, got {normal!r}")
            a, b = curve.domain
            normal = plane_normal(curve.evaluate(np.linspace(a, b, 64)))
        if normal is not None:
            m = np.asarray(normal, dtype=np.float64)
            m = m / np.linalg.norm(m)
            T = d1 / np.linalg.norm(d1, axis=-1, keepdims=True)
            ref = np.cross(m, T)
        else:
            length = np.linalg.norm(kvec, axis=-1, keepdims=True)
            ref = np.where(length > 0, kvec / np.where(length > 0, length, 1.0), 0.0)
    return C, _dot(kvec, ref), ref


def curvature_comb(curve: BSplineCurve, count: int = 100, *, scale: float | None = None, sign: float = 1.0,
                   normal="auto", surface: BSplineSurface | None = None, surface_parameters=None,
                   fraction: float = DEFAULT_COMB_FRACTION) -> CurvatureComb:
    """A curvature comb of ``count`` teeth spaced uniformly in arc length (``density``).
    ``scale``: tooth length per unit curvature (m per 1/m), None for automatic
    (:func:`comb_scale` with ``fraction`` of the curve's size). ``sign``: +1 teeth on the
    convex side (CAD convention), -1 towards the centre of curvature. ``normal``,
    ``surface``: see :func:`curve_curvature`; for lines on a surface pass
    ``surface_parameters`` as a callable t -> (u, v)."""
    count = int(count)
    if count < 2:
        raise GeometryError(f"a comb needs at least 2 teeth, got {count}")
    t = _arclength_parameters(curve, count)
    uv = surface_parameters(t) if callable(surface_parameters) else surface_parameters
    C, kappa, ref = curve_curvature(curve, t, normal=normal, surface=surface, surface_parameters=uv)
    if scale is None:
        scale = comb_scale([kappa], curve.size(), fraction)
    s = 1.0 if sign >= 0 else -1.0
    teeth = C - (s * float(scale) * kappa)[:, None] * ref
    return CurvatureComb(t, C, kappa, ref, teeth, float(scale), s)


def iso_line_comb(surface: BSplineSurface, direction: str, value: float, count: int = 100, **kwargs) -> CurvatureComb:
    """Comb of the normal curvature along the iso line u = value (``direction='u'``) or
    v = value, with the surface normal as reference (inflections of the surface show as
    the comb crossing the line)."""
    curve = surface.iso_curve(direction, value)
    if direction == "u":
        params = lambda t: (np.full_like(t, value), t)  # noqa: E731
    else:
        params = lambda t: (t, np.full_like(t, value))  # noqa: E731
    return curvature_comb(curve, count, surface=surface, surface_parameters=params, **kwargs)


# ---------------------------------------------------------------------------------------
# colour maps and limits
# ---------------------------------------------------------------------------------------
def symmetric_limits(values, percentile: float = DEFAULT_PERCENTILE, weights=None) -> tuple[float, float]:
    """(-c, c) with c the ``percentile`` of |values| (robust clipping: a few huge values at
    tips and edges do not wash out the rest). ``weights`` (same shapes as values, e.g. the
    area each map vertex stands for) make it an area percentile, so that narrow edge
    surfaces densely sampled do not dominate. 100 gives the full range. Never zero."""
    flat = lambda x: np.concatenate([np.ravel(a) for a in x]) if isinstance(x, (list, tuple)) else np.ravel(x)  # noqa: E731
    v = np.abs(flat(values)).astype(np.float64)
    w = np.ones_like(v) if weights is None else np.asarray(flat(weights), dtype=np.float64)
    if w.shape != v.shape:
        raise GeometryError(f"weights: expected {v.shape[0]} values, got {w.shape[0]}")
    if not 0.0 < percentile <= 100.0:
        raise GeometryError(f"percentile must be in (0, 100], got {percentile!r}")
    ok = np.isfinite(v) & np.isfinite(w) & (w > 0)
    v, w = v[ok], w[ok]
    if v.size == 0:
        return -1.0, 1.0
    if weights is None:
        c = float(np.percentile(v, percentile))
    else:
        order = np.argsort(v)
        cw = np.cumsum(w[order])
        c = float(v[order][min(np.searchsorted(cw, percentile / 100.0 * cw[-1]), v.size - 1)])
    if c <= 0.0:
        c = float(v.max()) if v.max() > 0 else 1.0
    return -c, c


def diverging_colours(values, limits: tuple[float, float]) -> np.ndarray:
    """sRGB RGBA (n..., 4) in 0..1 of ``values`` on :data:`DIVERGING_CONTROL_COLOURS`,
    with limits[0] -> the blue end, limits[1] -> the orange end, the middle -> white;
    values outside the limits are clipped to the end colours."""
    lo, hi = float(limits[0]), float(limits[1])
    if not hi > lo:
        raise GeometryError(f"colour limits must increase, got {limits!r}")
    x = np.asarray(values, dtype=np.float64)
    s = np.clip(2.0 * (x - lo) / (hi - lo) - 1.0, -1.0, 1.0)
    s = np.where(np.isfinite(s), s, 0.0)
    stops = np.linspace(-1.0, 1.0, len(DIVERGING_CONTROL_COLOURS))
    out = np.ones(x.shape + (4,))
    for c in range(3):
        out[..., c] = np.interp(s, stops, DIVERGING_CONTROL_COLOURS[:, c])
    return out


def clipped_fraction(values, limits) -> float:
    """Fraction of finite values outside the limits."""
    v = np.ravel(np.asarray(values, dtype=np.float64))
    v = v[np.isfinite(v)]
    return float(np.mean((v < limits[0]) | (v > limits[1]))) if v.size else 0.0


# ---------------------------------------------------------------------------------------
# comparison
# ---------------------------------------------------------------------------------------
#: Tessellation intervals per knot span of the start points of :func:`signed_deviation`.
DEVIATION_SEED_SAMPLES = 6
#: Nearest tessellation points looked at per point (other branches near seams and tips).
DEVIATION_SEED_NEIGHBOURS = 4
#: Newton of the deviation map: zero-cosine tolerance and iteration cap. The distance
#: error left by a cosine c is about c² d (1e-10 d at 1e-5), far below the map's
#: resolution; a tighter tolerance only adds iterations.
DEVIATION_COSINE_TOL = 1e-5
DEVIATION_ITERATIONS = 25
#: Index distance (tessellation intervals) beyond which a neighbour is on another branch.
DEVIATION_BRANCH_GAP = 2
#: Relative slack when comparing a Newton distance with a tessellation point's distance.
DEVIATION_COMPARE_SLACK = 1e-9
#: signed_deviation_grid: every this many rows and columns are projected in full.
DEVIATION_GRID_STRIDE = 4
#: Gauss–Newton has converged when the residual's tangential part t is below this
#: fraction of the surface's size; the residual's normal part is then the distance to
#: within about κ t² / 2 (1e-13 m for a 0.3 m blade with a 0.1 mm edge radius).
DEVIATION_TANGENT_FRACTION = 1e-8
#: Gauss–Newton steps from a tessellation start, and from a blended start in a grid.
DEVIATION_GN_ITERATIONS = 6
DEVIATION_GRID_GN_ITERATIONS = 3


class DeviationSeeds:
    """Start points of :func:`signed_deviation` on ``surface``: its tessellation
    (``samples_per_span`` intervals per knot span each way) in a KD-tree. Build it once
    per reference surface and pass it to every call against that surface."""

    def __init__(self, surface: BSplineSurface, samples_per_span: int | None = None):
        from scipy.spatial import cKDTree

        per = DEVIATION_SEED_SAMPLES if samples_per_span is None else int(samples_per_span)
        self.surface = surface
        self.us = span_parameters(surface.knots_u, surface.degree_u, per)
        self.vs = span_parameters(surface.knots_v, surface.degree_v, per)
        grid = surface.evaluate_grid(self.us, self.vs)
        # reach of each tessellation point: the diagonal of its largest adjacent cell
        # (every surface point of the cells around it lies within this distance)
        eu = np.linalg.norm(np.diff(grid, axis=0), axis=-1)
        ev = np.linalg.norm(np.diff(grid, axis=1), axis=-1)
        eu = np.maximum(np.pad(eu, ((1, 0), (0, 0))), np.pad(eu, ((0, 1), (0, 0))))
        ev = np.maximum(np.pad(ev, ((0, 0), (1, 0))), np.pad(ev, ((0, 0), (0, 1))))
        self.reach = np.hypot(eu, ev).ravel()
        self.tree = cKDTree(grid.reshape(-1, surface.dim))

    def query(self, flat: np.ndarray):
        """(distances (n, k), reach (n, k), u index (n, k), v index (n, k)) of the k
        nearest tessellation points."""
        k = min(DEVIATION_SEED_NEIGHBOURS, self.us.size * self.vs.size)
        dist, idx = self.tree.query(flat, k=k)
        dist, idx = dist.reshape(flat.shape[0], -1), idx.reshape(flat.shape[0], -1)
        return dist, self.reach[idx], idx // self.vs.size, idx % self.vs.size


def _gauss_newton(surface: BSplineSurface, X: np.ndarray, u, v, iterations: int):
    """Gauss–Newton on S(u, v) ≈ X from (u, v) (first derivatives only; converges fast
    for points near the surface, where the neglected term r · S_uu is small): at most
    ``iterations`` steps. Returns (u, v, signed normal part of the residual, converged):
    a point has converged when the residual's tangential part is below
    DEVIATION_TANGENT_FRACTION of the surface's size, and its normal part is then the
    signed distance to within κ t²."""
    u, v = np.array(u, dtype=np.float64), np.array(v, dtype=np.float64)
    (ua, ub), (va, vb) = surface.domain_u, surface.domain_v
    tol = DEVIATION_TANGENT_FRACTION * surface.size()
    dn = np.zeros(u.shape)
    converged = np.zeros(u.shape, dtype=bool)
    active = np.arange(u.size)
    for step in range(iterations + 1):
        D = surface.derivatives(u[active], v[active], 1)
        r = X[active] - D[:, 0, 0]
        Su, Sv = D[:, 1, 0], D[:, 0, 1]
        normal = np.cross(Su, Sv)
        nn = np.linalg.norm(normal, axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            d = _dot(r, normal) / nn
        tangential = np.sqrt(np.maximum(_dot(r, r) - d**2, 0.0))
        ok = (nn > 0) & np.isfinite(d) & (tangential <= tol)
        dn[active[ok]] = d[ok]
        converged[active[ok]] = True
        if step == iterations or np.all(ok):
            break
        go = ~ok
        Su, Sv, r = Su[go], Sv[go], r[go]
        g11, g12, g22 = _dot(Su, Su), _dot(Su, Sv), _dot(Sv, Sv)
        f1, f2 = _dot(Su, r), _dot(Sv, r)
        det = g11 * g22 - g12**2
        with np.errstate(divide="ignore", invalid="ignore"):
            du = np.where(det > 0, (f1 * g22 - f2 * g12) / det, 0.0)
            dv = np.where(det > 0, (f2 * g11 - f1 * g12) / det, 0.0)
        active = active[go]
        u[active] = np.clip(u[active] + np.nan_to_num(du), ua, ub)
        v[active] = np.clip(v[active] + np.nan_to_num(dv), va, vb)
    return u, v, dn, converged


def _project_from(surface: BSplineSurface, X: np.ndarray, u, v, cos_tol: float, iterations: int):
    """Closest points of X from the starts (u, v): Gauss–Newton, then the safeguarded
    Newton of :func:`~..nurbs.projection.refine_closest_points` for the points it leaves
    (far points, boundaries). Returns (u, v, signed distance)."""
    from ..nurbs.projection import refine_closest_points

    u, v, dn, ok = _gauss_newton(surface, X, u, v, iterations)
    rest = np.flatnonzero(~ok)
    if rest.size:
        # from the better of the start and where Gauss–Newton ended (it does not search)
        u2, v2, d2 = refine_closest_points(surface, X[rest], u[rest], v[rest], cos_tol=cos_tol,
                                           max_iterations=DEVIATION_ITERATIONS)
        u[rest], v[rest] = u2, v2
        dn[rest] = _signed(X[rest], surface, u2, v2, d2)
    return u, v, dn


def _closest(flat: np.ndarray, surface: BSplineSurface, seeds: "DeviationSeeds", restarts: str, cos_tol: float):
    """Closest points of ``flat`` (n, 3) on ``surface`` by the vectorised projection of
    :func:`signed_deviation`: (u, v, signed distance), each (n,)."""
    if restarts not in ("suspect", "all"):
        raise GeometryError(f"restarts must be 'suspect' or 'all', got {restarts!r}")
    us, vs = seeds.us, seeds.vs
    dk, reach, iu, iv = seeds.query(flat)
    u, v, sd = _project_from(surface, flat, us[iu[:, 0]], vs[iv[:, 0]], cos_tol, DEVIATION_GN_ITERATIONS)
    (ua, ub), (va, vb) = surface.domain_u, surface.domain_v
    tried = [0]
    for k in range(1, iu.shape[1]):
        other = np.ones(flat.shape[0], dtype=bool)
        for j in tried:  # a branch not started from yet
            other &= (np.abs(iu[:, k] - iu[:, j]) > DEVIATION_BRANCH_GAP) | (
                np.abs(iv[:, k] - iv[:, j]) > DEVIATION_BRANCH_GAP)
        tried.append(k)
        if restarts == "suspect":
            # held on the domain's boundary, or the cells around neighbour k may hold a
            # nearer point than the one found
            held = (u <= ua) | (u >= ub) | (v <= va) | (v >= vb)
            other &= held | (dk[:, k] - reach[:, k] < np.abs(sd) * (1.0 - DEVIATION_COMPARE_SLACK))
        if not np.any(other):
            continue
        sel = np.flatnonzero(other)
        u2, v2, s2 = _project_from(surface, flat[sel], us[iu[sel, k]], vs[iv[sel, k]], cos_tol,
                                   DEVIATION_GN_ITERATIONS)
        better = np.abs(s2) < np.abs(sd[sel])
        u[sel[better]], v[sel[better]], sd[sel[better]] = u2[better], v2[better], s2[better]
    return u, v, sd


def _signed(P, surface, u, v, d):
    """d with the sign of (P - S(u, v)) · n (positive where the normal is undefined)."""
    Q = surface.evaluate(u, v)
    with np.errstate(divide="ignore", invalid="ignore"):  # a collapsed edge has no normal
        side = np.sign(_dot(P - Q, surface.normal(u, v)))
    return d * np.where((side == 0) | ~np.isfinite(side), 1.0, side)


def signed_deviation(points, surface: BSplineSurface, samples_per_span: int | None = None, *,
                     seeds: "DeviationSeeds | None" = None, restarts: str = "suspect",
                     cos_tol: float = DEVIATION_COSINE_TOL, **closest_kwargs) -> np.ndarray:
    """Signed distance (m) of points (S + (3,)) from ``surface``: the closest-point
    distance, positive on the side S_u × S_v points to.

    Vectorised projection: every point starts from the nearest point of a tessellation
    of the surface (:class:`DeviationSeeds`, ``samples_per_span`` intervals per knot span
    each way, default DEVIATION_SEED_SAMPLES; a KD-tree query), takes Gauss–Newton steps
    (first derivatives) until the residual is normal to the surface to
    DEVIATION_TANGENT_FRACTION of its size, and, where that does not converge, the
    safeguarded Newton iteration of :func:`~..nurbs.projection.refine_closest_points`
    (zero-cosine tolerance ``cos_tol``). Next to a seam or a collapsed edge (a closed
    trailing edge, a tip) or a thin part, the nearest tessellation points lie on
    separate branches of the parameter domain; a point is started again from such a
    neighbour (once per branch), keeping the nearer result, when ``restarts="all"``, or
    (the default, ``"suspect"``) only when its result is suspect: held on a boundary of
    the domain, or farther than the neighbour's distance less its reach (the diagonal of
    its largest tessellation cell: the cells around it may hold a nearer point). The
    review compares points that lie close to the reference (a smoothed blade and its
    unsmoothed one), for which the nearest tessellation point is in the basin of the
    closest point; with ``closest_kwargs`` the general
    :func:`~..nurbs.projection.closest_point_surface` (its adaptive start grid and
    several starts per point) is used instead. For a grid of points (a review map) see
    :func:`signed_deviation_grid`."""
    from ..nurbs.projection import closest_point_surface

    P = np.asarray(points, dtype=np.float64)
    if closest_kwargs:
        u, v, d = closest_point_surface(surface, P, **closest_kwargs)
        return _signed(P, surface, u, v, d)
    if seeds is None:
        seeds = DeviationSeeds(surface, samples_per_span)
    elif seeds.surface is not surface:
        raise GeometryError("the seeds were built for another surface")
    flat = P.reshape(-1, P.shape[-1])
    _, _, sd = _closest(flat, surface, seeds, restarts, cos_tol)
    return sd.reshape(P.shape[:-1])


def signed_deviation_grid(points, surface: BSplineSurface, seeds: "DeviationSeeds | None" = None, *,
                          stride: int = DEVIATION_GRID_STRIDE, cos_tol: float = DEVIATION_COSINE_TOL) -> np.ndarray:
    """:func:`signed_deviation` of a grid of points (nu, nv, 3), such as a review map's
    (one value per map vertex), from coarse to fine: the points of every ``stride``-th
    row and column (and the last) are projected as :func:`signed_deviation` does; inside
    each cell of that coarse grid whose four corners found their closest points on one
    branch (parameters within DEVIATION_BRANCH_GAP tessellation intervals, none on the
    domain's boundary) the other points start from the bilinear blend of the corners'
    parameters (the closest-point map is smooth there) and take Gauss–Newton steps (at
    most DEVIATION_GRID_GN_ITERATIONS; usually one), then Newton if they have not
    converged; the points of the other cells are projected like the corners. Same
    result as :func:`signed_deviation` to the tolerances, at a fraction of the cost."""
    P = np.asarray(points, dtype=np.float64)
    if P.ndim != 3 or P.shape[-1] != surface.dim:
        raise GeometryError(f"expected a grid of points (nu, nv, {surface.dim}), got shape {P.shape}")
    if seeds is None:
        seeds = DeviationSeeds(surface)
    elif seeds.surface is not surface:
        raise GeometryError("the seeds were built for another surface")
    nu, nv = P.shape[:2]
    stride = max(int(stride), 1)
    ci = np.unique(np.r_[np.arange(0, nu, stride), nu - 1])
    cj = np.unique(np.r_[np.arange(0, nv, stride), nv - 1])
    C = P[np.ix_(ci, cj)].reshape(-1, P.shape[-1])
    cu, cv, _ = _closest(C, surface, seeds, "suspect", cos_tol)
    cu, cv = cu.reshape(ci.size, cj.size), cv.reshape(ci.size, cj.size)
    # the coarse cell of every point and its place in it
    a = np.clip(np.searchsorted(ci, np.arange(nu), side="right") - 1, 0, max(ci.size - 2, 0))
    b = np.clip(np.searchsorted(cj, np.arange(nv), side="right") - 1, 0, max(cj.size - 2, 0))
    a1, b1 = np.minimum(a + 1, ci.size - 1), np.minimum(b + 1, cj.size - 1)
    su = np.where(ci[a1] > ci[a], (np.arange(nu) - ci[a]) / np.maximum(ci[a1] - ci[a], 1), 0.0)
    sv = np.where(cj[b1] > cj[b], (np.arange(nv) - cj[b]) / np.maximum(cj[b1] - cj[b], 1), 0.0)
    A, B = np.meshgrid(a, b, indexing="ij")
    A1, B1 = np.meshgrid(a1, b1, indexing="ij")
    SU, SV = np.meshgrid(su, sv, indexing="ij")
    corners_u = np.stack([cu[A, B], cu[A1, B], cu[A, B1], cu[A1, B1]])
    corners_v = np.stack([cv[A, B], cv[A1, B], cv[A, B1], cv[A1, B1]])
    (ua, ub), (va, vb) = surface.domain_u, surface.domain_v
    gap_u = DEVIATION_BRANCH_GAP * float(np.max(np.diff(seeds.us)))
    gap_v = DEVIATION_BRANCH_GAP * float(np.max(np.diff(seeds.vs)))
    smooth = ((np.ptp(corners_u, axis=0) <= gap_u) & (np.ptp(corners_v, axis=0) <= gap_v)
              & np.all((corners_u > ua) & (corners_u < ub) & (corners_v > va) & (corners_v < vb), axis=0))
    w = np.stack([(1 - SU) * (1 - SV), SU * (1 - SV), (1 - SU) * SV, SU * SV])
    u0, v0 = np.sum(w * corners_u, axis=0).ravel(), np.sum(w * corners_v, axis=0).ravel()
    flat = P.reshape(-1, P.shape[-1])
    out = np.empty(nu * nv)
    fine = np.flatnonzero(smooth.ravel())
    if fine.size:
        _, _, out[fine] = _project_from(surface, flat[fine], u0[fine], v0[fine], cos_tol,
                                        DEVIATION_GRID_GN_ITERATIONS)
    rest = np.flatnonzero(~smooth.ravel())
    if rest.size:
        _, _, out[rest] = _closest(flat[rest], surface, seeds, "suspect", cos_tol)
    return out.reshape(nu, nv)
