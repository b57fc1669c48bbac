"""Airfoil coordinate files (.dat): Selig, reverse Selig and Lednicer, detected automatically.

- Selig (UIUC database): a name line, then x y pairs from the trailing edge over the upper
  surface to the leading edge and back along the lower surface.
- Reverse Selig: the same with the lower surface first (e.g. WISDEM/NREL 5-MW files).
- Lednicer: a name line, a line with the two point counts (``61.  61.``), then the upper
  surface from leading to trailing edge and the lower surface from leading to trailing edge.

Lines starting with '#' are comments; non-numeric lines before the first coordinate (the
name, a column header such as ``x_c y_c``) are skipped. The name is the first of them that
is not a column header, else the file name. A coordinate that is not a number, NaN or
infinite, or a point repeating the previous one, is refused with the file and line; so are
binary files, more than :data:`MAX_AIRFOIL_POINTS` points, fewer than 5, an outline that
crosses itself (the two segments and their points named) and one of zero thickness.

The trailing edge is sharp when its two ends are within :data:`SHARP_TE_TOL` chord of each
other (re-panelled files leave ~1e-17 of rounding there), blunt otherwise.

The result is normalised to unit chord: the leading edge (the point farthest from the
trailing-edge midpoint) at the origin and the trailing-edge midpoint at (1, 0).
"""
from __future__ import annotations

import math
import pathlib
import re
from dataclasses import dataclass, replace

import numpy as np

from ..errors import DefinitionError
from ..validation import read_bytes

#: Two consecutive points closer than this (in the file's units, relative to the chord)
#: are reported as duplicates.
DUPLICATE_TOL = 1e-12
#: Most coordinate lines read (README "Limits of definitions"); UIUC files have 30-400.
MAX_AIRFOIL_POINTS = 5000
#: A trailing edge thinner than this fraction of the chord is sharp.
SHARP_TE_TOL = 1e-6
#: An outline enclosing less than this area (in chord²) has zero thickness.
MIN_AREA = 1e-6
#: A non-numeric line made only of these words is a column header, not a name
#: ("x y", "x_c y_c", "X/C Y/C", "x(c) y(c)").
_HEADER_WORD = re.compile(r"^[(\[]?[xyz]([_/(]?c\)?)?[)\]]?[,;:]?$", re.IGNORECASE)


def _is_header(line: str) -> bool:
    words = line.replace(",", " ").split()
    return bool(words) and all(_HEADER_WORD.match(w) for w in words)


@dataclass(frozen=True, eq=False)
class Airfoil:
    """A unit-chord airfoil.

    name: the file's name line (or the file stem).
    upper: (n, 2) suction (upper) side from the leading edge (0, 0) to the trailing edge.
    lower: (m, 2) pressure (lower) side from the leading edge (0, 0) to the trailing edge.
    format: "selig", "reverse-selig" or "lednicer" (as detected).
    path: the file read.
    smoothing_deviation: for an outline smoothed by :func:`smoothed_airfoil`, the largest
    distance between the smoothed and the unsmoothed curve, as a fraction of the chord
    (Hvid 1993 §3.2, measured both ways by closest point); None when not smoothed.
    """

    name: str
    upper: np.ndarray
    lower: np.ndarray
    format: str
    path: str = ""
    smoothing_deviation: float | None = None

    @property
    def outline(self) -> np.ndarray:
        """Selig order: trailing edge, upper surface, leading edge, lower surface: (n+m-1, 2)."""
        return np.concatenate([self.upper[::-1], self.lower[1:]])

    @property
    def trailing_edge_thickness(self) -> float:
        return float(np.linalg.norm(self.upper[-1] - self.lower[-1]))

    @property
    def sharp_trailing_edge(self) -> bool:
        """The TE ends are within :data:`SHARP_TE_TOL` chord (the outline is at unit chord)."""
        return self.trailing_edge_thickness <= SHARP_TE_TOL


def _parse(path: pathlib.Path):
    """Numeric rows with their 1-based line numbers, and the name line."""
    data = read_bytes(path, what="airfoil file")
    nul = data.find(b"\0")
    if nul >= 0:
        raise DefinitionError(f"binary data (a NUL byte at offset {nul}), not an airfoil file", path=str(path))
    # names in old files are often Latin-1: decode leniently, the numbers are ASCII
    text = data.decode("utf-8", errors="replace")
    name = ""
    rows: list[tuple[int, list[float]]] = []
    blank_after: set[int] = set()  # indices of rows followed by a blank line (Lednicer)
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line:
            if rows:
                blank_after.add(len(rows) - 1)
            continue
        if line.startswith("#"):
            continue
        tokens = line.replace(",", " ").split()
        values = []
        for tok in tokens:
            try:
                values.append(float(tok))
            except ValueError:
                values = None
                break
        if values is None:
            if rows:
                raise DefinitionError(f"line {lineno}: expected two numbers 'x y', got {line!r}", path=str(path))
            if not name and not _is_header(line):
                name = line
            continue
        if len(values) != 2:
            raise DefinitionError(f"line {lineno}: expected two numbers 'x y', got {line!r}", path=str(path))
        for v in values:
            if not math.isfinite(v):
                raise DefinitionError(f"line {lineno}: coordinate is {v} (NaN or infinite): {line!r}", path=str(path))
        rows.append((lineno, values))
        if len(rows) > MAX_AIRFOIL_POINTS + 1:  # + 1: a Lednicer count line
            raise DefinitionError(f"line {lineno}: more than MAX_AIRFOIL_POINTS = {MAX_AIRFOIL_POINTS} points",
                                  path=str(path))
    if len(rows) < 5:
        raise DefinitionError(f"only {len(rows)} coordinate lines; an airfoil needs at least 5", path=str(path))
    return name or path.stem, rows


