"""Files we write, imported by gmsh (OpenCASCADE kernel) and meshed in 2-D.

``gmsh.model.occ.importShapes`` then ``gmsh.model.mesh.generate(2)`` must succeed with
mesh nodes inside every face, and without errors in gmsh's log.
"""
from __future__ import annotations

import numpy as np
import pytest

gmsh = pytest.importorskip("gmsh")

from bladesmith.iges import surface_from_geometry, write_iges  # noqa: E402
from bladesmith.iges.examples import random_surface, trimmed_cylinder_band, trimmed_plane_with_hole  # noqa: E402


@pytest.fixture
def session():
    gmsh.initialize(readConfigFiles=False)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.logger.start()
    try:
        yield gmsh
    finally:
        gmsh.logger.stop()
        gmsh.finalize()


def mesh_file(path, expected_faces: int, mesh_size: float):
    gmsh.model.add("iges")
    gmsh.model.occ.importShapes(str(path))
    gmsh.model.occ.synchronize()
    faces = gmsh.model.getEntities(2)
    assert len(faces) == expected_faces
    gmsh.option.setNumber("Mesh.MeshSizeMax", mesh_size)
    gmsh.model.mesh.generate(2)
    for dim, tag in faces:
        nodes, _, _ = gmsh.model.mesh.getNodes(dim, tag, includeBoundary=False)
        assert len(nodes) > 0, f"no mesh nodes inside face {tag}"
        types, elements, _ = gmsh.model.mesh.getElements(dim, tag)
        assert sum(len(e) for e in elements) > 0
    complaints = [line for line in gmsh.logger.get() if line.startswith(("Error", "Warning"))]
    assert complaints == [], complaints
    return faces


def test_trimmed_surface_of_revolution_meshes(session, tmp_path):
    path = tmp_path / "band.igs"
    write_iges(path, [trimmed_cylinder_band()[0]])
    mesh_file(path, 1, mesh_size=200.0)  # gmsh works in OCC's millimetres


def test_trimmed_plane_with_hole_meshes(session, tmp_path):
    path = tmp_path / "plane.igs"
    write_iges(path, [trimmed_plane_with_hole()[0]])
    mesh_file(path, 1, mesh_size=100.0)


def test_random_surfaces_mesh(session, tmp_path):
    rng = np.random.default_rng(3)
    recs = [surface_from_geometry(random_surface(rng, shape=(8, 7), degrees=(3, 3))) for _ in range(4)]
    band, _ = trimmed_cylinder_band()
    path = tmp_path / "many.igs"
    write_iges(path, recs + [band])
    mesh_file(path, 5, mesh_size=100.0)
