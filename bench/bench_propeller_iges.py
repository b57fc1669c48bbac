"""The hub sector (Hally 2013 §10) and the propeller's IGES file (§11) for DTMB 4119.

Times: the hub sector (C1 spine, Eqs. 51–58, footprint spline, area); building the IGES
records; writing the file (validation + serialisation + atomic write); the blade
smoothing when ``geometry/propeller/smoothing.py`` exists (else a stand-in of five
bicubic patches is used and its time is shown but not counted as smoothing); and the whole
pipeline (definition -> model -> smoothing -> hub sector -> file), against the issue's 2 s
budget. Baseline: writing the five blade surfaces alone (no hub), measured in the same run.
"""
from __future__ import annotations

import importlib
import importlib.util
import inspect
import tempfile

from common import ROOT, load_checkout, median_time, report

BUDGET_S = 2.0


def _blade_maker():
    """(callable model -> blade surfaces, description)."""
    try:
        smoothing = importlib.import_module("bladesmith.geometry.propeller.smoothing")
    except ImportError:
        smoothing = None
    if smoothing is not None:
        fn = smoothing.smooth_blade
        params = list(inspect.signature(fn).parameters.values())
        if len(params) > 1 and params[1].default is inspect.Parameter.empty:
            cls = next((getattr(smoothing, n) for n in ("SmoothingSettings", "Settings", "TipSmoothingSettings")
                        if hasattr(smoothing, n)), None)
            if cls is not None:
                return (lambda m: fn(m, cls())), "smooth_blade"
        else:
            return fn, "smooth_blade"
    tests = ROOT / "tests" / "iges" / "test_propeller_iges.py"
    spec = importlib.util.spec_from_file_location("_propeller_iges_tests", tests)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.stand_in_blade, "stand-in (smoothing.py not there yet)"


def main() -> dict:
    load_checkout()
    import sys

    sys.path.insert(0, str(ROOT / "tests" / "iges"))  # occ_support for the stand-in module's imports
    from bladesmith.geometry.propeller import Propeller
    from bladesmith.geometry.propeller.hub_sector import hub_sector
    from bladesmith.iges import surface_from_geometry, write_iges
    from bladesmith.iges.propeller import BLADE_SURFACES, propeller_iges_entities, write_propeller_iges

    path_toml = ROOT / "data" / "propellers" / "dtmb4119.toml"
    make_blade, blade_kind = _blade_maker()
    model = Propeller.from_toml(path_toml).build()
    model.blade_hub_intersection
    blade = make_blade(model)
    sector = hub_sector(model)
    tmp = tempfile.mkdtemp(prefix="bench_prop_iges_")
    out = f"{tmp}/dtmb4119.igs"

    def fresh_sector():
        m = Propeller.from_toml(path_toml).build()
        m.blade_hub_intersection
        return m

    models = [fresh_sector() for _ in range(8)]
    it = iter(models)
    t_sector = median_time(lambda: hub_sector(next(it)), repeat=5, warmup=1)
    t_records = median_time(lambda: propeller_iges_entities(model, blade, sector), repeat=5)
    t_write = median_time(lambda: write_propeller_iges(out, model, blade, sector), repeat=5)
    blades_only = [surface_from_geometry(getattr(blade, name)) for name, _ in BLADE_SURFACES]
    t_base = median_time(lambda: write_iges(f"{tmp}/blades.igs", blades_only), repeat=5)
    t_blade = median_time(lambda: make_blade(model), repeat=3)

    def pipeline():
        m = Propeller.from_toml(path_toml).build()
        b = make_blade(m)
        write_propeller_iges(out, m, b, hub_sector(m))

    t_total = median_time(pipeline, repeat=3)
    size = len(open(out, "rb").read())
    rows = [
        ("hub sector (spine, Eqs. 51-58, footprint, area)", t_sector, f"area {sector.area:.9g} m2, "
         f"footprint {sector.footprint.n_control} ctrl pts, dev {sector.footprint_deviation:.2g} m"),
        ("IGES records (5 x 128 + 144/120/142/102)", t_records, ""),
        ("write file (validate + serialise + atomic)", t_write, f"{size / 1024:.0f} KiB, "
         f"{t_write / t_base:.2f}x writing the blades alone"),
        ("baseline: write the 5 blade 128s alone", t_base, ""),
        (f"blade surfaces: {blade_kind}", t_blade, ""),
        ("pipeline: toml -> model -> blade -> sector -> file", t_total,
         f"{t_total / BUDGET_S:.2f} of the 2 s budget"),
    ]
    report("DTMB 4119 hub sector and IGES file", rows)
    return {"hub_sector_s": t_sector, "write_s": t_write, "pipeline_s": t_total, "blade": blade_kind}


if __name__ == "__main__":
    main()
