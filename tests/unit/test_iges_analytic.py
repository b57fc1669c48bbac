"""The analytic surfaces 190-198 (iges/analytic.py): closed-form inverse and exact NURBS."""
from __future__ import annotations

import math

import numpy as np
import pytest

from bladesmith.iges.analytic import AnalyticSurface, analytic_nurbs, analytic_points, analytic_uv, unwrap_loop

RNG = np.random.default_rng(17)


def _surface(t: int) -> AnalyticSurface:
    A = RNG.normal(size=3)
    A /= np.linalg.norm(A)
    X = np.cross(A, RNG.normal(size=3))
    X /= np.linalg.norm(X)
    return AnalyticSurface(surface_type=t, surface_form=1, location=RNG.normal(size=3), axis=A, reference=X,
                           radius=2.0, minor_radius=0.5 if t == 198 else 0.0,
                           semi_angle=math.radians(20.0) if t == 194 else 0.0)


PATCHES = {190: ((-1.0, 2.0), (0.5, 3.0)), 192: ((-2.5, 2.9), (-1.0, 1.5)), 194: ((0.3, 5.9), (-1.0, 2.0)),
           196: ((-3.0, 1.0), (-1.2, 1.4)), 198: ((1.0, 4.0), (-2.0, 2.5))}


@pytest.mark.parametrize("t", sorted(PATCHES))
def test_exact_nurbs_lies_on_the_surface_and_spans_the_patch(t):
    s = _surface(t)
    (u0, u1), (v0, v1) = PATCHES[t]
    n = analytic_nurbs(s, (u0, u1), (v0, v1))
    (a, b), (c, d) = n.domain_u, n.domain_v
    U, V = np.meshgrid(np.linspace(a, b, 41), np.linspace(c, d, 37), indexing="ij")
    P = n.evaluate(U, V).reshape(-1, 3)
    uv = analytic_uv(s, P)
    back = analytic_points(s, uv[:, 0], uv[:, 1])
    assert np.abs(back - P).max() <= 1e-12 * 10  # every NURBS point is on the analytic surface
    # the corners and the edges' ends are the patch's own
    for (x, y), (p, q) in zip(((a, c), (b, c), (a, d), (b, d)), ((u0, v0), (u1, v0), (u0, v1), (u1, v1))):
        assert np.abs(n.evaluate(np.array(x), np.array(y)) - analytic_points(s, p, q)).max() <= 1e-12 * 10
    # the patch is covered: its parameter box in (u, v) is the NURBS's image
    got = uv if t == 190 else np.c_[np.unwrap(uv[:, 0].reshape(U.shape), axis=0).ravel(), uv[:, 1]]
    if t != 190:
        got[:, 0] += 2 * math.pi * np.round((u0 - got[0, 0]) / (2 * math.pi))
    assert np.allclose(got.min(axis=0), [u0, v0], atol=1e-9) and np.allclose(got.max(axis=0), [u1, v1], atol=1e-9)


@pytest.mark.parametrize("t", sorted(PATCHES))
def test_inverse_recovers_points(t):
    s = _surface(t)
    (u0, u1), (v0, v1) = PATCHES[t]
    u, v = RNG.uniform(u0, u1, 200), RNG.uniform(v0, v1, 200)
    P = analytic_points(s, u, v)
    uv = analytic_uv(s, P)
    assert np.abs(analytic_points(s, uv[:, 0], uv[:, 1]) - P).max() <= 1e-12 * 10


def test_a_loop_over_the_pole_keeps_its_area():
    # hemisphere: equator 0 -> 2 pi, seam up, over the pole (a vertex edge stepping u by
    # -360 degrees, as OCC writes it), seam down
    s = _surface(196)
    t = np.linspace(0, 2 * math.pi, 50)
    lat = np.linspace(0, 0.5 * math.pi, 20)
    edges = [analytic_points(s, t, 0 * t), analytic_points(s, 0 * lat, lat), analytic_points(s, 0 * lat, lat[::-1])]
    uv = [analytic_uv(s, e) for e in edges]
    loop = unwrap_loop(s, uv, {2: -360.0})
    x, y = loop[:, 0], loop[:, 1]
    area = abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))) / 2
    assert math.isclose(area, math.pi ** 2, rel_tol=1e-9)  # [0, 2 pi] x [0, pi / 2]
    # without the pole crossing the two seams coincide and the loop has no area
    flat = unwrap_loop(s, uv, {})
    x, y = flat[:, 0], flat[:, 1]
    assert abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))) / 2 < 1e-9


def test_trimmed_cylinder_face_from_model_space_loop(tmp_path):
    import importlib.util
    import pathlib

    from bladesmith.iges.importer import import_path

    spec = importlib.util.spec_from_file_location("import_cases", pathlib.Path(__file__).with_name("import_cases.py"))
    C = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(C)
    text, area = C.cylinder_face()
    path = tmp_path / "cyl.igs"
    path.write_text(text)
    report = import_path(path)
    assert report.counts == {"mesh": 1} and not report.skipped, (report.counts, report.skipped_summary())
    m = report.items[0].mesh
    V, T = m.vertices, m.triangles
    got = 0.5 * np.linalg.norm(np.cross(V[T[:, 1]] - V[T[:, 0]], V[T[:, 2]] - V[T[:, 0]]), axis=1).sum()
    assert abs(got - area) <= 2e-3 * area, (got, area)
    # on the cylinder of radius 2 about the transformed axis
    R, t = C.rot([1.0, 2.0, 2.0], 0.6), np.array([1.0, -2.0, 0.5])
    local = (V - t) @ R  # back to the cylinder's frame
    assert np.abs(np.hypot(local[:, 0], local[:, 1]) - 2.0).max() <= 1e-9
