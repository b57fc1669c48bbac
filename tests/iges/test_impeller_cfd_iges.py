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


def free_edge_samples(sewing, count: int = 9) -> list:
    """Points (count, 3) along each free edge of ``sewing`` (model units)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve

    out = []
    for i in range(1, sewing.NbFreeEdges() + 1):
        a = BRepAdaptor_Curve(sewing.FreeEdge(i))
        t = np.linspace(a.FirstParameter(), a.LastParameter(), count)
        out.append(np.array([[a.Value(x).X(), a.Value(x).Y(), a.Value(x).Z()] for x in t]))
    return out


def outer_pieces(cfd, samples: int = 4001) -> list:
    """(kind, wall, dense 3-D polyline) of every outer-loop piece of every wall sector:
    "side" (the periodic sides), "outlet" and "inlet", mapped from (u, φ) through the
    wall's contour (metres)."""
    out = []
    for sector in cfd.walls:
        loop = sector.outer.parameter
        low = (len(loop) - 2) // 2  # low side pieces, outlet, up side pieces, inlet
        for i, curve in enumerate(loop):
            kind = "outlet" if i == low else "inlet" if i == len(loop) - 1 else "side"
            uphi = curve.evaluate(np.linspace(*curve.domain, samples))
            zr = sector.contour.curve.evaluate(uphi[:, 0])
            out.append((kind, sector.which, np.stack([zr[:, 1] * np.cos(uphi[:, 1]), zr[:, 1] * np.sin(uphi[:, 1]),
                                                      zr[:, 0]], axis=1)))
    return out


def polyline_distance(P, Q) -> float:
    """Largest distance of the points P from the polyline Q (point to segment)."""
    A, AB = Q[:-1], np.diff(Q, axis=0)
    L2 = np.maximum(np.sum(AB * AB, axis=1), 1e-300)
    worst = 0.0
    for p in P:
        t = np.clip(np.sum((p - A) * AB, axis=1) / L2, 0.0, 1.0)
        worst = max(worst, float(np.min(np.linalg.norm(A + t[:, None] * AB - p, axis=1))))
    return worst


def classify_free_edges(cfd, sewing, units: float = 1000.0) -> dict:
    """{"<kind> (<wall>)": count} of the free edges: each edge's samples all lie (within
    1e-6 × the diameter) on one outer-loop piece of a wall sector, the inlet line, the
    outlet line or a periodic side; "other" for an edge on none of them."""
    pieces = outer_pieces(cfd)
    counts = {}
    for P in free_edge_samples(sewing):
        P = P / units
        near = [(polyline_distance(P, Q), f"{kind} ({wall})") for kind, wall, Q in pieces
                if np.all(P >= Q.min(axis=0) - 1e-3) and np.all(P <= Q.max(axis=0) + 1e-3)]
        d, label = min(near, default=(np.inf, "other"))
        label = label if d <= 1e-6 * cfd.diameter else "other"
        counts[label] = counts.get(label, 0) + 1
    return counts


def shells(sewing) -> int:
    """Shells in the sewn shape: 1 when the faces sewed into one connected shell."""
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer

    count, explorer = 0, TopExp_Explorer(sewing.SewedShape(), TopAbs_SHELL)
    while explorer.More():
        count += 1
        explorer.Next()
    return count


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


@pytest.mark.parametrize("name", ["high_flow", "intermediate_flow", "low_flow", "return_channel"])
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
    # every free edge, sampled along its length, lies on the inlet, the outlet or a periodic
    # side of the sector (3 pieces per side: upstream line, blade-following curve, downstream)
    assert classify_free_edges(cfd, sewing) == {"inlet (hub)": 1, "inlet (shroud)": 1, "outlet (hub)": 1,
                                                "outlet (shroud)": 1, "side (hub)": 6, "side (shroud)": 6}
    assert sewing.NbMultipleEdges() == 0 and shells(sewing) == 1


@pytest.mark.parametrize("name", ["high_flow", "intermediate_flow", "low_flow", "return_channel"])
def test_full_wheel_sews_closed_but_inlet_and_outlet(tmp_path, name):
    model, cfd, path = written(tmp_path, name, True)
    res = read_with_occ(path)
    assert res.load_messages == [] and res.transfer_messages == []
    assert len(res.faces) == model.count * (2 + 4 * (1 + (model.splitter is not None)))
    sewing, mids = sew(res.faces, SEWING_FRACTION * cfd.diameter * 1000.0)
    assert shells(sewing) == 1
    assert len(mids) == 4 * model.count and on_inlet_or_outlet(model, mids).all()
    Z = model.count
    assert classify_free_edges(cfd, sewing) == {"inlet (hub)": Z, "inlet (shroud)": Z, "outlet (hub)": Z,
                                                "outlet (shroud)": Z}


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
    assert classify_free_edges(cfd, sewing) == {"inlet (hub)": 1, "inlet (shroud)": 1, "outlet (hub)": 1,
                                                "outlet (shroud)": 1, "side (hub)": 6, "side (shroud)": 6}
