"""The axisymmetric hub h(ξ_h, θ) (Hally 2013 §10).

The spine is a planar curve (ρ(ξ_h), z(ξ_h)) in the meridional half-plane, an exact
rational quadratic B-spline (degree 2; the elliptic nose and tail are exact quarter
ellipses) made of: the nose (from the axis at z = -upstream_length to the hub radius), the
cylinder of the hub radius, and the tail (back to the axis at z = +downstream_length).
ξ_h runs over [0, 1] from the upstream end (ξ_lo = 0) to the downstream end (ξ_hi = 1);
the knots at the joins are placed by the lengths of the pieces.

The surface turns the spine about the z axis:

    h(ξ_h, θ) = (ρ sin θ, ρ cos θ, z),

θ measured from +y (the reference blade's generator line) towards +x: the rotation sense
of a right-handed propeller, a right-hand rotation about -z. With ξ_h running downstream,
h_ξ × h_θ points out of the hub (into the fluid). The parameterization does not depend on
the hand of the propeller. For IGES (Surface of Revolution, entity 120) the axis is then
the line from (0, 0, 0) to (0, 0, -1).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..errors import GeometryError
from ..nurbs import BSplineCurve

_HALF_SQRT2 = np.sqrt(0.5)


def _end_piece(shape: str, radius: float, z_axis: float, length: float, upstream: bool):
    """Control points (3, 2) in (ρ, z) and middle weight of a nose (upstream) or tail piece,
    oriented from upstream to downstream."""
    sign = 1.0 if upstream else -1.0
    z_cyl = z_axis + sign * length
    if shape == "ellipse":
        pts = [(0.0, z_axis), (radius, z_axis), (radius, z_cyl)]
        w = _HALF_SQRT2
    elif shape == "cone":
        pts = [(0.0, z_axis), (0.5 * radius, 0.5 * (z_axis + z_cyl)), (radius, z_cyl)]
        w = 1.0
    elif shape == "flat":
        pts = [(0.0, z_axis), (0.5 * radius, z_axis), (radius, z_axis)]
        w = 1.0
    else:
        raise GeometryError(f"unknown hub end shape {shape!r}")
    pts = np.array(pts)
    if not upstream:
        pts = pts[::-1]
    length_est = float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))
    return pts, w, length_est


@dataclass(frozen=True, eq=False)
class Hub:
    """Axisymmetric hub: ``spine`` is a 2D BSplineCurve of (ρ, z) on [0, 1]; ``radius`` the
    radius of its cylindrical part."""

    spine: BSplineCurve
    radius: float

    @classmethod
    def from_definition(cls, propeller) -> "Hub":
        hub = propeller.hub
        rh = propeller.hub_radius
        nose, wn, ln = _end_piece(hub.nose_shape, rh, -hub.upstream_length, hub.nose_length, True)
        tail, wt, lt = _end_piece(hub.tail_shape, rh, hub.downstream_length, hub.tail_length, False)
        z0, z1 = nose[-1, 1], tail[0, 1]
        cyl = np.array([(rh, z0), (rh, 0.5 * (z0 + z1)), (rh, z1)])
        lc = z1 - z0
        if lc <= 0:
            raise GeometryError("the hub's nose and tail overlap: no cylindrical part is left")
        P = np.concatenate([nose, cyl[1:], tail[1:]])
        W = np.array([1.0, wn, 1.0, 1.0, 1.0, wt, 1.0])
        total = ln + lc + lt
        k1, k2 = ln / total, (ln + lc) / total
        knots = np.array([0.0, 0.0, 0.0, k1, k1, k2, k2, 1.0, 1.0, 1.0])
        spine = BSplineCurve(2, knots, P, W)
        return cls(spine=spine, radius=rh)

    @property
    def z_range(self) -> tuple[float, float]:
        P = self.spine.control_points
        return float(P[0, 1]), float(P[-1, 1])

    @cached_property
    def _cylinder_params(self) -> tuple[float, float]:
        U = self.spine.knots
        return float(U[3]), float(U[5])

    def spine_derivatives(self, xi_h, order: int = 2) -> np.ndarray:
        """(ρ, z) and derivatives in ξ_h: shape B + (order+1, 2)."""
        return self.spine.derivatives(np.clip(np.asarray(xi_h, dtype=np.float64), 0.0, 1.0), order)

    def evaluate(self, xi_h, theta) -> np.ndarray:
        """Points h(ξ_h, θ): broadcast shape + (3,)."""
        xi_h, theta = np.broadcast_arrays(np.asarray(xi_h, dtype=np.float64), np.asarray(theta, dtype=np.float64))
        C = self.spine.evaluate(np.clip(xi_h, 0.0, 1.0))
        rho, z = C[..., 0], C[..., 1]
        return np.stack([rho * np.sin(theta), rho * np.cos(theta), z], axis=-1)

    __call__ = evaluate

    def derivatives(self, xi_h, theta, order: int = 2) -> np.ndarray:
        """h and its partial derivatives: B + (order+1, order+1, 3); [k, l] is
        ∂^(k+l) h / ∂ξ_h^k ∂θ^l for k + l <= order."""
        xi_h, theta = np.broadcast_arrays(np.asarray(xi_h, dtype=np.float64), np.asarray(theta, dtype=np.float64))
        C = self.spine_derivatives(xi_h, order)
        out = np.zeros(xi_h.shape + (order + 1, order + 1, 3))
        s, c = np.sin(theta), np.cos(theta)
        # d^l/dθ^l of (sin, cos): l = 0: (s, c); 1: (c, -s); 2: (-s, -c)
        trig = [(s, c), (c, -s), (-s, -c)]
        for k in range(order + 1):
            rho_k, z_k = C[..., k, 0], C[..., k, 1]
            for l in range(order + 1 - k):
                ts, tc = trig[l]
                out[..., k, l, 0] = rho_k * ts
                out[..., k, l, 1] = rho_k * tc
                if l == 0:
                    out[..., k, l, 2] = z_k
        return out

    def normal(self, xi_h, theta) -> np.ndarray:
        """Unit outward normal h_ξ × h_θ / |·|."""
        D = self.derivatives(xi_h, theta, 1)
        n = np.cross(D[..., 1, 0, :], D[..., 0, 1, :])
        return n / np.linalg.norm(n, axis=-1, keepdims=True)

    def display_parameters(self, n_xi: int = 48, n_theta: int = 64):
        return np.linspace(0.0, 1.0, n_xi), np.linspace(-np.pi, np.pi, n_theta)

    def sample(self, n_xi: int = 48, n_theta: int = 64) -> np.ndarray:
        """Display grid (n_xi, n_theta, 3), θ from -π to π."""
        xs, ts = self.display_parameters(n_xi, n_theta)
        return self.evaluate(xs[:, None], ts[None, :])

    def parameter_at_z(self, z) -> np.ndarray:
        """ξ_h of the spine point at axial position z on the cylindrical part (exact there:
        the cylinder piece is linear in ξ_h), clipped to the hub's ends elsewhere."""
        a, b = self._cylinder_params
        P = self.spine.control_points
        z0, z1 = P[2, 1], P[4, 1]
        t = (np.asarray(z, dtype=np.float64) - z0) / (z1 - z0)
        return np.clip(a + t * (b - a), 0.0, 1.0)
