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
from ..nurbs import BSplineSurface, interpolate, skin
from ..nurbs.fitting import approximation_knots, parameterize
from ..nurbs.projection import closest_point_curve
from ..nurbs.skinning import skin_parameters
from .definition import BladeDefinition
from .sections import (
    SECTION_DEGREE,
    SplitSection,
    TwoPartFit,
    default_knots,
    fit_single,
    fit_two_part,
    section_points,
    split_section,
)

#: Upper limit of the control points per half when raising them to meet the tolerance.
MAX_CONTROL_POINTS = 60
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
            base = trailing_edge_surface(up, lo)
            if base is not None:
                out[name] = base
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


def _fit_all(splits, aero, n, degree, defn):
    Ku = common_knots([splits[k].upper for k in aero], n, degree)
    Kl = common_knots([splits[k].lower for k in aero], n, degree)
    ratios = []
    for k in aero:
        try:
            f = fit_two_part(splits[k], Ku, Kl, degree=degree)
        except BladesmithError as exc:
            raise _station_error(k, defn.stations[k], exc) from None
        ratios.append(f.magnitude_upper / f.magnitude_lower)
    rho = float(np.exp(np.mean(np.log(ratios))))
    fits = []
    for k, sp in enumerate(splits):
        try:
            fits.append(fit_two_part(sp, Ku, Kl, degree=degree, ratio=rho))
        except BladesmithError as exc:
            raise _station_error(k, defn.stations[k], exc) from None
    return fits, rho


def section_deviation(split: SplitSection, fit: TwoPartFit) -> float:
    """Largest closest-point distance of the section's data to its two fitted halves,
    as a fraction of the chord."""
    du = closest_point_curve(fit.upper, split.points[split.upper_data])[1]
    dl = closest_point_curve(fit.lower, split.points[split.lower_data])[1]
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
    cols = [interpolate(root_nets[:, i], q, params=w, end_derivative=D[i]) for i in range(root_nets.shape[1])]
    net = np.stack([c.control_points for c in cols], axis=0)
    return BSplineSurface(aero.degree_u, q, aero.knots_u, cols[0].knots, net)


#: Trailing-edge edges closer than this everywhere (relative to the surface size) are one
#: edge: the trailing edge is sharp and needs no base surface.
SHARP_TE_TOL = 1e-12


def trailing_edge_surface(upper: BSplineSurface, lower: BSplineSurface) -> BSplineSurface | None:
    """The ruled base of a blunt trailing edge between lower(1, v) and upper(0, v) (both
    halves share v knots), or None when the edges coincide (sharp TE, C0 join)."""
    a, b = lower.control_points[-1], upper.control_points[0]
    if np.linalg.norm(a - b, axis=1).max() <= SHARP_TE_TOL * upper.size():
        return None
    return BSplineSurface(1, upper.degree_v, np.array([0.0, 0.0, 1.0, 1.0]), upper.knots_v, np.stack([a, b]))


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


