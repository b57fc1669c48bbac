"""OpenCASCADE helpers for the third-party reader tests (OCP = cadquery-ocp-novtk)."""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class OccResult:
    shape: object
    load_messages: list = field(default_factory=list)   # (kind, text) from ModelCheckList
    transfer_messages: list = field(default_factory=list)  # (kind, text) from the transfer check list
    faces: list = field(default_factory=list)


def _messages(check_iterator) -> list:
    out = []
    check_iterator.Start()
    while check_iterator.More():
        check = check_iterator.Value()
        for i in range(1, check.NbFails() + 1):
            out.append(("fail", check.CFail(i, True)))
        for i in range(1, check.NbWarnings() + 1):
            out.append(("warning", check.CWarning(i, True)))
        check_iterator.Next()
    return out


def read_with_occ(path) -> OccResult:
    """Read an IGES file with IGESControl_Reader; collect load and transfer messages."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.IGESControl import IGESControl_Reader
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    reader = IGESControl_Reader()
    status = reader.ReadFile(str(path))
    if status != IFSelect_RetDone:
        raise AssertionError(f"OCC could not read {path}: status {status}")
    ws = reader.WS()
    load = _messages(ws.ModelCheckList(True))
    reader.TransferRoots()
    tp = ws.TransferReader().TransientProcess()
    transfer = _messages(tp.CheckList(False))
    shape = reader.OneShape()
    faces = []
    exp = TopExp_Explorer(shape, TopAbs_FACE)
    while exp.More():
        faces.append(TopoDS.Face(exp.Current()))
        exp.Next()
    return OccResult(shape, load, transfer, faces)


def face_area(face) -> float:
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face, props)
    return props.Mass()


def is_valid(shape) -> bool:
    from OCP.BRepCheck import BRepCheck_Analyzer

    return BRepCheck_Analyzer(shape).IsValid()


def algo_check(shape) -> bool:
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Check

    return BRepAlgoAPI_Check(shape).IsValid()


def wires_of(face) -> list:
    from OCP.TopAbs import TopAbs_WIRE
    from OCP.TopExp import TopExp_Explorer

    out = []
    exp = TopExp_Explorer(face, TopAbs_WIRE)
    while exp.More():
        out.append(exp.Current())
        exp.Next()
    return out


def fluid_volume_mesh(domain, solid, curvature_points: float, min_size: float, max_size: float):
    """Cut ``solid`` from ``domain`` (OCC shapes, the same units as the sizes), write the
    fluid as BREP and mesh it in 3-D with gmsh, no repair or healing: sizes from curvature
    (``curvature_points`` elements per 2π) between ``min_size`` and ``max_size``, 2-D
    Delaunay, 3-D Delaunay with gmsh's Netgen optimiser. Returns (OCC validity of the
    fluid, number of tetrahedra, min SICN). One fluid volume is asserted."""
    import os
    import tempfile

    import gmsh
    import numpy as np
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepTools import BRepTools

    cut = BRepAlgoAPI_Cut(domain, solid)
    cut.Build()
    assert cut.IsDone()
    fluid = cut.Shape()
    valid = is_valid(fluid)
    with tempfile.TemporaryDirectory() as tmp:
        brep = os.path.join(tmp, "fluid.brep")
        BRepTools.Write_s(fluid, brep)
        gmsh.initialize()
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.option.setNumber("General.NumThreads", 1)
            gmsh.model.occ.importShapes(brep)
            gmsh.model.occ.synchronize()
            assert len(gmsh.model.getEntities(3)) == 1
            gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", curvature_points)
            gmsh.option.setNumber("Mesh.MeshSizeMax", max_size)
            gmsh.option.setNumber("Mesh.MeshSizeMin", min_size)
            gmsh.option.setNumber("Mesh.Algorithm", 5)
            gmsh.option.setNumber("Mesh.Algorithm3D", 1)
            gmsh.option.setNumber("Mesh.OptimizeNetgen", 1)
            gmsh.model.mesh.generate(3)
            tets = []
            for _, tag in gmsh.model.getEntities(3):
                types, tags, _ = gmsh.model.mesh.getElements(3, tag)
                for t, ids in zip(types, tags):
                    if t == 4:  # 4-node tetrahedra
                        tets.extend(ids)
            quality = gmsh.model.mesh.getElementQualities(tets, "minSICN")
        finally:
            gmsh.finalize()
    return valid, len(tets), float(np.min(quality))
