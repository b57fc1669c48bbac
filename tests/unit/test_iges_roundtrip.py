"""IGES writer/reader round trips, file layout and conversion to geometry (no OCC)."""
from __future__ import annotations

import datetime as dt
import math
import re

import numpy as np
import pytest

from bladesmith.geometry.nurbs import BSplineCurve, BSplineSurface
from bladesmith.iges import (
    BSplineCurve126,
    BSplineSurface128,
    CircularArc,
    CompositeCurve,
    Line,
    SurfaceOfRevolution,
    TransformationMatrix,
    TrimmedSurface,
    curve_from_geometry,
    format_real,
    make_header,
    parse_iges,
    read_iges,
    surface_from_geometry,
    to_geometry,
    to_string,
    write_iges,
)
from bladesmith.iges.convert import curve_points, surface_points
from bladesmith.iges.examples import (
    bicubic_spline_114,
    cubic_spline_112,
    random_curve,
    random_surface,
    trimmed_cylinder_band,
    trimmed_plane_with_hole,
)

STAMP = dt.datetime(2024, 5, 17, 13, 45, 9)


def sample_models():
    rng = np.random.default_rng(11)
    band, _ = trimmed_cylinder_band()
    plane, _ = trimmed_plane_with_hole()
    surf = surface_from_geometry(random_surface(rng))
    poly = surface_from_geometry(random_surface(rng, rational=False, shape=(5, 5), degrees=(2, 3)))
    curve = curve_from_geometry(random_curve(rng))
    spline_surface = bicubic_spline_114(rng)
    moved = Line([0.0, 0.0, 0.0], [1.0, 2.0, 3.0], transform=TransformationMatrix(
        np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]), [1.0, 2.0, 3.0]))
    arc = CircularArc([1.0, 2.0], [3.0, 2.0], [1.0, 4.0], z=0.5)
    rev = SurfaceOfRevolution(Line([0, 0, 0], [0, 0, 1.0]), curve_from_geometry(random_curve(rng)), 0.1, 5.0)
    return {
        "band": [band], "plane": [plane], "rational surface": [surf], "polynomial surface": [poly],
        "curve": [curve], "112": [cubic_spline_112(rng)], "114": [spline_surface],
        "transformed line": [moved], "arc": [arc], "revolution": [rev],
        "everything": [band, plane, surf, poly, curve, spline_surface, moved, arc, rev],
    }


MODELS = sample_models()


@pytest.mark.parametrize("name", sorted(MODELS))
def test_write_read_write_is_byte_identical(name, tmp_path):
    path = tmp_path / "a.igs"
    write_iges(path, MODELS[name], timestamp=STAMP, author="A. Author, Esq.", organization="Bladesmith")
    first = path.read_bytes()
    model = read_iges(path)
    write_iges(tmp_path / "b.igs", model)
    assert (tmp_path / "b.igs").read_bytes() == first
    assert to_string(parse_iges(first)) == first.decode("ascii")


@pytest.mark.parametrize("name", sorted(MODELS))
def test_file_layout(name):
    text = to_string(MODELS[name], timestamp=STAMP)
    lines = text.split("\n")
    assert lines[-1] == ""
    lines = lines[:-1]
    assert all(len(line) == 80 for line in lines)
    counts = {}
    order = "SGDPT"
    last = 0
    for line in lines:
        code = line[72]
        assert order.index(code) >= last
        last = order.index(code)
        counts[code] = counts.get(code, 0) + 1
        assert int(line[73:]) == counts[code]
    t = lines[-1]
    assert t[:32] == f"S{counts['S']:7d}G{counts['G']:7d}D{counts['D']:7d}P{counts['P']:7d}"
    d = [line for line in lines if line[72] == "D"]
    p = [line for line in lines if line[72] == "P"]
    for i in range(0, len(d), 2):
        ptr, count = int(d[i][8:16]), int(d[i + 1][24:32])
        assert d[i][:8] == d[i + 1][:8]
        block = p[ptr - 1 : ptr - 1 + count]
        assert all(int(line[65:72]) == i + 1 for line in block)  # back-pointers
        assert all(line[64] == " " for line in block)
        data = "".join(line[:64] for line in block)
        assert data.split(",")[0] == d[i][:8].strip()
        assert data.rstrip().endswith(";") and data.count(";") == 1


