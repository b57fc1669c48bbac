"""IGES 5.3 reader, fixed 80-column ASCII form (IGES 5.3 §2.2).

Parses a file into the records of :mod:`.records` (references resolved into objects)
and, through :meth:`IgesModel.to_geometry`, into ``geometry.nurbs`` objects.

Robustness: every malformed input raises :class:`IgesError` with the 1-based line
number and a reason; nothing else escapes. The work is linear in the file size: each
count read from the file is checked against the number of parameters actually present
before anything is allocated, every pointer is range-checked, and reference chains are
followed with a depth limit and a cycle check, never with unbounded recursion.
"""
from __future__ import annotations

import math
import os
import re
import sys
import warnings
from dataclasses import dataclass

import numpy as np

from ..geometry.errors import BladesmithError, IgesError
from .records import (
    GLOBAL_FIELDS,
    BSplineCurve126,
    BSplineSurface128,
    CircularArc,
    CompositeCurve,
    CurveOnSurface,
    DirectoryInfo,
    Entity,
    GenericEntity,
    GlobalSection,
    Line,
    ParametricSpline,
    ParametricSplineSurface,
    SurfaceOfRevolution,
    TransformationMatrix,
    TrimmedSurface,
)
from .validate import MAX_DEGREE, check_structure

#: Reference chains (144 -> 142 -> 102 -> 126 ...) deeper than this are refused.
MAX_REFERENCE_DEPTH = 64
#: Largest file read (bytes); bigger inputs are refused rather than exhausting memory.
MAX_FILE_BYTES = 1 << 31
SECTIONS = "SGDPT"

_INT = re.compile(r"[+-]?[0-9]{1,12}")
_DIGITS = re.compile(r"[0-9]{1,12}")
_REAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[EeDd][+-]?[0-9]{1,4})?")
#: The characters an IGES real is written with (and the parameter delimiter between them).
_REAL_CHARS = b"0123456789+-.EeDd, "
#: The same without the Fortran exponent letters: text that numpy reads as it is.
_PLAIN_CHARS = b"0123456789+-.Ee, "
_HOLLERITH = re.compile(r" *([0-9]{1,9})H")


class _Str(str):
    """A Hollerith string parameter (as opposed to a number or a default)."""


class _StrTokens(list):
    """Parameters of a record in which at least one Hollerith string was read."""


#: Parameters of a string-free record split eagerly at each end (integers, pointers and
#: single reals are read there); the middle, usually a long run of reals, is parsed in bulk.
_ENDS = 16
#: Runs of reals at least this long are parsed with one numpy call (:meth:`_Params.reals`).
_BULK_MIN = 16


#: numpy's 80-bit x87 extended type (16 bytes, 64-bit significand in the first 8, little
#: endian), or None where ``np.longdouble`` is something else (double, quad, double-double)
_EXTENDED = (np.longdouble if np.finfo(np.longdouble).nmant == 63 and np.dtype(np.longdouble).itemsize == 16
             and sys.byteorder == "little" else None)


