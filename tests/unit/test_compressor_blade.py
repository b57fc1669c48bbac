"""Channel, blades and their continuity (Casey 1983, Figs. 5–7, Appendix A1–A5)."""
import math
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.compressor import (
    ImpellerDefinition, axial_section, blade_net, casey_shooting, cubic_string_through, distribution, rulings,
    scaled_channel, standardise, surface_end_angles, write_net_csv,
)
from bladesmith.geometry.compressor.uses import ruling_hub_angles
from bladesmith.geometry.errors import DefinitionError
from bladesmith.geometry.nurbs import closest_point_curve

PRESETS = pathlib.Path(__file__).resolve().parents[2] / "data" / "impellers"
NAMES = sorted(p.stem for p in PRESETS.glob("*.toml"))
#: Acceptance tolerances (issue 8).
C2_TOL = 1e-9
ANGLE_TOL = 1e-9
EDGE_TOL = 1e-9
SECTION_TOL = 1e-9


@pytest.fixture(scope="module")
def models():
    return {n: ImpellerDefinition.from_toml(PRESETS / f"{n}.toml").build() for n in NAMES}


def test_presets_exist():
    assert {"high_flow", "intermediate_flow", "low_flow", "return_channel"} <= set(NAMES)


def test_direct_end_conditions_equal_casey_shooting():
    rng = np.random.default_rng(1)
    X = np.cumsum(rng.random((6, 3)), axis=0)
    d0, d1 = rng.random(3), rng.random(3)
    a = cubic_string_through(X, d0, d1)
    b = casey_shooting(X, d0, d1)
    for sa, sb in zip(a.segments, b.segments):
        assert np.allclose(sa.control_points, sb.control_points, atol=1e-9)
    # Eq. A2 recurrence, A3, A4
    S = [s.control_points for s in a.segments]
    for j in range(len(S) - 1):
        aj, bj, cj, dj = S[j]
        assert np.allclose(S[j + 1][1], 2 * dj - cj) and np.allclose(S[j + 1][2], bj + 4 * dj - 4 * cj)
    assert np.allclose(3 * (S[0][1] - S[0][0]), d0) and np.allclose(3 * (S[-1][3] - S[-1][2]), d1)


@pytest.mark.parametrize("name", NAMES)
def test_channel_slope_and_curvature_continuous(models, name):
    for which, (angles, curvatures) in models[name].channel.junction_report().items():
        assert np.all(angles < 1e-12) and np.all(curvatures < 1e-9), which


@pytest.mark.parametrize("name", NAMES)
def test_blade_c2_and_imposed_angles(models, name):
    m = models[name]
    for blade in filter(None, (m.blade, m.splitter)):
        for s in "BSP":
            surf = blade.surface(s)
            for string in (surf.lower, surf.upper):
                assert np.max(string.junction_jumps(2)) < C2_TOL
            got = surface_end_angles(surf)
            want = blade.imposed_angles[s]
            ok = np.isfinite(want)
            assert np.max(np.abs(got[ok] - want[ok])) < ANGLE_TOL
        # corner points of B, S and P lie on the hub and shroud contours
        corners = np.array([seg.control_points[0] for seg in blade.camber.lower.segments])
        zr = np.stack([corners[:, 2], np.hypot(corners[:, 0], corners[:, 1])], 1)
        assert closest_point_curve(m.channel.hub.to_bspline(), zr)[1].max() < 1e-12


def test_camber_matches_beta(models):
    """The imposed LE angle is β_LE of the definition (B surface)."""
    d = ImpellerDefinition.from_toml(PRESETS / "high_flow.toml")
    b = models["high_flow"].blade
    assert abs(b.imposed_angles["B"][0, 0] - math.radians(d.blade.beta_hub[0])) < ANGLE_TOL
    assert abs(b.imposed_angles["B"][1, 1] - math.radians(d.blade.beta_shroud[-1])) < ANGLE_TOL


def test_axial_elements(models):
    m = models["low_flow"]
    assert m.blade.axial_elements
    L = rulings(m.blade.suction, np.linspace(0, 1, 33))
    d = L[:, 1] - L[:, 0]
    assert np.max(np.hypot(d[:, 0], d[:, 1])) < 1e-12
    # the shroud edge follows the shroud wall of the passage, not the inlet that reaches
    # the same radii upstream (it stood 9 mm off the wall when the first crossing was taken)
    wall = m.channel.shroud.to_bspline()
    for s in (m.blade.suction, m.blade.pressure, m.blade.camber):
        X = s.upper.evaluate(np.linspace(0, s.count, 801))
        zr = np.column_stack([X[:, 2], np.hypot(X[:, 0], X[:, 1])])
        assert closest_point_curve(wall, zr)[1].max() < 1e-5  # the cubic z(r) between corners


