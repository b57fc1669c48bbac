"""NREL 5-MW mold halves through OpenCASCADE: 128 surfaces and 126 parting lines read with
zero fail/warning messages, valid faces, and the faces sew at 1e-7 m into one shell whose
free edges lie only at the root (r = 1.5 m) and the tip (r = 63 m)."""
from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("OCP")

from bladesmith.geometry.mold import build_blade, load_preset  # noqa: E402
from bladesmith.iges.mold import write_molds  # noqa: E402
from bladesmith.iges import read_iges  # noqa: E402
from bladesmith.iges.records import BSplineCurve126, BSplineSurface128  # noqa: E402
from occ_support import is_valid, read_with_occ  # noqa: E402

MM_PER_M = 1000.0  # OCC works in millimetres
SEWING_TOL = 1e-7  # m (issue 7)
END_TOL = 1e-6  # m: a free edge lies at the root or tip plane within this


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    molds = build_blade(load_preset("NREL5MW"), fairness=False, single=False)
    path = tmp_path_factory.mktemp("mold") / "nrel5mw_molds.igs"
    write_molds(path, molds)
    return molds, path, read_with_occ(path)


def test_records(case):
    molds, path, _ = case
    ents = read_iges(path).entities
    assert sum(isinstance(e, BSplineSurface128) for e in ents) == len(molds.surfaces)
    assert sum(isinstance(e, BSplineCurve126) for e in ents) == len(molds.parting_lines)


def test_occ_reads_without_messages(case):
    occ = case[2]
    assert occ.load_messages == [] and occ.transfer_messages == []


def test_valid_faces(case):
    molds, _, occ = case
    assert len(occ.faces) == len(molds.surfaces)
    assert all(is_valid(f) for f in occ.faces)


def test_halves_sew_into_one_shell_open_only_at_root_and_tip(case):
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer

    molds, _, occ = case
    sewing = BRepBuilderAPI_Sewing(SEWING_TOL * MM_PER_M)
    for f in occ.faces:
        sewing.Add(f)
    sewing.Perform()
    shells = 0
    exp = TopExp_Explorer(sewing.SewedShape(), TopAbs_SHELL)
    while exp.More():
        shells += 1
        exp.Next()
    assert shells == 1
    assert sewing.NbMultipleEdges() == 0
    r_root, r_tip = molds.definition.stations[0].r, molds.definition.stations[-1].r
    ends = set()
    for i in range(1, sewing.NbFreeEdges() + 1):
        c = BRepAdaptor_Curve(sewing.FreeEdge(i))
        ts = np.linspace(c.FirstParameter(), c.LastParameter(), 7)
        z = np.array([c.Value(t).Z() for t in ts]) / MM_PER_M
        at_root, at_tip = np.all(np.abs(z - r_root) < END_TOL), np.all(np.abs(z - r_tip) < 0.5)
        assert at_root or at_tip, f"free edge {i} at z = {z}"
        ends.add("root" if at_root else "tip")
    print(f"\nsewing: 1 shell, {sewing.NbFreeEdges()} free edges at {sorted(ends)}")
    assert ends == {"root", "tip"}


def test_units_scale_the_coordinates(tmp_path):
    """A file in millimetres holds coordinates 1000 times those in metres."""
    from bladesmith.geometry.mold import build_blade, load_preset
    from bladesmith.iges import read_iges

    molds = build_blade(load_preset("S823_SMALL"), fairness=False)
    metres, millimetres = tmp_path / "m.igs", tmp_path / "mm.igs"
    write_molds(metres, molds, units="m")
    write_molds(millimetres, molds, units="mm")
    a = {r.label: r for r in read_iges(metres).roots}
    b = {r.label: r for r in read_iges(millimetres).roots}
    assert read_iges(millimetres).header.unit_name == "MM"
    for label, record in a.items():
        assert np.allclose(np.asarray(b[label].control_points), 1000.0 * np.asarray(record.control_points), rtol=1e-15)
