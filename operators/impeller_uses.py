"""Casey's (1983) uses of an impeller in Blender, on the active impeller root:

- ``bpy.ops.bladesmith.impeller_net(surface, count_u, count_v, cluster_start, cluster_end,
  cluster_hub, cluster_shroud, as_curves, filepath)``: the (u, v) net of a blade surface
  (B, S or P) or of the meridional channel between the blade's LE and TE (Figs. 9–10), the
  counts and clustering being Casey's supplementary parameters (:func:`distribution`), as a
  grid MESH or as poly CURVE lines; with ``filepath`` the net points go to a CSV file
  (i, j, u, v, x, y, z; the channel net as i, j, u, v, z, r);
- ``bpy.ops.bladesmith.impeller_sections(surface, planes, count, as_curves, filepath)``: axial
  cross-sections z = const of a blade surface (Fig. 8) at the listed planes (metres, comma
  separated) or at ``count`` planes spread over the blade, as poly CURVE (or edge MESH)
  objects; with ``filepath`` a CSV (plane, i, U, v, x, y, z);
- ``bpy.ops.bladesmith.save_impeller_definition(filepath)``: the root's definition as a TOML
  file that rebuilds the same wheel (the panel's edits included);
- ``bpy.ops.bladesmith.export_impeller_cfd(filepath, full_wheel, include_camber, units)``: the
  CFD set of the active impeller as IGES (:mod:`..geometry.compressor.cfd`): hub and shroud
  trimmed at the blade footprints, the blades without the camber sheet B unless asked, one
  passage or the full wheel;
- ``bpy.ops.bladesmith.fit_impeller(filepath, tolerance, full_wheel)``: an impeller point
  file (:mod:`..geometry.compressor.points`) fitted in Casey's representation (channel
  patches, cubic-linear blade surfaces) and shown as an Empty with the wall and blade
  surfaces as children; the deviation per surface is reported (a WARNING when a surface
  misses the tolerance).
"""
import os

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ExportHelper

from ..geometry.compressor import ImpellerDefinition, axial_section, blade_net, channel_net, distribution
from ..geometry.compressor.uses import net_csv
from ..geometry.errors import BladesmithError, DefinitionError
from ..geometry.files import atomic_write
from .impeller import PART_KEY, ROOT_KEY, definition_from_root

SURFACES = [("B", "Camber B", "Camber surface"), ("S", "Suction S", "Suction surface"),
            ("P", "Pressure P", "Pressure surface"), ("channel", "Channel", "Meridional channel between LE and TE")]


def _root(context):
    obj = context.active_object
    while obj is not None and not obj.get(ROOT_KEY):
        obj = obj.parent
    return obj


def _model(root):
    return ImpellerDefinition.from_dict(definition_from_root(root)).build()


def _poly_curves(name: str, lines, collection):
    """Each (k, 3) array of ``lines`` as one POLY spline of a CURVE object."""
    data = bpy.data.curves.new(name, "CURVE")
    data.dimensions = "3D"
    for pts in lines:
        if len(pts) < 2:
            continue
        spline = data.splines.new("POLY")
        spline.points.add(len(pts) - 1)
        co = np.ones((len(pts), 4))
        co[:, :3] = pts
        spline.points.foreach_set("co", co.ravel())
    obj = bpy.data.objects.new(name, data)
    collection.objects.link(obj)
    return obj


def _grid_mesh(name: str, net: np.ndarray, collection):
    nu, nv, _ = net.shape
    idx = np.arange(nu * nv).reshape(nu, nv)
    faces = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], axis=-1).reshape(-1, 4)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(net.reshape(-1, 3).tolist(), [], faces.tolist())
    obj = bpy.data.objects.new(name, mesh)
    collection.objects.link(obj)
    return obj


def _attach(root, obj, part: str):
    obj[PART_KEY] = part
    obj.parent = root


class _OnImpeller:
    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT" and _root(context) is not None


