"""Mold halves of a wind-turbine blade (Hosseini & Moetakef-Imani 2016, §3–§5.1).

Pipeline (:func:`build_blade`):

1. sections in 3-D (Eq. 5) and the silhouette split at S (§4, :mod:`.sections`);
2. a common knot vector per half by averaging the sections' knot vectors (§3; NURBS Book
   Eqs. 9.68–9.69 per section), every section refitted on it with its G1 constraint at S
   and the tangent magnitudes by SLSQP, the control-point count raised until every
   section is within the tolerance of its points;
3. skinning of the columns of control points into the upper and lower mold surfaces
   (§5; NURBS Book §10.3), with one set of section parameters for both halves;
4. the structural-zone root transition per half (§5.1), G1 in v with the aerodynamic
   surface;
5. the traditional single surface on the same stations, for comparison;
6. fairness (§5 Eq. 6) and the continuity and tolerance measurements.

G1 along the whole LE parting line: at each station the halves' derivatives at S are
λ_u t and λ_l t. Skinning is linear in the control points, so between stations the
cross-boundary derivatives stay parallel only if λ_u / λ_l is one ratio ρ for all
stations; the fits are therefore done twice: free (per-station optimum), then with the
SLSQP equality constraint λ_u = ρ λ_l, ρ the geometric mean of the free ratios.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import BladesmithError, GeometryError
from ..nurbs import BSplineCurve, BSplineSurface, interpolate, skin
from ..nurbs.fitting import approximation_knots, parameterize
from ..nurbs.local_projection import closest_points_near
from ..nurbs.projection import closest_point_curve
from ..nurbs.skinning import skin_parameters
from .definition import BladeDefinition
from .sections import (
    SECTION_DEGREE,
    SplitSection,
    TwoPartFit,
    aligned_parameters,
    default_knots,
    densified,
    densified_section,
    fit_single,
    fit_two_part,
    section_points,
    split_section,
)

#: Upper limit of the control points per half when raising them to meet the tolerance.
MAX_CONTROL_POINTS = 60
#: Upper limit of the control points per half of the densified fit (:func:`_fit_dense`).
MAX_DENSE_CONTROL_POINTS = 160
#: Step of the control-point count between attempts.
CONTROL_POINT_STEP = 2
#: Samples per knot span for the parting-line continuity measurements.
CONTINUITY_SAMPLES_PER_SPAN = 8


@dataclass
class StationReport:
    """Per station: the two-part and single fits' least-squares errors (Eq. 3), the tangent
    magnitudes at S, and the largest closest-point distance of the station's points to the
    skinned surface's section, as a fraction of the chord."""

    index: int
    r: float
    chord: float
    lsq_two_part: float
    lsq_single: float
    magnitude_upper: float
    magnitude_lower: float
    deviation_two_part: float = float("nan")


@dataclass
class BladeMolds:
    """Everything :func:`build_blade` makes. Surfaces have u along the section (upper:
    TE -> S; lower: S -> TE; single: TE upper -> LE -> TE lower) and v root -> tip."""

    definition: BladeDefinition
    upper: BSplineSurface
    lower: BSplineSurface
    single: BSplineSurface | None
    transition_upper: BSplineSurface | None
    transition_lower: BSplineSurface | None
    parting_lines: dict
    stations: list
    control_points: int
    ratio: float
    section_params: np.ndarray
    fairness: dict = field(default_factory=dict)
    continuity: dict = field(default_factory=dict)
    times: dict = field(default_factory=dict)
    #: The fits used :func:`.sections.aligned_parameters` (the plain chord-length ones failed).
    aligned_parameters: bool = False
    #: Per station: the tolerance (chord fraction) it was fitted to.
    tolerances: np.ndarray | None = None
    #: The fits approximate each section's interpolant (:func:`.sections.densified`) on a
    #: knot vector refined where a station missed its tolerance (:func:`_fit_dense`).
    densified: bool = False

    @property
    def surfaces(self) -> dict:
        """The mold surfaces by name; a blunt trailing edge adds its ruled base surfaces
        (lower TE edge -> upper TE edge, degree 1 across), which close the shell."""
        out = {"upper": self.upper, "lower": self.lower}
        if self.transition_upper is not None:
            out["transition_upper"] = self.transition_upper
            out["transition_lower"] = self.transition_lower
        pairs = [("trailing_edge", self.upper, self.lower)]
        if self.transition_upper is not None:
            pairs.append(("transition_trailing_edge", self.transition_upper, self.transition_lower))
        for name, up, lo in pairs:
            for j, base in enumerate(trailing_edge_surfaces(up, lo)):
                out[name if j == 0 else f"{name}_{j + 1}"] = base
        return out


def _station_error(k: int, station, exc: Exception) -> GeometryError:
    return GeometryError(f"station {k} (r = {station.r:g} m, airfoil {station.airfoil_name or station.airfoil.name!r}): {exc}")


def blade_sections(defn: BladeDefinition, degree: int = SECTION_DEGREE) -> list[SplitSection]:
    """3-D points (Eq. 5) of every station split at its silhouette point S.

    Only the aerodynamic stations are wrapped onto their cylinders (when ``defn.wrap``):
    the structural-zone stations before ``first_aerodynamic_station`` stay flat, so the
    root stays the circle the root flange is machined to (a 3.5 m chord wrapped on a
    1.5 m cylinder would not be one)."""
    out = []
    for k, st in enumerate(defn.stations):
        xy = st.airfoil.outline
        wrap = defn.wrap and k >= defn.first_aerodynamic_station
        Q = section_points(xy, st.r, st.chord, st.twist_deg, st.pitch_axis, st.prebend, st.sweep, wrap)
        try:
            out.append(split_section(Q, xy[:, 0], st.chord, defn.mold_direction, wrap, degree))
        except BladesmithError as exc:
            raise _station_error(k, st, exc) from None
    return out


