"""The hub sector (Hally 2013 §10) and the propeller's IGES file (§11) for DTMB 4119.

Times: the hub sector (C1 spine, Eqs. 51–58, footprint spline, area); building the IGES
records; writing the file (validation + serialisation + atomic write); the blade
smoothing (without its deviation measurement, which the file does not need); and the whole
pipeline (definition -> model -> smoothing -> hub sector -> file), against the issue's 2 s
budget. Baseline: writing the five blade surfaces alone (no hub), measured in the same run.
"""
from __future__ import annotations

import tempfile

from common import ROOT, load_checkout, median_time, report

BUDGET_S = 2.0


def main() -> dict:
    load_checkout()
    from bladesmith.geometry.propeller import Propeller, smooth_blade
    from bladesmith.geometry.propeller.hub_sector import hub_sector
    from bladesmith.iges import surface_from_geometry, write_iges
    from bladesmith.iges.propeller import BLADE_SURFACES, propeller_iges_entities, write_propeller_iges

    path_toml = ROOT / "data" / "propellers" / "dtmb4119.toml"
    def make_blade(m):
        return smooth_blade(m, measure=False)

    blade_kind = "smooth_blade"
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
