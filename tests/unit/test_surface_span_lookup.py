"""The binned span lookup of the surface table path (issue 22) returns exactly what
``find_span`` (NURBS Book Alg. A2.1) returns, on random and repeated knots, at the
knots themselves, one ulp either side, and at both ends of the domain; and the table
path's points and derivatives agree with the per-pair gather path."""
import numpy as np
import pytest

from bladesmith.geometry.nurbs import BSplineSurface
from bladesmith.geometry.nurbs.basis import find_span
from bladesmith.geometry.nurbs.surface import _SpanLookup


def knot_vectors():
    rng = np.random.default_rng(22)
    for degree in (1, 2, 3, 5):
        for n_inner in (0, 1, 7, 40):
            inner = np.sort(rng.uniform(0.2, 3.0, n_inner))
            yield degree, np.r_[[0.2] * (degree + 1), inner, [3.0] * (degree + 1)]
            if n_inner >= 3:  # repeated interior knots (multiplicity up to the degree)
                rep = np.repeat(inner[:3], [degree, 2, 1][: 3])
                yield degree, np.r_[[0.2] * (degree + 1), np.sort(np.r_[rep, inner[3:]]), [3.0] * (degree + 1)]
    # clustered knots: many knots inside one bin
    yield 3, np.r_[[0.0] * 4, 0.5 + 1e-9 * np.arange(30), [1.0] * 4]
    # unclamped uniform
    yield 3, np.arange(12.0)


@pytest.mark.parametrize("degree,knots", list(knot_vectors()))
def test_span_lookup_equals_find_span(degree, knots):
    a, b = knots[degree], knots[len(knots) - degree - 1]
    inside = knots[(knots >= a) & (knots <= b)]
    rng = np.random.default_rng(int(knots.size))
    u = np.concatenate([
        rng.uniform(a, b, 5000), inside, np.nextafter(inside, -np.inf), np.nextafter(inside, np.inf), [a, b],
    ])
    u = np.clip(u, a, b)
    assert np.array_equal(_SpanLookup(knots, degree)(u), find_span(knots, degree, u))


def test_table_path_matches_gather_path():
    rng = np.random.default_rng(5)
    knots = [np.r_[[0.0] * 4, np.sort(rng.uniform(0, 1, 12)), [1.0] * 4] for _ in range(2)]
    s = BSplineSurface(3, 3, knots[0], knots[1], rng.normal(size=(16, 16, 3)),
                       rng.uniform(0.5, 2.0, (16, 16)))
    u, v = rng.uniform(0, 1, 3000), rng.uniform(0, 1, 3000)
    assert s._use_patch_table(u.size)
    for order in (0, 1, 3):
        table = s._table_derivatives(u, v, order)
        gather = s._gather_derivatives(u, v, order)
        scale = np.abs(gather).max(axis=0)
        assert np.all(np.abs(table - gather) <= 1e-12 * scale)
