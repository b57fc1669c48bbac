"""windIO import (issue 19, item 3): the strict YAML-subset reader against PyYAML on both
IEA 15 MW files, its refusals, and the blade both windIO versions give."""
from __future__ import annotations

import math
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.errors import DefinitionError
from bladesmith.geometry.mold import blade_from_dict, load_blade, yaml_subset
from bladesmith.geometry.mold.windio import open_flatback, windio_blade_dict

WIND = pathlib.Path(__file__).resolve().parents[3] / "shared" / "data" / "wind"
V1 = WIND / "IEA-15-240-RWT.yaml"
V2 = WIND / "IEA-15-240-RWT_windIO2.yaml"


def _same(ours, theirs, where="$") -> list[str]:
    """Differences between our tree and PyYAML's. PyYAML resolves YAML 1.1, which reads a
    float without a dot (2e6, 3.55e10) as a string; YAML 1.2 (ours) reads a number."""
    if isinstance(theirs, str) and isinstance(ours, float):
        try:
            return [] if float(theirs) == ours else [f"{where}: {ours!r} != {theirs!r}"]
        except ValueError:
            return [f"{where}: {ours!r} != {theirs!r}"]
    if type(ours) is not type(theirs) and not (
            isinstance(ours, (int, float)) and isinstance(theirs, (int, float))
            and not isinstance(ours, bool) and not isinstance(theirs, bool)):
        return [f"{where}: type {type(ours).__name__} != {type(theirs).__name__}"]
    if isinstance(ours, dict):
        if list(ours) != list(theirs):
            return [f"{where}: keys {list(ours)[:5]} != {list(theirs)[:5]}"]
        return [d for k in ours for d in _same(ours[k], theirs[k], f"{where}.{k}")]
    if isinstance(ours, list):
        if len(ours) != len(theirs):
            return [f"{where}: length {len(ours)} != {len(theirs)}"]
        return [d for i, (a, b) in enumerate(zip(ours, theirs)) for d in _same(a, b, f"{where}[{i}]")]
    if ours != theirs and not (isinstance(ours, float) and math.isnan(ours) and math.isnan(theirs)):
        return [f"{where}: {ours!r} != {theirs!r}"]
    return []


@pytest.mark.parametrize("path", [V1, V2], ids=["windIO1", "windIO2"])
def test_subset_reader_equals_pyyaml_on_the_iea_15mw_files(path):
    yaml = pytest.importorskip("yaml")  # test-only dependency (requirements-test.txt)
    with open(path) as fh:
        theirs = yaml.safe_load(fh)
    ours = yaml_subset.load(path)
    assert _same(ours, theirs) == []
    # anchors and aliases are one object, as PyYAML makes them
    if path == V1:
        blade = ours["components"]["blade"]
        assert blade["outer_shape_bem"]["twist"] is blade["elastic_properties_mb"]["six_x_six"]["twist"]


@pytest.mark.parametrize("text, line, words", [
    ("a: 1\nb: |\n  text\n", 2, "unsupported"),
    ("a: 1\n\tb: 2\n", 2, "tab"),
    ("a: 1\na: 2\n", 2, "duplicate key"),
    ("a: *nowhere\n", 1, "unknown alias"),
    ("a: [1, 2\n", 1, "does not close"),
    ("a: 'open\n", 1, "does not end"),
    ("a: 1\n  b: 2\n", 2, "indentation"),
    ("a: !!float 1\n", 1, "unsupported"),
    ("a: 1\n---\nb: 2\n", 2, "one document"),
])
def test_subset_reader_refuses_what_it_does_not_read_with_the_line(text, line, words):
    with pytest.raises(DefinitionError, match=rf"x\.yaml: line {line}: .*{words}"):
        yaml_subset.loads(text, "x.yaml")


