"""Blade surfaces B, S and P from camber-angle and thickness distributions (Casey 1983).

Casey (1983), "Blade Surfaces (B, S and P)", procedure a–g, and the Appendix (Eqs. A1–A5):

a. the blade lies in a meridional channel M (:mod:`.channel`);
b. it is placed by four channel parameters U: leading and trailing edge on hub and shroud;
c. the camber angle β(m) along hub and shroud is integrated along the channel walls,
   φ(m) = φ_LE + ∫ tan β / r dm;
d. a thickness δ(m) puts S and P at ±δ/2 either side of the camber surface B;
e. patch-corner points are spaced equidistantly in meridional distance m on each wall
   (the "projection of the blade surface onto the meridional channel") and the corner
   j on the hub is joined to corner j on the shroud by a straight line element;
f. each surface is a string of cubic-linear patches whose hub and shroud curves are C2
   cubic splines through the corner points with the blade angles imposed at LE and TE
   (A1–A5). We solve the end conditions directly: the tridiagonal system
   D_{j-1} + 4 D_j + D_{j+1} = 3 (x_{j+1} - x_{j-1}) with D_0, D_n prescribed (Eq. A5),
   then b_j = x_j + D_j/3, c_j = x_{j+1} - D_{j+1}/3 (Eq. A3/A4). This is the same spline
   as Casey's shooting on c_1 with linear extrapolation (:func:`casey_shooting`, kept for
   comparison) but stays well conditioned for many patches;
g. the end patches at LE and TE may be rounded (:func:`rounded_end_patch`).

Conventions. The axis is z; φ is the angle about +z (right-handed), x = r cos φ,
y = r sin φ (Casey's A5 measures φ the other way, which flips the sign of the φ terms).
β is measured from the meridional direction, positive towards +φ. δ is the thickness
normal to the camber line in the blade-to-blade surface: S and P are the camber surface
shifted by ∓δ / (2 r cos β) in φ at the same (z, r) (P on the +φ side, the side that
faces the rotation when the wheel turns towards +φ), so the corner points of all three
surfaces lie exactly on the channel walls.

Axial-element option (Casey 1983, item b after g): every straight line element is
parallel to the axis. The hub curve is built as above; the shroud curve has the hub
curve's x, y polygon and a z polygon from the C2 spline through the shroud contour's z at
the corner radii, so the elements are axial for every u, not only at the corners. The
shroud β and δ and the shroud LE/TE parameters are then not used.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import solve_banded
from scipy.optimize import brentq

from ..errors import DefinitionError, GeometryError
from .bezier import BezierCurve, BezierString, PatchString, RuledPatch, bernstein_function, bernstein_function_derivative
from .channel import MeridionalChannel

#: Gauss–Legendre points per quadrature interval and intervals per wall for m(U), φ(U).
QUADRATURE_POINTS = 6
QUADRATURE_INTERVALS = 48
#: Newton tolerance (in U) when inverting m(U).
INVERSE_TOLERANCE = 1e-13
#: Largest |β| accepted (deg): S and P need cos β > 0.
MAX_BETA_DEG = 85.0

_GL_X, _GL_W = np.polynomial.legendre.leggauss(QUADRATURE_POINTS)


# -- Appendix: C2 cubic strings with prescribed end slopes -------------------------------------
def cubic_string_through(points, start_derivative, end_derivative) -> BezierString:
    """The C2 cubic Bézier string through ``points`` (n+1, dim), each patch over a unit
    parameter interval, with dx/du prescribed at both ends (Casey 1983 Eqs. A1–A4, the end
    conditions solved directly; see the module docstring)."""
    X = np.asarray(points, dtype=float)
    n = X.shape[0] - 1
    if n < 1:
        raise GeometryError("a string needs at least two corner points")
    D = np.empty_like(X)
    D[0] = start_derivative
    D[-1] = end_derivative
    if n > 1:
        rhs = 3.0 * (X[2:] - X[:-2])
        rhs[0] -= D[0]
        rhs[-1] -= D[-1]
        ab = np.zeros((3, n - 1))
        ab[0, 1:] = 1.0
        ab[1, :] = 4.0
        ab[2, :-1] = 1.0
        D[1:-1] = solve_banded((1, 1), ab, rhs)
    segs = tuple(
        BezierCurve(np.array([X[j], X[j] + D[j] / 3.0, X[j + 1] - D[j + 1] / 3.0, X[j + 1]])) for j in range(n)
    )
    return BezierString(segs)


def casey_shooting(points, start_derivative, end_derivative) -> BezierString:
    """Casey's own procedure (Appendix): b_1 from Eq. A3, c_1 = 0 and c_1 = 1 marched
    through the recurrence A2 (d_j = a_{j+1} = x_{j+1}, b_{j+1} = 2 d_j - c_j,
    c_{j+1} = b_j + 4 d_j - 4 c_j), c_1 chosen by linear extrapolation so that Eq. A4
    gives the end slope, then A2 applied once more. Amplifies rounding by about
    (2 + √3)^n; use :func:`cubic_string_through` in production."""
    X = np.asarray(points, dtype=float)
    n = X.shape[0] - 1

    def march(c1):
        b = [X[0] + np.asarray(start_derivative, float) / 3.0]
        c = [np.broadcast_to(np.asarray(c1, float), X[0].shape).astype(float)]
        for j in range(n - 1):
            d = X[j + 1]
            b_next = 2.0 * d - c[j]
            c_next = b[j] + 4.0 * d - 4.0 * c[j]
            b.append(b_next)
            c.append(c_next)
        return b, c

    slopes = []
    for trial in (0.0, 1.0):
        b, c = march(trial)
        slopes.append(3.0 * (X[n] - c[-1]))
    s0, s1 = slopes
    c1 = (np.asarray(end_derivative, float) - s0) / (s1 - s0)
    b, c = march(c1)
    return BezierString(tuple(BezierCurve(np.array([X[j], b[j], c[j], X[j + 1]])) for j in range(n)))


# -- camber lines along a wall ---------------------------------------------------------------
class WallCamber:
    """Meridional distance m(U), camber angle β and circumferential position φ(U) of the
    camber line along one channel wall between U0 (LE) and U1 (TE) (Casey 1983, step c).

    beta_deg: Bernstein coefficients of β over m̄ = m / m_total in [0, 1], degrees.
    """

    def __init__(self, wall: BezierString, U0: float, U1: float, beta_deg, phi0: float):
        self.wall = wall
        self.U0, self.U1 = float(U0), float(U1)
        self.beta_coefficients = np.radians(np.asarray(beta_deg, dtype=float))
        self.phi0 = float(phi0)
        edges = np.linspace(self.U0, self.U1, QUADRATURE_INTERVALS + 1)
        self._edges = edges
        h = np.diff(edges)
        nodes = edges[:-1, None] + 0.5 * h[:, None] * (_GL_X[None, :] + 1.0)
        speed = self._speed(nodes)
        self._m_table = np.r_[0.0, np.cumsum(0.5 * h * (speed @ _GL_W))]
        self.m_total = float(self._m_table[-1])
        if self.m_total <= 0.0:
            raise GeometryError("the blade has zero meridional length")
        rate = self._phi_rate(nodes.ravel()).reshape(nodes.shape)
        self._phi_table = self.phi0 + np.r_[0.0, np.cumsum(0.5 * h * (rate @ _GL_W))]

    def _speed(self, U) -> np.ndarray:
        d = self.wall.derivatives(U, 1)[1]
        return np.linalg.norm(d, axis=-1)

    def _partial(self, U, integrand) -> tuple[np.ndarray, np.ndarray]:
        """(k, ∫_{edge_k}^{U} integrand dU) for the table interval k holding U."""
        U = np.asarray(U, dtype=float)
        k = np.clip(np.searchsorted(self._edges, U, side="right") - 1, 0, QUADRATURE_INTERVALS - 1)
        a = self._edges[k]
        half = 0.5 * (U - a)
        nodes = a[..., None] + half[..., None] * (_GL_X + 1.0)
        return k, half * (integrand(nodes) @ _GL_W)

    def m(self, U) -> np.ndarray:
        """Meridional distance from the LE along the wall."""
        k, part = self._partial(U, self._speed)
        return self._m_table[k] + part

    def mbar(self, U) -> np.ndarray:
        return self.m(U) / self.m_total

    def beta(self, U) -> np.ndarray:
        """β at U (radians)."""
        return bernstein_function(self.beta_coefficients, self.mbar(U))

    def beta_slope(self, U) -> np.ndarray:
        """dβ/dm at U (rad per metre), Eq. 9 on the Bernstein coefficients."""
        return bernstein_function_derivative(self.beta_coefficients, self.mbar(U)) / self.m_total

    def _phi_rate(self, U) -> np.ndarray:
        U = np.asarray(U, dtype=float)
        zr = self.wall.evaluate(U)
        return np.tan(self.beta(U)) / zr[..., 1] * self._speed(U)

    def phi(self, U) -> np.ndarray:
        """φ of the camber line at U: φ_LE + ∫ tan β / r dm (step c)."""
        k, part = self._partial(U, self._phi_rate)
        return self._phi_table[k] + part

    def U_of_m(self, m) -> np.ndarray:
        """Inverse of m(U) by table interpolation and Newton steps on dm/dU = |M'(U)|."""
        m = np.asarray(m, dtype=float)
        U = np.interp(m, self._m_table, self._edges)
        for _ in range(20):
            step = (self.m(U) - m) / self._speed(U)
            U = np.clip(U - step, self.U0, self.U1)
            if np.all(np.abs(step) < INVERSE_TOLERANCE):
                break
        return U