class BLADESMITH_OT_impeller_net(_OnImpeller, bpy.types.Operator):
    """Net of (u, v) points on a blade surface or the channel (Casey 1983, Figs. 9-10), optionally written as CSV"""

    bl_idname = "bladesmith.impeller_net"
    bl_label = "Impeller Net"
    bl_options = {"REGISTER", "UNDO"}

    surface: EnumProperty(name="Surface", items=SURFACES, default="B")
    count_u: IntProperty(name="Points along", default=41, min=2, max=2000)
    count_v: IntProperty(name="Points across", default=11, min=2, max=500)
    cluster_start: FloatProperty(name="Cluster at LE", default=1.5, min=0.0, max=10.0,
                                 description="Clustering towards the leading edge (0 = even)")
    cluster_end: FloatProperty(name="Cluster at TE", default=1.5, min=0.0, max=10.0,
                               description="Clustering towards the trailing edge (0 = even)")
    cluster_hub: FloatProperty(name="Cluster at hub", default=0.0, min=0.0, max=10.0)
    cluster_shroud: FloatProperty(name="Cluster at shroud", default=0.0, min=0.0, max=10.0)
    as_curves: BoolProperty(name="As Curves", default=False, description="u = const and v = const lines as curves")
    filepath: StringProperty(name="CSV", subtype="FILE_PATH", default="",
                             description="Write the net points to this CSV file (empty: no file)")

    def execute(self, context):
        root = _root(context)
        try:
            model = _model(root)
            u = distribution(self.count_u, self.cluster_start, self.cluster_end)
            v = distribution(self.count_v, self.cluster_hub, self.cluster_shroud)
            if self.surface == "channel":
                b = model.blade
                U0 = float(np.nanmin(b.corner_U[:, 0]))
                U1 = float(np.nanmax(b.corner_U[:, -1]))
                zr = channel_net(model.master_channel, U0, U1, u, v)
                net = np.stack([zr[..., 1], np.zeros(zr.shape[:2]), zr[..., 0]], axis=-1)  # the plane y = 0
                text = net_csv(zr, u, v)
            else:
                net = blade_net(model.blade.surface(self.surface), u, v)
                text = net_csv(net, u, v)
            if self.filepath:
                atomic_write(bpy.path.abspath(self.filepath), text)
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        except OSError as exc:
            self.report({"ERROR"}, f"{self.filepath}: cannot write: {exc.strerror}")
            return {"CANCELLED"}
        name = f"{root.name} net {self.surface}"
        collection = root.users_collection[0]
        if self.as_curves:
            lines = [net[i] for i in range(net.shape[0])] + [net[:, j] for j in range(net.shape[1])]
            obj = _poly_curves(name, lines, collection)
        else:
            obj = _grid_mesh(name, net, collection)
        _attach(root, obj, f"net {self.surface}")
        self.report({"INFO"}, f"{name}: {net.shape[0]} x {net.shape[1]} points"
                    + (f", written to {self.filepath}" if self.filepath else ""))
        return {"FINISHED"}


class BLADESMITH_OT_impeller_sections(_OnImpeller, bpy.types.Operator):
    """Axial cross-sections z = const of a blade surface (Casey 1983, Fig. 8), optionally written as CSV"""

    bl_idname = "bladesmith.impeller_sections"
    bl_label = "Axial Sections"
    bl_options = {"REGISTER", "UNDO"}

    surface: EnumProperty(name="Surface", items=SURFACES[:3], default="B")
    planes: StringProperty(name="Planes z", default="",
                           description="Axial positions in metres, comma separated; empty: Count planes over the blade")
    count: IntProperty(name="Count", default=5, min=1, max=200)
    as_curves: BoolProperty(name="As Curves", default=True, description="Curves (else edge meshes)")
    filepath: StringProperty(name="CSV", subtype="FILE_PATH", default="")

    def _planes(self, surface) -> np.ndarray:
        if self.planes.strip():
            try:
                return np.array([float(s) for s in self.planes.replace(";", ",").split(",") if s.strip()])
            except ValueError:
                raise DefinitionError(f"expected numbers separated by commas, got {self.planes!r}",
                                      field="planes") from None
        U = np.linspace(0.0, surface.count, 64 * surface.count + 1)
        z = np.concatenate([surface.lower.evaluate(U)[:, 2], surface.upper.evaluate(U)[:, 2]])
        lo, hi = float(z.min()), float(z.max())
        return lo + (hi - lo) * (np.arange(self.count) + 0.5) / self.count

    def execute(self, context):
        root = _root(context)
        try:
            model = _model(root)
            surface = model.blade.surface(self.surface)
            planes = self._planes(surface)
            cuts = [axial_section(surface, float(z)) for z in planes]
            if self.filepath:
                lines = ["plane,i,U,v,x,y,z"]
                for k, (U, v, X) in enumerate(cuts):
                    lines += [f"{k},{i},{U[i]!r},{v[i]!r}," + ",".join(repr(float(c)) for c in X[i]) for i in range(len(U))]
                atomic_write(bpy.path.abspath(self.filepath), "\n".join(lines) + "\n")
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        except OSError as exc:
            self.report({"ERROR"}, f"{self.filepath}: cannot write: {exc.strerror}")
            return {"CANCELLED"}
        name = f"{root.name} sections {self.surface}"
        collection = root.users_collection[0]
        lines = [X for _, _, X in cuts]
        if self.as_curves:
            obj = _poly_curves(name, lines, collection)
        else:
            verts, edges = [], []
            for X in lines:
                base = len(verts)
                verts += X.tolist()
                edges += [(base + i, base + i + 1) for i in range(len(X) - 1)]
            mesh = bpy.data.meshes.new(name)
            mesh.from_pydata(verts, edges, [])
            obj = bpy.data.objects.new(name, mesh)
            collection.objects.link(obj)
        _attach(root, obj, f"sections {self.surface}")
        self.report({"INFO"}, f"{name}: {len(planes)} planes, {sum(len(X) for X in lines)} points")
        return {"FINISHED"}


