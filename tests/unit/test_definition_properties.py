"""Property tests of the three definition formats (issue 20, Deliver 4): a shipped preset
mutated at random (tests/definition_mutations.py) either builds, or is refused with a
BladesmithError that names a field; nothing else may escape. The scene side (operators
leave it unchanged) is tests/blender/test_definition_properties_operators.py.

Default: DEFAULT_EXAMPLES cases per format, derandomised. The measured runs of the report
set BLADESMITH_PROPERTY_EXAMPLES=2000 (random seeds) and print the counts; each case must
then finish within CASE_SECONDS (README "Property tests")."""
import pathlib
import sys
import time
import tomllib

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
import definition_mutations as dm  # noqa: E402

from bladesmith.geometry.compressor import ImpellerDefinition  # noqa: E402
from bladesmith.geometry.compressor import definition as impeller_definition  # noqa: E402
from bladesmith.geometry.compressor.export import impeller_surfaces  # noqa: E402
from bladesmith.geometry.errors import BladesmithError, DefinitionError  # noqa: E402
from bladesmith.geometry.mold import definition as wind_definition  # noqa: E402
from bladesmith.geometry.mold.blade import build_blade  # noqa: E402
from bladesmith.geometry.mold.definition import blade_from_dict  # noqa: E402
from bladesmith.geometry.propeller import Propeller  # noqa: E402
from bladesmith.geometry.propeller import definition as propeller_definition  # noqa: E402
from bladesmith.geometry.propeller.display import (  # noqa: E402
    DISPLAY_TOLERANCE_FRACTION,
    blade_display_surface,
    hub_surface,
)

ROOT = pathlib.Path(__file__).resolve().parents[2]
#: Longest a case may take in the measured runs (a wind blade at the largest counts).
CASE_SECONDS = 60.0


def _load(path):
    return tomllib.loads(path.read_text())


PROPELLERS = sorted((ROOT / "data" / "propellers").glob("*.toml"))
IMPELLERS = sorted((ROOT / "data" / "impellers").glob("*.toml"))
WIND = ROOT / "data" / "blades" / "s823_small.toml"


def wind_base() -> dict:
    """The S823 small blade at a tolerance it meets with few control points (0.3 s a build)."""
    data = _load(WIND)
    data["tolerance"] = 3e-3
    data["control_points"] = 10
    return data


def build_propeller(data, path):
    p = Propeller.from_dict(data, source=path)
    model = p.build()
    blade_display_surface(model.blade, DISPLAY_TOLERANCE_FRACTION * p.diameter)
    hub_surface(model.hub)


def build_wind(data, path):
    defn = blade_from_dict(data, str(path), path.parent)
    build_blade(defn, fairness=True)


def build_impeller(data, path):
    model = ImpellerDefinition.from_dict(data, str(path)).build()
    impeller_surfaces(model, 1, include_camber=True)


VOCABULARY = {
    "propeller": set(propeller_definition._TOP_KEYS) | propeller_definition._SECTION_KEYS
    | propeller_definition._HUB_KEYS | set(propeller_definition.RADIAL_FIELDS) | {"display_tolerance"},
    "wind": set(wind_definition.TOP_KEYS) | set(wind_definition.REQUIRED) | set(wind_definition.OPTIONAL),
    "impeller": set(impeller_definition.TOP_KEYS) | set(impeller_definition.CHANNEL_KEYS)
    | set(impeller_definition.BLADE_KEYS) | set(impeller_definition.SPLITTER_KEYS)
    | set(impeller_definition.STANDARDISATION_KEYS),
}
COUNTS = {kind: {"built": 0, "refused": 0, "other": 0, "max_seconds": 0.0} for kind in VOCABULARY}


def check_case(kind: str, build, data, log, path):
    counts = COUNTS[kind]
    start = time.perf_counter()
    try:
        build(data, path)
        outcome = "built"
    except BladesmithError as exc:
        outcome = "refused"
        message = str(exc)
        assert dm.names_a_field(message, log, VOCABULARY[kind]), (message, log)
        if isinstance(exc, DefinitionError):
            assert path.name in message, message  # and the file
    except BaseException:
        counts["other"] += 1
        raise
    finally:
        elapsed = time.perf_counter() - start
        counts["max_seconds"] = max(counts["max_seconds"], elapsed)
    counts[outcome] += 1
    dm.save_counts("unit", COUNTS)
    if dm.measuring():
        assert elapsed <= CASE_SECONDS, (elapsed, log)


def _settings():
    return settings(max_examples=dm.examples(), deadline=None, derandomize=not dm.measuring(), database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.filter_too_much])


@_settings()
@given(st.data())
def test_propeller_definitions_build_or_are_refused_by_name(data):
    path = data.draw(st.sampled_from(PROPELLERS))
    definition, log = data.draw(dm.mutated(_load(path)))
    check_case("propeller", build_propeller, definition, log, path)


@settings(parent=_settings(), max_examples=max(dm.examples() // 5, 20) if not dm.measuring() else dm.examples())
@given(st.data())
def test_wind_definitions_build_or_are_refused_by_name(data):
    definition, log = data.draw(dm.mutated(wind_base()))
    check_case("wind", build_wind, definition, log, WIND)


@_settings()
@given(st.data())
def test_impeller_definitions_build_or_are_refused_by_name(data):
    path = data.draw(st.sampled_from(IMPELLERS))
    definition, log = data.draw(dm.mutated(_load(path)))
    check_case("impeller", build_impeller, definition, log, path)


@pytest.fixture(scope="module", autouse=True)
def print_counts():
    yield
    if dm.measuring():
        for kind, counts in COUNTS.items():
            print(f"\nproperty {kind}: {counts}")
