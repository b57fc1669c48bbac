"""DTMB 4119 (shared/data/marine/dtmb4119_geometry.csv): at every radial station the section
cut of b(ξ, η) at that radius reproduces the table to 1e-6 D (issue 4 acceptance):
chord along the helix, pitch of the nose–tail line, maximum thickness, maximum camber,
skew of the mid-chord point and rake."""
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.propeller import Propeller

ROOT = pathlib.Path(__file__).resolve().parents[2]
CSV = ROOT.parent / "shared" / "data" / "marine" / "dtmb4119_geometry.csv"
TOL = 1e-6  # in units of D


def _table():
    lines = [ln for ln in CSV.read_text().splitlines() if ln and not ln.startswith("#")]
    header = lines[0].split(",")
    data = np.array([ln.split(",") for ln in lines[1:]], dtype=float)
    return [dict(zip(header, row)) for row in data]


@pytest.fixture(scope="module")
def model():
    return Propeller.from_toml(ROOT / "data" / "propellers" / "dtmb4119.toml").build()


@pytest.mark.parametrize("row", _table(), ids=lambda r: f"r_R={r['r_R']}")
def test_station_reproduced(model, row):
    blade = model.blade
    D = model.definition.diameter
    m = blade.measure_section(row["r_R"] * blade.radius)
    chord = row["c_D"] * D
    assert abs(m.chord - chord) < TOL * D
    assert abs(m.max_thickness - row["t0_c"] * chord) < TOL * D
    assert abs(m.max_camber - row["f0_c"] * chord) < TOL * D
    assert abs(np.radians(m.skew_deg - row["skew_deg"]) * m.radius) < TOL * D
    assert abs(m.rake - row["rake_D"] * D) < TOL * D
    if chord > 0:
        assert abs(m.pitch - row["P_D"] * D) < TOL * D
        phi = np.degrees(np.arctan(row["P_D"] * D / (2 * np.pi * m.radius)))
        assert m.pitch_angle_deg == pytest.approx(phi, abs=1e-9)
