"""Before/after review of the tip-smoothed DTMB 4119 against the unsmoothed blade (issue
15): the deviation maps of ``curvature_review(reference=...)``, one signed distance per
map vertex of the five smoothed surfaces from the unsmoothed blade's display surface.

Measured in the same run (CPU time of this process: the work is single-threaded numpy,
and on a shared machine CPU time is the one-core figure; wall time is also printed):

- the previous method (baseline): every map point from its nearest tessellation point
  by the safeguarded Newton iteration (zero-cosine tolerance 1e-8) and again from every
  neighbour on another branch (what ``signed_deviation`` did before);
- ``signed_deviation_grid`` (what the review calls now): coarse points in full, the rest
  by Gauss–Newton from blended starts; its largest difference from the baseline;
- the curvature maps of the same five surfaces (what the review computes anyway);
- with the bpy module: the whole review, ``review_objects(reference=...)`` of the
  smoothed propeller's blade against the unsmoothed one's (what
  ``bpy.ops.bladesmith.curvature_review(reference=...)`` runs), median of 3.

``figures()`` gives the table rows of ``make bench`` (bench/summary.py).
"""
from __future__ import annotations

import time

import numpy as np

from common import ROOT, load_checkout, report

REPEAT = 3
#: The previous method's Newton tolerance and neighbours.
BASELINE_COSINE_TOL = 1e-8


def _cpu(fn, repeat: int = REPEAT):
    """(result, median CPU seconds, median wall seconds) after one warm-up run."""
    fn()
    cpu, wall = [], []
    for _ in range(repeat):
        c, w = time.process_time(), time.perf_counter()
        out = fn()
        cpu.append(time.process_time() - c)
        wall.append(time.perf_counter() - w)
    return out, float(np.median(cpu)), float(np.median(wall))


def baseline_deviation(points, reference):
    """The previous signed_deviation: KD-tree start, Newton to 1e-8, restarts from every
    other-branch neighbour among the 4 nearest tessellation points."""
    from scipy.spatial import cKDTree

    from bladesmith.geometry.fairing.surface_curvature import span_parameters
    from bladesmith.geometry.nurbs.projection import refine_closest_points

    us = span_parameters(reference.knots_u, reference.degree_u, 6)
    vs = span_parameters(reference.knots_v, reference.degree_v, 6)
    G = reference.evaluate_grid(us, vs).reshape(-1, 3)
    _, idx = cKDTree(G).query(points, k=4)
    iu, iv = idx // vs.size, idx % vs.size
    newton = {"cos_tol": BASELINE_COSINE_TOL, "max_iterations": 25}
    u, v, d = refine_closest_points(reference, points, us[iu[:, 0]], vs[iv[:, 0]], **newton)
    for k in range(1, 4):
        other = (np.abs(iu[:, k] - iu[:, 0]) > 2) | (np.abs(iv[:, k] - iv[:, 0]) > 2)
        if not np.any(other):
            continue
        sel = np.flatnonzero(other)
        u2, v2, d2 = refine_closest_points(reference, points[sel], us[iu[sel, k]], vs[iv[sel, k]], **newton)
        better = d2 < d[sel]
        u[sel[better]], v[sel[better]], d[sel[better]] = u2[better], v2[better], d2[better]
    with np.errstate(divide="ignore", invalid="ignore"):
        side = np.sign(np.einsum("ij,ij->i", points - reference.evaluate(u, v), reference.normal(u, v)))
    return d * np.where((side == 0) | ~np.isfinite(side), 1.0, side)


