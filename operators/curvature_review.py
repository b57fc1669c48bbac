"""Curvature review in Blender: ``bpy.ops.bladesmith.curvature_review`` and
:func:`render_review_image`.

Everything is computed from the exact float64 model of each reviewed object
(:func:`.nurbs_objects.object_to_geometry`), never from Blender's tessellation:

- **maps**: per surface spline a mesh object ``<source> map`` built from the surface's own
  grid (uniform per knot span, :func:`~..geometry.fairing.review.surface_map`), with the
  chosen quantity in the float attribute ``bladesmith_value`` and its colour in the colour
  attribute ``bladesmith_curvature`` (diverging blue-white-orange map, symmetric limits
  from a percentile of |value| over everything reviewed in the run). The mesh is lifted by
  :data:`DISPLAY_OFFSET_FRACTION` of the object's size along the normal so it does not
  z-fight with the source in the viewport; the values are those of the exact surface.
  Linked duplicates (the copies of a propeller blade) get objects sharing the same mesh.
- **combs**: ``<source> combs``, a curve object of poly splines: per comb the teeth
  (base, tip, base, next base, ...) and the envelope. Iso lines of surfaces use the normal
  curvature against the surface normal, curve objects their signed in-plane curvature
  when planar (:func:`~..geometry.fairing.surface_curvature.curvature_comb`).
- **legend**: a colour bar mesh and black text meshes (limits, quantity, units, clipping).
- **numbers**: per surface, stored on its map object as ``bladesmith_review`` (JSON) and
  shown by :mod:`..ui.review_panel`.
- **comparison**: with ``reference`` (an object or collection name: the geometry before
  smoothing) the reference is reviewed with the same limits and shown shifted by
  -spacing along x, and a difference map (signed closest-point deviation in metres) of
  each reviewed surface from the nearest reference surface is shown at +spacing.

All review objects live in the collection :data:`REVIEW_COLLECTION` and are owned by it:
running the operator again updates them in place (objects not produced by the new run are
removed), and deleting the collection with its objects leaves the scene as it was. The
reviewed objects, the selection and the active object are never touched.
"""

import json
import math
import os
import pathlib
import tempfile
import time
from dataclasses import dataclass, field

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty
from mathutils import Matrix, Vector

from ..geometry.errors import BladesmithError, GeometryError
from ..geometry.fairing.review import DEFAULT_SAMPLES_PER_SPAN, surface_map, surface_numbers
from ..geometry.fairing.review_display import (
    NON_NEGATIVE,
    blade_landmarks,
    length_label,
    nice_length,
    segment_count,
    sequential_colours,
    span_segments,
    sign_convention,
    upper_limit,
    zebra_colours,
    zebra_values,
)
from ..geometry.fairing.surface_curvature import (
    DEFAULT_PERCENTILE,
    DeviationSeeds,
    comb_scale,
    curvature_comb,
    diverging_colours,
    iso_line_comb,
    signed_deviation_grid,
    symmetric_limits,
)
from ..geometry.nurbs import BSplineCurve, BSplineSurface
from .nurbs_objects import object_to_geometry, remove_object
from .scene_guard import check_output_file, unchanged_on_refusal

REVIEW_COLLECTION = "Bladesmith Review"
#: Custom property on every review object: {"role": ..., "source": ..., "index": ...}.
ROLE_KEY = "bladesmith_review_role"
#: Custom property (JSON text) with a map object's numbers (SurfaceNumbers.as_dict()).
NUMBERS_KEY = "bladesmith_review"
#: Custom property on the collection (JSON): quantity, limits, units, clipped fraction.
SETTINGS_KEY = "bladesmith_review_settings"
#: Custom property on the collection (JSON) after the operator rendered an image: its path,
#: views and legends' limits, and the pixel rows of an included hub's own panel.
IMAGE_KEY = "bladesmith_review_image"
VALUE_ATTRIBUTE = "bladesmith_value"
COLOUR_ATTRIBUTE = "bladesmith_curvature"
#: Maps are lifted along the normal by this fraction of the object's size (display only).
DISPLAY_OFFSET_FRACTION = 1e-4
#: Fairness integrals in the review: Gauss nodes per knot span (the MVS of surfaces with
#: collapsed corners is dominated by the corners either way; 4 keeps the review fast).
REVIEW_QUADRATURE_POINTS = 4
#: Legend layout, as fractions of the bar's width: bar height and text size. The legend
#: spans y from -LEGEND_BELOW to +LEGEND_ABOVE (times the width) about the bar's bottom.
LEGEND_BAR_HEIGHT = 0.03
LEGEND_TEXT_SIZE = 0.022
LEGEND_BELOW = 0.03
LEGEND_ABOVE = 0.065
#: Comb tube radius as a fraction of the reviewed size (so combs show in renders).
COMB_BEVEL_FRACTION = 5e-4

QUANTITY_ITEMS = (
    ("mean", "Mean", "Mean curvature H (1/m)"),
    ("gaussian", "Gaussian", "Gaussian curvature K (1/m²)"),
    ("k1", "Maximum principal", "κ1 (1/m)"),
    ("k2", "Minimum principal", "κ2 (1/m)"),
    ("max_abs", "Largest principal", "The principal curvature of larger magnitude (1/m)"),
    ("strain_energy", "Strain energy density", "κ1² + κ2² (1/m²)"),
    ("mvs", "MVS density", "(∂κ1/∂e1)² + (∂κ2/∂e2)² (1/m⁴)"),
    ("zebra", "Zebra stripes", "Reflection lines of parallel light stripes: bent or broken stripes show curvature "
                               "jumps and creases"),
)
LABELS = {
    "mean": ("mean curvature H", "1/m"), "gaussian": ("Gaussian curvature K", "1/m²"),
    "k1": ("principal curvature κ1", "1/m"), "k2": ("principal curvature κ2", "1/m"),
    "max_abs": ("largest principal curvature", "1/m"), "strain_energy": ("κ1² + κ2²", "1/m²"),
    "mvs": ("MVS density", "1/m⁴"), "deviation": ("deviation from reference", "m"),
    "zebra": ("zebra stripes", "reflection lines"),
}


# ---------------------------------------------------------------------------------------
# objects owned by the review collection
# ---------------------------------------------------------------------------------------
def review_collection(scene, create: bool = True):
    coll = bpy.data.collections.get(REVIEW_COLLECTION)
    if coll is not None and coll.name not in scene.collection.children:
        if create:
            scene.collection.children.link(coll)
    if coll is None and create:
        coll = bpy.data.collections.new(REVIEW_COLLECTION)
        scene.collection.children.link(coll)
    return coll


def _role(obj) -> tuple | None:
    r = obj.get(ROLE_KEY)
    return None if r is None else tuple(json.loads(r))


class _Registry:
    """The review objects of the collection by role key; those not claimed in a run are
    removed at the end (:meth:`prune`)."""

    def __init__(self, collection):
        self.collection = collection
        self.existing = {}
        for obj in collection.objects:
            key = _role(obj)
            if key is not None:
                self.existing[key] = obj
        self.claimed = set()

    def get(self, key: tuple, data_type: str, name: str, new_data):
        """The object for ``key`` with data of type ``data_type`` (new or reused)."""
        self.claimed.add(key)
        obj = self.existing.get(key)
        if obj is not None and obj.type == data_type and obj.name in bpy.data.objects:
            return obj
        if obj is not None:
            remove_object(obj)
        data = new_data(name) if new_data is not None else None
        obj = bpy.data.objects.new(name, data)
        obj[ROLE_KEY] = json.dumps(list(key))
        self.collection.objects.link(obj)
        self.existing[key] = obj
        return obj

    def prune(self):
        for key, obj in list(self.existing.items()):
            if key not in self.claimed:
                remove_object(obj)
                del self.existing[key]


def clear_review(scene=None) -> None:
    """Delete the review collection, its objects and their data (what the user does by
    deleting the collection in the outliner)."""
    coll = bpy.data.collections.get(REVIEW_COLLECTION)
    if coll is None:
        return
    for obj in list(coll.all_objects):
        remove_object(obj)
    bpy.data.collections.remove(coll)


