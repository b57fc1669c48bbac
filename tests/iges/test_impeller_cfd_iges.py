"""The impeller CFD set (issue 18): hub and shroud trimmed at the blade footprints (144 over
120), blades S, P, LE and TE caps, no camber sheet; read by OpenCASCADE with zero messages,
sewn at 1e-7 × the outer diameter into a shell whose only free edges are the inlet, the
outlet and (single passage) the periodic sides; gmsh meshes every face."""
import pathlib

import numpy as np
import pytest

pytest.importorskip("OCP")

from occ_support import is_valid, read_with_occ  # noqa: E402

from bladesmith.geometry.compressor import ImpellerDefinition  # noqa: E402
from bladesmith.geometry.compressor.cfd import cfd_set  # noqa: E402
from bladesmith.iges.impeller import write_cfd_iges  # noqa: E402

PRESETS = pathlib.Path(__file__).resolve().parents[2] / "data" / "impellers"
#: Issue 18: the CFD set sews at this fraction of the outer diameter.
SEWING_FRACTION = 1e-7


def sew(faces, tolerance):
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing

    sewing = BRepBuilderAPI_Sewing(tolerance)
    for f in faces:
        sewing.Add(f)
    sewing.Perform()
    mids = []
    for i in range(1, sewing.NbFreeEdges() + 1):
        a = BRepAdaptor_Curve(sewing.FreeEdge(i))
        p = a.Value(0.5 * (a.FirstParameter() + a.LastParameter()))
        mids.append((p.X(), p.Y(), p.Z()))
    return sewing, np.array(mids).reshape(-1, 3)


def written(tmp_path, name, full_wheel):
    model = ImpellerDefinition.from_toml(PRESETS / f"{name}.toml").build()
    cfd = cfd_set(model, full_wheel=full_wheel)
    path = tmp_path / f"{name}_{'wheel' if full_wheel else 'passage'}.igs"
    write_cfd_iges(path, cfd, units="mm")
    return model, cfd, path


def on_inlet_or_outlet(model, mids_mm):
    """Whether each point lies on the inlet or outlet circle of hub or shroud."""
    ends = np.array([model.channel.wall(w).evaluate(U) for w in ("hub", "shroud") for U in (0.0, model.channel.count)])
    zr = np.stack([mids_mm[:, 2], np.hypot(mids_mm[:, 0], mids_mm[:, 1])], axis=1) / 1000.0
    return np.min(np.linalg.norm(zr[:, None, :] - ends[None, :, :], axis=-1), axis=1) < 1e-9


@pytest.mark.parametrize("name", ["high_flow", "intermediate_flow"])
def test_single_passage_sews_closed_but_inlet_outlet_and_periodic_sides(tmp_path, name):
    model, cfd, path = written(tmp_path, name, False)
    res = read_with_occ(path)
    assert res.load_messages == [] and res.transfer_messages == []
    blades = 1 + (model.splitter is not None)
    assert len(res.faces) == 2 + 4 * blades  # hub, shroud; S, P, LE, TE per blade (no B)
    assert all(is_valid(f) for f in res.faces)
    sewing, mids = sew(res.faces, SEWING_FRACTION * cfd.diameter * 1000.0)
    ends = on_inlet_or_outlet(model, mids)
    # inlet and outlet on both walls, and the periodic sides: 3 pieces (upstream line,
    # blade-following curve, downstream line) per side, two sides per wall
    assert ends.sum() == 4 and (~ends).sum() == 12, mids
    # the periodic side edges lie one pitch apart: each rotates onto another free edge
    side = mids[~ends]
    pitch = 2.0 * np.pi / model.count
    c, s = np.cos(pitch), np.sin(pitch)
    turned = side @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]).T
    matched = np.min(np.linalg.norm(turned[:, None] - side[None], axis=-1), axis=1) < 1e-6 * cfd.diameter * 1000.0
    assert matched.sum() == 6


def test_full_wheel_sews_closed_but_inlet_and_outlet(tmp_path):
    model, cfd, path = written(tmp_path, "high_flow", True)
    res = read_with_occ(path)
    assert res.load_messages == [] and res.transfer_messages == []
    assert len(res.faces) == model.count * (2 + 4)
    sewing, mids = sew(res.faces, SEWING_FRACTION * cfd.diameter * 1000.0)
    assert len(mids) == 4 * model.count and on_inlet_or_outlet(model, mids).all()


def test_gmsh_meshes_every_face_of_the_passage(tmp_path):
    gmsh = pytest.importorskip("gmsh")
    _, _, path = written(tmp_path, "intermediate_flow", False)
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.logger.start()
        gmsh.model.add("passage")
        gmsh.model.occ.importShapes(str(path))
        gmsh.model.occ.synchronize()
        faces = gmsh.model.getEntities(2)
        assert len(faces) == 10
        gmsh.option.setNumber("Mesh.MeshSizeMax", 10.0)  # mm
        gmsh.model.mesh.generate(2)
        for dim, tag in faces:
            _, element_tags, _ = gmsh.model.mesh.getElements(dim, tag)
            assert sum(len(t) for t in element_tags) > 0, tag
        complaints = [line for line in gmsh.logger.get() if line.startswith(("Error", "Warning"))]
        assert complaints == [], complaints
    finally:
        gmsh.logger.stop()
        gmsh.finalize()


def test_standardised_passage_sews_closed_but_inlet_outlet_and_periodic_sides(tmp_path):
    """A standardised impeller (Casey 1983, Fig. 11: intermediate_flow with a 20 % shroud
    cut) has a CFD set too: the new channel's walls trimmed at the footprints of the
    trimmed blades; OCC reads it with 0 messages and it sews like the master's."""
    d = ImpellerDefinition.from_toml(PRESETS / "intermediate_flow.toml")
    data = d.to_dict()
    data["standardisation"] = {"shroud_factor": 0.8}
    model = type(d).from_dict(data).build()
    cfd = cfd_set(model)
    path = tmp_path / "standardised_passage.igs"
    write_cfd_iges(path, cfd, units="mm")
    res = read_with_occ(path)
    assert res.load_messages == [] and res.transfer_messages == []
    assert len(res.faces) == 2 + 4 * 2 and all(is_valid(f) for f in res.faces)  # blade and splitter
    sewing, mids = sew(res.faces, SEWING_FRACTION * cfd.diameter * 1000.0)
    ends = on_inlet_or_outlet(model, mids)
    assert ends.sum() == 4 and (~ends).sum() == 12, mids