@pytest.mark.parametrize("factor", [0.8, 1.1])
def test_standardisation_edges_on_new_channel(models, factor):
    m = models["high_flow"]
    ch = scaled_channel(m.channel, factor)
    U = np.linspace(0, m.blade.count, 201)
    for s in "BSP":
        st = standardise(m.blade.surface(s), ch)
        P = st.evaluate(U, [0.0, 1.0])
        zr = np.stack([P[..., 2], np.hypot(P[..., 0], P[..., 1])], -1)
        assert closest_point_curve(ch.hub.to_bspline(), zr[:, 0])[1].max() < EDGE_TOL
        assert closest_point_curve(ch.shroud.to_bspline(), zr[:, 1])[1].max() < EDGE_TOL
        vh, vs = st.bounds(U)
        if factor > 1:
            assert vs.max() > 1.0  # extrapolated linearly beyond the original shroud


@pytest.mark.parametrize("name", ["high_flow", "intermediate_flow"])
def test_axial_sections_agree_with_direct_intersection(models, name):
    from scipy.optimize import brentq

    surf = models[name].blade.suction
    bs = surf.to_bspline()
    zmin, zmax = (np.min(surf.lower.evaluate(np.linspace(0, surf.count, 50))[:, 2]),
                  np.max(surf.upper.evaluate(np.linspace(0, surf.count, 50))[:, 2]))
    for z in np.linspace(zmin, zmax, 5)[1:-1]:
        U, v, P = axial_section(surf, z)
        assert len(U) > 0
        for Ui, Pi in zip(U[:: max(1, len(U) // 8)], P[:: max(1, len(U) // 8)]):
            f = lambda t: bs.evaluate(Ui, t)[2] - z  # noqa: E731
            if f(0.0) * f(1.0) > 0:
                continue
            t = brentq(f, 0.0, 1.0, xtol=1e-15)
            assert np.linalg.norm(bs.evaluate(Ui, t) - Pi) < SECTION_TOL


def test_nets_and_csv(models, tmp_path):
    s = models["high_flow"].blade.pressure
    u, v = distribution(21, 2.0, 2.0), distribution(7)
    net = blade_net(s, u, v)
    assert net.shape == (21, 7, 3)
    path = tmp_path / "net.csv"
    write_net_csv(path, net, u, v)
    rows = path.read_text().splitlines()
    assert rows[0] == "i,j,u,v,x,y,z" and len(rows) == 1 + 21 * 7
    assert np.allclose(np.array(rows[-1].split(","), float)[4:], net[-1, -1])


def test_rulings_nearly_normal_to_hub(models):
    m = models["high_flow"]
    ang = np.degrees(ruling_hub_angles(m.blade.suction, m.channel, np.linspace(0, 1, 11)))
    assert abs(ang[0] - 90.0) < 1e-6  # the radial LE element is normal to the axial hub
    assert np.all((ang > 20) & (ang < 160))


def _definition(**changes):
    import tomllib

    data = tomllib.loads((PRESETS / "high_flow.toml").read_text())
    for key, value in changes.items():
        section, field = key.split("__")
        data[section][field] = value
    return ImpellerDefinition.from_dict(data)


@pytest.mark.parametrize("changes, field", [
    ({"channel__shroud_r": [0.13, 0.13, 0.145, 0.20, 0.28], "channel__shroud_z": [-0.14, -0.08, -0.04, 0.03, 0.03]},
     "channel.shroud_r"),
    ({"blade__leading_edge_hub": 3.0, "blade__trailing_edge_hub": 1.5}, "blade.leading_edge_hub"),
    ({"blade__thickness_hub": [0.004, -0.001, 0.003, 0.002]}, "blade.thickness_hub"),
    ({"channel__hub_fractions": [[0.5, 0.5], [1.5, 0.5], [0.5, 0.5], [0.5, 0.5]]}, "channel.hub_fractions"),
])
def test_bad_skeletal_data_is_refused_with_the_field(changes, field):
    with pytest.raises(DefinitionError) as err:
        _definition(**changes).build()
    assert err.value.field == field and field in str(err.value)
