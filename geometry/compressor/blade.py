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
from .bezier import BezierCurve, BezierString, PatchString, bernstein_function, bernstein_function_derivative
from .channel import MeridionalChannel

#: Gauss–Legendre points per quadrature interval and intervals per wall for m(U), φ(U).
QUADRATURE_POINTS = 6
QUADRATURE_INTERVALS = 48
#: Newton tolerance (in U) when inverting m(U).
INVERSE_TOLERANCE = 1e-13
#: Largest |β| accepted (deg): S and P need cos β > 0.
MAX_BETA_DEG = 85.0

_GL_X, _GL_W = np.polynomial.legendre.leggauss(QUADRATURE_POINTS)


def _norm(x: np.ndarray) -> np.ndarray:
    """Euclidean norms along the last axis of a real array: what ``np.linalg.norm(x,
    axis=-1)`` computes (sqrt of the sum of squares, the same reduction, bit for bit),
    without its argument handling, which costs more than the sum on the few points of
    each call in the hot paths here."""
    return np.sqrt(np.add.reduce(x * x, axis=-1))


def _integration_matrix(x: np.ndarray) -> np.ndarray:
    """Q with Q[i, j] = ∫_{-1}^{x_i} L_j(t) dt, L_j the Lagrange polynomials on the nodes x:
    Q @ f gives the running integral of the polynomial through the samples f at each node
    (spectral integration; exact for degree len(x) - 1)."""
    k = np.arange(len(x))
    coefficients = np.linalg.solve(np.vander(x, len(x), increasing=True), np.eye(len(x)))  # column j: L_j
    antiderivative = coefficients / (k + 1.0)[:, None]
    powers = lambda t: np.asarray(t, float)[:, None] ** (k + 1.0)[None, :]  # noqa: E731
    return powers(x) @ antiderivative - powers(np.array([-1.0])) @ antiderivative


#: Running integrals to the Gauss nodes of one interval: m at the nodes from the speeds
#: there, without a second quadrature per node (the integrands of φ and s need β(m)).
_GL_Q = _integration_matrix(_GL_X)


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
        # the channel patches are G2 but each spans one unit of U, so |M'(U)| jumps at
        # their junctions: those must be interval edges, never inside a Gauss interval
        junctions = np.arange(np.floor(self.U0) + 1.0, np.ceil(self.U1))
        edges = np.union1d(np.linspace(self.U0, self.U1, QUADRATURE_INTERVALS + 1), junctions)
        self._edges = edges
        h = np.diff(edges)
        nodes = edges[:-1, None] + 0.5 * h[:, None] * (_GL_X[None, :] + 1.0)
        r, speed = self._radius_speed(nodes)
        self._m_table = np.r_[0.0, np.cumsum(0.5 * h * (speed @ _GL_W))]
        self.m_total = float(self._m_table[-1])
        if self.m_total <= 0.0:
            raise GeometryError("the blade has zero meridional length")
        beta = self._beta_at_nodes(self._m_table[:-1], 0.5 * h, speed)
        rate = np.tan(beta) / r * speed
        self._phi_table = self.phi0 + np.r_[0.0, np.cumsum(0.5 * h * (rate @ _GL_W))]
        rate = speed / np.cos(beta)
        self._s_table = np.r_[0.0, np.cumsum(0.5 * h * (rate @ _GL_W))]

    def _radius_speed(self, U) -> tuple[np.ndarray, np.ndarray]:
        C = self.wall.derivatives(U, 1)
        return C[0][..., 1], _norm(C[1])

    def _beta_at_nodes(self, m_start, half, speed) -> np.ndarray:
        """β at the Gauss nodes of intervals starting at m = ``m_start`` with half-widths
        ``half``: m at the nodes by the running integral of the speeds there (_GL_Q)."""
        m = np.asarray(m_start)[..., None] + np.asarray(half)[..., None] * (speed @ _GL_Q.T)
        return bernstein_function(self.beta_coefficients, m / self.m_total)

    def _nodes(self, U):
        """(table interval k, half-width, Gauss nodes of [edge_k, U]) for U."""
        U = np.asarray(U, dtype=float)
        # beyond the TE (rounded caps) integrate from the last edge itself: the interval
        # before it may end at a channel junction, where |M'(U)| jumps
        k = np.minimum(np.maximum(np.searchsorted(self._edges, U, side="right") - 1, 0), len(self._edges) - 1)
        a = self._edges[k]
        half = 0.5 * (U - a)
        return k, half, a[..., None] + half[..., None] * (_GL_X + 1.0)

    def _speed(self, U) -> np.ndarray:
        d = self.wall.derivatives(U, 1)[1]
        return _norm(d)

    def _partial(self, U, integrand) -> tuple[np.ndarray, np.ndarray]:
        """(k, ∫_{edge_k}^{U} integrand dU) for the table interval k holding U."""
        U = np.asarray(U, dtype=float)
        # beyond the TE (rounded caps) integrate from the last edge itself: the interval
        # before it may end at a channel junction, where |M'(U)| jumps
        k = np.minimum(np.maximum(np.searchsorted(self._edges, U, side="right") - 1, 0), len(self._edges) - 1)
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
        k, half, nodes = self._nodes(U)
        r, speed = self._radius_speed(nodes)
        beta = self._beta_at_nodes(self._m_table[k], half, speed)
        return self._phi_table[k] + half * ((np.tan(beta) / r * speed) @ _GL_W)

    def _length_rate(self, U) -> np.ndarray:
        return self._speed(U) / np.cos(self.beta(U))

    def s(self, U) -> np.ndarray:
        """Length along the camber line on this wall from the LE, ds = dm / cos β (the
        blade-surface measure of Casey 1983 step e)."""
        k, half, nodes = self._nodes(U)
        _, speed = self._radius_speed(nodes)
        beta = self._beta_at_nodes(self._m_table[k], half, speed)
        return self._s_table[k] + half * ((speed / np.cos(beta)) @ _GL_W)

    def _invert(self, values, measure, rate, table, clip: bool = True) -> np.ndarray:
        values = np.asarray(values, dtype=float)
        U = np.interp(values, table, self._edges)
        if not clip:
            # beyond the blade (rounded end caps): start from the end slope
            U = np.where(values < table[0], self.U0 + (values - table[0]) / rate(self.U0), U)
            U = np.where(values > table[-1], self.U1 + (values - table[-1]) / rate(self.U1), U)
        for _ in range(20):
            step = (measure(U) - values) / rate(U)
            U = U - step
            if clip:
                U = np.clip(U, self.U0, self.U1)
            if np.all(np.abs(step) < INVERSE_TOLERANCE):
                break
        return U

    def U_of_m(self, m, clip: bool = True) -> np.ndarray:
        """Inverse of m(U) by table interpolation and Newton steps on dm/dU = |M'(U)|;
        ``clip=False`` follows the wall beyond the blade's LE and TE."""
        return self._invert(m, self.m, self._speed, self._m_table, clip)

    def U_of_s(self, s) -> np.ndarray:
        """Inverse of :meth:`s`."""
        return self._invert(s, self.s, self._length_rate, self._s_table)


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
        m = self.camber.m(np.array([self.U0, self.U1]))
        return float(m[0]), float(m[1])


