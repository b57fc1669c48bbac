"""Blender NURBS objects as views of the float64 model, and back.

Writing (model -> Blender)
--------------------------
:func:`surface_to_object` and :func:`curve_to_object` show a float64 B-spline exactly.
Blender's legacy NURBS have no custom knot vectors, so the model is first decomposed into
Bezier pieces (knot insertion until every interior knot has multiplicity p; Piegl & Tiller,
The NURBS Book 2e, §5.3 and Alg. A5.6) and then written with ``use_endpoint`` and
``use_bezier`` on and order = degree + 1. Blender's knot vector for that mode (below) is
then 0^(p+1), 1^p, 2^p, ..., m^(p+1): a Bezier segment per unit interval. A Bezier segment's
shape does not depend on its parameter interval (only its parametrisation does, by an affine
change), so the Blender object has exactly the shape of the model, up to float32 rounding
of the control points. Rows of a surface net are joined into one surface spline with
``bpy.ops.curve.make_segment`` in edit mode (the RNA ``point_count_v`` is read-only and
``splines.new`` only makes single rows); this works in background mode. ``make_segment``
refuses rows of two points, which only occur for a single linear segment in v; such a net
gets the homogeneous midpoint column inserted first (exact knot insertion, NURBS Book
Eq. 5.15), which leaves the surface unchanged.

Both functions keep the exact float64 data on the object as the custom property
``bladesmith_nurbs`` (a group: ``version``, ``kind`` "curve"/"surface", ``degree`` or
``degree_u``/``degree_v``, ``knots`` or ``knots_u``/``knots_v``, ``shape``, flat
``control_points`` and optional ``weights`` as double arrays, ``fingerprint``) together with a SHA-256 fingerprint of what Blender holds (spline
types, counts, orders, knot flags and the float32 control points). :func:`stored_geometry`
returns the stored data only while the fingerprint still matches, so export after reopening
a .blend file is exact, and a hand-edited object is read from its Blender data instead.

Reading (Blender -> model)
--------------------------
:func:`object_to_geometry` reads every spline of a CURVE or SURFACE object: NURBS splines
in any knot mode (uniform, endpoint, Bezier, endpoint + Bezier), cyclic or not, orders
2-6, rational or not; POLY splines (degree 1) and BEZIER splines (cubic, handles as inner
control points) of curve objects. Results are in object-local coordinates.

Blender's knot vectors (Blender 4.5 LTS; ``calcknots`` in blenkernel/intern/curve.cc for
legacy surfaces, ``bke::curves::nurbs::calculate_knots`` for curve objects, which are
evaluated through the new curves code; both compute the same vector). With n points,
order k = p + 1, the vector has n + k knots, or n + 2k - 1 when cyclic, built as:

- ``repeat`` = k - 1 for Bezier mode, else 1: how often each inner knot value is repeated.
- ``head`` = number of leading zeros: k (k - 1 when cyclic) with endpoint; min(2, k - 1)
  for Bezier without endpoint; 1 otherwise.
- ``tail`` = 2k - 1 when cyclic, k with endpoint, else 0: the last ``tail`` knots are
  ``current + (knots[i] - knots[0])``, i.e. a copy of the head's spacing.
- With endpoint and cyclic, the first knot is 0 and counting starts at 1.
- In between, the values 0, 1, 2, ... are written, the first one ``head`` times and every
  later one ``repeat`` times.

  uniform, n=5, k=4:          0 1 2 3 4 5 6 7 8
  endpoint, n=5, k=4:         0 0 0 0 1 2 2 2 2
  Bezier, n=7, k=4:           0 0 1 1 1 2 2 2 3 3 3
  endpoint+Bezier, n=7, k=4:  0 0 0 0 1 1 1 2 2 2 2

Cyclic splines use the n points followed by the first k - 1 again. The evaluated domain
is [knots[k - 1], knots[n]] (knots[n + k - 1] when cyclic). Control points whose basis
function vanishes on that domain (the outer "handles" of Bezier mode without endpoint, and
surplus points in Bezier mode when (n - 1) is not a multiple of p) are dropped on reading,
with their knots; the result is the same curve with every control point active. Blender
displays nothing (surfaces) or only the control polygon (curves) when n < k, when Bezier
mode without endpoint has n <= k, or when cyclic Bezier mode has n not a multiple of k - 1;
such splines raise :class:`GeometryError`.

Rational convention (checked against evaluated geometry): ``SplinePoint.co`` is
(x, y, z, w) with x, y, z the Euclidean point, not pre-multiplied by w; the weight is
``co[3]`` (which ``SplinePoint.weight`` aliases). Evaluation is sum(N w P) / sum(N w)
(NURBS Book Eq. 4.2). Legacy surfaces are evaluated as rational only when some w != 1.

Orders 5 and 6 (degrees 4 and 5): Blender 4.5 builds Bezier-mode knots for every order
(inner multiplicity k - 1; the 2.x limit to orders 3 and 4 is gone), and the evaluated
points of order-5 and -6 Bezier-mode curves and surfaces agree with the exact float64
evaluation to float32 precision, so degrees up to 5 are shown exactly. Blender's maximum
order is 6; degree 6 and above raise :class:`GeometryError` (no approximation is made).

Evaluated points, for tests: legacy surfaces sample ``resolution * n`` parameters per
direction, uniformly over the whole domain (accumulating the step in float32, which can
step a few ulps past the end of an unclamped domain); curves sample
``resolution * (n - 1)`` (``resolution * n`` cyclic) parameters uniformly over the domain.
"""
from __future__ import annotations

