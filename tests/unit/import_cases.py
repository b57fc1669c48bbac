"""Small IGES files for the import tests (units, placement, trimmed faces with holes), built
with Bladesmith's own writer and then edited the way other CAD systems write them.

Shared by tests/unit/test_iges_import.py and tests/iges/test_import_vs_occ.py (loaded by
path there). Every case returns the file text and what a correct importer shows.
"""
from __future__ import annotations

import datetime as dt
import math

import numpy as np

from bladesmith.iges import (
    BSplineCurve126,
    CompositeCurve,
    Line,
    TransformationMatrix,
    parse_iges,
    surface_from_geometry,
    to_string,
)
from bladesmith.iges import examples
from bladesmith.iges.records import GLOBAL_FIELDS

STAMP = dt.datetime(2024, 1, 2, 3, 4, 5)
KEEP = object()


def _hollerith(s: str) -> str:
    return f"{len(s)}H{s}" if s else ""


def set_global(text: str, **changes) -> str:
    """``text`` with Global fields replaced: a value, or None for a defaulted (empty) field."""
    header = parse_iges(text).header
    tokens = []
    for name, kind in GLOBAL_FIELDS:
        value = changes.get(name, getattr(header, name))
        if value is None:
            tokens.append("")
        elif kind == "s":
            tokens.append(_hollerith(value))
        elif kind == "i":
            tokens.append(str(int(value)))
        else:
            tokens.append(repr(float(value)).upper())
    body = ",".join(tokens) + ";"
    glines = [f"{body[i:i + 72]:<72}G{k + 1:7d}" for k, i in enumerate(range(0, len(body), 72))]
    lines = text.split("\n")
    if lines[-1] == "":
        lines.pop()
    s = [ln for ln in lines if ln[72] == "S"]
    rest = [ln for ln in lines if ln[72] in "DP"]
    t = lines[-1]
    t = t[:8] + f"G{len(glines):7d}" + t[16:]
    return "\n".join(s + glines + rest + [t]) + "\n"


def line_file(length: float = 1000.0) -> str:
    """One line of ``length`` along x from the origin."""
    return to_string([Line([0.0, 0.0, 0.0], [length, 0.0, 0.0])], timestamp=STAMP)


#: (changes to Global fields, metres per file unit a correct reader uses) for the unit cases
UNIT_CASES = {
    "flag 2, name MM": (dict(unit_flag=2, unit_name="MM"), 1e-3),
    "flag 2, blank name": (dict(unit_flag=2, unit_name=None), 1e-3),
    "flag 2, name MILLIMETER": (dict(unit_flag=2, unit_name="MILLIMETER"), 1e-3),
    "flag 3, name MILLIMETRE": (dict(unit_flag=3, unit_name="MILLIMETRE"), 1e-3),
    "flag 3, name INCH": (dict(unit_flag=3, unit_name="INCH"), 0.0254),
    "flag 10, name M (flag rules)": (dict(unit_flag=10, unit_name="M"), 1e-2),
    "defaulted flag and name (inches)": (dict(unit_flag=None, unit_name=None), 0.0254),
    "flag 6, name M": (dict(unit_flag=6, unit_name="M"), 1.0),
    "flag 4, name FT": (dict(unit_flag=4, unit_name="FT"), 0.3048),
}


def rot(axis, angle) -> np.ndarray:
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


R1 = rot([1, 2, 3], 0.7)
T1 = np.array([10.0, -20.0, 5.0])
R2 = rot([0, 0, 1], 0.5)
T2 = np.array([-3.0, 4.0, 1.0])


def composite_with_transform() -> tuple[str, np.ndarray]:
    """A 102 of two lines carrying a 124: returns (text, expected points (4, 3))."""
    a, b, c = np.array([0.0, 0, 0]), np.array([2.0, 0, 0]), np.array([2.0, 1, 0])
    comp = CompositeCurve([Line(a, b), Line(b, c)], transform=TransformationMatrix(R1, T1))
    expected = np.stack([a, b, b, c]) @ R1.T + T1
    return to_string([comp], timestamp=STAMP), expected


def trimmed_with_transforms() -> tuple[str, float]:
    """The plane-with-hole 144 carrying a 124, over a surface with its own 124: returns
    (text, exact area). The file is in metres."""
    t, area = examples.trimmed_plane_with_hole()
    from dataclasses import replace

    surface = replace(t.surface, transform=TransformationMatrix(R2, T2))
    outer = None if t.outer is None else replace(t.outer, surface=surface, model_curve=None)
    inner = tuple(replace(c, surface=surface, model_curve=None) for c in t.inner)
    moved = replace(t, surface=surface, outer=outer, inner=inner, transform=TransformationMatrix(R1, T1))
    return to_string([moved], timestamp=STAMP), area


def plane_with_hole_mm() -> tuple[str, float]:
    t, area = examples.trimmed_plane_with_hole()
    return to_string([t], units="mm", timestamp=STAMP), area


