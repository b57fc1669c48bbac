"""The README's review images, headless: ``.venv/bin/python scripts/review_images.py [--out docs]``.

Builds, with the scripting contract (``bpy.ops.bladesmith.*``), the tip-smoothed DTMB 4119
propeller, the NREL 5-MW mold halves and the high-flow impeller, and renders each one's
curvature review image (:func:`bladesmith.operators.curvature_review.render_review_image`):

- ``review_dtmb4119.png``: the whole propeller selected (blade, copies and hub; the hub
  is left out of the colour limits), mean curvature;
- ``review_nrel5mw_molds.png``: the mold halves and root transitions, mean curvature, in
  span segments;
- ``review_nrel5mw_zebra.png``: the same blade as zebra stripes (reflection lines);
- ``review_iea15mw_molds.png`` (only with ``--only iea``): the IEA 15 MW mold halves from
  its windIO file (../shared/data/wind), at the default tolerance, mean curvature;
- ``review_high_flow.png``: one blade of the high-flow impeller (S, P and LE surfaces),
  mean curvature;
- ``review_dtmb4119_before_after.png``: the smoothed blade against the unsmoothed one
  (before | after | deviation, same limits), at the default 6 samples per knot span; the
  heading names the preset, before/after and the smoothing settings.
"""
from __future__ import annotations

import argparse
import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
from demo import load_addon  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "docs"))
    parser.add_argument("--only", default="", help="comma-separated subset: dtmb,nrel,zebra,impeller,compare,iea")
    args = parser.parse_args(argv)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    only = set(filter(None, args.only.split(",")))

    import bpy

    addon = load_addon()
    addon.register()
    try:
        from bladesmith.operators.curvature_review import clear_review, render_review_image

        def fresh():
            bpy.ops.wm.read_factory_settings(use_empty=True)

        def roots():
            return [o for o in bpy.context.scene.objects if o.parent is None and o.type == "EMPTY"]

        def run(name, objects, title, **options):
            t = time.perf_counter()
            info = render_review_image(objects, str(out / name), title=title, **options)
            clear_review(bpy.context.scene)
            print(f"wrote {out / name}: {info['views']} in {time.perf_counter() - t:.1f} s")

        if not only or "dtmb" in only:
            fresh()
            assert bpy.ops.bladesmith.add_propeller(preset="DTMB4119", smooth_tip=True) == {"FINISHED"}
            run("review_dtmb4119.png", roots(), "DTMB 4119 propeller (preset DTMB4119), tip smoothed (Hally 2013), "
                "whole propeller selected", percentile=90.0, comb_lines=0)
        if not only or "compare" in only:
            fresh()
            assert bpy.ops.bladesmith.add_propeller(preset="DTMB4119", smooth_tip=False) == {"FINISHED"}
            before = roots()[0]
            before.name = "DTMB 4119 unsmoothed"
            assert bpy.ops.bladesmith.add_propeller(preset="DTMB4119", smooth_tip=True) == {"FINISHED"}
            after = [r for r in roots() if r is not before][0]
            blade = lambda root: [o for o in root.children_recursive  # noqa: E731
                                  if o.get("bladesmith_part") == "blade" and int(o.get("bladesmith_blade", 0)) == 0]
            ref = bpy.data.collections.new("unsmoothed blade")
            for o in blade(before):
                ref.objects.link(o)
            # the default heading: preset, before/after and the smoothing settings
            run("review_dtmb4119_before_after.png", blade(after), "", percentile=90.0, comb_lines=0,
                reference=ref.name)
        if not only or "nrel" in only or "zebra" in only:
            fresh()
            assert bpy.ops.bladesmith.add_wind_blade(preset="NREL5MW", mold_halves=True) == {"FINISHED"}
            surfaces = [o for o in bpy.context.scene.objects if o.type == "SURFACE"]
            if not only or "nrel" in only:
                run("review_nrel5mw_molds.png", surfaces, "NREL 5-MW blade (preset NREL5MW), mold halves "
                    "(Hosseini 2016)", percentile=95.0, comb_lines=0, panel_size=360)
            if not only or "zebra" in only:
                run("review_nrel5mw_zebra.png", surfaces, "NREL 5-MW blade (preset NREL5MW), mold halves: zebra "
                    "stripes", quantity="zebra", comb_lines=0, samples_per_span=16, panel_size=360)
        if "iea" in only:
            fresh()
            iea = ROOT.parent / "shared" / "data" / "wind" / "IEA-15-240-RWT.yaml"
            assert bpy.ops.bladesmith.add_wind_blade(definition=str(iea), mold_halves=True) == {"FINISHED"}
            surfaces = [o for o in bpy.context.scene.objects if o.type == "SURFACE"]
            # the heading is not wrapped: keep it within the narrow (one-blade-wide) image
            run("review_iea15mw_molds.png", surfaces, "IEA 15 MW (windIO), mold halves, tolerance 1e-4 c",
                percentile=95.0, comb_lines=0, panel_size=360)
        if not only or "impeller" in only:
            fresh()
            assert bpy.ops.bladesmith.add_impeller(preset="high_flow", full_wheel=False) == {"FINISHED"}
            # the blade's suction, pressure and leading-edge surfaces (not the camber sheet B)
            surfaces = [o for o in bpy.context.scene.objects if o.type == "SURFACE"
                        and str(o.get("bladesmith_part", "")).startswith("blade") and not o["bladesmith_part"].endswith(" B")]
            run("review_high_flow.png", surfaces, "High-flow impeller (preset high_flow, Casey 1983): one blade's S, P and LE surfaces", percentile=95.0, comb_lines=0)
    finally:
        addon.unregister()
    return 0


if __name__ == "__main__":
    sys.exit(main())
