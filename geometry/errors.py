"""The one exception family of Bladesmith.

Operators catch only these (ARCHITECTURE.md, house style 6); anything else escaping
is a bug and must surface in tests.
"""
from __future__ import annotations

import re

#: numpy 2 writes its scalars' repr as ``np.float64(1.5)`` (numpy 1: ``1.5``).
_NUMPY_SCALAR = re.compile(r"\bnp\.(?:float|int|uint|complex|str|bytes)_?\d*\(([^()]*)\)")


def plain_numbers(text: str) -> str:
    """``text`` with numpy 2's scalar reprs (``np.float64(1.5)``) written as the numbers
    they are (``1.5``), so a message names the value the same way under every numpy."""
    return _NUMPY_SCALAR.sub(r"\1", text)


class BladesmithError(ValueError):
    """Base class of every error Bladesmith raises on purpose. Its message names values as
    plain numbers under numpy 1 and 2 alike (:func:`plain_numbers`)."""

    def __init__(self, *args):
        super().__init__(*(plain_numbers(a) if isinstance(a, str) else a for a in args))


class DefinitionError(BladesmithError):
    """A definition file or panel value is invalid.

    The message names the file (when there is one), the field and the value.
    """

    def __init__(self, message: str, *, path: str | None = None, field: str | None = None):
        self.path = path
        self.field = field
        self.message = plain_numbers(message)
        parts = []
        if path:
            parts.append(str(path))
        if field:
            parts.append(f"field '{field}'")
        prefix = ": ".join(parts)
        super().__init__(f"{prefix}: {message}" if prefix else message)


    def with_path(self, path) -> "DefinitionError":
        """The same refusal naming ``path`` (for checks made where the file is not known)."""
        return DefinitionError(self.message, path=self.path or path, field=self.field)


class GeometryError(BladesmithError):
    """Geometric data is inconsistent or an algorithm cannot produce a valid result."""


class IgesError(BladesmithError):
    """An IGES file is malformed, or data cannot be written as valid IGES.

    ``line`` is the 1-based line number in the file when reading.
    """

    def __init__(self, message: str, *, path: str | None = None, line: int | None = None):
        self.path = path
        self.line = line
        where = []
        if path:
            where.append(str(path))
        if line is not None:
            where.append(f"line {line}")
        prefix = ", ".join(where)
        super().__init__(f"{prefix}: {message}" if prefix else message)
