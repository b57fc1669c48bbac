"""Hally (2013) tip smoothing of the reference blade, §§3–9: settings, the pipeline and
its report.

``smooth_blade(model, settings)`` splits the blade b(ξ, η) into five surfaces (§3–4),
computes the side curves (§5), the cuts (§6), smooths the cuts near the tip (§7), builds
the curves around the edges and the tip (§8) and the spline surfaces with one common knot
sequence and exactly shared edges (§9). The hub sector and IGES (§§10–11) live elsewhere.

Units: every length setting is a fraction of the propeller radius R (dimensionless), so
the defaults suit any size; ``transition_s`` is a fractional arclength along c_LETE.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, fields, replace

import numpy as np

from ..errors import DefinitionError, GeometryError
from ..nurbs import BSplineCurve, BSplineSurface
from ..nurbs.fitting import greville_abscissae
from .blade_surfaces import (
    DEGREE,
    across_knots,
    central_surface,
    common_knots,
    edge_surface,
    evaluate_curves,
    fit_rows,
)
from .corners import DefiningPoints, blade_derivatives, blade_points, check_corner_order, corner_points
from .cut_smoothing import (
    MAX_STABLE_FILTER_STRENGTH,
    SMOOTHING_ZONE_BOUND,
    curvature_sign_changes,
    spline_signed_curvature,
)
from .edge_curves import EdgeCurveSet, build_edge_curves
from .irregularity import tip_irregularity
from .side_curves import side_curves

SURFACE_NAMES = ("pressure_central", "suction_central", "leading_edge", "trailing_edge", "tip")
#: Fraction of a tip-surface edge at each end left out of the normal-angle check: the
#: tip surface meets c_9/c_12 (and c_10/c_12, c_9/c_11, c_10/c_11) at corners where its
#: boundary curves continue each other (corner angle ~180°), so S_u and S_v are nearly
#: parallel there and the normal is undefined (a property of Hally's five-surface layout).
TIP_CORNER_EXCLUSION = 0.02
#: Newton iterations of the closest-point projection onto b.
PROJECTION_ITERATIONS = 12
#: Samples per direction of each surface in the deviation report, and Newton iterations.
DEVIATION_SAMPLES = 31
DEVIATION_ITERATIONS = 25
#: Refinement of the deviation maxima: the worst samples, and points per direction.
DEVIATION_WORST = 6
#: Samples of the tip surface per interval between its cuts, across them.
DEVIATION_TIP_PER_CUT = 4
#: Extra samples along the cuts across the blade's edge (t = 1/2 of every cut round the
#: LE, TE and tip, Hally Eqs. 38-40): DEVIATION_EDGE_SAMPLES over ±DEVIATION_EDGE_CELLS
#: cells of the coarse grid. The edge radius near the tip is 1e-5..1e-4 D, so the
#: deviation peaks in a band narrower than one coarse cell; the coarse grid and the
#: refinement round its worst samples missed it (issue 15: raked demo 1.89e-5 D reported
#: against 2.97e-5 D by an independent 161² projection, at t = 0.51).
DEVIATION_EDGE_SAMPLES = 41
DEVIATION_EDGE_CELLS = 2
DEVIATION_REFINE = 9
#: The deviation report also starts from the other face (ξ -> 1 - ξ) where that face's
#: point lies within this many times the distance found (a thin tip).
MIRROR_REACH = 10.0
#: Seed grid on b for projecting the tip surface (ξ by w = sqrt(1 - η)), from this far
#: below the lowest η of the tip cuts.
SEED_XI = 480
SEED_W = 120
SEED_ETA_MARGIN = 0.02


@dataclass(frozen=True)
class SmoothingSettings:
    """Settings of Hally (2013) tip smoothing. Lengths are fractions of the radius R.

    delta_c: Δc of Hally Eqs. 31 and 49, the largest spacing of the curves along the
        leading and trailing edges. Default 0.02 (0.01 D).
    tip_smoothing_distance: d_t of Eq. 30, smoothing acts on cuts whose edge point lies
        within d_t of the tip along the edge. Default 0.1.
    edge_smoothing_distance: d_e of Eq. 30, smoothing acts within d_e of the edge point
        along each cut. Default 0.05.
    transition_s: s_j of Eq. 48, the point of c_LETE (fractional arclength from the
        trailing edge at the hub) above which the curves are plain cuts; below, they come
        from transfinite interpolation. Must exceed s_tip + d_t/L. Default 0.75 (about
        half-way down the leading edge, Hally's advice).
    filter_strength: α of Eq. 30 (0 < α <= 0.75, the stability limit of Eq. 29).
        Default 0.5.
    filter_iterations: n of Eq. 29. Default 100 (the filter works in arclength and
        is guarded, see :func:`~.cut_smoothing.smooth_cut`).
    tolerance: the accuracy of the spline curves (§9). Default 2e-5 (= 1e-5 D).
    sample_spacing: d of Eqs. 27–28, the largest spacing of the cut samples (§7).
        Default 0.01.
    edge_spacing_ratio: h/d of Eq. 28; Hally: h = d/100. Default 0.01.
    defining_points: the six points of §4 (:class:`~.corners.DefiningPoints`).
    """

    delta_c: float = 0.02
    tip_smoothing_distance: float = 0.1
    edge_smoothing_distance: float = 0.05
    transition_s: float = 0.75
    filter_strength: float = 0.5
    filter_iterations: int = 100
    tolerance: float = 2e-5
    sample_spacing: float = 0.01
    edge_spacing_ratio: float = 0.01
    defining_points: DefiningPoints = field(default_factory=DefiningPoints)

    def __post_init__(self):
        def num(name, lo=None, hi=None, lo_open=True, hi_open=False):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not np.isfinite(v):
                raise DefinitionError(f"must be a finite number, got {v!r}", field=name)
            if lo is not None and (v <= lo if lo_open else v < lo):
                raise DefinitionError(f"must be {'>' if lo_open else '>='} {lo}, got {v}", field=name)
            if hi is not None and (v >= hi if hi_open else v > hi):
                raise DefinitionError(f"must be {'<' if hi_open else '<='} {hi}, got {v}", field=name)

        num("delta_c", 0.0, 1.0)
        num("tip_smoothing_distance", 0.0, 2.0)
        num("edge_smoothing_distance", 0.0, 2.0)
        num("transition_s", 0.0, 1.0, hi_open=True)
        num("filter_strength", 0.0, MAX_STABLE_FILTER_STRENGTH, lo_open=False)
        num("tolerance", 0.0, 0.01)
        num("sample_spacing", 0.0, 1.0)
        num("edge_spacing_ratio", 0.0, 1.0, hi_open=True)
        it = self.filter_iterations
        if isinstance(it, bool) or not isinstance(it, (int, np.integer)) or it < 0:
            raise DefinitionError(f"must be an integer >= 0, got {it!r}", field="filter_iterations")
        if not isinstance(self.defining_points, DefiningPoints):
            raise DefinitionError("expected a DefiningPoints", field="defining_points")
        self.defining_points.validate(field_prefix="defining_points.")

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in fields(cls))

    #: Settings that are lengths (fractions of R here; metres in :meth:`from_metres`).
    LENGTH_FIELDS = ("delta_c", "tip_smoothing_distance", "edge_smoothing_distance", "tolerance", "sample_spacing")

    @classmethod
    def from_metres(cls, values, radius: float) -> "SmoothingSettings":
        """Settings from a mapping keyed like the fields whose lengths are in metres (the
        operator's convention); missing keys keep their defaults. ``defining_points`` may
        be a DefiningPoints or a mapping of its fields."""
        kw = {}
        for name in cls.field_names():
            if name not in values:
                continue
            v = values[name]
            if name in cls.LENGTH_FIELDS:
                v = float(v) / radius
            elif name == "defining_points" and not isinstance(v, DefiningPoints):
                v = DefiningPoints(**dict(v))
            kw[name] = v
        return cls(**kw)


class Overlays(dict):
    """Display polylines (metres), computed when first asked for: 'cuts' (list of
    (201, 3): the tip, leading-edge and trailing-edge curves), 'lete' (801, 3) and
    'transition' (the 0-based index j of the transition cut)."""

    def __init__(self, blade, curves):
        super().__init__()
        self._blade, self._curves = blade, curves

    def __missing__(self, key):
        c, b = self._curves, self._blade
        if key == "cuts":
            tt = np.linspace(0.0, 1.0, 201)
            fam = c.tip + c.leading + c.trailing
            X, _ = evaluate_curves(b, fam, tt)
            value = list(X)
        elif key == "lete":
            value = c.lete.points(b, np.linspace(0.0, 1.0, 801))
        elif key == "transition":
            value = c.transition
        else:
            raise KeyError(key)
        self[key] = value
        return value


@dataclass(frozen=True, eq=False)
class SmoothedBlade:
    """The result of :func:`smooth_blade`.

    pressure_central, suction_central, leading_edge, trailing_edge, tip: the five
    BSplineSurfaces (cubic, outward normals S_u × S_v). ``parameter_surfaces``: companion
    surfaces of approximate blade parameters (for projections). ``curves``: the §8
    EdgeCurveSet (c_LETE, cuts, families, transition index j). ``overlays``: polylines
    (metres) for display: 'cuts' (list of (n, 3)), 'lete' (n, 3), 'transition' (index j,
    0-based). ``report``: counts, knots, deviations, fallbacks, stage times."""

    pressure_central: BSplineSurface
    suction_central: BSplineSurface
    leading_edge: BSplineSurface
    trailing_edge: BSplineSurface
    tip: BSplineSurface
    parameter_surfaces: dict
    curves: EdgeCurveSet
    overlays: dict
    report: dict
    settings: SmoothingSettings

    @property
    def surfaces(self) -> tuple[BSplineSurface, ...]:
        """The five surfaces in the order of SURFACE_NAMES."""
        return tuple(getattr(self, n) for n in SURFACE_NAMES)

    @property
    def named_surfaces(self) -> dict[str, BSplineSurface]:
        """The five surfaces by name (SURFACE_NAMES)."""
        return {n: getattr(self, n) for n in SURFACE_NAMES}


# shared edges: (surface a, side a, surface b, side b, reversed)
SHARED_EDGES = (
    ("pressure_central", "u1", "leading_edge", "u0", False),
    ("pressure_central", "u0", "trailing_edge", "u1", False),
    ("suction_central", "u0", "leading_edge", "u1", False),
    ("suction_central", "u1", "trailing_edge", "u0", False),
    ("pressure_central", "v1", "tip", "v0", False),
    ("suction_central", "v1", "tip", "v1", True),
    ("leading_edge", "v1", "tip", "u1", False),
    ("trailing_edge", "v1", "tip", "u0", True),
)


def boundary_parameters(side: str, t) -> tuple[np.ndarray, np.ndarray]:
    t = np.asarray(t, dtype=np.float64)
    fixed = np.full_like(t, 0.0 if side.endswith("0") else 1.0)
    return (fixed, t) if side.startswith("u") else (t, fixed)


def shared_edge_report(surfaces: dict, samples: int = 200) -> list[dict]:
    """For every shared edge: the largest distance between the two surfaces at
    ``samples`` points, and the largest angle (degrees) between their normals away from
    the tip surface's corners (``max_normal_angle_deg``; within TIP_CORNER_EXCLUSION of
    them the tip surface's u and v directions are parallel, see the module docstring;
    ``max_normal_angle_all_deg`` includes them)."""
    t = np.linspace(0.0, 1.0, samples)
    out = []
    for a, sa, b, sb, rev in SHARED_EDGES:
        ua, va = boundary_parameters(sa, t)
        ub, vb = boundary_parameters(sb, t[::-1] if rev else t)
        Xa, Xb = surfaces[a].evaluate(ua, va), surfaces[b].evaluate(ub, vb)
        Na, Nb = surfaces[a].normal(ua, va), surfaces[b].normal(ub, vb)
        ang = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", Na, Nb), -1.0, 1.0)))
        keep = np.ones(samples, dtype=bool)
        if b == "tip":
            keep = (t >= TIP_CORNER_EXCLUSION) & (t <= 1.0 - TIP_CORNER_EXCLUSION)
        out.append({"edge": f"{a}.{sa} / {b}.{sb}", "max_gap": float(np.max(np.linalg.norm(Xa - Xb, axis=1))),
                    "max_normal_angle_deg": float(np.max(ang[keep])), "max_normal_angle_all_deg": float(np.max(ang)),
                    "angles": ang})
    return out


def project_to_blade(blade, X, p_guess, iterations: int = PROJECTION_ITERATIONS):
    """Closest points on b from starting parameters (Newton on |b(p) - x|², full Hessian
    where it is positive definite, Gauss–Newton otherwise): (distances (n,), p (n, 2))."""
    p = np.array(p_guess, dtype=np.float64)
    for _ in range(iterations):
        D = blade_derivatives(blade, p, 2)
        r = D[:, 0, 0] - X
        bx, be = D[:, 1, 0], D[:, 0, 1]
        g = np.stack([np.einsum("ij,ij->i", bx, r), np.einsum("ij,ij->i", be, r)], axis=1)
        a = np.einsum("ij,ij->i", bx, bx)
        b = np.einsum("ij,ij->i", bx, be)
        c = np.einsum("ij,ij->i", be, be)
        ha = a + np.einsum("ij,ij->i", D[:, 2, 0], r)
        hb = b + np.einsum("ij,ij->i", D[:, 1, 1], r)
        hc = c + np.einsum("ij,ij->i", D[:, 0, 2], r)
        det = ha * hc - hb * hb
        use = (det > 0) & (ha > 0)
        ha, hb, hc = np.where(use, ha, a), np.where(use, hb, b), np.where(use, hc, c)
        det = ha * hc - hb * hb
        with np.errstate(divide="ignore", invalid="ignore"):
            dx = np.where(det > 0, -(hc * g[:, 0] - hb * g[:, 1]) / det, 0.0)
            de = np.where(det > 0, -(-hb * g[:, 0] + ha * g[:, 1]) / det, 0.0)
        p[:, 0] += np.clip(dx, -0.05, 0.05)
        p[:, 1] = np.clip(p[:, 1] + np.clip(de, -0.05, 0.05), blade.eta_min, 1.0)
    dist = np.linalg.norm(blade_points(blade, p) - X, axis=1)
    return dist, p


def _zone_mask(smoothed: np.ndarray, coord: np.ndarray) -> np.ndarray:
    """Samples whose across-curve coordinate lies within one curve spacing of a smoothed
    curve (the smoothing zone)."""
    idx = np.flatnonzero(smoothed)
    if idx.size == 0:
        return np.zeros(coord.shape, dtype=bool)
    k = coord * (len(smoothed) - 1)
    return (k >= idx.min() - 1) & (k <= idx.max() + 1)


class BladeSeeds:
    """Nearest points of a grid on b above η_low (ξ uniform, η = 1 - w² with w uniform,
    so the grid closes on the tip like the blade does), for starting projections: a
    KD-tree over n_xi × n_w points."""

    def __init__(self, blade, eta_low: float, n_xi: int = None, n_w: int = None):
        from scipy.spatial import cKDTree

        n_xi = SEED_XI if n_xi is None else n_xi
        n_w = SEED_W if n_w is None else n_w
        xi = np.arange(n_xi) / n_xi
        w = np.linspace(0.0, np.sqrt(1.0 - max(eta_low, blade.eta_min)), n_w)
        XI, W = np.meshgrid(xi, w, indexing="ij")
        self.params = np.stack([XI.ravel(), 1.0 - W.ravel() ** 2], axis=1)
        self.tree = cKDTree(blade.evaluate(self.params[:, 0], self.params[:, 1]))

    def nearest(self, X) -> np.ndarray:
        _, idx = self.tree.query(np.asarray(X, dtype=np.float64))
        return self.params[idx]


def _mirrored(P) -> np.ndarray:
    """The same chordwise place on the other face of the blade: ξ -> 1 - ξ (pressure <->
    suction side, Hally §2; the leading edge ξ = 1/2 and the trailing edge 0 ≡ 1 map to
    themselves)."""
    Q = np.array(P, dtype=np.float64)
    Q[:, 0] = 1.0 - Q[:, 0]
    return Q


def _project(blade, X, starts, mirror: bool = False):
    """Shortest closest-point distance over several start parameter sets; with
    ``mirror`` also from the other face of the best result (:func:`_mirrored`): near the
    tip the blade is thinner than the seed grid is fine, and a start on the wrong face
    ends in a local minimum there, which overstated the deviation (issue 15: +6.8 % on
    the 72°-skew tip)."""
    if mirror:
        d, p = _project(blade, X, starts)
        # only where the other face is near: thick parts cannot hold a nearer point there
        Q = _mirrored(p)
        other = np.flatnonzero(np.linalg.norm(blade_points(blade, Q) - X, axis=1) < MIRROR_REACH * d)
        if other.size:
            d2, p2 = project_to_blade(blade, X[other], Q[other], iterations=DEVIATION_ITERATIONS)
            better = d2 < d[other]
            d[other[better]], p[other[better]] = d2[better], p2[better]
        return d, p
    best_d, best_p = None, None
    for P in starts:
        d, p = project_to_blade(blade, X, P, iterations=DEVIATION_ITERATIONS)
        if best_d is None:
            best_d, best_p = d, p
        else:
            take = d < best_d
            best_d, best_p = np.where(take, d, best_d), np.where(take[:, None], p, best_p)
    return best_d, best_p


def deviation_report(blade, smoothed_surfaces: dict, param_surfaces: dict, curves: EdgeCurveSet,
                     samples: int = DEVIATION_SAMPLES):
    """Closest-point distance from the surfaces to the unsmoothed blade, split into the
    smoothing zone and the rest (metres): dict per surface and overall maxima.

    Samples: a ``samples``² grid of each surface, then a finer grid (DEVIATION_REFINE²
    points over one cell each way) around the DEVIATION_WORST largest samples inside and
    outside the zone, so the maxima are the surface's and not the coarse grid's. Starts:
    the companion parameters; on the tip (which has none, its parameters jump between ξ
    branches across the tip), the nearest cut and the nearest point of a grid on b
    (:class:`BladeSeeds`), keeping the shorter distance: from the cut alone the
    projection can end in a far local minimum where the parameter lines crowd."""
    t = np.linspace(0.0, 1.0, samples)
    seeds = None
    out = {}
    for name, S in smoothed_surfaces.items():
        # the tip surface across its cuts: DEVIATION_TIP_PER_CUT samples per interval (the
        # surface is exact on the cuts; it departs from b between them)
        tu = np.linspace(0.0, 1.0, DEVIATION_TIP_PER_CUT * (len(curves.tip) - 1) + 1) if name == "tip" else t
        tv = t
        # a fine band across the blade's edge, along the cuts (u on the LE and TE surfaces,
        # v on the tip)
        half = DEVIATION_EDGE_CELLS / (samples - 1)
        band = np.linspace(0.5 - half, 0.5 + half, DEVIATION_EDGE_SAMPLES)
        if name == "tip":
            tv = np.union1d(t, band)
        elif name in ("leading_edge", "trailing_edge"):
            tu = np.union1d(t, band)
        U, V = np.meshgrid(tu, tv, indexing="ij")
        u, v = U.ravel(), V.ravel()
        zone_coord = {"leading_edge": (curves.smoothed_leading, v), "trailing_edge": (curves.smoothed_trailing, v),
                      "tip": (curves.smoothed_tip, u)}
        coarse_u = DEVIATION_TIP_PER_CUT * (len(curves.tip) - 1) + 1 if name == "tip" else samples
        local = np.stack(np.meshgrid(np.linspace(-1, 1, DEVIATION_REFINE) / (coarse_u - 1),
                                     np.linspace(-1, 1, DEVIATION_REFINE) / (samples - 1), indexing="ij"))
        X = S.evaluate(u, v)
        if name == "tip":
            k = np.rint(u * (len(curves.tip) - 1)).astype(int)
            P = np.empty((u.size, 2))
            for kk in np.unique(k):
                P[k == kk] = curves.tip[kk].parameters(v[k == kk])
            if seeds is None:
                seeds = BladeSeeds(blade, float(P[:, 1].min()) - SEED_ETA_MARGIN)
            d, p = _project(blade, X, [P, seeds.nearest(X)], mirror=True)
        else:
            d, p = _project(blade, X, [param_surfaces[name].evaluate(u, v)], mirror=name in zone_coord)
        if name in zone_coord:
            zone = _zone_mask(*zone_coord[name])
        else:
            zone = np.zeros(d.shape, dtype=bool)
        res = {}
        for key, mask in (("outside", ~zone), ("inside", zone)):
            if not np.any(mask):
                res[key] = 0.0
                continue
            idx = np.flatnonzero(mask)
            top = idx[np.argsort(d[idx])[-DEVIATION_WORST:]]
            du, dv = local
            uu = np.clip(u[top, None] + du.ravel()[None], 0.0, 1.0).ravel()
            vv = np.clip(v[top, None] + dv.ravel()[None], 0.0, 1.0).ravel()
            Xr = S.evaluate(uu, vv)
            other = seeds.nearest(Xr) if name == "tip" else param_surfaces[name].evaluate(uu, vv)
            dr, _ = _project(blade, Xr, [np.repeat(p[top], du.size, axis=0), other], mirror=name in zone_coord)
            res[key] = float(max(d[idx].max(), dr.max()))
        out[name] = res
    out["max_outside"] = max(v["outside"] for v in out.values() if isinstance(v, dict))
    out["max_inside"] = max(v["inside"] for v in out.values() if isinstance(v, dict))
    return out


def tip_cut_fairness(blade, curves: EdgeCurveSet, tip_surface: BSplineSurface, samples: int = 801) -> list[dict]:
    """Sign changes of the in-plane curvature (see
    :func:`~.cut_smoothing.curvature_sign_changes`) along every tip cut: the unsmoothed
    cut and the smoothed cut (each as its spline on the common knots of §9) and the tip
    surface's iso-curve through it (Hally §7: smoothing must not add inflections)."""
    U = tip_surface.knots_v
    g = greville_abscissae(U, DEGREE)
    plain = [replace(c.curve, offset=None) for c in curves.cuts["tip"]]
    X0, _ = evaluate_curves(blade, plain, g)
    X1, _ = evaluate_curves(blade, curves.tip, g)
    R0, R1 = fit_rows(U, X0), fit_rows(U, X1)
    t = np.linspace(0.0, 1.0, samples)
    n_t = len(curves.tip)
    out = []
    for i, cut in enumerate(curves.cuts["tip"]):
        n = cut.normal
        k0 = spline_signed_curvature(BSplineCurve(DEGREE, U, R0[i]), t, n)
        k1 = spline_signed_curvature(BSplineCurve(DEGREE, U, R1[i]), t, n)
        k2 = spline_signed_curvature(tip_surface.iso_curve("u", i / (n_t - 1)), t, n)
        out.append({"cut": i, "smoothed": bool(curves.smoothed_tip[i]),
                    "sign_changes_unsmoothed": curvature_sign_changes(k0),
                    "sign_changes_smoothed": curvature_sign_changes(k1),
                    "sign_changes_surface": curvature_sign_changes(k2)})
    return out


def smooth_blade(model, settings: SmoothingSettings | None = None, progress=None, measure: bool = True) -> SmoothedBlade:
    """Hally (2013) §§3–9 for the reference blade of ``model`` (a PropellerModel).
    ``settings``: SmoothingSettings (lengths as fractions of R) or a mapping with lengths
    in metres (:meth:`SmoothingSettings.from_metres`, the operator's convention).
    ``progress(stage, fraction)`` is called between stages. With ``measure`` the report
    includes the deviation from the unsmoothed blade and the shared-edge checks."""
    blade = model.blade
    if settings is None:
        settings = SmoothingSettings()
    elif not isinstance(settings, SmoothingSettings):
        settings = SmoothingSettings.from_metres(settings, blade.radius)
    R = blade.radius
    times = {}
    clock = time.perf_counter()

    def lap(name):
        nonlocal clock
        now = time.perf_counter()
        times[name] = now - clock
        clock = now
        if progress:
            progress(name, 1.0)

    settings.defining_points.validate(blade, field_prefix="defining_points.")
    corners = corner_points(blade, model.blade_hub_intersection, settings.defining_points)
    check_corner_order(corners)
    lap("corners")
    sides = side_curves(blade, corners)
    lap("side_curves")
    curves = build_edge_curves(blade, corners, sides, settings)
    lap("cuts_and_edge_curves")
    tol = settings.tolerance * R
    # one knot sequence for every distinct curve (c_11, c_12 are shared by two families)
    unique = curves.leading + curves.trailing[:-1] + curves.tip[1:-1]
    knot_report: dict = {}
    U, C, Pg = common_knots(blade, unique, tol, knot_report)
    nL, nT = len(curves.leading), len(curves.trailing)
    C_le, P_le = C[:nL], Pg[:nL]
    te_rows, te_prows = C[nL : nL + nT - 1], Pg[nL : nL + nT - 1]
    tip_rows, tip_prows = C[nL + nT - 1 :], Pg[nL + nT - 1 :]
    # c_11 (the first tip cut, the top trailing-edge curve reversed): with the symmetric
    # knots, reversing its fitted row gives the fit of the reversed curve
    g = greville_abscissae(U, DEGREE)
    X11, P11 = evaluate_curves(blade, [curves.tip[0]], g)
    row_c11, prow_c11 = fit_rows(U, X11)[0], P11[0]
    C_te = np.concatenate([te_rows, row_c11[None, ::-1]])
    P_te = np.concatenate([te_prows, prow_c11[None, ::-1]])
    # c_12 is the top leading-edge curve and the last tip cut (one object)
    C_tip = np.concatenate([row_c11[None], tip_rows, C_le[-1:]])
    P_tip = np.concatenate([prow_c11[None], tip_prows, P_le[-1:]])
    lap("common_knots")
    le = edge_surface(U, C_le, P_le)
    te = edge_surface(U, C_te, P_te)
    tip = edge_surface(U, C_tip, P_tip, along_u=False)
    # central surfaces (§9 steps 3–5)
    n_t, n_e = len(curves.tip), nL
    _, V_t = across_knots(n_t)
    _, V_e = across_knots(n_e)
    ut, ue = curves.u_tip, curves.u_edge
    e = curves.edges
    pc = central_surface(
        blade, e["c2"].parameters(ut), e["c9"].parameters(ut), e["c5"].parameters(ue), e["c6"].parameters(ue),
        V_t, V_e,
        {"u0": te.surface.control_points[-1], "u1": le.surface.control_points[0], "v1": tip.surface.control_points[:, 0]},
    )
    sc = central_surface(
        blade, e["c4"].parameters(ut), e["c10"].parameters(ut), e["c7"].parameters(ue), e["c8"].parameters(ue) + np.array([1.0, 0.0]),
        V_t, V_e,
        {"u0": le.surface.control_points[-1], "u1": te.surface.control_points[0],
         "v1": tip.surface.control_points[::-1, -1]},
    )
    pairs = {"pressure_central": pc, "suction_central": sc, "leading_edge": le, "trailing_edge": te, "tip": tip}
    if blade.hand < 0:  # ξ in (0, 1/2) is the suction side of a left-handed blade
        pairs["pressure_central"], pairs["suction_central"] = sc, pc
    lap("surfaces")
    surfaces = {k: v.surface for k, v in pairs.items()}
    params = {k: v.parameters for k, v in pairs.items()}
    _check_orientation(blade, pairs)
    fallbacks = {"xi_search": 0, "bisection": 0}
    all_cuts = list(curves.cuts["tip"]) + list(curves.cuts["leading"].values()) + list(curves.cuts["trailing"].values())
    for c in all_cuts:
        for k in fallbacks:
            fallbacks[k] += c.fallbacks.get(k, 0)
    overlays = Overlays(blade, curves)
    report = {
        "cuts": {"tip": len(curves.tip), "leading_edge": nL, "trailing_edge": nT, "planar": len(all_cuts),
                 "smoothed": int(curves.smoothed_tip.sum() + curves.smoothed_leading[:-1].sum()
                                 + curves.smoothed_trailing[:-1].sum())},
        "transition_index": curves.transition,
        "knots": knot_report,
        "newton_fallbacks": fallbacks,
        "tolerance_m": tol,
        "max_smoothing_displacement_m": max([s.max_displacement for s in curves.smoothing.values()], default=0.0),
        "times_s": times,
    }
    # the guard of §7 (cut_smoothing.smooth_cut): cuts where fewer sweeps were kept, and why
    report["smoothing_stops"] = [sm.stopped for sm in curves.smoothing.values() if sm.stopped]
    #: missed tolerances and bounds, with figures (the operator reports them as warnings)
    report["warnings"] = list(report["smoothing_stops"])
    report["tip_irregularity"] = tip_irregularity(blade, curves, settings.edge_smoothing_distance * R)
    lap("report")
    if measure:
        dev = deviation_report(blade, surfaces, params, curves)
        report["deviation_m"] = dev
        report["deviation_bound_inside_m"] = SMOOTHING_ZONE_BOUND * R
        D = 2.0 * R
        if dev["max_outside"] > tol:
            worst = max((k for k in SURFACE_NAMES), key=lambda k: dev[k]["outside"])
            report["warnings"].append(
                f"outside the smoothing zone the surfaces depart from the blade by up to {dev['max_outside']:.3g} m "
                f"({dev['max_outside'] / D:.3g} D, on the {worst} surface), more than the tolerance {tol:.3g} m")
        if dev["max_inside"] > SMOOTHING_ZONE_BOUND * R:
            report["warnings"].append(
                f"inside the smoothing zone the surfaces depart from the blade by up to {dev['max_inside']:.3g} m "
                f"({dev['max_inside'] / D:.3g} D), more than the bound {SMOOTHING_ZONE_BOUND * R:.3g} m")
        # SHARED_EDGES names the surfaces by their place (pressure_central at ξ < 1/2, the
        # pressure side of a right-handed blade); a left-handed blade's are swapped above
        layout = dict(surfaces)
        if blade.hand < 0:
            layout["pressure_central"], layout["suction_central"] = surfaces["suction_central"], surfaces["pressure_central"]
        report["shared_edges"] = [{k: v for k, v in e.items() if k != "angles"} for e in shared_edge_report(layout)]
        lap("measure")
    report["times_s"]["total"] = sum(v for k, v in times.items() if k != "total")
    return SmoothedBlade(**surfaces, parameter_surfaces=params, curves=curves, overlays=overlays, report=report,
                         settings=settings)


def _check_orientation(blade, pairs: dict) -> None:
    """S_u × S_v must point out of the blade on all five surfaces (Hally Eq. 1): three
    points each, the blade's normals at all of them in one evaluation."""
    u = np.array([0.3, 0.5, 0.7])
    names = list(pairs)
    n_s = np.concatenate([pairs[k].surface.normal(u, u) for k in names])
    P = np.concatenate([pairs[k].parameters.evaluate(u, u) for k in names])
    n_b = blade.normal(P[:, 0], np.clip(P[:, 1], blade.eta_min, 1 - 1e-9))
    bad = np.einsum("ij,ij->i", n_s, n_b).reshape(len(names), u.size) <= 0
    for name, row in zip(names, bad):
        if np.any(row):
            raise GeometryError(f"the {name} surface is not oriented outwards (internal error)")
