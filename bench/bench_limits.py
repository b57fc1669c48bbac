"""The largest valid definition of each format at the documented bounds (README "Limits of
definitions"): build time and peak memory, each in its own process.

    python bench/bench_limits.py              # geometry/ builds (no Blender)
    python bench/bench_limits.py --blender    # the add_* operators in the bpy module
    python bench/bench_limits.py wind         # one format

- propeller: MAX_RADIAL_STATIONS stations (the DTMB 4119 columns interpolated), MAX_BLADES
  blades, diameter MAX_LENGTH; the model, the display fit and the hub.
- wind: MAX_STATIONS stations (the NREL 5-MW planform interpolated, its airfoils by
  nearest station); both mold halves and the
  single surface, with fairness.
- impeller: MAX_CHANNEL_PATCHES channel patches, MAX_BLADES blades with a splitter,
  MAX_BLADE_PATCHES patches, MAX_COEFFICIENTS Bernstein coefficients per β and δ; the model
  and its exported surfaces.
"""
from __future__ import annotations

import os
import pathlib
import subprocess
import sys
import tempfile
import time
import tomllib

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from common import ROOT, load_checkout  # noqa: E402


def propeller_definition() -> dict:
    from bladesmith.geometry.propeller import definition as d
    from bladesmith.geometry.validation import MAX_LENGTH

    data = tomllib.loads((ROOT / "data" / "propellers" / "dtmb4119.toml").read_text())
    r = np.asarray(data["radial"]["r_R"])
    n = d.MAX_RADIAL_STATIONS
    r_new = r[0] + (1.0 - r[0]) * np.sin(np.linspace(0.0, np.pi / 2, n))  # dense at the tip
    r_new[-1] = 1.0
    data["radial"] = {k: np.interp(r_new, r, v).tolist() for k, v in data["radial"].items()}
    data["blades"] = d.MAX_BLADES
    data["diameter"] = MAX_LENGTH
    scale = MAX_LENGTH / 0.3048
    data["hub"] = {k: v * scale if isinstance(v, float) else v for k, v in data["hub"].items()}
    data["name"] = "largest propeller"
    return data


def wind_definition() -> dict:
    from bladesmith.geometry.mold import definition as d

    data = tomllib.loads((ROOT / "data" / "blades" / "nrel5mw.toml").read_text())
    st = data["stations"]
    r = np.asarray(st["r"])
    n = d.MAX_STATIONS
    r_new = np.linspace(r[0], r[-1], n)
    new = {k: np.interp(r_new, r, st[k]).tolist() for k in ("chord", "twist_deg", "pitch_axis")}
    first = data.get("first_aerodynamic_station", 0)
    nearest = [int(np.argmin(np.abs(r - x))) for x in r_new]
    # keep the root transition: the cylinder stations stay in the structural zone
    airfoil = [st["airfoil"][k] for k in nearest]
    new_first = int(np.searchsorted(r_new, r[first]))
    for k in range(new_first):
        airfoil[k] = st["airfoil"][0]
    for k in range(new_first, n):
        if st["airfoil"][nearest[k]].lower().find("cylinder") >= 0:
            airfoil[k] = st["airfoil"][first]
    new["r"], new["airfoil"] = r_new.tolist(), airfoil
    data["stations"] = new
    data["first_aerodynamic_station"] = new_first
    # the preset's start (26); the fit raises it as needed up to mold.blade.MAX_CONTROL_POINTS
    # (a start of MAX_START_CONTROL_POINTS is valid but the cylinder's data cannot carry it)
    data["name"] = "largest wind blade"
    return data


def impeller_definition() -> dict:
    from bladesmith.geometry.compressor import definition as d

    data = tomllib.loads((ROOT / "data" / "impellers" / "high_flow.toml").read_text())
    ch = data["channel"]
    extra = d.MAX_CHANNEL_PATCHES - len(ch["degrees"])  # split the straight inlet patch
    for w in ("hub", "shroud"):
        z0, z1 = ch[f"{w}_z"][0], ch[f"{w}_z"][1]
        zs = np.linspace(z0, z1, extra + 2)[1:-1].tolist()
        ch[f"{w}_z"] = [z0] + zs + ch[f"{w}_z"][1:]
        ch[f"{w}_r"] = [ch[f"{w}_r"][0]] * (extra + 1) + ch[f"{w}_r"][1:]
        ch[f"{w}_angle"] = ["auto"] * (extra + 1) + ch[f"{w}_angle"][1:]
        ch[f"{w}_fractions"] = [[0.5, 0.5]] * extra + ch[f"{w}_fractions"]
    ch["degrees"] = [1] * extra + ch["degrees"]
    b = data["blade"]
    for key in ("leading_edge_hub", "leading_edge_shroud", "trailing_edge_hub", "trailing_edge_shroud"):
        b[key] += extra
    m = np.linspace(0.0, 1.0, d.MAX_COEFFICIENTS)
    for key in ("beta_hub", "beta_shroud", "thickness_hub", "thickness_shroud"):
        b[key] = np.interp(m, np.linspace(0.0, 1.0, len(b[key])), b[key]).tolist()
    b["count"] = d.MAX_BLADES
    b["patches"] = d.MAX_BLADE_PATCHES
    le = b["leading_edge_hub"]
    data["splitter"] = {"leading_edge_hub": le + 1.0, "leading_edge_shroud": b["leading_edge_shroud"] + 1.0,
                        "thickness_hub": b["thickness_hub"], "thickness_shroud": b["thickness_shroud"],
                        "pitch_fraction": 0.5, "patches": d.MAX_BLADE_PATCHES}
    data["name"] = "largest impeller"
    return data


