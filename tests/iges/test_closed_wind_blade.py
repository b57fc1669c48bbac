"""The wind blade closed for CFD or FE: the mold surfaces plus root and tip caps
(:func:`bladesmith.iges.mold.write_closed_blade`), read by OpenCASCADE, sewn at 1e-7 of the
blade's size into one closed shell and made a valid solid. The mold halves stay the
default export; this is the opt-in closed form.

S823_SMALL and NREL 5-MW run always (NREL's build is about 1 s, each of its fluid meshes
about 5 s).
"""
from __future__ import annotations

import pathlib

import numpy as np
import pytest

pytest.importorskip("OCP")

from bladesmith.geometry.errors import GeometryError  # noqa: E402
from bladesmith.geometry.mold.blade import build_blade  # noqa: E402
from bladesmith.geometry.mold.caps import blade_caps, closed_surfaces  # noqa: E402
from bladesmith.geometry.mold.definition import load_blade  # noqa: E402
from bladesmith.iges.mold import write_closed_blade  # noqa: E402
from occ_support import fluid_volume_mesh, read_with_occ  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
SEWING_TOL_FRACTION = 1e-7
_MOLDS: dict = {}


def molds_of(name):
    if name not in _MOLDS:
        _MOLDS[name] = build_blade(load_blade(ROOT / "data" / "blades" / f"{name}.toml"), fairness=False)
    return _MOLDS[name]


BLADES = ["s823_small", "nrel5mw"]


@pytest.mark.parametrize("caps", ["ruled", "rounded"])
@pytest.mark.parametrize("name", BLADES)
def test_closed_blade_sews_into_one_valid_solid(name, caps, tmp_path):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopoDS import TopoDS

    molds = molds_of(name)
    path = write_closed_blade(tmp_path / f"{name}.igs", molds, caps=caps)
    occ = read_with_occ(path)
    assert occ.load_messages == [] and occ.transfer_messages == []
    assert len(occ.faces) == len(closed_surfaces(molds)) + 2
    size = max(float(np.ptp(s.control_points.reshape(-1, 3), axis=0).max()) for s in molds.surfaces.values())
    sewing = BRepBuilderAPI_Sewing(SEWING_TOL_FRACTION * size * 1000.0)  # OCC reads millimetres
    for face in occ.faces:
        sewing.Add(face)
    sewing.Perform()
    assert sewing.NbFreeEdges() == 0 and sewing.NbMultipleEdges() == 0
    assert sewing.SewedShape().ShapeType() == TopAbs_SHELL
    solid = BRepBuilderAPI_MakeSolid(TopoDS.Shell(sewing.SewedShape())).Solid()
    assert BRepCheck_Analyzer(solid).IsValid()
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(solid, props, 1e-9)
    print(f"\n{name} ({caps} caps): {len(occ.faces)} faces, {sewing.NbFreeEdges()} free edges, valid solid, "
          f"volume {props.Mass() * 1e-9:.6g} m3")
    assert props.Mass() > 0  # the caps' normals point out, like the mold surfaces'


def test_cap_edges_are_the_halves_end_rows():
    """The ruled caps' long edges are the halves' end rows (the same curves, after exact
    knot insertion) and the tip's planar form is refused where the section is not planar."""
    molds = molds_of("s823_small")
    root, tip = blade_caps(molds)
    u = np.linspace(0.0, 1.0, 101)
    for cap, surfaces, v in ((root, (molds.transition_upper, molds.transition_lower), 0.0),
                             (tip, (molds.upper, molds.lower), 1.0)):
        up, lo = surfaces
        edges = [cap.evaluate(u, np.zeros_like(u)), cap.evaluate(u, np.ones_like(u))]
        ref_up = up.evaluate(u, np.full_like(u, v))
        ref_lo = lo.evaluate(1.0 - u, np.full_like(u, v))
        gap = min(max(np.abs(edges[0] - ref_up).max(), np.abs(edges[1] - ref_lo).max()),
                  max(np.abs(edges[1] - ref_up).max(), np.abs(edges[0] - ref_lo).max()))
        assert gap <= 1e-12 * float(np.ptp(ref_up, axis=0).max())
        # outward normal: away from the blade's mid-span point
        D = cap.derivatives(0.5, 0.5, 1)
        normal = np.cross(D[1, 0], D[0, 1])
        mid = 0.5 * (molds.upper.evaluate(0.5, 0.5) + molds.lower.evaluate(0.5, 0.5))
        assert float(normal @ (cap.evaluate(0.5, 0.5) - mid)) > 0
    with pytest.raises(GeometryError, match="not planar"):
        blade_caps(molds, "planar")


