"""The curves that wrap the leading edge, the trailing edge and the tip (Hally 2013 §8,
Eqs. 31–49).

- c_LETE(s): up the trailing edge from the hub to the tip, then down the leading edge to
  the hub, s the fractional arclength (total length L); its parameters p_LETE(s) have
  ξ = 0 on the trailing edge and ξ = 1/2 on the leading edge. The arclength is taken in
  w = sqrt(1 - η), in which the edges are smooth up to the closing tip.
- Tip cuts (Eqs. 31–33): about L (s_LE - s_TE) / Δc + 1 cuts, at most Δc apart, through
  x_0 = c_9(u), x_1 = c_LETE(s_TE + u (s_LE - s_TE)), x_2 = c_10(1 - u). Cut 1 is c_11 and
  cut N_t is c_12. The tip point lies midway between two cuts (tip_cut_positions;
  Hally does not discuss cuts at the singular tip).
- Leading-edge curves (Eqs. 34–35, 49): N_LE = N_TE = ceil(max(1 - s_LE, s_TE) L / Δc) + 1;
  curve i >= j is the cut through x_0 = c_6(u_i), x_1 = c_LETE(1 - u_i (1 - s_LE)),
  x_2 = c_7(u_i); curve N_LE is c_12. Trailing edge likewise with x_0 = c_8(u_i),
  x_1 = c_LETE(u_i s_TE), x_2 = c_5(u_i) (running suction -> pressure, ξ increasing
  through 0, the orientation of c_1); curve N_TE is c_11 reversed.
- A cut is smoothed (§7) when its edge point is within d_t of the tip along c_LETE.
- Below the transition cut j the curves come from the transfinite interpolation in
  parameter space between c_3 (c_1), cut j, c_6 (c_8) and c_7 (c_5) (Eqs. 36–47), with the
  re-parameterisation of Eqs. 38–40 so that every curve passes through its edge point at
  v = 1/2; f_u, f_v of Eq. 42 are found by Newton.

Corrections to the printed §8 (the text is written with s measured from the leading-edge
hub in places): the TFI corners of Eq. 41 are those of its four boundaries,
q(0,0) = p_3(0), q(0,1) = p_3(1), q(u_j,0) = p_c(0), q(u_j,1) = p_c(1) (printed p_LL,
p_LR^(s), p_UR, p_UL^(s)); the edge target of Eq. 42 is the edge point of curve i,
p_LETE(1 - u(1 - s_LE)) on the leading edge and p_LETE(u s_TE) on the trailing edge; j is
the first curve whose edge point lies above s_j (s < s_j on the leading edge); the
smoothing test after Eq. 35 reads (1 - u(1 - s_LE) - s_tip) L < d_t. One transition
index j serves both edges (N_LE = N_TE), and both cuts j must lie outside the smoothing
range.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import make_interp_spline

from ..errors import DefinitionError, GeometryError
from .corners import Corners, HubCurve, ParameterCurve, SplineCurve, blade_points, hub_edge_curves, top_edge_curves
from .cut_smoothing import GUARD_BOUND_FRACTION, SMOOTHING_ZONE_BOUND, smooth_cuts
from .cuts import blade_cache, march_cuts

#: Samples of each edge (in w = sqrt(1 - η)) for the arclength of c_LETE.
LETE_SAMPLES = 1025
#: Newton for f_u, f_v (Eq. 42): tolerance and iteration cap.
TFI_NEWTON_TOL = 1e-14
TFI_NEWTON_MAX_ITERATIONS = 40
#: Fewest curves across an edge surface (cubic interpolation across the curves).
MIN_CURVES = 4


@dataclass(frozen=True, eq=False)
class LeteCurve:
    """c_LETE(s) of Hally §8 (Fig. 7): total length L (m), s_tip, and the arclength maps.
    ``parameters(s)`` gives p_LETE(s) (ξ = 0 on the trailing edge, 1/2 on the leading
    edge); ``s_of(edge, eta)`` the s of a point of an edge."""

    length: float
    s_tip: float
    _w_te: object = field(repr=False)
    _w_le: object = field(repr=False)
    _s_te: object = field(repr=False)
    _s_le: object = field(repr=False)

    @classmethod
    def build(cls, blade, corners: Corners, samples: int = LETE_SAMPLES) -> "LeteCurve":
        parts = {}
        for name, p_hub, xi in (("te", corners.te_hub, 0.0), ("le", corners.le_hub, 0.5)):
            w_hub = np.sqrt(1.0 - p_hub[1])
            w = np.linspace(w_hub, 0.0, samples)  # hub -> tip
            X = blade.evaluate(np.full(samples, xi), 1.0 - w**2)
            sigma = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(X, axis=0), axis=1))])
            parts[name] = (w, sigma)
        (w_te, s_te), (w_le, s_le) = parts["te"], parts["le"]
        L_te, L_le = s_te[-1], s_le[-1]
        L = L_te + L_le
        # TE: s = σ/L from the hub up; LE: s = (L_te + (L_le - σ))/L from the tip down
        te_w = make_interp_spline(s_te / L, w_te, k=3)
        le_s = (L_te + (L_le - s_le)) / L
        le_w = make_interp_spline(le_s[::-1], w_le[::-1], k=3)
        te_s = make_interp_spline(w_te[::-1], (s_te / L)[::-1], k=3)
        le_sw = make_interp_spline(w_le[::-1], le_s[::-1], k=3)
        return cls(float(L), float(L_te / L), te_w, le_w, te_s, le_sw)

    def parameters(self, s) -> np.ndarray:
        s = np.clip(np.asarray(s, dtype=np.float64), 0.0, 1.0)
        te = s <= self.s_tip
        w = np.where(te, self._w_te(np.minimum(s, self.s_tip)), self._w_le(np.maximum(s, self.s_tip)))
        w = np.clip(w, 0.0, None)
        return np.stack([np.where(te, 0.0, 0.5), 1.0 - w**2], axis=-1)

    def points(self, blade, s) -> np.ndarray:
        return blade_points(blade, self.parameters(s))

    def s_of(self, edge: str, eta: float) -> float:
        w = np.sqrt(1.0 - eta)
        return float(self._s_te(w) if edge == "te" else self._s_le(w))


def tip_cut_positions(s_te: float, s_tip: float, s_le: float, spacing: float) -> np.ndarray:
    """The s of the tip cuts' edge points x_1 (Hally Eqs. 31–33): from s_TE to s_LE, no two
    more than ``spacing`` (Δc/L) apart, and the tip point s_tip midway between two cuts,
    each side of it evenly spaced: n_a cuts s_TE + i δ_a (i < n_a) with
    δ_a = (s_tip - s_TE)/(n_a - 1/2), likewise n_b cuts down from s_LE.

    Hally spaces all N_t cuts evenly (Eq. 33) and does not discuss a cut that falls on or
    next to the tip, where the blade parameterisation is singular. Moving such a cut
    aside (the earlier rule: to Δc/2 from the tip) can put it next to its
    neighbour (measured 6e-4 in s apart on steep_coarse), and the tip surface, which
    interpolates its cuts at even v_j (Eq. 50), then folds between the two. Here the cuts
    nearest the tip are at least spacing/2 · x/(x + 1) from it (x = the edge's length in
    spacings) and the spacing never exceeds Δc."""
    if not s_te < s_tip < s_le:
        raise DefinitionError("x_TE and x_LE must lie below the tip on their edges",
                              field="eta_te" if not s_te < s_tip else "eta_le")
    n_a = int(np.ceil((s_tip - s_te) / spacing + 0.5))
    n_b = int(np.ceil((s_le - s_tip) / spacing + 0.5))
    d_a = (s_tip - s_te) / (n_a - 0.5)
    d_b = (s_le - s_tip) / (n_b - 0.5)
    te_side = s_te + d_a * np.arange(n_a)
    le_side = (s_le - d_b * np.arange(n_b))[::-1]
    return np.concatenate([te_side, le_side])


@dataclass(frozen=True, eq=False)
class TFICurve(ParameterCurve):
    """Curve i below the transition cut (Hally Eqs. 37–41): t -> q(U(u_i, t), V(u_i, t)),
    U = u + 4t(1 - t)(f_u - u), V = t + 4t(1 - t)(f_v - 1/2)."""

    bottom: ParameterCurve  # p_3 (or p_1): hub curve, t in [0, 1]
    transition: SplineCurve  # p_c: cut j
    first: SplineCurve  # p_6 (or p_8): at v = 0
    second: SplineCurve  # p_7 (or p_5): at v = 1
    u_j: float
    u: float
    f_u: float
    f_v: float

    def parameters(self, t):
        t = np.asarray(t, dtype=np.float64)
        bump = 4.0 * t * (1.0 - t)
        U = self.u + bump * (self.f_u - self.u)
        V = t + bump * (self.f_v - 0.5)
        return tfi_q(self, U, V)


def _hub_derivative(curve: HubCurve, t):
    dxi = curve.xi_end - curve.xi_start
    xi = curve.xi_start + np.asarray(t) * dxi
    return np.stack([np.full_like(xi, dxi), curve.eta_h(np.mod(xi, 1.0), 1) * dxi], axis=-1)


def tfi_q(c, U, V, derivatives: bool = False):
    """q(U, V) of Hally Eq. 41 (with the corners of its boundaries), and optionally
    ∂q/∂U, ∂q/∂V."""
    U, V = np.broadcast_arrays(np.asarray(U, float), np.asarray(V, float))
    uj = c.u_j
    a = ((uj - U) / uj)[..., None]
    b = (U / uj)[..., None]
    Vv = V[..., None]
    P3, Pc = c.bottom.parameters(V), c.transition.spline(V)
    P6, P7 = c.first.spline(U), c.second.spline(U)
    q00, q01 = c.bottom.parameters(np.array(0.0)), c.bottom.parameters(np.array(1.0))
    qj0, qj1 = c.transition.spline(0.0), c.transition.spline(1.0)
    q = a * P3 + b * Pc + (1 - Vv) * P6 + Vv * P7 - (a * (1 - Vv) * q00 + a * Vv * q01 + b * (1 - Vv) * qj0 + b * Vv * qj1)
    if not derivatives:
        return q
    qu = (Pc - P3) / uj + (1 - Vv) * c.first.spline(U, 1) + Vv * c.second.spline(U, 1) - (
        ((1 - Vv) * (qj0 - q00) + Vv * (qj1 - q01)) / uj)
    qv = a * _hub_derivative(c.bottom, V) + b * c.transition.spline(V, 1) - P6 + P7 - (
        a * (q01 - q00) + b * (qj1 - qj0))
    return q, qu, qv


def tfi_curves(bottom, transition, first, second, u_values, u_j, targets, label) -> list[TFICurve]:
    """The curves of Eqs. 37–47 for the u values below u_j, with f_u, f_v from Newton on
    q(f_u, f_v) = target (Eq. 42), all at once."""
    proto = TFICurve(bottom, transition, first, second, u_j, 0.0, 0.0, 0.5)
    u = np.asarray(u_values, float)
    F = np.stack([u, np.full_like(u, 0.5)], axis=1)
    for _ in range(TFI_NEWTON_MAX_ITERATIONS):
        q, qu, qv = tfi_q(proto, F[:, 0], F[:, 1], derivatives=True)
        r = q - targets
        J = np.stack([qu, qv], axis=-1)  # (n, 2, 2)
        delta = np.linalg.solve(J, -r[..., None])[..., 0]
        F += delta
        if np.max(np.abs(delta)) < TFI_NEWTON_TOL:
            break
    else:
        k = int(np.argmax(np.abs(delta).max(axis=1)))
        raise GeometryError(
            f"{label} curve {k + 1}: Newton for f_u, f_v (Hally Eq. 42) did not converge "
            f"(ξ = {targets[k, 0]:.6g}, η = {targets[k, 1]:.6g})"
        )
    return [TFICurve(bottom, transition, first, second, u_j, float(ui), float(fu), float(fv))
            for ui, (fu, fv) in zip(u, F)]


@dataclass(frozen=True, eq=False)
class EdgeCurveSet:
    """Everything §8 produces: c_LETE, the curve families (each a list of
    ParameterCurve, parameter t in [0, 1], t = 1/2 on the edge), the raw cuts and their
    smoothing, and the indices.

    tip: N_t curves from c_11 (u = 0) to c_12; leading: N_LE curves from c_3 to c_12
    (pressure -> suction); trailing: N_TE curves from c_1 to c_11 reversed (suction ->
    pressure). transition: j (0-based index of the transition cut in the edge
    families). smoothed_*: which curves were smoothed (bool arrays)."""

    lete: LeteCurve
    s_le: float
    s_te: float
    tip: list
    leading: list
    trailing: list
    transition: int
    u_edge: np.ndarray
    u_tip: np.ndarray
    s_tip_cuts: np.ndarray
    s_le_curves: np.ndarray
    s_te_curves: np.ndarray
    smoothed_tip: np.ndarray
    smoothed_leading: np.ndarray
    smoothed_trailing: np.ndarray
    cuts: dict
    smoothing: dict
    edges: dict


def build_edge_curves(blade, corners: Corners, sides: dict, settings, progress=None) -> EdgeCurveSet:
    """Hally §8 (Eqs. 31–49) for a blade, its corners and side curves c_5..c_8, with the
    settings of :class:`~.smoothing.SmoothingSettings` (lengths as fractions of R)."""
    R = blade.radius
    dc = settings.delta_c * R
    d_t = settings.tip_smoothing_distance * R
    d_e = settings.edge_smoothing_distance * R
    lete = LeteCurve.build(blade, corners)
    L, s_tip = lete.length, lete.s_tip
    s_le = lete.s_of("le", corners.le[1])
    s_te = lete.s_of("te", corners.te[1])
    if d_t >= min(s_tip, 1.0 - s_tip) * L:
        raise DefinitionError(
            f"{d_t:.4g} m is longer than the leading or trailing edge ({min(s_tip, 1 - s_tip) * L:.4g} m): "
            "the smoothing range must end on the blade",
            field="tip_smoothing_distance",
        )
    # Eq. 31, with the tip point midway between two cuts (see tip_cut_positions)
    s_cut = tip_cut_positions(s_te, s_tip, s_le, dc / L)
    N_t = s_cut.size
    N = int(np.ceil(max(1.0 - s_le, s_te) * L / dc)) + 1  # Eq. 49
    if min(N_t, N) < MIN_CURVES:
        raise DefinitionError(
            f"Δc = {dc:.4g} m gives only {min(N_t, N)} curves across a surface; at least {MIN_CURVES} are needed",
            field="delta_c",
        )
    # --- tip cuts (Eqs. 32–33)
    u_tip = (s_cut - s_te) / (s_le - s_te)  # Eq. 33 solved for u (Eq. 32: x_1 = c_LETE(s_te + u (s_le - s_te)))
    u_tip[0], u_tip[-1] = 0.0, 1.0
    top = top_edge_curves(corners, blade, sides)  # c_9, c_10 raised at their ends (corners.py)
    c9 = top["c9"].parameters(u_tip)
    c10 = top["c10"].parameters(1.0 - u_tip)
    p1_tip = lete.parameters(s_cut)
    c10 = c10 - np.where(p1_tip[:, :1] == 0.0, [[1.0, 0.0]], 0.0)  # periodic blade across the TE
    # --- edge families (Eqs. 34–35, 48)
    u = np.arange(N) / (N - 1)
    s_le_c = 1.0 - u * (1.0 - s_le)
    s_te_c = u * s_te
    s_j = settings.transition_s
    if not s_le < s_j < 1.0:
        raise DefinitionError(
            f"s_j = {s_j} must lie between s_LE = {s_le:.4f} (the top leading-edge cut) and 1 (the hub)",
            field="transition_s",
        )
    if not s_j > s_tip + d_t / L:  # Eq. 48
        raise DefinitionError(
            f"s_j = {s_j} lies inside the tip smoothing range: Hally Eq. 48 needs s_j > s_tip + d_t/L = "
            f"{s_tip + d_t / L:.4f}",
            field="transition_s",
        )
    j = int(np.flatnonzero(s_le_c < s_j)[0])
    if j < 1:
        raise DefinitionError("s_j is too close to the hub: no curve lies below the transition cut",
                              field="transition_s")
    if (s_le_c[j] - s_tip) * L < d_t or (s_tip - s_te_c[j]) * L < d_t:
        raise DefinitionError(
            f"the transition cut j = {j + 1} (leading edge at s = {s_le_c[j]:.4f}, trailing edge at "
            f"s = {s_te_c[j]:.4f}) lies inside the tip smoothing range d_t; lower s_j",
            field="transition_s",
        )
    c5, c6, c7, c8 = (sides[k] for k in ("c5", "c6", "c7", "c8"))
    ie = np.arange(j, N - 1)  # cuts below the top
    p_le = (c6.spline(u[ie]), lete.parameters(s_le_c[ie]), c7.spline(u[ie]))
    p_te = (c8.spline(u[ie]), lete.parameters(s_te_c[ie]), c5.spline(u[ie]))
    labels = ([f"tip {i + 1}" for i in range(N_t)] + [f"LE {i + 1}" for i in ie] + [f"TE {i + 1}" for i in ie])
    P0 = np.concatenate([c9, p_le[0], p_te[0]])
    P1 = np.concatenate([p1_tip, p_le[1], p_te[1]])
    P2 = np.concatenate([c10, p_le[2], p_te[2]])
    if progress:
        progress("cuts", 0.0)
    cache = blade_cache(blade)
    all_cuts = march_cuts(blade, P0, P1, P2, labels=labels, cache=cache)
    tip_cuts = all_cuts[:N_t]
    le_cuts = all_cuts[N_t : N_t + len(ie)]
    te_cuts = all_cuts[N_t + len(ie) :]
    if progress:
        progress("cuts", 1.0)
    # --- smoothing (§7)
    kw = dict(d_t=d_t, d_e=d_e, strength=settings.filter_strength, iterations=settings.filter_iterations,
              spacing=settings.sample_spacing * R, edge_spacing=settings.sample_spacing * settings.edge_spacing_ratio * R,
              bound=GUARD_BOUND_FRACTION * SMOOTHING_ZONE_BOUND * R)
    smoothing = {}
    # every cut within d_t of the tip, smoothed in one batch (cut_smoothing.smooth_cuts)
    todo = [(c, abs(s - s_tip) * L, ("tip", i)) for i, (c, s) in enumerate(zip(tip_cuts, s_cut))]
    todo += [(c, abs(s_le_c[i] - s_tip) * L, ("leading", i)) for c, i in zip(le_cuts, ie)]
    todo += [(c, abs(s_te_c[i] - s_tip) * L, ("trailing", i)) for c, i in zip(te_cuts, ie)]
    todo = [x for x in todo if x[1] < d_t]
    smoothing.update(zip([x[2] for x in todo], smooth_cuts(blade, [x[0] for x in todo], [x[1] for x in todo], **kw)))

    def finish(cut, s_edge, key):
        sm = smoothing.get(key)
        if sm is not None:
            return sm.curve, True
        return cut.curve, False

    tip_curves, sm_tip = zip(*[finish(c, s, ("tip", i)) for i, (c, s) in enumerate(zip(tip_cuts, s_cut))])
    le_top, te_top = tip_curves[-1], tip_curves[0]
    le_upper = [finish(c, s_le_c[i], ("leading", i)) for c, i in zip(le_cuts, ie)]
    te_upper = [finish(c, s_te_c[i], ("trailing", i)) for c, i in zip(te_cuts, ie)]
    # --- transfinite interpolation below cut j (Eqs. 36–47)
    hub = hub_edge_curves(corners)
    if j == N - 1:
        le_j, te_j = le_top, te_top.reversed()
        if sm_tip[-1] or sm_tip[0]:
            raise DefinitionError("the transition cut is smoothed", field="transition_s")
    else:
        le_j, te_j = le_upper[0][0], te_upper[0][0]
    if not isinstance(le_j, SplineCurve) or le_j.offset is not None:
        raise DefinitionError("the transition cut is smoothed", field="transition_s")
    if not isinstance(te_j, SplineCurve):
        te_j = SplineCurve(make_interp_spline(np.linspace(0, 1, 513), te_j.parameters(np.linspace(0, 1, 513)), k=3))
    le_j, te_j = le_j.as_parameter_spline(), te_j.as_parameter_spline()
    le_low = tfi_curves(hub["c3"], le_j, c6, c7, u[:j], u[j], lete.parameters(s_le_c[:j]), "leading-edge")
    te_low = tfi_curves(hub["c1"], te_j, c8, c5, u[:j], u[j], lete.parameters(s_te_c[:j]), "trailing-edge")
    leading = list(le_low) + [c for c, _ in le_upper] + [le_top]
    trailing = list(te_low) + [c for c, _ in te_upper] + [te_top.reversed()]
    sm_le = np.array([False] * j + [f for _, f in le_upper] + [sm_tip[-1]])
    sm_te = np.array([False] * j + [f for _, f in te_upper] + [sm_tip[0]])
    edges = {**hub, **top, **sides, "c11": tip_curves[0], "c12": tip_curves[-1]}
    return EdgeCurveSet(
        lete=lete, s_le=s_le, s_te=s_te, tip=list(tip_curves), leading=leading, trailing=trailing, transition=j,
        u_edge=u, u_tip=u_tip, s_tip_cuts=s_cut, s_le_curves=s_le_c, s_te_curves=s_te_c,
        smoothed_tip=np.array(sm_tip), smoothed_leading=sm_le, smoothed_trailing=sm_te,
        cuts={"tip": tip_cuts, "leading": dict(zip(ie.tolist(), le_cuts)), "trailing": dict(zip(ie.tolist(), te_cuts))},
        smoothing=smoothing, edges=edges,
    )
