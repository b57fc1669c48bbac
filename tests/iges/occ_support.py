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