def _check_duplicates(points: np.ndarray, lines: np.ndarray, path: pathlib.Path) -> None:
    scale = max(float(np.ptp(points[:, 0])), 1e-300)
    gaps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    bad = np.nonzero(gaps <= DUPLICATE_TOL * scale)[0]
    if bad.size:
        i = bad[0]
        raise DefinitionError(
            f"line {lines[i + 1]}: point {i + 1} ({points[i + 1, 0]:g}, {points[i + 1, 1]:g}) duplicates "
            f"the point on line {lines[i]} (point {i})",
            path=str(path),
        )


def _normalised_sides(outline: np.ndarray, te_mid: np.ndarray, path) -> tuple[np.ndarray, np.ndarray]:
    """The two sides of ``outline`` (TE -> LE -> TE), each from the leading edge (the point
    farthest from the trailing-edge midpoint ``te_mid``) to its trailing-edge end, at unit
    chord: the leading edge at (0, 0), ``te_mid`` at (1, 0). First the side listed first."""
    dist = np.linalg.norm(outline - te_mid, axis=1)
    i_le = int(np.argmax(dist))
    if i_le == 0 or i_le == len(outline) - 1:
        raise DefinitionError("cannot find a leading edge between the two trailing-edge ends", path=str(path))
    first, second = outline[: i_le + 1][::-1], outline[i_le:]
    le = outline[i_le]
    chord_vec = te_mid - le
    chord = float(np.hypot(*chord_vec))
    cos_a, sin_a = chord_vec / chord
    rot = np.array([[cos_a, sin_a], [-sin_a, cos_a]])

    def normalise(p):
        return ((p - le) @ rot.T) / chord

    return normalise(first), normalise(second)


def read_airfoil(path) -> Airfoil:
    """Read an airfoil .dat file (format auto-detected) and normalise it to unit chord."""
    path = pathlib.Path(path)
    name, rows = _parse(path)
    lines = np.array([r[0] for r in rows])
    pts = np.array([r[1] for r in rows], dtype=np.float64)

    n_up, n_lo = pts[0]
    is_lednicer = (
        n_up >= 2 and n_lo >= 2 and float(n_up).is_integer() and float(n_lo).is_integer()
        and int(n_up) + int(n_lo) == len(pts) - 1
    )
    if is_lednicer:
        nu = int(n_up)
        upper, lower = pts[1 : 1 + nu], pts[1 + nu :]
        lu, ll = lines[1 : 1 + nu], lines[1 + nu :]
        _check_duplicates(upper, lu, path)
        _check_duplicates(lower, ll, path)
        fmt = "lednicer"
        te_mid = 0.5 * (upper[-1] + lower[-1])
        # the leading edge is shared by both lists in Lednicer files
        outline = np.concatenate([upper[::-1], lower[1:] if np.allclose(lower[0], upper[0]) else lower])
    else:
        closed = np.linalg.norm(pts[0] - pts[-1]) <= DUPLICATE_TOL * max(np.ptp(pts[:, 0]), 1e-300)
        body, body_lines = (pts[:-1], lines[:-1]) if closed else (pts, lines)
        _check_duplicates(body, body_lines, path)
        te_mid = 0.5 * (pts[0] + pts[-1])
        outline = pts
        fmt = "selig"
    _check_crossing(outline, None if is_lednicer else lines, path)
    first, second = _normalised_sides(outline, te_mid, path)
    _check_thickness(np.concatenate([first[::-1], second[1:]]), path)
    if is_lednicer:
        upper, lower = first, second
    else:
        # Selig lists the upper side first; a file whose first half lies below the second
        # is reverse Selig.
        if np.mean(first[:, 1]) >= np.mean(second[:, 1]):
            upper, lower = first, second
        else:
            upper, lower = second, first
            fmt = "reverse-selig"
    return Airfoil(name=name, upper=upper, lower=lower, format=fmt, path=str(path))


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


#: Segments compared at once by the crossing test (bounds its memory to ~100 MB).
_CROSSING_BLOCK = 256


