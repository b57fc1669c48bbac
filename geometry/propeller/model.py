"""The propeller model: definition -> blade b(ξ, η) + hub h(ξ_h, θ) (Hally 2013 §2, §10)."""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .blade import BladeSurface
from .hub import Hub
from .intersection import BladeHubIntersection, blade_hub_intersection


@dataclass(frozen=True, eq=False)
class PropellerModel:
    """definition: the validated :class:`~.definition.Propeller`; blade: the reference
    blade (at the reference line, +y); hub: the hub. Blade k of Z is the reference blade
    turned by 2πk/Z about the axis in the sense of θ (see :meth:`blade_rotation`)."""

    definition: object
    blade: BladeSurface
    hub: Hub

    @classmethod
    def from_definition(cls, propeller) -> "PropellerModel":
        return cls(definition=propeller, blade=BladeSurface.from_definition(propeller), hub=Hub.from_definition(propeller))

    @property
    def blades(self) -> int:
        return self.definition.blades

    def blade_rotation(self, k: int) -> np.ndarray:
        """3x3 matrix taking the reference blade to blade k (angle 2πk/Z in the θ sense)."""
        a = 2.0 * np.pi * k / self.blades
        s, c = np.sin(a), np.cos(a)
        # (r sin ϕ, r cos ϕ) -> (r sin(ϕ + a), r cos(ϕ + a))
        return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])

    def intersection(self, n: int = 129) -> BladeHubIntersection:
        return blade_hub_intersection(self.blade, self.hub, n)

    @cached_property
    def blade_hub_intersection(self) -> BladeHubIntersection:
        return self.intersection()
