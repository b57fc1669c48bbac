"""``bpy.ops.bladesmith.smooth_curve``: Hvid (1993) smoothing of the active curve object.

The active CURVE object (one spline: poly, NURBS or Bezier; planar in any orientation)
is read with :func:`object_to_geometry`, mapped into its own plane, smoothed by
``smooth2d`` (any curve) or ``smoothfoil`` (airfoils: objects made by
``bladesmith.import_airfoil``, or ``kind='AIRFOIL'``) and mapped back. Beside it the
operator adds, in a collection "<name> fairing":

- "<name> smoothed": the smoothed cubic B-spline (exact; overlays the original, Fig. 3.14);
- "<name> curvature before" / "after": curvature against normalised arc length under the
  curve (§3.1.1; both on the same axes, Fig. 3.15);
- "<name> comb": a curvature comb on the smoothed curve;
- "<name> deviation": the deviation of Fig. 3.4, magnified, against normalised arc length.

The jobcard properties (Hvid 1993, Appendix / §3.4) come from
:class:`.hvid_properties.HvidProperties`, shared with the import redo panel and the sidebar.
A closed curve is smoothed with smoothing type 1 unless the caller sets the type. If the
iteration does not converge the operator reports the residual history and what to change,
and cancels; nothing in the scene changes.

Reached from the curve context menus (object mode and edit mode, :data:`MENUS`), the
sidebar's Curve Smoothing (Hvid) panel and *File > Import > Airfoil*'s Smooth option.
"""

import bpy
import numpy as np
from bpy.props import BoolProperty, FloatProperty, StringProperty

from ..geometry.errors import BladesmithError, DefinitionError, GeometryError
from ..geometry.fairing import (
    curvature_comb,
    curvature_plot,
    smooth2d,
    smoothfoil,
    write_points,
)
from ..geometry.fairing.curvature import span_samples
from ..geometry.nurbs import BSplineCurve
from ..geometry.fairing.hvid import is_closed
from .hvid_properties import HvidProperties, draw_jobcard
from .import_airfoil import stored_airfoil
from .nurbs_objects import curve_to_object, object_to_geometry, remove_object, stored_geometry
from .scene_guard import check_output_file, unchanged_on_refusal

#: Points farther than this fraction of the curve's size from its best-fit plane make
#: the curve non-planar (float32 coordinates leave ~1e-7 of noise).
PLANAR_TOL = 1e-5

#: Fewest control points of a curve to smooth (the cubic through them needs 4).
MIN_CURVE_POINTS = 4

#: Samples per knot span used to read a non-polyline curve as airfoil data.
AIRFOIL_SAMPLES_PER_SPAN = 2

#: Custom property with the smoothing report on the smoothed object.
REPORT_KEY = "bladesmith_fairing"

#: Object colours (viewport "Object" colour) of the overlays.
COLOUR_AFTER = (0.1, 0.45, 1.0, 1.0)
COLOUR_BEFORE = (1.0, 0.35, 0.1, 1.0)
COLOUR_COMB = (0.2, 0.8, 0.3, 1.0)


