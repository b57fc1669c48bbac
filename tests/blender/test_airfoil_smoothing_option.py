"""Issue 6 in Blender: the propeller panel's "Smooth airfoil (Hvid)" and the wind-blade
panel's "Smooth airfoils (Hvid)" regenerate the objects, and switching them off again
brings the first geometry back."""
import pathlib
import tomllib

import bpy
import numpy as np
import pytest

from bladesmith.geometry.nurbs.projection import closest_point_surface
from bladesmith.geometry.propeller import Propeller
from bladesmith.operators import propeller as prop_ops
from bladesmith.operators import wind_blade as blade_ops
from bladesmith.operators.nurbs_objects import stored_geometry
from bladesmith.ui import propeller_panel, wind_blade_panel

ROOT = pathlib.Path(__file__).resolve().parents[2]
DTMB = ROOT / "data" / "propellers" / "dtmb4119.toml"
S823 = ROOT / "data" / "blades" / "airfoils" / "s823.dat"
#: Control points per half the S823 blade is fitted with (see test_wind_blade_operator).
S823_CONTROL_POINTS = 24


class Layout:
    """Stands in for UILayout; records the properties drawn and the rows' ``enabled``."""

    def __init__(self, calls, state=None):
        object.__setattr__(self, "calls", calls)
        object.__setattr__(self, "state", state if state is not None else {})

    def __getattr__(self, name):  # row, column, box, operator, label, template_list, ...
        return lambda *args, **kwargs: Layout(self.calls, {})

    def __setattr__(self, name, value):
        self.state[name] = value

    def prop(self, data, name, **kwargs):
        assert name in data.bl_rna.properties, f"{data} has no property {name!r}"
        self.calls.append((name, self.state.get("enabled", True)))


def drawn(panel_cls) -> dict:
    calls = []
    fake = type("FakePanel", (), {"layout": Layout(calls)})()
    panel_cls.draw(fake, bpy.context)
    return dict(calls)


def _surface(obj):
    (entity,) = stored_geometry(obj)
    return entity


# -- the propeller ---------------------------------------------------------------------------------
@pytest.fixture
def propeller(scene, tmp_path):
    text = DTMB.read_text().replace('thickness = "naca66mod"', f'thickness = "{S823.as_posix()}"')
    path = tmp_path / "s823_propeller.toml"
    path.write_text(text.replace('meanline = "a=0.8"', 'meanline = "airfoil"'))
    assert bpy.ops.bladesmith.add_propeller(definition=str(path)) == {"FINISHED"}
    (root,) = [obj for obj in bpy.data.objects if prop_ops.find_root(obj) is obj]
    bpy.context.view_layer.objects.active = root
    return root


def _points(surface, samples: np.ndarray) -> np.ndarray:
    """The surface at ``samples`` (2, n) in [0, 1]², mapped onto its parameter domain."""
    ku, kv = surface.knots_u, surface.knots_v
    return surface.evaluate(ku[0] + (ku[-1] - ku[0]) * samples[0], kv[0] + (kv[-1] - kv[0]) * samples[1])


def test_propeller_toggle_regenerates_and_restores(propeller):
    s = propeller.bladesmith_propeller
    assert s.smooth_airfoil is False and s.thickness_kind == prop_ops.THICKNESS_FILE
    parts = prop_ops.propeller_parts(propeller)
    ids = {key: obj.as_pointer() for key, obj in parts.items()}
    before = _surface(parts[("blade", 0, 0)])
    before_toml = s.definition_toml
    assert "smooth_airfoil" not in before_toml

    s.smooth_airfoil = True
    assert not s.status_is_error, s.status
    assert "airfoil smoothed (Hvid), deviation" in s.status
    after = _surface(prop_ops.propeller_parts(propeller)[("blade", 0, 0)])
    assert {key: obj.as_pointer() for key, obj in prop_ops.propeller_parts(propeller).items()} == ids
    definition = Propeller.from_dict(tomllib.loads(s.definition_toml))
    assert definition.section.smooth_airfoil is True
    # the shown blade moved, by less than a thousandth of the diameter
    uv = np.random.default_rng(3).random((2, 2000))
    a, b = _points(before, uv), _points(after, uv)
    change = np.abs(a - b).max()
    print(f"\nS823 propeller: smoothing moves the shown blade by up to {change:.2e} m (D = 0.3048 m)")
    assert 1e-7 < change < 1e-3 * definition.diameter

    # fewer passes: a live edit, closer to the file
    s.smooth_passes = 1
    assert not s.status_is_error, s.status
    assert tomllib.loads(s.definition_toml)["section"]["smooth_passes"] == 1
    one_pass = _surface(prop_ops.propeller_parts(propeller)[("blade", 0, 0)])
    assert np.abs(_points(one_pass, uv) - a).max() < change
    s.smooth_passes = 4

    s.smooth_airfoil = False
    assert not s.status_is_error, s.status
    assert "smoothed" not in s.status
    restored = _surface(prop_ops.propeller_parts(propeller)[("blade", 0, 0)])
    assert s.definition_toml == before_toml
    # the previous knots still hold the tolerance, so the first net comes back exactly
    assert np.array_equal(restored.control_points, before.control_points)
    assert np.array_equal(_points(restored, uv), a)


