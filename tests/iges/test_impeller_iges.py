"""A full preset impeller (channel + 15 blades) written as IGES 128 surfaces, read by
OpenCASCADE with zero fail and warning messages and valid faces, and meshed by gmsh; and
the same for a standardised impeller (Casey 1983, Fig. 11: trimmed to a 20 % narrower
channel, blades and splitters)."""
import pathlib

import numpy as np
import pytest

pytest.importorskip("OCP")

from occ_support import is_valid, read_with_occ  # noqa: E402

from bladesmith.geometry.compressor import ImpellerDefinition  # noqa: E402
from bladesmith.geometry.compressor.export import impeller_surfaces  # noqa: E402
from bladesmith.iges import surface_from_geometry, write_iges  # noqa: E402

PRESET = pathlib.Path(__file__).resolve().parents[2] / "data" / "impellers" / "high_flow.toml"
STANDARDISED = PRESET.with_name("intermediate_flow.toml")
#: OCC's evaluation (mm) of the blade surfaces matches ours to this (relative to size).
EVALUATION_TOLERANCE = 1e-12


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    model = ImpellerDefinition.from_toml(PRESET).build()
    assert model.count == 15
    surfaces = impeller_surfaces(model)
    path = tmp_path_factory.mktemp("impeller") / "impeller.igs"
    write_iges(path, [surface_from_geometry(s) for _, s in surfaces], units="m")
    return path, surfaces


@pytest.fixture(scope="module")
def standardised(tmp_path_factory):
    data = ImpellerDefinition.from_toml(STANDARDISED).to_dict()
    data["standardisation"] = {"shroud_factor": 0.8}
    model = ImpellerDefinition.from_dict(data).build()
    assert model.standardisation is not None and model.count == 15
    surfaces = impeller_surfaces(model)
    path = tmp_path_factory.mktemp("standardised") / "standardised.igs"
    write_iges(path, [surface_from_geometry(s) for _, s in surfaces], units="m")
    return path, surfaces, model


def test_occ_reads_standardised_impeller_cleanly(standardised):
    from OCP.BRep import BRep_Tool

    path, surfaces, model = standardised
    res = read_with_occ(path)
    assert res.load_messages == [] and res.transfer_messages == []
    assert len(res.faces) == len(surfaces) == 8 + 15 * 4 + 15 * 4  # walls, S P LE TE of blades and splitters
    assert all(is_valid(f) for f in res.faces)
    # the trimmed blade faces evaluate as ours (OCC in mm), edges on the new walls
    st = model.standardisation
    for index in (8, 9, 10, 11):
        name, ours = surfaces[index]
        assert ours is st.parts[name.split()[0]][name.split()[2]].surface
        S = BRep_Tool.Surface_s(res.faces[index])
        u, v = np.linspace(0, ours.knots_u[-1], 7), np.array([0.0, 0.25, 0.5, 1.0, 1.0, 0.0, 0.75])
        occ = np.array([[(p := S.Value(a, b)).X(), p.Y(), p.Z()] for a, b in zip(u, v)]) / 1000.0
        assert np.max(np.abs(occ - ours.evaluate(u, v))) < EVALUATION_TOLERANCE * ours.size() + 1e-15


def test_gmsh_meshes_standardised_impeller(standardised):
    path, surfaces, _ = standardised
    mesh_with_gmsh(path, len(surfaces))


def test_occ_reads_full_impeller_cleanly(written):
    from OCP.BRep import BRep_Tool

    path, surfaces = written
    res = read_with_occ(path)
    assert res.load_messages == [] and res.transfer_messages == []
    assert len(res.faces) == len(surfaces) == 8 + 15 * 4  # S, P, rounded LE, TE closing face
    assert all(is_valid(f) for f in res.faces)
    # a blade face evaluates as ours (OCC in mm)
    name, ours = surfaces[8]
    S = BRep_Tool.Surface_s(res.faces[8])
    u, v = np.linspace(0, ours.knots_u[-1], 7), np.linspace(0, 1, 7)
    occ = np.array([[(p := S.Value(a, b)).X(), p.Y(), p.Z()] for a, b in zip(u, v)]) / 1000.0
    assert np.max(np.abs(occ - ours.evaluate(u, v))) < EVALUATION_TOLERANCE * ours.size() + 1e-15


def test_gmsh_meshes_full_impeller(written):
    path, surfaces = written
    mesh_with_gmsh(path, len(surfaces))


def mesh_with_gmsh(path, n_surfaces: int) -> None:
    """gmsh imports every face and meshes it, with no error or warning."""
    gmsh = pytest.importorskip("gmsh")
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.logger.start()
        gmsh.model.add("impeller")
        gmsh.model.occ.importShapes(str(path))
        gmsh.model.occ.synchronize()
        faces = gmsh.model.getEntities(2)
        assert len(faces) == n_surfaces
        gmsh.option.setNumber("Mesh.MeshSizeMax", 10.0)  # mm
        gmsh.model.mesh.generate(2)
        for dim, tag in faces:
            # a closing face of a cut-off trailing edge is narrower than the mesh size:
            # it gets triangles on its boundary nodes only, so count elements, not nodes
            _, element_tags, _ = gmsh.model.mesh.getElements(dim, tag)
            assert sum(len(t) for t in element_tags) > 0, tag
        complaints = [line for line in gmsh.logger.get() if line.startswith(("Error", "Warning"))]
        assert complaints == [], complaints
    finally:
        gmsh.logger.stop()
        gmsh.finalize()
