"""Refusals name values as plain numbers under numpy 1 and numpy 2 alike.

Blender 5.x bundles numpy 2, whose scalar repr is ``np.float64(1.5)``: messages built with
``{value!r}`` from numpy scalars read 'new_knots[1] = np.float64(1.5) is outside ...' there
(seen in tests/unit on bpy 5.2's Python 3.13 and numpy 2.5). The error family writes them as
numbers, so one check of the messages holds on every Blender."""
from __future__ import annotations

import pytest

from bladesmith.geometry.errors import DefinitionError, GeometryError, IgesError, plain_numbers


@pytest.mark.parametrize("text, plain", [
    ("u = np.float64(1.5) is outside [0.0, 1.0]", "u = 1.5 is outside [0.0, 1.0]"),
    ("count np.int64(-3), knot np.float32(0.25)", "count -3, knot 0.25"),
    ("value np.float64(nan) and np.float64(-inf)", "value nan and -inf"),
    ("name np.str_('tip')", "name 'tip'"),
    ("no numpy here: f(1.5), (2, 3)", "no numpy here: f(1.5), (2, 3)"),
])
def test_plain_numbers(text, plain):
    assert plain_numbers(text) == plain


def test_every_error_of_the_family_writes_plain_numbers():
    assert str(GeometryError("knot np.float64(0.7) 3 time(s)")) == "knot 0.7 3 time(s)"
    assert str(IgesError("scale np.float64(-1.0)", path="a.igs", line=3)) == "a.igs, line 3: scale -1.0"
    e = DefinitionError("pitch np.float64(2.5) > 2", path="p.toml", field="P_D")
    assert e.message == "pitch 2.5 > 2" and str(e) == "p.toml: field 'P_D': pitch 2.5 > 2"
    assert str(e.with_path("q.toml")) == "p.toml: field 'P_D': pitch 2.5 > 2"