def _write(data: dict, folder: pathlib.Path, name: str) -> pathlib.Path:
    from bladesmith.geometry.propeller.definition import dumps_toml

    path = folder / name
    path.write_text(dumps_toml(data))
    return path


def build(kind: str, path: pathlib.Path) -> str:
    if kind == "propeller":
        from bladesmith.geometry.propeller import Propeller
        from bladesmith.geometry.propeller.display import DISPLAY_TOLERANCE_FRACTION, blade_display_surface, hub_surface

        p = Propeller.from_toml(path)
        model = p.build()
        s = blade_display_surface(model.blade, DISPLAY_TOLERANCE_FRACTION * p.diameter)
        hub_surface(model.hub)
        return f"{len(p.radial.r_R)} stations, {p.blades} blades, D = {p.diameter:g} m; display {s.surface.shape[:2]}"
    if kind == "wind":
        from bladesmith.geometry.mold.blade import build_blade
        from bladesmith.geometry.mold.definition import load_blade

        defn = load_blade(path)
        molds = build_blade(defn, fairness=True)
        return f"{len(defn.stations)} stations, {getattr(molds, 'control_points', '?')} control points per half"
    from bladesmith.geometry.compressor import ImpellerDefinition
    from bladesmith.geometry.compressor.export import impeller_surfaces

    d = ImpellerDefinition.from_toml(path)
    model = d.build()
    surfaces = impeller_surfaces(model, model.count)
    return (f"{len(d.channel.degrees)} channel patches, {d.blade.count} blades + splitters, {d.blade.patches} "
            f"patches, {len(d.blade.beta_hub)} coefficients; {len(surfaces)} surfaces")


def build_blender(kind: str, path: pathlib.Path) -> str:
    import bpy

    module = sys.modules["bladesmith"]
    module.register()
    try:
        op = {"propeller": bpy.ops.bladesmith.add_propeller, "wind": bpy.ops.bladesmith.add_wind_blade,
              "impeller": bpy.ops.bladesmith.add_impeller}[kind]
        result = op(definition=str(path))
        return f"{result}, {len(bpy.data.objects)} objects"
    finally:
        module.unregister()


def child(kind: str, path: str, blender: bool) -> None:
    if blender:
        import bpy  # noqa: F401  (before the checkout, as the tests do)
    load_checkout()
    start = time.perf_counter()
    what = (build_blender if blender else build)(kind, pathlib.Path(path))
    print(f"{time.perf_counter() - start:.2f}|{what}")


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        child(sys.argv[2], sys.argv[3], sys.argv[4] == "1")
        return
    blender = "--blender" in sys.argv
    load_checkout()
    makers = {"propeller": propeller_definition, "wind": wind_definition, "impeller": impeller_definition}
    with tempfile.TemporaryDirectory() as tmp:
        folder = pathlib.Path(tmp)
        import shutil

        shutil.copytree(ROOT / "data" / "blades" / "airfoils", folder / "airfoils")
        print(f"== largest valid definitions ({'add_* operators, bpy' if blender else 'geometry/ build'})")
        only = [a for a in sys.argv[1:] if a in makers]
        for kind, make in makers.items():
            if only and kind not in only:
                continue
            path = _write(make(), folder, f"{kind}.toml")
            proc = subprocess.Popen([sys.executable, __file__, "--child", kind, str(path), "1" if blender else "0"],
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            _, status, usage = os.wait4(proc.pid, 0)
            out, err = proc.stdout.read(), proc.stderr.read()
            if status != 0:
                print(f"{kind}: FAILED\n{err[-2000:]}")
                continue
            seconds, what = out.strip().splitlines()[-1].split("|", 1)
            print(f"{kind:10s} build {float(seconds):7.2f} s   peak RSS {usage.ru_maxrss / 1024:7.0f} MB   {what}")


if __name__ == "__main__":
    main()