# -- corner points and end slopes ---------------------------------------------------------------
@dataclass(frozen=True)
class WallBlade:
    """What one wall contributes to a blade: the camber line, the blade's own U range on
    it (a splitter uses part of the main blade's camber line) and its thickness."""

    camber: WallCamber
    U0: float
    U1: float
    thickness: np.ndarray  # Bernstein coefficients of δ over the blade's own m̄ (metres)
    phi_offset: float = 0.0

    def m_range(self) -> tuple[float, float]:
        return float(self.camber.m(self.U0)), float(self.camber.m(self.U1))


def _surface_state(wb: WallBlade, U, side: float):
    """Points X (k, 3) and dX/dm (k, 3) of surface ``side`` (0 B, +1 P, -1 S) at U, and
    the angle of dX/dm from the meridional direction (rad)."""
    c = wb.camber
    U = np.asarray(U, dtype=float)
    zr, dzr = c.wall.derivatives(U, 1)
    z, r = zr[..., 0], zr[..., 1]
    g = np.linalg.norm(dzr, axis=-1)
    cos_e, sin_e = dzr[..., 0] / g, dzr[..., 1] / g
    beta = c.beta(U)
    dbeta = c.beta_slope(U)
    m0, m1 = wb.m_range()
    length = m1 - m0
    mbar = (c.m(U) - m0) / length
    delta = bernstein_function(wb.thickness, mbar)
    ddelta = bernstein_function_derivative(wb.thickness, mbar) / length
    cb = np.cos(beta)
    half = delta / (2.0 * r * cb)
    phi = c.phi(U) + wb.phi_offset + side * half
    dhalf = ddelta / (2.0 * r * cb) - delta * sin_e / (2.0 * r * r * cb) + half * np.tan(beta) * dbeta
    dphi = np.tan(beta) / r + side * dhalf
    X = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)
    dX = np.stack(
        [sin_e * np.cos(phi) - r * np.sin(phi) * dphi, sin_e * np.sin(phi) + r * np.cos(phi) * dphi, cos_e], axis=-1
    )
    return X, dX, np.arctan(r * dphi)