import hashlib
from contextlib import contextmanager

import bpy
import numpy as np

from ..geometry.errors import GeometryError
from ..geometry.nurbs import BSplineCurve, BSplineSurface

#: Blender's largest NURBS order (``order_u``/``order_v`` are clamped to 2..6).
MAX_BLENDER_ORDER = 6
MIN_BLENDER_ORDER = 2
#: The largest degree shown exactly: Blender's maximum order minus one.
MAX_DEGREE = MAX_BLENDER_ORDER - 1

#: Custom property holding the exact float64 model on generated objects.
PROPERTY_KEY = "bladesmith_nurbs"
#: Layout version of :data:`PROPERTY_KEY`; bump when the stored layout changes.
STORAGE_VERSION = 1

#: Default evaluated points per control point and direction of generated surfaces
#: (Blender samples ``resolution * point_count`` parameters per direction).
DEFAULT_SURFACE_RESOLUTION = 4
#: Default evaluated points per control-point interval of generated curves.
DEFAULT_CURVE_RESOLUTION = 8

#: Blender stores three (curves) or four (points with weight) float32 coordinates.
_BLENDER_DIM = 3


# -- degree and order: the one place they are converted ---------------------------------
def order_from_degree(degree: int) -> int:
    """Blender's ``order`` for a polynomial degree (order = degree + 1).

    Raises :class:`GeometryError` for degrees Blender cannot show (above
    :data:`MAX_DEGREE`).
    """
    degree = int(degree)
    if degree < 1:
        raise GeometryError(f"degree must be >= 1, got {degree}")
    if degree > MAX_DEGREE:
        raise GeometryError(
            f"degree {degree} cannot be shown in Blender: its NURBS order is at most "
            f"{MAX_BLENDER_ORDER} (degree {MAX_DEGREE})"
        )
    return degree + 1


def degree_from_order(order: int) -> int:
    """Polynomial degree of a Blender NURBS ``order`` (degree = order - 1)."""
    order = int(order)
    if not MIN_BLENDER_ORDER <= order <= MAX_BLENDER_ORDER:
        raise GeometryError(f"Blender NURBS order must be {MIN_BLENDER_ORDER}..{MAX_BLENDER_ORDER}, got {order}")
    return order - 1


# -- Blender's knot vectors -------------------------------------------------------------
def blender_knots(n_points: int, order: int, *, endpoint: bool, bezier: bool, cyclic: bool) -> np.ndarray:
    """The knot vector Blender 4.5 uses for a NURBS direction (rules in the module docstring).

    Returns n + order knots, or n + 2 order - 1 for cyclic directions (whose control
    points are the n points followed by the first order - 1 again).
    """
    repeat = order - 1 if bezier else 1
    if endpoint:
        head = order - 1 if cyclic else order
    else:
        head = min(2, repeat) if bezier else 1
    tail = 2 * order - 1 if cyclic else (order if endpoint else 0)
    count = n_points + order + (order - 1 if cyclic else 0)
    knots = np.zeros(count)
    current = 0.0
    start = 0
    if endpoint and cyclic:
        start, current = 1, 1.0
    left = head
    for i in range(start, count - tail):
        knots[i] = current
        left -= 1
        if left == 0:
            current += 1.0
            left = repeat
    # one at a time, as Blender does: with few points the copied head overlaps the tail
    for i in range(tail):
        knots[count - tail + i] = current + (knots[i] - knots[0])
    return knots


