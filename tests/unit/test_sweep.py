"""Design sweeps (issue 23): the sweep file, variant keys, a sweep on an in-process Dask
cluster with variants invalid by design, resuming, and the per-kind metrics."""
import json
import math
import pathlib
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from bladesmith.geometry.errors import DefinitionError
from bladesmith.sweep.spec import load_spec
from bladesmith.sweep.variant import RECORD_FILE, VARIANTS_FOLDER, run_variant

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "data"
#: Cheap smoothing (coarse cuts, loose tolerance, few filter passes): the tests check the
#: sweep, not the smoothing.
CHEAP_PROPELLER = """
[settings]
delta_c = 0.04
tolerance = 1e-4
filter_iterations = 10
"""


def write(path: pathlib.Path, text: str) -> pathlib.Path:
    path.write_text(textwrap.dedent(text))
    return path


def impeller_spec(tmp_path, rows=20, bad=(5, 13)):
    """An impeller sweep over an explicit CSV design: ``rows`` variants, those in ``bad``
    with a negative hub thickness scale (invalid by design: blade.thickness_hub < 0)."""
    lines = ["thickness_scale,beta_te"]
    for i in range(rows):
        scale = -1.0 if i in bad else 0.8 + 0.02 * i
        lines.append(f"{scale},{-3.0 + 0.3 * i}")
    (tmp_path / "variants.csv").write_text("\n".join(lines) + "\n")
    return write(tmp_path / "impeller_sweep.toml", f"""
        base = "{DATA / 'impellers' / 'high_flow.toml'}"
        output = "out"
        [parameters]
        thickness_scale = {{ field = "blade.thickness_hub", action = "scale", range = [0.5, 1.5] }}
        beta_te = {{ field = "blade.beta_shroud", action = "offset", index = -1, range = [-3.0, 3.0] }}
        [design]
        type = "csv"
        file = "variants.csv"
        """)


@pytest.fixture(scope="module")
def cluster_client():
    pytest.importorskip("pyarrow")
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None)
    client = distributed.Client(cluster)
    yield client
    client.close()
    cluster.close()


def test_cluster_sweep_records_errors_and_resumes(tmp_path, cluster_client):
    import pyarrow.parquet as pq

    from bladesmith.sweep.runner import run_sweep

    spec = load_spec(impeller_spec(tmp_path))
    result = run_sweep(spec, client=cluster_client, stream=None)
    assert (result["variants"], result["built"], result["skipped"], result["failed"]) == (20, 20, 0, 2)

    table = pq.read_table(spec.output / "metrics.parquet").to_pylist()
    assert len(table) == 20 and [r["variant"] for r in table] == list(range(20))
    ok = [r for r in table if r["status"] == "ok"]
    failed = [r for r in table if r["status"] == "failed"]
    assert len(ok) == 18 and all(math.isfinite(r["edge_wall_distance_m"]) and r["passage_area_m2"] > 0 for r in ok)
    assert all(r["build_time_s"] > 0 and r["iges_files"].endswith(".igs") for r in ok)
    assert [r["variant"] for r in failed] == [5, 13]
    for r in failed:
        assert r["error_field"] == "blade.thickness_hub" and r["error_type"] == "DefinitionError"
        assert "blade.thickness_hub" in r["error"] and math.isnan(r["passage_area_m2"]) and r["iges_files"] == ""
    csv_lines = (spec.output / "metrics.csv").read_text().splitlines()
    assert len(csv_lines) == 21 and csv_lines[0].startswith("variant,key,thickness_scale,beta_te,status")
    # the blades' wall edges near the walls (issue 18 measured up to 0.97 mm off the hub
    # wall on these presets, and is putting them on it: only a bound that holds either way)
    assert all(0.0 <= r["edge_wall_distance_m"] < 2e-3 for r in ok)

    records = sorted((spec.output / VARIANTS_FOLDER).glob(f"*/{RECORD_FILE}"))
    stamps = {p: p.stat().st_mtime_ns for p in records}
    again = run_sweep(load_spec(spec.path), client=cluster_client, stream=None)
    assert (again["built"], again["skipped"], again["failed"]) == (0, 20, 2)
    assert all(p.stat().st_mtime_ns == t for p, t in stamps.items())
    assert (spec.output / "metrics.csv").read_text().splitlines() == csv_lines

    # a damaged output and a missing record (a variant killed mid-way) are rebuilt, nothing else
    first_ok = spec.output / ok[0]["iges_files"]
    first_ok.write_bytes(first_ok.read_bytes()[:-10])
    (spec.output / VARIANTS_FOLDER / ok[1]["key"] / RECORD_FILE).unlink()
    third = run_sweep(load_spec(spec.path), client=cluster_client, stream=None)
    assert (third["built"], third["skipped"]) == (2, 18)
    areas = pq.read_table(spec.output / "metrics.parquet").column("passage_area_m2").to_pylist()
    assert areas[:5] == [r["passage_area_m2"] for r in table][:5] and math.isnan(areas[5])