def _surface_phi(wb: WallBlade, U, side):
    """Target of surface ``side`` (0 B, +1 P, -1 S) on its wall at channel parameter U
    (Casey 1983 steps c and d): z, r, φ, dφ/dm and the wall direction (sin ε, cos ε).
    ``side`` may be an array broadcasting against U (several surfaces at once: the wall
    quantities are computed once); φ and dφ/dm then have the broadcast shape."""
    c = wb.camber
    U = np.asarray(U, dtype=float)
    zr, dzr = c.wall.derivatives(U, 1)
    z, r = zr[..., 0], zr[..., 1]
    g = _norm(dzr)
    cos_e, sin_e = dzr[..., 0] / g, dzr[..., 1] / g
    mU = c.m(U)
    beta = bernstein_function(c.beta_coefficients, mU / c.m_total)
    dbeta = bernstein_function_derivative(c.beta_coefficients, mU / c.m_total) / c.m_total
    m0, m1 = wb.m_range()
    length = m1 - m0
    mbar = (mU - m0) / length
    delta = bernstein_function(wb.thickness, mbar)
    ddelta = bernstein_function_derivative(wb.thickness, mbar) / length
    cb = np.cos(beta)
    half = delta / (2.0 * r * cb)
    phi = c.phi(U) + wb.phi_offset + side * half
    dhalf = ddelta / (2.0 * r * cb) - delta * sin_e / (2.0 * r * r * cb) + half * np.tan(beta) * dbeta
    dphi = np.tan(beta) / r + side * dhalf
    return z, r, phi, dphi, sin_e, cos_e