def common_knots(point_sets, n_control: int, degree: int = SECTION_DEGREE) -> np.ndarray:
    """The average of the sections' knot vectors (Hosseini §3): each from its chord-length
    parameters by NURBS Book Eqs. 9.68–9.69, all of the same length."""
    return np.mean([default_knots(P, n_control, degree) for P in point_sets], axis=0)


class StationFitError(GeometryError):
    """A section that cannot be fitted on the common knots: ``station`` is its index."""

    def __init__(self, message: str, station: int):
        super().__init__(message)
        self.station = station


def _fit_all(splits, aero, n, degree, defn, align: bool = False, magnitudes=None, knots=None):
    """Every section on the common knots (Hosseini §3) with G1 at S (§4): free SQP fits of
    the aero sections give the ratio ρ, then all are refitted with λ_u = ρ λ_l. align:
    parameters of :func:`.sections.aligned_parameters`. magnitudes: (λ_u, λ_l) by hand, in
    chords (each station's derivative at S is λ × its chord). knots: (upper, lower) knot
    vectors instead of the averaged ones for ``n``."""
    if knots is None:
        Ku = common_knots([splits[k].upper for k in aero], n, degree)
        Kl = common_knots([splits[k].lower for k in aero], n, degree)
    else:
        Ku, Kl = (np.asarray(K, dtype=np.float64) for K in knots)

    def params(k):
        if not align:
            return {}
        return {"params_upper": aligned_parameters(splits[k].upper, Ku, degree),
                "params_lower": aligned_parameters(splits[k].lower, Kl, degree)}

    halves = {}  # per station: the halves' solutions, shared by its free and constrained fits

    def fit(k, **kw):
        try:
            return fit_two_part(splits[k], Ku, Kl, degree=degree, **params(k), **kw, cache=halves.setdefault(k, {}))
        except BladesmithError as exc:
            st = defn.stations[k]
            raise StationFitError(f"station {k} (r = {st.r:g} m, airfoil {st.airfoil_name or st.airfoil.name!r}): "
                                  f"{exc}", k) from None

    if magnitudes is not None:  # by hand, in chords: one ratio for every station (G1 along the LE)
        fits = [fit(k, magnitudes=(magnitudes[0] * splits[k].chord, magnitudes[1] * splits[k].chord))
                for k in range(len(splits))]
        return fits, magnitudes[0] / magnitudes[1]
    ratios = []
    for k in aero:
        f = fit(k)
        ratios.append(f.magnitude_upper / f.magnitude_lower)
    rho = float(np.exp(np.mean(np.log(ratios))))
    return [fit(k, ratio=rho) for k in range(len(splits))], rho


def data_parameters(split: SplitSection, fit: TwoPartFit) -> tuple[np.ndarray, np.ndarray]:
    """The parameters the fit gave the section's data points (upper_data, lower_data
    order) on its two halves: where their closest points are sought first."""
    nu, nl = len(split.upper_data), len(split.lower_data)
    pu, pl = fit.params_upper, fit.params_lower
    if split.upper_marks is not None and pu is not None and pl is not None:
        return pu[split.upper_marks], pl[split.lower_marks]
    if pu is not None and pl is not None and len(pu) == nu + 1 and len(pl) == nl + 1:
        return pu[:-1], pl[1:]  # S (interpolated) is the last row of upper, the first of lower
    if pu is not None and pl is not None and nu and nl and (len(pu) - 1) % nu == 0 and (len(pl) - 1) % nl == 0:
        # fitted to the densified halves (:func:`.sections.densified`): every samples-th row
        su, sl = (len(pu) - 1) // nu, (len(pl) - 1) // nl
        return pu[np.arange(nu) * su], pl[(np.arange(nl) + 1) * sl]
    # no fit parameters: evenly along each half (a start only; the search is global)
    return np.linspace(0.0, 1.0, nu + 1)[:-1], np.linspace(0.0, 1.0, nl + 1)[1:]


def _closest_distances(pairs) -> list[np.ndarray]:
    """Closest-point distances of each (curve, points, guess) of ``pairs``, all in one
    pass (:func:`..nurbs.local_projection.closest_points_near`, certified global)."""
    counts = [len(P) for _, P, _ in pairs]
    _, d = closest_points_near([c for c, _, _ in pairs], np.concatenate([P for _, P, _ in pairs]),
                               np.concatenate([g for _, _, g in pairs]), np.repeat(np.arange(len(pairs)), counts))
    return np.split(d, np.cumsum(counts)[:-1])


def section_deviation(split: SplitSection, fit: TwoPartFit) -> float:
    """Largest closest-point distance of the section's data to its two fitted halves,
    as a fraction of the chord."""
    gu, gl = data_parameters(split, fit)
    du, dl = _closest_distances([(fit.upper, split.points[split.upper_data], gu),
                                 (fit.lower, split.points[split.lower_data], gl)])
    return float(max(du.max(), dl.max()) / split.chord)


def section_parameters(nets) -> np.ndarray:
    """v̄_k shared by both halves: chord-length parameters of every column of control points
    across the sections, averaged over the columns of both halves (NURBS Book §10.3)."""
    cols = np.concatenate(nets, axis=1)  # (K, columns, 3)
    steps = np.linalg.norm(np.diff(cols, axis=0), axis=2)
    frac = np.cumsum(steps, axis=0) / steps.sum(axis=0)
    v = np.concatenate([[0.0], frac.mean(axis=1)])
    v[-1] = 1.0
    return v


