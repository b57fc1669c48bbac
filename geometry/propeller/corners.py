"""The six defining points, the ten corner points and the twelve edge curves that split
the blade into five surfaces (Hally 2013 §4, Figs. 4–5, Eqs. 2–7).

Everything here lives in the blade parameter space p = (ξ, η) of b(ξ, η)
(:class:`~.blade.BladeSurface`): a curve on the blade is a map t -> p(t) and its points
are b(p(t)). ξ is periodic (b(ξ - 1, η) = b(ξ, η), Hally §2), so curves that wrap the
trailing edge are written with ξ running through 0 into negative values; the blade
evaluates them on the periodic surface.

A curve may also carry a displacement d(t) (the smoothed cuts of §7, which leave the
blade): its points are b(p(t)) + d(t). The protocol every edge curve follows:

- ``parameters(t)``: blade parameters (n, 2) (for a smoothed cut those of the unsmoothed
  cut, which are then only the parameters of the nearest blade point);
- ``displacement(t)``: (n, 3) or None;
- ``reversed()``: the same curve run backwards, t -> 1 - t.

Known extraction errors in Hally §4 that are corrected here (shared/papers/README.md):
item 6 reads p_TE = (0, η_TE); Eq. 5 defines c_4; x_UR is a free point (not on the hub).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline

from ..errors import DefinitionError, GeometryError

#: Samples of η_h(ξ) over one period used to spline the blade–hub intersection.
HUB_CURVE_SAMPLES = 257
#: Largest η used in Newton iterations and parameter splines: the blade's η-derivatives
#: are infinite at the tip η = 1 when the chord closes there.
ETA_TIP_GUARD = 1e-12


def blade_points(blade, p) -> np.ndarray:
    """b(p) for parameters p of shape S + (2,): S + (3,). η is clipped to the blade."""
    p = np.asarray(p, dtype=np.float64)
    eta = np.clip(p[..., 1], blade.eta_min, 1.0)
    return blade.evaluate(p[..., 0], eta)


def blade_derivatives(blade, p, order: int = 1) -> np.ndarray:
    """Derivatives of b at p (S + (2,)): S + (order+1, order+1, 3), η kept below the
    tip by :data:`ETA_TIP_GUARD` where the derivatives are singular."""
    p = np.asarray(p, dtype=np.float64)
    eta = np.clip(p[..., 1], blade.eta_min, 1.0 - ETA_TIP_GUARD)
    return blade.derivatives(p[..., 0], eta, order)


# ---------------------------------------------------------------------------------------
# parameter curves
# ---------------------------------------------------------------------------------------
class ParameterCurve:
    """Base of the curves on the blade (protocol in the module docstring)."""

    def parameters(self, t) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def displacement(self, t):
        return None

    def points(self, blade, t) -> np.ndarray:
        t = np.asarray(t, dtype=np.float64)
        X = blade_points(blade, self.parameters(t))
        d = self.displacement(t)
        return X if d is None else X + d

    def reversed(self) -> "ParameterCurve":
        return ReversedCurve(self)


@dataclass(frozen=True, eq=False)
class ReversedCurve(ParameterCurve):
    """``base`` run backwards: t -> base(1 - t)."""

    base: ParameterCurve

    def parameters(self, t):
        return self.base.parameters(1.0 - np.asarray(t, dtype=np.float64))

    def displacement(self, t):
        return self.base.displacement(1.0 - np.asarray(t, dtype=np.float64))

    def reversed(self):
        return self.base


@dataclass(frozen=True, eq=False)
class LineCurve(ParameterCurve):
    """Straight line in parameter space p(t) = p_a + t (p_b - p_a) (Hally Eqs. 6–7)."""

    start: np.ndarray
    end: np.ndarray

    def parameters(self, t):
        t = np.asarray(t, dtype=np.float64)[..., None]
        return np.asarray(self.start) + t * (np.asarray(self.end) - np.asarray(self.start))


@dataclass(frozen=True, eq=False)
class HubCurve(ParameterCurve):
    """Blade–hub intersection between ξ_a and ξ_b: p(t) = (ξ(t), η_h(ξ(t))), ξ linear in t
    (Hally Eqs. 2–5). ``eta_h`` is a periodic spline of η_h(ξ) (period 1)."""

    xi_start: float
    xi_end: float
    eta_h: BSpline

    def parameters(self, t):
        t = np.asarray(t, dtype=np.float64)
        xi = self.xi_start + t * (self.xi_end - self.xi_start)
        return np.stack([xi, self.eta_h(np.mod(xi, 1.0))], axis=-1)


def to_tip_chart(p) -> np.ndarray:
    """Blade parameters (ξ, η) -> the tip chart (X, Y) = w (cos 2πξ, sin 2πξ), w = sqrt(1 - η).

    Near the tip the sections are small loops whose size is proportional to w and which
    ξ runs around, so (ξ, w) are polar coordinates about the tip point and (X, Y) is a
    regular chart there (the tip, singular in (ξ, η), is the origin). Cuts are marched
    and splined in this chart."""
    p = np.asarray(p, dtype=np.float64)
    w = np.sqrt(np.clip(1.0 - p[..., 1], 0.0, None))
    a = 2.0 * np.pi * p[..., 0]
    return np.stack([w * np.cos(a), w * np.sin(a)], axis=-1)


def from_tip_chart(c, xi_ref: float = 0.0) -> np.ndarray:
    """The inverse of :func:`to_tip_chart`, with ξ in (xi_ref - 1/2, xi_ref + 1/2]."""
    c = np.asarray(c, dtype=np.float64)
    xi = np.arctan2(c[..., 1], c[..., 0]) / (2.0 * np.pi)
    xi = xi_ref + np.mod(xi - xi_ref + 0.5, 1.0) - 0.5
    return np.stack([xi, 1.0 - (c[..., 0] ** 2 + c[..., 1] ** 2)], axis=-1)


@dataclass(frozen=True, eq=False)
class SplineCurve(ParameterCurve):
    """A parameter curve given by a cubic spline t -> (ξ, η) (Hally Eq. 14 and §6
    step 3), or t -> (X, Y) in the tip chart when ``xi_ref`` is set (the cuts; ξ is then
    reported in (xi_ref - 1/2, xi_ref + 1/2]); optionally displaced off the blade by a
    spline t -> d (Hally §7)."""

    spline: BSpline
    offset: BSpline | None = None
    xi_ref: float | None = None

    def parameters(self, t):
        p = self.spline(np.asarray(t, dtype=np.float64))
        if self.xi_ref is not None:
            return from_tip_chart(p, self.xi_ref)
        p[..., 1] = np.minimum(p[..., 1], 1.0)
        return p

    def as_parameter_spline(self, samples: int = 513) -> "SplineCurve":
        """The same curve as a spline in (ξ, η) (resampled; for curves away from the tip)."""
        if self.xi_ref is None:
            return self
        t = np.linspace(0.0, 1.0, samples)
        return SplineCurve(make_interp_spline(t, self.parameters(t), k=3), self.offset)

    def displacement(self, t):
        if self.offset is None:
            return None
        return self.offset(np.asarray(t, dtype=np.float64))


def periodic_hub_spline(intersection, samples: int = HUB_CURVE_SAMPLES) -> BSpline:
    """η_h(ξ) on [0, 1] as a periodic cubic spline through the Newton solution of the
    blade–hub intersection at ``samples`` points (Hally §4 item 1; Ref. 1 §9.1.6)."""
    xi = np.linspace(0.0, 1.0, samples)
    eta = np.asarray(intersection.eta_h(xi[:-1]), dtype=np.float64)
    eta = np.concatenate([eta, eta[:1]])
    return make_interp_spline(xi, eta, k=3, bc_type="periodic")


# ---------------------------------------------------------------------------------------
# the six defining points and the ten corners (§4)
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class DefiningPoints:
    """The six points of Hally (2013) §4 that split the blade into five surfaces, in
    blade parameters (dimensionless; η = r/R). Defaults suit DTMB 4119 and most
    conventional blades: the central surfaces end about 10% of the chord from the
    leading and trailing edges (ξ = 0.1 and 0.4 map to 9.5% of the chord with the cosine
    chordwise parameter), and the tip surface starts at 0.9 R.

    xi_ll: ξ_LL, lower-left corner of the pressure-side central surface, on the hub
        (trailing-edge side). Default 0.1.
    xi_lr: ξ_LR, lower-right corner, on the hub (leading-edge side). Default 0.4.
    xi_ul, eta_ul: p_UL, upper-left corner (trailing-edge side). Default (0.1, 0.9).
    xi_ur, eta_ur: p_UR, upper-right corner (leading-edge side). Default (0.4, 0.9).
    eta_le: η_LE of x_LE = b(1/2, η_LE) on the leading edge. Default 0.9.
    eta_te: η_TE of x_TE = b(0, η_TE) on the trailing edge. Default 0.9.

    The suction-side corners are the images ξ -> 1 - ξ (Hally §4).
    """

    xi_ll: float = 0.1
    xi_lr: float = 0.4
    xi_ul: float = 0.1
    eta_ul: float = 0.9
    xi_ur: float = 0.4
    eta_ur: float = 0.9
    eta_le: float = 0.9
    eta_te: float = 0.9

    def validate(self, blade=None, field_prefix: str = "") -> None:
        """Refuse points that cannot split the blade (DefinitionError naming the field)."""
        def bad(name, msg):
            raise DefinitionError(msg, field=field_prefix + name)

        for name in ("xi_ll", "xi_lr", "xi_ul", "xi_ur", "eta_ul", "eta_ur", "eta_le", "eta_te"):
            v = getattr(self, name)
            if not isinstance(v, (int, float, np.floating, np.integer)) or not np.isfinite(v):
                bad(name, f"must be a finite number, got {v!r}")
        for name in ("xi_ll", "xi_ul"):
            v = getattr(self, name)
            if not 0.0 < v < 0.25:
                bad(name, f"must lie in (0, 0.25) (pressure side, trailing-edge half), got {v}")
        for name in ("xi_lr", "xi_ur"):
            v = getattr(self, name)
            if not 0.25 < v < 0.5:
                bad(name, f"must lie in (0.25, 0.5) (pressure side, leading-edge half), got {v}")
        lo = blade.hub_ratio if blade is not None else 0.0
        for name in ("eta_ul", "eta_ur", "eta_le", "eta_te"):
            v = getattr(self, name)
            if not lo < v < 1.0:
                bad(name, f"must lie between the hub radius ratio {lo:.4g} and the tip 1, got {v}")


@dataclass(frozen=True, eq=False)
class Corners:
    """The ten corner points (Hally §4, Fig. 4) in blade parameters, (2,) each, with the
    leading/trailing-edge points and the points where the edges meet the hub.

    Pressure side: ll, lr (on the hub), ul, ur. Suction side (superscript (s)):
    ll_s = (1 - ξ_LR, η_h), lr_s = (1 - ξ_LL, η_h), ul_s = (1 - ξ_UR, η_UR),
    ur_s = (1 - ξ_UL, η_UL). le = (1/2, η_LE), te = (0, η_TE); le_hub = (1/2, η_h(1/2)),
    te_hub = (0, η_h(0)). ``eta_h`` is the periodic spline of η_h(ξ)."""

    ll: np.ndarray
    lr: np.ndarray
    ul: np.ndarray
    ur: np.ndarray
    ll_s: np.ndarray
    lr_s: np.ndarray
    ul_s: np.ndarray
    ur_s: np.ndarray
    le: np.ndarray
    te: np.ndarray
    le_hub: np.ndarray
    te_hub: np.ndarray
    eta_h: BSpline = field(repr=False)

    def points(self, blade) -> dict[str, np.ndarray]:
        """The corner points b(p) in metres, by name."""
        names = ("ll", "lr", "ul", "ur", "ll_s", "lr_s", "ul_s", "ur_s", "le", "te", "le_hub", "te_hub")
        P = blade_points(blade, np.stack([getattr(self, n) for n in names]))
        return dict(zip(names, P))


def corner_points(blade, intersection, points: DefiningPoints) -> Corners:
    """The ten corners from the six defining points (Hally §4 items 1–6 and the (s)
    images under ξ -> 1 - ξ)."""
    points.validate(blade)
    eta_h = periodic_hub_spline(intersection)
    h = lambda xi: float(eta_h(np.mod(xi, 1.0)))  # noqa: E731
    d = points
    a = np.array
    c = Corners(
        ll=a([d.xi_ll, h(d.xi_ll)]),
        lr=a([d.xi_lr, h(d.xi_lr)]),
        ul=a([d.xi_ul, d.eta_ul]),
        ur=a([d.xi_ur, d.eta_ur]),
        ll_s=a([1.0 - d.xi_lr, h(1.0 - d.xi_lr)]),
        lr_s=a([1.0 - d.xi_ll, h(1.0 - d.xi_ll)]),
        ul_s=a([1.0 - d.xi_ur, d.eta_ur]),
        ur_s=a([1.0 - d.xi_ul, d.eta_ul]),
        le=a([0.5, d.eta_le]),
        te=a([0.0, d.eta_te]),
        le_hub=a([0.5, h(0.5)]),
        te_hub=a([0.0, h(0.0)]),
        eta_h=eta_h,
    )
    for name in ("ul", "ur", "le", "te"):
        eta = getattr(c, name)[1]
        hub = h(getattr(c, name)[0])
        if eta <= hub:
            raise DefinitionError(
                f"the point lies at or below the blade–hub intersection (η = {eta:.4g} <= η_h = {hub:.4g})",
                field=f"eta_{name}",
            )
    return c


# ---------------------------------------------------------------------------------------
# the twelve edge curves (Fig. 5)
# ---------------------------------------------------------------------------------------
def hub_edge_curves(corners: Corners) -> dict[str, ParameterCurve]:
    """c_1 ... c_4 along the blade–hub intersection (Hally Eqs. 2–5).

    c_1 wraps the trailing edge from x_LR^(s) to x_LL with ξ(u) = (2u - 1) ξ_LL (ξ runs
    through 0: the periodic blade); c_2 runs x_LL -> x_LR; c_3 wraps the leading edge
    x_LR -> x_LL^(s); c_4 runs x_LL^(s) -> x_LR^(s) (Eq. 5, printed as c_3)."""
    c = corners
    return {
        "c1": HubCurve(c.lr_s[0] - 1.0, c.ll[0], c.eta_h),
        "c2": HubCurve(c.ll[0], c.lr[0], c.eta_h),
        "c3": HubCurve(c.lr[0], c.ll_s[0], c.eta_h),
        "c4": HubCurve(c.ll_s[0], c.lr_s[0], c.eta_h),
    }


def top_edge_curves(corners: Corners, blade=None, sides: dict | None = None) -> dict[str, ParameterCurve]:
    """c_9 (x_UL -> x_UR) and c_10 (x_UL^(s) -> x_UR^(s)).

    Without ``blade``: straight in parameter space (Hally Eqs. 6–7). With ``blade`` and the
    side curves ``sides`` (c_5 ... c_8 of §5): the same lines bent near their ends so that
    the tip surface has no 180° corners (:func:`raised_top_edge`; a deviation from Hally,
    see :data:`TOP_EDGE_BEND_FRACTION`)."""
    if blade is None or not BEND_TOP_EDGES:
        return {"c9": LineCurve(corners.ul, corners.ur), "c10": LineCurve(corners.ul_s, corners.ur_s)}
    X = corners.points(blade)
    plane_c11 = (X["ul"], X["te"], X["ur_s"])  # Hally §4 item 11
    plane_c12 = (X["ur"], X["le"], X["ul_s"])  # item 12
    return {
        "c9": raised_top_edge(blade, corners.ul, corners.ur, (plane_c11, sides["c5"]), (plane_c12, sides["c6"]), "c9"),
        "c10": raised_top_edge(blade, corners.ul_s, corners.ur_s, (plane_c12, sides["c7"]), (plane_c11, sides["c8"]),
                               "c10"),
    }


# ---------------------------------------------------------------------------------------
# the tip surface's corners
# ---------------------------------------------------------------------------------------
#: Fraction of c_9 / c_10 (in its parameter) at each end over which it departs from
#: Hally's straight line (Eqs. 6–7) and returns to it.
#:
#: Why: at x_UL, x_UR and their suction-side images three surfaces meet: the central surface
#: (between c_5/c_6 and c_9), the edge surface (between c_5/c_6 and c_11/c_12) and the tip
#: surface (between c_11/c_12 and c_9). With Hally's straight c_9 the central and edge
#: surfaces take about 90° each, so the tip surface's corner is about 180°: its boundary
#: curves c_11 and c_9 continue each other and S_u, S_v of the tip surface are parallel
#: there (measured min sin∠(S_u, S_v) 5e-4 to 9e-4 next to the corners), which no
#: re-parameterisation of a four-sided patch can cure. Here c_9 leaves each corner along
#: the direction opposite to the bisector of the edge surface's corner, so the central and
#: the tip surface share the remaining angle equally (180° minus half the edge surface's
#: corner angle each), and rejoins the straight line within this fraction, so the tip cuts
#: in the middle (the smoothed ones, near the tip) are Hally's.
TOP_EDGE_BEND_FRACTION = 0.2
#: Bend c_9/c_10 at their ends (:func:`raised_top_edge`) when the blade is given to
#: :func:`top_edge_curves`. Off by default: measured, the bend lifts the tip surface's
#: corner min sin∠(S_u, S_v) from 5e-4–2e-3 to 0.05–0.40, but the gmsh 3-D mesh of the
#: full DTMB 4119 (tests/iges/test_full_propeller_mesh.py, five-surface layout) then drops
#: from min SICN 0.068 to 0.046 (0.027–0.034 with other bend lengths), its worst elements
#: sitting on triangles that straddle the wrap-around faces' edges, not at the corners. With
#: the edges split (blade_surfaces.split_at_edges) the 2-D meshes of every face have 0 invalid
#: elements with or without the bend (tests/iges/test_propeller_face_mesh.py).
BEND_TOP_EDGES = False
#: Largest departure angle (degrees) of c_9 / c_10 from the straight line: below 90° the
#: bent edge keeps moving along the chord (with :func:`_bump`, its chordwise speed stays
#: above 1 - 0.25 (1 - cos θ) ... >= 1/2 of the line's at 60°), so the tip cuts through
#: its points stay in order and the tip surface cannot fold.
TOP_EDGE_MAX_DEPARTURE_DEG = 60.0


def _bump(x, f):
    """B(x) = x (1 - x/f)³ on [0, f], 0 beyond: B(0) = 0, B'(0) = 1, and B, B', B'' vanish
    at x = f (the bent curve rejoins the line C2)."""
    x = np.asarray(x, dtype=np.float64)
    return np.where(x < f, x * np.clip(1.0 - x / f, 0.0, None) ** 3, 0.0)


@dataclass(frozen=True, eq=False)
class RaisedLineCurve(ParameterCurve):
    """The straight line of Hally Eqs. 6–7 bent at its ends:
    p(t) = p_a + t (p_b - p_a) + B(t) e_a - B(1 - t) e_b, B = :func:`_bump` over ``bend``,
    so p'(0) = (p_b - p_a) + e_a and p'(1) = (p_b - p_a) + e_b, and p is the line for
    t in [bend, 1 - bend]."""

    start: np.ndarray
    end: np.ndarray
    bend_start: np.ndarray
    bend_end: np.ndarray
    bend: float

    def parameters(self, t):
        t = np.asarray(t, dtype=np.float64)
        a, b, f = np.asarray(self.start), np.asarray(self.end), self.bend
        return (a + t[..., None] * (b - a) + _bump(t, f)[..., None] * np.asarray(self.bend_start)
                - _bump(1.0 - t, f)[..., None] * np.asarray(self.bend_end))


def _unit(v):
    return v / np.linalg.norm(v)


def _corner_tangent(blade, p, delta, plane, side, at_start: bool, name: str):
    """At the corner p of a top edge (chord direction delta in parameters): the parameter
    direction d with b_ξ d_ξ + b_η d_η = the unit tangent along which the top edge leaves
    the corner (opposite to the bisector of the out-going tangents of the cut through
    ``plane`` and of the side curve), and |a|, a = b_ξ delta_ξ + b_η delta_η."""
    D = blade_derivatives(blade, np.asarray(p, dtype=np.float64)[None], 1)[0]
    bx, be = D[1, 0], D[0, 1]
    J = np.stack([bx, be], axis=1)  # (3, 2)
    a = J @ delta
    n_blade = np.cross(bx, be)
    x0, x1, x2 = plane
    n_plane = np.cross(x1 - x0, x1 - x2)  # Hally Eq. 15
    cut = np.cross(n_blade, n_plane)
    cut = _unit(cut if (cut @ a > 0) != at_start else -cut)  # away from the top edge
    eps = 1e-6
    q1, q0 = side.parameters(np.array([1.0, 1.0 - eps]))
    dq = q1 - q0
    dq[0] = np.mod(dq[0] + 0.5, 1.0) - 0.5
    down = _unit(-(J @ dq))  # the side curve leaving the corner towards the hub
    out = -(cut + down)
    out = out - (out @ _unit(n_blade)) * _unit(n_blade)
    if not np.linalg.norm(out) > 1e-3 * np.linalg.norm(cut + down + out):
        raise GeometryError(f"{name}: the cut and the side curve leave the corner in opposite directions")
    out = _unit(out)
    along = _unit(a if at_start else -a)  # Hally's straight top edge leaving the corner
    perp = _unit(np.cross(n_blade, along))
    if perp @ be < 0.0:
        perp = -perp  # towards the tip
    phi = float(np.arctan2(out @ perp, out @ along))
    if not phi > 0.0:
        raise GeometryError(f"{name}: the edge surface's corner at ξ = {p[0]:.4g}, η = {p[1]:.4g} is reflex")
    phi = min(phi, np.radians(TOP_EDGE_MAX_DEPARTURE_DEG))
    out = np.cos(phi) * along + np.sin(phi) * perp
    d = np.linalg.solve(J.T @ J, J.T @ out)
    return d, float(np.linalg.norm(a))


def raised_top_edge(blade, p_start, p_end, start_neighbours, end_neighbours, name: str = "top edge",
                    bend: float = TOP_EDGE_BEND_FRACTION) -> RaisedLineCurve:
    """c_9 or c_10 (Hally Eqs. 6–7) bent over ``bend`` of its length at each end so that it
    leaves each corner opposite to the bisector of the edge surface's corner there
    (:data:`TOP_EDGE_BEND_FRACTION`). ``*_neighbours``: (the three points of the cut's plane,
    the side curve ending at that corner). The end speeds are kept (|b' | = |a|)."""
    p_start, p_end = np.asarray(p_start, dtype=np.float64), np.asarray(p_end, dtype=np.float64)
    delta = p_end - p_start
    d0, a0 = _corner_tangent(blade, p_start, delta, *start_neighbours, True, name)
    d1, a1 = _corner_tangent(blade, p_end, delta, *end_neighbours, False, name)
    curve = RaisedLineCurve(p_start, p_end, a0 * d0 - delta, -a1 * d1 - delta, float(bend))
    eta = curve.parameters(np.linspace(0.0, 1.0, 101))[:, 1]
    if not eta.max() < 1.0 - ETA_TIP_GUARD:
        raise GeometryError(f"{name}: bent to η = {eta.max():.4g}, beyond the tip; lower eta_ul / eta_ur")
    return curve


def check_corner_order(corners: Corners) -> None:
    """The central surfaces must not be inverted: ξ_LL < ξ_LR and ξ_UL < ξ_UR."""
    if not corners.ll[0] < corners.lr[0]:
        raise DefinitionError(f"xi_ll ({corners.ll[0]}) must be smaller than xi_lr ({corners.lr[0]})", field="xi_ll")
    if not corners.ul[0] < corners.ur[0]:
        raise DefinitionError(f"xi_ul ({corners.ul[0]}) must be smaller than xi_ur ({corners.ur[0]})", field="xi_ul")


def require_finite(name: str, values) -> None:
    if not np.all(np.isfinite(values)):
        raise GeometryError(f"{name}: non-finite values")
