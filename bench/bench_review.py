"""Curvature review of the smoothed DTMB 4119 blade (5 surfaces): maps at display
resolution and combs on 20 iso lines, with and without the numbers, and the review image.
Baseline measured in the same run: evaluating the points alone of the same five grids
(``evaluate_grid``), i.e. what a plain tessellation of the exact model costs."""
from __future__ import annotations

import os
import sys
import tempfile
import time

from common import load_checkout, median_time, report


def main() -> None:
    try:
        import bpy
    except ImportError:
        print("bench_review: needs the bpy module; skipped")
        return
    load_checkout()
    from bladesmith.geometry.fairing.review import tip_cut_sign_changes
    from bladesmith.geometry.propeller import Propeller, SmoothingSettings, smooth_blade
    from bladesmith.operators import curvature_review as cr
    from bladesmith.operators.nurbs_objects import surface_to_object

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    model = Propeller.from_toml(os.path.join(os.path.dirname(__file__), "..", "data", "propellers", "dtmb4119.toml")).build()
    smoothed = smooth_blade(model, measure=False)
    plain = smooth_blade(model, SmoothingSettings(filter_iterations=0), measure=False)
    print("\n== DTMB 4119 tip cuts: in-plane curvature sign changes (tip surface iso lines u = i/(N_t-1))")
    before, after = tip_cut_sign_changes(plain), tip_cut_sign_changes(smoothed)
    flags = smoothed.curves.smoothed_tip
    print("  cut       " + " ".join(f"{i:2d}" for i in range(len(before))))
    print("  smoothed? " + " ".join(" y" if f else " ." for f in flags))
    print("  before    " + " ".join(f"{c:2d}" for c in before) + f"   total {sum(before)}")
    print("  after     " + " ".join(f"{c:2d}" for c in after) + f"   total {sum(after)}")
    root = bpy.data.objects.new("DTMB 4119", None)
    scene.collection.objects.link(root)
    objs = []
    for i, (name, S) in enumerate(smoothed.named_surfaces.items()):
        o = surface_to_object(S, f"DTMB 4119 blade {name}", resolution=2)
        o.parent = root
        o["bladesmith_part"], o["bladesmith_patch"] = "blade", i
        objs.append(o)
    from bladesmith.geometry.fairing.surface_curvature import span_parameters

    grids = [(S, span_parameters(S.knots_u, 3, 6), span_parameters(S.knots_v, 3, 6)) for S in smoothed.surfaces]

    def blender_tessellation():
        for S, us, vs in grids:
            S.evaluate_grid(us, vs)

    opts = dict(comb_lines=2, comb_teeth=100)  # 5 surfaces x 2 directions x 2 lines = 20 combs
    first = time.perf_counter()
    r = cr.review_objects(scene, [root], numbers=False, **opts)
    first = time.perf_counter() - first
    n_vertices = sum(len(m.data.vertices) for m in r.maps)
    base = median_time(blender_tessellation, repeat=5)
    maps_combs = median_time(lambda: cr.review_objects(scene, [root], numbers=False, **opts), repeat=5)
    full = median_time(lambda: cr.review_objects(scene, [root], **opts), repeat=5)
    cr.clear_review(scene)
    fresh = median_time(lambda: (cr.clear_review(scene), cr.review_objects(scene, [root], **opts)), repeat=3)
    report("curvature review, smoothed DTMB 4119 blade (5 surfaces)", [
        ("baseline: evaluate_grid, same grids", base, "points only"),
        ("review: maps + 20 combs (update)", maps_combs, f"{n_vertices} map vertices, ratio {maps_combs / base:.1f}x"),
        ("review: maps + combs + numbers", full, f"ratio {full / base:.1f}x (numbers: MVS, strain energy, iso counts)"),
        ("review from scratch, with numbers", fresh, "new objects every time"),
        ("first review in the session", first, "includes warm-up"),
    ])
    path = os.path.join(tempfile.mkdtemp(), "review.png")
    out = cr.render_review_image([root], path, percentile=90.0, **opts)
    if os.environ.get("BLADESMITH_REVIEW_IMAGE"):  # e.g. docs/review_dtmb4119.png
        import shutil

        shutil.copy(path, os.environ["BLADESMITH_REVIEW_IMAGE"])
    render = out["times"]
    report("review image (Workbench, 3 views 480 px + legend)", [
        ("review", render["review"], ""), ("3 views", render["views"], ""),
        ("legend + composite + write", render["legend_and_write"], ""),
        ("total", render["total"], f"limit ±{r.settings['limits'][1]:.3g} at 98%; image {path}"),
    ])


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(__file__))
    main()