def test_keys_follow_the_definition_not_the_design(tmp_path):
    """The same definition and settings get the same key from any design; LHS is seeded."""
    base = DATA / "propellers" / "dtmb4119.toml"

    def spec(design, name):
        return load_spec(write(tmp_path / f"{name}.toml", f"""
            base = "{base}"
            [parameters]
            pitch_scale = {{ field = "radial.P_D", action = "scale", range = [0.9, 1.1] }}
            d_t = {{ field = "settings.tip_smoothing_distance", range = [0.03, 0.07] }}
            [design]
            {design}
            """))

    grid = spec("type = \"grid\"\nlevels = 3", "grid").variants()
    assert len(grid) == 9 and len({v.key for v in grid}) == 9
    (tmp_path / "rows.csv").write_text("d_t,pitch_scale\n0.05,1.1\n0.03,0.9\n")
    rows = spec("type = \"csv\"\nfile = \"rows.csv\"", "csv").variants()
    by_values = {(v.values["pitch_scale"], v.values["d_t"]): v.key for v in grid}
    assert rows[0].key == by_values[(1.1, 0.05)] and rows[1].key == by_values[(0.9, 0.03)]
    assert rows[0].definition["radial"]["P_D"][0] == pytest.approx(1.105 * 1.1)
    assert rows[0].settings["tip_smoothing_distance"] == 0.05

    lhs = [spec(f"type = \"lhs\"\nsamples = 10\nseed = {s}", f"lhs{s}").variants() for s in (1, 1, 2)]
    assert [v.key for v in lhs[0]] == [v.key for v in lhs[1]] != [v.key for v in lhs[2]]
    for q, lo, hi in (("pitch_scale", 0.9, 1.1), ("d_t", 0.03, 0.07)):
        # a Latin hypercube: one sample in each of the 10 strata of every parameter
        strata = sorted(int((v.values[q] - lo) / (hi - lo) * 10) for v in lhs[0])
        assert strata == list(range(10))


@pytest.mark.parametrize("parameter, field", [
    ('x = { field = "radial.pitch", action = "scale", range = [0.9, 1.1] }', "parameters.x.field"),
    ('x = { field = "radial.P_D", range = [0.9, 1.1] }', "parameters.x.action"),
    ('x = { field = "radial.P_D", action = "stretch", range = [0.9, 1.1] }', "parameters.x.action"),
    ('x = { field = "diameter", range = [2.0, 1.0] }', "parameters.x.range"),
    ('x = { field = "settings.smoothness", range = [0.0, 1.0] }', "parameters.x.field"),
    ('x = { field = "radial.P_D", action = "scale", index = 99, range = [0.9, 1.1] }', "parameters.x.index"),
])
def test_bad_sweep_files_are_refused_naming_the_field(tmp_path, parameter, field):
    path = write(tmp_path / "bad.toml", f"""
        base = "{DATA / 'propellers' / 'dtmb4119.toml'}"
        [parameters]
        {parameter}
        [design]
        type = "lhs"
        samples = 4
        seed = 0
        """)
    with pytest.raises(DefinitionError) as info:
        load_spec(path)
    assert info.value.field == field and str(path) in str(info.value)


