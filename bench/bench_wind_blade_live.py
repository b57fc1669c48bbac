"""Wind-blade molds in Blender (bpy module, background mode): add_wind_blade per preset and
a station edited in the panel -> the molds rebuilt and the objects rewritten in place.

Printed per preset: build_blade alone with fairness (baseline, the operator's geometry),
the add_wind_blade operator, a live chord edit (fairness off, fit seeded with the shown
control-point count), the same plus Blender's evaluation, the "Compute Fairness" button,
and the "Regenerate" button (fit from the definition's count, raising until within
tolerance), with ratios against the baseline measured in the same run.
"""
from __future__ import annotations

import sys

from common import load_checkout, median_time, report

REPEAT = 5


def main() -> None:
    bladesmith = load_checkout()
    import bpy

    from bladesmith.geometry.mold import build_blade, load_preset
    from bladesmith.operators import wind_blade as ops
    from bladesmith.ui import wind_blade_panel as panel

    bladesmith.register()
    here = not hasattr(bpy.types.Object, "bladesmith_wind_blade")
    if here:
        ops.register()
        panel.register()
    try:
        for preset, station_index in (("S823_SMALL", 5), ("NREL5MW", 10)):
            bpy.ops.wm.read_factory_settings(use_empty=True)
            defn = load_preset(preset)

            def build():
                build_blade(defn, fairness=True)

            def add():
                bpy.ops.bladesmith.add_wind_blade(preset=preset)

            baseline = median_time(build, REPEAT)
            rows = [("build_blade with fairness (baseline)", baseline, "x1.0")]
            seconds = median_time(add, REPEAT)
            rows.append(("add_wind_blade (build + objects)", seconds, f"x{seconds / baseline:.2f} baseline"))

            root = next(obj for obj in bpy.data.objects if ops.find_root(obj) is obj)
            bpy.context.view_layer.objects.active = root
            settings = root.bladesmith_wind_blade
            station = settings.stations[station_index]
            base_chord = station.chord
            state = {"n": 0}
            view_layer = bpy.context.view_layer

            def edit_chord():
                state["n"] += 1
                station.chord = base_chord * (1.0 + 0.01 * (-1) ** state["n"])

            def edit_and_evaluate():
                edit_chord()
                view_layer.update()

            def fairness():
                bpy.ops.bladesmith.wind_blade_fairness()

            def regenerate_fresh():
                bpy.ops.bladesmith.regenerate_wind_blade()

            for label, fn in (
                ("live chord edit (fairness off, seeded count)", edit_chord),
                ("live chord edit + Blender evaluation", edit_and_evaluate),
                ("Compute Fairness button", fairness),
                ("Regenerate button (count raised afresh)", regenerate_fresh),
            ):
                seconds = median_time(fn, REPEAT)
                rows.append((label, seconds, f"x{seconds / baseline:.2f} baseline"))
            report(f"Wind blade {preset} (median of {REPEAT})", rows)
            print(f"  {len(settings.stations)} stations, {settings.fitted_control_points} control points per half; "
                  f"status: {settings.status}")
    finally:
        if here:
            panel.unregister()
            ops.unregister()
        bladesmith.unregister()


if __name__ == "__main__":
    sys.exit(main())
