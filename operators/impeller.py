"""Impellers in Blender: ``bpy.ops.bladesmith.add_impeller`` (Casey 1983 channel and blades).

A root Empty named after the definition holds the definition as TOML text
(``definition_toml``) and the editable values in ``Object.bladesmith_impeller`` (the
property group of :mod:`..ui.impeller_panel`); its children are SURFACE objects showing
the exact surfaces of :func:`~..geometry.compressor.export.impeller_surfaces` (channel
walls as four quarter surfaces of revolution each, blade k's S, P and rounded end patches,
splitters), each storing its float64 surface, so File > Export > IGES writes them exactly.
With ``blade_net`` a MESH object shows the (u, v) net of the camber surface B. A
definition with a ``[standardisation]`` table (Casey 1983, Fig. 11) shows its new channel
and the blades trimmed to it; the operator reports the largest edge-to-wall distance and
the knot counts of the trimmed surfaces.
Editing a value in the panel rebuilds the model and replaces the children.
"""
import pathlib
import tomllib

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, StringProperty

from ..geometry.compressor import ImpellerDefinition, blade_net, distribution, dumps_toml
from ..geometry.compressor.export import construction_summary, impeller_surfaces
from ..geometry.errors import BladesmithError, DefinitionError
from .nurbs_objects import PROPERTY_KEY, remove_object, surface_to_object, write_surface
from .scene_guard import unchanged_on_refusal

PRESET_DIR = pathlib.Path(__file__).resolve().parent.parent / "data" / "impellers"
ROOT_KEY = "bladesmith_impeller_root"
PART_KEY = "bladesmith_part"
#: Blender evaluation points per control point of the displayed surfaces (along a
#: direction with one linear segment, see :func:`display_resolution`).
SURFACE_RESOLUTION = 3
#: Curve data of other net sizes a part has shown, kept per part (object name) for reuse:
#: a Blender surface net changes size only through edit mode (``make_segment``, three
#: operator calls that each re-evaluate the view layer), and a panel edit that changes a
#: blade's patch count (a splitter LE, a tolerance) often goes back to a size shown before.
SPARE_SIZES = 4
_SPARES: dict = {}


def preset_names() -> list[str]:
    return sorted(p.stem for p in PRESET_DIR.glob("*.toml"))


def _preset_items(self, context):
    return [(n, n.replace("_", " "), f"data/impellers/{n}.toml") for n in preset_names()]


def preset_file(name: str) -> pathlib.Path:
    """The definition file of a preset, matched without regard to case, as the propeller
    and wind-blade presets are ("HIGH_FLOW", "High_Flow" and "high_flow.toml" all work)."""
    key = str(name).strip().lower()
    if key.endswith(".toml"):
        key = key[: -len(".toml")]
    if key not in preset_names():
        raise DefinitionError(f"unknown preset {name!r}; available: {', '.join(preset_names())}", field="preset")
    return PRESET_DIR / f"{key}.toml"


def load_definition(definition: str = "", preset: str = "") -> ImpellerDefinition:
    if definition:
        return ImpellerDefinition.from_toml(bpy.path.abspath(definition))
    return ImpellerDefinition.from_toml(preset_file(preset))


def net_to_mesh(net: np.ndarray, name: str, collection):
    """A structured (nu, nv, 3) net as a grid MESH object (Casey 1983, Figs. 9–10)."""
    nu, nv, _ = net.shape
    idx = np.arange(nu * nv).reshape(nu, nv)
    faces = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], axis=-1).reshape(-1, 4)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(net.reshape(-1, 3).tolist(), [], faces.tolist())
    obj = bpy.data.objects.new(name, mesh)
    collection.objects.link(obj)
    return obj


def display_resolution(surface) -> tuple[int, int]:
    """Blender's (u, v) resolution for ``surface``: SURFACE_RESOLUTION, but 1 along a
    direction that is one linear segment (the v of Casey's ruled blade surfaces, S, P,
    B and the end caps, trimmed or not): Blender then evaluates the two edges only, and
    the straight rulings between them are the surface's own, so the shape drawn along v
    is exact; the rows in between only cost evaluation, Z times in a full wheel (the
    linked copies each tessellate the shared data)."""
    def one(degree, count):
        return 1 if degree == 1 and count == 2 else SURFACE_RESOLUTION

    n_u, n_v = surface.control_points.shape[:2]
    return one(surface.degree_u, n_u), one(surface.degree_v, n_v)


