"""Property tests through the add operators (issue 20, Deliver 4): a mutated preset
(tests/definition_mutations.py) written as a TOML file either builds (FINISHED) or is
refused with an ERROR report naming the file and a field, and then every data-block,
collection and link of the scene is as before. A Python traceback is a failure.

Default: a few dozen cases per format; BLADESMITH_PROPERTY_EXAMPLES=2000 for the
measured runs (README "Property tests")."""
import pathlib
import shutil
import sys
import tempfile
import time
import tomllib

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

bpy = pytest.importorskip("bpy")

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
import definition_mutations as dm  # noqa: E402

from bladesmith.geometry.compressor import definition as impeller_definition  # noqa: E402
from bladesmith.geometry.mold import definition as wind_definition  # noqa: E402
from bladesmith.geometry.propeller import definition as propeller_definition  # noqa: E402
from bladesmith.geometry.propeller.definition import dumps_toml  # noqa: E402
from bladesmith.operators.scene_guard import remove_new, snapshot  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
KINDS = ("objects", "curves", "meshes", "collections", "materials", "images", "scenes", "cameras", "worlds")
CASE_SECONDS = 60.0
COUNTS = {kind: {"built": 0, "refused": 0, "other": 0, "max_seconds": 0.0} for kind in ("propeller", "wind",
                                                                                        "impeller")}

VOCABULARY = {
    "propeller": set(propeller_definition._TOP_KEYS) | propeller_definition._SECTION_KEYS
    | propeller_definition._HUB_KEYS | set(propeller_definition.RADIAL_FIELDS) | {"display_tolerance"},
    "wind": set(wind_definition.TOP_KEYS) | set(wind_definition.REQUIRED) | set(wind_definition.OPTIONAL),
    "impeller": set(impeller_definition.TOP_KEYS) | set(impeller_definition.CHANNEL_KEYS)
    | set(impeller_definition.BLADE_KEYS) | set(impeller_definition.SPLITTER_KEYS)
    | set(impeller_definition.STANDARDISATION_KEYS),
}


def state():
    out = {kind: sorted(b.name for b in getattr(bpy.data, kind)) for kind in KINDS}
    out["links"] = sorted((c.name, o.name) for c in bpy.data.collections for o in c.objects)
    out["scene"] = sorted(o.name for o in bpy.context.scene.collection.objects)
    return out


@pytest.fixture(scope="module")
def folder(addon):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        shutil.copytree(ROOT / "data" / "blades" / "airfoils", tmp / "airfoils")
        yield tmp
    if dm.measuring():
        for kind, counts in COUNTS.items():
            print(f"\noperator property {kind}: {counts}")


def _run(kind, folder, source, data, log, call):
    try:
        text = dumps_toml(data)
        tomllib.loads(text)
    except (TypeError, ValueError):
        assume(False)  # not representable as TOML (e.g. a table inside an array)
    path = folder / source.name
    path.write_text(text)
    before, blocks = state(), snapshot()
    start = time.perf_counter()
    try:
        result = call(path)
        assert result == {"FINISHED"}
        COUNTS[kind]["built"] += 1
        remove_new(blocks)  # the next case starts from the same scene
    except RuntimeError as exc:
        message = str(exc)
        if "Traceback" in message:
            COUNTS[kind]["other"] += 1
            raise
        COUNTS[kind]["refused"] += 1
        assert source.name in message or "field" in message, message
        assert dm.names_a_field(message, log, VOCABULARY[kind]) or "not valid TOML" in message, (message, log)
        assert state() == before
    finally:
        elapsed = time.perf_counter() - start
        COUNTS[kind]["max_seconds"] = max(COUNTS[kind]["max_seconds"], elapsed)
    dm.save_counts("operators", COUNTS)
    if dm.measuring():
        assert elapsed <= CASE_SECONDS


def _settings(default):
    n = dm.examples() if dm.measuring() else default
    return settings(max_examples=n, deadline=None, derandomize=not dm.measuring(), database=None,
                    suppress_health_check=list(HealthCheck))


PROPELLERS = sorted((ROOT / "data" / "propellers").glob("*.toml"))
IMPELLERS = sorted((ROOT / "data" / "impellers").glob("*.toml"))
WIND = ROOT / "data" / "blades" / "s823_small.toml"


@_settings(25)
@given(st.data())
def test_add_propeller_builds_or_refuses_cleanly(folder, data):
    source = data.draw(st.sampled_from(PROPELLERS))
    definition, log = data.draw(dm.mutated(tomllib.loads(source.read_text())))
    _run("propeller", folder, source, definition, log,
         lambda path: bpy.ops.bladesmith.add_propeller(definition=str(path)))


@_settings(8)
@given(st.data())
def test_add_wind_blade_builds_or_refuses_cleanly(folder, data):
    base = tomllib.loads(WIND.read_text())
    base["tolerance"], base["control_points"] = 3e-3, 10  # a fast build (0.3 s)
    definition, log = data.draw(dm.mutated(base))
    _run("wind", folder, WIND, definition, log,
         lambda path: bpy.ops.bladesmith.add_wind_blade(definition=str(path), fairness=False))


@_settings(25)
@given(st.data())
def test_add_impeller_builds_or_refuses_cleanly(folder, data):
    source = data.draw(st.sampled_from(IMPELLERS))
    definition, log = data.draw(dm.mutated(tomllib.loads(source.read_text())))
    _run("impeller", folder, source, definition, log,
         lambda path: bpy.ops.bladesmith.add_impeller(definition=str(path), full_wheel=False))
