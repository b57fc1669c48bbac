"""Impeller panel edit in Blender: one beta coefficient changed, the full wheel regenerated
(channel and first blade written in place, blades 2..Z as linked rotated copies) and the
depsgraph evaluated. The issue's budget is 0.2 s; the baseline is the geometry alone
(definition -> model -> surfaces of the full wheel), measured in the same run."""
from __future__ import annotations

from common import load_checkout, median_time, report

PRESETS = ("high_flow", "intermediate_flow", "low_flow", "return_channel")
#: Also timed standardised (Casey Fig. 11): the trimmed blades are fitted on every edit.
STANDARDISED = (("intermediate_flow", 0.8),)


def main() -> dict:
    addon = load_checkout()
    import bpy

    from bladesmith.geometry.compressor.export import impeller_surfaces
    from bladesmith.operators import impeller as ops

    addon.register()
    results = {}
    try:
        for preset, factor in [(p, 1.0) for p in PRESETS] + list(STANDARDISED):
            bpy.ops.wm.read_factory_settings(use_empty=True)
            assert bpy.ops.bladesmith.add_impeller(preset=preset, full_wheel=True) == {"FINISHED"}
            root = bpy.context.active_object
            settings = root.bladesmith_impeller
            definition = ops.load_definition(preset=preset)
            if factor != 1.0:
                settings.shroud_factor = factor
                assert settings.status == "", settings.status
                data = definition.to_dict()
                data["standardisation"] = {"shroud_factor": factor}
                definition = type(definition).from_dict(data)
                preset = f"{preset}, shroud factor {factor}"
            sign = [1.0]

            def edit():
                settings.beta_hub[1].value = settings.beta_hub[1].value + 0.5 * sign[0]
                sign[0] = -sign[0]
                bpy.context.evaluated_depsgraph_get().update()

            t_edit = median_time(edit, repeat=7)
            t_geometry = median_time(lambda: impeller_surfaces(definition.build()), repeat=7)
            results[preset] = t_edit
            report(f"impeller panel edit, {preset} ({len(root.children)} objects)", [
                ("edit -> objects + depsgraph", t_edit, f"{t_edit / 0.2:.2f} of the 0.2 s budget"),
                ("baseline: geometry of the full wheel", t_geometry, f"edit = {t_edit / t_geometry:.1f} x baseline"),
            ])
    finally:
        addon.unregister()
    return results


if __name__ == "__main__":
    main()
