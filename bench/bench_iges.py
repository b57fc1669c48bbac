"""Benchmark: write 100 bicubic B-spline surfaces of 40 x 40 control points as IGES.

Prints the median wall time of ``bladesmith.iges.write_iges`` and, measured in the same
run on the same surfaces, that of OpenCASCADE's own ``IGESControl_Writer`` writing them as
faces of ``Geom_BSplineSurface`` (AddShape + Write), and the ratio ours / OCC.
Never part of pass/fail (ARCHITECTURE.md, house style 10).

    .venv/bin/python bench/bench_iges.py [--repeat 7] [--surfaces 100] [--size 40]
"""
from __future__ import annotations

import argparse
import os
import pathlib
import statistics
import sys
import tempfile
import time

import numpy as np

from common import load_checkout



def _load_bladesmith():
    return load_checkout()


def random_surfaces(count: int, size: int, seed: int = 0):
    """``count`` random non-uniform bicubic surfaces of size x size control points (metres)."""
    _load_bladesmith()
    from bladesmith.geometry.nurbs import BSplineSurface

    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        knots = []
        for _d in range(2):
            gaps = rng.uniform(0.5, 1.5, size - 3)
            inner = np.cumsum(gaps)[:-1] / gaps.sum()
            knots.append(np.r_[[0.0] * 4, inner, [1.0] * 4])
        grid = np.stack(np.meshgrid(np.linspace(0, 1, size), np.linspace(0, 1, size), indexing="ij"), -1)
        P = np.concatenate([grid, 0.1 * rng.normal(size=(size, size, 1))], -1)
        P = P + 1e-3 * rng.normal(size=P.shape)
        out.append(BSplineSurface(3, 3, knots[0], knots[1], P))
    return out


def occ_faces(surfaces):
    """The surfaces as OCC faces (Geom_BSplineSurface, distinct knots + multiplicities)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt

    try:  # OCCT 8 bindings expose NCollection arrays under OCP.collections
        from OCP.collections import Array1_double as TColStd_Array1OfReal
        from OCP.collections import Array1_int as TColStd_Array1OfInteger
        from OCP.collections import Array2_gp_Pnt as TColgp_Array2OfPnt
    except ImportError:  # OCCT 7
        from OCP.TColgp import TColgp_Array2OfPnt
        from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

    faces = []
    for s in surfaces:
        nu, nv = s.shape
        poles = TColgp_Array2OfPnt(1, nu, 1, nv)
        for i in range(nu):
            for j in range(nv):
                poles.SetValue(i + 1, j + 1, gp_Pnt(*map(float, s.control_points[i, j])))

        def km(U):
            vals, mult = np.unique(U, return_counts=True)
            K = TColStd_Array1OfReal(1, len(vals))
            M = TColStd_Array1OfInteger(1, len(vals))
            for k, (v, m) in enumerate(zip(vals, mult), 1):
                K.SetValue(k, float(v))
                M.SetValue(k, int(m))
            return K, M

        ku, mu = km(s.knots_u)
        kv, mv = km(s.knots_v)
        g = Geom_BSplineSurface(poles, ku, kv, mu, mv, s.degree_u, s.degree_v)
        faces.append(BRepBuilderAPI_MakeFace(g, 1e-7).Face())
    return faces


def time_ours(records, path) -> float:
    from bladesmith.iges import write_iges

    t = time.perf_counter()
    write_iges(path, records, units="m")
    return time.perf_counter() - t


def time_occ(faces, path) -> float:
    from OCP.IGESControl import IGESControl_Writer

    t = time.perf_counter()
    w = IGESControl_Writer("M", 0)
    for f in faces:
        w.AddShape(f)
    w.ComputeModel()
    ok = w.Write(str(path))
    dt = time.perf_counter() - t
    if not ok:
        raise RuntimeError("IGESControl_Writer.Write failed")
    return dt


GOAL_RATIO = 0.5


def measure(repeat: int = 7, count: int = 100, size: int = 40) -> dict:
    """Median write times of ours and OCC's writer, interleaved in the same run."""
    _load_bladesmith()
    from bladesmith.iges import surface_from_geometry

    surfaces = random_surfaces(count, size)
    records = [surface_from_geometry(s) for s in surfaces]
    try:
        faces = occ_faces(surfaces)
    except ImportError:
        faces = None
    with tempfile.TemporaryDirectory() as tmp:
        ours_path = os.path.join(tmp, "ours.igs")
        occ_path = os.path.join(tmp, "occ.igs")
        ours, occ = [], []
        for _ in range(repeat):
            ours.append(time_ours(records, ours_path))
            if faces is not None:
                occ.append(time_occ(faces, occ_path))
        size_ours = os.path.getsize(ours_path)
        size_occ = os.path.getsize(occ_path) if faces is not None else 0
    m_ours = statistics.median(ours)
    m_occ = statistics.median(occ) if faces is not None else float("nan")
    return {"ours": m_ours, "occ": m_occ, "ratio": m_ours / m_occ, "size_ours": size_ours, "size_occ": size_occ}


def figures() -> list[dict]:
    r = measure()
    baseline = (f"OCC IGESControl_Writer {r['occ']:.2f} s, same run (ours {r['ours']:.2f} s)"
                if r["occ"] == r["occ"] else "OCP not installed: no OCC baseline")
    return [{"figure": "IGES write vs OCC, 100 surfaces of 40x40", "value": r["ratio"], "unit": "x",
             "baseline": baseline, "goal": f"<= {GOAL_RATIO}x"}]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--surfaces", type=int, default=100)
    ap.add_argument("--size", type=int, default=40)
    args = ap.parse_args([] if argv is None else argv)
    r = measure(args.repeat, args.surfaces, args.size)
    print(f"bladesmith.iges write_iges: {args.surfaces} bicubic surfaces of {args.size}x{args.size} "
          f"control points: median {r['ours']:.3f} s over {args.repeat} runs ({r['size_ours'] / 1e6:.1f} MB)")
    if r["occ"] == r["occ"]:
        print(f"OpenCASCADE IGESControl_Writer (faces of Geom_BSplineSurface): median {r['occ']:.3f} s "
              f"({r['size_occ'] / 1e6:.1f} MB)")
        print(f"ratio bladesmith / OCC: {r['ratio']:.2f} (goal <= {GOAL_RATIO})")
    else:
        print("OCP not installed: no OpenCASCADE baseline")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
