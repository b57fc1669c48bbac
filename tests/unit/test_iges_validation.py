"""The writer refuses inconsistent data before writing, and writes atomically."""
from __future__ import annotations

import math
import os

import numpy as np
import pytest

from bladesmith.geometry.errors import BladesmithError, IgesError
from bladesmith.iges import (
    BSplineCurve126,
    BSplineSurface128,
    CompositeCurve,
    CurveOnSurface,
    GenericEntity,
    Line,
    SurfaceOfRevolution,
    TrimmedSurface,
    to_string,
    write_iges,
)
from bladesmith.iges import writer as writer_module
from bladesmith.iges.examples import circle_loop, trimmed_cylinder_band, trimmed_plane_with_hole


def plane():
    return BSplineSurface128(1, 1, [0, 0, 1, 1], [0, 0, 1, 1], [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]]])


def square(a=0.0, b=1.0, gap=0.0):
    return CompositeCurve([Line([a, a], [b, a]), Line([b, a], [b, b]), Line([b, b], [a, b]), Line([a, b], [a, a + gap])])


def refused(entities, match, tmp_path=None, **options):
    with pytest.raises(IgesError, match=match):
        to_string(entities, **options)
    if tmp_path is not None:
        target = tmp_path / "x.igs"
        with pytest.raises(IgesError, match=match):
            write_iges(target, entities, **options)
        assert not target.exists()
        assert os.listdir(tmp_path) == []  # not even a temporary file


def test_knot_count(tmp_path):
    c = BSplineCurve126(3, [0, 0, 0, 0, 0.5, 1, 1, 1], np.zeros((5, 3)) + np.arange(5)[:, None])
    refused([c], r"expected 9 knots", tmp_path)
    s = BSplineSurface128(1, 1, [0, 0, 1, 1, 1], [0, 0, 1, 1], np.zeros((2, 2, 3)))
    refused([s], r"expected 4 u knots", tmp_path)


def test_decreasing_knots_and_bad_weights():
    P = np.arange(12.0).reshape(4, 3)
    refused([BSplineCurve126(2, [0, 0, 0, 0.7, 0.5, 1, 1], P)], "non-decreasing")
    refused([BSplineCurve126(2, [0, 0, 0, 0.5, 1, 1, 1], P, [1, 0, 1, 1])], r"weights must be > 0")
    refused([BSplineCurve126(2, [0, 0, 0, 0.5, 1, 1, 1], P, [1, np.nan, 1, 1])], r"not finite")
    refused([BSplineCurve126(30, [0] * 31 + [1] * 31, np.ones((31, 3)))], r"degree must be in 1..25")


def test_parameter_ranges():
    P = np.arange(12.0).reshape(4, 3)
    refused([BSplineCurve126(2, [0, 0, 0, 0.5, 1, 1, 1], P, start=-0.5, end=1.0)], r"outside the knot domain")
    refused([BSplineCurve126(2, [0, 0, 0, 0.5, 1, 1, 1], P, start=0.6, end=0.2)], r"empty")
    refused([BSplineSurface128(1, 1, [0, 0, 1, 1], [0, 0, 1, 1], np.zeros((2, 2, 3)), u_range=(0, 2))],
            r"u range .* outside")
    axis = Line([0, 0, 0], [0, 0, 1])
    gen = Line([1, 0, 0], [1, 0, 1])
    refused([SurfaceOfRevolution(axis, gen, 0.0, 7.0)], r"end angle <= start \+ 2 pi")
    refused([SurfaceOfRevolution(Line([0, 0, 0], [0, 0, 0]), gen, 0.0, 1.0)], r"distinct start and end")


def test_trimming_curve_outside_the_parameter_domain(tmp_path):
    s = plane()
    hole = CurveOnSurface(s, circle_loop([0.9, 0.5], 0.2), None)
    refused([TrimmedSurface(s, None, [hole])], r"leaves the surface's parameter domain", tmp_path)
    outer = CurveOnSurface(s, square(0.0, 1.2), None)
    refused([TrimmedSurface(s, outer, [])], r"leaves the surface's parameter domain")


def test_loops_must_close_within_the_resolution(tmp_path):
    s = plane()
    open_loop = CurveOnSurface(s, square(gap=1e-5), None)
    refused([TrimmedSurface(s, open_loop, [])], r"not closed", tmp_path, resolution=1e-7)
    to_string([TrimmedSurface(s, open_loop, [])], resolution=1e-4)  # within a coarser resolution
    broken = CompositeCurve([Line([0, 0], [1, 0]), Line([1, 0.001], [1, 1]), Line([1, 1], [0, 0])])
    refused([TrimmedSurface(s, CurveOnSurface(s, broken, None), [])], r"constituents 0 and 1 do not meet")


def test_model_curve_must_match_and_close():
    s = plane()
    b = square()
    c_wrong = CompositeCurve([Line([0, 0, 1], [1, 0, 1]), Line([1, 0, 1], [1, 1, 1]),
                              Line([1, 1, 1], [0, 1, 1]), Line([0, 1, 1], [0, 0, 1])])
    refused([TrimmedSurface(s, CurveOnSurface(s, b, c_wrong, preferred=3), [])], r"model-space curve starts")


