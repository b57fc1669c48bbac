"""The import against OpenCASCADE: units and placement cases come in at OCC's size and
place; a small slice of the public corpus (tests/iges/corpus_manifest.toml) is compared
face by face. The whole corpus table: ``python tests/iges/corpus.py``."""
from __future__ import annotations

import importlib.util
import pathlib
import sys

import numpy as np
import pytest

from bladesmith.iges.importer import import_path

HERE = pathlib.Path(__file__).resolve().parent


def _load(name, path):
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


C = _load("import_cases", HERE.parent / "unit" / "import_cases.py")
corpus = _load("iges_corpus", HERE / "corpus.py")


def ours_box(report):
    P = np.concatenate([corpus._item_points(it) for it in report.items])
    return np.array([P.min(axis=0), P.max(axis=0)])


def compare_with_occ(tmp_path, text, name="case.igs"):
    path = tmp_path / name
    path.write_text(text)
    occ_faces, occ_box, _ = corpus.occ_summary(path)
    report = import_path(path)
    return report, ours_box(report), occ_faces, occ_box


@pytest.mark.parametrize("case", sorted(C.UNIT_CASES))
def test_units_match_opencascade(tmp_path, case):
    changes, metres = C.UNIT_CASES[case]
    text = C.set_global(C.line_file(1000.0), **changes)
    report, box, _, occ_box = compare_with_occ(tmp_path, text)
    assert np.isclose(box[1, 0], 1000.0 * metres, rtol=1e-12)
    assert np.abs(box - occ_box).max() <= 1e-6 * np.linalg.norm(occ_box[1] - occ_box[0]), (box, occ_box)


@pytest.mark.parametrize("case", ["composite", "nested composites", "subfigure instance", "trimmed with transforms",
                                  "plane face with hole", "tabulated cylinder face"])
def test_placement_matches_opencascade(tmp_path, case):
    text = {
        "composite": lambda: C.composite_with_transform()[0],
        "nested composites": lambda: C.nested_composites(3)[0],
        # scale 1: OpenCASCADE 7.x places a scaled 408 differently from IGES 5.3 (type 408)
        # (which the unit test checks); translation and the 408's matrix agree
        "subfigure instance": lambda: C.subfigure_instance(1.0)[0],
        "trimmed with transforms": lambda: C.trimmed_with_transforms()[0],
        "plane face with hole": lambda: C.plane_face_with_hole()[0],
        "tabulated cylinder face": lambda: C.tabulated_cylinder_face()[0],
    }[case]()
    report, box, occ_faces, occ_box = compare_with_occ(tmp_path, text)
    faces = report.counts.get("mesh", 0) + report.counts.get("surface", 0)
    assert faces == occ_faces
    diag = np.linalg.norm(occ_box[1] - occ_box[0])
    # exact entities (curves) to 1e-6 of the diagonal; meshes within their display tolerance
    tol = 1e-6 if faces == 0 else 2e-3
    assert np.abs(box - occ_box).max() <= tol * diag, (box, occ_box)


def _write_brep_iges(shape, path):
    """``shape`` written by OpenCASCADE as an IGES B-rep solid (186/5xx), in millimetres."""
    from OCP.IGESControl import IGESControl_Writer
    from OCP.Interface import Interface_Static

    before = Interface_Static.IVal_s("write.iges.brep.mode")
    try:
        Interface_Static.SetIVal_s("write.iges.brep.mode", 1)
        w = IGESControl_Writer("MM", 1)
        w.AddShape(shape)
        w.ComputeModel()
        assert w.Write(str(path))
    finally:
        Interface_Static.SetIVal_s("write.iges.brep.mode", before)