def _net_size(surface) -> tuple[int, int]:
    """The (u, v) size of the Blender net :func:`write_surface` makes of ``surface``: its
    Bezier form (p (interior breaks + 1) + 1 points per direction of a clamped knot
    vector), a single linear segment in v with the midpoint column added."""
    sizes = []
    for p, knots in ((surface.degree_u, surface.knots_u), (surface.degree_v, surface.knots_v)):
        sizes.append(p * (np.unique(knots[p + 1:-p - 1]).size + 1) + 1)
    return sizes[0], 3 if sizes[1] == 2 else sizes[1]


def _net_of(data):
    splines = data.splines
    return (splines[0].point_count_u, splines[0].point_count_v) if len(splines) == 1 else None


def _reuse_spare(obj, surface, donors: dict) -> None:
    """Give ``obj`` curve data whose net has the size ``surface`` needs, when its own has
    another size: the spare of that size (no user, one spline: made by
    :func:`write_surface` for this part before), else a copy of ``donors``' data of that
    size (a part written just before with the same net size: S, P and B of a blade share
    their patch count); its own data becomes a spare. The write that follows then only
    rewrites points (the flags and orders of a :func:`write_surface` net are the same for
    every part); with neither it rebuilds the net as before. Linked copies (full wheel)
    are pointed at the new data by :func:`build_children`."""
    have, need = _net_of(obj.data), _net_size(surface)
    if have == need:
        return
    spares = _SPARES.setdefault(obj.name, {})
    name = spares.pop(need, None)
    data = bpy.data.curves.get(name) if name is not None else None
    if data is None or data.users != 0 or _net_of(data) != need:
        donor = donors.get(need)
        if donor is None:
            return
        data = donor.copy()
    old = obj.data
    obj.data = data
    if have is not None:
        spares[have] = old.name
    while len(spares) > SPARE_SIZES:
        oldest = bpy.data.curves.get(spares.pop(next(iter(spares))))
        if oldest is not None and oldest.users == 0:
            bpy.data.curves.remove(oldest)


def _keep_spare(obj, surface) -> None:
    """Before ``obj``'s net is rebuilt for ``surface`` (another size, no spare): keep a
    copy of its current data as the spare of its size."""
    have = _net_of(obj.data)
    if have is None or have == _net_size(surface):
        return
    spares = _SPARES.setdefault(obj.name, {})
    if have in spares and bpy.data.curves.get(spares[have]) is not None:
        return
    spare = obj.data.copy()
    spares[have] = spare.name
    while len(spares) > SPARE_SIZES:
        oldest = bpy.data.curves.get(spares.pop(next(iter(spares))))
        if oldest is not None and oldest.users == 0:
            bpy.data.curves.remove(oldest)


def _child(root, name: str, data, collection):
    obj = bpy.data.objects.new(f"{root.name} {name}", data)
    collection.objects.link(obj)
    obj[PART_KEY] = name
    obj.parent = root
    return obj


def build_children(root, definition: ImpellerDefinition, full_wheel: bool, show_net: bool, model=None):
    """Build the model (unless given) and make the root's children show it; returns the
    model; raises BladesmithError.

    The channel walls and the first blade (and splitter) are written in place into the
    existing objects (:func:`write_surface` reuses their curve data); blades 2..Z are
    linked copies of the first, rotated about the axis, so a panel edit rewrites one
    blade, not Z. Children no longer needed are removed. A standardised definition shows
    the new channel and the trimmed blades (and the trimmed camber surface's net)."""
    if model is None:
        model = definition.build()
    reference = impeller_surfaces(model, 1, include_camber=True)
    existing = {child.get(PART_KEY): child for child in root.children}
    collection = root.users_collection[0]
    wanted, donors = {}, {}
    for name, surface in reference:
        obj = existing.get(name)
        if obj is None or obj.type != "SURFACE":
            obj = surface_to_object(surface, f"{root.name} {name}", collection, display_resolution(surface))
            obj[PART_KEY] = name
            obj.parent = root
        else:
            _reuse_spare(obj, surface, donors)
            _keep_spare(obj, surface)
            write_surface(obj, surface, display_resolution(surface))
        donors.setdefault(_net_of(obj.data), obj.data)
        wanted[name] = obj
    count = model.count if full_wheel else 1
    for k in range(1, count):
        for name, _ in reference:
            words = name.split(" ", 2)
            if len(words) != 3 or words[0] not in ("blade", "splitter") or words[1] != "1" or words[2] == "B":
                continue
            label, _, part = words
            source = wanted[name]
            copy_name = f"{label} {k + 1} {part}"
            obj = existing.get(copy_name)
            if obj is None or obj.type != "SURFACE":
                obj = _child(root, copy_name, source.data, collection)
            elif obj.data is not source.data:
                obj.data = source.data
            obj.rotation_euler = (0.0, 0.0, float(model.blade_angle(k)))
            obj[PROPERTY_KEY] = source[PROPERTY_KEY].to_dict()
            wanted[copy_name] = obj
    for name, obj in existing.items():
        if name not in wanted:
            remove_object(obj)
    if show_net:
        u, v = distribution(41, 1.5, 1.5), distribution(11)
        if model.standardisation is None:
            net = blade_net(model.blade.camber, u, v)
        else:
            net = model.standardisation.trimmed("blade", "B").exact.net(u, v)
        obj = net_to_mesh(net, f"{root.name} net B", collection)
        obj[PART_KEY] = "net B"
        obj.parent = root
    root["definition_toml"] = dumps_toml(definition.to_dict())
    return model