def test_propeller_flag_only_applies_to_airfoil_files(propeller):
    s = propeller.bladesmith_propeller
    s.smooth_airfoil = True
    assert not s.status_is_error, s.status
    assert drawn(propeller_panel.BLADESMITH_PT_propeller_section)["smooth_airfoil"] is True
    smoothed = Propeller.from_dict(tomllib.loads(s.definition_toml))
    s.meanline = "A08"
    s.thickness_kind = "NACA66MOD"
    assert not s.status_is_error, s.status  # the flag is ignored, and drawn disabled
    assert "smooth_airfoil" not in prop_ops.settings_to_dict(s)["section"]
    assert drawn(propeller_panel.BLADESMITH_PT_propeller_section)["smooth_airfoil"] is False
    # loading a definition writes the flag into the panel
    prop_ops.definition_to_settings(s, Propeller.from_dict(tomllib.loads(s.definition_toml)))
    assert s.smooth_airfoil is False
    prop_ops.definition_to_settings(s, smoothed)
    assert s.smooth_airfoil is True and s.thickness_kind == prop_ops.THICKNESS_FILE
    assert prop_ops.settings_to_definition(s) == smoothed


# -- the wind blade --------------------------------------------------------------------------------
@pytest.fixture
def blade(scene):
    bpy.ops.bladesmith.add_wind_blade(preset="S823_SMALL", control_points=S823_CONTROL_POINTS, fairness=False)
    (root,) = [obj for obj in bpy.data.objects if blade_ops.find_root(obj) is obj]
    bpy.context.view_layer.objects.active = root
    return root


def test_wind_blade_toggle_regenerates_and_restores(blade):
    s = blade.bladesmith_wind_blade
    assert s.smooth_airfoils is False
    assert "smooth_airfoils" in drawn(wind_blade_panel.BLADESMITH_PT_wind_blade)
    parts = blade_ops.mold_parts(blade)
    before_surfaces = {name: _surface(obj) for name, obj in parts.items()}
    before = {name: surface.control_points.copy() for name, surface in before_surfaces.items()}
    u, v = np.meshgrid(np.linspace(0.02, 0.98, 25), np.linspace(0.02, 0.98, 25))
    grid = np.stack([u.ravel(), v.ravel()])
    before_toml = s.definition_toml

    s.smooth_airfoils = True
    assert not s.status_is_error, s.status
    assert "airfoils smoothed (Hvid), worst deviation" in s.status
    assert tomllib.loads(s.definition_toml)["smooth_airfoils"] is True
    upper = _surface(blade_ops.mold_parts(blade)["upper"])
    assert upper.control_points.shape != before["upper"].shape or not np.allclose(upper.control_points,
                                                                                   before["upper"])
    # geometrically a small change: the smoothed upper mold against the first one
    _, _, distance = closest_point_surface(before_surfaces["upper"], _points(upper, grid))
    chord = max(st.chord for st in s.stations)
    print(f"\nS823 blade: smoothing moves the upper mold by up to {distance.max():.2e} m "
          f"({distance.max() / chord:.2e} of the largest chord)")
    assert 1e-7 < distance.max() < 2e-3 * chord

    s.smooth_airfoils = False
    assert not s.status_is_error, s.status
    assert s.definition_toml == before_toml
    for name, obj in blade_ops.mold_parts(blade).items():
        assert np.array_equal(_surface(obj).control_points, before[name]), name
