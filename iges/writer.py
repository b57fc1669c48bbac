"""IGES 5.3 writer, fixed 80-column ASCII form (IGES 5.3 §2.2).

The five sections (IGES 5.3 §2.2.4): Start (S), Global (G), Directory Entry (D, two
lines per entity), Parameter Data (P, columns 1-64 data, 66-72 the back-pointer to the
entity's first DE line) and Terminate (T). Columns 73-80 hold the section letter and a
sequence number counting from 1 in each section.

Everything is validated and serialised in memory before the file is touched; the
file is then written to a temporary file in the same folder and moved over the target
with ``os.replace``, so a failed export never leaves a partial file or clobbers the
previous one (ARCHITECTURE.md, house style 8).
"""
from __future__ import annotations

import datetime as _dt
import math
import os
import re
from itertools import chain

import numpy as np

from ..geometry.files import atomic_write as _atomic_write
from ..geometry.errors import BladesmithError, IgesError
from .records import (
    UNIT_NAMES,
    UNITS,
    BSplineCurve126,
    BSplineSurface128,
    CircularArc,
    CompositeCurve,
    CurveOnSurface,
    Entity,
    GenericEntity,
    GlobalSection,
    GLOBAL_FIELDS,
    Line,
    ParametricSpline,
    ParametricSplineSurface,
    SurfaceOfRevolution,
    TransformationMatrix,
    TrimmedSurface,
)
from .brep import BREP_TYPES, parameter_curves, parameter_tokens, validate_brep
from .validate import curve_flags, surface_flags, validate_entity, validate_loop

#: Arrays up to this length are written with Python's shortest round-trip repr; longer ones
#: (control nets) with 17 significant digits, which is as exact and about twice as fast.
SHORTEST_REPR_SIZE = 256
#: Default minimum user-intended resolution (Global field 19), in file units.
DEFAULT_RESOLUTION = 1e-7
#: Parameter data occupy columns 1-64 of a P line (IGES 5.3 §2.2.4.5).
PD_COLUMNS = 64
#: Start and Global data occupy columns 1-72.
DATA_COLUMNS = 72
#: Entities nested deeper than this are refused (records cannot be cyclic, but be safe).
MAX_DEPTH = 256
START_TEXT = "Bladesmith exact NURBS geometry, IGES 5.3 fixed format."

_EXPONENT = re.compile(r"(\d+)(\.\d*)?e")


def _fix_exponent(m: re.Match) -> str:
    return m.group(1) + (m.group(2) or ".") + "E"


def format_real(x: float) -> str:
    """An IGES real constant that reads back as exactly ``x`` (IGES 5.3 §2.2.2.3).

    Python's shortest round-trip repr, with a decimal point always present and the
    exponent letter E (``1e-05`` -> ``1.E-05``).
    """
    s = repr(float(x))
    return _EXPONENT.sub(_fix_exponent, s) if "e" in s else s


def _reals(values) -> str:
    """Comma-separated :func:`format_real` of all values, fast for large arrays."""
    a = np.asarray(values, dtype=np.float64).ravel()
    if a.size > 1 and np.all(a == a[0]) and not (a[0] == 0 and np.any(np.signbit(a))):
        return ",".join([format_real(a[0])] * a.size)  # e.g. the unit weights of a polynomial surface
    mag = np.abs(a)
    if a.size <= SHORTEST_REPR_SIZE:
        strs = list(map(repr, a.tolist()))
        # repr switches to exponent notation below 1e-4 and from 1e16 on: fix only those
        for i in np.flatnonzero((mag != 0) & ((mag < 1e-4) | (mag >= 1e16))).tolist():
            strs[i] = format_real(a[i])
        return ",".join(strs)
    # Bulk data: 17 significant digits (max_digits10, exact for every double), the text
    # of "%.17g" built by numpy (_bulk_reals); the few integral or exponent-form values
    # are written by format_real so that every real keeps its decimal point.
    return ",".join(_bulk_reals(a[s : s + BULK_CHUNK]) for s in range(0, a.size, BULK_CHUNK))


# -- bulk reals: "%.17g" by array arithmetic --------------------------------------------------
#: Reals formatted per numpy pass: keeps the (chunk, 24) byte temporaries in cache.
BULK_CHUNK = 1 << 13
#: 10**k for k = 0..22, all exact doubles.
_POW10 = 10.0 ** np.arange(23)
#: Veltkamp's splitting constant 2**27 + 1: exact products without a fused multiply-add.
_SPLIT = 134217729.0
#: The characters of 0000 .. 9999 as little-endian 4-byte words (first character lowest).
_FOUR_DIGITS = np.frombuffer("".join(f"{i:04d}" for i in range(10**4)).encode("ascii"), dtype="<u4")
#: Trailing zero digits of 0000 .. 9999 (4 for 0000).
_TRAILING_ZEROS = np.array([len(f"{i:04d}") - len(f"{i:04d}".rstrip("0")) for i in range(10**4)], dtype=np.int64)
#: Word masks keeping the first 4, 3, 2, 1, 0 characters.
_KEEP_MASK = np.array([0xFFFFFFFF, 0x00FFFFFF, 0x0000FFFF, 0x000000FF, 0], dtype="<u4")
_COMMA, _DOT, _ZERO, _MINUS, _HOLE = (ord(c) for c in ",.0-#")


