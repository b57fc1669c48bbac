"""Before/after review of the tip-smoothed DTMB 4119 against the unsmoothed blade (issue
15): the deviation maps of ``curvature_review(reference=...)``, i.e. ``signed_deviation``
of the five smoothed surfaces' map points from the unsmoothed blade's display surface
(the vectorised projection). Baseline measured in the same run: the curvature maps of
the same five surfaces (what the review computes anyway).
"""
from __future__ import annotations

from common import ROOT, load_checkout, median_time, report

REPEAT = 3


def main() -> dict:
    load_checkout()
    from bladesmith.geometry.fairing.review import surface_map
    from bladesmith.geometry.fairing.surface_curvature import signed_deviation
    from bladesmith.geometry.propeller import Propeller
    from bladesmith.geometry.propeller.display import blade_display_surface
    from bladesmith.geometry.propeller.smoothing import smooth_blade

    model = Propeller.from_toml(ROOT / "data" / "propellers" / "dtmb4119.toml").build()
    smoothed = smooth_blade(model, measure=False)
    reference = blade_display_surface(model.blade, 2e-4 * model.blade.radius).surface
    surfaces = list(smoothed.named_surfaces.values())
    maps = [surface_map(s) for s in surfaces]
    points = [m.points.reshape(-1, 3) for m in maps]

    def deviation():
        for p in points:
            signed_deviation(p, reference)

    base = median_time(lambda: [surface_map(s) for s in surfaces], repeat=REPEAT)
    t = median_time(deviation, repeat=REPEAT)
    n = sum(len(p) for p in points)
    report("before/after deviation maps, DTMB 4119", [
        (f"signed_deviation of {n} map points (5 surfaces)", t, f"= {t / base:.2f} x baseline"),
        ("baseline: the five curvature maps", base, ""),
    ])
    return {"deviation": t}


if __name__ == "__main__":
    main()