def _fromstring(text: str, dtype) -> np.ndarray | None:
    """numpy's parse of comma-separated numbers, or None when it stops short."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # numpy: "could not be read to its end"
            return np.fromstring(text, dtype=dtype, sep=",")
    except (ValueError, DeprecationWarning):
        return None


class _Tokens:
    """The parameters of a record without strings, split lazily (IGES 5.3 §2.2.3).

    Behaves as the list ``body.split(pd)`` (length, indexing, slicing, iteration) but splits
    only the first and last :data:`_ENDS` parameters up front; the whole list is built only
    when something asks for a parameter in the middle. :meth:`reals_from` parses every
    parameter from an index to the end with one numpy call, so a B-spline's thousands of
    knots, weights and coordinates never become Python strings."""

    __slots__ = ("body", "pd", "plain", "n", "head", "tail", "offsets", "_all")

    def __init__(self, body: str, pd: str, plain: bool = False):
        # plain: the body is known to hold only the characters of _PLAIN_CHARS
        self.body, self.pd, self.plain, self._all = body, pd, plain, None
        head = body.split(pd, _ENDS)
        if len(head) <= _ENDS:  # short record: everything is split already
            self.n, self.head, self.tail = len(head), head, []
            self._all = head
        else:
            self.n = body.count(pd) + 1
            self.head = head[:_ENDS]
            self.tail = body.rsplit(pd, _ENDS)[1:] if self.n > 2 * _ENDS else self.all()[_ENDS:]
        # character offset of parameter k (k <= _ENDS) in ``body``, for the bulk parse
        offsets = [0]
        for t in self.head[:_ENDS]:
            offsets.append(offsets[-1] + len(t) + 1)
        self.offsets = offsets

    def all(self) -> list:
        if self._all is None:
            self._all = self.body.split(self.pd)
            self._all[0] = self.head[0]
        return self._all

    def __len__(self):
        return self.n

    def __bool__(self):
        return self.n > 0

    def __getitem__(self, k):
        if isinstance(k, slice):
            return self.all()[k]
        if k < 0:
            k += self.n
        if 0 <= k < len(self.head):
            return self.head[k]
        if self.n - len(self.tail) <= k < self.n:
            return self.tail[k - self.n + len(self.tail)]
        return self.all()[k]

    def __setitem__(self, k, value):
        if k != 0:
            raise IndexError("only the entity type parameter is replaced")
        self.head[0] = value
        if self._all is not None:
            self._all[0] = value

    def __iter__(self):
        return iter(self.all())

    def reals_from(self, i: int) -> np.ndarray | None:
        """Parameters i..n-1 as float64 when every one of them is a finite real written with
        the characters of IGES reals only, else None (the caller then reads them one by one
        and names the bad one). The values are those of ``float`` on each parameter: numpy's
        text parser rounds correctly (in double, or in extended precision with the double
        rounding checked), and what it would take that ``float`` refuses (a blank
        parameter, ``nan``, any other character) is ruled out."""
        if self.pd != "," or i >= len(self.offsets):
            return None
        text = self.body[self.offsets[i]:]
        if not self.plain:  # (plain: checked for the whole section at once, parse_iges)
            if text.encode("latin-1", "replace").translate(None, _REAL_CHARS):
                return None
            if "D" in text or "d" in text:
                text = text.replace("D", "E").replace("d", "e")
        if _EXTENDED is None:
            a = _fromstring(text, np.float64)
        else:
            a = _fromstring(text, _EXTENDED)
            if a is not None:
                # read in x87 extended precision (the C library's strtold, faster than
                # Python's strtod) and rounded to double: exact unless the extended value
                # lies at (or within one unit of) a midpoint between two doubles, where
                # rounding twice can differ from rounding once; such records, and
                # subnormals, are read again straight to double
                mant = a.view(np.uint64)[0::2]  # the 64-bit significand of each value
                with np.errstate(over="ignore"):  # beyond double: inf, refused below
                    x = a.astype(np.float64)
                near_mid = ((mant - np.uint64(0x3FF)) & np.uint64(0x7FF)) <= np.uint64(2)
                # below the least normal double (including what rounded to zero) unless 0
                small = np.abs(x) < np.finfo(np.float64).tiny
                tiny = np.any(small) and np.any(a[small] != 0)
                a = _fromstring(text, np.float64) if tiny or np.any(near_mid) else x
        if a is None:
            return None
        # an empty parameter stops numpy short (fewer values); a blank one is a default (0.0
        # in reals), which numpy's extended parse reads as 0.0 but its double parse as
        # -1.0, so a -1.0 has its parameters looked at
        if a.size != self.n - i or not np.all(np.isfinite(a)):
            return None
        if np.any(a == -1.0):
            compact = text.replace(" ", "")
            if not compact or ",," in compact or compact[0] == "," or compact[-1] == ",":
                return None
        return a


# -- the model -----------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class IgesModel:
    """A parsed file: records in Directory Entry order, the Global section, the Start text."""

    entities: tuple
    header: GlobalSection
    start: str = ""
    path: str | None = None
    #: lenient reading only: entities skipped, with reasons (:class:`SkippedEntity`)
    skipped: tuple = ()
    #: lenient reading only: what was tolerated (blank lines, wrong counts ...)
    notes: tuple = ()
    #: Global fields that were defaulted (empty) in the file
    defaulted: frozenset = frozenset()
    #: ids of entities that are not independent although nothing read refers to them
    dependent: frozenset = frozenset()

    @property
    def roots(self) -> tuple:
        """Entities no other entity references (the independent ones)."""
        referenced = set(self.dependent)
        for e in self.entities:
            for c in e.references():
                referenced.add(id(c))
            if e.transform is not None:
                referenced.add(id(e.transform))
        return tuple(e for e in self.entities if id(e) not in referenced)

    def of_type(self, cls) -> list:
        return [e for e in self.entities if isinstance(e, cls)]

    def to_geometry(self) -> list:
        """(record, geometry) for every independent curve or surface entity; see
        :func:`bladesmith.iges.convert.to_geometry`."""
        from .convert import to_geometry

        out = []
        for e in self.roots:
            if isinstance(e, (GenericEntity, TransformationMatrix)):
                continue
            try:
                out.append((e, to_geometry(e)))
            except IgesError as exc:
                line = e.directory.line if e.directory is not None else None
                raise IgesError(str(exc), path=self.path, line=line) from None
        return out


# -- lines and sections -------------------------------------------------------------------------
class _Source:
    def __init__(self, path):
        self.path = None if path is None else os.fspath(path)

    def error(self, message: str, line: int | None):
        raise IgesError(message, path=self.path, line=line)


def _split_lines(data, lenient: bool = False, notes: list | None = None) -> list[str]:
    if isinstance(data, (bytes, bytearray)):
        text = bytes(data).decode("latin-1")
    else:
        text = data
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    if not lenient:
        return lines
    # What CAD systems really write: no newlines at all (80-column records run together),
    # trailing blanks stripped, blank lines (often after the T section), padding past 80.
    if len(lines) == 1 and len(lines[0]) > 80:
        flat = lines[0]
        lines = [flat[k : k + 80] for k in range(0, len(flat), 80)]
        notes.append("the file has no line breaks; read as 80-column records")
    out, blank = [], 0
    for line in lines:
        if not line.strip():
            blank += 1
            continue
        if len(line) > 80 and not line[80:].strip():
            line = line[:80]
        elif 73 <= len(line) < 80:
            line = line.ljust(80)
        out.append(line)
    if blank:
        notes.append(f"{blank} blank line(s) ignored")
    return out


def _sections(lines: list[str], src: _Source, lenient: bool = False, notes: list | None = None) -> dict:
    """Lines per section as (line number, text), checking columns, order and sequence numbers.

    ``lenient``: sequence numbers, the Terminate counts and lines after T are only noted in
    ``notes``; what makes the sections unreadable (columns, section letters, order) is
    still refused."""
    fast = _sections_fast(lines)
    if fast is not None:
        return fast
    sec = {k: [] for k in SECTIONS}
    current = 0
    renumbered = 0
    for n, line in enumerate(lines, 1):
        if len(line) != 80:
            if len(line) >= 73 and line[72] in "CB" and n == 1:
                src.error("compressed and binary IGES forms are not supported; expected the fixed "
                          "80-column ASCII form", n)
            src.error(f"expected 80 columns, got {len(line)}", n)
        code = line[72]
        k = SECTIONS.find(code)
        if k < 0:
            src.error(f"column 73 must be one of S, G, D, P, T; got {code!r}", n)
        if k < current:
            if lenient and current == 4:
                notes.append(f"line {n}: text after the Terminate section ignored")
                break
            src.error(f"section {code} after section {SECTIONS[current]}", n)
        current = k
        seq_text = line[73:80].strip()
        if not _DIGITS.fullmatch(seq_text) or int(seq_text) != len(sec[code]) + 1:
            if not lenient:
                src.error(f"sequence number {line[73:80]!r} in columns 74-80; expected {len(sec[code]) + 1}", n)
            renumbered += 1  # pointers count lines by position, so the position rules
        sec[code].append((n, line))
    if not lines:
        src.error("the file is empty", None)
    if not sec["G"]:
        src.error("the Global section is missing", len(lines))
    if renumbered:
        notes.append(f"{renumbered} wrong sequence number(s) ignored (lines are counted by position)")
    if lenient and len(sec["T"]) != 1:
        notes.append("missing or repeated Terminate section (file truncated?)")
    else:
        if len(sec["T"]) != 1:
            src.error("missing or repeated Terminate section (file truncated?)", len(lines))
        tn, tline = sec["T"][0]
        if tn != len(lines) and not lenient:
            src.error("lines after the Terminate section", tn + 1)
        for i, code in enumerate("SGDP"):
            field = tline[8 * i : 8 * i + 8]
            count = field[1:].strip()
            if field[0] != code or not _DIGITS.fullmatch(count) or int(count) != len(sec[code]):
                if lenient:
                    notes.append(f"Terminate section: {field!r} does not count {len(sec[code])} {code} lines")
                    continue
                src.error(f"Terminate section: expected {code}{len(sec[code]):7d} in columns "
                          f"{8 * i + 1}-{8 * i + 8}, got {field!r}", tn)
    if len(sec["D"]) % 2:
        if not lenient:
            src.error("the Directory Entry section has an odd number of lines", sec["D"][-1][0])
        notes.append(f"line {sec['D'][-1][0]}: unpaired last Directory Entry line ignored")
        sec["D"].pop()
    return sec


class _Rows:
    """Lines lo..hi-1 of a fixed 80-column file held as a (n, 80) uint8 array, as the
    (line number, text) pairs :func:`_sections` gives, decoded only when asked for."""

    def __init__(self, a: np.ndarray, lo: int, hi: int):
        self.a, self.lo, self.hi = a, lo, hi

    def __len__(self):
        return self.hi - self.lo

    def __getitem__(self, k):
        if isinstance(k, slice):
            return [self[j] for j in range(*k.indices(len(self)))]
        if k < 0:
            k += len(self)
        if not 0 <= k < len(self):
            raise IndexError(k)
        return self.lo + k + 1, self.a[self.lo + k].tobytes().decode("latin-1")

    def __iter__(self):
        return (self[k] for k in range(len(self)))

    def columns(self, c0: int, c1: int) -> np.ndarray:
        # contiguous first: tobytes() of a strided view is many times slower than a copy
        return np.ascontiguousarray(self.a[self.lo : self.hi, c0:c1])


def _fixed_array(data) -> np.ndarray | None:
    """The (n, 80) uint8 array of a file of n lines of exactly 80 columns, each ended by
    one line feed or CR LF (the last one optionally), or None."""
    if isinstance(data, str):
        try:
            data = data.encode("latin-1")
        except UnicodeEncodeError:
            return None
    b = bytes(data)
    for eol in (b"\n", b"\r\n"):
        w = 80 + len(eol)
        if len(b) % w == 80:
            b = b + eol
        if len(b) < w or len(b) % w:
            continue
        a = np.frombuffer(b, dtype=np.uint8).reshape(-1, w)
        # every line ends with ``eol`` and no other CR or LF is in the file
        if (np.all(a[:, 80:] == np.frombuffer(eol, dtype=np.uint8))
                and b.count(b"\n") == len(a)
                and (b"\r" not in b if eol == b"\n" else b.count(b"\r") == len(a))):
            return a[:, :80]
    return None


def _sections_fast(lines):
    """:func:`_sections` for a well-formed file, vectorised (numpy over the 80-column
    records); None whenever anything is unusual, and the line-by-line check then says what.
    ``lines``: a list of lines, or the (n, 80) uint8 array of :func:`_fixed_array` (then
    the Parameter Data section is a lazy :class:`_Rows`)."""
    if isinstance(lines, np.ndarray):
        a = lines
        n = len(a)
        if n < 2:
            return None
    else:
        n = len(lines)
        if n < 2 or set(map(len, lines)) != {80}:
            return None
        try:
            flat = "".join(lines).encode("latin-1")
        except UnicodeEncodeError:
            return None
        a = np.frombuffer(flat, dtype=np.uint8).reshape(n, 80)
    order = np.full(256, -1, dtype=np.int64)
    for k, c in enumerate(SECTIONS):
        order[ord(c)] = k
    code = order[a[:, 72]]
    if np.any(code < 0) or np.any(np.diff(code) < 0):
        return None
    value = _column_integers(a[:, 73:80])
    if value is None:
        return None
    starts = np.searchsorted(code, np.arange(len(SECTIONS)))
    expected = np.arange(n) - starts[code] + 1
    if not np.array_equal(value, expected):
        return None
    counts = np.bincount(code, minlength=len(SECTIONS))
    if counts[4] != 1 or counts[1] == 0 or counts[2] % 2:
        return None
    tline = a[-1].tobytes().decode("latin-1")
    for i, c in enumerate("SGDP"):
        field = tline[8 * i : 8 * i + 8]
        cnt = field[1:].strip()
        if field[0] != c or not _DIGITS.fullmatch(cnt) or int(cnt) != counts[i]:
            return None
    sec = {}
    for k, c in enumerate(SECTIONS):
        lo, hi = int(starts[k]), int(starts[k]) + int(counts[k])
        rows = _Rows(a, lo, hi)
        sec[c] = rows if c == "P" else list(rows)
    return sec


def _column_integers(f: np.ndarray) -> np.ndarray | None:
    """Right-justified unsigned integers in columns of a uint8 array (one per row, leading
    blanks, at least the last column a digit); None when any row is not such a number.

    Column by column (a handful of passes over the rows, no (rows, columns) temporaries
    beyond the digit mask): this runs on every sequence number and back pointer of a file."""
    d = f - np.uint8(48)  # digits 0..9; a blank wraps to 240
    digit = d <= 9
    if not np.all(digit | (f == 32)) or not np.all(digit[:, -1]):
        return None
    # blanks may only lead: no digit is followed by a blank
    if np.any(digit[:, :-1] > digit[:, 1:]):
        return None
    d[~digit] = 0
    value = d[:, 0].astype(np.int64)
    for k in range(1, f.shape[1]):
        value *= 10
        value += d[:, k]
    return value


# -- parameters ----------------------------------------------------------------------------------
def _tokenize(data: str, pd: str, rd: str, src: _Source, line_of, strip: bool = True,
              plain: bool = False) -> list:
    """Parameters of one record up to its record delimiter (IGES 5.3 §2.2.3).

    ``strip=False``: a record without strings comes back as a lazily split
    :class:`_Tokens` whose tokens may keep blanks around them (:class:`_Params` strips what
    it reads one by one, and reads runs of reals in bulk without splitting them)."""
    if "H" not in data:
        end = data.find(rd)
        if end < 0:
            src.error("missing record delimiter", line_of(len(data) - 1))
        body = data[:end]
        if not strip:
            return _Tokens(body, pd, plain)
        if " " not in body:
            return body.split(pd)
        return [t.strip() for t in body.split(pd)]
    out = _StrTokens()
    pos, n = 0, len(data)
    # the next record delimiter is searched once and again only after a string ran past it,
    # so the scan stays linear in the record length whatever the strings contain
    b = data.find(rd)
    while True:
        m = _HOLLERITH.match(data, pos)
        if m:
            count = int(m.group(1))
            start = m.end()
            if count > n - start:
                src.error("Hollerith string runs past the end of its record", line_of(pos))
            out.append(_Str(data[start : start + count]))
            pos = start + count
            while pos < n and data[pos] == " ":
                pos += 1
            if pos >= n:
                src.error("missing record delimiter", line_of(n - 1))
            c = data[pos]
            if c == pd:
                pos += 1
                continue
            if c == rd:
                return out
            src.error(f"expected a delimiter after a string, got {c!r}", line_of(pos))
        if 0 <= b < pos:
            b = data.find(rd, pos)
        a = data.find(pd, pos, b if b >= 0 else n)
        if b < 0:
            src.error("missing record delimiter", line_of(n - 1))
        if 0 <= a < b:
            out.append(data[pos:a].strip())
            pos = a + 1
        else:
            out.append(data[pos:b].strip())
            return out


def _parse_int(tok, default=None):
    if tok == "" and default is not None:
        return default
    if isinstance(tok, _Str) or not _INT.fullmatch(tok):
        return None
    return int(tok)


def _parse_real(tok, default=None):
    if tok == "" and default is not None:
        return default
    if isinstance(tok, _Str) or not _REAL.fullmatch(tok):
        return None
    x = float(tok.replace("D", "E").replace("d", "e"))
    return x if math.isfinite(x) else None


class _Params:
    """A cursor over one entity's parameters with checked reads."""

    def __init__(self, tokens, src: _Source, where: str, line: int, line_of_index, n_entities: int):
        self.t = tokens
        self.i = 1  # tokens[0] is the entity type
        self.src, self.where, self.line = src, where, line
        self.line_of_index = line_of_index
        self.n_entities = n_entities
        self.has_strings = type(tokens) is _StrTokens
        #: (index, values of every parameter from that index on) once ``tokens.reals_from``
        #: parsed them, False when it could not, None before it was asked
        self.bulk = None

    def error(self, message: str, index: int | None = None):
        index = self.i if index is None else index
        self.src.error(f"{self.where}, parameter {index + 1}: {message}", self.line_of_index(index))

    @property
    def remaining(self) -> int:
        return len(self.t) - self.i

    def _next(self, what: str, optional: bool):
        if self.i >= len(self.t):
            if optional:
                self.i += 1
                return ""
            self.error(f"{what} is missing (record ends early)")
        tok = self.t[self.i]
        self.i += 1
        return tok if self.has_strings else tok.strip()

    def int(self, what: str, default: int | None = None, lo: int | None = None, hi: int | None = None) -> int:
        tok = self._next(what, default is not None)
        v = _parse_int(tok, default)
        if v is None:
            self.error(f"{what}: expected an integer, got {str(tok)[:40]!r}", self.i - 1)
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            self.error(f"{what} = {v} is outside {lo}..{hi}", self.i - 1)
        return v

    def count(self, what: str, per_item: int, lo: int = 0, offset: int = 0) -> int:
        """An integer count c with (c + offset) * per_item parameters still to come."""
        v = self.int(what, lo=lo)
        if (v + offset) * per_item > self.remaining:
            self.error(f"{what} = {v} needs {(v + offset) * per_item} more parameters, but the record "
                       f"has {self.remaining}", self.i - 1)
        return v

    def real(self, what: str, default: float | None = None) -> float:
        tok = self._next(what, default is not None)
        v = _parse_real(tok, default)
        if v is None:
            self.error(f"{what}: expected a finite real number, got {str(tok)[:40]!r}", self.i - 1)
        return v

    def reals(self, count: int, what: str) -> np.ndarray:
        if count < 0 or count > self.remaining:
            self.error(f"{what}: {count} values needed, {max(self.remaining, 0)} present")
        if count >= _BULK_MIN and self.bulk is not False and type(self.t) is _Tokens:
            if self.bulk is None:  # tried once per record, so the work stays linear
                a = self.t.reals_from(self.i)
                self.bulk = False if a is None else (self.i, a)
            if self.bulk and self.i >= self.bulk[0]:
                k = self.i - self.bulk[0]
                self.i += count
                return self.bulk[1][k : k + count].copy()
        toks = self.t[self.i : self.i + count]
        try:
            if self.has_strings and any(isinstance(t, _Str) for t in toks):
                raise ValueError
            # Fast path: only the characters of IGES reals (one C pass over the joined
            # tokens), then Python's float per token (faster than a regex pass and numpy's
            # text parser). float() accepts more than IGES (a 5-digit exponent), never a
            # character outside the set; empty tokens, repeated signs or points raise and
            # take the checked path below, which names the bad token.
            joined = ",".join(toks).encode("latin-1")
            # blanks around a token are allowed (float() skips them; blanks inside a
            # token make float() raise)
            if joined.translate(None, _REAL_CHARS):
                raise ValueError
            if b"D" in joined or b"d" in joined:
                toks = joined.replace(b"D", b"E").replace(b"d", b"e").split(b",")
            a = np.array(list(map(float, toks)), dtype=np.float64) if count else np.empty(0)
            if a.size != count or not np.all(np.isfinite(a)):
                raise ValueError
        except (ValueError, UnicodeEncodeError):
            a = np.empty(count)
            for k, t in enumerate(self.t[self.i : self.i + count]):
                t = t if isinstance(t, _Str) else t.strip()
                v = _parse_real(t, 0.0)
                if v is None:
                    self.error(f"{what}[{k}]: expected a finite real number, got {str(t)[:40]!r}", self.i + k)
                a[k] = v
        self.i += count
        return a

    def pointer(self, what: str, optional: bool = False):
        """A DE pointer (odd sequence number of a first DE line) as an entity index, or None."""
        tok = self._next(what, optional)
        v = _parse_int(tok, 0 if optional else None)
        if v is None:
            self.error(f"{what}: expected a pointer, got {str(tok)[:40]!r}", self.i - 1)
        if v == 0:
            if optional:
                return None
            self.error(f"{what}: null pointer", self.i - 1)
        if v < 0 or v % 2 == 0 or v > 2 * self.n_entities - 1:
            self.error(f"{what}: dangling pointer {v} (the file has DE lines 1..{2 * self.n_entities})",
                       self.i - 1)
        return (v - 1) // 2

    def string(self, what: str) -> str:
        tok = self._next(what, True)
        if tok == "":
            return ""
        if not isinstance(tok, _Str):
            self.error(f"{what}: expected a string, got {str(tok)[:40]!r}", self.i - 1)
        return str(tok)


