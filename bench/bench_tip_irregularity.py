"""Issue 15 acceptance figures (not pass/fail): for every preset and the irregular-tip
fixtures of tests/data/irregular_tips, the tip irregularity before -> after smoothing at
default settings, the deviation inside and outside the smoothing zone as reported and as
measured independently (a dense KD-tree-seeded projection of a 161 x 161 grid of every
surface onto b), and the sweeps of n (0..10,000) and α (0.05..0.75) on the steep irregular
tip. Baseline measured in the same run: smooth_blade(measure=False) on DTMB 4119.
"""
from __future__ import annotations

import time

import numpy as np

from common import ROOT, load_checkout, median_time, report

CASES = [ROOT / "data" / "propellers" / f"{n}.toml" for n in ("dtmb4119", "skewed_demo", "raked_demo")] + \
    [ROOT / "tests" / "data" / "irregular_tips" / f"{n}.toml" for n in ("steep_coarse", "skewed_fast")]
SWEEP_N = (0, 1, 10, 50, 100, 200, 500, 1000, 2000, 5000, 10000)
SWEEP_ALPHA = (0.05, 0.1, 0.25, 0.5, 0.75)


def independent_deviation(blade, sb, samples: int = 161):
    """Largest closest-point distance of each surface to b, inside and outside the zone."""
    from bladesmith.geometry.propeller.smoothing import BladeSeeds, _zone_mask, project_to_blade

    seeds = BladeSeeds(blade, blade.eta_min, 2400, 900)
    t = np.linspace(0.0, 1.0, samples)
    U, V = np.meshgrid(t, t, indexing="ij")
    u, v = U.ravel(), V.ravel()
    c = sb.curves
    zone = {"leading_edge": (c.smoothed_leading, v), "trailing_edge": (c.smoothed_trailing, v),
            "tip": (c.smoothed_tip, u)}
    inside, outside = 0.0, 0.0
    for name, S in sb.named_surfaces.items():
        X = S.evaluate(u, v)
        d, _ = project_to_blade(blade, X, seeds.nearest(X), iterations=60)
        z = _zone_mask(*zone[name]) if name in zone else np.zeros(d.shape, bool)
        inside = max(inside, float(d[z].max()) if z.any() else 0.0)
        outside = max(outside, float(d[~z].max()))
    return inside, outside


def main() -> dict:
    load_checkout()
    from bladesmith.geometry.propeller import Propeller
    from bladesmith.geometry.propeller.smoothing import SmoothingSettings, smooth_blade

    dtmb = Propeller.from_toml(CASES[0]).build()
    base = median_time(lambda: smooth_blade(dtmb, measure=False), repeat=3)
    for path in CASES:
        model = Propeller.from_toml(path).build()
        D = 2.0 * model.blade.radius
        start = time.perf_counter()
        sb = smooth_blade(model)
        took = time.perf_counter() - start
        ti, dev = sb.report["tip_irregularity"], sb.report["deviation_m"]
        ind_in, ind_out = independent_deviation(model.blade, sb)
        report(f"{path.stem}: tip irregularity {ti['unsmoothed']:.4g} -> {ti['smoothed']:.4g} "
               f"(x{ti['ratio']:.3f}); deviation/D inside {dev['max_inside'] / D:.3e} "
               f"(independent {ind_in / D:.3e}), outside {dev['max_outside'] / D:.3e} "
               f"(independent {ind_out / D:.3e}); {len(sb.report['warnings'])} warnings",
               [("smooth_blade(measure=True)", took, f"= {took / base:.1f} x baseline"),
                ("baseline: DTMB 4119 smooth_blade(measure=False)", base, "")])
    steep = Propeller.from_toml(CASES[3]).build()
    R = steep.blade.radius
    for label, key, values in (("n", "filter_iterations", SWEEP_N), ("alpha", "filter_strength", SWEEP_ALPHA)):
        print(f"\n== sweep of {label} on steep_coarse (measure, inside/R, stops)")
        for value in values:
            sb = smooth_blade(steep, SmoothingSettings(**{key: value}))
            ti = sb.report["tip_irregularity"]
            print(f"  {label} = {value:<6}  {ti['unsmoothed']:.4g} -> {ti['smoothed']:.4g}  "
                  f"inside/R {sb.report['deviation_m']['max_inside'] / R:.2e}  stops {len(sb.report['smoothing_stops'])}")
    return {"baseline": base}


if __name__ == "__main__":
    main()