def test_subset_reader_scalars_flow_and_block_forms():
    doc = yaml_subset.loads(
        "a: [1, -2.5e3, .inf, ~, true, 'it''s', \"q\\\"\", plain text]\n"
        "b: {x: 1, y: [2, 3]}\nc:\n- k: 1\n  m: 2\n-  - 5\n   - 6\nd: &A [7]\ne: *A\n# end\n")
    assert doc["a"][:2] == [1, -2500.0] and doc["a"][2] == math.inf and doc["a"][3:] == [
        None, True, "it's", 'q"', "plain text"]
    assert doc["b"] == {"x": 1, "y": [2, 3]}
    assert doc["c"] == [{"k": 1, "m": 2}, [5, 6]]
    assert doc["e"] is doc["d"]


def test_both_windio_versions_give_the_same_blade():
    a, b = windio_blade_dict(V1), windio_blade_dict(V2)
    assert a["source"]["windio_version"] == 1 and b["source"]["windio_version"] == 2
    for key in ("r", "chord", "twist_deg", "prebend", "sweep"):
        assert np.allclose(a["stations"][key], b["stations"][key], rtol=0, atol=1e-9), key
    # v1 gives the pitch axis on its own 50-point grid, v2 the offset on the chord's 53
    # points: between grid points the two interpolants differ by up to 1e-4 chord (near the tip)
    assert np.allclose(a["stations"]["pitch_axis"], b["stations"]["pitch_axis"], rtol=0, atol=2e-4)
    strip = [lambda s: s.split("#", 1)[-1]]
    assert [strip[0](x) for x in a["stations"]["airfoil"]] == [strip[0](x) for x in b["stations"]["airfoil"]]
    assert a["first_aerodynamic_station"] == b["first_aerodynamic_station"] == 2


def test_iea15mw_planform_as_published():
    d = load_blade(V1)  # the definition path: a windIO file through the TOML checks
    st = d.stations
    assert d.hub_radius == pytest.approx(3.97)
    assert st[0].r == pytest.approx(3.97) and st[-1].r == pytest.approx(3.97 + 117.0)
    assert st[0].chord == pytest.approx(5.2) and st[-1].chord == pytest.approx(0.5)
    assert st[0].twist_deg == pytest.approx(np.degrees(0.27217629557079365))
    assert st[-1].prebend == pytest.approx(-4.0)
    assert [s.airfoil_name for s in st[:2]] == ["circle", "circle"]
    assert st[2].airfoil_name.endswith("#SNL-FFA-W3-500")
    # windIO closes the flatback: we open it, the TE is 2 % of the chord thick
    assert st[2].airfoil.trailing_edge_thickness == pytest.approx(0.0206, abs=5e-4)
    # a blend between two of the file's airfoils, named so that a saved definition reads it again
    blend = next(s for s in st if "|" in s.airfoil_name)
    again = blade_from_dict(d.to_dict(), str(V1), V1.parent)
    k = st.index(blend)
    assert np.array_equal(again.stations[k].airfoil.outline, blend.airfoil.outline)


def test_open_flatback_drops_only_the_base_steps():
    x = 0.5 * (1 - np.cos(np.linspace(0, np.pi, 40)))
    up = np.column_stack([x[::-1], 0.1 * np.sin(np.pi * x[::-1]) + 0.01 * x[::-1]])
    lo = np.column_stack([x[1:], -0.1 * np.sin(np.pi * x[1:]) - 0.01 * x[1:]])
    closed = np.vstack([[1.0, 0.0], up, lo, [1.0, 0.0]])
    assert np.array_equal(open_flatback(closed), np.vstack([up, lo]))
    assert np.array_equal(open_flatback(np.vstack([up, lo])), np.vstack([up, lo]))


def test_missing_windio_field_is_named(tmp_path):
    text = V2.read_text().replace("            chord:\n", "            chrd:\n", 1)
    bad = tmp_path / "bad.yaml"
    bad.write_text(text)
    with pytest.raises(DefinitionError, match=r"bad\.yaml: field 'components\.blade\.outer_shape\.chord'"):
        load_blade(bad)
