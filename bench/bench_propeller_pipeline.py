"""Issue 22's propeller figures: the Hally pipeline (DTMB 4119, TOML -> smoothed surfaces ->
hub sector -> IGES) and a panel edit with and without tip smoothing (bpy module, with
Blender's evaluation of the changed objects, what a redraw waits for).

Baselines measured in the same run:
- pipeline: the same pipeline of the code before issue 22's speed work (commit
  BASELINE_COMMIT, unpacked from git into a temporary folder and imported as a second
  package), timed alternately with this checkout so both see the same load. Without git
  (an unpacked zip) the baseline is left out.
- smoothed panel edit: ``smooth_blade`` alone on this checkout (the edit adds the model, the
  display objects and Blender's evaluation); the same edit before issue 22 took 563 ms
  (issue text).
- unsmoothed panel edit: the definition + model build, uncached.

One core: run with OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 (set here when numpy is not
imported yet). ``python bench/run.py propeller_pipeline``.
"""
from __future__ import annotations

import importlib.util
import os
import pathlib
import shutil
import statistics
import tempfile
import time

for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

from common import ROOT, load_checkout, load_commit, median_time  # noqa: E402

#: The main commit before issue 22's second session (pipeline 446 ms quiet there).
BASELINE_COMMIT = "25a7105"
REPEAT = 7
LIVE_REPEAT = 9


def _pipeline(package: str, out: str):
    propeller = importlib.import_module(package + ".geometry.propeller")
    sector = importlib.import_module(package + ".geometry.propeller.hub_sector")
    iges = importlib.import_module(package + ".iges.propeller")
    path = ROOT / "data" / "propellers" / "dtmb4119.toml"

    def run():
        model = propeller.Propeller.from_toml(path).build()
        blade = propeller.smooth_blade(model, measure=False)
        iges.write_propeller_iges(out, model, blade, sector.hub_sector(model))

    return run


def pipeline_figures() -> list[dict]:
    load_checkout()
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="bench_pipeline_"))
    try:
        base = load_commit(BASELINE_COMMIT, tmp, "bladesmith_baseline")
        runs = {"bladesmith": _pipeline("bladesmith", str(tmp / "new.igs"))}
        if base is not None:
            runs[base] = _pipeline(base, str(tmp / "old.igs"))
        times = {k: [] for k in runs}
        for fn in runs.values():
            fn()
        for _ in range(REPEAT):  # alternate, so that both see the same load
            for k, fn in runs.items():
                start = time.perf_counter()
                fn()
                times[k].append(time.perf_counter() - start)
        new = statistics.median(times["bladesmith"])
        if base is not None:
            old = statistics.median(times[base])
            baseline = f"{old * 1e3:.0f} ms at {BASELINE_COMMIT} in the same run ({new / old:.2f}x)"
        else:
            baseline = ""
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return [{"figure": "Hally pipeline, DTMB 4119, TOML -> IGES, one core", "value": new * 1e3, "unit": "ms",
             "baseline": baseline, "goal": "<= 50 ms"}]


def live_figures() -> list[dict]:
    bladesmith = load_checkout()
    import bpy

    from bladesmith.geometry.propeller import smooth_blade
    from bladesmith.operators import propeller as ops

    bladesmith.register()
    try:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        bpy.ops.bladesmith.add_propeller(preset="DTMB4119")
        root = next(obj for obj in bpy.data.objects if ops.find_root(obj) is obj)
        settings = root.bladesmith_propeller
        view_layer = bpy.context.view_layer
        view_layer.update()
        station = settings.radial[5]
        base_pitch = station.P_D
        state = {"n": 0}

        def edit_pitch():
            state["n"] += 1
            station.P_D = base_pitch * (1.0 + 0.002 * (-1) ** state["n"])
            view_layer.update()

        def build_model():
            ops.settings_to_definition(settings).build()

        unsmoothed = median_time(edit_pitch, LIVE_REPEAT)
        model_build = median_time(build_model, LIVE_REPEAT)
        settings.smooth_tip = True
        view_layer.update()
        if settings.status_is_error:
            raise RuntimeError(f"smoothing failed in the bench: {settings.status}")
        smoothed = median_time(edit_pitch, LIVE_REPEAT)
        base_delta = settings.delta_c

        def edit_delta_c():
            state["n"] += 1
            settings.delta_c = base_delta * (1.0 + 0.01 * (-1) ** state["n"])
            view_layer.update()

        smoothing_edit = median_time(edit_delta_c, LIVE_REPEAT)
        settings.delta_c = base_delta
        base_tolerance = settings.display_tolerance

        def edit_display():  # the smoothed blade is reused (same model and smoothing settings)
            state["n"] += 1
            settings.display_tolerance = base_tolerance * (1.0 + 0.1 * (-1) ** state["n"])
            view_layer.update()

        display_edit = median_time(edit_display, LIVE_REPEAT)
        settings.display_tolerance = base_tolerance
        model = ops.build_model(ops.settings_to_definition(settings))
        values = ops.smoothing_settings(ops.smoothing_values(settings), model.definition.diameter)
        smooth_only = median_time(lambda: smooth_blade(model, values, measure=False), LIVE_REPEAT)
        settings.smooth_tip = False
        station.P_D = base_pitch
        view_layer.update()
    finally:
        bladesmith.unregister()
    print(f"  (smoothing-setting edit, delta_c, model reused: {smoothing_edit * 1e3:.1f} ms; display-setting edit "
          f"with smooth_tip on, smoothed blade reused: {display_edit * 1e3:.1f} ms)")
    return [
        {"figure": "panel edit with smooth_tip on (+ depsgraph)", "value": smoothed * 1e3, "unit": "ms",
         "baseline": f"smooth_blade alone {smooth_only * 1e3:.0f} ms in the same run; 563 ms before issue 22",
         "goal": "<= 50 ms"},
        {"figure": "panel edit, unsmoothed (+ depsgraph)", "value": unsmoothed * 1e3, "unit": "ms",
         "baseline": f"definition + model build {model_build * 1e3:.1f} ms in the same run "
                     f"({unsmoothed / model_build:.1f}x)", "goal": "<= 16 ms"},
    ]


def figures() -> list[dict]:
    return pipeline_figures() + live_figures()


def main() -> list[dict]:
    rows = figures()
    print(f"\n== Issue 22 propeller figures (load {os.getloadavg()[0]:.1f})")
    for r in rows:
        print(f"  {r['figure']:<52} {r['value']:9.1f} {r['unit']:<3} goal {r['goal']:<9} baseline: {r['baseline']}")
    return rows


if __name__ == "__main__":
    main()