def _surface_state(wb: WallBlade, U, side):
    """Points X (k, 3) and dX/dm (k, 3) of surface ``side`` (0 B, +1 P, -1 S) at U, and
    the angle of dX/dm from the meridional direction (rad); ``side`` may be an array
    broadcasting against U (leading axes of the results)."""
    z, r, phi, dphi, sin_e, cos_e = _surface_phi(wb, U, side)
    shape = np.shape(phi)
    z, cos_e = np.broadcast_to(z, shape), np.broadcast_to(cos_e, shape)
    X = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)
    dX = np.stack(
        [sin_e * np.cos(phi) - r * np.sin(phi) * dphi, sin_e * np.sin(phi) + r * np.cos(phi) * dphi, cos_e], axis=-1
    )
    return X, dX, np.arctan(r * dphi)


#: Casey's (1983, step e) two patch spacings: equidistant along the projection of the
#: blade onto the meridional channel (in m), or along the blade surface (camber-line
#: length s on each wall, ds = dm / cos β).
PATCH_SPACINGS = ("meridional", "blade")


def corner_parameters(wb: WallBlade, n_patches: int, spacing: str = "meridional") -> np.ndarray:
    """Channel U of the n+1 patch corners, equidistant between the blade's LE and TE in
    the measure ``spacing`` (:data:`PATCH_SPACINGS`, Casey 1983 step e)."""
    c = wb.camber
    if spacing == "meridional":
        m0, m1 = wb.m_range()
        U = c.U_of_m(np.linspace(m0, m1, n_patches + 1))
    elif spacing == "blade":
        s0, s1 = float(c.s(wb.U0)), float(c.s(wb.U1))
        U = c.U_of_s(np.linspace(s0, s1, n_patches + 1))
    else:
        raise GeometryError(f"patch spacing must be one of {PATCH_SPACINGS}, got {spacing!r}")
    U[0], U[-1] = wb.U0, wb.U1
    return U


def _end_speed(wb: WallBlade, U_corners: np.ndarray, spacing: str) -> tuple[float, float]:
    """dm/dt at the LE and TE of a string whose corners are one unit of t apart and
    equidistant in the ``spacing`` measure: Δm for meridional spacing, Δs · cos β for
    blade spacing (so the imposed end derivative matches the parameter speed)."""
    c = wb.camber
    if spacing == "meridional":
        m = c.m(U_corners[[0, 1]])
        return float(m[1] - m[0]), float(m[1] - m[0])
    s = c.s(U_corners[[0, -1]])
    ds = (float(s[1]) - float(s[0])) / (len(U_corners) - 1)
    cb = np.cos(c.beta(U_corners[[0, -1]]))
    return ds * float(cb[0]), ds * float(cb[1])


@dataclass(frozen=True, eq=False)
class BladeSurfaces:
    """One blade: camber surface B, suction S and pressure P as strings of cubic-linear
    patches (lower curve on the hub, v = 0; upper on the shroud, v = 1; U in [0, n]),
    the LE and TE end caps joining P to S (rounded, or the flat face closing a cut-off
    edge; strings of cubic-linear patches too, or None when the edge has no thickness),
    the channel U of the corners on hub and shroud (2, n+1), the imposed end angles (rad)
    per surface as {"B"|"S"|"P": (2 walls, 2 ends)} and the construction ``report``
    (:func:`build_blade`)."""

    camber: PatchString
    suction: PatchString
    pressure: PatchString
    leading_edge: PatchString | None
    trailing_edge: PatchString | None
    corner_U: np.ndarray
    imposed_angles: dict = field(default_factory=dict)
    axial_elements: bool = False
    report: dict = field(default_factory=dict)

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

        def turn(p: PatchString | None) -> PatchString | None:
            return None if p is None else PatchString(turn_string(p.lower), turn_string(p.upper))

        return BladeSurfaces(
            turn(self.camber), turn(self.suction), turn(self.pressure), turn(self.leading_edge),
            turn(self.trailing_edge), self.corner_U, self.imposed_angles, self.axial_elements, self.report,
        )


