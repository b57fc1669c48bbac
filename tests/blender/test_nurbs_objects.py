"""Blender NURBS objects as exact views of the float64 model, and Blender's knot rules.

Measured here (printed with ``pytest -s``):
- display: every vertex of Blender's evaluated mesh against the float64 model, by
  closest-point distance, as a fraction of the control-net size;
- read-back: the model read from a Blender spline against Blender's own evaluated points,
  for every knot mode, orders 2-6, cyclic or not, with weights;
- storage: exact float64 data after saving and reopening the .blend file.
"""
import numpy as np
import pytest

import bpy

from bladesmith.geometry.errors import GeometryError
from bladesmith.geometry.nurbs import BSplineCurve, BSplineSurface
from bladesmith.geometry.nurbs.projection import closest_point_curve, closest_point_surface
from bladesmith.operators.nurbs_objects import (
    MAX_DEGREE,
    PROPERTY_KEY,
    blender_knots,
    curve_to_object,
    degree_from_order,
    object_to_geometry,
    order_from_degree,
    stored_geometry,
    surface_to_object,
)

#: Display exactness: vertex-to-model distance as a fraction of the control-net size.
DISPLAY_TOL = 1e-6
#: Read-back: Blender's float32 evaluation against ours, relative to the largest coordinate
#: (float32 epsilon is 1.2e-7; order-6 sums and float32 parameters lose a few bits more).
READBACK_TOL = 2e-6

KNOT_MODES = {  # name: (use_endpoint, use_bezier)
    "uniform": (False, False),
    "endpoint": (True, False),
    "bezier": (False, True),
    "endpoint_bezier": (True, True),
}


# -- helpers ----------------------------------------------------------------------------------
def evaluated_vertices(obj) -> np.ndarray:
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    mesh = evaluated.to_mesh()
    try:
        co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", co)
    finally:
        evaluated.to_mesh_clear()
    return co.reshape(-1, 3).astype(np.float64)


def random_knots(rng, n, p, domain=(0.0, 1.0)):
    """Clamped, strongly non-uniform knots."""
    a, b = domain
    inner = np.sort(rng.uniform(0.0, 1.0, n - p - 1) ** 2)
    return np.concatenate([np.full(p + 1, a), a + (b - a) * inner, np.full(p + 1, b)])


def random_surface(rng, degree_u, degree_v, nu, nv, rational):
    P = rng.normal(scale=0.3, size=(nu, nv, 3))
    P[..., 0] += np.arange(nu)[:, None]
    P[..., 1] += np.arange(nv)[None, :]
    P[..., 2] += np.sin(P[..., 0]) * np.cos(P[..., 1])
    W = rng.uniform(0.4, 2.5, (nu, nv)) if rational else None
    return BSplineSurface(degree_u, degree_v, random_knots(rng, nu, degree_u), random_knots(rng, nv, degree_v), P, W)


def random_curve(rng, degree, n, rational, dim=3):
    P = rng.normal(scale=0.5, size=(n, dim))
    P[:, 0] += np.arange(n)
    W = rng.uniform(0.4, 2.5, n) if rational else None
    return BSplineCurve(degree, random_knots(rng, n, degree), P, W)


def bezier_segment_parameters(knots, degree, blender_t, segments=None):
    """Our parameters of Blender parameters t of an endpoint+Bezier object: segment s is
    [s, s+1] in Blender and [k_s, k_s+1] (the distinct knots) in the model. A single
    linear segment that the writer split at its middle has ``segments=2``."""
    breaks = np.unique(knots[degree : len(knots) - degree])
    if segments is not None and segments != len(breaks) - 1:
        assert len(breaks) == 2
        breaks = np.linspace(breaks[0], breaks[1], segments + 1)
    s = np.clip(np.floor(blender_t).astype(int), 0, len(breaks) - 2)
    return breaks[s] + (blender_t - s) * (breaks[s + 1] - breaks[s])


def legacy_surface_parameters(knots, order, n_points, resolution, cyclic):
    """Blender's legacy surface samples (BKE_nurb_makeFaces): float32 start, step and sum."""
    k = knots.astype(np.float32)
    start = k[order - 1]
    end = k[n_points + order - 1] if cyclic else k[n_points]
    total = n_points * resolution
    step = np.float32((end - start) / np.float32(total if cyclic else total - 1))
    out = np.empty(total, dtype=np.float32)
    u = np.float32(start)
    for i in range(total):
        out[i] = u
        u = np.float32(u + step)
    return out.astype(np.float64)