# -- entity builders -------------------------------------------------------------------------------
def _b110(p: _Params, r, form: int):
    return dict(start=p.reals(3, "start point"), end=p.reals(3, "end point"), line_form=form)


def _b100(p, r, form):
    z = p.real("ZT", 0.0)
    c = p.reals(2, "center")
    s = p.reals(2, "start point")
    e = p.reals(2, "end point")
    return dict(center=c, start=s, end=e, z=z)


def _b102(p, r, form):
    n = p.count("N (number of curves)", 1, lo=1)
    return dict(curves=tuple(r(p.pointer(f"curve {k + 1}"), "constituent") for k in range(n)))


def _b112(p, r, form):
    ctype = p.int("CTYPE", lo=1, hi=6)
    h = p.int("H (continuity)", default=0)
    ndim = p.int("NDIM", lo=2, hi=3)
    n = p.count("N (number of segments)", 13, lo=1)
    T = p.reals(n + 1, "breakpoints")
    C = p.reals(12 * n, "coefficients").reshape(n, 3, 4)
    TP = p.reals(12, "terminal values").reshape(3, 4) if p.remaining >= 12 else np.zeros((3, 4))
    return dict(spline_type=ctype, continuity=h, ndim=ndim, breakpoints=T, coefficients=C, terminal=TP)


