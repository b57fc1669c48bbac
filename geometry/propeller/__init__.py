"""Propellers after Hally (2013): the blade b(ξ, η) from a table of sections, the hub,
the blade–hub intersection, tip smoothing into five spline surfaces (§§3–9) and the
trimmed hub sector (§10)."""
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
from .hub_sector import HubSector
from .intersection import BladeHubIntersection, blade_hub_intersection, solve_intersection
from .model import PropellerModel
from .smoothing import SmoothedBlade, SmoothingSettings, smooth_blade

__all__ = [
    "BladeHubIntersection",
    "BladeSurface",
    "Hub",
    "HubSector",
    "HubDefinition",
    "Propeller",
    "PropellerModel",
    "RadialDistribution",
    "SectionDefinition",
    "SectionMeasurement",
    "SmoothedBlade",
    "SmoothingSettings",
    "blade_hub_intersection",
    "dumps_toml",
    "read_radial_csv",
    "smooth_blade",
    "solve_intersection",
]
