"""The reader's and the trimmed-face mesher's fast paths give what the plain ones give.

* A long run of reals is parsed with one numpy call per record (reader ``_Tokens``): the
  values must be those of ``float`` on every parameter, defaults and errors included; the
  oracle is the same text read with the bulk path switched off.
* The even-odd test ``inside`` forms only the crossing (point, edge) pairs: it must agree
  with the all-pairs rule on points lying on vertices, on edges and on horizontal edges,
  whatever the chunk size.
"""
from __future__ import annotations

import datetime as dt

import numpy as np
import pytest

from bladesmith.geometry.errors import IgesError
from bladesmith.iges import BSplineCurve126, parse_iges, to_string
from bladesmith.iges import reader as R
from bladesmith.iges import tessellate as T

STAMP = dt.datetime(2024, 1, 2, 3, 4, 5)


def curve(n=40):
    rng = np.random.default_rng(11)
    knots = np.concatenate([[0.0] * 4, np.linspace(0, 1, n - 2)[1:-1], [1.0] * 4])
    P = rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-6, 6, size=(n, 1))
    return BSplineCurve126(degree=3, knots=knots, control_points=P)


def tampered(entity, old, new):
    """The file of ``entity`` with the first ``old`` of its parameter data replaced."""
    from bladesmith.iges import writer

    real = writer._pd

    def fake(e, de, resolution):
        text = real(e, de, resolution)
        assert old in text
        return text.replace(old, new, 1)

    writer._pd = fake
    try:
        return to_string([entity], timestamp=STAMP)
    finally:
        writer._pd = real


def read_both(text, monkeypatch):
    """(bulk, plain): the control points read with the numpy bulk path and without it."""
    bulk = parse_iges(text).entities[0]
    with monkeypatch.context() as m:
        m.setattr(R, "_BULK_MIN", 10**9)
        plain = parse_iges(text).entities[0]
    return bulk, plain


def test_bulk_reals_are_float_of_every_parameter(monkeypatch):
    c = curve()
    text = to_string([c], timestamp=STAMP)
    bulk, plain = read_both(text, monkeypatch)
    for name in ("knots", "weights", "control_points"):
        got = getattr(bulk, name)
        assert got.tobytes() == getattr(plain, name).tobytes(), name
        assert got.tobytes() == np.asarray(getattr(c, name), dtype=np.float64).tobytes(), name
    x = repr(float(c.control_points[5, 1]))
    variants = [
        (x, " " + x + "  "),  # blanks around a parameter
        (x, " "),  # a blank parameter is defaulted (0.0); numpy alone would read -1
        (x, "   "),
        (x, "-1.0"),  # a true -1 among the values
        (x, ""),  # an empty one too
        (x, x.replace("e", "D") if "e" in x else x + "D0"),  # Fortran exponent letter
        (x, x.replace("e", "d") if "e" in x else x + "d+00"),
        (x, "00" + x.lstrip("-") if not x.startswith("-") else "-00" + x[1:]),
    ]
    for old, new in variants:
        text = tampered(c, "," + old + ",", "," + new + ",")
        bulk, plain = read_both(text, monkeypatch)
        assert bulk.control_points.tobytes() == plain.control_points.tobytes(), (old, new)
        assert bulk.knots.tobytes() == plain.knots.tobytes()
    default = tampered(c, "," + x + ",", ", ,")
    assert parse_iges(default).entities[0].control_points[5, 1] == 0.0


@pytest.mark.parametrize("bad", ["1.2.3", "nan", "inf", "1e999", "0x10", "1 2", "+-1", "--1", "e5", "."])
def test_a_bad_parameter_in_a_bulk_run_is_named(bad):
    c = curve()
    x = repr(float(c.control_points[7, 2]))
    text = tampered(c, "," + x + ",", "," + bad + ",")
    with pytest.raises(IgesError, match=r"control points\[23\]: expected a finite real number") as info:
        parse_iges(text)
    assert info.value.line is not None


