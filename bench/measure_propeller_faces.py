"""Issue 15 item 5 figures (not pass/fail, not part of ``make bench``: it meshes with gmsh
for minutes). For every propeller preset and the irregular tips of tests/data/irregular_tips:

- the tip surface's min sin∠(S_u, S_v) within 0.05 of each corner, and over the surface;
- the largest gap along the shared edges of the five surfaces and of the eight of
  ``split_at_edges`` (fractions of D);
- gmsh's 2-D mesh of every face of the IGES file, five-surface layout and split at the
  edges, at the curvature-adapted sizing (30 per 2π, D/1000 to D/10) and a uniform D/200:
  per face, triangles / invalid (gmsh's "elements remain invalid" count, and our own count
  of triangles against the surface normal at their parametric centroid).

Usage: python bench/measure_propeller_faces.py [--cases dtmb4119,raked_demo]
       [--layouts five,split] [--sizings curvature,uniform] [--bend] [--no-mesh]
"""
from __future__ import annotations

import argparse
import re
import tempfile
import time

import numpy as np

from common import ROOT, load_checkout

MM_PER_M = 1000.0
CORNER_BOX = 0.05
UNIFORM_SIZE_D = 1.0 / 200.0
CASES = {p.stem: p for p in sorted((ROOT / "data" / "propellers").glob("*.toml"))
         + sorted((ROOT / "tests" / "data" / "irregular_tips").glob("*.toml"))}


def sines(S, u, v):
    D = S.derivatives(u, v, 1)
    su, sv = D[:, 1, 0], D[:, 0, 1]
    return np.linalg.norm(np.cross(su, sv), axis=1) / (np.linalg.norm(su, axis=1) * np.linalg.norm(sv, axis=1))


def corner_figures(tip):
    s = np.linspace(0.0, CORNER_BOX, 21)
    out = []
    for cu in (0.0, 1.0):
        for cv in (0.0, 1.0):
            U, V = np.meshgrid(np.abs(cu - s), np.abs(cv - s), indexing="ij")
            out.append(float(sines(tip, U.ravel(), V.ravel()).min()))
    g = np.linspace(0.0, 1.0, 201)
    U, V = np.meshgrid(g, g, indexing="ij")
    return out, float(sines(tip, U.ravel(), V.ravel()).min())


def edge_gaps(surfaces: dict, edges, hand: int, D: float) -> float:
    from bladesmith.geometry.propeller.smoothing import boundary_parameters

    swap = (lambda n: n.replace("pressure", "#").replace("suction", "pressure").replace("#", "suction")) \
        if hand < 0 else (lambda n: n)
    t = np.linspace(0.0, 1.0, 401)
    worst = 0.0
    for a, sa, b, sb, rev in edges:
        A, B = surfaces[swap(a)], surfaces[swap(b)]
        ua, va = boundary_parameters(sa, t)
        ub, vb = boundary_parameters(sb, t[::-1] if rev else t)
        worst = max(worst, float(np.linalg.norm(A.evaluate(ua, va) - B.evaluate(ub, vb), axis=1).max()))
    return worst / D


