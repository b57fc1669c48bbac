"""The reference blade b(ξ, η) of a propeller defined by a table of sections.

Conventions (Hally 2013 §2, Eq. 1; standard propeller practice for pitch, skew, rake):

Axes. z is the propeller axis, increasing from upstream to downstream; y runs outward
along the reference line (the generator line of the reference blade, at top dead
centre); x completes a right-handed system (to starboard). The angle ϕ about the axis is
measured from +y towards +x: point (x, y) = (r sin ϕ, r cos ϕ). A right-handed propeller
turns clockwise seen from astern (from downstream, looking upstream), i.e. towards +ϕ;
its angular velocity is along -z.

Parameters. η = r/R, R = D/2: 0 on the axis, 1 at the tip. The model is defined for
η in [eta_min, 1] with eta_min below the hub radius, so that the blade–hub intersection
exists; the radial distributions are extended below the first station linearly, which is
C2 because the splines have a natural end condition (zero second derivative) there.
ξ is periodic with period 1: on a right-handed blade ξ runs from 0 at the trailing edge
along the pressure side to 0.5 at the leading edge, then along the suction side back to
the trailing edge at 1; on a left-handed blade the suction side comes first
(b_left(ξ, η) = M b_right(1 - ξ, η), M the mirror x -> -x). Either way b_ξ × b_η points
out of the blade (Hally 2013 Eq. 1). Every point b(ξ, η) lies on the cylinder r = ηR
(cylindrical sections), so the section cut at radius r is the curve ξ -> b(ξ, r/R).

Radial distributions. C2 cubic splines in η through the stations (scipy
``CubicSpline``; natural at the root, not-a-knot at the tip) for pitch P, skew θ_s, rake
i_G, t/c and f/c. The chord is splined as c² when the table's tip chord is zero: a
rounded tip has c ~ sqrt(1 - r/R) (c² is then regular and linear at the tip, so
c = sqrt(spline) reproduces the square-root closure); this is the coordinate singularity
that tip smoothing removes (Hally 2013 §1, §3). A finite tip chord is splined directly.

Section placement. The section (unit chord; x from the LE, y to the suction side; see
:mod:`bladesmith.geometry.sections.shape`) is scaled by the chord c and laid on the
developed cylinder (s = rϕ, z) with its nose–tail line on the helix of pitch P through
the mid-chord point: pitch angle φ = atan(P / 2πr); the TE lies towards -ϕ and +z (the
LE leads the rotation and faces upstream), the suction side faces upstream. The mid-chord
point is at ϕ_m = -θ_s (positive skew is skew-back, against the rotation) and at
z_m = i_G + r θ_s tan φ: i_G is the generator-line rake (positive downstream, aft) and
r θ_s tan φ the skew-induced rake, so the mid-chord point lies on the pitch helix through
the generator-line point (0, r, i_G). Hence

  s = r ϕ_m + c(-(X - 1/2) cos φ - Y sin φ),  z = z_m + c((X - 1/2) sin φ - Y cos φ),
  b = (h r sin(s/r), r cos(s/r), z),  h = +1 right hand, -1 left hand.

Derivatives are analytic (second-order forward mode, :mod:`.jet`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline, PPoly
from scipy.optimize import minimize_scalar

from ..errors import DefinitionError, GeometryError
from ..sections.shape import SectionShape, polygons_are_simple
from .jet import Jet

TWO_PI = 2.0 * np.pi
#: η may exceed [eta_min, 1] by this much (rounding in callers) before it is refused.
ETA_RANGE_TOL = 1e-12
#: The blade is extended below min(first station, hub radius) by this fraction of the hub
#: radius ratio, at most MAX_ROOT_EXTENSION in η.
ROOT_EXTENSION_FRACTION = 0.5
MAX_ROOT_EXTENSION = 0.1
#: Points on each station outline checked for self-intersection.
OUTLINE_CHECK_POINTS = 120
#: Samples per η used to check that the splined distributions stay valid.
RADIAL_CHECK_SAMPLES = 801

# columns of the stacked radial spline
_CHORD, _PITCH, _SKEW, _RAKE, _TC, _FC = range(6)
_RADIAL_FIELDS = ("c_D", "P_D", "skew_deg", "rake_D", "t_c", "f_c")


def _radial_spline(eta_stations: np.ndarray, values: np.ndarray, eta_min: float) -> PPoly:
    """C2 cubic spline through the stations (natural at the root, not-a-knot at the tip),
    extended linearly down to ``eta_min`` (C2, since the second derivative is 0 there)."""
    bc_root = (2, np.zeros(values.shape[1]))
    bc_tip = "not-a-knot" if len(eta_stations) > 3 else (2, np.zeros(values.shape[1]))
    spline = CubicSpline(eta_stations, values, bc_type=(bc_root, bc_tip), axis=0)
    r0 = eta_stations[0]
    slope = spline(r0, 1)
    ext = np.zeros((4, 1) + values.shape[1:])
    ext[2, 0] = slope
    ext[3, 0] = spline(r0) - slope * (r0 - eta_min)
    c = np.concatenate([ext, spline.c], axis=1)
    x = np.concatenate([[eta_min], spline.x])
    return PPoly(c, x, extrapolate=False)


#: Recent results of the outline check, keyed by section and (t/c, f/c) values: a live
#: edit of pitch, chord, skew or rake leaves the sections as they are.
_OUTLINE_CHECKS: dict = {}
OUTLINE_CHECK_CACHE_SIZE = 8


def _simple_outlines(section: SectionShape, tc: np.ndarray, fc: np.ndarray) -> np.ndarray:
    """Whether the section outlines with thickness ratios ``tc`` and camber ratios ``fc``
    (OUTLINE_CHECK_POINTS points each) are simple polygons, remembered for the last few
    (section, tc, fc): the check is most of the cost of building a blade."""
    key = (id(section), tc.tobytes(), fc.tobytes())
    hit = _OUTLINE_CHECKS.get(key)
    if hit is not None and hit[0] is section:  # the section is held, so its id is not reused
        return hit[1]
    psi = np.linspace(0.0, TWO_PI, OUTLINE_CHECK_POINTS, endpoint=False)
    simple = polygons_are_simple(section.points(psi[None, :], tc[:, None], fc[:, None]))
    simple.flags.writeable = False
    while len(_OUTLINE_CHECKS) >= OUTLINE_CHECK_CACHE_SIZE:
        _OUTLINE_CHECKS.pop(next(iter(_OUTLINE_CHECKS)))
    _OUTLINE_CHECKS[key] = (section, simple)
    return simple


@dataclass(frozen=True)
class SectionMeasurement:
    """A blade section cut at radius r, measured on the developed cylinder (metres,
    degrees). Thickness is the largest distance between the points ξ and 1 - ξ (the
    thickness normal to the mean line), camber the largest distance of their midpoint from
    the nose–tail line (positive towards the suction side)."""

    radius: float
    chord: float
    pitch_angle_deg: float
    pitch: float
    max_thickness: float
    max_camber: float
    skew_deg: float
    rake: float
    leading_edge: np.ndarray
    trailing_edge: np.ndarray


@dataclass(frozen=True, eq=False)
class BladeSurface:
    """b(ξ, η): the unsmoothed reference blade (conventions in the module docstring).

    radius: R = D/2 (m). hand: +1 right-handed, -1 left-handed. eta_min: lowest η of the
    model. hub_ratio: hub radius / R. section: the section form. radial: the stacked PPoly
    in η of (c or c², P, θ_s [rad], i_G, t/c, f/c). chord_squared: whether column 0 is c².
    """

    radius: float
    hand: int
    eta_min: float
    hub_ratio: float
    section: SectionShape
    radial: PPoly
    chord_squared: bool
    stations: np.ndarray

    # -- construction -------------------------------------------------------------
    @classmethod
    def from_definition(cls, propeller, section: SectionShape | None = None) -> "BladeSurface":
        """Build from a validated :class:`~.definition.Propeller`."""
        rad = propeller.radial
        D = float(propeller.diameter)
        path = propeller.source
        if section is None:
            section = propeller.section.shape(propeller.base_dir, path)
        eta = np.asarray(rad.r_R, dtype=np.float64)
        h = float(propeller.hub_diameter_ratio)
        eta_min = min(eta[0], h) - min(ROOT_EXTENSION_FRACTION * h, MAX_ROOT_EXTENSION)
        chord = np.asarray(rad.c_D, dtype=np.float64) * D
        chord_squared = chord[-1] == 0.0
        values = np.stack(
            [
                chord**2 if chord_squared else chord,
                np.asarray(rad.P_D) * D,
                np.radians(rad.skew_deg),
                np.asarray(rad.rake_D) * D,
                np.asarray(rad.t_c, dtype=np.float64),
                np.asarray(rad.f_c, dtype=np.float64),
            ],
            axis=1,
        )
        ppoly = _radial_spline(eta, values, eta_min)
        blade = cls(
            radius=0.5 * D,
            hand=1 if propeller.hand == "right" else -1,
            eta_min=float(eta_min),
            hub_ratio=h,
            section=section,
            radial=ppoly,
            chord_squared=bool(chord_squared),
            stations=eta,
        )
        blade._check(path)
        return blade

    def _check(self, path) -> None:
        """Refuse distributions whose splines leave the valid range, and sections that
        self-intersect (DefinitionError naming the field)."""
        tip_gap = 1e-9
        eta = np.linspace(self.eta_min, 1.0 - tip_gap, RADIAL_CHECK_SAMPLES)
        Q = self.radial(eta)
        for col, name in ((_CHORD, "c_D"), (_PITCH, "P_D"), (_TC, "t_c")):
            bad = Q[:, col] <= 0
            if np.any(bad):
                e = eta[np.argmax(bad)]
                where = "below the root station (extrapolated)" if e < self.stations[0] else "between stations"
                raise DefinitionError(
                    f"the spline through the stations is not positive at r/R = {e:.4f} ({where})",
                    path=path,
                    field=f"radial.{name}",
                )
        # self-intersection of the section at every station and at the lowest η
        check_eta = np.concatenate([self.stations[self.stations < 1.0], [self.eta_min]])
        Qs = self.radial(check_eta)
        simple = _simple_outlines(self.section, Qs[:, _TC], Qs[:, _FC])
        if not np.all(simple):
            k = int(np.argmin(simple))
            e, q = check_eta[k], Qs[k]
            raise DefinitionError(
                f"the section at r/R = {e:.4f} (t/c = {q[_TC]:.4g}, f/c = {q[_FC]:.4g}) self-intersects",
                path=path,
                field="radial.t_c",
            )

    # -- radial distributions -------------------------------------------------------
    def distributions(self, eta, nu: int = 0) -> dict[str, np.ndarray]:
        """Chord c (m), pitch P (m), skew θ_s (rad), rake i_G (m), t/c, f/c at η (nu = 0)."""
        eta = self._check_eta(eta)
        Q = self.radial(eta)
        if self.chord_squared:
            self._snap_tip(Q, eta)
        c = np.sqrt(Q[..., _CHORD]) if self.chord_squared else Q[..., _CHORD]
        return {
            "chord": c,
            "pitch": Q[..., _PITCH],
            "skew": Q[..., _SKEW],
            "rake": Q[..., _RAKE],
            "t_c": Q[..., _TC],
            "f_c": Q[..., _FC],
        }

    @staticmethod
    def _snap_tip(Q: np.ndarray, eta: np.ndarray) -> None:
        """c² is exactly 0 at the tip (the spline leaves rounding there) and never negative."""
        q = Q[..., _CHORD]
        q[...] = np.where(eta >= 1.0, 0.0, np.maximum(q, 0.0))

    def _check_eta(self, eta) -> np.ndarray:
        eta = np.asarray(eta, dtype=np.float64)
        if eta.size and (np.nanmin(eta) < self.eta_min - ETA_RANGE_TOL or np.nanmax(eta) > 1.0 + ETA_RANGE_TOL):
            raise GeometryError(
                f"eta must lie in [{self.eta_min:.6g}, 1], got values in [{np.nanmin(eta):.6g}, {np.nanmax(eta):.6g}]"
            )
        if np.any(np.isnan(eta)):
            raise GeometryError("eta contains NaN")
        return np.clip(eta, self.eta_min, 1.0)

    # -- evaluation -------------------------------------------------------------------
    def _angles(self, xi, eta):
        """(ξ, η, hand, dψ/dξ, ψ) with ξ and η checked: ψ = 2πξ (right hand) or 2π(1 - ξ)
        (left hand), the chordwise angle both :meth:`_jets` and :meth:`_first_derivatives`
        start from."""
        xi = np.asarray(xi, dtype=np.float64)
        if np.any(~np.isfinite(xi)):
            raise GeometryError("xi contains NaN or infinite values")
        eta = self._check_eta(eta)
        h = self.hand
        psi = np.mod(TWO_PI * xi if h > 0 else TWO_PI * (1.0 - xi), TWO_PI)
        return xi, eta, h, TWO_PI * h, psi

    def _jets(self, xi, eta, order: int, pure: bool = True):
        # ---- chordwise (ξ only)
        xi, eta, h, dpsi, psi = self._angles(xi, eta)
        S_tab = self.section.thickness
        d = dpsi if order else 0.0

        def xi_jet(f0, f1, f2):
            if order == 0:
                return Jet(f0)
            return Jet.of_first(f0, f1, f2 if order > 1 and pure else 0.0, d)

        cpsi, spsi = np.cos(psi), np.sin(psi)
        S = xi_jet(S_tab(psi), S_tab(psi, 1) if order else 0.0, S_tab(psi, 2) if order > 1 else 0.0)
        xj = xi_jet(0.5 * (1.0 + cpsi), -0.5 * spsi, -0.5 * cpsi)
        cambered = self.section.meanline is not None
        if cambered:
            xv = xj.v
            F = [self.section.camber(xv, k) for k in range(min(order, 2) + 2)] + [None] * 2
            Fj = xj.compose(F[0], F[1] if order else 0.0, F[2] if order > 1 else 0.0)
            Fpj = xj.compose(F[1], F[2] if order else 0.0, F[3] if order > 1 else 0.0)

        # ---- radial (η only)
        Qd = [self.radial(eta, k) for k in range(order + 1)] + [0.0, 0.0]
        if self.chord_squared:
            self._snap_tip(Qd[0], eta)

        def eta_jet(col):
            if order == 0:
                return Jet(Qd[0][..., col])
            return Jet.of_second(Qd[0][..., col], Qd[1][..., col], Qd[2][..., col] if order > 1 and pure else 0.0)

        q = eta_jet(_CHORD)
        c = q.sqrt() if self.chord_squared else q
        P = eta_jet(_PITCH)
        th = eta_jet(_SKEW)
        iG = eta_jet(_RAKE)
        tc = eta_jet(_TC)
        R = self.radius
        r = Jet(R * eta, 0.0, R if order else 0.0)
        p = P / (TWO_PI * r)  # tan φ
        cos_phi = (p * p + 1.0).sqrt().reciprocal()
        sin_phi = p * cos_phi
        z_m = iG + th * P * (1.0 / TWO_PI)

        # ---- unit section (X, Y)
        if cambered:
            fc = eta_jet(_FC)
            m = fc * Fj
            mp = fc * Fpj
            w = (mp * mp + 1.0).sqrt().reciprocal()
            Sw = tc * S * w
            X = xj - Sw * mp
            Y = m + Sw
        else:
            X = xj
            Y = tc * S
        A = X - 0.5
        ds = c * (-(A * cos_phi) - Y * sin_phi)
        z = z_m + c * (A * sin_phi - Y * cos_phi)
        ang = ds / r - th
        rs = r * ang.sin()
        if h < 0:
            rs = -rs
        rc = r * ang.cos()
        return rs, rc, z

    def _first_derivatives(self, xi, eta):
        """(value, ∂/∂ξ, ∂/∂η) of (x, y, z): the order-1 part of :meth:`_jets` written
        out, the same operations in the same order (so the same rounding). The ξ-only
        and η-only factors keep their vanishing partials out of the products, as the jets
        do, so the infinite η-derivatives at a closing tip never meet a zero."""
        xi, eta, h, dpsi, psi = self._angles(xi, eta)
        cpsi, spsi = np.cos(psi), np.sin(psi)
        # ξ-only: (value, ∂ξ)
        S, S_a = self.section.thickness(psi), self.section.thickness(psi, 1) * dpsi
        xj, xj_a = 0.5 * (1.0 + cpsi), (-0.5 * spsi) * dpsi
        # η-only: (value, ∂η)
        Q0, Q1 = self.radial(eta, 0), self.radial(eta, 1)
        if self.chord_squared:
            self._snap_tip(Q0, eta)
        q, q_b = Q0[..., _CHORD], Q1[..., _CHORD]
        if self.chord_squared:
            c = np.sqrt(q)
            c_b = (0.5 / c) * q_b
        else:
            c, c_b = q, q_b
        P, P_b = Q0[..., _PITCH], Q1[..., _PITCH]
        th, th_b = Q0[..., _SKEW], Q1[..., _SKEW]
        iG, iG_b = Q0[..., _RAKE], Q1[..., _RAKE]
        tc, tc_b = Q0[..., _TC], Q1[..., _TC]
        R = self.radius
        r = R * eta
        tr, tr_b = r * TWO_PI, R * TWO_PI
        rr = 1.0 / tr
        rec, rec_b = rr, (-rr * rr) * tr_b
        p, p_b = P * rec, P_b * rec + P * rec_b
        pp, pp_b = p * p + 1.0, p_b * p + p * p_b
        sq = np.sqrt(pp)
        sq_b = (0.5 / sq) * pp_b
        rr = 1.0 / sq
        cos_phi, cos_b = rr, (-rr * rr) * sq_b
        sin_phi, sin_b = p * cos_phi, p_b * cos_phi + p * cos_b
        k = 1.0 / TWO_PI
        thP, thP_b = th * P, th_b * P + th * P_b
        z_m, z_m_b = iG + thP * k, iG_b + thP_b * k
        if self.section.meanline is not None:
            F0, F1, F2 = (self.section.camber(xj, n) for n in range(3))
            fc, fc_b = Q0[..., _FC], Q1[..., _FC]
            m, m_a, m_b = fc * F0, fc * (F1 * xj_a), fc_b * F0
            mp, mp_a, mp_b = fc * F1, fc * (F2 * xj_a), fc_b * F1
            mm, mm_a, mm_b = mp * mp + 1.0, mp_a * mp + mp * mp_a, mp_b * mp + mp * mp_b
            s2 = np.sqrt(mm)
            d1 = 0.5 / s2
            s2_a, s2_b = d1 * mm_a, d1 * mm_b
            rr = 1.0 / s2
            f1 = -rr * rr
            w, w_a, w_b = rr, f1 * s2_a, f1 * s2_b
            tS, tS_a, tS_b = tc * S, tc * S_a, tc_b * S
            Sw, Sw_a, Sw_b = tS * w, tS_a * w + tS * w_a, tS_b * w + tS * w_b
            Sm, Sm_a, Sm_b = Sw * mp, Sw_a * mp + Sw * mp_a, Sw_b * mp + Sw * mp_b
            X, X_a, X_b = xj + -Sm, xj_a + -Sm_a, -Sm_b
            Y, Y_a, Y_b = m + Sw, m_a + Sw_a, m_b + Sw_b
            A, A_a, A_b = X + -0.5, X_a, X_b
            Ac_b = A_b * cos_phi + A * cos_b
            Yc_b = Y_b * cos_phi + Y * cos_b
            As_b = A_b * sin_phi + A * sin_b
            Ys_b = Y_b * sin_phi + Y * sin_b
        else:
            A, A_a = xj + -0.5, xj_a
            Y, Y_a, Y_b = tc * S, tc * S_a, tc_b * S
            Ac_b = A * cos_b
            Yc_b = Y_b * cos_phi + Y * cos_b
            As_b = A * sin_b
            Ys_b = Y_b * sin_phi + Y * sin_b
        Ac, Ac_a = A * cos_phi, A_a * cos_phi
        Ys, Ys_a = Y * sin_phi, Y_a * sin_phi
        As, As_a = A * sin_phi, A_a * sin_phi
        Yc, Yc_a = Y * cos_phi, Y_a * cos_phi
        i1, i1_a, i1_b = -Ac + -Ys, -Ac_a + -Ys_a, -Ac_b + -Ys_b
        ds, ds_a, ds_b = c * i1, c * i1_a, c_b * i1 + c * i1_b
        i2, i2_a, i2_b = As + -Yc, As_a + -Yc_a, As_b + -Yc_b
        z, z_a, z_b = z_m + c * i2, c * i2_a, z_m_b + (c_b * i2 + c * i2_b)
        rr = 1.0 / r
        rrec_b = (-rr * rr) * R
        ang, ang_a, ang_b = ds * rr + -th, ds_a * rr, (ds_b * rr + ds * rrec_b) + -th_b
        sa, ca = np.sin(ang), np.cos(ang)
        si_a, si_b = ca * ang_a, ca * ang_b
        co_a, co_b = (-sa) * ang_a, (-sa) * ang_b
        rs, rs_a, rs_b = r * sa, r * si_a, R * sa + r * si_b
        if h < 0:
            rs, rs_a, rs_b = -rs, -rs_a, -rs_b
        rc, rc_a, rc_b = r * ca, r * co_a, R * ca + r * co_b
        return (rs, rs_a, rs_b), (rc, rc_a, rc_b), (z, z_a, z_b)

    def derivatives(self, xi, eta, order: int = 2) -> np.ndarray:
        """b and its partial derivatives: shape B + (order+1, order+1, 3), entry [k, l] =
        ∂^(k+l) b / ∂ξ^k ∂η^l for k + l <= order (zero above), B the broadcast shape of
        ξ and η (the layout of BSplineSurface.derivatives). Analytic; order <= 2.
        At the tip (η = 1) the η-derivatives are infinite when the chord closes there."""
        if order not in (0, 1, 2):
            raise GeometryError(f"derivative order must be 0, 1 or 2, got {order}")
        shape = np.broadcast_shapes(np.shape(xi), np.shape(eta))
        out = np.zeros(shape + (order + 1, order + 1, 3))
        if order == 1:
            with np.errstate(divide="ignore", invalid="ignore"):
                comps = self._first_derivatives(xi, eta)
            for k, (v, a, b) in enumerate(comps):
                out[..., 0, 0, k], out[..., 1, 0, k], out[..., 0, 1, k] = v, a, b
            return out
        with np.errstate(divide="ignore", invalid="ignore"):
            comps = self._jets(xi, eta, order)
        for k, jet in enumerate(comps):
            jet.stack_into(out, k, order)
        return out

    def _points(self, xi, eta):
        """(x, y, z) of b(ξ, η) in plain numpy: the value part of :meth:`_jets`, the same
        operations in the same order (so the same rounding), without the Jet bookkeeping
        that dominates the cost of the many small evaluations in tip smoothing."""
        xi = np.asarray(xi, dtype=np.float64)
        if np.any(~np.isfinite(xi)):
            raise GeometryError("xi contains NaN or infinite values")
        eta = self._check_eta(eta)
        h = self.hand
        psi = np.mod(TWO_PI * xi if h > 0 else TWO_PI * (1.0 - xi), TWO_PI)
        S = self.section.thickness(psi)
        xj = 0.5 * (1.0 + np.cos(psi))
        Q = self.radial(eta)
        if self.chord_squared:
            self._snap_tip(Q, eta)
        q = Q[..., _CHORD]
        c = np.sqrt(q) if self.chord_squared else q
        P, th, iG, tc = Q[..., _PITCH], Q[..., _SKEW], Q[..., _RAKE], Q[..., _TC]
        r = self.radius * eta
        p = P * (1.0 / (TWO_PI * r))
        cos_phi = 1.0 / np.sqrt(p * p + 1.0)
        sin_phi = p * cos_phi
        z_m = iG + th * P * (1.0 / TWO_PI)
        if self.section.meanline is not None:
            fc = Q[..., _FC]
            m = fc * self.section.camber(xj, 0)
            mp = fc * self.section.camber(xj, 1)
            w = 1.0 / np.sqrt(mp * mp + 1.0)
            Sw = tc * S * w
            X = xj + -(Sw * mp)
            Y = m + Sw
        else:
            X = xj
            Y = tc * S
        A = X + -0.5
        ds = c * (-(A * cos_phi) + -(Y * sin_phi))
        z = z_m + c * (A * sin_phi + -(Y * cos_phi))
        ang = ds * (1.0 / r) + -th
        rs = r * np.sin(ang)
        return (-rs if h < 0 else rs), r * np.cos(ang), z

    def mixed_derivatives(self, xi, eta) -> np.ndarray:
        """b, b_ξ, b_η and b_ξη in the layout of :meth:`derivatives` (order 2) with the pure
        second derivatives b_ξξ, b_ηη left 0. No jet product or function takes the mixed
        part from the pure ones, so b_ξη is the one :meth:`derivatives` gives, bit for bit,
        for about two thirds of the work (the marching surrogate of the cuts needs no more)."""
        shape = np.broadcast_shapes(np.shape(xi), np.shape(eta))
        with np.errstate(divide="ignore", invalid="ignore"):
            comps = self._jets(xi, eta, 2, pure=False)
        out = np.zeros(shape + (3, 3, 3))
        for k, jet in enumerate(comps):
            jet.stack_into(out, k, 2)
        out[..., 2, 0, :] = 0.0
        out[..., 0, 2, :] = 0.0
        return out

    def evaluate(self, xi, eta) -> np.ndarray:
        """Points b(ξ, η): shape B + (3,), B the broadcast shape of ξ and η."""
        shape = np.broadcast_shapes(np.shape(xi), np.shape(eta))
        comps = self._points(xi, eta)
        out = np.empty(shape + (3,))
        for k, v in enumerate(comps):
            out[..., k] = v
        return out

    __call__ = evaluate

    def evaluate_grid(self, xis, etas) -> np.ndarray:
        """Points on the grid xis × etas: (len(xis), len(etas), 3)."""
        return self.evaluate(np.asarray(xis, dtype=np.float64)[:, None], np.asarray(etas, dtype=np.float64)[None, :])

    def normal(self, xi, eta) -> np.ndarray:
        """Unit outward normal b_ξ × b_η / |b_ξ × b_η| (Hally 2013 Eq. 1): B + (3,)."""
        D = self.derivatives(xi, eta, 1)
        n = np.cross(D[..., 1, 0, :], D[..., 0, 1, :])
        return n / np.linalg.norm(n, axis=-1, keepdims=True)

    def display_parameters(self, n_xi: int = 64, n_eta: int = 48, eta_start: float | None = None):
        """Parameters of a display grid: ξ uniform on [0, 1] (both ends, so the TE closes)
        and η from ``eta_start`` (default the hub radius ratio) to the tip, clustered
        towards the tip where the geometry changes fastest."""
        start = self.hub_ratio if eta_start is None else float(eta_start)
        xis = np.linspace(0.0, 1.0, n_xi)
        etas = start + (1.0 - start) * np.sin(0.5 * np.pi * np.linspace(0.0, 1.0, n_eta))
        etas[-1] = 1.0
        return xis, etas

    def sample(self, n_xi: int = 64, n_eta: int = 48, eta_start: float | None = None) -> np.ndarray:
        """Display grid of points (n_xi, n_eta, 3); see :meth:`display_parameters`."""
        return self.evaluate_grid(*self.display_parameters(n_xi, n_eta, eta_start))

    # -- section cuts -----------------------------------------------------------------
    def section_cut(self, r: float, count: int = 201) -> np.ndarray:
        """``count`` points of the section at radius r (metres), ξ uniform on [0, 1]."""
        return self.evaluate(np.linspace(0.0, 1.0, count), r / self.radius)

    def _developed(self, xi, eta: float) -> np.ndarray:
        """(s = rϕ, z) of b(ξ, η), ϕ from +y towards +x for right hands (mirrored for left)."""
        P = self.evaluate(xi, eta)
        r = self.radius * eta
        phi = np.arctan2(self.hand * P[..., 0], P[..., 1])
        return np.stack([r * phi, P[..., 2]], axis=-1)

    def measure_section(self, r: float, samples: int = 2001, xtol: float = 1e-13) -> SectionMeasurement:
        """Measure the section cut of b at radius r (see :class:`SectionMeasurement`):
        chord along the helix, pitch of the nose–tail line, maximum thickness and camber,
        skew angle of the mid-chord point and generator-line rake."""
        eta = r / self.radius
        le, te = self._developed(np.array([0.5, 0.0]), eta)
        chord_vec = le - te
        chord = float(np.hypot(*chord_vec))
        if chord > 0:
            phi = float(np.arctan2(te[1] - le[1], le[0] - te[0]))
        else:  # a closed tip: the nose–tail line has no direction; use the pitch distribution
            phi = float(np.arctan(self.distributions(eta)["pitch"] / (TWO_PI * r)))
        pitch = TWO_PI * r * np.tan(phi)
        mid = 0.5 * (le + te)
        skew = -mid[0] / r
        rake = mid[1] - r * skew * np.tan(phi)
        n_s = np.array([-np.sin(phi), -np.cos(phi)])

        def thickness(x):
            a, b = self._developed(np.array([x, 1.0 - x]), eta)
            return float(np.hypot(*(a - b)))

        def camber(x):
            a, b = self._developed(np.array([x, 1.0 - x]), eta)
            return float((0.5 * (a + b) - te) @ n_s)

        def maximise(fn):
            xs = np.linspace(0.0, 0.5, samples)
            pts = self._developed(np.concatenate([xs, 1.0 - xs]), eta)
            a, b = pts[: samples], pts[samples:]
            vals = np.hypot(*(a - b).T) if fn is thickness else (0.5 * (a + b) - te) @ n_s
            i = int(np.argmax(np.abs(vals)))
            if i in (0, samples - 1) or chord == 0.0:
                return float(vals[i])
            sign = np.sign(vals[i])
            res = minimize_scalar(lambda x: -sign * fn(x), bounds=(xs[i - 1], xs[i + 1]), method="bounded",
                                  options={"xatol": xtol})
            return float(max(abs(vals[i]), -res.fun) * sign)

        return SectionMeasurement(
            radius=float(r),
            chord=chord,
            pitch_angle_deg=float(np.degrees(phi)),
            pitch=float(pitch),
            max_thickness=maximise(thickness) if chord > 0 else 0.0,
            max_camber=maximise(camber) if chord > 0 else 0.0,
            skew_deg=float(np.degrees(skew)),
            rake=float(rake),
            leading_edge=le,
            trailing_edge=te,
        )
