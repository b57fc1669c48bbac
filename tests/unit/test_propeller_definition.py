"""Propeller definition files: reading, round trip, and refusal of invalid definitions
(the message names the file, the field and the value; nothing is built)."""
import pathlib
import shutil

import numpy as np
import pytest

from bladesmith.geometry.errors import DefinitionError
from bladesmith.geometry.propeller import Propeller, dumps_toml

ROOT = pathlib.Path(__file__).resolve().parents[2]
PRESETS = ROOT / "data" / "propellers"
SHARED_DATA = ROOT.parent / "shared" / "data"
DTMB = PRESETS / "dtmb4119.toml"


def test_presets_load_and_build():
    for path in sorted(PRESETS.glob("*.toml")):
        p = Propeller.from_toml(path)
        model = p.build()
        assert model.blade.radius == pytest.approx(0.5 * p.diameter)


def test_dtmb4119_matches_shared_table():
    p = Propeller.from_toml(DTMB)
    rows = [
        line.split(",")
        for line in (SHARED_DATA / "marine" / "dtmb4119_geometry.csv").read_text().splitlines()
        if line and not line.startswith("#")
    ]
    header, data = rows[0], np.array(rows[1:], dtype=float)
    col = {h: data[:, i] for i, h in enumerate(header)}
    for ours, theirs in (("r_R", "r_R"), ("c_D", "c_D"), ("P_D", "P_D"), ("t_c", "t0_c"), ("f_c", "f0_c"),
                         ("skew_deg", "skew_deg"), ("rake_D", "rake_D")):
        assert np.array_equal(getattr(p.radial, ours), col[theirs]), ours
    assert (p.blades, p.hub_diameter_ratio, p.hand) == (3, 0.2, "right")


def test_toml_round_trip(tmp_path):
    p = Propeller.from_toml(DTMB)
    out = tmp_path / "copy.toml"
    p.to_toml(out, header="copy")
    q = Propeller.from_toml(out)
    assert q == p
    assert out.read_text().startswith("# copy")


def test_round_trip_rewrites_airfoil_path(tmp_path):
    folder = tmp_path / "a"
    folder.mkdir()
    shutil.copy(SHARED_DATA / "airfoils" / "s823.dat", folder / "s823.dat")
    text = DTMB.read_text().replace('thickness = "naca66mod"', 'thickness = "s823.dat"').replace('meanline = "a=0.8"', 'meanline = "airfoil"')
    (folder / "p.toml").write_text(text)
    p = Propeller.from_toml(folder / "p.toml")
    (tmp_path / "b").mkdir()
    p.to_toml(tmp_path / "b" / "q.toml")
    q = Propeller.from_toml(tmp_path / "b" / "q.toml")
    assert q.section.thickness == "../a/s823.dat"
    assert q.radial == p.radial
    q.build()


def test_radial_table_csv(tmp_path):
    shutil.copy(SHARED_DATA / "marine" / "dtmb4119_geometry.csv", tmp_path / "t.csv")
    text = DTMB.read_text()
    text = text[: text.index("[radial]")]
    text = text.replace('hand = "right"', 'hand = "right"\nradial_table = "t.csv"')
    (tmp_path / "p.toml").write_text(text)
    p = Propeller.from_toml(tmp_path / "p.toml")
    assert p.radial == Propeller.from_toml(DTMB).radial


# ---- invalid definitions ----------------------------------------------------------------
def _edited(tmp_path, old, new, name="bad.toml"):
    text = DTMB.read_text()
    assert old in text, old
    path = tmp_path / name
    path.write_text(text.replace(old, new, 1))
    return path


def _refused(path, *fragments):
    with pytest.raises(DefinitionError) as info:
        Propeller.from_toml(path).build()
    message = str(info.value)
    assert str(path.name) in message
    for fragment in fragments:
        assert fragment in message, (fragment, message)
    return info.value


def test_refuses_non_increasing_radii(tmp_path):
    path = _edited(tmp_path, "r_R      = [0.20,    0.30,    0.40", "r_R      = [0.20,    0.40,    0.40")
    _refused(path, "radial.r_R", "0.4")


def test_refuses_negative_chord(tmp_path):
    path = _edited(tmp_path, "0.4392,  0.4610", "-0.4392,  0.4610")
    e = _refused(path, "radial.c_D", "-0.4392", "negative")
    assert e.field == "radial.c_D"


