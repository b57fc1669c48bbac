"""Acceptance figures of a wind blade (issue 19): build time, control points, worst
section against the tolerance, the signed trailing-edge thickness, and the IGES file read
back by OpenCASCADE (messages, faces, sewing at 1e-7 x size, free edges at root and tip).
Needs the test requirements (cadquery-ocp-novtk).

    python scripts/wind_acceptance.py ../shared/data/wind/IEA-15-240-RWT.yaml --tolerance 2e-4 --out out
    python scripts/wind_acceptance.py NREL5MW --out out
    python scripts/wind_acceptance.py ../shared/data/wind/IEA-15-240-RWT.yaml --caps rounded --out out

``--caps ruled|planar|rounded`` also writes the closed blade (root and tip caps) and sews it
at 1e-7 x size into one solid (free edges, OCC validity, volume).
"""
from __future__ import annotations

import argparse
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "iges"))


def main(argv=None) -> int:
    from wind_sweep import load_checkout

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("blade", help="preset name or definition file (.toml, windIO .yaml)")
    parser.add_argument("--tolerance", type=float, default=0.0, help="chord fraction; 0 = the definition's")
    parser.add_argument("--out", default="out")
    parser.add_argument("--caps", default="", help="also the closed blade with these caps: ruled, planar, rounded")
    args = parser.parse_args(argv)
    load_checkout()
    from bladesmith.geometry.mold import build_blade, load_blade, load_preset
    from bladesmith.iges.mold import write_molds
    from occ_support import read_with_occ

    path = pathlib.Path(args.blade)
    t = time.perf_counter()
    defn = load_blade(path) if path.suffix else load_preset(args.blade)
    t_load = time.perf_counter() - t
    t, c = time.perf_counter(), time.process_time()
    molds = build_blade(defn, tolerance=args.tolerance or None, single=False, fairness=False)
    t_build, c_build = time.perf_counter() - t, time.process_time() - c
    worst = max(r.deviation_two_part / molds.tolerances[r.index] for r in molds.stations)
    print(f"{defn.name}: {len(defn.stations)} stations (aerodynamic from {defn.first_aerodynamic_station}); "
          f"read {t_load:.2f} s, built {t_build:.1f} s ({c_build:.1f} s CPU); {molds.control_points} control points per half"
          f"{', aligned parameters' if molds.aligned_parameters else ''}"
          f"{', densified fit' if getattr(molds, 'densified', False) else ''}")
    print(f"worst section / its tolerance: {worst:.3f} (every station within: {worst <= 1.0}); "
          f"stage times {{{', '.join(f'{k}: {v:.1f}' for k, v in molds.times.items())}}} s")
    print("continuity: " + ", ".join(f"{k} {v:.2e}" for k, v in molds.continuity.items()))
    for a, b in (("upper", "lower"), ("transition_upper", "transition_lower")):
        if a in molds.surfaces:
            up, lo = molds.surfaces[a], molds.surfaces[b]
            v = np.linspace(up.knots_v[0], up.knots_v[-1], 1000)
            U, L, LE = up.evaluate(0.0, v), lo.evaluate(1.0, v), up.evaluate(1.0, v)
            n = np.cross([0.0, 0.0, 1.0], 0.5 * (U + L) - LE)
            th = np.einsum("ij,ij->i", U - L, n / np.linalg.norm(n, axis=1, keepdims=True))
            print(f"signed TE thickness {a}/{b}: min {th.min():.3e} m, max {th.max():.3e} m (1000 points)")
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    igs = out / (path.stem.lower() + "_molds.igs")
    write_molds(igs, molds)
    occ = read_with_occ(igs)
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing

    size = max(s.size() for s in molds.surfaces.values())
    sewing = BRepBuilderAPI_Sewing(1e-7 * size * 1000.0)
    for f in occ.faces:
        sewing.Add(f)
    sewing.Perform()
    print(f"IGES {igs}: OCC load messages {len(occ.load_messages)}, transfer messages {len(occ.transfer_messages)}, "
          f"faces {len(occ.faces)} of {len(molds.surfaces)}; sewing at {1e-7 * size:.2e} m: "
          f"{sewing.NbFreeEdges()} free edges, {sewing.NbMultipleEdges()} multiple edges")
    if args.caps:
        from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid
        from OCP.BRepCheck import BRepCheck_Analyzer
        from OCP.BRepGProp import BRepGProp
        from OCP.GProp import GProp_GProps
        from OCP.TopoDS import TopoDS

        from bladesmith.iges.mold import write_closed_blade

        closed = out / (path.stem.lower() + f"_closed_{args.caps}.igs")
        write_closed_blade(closed, molds, caps=args.caps)
        occ = read_with_occ(closed)
        sewing = BRepBuilderAPI_Sewing(1e-7 * size * 1000.0)
        for f in occ.faces:
            sewing.Add(f)
        sewing.Perform()
        solid = BRepBuilderAPI_MakeSolid(TopoDS.Shell(sewing.SewedShape())).Solid()
        props = GProp_GProps()
        BRepGProp.VolumeProperties_s(solid, props, 1e-9)
        print(f"closed blade {closed} ({args.caps} caps): OCC messages {len(occ.load_messages)} + "
              f"{len(occ.transfer_messages)}, faces {len(occ.faces)}; sewing at {1e-7 * size:.2e} m: "
              f"{sewing.NbFreeEdges()} free edges; valid solid {BRepCheck_Analyzer(solid).IsValid()}, "
              f"volume {props.Mass() / 1e9:.3f} m3")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    sys.exit(main())