class BLADESMITH_OT_add_impeller(bpy.types.Operator):
    """Add a centrifugal impeller or return channel (Casey 1983): channel, B/S/P blades, full wheel"""

    bl_idname = "bladesmith.add_impeller"
    bl_label = "Add Impeller"
    bl_options = {"REGISTER", "UNDO"}

    definition: StringProperty(name="Definition", description="Impeller TOML file", subtype="FILE_PATH", default="")
    preset: StringProperty(
        name="Preset name",
        description="Preset, by name without regard to case (e.g. high_flow); used when no definition is given",
        default="high_flow",
    )
    preset_choice: EnumProperty(name="Preset", description="Preset, chosen from the list", items=_preset_items)
    full_wheel: BoolProperty(name="Full Wheel", description="All Z blades (and splitters), not only the first", default=True)
    blade_net: BoolProperty(name="Blade Net", description="Add the (u, v) net of the camber surface as a mesh", default=False)

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT"

    def _preset_name(self) -> str:
        # a script names `preset`; the redo panel's list sets `preset_choice`
        if self.properties.is_property_set("preset") or not self.properties.is_property_set("preset_choice"):
            return self.preset
        return self.preset_choice

    @unchanged_on_refusal
    def execute(self, context):
        try:
            definition = load_definition(self.definition, self._preset_name())
            model = definition.build()  # validate before touching the scene
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        root = bpy.data.objects.new(definition.name, None)
        context.collection.objects.link(root)
        root[ROOT_KEY] = True
        try:
            build_children(root, definition, self.full_wheel, self.blade_net, model)
        except BladesmithError as exc:
            for child in list(root.children):
                bpy.data.objects.remove(child)
            bpy.data.objects.remove(root)
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        summary = "" if model.standardisation is None else model.standardisation.summary()
        construction, met = construction_summary(model)
        settings = getattr(root, "bladesmith_impeller", None)
        if settings is not None:
            settings.load(definition, self.full_wheel, summary, construction)
        for obj in context.view_layer.objects:
            obj.select_set(False)
        root.select_set(True)
        context.view_layer.objects.active = root
        if summary:
            self.report({"INFO"}, f"{definition.name}: {summary}")
        if construction:
            self.report({"INFO"} if met else {"WARNING"}, f"{definition.name}: {construction}")
        return {"FINISHED"}


def regenerate(root, definition_dict: dict, full_wheel: bool):
    """Rebuild a root's children from an edited definition dictionary (panel edits);
    returns the model."""
    definition = ImpellerDefinition.from_dict(definition_dict)
    return build_children(root, definition, full_wheel, any(c.get(PART_KEY) == "net B" for c in root.children))


def definition_from_root(root) -> dict:
    return tomllib.loads(root["definition_toml"])


_classes = (BLADESMITH_OT_add_impeller,)
_register, _unregister = bpy.utils.register_classes_factory(_classes)


def menu_func(self, context):
    self.layout.operator(BLADESMITH_OT_add_impeller.bl_idname, text="Impeller (Casey)")


def register():
    _register()
    bpy.types.VIEW3D_MT_add.append(menu_func)


def unregister():
    bpy.types.VIEW3D_MT_add.remove(menu_func)
    _unregister()
