"""Display surfaces of a propeller: the unsmoothed blade b(ξ, η) as a cubic B-spline
surface within a display tolerance, and the hub as its exact NURBS surface of revolution.

Blade
-----
:func:`blade_display_surface` approximates b(ξ, η) (Hally 2013 Eq. 1; see
:mod:`.blade`) by a tensor-product cubic B-spline S(u, v) with u = ξ on [0, 1] (trailing
edge at both ends, leading edge at u = 1/2) and v on [0, 1] mapped to the radius by

    η(v) = η_s + (1 - η_s) (1 - (1 - v)²)      (closed tip: the table's tip chord is 0)
    η(v) = η_s + (1 - η_s) v                   (finite tip chord)

η_s is the hub radius ratio, so the root edge lies on the hub cylinder (every blade point
lies on the cylinder r = ηR). At a closed tip the chord behaves like c ~ sqrt(1 - η)
(:mod:`.blade`), whose η-derivative is infinite; with 1 - η = (1 - η_s)(1 - v)² the chord
is ~ (1 - v), smooth, so a polynomial in v can follow it without piling knots up at the
tip. The tip row v = 1 collapses to the tip point, as b does.

The fit is interpolation at the Greville abscissae of the knot vectors (tensor product:
one banded solve along u for all columns, then one along v; NURBS Book 2e Alg. A9.1
with prescribed knots, §9.2.5), with knots refined by bisection of failing spans as in
Hally (2013) §9. The interpolant restricted to a Greville line v = v̄_l is exactly the
u-interpolant of b(·, η(v̄_l)) (interpolation is unique), so sampling along those lines
measures the u-error alone, and the lines u = ū_k the v-error alone; each direction is
refined against half the tolerance. A final check on a dense grid (every knot span
sampled ``check_samples`` times in each direction, plus the span midpoints of the
interior) measures |b(ξ, η(v)) - S(ξ, v)| at the same parameters, an upper bound of the
distance from the surface to the blade; if it exceeds the tolerance, the per-direction
budgets are lowered and the refinement continues.

Hub
---
:func:`hub_surface` is exact: the rational quadratic spine (ρ(t), z(t)) of
:class:`~.hub.Hub` times the rational quadratic full circle of nine control points on the
unit square with weights (1, √2/2, 1, ...) and knots (0,0,0,¼,¼,½,½,¾,¾,1,1,1): the
surface of revolution of NURBS Book 2e §8.5 (Alg. A8.1), P_ij = (ρ_i x_j, ρ_i y_j, z_i),
w_ij = w_i w_j. The circle starts at θ = 0 (+y) and runs towards +x, the sense of θ in
h(ξ_h, θ) = (ρ sin θ, ρ cos θ, z), so S_u × S_v points out of the hub like h_ξ × h_θ.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import GeometryError
from ..nurbs import BSplineSurface
from ..nurbs.basis import check_parameters
from ..nurbs.fitting import greville_abscissae, interpolate_at

#: Default display tolerance as a fraction of the diameter D.
DISPLAY_TOLERANCE_FRACTION = 1e-4
#: Cubic display surfaces: Blender shows them exactly (order 4, Bezier knot mode).
DISPLAY_DEGREE = 3
#: Initial uniform knot spans along ξ (an even count puts a knot at the leading edge ξ = 1/2;
#: 16 resolves the trailing-edge region well enough that the checks do not miss peaks there).
INITIAL_SPANS_XI = 16
#: Initial uniform knot spans along v.
INITIAL_SPANS_V = 4
#: Deviation samples per knot span and direction, during refinement and in the final check.
REFINE_SAMPLES = 4
CHECK_SAMPLES = 6
#: Refinement stops with a GeometryError beyond this many control points per direction.
MAX_CONTROL_POINTS = 400
#: Budget of each direction as a fraction of the tolerance, and its reduction when the
#: final check fails (the two errors add up, amplified by the interpolation's Lebesgue
#: constant, so half the tolerance each is usually, not always, enough).
DIRECTION_BUDGET = 0.5
BUDGET_REDUCTION = 0.7
MAX_ROUNDS = 12

_HALF_SQRT2 = np.sqrt(0.5)


@dataclass(frozen=True, eq=False)
class BladeDisplay:
    """The blade display surface and how well it follows b(ξ, η).

    surface: S(u, v), u = ξ, v as in the module docstring. eta_start: η_s. closed_tip:
    whether η(v) is the quadratic map. max_deviation: largest |b - S| found by the final
    check (metres). tolerance: the requested bound (metres). check_points: size of the
    final check grid. evaluations: evaluations of b in all. rounds: refinement rounds.
    """

    surface: BSplineSurface
    eta_start: float
    closed_tip: bool
    tolerance: float
    max_deviation: float
    check_points: int
    evaluations: int
    rounds: int
    stats: dict = field(default_factory=dict)

    def eta(self, v) -> np.ndarray:
        """η(v), the radius ratio of the display parameter v."""
        return eta_of_v(v, self.eta_start, self.closed_tip)


def eta_of_v(v, eta_start: float, closed_tip: bool) -> np.ndarray:
    """η(v) of the display parameterisation (module docstring)."""
    v = np.asarray(v, dtype=np.float64)
    s = 1.0 - (1.0 - v) ** 2 if closed_tip else v
    eta = eta_start + (1.0 - eta_start) * s
    return np.where(v >= 1.0, 1.0, eta)


def _uniform_knots(spans: int, degree: int) -> np.ndarray:
    return np.concatenate([np.zeros(degree), np.linspace(0.0, 1.0, spans + 1), np.ones(degree)])


def _start_knots(knots, degree: int, what: str) -> np.ndarray:
    U = np.asarray(knots, dtype=np.float64).ravel()
    clamped = U.size >= 2 * degree + 2 and np.all(U[: degree + 1] == 0.0) and np.all(U[-degree - 1 :] == 1.0)
    if not clamped or np.any(np.diff(U) < 0) or not np.all(np.isfinite(U)):
        raise GeometryError(f"{what}: expected a clamped degree-{degree} knot vector on [0, 1], got {U.tolist()!r}")
    return U


def _span_samples(knots: np.ndarray, per_span: int) -> np.ndarray:
    """``per_span`` samples in every span, both ends included once: sorted (spans*per_span + 1,)."""
    breaks = np.unique(knots)
    local = np.arange(per_span) / per_span
    t = (breaks[:-1, None] + np.diff(breaks)[:, None] * local[None, :]).ravel()
    return np.concatenate([t, breaks[-1:]])


def _interpolate_grid(U, V, p, gu, gv, F) -> np.ndarray:
    """Control net (nu, nv, 3) of the tensor-product interpolant of F (nu, nv, 3) at
    gu × gv: a banded solve along u with every column as right-hand side, then along v."""
    nu, nv, dim = F.shape
    A = interpolate_at(U, p, gu, F.reshape(nu, nv * dim)).control_points.reshape(nu, nv, dim)
    B = interpolate_at(V, p, gv, A.transpose(1, 0, 2).reshape(nv, nu * dim)).control_points
    return B.reshape(nv, nu, dim).transpose(1, 0, 2)


def _grid(surface: BSplineSurface, us: np.ndarray, vs: np.ndarray) -> np.ndarray:
    """S on the grid us × vs, (len(us), len(vs), 3), for a non-rational surface: two dense
    matrix products with the collocation matrices (BLAS; einsum does not use it)."""
    nu, nv, dim = surface.control_points.shape
    A = surface.basis_matrix_u(us) @ surface.control_points.reshape(nu, nv * dim)  # (len(us), nv*dim)
    A = A.reshape(len(us), nv, dim).transpose(1, 0, 2).reshape(nv, len(us) * dim)
    B = surface.basis_matrix_v(vs) @ A  # (len(vs), len(us)*dim)
    return B.reshape(len(vs), len(us), dim).transpose(1, 0, 2)


def _span_maxima(t: np.ndarray, dev: np.ndarray, knots: np.ndarray) -> np.ndarray:
    """Largest deviation per non-empty knot span; dev (len(t),) sampled at sorted t."""
    breaks = np.unique(knots)
    # a sample on a break counts for both spans it bounds
    left = np.clip(np.searchsorted(breaks, t, side="right") - 1, 0, breaks.size - 2)
    right = np.clip(np.searchsorted(breaks, t, side="left") - 1, 0, breaks.size - 2)
    out = np.zeros(breaks.size - 1)
    np.maximum.at(out, left, dev)
    np.maximum.at(out, right, dev)
    return out


def _bisect(knots: np.ndarray, failing: np.ndarray, degree: int) -> np.ndarray:
    breaks = np.unique(knots)
    mids = 0.5 * (breaks[:-1] + breaks[1:])[failing]
    interior = np.sort(np.concatenate([knots[degree + 1 : len(knots) - degree - 1], mids]))
    return np.concatenate([np.zeros(degree + 1), interior, np.ones(degree + 1)])


def blade_display_surface(
    blade,
    tolerance: float,
    *,
    eta_start: float | None = None,
    knots=None,
    check_samples: int = CHECK_SAMPLES,
    progress=None,
) -> BladeDisplay:
    """Cubic B-spline surface within ``tolerance`` (metres) of the unsmoothed blade.

    blade: a :class:`~.blade.BladeSurface`. eta_start: η_s (default the hub radius ratio).
    knots: optional (knots_u, knots_v), clamped cubic knot vectors on [0, 1] to start the
    refinement from (default: uniform, :data:`INITIAL_SPANS_XI` × :data:`INITIAL_SPANS_V`
    spans). Knots are only inserted, so starting from the knots of a previous display
    keeps the control net's size whenever those knots still meet the tolerance: live
    editing uses this to rewrite Blender's data in place.
    Parameterisation, fit and measurement are described in the module docstring; the
    returned :class:`BladeDisplay` carries the surface and the measured maximum deviation.
    progress: optional callable taking a fraction in [0, 1].
    Raises :class:`GeometryError` if the tolerance cannot be met with
    :data:`MAX_CONTROL_POINTS` control points per direction.
    """
    tol = float(tolerance)
    if not np.isfinite(tol) or tol <= 0:
        raise GeometryError(f"display tolerance must be a positive length, got {tolerance!r}")
    p = DISPLAY_DEGREE
    eta_s = float(blade.hub_ratio if eta_start is None else eta_start)
    if not blade.eta_min <= eta_s < 1.0:
        raise GeometryError(f"eta_start must lie in [{blade.eta_min:.6g}, 1), got {eta_s!r}")
    closed = bool(blade.chord_squared)

    def b(xi, v):
        return blade.evaluate(xi, eta_of_v(v, eta_s, closed))

    if knots is None:
        U, V = _uniform_knots(INITIAL_SPANS_XI, p), _uniform_knots(INITIAL_SPANS_V, p)
    else:
        U, V = (_start_knots(k, p, name) for k, name in zip(knots, ("knots_u", "knots_v")))
    budget = DIRECTION_BUDGET
    evaluations = 0
    rounds = 0
    if knots is not None:
        # seeded: the given knots usually still suffice; one fit and the final check decide
        surface, G = _fit_and_check(b, U, V, p, check_samples)
        evaluations += G.size + surface.shape[0] * surface.shape[1]
        if G.max() <= tol:
            return _result(surface, eta_s, closed, tol, G, evaluations, 0)
    while True:
        rounds += 1
        if rounds > MAX_ROUNDS:
            raise GeometryError(
                f"the blade display surface did not reach the tolerance {tol:.3g} m in {MAX_ROUNDS} rounds"
            )
        # -- refine each direction against its budget
        while True:
            gu, gv = greville_abscissae(U, p), greville_abscissae(V, p)
            F = b(gu[:, None], gv[None, :])
            evaluations += F.shape[0] * F.shape[1]
            net = _interpolate_grid(U, V, p, gu, gv, F)
            surface = BSplineSurface(p, p, U, V, net)
            tu, tv = _span_samples(U, REFINE_SAMPLES), _span_samples(V, REFINE_SAMPLES)
            dev_u = np.linalg.norm(b(tu[:, None], gv[None, :]) - _grid(surface, tu, gv), axis=-1).max(axis=1)
            dev_v = np.linalg.norm(b(gu[:, None], tv[None, :]) - _grid(surface, gu, tv), axis=-1).max(axis=0)
            evaluations += tu.size * gv.size + gu.size * tv.size
            fail_u = _span_maxima(tu, dev_u, U) > budget * tol
            fail_v = _span_maxima(tv, dev_v, V) > budget * tol
            if not (fail_u.any() or fail_v.any()):
                break
            U = _bisect(U, fail_u, p) if fail_u.any() else U
            V = _bisect(V, fail_v, p) if fail_v.any() else V
            if len(U) - p - 1 > MAX_CONTROL_POINTS or len(V) - p - 1 > MAX_CONTROL_POINTS:
                raise GeometryError(
                    f"the blade display surface needs more than {MAX_CONTROL_POINTS} control points per "
                    f"direction for the tolerance {tol:.3g} m; use a larger display_tolerance"
                )
            if progress is not None:
                progress(min(0.9, 0.1 * rounds + 0.05 * (len(U) + len(V)) / MAX_CONTROL_POINTS))
        # -- final check on a dense grid, including the span midpoints
        cu, cv = _span_samples(U, check_samples), _span_samples(V, check_samples)
        G = np.linalg.norm(b(cu[:, None], cv[None, :]) - _grid(surface, cu, cv), axis=-1)
        evaluations += G.size
        if G.max() <= tol:
            break
        budget *= BUDGET_REDUCTION
    if progress is not None:
        progress(1.0)
    return _result(surface, eta_s, closed, tol, G, evaluations, rounds)


def _fit_and_check(b, U, V, p, check_samples):
    gu, gv = greville_abscissae(U, p), greville_abscissae(V, p)
    surface = BSplineSurface(p, p, U, V, _interpolate_grid(U, V, p, gu, gv, b(gu[:, None], gv[None, :])))
    cu, cv = _span_samples(U, check_samples), _span_samples(V, check_samples)
    return surface, np.linalg.norm(b(cu[:, None], cv[None, :]) - _grid(surface, cu, cv), axis=-1)


def _result(surface, eta_s, closed, tol, G, evaluations, rounds) -> BladeDisplay:
    return BladeDisplay(
        surface=surface,
        eta_start=eta_s,
        closed_tip=closed,
        tolerance=tol,
        max_deviation=float(G.max()),
        check_points=int(G.size),
        evaluations=evaluations,
        rounds=rounds,
        stats={"n_control": surface.shape,
               "n_spans": (np.unique(surface.knots_u).size - 1, np.unique(surface.knots_v).size - 1)},
    )


def display_deviation(display: BladeDisplay, blade, xi, v) -> np.ndarray:
    """|b(ξ, η(v)) - S(ξ, v)| at broadcast parameter arrays (for independent checks)."""
    xi = check_parameters(xi, display.surface.knots_u, display.surface.degree_u, "xi")
    v = check_parameters(v, display.surface.knots_v, display.surface.degree_v, "v")
    return np.linalg.norm(blade.evaluate(xi, display.eta(v)) - display.surface.evaluate(xi, v), axis=-1)


# -- hub ------------------------------------------------------------------------------
def full_circle() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rational quadratic unit circle (NURBS Book 2e Ex. 7.2, nine points): knots (12,),
    points (9, 2) as (x, y) = (sin θ, cos θ) from θ = 0 towards +x, weights (9,)."""
    knots = np.array([0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0])
    points = np.array(
        [(0, 1), (1, 1), (1, 0), (1, -1), (0, -1), (-1, -1), (-1, 0), (-1, 1), (0, 1)], dtype=np.float64
    )
    weights = np.array([1.0, _HALF_SQRT2] * 4 + [1.0])
    return knots, points, weights


def hub_surface(hub) -> BSplineSurface:
    """The hub as an exact rational surface of revolution, degree (2, 2): u along the
    spine (ξ_h, upstream to downstream), v round the axis (module docstring)."""
    spine = hub.spine
    if spine.dim != 2:
        raise GeometryError(f"the hub spine must be a curve in (rho, z), got dimension {spine.dim}")
    knots_v, circle, w_circle = full_circle()
    rho, z = spine.control_points[:, 0], spine.control_points[:, 1]
    w_spine = spine.weights if spine.weights is not None else np.ones(len(rho))
    points = np.empty((len(rho), len(circle), 3))
    points[..., 0] = rho[:, None] * circle[None, :, 0]
    points[..., 1] = rho[:, None] * circle[None, :, 1]
    points[..., 2] = z[:, None]
    weights = w_spine[:, None] * w_circle[None, :]
    return BSplineSurface(spine.degree, 2, spine.knots, knots_v, points, weights)
