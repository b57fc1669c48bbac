"""The whole propeller as a CFD engineer uses it: Z blades and the whole hub written to IGES,
read by OpenCASCADE, sewn at 1e-7 D into one closed shell, made a solid, cut from a
cylinder around it, and the fluid volume-meshed by gmsh with no repair step.

The cases are one parametrised list, :data:`CASES`: every shipped propeller preset, the
irregular-tip fixtures of tests/data/irregular_tips (a steep chord on a coarse table; 72°
skew and rake changing fast), a 72°-skew variant of skewed_demo (highly skewed), and DTMB
4119 with a finite tip chord (the largest the definition accepts, MAX_TIP_CHORD_RATIO of
the largest chord). Add cases by appending a :class:`Case`.

The export splits the leading-edge, trailing-edge and tip surfaces along the blade's edge
(:func:`~bladesmith.iges.propeller.split_at_edges`, 8 faces a blade): each of them wraps
round an edge of radius 1e-4 to 1e-6 D, and meshed whole at this size its triangles
straddle the edge and fold (the cause of the slivers, min SICN 0.002-0.03, and of gmsh's
"PLC Error: A segment and a facet intersect" before the split).

Mesh: gmsh's OCC kernel reads the fluid (a BREP written by OCC), sizes from curvature
(MESH_CURVATURE_POINTS elements per 2π) between MESH_MIN_SIZE and MESH_MAX_SIZE (fractions
of D), 2-D Delaunay, 3-D Delaunay with gmsh's Netgen optimiser (mesh optimisation, not
geometry repair). Threshold MIN_SICN = 0.05: below it a tetrahedron is a sliver that most
finite-volume solvers flag (non-orthogonality beyond ~85°). Measured (gmsh 4.15): DTMB
4119 0.165, RAKED_DEMO 0.122, SKEWED_DEMO 0.112, bounded by tetrahedra on the blade's edge
lines near r/R 0.4-0.5 (re-measured 2026-11-24: 0.184, 0.126, 0.137); before the split they
gave 0.074, a PLC error and 0.014.

The cases still short of it, each with the figures and the cause in its ``mesh_xfail``
(re-measured 2026-11-24): the 72°-skew and skewed_fast tips (the tip surface along its
edge line and at its corner x_TE), the finite tip (its closure's two halves overlap in
the mesh) and steep_coarse (now at the hub's seam, not the tip); they run only with
BLADESMITH_SLOW=1, like cases marked ``slow`` (the suite's budget for 3-D meshing is
about 4 minutes on 2 cores).
"""
from __future__ import annotations

import os
import pathlib
import tomllib
from dataclasses import dataclass, field

import numpy as np
import pytest

pytest.importorskip("OCP")
gmsh = pytest.importorskip("gmsh")

from bladesmith.geometry.propeller import Propeller, smooth_blade  # noqa: E402
from bladesmith.geometry.propeller.definition import MAX_TIP_CHORD_RATIO  # noqa: E402
from bladesmith.geometry.propeller.hub_sector import hub_sector, root_footprint_distance  # noqa: E402
from bladesmith.iges.propeller import (WRAPPED_SURFACES, _blade_surfaces, faces_per_blade,  # noqa: E402
                                       full_propeller_iges_entities, split_at_edges, write_full_propeller_iges)
from bladesmith.iges.records import TrimmedSurface  # noqa: E402
from occ_support import fluid_volume_mesh, read_with_occ  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
MM_PER_M = 1000.0
SEWING_TOL_FRACTION = 1e-7  # of D
JUNCTION_TOL_FRACTION = 1e-12  # of D
VOLUME_EPS = 1e-9
MESH_CURVATURE_POINTS = 8
MESH_MAX_SIZE = 0.15  # of D
MESH_MIN_SIZE = 0.01  # of D
MIN_SICN = 0.05
#: The fluid domain: a cylinder of this many radii R, reaching this fraction of D beyond the hub ends.
DOMAIN_RADIUS = 1.5
DOMAIN_MARGIN = 0.25
SLOW = os.environ.get("BLADESMITH_SLOW", "") not in ("", "0")


@dataclass(frozen=True)
class Case:
    """A propeller for the mesh test: a definition file (a preset by default), with
    optional changes to its radial columns (column name -> function of the list).
    ``slow``: the 3-D mesh runs only with BLADESMITH_SLOW=1. ``mesh_xfail``: the reason,
    with the figures measured, when the 3-D mesh is known not to reach MIN_SICN (such a
    case is also slow)."""

    name: str
    preset: str
    radial: dict = field(default_factory=dict)
    slow: bool = False
    definition: str = ""
    mesh_xfail: str = ""

    def propeller(self):
        path = ROOT / (self.definition or f"data/propellers/{self.preset}.toml")
        data = tomllib.loads(path.read_text())
        radial = dict(data["radial"])
        for column, change in self.radial.items():
            radial[column] = change(list(radial[column]))
        return Propeller.from_dict({**data, "radial": radial})