def test_reals_round_trip_and_have_a_decimal_point():
    rng = np.random.default_rng(0)
    values = np.concatenate([
        rng.normal(size=2000), rng.normal(size=500) * 1e-9, rng.normal(size=500) * 1e20,
        rng.integers(-50, 50, 300).astype(float),
        [0.0, -0.0, 1e-4, 9.99e-5, 1e16, 1e17, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308, 0.1],
    ])
    from bladesmith.iges.writer import _reals

    for text in (_reals(values), ",".join(format_real(v) for v in values)):
        tokens = text.split(",")
        assert [float(t) for t in tokens] == values.tolist()
        assert all(re.fullmatch(r"-?\d+\.\d*(E[+-]\d+)?", t) for t in tokens), tokens[:5]
    assert format_real(1e-5) == "1.E-05" and format_real(0.5) == "0.5"


def records_match(a, b):
    assert type(a) is type(b)
    for name in a.__dataclass_fields__:
        if name in ("directory",):
            continue
        x, y = getattr(a, name), getattr(b, name)
        if isinstance(x, np.ndarray):
            assert np.array_equal(x, y), name
        elif isinstance(x, tuple) and x and hasattr(x[0], "type_number"):
            assert len(x) == len(y)
            for u, w in zip(x, y):
                records_match(u, w)
        elif hasattr(x, "type_number"):
            records_match(x, y)
        elif name in ("start", "end", "u_range", "v_range") and x is None:
            continue  # written as the knot domain, read back explicitly
        else:
            assert x == y, name


@pytest.mark.parametrize("name", ["band", "plane", "rational surface", "curve", "112", "114", "arc", "revolution"])
def test_records_read_back_exactly(name):
    model = parse_iges(to_string(MODELS[name]))
    roots = model.roots
    assert len(roots) == len(MODELS[name])
    for a, b in zip(MODELS[name], roots):
        records_match(a, b)


def test_global_section_fields():
    band, _ = trimmed_cylinder_band()
    for units, flag, name in (("m", 6, "M"), ("mm", 2, "MM"), ("inch", 1, "IN")):
        text = to_string([band], units=units, resolution=2.5e-8, timestamp=STAMP, file_name="x.igs")
        h = parse_iges(text).header
        assert (h.unit_flag, h.unit_name, h.resolution, h.model_scale) == (flag, name, 2.5e-8, 1.0)
        assert h.version_flag == 11 and h.created == "20240517.134509"
        # an upper bound from the control hulls (the rim arcs' middle points at 2 / cos(1.25)),
        # never from parameter-space curves
        assert 3.0 <= h.max_coordinate <= 2.0 / math.cos(1.25)
        assert h.file_name == "x.igs"


def test_long_and_awkward_strings_in_the_global_section():
    author = "Ann, O'Neil; " * 12  # longer than a line, with both delimiters inside
    text = to_string(MODELS["curve"], author=author, organization="H1H,2H;;", timestamp=STAMP)
    h = parse_iges(text).header
    assert h.author == author and h.organization == "H1H,2H;;"


def test_status_numbers_mark_dependants_and_parameter_space_curves():
    text = to_string(MODELS["band"], timestamp=STAMP)
    d = [line for line in text.split("\n") if line[72:73] == "D"]
    status = {}
    for i in range(0, len(d), 2):
        status.setdefault(int(d[i][:8]), set()).add(d[i][64:72])
    assert status[144] == {"00000000"}  # the one independent entity
    assert status[142] == {"00010000"}
    assert "00010500" in status[110] and "00010000" in status[110]  # 2-D and 3-D lines
    assert status[120] == {"00010000"}


def test_flags_are_truthful():
    rng = np.random.default_rng(3)
    c = random_curve(rng, rational=True)
    text = to_string([curve_from_geometry(c)])
    params = text.split("\n")[[i for i, ln in enumerate(text.split("\n")) if ln[72:73] == "P"][0]].split(",")
    assert params[:7] == ["126", str(c.n_control - 1), "3", "0", "0", "0", "0"]
    poly = random_curve(rng, rational=False)
    text = to_string([curve_from_geometry(poly)])
    line = [ln for ln in text.split("\n") if ln[72:73] == "P"][0]
    assert line.split(",")[3:7] == ["0", "0", "1", "0"]
    # a closed planar circle made of one 126 with a double knot: closed, planar, rational, periodic (C1)
    s2 = math.sqrt(0.5)
    d = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]], float)
    circle = BSplineCurve126(2, [0, 0, 0, .25, .25, .5, .5, .75, .75, 1, 1, 1], d, [1, s2, 1, s2, 1, s2, 1, s2, 1])
    line = [ln for ln in to_string([circle]).split("\n") if ln[72:73] == "P"][0]
    assert line.split(",")[3:7] == ["1", "1", "0", "1"]