def _scaled_integers(m: np.ndarray, t: np.ndarray) -> np.ndarray:
    """round(m * 10**t) exactly (ties to even), for 10**16 <= m * 10**t < 2**63: the
    product as hi + lo by Dekker's TwoProduct (hi >= 2**53 is an even integer, so
    rounding lo to even rounds the sum to even)."""
    pw = _POW10[t]
    hi = m * pw
    s = _SPLIT * m
    mh = s - (s - m)
    ml = m - mh
    s = _SPLIT * pw
    ph = s - (s - pw)
    pl = pw - ph
    lo = ((mh * ph - hi) + mh * pl + ml * ph) + ml * pl
    return hi.astype(np.int64) + np.rint(lo).astype(np.int64)


def _is_bulk(a: np.ndarray, m: np.ndarray) -> np.ndarray:
    """The reals that "%.17g" writes in positional form with a fraction (the others are
    written by :func:`format_real`)."""
    return (m >= 1e-4) & (m < 1e17) & (a != np.trunc(a))


def _digit_words(m: np.ndarray):
    """For magnitudes 1e-4 <= m < 1e17: (t, words, trailing): m = D · 10**-t with D the
    17-digit integer nearest to m · 10**t (:func:`_scaled_integers`), D's digits as five
    little-endian 4-byte words (the leading digit in the last byte of the first word, then
    four groups of four looked up in a table of "0000".."9999"), and the number of
    trailing zero digits of D (the fraction is never all zero)."""
    t = 16 - np.floor(np.log10(m)).astype(np.intp)
    D = _scaled_integers(m, t)
    for _ in range(2):  # log10 may be one off next to a power of ten
        wrong = np.flatnonzero((D >= 10**17) | (D < 10**16))
        if not wrong.size:
            break
        t[wrong] += np.where(D[wrong] < 10**16, 1, -1)
        D[wrong] = _scaled_integers(m[wrong], t[wrong])
    # D = lead · 10**16 + g1 · 10**12 + g2 · 10**8 + g3 · 10**4 + g4, in 32-bit arithmetic
    # after one 64-bit division
    hi, lo = np.divmod(D, 10**8)
    lead, h8 = np.divmod(hi.astype(np.uint32), np.uint32(10**8))
    g1, g2 = np.divmod(h8, np.uint32(10**4))
    g3, g4 = np.divmod(lo.astype(np.uint32), np.uint32(10**4))
    words = np.empty((D.size, 5), dtype="<u4")
    words[:, 0] = (np.uint32(_ZERO) + lead) << np.uint32(24)
    for col, group in ((1, g1), (2, g2), (3, g3), (4, g4)):
        words[:, col] = np.take(_FOUR_DIGITS, group)
    tz = _TRAILING_ZEROS
    trailing = np.take(tz, g4) + (g4 == 0) * (
        np.take(tz, g3) + (g3 == 0) * (np.take(tz, g2) + (g2 == 0) * np.take(tz, g1)))
    return t, words, trailing


def _bulk_reals(a: np.ndarray) -> str:
    """``",".join("%.17g" % x ...)`` for reals with 1e-4 <= |x| < 1e17 and a fraction
    (byte-identical to C's printf, which rounds the exact binary value to 17 significant
    digits, half to even), and :func:`format_real` for the others.

    |x| = D · 10**-t with D the 17-digit integer nearest to |x| · 10**t, computed exactly
    (:func:`_scaled_integers`); "%g" then writes D's digits with the point after digit
    16 - t (or "0.000" before them) and drops trailing zeros of the fraction."""
    values = a
    m = np.abs(a)
    bulk = _is_bulk(a, m)
    special = None if bulk.all() else np.flatnonzero(~bulk)
    if special is not None:
        keep = np.flatnonzero(bulk)
        a, m = a[keep], m[keep]
    t, words, trailing = _digit_words(m)
    for col in (4, 3, 2, 1):  # zeros dropped from this word: min(4, max(0, trailing - 4 (4 - col)))
        drop = np.clip(trailing - 4 * (4 - col), 0, 4)
        words[:, col] &= np.take(_KEEP_MASK, drop)
    digits = words.view(np.uint8)[:, 3:]  # (n, 17)
    rows = np.zeros((t.size, 24), dtype=np.uint8)  # sign, up to 22 characters, comma
    rows[:, 0] = np.where(a < 0, _MINUS, 0)
    rows[:, 23] = _COMMA
    X = 16 - t  # the decimal exponent, -4 <= X <= 16
    for e in np.unique(X).tolist():
        idx = np.flatnonzero(X == e)
        d = digits[idx]
        if e >= 0:
            block = np.empty((idx.size, 18), dtype=np.uint8)
            block[:, : e + 1] = d[:, : e + 1]
            block[:, e + 1] = _DOT
            block[:, e + 2 :] = d[:, e + 1 :]
        else:
            block = np.full((idx.size, 18 - e), _ZERO, dtype=np.uint8)  # "0." and -e - 1 zeros
            block[:, 1] = _DOT
            block[:, 1 - e :] = d
        rows[idx, 1 : 1 + block.shape[1]] = block
    if special is not None:
        full = np.zeros((bulk.size, 24), dtype=np.uint8)
        full[keep] = rows
        full[special, 0] = _HOLE
        full[special, 23] = _COMMA
        rows = full
    flat = rows.ravel()
    text = flat[flat != 0].tobytes().decode("ascii")[:-1]
    if special is None:
        return text
    others = [format_real(x) for x in values[special].tolist()] + [""]
    return "".join(chain.from_iterable(zip(text.split(chr(_HOLE)), others)))