def root_transition(root_nets, aero: BSplineSurface, w, scale: float, degree_w: int = 3) -> BSplineSurface:
    """Structural-zone surface from the root sections to the first airfoil (Hosseini §5.1).

    root_nets: (K, n, 3) control points of the root sections on the aerodynamic surface's
    u knots, the last one the first aerodynamic section (= aero's v = 0 row). Each column
    is interpolated across w (NURBS Book Alg. A9.1 with an end derivative, §9.2.2) with
    the end derivative ``scale`` times the aero column's v-derivative coefficient
    q/(v_{q+1} - v_0) (P_{i,1} - P_{i,0}), so T(u, 1) = S(u, 0) and
    T_w(u, 1) = scale · S_v(u, 0): G1 (indeed C1 up to the factor) in v across the joint.
    ``scale`` ≈ (span of the transition) / (span of the aero surface) keeps the speeds alike.
    """
    K = root_nets.shape[0]
    q = min(degree_w, K)
    V, P = aero.knots_v, aero.control_points
    D = scale * aero.degree_v / (V[aero.degree_v + 1] - V[0]) * (P[:, 1] - P[:, 0])
    # every column on the same parameters and knots: one banded system, a right-hand side
    # column per coordinate of every column (LAPACK solves them independently)
    n = root_nets.shape[1]
    cols = interpolate(root_nets.reshape(K, -1), q, params=w, end_derivative=D.reshape(-1))
    net = np.ascontiguousarray(cols.control_points.reshape(-1, n, root_nets.shape[2]).transpose(1, 0, 2))
    # the end rows are the root section and the first airfoil (shared with the aero surface):
    # the banded solve with the derivative row reproduces them only to rounding
    net[:, 0], net[:, -1] = root_nets[0], P[:, 0]
    return BSplineSurface(aero.degree_u, q, aero.knots_u, cols.knots, net)


#: Two independently solved copies of a shared row may differ by round-off only; more
#: than this (relative to the surface size) means they are not the same row at all.
SHARED_ROW_TOL = 1e-12


def _with_row(surface: BSplineSurface, index, row: np.ndarray) -> BSplineSurface:
    net = surface.control_points.copy()
    size = max(surface.size(), 1.0)
    if np.abs(net[index] - row).max() > SHARED_ROW_TOL * size:
        raise GeometryError(f"a shared mold edge differs by {np.abs(net[index] - row).max():.3g} between its surfaces")
    net[index] = row
    return BSplineSurface(surface.degree_u, surface.degree_v, surface.knots_u, surface.knots_v, net, surface.weights)


def share_mold_edges(upper, lower, tr_u=None, tr_l=None):
    """Make every edge two mold surfaces share one array, copied (ARCHITECTURE: shared
    means shared). The LE parting line is upper's last u row, copied into lower's first;
    the joint of a root transition (w = 1) is the aero half's v = 0 column, copied into
    the transition; the transitions' parting line likewise. Each copy replaces a row that
    was solved separately and agrees to round-off only (checked against
    :data:`SHARED_ROW_TOL`), which differs between CPUs and BLAS kernels."""
    lower = _with_row(lower, 0, upper.control_points[-1].copy())
    if tr_u is not None:
        tr_u = _with_row(tr_u, (slice(None), -1), upper.control_points[:, 0].copy())
        tr_l = _with_row(tr_l, (slice(None), -1), lower.control_points[:, 0].copy())
        tr_l = _with_row(tr_l, 0, tr_u.control_points[-1].copy())
    return upper, lower, tr_u, tr_l


#: Trailing-edge edges closer than this everywhere (relative to the surface size) are one
#: edge: the trailing edge is sharp and needs no base surface.
SHARP_TE_TOL = 1e-12

#: Control points of the trailing-edge thickness spline shorter than this (relative to the
#: blade size) are the rounding of a zero thickness: they are set to exactly zero, so the
#: halves of a sharp trailing edge share their edge bit for bit.
TE_ZERO_TOL = 1e-12


def trailing_edge_thickness_spline(params, thickness, degree: int, end_derivative=None) -> BSplineCurve:
    """The trailing-edge thickness vector T(v) = upper TE - lower TE between the stations,
    as a B-spline of ``degree`` that keeps the sign of its data: the shape-preserving C1
    cubic Hermite interpolant (Fritsch & Carlson 1980; the derivatives of
    ``scipy.interpolate.PchipInterpolator``, per component) written in Bezier form on the
    station parameters (knots of multiplicity 2) and degree-elevated to ``degree``
    (NURBS Book Alg. A5.9); piecewise linear when ``degree`` < 3.

    Why: the skinning of Hosseini §5 (NURBS Book §10.3) interpolates every column of
    control points with one C2 spline, a global interpolant. Where the thickness jumps
    from a blunt airfoil to a sharp one (NREL 5-MW: 12.6 mm at r = 40.45 m, 0 from
    44.55 m) it rings, and between the sharp stations the two halves cross. The Hermite
    interpolant stays, in each component, within the range of its two neighbouring station
    values: exactly zero between two sharp stations, never of the other sign between blunt
    ones. ``end_derivative``: T'(params[-1]) when given (the root transition meets the
    aerodynamic surface G1 along its trailing edge too).
    """
    from scipy.interpolate import PchipInterpolator

    from ..nurbs.operations import elevate_degree

    v = np.asarray(params, dtype=np.float64)
    d = np.asarray(thickness, dtype=np.float64)
    if degree < 3:
        curve = BSplineCurve(1, np.concatenate([[v[0]], v, [v[-1]]]), d)
        return elevate_degree(curve, degree - 1) if degree > 1 else curve
    m = PchipInterpolator(v, d, axis=0).derivative()(v)
    if end_derivative is not None:
        m[-1] = end_derivative
    h = np.diff(v)[:, None]
    inner = np.empty((2 * (len(v) - 1), d.shape[1]))
    inner[0::2] = d[:-1] + h * m[:-1] / 3.0  # second Bezier point of each segment
    inner[1::2] = d[1:] - h * m[1:] / 3.0  # third
    cps = np.vstack([d[:1], inner, d[-1:]])
    knots = np.concatenate([[v[0]] * 4, np.repeat(v[1:-1], 2), [v[-1]] * 4])
    return elevate_degree(BSplineCurve(3, knots, cps), degree - 3) if degree > 3 else BSplineCurve(3, knots, cps)


