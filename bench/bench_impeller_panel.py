"""Impeller panel edits of the settings issue 18 exposes (blade count, patches, tolerance,
element type, LE/TE rounding, splitter on/off, patch spacing), each regenerating the first
blade (full wheel off) and evaluating the depsgraph; and the standardised impeller panel
edit of issue 22 (intermediate_flow, shroud factor 0.8, full wheel, one β coefficient).
Budget 50 ms per edit (issues 18 and 22).

Three figures per setting, measured in the same run:
- "repeat": the edit toggles between two values, so after the first round every piece
  is in the build memory (geometry/compressor/memo.py): what a designer going back and
  forth between two values sees;
- "new value": every edit sets a value not used before in this session: the memory then
  holds only the pieces the edit does not change (a blade-count edit keeps the blade, an
  LE-rounding edit keeps B/S/P, a tolerance edit keeps the counts it visited before);
- "cold": the memory emptied before each edit: everything rebuilt, as before the memory
  existed (the old path; the geometry is also faster than on main, so "cold" is not main).
"""
from __future__ import annotations

import itertools
import statistics
import time

from common import load_checkout, median_time, report

BUDGET = 0.05
#: Edits per figure (medians).
REPEAT = 5

#: label: (property, two values to toggle, a generator of values never used before)
SETTINGS = {
    "blade count": ("blade_count", (15, 14), (16 + k for k in itertools.count())),
    "patches": ("patches", (65, 66), (40 + k for k in itertools.count())),
    "tolerance": ("tolerance", (1e-6, 2e-6), (1.05e-6 + 0.1e-6 * k for k in itertools.count())),
    "element type": ("elements", ("arbitrary", "axial"), None),
    "LE rounding": ("leading_edge_ratio", (3.0, 2.5), (2.0 + 0.1 * k for k in itertools.count())),
    "TE rounding": ("trailing_edge_ratio", (0.0, 2.0), (1.0 + 0.1 * k for k in itertools.count())),
    "splitter": ("splitter", (False, True), None),
    "splitter LE hub U": ("splitter_leading_edge_hub", (1.55, 1.6), (1.5 + 0.01 * k for k in itertools.count())),
    "patch spacing": ("patch_spacing", ("meridional", "blade"), None),
}


def _timed(edit, count: int) -> float:
    times = []
    for _ in range(count):
        start = time.perf_counter()
        edit()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> dict:
    addon = load_checkout()
    import bpy

    from bladesmith.geometry.compressor import export
    from bladesmith.geometry.compressor.memo import MEMORY

    def forget():
        MEMORY.clear()
        export._CONVERTED.clear()

    addon.register()
    results = {}
    try:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        assert bpy.ops.bladesmith.add_impeller(preset="high_flow", full_wheel=False) == {"FINISHED"}
        s = bpy.context.active_object.bladesmith_impeller
        rows = []
        for label, (key, (a, b), fresh) in SETTINGS.items():
            if label.startswith("splitter ") and not s.splitter:
                s.splitter = True
            state = [b]

            def toggle():
                setattr(s, key, state[0])
                state[0] = a if state[0] == b else b
                bpy.context.evaluated_depsgraph_get().update()

            def new_value():
                setattr(s, key, next(fresh))
                bpy.context.evaluated_depsgraph_get().update()

            def cold():
                forget()
                toggle()

            t_repeat = median_time(toggle, repeat=REPEAT + 1, warmup=2)
            assert s.status == "", (label, s.status)
            t_new = _timed(new_value, REPEAT) if fresh is not None else None
            assert s.status == "", (label, s.status)
            t_cold = _timed(cold, 3)
            setattr(s, key, a)
            if label.startswith("splitter"):
                s.splitter = False
            results[label] = (t_repeat, t_new, t_cold)
            rows.append((f"{label}: repeat", t_repeat, f"{t_repeat / BUDGET:.2f} of the budget"))
            if t_new is not None:
                rows.append((f"{label}: new value", t_new, f"{t_new / BUDGET:.2f} of the budget"))
            rows.append((f"{label}: cold (memory emptied)", t_cold, f"new value = {(t_new or t_repeat) / t_cold:.2f} x cold"))
        report("impeller panel edits (high_flow, first blade)", rows)

        # issue 22's row: standardised impeller, full wheel, a β coefficient edited
        bpy.ops.wm.read_factory_settings(use_empty=True)
        assert bpy.ops.bladesmith.add_impeller(preset="intermediate_flow", full_wheel=True) == {"FINISHED"}
        root = bpy.context.active_object
        settings = root.bladesmith_impeller
        settings.shroud_factor = 0.8
        assert settings.status == "", settings.status
        base = settings.beta_hub[1].value
        steps = itertools.count(1)

        def beta_new():
            settings.beta_hub[1].value = base + 0.01 * next(steps)
            bpy.context.evaluated_depsgraph_get().update()

        sign = [1.0]

        def beta_toggle():
            settings.beta_hub[1].value = base + 0.5 * (sign[0] > 0)
            sign[0] = -sign[0]
            bpy.context.evaluated_depsgraph_get().update()

        t_std_new = _timed(beta_new, REPEAT)
        t_std_repeat = median_time(beta_toggle, repeat=REPEAT + 1, warmup=2)

        def beta_cold():
            forget()
            beta_toggle()

        t_std_cold = _timed(beta_cold, 3)
        assert settings.status == "", settings.status
        results["standardised impeller panel edit"] = (t_std_repeat, t_std_new, t_std_cold)
        report("standardised impeller panel edit (intermediate_flow, shroud factor 0.8, full wheel, beta_hub[1])", [
            ("new value", t_std_new, f"{t_std_new / BUDGET:.2f} of the budget"),
            ("repeat", t_std_repeat, f"{t_std_repeat / BUDGET:.2f} of the budget"),
            ("cold (memory emptied)", t_std_cold, ""),
        ])
    finally:
        addon.unregister()
    return results


def figures() -> list[dict]:
    """Rows of the `make bench` table (bench/summary.py): the new-value edit per setting
    (the repeat figure where a setting has only two values), the cold edit as baseline."""
    out = []
    for label, (t_repeat, t_new, t_cold) in main().items():
        value, kind = (t_new, "new value") if t_new is not None else (t_repeat, "toggle")
        name = label if label.startswith("standardised") else f"impeller panel edit: {label} ({kind})"
        out.append({"figure": name, "value": value * 1e3, "unit": "ms",
                    "baseline": f"cold (memory emptied) {t_cold * 1e3:.0f} ms, repeat {t_repeat * 1e3:.0f} ms",
                    "goal": "<= 50 ms"})
    return out


if __name__ == "__main__":
    main()