def _primitives_brep_iges(path):
    """A box, cylinder, cone to its apex, sphere and torus (placed apart, one rotated),
    written by OpenCASCADE as B-rep solids (186/510 faces on 190-198 surfaces)."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
    from OCP.BRepPrimAPI import (BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCone, BRepPrimAPI_MakeCylinder,
                                 BRepPrimAPI_MakeSphere, BRepPrimAPI_MakeTorus)
    from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec
    from OCP.TopoDS import TopoDS_Compound

    def at(x, y, z, d=(0, 0, 1)):
        return gp_Ax2(gp_Pnt(x, y, z), gp_Dir(*d))

    shapes = [BRepPrimAPI_MakeBox(gp_Pnt(-5, -5, -5), 10, 20, 30).Shape(),
              BRepPrimAPI_MakeCylinder(at(40, 0, 0, (1, 1, 0)), 6, 25).Shape(),
              BRepPrimAPI_MakeCone(at(0, 50, 0), 8, 0, 20).Shape(),
              BRepPrimAPI_MakeSphere(gp_Pnt(-30, 10, 5), 9).Shape(),
              BRepPrimAPI_MakeTorus(at(10, -40, 3, (0, 1, 1)), 12, 3).Shape()]
    trsf = gp_Trsf()
    trsf.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(1, 2, 3)), 0.7)
    trsf.SetTranslationPart(gp_Vec(3, -2, 7))
    shapes[1] = BRepBuilderAPI_Transform(shapes[1], trsf, True).Shape()
    comp, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(comp)
    for s in shapes:
        builder.Add(comp, s)
    _write_brep_iges(comp, path)


def test_analytic_surfaces_of_a_brep_solid_match_opencascade(tmp_path):
    path = tmp_path / "primitives.igs"
    _primitives_brep_iges(path)
    occ_faces, occ_box, _ = corpus.occ_summary(path)
    report = import_path(path)
    faces = report.counts.get("mesh", 0) + report.counts.get("surface", 0)
    assert faces == occ_faces == 13, (faces, occ_faces, report.skipped_summary())
    assert not report.skipped, report.skipped_summary()
    box = ours_box(report)
    diag = np.linalg.norm(occ_box[1] - occ_box[0])
    assert np.abs(box - occ_box).max() <= 2e-3 * diag, (box, occ_box)
    # every face's mesh is on its exact surface within the display tolerance, and the
    # faces together have OCC's area
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.IGESControl import IGESControl_Reader

    r = IGESControl_Reader()
    r.ReadFile(str(path))
    r.TransferRoots()
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(r.OneShape(), props)
    occ_area = props.Mass()  # mm^2 (OCC's default unit)
    ours = _mesh_area(report)
    assert abs(ours * 1e6 - occ_area) <= 5e-3 * occ_area, (ours * 1e6, occ_area)


def _item_area(item) -> float:
    """Area of one imported item's display mesh."""
    V, T = item.mesh.vertices, item.mesh.triangles
    return 0.5 * np.linalg.norm(np.cross(V[T[:, 1]] - V[T[:, 0]], V[T[:, 2]] - V[T[:, 0]]), axis=1).sum()


def _mesh_area(report) -> float:
    return sum(_item_area(it) for it in report.items)


def test_cylinder_face_with_model_space_loop_matches_opencascade(tmp_path):
    """A 144 on a 192 bounded by a model-space loop only: OCC's face count and area. (OCC's
    bounding box of this face is not a reference: it differs between runs and is larger
    than the face, -1.18 and -2.18 m against the face's -0.82 m.)"""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.IGESControl import IGESControl_Reader

    text, area = C.cylinder_face()
    path = tmp_path / "cylinder.igs"
    path.write_text(text)
    occ_faces, occ_box, _ = corpus.occ_summary(path)
    report = import_path(path)
    assert report.counts.get("mesh", 0) == occ_faces == 1
    r = IGESControl_Reader()
    r.ReadFile(str(path))
    r.TransferRoots()
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(r.OneShape(), props)
    occ_area = props.Mass() * 1e-6  # OCC's default unit is the millimetre
    assert abs(occ_area - area) <= 1e-9 * area
    assert abs(_mesh_area(report) - occ_area) <= 2e-3 * occ_area
    box = ours_box(report)
    assert np.all(box[0] >= occ_box[0] - 1e-6) and np.all(box[1] <= occ_box[1] + 1e-6)