def _check_blender_displays(n_points: int, order: int, bezier: bool, endpoint: bool, cyclic: bool, what: str):
    """Blender's own validity rules (``check_valid_eval_params``); it shows nothing otherwise."""
    if n_points < order:
        raise GeometryError(f"{what}: {n_points} points are fewer than the order {order}; Blender shows nothing")
    if bezier and not endpoint and n_points <= order:
        raise GeometryError(
            f"{what}: Bezier knot mode needs more than {order} points for order {order}, got {n_points}; "
            "Blender shows nothing"
        )
    if bezier and cyclic and n_points % (order - 1):
        raise GeometryError(
            f"{what}: cyclic Bezier knot mode needs a multiple of {order - 1} points, got {n_points}; "
            "Blender shows nothing"
        )


def _direction(n_points: int, order: int, endpoint: bool, bezier: bool, cyclic: bool, what: str):
    """Knots and control-point indices of one parametric direction of a Blender spline.

    Cyclic directions wrap the first order - 1 points; control points with no influence on
    the domain are dropped with their knots (see the module docstring).
    """
    _check_blender_displays(n_points, order, bezier, endpoint, cyclic, what)
    degree = degree_from_order(order)
    knots = blender_knots(n_points, order, endpoint=endpoint, bezier=bezier, cyclic=cyclic)
    index = np.arange(n_points)
    if cyclic:
        index = np.concatenate([index, index[: order - 1]])
    n = index.size
    a, b = knots[degree], knots[n]
    lo, hi = 0, n
    # N_i,p is zero on [a, b] when its support [U_i, U_{i+p+1}] touches it at most at an end
    while lo < hi and knots[lo + degree + 1] <= a:
        lo += 1
    while hi > lo and knots[hi - 1] >= b:
        hi -= 1
    if hi - lo < order:
        raise GeometryError(f"{what}: fewer than {order} control points act on the domain")
    return degree, knots[lo : hi + degree + 1], index[lo:hi]


# -- fingerprint and stored exact data --------------------------------------------------
def _float32_array(collection, attribute: str, width: int) -> np.ndarray:
    values = np.empty(len(collection) * width, dtype=np.float32)
    collection.foreach_get(attribute, values)
    return values


def blender_fingerprint(obj) -> str:
    """SHA-256 of what decides the shape Blender shows for a curve or surface object:
    spline types, point counts, orders, knot flags and the float32 coordinates."""
    data = obj.data
    digest = hashlib.sha256()
    digest.update(f"{obj.type}|{len(data.splines)}".encode())
    for spline in data.splines:
        header = (
            spline.type, spline.point_count_u, spline.point_count_v, spline.order_u, spline.order_v,
            spline.use_endpoint_u, spline.use_endpoint_v, spline.use_bezier_u, spline.use_bezier_v,
            spline.use_cyclic_u, spline.use_cyclic_v,
        )
        digest.update(repr(header).encode())
        if spline.type == "BEZIER":
            for attribute in ("co", "handle_left", "handle_right"):
                digest.update(_float32_array(spline.bezier_points, attribute, 3).tobytes())
        else:
            digest.update(_float32_array(spline.points, "co", 4).tobytes())
    return digest.hexdigest()


def _floats(values: np.ndarray) -> list[float]:
    """A float64 array as a Python list: Blender keeps it as a double ID-property array."""
    return [float(x) for x in np.ravel(values)]


