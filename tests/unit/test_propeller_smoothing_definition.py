"""Issue 15: the [smoothing] table of a propeller definition (Hally 2013 settings: Δc,
d_t, d_e, s_j, α, n, tolerance, the sample spacing d and h/d of Eqs. 27-28, and the six
defining points of §4, Fig. 4): read with strict keys, refused with the file, the field
and the value, written back, and reaching the pipeline."""
import pathlib
import tomllib

import pytest

from bladesmith.geometry.errors import DefinitionError
from bladesmith.geometry.propeller import Propeller
from bladesmith.geometry.propeller.corners import DefiningPoints
from bladesmith.geometry.propeller.definition import SMOOTHING_KEYS
from bladesmith.geometry.propeller.smoothing import SmoothingSettings

ROOT = pathlib.Path(__file__).resolve().parents[2]
DTMB = ROOT / "data" / "propellers" / "dtmb4119.toml"
R = 0.1524  # DTMB 4119: D = 0.3048 m

#: Every key, none at its default (lengths in metres).
FULL = {
    "smooth_tip": True, "delta_c": 0.0036, "tip_smoothing_distance": 0.014, "edge_smoothing_distance": 0.009,
    "tolerance": 4e-6, "sample_spacing": 0.0012, "transition_s": 0.8, "filter_strength": 0.4,
    "edge_spacing_ratio": 0.02, "filter_iterations": 80, "xi_ll": 0.12, "xi_lr": 0.38, "xi_ul": 0.11,
    "eta_ul": 0.88, "xi_ur": 0.39, "eta_ur": 0.89, "eta_le": 0.91, "eta_te": 0.92,
}


def _with(smoothing, path):
    data = tomllib.loads(DTMB.read_text())
    data["smoothing"] = smoothing
    return Propeller.from_dict(data, source=path)


def test_every_smoothing_key_is_read_and_converted(tmp_path):
    assert set(FULL) == set(SMOOTHING_KEYS)
    p = _with(FULL, tmp_path / "p.toml")
    s = p.smoothing_settings()
    assert s.delta_c == pytest.approx(0.0036 / R) and s.sample_spacing == pytest.approx(0.0012 / R)
    assert s.tolerance == pytest.approx(4e-6 / R) and s.edge_spacing_ratio == 0.02
    assert (s.transition_s, s.filter_strength, s.filter_iterations) == (0.8, 0.4, 80)
    assert s.defining_points == DefiningPoints(0.12, 0.38, 0.11, 0.88, 0.39, 0.89, 0.91, 0.92)
    # no table, or an empty one: the defaults
    assert Propeller.from_toml(DTMB).smoothing_settings() == SmoothingSettings()
    assert _with({}, None).smoothing_settings() == SmoothingSettings()


def test_smoothing_table_round_trip(tmp_path):
    p = _with(FULL, None)
    out = tmp_path / "with_smoothing.toml"
    p.to_toml(out)
    text = out.read_text()
    assert "[smoothing]" in text
    q = Propeller.from_toml(out)
    assert q == p and q.smoothing == FULL
    assert tomllib.loads(text)["smoothing"] == FULL
    # a definition without the table writes none
    plain = tmp_path / "plain.toml"
    Propeller.from_toml(DTMB).to_toml(plain)
    assert "[smoothing]" not in plain.read_text()


@pytest.mark.parametrize("changes, fragments", [
    ({"delta_c": -0.001}, ("smoothing.delta_c", "-0.001 m")),
    ({"delta_c": "fine"}, ("smoothing.delta_c", "'fine'")),
    ({"sample_spacing": 0.0}, ("smoothing.sample_spacing", "0.0 m")),
    ({"edge_spacing_ratio": 1.0}, ("smoothing.edge_spacing_ratio", "1.0")),
    ({"edge_spacing_ratio": float("nan")}, ("smoothing.edge_spacing_ratio", "nan")),
    ({"filter_strength": 0.9}, ("smoothing.filter_strength", "0.9")),
    ({"filter_iterations": 2.5}, ("smoothing.filter_iterations", "2.5")),
    ({"filter_iterations": -1}, ("smoothing.filter_iterations", "-1")),
    ({"filter_iterations": 10**9}, ("smoothing.filter_iterations", "1000000000")),
    ({"transition_s": 1.0}, ("smoothing.transition_s", "1.0")),
    ({"smooth_tip": "yes"}, ("smoothing.smooth_tip", "'yes'")),
    ({"xi_ll": 0.3}, ("smoothing.xi_ll", "0.3")),
    ({"xi_ur": 0.2}, ("smoothing.xi_ur", "0.2")),
    ({"eta_le": 0.15}, ("smoothing.eta_le", "0.15", "hub radius ratio 0.2")),
    ({"eta_te": 1.0}, ("smoothing.eta_te", "1.0")),
    ({"d_t": 0.01}, ("smoothing.d_t", "unknown key")),
    ({"sample_spacng": 0.01}, ("smoothing.sample_spacng", "did you mean 'sample_spacing'")),
])
def test_bad_smoothing_values_are_refused_naming_file_field_and_value(tmp_path, changes, fragments):
    path = tmp_path / "bad_smoothing.toml"
    with pytest.raises(DefinitionError) as info:
        _with({**FULL, **changes}, path)
    message = str(info.value)
    for fragment in (str(path), *fragments):
        assert fragment in message, (fragment, message)


def test_smoothing_must_be_a_table(tmp_path):
    with pytest.raises(DefinitionError, match="field 'smoothing': expected a table"):
        _with(3, tmp_path / "x.toml")