def _rotation(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


# -- edges on the walls, deviations from the prescription ------------------------------------
#: Default largest distance of a blade edge from its channel wall, as a fraction of the
#: outer diameter (:func:`outer_diameter`). Casey's ruled surfaces are bounded by curves on
#: the walls; a cubic cannot follow a curve on a surface of revolution exactly, so the patch
#: count is raised until the edges lie on the walls to this.
WALL_TOLERANCE = 1e-6
#: Default tolerance on the camber line (rθ against φ(m) of step c) and on S and P against
#: ±δ/2 (step d), as a fraction of the outer diameter.
DEFAULT_TOLERANCE = 1e-6
#: Most patches the adaptive construction uses per surface, and per end cap.
MAX_PATCHES = 256
MAX_CAP_PATCHES = 64
#: Samples per patch when measuring the deviations.
CHECK_SAMPLES = 4
#: A C2 cubic interpolant's error falls as h^4: the next count is n (e/tol)^(1/4) times this.
PATCH_MARGIN = 1.15
#: Foot points on a wall: Newton iterations and step tolerance (wall parameter).
FOOT_ITERATIONS = 30
FOOT_TOLERANCE = 1e-14
#: Wall samples per patch for the starting guesses of foot points far from any corner.
GUESS_SAMPLES = 64


def outer_diameter(hub: WallBlade, shroud: WallBlade) -> float:
    """2 × the largest radius of the blade's four corners: the length scale of the
    tolerances (the wheel's outer diameter for an impeller)."""
    r = [float(wb.camber.wall.evaluate(U)[1]) for wb in (hub, shroud) for U in (wb.U0, wb.U1)]
    return 2.0 * max(r)


def wall_foot(wall: BezierString, zr, U_guess) -> tuple[np.ndarray, np.ndarray]:
    """Foot points (U) and distances of meridional points ``zr`` (k, 2) on the wall contour,
    by Newton on C'(U)·(C(U) - X) = 0 from ``U_guess`` (The NURBS Book 2e Eqs. 6.3–6.4)."""
    X = np.asarray(zr, dtype=float)
    U = np.array(U_guess, dtype=float)
    for _ in range(FOOT_ITERATIONS):
        C = wall.derivatives(U, 2)
        d = C[0] - X
        f = np.sum(C[1] * d, axis=-1)
        fp = np.sum(C[2] * d, axis=-1) + np.sum(C[1] * C[1], axis=-1)
        step = f / fp
        U = np.clip(U - step, 0.0, wall.count)
        if np.max(np.abs(step), initial=0.0) < FOOT_TOLERANCE:
            break
    return U, _norm(wall.evaluate(U) - X)


def _guess(wall: BezierString, zr) -> np.ndarray:
    Us = np.linspace(0.0, wall.count, wall.count * GUESS_SAMPLES + 1)
    W = wall.evaluate(Us)
    return Us[np.argmin(np.linalg.norm(W[None, :, :] - np.asarray(zr)[:, None, :], axis=-1), axis=1)]


def _meridional(X) -> np.ndarray:
    return np.stack([X[..., 2], np.hypot(X[..., 0], X[..., 1])], axis=-1)


def _samples(count: int) -> np.ndarray:
    return (np.arange(count)[:, None] + (np.arange(CHECK_SAMPLES + 1) / CHECK_SAMPLES)[None, :]).ravel()


def edge_deviation(wb: WallBlade, string: BezierString, U_corners, side: float | None) -> tuple[float, float]:
    """(largest distance of ``string`` from its wall, largest circumferential error rθ
    against the target of surface ``side`` of steps c–d at the same wall point); side
    None: the wall distance only. Measured at CHECK_SAMPLES per patch."""
    t = _samples(string.count)
    X = string.evaluate(t)
    zr = _meridional(X)
    wall = wb.camber.wall
    guess = np.interp(t, np.arange(len(U_corners)), U_corners) if U_corners is not None and np.all(
        np.isfinite(U_corners)) else _guess(wall, zr)
    U, gap = wall_foot(wall, zr, guess)
    if side is None:
        return float(gap.max()), 0.0
    U = np.clip(U, wb.U0, wb.U1)
    _, r, phi, *_ = _surface_phi(wb, U, side)
    dphi = np.angle(np.exp(1j * (np.arctan2(X[:, 1], X[:, 0]) - phi)))
    return float(gap.max()), float(np.max(r * np.abs(dphi)))


def _edge_deviations(wb: WallBlade, strings, U_corners, sides) -> list[tuple[float, float]]:
    """:func:`edge_deviation` of several strings of the same patch count on one wall, with
    one foot-point solve and one target evaluation for all (``sides``: one per string, or
    None for the wall distance only)."""
    t = _samples(strings[0].count)
    X = np.concatenate([string.evaluate(t) for string in strings])
    zr = _meridional(X)
    wall = wb.camber.wall
    if U_corners is not None and np.all(np.isfinite(U_corners)):
        guess = np.tile(np.interp(t, np.arange(len(U_corners)), U_corners), len(strings))
    else:
        guess = _guess(wall, zr)
    U, gap = wall_foot(wall, zr, guess)
    gaps = gap.reshape(len(strings), -1).max(axis=1)
    if sides is None:
        return [(float(g), 0.0) for g in gaps]
    U = np.clip(U, wb.U0, wb.U1)
    _, r, phi, *_ = _surface_phi(wb, U, np.repeat(np.asarray(sides, dtype=float), t.size))
    dphi = np.angle(np.exp(1j * (np.arctan2(X[:, 1], X[:, 0]) - phi)))
    errors = (r * np.abs(dphi)).reshape(len(strings), -1).max(axis=1)
    return [(float(g), float(e)) for g, e in zip(gaps, errors)]


def _wall_strings(channel, hub: WallBlade, shroud: WallBlade, n: int, axial: bool, spacing: str):
    """Steps e–f for ``n`` patches: the hub and shroud strings of B, S and P, the imposed
    end angles and the corner parameters."""
    U_hub = corner_parameters(hub, n, spacing)
    walls = [(hub, U_hub, "lower")]
    U_shroud = np.full_like(U_hub, np.nan)
    if not axial:
        U_shroud = corner_parameters(shroud, n, spacing)
        walls.append((shroud, U_shroud, "upper"))
    strings, imposed = {}, {name: np.zeros((2, 2)) for name in ("B", "S", "P")}
    for w, (wb, U, which) in enumerate(walls):
        # the three surfaces at once: the camber line and thickness at U are shared
        X, dX, ang = _surface_state(wb, U, np.array([0.0, -1.0, 1.0])[:, None])
        v0, v1 = _end_speed(wb, U, spacing)
        for i, name in enumerate(("B", "S", "P")):
            imposed[name][w] = ang[i, [0, -1]]
            strings[(name, which)] = cubic_string_through(X[i], dX[i, 0] * v0, dX[i, -1] * v1)
    if axial:
        for name in ("B", "S", "P"):
            strings[(name, "upper")] = _axial_shroud(channel, strings[(name, "lower")], shroud, U_hub)
            imposed[name][1] = np.nan  # the shroud angles follow from the hub
    surfaces = {name: PatchString(strings[(name, "lower")], strings[(name, "upper")]) for name in ("B", "S", "P")}
    return surfaces, imposed, U_hub, U_shroud


def _deviations(hub: WallBlade, shroud: WallBlade, surfaces: dict, U_hub, U_shroud, axial: bool) -> dict:
    """Largest wall distance of the hub and shroud edges of B, S and P, camber error (B)
    and offset error of S and P (steps c and d), in metres."""
    names, sides = ("B", "S", "P"), (0.0, -1.0, 1.0)
    measured = _edge_deviations(hub, [surfaces[k].lower for k in names], U_hub, sides)
    measured += _edge_deviations(shroud, [surfaces[k].upper for k in names], U_shroud, None if axial else sides)
    gap = max(g for g, _ in measured)
    camber = max(e for (g, e), name in zip(measured, names * 2) if name == "B")
    offset = max(e for (g, e), name in zip(measured, names * 2) if name != "B")
    return {"wall_gap": gap, "camber": camber, "thickness": offset}


# -- LE/TE end caps on the walls ------------------------------------------------------------
def _hermite(t, rho0: float, rho1: float) -> np.ndarray:
    """σ(t) on [0, 1] with σ(0) = 0, σ(1) = 1, σ'(0) = ρ0, σ'(1) = ρ1 (cubic Hermite)."""
    t2, t3 = t * t, t * t * t
    return (3.0 * t2 - 2.0 * t3) + rho0 * (t3 - 2.0 * t2 + t) + rho1 * (t3 - t2)


class _CapWall:
    """One wall's edge of an end cap, exactly on the wall: a cubic Bézier c(σ) in the
    developed (m, φ) coordinates of the wall (the half ellipse of semi-axes ratio · δ/2 and
    δ/2 in the metric (dm, r dφ) of Casey 1983 step g, or the straight line of a cut-off
    edge) mapped onto the wall surface of revolution, X = (r(m) cos φ, r(m) sin φ, z(m))."""

    def __init__(self, wb: WallBlade, end: int, ratio: float, speed: float):
        c = wb.camber
        self.wb = wb
        U_end = wb.U0 if end == 0 else wb.U1
        out = -1.0 if end == 0 else 1.0
        m_end = float(c.m(U_end))
        first, second = (1.0, -1.0) if end == 0 else (-1.0, 1.0)  # LE: P to S; TE: S to P
        delta = float(bernstein_function(wb.thickness, np.array([float(end)]))[0])
        state = {}
        for side in (first, second):
            _, r, phi, dphi, _, _ = _surface_phi(wb, np.array([U_end]), side)
            state[side] = (float(r[0]), float(phi[0]), float(dphi[0]))
        r0, phi0, d0 = state[first]
        r3, phi3, d3 = state[second]
        c0, c3 = np.array([m_end, phi0]), np.array([m_end, phi3])
        self.rounded = ratio > 0.0
        if self.rounded:
            k = 4.0 / 3.0 * ratio * 0.5 * delta
            n0, n3 = np.hypot(1.0, r0 * d0), np.hypot(1.0, r3 * d3)
            c1 = c0 + out * k / n0 * np.array([1.0, d0])
            c2 = c3 + out * k / n3 * np.array([1.0, d3])
            # c'(0) = 3 out k / n0 · d(m, φ)/dm of the first surface, whose string has
            # dX/dt = dX/dm · speed there: the cap's end derivative is lam0 times it
            self.lam = (3.0 * k / (n0 * speed), 3.0 * k / (n3 * speed))
        else:
            c1, c2 = c0 + (c3 - c0) / 3.0, c0 + 2.0 * (c3 - c0) / 3.0
            self.lam = (1.0, 1.0)
        self.polygon = np.array([c0, c1, c2, c3])
        self.rho = (1.0, 1.0)

    def developed(self, t, order: int = 0) -> np.ndarray:
        s = _hermite(t, *self.rho)
        return BezierCurve(self.polygon).derivatives(s, order)

    def evaluate(self, t) -> np.ndarray:
        mp = self.developed(np.asarray(t, float))[0]
        c = self.wb.camber
        U = c.U_of_m(mp[..., 0], clip=False)
        zr = c.wall.evaluate(U)
        phi = mp[..., 1]
        return np.stack([zr[..., 1] * np.cos(phi), zr[..., 1] * np.sin(phi), zr[..., 0]], axis=-1)

    def flat_derivatives(self) -> tuple[np.ndarray, np.ndarray]:
        """dX/dt at both ends of a cut-off cap: Δφ ∂X/∂φ (a circular arc on the wall)."""
        out = []
        for t in (0.0, 1.0):
            X = self.evaluate(np.array([t]))[0]
            dphi = self.polygon[3, 1] - self.polygon[0, 1]
            out.append(dphi * np.array([-X[1], X[0], 0.0]))
        return out[0], out[1]


def _end_derivative(string: BezierString, end: int) -> np.ndarray:
    P = string.segments[0 if end == 0 else -1].control_points
    return 3.0 * (P[1] - P[0]) if end == 0 else 3.0 * (P[-1] - P[-2])


def end_cap(channel: MeridionalChannel, hub: WallBlade, shroud: WallBlade, surfaces: dict, end: int, ratio: float,
            axial: bool, speeds: dict, tolerance: float) -> tuple[PatchString, float]:
    """The LE (end 0: P to S) or TE (end 1: S to P) cap and its largest deviation from
    its exact on-wall edges (:class:`_CapWall`), Casey 1983 step g.

    Rounded (ratio > 0): G1 with S and P along the whole junction ruling. Two ruled surfaces
    sharing a ruling are tangent along all of it when the u-derivatives of the cap's two
    edges are the SAME multiple λ of the adjoining surface's edge derivatives (the normals
    are then (1-v)(λA') + v(λB') × (B - A) = λ N). Each wall's half ellipse asks for its
    own λ_w; the common λ is their mean, and each wall's edge is reparameterised by a cubic
    σ(t) with σ'(0) = λ / λ_w so that its exact shape is kept. Cut-off (ratio 0): the flat
    face closing the edge, its wall edges circular arcs at the edge's m.

    Each edge is the C2 cubic string (Eqs. A1–A4) through the exact on-wall points at
    n_c + 1 uniform t, with the end derivatives imposed, n_c doubled until the string lies
    within ``tolerance`` of the exact edge; the end points are the S and P corners
    themselves (copied arrays, so the shared rulings are equal)."""
    first, second = ("P", "S") if end == 0 else ("S", "P")
    out = -1.0 if end == 0 else 1.0
    walls = [("lower", hub)] if axial else [("lower", hub), ("upper", shroud)]
    caps = {which: _CapWall(wb, end, ratio, speeds[which]) for which, wb in walls}
    lam0 = float(np.mean([c.lam[0] for c in caps.values()]))
    lam1 = float(np.mean([c.lam[1] for c in caps.values()]))
    for cap in caps.values():
        cap.rho = (lam0 / cap.lam[0], lam1 / cap.lam[1]) if cap.rounded else (1.0, 1.0)
        if not all(0.0 < r < 3.0 for r in cap.rho):
            raise GeometryError(f"the {'leading' if end == 0 else 'trailing'} edge rounding differs too much between "
                                f"hub and shroud for one tangent-continuous cap (λ ratios {cap.rho})")
    n_c = 1 if ratio <= 0.0 else 2
    while True:
        strings, dev = {}, 0.0
        t = np.linspace(0.0, 1.0, n_c + 1)
        for which, wb in walls:
            cap = caps[which]
            A = getattr(surfaces[first], which)
            B = getattr(surfaces[second], which)
            pts = cap.evaluate(t)
            pts[0] = A.segments[0 if end == 0 else -1].control_points[0 if end == 0 else -1]
            pts[-1] = B.segments[0 if end == 0 else -1].control_points[0 if end == 0 else -1]
            if cap.rounded:
                D0 = out * lam0 * _end_derivative(A, end)
                D1 = -out * lam1 * _end_derivative(B, end)
            else:
                D0, D1 = cap.flat_derivatives()
            strings[which] = cubic_string_through(pts, D0 / n_c, D1 / n_c)
            T = _samples(n_c)
            dev = max(dev, float(np.max(np.linalg.norm(strings[which].evaluate(T) - cap.evaluate(T / n_c), axis=-1))))
        if axial:
            strings["upper"] = _axial_shroud(channel, strings["lower"], shroud, None)
            dev = max(dev, edge_deviation(shroud, strings["upper"], None, None)[0])
        if dev <= tolerance or n_c >= MAX_CAP_PATCHES:
            return PatchString(strings["lower"], strings["upper"]), dev
        n_c *= 2


def junction_kinks(blade: BladeSurfaces, samples: int = 11) -> dict:
    """Largest angle (deg) between the normals of S or P and the adjoining end cap along
    each junction ruling: {"LE-P", "LE-S", "TE-S", "TE-P"} for the caps present."""
    out = {}
    v = np.linspace(0.0, 1.0, samples)

    def normal(ps: PatchString, U):
        du = ps.derivatives_u(np.full_like(v, U), v, 1)[1]
        dv = ps.evaluate(np.full_like(v, U), np.ones_like(v)) - ps.evaluate(np.full_like(v, U), np.zeros_like(v))
        n = np.cross(du, dv)
        return n / np.linalg.norm(n, axis=-1, keepdims=True)

    for label, cap, pairs in (("LE", blade.leading_edge, (("P", 0.0, 0.0), ("S", 0.0, None))),
                              ("TE", blade.trailing_edge, (("S", None, 0.0), ("P", None, None)))):
        if cap is None:
            continue
        for (name, U_surface, U_cap) in pairs:
            surf = blade.surface(name)
            Us = float(surf.count) if U_surface is None else U_surface
            Uc = float(cap.count) if U_cap is None else U_cap
            c = np.clip(np.abs(np.sum(normal(surf, Us) * normal(cap, Uc), axis=-1)), 0.0, 1.0)
            out[f"{label}-{name}"] = float(np.degrees(np.max(np.arccos(c))))
    return out


@dataclass(frozen=True, eq=False)
class BladeStrings:
    """Steps e–f of one blade at its chosen patch count (:func:`blade_strings`): B, S, P as
    patch strings, the imposed end angles, the corner parameters on hub and shroud, the
    patch count and the measured deviations (:func:`_deviations`), with the tolerances
    they were held to. What the end caps (step g) are built on."""

    surfaces: dict
    imposed: dict
    U_hub: np.ndarray
    U_shroud: np.ndarray
    patches: int
    deviations: dict
    tolerance: float
    wall_tolerance: float


def blade_step(channel: MeridionalChannel, hub: WallBlade, shroud: WallBlade, n: int, axial: bool, spacing: str):
    """One construction at ``n`` patches: (surfaces, imposed angles, U_hub, U_shroud,
    deviations); a pure function of its arguments, so a caller may keep it (:func:`blade_strings`'s ``step``)."""
    surfaces, imposed, U_hub, U_shroud = _wall_strings(channel, hub, shroud, n, axial, spacing)
    return surfaces, imposed, U_hub, U_shroud, _deviations(hub, shroud, surfaces, U_hub, U_shroud, axial)


def blade_strings(channel: MeridionalChannel, hub: WallBlade, shroud: WallBlade, n_patches: int,
                  axial_elements: bool = False, tolerance: float = 0.0, wall_tolerance: float | None = None,
                  spacing: str = "meridional", step=None) -> BladeStrings:
    """Steps e–f with the adaptive patch count of :func:`build_blade`. ``step(n)``: the
    construction at n patches (default :func:`blade_step` on these arguments; a caller
    may pass one that remembers earlier counts, since a tolerance edit revisits them)."""
    if n_patches < 1:
        raise GeometryError(f"a blade needs at least one patch, got {n_patches}")
    if spacing not in PATCH_SPACINGS:
        raise GeometryError(f"patch spacing must be one of {PATCH_SPACINGS}, got {spacing!r}")
    if step is None:
        def step(n):
            return blade_step(channel, hub, shroud, n, axial_elements, spacing)
    tol = float(tolerance)
    wall_tol = tol if wall_tolerance is None else float(wall_tolerance)
    n = int(n_patches)
    while True:
        surfaces, imposed, U_hub, U_shroud, dev = step(n)
        if tol <= 0.0:
            break
        ratio = max(dev["wall_gap"] / wall_tol, dev["camber"] / tol, dev["thickness"] / tol)
        if ratio <= 1.0 or n >= MAX_PATCHES:
            break
        n = min(MAX_PATCHES, max(n + 1, int(np.ceil(n * ratio ** 0.25 * PATCH_MARGIN))))
    return BladeStrings(surfaces, imposed, U_hub, U_shroud, n, dev, tol, wall_tol)


def build_blade(
    channel: MeridionalChannel,
    hub: WallBlade,
    shroud: WallBlade,
    n_patches: int,
    axial_elements: bool = False,
    leading_edge_ratio: float = 0.0,
    trailing_edge_ratio: float = 0.0,
    tolerance: float = 0.0,
    wall_tolerance: float | None = None,
    spacing: str = "meridional",
    strings: BladeStrings | None = None,
    caps: dict | None = None,
) -> BladeSurfaces:
    """B, S, P and the end caps of one blade (module docstring, steps a–g).

    tolerance: camber (rθ) and S/P offset tolerance in metres; > 0 makes the patch count
    adaptive: from ``n_patches`` it is raised (predicted from the h^4 convergence of the
    cubic spline) until the edges of B, S and P lie on the walls within ``wall_tolerance``
    (default: ``tolerance``) and follow steps c–d within ``tolerance``; 0 uses
    ``n_patches`` as given. The caps are fitted to the smaller of the two. The result's
    ``report`` holds the counts, the measured deviations (m) and whether they were met:
    a count that reaches MAX_PATCHES without meeting them is reported, not refused.

    strings: steps e–f already done (:func:`blade_strings` on the same arguments), e.g.
    kept by a caller across panel edits that change only the end caps; caps: a dict
    {end: (cap, deviation)} the caps of each end are looked up in and stored to by
    ``(end, ratio)`` (a caller's memory; only valid for these same strings)."""
    if strings is None:
        strings = blade_strings(channel, hub, shroud, n_patches, axial_elements, tolerance, wall_tolerance, spacing)
    surfaces, imposed, U_hub, U_shroud = strings.surfaces, strings.imposed, strings.U_hub, strings.U_shroud
    n, dev, tol, wall_tol = strings.patches, strings.deviations, strings.tolerance, strings.wall_tolerance
    cap_tol = min(tol, wall_tol) if tol > 0.0 else np.inf
    built, cap_dev = {}, {}
    for end, ratio_e in ((0, leading_edge_ratio), (1, trailing_edge_ratio)):
        d_hub = float(bernstein_function(hub.thickness, np.array([float(end)]))[0])
        d_shroud = float(bernstein_function((hub if axial_elements else shroud).thickness, np.array([float(end)]))[0])
        if min(d_hub, d_shroud) <= 0.0:
            built[end] = None
            continue
        key = (end, float(ratio_e))
        if caps is not None and key in caps:
            built[end], cap_dev[end] = caps[key]
            continue
        speeds = {"lower": _end_speed(hub, U_hub, spacing)[end]}
        if not axial_elements:
            speeds["upper"] = _end_speed(shroud, U_shroud, spacing)[end]
        built[end], cap_dev[end] = end_cap(channel, hub, shroud, surfaces, end, ratio_e, axial_elements, speeds,
                                           cap_tol)
        if caps is not None:
            caps[key] = (built[end], cap_dev[end])
    report = dict(dev)
    report.update({
        "patches": n, "spacing": spacing, "tolerance": tol, "wall_tolerance": wall_tol,
        "cap_patches": tuple(None if built[e] is None else built[e].count for e in (0, 1)),
        "cap_deviation": max(cap_dev.values(), default=0.0),
    })
    report["met"] = tol <= 0.0 or (dev["wall_gap"] <= wall_tol and dev["camber"] <= tol and dev["thickness"] <= tol
                                   and report["cap_deviation"] <= cap_tol)
    return BladeSurfaces(
        surfaces["B"], surfaces["S"], surfaces["P"], built[0], built[1], np.vstack([U_hub, U_shroud]), imposed,
        axial_elements, report,
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