def build_blade(defn: BladeDefinition, control_points: int | None = None, tolerance: float | None = None,
                degree: int = SECTION_DEGREE, degree_v: int = 3, single: bool = True, fairness: bool = True,
                adapt: bool = True, quadrature_points: int | None = None, progress=None) -> BladeMolds:
    """Mold halves of the blade ``defn`` (Hosseini & Moetakef-Imani 2016).

    control_points: per half and section (default the definition's); with ``adapt`` it is
    raised by :data:`CONTROL_POINT_STEP` until every section's data lie within
    ``tolerance`` × chord (default the definition's, 1e-4) of its fitted curve, at most
    :data:`MAX_CONTROL_POINTS`. single: also build the traditional single surface (with
    2n - 1 control points per section, the two halves' count with S shared). fairness: MVS
    and strain energy (Eq. 6) of the aero surfaces. progress: callable(fraction) or None.
    Returns :class:`BladeMolds`; ``times`` holds the stage times in seconds.
    """
    from ..fairing.surface_fairness import surface_fairness

    def tick(x):
        if progress is not None:
            progress(x)

    times = {}
    t0 = time.perf_counter()
    n = int(control_points or defn.control_points)
    tol = float(tolerance or defn.tolerance)
    k0 = defn.first_aerodynamic_station
    aero = list(range(k0, len(defn.stations)))
    if len(aero) < 2:
        raise GeometryError(f"the aerodynamic zone needs at least 2 stations, got {len(aero)}")
    splits = blade_sections(defn, degree)
    times["sections"] = time.perf_counter() - t0
    tick(0.15)

    t0 = time.perf_counter()
    chords = np.array([s.chord for s in defn.stations])
    while True:
        try:
            fits, rho = _fit_all(splits, aero, n, degree, defn)
            # |Q_r - C(t_r)| bounds the closest-point distance from above; measure the
            # latter only where the bound fails
            worst = np.array([f.max_residual for f in fits]) / chords
            for k in np.flatnonzero(worst > tol):
                worst[k] = section_deviation(splits[k], fits[k])
            ok = bool(np.all(worst <= tol))
        except BladesmithError as exc:
            if n == int(control_points or defn.control_points):
                raise
            ok, fits, failure = False, None, exc
        if ok or not adapt or n + CONTROL_POINT_STEP > MAX_CONTROL_POINTS:
            if fits is None:
                # name the station and the cause (the fit's own message)
                raise GeometryError(f"no fit with {n} control points per half (raised up to MAX_CONTROL_POINTS = "
                                    f"{MAX_CONTROL_POINTS}): {failure}") from failure
            break
        n += CONTROL_POINT_STEP
    if not ok:
        k = int(np.argmax(worst))
        raise GeometryError(
            f"station {k} (r = {defn.stations[k].r:g} m): the fit deviates {worst[k]:.3g} chord from its points "
            f"with {n} control points per half, more than the tolerance {tol:g}")
    times["section_fits"] = time.perf_counter() - t0
    tick(0.5)

    t0 = time.perf_counter()
    nets_u = np.stack([f.upper.control_points for f in fits])  # (K, n, 3)
    nets_l = np.stack([f.lower.control_points for f in fits])
    v = section_parameters([nets_u[k0:], nets_l[k0:]])
    upper = skin([fits[k].upper for k in aero], degree_v, params=v)
    lower = skin([fits[k].lower for k in aero], degree_v, params=v)
    tr_u = tr_l = None
    if k0 > 0:
        w = section_parameters([nets_u[: k0 + 1], nets_l[: k0 + 1]])
        span = lambda a, b: np.linalg.norm(fits[b].upper.control_points[-1] - fits[a].upper.control_points[-1])  # noqa: E731
        scale = span(0, k0) / span(k0, len(fits) - 1)
        tr_u = root_transition(nets_u[: k0 + 1], upper, w, scale, degree_v)
        tr_l = root_transition(nets_l[: k0 + 1], lower, w, scale, degree_v)
    times["skinning"] = time.perf_counter() - t0
    tick(0.65)

    t0 = time.perf_counter()
    single_surface = None
    single_fits = {}
    if single:
        Ks = np.mean([approximation_knots(parameterize(splits[k].points), 2 * n - 1, degree) for k in aero], axis=0)
        for k in aero:
            single_fits[k] = fit_single(splits[k].points, Ks, degree=degree)
        curves = [single_fits[k].curve for k in aero]
        v_single = skin_parameters(curves)
        single_surface = skin(curves, degree_v, params=v_single)
    times["single_surface"] = time.perf_counter() - t0
    tick(0.75)

    # tolerance by closest-point distance to the skinned surfaces' sections
    t0 = time.perf_counter()
    reports = []
    for k, (sp, f) in enumerate(zip(splits, fits)):
        rep = StationReport(k, defn.stations[k].r, sp.chord, f.lsq_error,
                            single_fits[k].lsq_error if k in single_fits else float("nan"),
                            f.magnitude_upper, f.magnitude_lower)
        if k >= k0:
            j = k - k0
            cu, cl = upper.iso_curve("v", v[j]), lower.iso_curve("v", v[j])
        else:
            cu, cl = tr_u.iso_curve("v", w[k]), tr_l.iso_curve("v", w[k])
        du = closest_point_curve(cu, sp.points[sp.upper_data])[1]
        dl = closest_point_curve(cl, sp.points[sp.lower_data])[1]
        rep.deviation_two_part = float(max(du.max(), dl.max()) / sp.chord)
        reports.append(rep)
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
                      continuity, times)