def _write_mesh(mesh, vertices: np.ndarray, quads: np.ndarray, colours: np.ndarray | None = None,
                values: np.ndarray | None = None) -> None:
    """Replace the mesh's geometry by vertices (n, 3), quads (m, 4), optional sRGB
    colours (n, 4) and float values (n,) on the points. When the vertex and quad counts
    are unchanged (a re-run), only positions, colours and values are rewritten.

    Written through the generic attributes (``position``, ``.corner_vert``): their
    foreach_set is a raw copy, unlike the legacy ``vertices.co``/``loops.vertex_index``."""
    same = len(mesh.vertices) == len(vertices) and len(mesh.polygons) == len(quads) and len(quads) > 0 \
        and mesh.get("bladesmith_topology") == _topology_key(quads)
    if not same:
        mesh.clear_geometry()
        mesh.vertices.add(len(vertices))
        if len(quads):
            mesh.loops.add(quads.size)
            mesh.polygons.add(len(quads))
            mesh.attributes[".corner_vert"].data.foreach_set("value", quads.astype(np.int32).ravel())
            mesh.polygons.foreach_set("loop_start", (np.arange(len(quads)) * 4).astype(np.int32))
        mesh["bladesmith_topology"] = _topology_key(quads)
    mesh.attributes["position"].data.foreach_set("vector", vertices.astype(np.float32).ravel())
    mesh.update(calc_edges=not same)
    if colours is not None:
        attr = mesh.color_attributes.get(COLOUR_ATTRIBUTE)
        if attr is None:
            attr = mesh.color_attributes.new(COLOUR_ATTRIBUTE, "FLOAT_COLOR", "POINT")
        attr.data.foreach_set("color", _srgb_to_linear(colours).astype(np.float32).ravel())
        mesh.color_attributes.active_color = attr
        mesh.color_attributes.render_color_index = mesh.color_attributes.find(COLOUR_ATTRIBUTE)
    if values is not None:
        attr = mesh.attributes.get(VALUE_ATTRIBUTE)
        if attr is None:
            attr = mesh.attributes.new(VALUE_ATTRIBUTE, "FLOAT", "POINT")
        attr.data.foreach_set("value", values.astype(np.float32).ravel())


def _topology_key(quads: np.ndarray) -> str:
    """A cheap signature of a quad list (count and a few entries) for in-place updates."""
    if len(quads) == 0:
        return "0"
    q = quads.ravel()
    return f"{len(quads)}:{int(q[:64].sum())}:{int(q[-64:].sum())}:{int(q[:: max(1, q.size // 97)].sum())}"


def _srgb_to_linear(rgba: np.ndarray) -> np.ndarray:
    """sRGB-encoded RGBA to linear (IEC 61966-2-1), alpha unchanged: FLOAT_COLOR attributes
    store linear values, and the raw ``color`` path of foreach_set is far faster than
    ``color_srgb``."""
    out = np.array(rgba, dtype=np.float64)
    c = out[..., :3]
    out[..., :3] = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return out


def _new_mesh(name):
    return bpy.data.meshes.new(name)


def _new_comb_curve(name):
    data = bpy.data.curves.new(name, "CURVE")
    data.dimensions = "3D"
    return data


def _write_combs(curve_data, combs, bevel: float, envelope: bool) -> None:
    curve_data.splines.clear()
    curve_data.bevel_depth = bevel
    curve_data.bevel_resolution = 0
    for comb in combs:
        base, tip = comb.points, comb.teeth
        n = len(base)
        # base_i, tip_i, base_i, base_i+1, ... draws every tooth and the curve in one spline
        path = np.empty((3 * n - 1, 3))
        path[0::3] = base
        path[1::3] = tip
        path[2::3] = base[:-1]
        polylines = [path] + ([tip] if envelope else [])
        for line in polylines:
            spline = curve_data.splines.new("POLY")
            spline.points.add(len(line) - 1)
            co = np.ones((len(line), 4))
            co[:, :3] = line
            spline.points.foreach_set("co", co.astype(np.float32).ravel())


# ---------------------------------------------------------------------------------------
# text and legend (meshes with a black colour attribute, so they read in renders)
# ---------------------------------------------------------------------------------------
def _text_mesh(body: str, name: str, size: float, mesh=None):
    """A mesh of ``body`` in the xy plane (height ~ size), black via its colour attribute."""
    font = bpy.data.curves.new(name + " font", "FONT")
    font.body = body
    font.size = size
    tmp = bpy.data.objects.new(name + " tmp", font)
    try:
        new = bpy.data.meshes.new_from_object(tmp)
    finally:
        bpy.data.objects.remove(tmp)
        bpy.data.curves.remove(font)
    if mesh is not None:
        # keep the data-block identity for idempotent updates
        verts = np.zeros(len(new.vertices) * 3)
        new.vertices.foreach_get("co", verts)
        loops = np.zeros(len(new.loops), dtype=np.int32)
        new.loops.foreach_get("vertex_index", loops)
        starts = np.zeros(len(new.polygons), dtype=np.int32)
        totals = np.zeros(len(new.polygons), dtype=np.int32)
        new.polygons.foreach_get("loop_start", starts)
        new.polygons.foreach_get("loop_total", totals)
        bpy.data.meshes.remove(new)
        mesh.clear_geometry()
        mesh.vertices.add(len(verts) // 3)
        mesh.vertices.foreach_set("co", verts)
        mesh.loops.add(len(loops))
        mesh.loops.foreach_set("vertex_index", loops)
        mesh.polygons.add(len(starts))
        mesh.polygons.foreach_set("loop_start", starts)
        mesh.update(calc_edges=True)
        new = mesh
    else:
        new.name = name
    for a in list(new.color_attributes):
        new.color_attributes.remove(a)
    attr = new.color_attributes.new(COLOUR_ATTRIBUTE, "FLOAT_COLOR", "POINT")
    black = np.zeros((len(new.vertices), 4), dtype=np.float32)
    black[:, 3] = 1.0
    attr.data.foreach_set("color", black.ravel())
    new.color_attributes.active_color = attr
    return new


def hub_legend_settings(settings: dict) -> dict:
    """The legend settings of an included hub (its own limits), from the review's."""
    return dict(settings, limits=settings["hub_limits"], clipped=settings.get("hub_clipped", 0.0), part="hub")


def _format(x: float) -> str:
    return f"{x:.3g}"


def legend_lines(settings: dict) -> tuple[str, list[tuple[float, str]]]:
    """Title and (position 0..1, label) ticks of the legend of ``settings``."""
    name, units = LABELS.get(settings["quantity"], (settings["quantity"], ""))
    lo, hi = settings["limits"]
    title = f"{name} ({units})"
    if settings.get("part"):
        title = f"{settings['part']} (own limits): {title}"
    if settings.get("quantity") == "zebra":
        title = f"{name} ({units})" + (f": {settings['sign_convention']}" if settings.get("sign_convention") else "")
    elif settings.get("percentile", 100) < 100:
        title += f", limits at the {settings['percentile']:g}th area percentile of |value|"
        title += f" ({100 * settings.get('clipped', 0):.1f}% of the area beyond)"
    if settings.get("quantity") != "zebra" and settings.get("sign_convention"):
        title += f"; {settings['sign_convention']}"
    ticks = [(t, _format(lo + t * (hi - lo))) for t in (0.0, 0.25, 0.5, 0.75, 1.0)]
    if settings.get("quantity") == "zebra":
        ticks = [(0.0, "dark stripe"), (1.0, "light stripe")]
    return title, ticks


def build_legend(registry_or_collection, settings: dict, placement: Matrix, width: float, tag: str = "legend"):
    """Colour bar and labels laid out in the local xy plane of ``placement`` (bar from x = 0
    to ``width``, labels below, title above). Returns the objects."""
    registry = registry_or_collection if isinstance(registry_or_collection, _Registry) else None
    collection = registry.collection if registry else registry_or_collection
    h = LEGEND_BAR_HEIGHT * width
    n = 64
    x = np.linspace(0.0, width, n + 1)
    verts = np.concatenate([np.stack([x, np.zeros_like(x), np.zeros_like(x)], -1),
                            np.stack([x, np.full_like(x, h), np.zeros_like(x)], -1)])
    idx = np.arange(n)
    quads = np.stack([idx, idx + 1, idx + n + 2, idx + n + 1], -1)
    lo, hi = settings["limits"]
    values = np.tile(lo + (hi - lo) * x / width, 2)
    colours = colours_for(values, (lo, hi), settings.get("quantity", "mean"))
    objects = []

    def obtain(key, name, new_data):
        if registry:
            return registry.get(key, "MESH", name, new_data)
        obj = bpy.data.objects.new(name, new_data(name))
        collection.objects.link(obj)
        return obj

    prefix = "Review legend" if tag == "legend" else f"Review {tag}"
    bar = obtain((tag, "bar"), f"{prefix} bar", _new_mesh)
    _write_mesh(bar.data, verts, quads, colours)
    bar.matrix_world = placement
    objects.append(bar)
    title, ticks = legend_lines(settings)
    size = LEGEND_TEXT_SIZE * width
    texts = [(title, Matrix.Translation((0.0, h + 0.35 * size, 0.0)))]
    for t, label in ticks:
        x = t * width - 0.27 * size * len(label)  # centred on its tick, kept inside the bar's ends
        x = min(max(x, 0.0), width - 0.54 * size * len(label))
        texts.append((label, Matrix.Translation((x, -1.0 * size, 0.0))))
    for i, (body, offset) in enumerate(texts):
        obj = obtain((tag, "text", i), f"{prefix} text {i}", None if registry else (lambda nm: None))
        if obj.type != "MESH" or obj.data is None:
            # a fresh object without data: give it a text mesh (objects cannot change type)
            bpy.data.objects.remove(obj)
            mesh = _text_mesh(body, f"{prefix} text {i}", size)
            obj = bpy.data.objects.new(f"{prefix} text {i}", mesh)
            if registry:
                obj[ROLE_KEY] = json.dumps([tag, "text", i])
                registry.existing[(tag, "text", i)] = obj
            collection.objects.link(obj)
        else:
            _text_mesh(body, obj.name, size, mesh=obj.data)
        obj.matrix_world = placement @ offset
        objects.append(obj)
    return objects


# ---------------------------------------------------------------------------------------
# the review
# ---------------------------------------------------------------------------------------
def review_sources(objects) -> list:
    """CURVE and SURFACE objects to review: the given ones, and the descendants of given
    Empties (a propeller's root), in a stable order without repeats."""
    out, seen = [], set()

    def add(obj):
        if obj.name in seen:
            return
        seen.add(obj.name)
        if obj.type in {"CURVE", "SURFACE"}:
            out.append(obj)
        if obj.type == "EMPTY":
            for child in sorted(obj.children, key=lambda o: o.name):
                add(child)

    for obj in objects:
        add(obj)
    return out


def _collection_objects(name: str) -> list:
    if not name:
        return []
    obj = bpy.data.objects.get(name)
    if obj is not None:
        return [obj]
    coll = bpy.data.collections.get(name)
    if coll is not None:
        return sorted(coll.all_objects, key=lambda o: o.name)
    raise GeometryError(f"reference {name!r} is neither an object nor a collection")


@dataclass
class ReviewOptions:
    """Options of :func:`review_objects` (the operator's properties)."""

    quantity: str = "mean"
    percentile: float = DEFAULT_PERCENTILE
    limit: float = 0.0
    samples_per_span: int = DEFAULT_SAMPLES_PER_SPAN
    convex_positive: bool = True
    comb_lines: int = 2
    comb_teeth: int = 100
    comb_scale: float = 0.0
    comb_sign: float = 1.0
    envelope: bool = True
    iso_lines: int = 11
    quadrature_points: int = REVIEW_QUADRATURE_POINTS
    numbers: bool = True
    legend: bool = True
    reference: str = ""
    spacing: float = 0.0
    include_hub: bool = False


@dataclass
class ReviewResult:
    maps: list = field(default_factory=list)
    combs: list = field(default_factory=list)
    numbers: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)
    times: dict = field(default_factory=dict)


