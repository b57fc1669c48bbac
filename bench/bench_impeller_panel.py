"""Impeller panel edits of the settings issue 18 exposes (blade count, patches, tolerance,
element type, LE/TE rounding, splitter on/off), each regenerating the first blade (full
wheel off) and evaluating the depsgraph. Budget 50 ms per edit (issue 18). Baseline: the
geometry alone (definition -> model with the adaptive patch count -> surfaces of one
blade), measured in the same run, and the same with a fixed patch count (tolerance 0)."""
from __future__ import annotations

import dataclasses

from common import load_checkout, median_time, report

BUDGET = 0.05


def main() -> dict:
    addon = load_checkout()
    import bpy

    from bladesmith.geometry.compressor.export import impeller_surfaces
    from bladesmith.operators import impeller as ops

    addon.register()
    results = {}
    try:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        assert bpy.ops.bladesmith.add_impeller(preset="high_flow", full_wheel=False) == {"FINISHED"}
        s = bpy.context.active_object.bladesmith_impeller
        edits = {
            "blade count 15 <-> 14": ("blade_count", 15, 14),
            "patches 65 <-> 66": ("patches", 65, 66),
            "tolerance 1e-6 <-> 2e-6": ("tolerance", 1e-6, 2e-6),
            "LE rounding 3 <-> 2.5": ("leading_edge_ratio", 3.0, 2.5),
            "TE rounding 0 <-> 2": ("trailing_edge_ratio", 0.0, 2.0),
            "splitter off <-> on": ("splitter", False, True),
            "spacing meridional <-> blade": ("patch_spacing", "meridional", "blade"),
        }
        rows = []
        for label, (key, a, b) in edits.items():
            state = [b]

            def edit():
                setattr(s, key, state[0])
                state[0] = a if state[0] == b else b
                bpy.context.evaluated_depsgraph_get().update()

            t = median_time(edit, repeat=6)
            assert s.status == "", s.status
            results[label] = t
            rows.append((label, t, f"{t / BUDGET:.2f} of the 50 ms budget"))
        d = ops.load_definition(preset="high_flow")
        fixed = dataclasses.replace(d, blade=dataclasses.replace(d.blade, tolerance=0.0))
        rows.append(("baseline: geometry, adaptive (1e-6 D)", median_time(lambda: impeller_surfaces(d.build(), 1), 5), ""))
        rows.append(("baseline: geometry, fixed 65 patches", median_time(lambda: impeller_surfaces(fixed.build(), 1), 5), ""))
        report("impeller panel edits (high_flow, first blade)", rows)
    finally:
        addon.unregister()
    return results


if __name__ == "__main__":
    main()