def hollerith(text: str) -> str:
    return f"{len(text)}H{text}" if text else ""


# -- entity ordering and roles -------------------------------------------------------------------
def _children(entity: Entity):
    refs = list(entity.references())
    if entity.transform is not None:
        refs.append(entity.transform)
    return refs


def collect(roots) -> list[Entity]:
    """All entities reachable from ``roots``, each once, every entity after the ones it
    references (so a file we read and write again keeps its order)."""
    order: list[Entity] = []
    state: dict[int, int] = {}

    def visit(e, depth):
        if not isinstance(e, Entity):
            raise IgesError(f"expected an IGES record, got {type(e).__name__}")
        s = state.get(id(e))
        if s == 2:
            return
        if s == 1:
            raise IgesError(f"{e.describe()} references itself (cycle)")
        if depth > MAX_DEPTH:
            raise IgesError(f"{e.describe()}: references nested deeper than {MAX_DEPTH}")
        state[id(e)] = 1
        for c in _children(e):
            visit(c, depth + 1)
        state[id(e)] = 2
        order.append(e)

    for r in roots:
        visit(r, 0)
    return order


def _parameter_space(order) -> set[int]:
    """ids of entities used as parameter-space curves (the B of a 142), with constituents."""
    out: set[int] = set()

    def mark(e):
        if id(e) in out:
            return
        out.add(id(e))
        if isinstance(e, CompositeCurve):
            for c in e.curves:
                mark(c)

    for e in order:
        if isinstance(e, CurveOnSurface) and e.parameter_curve is not None:
            mark(e.parameter_curve)
        for c in parameter_curves(e):  # B-rep loops (508)
            mark(c)
    return out


def _status(entity, referenced: set, param: set) -> str:
    """DE field 9 (IGES 5.3 §2.2.4.4.9): blank, subordinate, use, hierarchy, 2 digits each.

    Subordinate 01 (physically dependent) for every entity another one points to; use
    flag 05 (2-D parametric) for parameter-space curves, 02 (definition) for matrices,
    else 00 (geometry).
    """
    sub = 1 if id(entity) in referenced else 0
    if id(entity) in param:
        use = 5
    elif isinstance(entity, TransformationMatrix):
        use = 2
    else:
        use = 0
    return f"00{sub:02d}{use:02d}00"