def test_rounded_tip_is_tangent_to_the_halves_and_beyond_the_tip():
    """The rounded tip (issue 16, the user's choice of rounded caps): its long edges are the
    halves' last rows, it lies outside the tip section's cylinder (a dome, not a dent), its
    normal along those edges is the halves' (G1 within 0.01°), and the root stays planar
    (the flange face)."""
    from bladesmith.geometry.mold.caps import Cap
    from bladesmith.geometry.nurbs.projection import closest_point_curve

    molds = molds_of("s823_small")
    root, tip = blade_caps(molds, "rounded")
    assert isinstance(root, Cap)
    u = np.linspace(0.0, 1.0, 101)
    r_tip = molds.definition.stations[-1].r
    chord = molds.definition.stations[-1].chord
    dome = tip.evaluate(u, np.full_like(u, 0.5))
    beyond = np.hypot(dome[:, 0], dome[:, 2]) - r_tip
    assert beyond.min() >= -1e-12 * r_tip and beyond.max() > 0.02 * chord
    ui = np.linspace(0.05, 0.95, 19)
    for w, half in ((0.0, molds.upper), (1.0, molds.lower)):
        edge = tip.evaluate(ui, np.full_like(ui, w))
        t, d = closest_point_curve(half.iso_curve("v", 1.0), edge)[:2]
        assert np.max(d) <= 1e-12 * molds.upper.size()
        n_cap = tip.normal(ui, np.full_like(ui, w))
        n_half = half.normal(np.asarray(t), np.ones_like(t))
        angle = np.degrees(np.arccos(np.clip(np.abs(np.einsum("ij,ij->i", n_cap, n_half)), 0.0, 1.0)))
        assert angle.max() < 0.01, f"tip cap not tangent to the halves: {angle.max():.3g}°"


# ---------------------------------------------------------------------------------------
# the fluid around the closed blade, volume-meshed by gmsh with no repair (issue 16, item 5)
# ---------------------------------------------------------------------------------------
#: The fluid domain: the blade's bounding box grown by this fraction of its largest side.
BOX_MARGIN = 0.25
#: Coarse, curvature-adapted sizing (fractions of the blade's largest side L): gmsh's
#: MeshSizeFromCurvature elements per 2π, between MESH_MIN_SIZE and MESH_MAX_SIZE.
MESH_CURVATURE_POINTS = 8
MESH_MAX_SIZE = 0.15
MESH_MIN_SIZE = 0.005
#: Below SICN 0.05 a tetrahedron is a sliver that finite-volume solvers flag (its faces
#: meet at beyond ~85° non-orthogonality) and finite-element stiffness matrices lose
#: conditioning; the propeller mesh test (test_full_propeller_mesh.py) uses the same bar.
MIN_SICN = 0.05

#: (Blade, caps) whose closed solid is valid but whose coarse mesh is known to miss MIN_SICN, with
#: the cause measured; everything else is still asserted, and the test fails if they pass.
KNOWN_SLIVERS = {
    ("nrel5mw", "ruled"): "the flat ruled tip cap (1.42 m chord, 0.26 m thick) meets the upper half's tip row, "
                          "which gmsh splits into 0.9 m segments (the row's own curvature is low); the cap's "
                          "triangle on such a segment is a needle, 11 mm high, and its tetrahedron a sliver "
                          "(measured min SICN 0.033, one tetrahedron). The rounded tip's curvature refines that "
                          "row (min SICN 0.187)",
}