def _missing_knots(have: np.ndarray, want: np.ndarray) -> list[float]:
    """The knots of ``want`` not in ``have``, counted with multiplicity (sorted)."""
    out = []
    for value in np.unique(want):
        out += [float(value)] * max(0, int(np.count_nonzero(want == value)) - int(np.count_nonzero(have == value)))
    return out


def shape_preserving_trailing_edge(upper: BSplineSurface, lower: BSplineSurface, params, thickness,
                                   end_derivative=None) -> tuple[BSplineSurface, BSplineSurface]:
    """The skinned halves with a trailing edge that never folds (issue 19, item 1).

    ``thickness``: (K, 3) upper TE point - lower TE point at the K stations (parameters
    ``params``). T(v) of :func:`trailing_edge_thickness_spline` and the two halves are
    brought onto one knot vector by knot insertion (NURBS Book Alg. A5.4; nothing moves):
    the halves gain the station parameters as double knots, T gains the skinning knots.
    The lower half's TE column becomes the upper half's minus T's control points. Every
    other column keeps its C2 skinning curve, and the lower TE edge still passes through
    the station points; only it is C1 (not C2) at the stations. Thickness control points
    below :data:`TE_ZERO_TOL` × size are set to zero, so a sharp stretch is one edge.
    A blade sharp at every station is returned unchanged.
    """
    from ..nurbs.operations import refine_knots, refine_knots_surface

    d = np.asarray(thickness, dtype=np.float64)
    size = max(upper.size(), lower.size())
    if np.all(np.linalg.norm(d, axis=1) <= SHARP_TE_TOL * size):
        return upper, lower
    T = trailing_edge_thickness_spline(params, d, upper.degree_v, end_derivative)
    to_surface = _missing_knots(upper.knots_v, T.knots)
    to_thickness = _missing_knots(T.knots, upper.knots_v)
    up = refine_knots_surface(upper, "v", to_surface) if to_surface else upper
    lo = refine_knots_surface(lower, "v", to_surface) if to_surface else lower
    T = refine_knots(T, to_thickness) if to_thickness else T
    if T.knots.shape != up.knots_v.shape or np.any(T.knots != up.knots_v):
        raise GeometryError("the trailing-edge thickness spline and the mold halves ended on different knots")
    coeffs = np.array(T.control_points)
    coeffs[np.linalg.norm(coeffs, axis=1) <= TE_ZERO_TOL * size] = 0.0
    # the end rows are the first and last sections (shared with the root transition and
    # the caps): knot insertion reproduces them only to rounding, so copy them back
    Pu = up.control_points.copy()
    Pu[:, 0], Pu[:, -1] = upper.control_points[:, 0], upper.control_points[:, -1]
    P = lo.control_points.copy()
    P[-1] = Pu[0] - coeffs
    P[:, 0], P[:, -1] = lower.control_points[:, 0], lower.control_points[:, -1]
    P[0] = Pu[-1]  # the LE parting line: one array for both halves
    return (BSplineSurface(up.degree_u, up.degree_v, up.knots_u, up.knots_v, Pu),
            BSplineSurface(lo.degree_u, lo.degree_v, lo.knots_u, up.knots_v, P))


def trailing_edge_pieces(upper: BSplineSurface, lower: BSplineSurface) -> list[tuple[float, float]]:
    """The v intervals where the trailing edge is blunt (its two edges apart): maximal runs
    of knot spans whose thickness control points are not all zero."""
    diff = np.linalg.norm(upper.control_points[0] - lower.control_points[-1], axis=1)
    tol = SHARP_TE_TOL * upper.size()
    W, q = upper.knots_v, upper.degree_v
    pieces = []
    for s in range(q, len(W) - q - 1):
        if W[s + 1] <= W[s]:
            continue
        blunt = bool(np.any(diff[s - q: s + 1] > tol))
        if blunt and pieces and pieces[-1][1] == W[s]:
            pieces[-1] = (pieces[-1][0], float(W[s + 1]))
        elif blunt:
            pieces.append((float(W[s]), float(W[s + 1])))
    return pieces


def trailing_edge_surfaces(upper: BSplineSurface, lower: BSplineSurface) -> list[BSplineSurface]:
    """The ruled bases of a blunt trailing edge between lower(1, v) and upper(0, v) (both
    halves share v knots; degree 1 across), one per blunt stretch of the span; none where
    the edges coincide (sharp TE, the halves join C0 along one edge)."""
    from ..nurbs.operations import split_surface

    a, b = lower.control_points[-1], upper.control_points[0]
    if np.linalg.norm(a - b, axis=1).max() <= SHARP_TE_TOL * upper.size():
        return []
    ruled = BSplineSurface(1, upper.degree_v, np.array([0.0, 0.0, 1.0, 1.0]), upper.knots_v, np.stack([a, b]))
    v0, v1 = upper.knots_v[0], upper.knots_v[-1]
    out = []
    for lo_v, hi_v in trailing_edge_pieces(upper, lower):
        piece = ruled
        if hi_v < v1:
            piece = split_surface(piece, "v", hi_v)[0]
        if lo_v > v0:
            piece = split_surface(piece, "v", lo_v)[1]
        out.append(piece)
    return out


def trailing_edge_surface(upper: BSplineSurface, lower: BSplineSurface) -> BSplineSurface | None:
    """The first ruled base of :func:`trailing_edge_surfaces`, or None (sharp TE)."""
    pieces = trailing_edge_surfaces(upper, lower)
    return pieces[0] if pieces else None


def _te_start_derivative(upper: BSplineSurface, lower: BSplineSurface, scale: float) -> np.ndarray:
    """scale · d/dv (upper TE - lower TE) at v = 0: the clamped end derivative
    q / (v_{q+1} - v_0) (P_1 - P_0) of both TE columns."""
    V, q = upper.knots_v, upper.degree_v
    du = upper.control_points[0, 1] - upper.control_points[0, 0]
    dl = lower.control_points[-1, 1] - lower.control_points[-1, 0]
    return scale * q / (V[q + 1] - V[0]) * (du - dl)