def colours_for(values, limits, quantity: str) -> np.ndarray:
    """sRGB RGBA of ``values``: sequential from 0 for quantities that are never negative,
    black and white stripes for zebra, diverging about 0 otherwise."""
    if quantity == "zebra":
        return zebra_colours(values)
    if quantity in NON_NEGATIVE:
        return sequential_colours(values, limits)
    return diverging_colours(values, limits)


def is_hub(obj) -> bool:
    """A propeller's hub (or hub sector): excluded from the colour limits by default, its
    curvature (nose, tail) would set them and wash the blade out."""
    return obj is not None and obj.get("bladesmith_part") == "hub"


def _zebra_frame(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(view direction, stripe axis) for zebra stripes over all reviewed points: looking
    along the direction of smallest extent; the stripe axis is the middle one (a blade's
    chord, across which its normals turn), so the stripes run along the largest (span)."""
    centre = points.mean(axis=0)
    _, _, Vt = np.linalg.svd(points - centre, full_matrices=False)
    return -Vt[2], Vt[1]


def _geometry(obj):
    try:
        return object_to_geometry(obj)
    except GeometryError as error:
        raise GeometryError(f"{obj.name}: {error}") from None


def review_objects(scene, objects, options: ReviewOptions | None = None, **kwargs) -> ReviewResult:
    """Review ``objects`` (see the module docstring) into the review collection of
    ``scene``; returns the numbers, settings and stage times. Raises BladesmithError
    (nothing is created then) for unusable input."""
    opt = options or ReviewOptions(**kwargs)
    if opt.quantity not in LABELS or opt.quantity == "deviation":
        raise GeometryError(f"unknown quantity {opt.quantity!r}")
    clock = time.perf_counter()
    times = {}
    sources = review_sources(objects)
    references = review_sources(_collection_objects(opt.reference))
    references = [r for r in references if r.name not in {s.name for s in sources}]
    if not sources:
        raise GeometryError("nothing to review: select curve or surface objects (or a propeller)")
    sign = -1.0 if opt.convex_positive else 1.0  # convex (outward normals) positive
    # ---- compute (bpy-free work; nothing is created until everything succeeded)
    groups = {}  # data -> [objects] (linked duplicates share one review)
    for obj in sources + references:
        groups.setdefault(obj.data.name + "\0" + obj.type, []).append(obj)
    computed = []  # (role, owner object, duplicates, surface or curve, index, map)
    for key, objs in groups.items():
        owner = objs[0]
        role = "reference" if owner in references else "source"
        for index, entity in enumerate(_geometry(owner)):
            if isinstance(entity, BSplineSurface):
                if entity.dim != 3:
                    continue
                m = surface_map(entity, "mean" if opt.quantity == "zebra" else opt.quantity, opt.samples_per_span, sign)
                computed.append((role, owner, objs, entity, index, m))
            elif isinstance(entity, BSplineCurve) and role == "source":
                computed.append((role, owner, objs, entity, index, None))
    times["maps"] = time.perf_counter() - clock
    if opt.quantity == "zebra" and any(c[5] is not None for c in computed):
        from dataclasses import replace

        pts = np.concatenate([c[5].points.reshape(-1, 3) @ np.array(c[1].matrix_world)[:3, :3].T for c in computed
                              if c[5] is not None])
        view, axis = _zebra_frame(pts)
        for k, c in enumerate(computed):
            if c[5] is None:
                continue
            R = np.array(c[1].matrix_world)[:3, :3]
            normals = c[5].curvature.normal @ R.T
            normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
            computed[k] = c[:5] + (replace(c[5], values=zebra_values(normals, view, axis), quantity="zebra"),)
    maps = [c for c in computed if c[5] is not None]
    # the hub's curvature (nose, tail, fillets) would set the limits and wash the blade
    # out: the blade alone sets them; an included hub gets limits of its own
    counted = [c for c in maps if not is_hub(c[1])] or maps
    hubs = [c for c in maps if c not in counted]
    excluded = [] if opt.include_hub else sorted({c[1].name for c in hubs})
    own = hubs if opt.include_hub else []
    limits, clipped = _colour_limits(counted, opt)
    hub_limits, hub_clipped = _colour_limits(own, opt) if own else (None, 0.0)
    # combs: iso lines of surfaces and the curves themselves, one scale for all
    raw_combs = []
    teeth = max(int(opt.comb_teeth), 2)
    for role, owner, objs, entity, index, m in computed:
        if role != "source":
            continue
        if m is None:
            raw_combs.append((owner, curvature_comb(entity, teeth, scale=1.0, sign=opt.comb_sign)))
        elif opt.comb_lines > 0:
            for direction, (lo, hi) in (("u", entity.domain_u), ("v", entity.domain_v)):
                for value in np.linspace(lo, hi, opt.comb_lines + 2)[1:-1]:
                    raw_combs.append((owner, iso_line_comb(entity, direction, float(value), teeth, scale=1.0,
                                                           sign=opt.comb_sign * (1 if sign > 0 else -1))))
    size = _world_size([c[1] for c in computed])
    scale = opt.comb_scale if opt.comb_scale > 0 else comb_scale([c.curvature for _, c in raw_combs], size) if raw_combs else 0.0
    times["combs"] = time.perf_counter() - clock - times["maps"]
    numbers = {}
    if opt.numbers:
        for role, owner, objs, entity, index, m in maps:
            label = f"{owner.name}" + (f" [{index}]" if index else "")
            numbers[(owner.name, index)] = surface_numbers(
                entity, label, curvature=m.curvature, iso_lines=opt.iso_lines,
                quadrature_points=opt.quadrature_points)
    times["numbers"] = time.perf_counter() - clock - times["maps"] - times["combs"]
    deviation = {}
    spacing = opt.spacing if opt.spacing > 0 else 1.2 * size
    if references:
        # one KD-tree per reference surface; each map coarse to fine (signed_deviation_grid)
        ref_seeds = [DeviationSeeds(c[3]) for c in maps if c[0] == "reference"]
        for c in maps:
            if c[0] != "source":
                continue
            best = None
            for seeds in ref_seeds:
                d = signed_deviation_grid(c[5].points, seeds.surface, seeds)
                best = d if best is None else np.where(np.abs(d) < np.abs(best), d, best)
            deviation[(c[1].name, c[4])] = best.reshape(c[5].values.shape)
    times["comparison"] = time.perf_counter() - clock - sum(times.values())
    # ---- write Blender objects
    write_clock = time.perf_counter()
    coll = review_collection(scene)
    registry = _Registry(coll)
    result = ReviewResult(settings={"quantity": opt.quantity, "limits": list(limits), "percentile": opt.percentile
                                    if opt.limit <= 0 else 100.0, "clipped": clipped, "sign": sign,
                                    "comb_scale": scale, "sources": [s.name for s in sources],
                                    "reference": opt.reference, "excluded_from_limits": excluded,
                                    "samples_per_span": opt.samples_per_span,
                                    "sign_convention": sign_convention(opt.quantity, opt.convex_positive)})
    if hub_limits is not None:
        # an included hub: coloured on its own limits, drawn in its own panel and legend
        result.settings.update(hub=sorted({c[1].name for c in own}), hub_limits=list(hub_limits),
                               hub_clipped=hub_clipped)
    shift = {"source": Vector((0.0, 0.0, 0.0)), "reference": Vector((-spacing, 0.0, 0.0))}
    result.settings["spacing"] = spacing
    # one colour scale for every deviation map, so they compare with each other
    # (a hub's deviation, like its curvature, does not set the blade's scale)
    blade_dev = [d for (name, _), d in deviation.items() if not is_hub(bpy.data.objects.get(name))]
    dlim = symmetric_limits(blade_dev or list(deviation.values()), 100.0) if deviation else None
    if dlim is not None:
        result.settings["deviation_limits"] = list(dlim)
    for role, owner, objs, entity, index, m in maps:
        offset = DISPLAY_OFFSET_FRACTION * max(entity.size(), 1e-12)
        verts = (m.points + offset * m.curvature.normal).reshape(-1, 3)
        quads = m.quads()
        colours = colours_for(m.values.ravel(), hub_limits if hub_limits is not None and is_hub(owner) else limits,
                              opt.quantity)
        first = None
        for k, obj in enumerate(objs):
            name = f"{obj.name} map" + (f" {index}" if index else "")
            key = ("map", role, obj.name, index)
            if first is None:
                target = registry.get(key, "MESH", name, _new_mesh)
                _write_mesh(target.data, verts, quads, colours, m.values.ravel())
                first = target
                n = numbers.get((owner.name, index))
                target[NUMBERS_KEY] = json.dumps(n.as_dict()) if n is not None else "{}"
            else:
                target = registry.get(key, "MESH", name, _new_mesh)
                if target.data is not first.data:
                    old = target.data
                    target.data = first.data
                    if old.users == 0:
                        bpy.data.meshes.remove(old)
            target.matrix_world = Matrix.Translation(shift[role]) @ obj.matrix_world
            result.maps.append(target)
        dev = deviation.get((owner.name, index))
        if dev is not None:
            target = registry.get(("deviation", owner.name, index), "MESH", f"{owner.name} deviation", _new_mesh)
            _write_mesh(target.data, verts, quads, diverging_colours(dev.ravel(), dlim), dev.ravel())
            target["bladesmith_deviation_limits"] = list(dlim)
            target.matrix_world = Matrix.Translation((spacing, 0.0, 0.0)) @ owner.matrix_world
            result.maps.append(target)
            result.settings.setdefault("deviation_max", 0.0)
            result.settings["deviation_max"] = max(result.settings["deviation_max"], float(np.max(np.abs(dev))))
    by_owner = {}
    for owner, comb in raw_combs:
        by_owner.setdefault(owner.name, (owner, []))[1].append(comb)
    for name, (owner, combs) in by_owner.items():
        scaled = [_rescale(c, scale) for c in combs]
        target = registry.get(("combs", name), "CURVE", f"{name} combs", _new_comb_curve)
        _write_combs(target.data, scaled, COMB_BEVEL_FRACTION * size, opt.envelope)
        target.matrix_world = owner.matrix_world
        result.combs.append(target)
    if opt.legend and maps:
        lo_corner, hi_corner = _world_bounds([c[1] for c in computed])
        width = 0.6 * size
        placement = Matrix.Translation((lo_corner[0], lo_corner[1], lo_corner[2] - 0.15 * size)) @ Matrix.Rotation(
            math.pi / 2, 4, "X")
        build_legend(registry, result.settings, placement, width)
        if hub_limits is not None:
            build_legend(registry, hub_legend_settings(result.settings),
                         Matrix.Translation((0.0, 0.0, -0.12 * size)) @ placement, width, tag="hub legend")
    registry.prune()
    coll[SETTINGS_KEY] = json.dumps(result.settings)
    result.numbers = {f"{k[0]}" + (f" [{k[1]}]" if k[1] else ""): v for k, v in numbers.items()}
    times["write"] = time.perf_counter() - write_clock
    times["total"] = time.perf_counter() - clock
    result.times = times
    return result


def _colour_limits(maps, opt: ReviewOptions) -> tuple[tuple, float]:
    """Colour limits of the computed ``maps`` (zebra 0..1, 0..hi for never-negative
    quantities, symmetric otherwise; ``opt.limit`` or the area percentile) and the
    fraction of their area beyond them."""
    values = [c[5].values for c in maps]
    if not values:
        return (-1.0, 1.0), 0.0
    areas = [c[5].vertex_areas() for c in maps]
    if opt.quantity == "zebra":
        limits = (0.0, 1.0)
    elif opt.quantity in NON_NEGATIVE:
        limits = (0.0, opt.limit) if opt.limit > 0 else upper_limit(values, opt.percentile, areas)
    else:
        limits = (-opt.limit, opt.limit) if opt.limit > 0 else symmetric_limits(values, opt.percentile, areas)
    v_all = np.concatenate([v.ravel() for v in values])
    a_all = np.concatenate([a.ravel() for a in areas])
    outside = (v_all < limits[0]) | (v_all > limits[1])
    return limits, float(a_all[outside].sum() / max(a_all.sum(), 1e-300))  # fraction of the area


def _rescale(comb, scale: float):
    from dataclasses import replace

    teeth = comb.points - (comb.sign * scale * comb.curvature)[:, None] * comb.reference
    return replace(comb, teeth=teeth, scale=scale)


def _world_bounds(objects):
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for obj in objects:
        M = np.array(obj.matrix_world)
        corners = np.array([list(c) + [1.0] for c in obj.bound_box]) @ M.T
        lo = np.minimum(lo, corners[:, :3].min(axis=0))
        hi = np.maximum(hi, corners[:, :3].max(axis=0))
    if not np.all(np.isfinite(lo)):
        return np.zeros(3), np.ones(3)
    return lo, hi


def _world_size(objects) -> float:
    lo, hi = _world_bounds(objects)
    return float(max(np.linalg.norm(hi - lo), 1e-9))


# ---------------------------------------------------------------------------------------
# the review image
# ---------------------------------------------------------------------------------------
def _look_at(position: np.ndarray, target: np.ndarray, up: np.ndarray) -> Matrix:
    forward = target - position
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    R = np.column_stack([right, true_up, -forward])
    M = Matrix.Identity(4)
    for i in range(3):
        for j in range(3):
            M[i][j] = R[i, j]
        M[i][3] = position[i]
    return M


def _map_points(maps) -> tuple[np.ndarray, np.ndarray, list]:
    """World points and normals of the map meshes (sampled), and each map's mean normal."""
    P, N, means = [], [], []
    for obj in maps:
        mesh = obj.data
        co = np.zeros(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", co)
        co = co.reshape(-1, 3).astype(np.float64)[::7]
        nrm = np.zeros(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("normal", nrm)
        nrm = nrm.reshape(-1, 3).astype(np.float64)[::7]
        M = np.array(obj.matrix_world)
        P.append(co @ M[:3, :3].T + M[:3, 3])
        n = nrm @ M[:3, :3].T
        N.append(n)
        means.append(n.mean(axis=0))
    return np.concatenate(P), np.concatenate(N), means


def _orthonormal_views(P: np.ndarray, span: np.ndarray, side: np.ndarray, names) -> list[dict]:
    """Pressure/suction views along ±side (orthogonalised against span, which is up) and a
    three-quarter tip close-up, framed on the points P (world)."""
    span = span / np.linalg.norm(span)
    side = side - span * np.dot(side, span)
    side /= np.linalg.norm(side)
    chord = np.cross(side, span)
    proj_s, proj_c = P @ span, P @ chord
    ext_s, ext_c = np.ptp(proj_s), np.ptp(proj_c)
    mid = span * 0.5 * (proj_s.max() + proj_s.min()) + chord * 0.5 * (proj_c.max() + proj_c.min())
    mid = mid + side * np.mean(P @ side)
    scale = 1.3 * max(ext_s, ext_c)  # room for the LE/TE/root/tip labels outside the blade
    dist = 4.0 * scale
    tip_point = P[np.argmax(proj_s)]
    tip_centre = tip_point - span * 0.12 * ext_s
    tip_dir = side * 0.9 + span * 0.35
    tip_dir /= np.linalg.norm(tip_dir)
    return [
        {"title": names[0], "matrix": _look_at(mid + side * dist, mid, span), "ortho_scale": scale},
        {"title": names[1], "matrix": _look_at(mid - side * dist, mid, span), "ortho_scale": scale},
        {"title": "tip close-up" if names[0] == "pressure side" else "close-up (far end)",
         "matrix": _look_at(tip_centre + tip_dir * dist, tip_centre, span),
         "ortho_scale": 0.4 * max(ext_s, ext_c)},
    ]


def review_views(maps) -> list[dict]:
    """The three fixed views: pressure side, suction side and a tip close-up.

    For a Bladesmith propeller blade (maps of objects tagged ``bladesmith_part = "blade"``
    under a root Empty) the span is the radial direction from the root's axis (its local
    z) and the side the mean normal of the pressure surface (patch 0). Otherwise: span is
    the principal axis of largest extent, the side the one of smallest, named front/back."""
    def source_of(obj):
        key = _role(obj)
        return bpy.data.objects.get(key[2]) if key and key[0] == "map" else None

    # frame the reference blade when the maps are a Bladesmith propeller's (copies and hub
    # still show in the views; they are rendered, only not framed)
    blade = [o for o in maps if source_of(o) is not None and source_of(o).get("bladesmith_part") == "blade"
             and int(source_of(o).get("bladesmith_blade", 0)) == 0]
    P, _, _ = _map_points(blade or maps)
    for obj in blade or maps:
        key = _role(obj)
        source = bpy.data.objects.get(key[2]) if key and key[0] == "map" else None
        if source is None or source.get("bladesmith_part") != "blade" or source.get("bladesmith_patch") != 0:
            continue
        root = source.parent
        M = np.array(root.matrix_world) if root is not None else np.eye(4)
        axis, origin = M[:3, 2] / np.linalg.norm(M[:3, 2]), M[:3, 3]
        radial = P.mean(axis=0) - origin
        radial -= axis * np.dot(radial, axis)
        side = _map_points([obj])[2][0]
        return _orthonormal_views(P, radial, side, ("pressure side", "suction side"))
    centre = P.mean(axis=0)
    _, _, Vt = np.linalg.svd(P - centre, full_matrices=False)
    return _orthonormal_views(P, Vt[0], Vt[2], ("front", "back"))


def _render(scene, path: str) -> None:
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True, scene=scene.name)


def _read_png(path: str) -> np.ndarray:
    img = bpy.data.images.load(path, check_existing=False)
    try:
        w, h = img.size
        px = np.zeros(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(px)
        return px.reshape(h, w, 4)
    finally:
        bpy.data.images.remove(img)


def _write_png(pixels: np.ndarray, path: str) -> None:
    h, w = pixels.shape[:2]
    img = bpy.data.images.new("bladesmith review composite", w, h, alpha=False)
    try:
        img.pixels.foreach_set(pixels.astype(np.float32).ravel())
        folder = os.path.dirname(os.path.abspath(path))
        fd, tmp = tempfile.mkstemp(suffix=".png", dir=folder)
        os.close(fd)
        try:
            img.filepath_raw = tmp
            img.file_format = "PNG"
            img.save()
            os.chmod(tmp, 0o644)  # mkstemp makes it private; the image is for sharing
            os.replace(tmp, path)
        except BaseException:
            if os.path.exists(tmp):
                os.remove(tmp)
            raise
    finally:
        bpy.data.images.remove(img)


def _propeller_edges(maps) -> dict:
    """World positions of a Bladesmith propeller blade's LE and TE at mid-span, from its
    first surface (patch 0 of blade 0: the smoothed blade's pressure_central, or the whole
    unsmoothed blade): u runs along +ξ from the trailing edge (ξ = 0) to the leading edge
    (ξ = 1/2) on either hand (geometry/propeller/blade.py)."""
    for obj in maps:
        src = _source_of(obj)
        if src is None or src.get("bladesmith_part") != "blade" or src.get("bladesmith_patch") != 0 \
                or int(src.get("bladesmith_blade", 0)) != 0:
            continue
        surfaces = [e for e in object_to_geometry(src) if isinstance(e, BSplineSurface)]
        if not surfaces:
            return {}
        S = surfaces[0]
        (u0, u1), (v0, v1) = S.domain_u, S.domain_v
        v = 0.5 * (v0 + v1)
        M = np.array(src.matrix_world)
        pts = np.array([S.evaluate(u1, v), S.evaluate(u0, v)]).reshape(2, -1)[:, :3]
        if np.linalg.norm(pts[0] - pts[1]) <= 1e-9 * max(S.size(), 1e-12):
            # the unsmoothed blade is one surface around the section, TE -> LE (ξ = 1/2) -> TE
            pts[0] = np.asarray(S.evaluate(0.5 * (u0 + u1), v)).reshape(-1)[:3]
        world = pts @ M[:3, :3].T + M[:3, 3]
        return {"LE": world[0], "TE": world[1]}
    return {}


def _source_of(obj):
    key = _role(obj)
    return bpy.data.objects.get(key[2]) if key and key[0] == "map" else None


def _root_of(obj):
    while obj is not None and obj.parent is not None:
        obj = obj.parent
    return obj


def _roots(maps) -> list:
    out = []
    for m in maps:
        root = _root_of(_source_of(m))
        if root is not None and root not in out:
            out.append(root)
    return out


def _propeller_settings(root):
    """The propeller property group of a Bladesmith propeller root, else None (without
    touching the group of other objects: reading it would store an empty one on them)."""
    if "bladesmith_propeller" not in root.keys():
        return None
    settings = getattr(root, "bladesmith_propeller", None)
    return settings if settings is not None and settings.is_propeller else None


def _described(root) -> tuple[str, str]:
    """(name, state) of a root: a propeller's definition name with its preset, and
    "tip smoothed" or "unsmoothed"; other roots: their name and ""."""
    s = _propeller_settings(root)
    if s is None:
        return root.name, ""
    from .propeller import PRESET_DIR

    name = s.definition_name or root.name
    source = pathlib.Path(s.source_path) if s.source_path else None
    if source is not None and source.parent.resolve() == PRESET_DIR.resolve():
        name += f" (preset {source.stem.upper()})"
    return name, "tip smoothed" if s.smooth_tip else "unsmoothed"


def default_title(maps, before=()) -> str:
    """The reviewed objects: their roots' names (a propeller with its preset and whether
    it is tip smoothed; a wind blade, an impeller); with ``before`` (the reference's
    maps) "name: before <state>, after <state>"."""
    after = [_described(r) for r in _roots(maps)]
    if before:
        ref = [_described(r) for r in _roots(before)]
        names = list(dict.fromkeys(n for n, _ in ref + after))
        state = lambda items: " + ".join(dict.fromkeys(st or n for n, st in items))  # noqa: E731
        return f"{', '.join(names[:2])}: before {state(ref)}, after {state(after)}"
    names = [n + (f", {st}" if st else "") for n, st in after]
    return ", ".join(names[:4]) + (f" and {len(names) - 4} more" if len(names) > 4 else "")


def smoothing_line(maps, before=()) -> str:
    """The tip-smoothing settings (Hally 2013 symbols, lengths as fractions of D) of the
    smoothed propellers among the reviewed roots (and the reference's), or ""."""
    lines = []
    for root in _roots(maps) + _roots(before):
        s = _propeller_settings(root)
        if s is None or not s.smooth_tip:
            continue
        text = (f"tip smoothing: delta_c {s.delta_c:g} D, d_t {s.tip_smoothing_distance:g} D, "
                f"d_e {s.edge_smoothing_distance:g} D, s_j {s.transition_s:g}, alpha {s.filter_strength:g}, "
                f"n {s.filter_iterations}, d {s.sample_spacing:g} D, h/d {s.edge_spacing_ratio:g}, "
                f"tolerance {s.tolerance:g} D")
        if text not in lines:
            lines.append(text)
    return "; ".join(lines)


def _settings_line(settings: dict) -> str:
    name, units = LABELS.get(settings["quantity"], (settings["quantity"], ""))
    lo, hi = settings["limits"]
    parts = [f"{name}", f"colour limits [{lo:.3g}, {hi:.3g}] {units}" if settings["quantity"] != "zebra" else "",
             "" if settings["quantity"] == "zebra" else
             f"{settings['percentile']:g}th area percentile" if settings.get("percentile", 100) < 100 else "fixed limits",
             f"{settings.get('samples_per_span', DEFAULT_SAMPLES_PER_SPAN)} samples per knot span"]
    if settings.get("excluded_from_limits"):
        parts.append("hub not counted in the limits (and not drawn)")
    if settings.get("hub_limits"):
        lo, hi = settings["hub_limits"]
        parts.append(f"hub: own panel and limits [{lo:.3g}, {hi:.3g}]")
    return "; ".join(p for p in parts if p)


def _wind_views(maps, panel_px: int) -> list[dict] | None:
    """A long blade (span over 3 chords) in span segments, per side: each segment a strip
    that fills the image's width, span running left (root) to right (tip)."""
    P, _, means = _map_points(maps)
    centre = P.mean(axis=0)
    _, sv, Vt = np.linalg.svd(P - centre, full_matrices=False)
    span, side = Vt[0], Vt[2]
    chord = np.cross(side, span)
    ps, pc = P @ span, P @ chord
    # root to the left: the root is the thicker end (largest extent along side)
    ends = [np.ptp((P @ side)[np.abs(ps - e) < 0.05 * np.ptp(ps)]) for e in (ps.min(), ps.max())]
    if ends[1] > ends[0]:
        span, chord = -span, -chord
        ps, pc = -ps, -pc
    count = segment_count(float(np.ptp(ps)), float(np.ptp(pc)))
    if count < 2:
        return None
    segments = span_segments(P, span, count)
    width_px = 3 * panel_px
    views = []
    for side_sign, name in ((1.0, "side A"), (-1.0, "side B")):
        # name the side after the mould part that faces the camera (outward normals)
        facing = [(float(np.dot(m, side_sign * side)), _source_of(o)) for o, m in zip(maps, means)]
        best = max(facing, key=lambda f: f[0])[1] if facing else None
        if best is not None and best.get("bladesmith_mold_part"):
            name = f"{str(best['bladesmith_mold_part']).replace('_', ' ')} side"
        for k, (a, b) in enumerate(segments):
            length = (b - a) * 1.04
            mid_s = 0.5 * (a + b)
            in_seg = (ps >= a) & (ps <= b)
            c_lo, c_hi = pc[in_seg].min(), pc[in_seg].max()
            height = max(c_hi - c_lo, 1e-9) * 1.25
            target = span * mid_s + chord * 0.5 * (c_lo + c_hi) + side * float(np.mean(P @ side))
            height_px = int(np.clip(round(width_px * height / length), 60, width_px))
            dist = 4.0 * length
            views.append({"title": f"{name}, span {k + 1}/{count}" if k == 0 else f"span {k + 1}/{count}",
                          # up = ±chord keeps the root on the left seen from either side
                          "matrix": _look_at(target + side_sign * side * dist, target, side_sign * chord),
                          "ortho_scale": length,
                          "resolution": (width_px, height_px), "span": span, "side": side * side_sign,
                          "row": True})
    return views


def _hub_view(hub_maps, width_px: int, panel_px: int) -> dict:
    """A side view of a propeller hub: looking at it across its axis (the root Empty's
    local z, drawn left to right) from the side of the reference blade, in a strip of the
    image's width, framed on the hub's maps."""
    P, _, _ = _map_points(hub_maps)
    root = _root_of(_source_of(hub_maps[0]))
    M = np.array(root.matrix_world) if root is not None else np.eye(4)
    axis = M[:3, 2] / np.linalg.norm(M[:3, 2])
    centre = P.mean(axis=0)
    radial = centre - M[:3, 3]
    radial -= axis * np.dot(radial, axis)
    if np.linalg.norm(radial) < 1e-9 * np.ptp(P @ axis):  # a whole hub: any side
        radial = M[:3, 0] - axis * np.dot(M[:3, 0], axis)
    radial /= np.linalg.norm(radial)
    up = np.cross(radial, axis)
    ext_h, ext_v = np.ptp(P @ axis), np.ptp(P @ up)
    mid = axis * 0.5 * ((P @ axis).max() + (P @ axis).min()) + up * 0.5 * ((P @ up).max() + (P @ up).min()) \
        + radial * float(np.mean(P @ radial))
    res_x = int(width_px)
    res_y = int(np.clip(round(res_x * 1.35 * ext_v / max(1.15 * ext_h, 1e-12)), panel_px // 2, panel_px))
    scale = max(1.15 * ext_h, 1.35 * ext_v * res_x / res_y)
    return {"title": "hub, on its own colour limits (legend below)", "centre": mid,
            "matrix": _look_at(mid + radial * 4.0 * scale, mid, up), "ortho_scale": scale,
            "resolution": (res_x, res_y), "row": True}


def _overlay_objects(view, landmarks: dict, centre: np.ndarray, made_meshes: list, tag: str) -> list:
    """Text and scale bar objects for one panel: the view's title, LE/TE/root/tip labels
    and a scale bar, all in the camera's plane in front of the maps."""
    M = np.array(view["matrix"])
    right, up, back = M[:3, 0], M[:3, 1], M[:3, 2]
    res_x, res_y = view.get("resolution", (1, 1))
    s = view["ortho_scale"]
    half_w = 0.5 * s
    half_h = half_w * res_y / res_x
    size = 0.013 * s if view.get("row") else 0.05 * s  # the same height in pixels on every strip
    cam_pos = M[:3, 3]
    cam_centre = cam_pos - back * np.dot(cam_pos - centre, back)  # the view centre in the map's depth
    front = back * (0.5 * s)

    def placed(anchor, dx=0.0, dy=0.0):
        R = Matrix(M)
        p = anchor + front + right * dx + up * dy
        R[0][3], R[1][3], R[2][3] = p
        return R

    out = []

    def text(body, anchor, dx, dy, name):
        mesh = _text_mesh(body, f"{tag} {name}", size)
        made_meshes.append(mesh)
        obj = bpy.data.objects.new(f"{tag} {name}", mesh)
        obj.matrix_world = placed(anchor, dx, dy)
        out.append(obj)

    text(view["title"], cam_centre, -half_w + 0.03 * s, half_h - 1.4 * size, "title")
    for name, point in landmarks.items():
        d = point - centre
        screen = np.array([np.dot(d, right), np.dot(d, up)])
        n = np.linalg.norm(screen)
        screen = screen / n if n > 0 else np.array([0.0, 1.0])
        offset = screen * 2.2 * size
        if name == "tip" and not view.get("row"):
            offset = np.array([1.0 * size, 0.4 * size])  # beside the tip, clear of the panel's title
            text(name, point, offset[0], offset[1], name)
            continue
        text(name, point, offset[0] - 0.3 * size * len(name), offset[1] - 0.35 * size, name)
    # scale bar in the lower left corner
    length = nice_length(0.22 * 2 * half_w)
    bar_h = 0.18 * size
    x0 = -half_w + 0.04 * s
    y0 = -half_h + 0.6 * size
    verts = np.array([[0, 0, 0], [length, 0, 0], [length, bar_h, 0], [0, bar_h, 0]], dtype=np.float64)
    mesh = bpy.data.meshes.new(f"{tag} scale bar")
    made_meshes.append(mesh)
    black = np.tile([0.0, 0.0, 0.0, 1.0], (4, 1))
    _write_mesh(mesh, verts, np.array([[0, 1, 2, 3]]), black)
    bar = bpy.data.objects.new(f"{tag} scale bar", mesh)
    bar.matrix_world = placed(cam_centre, x0, y0)
    out.append(bar)
    text(length_label(length), cam_centre, x0, y0 + bar_h + 0.25 * size, "scale label")
    return out


def render_review_image(objects, filepath: str, *, panel_size: int = 480, legend_height: int = 150,
                        scene=None, review: bool = True, samples: str = "8", title: str = "",
                        **review_options) -> dict:
    """Write a PNG review image of the curvature maps of ``objects``.

    Top: a title strip (``title``, default the reviewed roots' names; the quantity, colour
    limits, percentile and sampling; its sign convention; what the thin grey lines are).
    Middle: Workbench views with LE/TE/root/tip labels (blades) and a scale bar each:
    pressure side, suction side and tip close-up for a propeller blade, front, back and
    a close-up otherwise; a blade longer than three chords (a wind blade) is drawn in
    span segments stacked as strips that fill the width. With a reference (the review's
    ``reference``) every view shows before | after | deviation side by side, before and
    after on the same colour limits. Bottom: the legend(s).

    ``review``: run :func:`review_objects` first (with ``review_options``), else use the
    maps already in the review collection. The render happens in a temporary scene that
    holds only linked copies of the maps (the user's scene, its objects, camera and
    settings are untouched) and is removed afterwards with everything made for it. The
    file is written atomically. Returns {"filepath", "views", "times"}."""
    scene = scene or bpy.context.scene
    clock = time.perf_counter()
    times = {}
    if review:
        review_objects(scene, objects, **review_options)
    coll = review_collection(scene, create=False)
    if coll is None:
        raise GeometryError("no curvature review to render: run the review first")
    settings = json.loads(coll.get(SETTINGS_KEY, "{}"))
    roles = [(o, _role(o) or ("",)) for o in coll.objects]
    maps = [o for o, r in roles if r[0] == "map" and r[1] == "source"]
    if not maps:
        raise GeometryError("the review has no surface maps to render")
    # a propeller's hub is not drawn when it does not count for the limits: clipped, it
    # would only hide the blade root
    hub_hidden = bool(settings.get("excluded_from_limits"))
    # an included hub has limits of its own: it gets its own panel and legend below the
    # blade's, which keep the blade's limits
    hub_maps = []
    if settings.get("hub_limits"):
        hub_maps = [o for o in maps if is_hub(_source_of(o))]
        hub_hidden = hub_hidden or bool(hub_maps)
    if hub_hidden:
        maps = [o for o in maps if not is_hub(_source_of(o))] or maps
    # a propeller's other blades are linked copies of the reference blade: same colours,
    # and in the framed views they would only cover its root
    maps = [o for o in maps if _source_of(o) is None or int(_source_of(o).get("bladesmith_blade", 0)) == 0] or maps
    before = [o for o, r in roles if r[0] == "map" and r[1] == "reference"]
    after_dev = [o for o, r in roles if r[0] == "deviation"
                 and not (hub_hidden and is_hub(bpy.data.objects.get(r[1]) if len(r) > 1 else None))]
    columns = [("", maps, 0.0)]
    if hub_hidden:
        before = [o for o in before if not is_hub(_source_of(o))]
    if before and after_dev:
        spacing = float(settings.get("spacing", 0.0))
        columns = [("before", before, -spacing), ("after", maps, 0.0), ("deviation", after_dev, spacing)]
    times["review"] = time.perf_counter() - clock
    framed = [o for o in maps if not is_hub(_source_of(o))] or maps
    wind = any(_source_of(o) is not None and _source_of(o).get("bladesmith_mold_part") is not None for o in maps)
    views = _wind_views(framed, panel_size) if wind else None
    if views is None:
        views = review_views(maps)
        if len(columns) > 1:
            views = views[:2]  # pressure and suction sides (or front and back), each before | after | deviation
    # landmarks of the reference blade only (a propeller's copies are rendered, not labelled)
    blade0 = [o for o in framed if _source_of(o) is not None and int(_source_of(o).get("bladesmith_blade", 0)) == 0]
    P, _, _ = _map_points(blade0 or framed)
    # labels only where root, tip and the edges are known to mean what they say: a wind
    # blade or a propeller blade (an impeller blade's hub and shroud edges are not a root
    # and a tip along one axis)
    blade_like = wind or any(
        _source_of(o) is not None and _source_of(o).get("bladesmith_part") == "blade" for o in maps)
    propeller_edges = _propeller_edges(maps)
    made_objects, made_meshes = [], []
    layout = {}  # pixel rows (from the top) of the hub's panel and the legends' limits
    temp = bpy.data.scenes.new("Bladesmith review render")
    world = bpy.data.worlds.new("Bladesmith review world")
    camera_data = bpy.data.cameras.new("Bladesmith review camera")
    folder = tempfile.mkdtemp(prefix="bladesmith_review_")
    try:
        world.color = (1.0, 1.0, 1.0)
        temp.world = world
        temp.render.engine = "BLENDER_WORKBENCH"
        shading = temp.display.shading
        # flat light keeps the map's colours true to the legend; the outline draws the
        # surfaces' (patches') boundaries. No cavity: its screen-space sampling is what
        # speckled the earlier images.
        shading.light = "FLAT"
        shading.color_type = "VERTEX"
        shading.show_object_outline = True
        shading.object_outline_color = (0.35, 0.35, 0.35)
        shading.show_cavity = False
        temp.display.render_aa = samples
        temp.view_settings.view_transform = "Standard"
        temp.view_settings.look = "None"
        temp.render.film_transparent = False
        temp.render.image_settings.file_format = "PNG"
        temp.render.image_settings.color_mode = "RGB"
        temp.render.resolution_percentage = 100
        cam = bpy.data.objects.new("Bladesmith review camera", camera_data)
        temp.collection.objects.link(cam)
        made_objects.append(cam)
        temp.camera = cam
        camera_data.type = "ORTHO"
        copies = {}
        for _, group, _ in columns:
            for obj in group:
                if obj.name not in copies:
                    copy = bpy.data.objects.new(obj.name + " render", obj.data)
                    copy.matrix_world = obj.matrix_world
                    made_objects.append(copy)
                    copies[obj.name] = copy
        for obj in hub_maps:
            copy = bpy.data.objects.new(obj.name + " render", obj.data)
            copy.matrix_world = obj.matrix_world
            made_objects.append(copy)
            copies[obj.name] = copy

        def clear_scene():
            for obj in list(temp.collection.objects):
                if obj is not cam:
                    temp.collection.objects.unlink(obj)

        rows = []  # each a list of panels (h, w, 4), drawn top to bottom
        # square views side by side in one row; strips (segments) or comparisons one row each
        one_row = not views[0].get("row") and len(columns) == 1
        for i, view in enumerate(views):
            res_x, res_y = view.get("resolution", (panel_size, panel_size))
            if len(columns) > 1 and view.get("row"):
                res_x //= len(columns)
                res_y = max(60, int(res_y / len(columns)))
            view = dict(view, resolution=(res_x, res_y))
            temp.render.resolution_x, temp.render.resolution_y = res_x, res_y
            s = view["ortho_scale"]
            camera_data.ortho_scale = s
            camera_data.clip_start = 1e-3 * s
            camera_data.clip_end = 100.0 * s
            span = view.get("span")
            if span is None:
                M = np.array(view["matrix"])
                span, side = M[:3, 1], M[:3, 2]
            else:
                side = view["side"]
            landmarks = blade_landmarks(P, span, side) if blade_like else {}
            if landmarks:
                landmarks.update(propeller_edges)
            centre = P.mean(axis=0)
            panels = []
            for c, (label, group, dx) in enumerate(columns):
                clear_scene()
                shift = np.array([dx, 0.0, 0.0])
                for obj in group:
                    temp.collection.objects.link(copies[obj.name])
                panel_view = dict(view, title=(f"{view['title']}: {label}" if label else view["title"]),
                                  matrix=Matrix.Translation(shift) @ view["matrix"])
                overlays = _overlay_objects(panel_view, {k: v + shift for k, v in landmarks.items()}, centre + shift,
                                            made_meshes, f"Bladesmith review {i}.{c}")
                for obj in overlays:
                    temp.collection.objects.link(obj)
                made_objects.extend(overlays)
                cam.matrix_world = panel_view["matrix"]
                path = os.path.join(folder, f"view{i}_{c}.png")
                _render(temp, path)
                panels.append(_read_png(path))
            if one_row and rows:
                rows[0].extend(panels)
            else:
                rows.append(panels)
        total_w = max(sum(p.shape[1] for p in row) for row in rows)
        hub_row = None
        if hub_maps:
            clear_scene()
            for obj in hub_maps:
                temp.collection.objects.link(copies[obj.name])
            hub_view = _hub_view(hub_maps, total_w, panel_size)
            temp.render.resolution_x, temp.render.resolution_y = hub_view["resolution"]
            camera_data.ortho_scale = hub_view["ortho_scale"]
            camera_data.clip_start = 1e-3 * hub_view["ortho_scale"]
            camera_data.clip_end = 100.0 * hub_view["ortho_scale"]
            overlays = _overlay_objects(hub_view, {}, hub_view["centre"], made_meshes, "Bladesmith review hub")
            for obj in overlays:
                temp.collection.objects.link(obj)
            made_objects.extend(overlays)
            cam.matrix_world = hub_view["matrix"]
            path = os.path.join(folder, "hub.png")
            _render(temp, path)
            hub_row = _read_png(path)
        times["views"] = time.perf_counter() - clock - times["review"]
        # legend(s) and title strip: their own small renders, far from the maps
        # the sign convention is in the heading; the legend keeps name, units and limits
        legends = [{k: v for k, v in settings.items() if k != "sign_convention"}]
        if len(columns) > 1 and settings.get("deviation_limits"):
            legends.append({"quantity": "deviation", "limits": settings["deviation_limits"], "percentile": 100.0,
                            "sign_convention": "positive: outside the reference"})
        if hub_row is not None:
            legends.append(hub_legend_settings(legends[0] | {"hub_limits": settings["hub_limits"]}))
        strips = []
        width = 1.0
        for k, legend_settings in enumerate(legends):
            clear_scene()
            legend_objs = build_legend(temp.collection, legend_settings, Matrix.Identity(4), width,
                                       tag=f"render legend {k}")
            made_objects.extend(legend_objs)
            made_meshes.extend(o.data for o in legend_objs)
            strips.append(_render_strip(temp, cam, camera_data, folder, f"legend{k}", total_w, int(legend_height),
                                        (LEGEND_BELOW + LEGEND_ABOVE) * width, 1.12 * width,
                                        np.array([0.5 * width, 0.5 * (LEGEND_ABOVE - LEGEND_BELOW) * width, 0.0])))
        clear_scene()
        reference_maps = before if len(columns) > 1 else []
        lines = [title or default_title(maps, reference_maps) or "curvature review", _settings_line(settings),
                 f"{settings.get('sign_convention', '')}" + ("; " if settings.get("sign_convention") else "")
                 + "grey lines: edges of the NURBS surfaces"]
        smoothing = smoothing_line(maps, reference_maps)
        if smoothing:
            lines.insert(1, smoothing)
        text_h = 0.03
        extra = len(lines) - 3  # the heading grows by a line for each line beyond three
        for n, body in enumerate(lines):
            mesh = _text_mesh(body, f"Bladesmith review heading {n}", text_h * (1.25 if n == 0 else 1.0))
            made_meshes.append(mesh)
            obj = bpy.data.objects.new(f"Bladesmith review heading {n}", mesh)
            obj.matrix_world = Matrix.Translation((0.0, -1.6 * text_h * n, 0.0))
            temp.collection.objects.link(obj)
            made_objects.append(obj)
        content_h = (5.0 + 1.6 * extra) * text_h
        heading_h = int(legend_height * 0.9 * content_h / (5.0 * text_h))
        heading = _render_strip(temp, cam, camera_data, folder, "heading", total_w, heading_h,
                                content_h, 1.12 * width, np.array([0.5 * width, -(1.2 + 0.8 * extra) * text_h, 0.0]),
                                left_align=True)
        body_rows = []
        for panels in rows:
            row = np.concatenate(panels, axis=1)
            if row.shape[1] < total_w:
                pad = np.ones((row.shape[0], total_w - row.shape[1], 4), dtype=row.dtype)
                row = np.concatenate([row, pad], axis=1)
            x = 0
            for p in panels[:-1]:  # thin separators between the panels
                x += p.shape[1]
                row[:, x - 1 : x + 1, :3] = 0.6
            row[:2, :, :3] = 0.6
            body_rows.append(row)
        # top to bottom: heading, the views, their legend(s); an included hub's panel and
        # its legend last (image rows run bottom-up, hence the reversal)
        blocks = [heading] + body_rows + strips[: len(strips) - (hub_row is not None)]
        if hub_row is not None:
            if hub_row.shape[1] < total_w:
                pad = np.ones((hub_row.shape[0], total_w - hub_row.shape[1], 4), dtype=hub_row.dtype)
                hub_row = np.concatenate([hub_row, pad], axis=1)
            hub_row[-3:, :, :3] = 0.3  # a darker rule: a panel on other limits starts here
            top = sum(b.shape[0] for b in blocks)
            layout["hub"] = {"rows": [top, top + hub_row.shape[0]], "limits": settings["hub_limits"],
                             "names": settings.get("hub", [])}
            blocks += [hub_row, strips[-1]]
        layout["legends"] = [{"part": s.get("part", "blade" if hub_row is not None and s["quantity"] != "deviation"
                                            else ""),
                              "quantity": s["quantity"], "limits": list(s["limits"])} for s in legends]
        image = np.concatenate(list(reversed(blocks)), axis=0)
        _write_png(image, filepath)
        times["legend_and_write"] = time.perf_counter() - clock - times["review"] - times["views"]
    finally:
        for obj in made_objects:
            if obj.name in bpy.data.objects:
                bpy.data.objects.remove(obj)
        for mesh in made_meshes:
            if mesh.name in bpy.data.meshes and mesh.users == 0:
                bpy.data.meshes.remove(mesh)
        bpy.data.scenes.remove(temp)
        bpy.data.worlds.remove(world)
        bpy.data.cameras.remove(camera_data)
        for name in os.listdir(folder):
            os.remove(os.path.join(folder, name))
        os.rmdir(folder)
    times["total"] = time.perf_counter() - clock
    return {"filepath": filepath, "views": [v["title"] for v in views] + (["hub"] if hub_maps else []),
            "times": times, **layout}


def _render_strip(temp, cam, camera_data, folder, name, width_px, height_px, content_h, content_w, centre,
                  left_align: bool = False):
    """Render what is in ``temp`` around ``centre`` (the xy plane) into a strip of the
    image's width; ``left_align``: x = 0 near the strip's left edge instead."""
    temp.render.resolution_x, temp.render.resolution_y = int(width_px), int(height_px)
    temp.display.shading.light = "FLAT"
    camera_data.ortho_scale = max(content_w, content_h * 1.15 * width_px / height_px)
    if left_align:
        centre = np.array([0.48 * camera_data.ortho_scale, centre[1], centre[2]])
    cam.matrix_world = _look_at(centre + np.array([0.0, 0.0, 2.0]), centre, np.array([0.0, 1.0, 0.0]))
    camera_data.clip_start, camera_data.clip_end = 1e-3, 10.0
    path = os.path.join(folder, f"{name}.png")
    _render(temp, path)
    return _read_png(path)


# ---------------------------------------------------------------------------------------
# operators
# ---------------------------------------------------------------------------------------
class BLADESMITH_OT_curvature_review(bpy.types.Operator):
    """Curvature combs, curvature maps and fairness numbers of the selected curves and
    surfaces (and propellers), in the "Bladesmith Review" collection"""

    bl_idname = "bladesmith.curvature_review"
    bl_label = "Curvature Review"
    bl_options = {"REGISTER", "UNDO"}

    quantity: EnumProperty(name="Quantity", items=QUANTITY_ITEMS, default="mean")
    percentile: FloatProperty(name="Clip Percentile", default=DEFAULT_PERCENTILE, min=50.0, max=100.0,
                              description="Colour limits: this percentile of |value| (robust against tips and edges)")
    limit: FloatProperty(name="Limit", default=0.0, min=0.0,
                         description="Symmetric colour limit; 0 for the percentile")
    samples_per_span: IntProperty(name="Samples per Span", default=DEFAULT_SAMPLES_PER_SPAN, min=1, max=64)
    convex_positive: BoolProperty(name="Convex Positive", default=True,
                                  description="Curvature positive where the surface bulges along its normal "
                                              "(Bladesmith normals point outwards)")
    comb_lines: IntProperty(name="Comb Lines", default=2, min=0, max=50,
                            description="Iso lines per surface and direction that get a comb")
    comb_teeth: IntProperty(name="Comb Density", default=100, min=2, max=2000, description="Teeth per comb")
    comb_scale: FloatProperty(name="Comb Scale", default=0.0, min=0.0,
                              description="Tooth length per unit curvature (m²); 0 for automatic")
    comb_inside: BoolProperty(name="Teeth Inside", default=False,
                              description="Draw teeth towards the centre of curvature (default: convex side)")
    envelope: BoolProperty(name="Envelope", default=True)
    include_hub: BoolProperty(name="Include Hub", default=False,
                              description="Review a propeller hub on colour limits of its own (its own panel and "
                                          "legend; the blade keeps its limits). Off: the hub is left out of the "
                                          "limits and not drawn in the image")
    iso_lines: IntProperty(name="Counted Iso Lines", default=11, min=0, max=200)
    reference: StringProperty(name="Reference", default="",
                              description="Object or collection before smoothing: same limits, and a difference map")
    filepath: StringProperty(name="Review Image", default="", subtype="FILE_PATH",
                             description="Also render a review image (PNG) to this path")

    @classmethod
    def poll(cls, context):
        return any(o.type in {"CURVE", "SURFACE", "EMPTY"} for o in context.selected_objects)

    @unchanged_on_refusal
    def execute(self, context):
        options = ReviewOptions(
            quantity=self.quantity, percentile=self.percentile, limit=self.limit,
            samples_per_span=self.samples_per_span, convex_positive=self.convex_positive,
            comb_lines=self.comb_lines, comb_teeth=self.comb_teeth, comb_scale=self.comb_scale,
            comb_sign=-1.0 if self.comb_inside else 1.0, envelope=self.envelope, iso_lines=self.iso_lines,
            reference=self.reference, include_hub=self.include_hub,
        )
        wm = context.window_manager
        wm.progress_begin(0, 2)
        try:
            path = ""
            if self.filepath:
                # refuse before the review rewrites anything: an image needs surface maps and
                # a writable folder
                path = check_output_file(self.filepath)
                if not any(o.type == "SURFACE" for o in review_sources(list(context.selected_objects))):
                    raise GeometryError(f"cannot render {path!r}: the selection has no surfaces, so the review "
                                        "has no curvature maps to show (leave filepath empty to review curves)")
            result = review_objects(context.scene, list(context.selected_objects), options)
            wm.progress_update(1)
            if path:
                try:
                    info = render_review_image([], path, scene=context.scene, review=False)
                    review_collection(context.scene)[IMAGE_KEY] = json.dumps(
                        {k: v for k, v in info.items() if k != "times"})
                except OSError as exc:
                    raise GeometryError(f"cannot write the review image {path!r}: {exc.strerror or exc}") from None
        except BladesmithError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        space = getattr(context, "space_data", None)
        if space is not None and space.type == "VIEW_3D":
            space.shading.color_type = "VERTEX"  # show the colour attribute in Solid mode
        lo, hi = result.settings["limits"]
        hub = ""
        if result.settings.get("hub_limits"):
            hub = f" (hub on its own limits, up to {result.settings['hub_limits'][1]:.3g})"
        self.report({"INFO"}, f"reviewed {len(result.maps)} maps, {len(result.combs)} comb objects; "
                              f"limits ±{hi:.3g}{hub}, {result.times['total'] * 1e3:.0f} ms")
        return {"FINISHED"}


class BLADESMITH_OT_clear_curvature_review(bpy.types.Operator):
    """Delete the "Bladesmith Review" collection and everything in it"""

    bl_idname = "bladesmith.clear_curvature_review"
    bl_label = "Clear Curvature Review"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return REVIEW_COLLECTION in bpy.data.collections

    def execute(self, context):
        clear_review(context.scene)
        return {"FINISHED"}


_classes = (BLADESMITH_OT_curvature_review, BLADESMITH_OT_clear_curvature_review)
register, unregister = bpy.utils.register_classes_factory(_classes)