def _check_crossing(outline: np.ndarray, lines, path) -> None:
    """Refuse an outline (in file order) two of whose non-adjacent segments cross,
    naming the points (0-based, in the order read) and, when known, their lines. Work is
    O(n²) in blocks; n is bounded by :data:`MAX_AIRFOIL_POINTS`."""
    a, b = outline[:-1], outline[1:]
    d = b - a
    m = len(a)
    for start in range(0, m, _CROSSING_BLOCK):
        i = np.arange(start, min(start + _CROSSING_BLOCK, m))[:, None]
        j = np.arange(m)[None, :]
        ai, di = a[i[:, 0]][:, None, :], d[i[:, 0]][:, None, :]
        aj, dj = a[None, :, :], d[None, :, :]
        d1 = _cross(dj, ai - aj)
        d2 = _cross(dj, ai + di - aj)
        d3 = _cross(di, aj - ai)
        d4 = _cross(di, aj + dj - ai)
        hit = (d1 * d2 < 0) & (d3 * d4 < 0) & (j > i + 1)
        if hit.any():
            p, q = np.argwhere(hit)[0]
            p, q = int(i[p, 0]), int(q)
            where = "" if lines is None else f" (lines {lines[p]}-{lines[p + 1]} and {lines[q]}-{lines[q + 1]})"
            raise DefinitionError(
                f"the outline crosses itself: the segment from point {p} to {p + 1} crosses the segment from "
                f"point {q} to {q + 1}{where}", path=str(path))


def _check_thickness(outline: np.ndarray, path) -> None:
    """Refuse an outline (unit chord) enclosing (almost) no area: zero thickness."""
    x, y = outline[:, 0], outline[:, 1]
    area = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
    if area < MIN_AREA:
        k = int(np.argmax(np.abs(y)))
        raise DefinitionError(
            f"zero thickness: the outline encloses {area:.3g} chord², less than MIN_AREA = {MIN_AREA:g} "
            f"(the point farthest from the chord line, point {k}, is {abs(y[k]):.3g} chord off it)", path=str(path))


def airfoil_from_outline(outline, name: str, format: str = "selig", path: str = "") -> Airfoil:
    """An :class:`Airfoil` from outline points in Selig order (TE, upper side, LE, lower
    side, TE), normalised to unit chord the way :func:`read_airfoil` normalises a file:
    the leading edge is the point farthest from the trailing-edge midpoint."""
    outline = np.asarray(outline, dtype=np.float64)
    upper, lower = _normalised_sides(outline, 0.5 * (outline[0] + outline[-1]), path)
    return Airfoil(name=name, upper=upper, lower=lower, format=format, path=str(path))


def smoothed_airfoil(airfoil: Airfoil, **options) -> Airfoil:
    """``airfoil`` with its outline smoothed by Hvid's smoothfoil (Hvid 1993, DTU AFM 93-08;
    :func:`~..fairing.hvid.smooth_airfoil_result`, default jobcard unless ``options`` give
    :class:`~..fairing.hvid.SmoothingSettings` fields), renormalised to unit chord; name,
    format and path are kept, and ``smoothing_deviation`` is set. A blunt trailing edge
    stays blunt (cut back at its ends).

    Raises :class:`~..fairing.hvid.SmoothingNotConverged` (a GeometryError) when the
    iteration does not converge, GeometryError when the outline cannot be smoothed."""
    from ..fairing.hvid import smooth_airfoil_result  # the fairing package imports this module

    result = smooth_airfoil_result(airfoil.outline, **options)
    out = airfoil_from_outline(result.points, airfoil.name, airfoil.format, airfoil.path)
    return replace(out, smoothing_deviation=float(result.deviation.true))


def _surface_at(surface: np.ndarray, x: np.ndarray) -> np.ndarray:
    """y of a surface (from the LE at x = 0 to the TE) at chordwise x, interpolated in
    sqrt(x), which makes the round leading edge regular."""
    from scipy.interpolate import PchipInterpolator

    xs = np.clip(surface[:, 0], 0.0, None)
    u = np.sqrt(xs)
    order = np.argsort(u, kind="stable")
    u, y = u[order], surface[order, 1]
    keep = np.concatenate([[True], np.diff(u) > 0])
    return PchipInterpolator(u[keep], y[keep], extrapolate=True)(np.sqrt(np.clip(x, 0.0, 1.0)))


def thickness_and_camber(airfoil: Airfoil, x) -> tuple[np.ndarray, np.ndarray]:
    """Thickness y_upper - y_lower and mean line (y_upper + y_lower)/2 at chordwise ``x``,
    both measured normal to the chord line (unit chord)."""
    x = np.asarray(x, dtype=np.float64)
    yu = _surface_at(airfoil.upper, x)
    yl = _surface_at(airfoil.lower, x)
    return yu - yl, 0.5 * (yu + yl)