def _angle_deg(a, b) -> np.ndarray:
    c = np.abs(np.einsum("...i,...i->...", a, b)) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1))
    s = np.linalg.norm(np.cross(a, b), axis=-1) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1))
    return np.degrees(np.arctan2(s, c))


def _span_samples(knots, degree, per_span=CONTINUITY_SAMPLES_PER_SPAN) -> np.ndarray:
    br = np.unique(knots)
    t = (br[:-1, None] + np.diff(br)[:, None] * np.arange(per_span)[None, :] / per_span).ravel()
    return np.concatenate([t, br[-1:]])


def parting_line_continuity(upper: BSplineSurface, lower: BSplineSurface) -> tuple[float, float]:
    """Largest gap |upper(1, v) - lower(0, v)| and normal angle (degrees) along the LE
    parting line, sampled per knot span of v."""
    v = _span_samples(upper.knots_v, upper.degree_v)
    gap = np.linalg.norm(upper.evaluate(1.0, v) - lower.evaluate(0.0, v), axis=1).max()
    ang = _angle_deg(upper.normal(1.0, v), lower.normal(0.0, v)).max()
    return float(gap), float(ang)


def joint_continuity(transition: BSplineSurface, aero: BSplineSurface) -> tuple[float, float]:
    """Gap and normal angle (degrees) where the root transition (w = 1) meets the aero
    surface (v = 0), sampled per knot span of u."""
    u = _span_samples(aero.knots_u, aero.degree_u)
    gap = np.linalg.norm(transition.evaluate(u, 1.0) - aero.evaluate(u, 0.0), axis=1).max()
    ang = _angle_deg(transition.normal(u, 1.0), aero.normal(u, 0.0)).max()
    return float(gap), float(ang)


def _deviations(splits, fits, chords, tols) -> np.ndarray:
    """Per station: the largest distance of its points to its fitted halves / chord.
    |Q_r - C(t_r)| bounds the closest-point distance from above; the latter is measured
    only where the bound misses the tolerance, worst bound first, and no further once one
    station really misses it (the others keep their bounds: the attempt fails anyway)."""
    worst = np.array([f.max_residual for f in fits]) / chords
    for k in np.argsort(-(worst / tols)):
        if worst[k] <= tols[k]:
            break
        worst[k] = section_deviation(splits[k], fits[k])
        if worst[k] > tols[k]:
            break
    return worst


def _why(defn: BladeDefinition, k: int) -> str:
    """What makes station k hard, from its neighbours (for the refusal message)."""
    st = defn.stations
    notes = []
    for j in (k - 1, k + 1):
        if 0 <= j < len(st):
            ratio = max(st[j].chord, st[k].chord) / min(st[j].chord, st[k].chord)
            circle = (st[j].airfoil_name == "circle") != (st[k].airfoil_name == "circle")
            if ratio >= 2.0 or circle:
                notes.append(f"station {j} has chord {st[j].chord:g} m ({ratio:.2g}x)"
                             + (", one of the two is the root circle" if circle else ""))
    if k < defn.first_aerodynamic_station:
        notes.append("it lies in the root transition (structural zone), fitted on the aerodynamic zone's knots")
    te = st[k].airfoil.trailing_edge_thickness
    if te > 0.02:
        notes.append(f"its trailing edge is {te:.3g} chord thick")
    return "; ".join(notes)


_MODE_NOTE = {True: ", aligned parameters", "dense": ", densified data, refined knots"}


def _no_fit_message(defn: BladeDefinition, attempts: list, tols: np.ndarray) -> str:
    """Which station, why, and the nearest setting that builds (issue 19, item 2)."""
    measured = [a for a in attempts if a[2] is not None]
    if measured:
        n, align, worst, _ = min(measured, key=lambda a: float(np.max(a[2] / tols)))
        k = int(np.argmax(worst / tols))
        st = defn.stations[k]
        why = _why(defn, k)
        reach = float(np.max(worst / tols))
        msg = (f"station {k} (r = {st.r:g} m, airfoil {st.airfoil_name or st.airfoil.name!r}) cannot be fitted within "
               f"its tolerance {tols[k]:g} chord: the best fit ({n} control points per half"
               f"{_MODE_NOTE.get(align, '')}) deviates {worst[k]:.3g} chord")
        if why:
            msg += f" ({why})"
        fixes = [f"tolerance = {float(np.max(worst)) * 1.01:.2g} (or this station's tolerance {worst[k] * 1.01:.2g}) "
                 + ("(the densified fit starts again from the count the plain fit reaches)" if align == "dense"
                    else f"with control_points = {n}")]
        if k == defn.first_aerodynamic_station and k + 1 < len(defn.stations) - 1:
            fixes.append(f"first_aerodynamic_station = {k + 1} (station {k} in the root transition)")
        return msg + "; nearest setting that builds: " + " or ".join(fixes) + f" (worst/tolerance {reach:.3g})"
    n, align, _, exc = attempts[-1]
    k = getattr(exc, "station", None)
    fixes = f"control_points = {max(MIN_SECTION_CONTROL_POINTS, n - 2 * CONTROL_POINT_STEP)}"
    if k is not None and k + 1 < len(defn.stations) - 1:
        fixes += f" or first_aerodynamic_station = {k + 1}"
    return f"no fit with {n} control points per half: {exc}; nearest setting to try: {fixes}"


#: The fewest control points per half a section fit is tried with.
MIN_SECTION_CONTROL_POINTS = 5


#: The aligned parameters are tried at a count only when the plain fit failed or came
#: within this factor of the tolerance.
ALIGN_RATIO = 4.0
#: The largest raise of the control-point count between two attempts.
MAX_CONTROL_POINT_JUMP = 8 * CONTROL_POINT_STEP


