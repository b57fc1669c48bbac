"""Prints the worst errors of the NURBS core's invariants on random data (the figures the
foundation issue asks for). The tests assert the same bounds; this shows the numbers.

    .venv/bin/python scripts/measure_nurbs.py
"""
from __future__ import annotations

import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / "bench"))
from common import load_checkout  # noqa: E402

load_checkout()
from scipy.interpolate import BSpline, NdBSpline  # noqa: E402

from bladesmith.geometry.nurbs import (  # noqa: E402
    BSplineCurve,
    BSplineSurface,
    approximate,
    approximate_common,
    elevate_degree,
    insert_knot,
    interpolate,
    refine_knots,
    to_bezier_form,
)
from bladesmith.geometry.nurbs.operations import elevate_degree_surface, surface_to_bezier_form  # noqa: E402

rng = np.random.default_rng(2026)


def knots(n, p):
    gaps = rng.uniform(0.2, 1.0, n - p)
    return np.r_[np.zeros(p + 1), np.cumsum(gaps)[:-1] / gaps.sum(), np.ones(p + 1)]


def rel(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


worst = {}


def record(name, value):
    worst[name] = max(worst.get(name, 0.0), float(value))


for trial in range(40):
    p = 1 + trial % 5
    n = p + 1 + int(rng.integers(0, 12))
    U, P = knots(n, p), rng.normal(size=(n, 3))
    c, ref = BSplineCurve(p, U, P), BSpline(knots(n, p) * 0 + U, P, p)
    u = rng.uniform(0, 1, 3000)
    D = c.derivatives(u, 2)
    for k in range(min(p, 2) + 1):
        record(f"curve derivative {k} vs scipy BSpline", rel(D[:, k], ref(u, nu=k)))
    q = 1 + (trial // 5) % 5
    nu, nv = p + 1 + int(rng.integers(0, 6)), q + 1 + int(rng.integers(0, 6))
    Uu, Uv, N = knots(nu, p), knots(nv, q), rng.normal(size=(nu, nv, 3))
    s, sref = BSplineSurface(p, q, Uu, Uv, N), NdBSpline((Uu, Uv), N, (p, q))
    uv = rng.uniform(0, 1, (3000, 2))
    S = s.derivatives(uv[:, 0], uv[:, 1], 2)
    for kl in [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]:
        if kl[0] <= p and kl[1] <= q:
            record(f"surface derivative {kl} vs NdBSpline", rel(S[:, kl[0], kl[1]], sref(uv, nu=kl)))
    # geometry-preserving operations, rational
    w = rng.uniform(0.3, 3.0, n)
    cr = BSplineCurve(p, U, P, w)
    size = cr.size()
    x = rng.uniform(0.05, 0.95)
    for name, other in [
        ("insert_knot", insert_knot(cr, x, 1)),
        ("refine_knots", refine_knots(cr, np.sort(rng.uniform(0, 1, 6)))),
        ("to_bezier_form", to_bezier_form(cr)),
        ("elevate_degree x2", elevate_degree(cr, 2)),
    ]:
        record(f"{name} (curve, rational)", np.abs(other.evaluate(u) - cr.evaluate(u)).max() / size)
    sr = BSplineSurface(p, q, Uu, Uv, N, rng.uniform(0.3, 3.0, (nu, nv)))
    for name, other in [("surface_to_bezier_form", surface_to_bezier_form(sr)),
                        ("elevate_degree_surface u", elevate_degree_surface(sr, "u", 1))]:
        record(f"{name} (rational)", np.abs(other.evaluate(uv[:, 0], uv[:, 1]) - sr.evaluate(uv[:, 0], uv[:, 1])).max() / sr.size())
    # interpolation with end derivatives
    pts = np.cumsum(rng.normal(size=(12, 3)), axis=0)
    d0, d1 = rng.normal(size=3), rng.normal(size=3)
    it = interpolate(pts, 3, start_derivative=d0, end_derivative=d1)
    from bladesmith.geometry.nurbs.fitting import parameterize

    t = parameterize(pts)
    scale = np.abs(pts).max()
    record("interpolation through points", np.abs(it.evaluate(t) - pts).max() / scale)
    ends = it.derivatives(np.array([0.0, 1.0]), 1)[:, 1]
    record("interpolation end derivatives", np.abs(ends - [d0, d1]).max() / np.abs([d0, d1]).max())

# adaptive approximation: tolerance met by dense sampling, initial knots kept
tol = 1e-6
helix = lambda t: np.stack([np.cos(6 * t), np.sin(6 * t), 0.3 * t + 0.05 * np.sin(17 * t)], axis=-1)  # noqa: E731
initial = [0.25, 0.5, 0.75]
curve = approximate(helix, tol, initial_knots=initial)
dense = np.linspace(0, 1, 200001)
record("approximate: max deviation / tolerance", np.linalg.norm(curve.evaluate(dense) - helix(dense), axis=1).max() / tol)
kept = all(np.any(np.abs(curve.knots - k) == 0) for k in initial)

# 20 different curves, one knot vector
funcs = []
for i in range(20):
    a, b, c_ = rng.uniform(1, 6, 3)
    phase = rng.uniform(0, 6)
    funcs.append(lambda t, a=a, b=b, c_=c_, phase=phase: np.stack(
        [np.cos(a * t + phase), np.sin(b * t), 0.2 * np.sin(c_ * t) + t], axis=-1))
common = approximate_common(funcs, 1e-5)
same = all(np.array_equal(common[0].knots, c.knots) for c in common)
dev = max(np.linalg.norm(c.evaluate(dense[::10]) - f(dense[::10]), axis=1).max() for c, f in zip(common, funcs))

for name, value in worst.items():
    print(f"{name:55s} {value:.2e}")
print(f"{'approximate: initial knots kept':55s} {kept}")
print(f"{'20 curves: one knot vector':55s} {same} ({common[0].knots.size} knots), "
      f"worst deviation {dev:.2e} (tolerance 1e-5)")
