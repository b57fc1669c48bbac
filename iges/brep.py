"""Manifold solid B-rep records (IGES 5.3 §4.25 entity 186 and §4.145–4.151 entities 502,
504, 508, 510, 514) and a builder that makes them from faces that share their edge curves.

Records (parameter data, IGES 5.3):

* 502 Vertex List, form 1: N, then X, Y, Z of each vertex.
* 504 Edge List, form 1: N, then per edge CURV (a model-space curve), SVP, SV, TVP, TV (the
  vertex lists and 1-based indices of its start and terminate vertices).
* 508 Loop, form 1: N, then per edge use TYPE (0 edge, 1 vertex: a degenerate edge), EDGE
  (the 504, or the 502 for a vertex), NDX (index in it),
  OF (1 when the use runs along the edge's curve, 0 against it), K (parameter-space curves,
  here 1) and K pairs ISOP (1 for an isoparametric curve), CURV (a 2-D curve in the face
  surface's parameter space, running along the edge's curve with the same parameter).
* 510 Face, form 1: SURF, N loops, OF (1: the first loop is the outer boundary; 0: none is,
  the surface's own boundary is), the loops.
* 514 Shell, form 1 (closed): N faces, then per face FACE and OF (1: the face's normal is the
  surface's).
* 186 Manifold Solid B-Rep Object, form 0: SHELL, SOF (1: the shell's normals point out),
  N void shells (0 here).

:func:`solid_from_faces` takes the faces as plain geometry: each face a surface record and
its loops, each loop a list of edge uses (3-D curve, 2-D curve, isoparametric flag) in the
loop's sense. An edge is identified by its 3-D control points (forwards or backwards):
faces that share an edge give the same float64 control points, which is how Bladesmith
builds shared edges, so every edge is written once and used by exactly two loops.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..geometry.errors import IgesError
from ..geometry.nurbs import BSplineCurve
from .convert import curve_from_geometry
from .records import Entity


@dataclass(frozen=True, eq=False)
class VertexList(Entity):
    """Vertex List entity, type 502 form 1: ``points`` (n, 3)."""

    type_number: ClassVar[int] = 502
    points: np.ndarray = None

    @property
    def form(self) -> int:
        return 1


@dataclass(frozen=True, eq=False)
class EdgeList(Entity):
    """Edge List entity, type 504 form 1: ``edges`` a tuple of (curve, start vertex index,
    terminate vertex index), indices 1-based into ``vertices``."""

    type_number: ClassVar[int] = 504
    vertices: VertexList = None
    edges: tuple = ()

    @property
    def form(self) -> int:
        return 1

    def references(self):
        return (self.vertices,) + tuple(c for c, _, _ in self.edges)


@dataclass(frozen=True, eq=False)
class Loop(Entity):
    """Loop entity, type 508 form 1: ``uses`` a tuple of (kind, index (1-based), orientation
    flag, isoparametric flag, parameter-space curve); kind 0 is an edge of ``edge_list``,
    kind 1 a vertex of ``vertex_list`` (a degenerate edge, as at a pole)."""

    type_number: ClassVar[int] = 508
    edge_list: EdgeList = None
    vertex_list: VertexList = None
    uses: tuple = ()

    @property
    def form(self) -> int:
        return 1

    def references(self):
        lists = tuple(x for x in (self.edge_list, self.vertex_list) if x is not None)
        return lists + tuple(c for _, _, _, _, c in self.uses)


@dataclass(frozen=True, eq=False)
class Face(Entity):
    """Face entity, type 510 form 1: ``surface``, ``loops``; ``outer`` whether the first
    loop is the outer boundary."""

    type_number: ClassVar[int] = 510
    surface: Entity = None
    loops: tuple = ()
    outer: bool = True

    @property
    def form(self) -> int:
        return 1

    def references(self):
        return (self.surface,) + tuple(self.loops)


@dataclass(frozen=True, eq=False)
class Shell(Entity):
    """Shell entity, type 514: ``faces`` a tuple of (face, orientation flag); form 1 closed."""

    type_number: ClassVar[int] = 514
    faces: tuple = ()
    closed: bool = True

    @property
    def form(self) -> int:
        return 1 if self.closed else 2

    def references(self):
        return tuple(f for f, _ in self.faces)


@dataclass(frozen=True, eq=False)
class ManifoldSolid(Entity):
    """Manifold Solid B-Rep Object entity, type 186 form 0: one outer ``shell``, no voids."""

    type_number: ClassVar[int] = 186
    shell: Shell = None
    outward: bool = True

    def references(self):
        return (self.shell,)


BREP_TYPES = (VertexList, EdgeList, Loop, Face, Shell, ManifoldSolid)


def parameter_tokens(entity: Entity, de: dict, reals) -> list[str]:
    """The parameter data of a B-rep record after its type number (see the module docstring);
    ``de`` maps id(record) to its DE pointer, ``reals`` formats a float array."""
    if isinstance(entity, VertexList):
        P = np.asarray(entity.points, dtype=np.float64)
        return [str(P.shape[0]), reals(P)]
    if isinstance(entity, EdgeList):
        v = str(de[id(entity.vertices)])
        out = [str(len(entity.edges))]
        for curve, a, b in entity.edges:
            out += [str(de[id(curve)]), v, str(a), v, str(b)]
        return out
    if isinstance(entity, Loop):
        lists = (str(de[id(entity.edge_list)]), str(de[id(entity.vertex_list)]) if entity.vertex_list else "0")
        out = [str(len(entity.uses))]
        for kind, index, orient, isop, curve in entity.uses:
            out += [str(kind), lists[kind], str(index), str(int(orient)), "1", str(int(isop)), str(de[id(curve)])]
        return out
    if isinstance(entity, Face):
        return [str(de[id(entity.surface)]), str(len(entity.loops)), str(int(entity.outer)),
                *(str(de[id(lp)]) for lp in entity.loops)]
    if isinstance(entity, Shell):
        out = [str(len(entity.faces))]
        for face, orient in entity.faces:
            out += [str(de[id(face)]), str(int(orient))]
        return out
    if isinstance(entity, ManifoldSolid):
        return [str(de[id(entity.shell)]), str(int(entity.outward)), "0"]
    raise IgesError(f"{entity.describe()}: not a B-rep record")


def parameter_curves(entity: Entity) -> tuple:
    """The parameter-space curves a B-rep record references (use flag 05 in their DE)."""
    if isinstance(entity, Loop):
        return tuple(c for _, _, _, _, c in entity.uses)
    return ()


def validate_brep(entity: Entity) -> None:
    """Counts and indices of a B-rep record (raises IgesError)."""
    if isinstance(entity, VertexList):
        P = np.asarray(entity.points, dtype=np.float64)
        if P.ndim != 2 or P.shape[1] != 3 or P.shape[0] < 1 or not np.all(np.isfinite(P)):
            raise IgesError(f"{entity.describe()}: expected finite (n >= 1, 3) points")
    elif isinstance(entity, EdgeList):
        n = len(entity.vertices.points)
        for k, (_, a, b) in enumerate(entity.edges):
            if not (1 <= a <= n and 1 <= b <= n):
                raise IgesError(f"{entity.describe()}: edge {k + 1} names vertices {a}, {b} of {n}")
    elif isinstance(entity, Loop):
        sizes = (len(entity.edge_list.edges), 0 if entity.vertex_list is None else len(entity.vertex_list.points))
        if not entity.uses:
            raise IgesError(f"{entity.describe()}: a loop needs at least one edge")
        for kind, index, _, _, _ in entity.uses:
            if kind not in (0, 1) or not 1 <= index <= sizes[kind]:
                raise IgesError(f"{entity.describe()}: {('edge', 'vertex')[kind % 2]} index {index} outside "
                                f"1..{sizes[kind % 2]}")
    elif isinstance(entity, Shell):
        if not entity.faces:
            raise IgesError(f"{entity.describe()}: a shell needs at least one face")


# -- builder -----------------------------------------------------------------------------------------------
@dataclass
class FaceSpec:
    """A face for :func:`solid_from_faces`: the surface record, whether its first loop is
    the outer boundary, and its loops, each a list of (3-D curve, 2-D curve, isoparametric)
    edge uses in the loop's sense (each 2-D curve runs with its 3-D curve, same parameter)."""

    surface: Entity
    loops: list
    outer: bool = True