def corner_parameters(wb: WallBlade, n_patches: int) -> np.ndarray:
    """Channel U of the n+1 patch corners, equidistant in m between the blade's LE and TE
    (Casey 1983 step e)."""
    m0, m1 = wb.m_range()
    U = wb.camber.U_of_m(np.linspace(m0, m1, n_patches + 1))
    U[0], U[-1] = wb.U0, wb.U1
    return U


@dataclass(frozen=True, eq=False)
class BladeSurfaces:
    """One blade: camber surface B, suction S and pressure P as strings of cubic-linear
    patches (lower curve on the hub, v = 0; upper on the shroud, v = 1; U in [0, n]),
    optional rounded LE/TE end patches joining P to S, the channel U of the corners on
    hub and shroud (2, n+1), and the imposed end angles (rad) per surface as
    {"B"|"S"|"P": (2 walls, 2 ends)}."""

    camber: PatchString
    suction: PatchString
    pressure: PatchString
    leading_edge: RuledPatch | None
    trailing_edge: RuledPatch | None
    corner_U: np.ndarray
    imposed_angles: dict = field(default_factory=dict)
    axial_elements: bool = False

    @property
    def count(self) -> int:
        return self.camber.count

    def surface(self, name: str) -> PatchString:
        return {"B": self.camber, "S": self.suction, "P": self.pressure}[name]

    def rotated(self, angle: float) -> "BladeSurfaces":
        """The blade turned by ``angle`` about +z (exact: the polygons are rotated)."""
        R = _rotation(angle)

        def turn_string(s: BezierString) -> BezierString:
            return BezierString(tuple(BezierCurve(seg.control_points @ R.T) for seg in s.segments))

        def turn(p: PatchString) -> PatchString:
            return PatchString(turn_string(p.lower), turn_string(p.upper))

        def turn_patch(p):
            if p is None:
                return None
            return RuledPatch(BezierCurve(p.lower.control_points @ R.T), BezierCurve(p.upper.control_points @ R.T))

        return BladeSurfaces(
            turn(self.camber), turn(self.suction), turn(self.pressure), turn_patch(self.leading_edge),
            turn_patch(self.trailing_edge), self.corner_U, self.imposed_angles, self.axial_elements,
        )