# -- files written by hand, for entities Bladesmith does not write --------------------------
def raw_file(entities, units_flag: int = 6, unit_name: str = "M", newline: str = "\n") -> str:
    """An IGES file of ``entities``: (type, [parameters after the type], form, transform DE
    number or 0, subordinate switch '00'..'03'). Parameters that point to entity k
    (1-based) are written as f"@{k}" and become DE numbers 2k - 1."""
    def de(k):
        return 2 * k - 1

    head = f"1H,,1H;,4Htest,4Htest,4Htest,4Htest,32,38,6,308,15,4Htest,1.0,{units_flag},"
    head += f"{len(unit_name)}H{unit_name},1,0.0,15H20240101.000000,1.0E-6,0.0,4Htest,4Htest,11,0,"
    head += "15H20240101.000000;"
    S = [f"{'hand-written test file':<72}S{1:7d}"]
    G = [f"{head[i:i + 72]:<72}G{k + 1:7d}" for k, i in enumerate(range(0, len(head), 72))]
    D, P = [], []
    for k, ent in enumerate(entities, 1):
        etype, params, form, tr, sub = (tuple(ent) + (0, 0, "00"))[:5] if len(ent) < 5 else ent
        toks = [str(etype)] + [str(de(int(p[1:]))) if isinstance(p, str) and p.startswith("@") else str(p)
                               for p in params]
        body = ",".join(toks) + ";"
        chunks = [body[i:i + 64] for i in range(0, len(body), 64)]
        start = len(P) + 1
        for c in chunks:
            P.append(f"{c:<64} {de(k):7d}P{len(P) + 1:7d}")
        status = f"0000{sub}00"
        tr_field = de(tr) if tr else 0
        D.append(f"{etype:8d}{start:8d}{0:8d}{0:8d}{0:8d}{0:8d}{tr_field:8d}{0:8d}{status:>8}D{len(D) + 1:7d}")
        D.append(f"{etype:8d}{0:8d}{0:8d}{len(chunks):8d}{form:8d}{'':8}{'':8}{'':8}{0:8d}D{len(D) + 1:7d}")
    T = f"S{len(S):7d}G{len(G):7d}D{len(D):7d}P{len(P):7d}{'':40}T{1:7d}"
    return newline.join(S + G + D + P + [T]) + newline


def matrix_params(R, T) -> list:
    M = np.c_[np.asarray(R, float), np.asarray(T, float)]
    return [repr(float(x)) for x in M.ravel()]


def subfigure_instance(scale: float = 2.0) -> tuple[str, np.ndarray]:
    """A 408 of a 308 holding one line, scale ``scale``, translation (1, 2, 3), and a 124 on
    the 408: returns (text, expected end points (2, 3)) by IGES 5.3 type 408 (definition
    scaled by S, then translated, then the 408's own matrix)."""
    p0, p1 = np.array([1.0, 0.0, 0.0]), np.array([1.0, 1.0, 0.5])
    ents = [
        (110, [*p0, *p1], 0, 0, "01"),               # 1: the member
        (308, [0, "4Hpart", 1, "@1"], 0, 0, "02"),    # 2: the definition
        (124, matrix_params(R1, T1), 0, 0, "01"),    # 3: the instance's transform
        (408, ["@2", 1.0, 2.0, 3.0, scale], 0, 3, "00"),  # 4: the instance
    ]
    expected = (scale * np.stack([p0, p1]) + [1.0, 2.0, 3.0]) @ R1.T + T1
    return raw_file(ents), expected


def nested_composites(depth: int = 3) -> tuple[str, np.ndarray]:
    """A line inside ``depth`` nested 102s, each carrying its own 124 (rotation R2 with
    translation (k, 0, 0)): returns (text, expected end points)."""
    p0, p1 = np.array([0.0, 0.0, 0.0]), np.array([1.0, 2.0, 3.0])
    ents = [(110, [*p0, *p1], 0, 0, "01")]
    expected = np.stack([p0, p1])
    for k in range(depth):
        ents.append((124, matrix_params(R2, [k + 1.0, 0.0, 0.0]), 0, 0, "01"))
        ents.append((102, [1, f"@{len(ents) - 1}"], 0, len(ents), "00" if k == depth - 1 else "01"))
        expected = expected @ R2.T + [k + 1.0, 0.0, 0.0]
    return raw_file(ents), expected


def exploding_composites(levels: int = 6, fan: int = 20) -> str:
    """102s that each name the previous one ``fan`` times: fan**levels curves from ~2 KB."""
    ents = [(110, [0, 0, 0, 1, 0, 0], 0, 0, "01")]
    for k in range(levels):
        ents.append((102, [fan] + [f"@{len(ents)}"] * fan, 0, 0, "01" if k < levels - 1 else "00"))
    return raw_file(ents)


