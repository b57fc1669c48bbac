"""Mold halves of NREL 5-MW (Hosseini & Moetakef-Imani 2016): stage times of the full
pipeline (sections, SLSQP section fits on common knots, skinning with root transitions,
single surface, closest-point tolerance check, continuity, fairness), median of runs,
with the section-fit stage as a ratio of a plain least-squares fit of the same sections."""
from __future__ import annotations

import statistics
import sys
import time

from common import load_checkout, median_time, report

REPEAT = 3


def main() -> None:
    load_checkout()
    from bladesmith.geometry.mold import build_blade, load_preset
    from bladesmith.geometry.mold.blade import blade_sections
    from bladesmith.geometry.mold.sections import fit_single

    defn = load_preset("NREL5MW")
    runs = []
    for _ in range(REPEAT):
        start = time.perf_counter()
        m = build_blade(defn)
        runs.append((time.perf_counter() - start, m.times))
    total = statistics.median(r[0] for r in runs)
    stages = {k: statistics.median(r[1][k] for r in runs) for k in runs[0][1]}
    splits = blade_sections(defn)
    n = m.control_points
    baseline = median_time(lambda: [fit_single(s.points, n_control=2 * n - 1) for s in splits], repeat=REPEAT)
    rows = [(k, v, "") for k, v in stages.items()]
    rows.append(("total (limit 3 s)", total, f"{len(defn.stations)} stations, {n} control points per half"))
    rows.append(("baseline: plain LSQ fits", baseline,
                 f"section fits / baseline = {stages['section_fits'] / baseline:.1f}x"))
    report("NREL 5-MW mold halves, root transitions and fairness", rows)


if __name__ == "__main__":
    sys.exit(main())
