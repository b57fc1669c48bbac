"""Curve Smoothing (Hvid) panel (3D View > Sidebar > Bladesmith): the jobcard of Hvid
(1993, Appendix) as scene settings, the distribution function's plot (Fig. 3.11), a
Smooth button that runs ``bladesmith.smooth_curve`` on the active curve with them, and the
last run's figures (iterations, residual history, κ before/after, deviation).

The plot is an image ("Bladesmith Hvid distribution", 2x1 aspect) drawn with numpy:
the distribution f(t) (normalised arc length against point index, Hvid §3.3) over the
uniform diagonal, with one tick per smoothing point on the arc-length axis, so where the
points crowd is visible at a glance, as in Fig. 3.11. It is redrawn when a distribution
setting changes. A non-monotone polynomial (refused by the smoother, §3.3) is not drawn;
the panel says so.
"""
import json

import bpy
import numpy as np
from bpy.props import PointerProperty

from ..geometry.errors import BladesmithError
from ..geometry.fairing import curvature_fractions
from ..operators.hvid_properties import JOBCARD, PLOT_HOOKS, HvidProperties, draw_jobcard

PLOT_IMAGE = "Bladesmith Hvid distribution"
PLOT_SIZE = (256, 128)  # width, height in pixels
#: Custom property the smoother writes on the smoothed object (operators/smooth_curve.py).
REPORT_KEY = "bladesmith_fairing"

BACKGROUND = (0.12, 0.12, 0.12, 1.0)
AXES = (0.55, 0.55, 0.55, 1.0)
CURVE = (0.25, 0.65, 1.0, 1.0)
TICKS = (1.0, 0.6, 0.2, 1.0)


def plot_pixels(fractions: np.ndarray, width: int = PLOT_SIZE[0], height: int = PLOT_SIZE[1], monotone: bool = True) -> np.ndarray:
    """(height, width, 4) float32 RGBA of the distribution plot: f(t_i) against t_i = i/(N−1)
    (left part, square) and the N points as ticks along the arc-length axis (right strip);
    ``monotone`` is only stored for the caller (an empty ``fractions`` draws the axes)."""
    img = np.empty((height, width, 4), dtype=np.float32)
    img[:] = BACKGROUND
    m = 8  # margin
    side = height - 2 * m
    x0, y0 = m, m
    f = np.asarray(fractions, dtype=np.float64)
    t = np.linspace(0.0, 1.0, f.size)

    def put(x, y, colour, thick=1):
        xi = np.clip(np.round(x).astype(int), 0, width - 1)
        yi = np.clip(np.round(y).astype(int), 0, height - 1)
        for d in range(thick):
            img[np.clip(yi + d, 0, height - 1), xi] = colour

    s = np.linspace(0.0, 1.0, 4 * side)
    put(x0 + s * side, np.full_like(s, y0), AXES)  # t axis
    put(np.full_like(s, x0), y0 + s * side, AXES)  # f axis
    put(x0 + s * side, y0 + s * side, AXES)  # uniform distribution
    if f.size:
        dense_t = np.linspace(0.0, 1.0, 8 * side)
        dense_f = np.interp(dense_t, t, f)
        put(x0 + dense_t * side, y0 + np.clip(dense_f, 0, 1) * side, CURVE, 2)
    # the points along the curve: one tick per point at its arc-length fraction
    xs = x0 + side + 3 * m
    put(np.full_like(s, xs), y0 + s * side, AXES)
    for frac in np.clip(f, 0.0, 1.0):
        put(xs + np.arange(1, 2 * m), np.full(2 * m - 1, y0 + frac * side), TICKS)
    return img  # row 0 is the bottom row of a Blender image, as the plot's y axis wants


def _fractions(settings, context) -> tuple[np.ndarray, bool]:
    """The smoothing points' arc-length fractions for the settings and the active curve."""
    n = int(settings.smoothing_points)
    obj = context.active_object if context is not None else None
    kind = settings.kind
    if kind == "AUTO":
        kind = "AIRFOIL" if obj is not None and obj.get("bladesmith_airfoil") is not None else "CURVE"
    if kind == "CURVE" and obj is not None and obj.type == "CURVE":
        from ..operators.smooth_curve import read_planar_curve

        curve, _, _ = read_planar_curve(obj)
        return curvature_fractions(curve, n, settings.alpha), True
    if kind == "CURVE":
        return np.linspace(0.0, 1.0, n), True
    try:
        return settings.polynomial_distribution().fractions(n), True
    except BladesmithError:  # not monotone (§3.3): the smoother refuses it; plot the diagonal only
        return np.empty(0), False