def _b114(p, r, form):
    ctype = p.int("CTYPE", lo=1, hi=6)
    ptype = p.int("PTYPE", default=0)
    m = p.count("M (u segments)", 1, lo=1)
    n = p.count("N (v segments)", 1, lo=1)
    if (m + 1) + (n + 1) + 48 * m * n > p.remaining:
        p.error(f"M = {m}, N = {n} need more parameters than the record has")
    TU = p.reals(m + 1, "u breakpoints")
    TV = p.reals(n + 1, "v breakpoints")
    C = np.empty((m, n, 3, 16))
    for i in range(m):
        for j in range(n):
            C[i, j] = p.reals(48, f"patch ({i + 1}, {j + 1})").reshape(3, 16)
        p.i += 48  # the arbitrary patch (i, N+1)
    return dict(spline_type=ctype, patch_type=ptype, breakpoints_u=TU, breakpoints_v=TV, coefficients=C)


def _b120(p, r, form):
    axis = r(p.pointer("L (axis)"), "axis")
    gen = r(p.pointer("C (generatrix)"), "generatrix")
    return dict(axis=axis, generatrix=gen, start_angle=p.real("SA", 0.0), end_angle=p.real("TA", 2 * math.pi))


def _b124(p, r, form):
    M = p.reals(12, "matrix").reshape(3, 4)
    return dict(rotation=M[:, :3], translation=M[:, 3], matrix_form=form)