def test_conversion_to_geometry_is_exact():
    rng = np.random.default_rng(5)
    s = random_surface(rng)
    rec = parse_iges(to_string([surface_from_geometry(s)])).roots[0]
    g = to_geometry(rec)
    u = rng.uniform(*s.domain_u, 50)
    v = rng.uniform(*s.domain_v, 50)
    assert np.array_equal(g.evaluate(u, v), s.evaluate(u, v))
    c = random_curve(rng)
    g = to_geometry(parse_iges(to_string([curve_from_geometry(c)])).roots[0])
    t = rng.uniform(*c.domain, 50)
    assert np.array_equal(g.evaluate(t), c.evaluate(t))


def test_112_114_100_and_120_convert_to_the_same_points():
    rng = np.random.default_rng(6)
    spline = cubic_spline_112(rng)
    t = np.linspace(spline.breakpoints[0], spline.breakpoints[-1], 41)
    g = to_geometry(spline)
    assert np.allclose(g.evaluate(t), curve_points(spline, t), atol=1e-12)
    sps = MODELS["114"][0]
    g = to_geometry(sps)
    u, v = rng.uniform(0, 1.2, 30), rng.uniform(0, 1, 30)
    assert np.allclose(g.evaluate(u, v), surface_points(sps, u, v), atol=1e-12)
    arc = MODELS["arc"][0]
    g = to_geometry(arc)
    P = g.evaluate(np.linspace(*g.domain, 33))
    assert np.allclose(np.hypot(P[:, 0] - 1.0, P[:, 1] - 2.0), 2.0, atol=1e-14) and np.allclose(P[:, 2], 0.5)
    rev = MODELS["revolution"][0]
    g = to_geometry(rev)
    # every point of the NURBS surface lies on the revolution: radius and height of the generatrix
    gen = to_geometry(rev.generatrix)
    us = np.linspace(*g.domain_u, 17)
    G = gen.evaluate(us)
    S = g.evaluate_grid(us, np.linspace(*g.domain_v, 23))
    assert np.allclose(np.hypot(S[..., 0], S[..., 1]), np.hypot(G[:, 0], G[:, 1])[:, None], atol=1e-12)
    assert np.allclose(S[..., 2], G[:, 2][:, None], atol=1e-12)
    # at the arc joints (knots) the v parameter is the angle itself
    assert np.allclose(g.evaluate(us[3], 5.0), surface_points(rev, us[3], 5.0), atol=1e-12)


def test_transform_is_applied_in_geometry():
    line = MODELS["transformed line"][0]
    g = to_geometry(parse_iges(to_string([line])).roots[0])
    assert np.allclose(g.evaluate(1.0), [1.0 - 2.0, 2.0 + 1.0, 3.0 + 3.0])


def test_trimmed_surface_geometry():
    model = parse_iges(to_string(MODELS["band"]))
    (record, geo), = model.to_geometry()
    assert isinstance(record, TrimmedSurface)
    assert len(geo.outer) == 4 and len(geo.inner) == 1 and len(geo.inner[0]) == 4
    assert all(c.dim == 2 for c in geo.outer)


def test_header_is_reused_when_writing_a_read_model():
    model = parse_iges(to_string(MODELS["curve"], units="mm", resolution=1e-5, timestamp=STAMP))
    text = to_string(model)
    assert parse_iges(text).header == model.header


def test_curve_from_2d_geometry_gets_z_zero():
    c = BSplineCurve(2, [0, 0, 0, 1, 1, 1], [[0, 0], [1, 1], [2, 0]])
    rec = curve_from_geometry(c)
    assert rec.control_points.shape == (3, 3) and np.all(rec.control_points[:, 2] == 0)


def test_units_scale_in_conversion():
    s = BSplineSurface(1, 1, [0, 0, 1, 1], [0, 0, 1, 1], np.arange(12.0).reshape(2, 2, 3))
    assert np.array_equal(surface_from_geometry(s, scale=1000.0).control_points, s.control_points * 1000)
    assert make_header(units="MM").unit_flag == 2