IRREGULAR = "tests/data/irregular_tips"
CASES = [
    Case("dtmb4119", "dtmb4119"),
    Case("finite_tip", "dtmb4119", {"c_D": lambda c: c[:-1] + [MAX_TIP_CHORD_RATIO * max(c)]},
         mesh_xfail="the finite tip's closure: gmsh 'Invalid boundary mesh (overlapping facets)' between the tip "
         "surface's pressure and suction halves (fluid surfaces 8 and 24), which bridge the open tip section "
         "about as far apart as the section is thick, below the mesh size (measured 2026-11-24, gmsh 4.15)"),
    Case("raked_demo", "raked_demo"),
    Case("skewed_demo", "skewed_demo"),
    Case("skew72", "skewed_demo", {"skew_deg": lambda s: [1.6 * x for x in s]},
         mesh_xfail="min SICN 0.0092 (2026-11-24): flat triangles on the tip surface against its edge line at r/R "
         "0.93 (2-D quality 7e-4): Hally's cut parameter (Eq. 24) runs up to 85x slower at the edge than "
         "mid-cut (DTMB 4119's tip cuts), so the tip's |S_v| nearly vanishes there. Tried on a branch: with the curves at their 3-D "
         "arclength those go, and the slivers move to the tip surface's corner at x_TE, where c_11 "
         "and the skewed trailing edge meet at 159 deg: 0.005 (0.018 adding corners.BEND_TOP_EDGES)"),
    Case("steep_coarse", "", definition=f"{IRREGULAR}/steep_coarse.toml",
         mesh_xfail="min SICN 0.044 (2026-11-24), no longer on the tip (next worst 0.09): a tetrahedron at the hub, "
         "r/R 0.215, between the whole hub face's seam curve and a blade root edge 4 nodes long (the hub face's "
         "worst triangle has quality 0.006)"),
    Case("skewed_fast", "", definition=f"{IRREGULAR}/skewed_fast.toml",
         mesh_xfail="min SICN 0.0091 (2026-11-24) against the tip surface's edge line at r/R 0.93, as on skew72; "
         "the tip surface's corner at x_TE is 159 deg (c_11 nearly continues the skewed trailing edge). With "
         "the curves at their 3-D arclength (tried on a branch): 0.031"),
]

_BUILT: dict = {}


def built(case: Case, tmp_path_factory):
    if case.name not in _BUILT:
        model = case.propeller().build()
        blade = smooth_blade(model, measure=False)
        sector = hub_sector(model, blade=blade)
        path = tmp_path_factory.mktemp("full") / f"{case.name}.igs"
        write_full_propeller_iges(path, model, blade, sector)
        _BUILT[case.name] = (model, blade, sector, path)
    return _BUILT[case.name]


_SEWN: dict = {}


def sewn_solid(path, D: float):
    """(occ result, sewing, solid, volume in m³) of the file's faces sewn at 1e-7 D
    (computed once per file)."""
    if str(path) not in _SEWN:
        _SEWN[str(path)] = _sew(path, D)
    return _SEWN[str(path)]


def _sew(path, D: float):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopoDS import TopoDS

    occ = read_with_occ(path)
    sewing = BRepBuilderAPI_Sewing(SEWING_TOL_FRACTION * D * MM_PER_M)
    for face in occ.faces:
        sewing.Add(face)
    sewing.Perform()
    shape = sewing.SewedShape()
    solid = None
    volume = float("nan")
    if shape.ShapeType() == TopAbs_SHELL:
        solid = BRepBuilderAPI_MakeSolid(TopoDS.Shell(shape)).Solid()
        props = GProp_GProps()
        BRepGProp.VolumeProperties_s(solid, props, VOLUME_EPS)
        volume = props.Mass() / MM_PER_M**3
    return occ, sewing, solid, volume


@pytest.fixture(params=CASES, ids=lambda c: c.name)
def case(request):
    return request.param


