"""Benchmark: read the 100-surface IGES file (100 bicubic B-spline surfaces of 40 x 40
control points, written by ``bench_iges.py``'s surfaces) with Bladesmith and OpenCASCADE.

Prints medians (wall time, and the ratios in CPU time too), measured in the same run on
the same file, of
* ``read_iges`` (strict parse into records),
* ``parse_iges(strict=False)`` + ``import_model`` (what File > Import runs before it makes
  Blender objects: lenient parse, units, placement, B-spline geometry),
* OpenCASCADE ``IGESControl_Reader`` ReadFile + TransferRoots,
and the ratios ours / OCC. Never part of pass/fail (ARCHITECTURE.md, house style 10).

    .venv/bin/python bench/bench_iges_read.py [--repeat 5] [--surfaces 100] [--size 40]
"""
from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time

from bench_iges import random_surfaces
from common import load_checkout


def occ_read(path):
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.IGESControl import IGESControl_Reader

    reader = IGESControl_Reader()
    if reader.ReadFile(str(path)) != IFSelect_RetDone:
        raise RuntimeError("OCC could not read the file")
    reader.TransferRoots()
    return reader.OneShape()


def measure(repeat: int = 5, surfaces: int = 100, size: int = 40) -> dict:
    """Medians in seconds: ``strict`` (read_iges), ``import`` (lenient parse + import_model),
    ``occ`` (None without OCP), and the file's ``bytes``."""
    load_checkout()
    from bladesmith.iges import read_iges, surface_from_geometry, write_iges
    from bladesmith.iges.importer import import_model
    from bladesmith.iges.reader import parse_iges

    records = [surface_from_geometry(s) for s in random_surfaces(surfaces, size)]
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "bench.igs")
        write_iges(path, records, units="m")

        def lenient():
            with open(path, "rb") as f:
                data = f.read()
            return import_model(parse_iges(data, path=path, strict=False), len(data))

        calls = {"strict": lambda: read_iges(path), "import": lenient, "occ": lambda: occ_read(path)}
        try:
            import OCP  # noqa: F401
        except ImportError:
            del calls["occ"]
        # interleaved (strict, import, OCC, strict, ...) so that a change of load on a
        # shared machine falls on all three alike; ratios are medians of per-round ratios
        # (CPU time too: on a shared machine it is far less noisy than wall time)
        times = {k: [] for k in calls}
        cpu = {k: [] for k in calls}
        for fn in calls.values():
            fn()  # warm-up (imports, caches)
        for _ in range(repeat):
            for k, fn in calls.items():
                t, c = time.perf_counter(), time.process_time()
                fn()
                times[k].append(time.perf_counter() - t)
                cpu[k].append(time.process_time() - c)
        out = {"bytes": os.path.getsize(path), "occ": None}
        out.update({k: statistics.median(v) for k, v in times.items()})
        if "occ" in times:
            for k in ("strict", "import"):
                out[f"{k}_ratio"] = statistics.median(a / b for a, b in zip(times[k], times["occ"]))
                out[f"{k}_cpu_ratio"] = statistics.median(a / b for a, b in zip(cpu[k], cpu["occ"]))
    return out


def figures() -> list[dict]:
    """Rows of the ``make bench`` summary (bench/summary.py)."""
    m = measure(repeat=5)
    occ = f"OCC IGESControl_Reader {1e3 * m['occ']:.0f} ms, same run" if m["occ"] else ""
    rows = [{"figure": "IGES read, 100 bicubic 40x40 surfaces (read_iges)", "value": 1e3 * m["strict"],
             "unit": "ms", "baseline": occ, "goal": ""}]
    if m["occ"]:
        rows.append({"figure": "IGES read / OCC IGESControl_Reader", "value": m["strict_ratio"], "unit": "x",
                     "baseline": f"OCC {1e3 * m['occ']:.0f} ms", "goal": "<= 1x"})
        rows.append({"figure": "IGES import (lenient + import_model) / OCC", "value": m["import_ratio"],
                     "unit": "x", "baseline": f"OCC {1e3 * m['occ']:.0f} ms", "goal": "<= 1x"})
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--surfaces", type=int, default=100)
    ap.add_argument("--size", type=int, default=40)
    args = ap.parse_args(argv)
    m = measure(args.repeat, args.surfaces, args.size)
    t_strict, t_import, t_occ = m["strict"], m["import"], m["occ"]
    print(f"file: {args.surfaces} bicubic surfaces of {args.size}x{args.size} control points, {m['bytes'] / 1e6:.1f} MB")
    print(f"bladesmith read_iges (strict parse): median {t_strict:.3f} s over {args.repeat} runs")
    print(f"bladesmith lenient parse + import_model: median {t_import:.3f} s")
    if t_occ is not None:
        print(f"OpenCASCADE IGESControl_Reader ReadFile + TransferRoots: median {t_occ:.3f} s")
        print(f"ratio read_iges / OCC: {m['strict_ratio']:.2f}; ratio import / OCC: {m['import_ratio']:.2f} "
              "(medians of per-round ratios, interleaved)")
        print(f"in CPU time: ratio read_iges / OCC {m['strict_cpu_ratio']:.2f}; import / OCC "
              f"{m['import_cpu_ratio']:.2f}; load average {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