def _bump_face_brep_iges(path):
    """One face on a bicubic B-spline bump (highest at the middle, inside the face) bounded by
    its four sides, written by OpenCASCADE as a B-rep solid (186/510/508): two of the four
    edges are used against their curve (OF = 0), with their parameter-space curves written
    the way the loop goes."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.IGESControl import IGESControl_Reader
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    from bladesmith.geometry.nurbs import BSplineSurface
    from bladesmith.iges.convert import surface_from_geometry
    from bladesmith.iges.writer import to_string

    # the bicubic bump, as a lone 128 that OCC reads, then writes as a B-rep face
    net = np.zeros((4, 4, 3))
    for i in range(4):
        for j in range(4):
            net[i, j] = (10.0 * i, 8.0 * j, 30.0 if i in (1, 2) and j in (1, 2) else 0.0)
    knots = [0.0] * 4 + [1.0] * 4
    lone = path.with_suffix(".128.igs")
    lone.write_text(to_string([surface_from_geometry(BSplineSurface(3, 3, knots, knots, net))], units="mm"))
    r = IGESControl_Reader()
    r.ReadFile(str(lone))
    r.TransferRoots()
    explorer = TopExp_Explorer(r.OneShape(), TopAbs_FACE)
    surface = BRep_Tool.Surface_s(TopoDS.Face(explorer.Current()))
    face = BRepBuilderAPI_MakeFace(surface, 0.0, 1.0, 0.0, 1.0, 1e-7).Face()
    _write_brep_iges(face, path)


def test_brep_face_loop_with_reversed_edges_matches_opencascade(tmp_path):
    """The 508 loop's parameter-space curves of OF = 0 edges run the way the loop goes in
    OpenCASCADE's files: reversing them crossed the loop, and the face lost its middle (the
    bump's top, 16.9 mm up, was lost; occt-misc's MAT.brep.igs 2.8e-2 of the diagonal)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.IGESControl import IGESControl_Reader

    path = tmp_path / "bump.igs"
    _bump_face_brep_iges(path)
    text = path.read_text()
    assert "\n508," in "\n" + "\n".join(line[:72] for line in text.splitlines())
    occ_faces, occ_box, _ = corpus.occ_summary(path)
    report = import_path(path)
    assert report.counts.get("mesh", 0) == occ_faces == 1, report.skipped_summary()
    r = IGESControl_Reader()
    r.ReadFile(str(path))
    r.TransferRoots()
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(r.OneShape(), props)
    occ_area = props.Mass() * 1e-6
    assert abs(_mesh_area(report) - occ_area) <= 2e-3 * occ_area, (_mesh_area(report), occ_area)
    box = ours_box(report)
    diag = np.linalg.norm(occ_box[1] - occ_box[0])
    assert np.abs(box - occ_box).max() <= 2e-3 * diag, (box, occ_box)
    assert box[1, 2] > 0.0168  # the bump's top (16.875 mm) is inside the face


def test_loop_pieces_oriented_either_way():
    """Both conventions for OF = 0 parameter curves: as written (OpenCASCADE) and along the
    edge's curve (Bladesmith's propeller solid): the reading whose pieces join is taken."""
    from bladesmith.iges.foreign import _orient_parameter_curves

    square = [np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[1.0, 0.0], [1.0, 1.0]]),
              np.array([[1.0, 1.0], [0.0, 1.0]]), np.array([[0.0, 1.0], [0.0, 0.0]])]
    as_written = _orient_parameter_curves(square, [2, 3])
    assert all(a is b for a, b in zip(as_written, square))
    along_curve = [square[0], square[1], square[2][::-1], square[3][::-1]]
    fixed = _orient_parameter_curves(along_curve, [2, 3])
    assert all(np.array_equal(a, b) for a, b in zip(fixed, square))


def test_own_full_propeller_solid_imports_with_occs_face_areas(tmp_path):
    """Bladesmith's own DTMB 4119 as one 186 solid: every face's display mesh has the area of
    OCC's face to 5e-3 (the flat triangles of a face within the display tolerance, 1e-3 of
    its size, fall short of a strongly curved one by up to 2.7e-3: the tip halves). The hub's three footprint loops are sampled per knot span of the
    blade root edges (5142 points each); as mesh vertices they once spent the face's point
    budget before its inside was refined, and the hub came in faceted at 0.54 rad steps
    (area 3.7 % short, 5.3 mm off the surface). The loops are now thinned within a tenth of
    the display tolerance (iges.tessellate._thin)."""
    import tomllib

    from occ_support import face_area, read_with_occ

    from bladesmith.geometry.propeller import Propeller, smooth_blade
    from bladesmith.geometry.propeller.hub_sector import hub_sector
    from bladesmith.iges.propeller import write_full_propeller_iges

    root = HERE.parents[1]
    model = Propeller.from_dict(tomllib.loads((root / "data/propellers/dtmb4119.toml").read_text())).build()
    blade = smooth_blade(model, measure=False)
    path = tmp_path / "dtmb4119_solid.igs"
    write_full_propeller_iges(path, model, blade, hub_sector(model, blade=blade), brep=True)
    report = import_path(path)
    occ = [face_area(f) * 1e-6 for f in read_with_occ(path).faces]  # OCC reads in millimetres
    ours = [_item_area(it) for it in report.items]
    assert len(ours) == len(occ) == 25
    rel = np.abs(np.array(ours) / np.array(occ) - 1.0)
    assert rel.max() <= 5e-3, (int(rel.argmax()), float(rel.max()))
