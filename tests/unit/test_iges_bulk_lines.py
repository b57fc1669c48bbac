"""The writer's array-built P lines of large nets (issue 22) are byte for byte the lines of
the per-token path (parameter string, greedy packing at delimiters, "%-64s %7dP%07d"):
for the arrays of the bulk-reals test (every magnitude, sign, power-of-ten neighbour and
special value), with heads and tails of several lengths, and for whole files of 128 and
126 entities written with and without the array path."""
import datetime
import importlib.util
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.nurbs import BSplineCurve, BSplineSurface
from bladesmith.iges import curve_from_geometry, surface_from_geometry
from bladesmith.iges import writer
from bladesmith.iges.writer import _bulk_lines, _pack, _reals, to_string

_spec = importlib.util.spec_from_file_location(
    "bulk_reals_cases", pathlib.Path(__file__).with_name("test_iges_bulk_reals.py"))
_cases_module = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_cases_module)
cases = _cases_module.cases


def reference_lines(head, a, tail, seq, pseq):
    chunks = _pack(head + _reals(a) + "," + tail)
    return "\n".join("%-64s %7dP%07d" % (c, seq, pseq + k) for k, c in enumerate(chunks)), len(chunks)


@pytest.mark.parametrize("head, tail", [
    ("128,", "0.0,1.0;"),
    ("126,39,3,0,0,1,0," + ",".join(["1.0"] * 300) + ",", "0.0,1.0,0.0,0.0,0.0;"),
    ("128,9,9,3,3,0,0,0,0,0,0.0,0.0,0.0,0.0,0.1234567890123,1.0,1.0,1.0,1.0,", "-1.5E-05,2.0;"),
])
def test_bulk_lines_equal_the_packed_string(head, tail):
    rng = np.random.default_rng(3)
    for a in cases():
        a = a.copy()
        rng.shuffle(a)
        if np.all(a == a[0]):
            continue
        seq, pseq = int(rng.integers(1, 9_000_000)), int(rng.integers(1, 900_000))
        text, n_lines = _bulk_lines(head, a, tail, seq, pseq)
        assert (text.decode("ascii"), n_lines) == reference_lines(head, a, tail, seq, pseq)


def test_files_with_and_without_the_array_path_are_identical(monkeypatch):
    rng = np.random.default_rng(11)
    records = []
    for scale in (1e-5, 1.0, 3e4):
        n, m = 23, 17
        U = np.r_[[0.0] * 4, np.sort(rng.uniform(0, 1, n - 4)), [1.0] * 4]
        V = np.r_[[0.0] * 4, np.sort(rng.uniform(0, 1, m - 4)), [1.0] * 4]
        P = scale * rng.normal(size=(n, m, 3))
        P[3, 4] = [0.0, -0.0, 2.0]
        records.append(surface_from_geometry(BSplineSurface(3, 3, U, V, P, rng.uniform(0.5, 2, (n, m)))))
        records.append(surface_from_geometry(BSplineSurface(3, 3, U, V, P)))
        K = np.r_[[0.0] * 4, np.linspace(0, 1, 100)[1:-1], [1.0] * 4]
        records.append(curve_from_geometry(BSplineCurve(3, K, scale * rng.normal(size=(102, 3)))))
    when = datetime.datetime(2026, 11, 24, 12, 0, 0, tzinfo=datetime.timezone.utc)
    fast = to_string(records, units="m", timestamp=when)
    monkeypatch.setattr(writer, "_bulk_parts", lambda entity, resolution: None)
    assert to_string(records, units="m", timestamp=when) == fast


def test_surface_flags_from_the_net_agree_with_the_evaluated_corners(monkeypatch):
    """The shortcut that settles an open surface from its clamped net's corners gives the
    flags of the evaluated corners, for open, closed, nearly closed and unclamped nets."""
    from bladesmith.iges import validate

    rng = np.random.default_rng(5)
    surfaces = []
    for _ in range(12):
        n, m = 9, 7
        U = np.r_[[0.0] * 4, np.sort(rng.uniform(0, 1, n - 4)), [1.0] * 4]
        V = np.r_[[0.0] * 4, np.sort(rng.uniform(0, 1, m - 4)), [1.0] * 4]
        P = rng.normal(size=(n, m, 3))
        surfaces.append(BSplineSurface(3, 3, U, V, P.copy()))
        closed = P.copy()
        closed[-1] = closed[0]  # closed in u
        surfaces.append(BSplineSurface(3, 3, U, V, closed))
        near = P.copy()
        near[-1, :] = near[0, :] + 0.9e-7  # within the resolution
        near[:, -1] = near[:, 0] + 0.5e-7
        surfaces.append(BSplineSurface(3, 3, U, V, near))
        apart = P.copy()
        apart[-1, :] = apart[0, :] + 1.5e-7  # just beyond it
        surfaces.append(BSplineSurface(3, 3, U, V, apart))
        surfaces.append(BSplineSurface(3, 3, np.linspace(0, 1, n + 4), V, P))  # unclamped in u
    records = [surface_from_geometry(s) for s in surfaces]
    fast = [validate.surface_flags(r, 1e-7) for r in records]
    monkeypatch.setattr(validate, "_corners_apart", lambda surface, resolution: False)
    slow = [validate.surface_flags(r, 1e-7) for r in records]
    assert fast == slow
    assert {f[0] for f in slow} == {0, 1} and {f[1] for f in slow} == {0, 1}
