"""A strict, bounded reader for the part of YAML that windIO turbine files use.

Why not PyYAML: Blender does not bundle a YAML reader (the bpy 4.5 wheel's RECORD lists
no ``yaml`` module, and Blender 4.2-5.x ship only numpy, requests, zstandard and their
helpers as third-party Python packages), and the extension zip ships scipy alone. windIO
files (IEA Task 37 ontology; IEA 15 MW, 22 MW, 3.4 MW reference turbines) are written by
PyYAML's dumper and use a small, regular subset, which this module reads:

- block mappings (``key: value``, ``key:`` then an indented block, or a sequence at the
  key's own indentation) and block sequences (``- value``, ``-  key: value ...``);
- flow sequences ``[a, b, [c, d]]`` and flow mappings ``{k: v}`` on one line;
- plain, single-quoted and double-quoted scalars, resolved by the YAML 1.2 core schema
  (null, bool, int, float including ``2e6`` and ``.inf``; anything else is a string);
- comments (``#`` at a line start or after white space), a leading ``---``;
- anchors ``&name`` and aliases ``*name`` (the alias is the same Python object, never a
  copy, so nesting aliases cannot blow up the memory).

Anything else (block scalars ``|`` / ``>``, tags ``!``, multi-line plain or flow scalars,
tabs in indentation, duplicate keys, complex keys, several documents) is refused with the
file and line: nothing is guessed. Work is linear in the file size; the file size and the
nesting depth are bounded (:data:`MAX_BYTES`, :data:`MAX_DEPTH`).
"""
from __future__ import annotations

import math
import pathlib
import re

from ..errors import DefinitionError

#: Largest file read (the IEA 15 MW windIO files are about 0.25 MB).
MAX_BYTES = 64 * 1024 * 1024
#: Deepest nesting of blocks and flow collections.
MAX_DEPTH = 200

_INT = re.compile(r"[-+]?[0-9]+$")
_FLOAT = re.compile(r"[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?$")
_ANCHOR = re.compile(r"[&*]([^\s,\[\]{}]+)")
_NULLS = {"", "~", "null", "Null", "NULL"}
_TRUE = {"true", "True", "TRUE"}
_FALSE = {"false", "False", "FALSE"}
_INFS = {".inf": math.inf, ".Inf": math.inf, ".INF": math.inf, "+.inf": math.inf, "+.Inf": math.inf,
         "+.INF": math.inf, "-.inf": -math.inf, "-.Inf": -math.inf, "-.INF": -math.inf}
_NANS = {".nan", ".NaN", ".NAN"}
_ESCAPES = {"\\": "\\", '"': '"', "/": "/", "n": "\n", "t": "\t", "r": "\r", "0": "\0", " ": " "}


def resolve_scalar(text: str):
    """A plain scalar's value by the YAML 1.2 core schema."""
    if text in _NULLS:
        return None
    if text in _TRUE:
        return True
    if text in _FALSE:
        return False
    if _INT.match(text):
        return int(text)
    if _FLOAT.match(text):
        return float(text)
    if text in _INFS:
        return _INFS[text]
    if text in _NANS:
        return math.nan
    return text