def _b126(p, r, form):
    k = p.int("K (upper index)", lo=0)
    m = p.int("M (degree)", lo=1, hi=MAX_DEGREE)
    for name in ("PROP1", "PROP2", "PROP3", "PROP4"):
        p.int(name, default=0, lo=0, hi=1)
    if (k + m + 2) + 4 * (k + 1) + 2 > p.remaining:
        p.error(f"K = {k}, M = {m} need {(k + m + 2) + 4 * (k + 1) + 2} more parameters, "
                f"the record has {p.remaining}")
    knots = p.reals(k + m + 2, "knots")
    w = p.reals(k + 1, "weights")
    P = p.reals(3 * (k + 1), "control points").reshape(k + 1, 3)
    v0, v1 = p.real("V(0)"), p.real("V(1)")
    return dict(degree=m, knots=knots, control_points=P, weights=w, start=v0, end=v1)


def _b128(p, r, form):
    k1 = p.int("K1", lo=0)
    k2 = p.int("K2", lo=0)
    m1 = p.int("M1", lo=1, hi=MAX_DEGREE)
    m2 = p.int("M2", lo=1, hi=MAX_DEGREE)
    for name in ("PROP1", "PROP2", "PROP3", "PROP4", "PROP5"):
        p.int(name, default=0, lo=0, hi=1)
    need = (k1 + m1 + 2) + (k2 + m2 + 2) + 4 * (k1 + 1) * (k2 + 1) + 4
    if need > p.remaining:
        p.error(f"K1 = {k1}, K2 = {k2}, M1 = {m1}, M2 = {m2} need {need} more parameters, "
                f"the record has {p.remaining}")
    ku = p.reals(k1 + m1 + 2, "u knots")
    kv = p.reals(k2 + m2 + 2, "v knots")
    w = p.reals((k1 + 1) * (k2 + 1), "weights").reshape(k2 + 1, k1 + 1).T
    P = p.reals(3 * (k1 + 1) * (k2 + 1), "control points").reshape(k2 + 1, k1 + 1, 3).transpose(1, 0, 2)
    ur = (p.real("U(0)"), p.real("U(1)"))
    vr = (p.real("V(0)"), p.real("V(1)"))
    return dict(degree_u=m1, degree_v=m2, knots_u=ku, knots_v=kv, control_points=P, weights=w,
                u_range=ur, v_range=vr)


