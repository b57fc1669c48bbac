"""The blade–hub intersection (Hally 2013 §4 item 1 and §10).

For each blade parameter ξ the intersection is the point b(ξ, η_h(ξ)) that lies on the
hub. Because every blade point lies on the cylinder r = ηR (cylindrical sections), the
conditions are two scalar equations in (η, ξ_h), solved by Newton's method with the
analytic derivatives of b and of the spine:

    ρ(ξ_h) - R η = 0,   z(ξ_h) - z_b(ξ, η) = 0.

The angle θ of the hub parameters is then the angle of the blade point, so that
h(ξ_h, θ) = b(ξ, η_h(ξ)). The curve is given both ways Hally uses it: η_h(ξ) in blade
parameter space, and p_b(u) = (ξ_h, θ) in hub parameter space with u ≡ ξ ∈ [0, 1].
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError
from .blade import BladeSurface
from .hub import Hub

#: Newton stops when the blade point is this close to the hub, relative to the radius R.
INTERSECTION_TOL = 1e-14
MAX_NEWTON_ITERATIONS = 50


def solve_intersection(blade: BladeSurface, hub: Hub, xi, tol: float = INTERSECTION_TOL):
    """(η_h, ξ_h, θ, residual) at blade parameters ``xi`` (any shape). ``residual`` is the
    distance |b(ξ, η_h) - h(ξ_h, θ)| in metres."""
    xi = np.asarray(xi, dtype=np.float64)
    shape = xi.shape
    xi = xi.ravel()
    R = blade.radius
    eta = np.full(xi.shape, hub.radius / R)
    xi_h = hub.parameter_at_z(blade.evaluate(xi, eta)[..., 2])
    for _ in range(MAX_NEWTON_ITERATIONS):
        Db = blade.derivatives(xi, eta, 1)
        Ds = hub.spine_derivatives(xi_h, 1)
        g1 = Ds[:, 0, 0] - R * eta
        g2 = Ds[:, 0, 1] - Db[:, 0, 0, 2]
        # J = [[ρ', -R], [z', -z_b,η]]
        a, b, c, d = Ds[:, 1, 0], -R, Ds[:, 1, 1], -Db[:, 0, 1, 2]
        det = a * d - b * c
        if np.any(det == 0):
            raise GeometryError("blade–hub intersection: singular Newton system (blade tangent to the hub?)")
        d_xh = (d * g1 - b * g2) / det
        d_eta = (-c * g1 + a * g2) / det
        xi_h = np.clip(xi_h - d_xh, 0.0, 1.0)
        eta = np.clip(eta - d_eta, blade.eta_min, 1.0)
        if max(np.max(np.abs(d_xh)), np.max(np.abs(d_eta))) < 1e-15:
            break
    pb = blade.evaluate(xi, eta)
    theta = np.arctan2(pb[:, 0], pb[:, 1])
    ph = hub.evaluate(xi_h, theta)
    residual = np.linalg.norm(pb - ph, axis=-1)
    if np.any(~np.isfinite(residual)) or np.max(residual) > max(tol, 1e-12) * R:
        i = int(np.nanargmax(residual))
        raise GeometryError(
            f"blade–hub intersection did not converge at xi = {xi[i]:.6g} (distance {residual[i]:.3g} m); "
            f"does the blade reach below the hub there (eta_min = {blade.eta_min:.4g})?"
        )
    return eta.reshape(shape), xi_h.reshape(shape), theta.reshape(shape), residual.reshape(shape)


@dataclass(frozen=True, eq=False)
class BladeHubIntersection:
    """The intersection sampled at ``xi`` (n,), with η_h, hub parameters (ξ_h, θ), points
    (n, 3) and the largest distance between blade and hub points (m). ``eta_h`` and
    ``hub_parameters`` evaluate it anywhere by the same Newton iteration."""

    blade: BladeSurface
    hub: Hub
    xi: np.ndarray
    eta: np.ndarray
    xi_h: np.ndarray
    theta: np.ndarray
    points: np.ndarray
    max_residual: float

    def eta_h(self, xi) -> np.ndarray:
        """η_h(ξ): b(ξ, η_h(ξ)) lies on the hub (Hally 2013 §4 item 1)."""
        return solve_intersection(self.blade, self.hub, xi)[0]

    def hub_parameters(self, u) -> np.ndarray:
        """p_b(u) = (ξ_h, θ), u ≡ ξ in [0, 1] (Hally 2013 §10): shape u.shape + (2,)."""
        _, xh, th, _ = solve_intersection(self.blade, self.hub, u)
        return np.stack([xh, th], axis=-1)

    def blade_parameters(self, xi) -> np.ndarray:
        """(ξ, η_h(ξ)): shape xi.shape + (2,)."""
        xi = np.asarray(xi, dtype=np.float64)
        return np.stack([xi, self.eta_h(xi)], axis=-1)


def blade_hub_intersection(blade: BladeSurface, hub: Hub, n: int = 129, tol: float = INTERSECTION_TOL) -> BladeHubIntersection:
    """The blade–hub intersection at n points ξ uniform on [0, 1] (Newton to ``tol`` R)."""
    xi = np.linspace(0.0, 1.0, n)
    eta, xi_h, theta, res = solve_intersection(blade, hub, xi, tol)
    return BladeHubIntersection(
        blade=blade, hub=hub, xi=xi, eta=eta, xi_h=xi_h, theta=theta,
        points=blade.evaluate(xi, eta), max_residual=float(np.max(res)),
    )