class _Reader:
    def __init__(self, text: str, path: str):
        self.path = path
        self.anchors: dict = {}
        self.lines = []  # (line number, indent, content)
        for number, raw in enumerate(text.split("\n"), start=1):
            body = raw.rstrip("\r")
            stripped = body.lstrip(" ")
            if stripped.startswith("\t"):
                self.fail(number, "a tab in the indentation")
            content = self._strip_comment(stripped, number).rstrip()
            if not content:
                continue
            if content == "---" and not self.lines:
                continue
            if content in ("---", "..."):
                self.fail(number, f"{content!r}: only one document per file is read")
            self.lines.append((number, len(body) - len(stripped), content))

    def fail(self, line: int, message: str):
        raise DefinitionError(f"line {line}: {message} (windIO YAML subset)", path=self.path)

    def _strip_comment(self, s: str, line: int) -> str:
        quote = None
        i = 0
        while i < len(s):
            c = s[i]
            if quote == "'":
                if c == "'":
                    if i + 1 < len(s) and s[i + 1] == "'":
                        i += 1
                    else:
                        quote = None
            elif quote == '"':
                if c == "\\":
                    i += 1
                elif c == '"':
                    quote = None
            elif c in "'\"" and (i == 0 or s[i - 1] in " ,[{:-"):
                quote = c
            elif c == "#" and (i == 0 or s[i - 1] in " \t"):
                return s[:i]
            i += 1
        if quote is not None:
            self.fail(line, "a quoted scalar that does not end on its line")
        return s

    # -- blocks ---------------------------------------------------------------------
    def document(self):
        if not self.lines:
            return None
        node, i = self.block(0, self.lines[0][1], 0)
        if i < len(self.lines):
            self.fail(self.lines[i][0], "text after the end of the top-level block (bad indentation)")
        return node

    def block(self, i: int, indent: int, depth: int):
        if depth > MAX_DEPTH:
            self.fail(self.lines[i][0], f"nesting deeper than {MAX_DEPTH}")
        line, ind, content = self.lines[i]
        if ind != indent:
            self.fail(line, f"indentation {ind}, expected {indent}")
        if _is_entry(content):
            return self.sequence(i, indent, depth)
        if self._key_split(content, line) is not None:
            return self.mapping(i, indent, depth)
        node = self.inline(content, line, depth)
        return node, i + 1

    def sequence(self, i: int, indent: int, depth: int):
        out = []
        while i < len(self.lines):
            line, ind, content = self.lines[i]
            if ind != indent or not _is_entry(content):
                if ind > indent:
                    self.fail(line, "unexpected indentation inside a sequence")
                break
            rest = content[1:].lstrip(" ")
            col = indent + len(content) - len(rest)
            if not rest:
                if i + 1 < len(self.lines) and self.lines[i + 1][1] > indent:
                    node, i = self.block(i + 1, self.lines[i + 1][1], depth + 1)
                else:
                    node, i = None, i + 1
            elif _is_entry(rest) or self._key_split(rest, line) is not None:
                # "- key: value": a block whose first line starts after the dash
                self.lines[i] = (line, col, rest)
                node, i = self.block(i, col, depth + 1)
            else:
                node, i = self.inline(rest, line, depth), i + 1
            out.append(node)
        return out, i

    def mapping(self, i: int, indent: int, depth: int):
        out: dict = {}
        while i < len(self.lines):
            line, ind, content = self.lines[i]
            if ind < indent:
                break
            if ind > indent:
                self.fail(line, "unexpected indentation (a multi-line scalar?)")
            if _is_entry(content):
                break
            split = self._key_split(content, line)
            if split is None:
                self.fail(line, f"expected 'key: value', got {content[:60]!r}")
            key_text, rest = split
            key = self._key(key_text, line)
            if key in out:
                self.fail(line, f"duplicate key {key!r}")
            anchor, rest = self._anchor(rest, line)
            if rest:
                value, i = self.inline(rest, line, depth), i + 1
            elif i + 1 < len(self.lines) and self.lines[i + 1][1] > indent:
                value, i = self.block(i + 1, self.lines[i + 1][1], depth + 1)
            elif i + 1 < len(self.lines) and self.lines[i + 1][1] == indent and _is_entry(self.lines[i + 1][2]):
                value, i = self.sequence(i + 1, indent, depth + 1)
            else:
                value, i = None, i + 1
            if anchor is not None:
                self.anchors[anchor] = value
            out[key] = value
        return out, i

    def _anchor(self, rest: str, line: int):
        if rest.startswith("&"):
            m = _ANCHOR.match(rest)
            if m is None:
                self.fail(line, "an anchor without a name")
            return m.group(1), rest[m.end():].lstrip(" ")
        return None, rest

    def _key(self, text: str, line: int):
        if text[:1] in "'\"":
            value, end = self.quoted(text, 0, line)
            if text[end:].strip():
                self.fail(line, f"text after the quoted key {text!r}")
            return value
        if text[:1] in "[{?&*!|>%@`":
            self.fail(line, f"unsupported key {text!r}")
        value = resolve_scalar(text)
        return value

    @staticmethod
    def _key_split(content: str, line: int):
        """(key, rest) when ``content`` is 'key: rest' or 'key:', else None."""
        quote = None
        depth = 0
        for i, c in enumerate(content):
            if quote:
                if c == quote:
                    quote = None
                continue
            if c in "'\"" and i == 0:
                quote = c
            elif c in "[{":
                if i == 0:
                    return None
                depth += 1
            elif c in "]}":
                depth -= 1
            elif c == ":" and depth == 0 and (i + 1 == len(content) or content[i + 1] == " "):
                return content[:i].rstrip(" "), content[i + 1:].strip(" ")
        return None

    # -- inline values ------------------------------------------------------------------
    def inline(self, text: str, line: int, depth: int):
        anchor, text = self._anchor(text, line)
        value, end = self.flow_value(text, 0, line, depth, flow=False)
        if text[end:].strip(" "):
            self.fail(line, f"unexpected text {text[end:][:40]!r}")
        if anchor is not None:
            self.anchors[anchor] = value
        return value

    def flow_value(self, s: str, i: int, line: int, depth: int, flow: bool):
        if depth > MAX_DEPTH:
            self.fail(line, f"nesting deeper than {MAX_DEPTH}")
        while i < len(s) and s[i] == " ":
            i += 1
        if i >= len(s):
            return None, i
        c = s[i]
        if c == "[":
            return self.flow_sequence(s, i + 1, line, depth + 1)
        if c == "{":
            return self.flow_mapping(s, i + 1, line, depth + 1)
        if c in "'\"":
            return self.quoted(s, i, line)
        if c == "*":
            m = _ANCHOR.match(s, i)
            if m is None or m.group(1) not in self.anchors:
                self.fail(line, f"unknown alias {s[i:i + 40]!r}")
            return self.anchors[m.group(1)], m.end()
        if c == "&" and flow:
            anchor, rest = self._anchor(s[i:], line)
            value, end = self.flow_value(rest, 0, line, depth, flow)
            self.anchors[anchor] = value
            return value, len(s) - len(rest) + end
        if c in "!|>%@`&":
            self.fail(line, f"unsupported YAML: {s[i:i + 40]!r}")
        stop = ",[]{}" if flow else ""
        j = i
        while j < len(s) and s[j] not in stop:
            if flow and s[j] == ":" and (j + 1 == len(s) or s[j + 1] == " "):
                break
            j += 1
        text = s[i:j].rstrip(" ")
        if not flow and (": " in text or text.endswith(":")):
            self.fail(line, f"a mapping where a value was expected: {text[:40]!r}")
        return resolve_scalar(text), j

    def flow_sequence(self, s: str, i: int, line: int, depth: int):
        out = []
        while True:
            while i < len(s) and s[i] == " ":
                i += 1
            if i >= len(s):
                self.fail(line, "a flow sequence '[' that does not close on its line")
            if s[i] == "]":
                return out, i + 1
            value, i = self.flow_value(s, i, line, depth, flow=True)
            out.append(value)
            while i < len(s) and s[i] == " ":
                i += 1
            if i < len(s) and s[i] == ",":
                i += 1
            elif i < len(s) and s[i] == "]":
                return out, i + 1
            elif i >= len(s):
                self.fail(line, "a flow sequence '[' that does not close on its line")
            else:
                self.fail(line, f"expected ',' or ']' in a flow sequence at column {i + 1}")

    def flow_mapping(self, s: str, i: int, line: int, depth: int):
        out: dict = {}
        while True:
            while i < len(s) and s[i] == " ":
                i += 1
            if i >= len(s):
                self.fail(line, "a flow mapping '{' that does not close on its line")
            if s[i] == "}":
                return out, i + 1
            key, i = self.flow_value(s, i, line, depth, flow=True)
            if i >= len(s) or s[i] != ":":
                self.fail(line, f"expected ':' after the key {key!r} in a flow mapping")
            if isinstance(key, (list, dict)) or key in out:
                self.fail(line, f"bad or duplicate key {key!r} in a flow mapping")
            value, i = self.flow_value(s, i + 1, line, depth, flow=True)
            out[key] = value
            while i < len(s) and s[i] == " ":
                i += 1
            if i < len(s) and s[i] == ",":
                i += 1
            elif i < len(s) and s[i] == "}":
                return out, i + 1
            elif i >= len(s):
                self.fail(line, "a flow mapping '{' that does not close on its line")
            else:
                self.fail(line, f"expected ',' or '}}' in a flow mapping at column {i + 1}")

    def quoted(self, s: str, i: int, line: int):
        q = s[i]
        out = []
        j = i + 1
        while j < len(s):
            c = s[j]
            if q == "'" and c == "'":
                if j + 1 < len(s) and s[j + 1] == "'":
                    out.append("'")
                    j += 2
                    continue
                return "".join(out), j + 1
            if q == '"' and c == '"':
                return "".join(out), j + 1
            if q == '"' and c == "\\":
                e = s[j + 1: j + 2]
                if e in _ESCAPES:
                    out.append(_ESCAPES[e])
                    j += 2
                    continue
                if e == "u" and re.match(r"[0-9A-Fa-f]{4}$", s[j + 2: j + 6] or ""):
                    out.append(chr(int(s[j + 2: j + 6], 16)))
                    j += 6
                    continue
                self.fail(line, f"unsupported escape \\{e} in a double-quoted scalar")
            out.append(c)
            j += 1
        self.fail(line, "a quoted scalar that does not end on its line")


def _is_entry(content: str) -> bool:
    return content == "-" or content.startswith("- ")


def loads(text: str, path: str = ""):
    """Parse YAML text of the windIO subset; DefinitionError names the file and line."""
    if len(text) > MAX_BYTES:
        raise DefinitionError(f"larger than {MAX_BYTES} bytes", path=path)
    return _Reader(text, path).document()


def load(path):
    """Read a YAML file of the windIO subset (UTF-8)."""
    path = pathlib.Path(path)
    try:
        size = path.stat().st_size
    except FileNotFoundError:
        raise DefinitionError("file not found", path=str(path)) from None
    if size > MAX_BYTES:
        raise DefinitionError(f"larger than {MAX_BYTES} bytes ({size})", path=str(path))
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise DefinitionError(f"not UTF-8 text ({exc})", path=str(path)) from None
    return loads(text, str(path))
