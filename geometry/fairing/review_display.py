"""What a review image needs besides the curvature itself, without Blender: a sequential
colour map for quantities that are never negative, zebra stripes (reflection lines) as a
quantity, sign conventions in words, a scale-bar length, where a blade's leading edge,
trailing edge, root and tip are, and span segments that let a long blade fill the frame.
"""
from __future__ import annotations

import numpy as np

from ..errors import GeometryError

#: Quantities that are never negative: shown on :func:`sequential_colours` from 0.
NON_NEGATIVE = frozenset({"strain_energy", "mvs", "zebra"})

#: sRGB stops of the sequential map, light (0) to dark (the upper limit): pale yellow,
#: orange, red, dark purple; lightness falls monotonically so it reads in grey too.
SEQUENTIAL_CONTROL_COLOURS = np.array([
    [1.00, 0.99, 0.88],
    [0.99, 0.84, 0.45],
    [0.96, 0.55, 0.22],
    [0.80, 0.22, 0.18],
    [0.45, 0.05, 0.30],
    [0.18, 0.02, 0.22],
])

#: Zebra stripes: light stripes per unit of the reflected direction's component along
#: the stripe axis (reflections of a plane of parallel light stripes; Klass 1980, the
#: "reflection lines" CAD systems show), and the contrast that sharpens the sine into
#: stripes while keeping their edges anti-aliased over a few vertices.
ZEBRA_STRIPES = 6.0
ZEBRA_CONTRAST = 3.0

#: Fraction of the chord at either end of a mid-span slice over which a blade's thickness
#: is compared to tell the rounded leading edge from the thin trailing edge.
EDGE_PROBE_FRACTION = 0.05
#: Points of the mid-span slice: within this fraction of the span of its middle.
SLICE_FRACTION = 0.04


def sequential_colours(values, limits: tuple[float, float]) -> np.ndarray:
    """sRGB RGBA (n..., 4) of ``values`` on :data:`SEQUENTIAL_CONTROL_COLOURS`, limits[0]
    (normally 0) the lightest, limits[1] the darkest; clipped outside."""
    lo, hi = float(limits[0]), float(limits[1])
    if not hi > lo:
        raise GeometryError(f"colour limits must increase, got {limits!r}")
    x = np.asarray(values, dtype=np.float64)
    s = np.clip((x - lo) / (hi - lo), 0.0, 1.0)
    s = np.where(np.isfinite(s), s, 0.0)
    stops = np.linspace(0.0, 1.0, len(SEQUENTIAL_CONTROL_COLOURS))
    out = np.ones(x.shape + (4,))
    for c in range(3):
        out[..., c] = np.interp(s, stops, SEQUENTIAL_CONTROL_COLOURS[:, c])
    return out


def zebra_colours(values) -> np.ndarray:
    """Black and white stripes (grey in between) of zebra ``values`` in [0, 1]."""
    v = np.clip(np.asarray(values, dtype=np.float64), 0.0, 1.0)
    out = np.ones(v.shape + (4,))
    out[..., :3] = v[..., None]
    return out


def upper_limit(values, percentile: float, weights=None) -> tuple[float, float]:
    """(0, c) with c the (area-weighted) ``percentile`` of the finite non-negative values."""
    v = np.concatenate([np.ravel(a) for a in values]) if isinstance(values, (list, tuple)) else np.ravel(values)
    w = np.ones_like(v) if weights is None else (
        np.concatenate([np.ravel(a) for a in weights]) if isinstance(weights, (list, tuple)) else np.ravel(weights))
    ok = np.isfinite(v) & np.isfinite(w) & (w > 0)
    v, w = np.abs(v[ok]), w[ok]
    if v.size == 0:
        return 0.0, 1.0
    order = np.argsort(v)
    cw = np.cumsum(w[order])
    c = float(v[order][min(np.searchsorted(cw, percentile / 100.0 * cw[-1]), v.size - 1)])
    if c <= 0.0:
        c = float(v.max()) if v.max() > 0 else 1.0
    return 0.0, c


def zebra_values(normals, view: np.ndarray, axis: np.ndarray, stripes: float = ZEBRA_STRIPES,
                 contrast: float = ZEBRA_CONTRAST) -> np.ndarray:
    """Zebra value in [0, 1] (1 light) at unit ``normals`` (..., 3): the viewing direction
    ``view`` reflected in the surface, r = v − 2 (v·n) n, looks at a plane of light stripes
    perpendicular to ``axis``; value = ½ + ½ clip(contrast · sin(π · stripes · r·axis)).
    A stripe follows the surface's slope, so a kink in the surface (G0) breaks the
    stripes, a jump in curvature (G1) kinks them and a wiggle makes them wobble. The sign
    of the normal does not matter (r is the same for n and −n)."""
    n = np.asarray(normals, dtype=np.float64)
    v = np.asarray(view, dtype=np.float64) / np.linalg.norm(view)
    a = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    r = v - 2.0 * (n @ v)[..., None] * n
    return 0.5 + 0.5 * np.clip(contrast * np.sin(np.pi * stripes * (r @ a)), -1.0, 1.0)


