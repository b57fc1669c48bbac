"""Hally (2013) tip smoothing of the blade (§§3–9) for DTMB 4119 and the skewed demo at
default settings: median time per stage and in total (issue 5: the blade part well under
2 s on one core; the hub sector and IGES take the rest). Baseline measured in the same
run: one evaluation of b and its first derivatives at 1000 points (the unit of cost the
marching and Newton stages pay per call).
"""
from __future__ import annotations

import statistics

import numpy as np

from common import ROOT, load_checkout, median_time, report

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


if __name__ == "__main__":
    main()
