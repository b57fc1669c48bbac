"""Checks shared by the three definition formats (propeller, wind blade, impeller).

Every definition is validated by its own module (``propeller/definition.py``,
``mold/definition.py``, ``compressor/definition.py``); this module holds what they share:

- reading a definition or data file, with every reading error (missing, a directory, not
  UTF-8, binary, too large, not TOML) turned into a :class:`DefinitionError` naming the file;
- refusing unknown keys with the nearest valid name (``difflib``), so a typo such as
  ``prebnd`` is never silently ignored;
- the size bounds of the float32 display: Blender stores coordinates as float32, so
  lengths are kept between :data:`MIN_LENGTH` and :data:`MAX_LENGTH` metres, where float32
  keeps the geometry (relative spacing 6e-8) and no Blender operation overflows;
- upper bounds on counts, named in the refusal so a user knows which limit was hit.

The bounds are documented in README "Limits of definitions".
"""
from __future__ import annotations

import difflib
import math
import os
import pathlib
import stat
import tomllib

from .errors import DefinitionError

#: Smallest length (m) of a blade, chord or hub the float32 display keeps: at 0.1 mm the
#: display's float32 spacing (about 1e-11 m) is still 1e-7 of the part.
MIN_LENGTH = 1e-4
#: Largest length (m): the float32 display of a part of 10 km keeps about 1 mm, 1e-7 of its
#: size; beyond, Blender's curve tools lose the geometry (a propeller of diameter 1e20
#: hangs ``curve.make_segment``).
MAX_LENGTH = 1e4
#: Largest definition or data file read (bytes). A real definition is a few kB; a 10^6-row
#: table would take minutes and gigabytes to build.
MAX_FILE_BYTES = 4_000_000
#: Largest name (characters).
MAX_NAME_LENGTH = 200


def _fmt(value) -> str:
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def read_bytes(path, *, what: str = "file", source=None, field: str | None = None) -> bytes:
    """The bytes of ``path``; every reading error is a DefinitionError naming the file
    (and ``source``/``field`` when the file was named by a definition field)."""
    path = pathlib.Path(path)
    where = dict(path=str(source), field=field) if source is not None else dict(path=str(path), field=field)
    prefix = "" if source is None else f"{what} {str(path)!r}: "
    try:
        info = os.stat(path)
        size = info.st_size
        if stat.S_ISDIR(info.st_mode):
            raise DefinitionError(f"{prefix}is a directory, not a file", **where)
        if not stat.S_ISREG(info.st_mode):  # a FIFO or device would block or never end
            raise DefinitionError(f"{prefix}is not a regular file", **where)
        if size > MAX_FILE_BYTES:
            raise DefinitionError(f"{prefix}{size} bytes is more than the limit MAX_FILE_BYTES = {MAX_FILE_BYTES}",
                                  **where)
        with open(path, "rb") as fh:
            return fh.read(MAX_FILE_BYTES + 1)
    except DefinitionError:
        raise
    except FileNotFoundError:
        raise DefinitionError(f"{prefix or what + ' '}not found", **where) from None
    except IsADirectoryError:
        raise DefinitionError(f"{prefix}is a directory, not a file", **where) from None
    except OSError as exc:
        raise DefinitionError(f"{prefix}cannot read ({exc.strerror or exc})", **where) from None
    except ValueError as exc:  # a NUL character in the name
        raise DefinitionError(f"{prefix or what + ' '}has an invalid name ({exc})", **where) from None


def read_text(path, *, what: str = "file", source=None, field: str | None = None) -> str:
    """The UTF-8 text of ``path``; binary content (NUL bytes) and invalid UTF-8 are
    refused with the byte offset."""
    data = read_bytes(path, what=what, source=source, field=field)
    where = dict(path=str(source), field=field) if source is not None else dict(path=str(path), field=field)
    prefix = "" if source is None else f"{what} {str(path)!r}: "
    nul = data.find(b"\0")
    if nul >= 0:
        raise DefinitionError(f"{prefix}binary data (a NUL byte at offset {nul}), not a text {what}", **where)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise DefinitionError(f"{prefix}not UTF-8 text: byte {data[exc.start]:#04x} at offset {exc.start}",
                              **where) from None