# -- parameter data ------------------------------------------------------------------------------
def _pd(entity: Entity, de: dict, resolution: float) -> str:
    """The parameter string of one entity, delimited by ',' and ended by ';'."""
    t = entity.type_number
    if isinstance(entity, BSplineSurface128):
        P = entity.control_points
        nu, nv = P.shape[:2]
        flags = surface_flags(entity, resolution)
        (u0, u1), (v0, v1) = entity.parameter_range_u, entity.parameter_range_v
        parts = [
            "128", str(nu - 1), str(nv - 1), str(entity.degree_u), str(entity.degree_v),
            *map(str, flags),
            _reals(entity.knots_u), _reals(entity.knots_v),
            _reals(entity.weights.T),  # W(0,0), W(1,0), ...: the u index varies fastest
            _reals(P.transpose(1, 0, 2)),
            _reals([u0, u1, v0, v1]),
        ]
    elif isinstance(entity, BSplineCurve126):
        planar, closed, poly, periodic, normal = curve_flags(entity, resolution)
        n = entity.control_points.shape[0]
        parts = [
            "126", str(n - 1), str(entity.degree), str(planar), str(closed), str(poly), str(periodic),
            _reals(entity.knots), _reals(entity.weights), _reals(entity.control_points),
            _reals(entity.parameter_range), _reals(normal),
        ]
    elif isinstance(entity, Line):
        parts = ["110", _reals(entity.start), _reals(entity.end)]
    elif isinstance(entity, CircularArc):
        parts = ["100", format_real(entity.z), _reals(entity.center), _reals(entity.start), _reals(entity.end)]
    elif isinstance(entity, CompositeCurve):
        parts = ["102", str(len(entity.curves)), *(str(de[id(c)]) for c in entity.curves)]
    elif isinstance(entity, CurveOnSurface):
        parts = [
            "142", str(entity.creation), str(de[id(entity.surface)]),
            str(de[id(entity.parameter_curve)]) if entity.parameter_curve is not None else "0",
            str(de[id(entity.model_curve)]) if entity.model_curve is not None else "0",
            str(entity.preferred),
        ]
    elif isinstance(entity, TrimmedSurface):
        parts = [
            "144", str(de[id(entity.surface)]), "0" if entity.outer is None else "1", str(len(entity.inner)),
            "0" if entity.outer is None else str(de[id(entity.outer)]),
            *(str(de[id(c)]) for c in entity.inner),
        ]
    elif isinstance(entity, SurfaceOfRevolution):
        parts = ["120", str(de[id(entity.axis)]), str(de[id(entity.generatrix)]),
                 format_real(entity.start_angle), format_real(entity.end_angle)]
    elif isinstance(entity, BREP_TYPES):
        parts = [str(t), *parameter_tokens(entity, de, _reals)]
    elif isinstance(entity, TransformationMatrix):
        M = np.concatenate([entity.rotation, entity.translation[:, None]], axis=1)
        parts = ["124", _reals(M)]
    elif isinstance(entity, ParametricSpline):
        T = entity.breakpoints
        parts = ["112", str(entity.spline_type), str(entity.continuity), str(entity.ndim), str(T.size - 1),
                 _reals(T), _reals(entity.coefficients), _reals(entity.terminal)]
    elif isinstance(entity, ParametricSplineSurface):
        TU, TV, C = entity.breakpoints_u, entity.breakpoints_v, entity.coefficients
        M, N = TU.size - 1, TV.size - 1
        zeros48 = ",".join(["0.0"] * 48)
        parts = ["114", str(entity.spline_type), str(entity.patch_type), str(M), str(N), _reals(TU), _reals(TV)]
        for i in range(M):
            parts.extend(_reals(C[i, j]) for j in range(N))
            parts.append(zeros48)  # the arbitrary patch (i, N+1)
        parts.extend([zeros48] * (N + 1))  # the arbitrary row M+1
    else:
        raise IgesError(f"{entity.describe()}: cannot be written")
    assert parts[0] == str(t)
    return ",".join(parts) + ";"


# -- parameter lines of large entities, laid out by array arithmetic ---------------------------
#: A P line: 64 data columns, a blank, the 7-digit DE pointer, "P", the 7-digit sequence
#: number, and the newline that joins the lines.
_LINE = 81
_SPACE, _NEWLINE, _LETTER_P = 32, 10, ord("P")


def _digit_offsets() -> np.ndarray:
    """Where the digits of a bulk real go, relative to the first character after its
    sign, by decimal exponent X = -4..16 and number of kept digits k = 1..17: row
    (X + 4) · 18 + k, column j (X >= 0: j + (j > X), the point after digit X; X < 0:
    1 - X + j, after "0." and -X - 1 zeros). Dropped digits hold -1."""
    J = np.arange(17)
    table = np.full((21 * 18, 17), -1, dtype=np.int64)
    for X in range(-4, 17):
        off = J + (J > X) if X >= 0 else 1 - X + J
        for k in range(1, 18):
            table[(X + 4) * 18 + k, :k] = off[:k]
    return table


_DIGIT_OFFSETS = _digit_offsets()


def _windows(buffer: np.ndarray, width: int) -> np.ndarray:
    """Every run of ``width`` bytes of ``buffer`` as a row (overlapping rows of a strided
    view): ``_windows(b, w)[starts] = rows`` writes each row at its start in one call,
    deterministic as long as the runs written by one call do not overlap."""
    return np.lib.stride_tricks.as_strided(buffer, shape=(buffer.size - width + 1, width), strides=(1, 1))


#: "P" and the sequence number's last 3 + 4 digits: the characters of columns 73-80.
_P_WORD = np.uint32(ord("P"))


def _bulk_parts(entity: Entity, resolution: float):
    """(head, reals, tail) of a 128 or 126 whose control net is written in bulk: the
    parameter string is ``head + _reals(reals) + "," + tail`` (head ends with its
    delimiter, tail with ";"); None for other entities and for nets :func:`_reals` writes
    otherwise (small, or all one value)."""
    if isinstance(entity, BSplineSurface128):
        P = entity.control_points
        nu, nv = P.shape[:2]
        flags = surface_flags(entity, resolution)
        (u0, u1), (v0, v1) = entity.parameter_range_u, entity.parameter_range_v
        head = ["128", str(nu - 1), str(nv - 1), str(entity.degree_u), str(entity.degree_v), *map(str, flags),
                _reals(entity.knots_u), _reals(entity.knots_v), _reals(entity.weights.T)]
        reals = P.transpose(1, 0, 2)
        tail = _reals([u0, u1, v0, v1]) + ";"
    elif isinstance(entity, BSplineCurve126):
        planar, closed, poly, periodic, normal = curve_flags(entity, resolution)
        n = entity.control_points.shape[0]
        head = ["126", str(n - 1), str(entity.degree), str(planar), str(closed), str(poly), str(periodic),
                _reals(entity.knots), _reals(entity.weights)]
        reals = entity.control_points
        tail = _reals(entity.parameter_range) + "," + _reals(normal) + ";"
    else:
        return None
    a = np.asarray(reals, dtype=np.float64).ravel()
    if a.size <= SHORTEST_REPR_SIZE or np.all(a == a[0]):
        return None
    return ",".join(head) + ",", a, tail