def _store(obj, entity) -> None:
    if isinstance(entity, BSplineSurface):
        record = {
            "kind": "surface",
            "degree_u": entity.degree_u,
            "degree_v": entity.degree_v,
            "knots_u": _floats(entity.knots_u),
            "knots_v": _floats(entity.knots_v),
        }
    else:
        record = {"kind": "curve", "degree": entity.degree, "knots": _floats(entity.knots)}
    record["version"] = STORAGE_VERSION
    record["shape"] = [int(s) for s in entity.control_points.shape]
    record["control_points"] = _floats(entity.control_points)
    if entity.weights is not None:
        record["weights"] = _floats(entity.weights)
    record["fingerprint"] = blender_fingerprint(obj)
    obj[PROPERTY_KEY] = record


def _array(record, key: str) -> np.ndarray:
    return np.array(record[key].to_list() if hasattr(record[key], "to_list") else record[key], dtype=np.float64)


def stored_geometry(obj) -> list[BSplineCurve | BSplineSurface] | None:
    """The exact float64 model stored on ``obj`` by :func:`surface_to_object` or
    :func:`curve_to_object`, or None when there is none, it is of an unknown layout, or the
    Blender data no longer matches its fingerprint (the object was edited by hand)."""
    record = obj.get(PROPERTY_KEY) if obj is not None else None
    if record is None or obj.type not in {"CURVE", "SURFACE"}:
        return None
    try:
        if int(record["version"]) != STORAGE_VERSION:
            return None
        if str(record["fingerprint"]) != blender_fingerprint(obj):
            return None
        shape = tuple(int(s) for s in record["shape"])
        points = _array(record, "control_points").reshape(shape)
        weights = _array(record, "weights").reshape(shape[:-1]) if "weights" in record else None
        if record["kind"] == "surface":
            entity = BSplineSurface(
                int(record["degree_u"]), int(record["degree_v"]),
                _array(record, "knots_u"), _array(record, "knots_v"), points, weights,
            )
        elif record["kind"] == "curve":
            entity = BSplineCurve(int(record["degree"]), _array(record, "knots"), points, weights)
        else:
            return None
    except (KeyError, TypeError, ValueError):
        # a damaged or foreign property: the Blender data is the only truth left
        return None
    return [entity]


# -- model -> Blender ---------------------------------------------------------------------
def _homogeneous_3d(points: np.ndarray, weights: np.ndarray | None, what: str) -> np.ndarray:
    """(..., 4) rows (x, y, z, w) with Euclidean x, y, z (Blender's convention); 2-D at z = 0."""
    dim = points.shape[-1]
    if dim > _BLENDER_DIM:
        raise GeometryError(f"{what}: Blender shows 2-D or 3-D geometry, got dimension {dim}")
    out = np.zeros(points.shape[:-1] + (4,))
    out[..., :dim] = points
    out[..., 3] = 1.0 if weights is None else weights
    return out


def _bezier_operations():
    # imported late: operations.py is written alongside this module
    from ..geometry.nurbs import operations

    return operations


def _new_curve_data(name: str, kind: str):
    data = bpy.data.curves.new(name, type=kind)
    data.dimensions = "3D"
    return data


def _link(obj, collection) -> None:
    target = collection if collection is not None else bpy.context.scene.collection
    target.objects.link(obj)


def write_curve(obj, curve: BSplineCurve, resolution: int = DEFAULT_CURVE_RESOLUTION) -> None:
    """Show ``curve`` exactly in the CURVE object ``obj`` (Bezier form, endpoint + Bezier
    knot mode), reusing its curve data: only the points change while the Bezier form keeps
    its size. 2-D curves are placed at z = 0. Stores the exact float64 curve on ``obj``
    (:func:`stored_geometry`). Raises :class:`GeometryError` for degrees above
    :data:`MAX_DEGREE` or dimensions above 3."""
    order = order_from_degree(curve.degree)
    bezier = _bezier_operations().to_bezier_form(curve)
    rows = _homogeneous_3d(bezier.control_points, bezier.weights, obj.name)
    splines = obj.data.splines
    if not (len(splines) == 1 and splines[0].type == "NURBS" and len(splines[0].points) == len(rows)):
        splines.clear()
        spline = splines.new("NURBS")
        spline.points.add(len(rows) - 1)
        spline.use_endpoint_u = spline.use_bezier_u = True
        spline.use_cyclic_u = False
    spline = splines[0]
    spline.points.foreach_set("co", rows.astype(np.float32).ravel())
    if spline.order_u != order:
        spline.order_u = order
        if spline.order_u != order:
            raise GeometryError(f"{obj.name}: Blender set order {spline.order_u} instead of {order}")
    if spline.resolution_u != int(resolution):
        spline.resolution_u = int(resolution)
    obj.data.update_tag()
    _store(obj, curve)