def sign_convention(quantity: str, convex_positive: bool = True) -> str:
    """One line saying what a positive (or any) value means."""
    if quantity in ("mean", "k1", "k2", "max_abs"):
        return ("positive: convex (the surface bulges out along its outward normal)" if convex_positive
                else "positive: concave (hollow seen from outside)")
    if quantity == "gaussian":
        return "positive: dome or dish (elliptic), negative: saddle (hyperbolic); sign independent of the normal"
    if quantity in ("strain_energy", "mvs"):
        return "never negative: 0 is flat (strain energy) or linearly varying curvature (MVS)"
    if quantity == "zebra":
        return "reflection lines: smooth = fair; kinked = curvature jump; broken = crease; wobbly = wiggle"
    if quantity == "deviation":
        return "positive: outside the reference surface (along its outward normal)"
    return ""


def nice_length(span: float) -> float:
    """The largest 1, 2 or 5 × 10^k not above ``span`` (a scale bar's length)."""
    if not span > 0:
        raise GeometryError(f"scale bar: need a positive length, got {span!r}")
    k = np.floor(np.log10(span))
    for m in (5.0, 2.0, 1.0):
        if m * 10.0**k <= span:
            return float(m * 10.0**k)
    return float(10.0**k)


def length_label(length: float) -> str:
    """'20 mm', '5 m', '0.5 mm' for a length in metres."""
    if length >= 1.0:
        return f"{length:g} m"
    return f"{1000.0 * length:g} mm"


def blade_landmarks(points, span: np.ndarray, side: np.ndarray) -> dict[str, np.ndarray]:
    """World positions of a blade's "root", "tip", "LE" and "TE" from its surface points
    (m, 3), the span direction (root → tip) and the side direction (normal of the view).

    Root and tip: the points farthest down and up the span (mid-chord of the end slices).
    LE and TE: the chord ends of the mid-span slice; the leading edge is the rounded end,
    thicker (along ``side``) within :data:`EDGE_PROBE_FRACTION` of the chord from its end
    than the trailing edge is. Returns {} when there are too few points."""
    P = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if P.shape[0] < 8:
        return {}
    span = span / np.linalg.norm(span)
    side = side - span * np.dot(side, span)
    side /= np.linalg.norm(side)
    chord = np.cross(side, span)
    s, c, t = P @ span, P @ chord, P @ side
    lo, hi = s.min(), s.max()
    length = hi - lo
    out = {}
    for name, at in (("root", lo), ("tip", hi)):
        near = np.abs(s - at) <= SLICE_FRACTION * length
        out[name] = P[near].mean(axis=0)
    mid = 0.5 * (lo + hi)
    band = np.abs(s - mid) <= SLICE_FRACTION * length
    if band.sum() < 4:
        band = np.abs(s - mid) <= 0.25 * length
    cs, ts, Ps = c[band], t[band], P[band]
    cmin, cmax = cs.min(), cs.max()
    probe = EDGE_PROBE_FRACTION * (cmax - cmin)

    def thickness(sel):
        return float(np.ptp(ts[sel])) if sel.sum() >= 2 else 0.0

    low_end, high_end = cs <= cmin + probe, cs >= cmax - probe
    lo_point, hi_point = Ps[np.argmin(cs)], Ps[np.argmax(cs)]
    if thickness(low_end) >= thickness(high_end):
        out["LE"], out["TE"] = lo_point, hi_point
    else:
        out["LE"], out["TE"] = hi_point, lo_point
    return out


def span_segments(points, span: np.ndarray, count: int, overlap: float = 0.03) -> list[tuple[float, float]]:
    """``count`` equal (slightly overlapping) intervals of the span coordinate that cover
    the points: a long blade drawn segment by segment fills a wide frame."""
    if count < 1:
        raise GeometryError(f"span segments: need at least 1, got {count}")
    s = np.asarray(points, dtype=np.float64).reshape(-1, 3) @ (span / np.linalg.norm(span))
    lo, hi = float(s.min()), float(s.max())
    step = (hi - lo) / count
    return [(lo + k * step - overlap * step, lo + (k + 1) * step + overlap * step) for k in range(count)]


def segment_count(span_length: float, chord_length: float, aspect: float = 3.0) -> int:
    """Segments so each is about ``aspect`` times as long as the chord (1 for stubby
    shapes): NREL 5-MW (61.5 m span, 4.7 m chord) gives 4."""
    if not (span_length > 0 and chord_length > 0):
        return 1
    return int(max(1, min(8, round(span_length / (aspect * chord_length)))))