def plane_face_with_hole() -> tuple[str, float]:
    """A 144 over a 108 plane z = 1, bounded by model-space loops (no parameter curves, as
    many systems write planes): a 4 x 3 rectangle with a 1 x 1 square hole. (text, area)."""
    sq = lambda x0, y0, x1, y1: [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]  # noqa: E731
    ents = [(108, [0.0, 0.0, 1.0, 1.0, 0, 0.0, 0.0, 0.0, 0.0], 1, 0, "01")]   # 1
    loops = []
    for corners in (sq(0, 0, 4, 3), sq(1, 1, 2, 2)[::-1]):
        first = len(ents) + 1
        for a, b in zip(corners, corners[1:] + corners[:1]):
            ents.append((110, [a[0], a[1], 1.0, b[0], b[1], 1.0], 0, 0, "01"))
        ents.append((102, [4] + [f"@{first + i}" for i in range(4)], 0, 0, "01"))
        ents.append((142, [0, "@1", 0, f"@{len(ents)}", 2], 0, 0, "01"))
        loops.append(len(ents))
    ents.append((144, ["@1", 1, 1, f"@{loops[0]}", f"@{loops[1]}"], 0, 0, "00"))
    return raw_file(ents), 4 * 3 - 1


def tabulated_cylinder_face() -> tuple[str, float]:
    """A 144 over a 122 (a quarter arc of radius 2 as a 126, pulled 3 along z), trimmed by
    its parameter domain with a hole of radius 0.2 about (u, v) = (0.5, 0.5) in
    parameter space. Returns (text, approximate area: the quarter cylinder's area)."""
    arc = examples.arc126([0.0, 0.0], 2.0, 0.0, 0.5 * math.pi, z=0.0)
    ents = []
    k = arc.control_points
    ents.append((126, [2, 2, 0, 0, 0, 0, *arc.knots, *arc.weights, *k.ravel(), 0.0, 1.0], 0, 0, "01"))  # 1
    ents.append((122, ["@1", 2.0, 0.0, 3.0], 0, 0, "01"))  # 2
    # outer: the unit square in (u, v)
    sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
    first = len(ents) + 1
    for a, b in zip(sq, sq[1:] + sq[:1]):
        ents.append((110, [a[0], a[1], 0.0, b[0], b[1], 0.0], 0, 0, "01"))
    ents.append((102, [4] + [f"@{first + i}" for i in range(4)], 0, 0, "01"))
    ents.append((142, [0, "@2", f"@{len(ents)}", 0, 1], 0, 0, "01"))
    outer = len(ents)
    ents.append((100, [0.0, 0.5, 0.5, 0.7, 0.5, 0.7, 0.5], 0, 0, "01"))  # a full circle in (u, v)
    ents.append((142, [0, "@2", f"@{len(ents)}", 0, 1], 0, 0, "01"))
    inner = len(ents)
    ents.append((144, ["@2", 1, 1, f"@{outer}", f"@{inner}"], 0, 0, "00"))
    return raw_file(ents), 0.5 * math.pi * 2.0 * 3.0


def cylinder_face() -> tuple[str, float]:
    """A 144 over a 192 right circular cylinder (radius 2 about z, form 1), bounded by a
    model-space loop only (PREF 2, no parameter curve) across the angle pi where atan2
    jumps: the arc 135..225 degrees at z = 0, up 3, back at z = 3, down; the 144 carries a
    124 (rotation and translation). Returns (text, area 2 * (pi / 2) * 3)."""
    ents = [(116, [0.0, 0.0, 0.0], 0, 0, "01"),                       # 1 location
            (123, [0.0, 0.0, 1.0], 0, 0, "01"),                       # 2 axis
            (123, [1.0, 0.0, 0.0], 0, 0, "01"),                       # 3 reference direction
            (192, ["@1", "@2", 2.0, "@3"], 1, 0, "01")]               # 4
    a0, a1 = 0.75 * math.pi, 1.25 * math.pi
    p0 = [2 * math.cos(a0), 2 * math.sin(a0)]
    p1 = [2 * math.cos(a1), 2 * math.sin(a1)]
    first = len(ents) + 1
    for arc in (examples.arc126([0.0, 0.0], 2.0, a0, a1, z=0.0), None, examples.arc126([0.0, 0.0], 2.0, a1, a0, z=3.0)):
        if arc is None:
            ents.append((110, [*p1, 0.0, *p1, 3.0], 0, 0, "01"))
            continue
        k = arc.control_points
        ents.append((126, [2, 2, 0, 0, 0, 0, *arc.knots, *arc.weights, *k.ravel(), 0.0, 1.0], 0, 0, "01"))
    ents.append((110, [*p0, 3.0, *p0, 0.0], 0, 0, "01"))
    ents.append((102, [4] + [f"@{first + i}" for i in range(4)], 0, 0, "01"))
    ents.append((142, [0, "@4", 0, f"@{len(ents)}", 2], 0, 0, "01"))
    loop = len(ents)
    ents.append((124, matrix_params(rot([1.0, 2.0, 2.0], 0.6), [1.0, -2.0, 0.5]), 0, 0, "01"))
    ents.append((144, ["@4", 1, 0, f"@{loop}"], 0, len(ents), "00"))
    return raw_file(ents), 2 * (0.5 * math.pi) * 3