def curve_parameters(knots, order, n_points, resolution, cyclic):
    """Blender's curve samples (bke::curves::nurbs::calculate_basis_cache, 4.5).

    Blender 5.0 puts ``resolution`` evenly spaced samples in each non-empty knot span of the
    domain, and the end point of an open curve; 4.5 spreads resolution * segments samples
    evenly over the whole domain.
    """
    if bpy.app.version >= (5, 0, 0):
        k = np.asarray(knots, dtype=np.float64)
        start = k[order - 1]
        end = k[n_points + order - 1] if cyclic else k[n_points]
        breaks = np.unique(k[(k >= start) & (k <= end)])
        spans = [a + (b - a) * np.arange(resolution) / resolution for a, b in zip(breaks[:-1], breaks[1:])]
        return np.concatenate(spans + ([] if cyclic else [[end]]))
    k = knots.astype(np.float32)
    count = resolution * (n_points if cyclic else n_points - 1)
    start = k[order - 1]
    end = k[n_points + order - 1] if cyclic else k[n_points]
    step = np.float32((end - start) / np.float32(count if cyclic else count - 1))
    t = start + step * np.arange(count, dtype=np.float32)
    return np.clip(t, start, end).astype(np.float64)


def blender_surface(name, nu, nv):
    """A raw Blender NURBS surface spline with nu x nv points (built through the writer from
    a bilinear surface, whose Bezier form is its own net; nv >= 3)."""
    grid = np.stack(np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij"), axis=-1)
    P = np.concatenate([grid, np.zeros((nu, nv, 1))], axis=-1).astype(float)
    flat = BSplineSurface(1, 1, random_knots(np.random.default_rng(0), nu, 1),
                          random_knots(np.random.default_rng(1), nv, 1), P)
    obj = surface_to_object(flat, name)
    del obj[PROPERTY_KEY]
    return obj


# -- conversions and knot rules -----------------------------------------------------------------
def test_order_and_degree_convert_in_one_place(addon):
    assert [order_from_degree(d) for d in range(1, MAX_DEGREE + 1)] == [2, 3, 4, 5, 6]
    assert [degree_from_order(o) for o in range(2, 7)] == [1, 2, 3, 4, 5]
    with pytest.raises(GeometryError, match="order is at most 6"):
        order_from_degree(6)
    with pytest.raises(GeometryError):
        degree_from_order(7)


@pytest.mark.parametrize(
    "n, order, endpoint, bezier, cyclic, expected",
    [
        (5, 4, False, False, False, [0, 1, 2, 3, 4, 5, 6, 7, 8]),
        (5, 4, True, False, False, [0, 0, 0, 0, 1, 2, 2, 2, 2]),
        (7, 4, False, True, False, [0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3]),
        (7, 4, True, True, False, [0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 2]),
        (7, 3, True, True, False, [0, 0, 0, 1, 1, 2, 2, 3, 3, 3]),
        (9, 5, True, True, False, [0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 2]),
    ],
)
def test_blender_knot_vectors(addon, n, order, endpoint, bezier, cyclic, expected):
    knots = blender_knots(n, order, endpoint=endpoint, bezier=bezier, cyclic=cyclic)
    np.testing.assert_array_equal(knots, expected)


# -- exact display ------------------------------------------------------------------------------------
@pytest.mark.parametrize("rational", [False, True], ids=["polynomial", "rational"])
@pytest.mark.parametrize("degrees, shape", [((3, 3), (8, 7)), ((3, 3), (5, 11)), ((2, 1), (6, 2)), ((4, 5), (7, 8))])
def test_surface_display_is_exact(scene, rational, degrees, shape):
    rng = np.random.default_rng(hash((rational, degrees, shape)) % 2**32)
    surface = random_surface(rng, *degrees, *shape, rational)
    obj = surface_to_object(surface, "blade", resolution=3)
    spline = obj.data.splines[0]
    assert (spline.order_u, spline.order_v) == (degrees[0] + 1, degrees[1] + 1)
    assert spline.use_endpoint_u and spline.use_endpoint_v and spline.use_bezier_u and spline.use_bezier_v
    V = evaluated_vertices(obj)
    assert len(V) == spline.point_count_u * spline.point_count_v * 9
    _, _, distance = closest_point_surface(surface, V)
    # second candidate, as for curves: Blender's own sample parameters mapped into the model
    (nu, ku, us), (nv, kv, vs) = (
        (n, k, legacy_surface_parameters(k, p + 1, n, 3, False))
        for n, p in ((spline.point_count_u, degrees[0]), (spline.point_count_v, degrees[1]))
        for k in [blender_knots(n, p + 1, endpoint=True, bezier=True, cyclic=False)]
    )
    mapped_u = bezier_segment_parameters(surface.knots_u, degrees[0], np.minimum(us, ku[-1]), (nu - 1) // degrees[0])
    mapped_v = bezier_segment_parameters(surface.knots_v, degrees[1], np.minimum(vs, kv[-1]), (nv - 1) // degrees[1])
    mapped = np.linalg.norm(surface.evaluate_grid(mapped_u, mapped_v).reshape(-1, 3) - V, axis=-1)
    worst = np.minimum(distance, mapped).max() / surface.size()
    print(f"\nsurface degrees {degrees} net {shape} rational={rational}: {len(V)} vertices, "
          f"max distance {worst:.2e} of net size (projection alone {distance.max() / surface.size():.2e})")
    assert worst <= DISPLAY_TOL


@pytest.mark.parametrize("rational", [False, True], ids=["polynomial", "rational"])
@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
@pytest.mark.parametrize("dim", [2, 3])
def test_curve_display_is_exact(scene, degree, rational, dim):
    rng = np.random.default_rng(100 * degree + 10 * dim + rational)
    curve = random_curve(rng, degree, degree + 6, rational, dim)
    obj = curve_to_object(curve, "section", resolution=6)
    V = evaluated_vertices(obj)
    if dim == 2:
        assert np.all(V[:, 2] == 0.0)
        V = V[:, :2]
    params, distance = closest_point_curve(curve, V)
    # The vertex at Blender's own parameter, mapped into the model's segment, is a second
    # candidate: the true closest distance is at most the smaller of the two.
    spline = obj.data.splines[0]
    knots = blender_knots(len(spline.points), degree + 1, endpoint=True, bezier=True, cyclic=False)
    t = curve_parameters(knots, degree + 1, len(spline.points), 6, False)
    mapped = np.linalg.norm(curve.evaluate(bezier_segment_parameters(curve.knots, degree, t)) - V, axis=-1)
    worst = np.minimum(distance, mapped).max() / curve.size()
    print(f"\ncurve degree {degree} dim {dim} rational={rational}: {len(V)} vertices, "
          f"max distance {worst:.2e} of net size (projection alone {distance.max() / curve.size():.2e})")
    assert worst <= DISPLAY_TOL


# -- Blender -> model ---------------------------------------------------------------------------------------
def _mode_cases():
    names = list(KNOT_MODES)
    for order in range(2, 7):
        for i, mode in enumerate(names):
            for cyclic in (False, True):
                yield order, mode, names[(i + order) % 4], cyclic


def _point_count(order, mode, cyclic, extra):
    endpoint, bezier = KNOT_MODES[mode]
    if bezier:
        return (order - 1) * (2 + extra) + (0 if cyclic else 1)
    return order + 1 + extra


@pytest.mark.parametrize("order, mode_u, mode_v, cyclic", list(_mode_cases()))
def test_surface_read_back_matches_blender(scene, order, mode_u, mode_v, cyclic):
    rng = np.random.default_rng(order * 97 + len(mode_u) * 7 + cyclic)
    order_v = 2 + (order + len(mode_v)) % 5
    nu = _point_count(order, mode_u, cyclic, extra=1)
    # at least 3 (rows of two are the writer's special case); order 2 takes any count
    nv = max(_point_count(order_v, mode_v, not cyclic, extra=0), 3)
    obj = blender_surface("raw", nu, nv)
    spline = obj.data.splines[0]
    co = rng.normal(size=(nv, nu, 4))
    co[..., 0] += np.arange(nu)[None, :]
    co[..., 1] += np.arange(nv)[:, None]
    co[..., 3] = rng.uniform(0.4, 2.5, (nv, nu))
    spline.points.foreach_set("co", co.astype(np.float32).ravel())
    spline.order_u, spline.order_v = order, order_v
    spline.use_endpoint_u, spline.use_bezier_u = KNOT_MODES[mode_u]
    spline.use_endpoint_v, spline.use_bezier_v = KNOT_MODES[mode_v]
    spline.use_cyclic_u, spline.use_cyclic_v = cyclic, not cyclic
    spline.resolution_u, spline.resolution_v = 3, 2
    V = evaluated_vertices(obj)
    (surface,) = object_to_geometry(obj)
    assert surface.degree_u == order - 1 and surface.degree_v == order_v - 1
    assert surface.is_rational
    ku = blender_knots(nu, order, endpoint=KNOT_MODES[mode_u][0], bezier=KNOT_MODES[mode_u][1], cyclic=cyclic)
    kv = blender_knots(nv, order_v, endpoint=KNOT_MODES[mode_v][0], bezier=KNOT_MODES[mode_v][1], cyclic=not cyclic)
    us = legacy_surface_parameters(ku, order, nu, 3, cyclic)
    vs = legacy_surface_parameters(kv, order_v, nv, 2, not cyclic)
    V = V.reshape(len(us), len(vs), 3)
    # Blender accumulates its parameter step in float32 and may step a few ulps past the end
    # of an unclamped domain, into the span beyond it: those samples are not on the surface.
    # (Blender clamps to its last knot, so on clamped ends the overshoot is harmless.)
    end_u, end_v = surface.domain_u[1], surface.domain_v[1]
    keep_u = (us <= end_u) | (ku[-1] == end_u)
    keep_v = (vs <= end_v) | (kv[-1] == end_v)
    ours = surface.evaluate_grid(np.minimum(us[keep_u], end_u), np.minimum(vs[keep_v], end_v))
    error = np.abs(ours - V[keep_u][:, keep_v]).max() / np.abs(co[..., :3]).max()
    print(f"\nsurface order ({order}, {order_v}) u {mode_u} v {mode_v} cyclic u={cyclic} v={not cyclic}: "
          f"read-back error {error:.2e} (dropped {np.sum(~keep_u)} + {np.sum(~keep_v)} overshooting rows)")
    assert error <= READBACK_TOL


@pytest.mark.parametrize("order, mode, other_mode, cyclic", list(_mode_cases()))
def test_curve_read_back_matches_blender(scene, order, mode, other_mode, cyclic):
    rng = np.random.default_rng(order * 31 + len(mode) + cyclic)
    endpoint, bezier = KNOT_MODES[mode]
    n = _point_count(order, mode, cyclic, extra=1)
    data = bpy.data.curves.new("raw", "CURVE")
    data.dimensions = "3D"
    obj = bpy.data.objects.new("raw", data)
    scene.collection.objects.link(obj)
    spline = data.splines.new("NURBS")
    spline.points.add(n - 1)
    co = rng.normal(size=(n, 4))
    co[:, 0] += np.arange(n)
    co[:, 3] = rng.uniform(0.4, 2.5, n)
    spline.points.foreach_set("co", co.astype(np.float32).ravel())
    spline.order_u = order
    spline.use_endpoint_u, spline.use_bezier_u, spline.use_cyclic_u = endpoint, bezier, cyclic
    spline.resolution_u = 5
    V = evaluated_vertices(obj)
    (curve,) = object_to_geometry(obj)
    assert curve.degree == order - 1 and curve.is_rational
    knots = blender_knots(n, order, endpoint=endpoint, bezier=bezier, cyclic=cyclic)
    t = curve_parameters(knots, order, n, 5, cyclic)
    error = np.abs(curve.evaluate(t) - V).max() / np.abs(co[:, :3]).max()
    print(f"\ncurve order {order} {mode} cyclic={cyclic}: read-back error {error:.2e}")
    assert error <= READBACK_TOL


def test_poly_and_bezier_splines_read_back(scene):
    data = bpy.data.curves.new("mixed", "CURVE")
    data.dimensions = "3D"
    obj = bpy.data.objects.new("mixed", data)
    scene.collection.objects.link(obj)
    rng = np.random.default_rng(7)
    poly = data.splines.new("POLY")
    poly.points.add(4)
    poly.points.foreach_set("co", np.c_[rng.normal(size=(5, 3)), np.ones(5)].astype(np.float32).ravel())
    bez = data.splines.new("BEZIER")
    bez.bezier_points.add(3)
    for attribute in ("co", "handle_left", "handle_right"):
        bez.bezier_points.foreach_set(attribute, rng.normal(size=12).astype(np.float32))
    bez.use_cyclic_u = True
    bez.resolution_u = 8
    curves = object_to_geometry(obj)
    assert [c.degree for c in curves] == [1, 3]
    assert curves[1].n_control == 13  # four cubic segments, closed
    V = evaluated_vertices(obj)
    d_poly = closest_point_curve(curves[0], V)[1]
    d_bez = closest_point_curve(curves[1], V)[1]
    worst = np.minimum(d_poly, d_bez).max() / max(curves[0].size(), curves[1].size())
    print(f"\npoly + cyclic Bezier spline: max distance {worst:.2e}")
    assert worst <= DISPLAY_TOL


def test_invalid_blender_spline_is_refused(scene):
    data = bpy.data.curves.new("raw", "CURVE")
    obj = bpy.data.objects.new("raw", data)
    scene.collection.objects.link(obj)
    spline = data.splines.new("NURBS")
    spline.points.add(3)
    spline.order_u = 4
    spline.use_bezier_u, spline.use_endpoint_u = True, False  # Blender shows only the polygon
    with pytest.raises(GeometryError, match="Blender shows nothing"):
        object_to_geometry(obj)


# -- stored exact data ------------------------------------------------------------------------------------
def test_stored_data_survives_save_and_reopen(scene, tmp_path):
    rng = np.random.default_rng(11)
    surface = random_surface(rng, 3, 3, 9, 6, rational=True)
    curve = random_curve(rng, 2, 7, rational=False, dim=2)
    surface_to_object(surface, "blade")
    curve_to_object(curve, "section")
    path = tmp_path / "stored.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))

    (back,) = object_to_geometry(bpy.data.objects["blade"])
    assert (back.degree_u, back.degree_v) == (3, 3)
    for name in ("knots_u", "knots_v", "control_points", "weights"):
        assert np.array_equal(getattr(back, name), getattr(surface, name)), name
    (back_curve,) = object_to_geometry(bpy.data.objects["section"])
    assert back_curve.degree == 2 and back_curve.dim == 2 and back_curve.weights is None
    assert np.array_equal(back_curve.knots, curve.knots)
    assert np.array_equal(back_curve.control_points, curve.control_points)

    # a hand edit: the stored data no longer describes what Blender shows
    obj = bpy.data.objects["blade"]
    point = obj.data.splines[0].points[5]
    point.co[2] += 0.25
    assert stored_geometry(obj) is None
    (edited,) = object_to_geometry(obj)
    assert edited.shape == (obj.data.splines[0].point_count_u, obj.data.splines[0].point_count_v)
    assert edited.control_points[5, 0, 2] == np.float32(point.co[2])
    # the edited Blender data is still read exactly: away from the edit it is the same shape
    _, _, distance = closest_point_surface(surface, edited.evaluate_grid([0.0, 4.0], [0.0, 1.0, 3.0]))
    assert distance.max() <= DISPLAY_TOL * surface.size()


# -- failures and side effects ----------------------------------------------------------------------------
def test_degree_above_five_is_refused_and_leaves_nothing(scene):
    rng = np.random.default_rng(3)
    before = (len(bpy.data.objects), len(bpy.data.curves))
    with pytest.raises(GeometryError, match="degree 6"):
        surface_to_object(random_surface(rng, 6, 3, 8, 5, False), "too high")
    with pytest.raises(GeometryError, match="degree 6"):
        curve_to_object(random_curve(rng, 6, 8, False), "too high")
    with pytest.raises(GeometryError, match="dimension 4"):
        curve_to_object(random_curve(rng, 3, 6, False, dim=4), "4-D")
    assert (len(bpy.data.objects), len(bpy.data.curves)) == before


def test_active_object_selection_and_mode_are_restored(scene):
    bpy.ops.mesh.primitive_cube_add()
    cube = bpy.context.active_object
    bpy.ops.object.mode_set(mode="EDIT")
    collection = bpy.data.collections.new("blades")
    scene.collection.children.link(collection)
    obj = surface_to_object(random_surface(np.random.default_rng(5), 3, 2, 6, 5, False), "blade", collection)
    assert bpy.context.view_layer.objects.active == cube
    assert cube.mode == "EDIT" and cube.select_get()
    assert not obj.select_get()
    assert obj.users_collection == (collection,)
