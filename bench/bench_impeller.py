"""Impeller regeneration after a panel edit: definition -> model (channel, B/S/P blades,
splitters) -> the exact display/IGES surfaces of the full wheel. Target < 0.2 s.
Baseline in the same run: building the model alone (no surfaces)."""
import pathlib

from common import ROOT, load_checkout, median_time, report


def main():
    load_checkout()
    from bladesmith.geometry.compressor import ImpellerDefinition
    from bladesmith.geometry.compressor.export import impeller_surfaces

    rows = []
    for path in sorted(pathlib.Path(ROOT, "data", "impellers").glob("*.toml")):
        d = ImpellerDefinition.from_toml(path)
        data = d.to_dict()

        def edit_and_regenerate():
            data["blade"]["beta_hub"][1] += 1e-3  # a panel edit
            model = ImpellerDefinition.from_dict(data).build()
            return impeller_surfaces(model)

        build = median_time(lambda: ImpellerDefinition.from_dict(data).build())
        full = median_time(edit_and_regenerate)
        rows.append((f"{path.stem}: model", build, ""))
        rows.append((f"{path.stem}: edit -> full wheel", full, f"{full / build:.2f}x model; target < 200 ms"))
    report("impeller regeneration (Casey 1983)", rows)


if __name__ == "__main__":
    main()