def remove_object(obj) -> None:
    """Delete ``obj``, and its curve or mesh data when nothing else uses it."""
    data = obj.data
    bpy.data.objects.remove(obj, do_unlink=True)
    if data is not None and data.users == 0:
        if isinstance(data, bpy.types.Mesh):
            bpy.data.meshes.remove(data)
        elif isinstance(data, bpy.types.Curve):
            bpy.data.curves.remove(data)


def _new_object(name: str, kind: str, write, collection):
    """A new object of curve ``kind`` filled by ``write(obj)`` and linked to ``collection``;
    nothing is left behind when that fails."""
    obj = bpy.data.objects.new(name, _new_curve_data(name, kind))
    try:
        write(obj)
        _link(obj, collection)
    except BaseException:
        remove_object(obj)
        raise
    return obj


def curve_to_object(curve: BSplineCurve, name: str, collection=None, resolution: int = DEFAULT_CURVE_RESOLUTION):
    """A new CURVE object showing ``curve`` exactly (:func:`write_curve`), linked to
    ``collection`` (the scene collection by default)."""
    order_from_degree(curve.degree)
    return _new_object(name, "CURVE", lambda obj: write_curve(obj, curve, resolution), collection)


def _resolution_pair(resolution) -> tuple[int, int]:
    if np.ndim(resolution) == 0:
        return int(resolution), int(resolution)
    ru, rv = resolution
    return int(ru), int(rv)


@contextmanager
def _editing(obj):
    """Edit mode on ``obj`` alone; afterwards the previous mode, active object and
    selection are restored. Works without a window (background mode)."""
    context = bpy.context
    view_layer = context.view_layer
    scene_objects = context.scene.collection.objects
    previous_active = view_layer.objects.active
    previous_mode = previous_active.mode if previous_active is not None else "OBJECT"
    if previous_mode != "OBJECT":
        bpy.ops.object.mode_set(mode="OBJECT")
    previous_selected = [o for o in view_layer.objects if o.select_get()]
    temporary_link = obj.name not in view_layer.objects
    if temporary_link:
        scene_objects.link(obj)
    for other in previous_selected:
        other.select_set(False)
    view_layer.objects.active = obj
    obj.select_set(True)
    try:
        bpy.ops.object.mode_set(mode="EDIT")
        yield
    finally:
        if obj.mode != "OBJECT":
            bpy.ops.object.mode_set(mode="OBJECT")
        obj.select_set(False)
        if temporary_link:
            scene_objects.unlink(obj)
        for other in previous_selected:
            if other.name in view_layer.objects:
                other.select_set(True)
        view_layer.objects.active = previous_active
        if previous_mode != "OBJECT" and previous_active is not None:
            try:
                bpy.ops.object.mode_set(mode=previous_mode)
            except RuntimeError:
                pass  # the previous mode may not be available from here; object mode is safe


def _midpoint_column(homogeneous: np.ndarray) -> np.ndarray:
    """Insert the knot at the middle of a single linear v segment: (nu, 2, 4) -> (nu, 3, 4).

    Done in homogeneous space (NURBS Book Eq. 5.15 with p = 1), so the surface is unchanged.
    """
    Pw = homogeneous.copy()
    Pw[..., :3] *= Pw[..., 3:]
    mid = 0.5 * (Pw[:, 0] + Pw[:, 1])
    Pw = np.stack([Pw[:, 0], mid, Pw[:, 1]], axis=1)
    Pw[..., :3] /= Pw[..., 3:]
    return Pw


