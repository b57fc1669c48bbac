"""Bicubic surface with 50x50 control points evaluated at 10^6 scattered parameter pairs.

Ratio against scipy.interpolate.NdBSpline on the same data in the same run (the
acceptance bound of the foundation issue is 1.5), and against geomdl when it is installed
(pure Python, so it runs on a 2,000-pair subset and the time is scaled per pair).
"""
from __future__ import annotations

import statistics

import numpy as np

from common import load_checkout, median_time, report

N_CONTROL = 50
N_PAIRS = 10**6
GEOMDL_PAIRS = 2000


GOAL_RATIO = 0.5


def measure(repeat: int = 5) -> dict:
    """Median times of our evaluate and NdBSpline at the same pairs, in the same run."""
    load_checkout()
    from bladesmith.geometry.nurbs import BSplineSurface
    from scipy.interpolate import NdBSpline

    rng = np.random.default_rng(2026)
    knots = [
        np.concatenate([np.zeros(4), np.sort(rng.uniform(0, 1, N_CONTROL - 4)), np.ones(4)]) for _ in range(2)
    ]
    net = rng.normal(size=(N_CONTROL, N_CONTROL, 3))
    ours = BSplineSurface(3, 3, knots[0], knots[1], net)
    scipy_surface = NdBSpline(tuple(knots), net, (3, 3))
    uv = rng.uniform(0, 1, (N_PAIRS, 2))
    u, v = uv[:, 0].copy(), uv[:, 1].copy()

    # interleaved, so that both see the same load on a shared machine
    t_ours, t_scipy = [], []
    ours.evaluate(u, v)  # warm-up: builds the cached patch table and span lookups
    for _ in range(repeat):
        t_ours.append(median_time(lambda: ours.evaluate(u, v), repeat=1, warmup=0))
        t_scipy.append(median_time(lambda: scipy_surface(uv), repeat=1, warmup=0))
    t_ours, t_scipy = statistics.median(t_ours), statistics.median(t_scipy)
    error = np.abs(ours.evaluate(u, v) - scipy_surface(uv)).max() / ours.size()
    return {"ours_s": t_ours, "ndbspline_s": t_scipy, "ratio": t_ours / t_scipy, "error": error,
            "knots": knots, "net": net, "uv": uv}


def figures() -> list[dict]:
    r = measure()
    return [{"figure": "surface evaluation vs NdBSpline, 10^6 points on a 50x50 bicubic", "value": r["ratio"],
             "unit": "x", "baseline": f"scipy NdBSpline {r['ndbspline_s'] * 1e3:.0f} ms, same run",
             "goal": f"<= {GOAL_RATIO}x"}]


def main() -> dict:
    r = measure()
    knots, net, uv = r["knots"], r["net"], r["uv"]
    t_ours, t_scipy, error = r["ours_s"], r["ndbspline_s"], r["error"]
    rows = [
        ("bladesmith BSplineSurface.evaluate", t_ours, f"ratio to NdBSpline {t_ours / t_scipy:.2f} (goal <= {GOAL_RATIO})"),
        ("scipy NdBSpline", t_scipy, f"max difference {error:.1e} of the net size"),
    ]
    result = {"ours_s": t_ours, "ndbspline_s": t_scipy, "ratio": t_ours / t_scipy}
    try:
        from geomdl import BSpline as GeomdlBSpline
    except ImportError:
        rows.append(("geomdl", float("nan"), "not installed (make bench installs requirements-bench.txt)"))
    else:
        g = GeomdlBSpline.Surface()
        g.degree_u = g.degree_v = 3
        g.ctrlpts2d = net.tolist()
        g.knotvector_u, g.knotvector_v = knots[0].tolist(), knots[1].tolist()
        pairs = uv[:GEOMDL_PAIRS].tolist()
        t_g = median_time(lambda: g.evaluate_list(pairs), repeat=3, warmup=0) * N_PAIRS / GEOMDL_PAIRS
        rows.append(("geomdl (scaled to 10^6 pairs)", t_g, f"ours is {t_g / t_ours:.0f}x faster"))
        result["geomdl_s"] = t_g
    report(f"bicubic {N_CONTROL}x{N_CONTROL} surface at {N_PAIRS:,} parameter pairs", rows)
    return result


if __name__ == "__main__":
    main()