def _b142(p, r, form):
    crtn = p.int("CRTN", default=0, lo=0, hi=3)
    s = r(p.pointer("SPTR (surface)"), "surface")
    b = p.pointer("BPTR (parameter curve)", optional=True)
    c = p.pointer("CPTR (model curve)", optional=True)
    pref = p.int("PREF", default=0, lo=0, hi=3)
    return dict(surface=s, parameter_curve=None if b is None else r(b, "parameter curve"),
                model_curve=None if c is None else r(c, "model curve"), creation=crtn, preferred=pref)


def _b144(p, r, form):
    s = r(p.pointer("PTS (surface)"), "surface")
    n1 = p.int("N1", default=0, lo=0, hi=1)
    n2 = p.count("N2 (number of holes)", 1, lo=0, offset=1)
    pto = p.pointer("PTO (outer boundary)", optional=True)
    inner = tuple(r(p.pointer(f"PTI({k + 1})"), "inner boundary") for k in range(n2))
    outer = None if (pto is None or n1 == 0) else r(pto, "outer boundary")
    return dict(surface=s, outer=outer, inner=inner)


BUILDERS = {
    100: (CircularArc, _b100), 102: (CompositeCurve, _b102), 110: (Line, _b110),
    112: (ParametricSpline, _b112), 114: (ParametricSplineSurface, _b114),
    120: (SurfaceOfRevolution, _b120), 124: (TransformationMatrix, _b124),
    126: (BSplineCurve126, _b126), 128: (BSplineSurface128, _b128), 142: (CurveOnSurface, _b142),
    144: (TrimmedSurface, _b144),
}


# -- the parser ---------------------------------------------------------------------------------
def _field_int(text: str, src: _Source, line: int, what: str) -> int:
    s = text.strip()
    if s == "":
        return 0
    if not _INT.fullmatch(s):
        src.error(f"Directory Entry {what}: expected an integer, got {text!r}", line)
    return int(s)