def mesh(path, D: float, sizing: str):
    import gmsh

    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.logger.start()
        gmsh.model.occ.importShapes(str(path))
        gmsh.model.occ.synchronize()
        Dmm = D * MM_PER_M
        if sizing == "curvature":
            gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 30)
            gmsh.option.setNumber("Mesh.MeshSizeMin", 1e-3 * Dmm)
            gmsh.option.setNumber("Mesh.MeshSizeMax", 0.1 * Dmm)
        else:
            gmsh.option.setNumber("Mesh.MeshSizeMin", UNIFORM_SIZE_D * Dmm)
            gmsh.option.setNumber("Mesh.MeshSizeMax", UNIFORM_SIZE_D * Dmm)
        start = time.perf_counter()
        gmsh.model.mesh.generate(2)
        seconds = time.perf_counter() - start
        log = gmsh.logger.get()
        warned = {int(m.group(2)): int(m.group(1)) for m in
                  (re.search(r"(\d+) elements remain invalid in surface (\d+)", line) for line in log) if m}
        faces = {}
        for _, tag in gmsh.model.getEntities(2):
            _, nodes = gmsh.model.mesh.getElementsByType(2, tag)
            node_tags, xyz, uv = gmsh.model.mesh.getNodes(2, tag, includeBoundary=True)
            index = np.full(int(node_tags.max()) + 1, -1)
            index[node_tags.astype(np.int64)] = np.arange(node_tags.size)
            tri = index[np.asarray(nodes, dtype=np.int64).reshape(-1, 3)]
            P, UV = xyz.reshape(-1, 3)[tri], uv.reshape(-1, 2)[tri]
            n = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
            ns = np.reshape(gmsh.model.getNormal(tag, UV.mean(axis=1).ravel()), (-1, 3))
            faces[tag] = (len(tri), warned.get(tag, 0), int(np.sum(np.einsum("ij,ij->i", n, ns) < 0.0)))
        other = [line for line in log if line.startswith(("Warning", "Error")) and "remain invalid" not in line]
        return faces, seconds, other
    finally:
        gmsh.logger.stop()
        gmsh.finalize()


def main(cases=None, layouts=("five", "split"), sizings=("curvature", "uniform"), bend: bool = False) -> None:
    load_checkout()
    from bladesmith.geometry.propeller import corners as corner_module

    corner_module.BEND_TOP_EDGES = bend
    from bladesmith.geometry.propeller import Propeller, smooth_blade
    from bladesmith.geometry.propeller.blade_surfaces import SPLIT_SHARED_EDGES, split_at_edges
    from bladesmith.geometry.propeller.hub_sector import hub_sector
    from bladesmith.geometry.propeller.smoothing import SHARED_EDGES
    from bladesmith.iges.propeller import BLADE_SURFACES, SPLIT_LABELS, write_propeller_iges

    tmp = tempfile.mkdtemp(prefix="bladesmith_faces_")
    for name in cases or CASES:
        model = Propeller.from_toml(CASES[name]).build()
        blade = smooth_blade(model, measure=False)
        sector = hub_sector(model, blade=blade)
        D = 2.0 * model.blade.radius
        hand = int(np.sign(model.blade.hand))
        corners, whole = corner_figures(blade.tip)
        five_gap = edge_gaps(blade.named_surfaces, SHARED_EDGES, hand, D)
        split_gap = edge_gaps(split_at_edges(blade.named_surfaces, hand), SPLIT_SHARED_EDGES, hand, D)
        print(f"\n== {name}: tip min sin within {CORNER_BOX} of corners (0,0),(0,1),(1,0),(1,1): "
              f"{', '.join(f'{x:.3g}' for x in corners)}; over the tip surface {whole:.3g}")
        print(f"   shared-edge gaps: five surfaces {five_gap:.2g} D, split {split_gap:.2g} D")
        for layout in layouts:
            labels = [label for _, label in BLADE_SURFACES] if layout == "five" else list(SPLIT_LABELS.values())
            path = f"{tmp}/{name}_{layout}.igs"
            write_propeller_iges(path, model, blade, sector, split_edges=(layout == "split"))
            for sizing in sizings:
                faces, seconds, other = mesh(path, D, sizing)
                cells = [f"{(labels + ['HUB'])[tag - 1]} {n}/{w}/{f}" for tag, (n, w, f) in sorted(faces.items())]
                total = sum(w for _, w, _ in faces.values())
                print(f"   {layout:5} {sizing:9} {seconds:6.1f} s  invalid {total:3d}  "
                      f"[face triangles/gmsh invalid/flipped] {'; '.join(cells)}" + (f"  other: {other}" if other else ""))


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--cases", default="")
    parser.add_argument("--layouts", default="five,split")
    parser.add_argument("--sizings", default="curvature,uniform")
    parser.add_argument("--bend", action="store_true", help="bend c_9/c_10 at the tip corners (BEND_TOP_EDGES)")
    parser.add_argument("--no-mesh", action="store_true", help="geometry figures only")
    a = parser.parse_args()
    main([c for c in a.cases.split(",") if c] or None, [] if a.no_mesh else a.layouts.split(","),
         a.sizings.split(","), a.bend)