def _rotation(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rounded_end_patch(first: PatchString, second: PatchString, end: int, ratio_hub: float, ratio_shroud: float,
                      thickness_hub: float, thickness_shroud: float) -> RuledPatch | None:
    """A cubic-linear end patch closing the blade at the LE (end 0) or TE (end 1): on each
    wall the cubic from the ``first`` surface's end point to the ``second``'s, with
    polygon P_0, P_0 ∓ k t_1, Q_0 ∓ k t_2, Q_0 (t the unit end tangents along the blade),
    k = 4/3 · ratio · δ/2. This is tangent to both surfaces (G1) and is the cubic
    Bézier form of a half ellipse of semi-axes (ratio · δ/2, δ/2) (Casey 1983 step g,
    after Smith & Merryweather). Returns None when ``ratio`` is 0 on both walls."""
    if ratio_hub <= 0.0 and ratio_shroud <= 0.0:
        return None
    curves = []
    for which, ratio, delta in (("lower", ratio_hub, thickness_hub), ("upper", ratio_shroud, thickness_shroud)):
        a_string = getattr(first, which)
        b_string = getattr(second, which)
        if end == 0:
            A = a_string.segments[0].control_points
            B = b_string.segments[0].control_points
            pa, ta = A[0], A[1] - A[0]
            pb, tb = B[0], B[1] - B[0]
            sign = -1.0
        else:
            A = a_string.segments[-1].control_points
            B = b_string.segments[-1].control_points
            pa, ta = A[-1], A[-1] - A[-2]
            pb, tb = B[-1], B[-1] - B[-2]
            sign = 1.0
        k = 4.0 / 3.0 * ratio * 0.5 * delta
        ta = ta / np.linalg.norm(ta)
        tb = tb / np.linalg.norm(tb)
        curves.append(BezierCurve(np.array([pa, pa + sign * k * ta, pb + sign * k * tb, pb])))
    return RuledPatch(curves[0], curves[1])


def build_blade(
    channel: MeridionalChannel,
    hub: WallBlade,
    shroud: WallBlade,
    n_patches: int,
    axial_elements: bool = False,
    leading_edge_ratio: float = 0.0,
    trailing_edge_ratio: float = 0.0,
) -> BladeSurfaces:
    """B, S and P of one blade (module docstring, steps a–g)."""
    if n_patches < 1:
        raise GeometryError(f"a blade needs at least one patch, got {n_patches}")
    U_hub = corner_parameters(hub, n_patches)
    strings = {}
    imposed = {}
    walls = [(hub, U_hub, "lower")]
    if not axial_elements:
        U_shroud = corner_parameters(shroud, n_patches)
        walls.append((shroud, U_shroud, "upper"))
    for name, side in (("B", 0.0), ("S", -1.0), ("P", 1.0)):
        angles = np.zeros((2, 2))
        for w, (wb, U, which) in enumerate(walls):
            X, dX, ang = _surface_state(wb, U, side)
            angles[w] = ang[[0, -1]]
            m = wb.camber.m(U)
            dm = np.diff(m)
            strings[(name, which)] = cubic_string_through(X, dX[0] * dm[0], dX[-1] * dm[-1])
        imposed[name] = angles
    if axial_elements:
        for name in ("B", "S", "P"):
            strings[(name, "upper")] = _axial_shroud(channel, strings[(name, "lower")], shroud, U_hub)
        U_shroud = np.full_like(U_hub, np.nan)
        for name in ("B", "S", "P"):
            imposed[name][1] = np.nan  # the shroud angles follow from the hub
    surfaces = {name: PatchString(strings[(name, "lower")], strings[(name, "upper")]) for name in ("B", "S", "P")}
    d_hub = bernstein_function(hub.thickness, np.array([0.0, 1.0]))
    d_shroud = bernstein_function((hub if axial_elements else shroud).thickness, np.array([0.0, 1.0]))
    le = rounded_end_patch(surfaces["P"], surfaces["S"], 0, leading_edge_ratio, leading_edge_ratio, d_hub[0], d_shroud[0]) \
        if min(d_hub[0], d_shroud[0]) > 0.0 else None
    te = rounded_end_patch(surfaces["S"], surfaces["P"], 1, trailing_edge_ratio, trailing_edge_ratio, d_hub[1], d_shroud[1]) \
        if min(d_hub[1], d_shroud[1]) > 0.0 else None
    return BladeSurfaces(
        surfaces["B"], surfaces["S"], surfaces["P"], le, te, np.vstack([U_hub, U_shroud]), imposed, axial_elements
    )


def _axial_shroud(channel: MeridionalChannel, lower: BezierString, shroud: WallBlade, U_hub) -> BezierString:
    """Shroud curve for axial elements: the hub polygon's x, y with z from the shroud
    contour at the same radii (module docstring)."""
    wall = channel.shroud
    Us = np.linspace(0.0, wall.count, wall.count * 200 + 1)
    rs = wall.evaluate(Us)[:, 1]
    corners = np.array([lower.segments[0].control_points[0]] + [s.control_points[-1] for s in lower.segments])
    radii = np.hypot(corners[:, 0], corners[:, 1])
    z = np.empty(len(radii))
    dzdr = np.empty(len(radii))
    for i, r in enumerate(radii):
        sign_change = np.nonzero(np.diff(np.sign(rs - r)) != 0)[0]
        if sign_change.size == 0:
            raise DefinitionError(f"the shroud contour never reaches r = {r:.6g} m needed by axial elements", field="blade.elements")
        # the contour can reach r more than once (an inlet turning outwards before the
        # passage): take the crossing nearest the blade's own span [U0, U1] on the shroud
        mid = 0.5 * (Us[sign_change] + Us[sign_change + 1])
        k = sign_change[np.argmin(np.maximum(shroud.U0 - mid, 0.0) + np.maximum(mid - shroud.U1, 0.0))]
        U = brentq(lambda t: wall.evaluate(t)[1] - r, Us[k], Us[k + 1], xtol=1e-15)
        zr, d = wall.derivatives(U, 1)
        if abs(d[1]) < 1e-12 * np.linalg.norm(d):
            raise DefinitionError("axial elements need a shroud contour that is not axial at the blade", field="blade.elements")
        z[i] = zr[0]
        dzdr[i] = d[0] / d[1]
    # dr/du of the hub curve at the ends
    h0 = lower.segments[0]
    h1 = lower.segments[-1]
    X0, D0 = h0.derivatives(0.0, 1)
    X1, D1 = h1.derivatives(1.0, 1)
    drdu0 = (X0[0] * D0[0] + X0[1] * D0[1]) / radii[0]
    drdu1 = (X1[0] * D1[0] + X1[1] * D1[1]) / radii[-1]
    zs = cubic_string_through(z[:, None], np.array([dzdr[0] * drdu0]), np.array([dzdr[-1] * drdu1]))
    segs = []
    for seg, zseg in zip(lower.segments, zs.segments):
        P = np.array(seg.control_points)
        P[:, 2] = zseg.control_points[:, 0]
        segs.append(BezierCurve(P))
    return BezierString(tuple(segs))


def surface_end_angles(surface: PatchString) -> np.ndarray:
    """Blade angles β (rad, from the meridional direction towards +φ) of the end tangents
    of ``surface``: shape (2 walls, 2 ends), from dX/du of the patch polygons."""
    out = np.zeros((2, 2))
    for w, string in enumerate((surface.lower, surface.upper)):
        for e, (seg, u) in enumerate(((string.segments[0], 0.0), (string.segments[-1], 1.0))):
            X, D = seg.derivatives(u, 1)
            r = np.hypot(X[0], X[1])
            e_r = np.array([X[0] / r, X[1] / r, 0.0])
            e_phi = np.array([-X[1] / r, X[0] / r, 0.0])
            d_m = np.hypot(D @ e_r, D[2])
            out[w, e] = np.arctan2(D @ e_phi, d_m)
    return out
