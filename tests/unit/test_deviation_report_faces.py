"""Issue 15: the deviation report's projection onto the unsmoothed blade b must not end on
the wrong face of a thin tip (geometry/propeller/smoothing.py, ``_project(mirror=True)``).

Near the tip of the 72°-skew irregular blade the section is thinner than the seed grid is
fine; a projection started on the other face ends in a local minimum 3-4 times farther
than the point really is, which overstated the reported deviation inside the smoothing
zone (2.03e-4 D reported against 1.90e-4 D by a dense independent projection)."""
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.propeller import Propeller
from bladesmith.geometry.propeller.smoothing import _mirrored, _project

SKEWED = pathlib.Path(__file__).resolve().parents[1] / "data" / "irregular_tips" / "skewed_fast.toml"


@pytest.fixture(scope="module")
def blade():
    return Propeller.from_toml(SKEWED).build().blade


@pytest.mark.parametrize("xi, eta, offset", [(0.979, 0.9816, 5e-5), (0.97, 0.985, 3e-5), (0.03, 0.98, 5e-5)])
def test_a_start_on_the_other_face_still_finds_the_point(blade, xi, eta, offset):
    p = np.array([[xi, eta]])
    X = blade.evaluate(p[:, 0], p[:, 1]) + offset * blade.normal(p[:, 0], p[:, 1])
    wrong_face = _mirrored(p)
    d, q = _project(blade, X, [wrong_face], mirror=True)
    assert d[0] == pytest.approx(offset, rel=1e-6)
    assert np.allclose(q[0], p[0], atol=1e-6)
    # without looking at the other face the same start ends far away (what the report did)
    d_plain, _ = _project(blade, X, [wrong_face])
    assert d_plain[0] > 2.0 * offset


def test_mirror_leaves_thick_parts_alone(blade):
    p = np.array([[0.55, 0.99], [0.3, 0.6]])
    X = blade.evaluate(p[:, 0], p[:, 1]) + 2e-5 * blade.normal(p[:, 0], p[:, 1])
    d, q = _project(blade, X, [p], mirror=True)
    assert np.allclose(d, 2e-5, rtol=1e-6) and np.allclose(q, p, atol=1e-6)