def _next_step(n: int, attempts: list) -> int:
    """How many control points to add after a failed count n: the least-squares error of
    a cubic fit to smooth data falls about as n^-4 (Hosseini Fig. 5), so the count that
    meets the tolerance is about n (worst / tolerance)^(1/4); a multiple of
    :data:`CONTROL_POINT_STEP`, between one and :data:`MAX_CONTROL_POINT_JUMP`."""
    ratios = [float(np.max(a[2] / a[3])) for a in attempts if a[0] == n and a[2] is not None]
    if not ratios:
        return CONTROL_POINT_STEP
    want = n * min(ratios) ** 0.25 - n
    steps = int(np.ceil(max(want, 1.0) / CONTROL_POINT_STEP))
    return int(min(MAX_CONTROL_POINT_JUMP, steps * CONTROL_POINT_STEP))


def _refined_knots(splits, fits, knots, tols, chords, degree):
    """(upper, lower) knot vectors with the midpoint of every knot span that holds a data
    point farther than its station's tolerance from its fitted half inserted (one common
    insertion for all stations, so the sections stay compatible, Hosseini §3). The
    error-bounded approximation of NURBS Book §9.4.1 places knots where the error is;
    here the spans with misses are halved."""
    new = ([], [])
    for k, (sp, f) in enumerate(zip(splits, fits)):
        tol = tols[k] * chords[k]
        if f.max_residual <= tol:
            continue
        for h, (curve, P, marks) in enumerate(((f.upper, sp.upper, sp.upper_marks), (f.lower, sp.lower, sp.lower_marks))):
            K = knots[h]
            t = parameterize(P)[marks]
            d = closest_point_curve(curve, P[marks])[1]
            spans = np.clip(np.searchsorted(K, t[d > tol], side="right") - 1, degree, len(K) - degree - 2)
            new[h].extend(0.5 * (K[spans] + K[spans + 1]))
    return tuple(np.sort(np.concatenate([K, np.unique(x)])) for K, x in zip(knots, new))


def _fit_dense(defn: BladeDefinition, splits, n: int, tols: np.ndarray, degree: int, magnitudes, attempts: list):
    """The fallback of :func:`fit_sections` when the data cannot carry the control points
    the tolerance needs: every section replaced by samples of its C2 interpolant
    (:func:`.sections.densified`; the deviation still measured at the original points),
    the averaged knots for ``n`` (Hosseini §3), then the spans where a station misses its
    tolerance halved (:func:`_refined_knots`) until every station is within it or the
    count reaches :data:`MAX_DENSE_CONTROL_POINTS`. Returns (fits, ρ, count) or None."""
    dense = [densified(s) for s in splits]
    aero = list(range(defn.first_aerodynamic_station, len(defn.stations)))
    chords = np.array([s.chord for s in defn.stations])
    knots = (common_knots([dense[k].upper for k in aero], n, degree),
             common_knots([dense[k].lower for k in aero], n, degree))
    while True:
        count = max(len(K) - degree - 1 for K in knots)
        try:
            fits, rho = _fit_all(dense, aero, n, degree, defn, False, magnitudes, knots)
        except StationFitError as exc:
            attempts.append((count, "dense", None, exc))
            return None
        worst = _deviations(dense, fits, chords, tols)
        attempts.append((count, "dense", worst, tols))
        if np.all(worst <= tols):
            return fits, rho, count
        if count >= MAX_DENSE_CONTROL_POINTS:
            return None
        refined = _refined_knots(dense, fits, knots, tols, chords, degree)
        grown = max(len(K) - degree - 1 for K in refined)
        if grown > MAX_DENSE_CONTROL_POINTS or all(len(a) == len(b) for a, b in zip(refined, knots)):
            return None  # at the limit, or no span to halve (bounded work either way)
        knots = refined


def fit_sections(defn: BladeDefinition, splits, n: int, tols: np.ndarray, degree: int = SECTION_DEGREE,
                 adapt: bool = True, magnitudes=None):
    """The section fits on common knots, the control-point count raised by
    :data:`CONTROL_POINT_STEP` (with ``adapt``) until every station k lies within
    ``tols[k]`` × chord. At each count the paper's chord-length parameters are tried
    first, then :func:`.sections.aligned_parameters`. When the data cannot carry the
    count (the plain fit is rank deficient) or the count reaches
    :data:`MAX_CONTROL_POINTS`, the densified fit :func:`_fit_dense` takes over from the
    best count measured. Returns (fits, ρ, n, mode, attempts), mode False (plain), True
    (aligned) or "dense"; raises GeometryError naming the station, the cause and the
    nearest setting that builds (:func:`_no_fit_message`). attempts: (n, mode,
    deviations, tolerances) of every measured try, (n, mode, None, error) of a try whose
    fit failed."""
    aero = list(range(defn.first_aerodynamic_station, len(defn.stations)))
    chords = np.array([s.chord for s in defn.stations])
    attempts = []
    while True:
        short = False
        for align in (False, True):
            plain = attempts[-1] if align else None
            if plain is not None and plain[2] is not None and np.max(plain[2] / tols) > ALIGN_RATIO:
                continue  # far from the tolerance: the count, not the parameters, is short
            try:
                fits, rho = _fit_all(splits, aero, n, degree, defn, align, magnitudes)
            except StationFitError as exc:
                attempts.append((n, align, None, exc))
                short = short or not align
                continue
            worst = _deviations(splits, fits, chords, tols)
            attempts.append((n, align, worst, tols))
            if np.all(worst <= tols):
                return fits, rho, n, align, attempts
        if adapt and (short or n >= MAX_CONTROL_POINTS):
            measured = [a for a in attempts if a[2] is not None]
            start = min(measured, key=lambda a: float(np.max(a[2] / tols)))[0] if measured else n
            dense = _fit_dense(defn, splits, start, tols, degree, magnitudes, attempts)
            if dense is not None:
                return dense[0], dense[1], dense[2], "dense", attempts
            raise GeometryError(_no_fit_message(defn, attempts, tols))
        if not adapt or n >= MAX_CONTROL_POINTS:
            raise GeometryError(_no_fit_message(defn, attempts, tols))
        n = min(MAX_CONTROL_POINTS, n + _next_step(n, attempts))