def test_structural_errors():
    s = plane()
    other = plane()
    refused([TrimmedSurface(s, CurveOnSurface(other, square(), None), [])], r"different surface")
    refused([TrimmedSurface(Line([0, 0, 0], [1, 0, 0]), None, [])], r"surface must be one of")
    refused([CompositeCurve([])], r"at least one constituent")
    refused([CurveOnSurface(s, None, None)], r"needs a parameter-space curve")
    refused([CurveOnSurface(s, square(), None, preferred=3)], r"PREF = 3 names a curve")
    refused([GenericEntity(entity_type=406, parameters=("1",))], r"cannot be written")
    refused([Line([0, 0, 0], [1, 1, 1], label="much too long")], r"at most 8 characters")
    refused([Line([0, 0, 0], [0, 0, 0])], r"distinct start and end")
    refused(["not a record"], r"expected an IGES record")
    refused([Line([0, 0, 0], [1, 1, 1])], r"unknown units", units="furlong")
    refused([Line([0, 0, 0], [1, 1, 1])], r"resolution .* must be > 0", resolution=0.0)
    refused([Line([0, 0, 0], [1, 1, 1])], r"printable ASCII", author="Åsa")


def test_valid_models_pass():
    for build in (trimmed_cylinder_band, trimmed_plane_with_hole):
        to_string([build()[0]])


def test_errors_are_of_the_project_family():
    with pytest.raises(BladesmithError):
        to_string([BSplineCurve126(2, [0, 1], np.zeros((3, 3)))])
    with pytest.raises(IgesError):
        BSplineCurve126(2, [0, 1], "not numbers")


# -- atomic writes -------------------------------------------------------------------------
def good_file(tmp_path):
    target = tmp_path / "blade.igs"
    write_iges(target, [trimmed_plane_with_hole()[0]])
    return target, target.read_bytes()


def test_failure_midway_through_serialisation_keeps_the_previous_file(tmp_path, monkeypatch):
    target, before = good_file(tmp_path)
    real_pd = writer_module._pd
    calls = []

    def exploding_pd(entity, de, resolution):
        calls.append(entity)
        if len(calls) == 3:
            raise IgesError("simulated failure in the middle of the parameter data")
        return real_pd(entity, de, resolution)

    monkeypatch.setattr(writer_module, "_pd", exploding_pd)
    band, _ = trimmed_cylinder_band()
    with pytest.raises(IgesError, match="simulated"):
        write_iges(target, [band])
    assert len(calls) == 3
    assert target.read_bytes() == before
    assert os.listdir(tmp_path) == ["blade.igs"]


def test_failure_while_writing_the_file_keeps_the_previous_file(tmp_path, monkeypatch):
    target, before = good_file(tmp_path)

    def failing_fsync(fd):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(writer_module.os, "fsync", failing_fsync)
    band, _ = trimmed_cylinder_band()
    with pytest.raises(IgesError, match="No space left"):
        write_iges(target, [band])
    assert target.read_bytes() == before
    assert os.listdir(tmp_path) == ["blade.igs"]


def test_interrupt_while_replacing_keeps_the_previous_file(tmp_path, monkeypatch):
    target, before = good_file(tmp_path)

    def interrupted(src, dst):
        raise KeyboardInterrupt

    monkeypatch.setattr(writer_module.os, "replace", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_iges(target, [trimmed_cylinder_band()[0]])
    assert target.read_bytes() == before
    assert os.listdir(tmp_path) == ["blade.igs"]


def test_successful_write_replaces_the_file(tmp_path):
    target, before = good_file(tmp_path)
    write_iges(target, [trimmed_cylinder_band()[0]])
    assert target.read_bytes() != before
    assert os.listdir(tmp_path) == ["blade.igs"]


def test_unwritable_folder_is_an_iges_error(tmp_path):
    with pytest.raises(IgesError, match="cannot write the file.*No such file or directory"):
        write_iges(tmp_path / "missing" / "x.igs", [Line([0, 0, 0], [1, 0, 0])])


def test_angles_of_revolution_are_radians():
    band, area = trimmed_cylinder_band(start_angle=0.0, end_angle=math.pi / 2)
    text = to_string([band])
    assert ",0.0,1.5707963267948966;" in text


def test_the_package_never_imports_bpy():
    import ast
    import pathlib

    root = pathlib.Path(__file__).resolve().parents[2] / "iges"
    for path in root.glob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            assert not any(n == "bpy" or n.startswith("bpy.") for n in names), path


def test_written_files_get_ordinary_permissions(tmp_path):
    """The temporary file is private; the result gets the mode open() would give it, or
    keeps the mode of the file it replaces."""
    import os
    import stat

    from bladesmith.iges import curve_from_geometry, write_iges
    from bladesmith.geometry.nurbs import BSplineCurve

    record = curve_from_geometry(BSplineCurve(1, [0, 0, 1, 1], [[0, 0, 0], [1, 0, 0]]))
    umask = os.umask(0o022)
    try:
        fresh = tmp_path / "fresh.igs"
        write_iges(fresh, [record])
        assert stat.S_IMODE(fresh.stat().st_mode) == 0o644
        kept = tmp_path / "kept.igs"
        kept.write_text("old")
        os.chmod(kept, 0o640)
        write_iges(kept, [record])
        assert stat.S_IMODE(kept.stat().st_mode) == 0o640
    finally:
        os.umask(umask)