def test_root_junction_is_the_blade_root_edge(case, tmp_path_factory):
    """Every hole of the whole hub is trimmed by its blade's root edge itself: the 142's
    model curves have the blade surfaces' v = 0 rows as control points, bit for bit, and
    the sector's root-footprint distance is 0 (<= 1e-12 D)."""
    model, blade, sector, _ = built(case, tmp_path_factory)
    D = 2.0 * model.blade.radius
    assert root_footprint_distance(sector, blade) <= JUNCTION_TOL_FRACTION * D
    records = full_propeller_iges_entities(model, blade, sector)
    hub = records[-1]
    assert isinstance(hub, TrimmedSurface) and hub.outer is None and len(hub.inner) == model.blades
    surfaces = records[:-1]
    rows = [s.control_points[:, 0] for s in surfaces]  # the v = 0 rows of every blade surface
    for hole in hub.inner:
        assert hole.preferred == 2
        for curve in hole.model_curve.curves:
            P = curve.control_points
            assert any(np.array_equal(P, r) or np.array_equal(P[::-1], r) for r in rows), \
                "a hole's 3-D curve is not a blade surface's root row"


def test_edge_surfaces_are_split_along_the_edge_exactly(case, tmp_path_factory):
    """The LE, TE and tip surfaces go out as two halves each (:func:`split_at_edges`): the
    halves are the surface (to round-off, 1e-14 D), meet along the line through the cuts'
    edge points (where the surface turns most: within 0.06 of the middle of the cut on every
    case), and every boundary of every half is, bit for bit, a boundary of another face
    or a root row (the shell sews at any tolerance)."""
    model, blade, _, _ = built(case, tmp_path_factory)
    D = 2.0 * model.blade.radius
    items = _blade_surfaces(blade)
    pieces = split_at_edges(items, int(np.sign(model.blade.hand)))
    assert len(pieces) == faces_per_blade()
    for label, whole in items:
        halves = [s for lab, s in pieces if lab == label]
        if label not in WRAPPED_SURFACES:
            assert len(halves) == 1 and halves[0] is whole
            continue
        assert len(halves) == 2
        along = WRAPPED_SURFACES[label]
        t = np.linspace(0.0, 1.0, 201)
        across = np.linspace(0.0, 1.0, 11)
        for half in halves:
            (u0, u1), (v0, v1) = half.domain_u, half.domain_v
            u = (u0 + (u1 - u0) * t)[:, None] if along == "u" else (u0 + (u1 - u0) * across)[:, None]
            v = (v0 + (v1 - v0) * across)[None, :] if along == "u" else (v0 + (v1 - v0) * t)[None, :]
            assert np.abs(half.evaluate(u, v) - whole.evaluate(u, v)).max() < 1e-14 * D
        # the split is where the cut turns fastest (its edge point)
        if along == "u":
            d = whole.derivatives(t[:, None], across[None, :], order=2)
            A, B = d[..., 1, 0, :], d[..., 2, 0, :]
        else:
            d = whole.derivatives(across[None, :], t[:, None], order=2)
            A, B = d[..., 0, 1, :], d[..., 0, 2, :]
        kappa = np.linalg.norm(np.cross(A, B), axis=-1) / np.linalg.norm(A, axis=-1) ** 3
        assert np.all(np.abs(t[np.argmax(kappa, axis=0)] - 0.5) < 0.06)
    nets = [s.control_points for _, s in pieces]
    rows = lambda P: (P[:, 0], P[:, -1], P[0, :], P[-1, :])  # noqa: E731
    for j, P in enumerate(nets):
        for r, row in enumerate(rows(P)):
            if r == 0 and pieces[j][0] != "TIP":
                continue  # a root row: it trims the hub (test_root_junction_is_the_blade_root_edge)
            assert any(np.array_equal(row, o) or np.array_equal(row[::-1], o)
                       for i, Q in enumerate(nets) if i != j for o in rows(Q)), (pieces[j][0], r)


def test_full_propeller_sews_into_one_valid_solid(case, tmp_path_factory):
    from OCP.BRepCheck import BRepCheck_Analyzer

    model, _, _, path = built(case, tmp_path_factory)
    D = 2.0 * model.blade.radius
    occ, sewing, solid, volume = sewn_solid(path, D)
    assert occ.load_messages == [] and occ.transfer_messages == []
    assert len(occ.faces) == faces_per_blade() * model.blades + 1
    assert sewing.NbFreeEdges() == 0
    assert sewing.NbMultipleEdges() == 0
    assert solid is not None and BRepCheck_Analyzer(solid).IsValid()
    # the hub alone: π R_h² times its length is an upper bound; the blades add a little
    assert 0.0 < volume