def test_propeller_metrics_scale_with_the_diameter(tmp_path):
    """Doubling D (everything else in fractions of D) doubles lengths: areas x4, volume
    x8, deviations x2, and the counts stay; a bad setting is recorded with its field."""
    # the hub's lengths are metres: scaled with D too, so the blade meets the same hub
    hub = {"upstream_length": 0.10668, "downstream_length": 0.13716, "nose_length": 0.04572, "tail_length": 0.06096}
    (tmp_path / "rows.csv").write_text("diameter," + ",".join(hub) + "\n" + "\n".join(
        ",".join(str(k * v) for v in (0.3048, *hub.values())) for k in (1, 2)) + "\n")
    parameters = "\n".join(f'{n} = {{ field = "hub.{n}", values = [0.0] }}' for n in hub)
    spec = load_spec(write(tmp_path / "prop.toml", f"""
        base = "{DATA / 'propellers' / 'dtmb4119.toml'}"
        output = "out"
        {CHEAP_PROPELLER}
        [parameters]
        diameter = {{ field = "diameter", values = [0.0] }}
        {parameters}
        [design]
        type = "csv"
        file = "rows.csv"
        """))
    small, large = (run_variant("propeller", v.key, v.index, v.values, v.definition, v.settings,
                                str(spec.base.parent), str(spec.output)) for v in spec.variants())
    assert small["status"] == large["status"] == "ok", (small["error"], large["error"])
    a, b = small["metrics"], large["metrics"]
    assert b["blade_area_m2"] == pytest.approx(4 * a["blade_area_m2"], rel=1e-6)
    assert b["blade_volume_m3"] == pytest.approx(8 * a["blade_volume_m3"], rel=1e-6)
    assert b["deviation_outside_m"] == pytest.approx(2 * a["deviation_outside_m"], rel=1e-3)
    for k in ("cuts_tip", "cuts_smoothed", "knots", "control_points", "tip_sign_changes"):
        assert a[k] == b[k]
    # DTMB 4119 blade: volume well inside the thickest section's slab, area about twice
    # the expanded area (both faces)
    assert 0 < a["blade_volume_m3"] < a["blade_area_m2"] * 0.5 * 0.2055 * 0.32 * 0.3048
    assert a["shared_edge_gap_m"] < 1e-12 and a["cuts_smoothed"] > 0
    assert (tmp_path / "out" / VARIANTS_FOLDER / small["key"] / "variant.igs").stat().st_size > 0

    bad = dict(spec.variants()[0].settings, tip_smoothing_distance=-0.01)
    record = run_variant("propeller", "bad0000000000000", 2, {}, spec.variants()[0].definition, bad,
                         str(spec.base.parent), str(spec.output))
    assert record["status"] == "failed" and record["error_field"] == "settings.tip_smoothing_distance"
    assert "-0.01" in record["error"]


def _face(origin, e1, e2):
    """A bilinear patch o + u e1 + v e2 (normal e1 x e2)."""
    from bladesmith.geometry.nurbs import BSplineSurface

    o, e1, e2 = (np.asarray(x, dtype=float) for x in (origin, e1, e2))
    P = np.array([[o, o + e2], [o + e1, o + e1 + e2]])
    return BSplineSurface(1, 1, np.array([0.0, 0.0, 1.0, 1.0]), np.array([0.0, 0.0, 1.0, 1.0]), P)


def test_area_and_volume_of_a_box_open_on_a_vertical_side():
    """A 1 x 2 x 3 box lifted to z in [5, 8], faces with outward S_u x S_v, the face
    x = 0 left open (as the blade root on the hub cylinder: n_z = 0 there): area of the
    five faces, and the whole volume."""
    from bladesmith.sweep.variant import area_and_volume

    a, b, c, z0 = 1.0, 2.0, 3.0, 5.0
    faces = [
        _face([a, 0, z0], [0, b, 0], [0, 0, c]),        # x = a, normal +x
        _face([0, 0, z0], [a, 0, 0], [0, 0, c]),        # y = 0, normal -y
        _face([0, b, z0], [0, 0, c], [a, 0, 0]),        # y = b, normal +y
        _face([0, 0, z0], [0, b, 0], [a, 0, 0]),        # z = z0, normal -z
        _face([0, 0, z0 + c], [a, 0, 0], [0, b, 0]),    # z = z0 + c, normal +z
    ]
    for f in faces:
        centre = f.evaluate(0.5, 0.5) - np.array([a / 2, b / 2, z0 + c / 2])
        assert np.dot(f.normal(0.5, 0.5), centre) > 0  # outward
    area, volume = area_and_volume(faces)
    assert area == pytest.approx(2 * a * b + 2 * a * c + b * c, rel=1e-13)
    assert volume == pytest.approx(a * b * c, rel=1e-13)


