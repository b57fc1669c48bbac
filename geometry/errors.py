"""The one exception family of Bladesmith.

Operators catch only these (ARCHITECTURE.md, house style 6); anything else escaping
is a bug and must surface in tests.
"""
from __future__ import annotations


class BladesmithError(ValueError):
    """Base class of every error Bladesmith raises on purpose."""


class DefinitionError(BladesmithError):
    """A definition file or panel value is invalid.

    The message names the file (when there is one), the field and the value.
    """

    def __init__(self, message: str, *, path: str | None = None, field: str | None = None):
        self.path = path
        self.field = field
        self.message = message
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