def _shows(obj, surface: BSplineSurface, resolution: tuple[int, int]) -> bool:
    """Whether ``obj`` already shows exactly ``surface``, unedited and at this resolution."""
    stored = stored_geometry(obj)
    if not stored or not isinstance(stored[0], BSplineSurface):
        return False
    old = stored[0]
    spline = obj.data.splines[0]
    same_weights = (old.weights is None and surface.weights is None) or (
        old.weights is not None and surface.weights is not None and np.array_equal(old.weights, surface.weights))
    return (
        (spline.resolution_u, spline.resolution_v) == resolution
        and (old.degree_u, old.degree_v) == (surface.degree_u, surface.degree_v)
        and np.array_equal(old.knots_u, surface.knots_u)
        and np.array_equal(old.knots_v, surface.knots_v)
        and np.array_equal(old.control_points, surface.control_points)
        and same_weights
    )


def write_surface(obj, surface: BSplineSurface, resolution=DEFAULT_SURFACE_RESOLUTION) -> bool:
    """Show ``surface`` exactly in the SURFACE object ``obj`` (Bezier form, endpoint +
    Bezier knot modes, order = degree + 1), reusing its curve data.

    The surface's u direction is Blender's u. ``resolution``: Blender's evaluated points
    per control point, one int or (u, v). When the data holds one spline whose net has the
    size of the new Bezier net, only the control points are rewritten; otherwise rows of
    points are joined into one surface spline with ``make_segment`` in edit mode (works in
    background mode; the active object, selection and mode are restored). Nothing is
    written when ``obj`` already shows ``surface``. Stores the exact float64 surface on
    ``obj`` (:func:`stored_geometry`). Returns True when the net was rebuilt. Raises
    :class:`GeometryError` for degrees above :data:`MAX_DEGREE` or dimensions above 3.
    """
    res = _resolution_pair(resolution)
    if _shows(obj, surface, res):
        return False
    order_u, order_v = order_from_degree(surface.degree_u), order_from_degree(surface.degree_v)
    bezier = _bezier_operations().surface_to_bezier_form(surface)
    net = _homogeneous_3d(bezier.control_points, bezier.weights, obj.name)
    if net.shape[1] == 2:
        net = _midpoint_column(net)  # make_segment does not join rows of two points
    nu, nv = net.shape[:2]
    data = obj.data
    splines = data.splines
    rebuild = not (len(splines) == 1 and (splines[0].point_count_u, splines[0].point_count_v) == (nu, nv))
    if rebuild:
        splines.clear()
        # low resolution before joining: Blender evaluates the net in edit mode, and at the
        # default resolution (12) a large net costs half a second there
        data.resolution_u, data.resolution_v = res
        for i in range(nu):
            row = splines.new("NURBS")
            row.resolution_u, row.resolution_v = res
            row.points.add(nv - 1)
            row.points.foreach_set("co", net[i].astype(np.float32).ravel())
            # selected here rather than by an operator: every bpy.ops call re-evaluates the
            # view layer twice
            row.points.foreach_set("select", np.ones(nv, dtype=bool))
        with _editing(obj):
            bpy.ops.curve.make_segment()
        if len(splines) != 1 or (splines[0].point_count_u, splines[0].point_count_v) != (nu, nv):
            raise GeometryError(f"{obj.name}: Blender did not join the {nu} rows into one {nu} x {nv} net")
    spline = splines[0]
    # point k of a surface spline is (u = k % nu, v = k // nu); rewrite them all so the
    # result does not depend on the order make_segment joined the rows in
    spline.points.foreach_set("co", net.transpose(1, 0, 2).astype(np.float32).ravel())
    if rebuild:
        spline.points.foreach_set("select", np.zeros(nu * nv, dtype=bool))
        spline.use_endpoint_u = spline.use_endpoint_v = True
        spline.use_bezier_u = spline.use_bezier_v = True
        spline.use_cyclic_u = spline.use_cyclic_v = False
        spline.use_smooth = True
    if (spline.order_u, spline.order_v) != (order_u, order_v):
        spline.order_u, spline.order_v = order_u, order_v
        if (spline.order_u, spline.order_v) != (order_u, order_v):
            raise GeometryError(
                f"{obj.name}: Blender set orders ({spline.order_u}, {spline.order_v}) instead of ({order_u}, {order_v})"
            )
    if (spline.resolution_u, spline.resolution_v) != res:
        spline.resolution_u, spline.resolution_v = res
    data.update_tag()
    _store(obj, surface)
    return rebuild