def brute_inside(points, loops):
    """The even-odd rule over every (point, edge) pair, the reference for ``inside``."""
    A = np.concatenate(loops)
    B = np.concatenate([np.roll(l, -1, axis=0) for l in loops])
    px, py = points[:, :1], points[:, 1:]
    x1, y1, x2, y2 = A[:, 0], A[:, 1], B[:, 0], B[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        cross = (y1 > py) != (y2 > py)
        xint = x1 + (py - y1) * ((x2 - x1) / (y2 - y1))
    return np.count_nonzero(cross & (px < xint), axis=1) % 2 == 1


@pytest.mark.parametrize("chunk", [T.PAIR_CHUNK, 1, 37])
def test_inside_agrees_with_all_pairs_on_vertices_and_edges(monkeypatch, chunk):
    monkeypatch.setattr(T, "PAIR_CHUNK", chunk)
    rng = np.random.default_rng(5)
    for k in range(60):
        m = int(rng.integers(3, 30))
        ang = np.sort(rng.random(m)) * 2 * np.pi
        outer = np.c_[np.cos(ang), np.sin(ang)] * (1 + rng.random(m))[:, None]
        if k % 2:  # on a lattice: horizontal edges, points exactly on vertices and edges
            outer = np.round(outer * 4) / 4
        hole = 0.3 * outer[::-1]
        pts = np.concatenate([rng.uniform(-2, 2, (300, 2)), outer, hole,
                              np.round(rng.uniform(-2, 2, (300, 2)) * 8) / 8,
                              0.5 * (outer + np.roll(outer, -1, axis=0))])
        loops = [outer, hole]
        assert np.array_equal(T.inside(pts, loops), brute_inside(pts, loops)), k


def test_jittered_triangulation_never_folds_over_close_loop_points(monkeypatch):
    """Qhull sees the points jittered; loop points closer together than the jitter must
    not leave folded (inverted, overlapping) triangles in the mesh of the unmoved points."""
    monkeypatch.setattr(T, "JITTER", 1e-5)  # far beyond the 1e-9 gaps below

    def plane(u, v):
        u, v = np.broadcast_arrays(u, v)
        return np.stack([u, v, np.zeros_like(u)], axis=-1)

    t = np.linspace(0, 1, 40, endpoint=False)
    gap = 1e-9 * np.arange(1, 8)
    # a square whose sides carry clusters of points 1e-9 apart, offset across the side too
    side = np.sort(np.concatenate([t, 0.5 + gap, 0.25 + gap]))
    wob = np.where((side > 0.25) & (side < 0.26) | (side > 0.5) & (side < 0.51), 1e-9, 0.0)
    outer = np.concatenate([np.c_[side, wob], np.c_[1 - wob, side], np.c_[1 - side, 1 - wob], np.c_[wob, 1 - side]])
    mesh = T.tessellate(plane, [outer], 1e-3, 5000)
    uv, tri = mesh.uv, mesh.triangles
    e1, e2 = uv[tri[:, 1]] - uv[tri[:, 0]], uv[tri[:, 2]] - uv[tri[:, 0]]
    signed = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    # consistently oriented, and covering the unit square once
    signed = signed * np.sign(signed.sum())
    assert abs(np.abs(signed).sum() - 1.0) < 1e-9
    assert abs(signed.sum() - 1.0) < 1e-9


@pytest.mark.parametrize("extended", ["native", "none"])
def test_bulk_reals_round_like_float_near_midpoints_and_at_the_ends_of_the_range(extended, monkeypatch):
    """Where numpy reads in x87 extended precision and rounds to double (``_EXTENDED``),
    rounding twice must give what one correct rounding (``float``) gives: decimals just
    off the midpoint between two doubles are the cases where it would not. "none" runs
    the double parse that CPUs without the x87 type (aarch64, Windows) use."""
    if extended == "none":
        monkeypatch.setattr(R, "_EXTENDED", None)
    from decimal import Decimal, localcontext

    rng = np.random.default_rng(3)
    x = rng.uniform(-1, 1, 3000) * 10.0 ** rng.integers(-30, 30, 3000)
    records = [
        ["%.17g" % v for v in x],  # the writer's format: no midpoint is near
        ["%.6g" % v for v in x] + [repr(float(v)) for v in x] + ["%.3f" % v for v in x[:500]],
        ["2.2250738585072014e-308", "4.9e-324", "1e-310", "1.7976931348623157e308", "0.0", "-0.0"] * 3,
    ]
    def near_midpoints(values):
        out = []
        with localcontext() as ctx:
            ctx.prec = 1200
            for v in values:
                d, e = Decimal(float(v)), Decimal(float(np.nextafter(v, np.inf)))
                mid, step = (d + e) / 2, (e - d) / 2**80  # far below one unit of 64 bits
                out += [str(mid + step), str(mid - step), str(mid)]
        return out

    records.append(near_midpoints(x[:400]))
    # subnormal doubles have fewer bits: their midpoints are not those of normal ones
    records.append(near_midpoints([1e-310, 2.5e-315, 7.1e-320, 1.5e-323, -3.3e-312, 5e-324]))
    records.append(near_midpoints([0.0, -5e-324]))  # rounding to zero or to the least subnormal
    for tokens in records:
        a = R._Tokens(",".join(tokens), ",").reals_from(0)
        ref = np.array([float(t) for t in tokens])
        assert a is not None and a.tobytes() == ref.tobytes()