MESH_CASES = [
    pytest.param("s823_small", "ruled", id="s823_small-ruled"),
    pytest.param("s823_small", "rounded", id="s823_small-rounded"),
    pytest.param("nrel5mw", "ruled", id="nrel5mw-ruled"),
    pytest.param("nrel5mw", "rounded", id="nrel5mw-rounded"),
]


def _fluid_mesh(solid, size_mm: float):
    """Cut ``solid`` from a box around it in OCC and mesh the fluid in 3-D with gmsh at the
    coarse curvature-adapted size, no repair (:func:`occ_support.fluid_volume_mesh`): (OCC
    validity of the fluid, number of tetrahedra, min SICN)."""
    from OCP.BRepBndLib import BRepBndLib
    from OCP.Bnd import Bnd_Box
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.gp import gp_Pnt

    pytest.importorskip("gmsh")
    box = Bnd_Box()
    BRepBndLib.Add_s(solid, box)
    lo, hi = box.CornerMin(), box.CornerMax()
    m = BOX_MARGIN * size_mm
    domain = BRepPrimAPI_MakeBox(gp_Pnt(lo.X() - m, lo.Y() - m, lo.Z() - m),
                                 gp_Pnt(hi.X() + m, hi.Y() + m, hi.Z() + m)).Shape()
    return fluid_volume_mesh(domain, solid, MESH_CURVATURE_POINTS, MESH_MIN_SIZE * size_mm, MESH_MAX_SIZE * size_mm)


