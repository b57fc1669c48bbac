"""Blade sections for mold design: 2-D airfoil to 3-D (Hosseini & Moetakef-Imani 2016,
§4 Eq. 5), the silhouette point S, and the two-part constrained fit with G1 at S.

Coordinates: x edgewise (tangential, the direction of rotation), y flapwise (the rotor
axis; the default mold direction), z along the span. A wrapped section lies on the
cylinder x² + z² = r² (Hosseini Fig. 4); a flat one in the plane z = r.

The two-part fit follows Hosseini §4: the section is split at S, where its tangent is
parallel to the mold direction; each half is a least-squares B-spline with its end point
and end derivative prescribed (Piegl & Tiller 2000; The NURBS Book 2e §9.4.1–9.4.2), the
derivative at S sharing one direction between the halves (G1) and its magnitude chosen by
SQP (``scipy.optimize.minimize(method="SLSQP")``) minimising the least-squares error
Eq. 3. The trailing edge is C0 (both ends interpolated), blunt or sharp.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import BSpline
from scipy.optimize import brentq, minimize

from ..errors import GeometryError
from ..nurbs import BSplineCurve, interpolate, parameterize
from ..nurbs.fitting import approximation_knots

#: Default degree of the section curves (cubic, as in Hosseini §2).
SECTION_DEGREE = 3

#: S is sought only where the section is within this chord fraction of the leading edge
#: (the leading-edge region of Hosseini Fig. 6b); elsewhere a tangent parallel to the mold
#: direction (e.g. a vertical blunt trailing edge) is not the LE parting line.
LE_REGION = 0.3

#: A mold direction whose component across the span is shorter than this (unit vector)
#: gives no silhouette: it is (nearly) parallel to the span axis.
DIRECTION_TOL = 1e-6

#: Data points closer to S than this fraction of the chord are dropped from the halves
#: (S is interpolated; a data point on top of it would repeat a parameter).
SPLIT_GAP = 1e-9

#: Lower bound of the tangent magnitude at S, as a fraction of the initial estimate, so
#: that SLSQP never proposes a cusp (zero derivative).
MIN_MAGNITUDE_FRACTION = 1e-3

#: The blade's span (pitch) axis.
SPAN_AXIS = np.array([0.0, 0.0, 1.0])

#: SLSQP stopping tolerance on the (chord-normalised) objective.
SLSQP_FTOL = 1e-14


# ---------------------------------------------------------------------------------------
# 2-D -> 3-D (Eq. 5)
# ---------------------------------------------------------------------------------------
def section_points(xy, r: float, chord: float, twist_deg: float, pitch_axis: float = 0.25,
                   prebend: float = 0.0, sweep: float = 0.0, wrap: bool = True) -> np.ndarray:
    """3-D section points from unit-chord airfoil points (Hosseini 2016, §4 Eq. 5).

    xy: (N, 2) unit chord, leading edge at the origin. The chord is scaled by c_i about the
    pitch axis (chord fraction ``pitch_axis`` from the LE), rotated by the twist Tw_i
    (R, θ of Eq. 5: (x', y') -> R(cos(θ+Tw), sin(θ+Tw))), offset by ``sweep`` (edgewise)
    and ``prebend`` (flapwise), and wrapped onto the cylinder of radius r_i:
    Q = (r sin(α/r), y, r cos(α/r)) with α = R cos(θ + Tw), an arc length (Eq. 5 writes
    sin(α); the angle is α/r, as in Pérez-Arribas & Trejo-Vargas 2012, so the wrap is an
    isometry). ``wrap=False`` gives the flat section Q = (α, y, r). Returns (N, 3).
    """
    P = np.asarray(xy, dtype=np.float64)
    xp = chord * (P[:, 0] - pitch_axis)
    yp = chord * P[:, 1]
    tw = np.radians(twist_deg)
    c, s = np.cos(tw), np.sin(tw)
    alpha = c * xp - s * yp + sweep
    y = s * xp + c * yp + prebend
    if not wrap:
        return np.column_stack([alpha, y, np.full_like(alpha, r)])
    phi = alpha / r
    return np.column_stack([r * np.sin(phi), y, r * np.cos(phi)])


def radial_directions(points, wrap: bool) -> np.ndarray:
    """Unit normals of the section's carrier surface (cylinder or plane z = r) at points."""
    P = np.asarray(points, dtype=np.float64)
    if not wrap:
        return np.broadcast_to(np.array([0.0, 0.0, 1.0]), P.shape)
    n = np.stack([P[..., 0], np.zeros(P.shape[:-1]), P[..., 2]], axis=-1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


# ---------------------------------------------------------------------------------------
# silhouette point S
# ---------------------------------------------------------------------------------------
def silhouette_function(curve: BSplineCurve, u, direction, wrap: bool) -> np.ndarray:
    """f(u) = det[C'(u), d, n(u)]: zero where the section tangent is parallel to the mold
    direction d within the carrier surface (normal n): the tangent vertical of Hosseini
    Fig. 6b. For the flat section and d in its plane it is C'_x d_y - C'_y d_x."""
    D = curve.derivatives(np.asarray(u, dtype=np.float64), 1)
    n = radial_directions(D[..., 0, :], wrap)
    return np.einsum("...i,...i->...", np.cross(D[..., 1, :], np.broadcast_to(direction, n.shape)), n)


def find_silhouette(curve: BSplineCurve, params, chordwise, direction, wrap: bool) -> float:
    """Parameter of S on the fitted section ``curve`` (Hosseini §4, Fig. 6b).

    params: data parameters; chordwise: chord fraction x of each data point (unit chord).
    The sign changes of :func:`silhouette_function` at the data parameters inside the
    leading-edge region (x < :data:`LE_REGION`) bracket the roots; the one nearest the
    leading edge (smallest x) is refined with ``brentq`` on the curve itself, not on the
    raw points. Raises GeometryError when there is none.
    """
    d = np.asarray(direction, dtype=np.float64)
    if np.linalg.norm(np.cross(d, SPAN_AXIS)) < DIRECTION_TOL * np.linalg.norm(d):
        raise GeometryError("the mold_direction gives no silhouette point: it is (nearly) along the span axis")
    f = silhouette_function(curve, params, d, wrap)
    x = np.asarray(chordwise)
    change = np.flatnonzero((np.sign(f[:-1]) != np.sign(f[1:])) & (np.minimum(x[:-1], x[1:]) < LE_REGION))
    exact = np.flatnonzero((f == 0) & (x < LE_REGION))
    if exact.size:
        return float(params[exact[np.argmin(x[exact])]])
    if not change.size:
        raise GeometryError("the mold_direction gives no silhouette point in the leading-edge region")
    k = change[np.argmin(np.minimum(x[change], x[change + 1]))]
    return float(brentq(lambda t: float(silhouette_function(curve, np.array([t]), d, wrap)[0]),
                        params[k], params[k + 1], xtol=1e-15, rtol=4 * np.finfo(float).eps))


# ---------------------------------------------------------------------------------------
# the split
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class SplitSection:
    """A section split at S.

    points: (N, 3) the section data (trailing edge upper -> LE -> trailing edge lower).
    upper: (nu, 3) from the upper TE point to S (S last); lower: (nl, 3) from S (first)
    to the lower TE point. upper_data / lower_data: index arrays of the data points in
    each half (S excluded). interpolant / u_silhouette: the C2 interpolant of the points
    the split was found on and S's parameter on it. upper_marks / lower_marks: None when
    ``upper`` / ``lower`` are the data themselves, else the rows of ``upper`` / ``lower``
    that are the data points (S excluded), in the order of upper_data / lower_data: the
    halves of :func:`densified`. tangent: unit C'(u_S) of the preliminary fit, pointing from
    the upper half into the lower one. magnitude_upper / magnitude_lower: |C'| at S scaled
    to each half's [0, 1] parameter: the initial tangent magnitudes. chord: local chord.
    """

    points: np.ndarray
    upper: np.ndarray
    lower: np.ndarray
    upper_data: np.ndarray
    lower_data: np.ndarray
    silhouette: np.ndarray
    tangent: np.ndarray
    magnitude_upper: float
    magnitude_lower: float
    chord: float
    interpolant: BSplineCurve | None = None
    u_silhouette: float = float("nan")
    upper_marks: np.ndarray | None = None
    lower_marks: np.ndarray | None = None


def split_section(points, chordwise, chord: float, direction=(0.0, 1.0, 0.0), wrap: bool = True,
                  degree: int = SECTION_DEGREE) -> SplitSection:
    """Fit the whole section (interpolation, chord-length parameters, NURBS Book Alg. A9.1),
    find S on it and split the data there (Hosseini §4)."""
    Q = np.asarray(points, dtype=np.float64)
    d = np.asarray(direction, dtype=np.float64)
    t = parameterize(Q)
    prelim = interpolate(Q, degree, params=t)
    uS = find_silhouette(prelim, t, chordwise, d, wrap)
    D = prelim.derivatives(np.array([uS]), 1)[0]
    S, dS = D[0], D[1]
    gap = SPLIT_GAP * chord
    up = np.flatnonzero((t < uS) & (np.linalg.norm(Q - S, axis=1) > gap))
    lo = np.flatnonzero((t > uS) & (np.linalg.norm(Q - S, axis=1) > gap))
    speed = float(np.linalg.norm(dS))
    return SplitSection(
        points=Q, upper=np.vstack([Q[up], S]), lower=np.vstack([S, Q[lo]]), upper_data=up, lower_data=lo,
        silhouette=S, tangent=dS / speed, magnitude_upper=speed * uS, magnitude_lower=speed * (1.0 - uS), chord=chord,
        interpolant=prelim, u_silhouette=float(uS),
    )


#: Samples per interval between consecutive data points of :func:`densified` (the data
#: points included): enough that every knot span of a common knot vector up to several
#: times as many control points as data points still holds data (Schoenberg–Whitney).
DENSE_SAMPLES = 8


def densified(split: SplitSection, samples: int = DENSE_SAMPLES) -> SplitSection:
    """The split with each half's data replaced by ``samples`` points per data interval of
    the section's C2 chord-length interpolant (``split.interpolant``, NURBS Book Alg. A9.1,
    the curve S was found on), the data points themselves among them (``upper_marks`` /
    ``lower_marks``).

    Why: Hosseini §4 fits each half to its airfoil points within the designer's tolerance
    per station; with coarse or irregular data (windIO airfoils: ~100 points a side, with
    corners and 1e-4-chord zig-zags) that tolerance needs about as many control points as
    there are points, where the least-squares problem (Eq. 3) is ill-posed: knot spans of
    the common knot vector (§3) hold no data. The interpolant is a C2 cubic through every
    data point (chord-length parameters, averaged knots: NURBS Book §9.2.1) with no
    shape of its own between them beyond the data's; a least-squares fit of its dense
    samples is well posed for any count, and its deviation is still measured at the
    original points only (:func:`~.blade.section_deviation`)."""
    if split.interpolant is None:
        raise GeometryError("the split has no interpolant to densify")
    t = parameterize(split.points)
    f = np.arange(samples) / samples

    def half(ts, first, last):
        s = np.concatenate([(a + (b - a) * f) for a, b in zip(ts[:-1], ts[1:])] + [ts[-1:]])
        P = split.interpolant.evaluate(s)
        P[0], P[-1] = first, last  # the ends bit for bit: the TE point and S
        return P

    up = half(np.concatenate([t[split.upper_data], [split.u_silhouette]]), split.upper[0], split.upper[-1])
    lo = half(np.concatenate([[split.u_silhouette], t[split.lower_data]]), split.lower[0], split.lower[-1])
    marks_u = np.arange(len(split.upper_data)) * samples
    marks_l = (np.arange(len(split.lower_data)) + 1) * samples
    return SplitSection(points=split.points, upper=up, lower=lo, upper_data=split.upper_data,
                        lower_data=split.lower_data, silhouette=split.silhouette, tangent=split.tangent,
                        magnitude_upper=split.magnitude_upper, magnitude_lower=split.magnitude_lower,
                        chord=split.chord, interpolant=split.interpolant, u_silhouette=split.u_silhouette,
                        upper_marks=marks_u, lower_marks=marks_l)


# ---------------------------------------------------------------------------------------
# constrained fits (Piegl & Tiller 2000) with the SQP magnitude
# ---------------------------------------------------------------------------------------
def _residual(curve: BSplineCurve, points, params) -> np.ndarray:
    return np.asarray(points) - curve.evaluate(params)


def _normal_equations_banded(A, R, degree: int) -> np.ndarray:
    """Least-squares solution of A X = R for a sparse B-spline collocation matrix A (each
    row has at most degree + 1 consecutive non-zeros): the normal equations AᵀA X = AᵀR
    (NURBS Book Eq. 9.66), banded with bandwidth p and symmetric positive definite when
    every column has data (Schoenberg–Whitney), solved by ``solveh_banded``. A dense
    ``lstsq`` (an SVD) costs O(m n²) per fit; this is O(m p²)."""
    from scipy.linalg import LinAlgError, solveh_banded

    M = (A.T @ A).todia()
    band = np.zeros((degree + 1, A.shape[1]))
    for off, diag in zip(M.offsets, M.data):
        if 0 <= off <= degree:
            band[degree - off, off:] = diag[off:]
    try:
        X = solveh_banded(band, A.T @ R, check_finite=False)
    except LinAlgError:
        X = None
    if X is None or not np.all(np.isfinite(X)):
        raise GeometryError("the least-squares system is rank deficient: some knot span holds no data "
                            "parameter (Schoenberg–Whitney); use fewer control points or other knots")
    return X


class _AffineHalf:
    """One half fitted with its end derivative λ·t at S: the least-squares control points
    are affine in λ (the prescribed control point P_1 or P_{n-1} of Piegl & Tiller 2000
    enters the right-hand side linearly), so the residual is r(λ) = r0 + λ g and two fits
    give the objective Σ|Q_r - C(t_r)|² (Hosseini Eq. 3) exactly as a quadratic in λ."""

    def __init__(self, points, knots, degree, tangent, at_start: bool, params=None):
        self.points = np.asarray(points, dtype=np.float64)
        self.params = parameterize(points) if params is None else np.asarray(params, dtype=np.float64)
        self.knots = np.asarray(knots, dtype=np.float64)
        self.degree = degree
        self.tangent = tangent
        self.at_start = at_start
        # the fit is affine in λ: one banded solve with two right-hand sides gives every λ
        # (control points P0 + λ dP), and one basis matrix gives every residual
        N = BSpline.design_matrix(self.params, self.knots, degree).tocsc()
        self.P0, self.dP = self._solve(N)
        self.r0 = (self.points - N @ self.P0).ravel()
        self.g = -(N @ self.dP).ravel()

    def _solve(self, N):
        """P0 and dP of the least-squares fit with P_0 = Q_0, P_n = Q_m and the derivative
        control point next to S (Piegl & Tiller 2000; NURBS Book Eqs. 9.63–9.67): the
        normal equations of the free control points (banded, bandwidth p, symmetric
        positive definite when every free basis function has data: Schoenberg–Whitney)
        by ``solveh_banded``, both right-hand sides at once."""
        Q, U, p = self.points, self.knots, self.degree
        nc = len(U) - p - 1
        n = nc - 1
        if nc < max(p + 1, 3):
            raise GeometryError(f"n_control too small: {nc} for degree {p} with an end derivative")
        if nc > len(Q):
            raise GeometryError(f"too few points: {nc} control points need at least {nc} data points, got {len(Q)}")
        P0 = np.zeros((nc, Q.shape[1]))
        dP = np.zeros_like(P0)
        P0[0], P0[n] = Q[0], Q[-1]
        if self.at_start:
            j, slope = 1, self.tangent * (U[p + 1] - U[1]) / p
            P0[1] = Q[0]
        else:
            j, slope = n - 1, -self.tangent * (U[n + p] - U[n]) / p
            P0[n - 1] = Q[-1]
        dP[j] = slope
        fixed = np.zeros(nc, dtype=bool)
        fixed[[0, j, n]] = True
        free = np.flatnonzero(~fixed)
        if free.size:
            rows = N[1:-1]
            R0 = Q[1:-1] - rows[:, fixed] @ P0[fixed]
            R1 = -(rows[:, fixed] @ dP[fixed])
            X = _normal_equations_banded(rows[:, free], np.hstack([R0, R1]), p)
            dim = Q.shape[1]
            P0[free], dP[free] = X[:, :dim], X[:, dim:]
        return P0, dP

    def _fit(self, magnitude: float) -> BSplineCurve:
        """The constrained fit with derivative magnitude λ at S: P0 + λ dP."""
        return BSplineCurve(self.degree, self.knots, self.P0 + magnitude * self.dP)

    def residuals(self, magnitude: float) -> np.ndarray:
        """(N, dim) data minus curve at the data parameters for λ."""
        return (self.r0 + magnitude * self.g).reshape(len(self.params), -1)

    def error(self, magnitude):
        r = self.r0 + magnitude * self.g
        return float(r @ r)

    def gradient(self, magnitude):
        return float(2.0 * (self.g @ (self.r0 + magnitude * self.g)))

    def best(self) -> float:
        """The unconstrained minimiser -(r0·g)/(g·g): a check on SLSQP."""
        return float(-(self.r0 @ self.g) / (self.g @ self.g))


@dataclass(frozen=True, eq=False)
class TwoPartFit:
    """Upper and lower section curves meeting at S with G1 (Hosseini §4).

    upper: TE(upper) -> S, with C'(1) = magnitude_upper · tangent; lower: S -> TE(lower),
    with C'(0) = magnitude_lower · tangent. lsq_error: Σ|Q_r - C(t_r)|² over both halves'
    data points (Eq. 3, S excluded); max_residual: largest |Q_r - C(t_r)|.
    """

    upper: BSplineCurve
    lower: BSplineCurve
    magnitude_upper: float
    magnitude_lower: float
    lsq_error: float
    max_residual: float
    slsqp_iterations: int
    #: The halves' data parameters (every row of the split's halves, S included): where
    #: the closest-point measurements start (:func:`~.blade.data_parameters`).
    params_upper: np.ndarray | None = None
    params_lower: np.ndarray | None = None


def default_knots(points, n_control: int, degree: int = SECTION_DEGREE) -> np.ndarray:
    """Chord-length parameters and approximation knots (NURBS Book Eqs. 9.5, 9.68–9.69)."""
    return approximation_knots(parameterize(points), n_control, degree)


def aligned_parameters(points, knots, degree: int = SECTION_DEGREE) -> np.ndarray:
    """Chord-length parameters of ``points`` mapped onto the knot vector ``knots``.

    The section's own approximation knots (NURBS Book Eqs. 9.68–9.69, as many as
    ``knots``) are sent onto ``knots`` by the piecewise-linear map through corresponding
    knots, and every parameter with them. Each knot span of ``knots`` then holds the data
    its own knot span held: Schoenberg–Whitney holds and the fit is as good as the
    section's own. Hosseini §3 averages the knot vectors and refits on the average; for
    sections of very different shape (a thick blunt root airfoil and a thin tip one, a
    circle and an airfoil) the plain chord-length parameters can leave a common knot span
    empty or nearly so. Used by :func:`~.blade.build_blade` when the plain fit fails."""
    t = parameterize(points)
    K = np.asarray(knots, dtype=np.float64)
    own = approximation_knots(t, len(K) - degree - 1, degree)
    a, b = own[degree: len(own) - degree], K[degree: len(K) - degree]
    keep = np.concatenate([[True], np.diff(a) > 0])
    return np.interp(t, a[keep], b[keep])


def fit_two_part(split: SplitSection, knots_upper=None, knots_lower=None, n_control: int = 12,
                 degree: int = SECTION_DEGREE, ratio: float | None = None, params_upper=None,
                 params_lower=None, magnitudes=None, cache: dict | None = None) -> TwoPartFit:
    """Two constrained least-squares fits with G1 at S and the tangent magnitudes by SQP.

    knots_upper / knots_lower: the knot vectors of the halves (e.g. the blade's common ones,
    Hosseini §3), or None for :func:`default_knots` with ``n_control`` per half. The
    magnitudes (λ_u, λ_l) of the derivative at S minimise the total least-squares error
    (Eq. 3) with ``scipy.optimize.minimize(method="SLSQP")``, bounded below by
    :data:`MIN_MAGNITUDE_FRACTION` of the preliminary fit's. ``ratio``: if given, the
    equality constraint λ_u = ratio · λ_l, which a blade needs so that the halves' cross
    derivatives stay parallel between its stations (G1 along the whole parting line).
    params_upper / params_lower: the halves' data parameters (default chord length; see
    :func:`aligned_parameters`). magnitudes: (λ_u, λ_l) set by hand instead of by SQP
    (the tangent magnitude at S of Hosseini Fig. 7a, in units of the halves' parameters).
    cache: a dict kept by the caller for refits of the same split on the same knots and
    parameters (a blade's free, then constrained fits): the two halves' least-squares
    solutions, which do not depend on the magnitudes, are solved once.
    """
    if cache is not None and "halves" in cache:
        up, lo = cache["halves"]
    else:
        Ku = default_knots(split.upper, n_control, degree) if knots_upper is None else np.asarray(knots_upper)
        Kl = default_knots(split.lower, n_control, degree) if knots_lower is None else np.asarray(knots_lower)
        up = _AffineHalf(split.upper, Ku, degree, split.tangent, at_start=False, params=params_upper)
        lo = _AffineHalf(split.lower, Kl, degree, split.tangent, at_start=True, params=params_lower)
        if cache is not None:
            cache["halves"] = (up, lo)
    if magnitudes is not None:
        lam_u, lam_l = (float(x) for x in magnitudes)
        if not (lam_u > 0 and lam_l > 0 and np.isfinite(lam_u) and np.isfinite(lam_l)):
            raise GeometryError(f"the tangent magnitudes at S must be positive and finite, got {magnitudes!r}")
        return _finish(up, lo, split, lam_u, lam_l, 0)
    scale = np.array([split.magnitude_upper, split.magnitude_lower])
    norm = split.chord**2

    def objective(x):
        lam = x * scale
        return (up.error(lam[0]) + lo.error(lam[1])) / norm

    def gradient(x):
        lam = x * scale
        return np.array([up.gradient(lam[0]), lo.gradient(lam[1])]) * scale / norm

    constraints = ()
    if ratio is not None:
        a = np.array([scale[0], -ratio * scale[1]])
        constraints = ({"type": "eq", "fun": lambda x: float(a @ x), "jac": lambda x: a},)
    result = minimize(objective, np.ones(2), jac=gradient, method="SLSQP",
                      bounds=[(MIN_MAGNITUDE_FRACTION, None)] * 2, constraints=constraints,
                      options={"ftol": SLSQP_FTOL, "maxiter": 200})
    lam_u, lam_l = result.x * scale
    return _finish(up, lo, split, float(lam_u), float(lam_l), int(result.nit))


def _finish(up: _AffineHalf, lo: _AffineHalf, split: SplitSection, lam_u: float, lam_l: float,
            iterations: int) -> TwoPartFit:
    cu, cl = up._fit(lam_u), lo._fit(lam_l)
    # at the data points only (S, interpolated, excluded; densified halves: their marks)
    ru, rl = up.residuals(lam_u), lo.residuals(lam_l)
    ru = ru[:-1] if split.upper_marks is None else ru[split.upper_marks]
    rl = rl[1:] if split.lower_marks is None else rl[split.lower_marks]
    err = float(np.sum(ru**2) + np.sum(rl**2))
    mx = float(max(np.linalg.norm(ru, axis=1).max(), np.linalg.norm(rl, axis=1).max()))
    return TwoPartFit(cu, cl, float(lam_u), float(lam_l), err, mx, iterations, up.params, lo.params)


@dataclass(frozen=True, eq=False)
class SingleFit:
    """The traditional single-curve fit of a whole section (TE -> LE -> TE), C0 at the TE."""

    curve: BSplineCurve
    lsq_error: float
    max_residual: float


def fit_single(points, knots=None, n_control: int = 23, degree: int = SECTION_DEGREE,
               align: bool = False, marks=None) -> SingleFit:
    """Least-squares fit of the whole section, ends interpolated (NURBS Book §9.4.1), on
    ``knots`` or the approximation knots for ``n_control`` (Eqs. 9.68–9.69); ``align``:
    the parameters of :func:`aligned_parameters`. marks: the rows of ``points`` that are
    data points (densified sections, :func:`densified_section`): the errors are measured
    there only; default all."""
    Q = np.asarray(points, dtype=np.float64)
    t = parameterize(Q)
    K = approximation_knots(t, n_control, degree) if knots is None else np.asarray(knots)
    if align:
        t = aligned_parameters(Q, K, degree)
    nc = len(K) - degree - 1
    if nc < degree + 1 or nc > len(Q):
        raise GeometryError(f"{nc} control points of degree {degree} need between {degree + 1} and {len(Q)} "
                            f"(the data points)")
    # the ends interpolated, the rest by least squares (NURBS Book §9.4.1), banded normal equations
    N = BSpline.design_matrix(t, K, degree).tocsc()
    P = np.zeros((nc, Q.shape[1]))
    P[0], P[-1] = Q[0], Q[-1]
    rows = N[1:-1]
    if nc > 2:
        R = Q[1:-1] - rows[:, [0, nc - 1]] @ P[[0, -1]]
        P[1:-1] = _normal_equations_banded(rows[:, 1:-1], R, degree)
    c = BSplineCurve(degree, K, P)
    r = _residual(c, Q, t)
    if marks is not None:
        r = r[marks]
    return SingleFit(c, float(np.sum(r**2)), float(np.linalg.norm(r, axis=1).max()))


def densified_section(split: SplitSection) -> tuple[np.ndarray, np.ndarray]:
    """(points, marks) of the whole densified section (:func:`densified`): upper half then
    lower half without its repeated S; marks: the rows that are data points."""
    if split.upper_marks is None:
        return split.points, np.arange(len(split.points))
    P = np.vstack([split.upper, split.lower[1:]])
    marks = np.concatenate([split.upper_marks, len(split.upper) - 1 + split.lower_marks])
    return P, marks