def _token_lengths(text: bytes) -> np.ndarray:
    """Lengths of the tokens of ``text`` (each ends with its delimiter ',' or ';')."""
    b = np.frombuffer(text, dtype=np.uint8)
    ends = np.flatnonzero((b == _COMMA) | (b == 59))
    return np.diff(ends, prepend=-1)


def _place_text(out: np.ndarray, text: bytes, lengths: np.ndarray, pos: np.ndarray) -> None:
    """Write the tokens of ``text`` (their lengths) at the buffer positions ``pos``."""
    if not lengths.size:
        return
    starts = np.cumsum(lengths) - lengths
    token = np.repeat(np.arange(lengths.size), lengths)
    out[pos[token] + (np.arange(len(text)) - starts[token])] = np.frombuffer(text, dtype=np.uint8)


def _orbit(step: np.ndarray, n: int) -> np.ndarray:
    """0, f(0), f(f(0)), ... up to and including n, for f = ``step`` on 0..n-1 (f(i) > i,
    increasing) and f(n) = n: the line starts of greedy filling. By repeated squaring
    (f, f², f⁴, ... until f^(2^K)(0) = n) and expansion from the coarsest level down,
    each level one array operation instead of one Python step per line."""
    levels = [np.append(step, n)]
    while levels[-1][0] != n:
        f = levels[-1]
        levels.append(f[f])
    A = np.zeros(1, dtype=np.int64)
    for f in reversed(levels[:-1]):  # A = f^0 .. f^(2^k - 1) of 0, doubled each level
        B = np.empty(2 * A.size, dtype=np.int64)
        B[0::2] = A
        B[1::2] = f[A]
        A = B
    A = np.append(A, n)
    return A[: int(np.searchsorted(A, n)) + 1]


def _bulk_lines(head: str, a: np.ndarray, tail: str, seq: int, pseq: int) -> tuple[bytes, int]:
    """The P lines of ``head + _reals(a) + "," + tail`` (``a`` with more than
    SHORTEST_REPR_SIZE values, not all equal), byte for byte what ``_pack`` and the line
    format give, built by array arithmetic instead of per-token and per-line strings.

    Every token's length is known before its text: a bulk real (:func:`_bulk_reals`)
    takes sign + kept digits + point + comma, and for X < 0 the "0" and -X - 1 zeros
    before the digits. Greedy line filling (the longest run of whole tokens of at most 64
    columns) then gives each token's line and column, hence its place in the (lines, 81)
    byte block, and every character is written straight to its place: digits, points,
    signs and commas of all bulk reals in a few array assignments (the dropped trailing
    zeros go to a scratch byte past the block), the other tokens from their text."""
    head_b, tail_b = head.encode("ascii"), tail.encode("ascii")
    m = np.abs(a)
    bulk = _is_bulk(a, m)
    ib = np.flatnonzero(bulk)
    t, words, trailing = _digit_words(m[ib])
    e = 16 - t  # the decimal exponent X, -4 <= X <= 16
    neg = (a[ib] < 0).astype(np.int64)
    kept = 17 - trailing
    lengths = np.empty(a.size, dtype=np.int64)
    lengths[ib] = neg + kept + 2 + np.maximum(0, -e)
    special = None if ib.size == a.size else np.flatnonzero(~bulk)
    if special is not None:
        special_b = "".join([format_real(x) + "," for x in a[special].tolist()]).encode("ascii")
        lengths[special] = _token_lengths(special_b)
    head_len, tail_len = _token_lengths(head_b), _token_lengths(tail_b)
    lengths = np.concatenate([head_len, lengths, tail_len])
    cum = np.concatenate([[0], np.cumsum(lengths)])
    # greedy filling: from token i, a line takes the tokens up to the last end within 64 columns
    reach = np.searchsorted(cum, cum[:-1] + PD_COLUMNS, side="right") - 1
    if np.any(reach <= np.arange(lengths.size)):
        raise IgesError(f"a parameter is longer than {PD_COLUMNS} columns")
    starts = _orbit(reach, lengths.size)
    L = starts.size - 1
    per_line = np.diff(starts)
    pos = np.repeat(np.arange(L) * _LINE - cum[starts[:-1]], per_line) + cum[:-1]
    scratch = L * _LINE
    out = np.empty(2 * scratch + 64, dtype=np.uint8)
    out[:scratch] = _SPACE
    h = head_len.size
    _place_text(out, head_b, head_len, pos[:h])
    _place_text(out, tail_b, tail_len, pos[h + a.size:])
    pos_a = pos[h : h + a.size]
    if special is not None:
        _place_text(out, special_b, lengths[h + special], pos_a[special])
    p = pos_a[ib] + neg  # where the digits (or the "0." before them) start
    out[p[neg == 1] - 1] = _MINUS
    out[pos_a[ib] + lengths[h + ib] - 1] = _COMMA
    digits = words.view(np.uint8)[:, 3:]  # (n, 17)
    # all 17 digits kept (the usual case): the digits are one run of 17 bytes (X < 0), or
    # two runs round the point (X >= 0: all 17 one place on, then the integer part over
    # them, then the point); the runs of one call never overlap (each token is longer)
    full = kept == 17
    whole = np.flatnonzero(full & (e < 0))
    _windows(out, 17)[p[whole] + 1 - e[whole]] = digits[whole]
    split_ = np.flatnonzero(full & (e >= 0))
    _windows(out, 17)[p[split_] + 1] = digits[split_]
    for x in np.unique(e[split_]).tolist():
        g = split_[e[split_] == x]
        _windows(out, x + 1)[p[g]] = digits[g, : x + 1]
    # trailing zeros dropped: digit by digit, the dropped ones sent to a scratch area as
    # long as the block, past its end, which is never read
    rest = np.flatnonzero(~full)
    if rest.size:
        table = np.where(_DIGIT_OFFSETS < 0, scratch + 1 + 32, _DIGIT_OFFSETS)
        out[p[rest, None] + np.take(table, (e[rest] + 4) * 18 + kept[rest], axis=0)] = digits[rest]
    positional = np.flatnonzero(e >= 0)
    out[p[positional] + e[positional] + 1] = _DOT
    for x in (-1, -2, -3, -4):  # "0." and -X - 1 zeros before the digits
        g = np.flatnonzero(e == x)
        if g.size:
            _windows(out, 1 - x)[p[g]] = np.frombuffer(b"0." + b"0" * (-x - 1), dtype=np.uint8)
    block = out[:scratch].reshape(L, _LINE)
    block[:, PD_COLUMNS + 1 : PD_COLUMNS + 8] = np.frombuffer(b"%7d" % seq, dtype=np.uint8)
    high, low = np.divmod(np.arange(pseq, pseq + L), 10**4)  # the sequence number < 10**7
    tail_words = np.empty((L, 2), dtype="<u4")
    tail_words[:, 0] = (np.take(_FOUR_DIGITS, high) & np.uint32(0xFFFFFF00)) | _P_WORD
    tail_words[:, 1] = np.take(_FOUR_DIGITS, low)
    block[:, PD_COLUMNS + 8 : PD_COLUMNS + 16] = tail_words.view(np.uint8)
    block[:, _LINE - 1] = _NEWLINE
    return out[: scratch - 1].tobytes(), L


