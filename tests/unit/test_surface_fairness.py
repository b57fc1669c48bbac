"""MVS and strain energy (Hosseini 2016 Eq. 6) against closed forms on exact rational
patches: a cylinder (κ1 = 1/R, κ2 = 0), a sphere zone (κ1 = κ2 = 1/R) and an elliptic
cylinder, whose MVS is H ∫ (dκ/ds)² ds along the ellipse."""
import numpy as np
import pytest
from scipy.integrate import quad

from bladesmith.geometry.errors import GeometryError
from bladesmith.geometry.fairing.surface_fairness import principal_curvatures, surface_fairness
from bladesmith.geometry.nurbs import BSplineSurface

#: Relative accuracy of the quadrature against the closed forms.
REL_TOL = 1e-8
QUAD_KNOTS = np.array([0, 0, 0, 1, 1, 1.0])
LIN_KNOTS = np.array([0, 0, 1, 1.0])


def arc(theta0, theta1, R=1.0):
    """Rational quadratic circular arc (NURBS Book Eq. 7.x): points (3, 2), weights (3,)."""
    half = 0.5 * (theta1 - theta0)
    mid = 0.5 * (theta0 + theta1)
    P = np.array([[np.cos(theta0), np.sin(theta0)], [np.cos(mid) / np.cos(half), np.sin(mid) / np.cos(half)],
                  [np.cos(theta1), np.sin(theta1)]]) * R
    return P, np.array([1.0, np.cos(half), 1.0])


def extruded(P2, w, H):
    net = np.zeros((3, 2, 3))
    net[:, :, :2] = P2[:, None, :]
    net[:, 1, 2] = H
    return BSplineSurface(2, 1, QUAD_KNOTS, LIN_KNOTS, net, np.repeat(w[:, None], 2, axis=1))


def test_cylinder():
    R, H = 2.0, 3.0
    s = extruded(*arc(0, np.pi / 2, R), H)
    f = surface_fairness(s)
    area = np.pi / 2 * R * H
    assert f.area == pytest.approx(area, rel=REL_TOL)
    assert f.strain_energy == pytest.approx(area / R**2, rel=REL_TOL)
    assert f.mvs == pytest.approx(0.0, abs=1e-20)


def test_sphere_zone():
    R = 1.5
    Pm, wm = arc(0.0, np.pi / 4, R)  # meridian (r, z)
    Pl, wl = arc(0.0, np.pi / 2, 1.0)  # longitude
    net = np.zeros((3, 3, 3))
    net[..., 0] = Pm[:, 0, None] * Pl[None, :, 0]
    net[..., 1] = Pm[:, 0, None] * Pl[None, :, 1]
    net[..., 2] = Pm[:, 1, None]
    s = BSplineSurface(2, 2, QUAD_KNOTS, QUAD_KNOTS, net, wm[:, None] * wl[None, :])
    f = surface_fairness(s, 8)
    area = R**2 * np.pi / 2 * np.sin(np.pi / 4)
    assert f.area == pytest.approx(area, rel=REL_TOL)
    assert f.strain_energy == pytest.approx(2 * area / R**2, rel=REL_TOL)
    assert f.mvs == pytest.approx(0.0, abs=1e-16)
    c = principal_curvatures(s, np.array([0.3]), np.array([0.6]))
    assert abs(c["k1"][0]) == pytest.approx(1 / R, rel=1e-12) and abs(c["k2"][0]) == pytest.approx(1 / R, rel=1e-12)


def test_elliptic_cylinder_mvs():
    a, b, H = 2.0, 1.0, 0.5
    P = np.array([[a, 0.0], [a, b], [0.0, b]])
    s = extruded(P, np.array([1.0, np.sqrt(0.5), 1.0]), H)

    def speed(t):
        return np.sqrt(a**2 * np.sin(t) ** 2 + b**2 * np.cos(t) ** 2)

    def dk_dt(t):
        return -1.5 * a * b * speed(t) ** -5 * 2 * (a**2 - b**2) * np.sin(t) * np.cos(t)

    mvs = H * quad(lambda t: dk_dt(t) ** 2 / speed(t), 0, np.pi / 2, epsabs=1e-14, epsrel=1e-13)[0]
    se = H * quad(lambda t: (a * b / speed(t) ** 3) ** 2 * speed(t), 0, np.pi / 2, epsabs=1e-14, epsrel=1e-13)[0]
    f = surface_fairness(s, 40)
    assert f.mvs == pytest.approx(mvs, rel=1e-6)
    assert f.strain_energy == pytest.approx(se, rel=1e-8)
    # unit principal directions: the curved one along the ellipse, the flat one along z
    c = principal_curvatures(s, np.array([0.37]), np.array([0.5]))
    curved = "1" if abs(c["k1"][0]) > abs(c["k2"][0]) else "2"
    flat = "2" if curved == "1" else "1"
    assert np.linalg.norm(c["e" + curved][0]) == pytest.approx(1.0, rel=1e-12)
    assert abs(c["e" + curved][0][2]) < 1e-12
    assert abs(abs(c["e" + flat][0][2]) - 1.0) < 1e-12