def test_wind_blade_metrics(tmp_path):
    spec = load_spec(write(tmp_path / "wind.toml", f"""
        base = "{DATA / 'blades' / 's823_small.toml'}"
        output = "out"
        [parameters]
        chord_scale = {{ field = "stations.chord", action = "scale", values = [1.1] }}
        [design]
        type = "grid"
        """))
    (v,) = spec.variants()
    record = run_variant("wind_blade", v.key, 0, v.values, v.definition, v.settings, str(spec.base.parent),
                         str(spec.output))
    assert record["status"] == "ok", record["error"]
    m = record["metrics"]
    assert m["mvs"] > 0 and m["strain_energy"] > 0 and 0 < m["worst_station_deviation"] <= 1e-4
    # the definition used was written with the airfoil path made relative to its folder
    text = (spec.output / VARIANTS_FOLDER / v.key / "definition.toml").read_text()
    assert "../../../" in text and "0.33" in text


def test_sweep_modules_need_neither_blender_nor_dask_to_import():
    """What Blender imports from sweep/ (folder, spec, variant) works without bpy, Dask
    and pyarrow: they are dependencies of the sweep command only."""
    script = textwrap.dedent(f"""
        import importlib, importlib.util, sys
        for name in ("bpy", "mathutils", "dask", "distributed", "pyarrow", "cloudpickle"):
            sys.modules[name] = None
        spec = importlib.util.spec_from_file_location(
            "bladesmith", {str(ROOT / "__init__.py")!r}, submodule_search_locations=[{str(ROOT)!r}])
        module = importlib.util.module_from_spec(spec)
        sys.modules["bladesmith"] = module
        spec.loader.exec_module(module)
        for name in ("folder", "spec", "variant", "runner", "cli", "worker", "__main__"):
            importlib.import_module("bladesmith.sweep." + name)
        print("ok")
        """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and "ok" in result.stdout, result.stderr


def test_folder_finds_variants(tmp_path):
    from bladesmith.sweep.folder import find_variant

    with pytest.raises(DefinitionError, match="not a sweep folder"):
        find_variant(tmp_path, 0)
    (tmp_path / "sweep.json").write_text(json.dumps({"kind": "impeller", "variants": [
        {"variant": 0, "key": "abc0", "values": {"x": 1.0}}, {"variant": 1, "key": "abd1", "values": {"x": 2.0}}]}))
    (tmp_path / VARIANTS_FOLDER / "abd1").mkdir(parents=True)
    (tmp_path / VARIANTS_FOLDER / "abd1" / "definition.toml").write_text("name = 'x'\n")
    assert find_variant(tmp_path, key="abd").key == "abd1" and find_variant(tmp_path, 1).values == {"x": 2.0}
    with pytest.raises(DefinitionError, match="not been built"):
        find_variant(tmp_path, 0)
    with pytest.raises(DefinitionError, match="more than one") as info:
        find_variant(tmp_path, key="ab")
    assert info.value.field == "key"


def test_tip_irregularity_taken_from_the_smoothing_report():
    """Issue 15's report entry (a dict) or a plain number; NaN where there is none."""
    from bladesmith.sweep.variant import tip_irregularity

    assert tip_irregularity({"tip_irregularity": {"smoothed": 0.5, "unsmoothed": 2.0, "ratio": 0.25}}) == (0.5, 0.25)
    value, ratio = tip_irregularity({"tip_irregularity": 3.0})
    assert value == 3.0 and math.isnan(ratio)
    assert all(math.isnan(x) for x in tip_irregularity({}))
