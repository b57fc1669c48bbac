"""The Hvid (1993) jobcard as Blender properties, shared by ``bladesmith.smooth_curve``,
the *File > Import > Airfoil* redo panel and the sidebar's Curve Smoothing panel.

Names spell out the jobcard's (Hvid 1993, Appendix and §3.4): ``output_points`` = np,
``smoothing_points`` = nsmooth, ``max_iterations`` = ntrial, ``tolx``, ``tolf``,
``smoothing_type`` = smttype, ``end_derivative_order`` = iorder; ``passes`` (ad hoc
passes), ``smoother``; the distribution: ``alpha`` (smooth2D, §3.3) and ``end0``, ``end1``,
``centre``, ``centre_slope`` (smoothfoil's 7th-order polynomial, §3.3, Fig. 3.9).
"""
import bpy
from bpy.props import EnumProperty, FloatProperty, IntProperty

from ..geometry.fairing import PolynomialDistribution, SmoothingSettings

#: Every jobcard property, in the order the panels show them.
JOBCARD = (
    "kind", "output_points", "smoothing_points", "max_iterations", "tolx", "tolf", "smoothing_type",
    "smoother", "passes", "smoothing_weight", "end_derivative_order", "alpha", "end0", "end1", "centre",
    "centre_slope",
)
#: The distribution's properties (the plot of Fig. 3.11 follows them).
DISTRIBUTION = ("alpha", "end0", "end1", "centre", "centre_slope")


#: Called with the context when a distribution setting of a property group changes: the
#: sidebar panel (ui/hvid_panel.py) registers its plot here, so this module needs no ui.
PLOT_HOOKS: list = []


def _distribution_changed(self, context):
    """Property update: redraw the sidebar's distribution plot (only for the scene's
    settings; operator properties change in redo panels and have no plot)."""
    if isinstance(self, bpy.types.PropertyGroup):
        for hook in PLOT_HOOKS:
            hook(context)


class HvidProperties:
    """Mixin with the jobcard properties (annotations are collected by Blender from
    mixins of operators and property groups alike)."""

    kind: EnumProperty(
        name="Kind",
        items=[
            ("AUTO", "Auto", "Airfoil for imported airfoils, curve otherwise"),
            ("CURVE", "Curve (smooth2D)", "Any plane curve, curvature-weighted distribution"),
            ("AIRFOIL", "Airfoil (smoothfoil)", "Airfoil outline TE-LE-TE: keeps LE curvature and chord"),
        ],
        default="AUTO",
        update=_distribution_changed,
    )
    output_points: IntProperty(name="np", description="Points of the final layout (jobcard np)", default=150, min=4)
    smoothing_points: IntProperty(
        name="nsmooth", description="Points of the smoothing spline (jobcard nsmooth)", default=180, min=8,
        update=_distribution_changed,
    )
    max_iterations: IntProperty(name="ntrial", description="Maximum Newton/secant iterations (jobcard ntrial)", default=10, min=1)
    tolx: FloatProperty(name="tolx", description="Tolerance on the sum of displacements", default=1e-10, min=0.0, precision=12)
    tolf: FloatProperty(name="tolf", description="Tolerance on the sum of curvature residuals", default=1e-9, min=0.0, precision=12)
    # an integer, as the jobcard's smttype (1: smooth the curvature everywhere, 2: keep the
    # largest curvature, the airfoil LE); other values are refused by SmoothingSettings
    smoothing_type: IntProperty(
        name="Smoothing type",
        description="Jobcard smttype: 1 smooths the curvature everywhere, 2 keeps the largest curvature (airfoil LE)",
        default=2, soft_min=1, soft_max=2,
    )
    smoother: EnumProperty(
        name="Smoother",
        items=[("ad_hoc", "Ad hoc (3-point)", "Passes of the 3-point mean"), ("least_squares", "Least squares", "Penalised least-squares spline")],
        default="ad_hoc",
    )
    passes: IntProperty(name="Passes", description="Passes of the ad hoc smoother", default=4, min=0)
    smoothing_weight: FloatProperty(name="LS weight", description="λ of the least-squares smoother (0: cross-validation)", default=10.0, min=0.0)
    end_derivative_order: IntProperty(name="iorder", description="Order of the end-tangent finite differences", default=2, min=2, max=3)
    alpha: FloatProperty(
        name="α", description="Damping of the curvature-weighted distribution (smooth2D)", default=3.0, min=0.0,
        update=_distribution_changed,
    )
    end0: FloatProperty(name="f'(0)", description="Airfoil distribution slope at the start", default=0.5, min=1e-6, update=_distribution_changed)
    end1: FloatProperty(name="f'(1)", description="Airfoil distribution slope at the end", default=0.5, min=1e-6, update=_distribution_changed)
    centre: FloatProperty(
        name="f(1/2)", description="Arc-length fraction of the middle point (the LE)", default=0.5, min=0.0, max=1.0,
        precision=4, update=_distribution_changed,
    )
    centre_slope: FloatProperty(name="f'(1/2)", description="Distribution slope at the LE", default=0.1, min=1e-6, update=_distribution_changed)

    def smoothing_settings(self, smoothing_type: int | None = None) -> SmoothingSettings:
        return SmoothingSettings(
            smoothing_points=self.smoothing_points,
            output_points=self.output_points,
            max_iterations=self.max_iterations,
            tolx=self.tolx,
            tolf=self.tolf,
            smoothing_type=int(self.smoothing_type) if smoothing_type is None else smoothing_type,
            smoother=self.smoother,
            passes=self.passes,
            end_derivative_order=self.end_derivative_order,
            smoothing_weight=self.smoothing_weight,
        )

    def polynomial_distribution(self) -> PolynomialDistribution:
        return PolynomialDistribution(self.end0, self.end1, self.centre, self.centre_slope)


def draw_jobcard(layout, props, kind: str = "AUTO", show_kind: bool = True) -> None:
    """The jobcard fields of ``props`` (an operator or the scene's settings) in ``layout``;
    ``kind`` chooses which distribution parameters are shown."""
    col = layout.column(align=True)
    if show_kind:
        col.prop(props, "kind")
    col.prop(props, "smoothing_type")
    col.prop(props, "smoother")
    if props.smoother == "ad_hoc":
        col.prop(props, "passes")
    else:
        col.prop(props, "smoothing_weight")
    col = layout.column(align=True)
    row = col.row(align=True)
    row.prop(props, "smoothing_points")
    row.prop(props, "output_points")
    row = col.row(align=True)
    row.prop(props, "max_iterations")
    row.prop(props, "end_derivative_order")
    row = col.row(align=True)
    row.prop(props, "tolx")
    row.prop(props, "tolf")
    col = layout.column(align=True)
    col.label(text="Distribution (Hvid §3.3)")
    if kind in ("AUTO", "AIRFOIL"):
        row = col.row(align=True)
        row.prop(props, "end0")
        row.prop(props, "end1")
        row = col.row(align=True)
        row.prop(props, "centre")
        row.prop(props, "centre_slope")
    if kind in ("AUTO", "CURVE"):
        col.prop(props, "alpha")