def refresh_plot(context) -> bpy.types.Image | None:
    """(Re)draw the distribution plot image from the scene's settings."""
    scene = context.scene if context is not None else None
    if scene is None or not hasattr(scene, "bladesmith_hvid"):
        return None
    try:
        fractions, monotone = _fractions(scene.bladesmith_hvid, context)
    except BladesmithError:
        return None
    img = bpy.data.images.get(PLOT_IMAGE)
    w, h = PLOT_SIZE
    if img is None or tuple(img.size) != (w, h):
        if img is not None:
            bpy.data.images.remove(img)
        img = bpy.data.images.new(PLOT_IMAGE, w, h, alpha=True)
    img.pixels.foreach_set(plot_pixels(fractions, w, h, monotone).ravel())
    img.update()
    img["monotone"] = bool(monotone)
    if img.preview is not None:
        img.preview.reload()
    return img


class BLADESMITH_PG_hvid(HvidProperties, bpy.types.PropertyGroup):
    """The scene's Hvid jobcard (the sidebar panel's settings)."""


class BLADESMITH_OT_hvid_plot(bpy.types.Operator):
    """Draw the distribution function of the current settings (Hvid Fig. 3.11)"""

    bl_idname = "bladesmith.hvid_plot_distribution"
    bl_label = "Plot Distribution"
    bl_options = {"INTERNAL"}

    def execute(self, context):
        refresh_plot(context)
        return {"FINISHED"}


class BLADESMITH_PT_hvid(bpy.types.Panel):
    bl_label = "Curve Smoothing (Hvid)"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Bladesmith"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.bladesmith_hvid
        obj = context.active_object
        is_curve = obj is not None and obj.type == "CURVE"
        row = layout.row()
        row.enabled = is_curve
        op = row.operator("bladesmith.smooth_curve", icon="MOD_SMOOTH", text="Smooth Active Curve")
        for name in JOBCARD:
            setattr(op, name, getattr(settings, name))
        if not is_curve:
            layout.label(text="Select a curve (or File > Import > Airfoil)", icon="INFO")
        draw_jobcard(layout, settings, settings.kind)
        box = layout.box()
        row = box.row()
        row.label(text="Distribution f(t) (Fig. 3.11)")
        row.operator(BLADESMITH_OT_hvid_plot.bl_idname, text="", icon="FILE_REFRESH")
        img = bpy.data.images.get(PLOT_IMAGE)
        if img is not None and img.preview is not None:
            box.template_icon(icon_value=img.preview.icon_id, scale=6.0)
            if not img.get("monotone", True):
                box.label(text="Not monotone: the smoother refuses it (§3.3)", icon="ERROR")
        _draw_last_result(layout, obj)


def _draw_last_result(layout, obj) -> None:
    """The figures of the last run on ``obj`` (or on its "<name> smoothed" result)."""
    if obj is None:
        return
    record = obj.get(REPORT_KEY)
    if record is None:
        smoothed = bpy.data.objects.get(f"{obj.name} smoothed")
        record = smoothed.get(REPORT_KEY) if smoothed is not None else None
    if record is None:
        return
    record = json.loads(json.dumps(record.to_dict() if hasattr(record, "to_dict") else record))
    box = layout.box()
    box.label(text=f"Last run: {record['kind']}, {'converged' if record['converged'] else 'NOT converged'} "
                   f"({record['reason']})", icon="CHECKMARK" if record["converged"] else "ERROR")
    col = box.column(align=True)
    for k, (f, x) in enumerate(zip(record["residuals"], record["steps"]), 1):
        col.label(text=f"iteration {k}: Σ|κ−κ*| {f:.4g}   Σ|δ| {x:.3g}")
    kb, ka = record["kappa_before"], record["kappa_after"]
    col.label(text=f"κ before [{kb[0]:.4g}, {kb[1]:.4g}]  after [{ka[0]:.4g}, {ka[1]:.4g}]")
    col.label(text=f"max deviation {record['max_deviation']:.3g} × reference length {record['reference_length']:.4g}")


_classes = (BLADESMITH_PG_hvid, BLADESMITH_OT_hvid_plot, BLADESMITH_PT_hvid)
_register, _unregister = bpy.utils.register_classes_factory(_classes)


def register():
    _register()
    bpy.types.Scene.bladesmith_hvid = PointerProperty(type=BLADESMITH_PG_hvid)
    PLOT_HOOKS.append(refresh_plot)


def unregister():
    if refresh_plot in PLOT_HOOKS:
        PLOT_HOOKS.remove(refresh_plot)
    del bpy.types.Scene.bladesmith_hvid
    _unregister()
