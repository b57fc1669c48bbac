"""The README's main job, headless: ``make demo`` (or ``.venv/bin/python scripts/demo.py``).

Builds the tip-smoothed DTMB 4119 propeller from the shipped preset with the scripting
contract a user would use (``bpy.ops.bladesmith.add_propeller``), then writes

- ``OUT/dtmb4119.blend``: the scene (the objects keep their exact float64 data);
- ``OUT/dtmb4119.igs``: the reference blade's five surfaces and the trimmed hub sector,
  written from the float64 model by ``bpy.ops.export_scene.iges`` (Hally 2013 §11);
- ``OUT/dtmb4119_review.png``: a curvature review image (pressure side, suction side,
  tip close-up, with the legend).

It prints what it did: counts, the deviation of the smoothed blade from the section
table's blade, the shared-edge gaps, and the time of each step.
"""
from __future__ import annotations

import argparse
import importlib.util
import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
PRESET = "DTMB4119"


def load_addon():
    spec = importlib.util.spec_from_file_location(
        "bladesmith", ROOT / "__init__.py", submodule_search_locations=[str(ROOT)]
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules["bladesmith"] = module
    spec.loader.exec_module(module)
    return module


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out", help="output folder (created)")
    args = parser.parse_args(argv)
    out = pathlib.Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)

    import bpy

    addon = load_addon()
    addon.register()
    try:
        from bladesmith.geometry.propeller import Propeller, smooth_blade
        from bladesmith.operators import propeller as propeller_ops

        bpy.ops.wm.read_factory_settings(use_empty=True)
        steps = {}
        start = time.perf_counter()
        result = bpy.ops.bladesmith.add_propeller(preset=PRESET, smooth_tip=True)
        steps["build (model, smoothing, display)"] = time.perf_counter() - start
        if result != {"FINISHED"}:
            print("add_propeller failed", file=sys.stderr)
            return 1
        root = next(o for o in bpy.context.scene.objects if getattr(o, "bladesmith_propeller", None)
                    and o.bladesmith_propeller.is_propeller)
        parts = propeller_ops.propeller_parts(root)
        print(f"{root.name}: {len(parts)} objects ({sum(1 for k in parts if k[0] == 'blade')} blade surfaces "
              f"including linked copies, hub)")

        # the numbers a user checks: a measured run of the same pipeline
        definition = Propeller.from_toml(ROOT / "data" / "propellers" / "dtmb4119.toml")
        t = time.perf_counter()
        smoothed = smooth_blade(definition.build(), measure=True)
        steps["smoothing with measurement"] = time.perf_counter() - t
        report = smoothed.report
        D = definition.diameter
        cuts, knots = report["cuts"], report["knots"]
        print(f"cuts: {cuts['tip']} tip, {cuts['leading_edge']} LE, {cuts['trailing_edge']} TE "
              f"({cuts['smoothed']} smoothed), transition cut j = {report['transition_index'] + 1} (1-based); one knot vector for "
              f"{knots['curves']} curves: {knots['n_control']} control points each")
        dev = report["deviation_m"]
        print(f"deviation from the section-table blade: {dev['max_outside']:.2e} m outside the smoothing zone "
              f"(tolerance {report['tolerance_m']:.2e} m), {dev['max_inside']:.2e} m inside "
              f"(bound {report['deviation_bound_inside_m']:.2e} m)")
        gaps = [e["max_gap"] for e in report["shared_edges"]]
        print(f"shared edges: {len(gaps)}, largest gap {max(gaps):.1e} m ({max(gaps) / D:.1e} D)")

        blend = out / "dtmb4119.blend"
        t = time.perf_counter()
        bpy.ops.wm.save_as_mainfile(filepath=str(blend))
        steps["save .blend"] = time.perf_counter() - t
        print(f"wrote {blend}")

        igs = out / "dtmb4119.igs"
        t = time.perf_counter()
        assert bpy.ops.export_scene.iges(filepath=str(igs), units="M") == {"FINISHED"}
        steps["IGES export"] = time.perf_counter() - t
        print(f"wrote {igs}")

        from bladesmith.operators.curvature_review import render_review_image

        image = out / "dtmb4119_review.png"
        t = time.perf_counter()
        # the five surfaces of the reference blade: the hub's curvature would set the limits
        reference_blade = [obj for key, obj in parts.items() if key[0] == "blade" and key[2] == 0]
        # the heading names the preset; the review adds a line with every smoothing setting
        title = f"{PRESET} preset, tip smoothed"
        render_review_image(reference_blade, str(image), percentile=90.0, title=title)
        steps["review image (curvature maps, 3 views)"] = time.perf_counter() - t
        print(f"wrote {image}")

        for name, seconds in steps.items():
            print(f"  {name:40s} {seconds:7.2f} s")
    finally:
        addon.unregister()
    return 0


if __name__ == "__main__":
    sys.exit(main())