def _key(P: np.ndarray) -> bytes:
    return np.ascontiguousarray(P, dtype=np.float64).tobytes()


def _reversed_curve(curve: BSplineCurve) -> BSplineCurve:
    from ..geometry.nurbs import reverse

    return reverse(curve)


def solid_from_faces(faces, *, scale: float = 1.0, label: str = "") -> ManifoldSolid:
    """A 186 whose closed shell holds ``faces`` (:class:`FaceSpec`), every face oriented
    with its surface's normal (which must point out of the solid).

    Edges are found by their 3-D control points: a use whose curve has the control points
    of a known edge (either way round) is a use of that edge, with OF = 0 when it runs the
    other way (its 2-D curve is then reversed, t -> a + b - t, so it runs with the edge's
    curve). Vertices are the curves' end points, merged when equal. Raises IgesError unless
    every edge is used exactly twice (a closed manifold shell)."""
    vertices: list[np.ndarray] = []
    vertex_index: dict[bytes, int] = {}
    edges: list[tuple] = []  # (3-D curve in file units, start index, end index)
    edge_index: dict[bytes, int] = {}
    use_count: list[int] = []
    curve_records: dict[int, Entity] = {}

    def vertex(p):
        k = _key(p)
        if k not in vertex_index:
            vertices.append(np.asarray(p, dtype=np.float64))
            vertex_index[k] = len(vertices)
        return vertex_index[k]

    face_records = []
    edge_list_holder: list = []
    loops_of_faces = []
    for face in faces:
        loops = []
        for loop in face.loops:
            uses = []
            for c3, c2, isop in loop:
                if isinstance(c3, np.ndarray):
                    uses.append((1, vertex(c3), 1, isop, curve_from_geometry(c2)))
                    continue
                P = np.asarray(c3.control_points, dtype=np.float64)
                fwd, back = _key(P), _key(P[::-1])
                if fwd in edge_index:
                    i, orient = edge_index[fwd], 1
                elif back in edge_index:
                    i, orient = edge_index[back], 0
                else:
                    edges.append((c3, vertex(P[0]), vertex(P[-1])))
                    use_count.append(0)
                    i, orient = len(edges), 1
                    edge_index[fwd] = i
                use_count[i - 1] += 1
                pc = c2 if orient else _reversed_curve(c2)
                uses.append((0, i, orient, isop, curve_from_geometry(pc)))
            loops.append(uses)
        loops_of_faces.append(loops)
    bad = [k + 1 for k, n in enumerate(use_count) if n != 2]
    if bad:
        raise IgesError(f"the faces do not close: edges {bad[:10]} are used {[use_count[k - 1] for k in bad[:10]]} "
                        f"times (a closed shell uses every edge twice)")
    vlist = VertexList(points=np.array(vertices) * scale)
    for c3, a, b in edges:
        rec = curve_from_geometry(c3, scale=scale)
        curve_records[len(curve_records)] = rec
        edge_list_holder.append((rec, a, b))
    elist = EdgeList(vertices=vlist, edges=tuple(edge_list_holder))
    for face, loops in zip(faces, loops_of_faces):
        loop_records = tuple(Loop(edge_list=elist, vertex_list=vlist if any(k == 1 for k, *_ in u) else None,
                                  uses=tuple(u)) for u in loops)
        face_records.append(Face(surface=face.surface, loops=loop_records, outer=face.outer))
    shell = Shell(faces=tuple((f, 1) for f in face_records), closed=True)
    return ManifoldSolid(shell=shell, outward=True, label=label)
