"""Hally (2013) tip smoothing of the blade (§§3–9) for DTMB 4119 and the skewed demo at
default settings: median time per stage and in total (issue 5: the blade part well under
2 s on one core; the hub sector and IGES take the rest). Baseline measured in the same
run: one evaluation of b and its first derivatives at 1000 points (the unit of cost the
marching and Newton stages pay per call).

``figures()`` (``make bench``, issue 22): the smoothing core alone, cold (TOML -> model ->
``smooth_blade``, the marching surrogate rebuilt as after a geometry edit), on this
checkout and on the main commit before issue 22's smoothing-core work (BASELINE_COMMIT,
unpacked from git into a temporary folder and imported as a second package), timed
alternately so that both see the same load; without git the baseline is left out.
"""
from __future__ import annotations

import importlib
import importlib.util
import os
import pathlib
import shutil
import statistics
import tempfile
import time

for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import numpy as np  # noqa: E402

from common import ROOT, load_checkout, load_commit, median_time, report  # noqa: E402

#: main before issue 22's smoothing-core work (session 5).
BASELINE_COMMIT = "7349c2f"
CORE_REPEAT = 9

REPEAT = 5
STAGES = ("corners", "side_curves", "cuts_and_edge_curves", "common_knots", "surfaces")


def main() -> dict:
    load_checkout()
    from bladesmith.geometry.propeller import Propeller
    from bladesmith.geometry.propeller.smoothing import smooth_blade

    results = {}
    for name in ("dtmb4119", "skewed_demo"):
        model = Propeller.from_toml(ROOT / "data" / "propellers" / f"{name}.toml").build()
        model.blade_hub_intersection  # part of the model, not of smoothing
        runs = []

        def run():
            runs.append(smooth_blade(model, measure=False).report["times_s"])

        total = median_time(run, repeat=REPEAT)
        rng = np.random.default_rng(1)
        xi, eta = rng.uniform(0, 1, 1000), rng.uniform(0.3, 1.0, 1000)
        base = median_time(lambda: model.blade.derivatives(xi, eta, 1), repeat=20)
        rows = [(stage, statistics.median(r[stage] for r in runs), "") for stage in STAGES]
        rows.append(("total (smooth_blade, measure=False)", total, f"= {total / base:.0f} x baseline"))
        rows.append(("baseline: b and derivatives at 1000 points", base, ""))
        measured = smooth_blade(model).report["times_s"]["measure"]
        rows.append(("(not in total) deviation and edge measurement", measured, ""))
        report(f"tip smoothing, {name}", rows)
        results[name] = total
    return results


def core_times(case: str = "dtmb4119", repeat: int = CORE_REPEAT) -> dict:
    """Median cold smooth_blade time (s) per package, this checkout and the baseline,
    timed alternately."""
    load_checkout()
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="bench_core_"))
    try:
        packages = ["bladesmith"]
        base = load_commit(BASELINE_COMMIT, tmp, "bladesmith_core_baseline")
        if base is not None:
            packages.append(base)
        path = ROOT / "data" / "propellers" / f"{case}.toml"
        runs = {}
        for pkg in packages:
            prop = importlib.import_module(pkg + ".geometry.propeller")

            def run(prop=prop):
                model = prop.Propeller.from_toml(path).build()
                model.blade_hub_intersection  # part of the model, not of smoothing
                start = time.perf_counter()
                prop.smooth_blade(model, measure=False)
                return time.perf_counter() - start

            run()
            runs[pkg] = run
        times = {k: [] for k in runs}
        for _ in range(repeat):
            for k, fn in runs.items():
                times[k].append(fn())
        return {("new" if k == "bladesmith" else "baseline"): statistics.median(v) for k, v in times.items()}
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def figures() -> list[dict]:
    t = core_times()
    new = t["new"]
    baseline = ""
    if "baseline" in t:
        baseline = f"{t['baseline'] * 1e3:.0f} ms at {BASELINE_COMMIT} in the same run ({new / t['baseline']:.2f}x)"
    return [{"figure": "Hally smoothing core, DTMB 4119, model -> 5 surfaces, cold, one core", "value": new * 1e3,
             "unit": "ms", "baseline": baseline, "goal": "<= 30 ms"}]


if __name__ == "__main__":
    main()
    for row in figures():
        print(f"\n  {row['figure']}: {row['value']:.1f} {row['unit']} (goal {row['goal']}); baseline: {row['baseline']}")