class BLADESMITH_OT_save_impeller_definition(_OnImpeller, bpy.types.Operator, ExportHelper):
    """Write the active impeller's definition (with the panel's edits) as a TOML file that rebuilds the same wheel"""

    bl_idname = "bladesmith.save_impeller_definition"
    bl_label = "Save Impeller Definition"
    filename_ext = ".toml"
    filter_glob: StringProperty(default="*.toml", options={"HIDDEN"})

    def execute(self, context):
        root = _root(context)
        text = root.get("definition_toml", "")
        header = f"# {root.name}: saved from Blender by Bladesmith (Casey 1983 impeller definition)\n"
        try:
            ImpellerDefinition.from_dict(definition_from_root(root))  # never write what cannot be read back
            atomic_write(self.filepath, header + text)
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        except OSError as exc:
            self.report({"ERROR"}, f"{self.filepath}: cannot write: {exc.strerror}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"saved {os.path.basename(self.filepath)}")
        return {"FINISHED"}


class BLADESMITH_OT_export_impeller_cfd(_OnImpeller, bpy.types.Operator, ExportHelper):
    """Export the CFD set of the active impeller: walls trimmed at the blade footprints, blades, as IGES"""

    bl_idname = "bladesmith.export_impeller_cfd"
    bl_label = "Export Impeller CFD Set"
    filename_ext = ".igs"
    filter_glob: StringProperty(default="*.igs;*.iges", options={"HIDDEN"})
    full_wheel: BoolProperty(name="Full Wheel", default=False, description="All Z passages (else one passage)")
    include_camber: BoolProperty(name="Camber Sheet B", default=False, description="Add the camber surface B")
    units: EnumProperty(name="Units", items=[("MM", "Millimetres", ""), ("M", "Metres", "")], default="MM")

    def execute(self, context):
        from ..geometry.compressor.cfd import cfd_set
        from ..iges.impeller import write_cfd_iges

        root = _root(context)
        try:
            cfd = cfd_set(_model(root), self.full_wheel, self.include_camber)
            write_cfd_iges(self.filepath, cfd, units=self.units.lower())
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        except OSError as exc:
            self.report({"ERROR"}, f"{self.filepath}: cannot write: {exc.strerror}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"CFD set: {len(cfd.walls)} trimmed walls, {len(cfd.blades)} blade surfaces "
                              f"-> {os.path.basename(self.filepath)}")
        return {"FINISHED"}


class BLADESMITH_OT_fit_impeller(bpy.types.Operator):
    """Fit an impeller from point data (hub and shroud contours, blade generating lines) with Casey's patches"""

    bl_idname = "bladesmith.fit_impeller"
    bl_label = "Fit Impeller from Points"
    bl_options = {"REGISTER", "UNDO"}

    filepath: StringProperty(name="Point file", subtype="FILE_PATH", default="")
    tolerance: FloatProperty(name="Tolerance", default=0.0, min=0.0, precision=6, unit="LENGTH",
                             description="Fit tolerance in metres (0: 5e-5 of the largest radius)")
    full_wheel: BoolProperty(name="Full Wheel", default=True)
    general_surfaces: BoolProperty(
        name="General Surfaces", default=False,
        description="Where the best ruled surface misses the points by more than the tolerance, fit a general "
                    "B-spline surface (edges still on the walls; no longer flank-millable)")

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT"

    def execute(self, context):
        from ..geometry.compressor.points import PointFile, fit_impeller, fitted_surfaces
        from .nurbs_objects import surface_to_object
        from .impeller import SURFACE_RESOLUTION

        try:
            fitted = fit_impeller(PointFile(bpy.path.abspath(self.filepath)), self.tolerance or None,
                                  general=self.general_surfaces)
            surfaces = fitted_surfaces(fitted, None if self.full_wheel else 1)
        except BladesmithError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        root = bpy.data.objects.new(fitted.name, None)
        context.collection.objects.link(root)
        root["bladesmith_fitted_impeller"] = fitted.summary()
        for name, surface in surfaces:
            obj = surface_to_object(surface, f"{root.name} {name}", context.collection, SURFACE_RESOLUTION)
            _attach(root, obj, name)
        for obj in context.view_layer.objects:
            obj.select_set(False)
        root.select_set(True)
        context.view_layer.objects.active = root
        self.report({"INFO"} if fitted.met else {"WARNING"}, fitted.summary())
        return {"FINISHED"}


_classes = (BLADESMITH_OT_impeller_net, BLADESMITH_OT_impeller_sections, BLADESMITH_OT_save_impeller_definition,
            BLADESMITH_OT_export_impeller_cfd, BLADESMITH_OT_fit_impeller)
register, unregister = bpy.utils.register_classes_factory(_classes)