def _parse_global(glines, src: _Source, notes: list | None = None) -> tuple:
    data = "".join(line[:72] for _, line in glines)
    first = glines[0][0]

    def line_of(offset):
        return first + min(max(offset, 0) // 72, len(glines) - 1)

    pos = 0
    if data.startswith("1H") and len(data) > 3:
        pd = data[2]
        pos = 3
        if data[pos] != pd:
            src.error("Global section: the parameter delimiter must follow field 1", first)
        pos += 1
    elif data.startswith(","):
        pd, pos = ",", 1
    else:
        src.error("Global section: field 1 must be the parameter delimiter (1Hx or defaulted)", first)
    if data.startswith("1H", pos) and len(data) > pos + 3:
        rd = data[pos + 2]
        pos += 3
        if data[pos] not in (pd, rd):
            src.error("Global section: a delimiter must follow field 2", line_of(pos))
        ended = data[pos] == rd
        pos += 1
    elif data[pos : pos + 1] == pd:
        rd, pos, ended = ";", pos + 1, False
    else:
        src.error("Global section: field 2 must be the record delimiter (1Hx or defaulted)", line_of(pos))
    if pd == rd or pd in " 0123456789+-.EDH" or rd in " 0123456789+-.EDH":
        src.error(f"Global section: unusable delimiters {pd!r} and {rd!r}", first)
    tokens = [] if ended else _tokenize(data[pos:], pd, rd, src, lambda o: line_of(o + pos))
    values = {"parameter_delimiter": pd, "record_delimiter": rd}
    defaulted = set()
    for k, (name, kind) in enumerate(GLOBAL_FIELDS[2:]):
        tok = tokens[k] if k < len(tokens) else ""
        where = f"Global section field {k + 3} ({name})"
        if tok == "":
            defaulted.add(name)
            continue
        try:
            if kind == "s":
                if not isinstance(tok, _Str):
                    src.error(f"{where}: expected a string, got {tok[:40]!r}", line_of(pos))
                values[name] = str(tok)
            elif kind == "i":
                v = _parse_int(tok)
                if v is None:
                    src.error(f"{where}: expected an integer, got {str(tok)[:40]!r}", line_of(pos))
                values[name] = v
            else:
                v = _parse_real(tok)
                if v is None:
                    src.error(f"{where}: expected a finite real, got {str(tok)[:40]!r}", line_of(pos))
                values[name] = v
        except IgesError as exc:
            # a field that does not decide size or place is noted, not fatal, when lenient
            if notes is None or name in ("model_scale", "unit_flag", "unit_name"):
                raise
            notes.append(f"{exc}; field ignored")
            defaulted.add(name)
    return GlobalSection(**values), pd, rd, frozenset(defaulted)


@dataclass(frozen=True)
class SkippedEntity:
    """An entity the lenient reader could not take (``parse_iges(..., strict=False)``).

    sequence: its DE sequence number; line: its first DE line; reason: why."""

    sequence: int
    entity_type: int
    form: int
    reason: str
    line: int | None = None


def _raw_pointers(etype: int, tokens, n_entities: int) -> list[int]:
    """Best-effort DE indices a skipped entity of a known referring type points to, so that
    its children are not taken for independent entities."""
    positions = {102: None, 142: (2, 3, 4), 144: None, 120: (1, 2), 122: (1,), 141: None, 143: None,
                 140: (2,), 308: None, 408: (1,), 186: None, 510: None, 508: None, 514: None, 502: None,
                 504: None, 402: None, 190: None, 192: None, 194: None, 196: None, 198: None}
    if etype not in positions:
        return []
    idx = positions[etype] or range(1, len(tokens))
    out = []
    for k in idx:
        if k < len(tokens):
            v = _parse_int(tokens[k] if isinstance(tokens[k], _Str) else tokens[k].strip())
            if v is not None and v > 0 and v % 2 == 1 and v <= 2 * n_entities - 1:
                out.append((v - 1) // 2)
    return out


def parse_iges(data, path=None, *, strict: bool = True) -> IgesModel:
    """Parse IGES text (str or bytes) into an :class:`IgesModel`; IgesError on malformed input.

    ``strict=False`` reads what CAD systems really write: blank lines, missing newlines,
    wrong S/G sequence numbers and Terminate counts are noted in ``model.notes``; an entity
    that cannot be read (or refers to one that cannot) is skipped and listed in
    ``model.skipped`` with its reason, and the rest of the file is read. Only what makes
    the file unreadable as a whole (sections, Global delimiters, units) is refused.
    """
    src = _Source(path)
    lenient = not strict
    notes: list = [] if lenient else None
    fixed = _fixed_array(data)
    sec = _sections_fast(fixed) if fixed is not None else None
    if sec is None:
        lines = _split_lines(data, lenient, notes)
        sec = _sections(lines, src, lenient, notes)
    start = "\n".join(line[:72].rstrip() for _, line in sec["S"])
    header, pd, rd, defaulted = _parse_global(sec["G"], src, notes)

    dlines, plines = sec["D"], sec["P"]
    # columns 1-64 of every P line (80 columns each: _sections checks it) and the back
    # pointers of columns 66-72, for slicing records out without a loop per line
    if isinstance(plines, _Rows):
        pbytes = plines.columns(0, 64).tobytes()
        pdata = pbytes.decode("latin-1")
        pback = _column_integers(plines.columns(65, 72))
    else:
        pdata = "".join([text[:64] for _, text in plines])
        pbytes = pdata.encode("latin-1", "replace")
        pback = None
    # a section of numbers only (no strings, no D exponents), checked once for all records
    plain = pd == "," and not pbytes.translate(None, _PLAIN_CHARS + rd.encode("latin-1", "replace"))
    if pback is None:
        pback = [text[65:72] for _, text in plines]
    n = len(dlines) // 2
    skipped: dict = {}
    directory: list = [None] * n
    for i in range(n):
        (l1, a), (l2, b) = dlines[2 * i], dlines[2 * i + 1]
        try:
            etype = _field_int(a[0:8], src, l1, "field 1 (entity type)")
            if _field_int(b[0:8], src, l2, "field 11 (entity type)") != etype:
                src.error(f"entity type {b[0:8].strip()!r} differs from {a[0:8].strip()!r} on the line before", l2)
            ptr = _field_int(a[8:16], src, l1, "field 2 (parameter data pointer)")
            tr = _field_int(a[48:56], src, l1, "field 7 (transformation matrix)")
            status = a[64:72]
            if not all(c in " 0123456789" for c in status):  # ASCII digits only
                src.error(f"Directory Entry field 9 (status number): expected digits, got {status!r}", l1)
            count = _field_int(b[24:32], src, l2, "field 14 (parameter line count)")
            form = _field_int(b[32:40], src, l2, "field 15 (form number)")
            level = _field_int(a[32:40], src, l1, "field 5 (level)")
            color = _field_int(b[16:24], src, l2, "field 13 (color)")
            label = b[56:64].strip()
            subscript = _field_int(b[64:72], src, l2, "field 19 (subscript)")
            if count < 1 or ptr < 1 or ptr + count - 1 > len(plines):
                src.error(f"parameter data lines {ptr}..{ptr + count - 1} are outside the Parameter Data "
                          f"section (1..{len(plines)})", l1)
            if tr < 0 or tr % 2 == 0 and tr != 0 or tr > 2 * n - 1:
                src.error(f"Directory Entry field 7: dangling transformation matrix pointer {tr}", l1)
        except IgesError as exc:
            if strict:
                raise
            t = _parse_int(a[0:8].strip()) or 0
            skipped[i] = SkippedEntity(2 * i + 1, t, 0, str(exc), l1)
            continue
        directory[i] = (etype, ptr, count, form, status, level, color, label, subscript, tr, l1)

    built: list = [None] * n
    visiting = [False] * n
    raw_refs: dict = {}
    check = check_structure
    if lenient:
        from .foreign import _lenient_builders, check_lenient

        lenient_builders = {**BUILDERS, **_lenient_builders()}
        check = check_lenient

    def build(i: int, depth: int, role: str, referrer_line: int):
        if built[i] is not None:
            return built[i]
        if i in skipped:
            return skipped[i]
        if visiting[i]:
            src.error(f"recursive reference: entity at DE {2 * i + 1} ({role}) refers back to itself",
                      referrer_line)
        if depth > MAX_REFERENCE_DEPTH:
            src.error(f"references nested deeper than {MAX_REFERENCE_DEPTH}", referrer_line)
        visiting[i] = True
        try:
            record = _build_one(i, depth)
        except IgesError as exc:
            visiting[i] = False
            if strict:
                raise
            etype, form, l1 = directory[i][0], directory[i][3], directory[i][10]
            skipped[i] = SkippedEntity(2 * i + 1, etype, form, str(exc), l1)
            return skipped[i]
        visiting[i] = False
        built[i] = record
        return record

    def _build_one(i: int, depth: int):
        etype, ptr, count, form, status, level, color, label, subscript, tr, l1 = directory[i]
        first_line = plines[ptr - 1][0]
        seq = 2 * i + 1
        expected = f"{seq:7d}"
        back = pback[ptr - 1 : ptr - 1 + count]
        if not (np.all(back == seq) if isinstance(back, np.ndarray) else back.count(expected) == count):
            for k in range(ptr - 1, ptr - 1 + count):  # not the usual right-justified form
                ln, text = plines[k]
                back = text[65:72].strip()
                if not _DIGITS.fullmatch(back) or int(back) != seq:
                    src.error(f"parameter line points back to DE {text[65:72].strip()!r}; expected {seq}", ln)
        # the Parameter Data text of the section is joined once; a record is a slice of it
        data = pdata[64 * (ptr - 1) : 64 * (ptr - 1 + count)]

        def line_of(offset):
            return first_line + min(max(offset, 0) // 64, count - 1)

        tokens = _tokenize(data, pd, rd, src, line_of, strip=False, plain=plain)
        if type(tokens) is not _StrTokens and tokens:
            tokens[0] = tokens[0].strip()

        def line_of_index(index):
            # locate the index-th parameter by counting delimiters (only on error)
            pos = 0
            for _ in range(min(index, len(tokens))):
                nxt = data.find(pd, pos)
                if nxt < 0:
                    break
                pos = nxt + 1
            return line_of(pos)

        where = f"entity type {etype} at DE {seq}"
        if not tokens or _parse_int(tokens[0]) != etype:
            src.error(f"{where}: parameter data start with {str(tokens[0])[:20] if tokens else ''!r}, "
                      f"not the entity type {etype}", first_line)
        if lenient:
            raw_refs[i] = _raw_pointers(etype, tokens, n)
        p = _Params(tokens, src, where, first_line, line_of_index, n)

        def resolve(j, what):
            got = build(j, depth + 1, what, first_line)
            if isinstance(got, SkippedEntity):
                src.error(f"{where}: its {what} (DE {got.sequence}, type {got.entity_type}) was skipped: "
                          f"{got.reason}", first_line)
            return got

        info = DirectoryInfo(sequence=seq, line=l1, parameter_line=first_line, form=form,
                             status=status, level=level, color=color)
        common = dict(label=label, subscript=subscript, directory=info)
        if tr:
            t = build((tr - 1) // 2, depth + 1, "transformation matrix", l1)
            if isinstance(t, SkippedEntity):
                src.error(f"{where}: its transformation matrix (DE {tr}) was skipped: {t.reason}", l1)
            if not isinstance(t, TransformationMatrix):
                src.error(f"{where}: field 7 points to {t.describe()}, not a transformation matrix", l1)
            common["transform"] = t
        builders = BUILDERS if strict else lenient_builders
        try:
            if etype in builders:
                cls, fn = builders[etype]
                record = cls(**fn(p, resolve, form), **common)
            else:
                record = GenericEntity(entity_type=etype, entity_form=form, parameters=tuple(
                    t if isinstance(t, _Str) else t.strip() for t in tokens[1:]), **common)
            check(record)
        except IgesError as exc:
            if exc.line is not None:
                raise
            src.error(f"{where}: {exc}", first_line)
        except BladesmithError as exc:
            src.error(f"{where}: {exc}", first_line)
        return record

    for i in range(n):
        if directory[i] is not None:
            build(i, 0, "entity", directory[i][10])
    if strict:
        return IgesModel(entities=tuple(built), header=header, start=start, path=src.path)
    entities = tuple(e for e in built if e is not None)
    # children of skipped entities, and entities the file marks as dependent (DE status
    # digits 3-4 non-zero, IGES 5.3 §2.2.4.4.9), are not independent roots
    dependent = set()
    # (and of entities read only generically, such as 190-198 surfaces under a skipped face)
    below_skipped = {j for i in skipped for j in raw_refs.get(i, ())}
    below_skipped |= {j for i, e in enumerate(built) if isinstance(e, GenericEntity) for j in raw_refs.get(i, ())}
    for i, e in enumerate(built):
        if e is None:
            continue
        if i in below_skipped:
            dependent.add(id(e))
        st = e.directory.status if e.directory is not None else ""
        if len(st) == 8 and st[2:4].strip() not in ("", "0", "00"):
            dependent.add(id(e))
    return IgesModel(entities=entities, header=header, start=start, path=src.path,
                     skipped=tuple(skipped[k] for k in sorted(skipped)), notes=tuple(notes),
                     defaulted=defaulted, dependent=frozenset(dependent))


def read_iges(path, *, strict: bool = True) -> IgesModel:
    """Read an IGES file (IGES 5.3 fixed form) into an :class:`IgesModel`."""
    p = os.fspath(path)
    try:
        size = os.path.getsize(p)
        if size > MAX_FILE_BYTES:
            raise IgesError(f"file of {size} bytes exceeds the limit of {MAX_FILE_BYTES}", path=p)
        with open(p, "rb") as f:
            data = f.read()
    except OSError as exc:
        raise IgesError(f"cannot read the file: {exc}", path=p) from exc
    return parse_iges(data, path=p, strict=strict)