def surface_to_object(surface: BSplineSurface, name: str, collection=None, resolution=DEFAULT_SURFACE_RESOLUTION):
    """A new SURFACE object showing ``surface`` exactly (:func:`write_surface`), linked to
    ``collection`` (the scene collection by default)."""
    order_from_degree(surface.degree_u)
    order_from_degree(surface.degree_v)
    return _new_object(name, "SURFACE", lambda obj: write_surface(obj, surface, resolution), collection)


# -- Blender -> model -----------------------------------------------------------------------
def _nurbs_spline(spline, what: str):
    nu, nv = spline.point_count_u, spline.point_count_v
    co = _float32_array(spline.points, "co", 4).astype(np.float64)
    net = co.reshape(nv, nu, 4).transpose(1, 0, 2)  # [u index, v index]
    degree_u, knots_u, index_u = _direction(
        nu, spline.order_u, spline.use_endpoint_u, spline.use_bezier_u, spline.use_cyclic_u, f"{what} u"
    )
    if nv == 1:
        rows = net[index_u, 0]
        weights = rows[:, 3] if np.any(rows[:, 3] != 1.0) else None
        return BSplineCurve(degree_u, knots_u, rows[:, :3], weights)
    degree_v, knots_v, index_v = _direction(
        nv, spline.order_v, spline.use_endpoint_v, spline.use_bezier_v, spline.use_cyclic_v, f"{what} v"
    )
    net = net[index_u][:, index_v]
    weights = net[..., 3] if np.any(net[..., 3] != 1.0) else None
    return BSplineSurface(degree_u, degree_v, knots_u, knots_v, net[..., :3], weights)


def _poly_spline(spline, what: str) -> BSplineCurve:
    points = _float32_array(spline.points, "co", 4).astype(np.float64).reshape(-1, 4)[:, :3]
    if spline.use_cyclic_u:
        points = np.concatenate([points, points[:1]])
    if len(points) < 2:
        raise GeometryError(f"{what}: a poly spline needs two points, got {len(points)}")
    n = len(points)
    knots = np.concatenate([[0.0], np.arange(n, dtype=float), [n - 1.0]])
    return BSplineCurve(1, knots, points)


def _bezier_spline(spline, what: str) -> BSplineCurve:
    points = spline.bezier_points
    co, left, right = (_float32_array(points, a, 3).astype(np.float64).reshape(-1, 3) for a in ("co", "handle_left", "handle_right"))
    n = len(co)
    segments = n if spline.use_cyclic_u else n - 1
    if segments < 1:
        raise GeometryError(f"{what}: a Bezier spline needs two points, got {n}")
    rows = [co[0]]
    for s in range(segments):
        t = (s + 1) % n
        rows += [right[s], left[t], co[t]]
    knots = np.concatenate([[0.0], np.repeat(np.arange(segments + 1, dtype=float), 3), [float(segments)]])
    return BSplineCurve(3, knots, np.array(rows))


def object_to_geometry(obj) -> list[BSplineCurve | BSplineSurface]:
    """Exact float64 model of a CURVE or SURFACE object, one entry per spline.

    Uses the stored exact data when :func:`stored_geometry` has it (in the model's own
    dimension, so a 2-D curve stays 2-D); otherwise Blender's splines, 3-D, with Blender's
    own knot vectors (module docstring), in object-local coordinates (apply
    ``obj.matrix_world`` for world coordinates). Surface-object splines with one row are
    returned as curves. Raises :class:`GeometryError` for other object types and for
    splines Blender does not display.
    """
    stored = stored_geometry(obj)
    if stored is not None:
        return stored
    if obj is None or obj.type not in {"CURVE", "SURFACE"}:
        kind = None if obj is None else obj.type
        raise GeometryError(f"expected a curve or surface object, got {kind}")
    result = []
    for number, spline in enumerate(obj.data.splines):
        what = f"{obj.name} spline {number}"
        if spline.type == "NURBS":
            result.append(_nurbs_spline(spline, what))
        elif spline.type == "POLY":
            result.append(_poly_spline(spline, what))
        elif spline.type == "BEZIER":
            result.append(_bezier_spline(spline, what))
        else:
            raise GeometryError(f"{what}: unsupported spline type {spline.type}")
    return result


def register():
    """Nothing to register: helpers for the operators."""


def unregister():
    """Nothing to unregister."""