#: Greedy line filling: the longest run of at most PD_COLUMNS characters ending in a delimiter.
_PD_LINE = re.compile(r".{0,%d}[,;]" % (PD_COLUMNS - 1), re.DOTALL)


def _pack(s: str, width: int = PD_COLUMNS) -> list[str]:
    """Split a parameter string at delimiters into chunks of at most ``width`` columns.

    Only for strings without Hollerith constants (numbers never contain ',' or ';').
    """
    if width == PD_COLUMNS:
        out = _PD_LINE.findall(s)
        if sum(map(len, out)) == len(s):
            return out
    out = []
    pos, n = 0, len(s)
    while n - pos > width:
        cut = s.rfind(",", pos, pos + width)
        if cut < 0:
            raise IgesError(f"a parameter is longer than {width} columns: {s[pos:pos + 40]}...")
        out.append(s[pos : cut + 1])
        pos = cut + 1
    out.append(s[pos:])
    return out


def _pack_tokens(tokens: list[str], width: int) -> list[str]:
    """Pack delimited tokens into lines; Hollerith strings longer than a line are split."""
    lines, cur = [], ""
    for tok in tokens:
        if len(cur) + len(tok) <= width:
            cur += tok
            continue
        if len(tok) > width:  # only strings get this long: continue them on the next lines
            room = width - len(cur)
            cur += tok[:room]
            tok = tok[room:]
            lines.append(cur)
            while len(tok) > width:
                lines.append(tok[:width])
                tok = tok[width:]
            cur = tok
        else:
            lines.append(cur)
            cur = tok
    if cur:
        lines.append(cur)
    return lines


# -- header -----------------------------------------------------------------------------------
def _timestamp(when: _dt.datetime | None) -> str:
    when = when or _dt.datetime.now(_dt.timezone.utc)
    return when.strftime("%Y%m%d.%H%M%S")