def test_finite_tip_chord_up_to_the_closure_limit_is_read_and_above_it_refused_with_the_fix(tmp_path):
    from bladesmith.geometry.propeller.definition import MAX_TIP_CHORD_RATIO

    c_max = 0.4622  # DTMB 4119's largest chord / D
    ok = _edited(tmp_path, "0.2775,  0.0000]", f"0.2775,  {MAX_TIP_CHORD_RATIO * c_max:.6f}]")
    assert Propeller.from_toml(ok).radial.c_D[-1] > 0
    bad = _edited(tmp_path, "0.2775,  0.0000]", "0.2775,  0.2000]")
    e = _refused(bad, "radial.c_D", "0.2", "tip chord", "Lower the tip chord")
    assert e.field == "radial.c_D"


def test_refuses_nan(tmp_path):
    path = _edited(tmp_path, "1.093,   1.088", "nan,   1.088")
    _refused(path, "radial.P_D", "nan")


def test_refuses_self_intersecting_thickness_table(tmp_path):
    path = _edited(
        tmp_path,
        'thickness = "naca66mod"',
        'thickness = "table"\nthickness_x_c = [0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0]\n'
        "thickness_t = [0.0, 0.6, 1.0, -0.2, 0.5, 0.3, 0.0]",
    )
    _refused(path, "section.thickness_t", "-0.2", "self-intersect")


def test_refuses_thickness_table_whose_spline_crosses_zero(tmp_path):
    # every ordinate positive, but far too few near a deep dip: the section still closes on itself
    path = _edited(
        tmp_path,
        'thickness = "naca66mod"',
        'thickness = "table"\nthickness_x_c = [0.0, 0.05, 0.3, 0.35, 0.4, 0.9, 1.0]\n'
        "thickness_t = [0.0, 1.0, 1.0, 0.001, 1.0, 0.3, 0.0]",
    )
    _refused(path, "section.thickness", "self-intersect")


def test_refuses_thick_section_on_curved_meanline(tmp_path):
    # thickness laid off normal to a strongly curved mean line folds the concave side
    path = _edited(tmp_path, "t_c      = [0.2055,  0.1553", "t_c      = [0.95,  0.1553")
    path.write_text(path.read_text().replace("f_c      = [0.01429", "f_c      = [0.45"))
    _refused(path, "radial.t_c", "self-intersects")


def test_refuses_missing_airfoil_file(tmp_path):
    path = _edited(tmp_path, 'thickness = "naca66mod"', 'thickness = "no_such_airfoil.dat"')
    _refused(path, "section.thickness", "no_such_airfoil.dat", "does not exist")


def test_refuses_hub_radius_at_or_above_tip(tmp_path):
    path = _edited(tmp_path, "hub_diameter_ratio = 0.2", "hub_diameter_ratio = 1.0")
    _refused(path, "hub_diameter_ratio", "1.0")


@pytest.mark.parametrize(
    "old, new, fragments",
    [
        ('hand = "right"', 'hand = "up"', ("hand", "'up'")),
        ("blades = 3", "blades = 0", ("blades", "0")),
        ("diameter = 0.3048", "diameter = -1.0", ("diameter", "-1.0")),
        ("P_D      = [1.105", "P_D      = [-1.105", ("radial.P_D", "-1.105")),
        ("t_c      = [0.2055", "t_c      = [0.0", ("radial.t_c", "0.0")),
        ('meanline = "a=0.8"', 'meanline = "b=0.7"', ("section.meanline", "b=0.7")),
        ('nose_shape = "ellipse"', 'nose_shape = "round"', ("hub.nose_shape", "round")),
        ("1.00]", "0.99]", ("radial.r_R", "0.99")),
        ("f_c      = [0.01429, ", "f_c      = [", ("radial.f_c", "9 entries")),
    ],
)
def test_refuses_other_invalid_values(tmp_path, old, new, fragments):
    _refused(_edited(tmp_path, old, new), *fragments)


def test_refuses_unknown_field(tmp_path):
    path = _edited(tmp_path, "blades = 3", "blades = 3\nblade_count = 3")
    _refused(path, "blade_count")


def test_with_values_revalidates():
    p = Propeller.from_toml(DTMB)
    q = p.with_values(blades=4, radial_P_D=tuple(np.array(p.radial.P_D) * 1.1), hub_nose_shape="cone")
    assert q.blades == 4 and q.hub.nose_shape == "cone"
    assert q.radial.P_D[0] == pytest.approx(1.2155)
    with pytest.raises(DefinitionError, match="radial.c_D"):
        p.with_values(radial_c_D=(0.32, -0.1) + p.radial.c_D[2:])


def test_dumps_toml_is_valid_toml():
    import tomllib

    text = dumps_toml({"a": 1, "b": [1.5, 2.0], "s": 'q"x', "t": {"k": "v"}})
    assert tomllib.loads(text) == {"a": 1, "b": [1.5, 2.0], "s": 'q"x', "t": {"k": "v"}}