def _fluid_mesh(solid, D: float):
    """Cut the solid from a cylinder around it in OCC and mesh the fluid in 3-D with gmsh
    (:func:`occ_support.fluid_volume_mesh`): (OCC validity of the fluid, number of
    tetrahedra, min SICN)."""
    from OCP.BRepBndLib import BRepBndLib
    from OCP.Bnd import Bnd_Box
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    Dmm = D * MM_PER_M
    box = Bnd_Box()
    BRepBndLib.Add_s(solid, box)
    z0, z1 = box.CornerMin().Z() - DOMAIN_MARGIN * Dmm, box.CornerMax().Z() + DOMAIN_MARGIN * Dmm
    cylinder = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, z0), gp_Dir(0, 0, 1)), DOMAIN_RADIUS * 0.5 * Dmm,
                                        z1 - z0).Shape()
    return fluid_volume_mesh(cylinder, solid, MESH_CURVATURE_POINTS, MESH_MIN_SIZE * Dmm, MESH_MAX_SIZE * Dmm)


def _mesh_params():
    out = []
    for c in CASES:
        marks = []
        if c.mesh_xfail:
            marks.append(pytest.mark.xfail(reason=c.mesh_xfail, strict=False))
        if c.slow or c.mesh_xfail:
            marks.append(pytest.mark.skipif(not SLOW, reason="slow (minutes); set BLADESMITH_SLOW=1"))
        out.append(pytest.param(c, marks=marks, id=c.name))
    return out


@pytest.mark.parametrize("mesh_case", _mesh_params())
def test_fluid_around_the_propeller_volume_meshes(mesh_case, tmp_path_factory):
    model, _, _, path = built(mesh_case, tmp_path_factory)
    D = 2.0 * model.blade.radius
    _, sewing, solid, _ = sewn_solid(path, D)
    assert sewing.NbFreeEdges() == 0 and solid is not None
    valid, tets, min_sicn = _fluid_mesh(solid, D)
    assert valid
    assert tets > 1000
    assert min_sicn > MIN_SICN, f"min SICN {min_sicn:.4g}"


def test_turned_copies_of_the_reference_set_sew_into_one_valid_solid(case, tmp_path_factory):
    """Hally's §11 set as a CFD engineer uses it: the reference blade and the hub sector
    trimmed by the blade root edge, turned Z times in OCC and sewn at 1e-7 D: one closed
    shell (the ±π/Z edges of neighbouring copies and the root junction all meet)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing, BRepBuilderAPI_Transform
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt, gp_Trsf
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopoDS import TopoDS

    from bladesmith.iges.propeller import write_propeller_iges

    model, blade, sector, _ = built(case, tmp_path_factory)
    D = 2.0 * model.blade.radius
    path = write_propeller_iges(tmp_path_factory.mktemp("ref") / f"{case.name}.igs", model, blade, sector)
    occ = read_with_occ(path)
    assert occ.load_messages == [] and occ.transfer_messages == [] and len(occ.faces) == 6
    sewing = BRepBuilderAPI_Sewing(SEWING_TOL_FRACTION * D * MM_PER_M)
    for k in range(model.blades):
        turn = gp_Trsf()
        turn.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, -1)), 2.0 * np.pi * k / model.blades)  # θ sense
        for face in occ.faces:
            sewing.Add(BRepBuilderAPI_Transform(face, turn, True).Shape())
    sewing.Perform()
    assert sewing.NbFreeEdges() == 0 and sewing.NbMultipleEdges() == 0
    shell = sewing.SewedShape()
    assert shell.ShapeType() == TopAbs_SHELL
    assert BRepCheck_Analyzer(BRepBuilderAPI_MakeSolid(TopoDS.Shell(shell)).Solid()).IsValid()


def test_brep_186_is_one_valid_solid_with_the_sewn_volume(case, tmp_path_factory):
    """The whole propeller as an IGES 186 manifold solid B-rep: OCC reads one valid solid
    with 0 messages, 5Z + 1 faces, and its volume equals the sewn shell's to 1e-9."""
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_SOLID

    model, blade, sector, path = built(case, tmp_path_factory)
    D = 2.0 * model.blade.radius
    brep = write_full_propeller_iges(tmp_path_factory.mktemp("brep") / f"{case.name}.igs", model, blade, sector,
                                     brep=True)
    lines = pathlib.Path(brep).read_text().splitlines()
    types = {int(line[:8]) for line in lines[::1] if len(line) >= 73 and line[72] == "D"}
    assert {186, 502, 504, 508, 510, 514} <= types
    occ = read_with_occ(brep)
    assert occ.load_messages == [] and occ.transfer_messages == []
    assert occ.shape.ShapeType() == TopAbs_SOLID and BRepCheck_Analyzer(occ.shape).IsValid()
    assert len(occ.faces) == faces_per_blade() * model.blades + 1
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(occ.shape, props, VOLUME_EPS)
    _, _, _, sewn_volume = sewn_solid(path, D)
    assert props.Mass() / MM_PER_M**3 == pytest.approx(sewn_volume, rel=1e-9)
