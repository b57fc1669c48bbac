"""Propellers after Hally (2013): the blade b(ξ, η) from a table of sections, the hub,
the blade–hub intersection (tip smoothing and the hub sector build on these)."""
from .blade import BladeSurface, SectionMeasurement
from .definition import (
    HubDefinition,
    Propeller,
    RadialDistribution,
    SectionDefinition,
    dumps_toml,
    read_radial_csv,
)
from .hub import Hub
from .intersection import BladeHubIntersection, blade_hub_intersection, solve_intersection
from .model import PropellerModel

__all__ = [
    "BladeHubIntersection",
    "BladeSurface",
    "Hub",
    "HubDefinition",
    "Propeller",
    "PropellerModel",
    "RadialDistribution",
    "SectionDefinition",
    "SectionMeasurement",
    "blade_hub_intersection",
    "dumps_toml",
    "read_radial_csv",
    "solve_intersection",
]