def _plane_frame(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(origin (3,), axes (2, 3)) of the best-fit plane (SVD); refuses non-planar curves."""
    origin = points.mean(axis=0)
    _, sv, vt = np.linalg.svd(points - origin, full_matrices=False)
    size = float(np.linalg.norm(np.ptp(points, axis=0)))
    off = np.abs((points - origin) @ vt[2])
    if size == 0 or off.max() > PLANAR_TOL * size:
        raise GeometryError(
            f"the curve is not planar: a point lies {off.max():.3g} off its best-fit plane "
            f"(allowed {PLANAR_TOL:g} × size {size:.3g})"
        )
    if abs(vt[2, 2]) > 1.0 - 1e-12:
        # in (a plane parallel to) XY: keep Blender's x and y, so a 2-D view stays a 2-D view
        return np.array([0.0, 0.0, origin[2]]), np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    axes = vt[:2].copy()
    return origin, axes


def read_planar_curve(obj) -> tuple[BSplineCurve, np.ndarray, np.ndarray]:
    """(2-D curve, origin, axes) of a one-spline curve object, in object-local coordinates."""
    curves = object_to_geometry(obj)
    if len(curves) != 1:
        raise GeometryError(f"{obj.name}: expected one spline, got {len(curves)}")
    curve = curves[0]
    if not isinstance(curve, BSplineCurve):
        raise GeometryError(f"{obj.name}: expected a curve, got a surface")
    if len(curve.control_points) < MIN_CURVE_POINTS:
        raise GeometryError(f"{obj.name}: the curve has {len(curve.control_points)} points; smoothing needs at "
                            f"least {MIN_CURVE_POINTS}")
    if curve.dim == 2:
        return curve, np.zeros(3), np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    P = curve.control_points[:, :3]
    origin, axes = _plane_frame(P)
    return curve.with_control_points((P - origin) @ axes.T), origin, axes


def _to_3d(points2d: np.ndarray, origin: np.ndarray, axes: np.ndarray) -> np.ndarray:
    return origin + points2d @ axes


def _poly_object(name: str, polylines: list[np.ndarray], collection, matrix, colour):
    data = bpy.data.curves.new(name, "CURVE")
    data.dimensions = "3D"
    for line in polylines:
        spline = data.splines.new("POLY")
        spline.points.add(len(line) - 1)
        rows = np.ones((len(line), 4))
        rows[:, :3] = line
        spline.points.foreach_set("co", rows.astype(np.float32).ravel())
    obj = bpy.data.objects.new(name, data)
    collection.objects.link(obj)
    obj.matrix_world = matrix
    obj.color = colour
    return obj


def build_objects(source_obj, result, origin, axes, plot_height: float, comb_length: float, deviation_gain: float):
    """Create the smoothed curve and its plots (module docstring). Returns the objects."""
    name = source_obj.name
    collection = bpy.data.collections.new(f"{name} fairing")
    parent = source_obj.users_collection[0] if source_obj.users_collection else bpy.context.scene.collection
    parent.children.link(collection)
    matrix = source_obj.matrix_world.copy()
    made = []
    try:
        curve = result.curve
        curve3 = curve.with_control_points(_to_3d(curve.control_points, origin, axes))
        smoothed = curve_to_object(curve3, f"{name} smoothed", collection)
        smoothed.matrix_world = matrix
        smoothed.color = COLOUR_AFTER
        made.append(smoothed)
        samples = curve.evaluate(span_samples(curve, 4))
        lo, hi = samples.min(axis=0), samples.max(axis=0)
        width = float(max(hi[0] - lo[0], hi[1] - lo[1]))
        s0, k0 = curvature_plot(result.unsmoothed)
        s1, k1 = curvature_plot(curve)
        sign = result.curvature_sign
        k0, k1 = sign * k0, sign * k1
        peak = float(max(np.abs(k0).max(), np.abs(k1).max(), 1e-300))
        height = plot_height * width
        base = np.array([lo[0], lo[1] - 0.25 * width - height])

        def plot(s, values, gain):
            xy = np.stack([base[0] + width * s, base[1] + gain * values], axis=1)
            return _to_3d(xy, origin, axes)

        axis_line = _to_3d(np.array([base, base + [width, 0.0]]), origin, axes)
        made.append(_poly_object(f"{name} curvature before", [plot(s0, k0, height / peak), axis_line], collection, matrix, COLOUR_BEFORE))
        made.append(_poly_object(f"{name} curvature after", [plot(s1, k1, height / peak)], collection, matrix, COLOUR_AFTER))
        kappa_max = float(np.abs(k1).max()) or 1.0
        base_pts, tips = curvature_comb(curve, sign * comb_length * width / kappa_max)
        teeth = [_to_3d(np.stack([b, t]), origin, axes) for b, t in zip(base_pts, tips)]
        made.append(_poly_object(f"{name} comb", teeth + [_to_3d(tips, origin, axes)], collection, matrix, COLOUR_COMB))
        sd, dd = result.deviation.profile
        if sd.size:
            dev_base = base - [0.0, 0.5 * height]
            xy = np.stack([dev_base[0] + width * sd, dev_base[1] + deviation_gain * dd], axis=1)
            made.append(_poly_object(f"{name} deviation", [_to_3d(xy, origin, axes)], collection, matrix, COLOUR_BEFORE))
        smoothed[REPORT_KEY] = {
            "kind": result.kind,
            "converged": bool(result.converged),
            "reason": result.reason,
            "residuals": [float(f) for f, _ in result.history],
            "steps": [float(x) for _, x in result.history],
            "kappa_before": [float(result.kappa_before.min()), float(result.kappa_before.max())],
            "kappa_after": [float(result.kappa_after.min()), float(result.kappa_after.max())],
            "max_deviation": float(result.deviation.true),
            "max_deviation_same_parameter": float(result.deviation.same_parameter),
            "reference_length": float(result.reference_length),
        }
    except BaseException:
        for obj in made:
            remove_object(obj)
        bpy.data.collections.remove(collection)
        raise
    return made


class BLADESMITH_OT_smooth_curve(HvidProperties, bpy.types.Operator):
    """Smooth the active curve by prescribing a smoothed curvature (Hvid 1993: smooth2D / smoothfoil)"""

    bl_idname = "bladesmith.smooth_curve"
    bl_label = "Smooth Curve (Hvid)"
    bl_options = {"REGISTER", "UNDO"}

    make_plots: BoolProperty(name="Plots", description="Add curvature plots, comb and deviation", default=True)
    plot_height: FloatProperty(name="Plot height", description="Curvature plot height as a fraction of the curve's width", default=0.4, min=0.01)
    comb_length: FloatProperty(name="Comb length", description="Longest comb tooth as a fraction of the curve's width", default=0.15, min=0.0)
    deviation_gain: FloatProperty(name="Deviation gain", description="Magnification of the deviation plot", default=100.0, min=0.0)
    filepath: StringProperty(name="Points file", description="Write the np points here at full precision (optional)", default="", subtype="FILE_PATH")

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and obj.type == "CURVE"

    @unchanged_on_refusal
    def execute(self, context):
        obj = context.active_object
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            path = check_output_file(self.filepath) if self.filepath else ""
            result, origin, axes = self._smooth(obj, lambda done, total: wm.progress_update(int(90 * done / max(total, 1))))
            if path:
                try:
                    write_points(path, result.points)
                except OSError as exc:
                    raise DefinitionError(f"cannot write {path!r}: {exc.strerror or exc}", field="filepath") from None
            made = build_objects(obj, result, origin, axes, self.plot_height, self.comb_length, self.deviation_gain) if self.make_plots else None
            if made is None:
                collection = obj.users_collection[0] if obj.users_collection else context.scene.collection
                curve = result.curve
                smoothed = curve_to_object(curve.with_control_points(_to_3d(curve.control_points, origin, axes)), f"{obj.name} smoothed", collection)
                smoothed.matrix_world = obj.matrix_world.copy()
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        for line in result.lines():
            print(line)
        self.report(
            {"INFO"},
            f"{result.kind}: converged in {len(result.history)} iterations; curvature "
            f"[{result.kappa_before.min():.4g}, {result.kappa_before.max():.4g}] -> "
            f"[{result.kappa_after.min():.4g}, {result.kappa_after.max():.4g}]; max deviation "
            f"{result.deviation.true:.3g} of the reference length {result.reference_length:.4g}",
        )
        return {"FINISHED"}

    def _smooth(self, obj, progress):
        return smooth_object(obj, self, progress, type_given=self.properties.is_property_set("smoothing_type"))

    def draw(self, context):
        draw_jobcard(self.layout, self, self.kind)
        col = self.layout.column(align=True)
        col.prop(self, "make_plots")
        if self.make_plots:
            col.prop(self, "plot_height")
            col.prop(self, "comb_length")
            col.prop(self, "deviation_gain")
        self.layout.prop(self, "filepath")


def smooth_object(obj, props, progress=None, type_given: bool = True):
    """(SmoothingResult, origin, axes) of Hvid smoothing ``obj`` with the jobcard ``props``
    (:class:`HvidProperties`). AUTO: smoothfoil for imported airfoils, smooth2D otherwise.
    A closed curve (cyclic spline, or ends that meet without a corner) is smoothed with
    smoothing type 1 unless ``type_given``: type 2 keeps the largest curvature, which is an
    airfoil's leading edge but on a closed outline just one of its noisy peaks."""
    airfoil = stored_airfoil(obj)
    kind = props.kind
    if kind == "AUTO":
        kind = "AIRFOIL" if airfoil is not None else "CURVE"
    if kind == "AIRFOIL":
        settings = props.smoothing_settings()
        distribution = props.polynomial_distribution()
        if airfoil is not None and stored_geometry(obj) is not None:
            points, chord = airfoil
            origin, axes = np.zeros(3), np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
            data = chord * points
        else:
            curve, origin, axes = read_planar_curve(obj)
            data = curve.control_points if curve.degree == 1 else curve.evaluate(span_samples(curve, AIRFOIL_SAMPLES_PER_SPAN))
        return smoothfoil(data, distribution, settings, progress), origin, axes
    curve, origin, axes = read_planar_curve(obj)
    # a cyclic Blender spline is a closed curve (smoothed periodically, no fixed seam);
    # otherwise smooth2d detects coinciding ends itself
    cyclic = bool(obj.data.splines) and bool(obj.data.splines[0].use_cyclic_u)
    closed = True if cyclic else is_closed(curve)
    settings = props.smoothing_settings(None if type_given or not closed else 1)
    return smooth2d(curve, props.alpha, settings, progress, closed=closed), origin, axes


def _menu_entry(self, context):
    obj = context.active_object
    if obj is not None and obj.type == "CURVE":
        self.layout.separator()
        self.layout.operator(BLADESMITH_OT_smooth_curve.bl_idname, icon="MOD_SMOOTH")


#: Menus that show the smoother when the active object is a curve: the object context
#: menu (right click in object mode), and edit mode's curve context menu and Curve menu.
MENUS = ("VIEW3D_MT_object_context_menu", "VIEW3D_MT_edit_curve_context_menu", "VIEW3D_MT_edit_curve")


_classes = (BLADESMITH_OT_smooth_curve,)
_register, _unregister = bpy.utils.register_classes_factory(_classes)


def register():
    _register()
    for name in MENUS:
        getattr(bpy.types, name).append(_menu_entry)


def unregister():
    for name in reversed(MENUS):
        getattr(bpy.types, name).remove(_menu_entry)
    _unregister()