def build_blade(defn: BladeDefinition, control_points: int | None = None, tolerance: float | None = None,
                degree: int | None = None, degree_v: int | None = None, single: bool = True, fairness: bool = True,
                adapt: bool = True, quadrature_points: int | None = None, progress=None,
                tangent_magnitudes=None) -> BladeMolds:
    """Mold halves of the blade ``defn`` (Hosseini & Moetakef-Imani 2016).

    control_points: per half and section (default the definition's); with ``adapt`` it is
    raised by :data:`CONTROL_POINT_STEP` until every section's data lie within its
    tolerance × chord (``tolerance``, default the definition's per-station tolerances or
    its one tolerance, 1e-4) of its fitted curve, at most :data:`MAX_CONTROL_POINTS`
    (see :func:`fit_sections`). degree / degree_v: p of the section curves and q across
    the sections (default the definition's, 3 and 3). tangent_magnitudes: (λ_u, λ_l) of
    the derivative at S by hand (Hosseini Fig. 7a), default the definition's, or None for
    SQP. single: also build the traditional single surface (with 2n - 1 control points
    per section, the two halves' count with S shared). fairness: MVS and strain energy
    (Eq. 6) of the aero surfaces. progress: callable(fraction) or None.
    Returns :class:`BladeMolds`; ``times`` holds the stage times in seconds.
    """
    from ..fairing.surface_fairness import surface_fairness

    def tick(x):
        if progress is not None:
            progress(x)

    times = {}
    t0 = time.perf_counter()
    n = int(control_points or defn.control_points)
    degree = int(degree or getattr(defn, "section_degree", SECTION_DEGREE))
    degree_v = int(degree_v or getattr(defn, "span_degree", 3))
    if tangent_magnitudes is None:
        tangent_magnitudes = getattr(defn, "tangent_magnitudes", None)
    k0 = defn.first_aerodynamic_station
    aero = list(range(k0, len(defn.stations)))
    if len(aero) < 2:
        raise GeometryError(f"the aerodynamic zone needs at least 2 stations, got {len(aero)}")
    if tolerance:
        tols = np.full(len(defn.stations), float(tolerance))
    else:
        per = getattr(defn, "station_tolerances", None)
        tols = np.array(per, dtype=np.float64) if per is not None else np.full(len(defn.stations), defn.tolerance)
    splits = blade_sections(defn, degree)
    times["sections"] = time.perf_counter() - t0
    tick(0.15)

    t0 = time.perf_counter()
    fits, rho, n, mode, attempts = fit_sections(defn, splits, n, tols, degree, adapt, tangent_magnitudes)
    aligned, dense = mode is True, mode == "dense"
    times["section_fits"] = time.perf_counter() - t0
    tick(0.5)

    t0 = time.perf_counter()
    nets_u = np.stack([f.upper.control_points for f in fits])  # (K, n, 3)
    nets_l = np.stack([f.lower.control_points for f in fits])
    v = section_parameters([nets_u[k0:], nets_l[k0:]])
    upper = skin([fits[k].upper for k in aero], degree_v, params=v)
    lower = skin([fits[k].lower for k in aero], degree_v, params=v)
    te = nets_u[:, 0] - nets_l[:, -1]  # (K, 3) trailing-edge thickness vectors of the stations
    upper, lower = shape_preserving_trailing_edge(upper, lower, v, te[k0:])
    tr_u = tr_l = None
    if k0 > 0:
        w = section_parameters([nets_u[: k0 + 1], nets_l[: k0 + 1]])
        span = lambda a, b: np.linalg.norm(fits[b].upper.control_points[-1] - fits[a].upper.control_points[-1])  # noqa: E731
        scale = span(0, k0) / span(k0, len(fits) - 1)
        tr_u = root_transition(nets_u[: k0 + 1], upper, w, scale, degree_v)
        tr_l = root_transition(nets_l[: k0 + 1], lower, w, scale, degree_v)
        # T_w(1) of the transition = scale · T_v(0) of the aero halves (G1 at the joint)
        tr_u, tr_l = shape_preserving_trailing_edge(tr_u, tr_l, w, te[: k0 + 1],
                                                    end_derivative=_te_start_derivative(upper, lower, scale))
    upper, lower, tr_u, tr_l = share_mold_edges(upper, lower, tr_u, tr_l)
    times["skinning"] = time.perf_counter() - t0
    tick(0.65)

    t0 = time.perf_counter()
    single_surface = None
    single_fits = {}
    if single:
        # densified: the single curve approximates the same interpolant samples (errors at the data)
        whole = {k: densified_section(densified(splits[k])) if dense else (splits[k].points, None) for k in aero}
        Ks = np.mean([approximation_knots(parameterize(whole[k][0]), 2 * n - 1, degree) for k in aero], axis=0)
        for k in aero:
            try:
                single_fits[k] = fit_single(whole[k][0], Ks, degree=degree, align=aligned, marks=whole[k][1])
            except BladesmithError:  # the single curve's knot spans differ from the halves'
                single_fits[k] = fit_single(whole[k][0], Ks, degree=degree, align=not aligned, marks=whole[k][1])
        curves = [single_fits[k].curve for k in aero]
        v_single = skin_parameters(curves)
        single_surface = skin(curves, degree_v, params=v_single)
    times["single_surface"] = time.perf_counter() - t0
    tick(0.75)

    # tolerance by closest-point distance to the skinned surfaces' sections
    t0 = time.perf_counter()
    reports, pairs = [], []
    for k, (sp, f) in enumerate(zip(splits, fits)):
        rep = StationReport(k, defn.stations[k].r, sp.chord, f.lsq_error,
                            single_fits[k].lsq_error if k in single_fits else float("nan"),
                            f.magnitude_upper, f.magnitude_lower)
        if k >= k0:
            j = k - k0
            cu, cl = upper.iso_curve("v", v[j]), lower.iso_curve("v", v[j])
        else:
            cu, cl = tr_u.iso_curve("v", w[k]), tr_l.iso_curve("v", w[k])
        gu, gl = data_parameters(sp, f)  # the iso-curves have the fits' knots
        pairs += [(cu, sp.points[sp.upper_data], gu), (cl, sp.points[sp.lower_data], gl)]
        reports.append(rep)
    dist = _closest_distances(pairs)  # every station's closest points in one pass
    for k, (rep, sp) in enumerate(zip(reports, splits)):
        rep.deviation_two_part = float(max(dist[2 * k].max(), dist[2 * k + 1].max()) / sp.chord)
    times["tolerance_check"] = time.perf_counter() - t0
    tick(0.85)

    t0 = time.perf_counter()
    continuity = {}
    continuity["le_gap"], continuity["le_angle_deg"] = parting_line_continuity(upper, lower)
    if tr_u is not None:
        g1, a1 = joint_continuity(tr_u, upper)
        g2, a2 = joint_continuity(tr_l, lower)
        continuity["root_gap"], continuity["root_angle_deg"] = max(g1, g2), max(a1, a2)
        continuity["root_le_gap"], continuity["root_le_angle_deg"] = parting_line_continuity(tr_u, tr_l)
    parting = {
        "leading_edge": upper.iso_curve("u", 1.0),
        "trailing_edge_upper": upper.iso_curve("u", 0.0),
        "trailing_edge_lower": lower.iso_curve("u", 1.0),
    }
    if tr_u is not None:
        parting["root_leading_edge"] = tr_u.iso_curve("u", 1.0)
        parting["root_trailing_edge_upper"] = tr_u.iso_curve("u", 0.0)
        parting["root_trailing_edge_lower"] = tr_l.iso_curve("u", 1.0)
    times["continuity"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    fair = {}
    if fairness:
        fu = surface_fairness(upper, quadrature_points)
        fl = surface_fairness(lower, quadrature_points)
        fair["two_part"] = {"mvs": fu.mvs + fl.mvs, "strain_energy": fu.strain_energy + fl.strain_energy,
                            "area": fu.area + fl.area}
        if single_surface is not None:
            fs = surface_fairness(single_surface, quadrature_points)
            fair["single"] = {"mvs": fs.mvs, "strain_energy": fs.strain_energy, "area": fs.area}
        if tr_u is not None:
            a, b = surface_fairness(tr_u, quadrature_points), surface_fairness(tr_l, quadrature_points)
            fair["transition"] = {"mvs": a.mvs + b.mvs, "strain_energy": a.strain_energy + b.strain_energy,
                                  "area": a.area + b.area}
    times["fairness"] = time.perf_counter() - t0
    tick(1.0)
    return BladeMolds(defn, upper, lower, single_surface, tr_u, tr_l, parting, reports, n, rho, v, fair,
                      continuity, times, aligned, tols, dense)



# ---------------------------------------------------------------------------------------
# the control-point sweep (the x-axis of Hosseini Figs. 5, 8, 10 and 11)
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SweepRow:
    """One count of :func:`control_point_sweep`: n control points per half (2n - 1
    distinct per section, S shared), the single surface with the same 2n - 1. LSQ: Eq. 3
    summed over the aerodynamic stations (m²); MVS and strain energy: Eq. 6 of the aero
    surfaces (both halves summed); worst: the largest station deviation / chord."""

    n: int
    lsq_two_part: float
    lsq_single: float
    mvs_two_part: float
    mvs_single: float
    strain_energy_two_part: float
    strain_energy_single: float
    worst_deviation: float


def control_point_sweep(defn: BladeDefinition, counts, quadrature_points: int | None = None,
                        progress=None) -> list[SweepRow]:
    """Build the blade at each control-point count of ``counts`` (no raising to meet the
    tolerance) and tabulate the least-squares errors and the fairness of the two-part and
    the single approach at equal total control points (Hosseini Figs. 5, 8, 10, 11)."""
    counts = [int(c) for c in counts]
    if not counts or any(c < MIN_SECTION_CONTROL_POINTS or c > MAX_CONTROL_POINTS for c in counts):
        raise GeometryError(f"sweep counts must lie in [{MIN_SECTION_CONTROL_POINTS}, {MAX_CONTROL_POINTS}], "
                            f"got {counts}")
    rows = []
    for i, n in enumerate(counts):
        m = build_blade(defn, control_points=n, tolerance=float("inf"), adapt=False, single=True, fairness=True,
                        quadrature_points=quadrature_points)
        aero = [r for r in m.stations if r.index >= defn.first_aerodynamic_station]
        f = m.fairness
        rows.append(SweepRow(n, float(sum(r.lsq_two_part for r in aero)), float(sum(r.lsq_single for r in aero)),
                             f["two_part"]["mvs"], f["single"]["mvs"], f["two_part"]["strain_energy"],
                             f["single"]["strain_energy"], float(max(r.deviation_two_part for r in m.stations))))
        if progress is not None:
            progress((i + 1) / len(counts))
    return rows


def format_sweep(rows, markdown: bool = True) -> str:
    """The sweep as a table (Markdown by default)."""
    head = ["n per half", "LSQ two-part (m²)", "LSQ single (m²)", "MVS two-part", "MVS single",
            "strain energy two-part", "strain energy single", "worst section (chord)"]
    lines = []
    if markdown:
        lines.append("| " + " | ".join(head) + " |")
        lines.append("|" + "---:|" * len(head))
    for r in rows:
        cells = [f"{r.n}", f"{r.lsq_two_part:.3e}", f"{r.lsq_single:.3e}", f"{r.mvs_two_part:.3e}",
                 f"{r.mvs_single:.3e}", f"{r.strain_energy_two_part:.1f}", f"{r.strain_energy_single:.1f}",
                 f"{r.worst_deviation:.2e}"]
        lines.append("| " + " | ".join(cells) + " |" if markdown else "  ".join(cells))
    return "\n".join(lines)