def _extent(order, param: set) -> float:
    """Approximate maximum coordinate (Global field 20) over model-space entities."""
    m = 0.0
    for e in order:
        if id(e) in param:
            continue
        if isinstance(e, (BSplineCurve126, BSplineSurface128)):
            P = e.control_points
        elif isinstance(e, Line):
            P = np.stack([e.start, e.end])
        elif isinstance(e, CircularArc):
            r = e.radius
            P = np.array([[abs(e.center[0]) + r, abs(e.center[1]) + r, e.z]])
        elif isinstance(e, ParametricSpline):
            P = e.coefficients[..., 0]
        elif isinstance(e, ParametricSplineSurface):
            P = e.coefficients[..., 0]
        else:
            continue
        if e.transform is not None:
            from .convert import _transform
            P = _transform(e, P.reshape(-1, 3))
        if P.size:
            m = max(m, float(np.max(np.abs(P))))
    return m


def _check_text(text: str, what: str):
    if not all(32 <= ord(ch) < 127 for ch in text):
        raise IgesError(f"{what} must be printable ASCII, got {text!r:.80}")


def _check_header(h: GlobalSection):
    for name, kind in GLOBAL_FIELDS:
        value = getattr(h, name)
        if kind == "s":
            if not isinstance(value, str):
                raise IgesError(f"Global section {name}: expected a string, got {value!r:.60}")
            _check_text(value, f"Global section {name}")
        elif kind == "i":
            if isinstance(value, bool) or not isinstance(value, int):
                raise IgesError(f"Global section {name}: expected an integer, got {value!r:.60}")
        else:
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise IgesError(f"Global section {name}: expected a finite real, got {value!r:.60}")
    if (h.parameter_delimiter, h.record_delimiter) != (",", ";"):
        raise IgesError("the writer uses the default delimiters ',' and ';' only")
    if not h.resolution > 0:
        raise IgesError(f"the resolution (Global field 19) must be > 0, got {h.resolution!r}")
    if not h.model_scale > 0:
        raise IgesError(f"the model-space scale (Global field 13) must be > 0, got {h.model_scale!r}")
    if h.unit_flag not in UNIT_NAMES and h.unit_flag != 3:
        raise IgesError(f"unknown unit flag (Global field 14): {h.unit_flag}")
    if h.unit_flag != 3 and h.unit_name != UNIT_NAMES[h.unit_flag]:
        raise IgesError(f"unit name {h.unit_name!r} does not match unit flag {h.unit_flag} "
                        f"({UNIT_NAMES[h.unit_flag]!r})")
    for name in ("created", "modified"):
        v = getattr(h, name)
        if v and not re.fullmatch(r"\d{8}\.\d{6}", v):
            raise IgesError(f"Global section {name}: expected YYYYMMDD.HHNNSS, got {v!r}")


def make_header(*, units: str = "m", resolution: float = DEFAULT_RESOLUTION, file_name: str = "",
                author: str = "", organization: str = "", product_id: str = "",
                timestamp: _dt.datetime | None = None, max_coordinate: float = 0.0,
                model_scale: float = 1.0) -> GlobalSection:
    """A Global section for a new file; ``units`` is a key of :data:`UNITS`."""
    try:
        flag, name = UNITS[units.lower()]
    except (KeyError, AttributeError):
        raise IgesError(f"unknown units {units!r}; expected one of {sorted(UNITS)}") from None
    stamp = _timestamp(timestamp)
    product = product_id or os.path.splitext(os.path.basename(file_name))[0] or "bladesmith"
    return GlobalSection(
        product_id=product, file_name=file_name, receiver_product_id=product,
        model_scale=float(model_scale), unit_flag=flag, unit_name=name,
        max_line_weight=float(resolution), created=stamp, resolution=float(resolution),
        max_coordinate=float(max_coordinate), author=author, organization=organization, modified=stamp,
    )


def _global_lines(h: GlobalSection) -> list[str]:
    tokens = []
    for name, kind in GLOBAL_FIELDS:
        v = getattr(h, name)
        if kind == "s":
            tokens.append(hollerith(v))
        elif kind == "i":
            tokens.append(str(v))
        else:
            tokens.append(format_real(v))
    tokens = [t + "," for t in tokens[:-1]] + [tokens[-1] + ";"]
    return _pack_tokens(tokens, DATA_COLUMNS)


# -- the file -----------------------------------------------------------------------------------
def to_string(entities, **options) -> str:
    """The IGES file for ``entities`` (records, or an :class:`IgesModel` read before) as text.

    Options: units, resolution, header, start, file_name, author, organization, timestamp
    (:func:`to_bytes`).
    """
    return to_bytes(entities, **options).decode("ascii")