def read_toml(path, what: str = "definition file") -> dict:
    """A TOML file as a dict; reading and syntax errors are DefinitionErrors naming it."""
    text = read_text(path, what=what)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise DefinitionError(f"not valid TOML: {exc}", path=str(path)) from None


def table(value, path, field: str) -> dict:
    """``value`` when it is a TOML table, else a DefinitionError."""
    if not isinstance(value, dict):
        raise DefinitionError(f"expected a table, got {_fmt(value)}", path=path, field=field)
    return value


def check_keys(data: dict, allowed, path, prefix: str = "") -> None:
    """Refuse keys of ``data`` not in ``allowed``, naming the key and the nearest valid
    one (``prefix`` is the table's name, e.g. "radial")."""
    allowed = tuple(allowed)
    for key in data:
        if key in allowed:
            continue
        close = difflib.get_close_matches(str(key), allowed, n=1, cutoff=0.6)
        hint = f"did you mean {close[0]!r}?" if close else f"valid keys: {', '.join(sorted(allowed))}"
        where = f"[{prefix}]" if prefix else "the top level"
        raise DefinitionError(f"unknown key {str(key)!r} in {where}; {hint}", path=path,
                              field=f"{prefix}.{key}" if prefix else str(key))


def check_count(count: int, maximum: int, bound_name: str, path, field: str, what: str) -> None:
    """Refuse more than ``maximum`` ``what`` (the bound ``bound_name`` is named)."""
    if count > maximum:
        raise DefinitionError(f"{count} {what} is more than the limit {bound_name} = {maximum}", path=path,
                              field=field)


def number(value, path, field: str, *, lo=None, hi=None, lo_open=False, hi_open=False, integer=False,
           entry: str = "") -> float:
    """A finite number (bools refused) in [lo, hi] (open ends when asked); ``integer``
    also refuses a fractional value and returns an int. ``entry`` (e.g. "entry 3: ")
    starts the message when the value is one of a list."""
    try:
        return _number(value, path, field, lo, hi, lo_open, hi_open, integer)
    except DefinitionError as exc:
        if not entry:
            raise
        raise DefinitionError(entry + str(exc).rsplit(f"field '{field}': ", 1)[-1], path=path, field=field) from None


def _number(value, path, field, lo, hi, lo_open, hi_open, integer):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise DefinitionError(f"expected {'an integer' if integer else 'a number'}, got {_fmt(value)}", path=path,
                              field=field)
    if not math.isfinite(value):
        raise DefinitionError(f"value {value} is not finite", path=path, field=field)
    if integer and not float(value).is_integer():
        raise DefinitionError(f"expected an integer, got {value}", path=path, field=field)
    below = lo is not None and (value <= lo if lo_open else value < lo)
    above = hi is not None and (value >= hi if hi_open else value > hi)
    if below or above:
        left = "(" if lo_open else "["
        right = ")" if hi_open else "]"
        low = "-inf" if lo is None else f"{lo:g}"
        high = "inf" if hi is None else f"{hi:g}"
        raise DefinitionError(f"{value!r} is outside {left}{low}, {high}{right}", path=path, field=field)
    return int(value) if integer else float(value)


def string(value, path, field: str, *, max_length: int = MAX_NAME_LENGTH) -> str:
    """A non-empty string of at most ``max_length`` characters."""
    if not isinstance(value, str) or not value.strip():
        raise DefinitionError(f"expected a non-empty string, got {_fmt(value)}", path=path, field=field)
    if len(value) > max_length:
        raise DefinitionError(f"{len(value)} characters is more than the limit {max_length}", path=path, field=field)
    return value


def number_list(value, path, field: str, *, maximum: int, bound_name: str, minimum: int = 1, lo=None, hi=None,
                what: str = "values") -> tuple:
    """A list of finite numbers (the count first, so a huge list is refused before any
    work), each in [lo, hi]; refusals name the entry."""
    if not isinstance(value, (list, tuple)):
        raise DefinitionError(f"expected a list of numbers, got {_fmt(value)}", path=path, field=field)
    check_count(len(value), maximum, bound_name, path, field, what)
    if len(value) < minimum:
        raise DefinitionError(f"expected at least {minimum} {what}, got {len(value)}", path=path, field=field)
    out = []
    for i, v in enumerate(value):
        out.append(number(v, path, field, lo=lo, hi=hi, entry=f"entry {i}: "))
    return tuple(out)
