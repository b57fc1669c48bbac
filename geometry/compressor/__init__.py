"""Centrifugal compressor channels and blades after Casey (1983), "A computational
geometry for the blades and internal flow channels of centrifugal compressors",
ASME J. Eng. Power.

- :mod:`.bezier`: Bernstein–Bézier curves, patches linear in v, strings, B-spline form;
- :mod:`.channel`: the meridional channel M from skeletal data, surfaces of revolution;
- :mod:`.blade`: B, S and P blade surfaces from β(m) and δ(m) (Appendix A1–A5);
- :mod:`.definition`: TOML definitions and the impeller model;
- :mod:`.fitting`: approximating existing impellers (DLR SRV2-O);
- :mod:`.uses`: nets, axial sections, standardisation, rulings;
- :mod:`.standardisation`: standardised (trimmed) blades as B-spline surfaces (Fig. 11).
"""
from .bezier import BezierCurve, BezierString, PatchString, RuledPatch, bernstein
from .blade import BladeSurfaces, build_blade, casey_shooting, cubic_string_through, surface_end_angles
from .channel import MeridionalChannel, channel_from_skeleton, surface_of_revolution
from .definition import ImpellerDefinition, ImpellerModel, dumps_toml
from .uses import axial_section, blade_net, channel_net, distribution, rulings, scaled_channel, standardise, write_net_csv

__all__ = [
    "BezierCurve", "BezierString", "BladeSurfaces", "ImpellerDefinition", "ImpellerModel", "MeridionalChannel",
    "PatchString", "RuledPatch", "axial_section", "bernstein", "blade_net", "build_blade", "casey_shooting",
    "channel_from_skeleton", "channel_net", "cubic_string_through", "distribution", "dumps_toml", "rulings",
    "scaled_channel", "standardise", "surface_end_angles", "surface_of_revolution", "write_net_csv",
]