def to_bytes(entities, *, units: str = "m", resolution: float | None = None, header: GlobalSection | None = None,
             start: str | None = None, file_name: str = "", author: str = "", organization: str = "",
             timestamp: _dt.datetime | None = None) -> bytes:
    """The IGES file for ``entities`` (records, or an :class:`IgesModel` read before) as
    ASCII bytes (what :func:`write_iges` writes; :func:`to_string` decodes them).

    Entities that the given ones reference are written too. ``header`` (a
    :class:`GlobalSection`) overrides units/resolution/author/...; a model read from a file
    carries its own header and start text, so write -> read -> write is byte-identical.
    Raises :class:`IgesError` for inconsistent data, before anything is produced.
    """
    from .reader import IgesModel

    if isinstance(entities, IgesModel):
        header = header or entities.header
        start = entities.start if start is None else start
        entities = entities.entities
    elif isinstance(entities, Entity):
        entities = [entities]
    try:
        roots = list(entities)
    except TypeError:
        raise IgesError(f"expected a sequence of IGES records, got {type(entities).__name__}") from None
    order = collect(roots)
    param = _parameter_space(order)
    if header is None:
        header = make_header(units=units, resolution=DEFAULT_RESOLUTION if resolution is None else resolution,
                             file_name=file_name, author=author, organization=organization,
                             timestamp=timestamp, max_coordinate=_extent(order, param))
    elif resolution is not None:
        raise IgesError("give the resolution either in the header or as resolution=, not both")
    _check_header(header)
    res = header.resolution

    # 1. validate everything (no output yet)
    try:
        for e in order:
            if isinstance(e, GenericEntity):
                raise IgesError(f"{e.describe()}: entities of unsupported types cannot be written")
            if not isinstance(e.label, str) or len(e.label) > 8:
                raise IgesError(f"{e.describe()}: labels have at most 8 characters")
            _check_text(e.label, f"{e.describe()}: label")
            if not -9_999_999 <= e.subscript <= 99_999_999:
                raise IgesError(f"{e.describe()}: subscript {e.subscript} does not fit 8 columns")
            if isinstance(e, BREP_TYPES):
                validate_brep(e)
            else:
                validate_entity(e, res)
        for e in order:
            if isinstance(e, TrimmedSurface):
                for loop in ((e.outer,) if e.outer is not None else ()) + e.inner:
                    validate_loop(loop, res)
    except BladesmithError as exc:
        if isinstance(exc, IgesError):
            raise
        raise IgesError(str(exc)) from None

    # 2. serialise
    referenced = {id(c) for e in order for c in _children(e)}
    de = {id(e): 2 * i + 1 for i, e in enumerate(order)}
    if 2 * len(order) > 9_999_999:
        raise IgesError("too many entities for 7-digit sequence numbers")
    start_lines = [ln for ln in (start if start is not None else START_TEXT).splitlines()] or [""]
    s_lines = []
    for ln in start_lines:
        _check_text(ln, "start section text")
        s_lines.extend(ln[i : i + DATA_COLUMNS] for i in range(0, max(len(ln), 1), DATA_COLUMNS))
    out = [f"{ln:<72}S{i:07d}" for i, ln in enumerate(s_lines, 1)]
    g_lines = _global_lines(header)
    out += [f"{ln:<72}G{i:07d}" for i, ln in enumerate(g_lines, 1)]
    d_out, p_out = [], []
    pseq = 1
    for e in order:
        seq = de[id(e)]
        parts = _bulk_parts(e, res)
        if parts is not None:  # a large net: laid out by array arithmetic
            text, n_lines = _bulk_lines(*parts, seq, pseq)
            p_out.append(text)
        else:
            chunks = _pack(_pd(e, de, res), PD_COLUMNS)
            n_lines = len(chunks)
            # one C-level format for all lines of the entity: "%-64s" data, back-pointer, sequence
            fmt = ("%%-64s %7dP%%07d" % seq,) * n_lines
            text = "\n".join(fmt) % tuple(chain.from_iterable(zip(chunks, range(pseq, pseq + n_lines))))
            p_out.append(text.encode("ascii"))
        t = e.type_number
        tr = de[id(e.transform)] if e.transform is not None else 0
        status = _status(e, referenced, param)
        d_out.append(f"{t:8d}{pseq:8d}{0:8d}{0:8d}{0:8d}{0:8d}{tr:8d}{0:8d}{status}D{seq:07d}")
        d_out.append(f"{t:8d}{0:8d}{0:8d}{n_lines:8d}{e.form:8d}{'':8}{'':8}{e.label:>8}"
                     f"{e.subscript:8d}D{seq + 1:07d}")
        pseq += n_lines
    if pseq - 1 > 9_999_999:
        raise IgesError("too many parameter lines for 7-digit sequence numbers")
    out += d_out
    term = f"S{len(s_lines):7d}G{len(g_lines):7d}D{len(d_out):7d}P{pseq - 1:7d}"
    return b"\n".join(["\n".join(out).encode("ascii"), *p_out, f"{term:<72}T{1:07d}\n".encode("ascii")])


def write_iges(path, entities, **options) -> str:
    """Write ``entities`` to ``path`` atomically; returns the path. Options as :func:`to_string`.

    The text is complete before the file system is touched; it then goes to a
    temporary file in the same folder, which replaces ``path`` in one ``os.replace``.
    """
    path = os.fspath(path)
    options.setdefault("file_name", os.path.basename(path))
    atomic_write(path, to_bytes(entities, **options))
    return path


def atomic_write(path: str, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (:func:`..geometry.files.atomic_write`),
    reporting failures as :class:`IgesError`."""
    try:
        _atomic_write(path, data)
    except OSError as exc:
        raise IgesError(f"cannot write the file: {exc}", path=path) from exc