def measure() -> dict:
    load_checkout()
    from bladesmith.geometry.fairing.review import surface_map
    from bladesmith.geometry.fairing.surface_curvature import DeviationSeeds, signed_deviation_grid
    from bladesmith.geometry.propeller import Propeller
    from bladesmith.geometry.propeller.display import blade_display_surface
    from bladesmith.geometry.propeller.smoothing import smooth_blade

    model = Propeller.from_toml(ROOT / "data" / "propellers" / "dtmb4119.toml").build()
    smoothed = smooth_blade(model, measure=False)
    reference = blade_display_surface(model.blade, 2e-4 * model.blade.radius).surface
    surfaces = list(smoothed.named_surfaces.values())
    grids = [surface_map(s).points for s in surfaces]

    def new():
        seeds = DeviationSeeds(reference)
        return [signed_deviation_grid(g, reference, seeds) for g in grids]

    old_values, old_cpu, old_wall = _cpu(lambda: [baseline_deviation(g.reshape(-1, 3), reference) for g in grids])
    new_values, new_cpu, new_wall = _cpu(new)
    _, maps_cpu, maps_wall = _cpu(lambda: [surface_map(s) for s in surfaces])
    diff = max(float(np.max(np.abs(a - b.ravel()))) for a, b in zip(old_values, new_values))
    # where they differ, the new value should be the nearer point (both are distances to
    # points of the surface): the largest amount by which it is farther
    farther = max(float(np.max(np.abs(b.ravel()) - np.abs(a))) for a, b in zip(old_values, new_values))
    largest = max(float(np.max(np.abs(a))) for a in old_values)
    return {"points": sum(g.shape[0] * g.shape[1] for g in grids), "old_cpu": old_cpu, "old_wall": old_wall,
            "new_cpu": new_cpu, "new_wall": new_wall, "maps_cpu": maps_cpu, "maps_wall": maps_wall,
            "max_difference_m": diff, "max_farther_m": farther, "max_deviation_m": largest}


def measure_review() -> dict | None:
    """CPU and wall time of the whole before/after review in Blender (None without bpy)."""
    try:
        import bpy
    except ImportError:
        return None
    addon = load_checkout()
    addon.register()
    try:
        from bladesmith.operators import curvature_review as cr

        bpy.ops.wm.read_factory_settings(use_empty=True)
        assert bpy.ops.bladesmith.add_propeller(preset="DTMB4119") == {"FINISHED"}
        before = bpy.context.view_layer.objects.active
        assert bpy.ops.bladesmith.add_propeller(preset="DTMB4119", smooth_tip=True) == {"FINISHED"}
        after = bpy.context.view_layer.objects.active

        def blade(root):
            return [o for o in root.children_recursive
                    if o.get("bladesmith_part") == "blade" and int(o.get("bladesmith_blade", 0)) == 0]

        ref = bpy.data.collections.new("unsmoothed blade")
        for o in blade(before):
            ref.objects.link(o)
        scene = bpy.context.scene
        sources = blade(after)
        _, cpu, wall = _cpu(lambda: cr.review_objects(scene, sources, reference=ref.name))
        cr.clear_review(scene)
        return {"review_cpu": cpu, "review_wall": wall}
    finally:
        addon.unregister()


_CACHE: dict = {}


def _measured() -> dict:
    if not _CACHE:
        _CACHE.update(measure())
        _CACHE.update(measure_review() or {})
    return _CACHE


def figures() -> list[dict]:
    m = _measured()
    rows = []
    if "review_cpu" in m:
        rows.append({"figure": "before/after review, DTMB 4119 smoothed vs unsmoothed (CPU, one core)", "value": m["review_cpu"],
                     "unit": "s", "baseline": "", "goal": "<= 2 s"})
    return rows + [
        {"figure": "review deviation maps, DTMB 4119 smoothed vs unsmoothed (CPU)", "value": m["new_cpu"] * 1e3,
         "unit": "ms", "baseline": "", "goal": "whole review <= 2 s"},
        {"figure": "review deviation maps: speed-up over the previous projection", "value": m["old_cpu"] / m["new_cpu"],
         "unit": "x", "baseline": "per-point Newton to 1e-8 with every restart, same run", "goal": ""},
    ]


def main() -> dict:
    m = _measured()
    report(f"before/after deviation maps, DTMB 4119 ({m['points']} map points, 5 surfaces; CPU time, wall in notes)", [
        ("signed_deviation_grid (the review's)", m["new_cpu"],
         f"= {m['old_cpu'] / m['new_cpu']:.2f}x faster than the baseline; wall {m['new_wall']:.2f} s"),
        ("baseline: previous per-point projection", m["old_cpu"], f"wall {m['old_wall']:.2f} s"),
        ("the five curvature maps", m["maps_cpu"], f"wall {m['maps_wall']:.2f} s"),
    ])
    if "review_cpu" in m:
        print(f"  whole review_objects(reference=...) in Blender: {m['review_cpu']:.2f} s CPU "
              f"({m['review_wall']:.2f} s wall)")
    print(f"  largest difference from the baseline {m['max_difference_m']:.3g} m, largest amount farther than "
          f"the baseline {m['max_farther_m']:.3g} m (largest deviation {m['max_deviation_m']:.3g} m)")
    return m


if __name__ == "__main__":
    main()
