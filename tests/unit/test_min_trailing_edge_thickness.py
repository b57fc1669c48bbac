"""``min_trailing_edge_thickness`` (issue 16): every station's trailing edge opened to at
least this thickness, so a blunt trailing-edge base never ends in a zero-angle cusp where
the airfoils turn sharp (NREL 5-MW: the NACA 64-618 from r = 44.55 m, the root circles).
The NREL 5-MW preset sets 4 mm; the README gives how far its surface moves."""
from __future__ import annotations

import numpy as np
import pytest

from bladesmith.geometry.errors import DefinitionError
from bladesmith.geometry.mold import blade_from_dict, load_preset
from bladesmith.geometry.mold.definition import TE_OPENING_BLEND, TOP_LEVEL_KEYS, opened_trailing_edge, preset_files
from bladesmith.geometry.validation import read_toml

NREL_TE_MIN = 0.004  # m, data/blades/nrel5mw.toml


def _published_nrel():
    path = preset_files()["NREL5MW"]
    data = read_toml(path)
    data["min_trailing_edge_thickness"] = 0.0
    return blade_from_dict(data, str(path), path.parent)


def test_nrel5mw_trailing_edge_is_at_least_4_mm_and_moves_at_most_2_mm():
    opened, published = load_preset("NREL5MW"), _published_nrel()
    assert opened.min_trailing_edge_thickness == NREL_TE_MIN
    moved_any = False
    for k, (a, b) in enumerate(zip(opened.stations, published.stations)):
        te = a.airfoil.trailing_edge_thickness * a.chord
        assert te >= NREL_TE_MIN * (1 - 1e-12), f"station {k}: trailing edge {te * 1e3:.3f} mm"
        for side in ("upper", "lower"):
            P, Q = getattr(a.airfoil, side), getattr(b.airfoil, side)
            assert np.array_equal(P[:, 0], Q[:, 0])  # only y moves
            move = np.abs(P[:, 1] - Q[:, 1]) * a.chord
            ahead = P[:, 0] <= 1.0 - TE_OPENING_BLEND
            assert np.all(move[ahead] == 0.0)
            assert move.max() <= 0.5 * NREL_TE_MIN * (1 + 1e-12)
            moved_any = moved_any or move.max() > 0
        if b.airfoil.trailing_edge_thickness * b.chord >= NREL_TE_MIN:  # the DU airfoils: as published
            assert a.airfoil is b.airfoil or np.array_equal(a.airfoil.upper, b.airfoil.upper)
    assert moved_any


def test_opening_keeps_the_camber_and_a_thick_edge():
    foil = load_preset("NREL5MW").stations[-1].airfoil  # opened NACA 64-618
    sharp = _published_nrel().stations[-1].airfoil
    assert sharp.sharp_trailing_edge
    out = opened_trailing_edge(sharp, 0.01)
    assert out.trailing_edge_thickness == pytest.approx(0.01, rel=1e-12)
    # the camber line (mean of the sides at equal x, here the TE point) does not move
    assert np.allclose(0.5 * (out.upper[-1] + out.lower[-1]), 0.5 * (sharp.upper[-1] + sharp.lower[-1]), atol=1e-15)
    assert opened_trailing_edge(foil, 0.5 * foil.trailing_edge_thickness) is foil


@pytest.mark.parametrize("value, words", [(-0.001, r"\[0, "), (1.0, "MAX_TE_THICKNESS_CHORDS"), ("thin", "finite")])
def test_min_trailing_edge_thickness_is_checked(value, words):
    data = load_preset("S823_SMALL").to_dict()
    data["min_trailing_edge_thickness"] = value
    with pytest.raises(DefinitionError, match=rf"t\.toml: field 'min_trailing_edge_thickness': .*{words}"):
        blade_from_dict(data, "t.toml", preset_files()["S823_SMALL"].parent)


def test_key_round_trips():
    assert "min_trailing_edge_thickness" in TOP_LEVEL_KEYS
    defn = load_preset("NREL5MW")
    again = blade_from_dict(defn.to_dict(), "t.toml", preset_files()["NREL5MW"].parent)
    assert again.min_trailing_edge_thickness == NREL_TE_MIN
    for a, b in zip(defn.stations, again.stations):
        assert np.array_equal(a.airfoil.upper, b.airfoil.upper) and np.array_equal(a.airfoil.lower, b.airfoil.lower)