@pytest.mark.parametrize("name, caps", MESH_CASES)
def test_fluid_around_the_closed_blade_volume_meshes(name, caps, tmp_path):
    """Issue 16, item 5: the closed blade (sewn at 1e-7 × size, a valid solid) cut from a
    box in OCC; gmsh meshes the fluid in 3-D at a coarse curvature-adapted size with no
    repair, every tetrahedron above MIN_SICN."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.TopoDS import TopoDS

    molds = molds_of(name)
    occ = read_with_occ(write_closed_blade(tmp_path / f"{name}.igs", molds, caps=caps))
    assert occ.load_messages == [] and occ.transfer_messages == []
    size = max(float(np.ptp(s.control_points.reshape(-1, 3), axis=0).max()) for s in molds.surfaces.values())
    sewing = BRepBuilderAPI_Sewing(SEWING_TOL_FRACTION * size * 1000.0)
    for face in occ.faces:
        sewing.Add(face)
    sewing.Perform()
    assert sewing.NbFreeEdges() == 0
    solid = BRepBuilderAPI_MakeSolid(TopoDS.Shell(sewing.SewedShape())).Solid()
    assert BRepCheck_Analyzer(solid).IsValid()
    valid, tets, min_sicn = _fluid_mesh(solid, size * 1000.0)
    print(f"\n{name} ({caps} caps): {tets} tetrahedra, min SICN {min_sicn:.4g}")
    assert valid and tets > 1000
    if (name, caps) in KNOWN_SLIVERS:
        assert min_sicn <= MIN_SICN, f"{name} now meshes (min SICN {min_sicn:.4g}): drop it from KNOWN_SLIVERS"
        pytest.xfail(f"min SICN {min_sicn:.4g}: {KNOWN_SLIVERS[name, caps]}")
    assert min_sicn > MIN_SICN, f"min SICN {min_sicn:.4g}"


# ---------------------------------------------------------------------------------------
# the trailing-edge base as part of the lower face (issue 16: NREL 5-MW's closed blade)
# ---------------------------------------------------------------------------------------
def test_lower_face_with_the_trailing_edge_base_is_the_halves_and_the_base():
    """NREL 5-MW's closed blade: its trailing-edge bases (blunt over the whole span since
    the preset opens its sharp stations to 4 mm) are part of the lower faces. The merged
    face is C1 (OCC reads it without a C0 warning), equals the lower half and the base
    outside the corner blend, ends exactly on the upper half's TE column and the LE
    parting line, and rounds the corner by a fraction of the base's width."""
    from bladesmith.geometry.mold.caps import CORNER_BLEND

    molds = molds_of("nrel5mw")
    faces = closed_surfaces(molds)
    assert "trailing_edge" not in faces and "transition_trailing_edge" not in faces
    # the root joint: one row for both merged faces, copied
    assert np.array_equal(faces["transition_lower"].control_points[:, -1], faces["lower"].control_points[:, 0])
    assert not any(k.startswith("trailing_edge") for k in faces)
    for lower, base, upper in ((molds.lower, molds.surfaces["trailing_edge"], molds.upper),
                               (molds.transition_lower, molds.surfaces["transition_trailing_edge"],
                                molds.transition_upper)):
        name = "lower" if lower is molds.lower else "transition_lower"
        m = faces[name]
        p = m.degree_u
        K = m.knots_u
        inner, counts = np.unique(K[p + 1:-p - 1], return_counts=True)
        assert counts.max() <= p - 1, "the merged face must be C1 (no C0 knot)"
        assert np.array_equal(m.control_points[-1], upper.control_points[0])  # shared TE edge, copied
        assert np.array_equal(m.control_points[0], lower.control_points[0])  # LE parting line, copied
        ua, ub = inner[counts == p - 1][-2:]
        s = K[p + 1] / lower.knots_u[p + 1]
        size = lower.size()
        v = np.linspace(0.0, 1.0, 41)
        for u in np.linspace(0.0, ua, 9):
            assert np.abs(m.evaluate(u, v) - lower.evaluate(u / s, v)).max() <= 1e-12 * size
        for u in np.linspace(ub, 1.0, 5):
            assert np.abs(m.evaluate(u, v) - base.evaluate((u - s) / (1.0 - s), v)).max() <= 1e-12 * size
        # the corner: the blend cuts it by less than its legs (the blend's share of the widest base;
        # the lower-side leg is set from the mean width, so it is not shorter where the base is thin)
        corner = lower.evaluate(1.0, v)
        width = np.linalg.norm(upper.evaluate(0.0, v) - corner, axis=1)
        cut = np.linalg.norm(m.evaluate(s, v) - corner, axis=1)
        print(f"\n{name}: TE corner rounded by {1e3 * cut.max():.2f} mm at most "
              f"(base {1e3 * width.min():.1f}-{1e3 * width.max():.1f} mm wide)")
        assert np.all(cut < CORNER_BLEND * width.max()) and cut.max() < 1.5e-3


@pytest.mark.parametrize("caps", ["ruled", "rounded"])
def test_gmsh_reads_the_closed_nrel5mw_without_complaints(caps, tmp_path):
    """The closed NREL 5-MW file itself (its merged, C1 lower faces among them) imported by
    gmsh and meshed in 2-D: every face gets inner nodes, gmsh's log has no warning or error."""
    gmsh = pytest.importorskip("gmsh")
    molds = molds_of("nrel5mw")
    path = write_closed_blade(tmp_path / f"nrel5mw_{caps}.igs", molds, caps=caps)
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.logger.start()
        gmsh.model.occ.importShapes(str(path))
        gmsh.model.occ.synchronize()
        faces = gmsh.model.getEntities(2)
        assert len(faces) == len(closed_surfaces(molds)) + 2
        lo, hi = np.array(gmsh.model.getBoundingBox(-1, -1)).reshape(2, 3)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.002 * float(np.max(hi - lo)))  # 0.13 m: inner nodes on the caps
        gmsh.model.mesh.generate(2)
        for dim, tag in faces:
            assert len(gmsh.model.mesh.getNodes(dim, tag, includeBoundary=False)[0]) > 0, f"face {tag}"
        complaints = [line for line in gmsh.logger.get() if line.startswith(("Error", "Warning"))]
        gmsh.logger.stop()
    finally:
        gmsh.finalize()
    assert complaints == [], complaints