def test_refuses_non_surfaces():
    with pytest.raises(GeometryError):
        surface_fairness("not a surface")


def test_curve_fairness_matches_its_surface_and_closed_forms():
    """The curve forms of Eq. 6 on the rational quarter ellipse: H × the curve's values
    equal the extruded surface's MVS and strain energy, and both match quadrature of
    the closed forms; a 3-D copy of the curve gives the same numbers."""
    from bladesmith.geometry.fairing.surface_fairness import curve_fairness
    from bladesmith.geometry.nurbs import BSplineCurve

    a, b, H = 2.0, 1.0, 0.5
    P = np.array([[a, 0.0], [a, b], [0.0, b]])
    w = np.array([1.0, np.sqrt(0.5), 1.0])
    c2 = BSplineCurve(degree=2, knots=QUAD_KNOTS, control_points=P, weights=w)
    f = curve_fairness(c2, 40)
    s = surface_fairness(extruded(P, w, H), 40)
    assert H * f.curvature_variation == pytest.approx(s.mvs, rel=1e-10)
    assert H * f.bending_energy == pytest.approx(s.strain_energy, rel=1e-10)
    assert f.length * H == pytest.approx(s.area, rel=1e-12)
    c3 = BSplineCurve(degree=2, knots=QUAD_KNOTS, control_points=np.column_stack([P, np.zeros(3)]), weights=w)
    g = curve_fairness(c3, 40)
    assert g.curvature_variation == pytest.approx(f.curvature_variation, rel=1e-12)
    # circle: κ = 1/R, dκ/ds = 0
    R = 3.0
    Pc, wc = arc(0.0, np.pi / 2, R)
    c = curve_fairness(BSplineCurve(degree=2, knots=QUAD_KNOTS, control_points=Pc, weights=wc), 10)
    assert c.bending_energy == pytest.approx(np.pi / 2 * R / R**2, rel=1e-12)
    assert c.curvature_variation < 1e-20
    # a straight segment: both zero, no division by zero
    line = curve_fairness(BSplineCurve(degree=1, knots=LIN_KNOTS, control_points=np.array([[0.0, 0.0], [1.0, 2.0]])))
    assert line.bending_energy == 0.0 and line.curvature_variation == 0.0
    with pytest.raises(GeometryError):
        curve_fairness("not a curve")


def test_grid_fairness_matches_the_per_point_principal_curvatures():
    """surface_fairness (tensor grid, closed-form 2x2 pencil) against the same quadrature
    of the per-point principal_curvatures (LAPACK Cholesky and eigh): an independent
    route to Eq. 6 on a wavy non-uniform bicubic with no umbilics in the way."""
    from bladesmith.geometry.fairing.surface_fairness import _gauss_nodes

    rng = np.random.default_rng(3)
    n = 9
    knots = np.r_[[0.0] * 4, np.sort(rng.uniform(0.1, 0.9, n - 4)), [1.0] * 4]
    x, y = np.meshgrid(np.linspace(0, 2, n), np.linspace(0, 1.5, n), indexing="ij")
    z = 0.3 * np.sin(2.1 * x + 0.4) * np.cos(1.7 * y) + 0.2 * x * y
    s = BSplineSurface(3, 3, knots, knots, np.stack([x, y, z], -1))
    f = surface_fairness(s)
    us, wu = _gauss_nodes(s.knots_u, 6)
    vs, wv = _gauss_nodes(s.knots_v, 6)
    c = principal_curvatures(s, us[:, None], vs[None, :])
    W = wu[:, None] * wv[None, :] * c["dA"]
    assert f.area == pytest.approx(float(W.sum()), rel=1e-13)
    assert f.strain_energy == pytest.approx(float(np.sum(W * (c["k1"] ** 2 + c["k2"] ** 2))), rel=1e-11)
    assert f.mvs == pytest.approx(float(np.sum(W * (c["dk1_de1"] ** 2 + c["dk2_de2"] ** 2))), rel=1e-9)
