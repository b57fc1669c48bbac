"""Mold halves of NREL 5-MW (Hosseini & Moetakef-Imani 2016): stage times of the full
pipeline (sections, SLSQP section fits on common knots, skinning with root transitions,
single surface, closest-point tolerance check, continuity, fairness), median of runs,
with the section-fit stage as a ratio of a plain least-squares fit of the same sections.

Baseline in the same run: the whole pipeline with the fairness integrals computed the
pre-issue-22 way (per point: ``principal_curvatures``, i.e. batched LAPACK Cholesky,
``inv`` and ``eigh`` on 2x2 matrices and scattered-point third derivatives)."""
from __future__ import annotations

import statistics
import sys
import time
from contextlib import contextmanager

from common import load_checkout, median_time, report

REPEAT = 3
GOAL_S = 0.3


def _old_surface_fairness(surface, quadrature_points=None):
    """The fairness integrals as computed before issue 22 (kept here as the baseline)."""
    import numpy as np
    from bladesmith.geometry.fairing import surface_fairness as sf

    g = sf.DEFAULT_QUADRATURE_POINTS if quadrature_points is None else int(quadrature_points)
    us, wu = sf._gauss_nodes(surface.knots_u, g)
    vs, wv = sf._gauss_nodes(surface.knots_v, g)
    c = sf.principal_curvatures(surface, us[:, None], vs[None, :])
    W = wu[:, None] * wv[None, :] * c["dA"]
    mvs = float(np.sum(W * (c["dk1_de1"] ** 2 + c["dk2_de2"] ** 2)))
    se = float(np.sum(W * (c["k1"] ** 2 + c["k2"] ** 2)))
    return sf.Fairness(mvs, se, float(W.sum()))


@contextmanager
def _old_fairness():
    from bladesmith.geometry.fairing import surface_fairness as sf

    saved = sf.surface_fairness
    sf.surface_fairness = _old_surface_fairness
    try:
        yield
    finally:
        sf.surface_fairness = saved


def measure(repeat: int = REPEAT) -> dict:
    load_checkout()
    from bladesmith.geometry.mold import build_blade, load_preset

    defn = load_preset("NREL5MW")
    build_blade(defn)  # warm-up (imports, caches)
    runs, old = [], []
    for _ in range(repeat):
        start = time.perf_counter()
        m = build_blade(defn)
        runs.append((time.perf_counter() - start, m.times))
        with _old_fairness():
            start = time.perf_counter()
            m_old = build_blade(defn)
            old.append((time.perf_counter() - start, m_old.times))
    if m_old.fairness != m.fairness:
        worst = max(abs(m.fairness[k][q] - m_old.fairness[k][q]) / abs(m_old.fairness[k][q])
                    for k in m.fairness for q in m.fairness[k])
        if worst > 1e-10:
            raise RuntimeError(f"fairness figures moved: relative difference {worst:.1e}")
    return {
        "defn": defn, "m": m,
        "total": statistics.median(r[0] for r in runs),
        "stages": {k: statistics.median(r[1][k] for r in runs) for k in runs[0][1]},
        "old_total": statistics.median(r[0] for r in old),
        "old_fairness": statistics.median(r[1]["fairness"] for r in old),
    }


def figures() -> list[dict]:
    r = measure()
    return [
        {"figure": "NREL 5-MW molds with fairness", "value": r["total"], "unit": "s",
         "baseline": f"{r['old_total']:.2f} s pre-issue-22 fairness, same run", "goal": f"<= {GOAL_S} s"},
    ]


def main() -> None:
    load_checkout()
    from bladesmith.geometry.mold.blade import blade_sections
    from bladesmith.geometry.mold.sections import fit_single

    r = measure()
    defn, m, stages, total = r["defn"], r["m"], r["stages"], r["total"]
    splits = blade_sections(defn)
    n = m.control_points
    baseline = median_time(lambda: [fit_single(s.points, n_control=2 * n - 1) for s in splits], repeat=REPEAT)
    rows = [(k, v, "") for k, v in stages.items()]
    rows.append(("total (limit 3 s)", total, f"{len(defn.stations)} stations, {n} control points per half; "
                 f"goal <= {GOAL_S} s"))
    rows.append(("baseline: plain LSQ fits", baseline,
                 f"section fits / baseline = {stages['section_fits'] / baseline:.1f}x"))
    rows.append(("baseline: pre-issue-22 fairness stage", r["old_fairness"],
                 f"fairness now {stages['fairness'] / r['old_fairness']:.2f}x of it"))
    rows.append(("baseline: total with pre-issue-22 fairness", r["old_total"],
                 f"total now {total / r['old_total']:.2f}x of it"))
    report("NREL 5-MW mold halves, root transitions and fairness", rows)


if __name__ == "__main__":
    sys.exit(main())
