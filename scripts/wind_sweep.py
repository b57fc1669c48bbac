"""Control-point sweep of a wind blade (Hosseini & Moetakef-Imani 2016, the x-axis of
Figs. 5, 8, 10 and 11): LSQ error, MVS and strain energy of the two-part molds and of the
single surface at equal total control points, as a Markdown table.

    python scripts/wind_sweep.py NREL5MW 8 12 16 20 26
    python scripts/wind_sweep.py path/to/blade.toml 10 20      (or a windIO .yaml)
"""
from __future__ import annotations

import argparse
import importlib.util
import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent


def load_checkout():
    spec = importlib.util.spec_from_file_location("bladesmith", ROOT / "__init__.py",
                                                  submodule_search_locations=[str(ROOT)])
    module = importlib.util.module_from_spec(spec)
    sys.modules["bladesmith"] = module
    spec.loader.exec_module(module)
    return module


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("blade", help="preset name (e.g. NREL5MW) or a definition file (.toml, windIO .yaml)")
    parser.add_argument("counts", nargs="+", type=int, help="control points per half")
    args = parser.parse_args(argv)
    load_checkout()
    from bladesmith.geometry.errors import BladesmithError
    from bladesmith.geometry.mold import control_point_sweep, format_sweep, load_blade, load_preset

    try:
        path = pathlib.Path(args.blade)
        defn = load_blade(path) if path.suffix else load_preset(args.blade)
        start = time.perf_counter()
        rows = control_point_sweep(defn, args.counts)
    except BladesmithError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    print(f"{defn.name}: {len(defn.stations)} stations, aerodynamic from station {defn.first_aerodynamic_station}; "
          f"{time.perf_counter() - start:.1f} s\n")
    print(format_sweep(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
