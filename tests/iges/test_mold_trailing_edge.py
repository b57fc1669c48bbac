"""Issue 19, item 1: the NREL 5-MW trailing edge never folds.

The signed trailing-edge thickness is measured on the surfaces read back from the IGES
file we write (our reader; OCC reads the same file in test_mold_iges.py), at 1,000 points
along the span of the aerodynamic halves and of the root transition: upper TE minus lower
TE, projected on the section's thickness direction (span axis × chord line, the chord line
from the LE parting line to the TE midpoint). It must never be negative, must be positive
wherever the airfoils prescribe a blunt trailing edge, and must be zero (one edge) between
sharp stations. Before the fix the C2 skinning rang outboard of the DU21 -> NACA 64 jump
(12.6 mm -> 0) and the halves crossed by about a millimetre.

The preset opens its sharp stations to 4 mm (``min_trailing_edge_thickness``, issue 16);
the jump is tested on the airfoils as published (the key set to 0)."""
from __future__ import annotations

import numpy as np
import pytest

from bladesmith.geometry.mold import build_blade
from bladesmith.geometry.mold.definition import blade_from_dict, preset_files
from bladesmith.geometry.validation import read_toml
from bladesmith.iges import read_iges
from bladesmith.iges.convert import bspline_surface
from bladesmith.iges.mold import write_molds
from bladesmith.iges.records import BSplineSurface128

SPAN_POINTS = 1000
#: Thickness below this (m) counts as zero: evaluating equal control points through two
#: different rows of the u basis differs by rounding only.
ZERO = 1e-12


@pytest.fixture(scope="module")
def surfaces(tmp_path_factory):
    path = preset_files()["NREL5MW"]
    data = read_toml(path)
    data["min_trailing_edge_thickness"] = 0.0  # the published sharp NACA 64 and root stations
    molds = build_blade(blade_from_dict(data, str(path), path.parent), fairness=False, single=False)
    path = tmp_path_factory.mktemp("te") / "nrel5mw.igs"
    write_molds(path, molds)
    out = {e.label: bspline_surface(e) for e in read_iges(path).entities if isinstance(e, BSplineSurface128)}
    return molds, out


def signed_thickness(upper, lower):
    v = np.linspace(upper.knots_v[0], upper.knots_v[-1], SPAN_POINTS)
    U, L, LE = upper.evaluate(0.0, v), lower.evaluate(1.0, v), upper.evaluate(1.0, v)
    chord = 0.5 * (U + L) - LE
    n = np.cross([0.0, 0.0, 1.0], chord)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return U[:, 2], np.einsum("ij,ij->i", U - L, n)


@pytest.mark.parametrize("halves", [("UPPER", "LOWER"), ("ROOTUP", "ROOTLO")], ids=["aero", "root"])
def test_nrel5mw_trailing_edge_never_folds(surfaces, halves):
    molds, srf = surfaces
    z, t = signed_thickness(srf[halves[0]], srf[halves[1]])
    st = molds.definition.stations
    r = np.array([s.r for s in st])
    blunt = np.array([s.airfoil.outline[0, 1] - s.airfoil.outline[-1, 1] for s in st]) * np.array([s.chord for s in st])
    print(f"\n{halves[0]}/{halves[1]}: signed TE thickness min {t.min():.3e} m, max {t.max():.4e} m "
          f"at {SPAN_POINTS} points over z = {z[0]:.2f}..{z[-1]:.2f} m")
    assert t.min() >= -ZERO, f"the halves cross by {-t.min():.3e} m at z = {z[np.argmin(t)]:.3f} m"
    # between two blunt stations strictly positive, between two sharp ones one edge
    k = np.clip(np.searchsorted(r, z, side="right") - 1, 0, len(r) - 2)
    both_blunt = (blunt[k] > 0) & (blunt[k + 1] > 0)
    both_sharp = (blunt[k] == 0) & (blunt[k + 1] == 0)
    assert both_sharp.any()  # the sharp stretch is there (the preset's 4 mm opening is off)
    assert np.all(t[both_blunt] > 0.5 * np.minimum(blunt[k], blunt[k + 1])[both_blunt])
    assert np.all(np.abs(t[both_sharp]) <= ZERO)
