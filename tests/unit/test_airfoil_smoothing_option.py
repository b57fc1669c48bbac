"""Issue 6: the propeller's ``section.smooth_airfoil`` and the wind blade's
``smooth_airfoils`` run the airfoil files through Hvid's (1993) smoothfoil first (default
jobcard). Off by default; a smoothing that fails is a DefinitionError naming the file.
Figures printed with ``pytest -s``."""
import pathlib
import time
import tomllib

import numpy as np
import pytest

from bladesmith.geometry.errors import DefinitionError
from bladesmith.geometry.fairing import SmoothingNotConverged, count_sign_changes, curve_sign_changes
from bladesmith.geometry.fairing import hvid
from bladesmith.geometry.fairing.hvid import spline_through
from bladesmith.geometry.mold import blade_from_dict, build_blade, load_preset
from bladesmith.geometry.mold import definition as mold_definition
from bladesmith.geometry.propeller import Propeller, dumps_toml
from bladesmith.geometry.sections import SectionShape, read_airfoil, thickness_and_camber
from bladesmith.geometry.sections.airfoil_file import airfoil_from_outline, smoothed_airfoil

ROOT = pathlib.Path(__file__).resolve().parents[2]
DTMB = ROOT / "data" / "propellers" / "dtmb4119.toml"
BLADES = ROOT / "data" / "blades"
S823 = BLADES / "airfoils" / "s823.dat"
#: ψ samples of the section shapes (TE and LE excluded: the curvature formula below
#: divides by the speed, which is finite there, but the ends repeat the TE).
PSI = np.linspace(0.0, 2.0 * np.pi, 8001)[1:-1]


def _not_converged(*args, **kwargs):
    raise SmoothingNotConverged("smoothfoil: the smoothing did not converge", [(1.0, 0.5), (3.0, 2.0)],
                                "a step of 1.77 exceeds 0.05 of the reference length (diverging)")


# -- the propeller ------------------------------------------------------------------------------
def _airfoil_definition(tmp_path, smooth=None, name="p.toml") -> pathlib.Path:
    text = DTMB.read_text().replace('thickness = "naca66mod"', f'thickness = "{S823.as_posix()}"')
    text = text.replace('meanline = "a=0.8"', 'meanline = "airfoil"')
    if smooth is not None:
        text = text.replace('meanline = "airfoil"', f'meanline = "airfoil"\nsmooth_airfoil = {str(smooth).lower()}')
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def shapes():
    """The S823 section shape read as is and smoothed, and the seconds each took."""
    start = time.perf_counter()
    raw = SectionShape.from_spec(str(S823), "airfoil")
    middle = time.perf_counter()
    smoothed = SectionShape.from_spec(str(S823), "airfoil", smooth_airfoil=True)
    end = time.perf_counter()
    return raw, smoothed, middle - start, end - middle


def _thickness_curvature(shape: SectionShape) -> np.ndarray:
    """Exact curvature of the unit-chord thickness form (X, Y) = (x(ψ), S(ψ)) from the
    spline's derivatives: X = (1 + cos ψ)/2."""
    x1, x2 = -0.5 * np.sin(PSI), -0.5 * np.cos(PSI)
    y1, y2 = shape.half_thickness(PSI, 1), shape.half_thickness(PSI, 2)
    return (x1 * y2 - y1 * x2) / np.hypot(x1, y1) ** 3


def test_propeller_default_is_off_and_unchanged(tmp_path):
    implicit = Propeller.from_toml(_airfoil_definition(tmp_path))
    explicit = Propeller.from_toml(_airfoil_definition(tmp_path, smooth=False, name="q.toml"))
    assert implicit.section.smooth_airfoil is False and explicit == implicit
    reference = SectionShape.from_spec(str(S823), "airfoil")  # no smoothing argument at all
    for p in (implicit, explicit):
        shape = p.section.shape(p.base_dir, p.source)
        assert np.array_equal(shape.thickness.c, reference.thickness.c)
        assert np.array_equal(shape.thickness.x, reference.thickness.x)
        assert np.array_equal(shape.meanline.c, reference.meanline.c)
    # and the airfoil the section is made from is the file's, bit for bit
    raw = read_airfoil(S823)
    xs = np.linspace(0.0, 1.0, 301)
    t, f = thickness_and_camber(raw, xs)
    t2, f2 = thickness_and_camber(read_airfoil(S823), xs)
    assert np.array_equal(t, t2) and np.array_equal(f, f2)


def test_propeller_smoothed_section_differs_slightly(shapes):
    raw, smoothed, t_raw, t_smoothed = shapes
    airfoil = read_airfoil(S823)
    t_max = float(np.max(thickness_and_camber(airfoil, np.linspace(0.0, 1.0, 20001))[0]))  # 0.21 c
    # half-thickness in chord units for the airfoil's own thickness (S is normalised to max thickness 1)
    dh = t_max * np.abs(smoothed.half_thickness(PSI) - raw.half_thickness(PSI))
    dp = np.linalg.norm(smoothed.points(PSI, t_max, 0.02) - raw.points(PSI, t_max, 0.02), axis=-1)
    print(f"\nS823 smoothed: max half-thickness change {dh.max():.3e} c (t/c = {t_max:.4f}), max point "
          f"change {dp.max():.3e} c with f/c = 0.02; section built in {t_raw * 1e3:.0f} ms raw, "
          f"{t_smoothed * 1e3:.0f} ms smoothed")
    assert 0.0 < dh.max() < 1e-3
    assert 0.0 < dp.max() < 2e-3
    assert "smoothed" in smoothed.name and "smoothed" not in raw.name


def test_propeller_smoothed_section_has_no_more_inflections(shapes):
    raw, smoothed, _, _ = shapes
    before, after = count_sign_changes(_thickness_curvature(raw)), count_sign_changes(_thickness_curvature(smoothed))
    # the outline itself, as the cubic through the points: the smoother's own measure
    airfoil = read_airfoil(S823)
    outline_before = curve_sign_changes(spline_through(airfoil.outline, 2)[0])
    outline_after = curve_sign_changes(spline_through(smoothed_airfoil(airfoil).outline, 2)[0])
    print(f"\nS823 curvature sign changes: thickness form {before} -> {after}, outline {outline_before} -> "
          f"{outline_after}")
    assert after <= before
    assert outline_after <= outline_before


def test_propeller_builds_with_the_smoothed_section(tmp_path):
    raw = Propeller.from_toml(_airfoil_definition(tmp_path))
    start = time.perf_counter()
    p = Propeller.from_toml(_airfoil_definition(tmp_path, smooth=True, name="s.toml"))
    smoothed_model = p.build()
    seconds = time.perf_counter() - start
    raw_model = raw.build()
    print(f"\nS823 propeller load + build with smoothing: {seconds:.2f} s")
    a, b = raw_model.blade.sample(60, 40), smoothed_model.blade.sample(60, 40)
    change = np.abs(a - b).max()
    assert 0.0 < change < 1e-3 * p.diameter


def test_propeller_toml_round_trip_keeps_the_flag(tmp_path):
    p = Propeller.from_toml(_airfoil_definition(tmp_path, smooth=True))
    assert p.section.smooth_airfoil is True
    out = tmp_path / "out" / "copy.toml"
    out.parent.mkdir()
    p.to_toml(out)
    assert tomllib.loads(out.read_text())["section"]["smooth_airfoil"] is True
    q = Propeller.from_toml(out)
    assert q.section.smooth_airfoil is True
    assert q.with_values(section_thickness=p.section.thickness) == p  # the path is written relative
    # off (the default) is not written, so existing files stay as they were
    default = Propeller.from_toml(DTMB)
    default.to_toml(tmp_path / "dtmb.toml")
    assert "smooth_airfoil" not in (tmp_path / "dtmb.toml").read_text()
    assert p.with_values(section_smooth_airfoil=False).section.smooth_airfoil is False
    assert "smooth_passes" not in out.read_text()  # the default is not written


def test_propeller_smoothing_passes(tmp_path):
    """``smooth_passes``: fewer passes stay closer to the file; the value round-trips and
    the shape carries the measured deviation; bad values name the field."""
    path = _airfoil_definition(tmp_path, smooth=True)
    one = tmp_path / "one.toml"
    one.write_text(path.read_text().replace("smooth_airfoil = true", "smooth_airfoil = true\nsmooth_passes = 1"))
    p1, p4 = Propeller.from_toml(one), Propeller.from_toml(path)
    assert p1.section.smooth_passes == 1 and p4.section.smooth_passes == 4
    d1 = p1.section.shape(p1.base_dir, p1.source).smoothing_deviation
    d4 = p4.section.shape(p4.base_dir, p4.source).smoothing_deviation
    print(f"\nS823 smoothed: deviation {d1:.2e} c with 1 pass, {d4:.2e} c with 4")
    assert 0.0 < d1 < 0.5 * d4 < 1e-3
    assert SectionShape.from_spec(str(S823), "airfoil").smoothing_deviation is None
    out = tmp_path / "copy.toml"
    p1.to_toml(out)
    assert tomllib.loads(out.read_text())["section"]["smooth_passes"] == 1
    for bad in ("0", "2.5", "true", "51"):
        one.write_text(path.read_text().replace("smooth_airfoil = true", f"smooth_airfoil = true\nsmooth_passes = {bad}"))
        with pytest.raises(DefinitionError, match="passes") as info:
            Propeller.from_toml(one)
        assert info.value.field == "section.smooth_passes"


def test_propeller_smoothing_needs_an_airfoil_file(tmp_path):
    text = DTMB.read_text().replace('meanline = "a=0.8"', 'meanline = "a=0.8"\nsmooth_airfoil = true')
    path = tmp_path / "formula.toml"
    path.write_text(text)
    with pytest.raises(DefinitionError, match="airfoil") as info:
        Propeller.from_toml(path)
    assert info.value.field == "section.smooth_airfoil" and info.value.path == str(path.resolve())
    assert "naca66mod" in str(info.value)
    with pytest.raises(DefinitionError) as info:
        SectionShape.from_spec("naca66mod", "a=0.8", smooth_airfoil=True)
    assert info.value.field == "section.smooth_airfoil"
    path.write_text(text.replace("smooth_airfoil = true", 'smooth_airfoil = "yes"'))
    with pytest.raises(DefinitionError, match="true or false") as info:
        Propeller.from_toml(path)
    assert info.value.field == "section.smooth_airfoil"


def test_propeller_non_convergence_is_a_definition_error(tmp_path, monkeypatch):
    monkeypatch.setattr(hvid, "smooth_airfoil_result", _not_converged)
    p = Propeller.from_toml(_airfoil_definition(tmp_path, smooth=True))
    with pytest.raises(DefinitionError, match="s823.dat") as info:
        p.build()
    assert info.value.field == "section.smooth_airfoil" and info.value.path == p.source
    assert "did not converge" in str(info.value) and "diverging" in str(info.value)


def test_airfoil_from_outline_normalises_like_the_reader():
    raw = read_airfoil(S823)
    again = airfoil_from_outline(raw.outline, raw.name, raw.format, raw.path)
    assert np.allclose(again.upper, raw.upper, atol=1e-15) and np.allclose(again.lower, raw.lower, atol=1e-15)
    smoothed = smoothed_airfoil(raw)
    assert (smoothed.name, smoothed.format, smoothed.path) == (raw.name, raw.format, raw.path)
    assert np.array_equal(smoothed.upper[0], [0.0, 0.0]) and np.array_equal(smoothed.lower[0], [0.0, 0.0])
    te = 0.5 * (smoothed.upper[-1] + smoothed.lower[-1])
    assert np.allclose(te, [1.0, 0.0], atol=1e-12)
    assert np.mean(smoothed.upper[:, 1]) > np.mean(smoothed.lower[:, 1])


def test_blunt_trailing_edge_airfoil_is_smoothed_and_stays_blunt():
    raw = read_airfoil(BLADES / "airfoils" / "nrel5mw_DU21_A17.dat")
    smoothed = smoothed_airfoil(raw)
    assert smoothed.trailing_edge_thickness == pytest.approx(raw.trailing_edge_thickness, rel=0.05)
    x = np.linspace(0.0, 1.0, 2001)
    dt = np.abs(thickness_and_camber(smoothed, x)[0] - thickness_and_camber(raw, x)[0]).max()
    print(f"\nDU21 (blunt TE {raw.trailing_edge_thickness:.4f} c): max thickness change {dt:.2e} c")
    assert 0.0 < dt < 5e-3
    shape = SectionShape.from_spec(str(BLADES / "airfoils" / "nrel5mw_DU21_A17.dat"), "airfoil", smooth_airfoil=True)
    assert np.max(np.abs(shape.half_thickness(PSI))) == pytest.approx(0.5)


# -- the wind blade -----------------------------------------------------------------------------
def _s823_data(**changes) -> dict:
    with open(BLADES / "s823_small.toml", "rb") as fh:
        data = tomllib.load(fh)
    data.update(changes)
    return data


def _load(data):
    path = BLADES / "s823_small.toml"
    return blade_from_dict(data, str(path), path.parent)


@pytest.fixture
def fresh_cache(monkeypatch):
    """An empty process-wide cache of smoothed airfoils, and a count of the smoothings."""
    monkeypatch.setattr(mold_definition, "_SMOOTHED", {})
    calls = []
    real = mold_definition.smoothed_airfoil

    def counting(foil, **options):
        calls.append(foil.path)
        return real(foil, **options)

    monkeypatch.setattr(mold_definition, "smoothed_airfoil", counting)
    return calls


def test_blade_default_is_off():
    defn = load_preset("S823_SMALL")
    assert defn.smooth_airfoils is False and defn.to_dict()["smooth_airfoils"] is False
    raw = read_airfoil(S823)
    for st in defn.stations[2:]:
        assert np.array_equal(st.airfoil.outline, raw.outline)


def test_blade_smoothed_airfoils_differ_slightly_and_build(fresh_cache):
    raw = load_preset("S823_SMALL")
    defn = _load(_s823_data(smooth_airfoils=True))
    assert defn.smooth_airfoils is True
    assert fresh_cache == [str(S823)], "the one airfoil file is smoothed once per load"
    for k, (a, b) in enumerate(zip(raw.stations, defn.stations)):
        if k < defn.first_aerodynamic_station:  # the root circles are kept
            assert np.array_equal(a.airfoil.outline, b.airfoil.outline)
            continue
        assert b.airfoil is defn.stations[2].airfoil
        assert b.airfoil_name == a.airfoil_name and b.chord == a.chord
    x = np.linspace(0.0, 1.0, 2001)
    t0, f0 = thickness_and_camber(raw.stations[2].airfoil, x)
    t1, f1 = thickness_and_camber(defn.stations[2].airfoil, x)
    dh, df = 0.5 * np.abs(t1 - t0).max(), np.abs(f1 - f0).max()
    start = time.perf_counter()
    molds = build_blade(defn)
    seconds = time.perf_counter() - start
    dev = max(s.deviation_two_part for s in molds.stations)
    print(f"\nS823 blade smoothed: max half-thickness change {dh:.2e} c, camber {df:.2e} c; built in "
          f"{seconds:.2f} s with {molds.control_points} control points per half, worst section {dev:.2e} c")
    assert 0.0 < dh < 1e-3 and 0.0 < df < 1e-3
    assert dev <= defn.tolerance
    # a second load reuses the smoothed airfoil
    _load(_s823_data(smooth_airfoils=True))
    assert len(fresh_cache) == 1


def test_blade_flag_round_trips_and_is_checked():
    defn = _load(_s823_data(smooth_airfoils=True))
    data = tomllib.loads(dumps_toml(defn.to_dict()))
    assert data["smooth_airfoils"] is True
    assert _load(data).smooth_airfoils is True
    with pytest.raises(DefinitionError, match="true or false") as info:
        _load(_s823_data(smooth_airfoils=1))
    assert info.value.field == "smooth_airfoils"
    assert _load(_s823_data(smooth_airfoils=True, smooth_passes=2)).smooth_passes == 2
    assert tomllib.loads(dumps_toml(_load(_s823_data(smooth_passes=3)).to_dict()))["smooth_passes"] == 3
    for bad in (0, 2.5, True, 51):
        with pytest.raises(DefinitionError, match="passes") as info:
            _load(_s823_data(smooth_airfoils=True, smooth_passes=bad))
        assert info.value.field == "smooth_passes"


def test_blade_non_convergence_names_the_station_and_airfoil(fresh_cache, monkeypatch):
    monkeypatch.setattr(hvid, "smooth_airfoil_result", _not_converged)
    with pytest.raises(DefinitionError) as info:
        _load(_s823_data(smooth_airfoils=True))
    message = str(info.value)
    assert info.value.field == "stations.airfoil[2]" and info.value.path.endswith("s823_small.toml")
    assert "station 2" in message and "airfoils/s823.dat" in message and "did not converge" in message
    assert not mold_definition._SMOOTHED, "a failure is not cached"


def test_nrel5mw_blade_smooths_every_airfoil_and_reports_the_deviation(fresh_cache):
    """NREL 5-MW: six airfoil files, four with blunt trailing edges (DU 35's end tangents
    meet 28 chords behind it, DU 30's 0.37 c: both take the gentle fallback extension);
    the root cylinders (structural zone) are not smoothed. Each smoothed airfoil carries
    its deviation, and it stays below 2.5e-3 c with the paper's jobcard."""
    data = tomllib.loads((BLADES / "nrel5mw.toml").read_text())
    data["smooth_airfoils"] = True
    defn = blade_from_dict(data, str(BLADES / "nrel5mw.toml"), BLADES)
    assert not any("Cylinder" in p for p in fresh_cache)
    assert len(fresh_cache) == len({p for p in fresh_cache}) == 6
    raw = load_preset("NREL5MW")
    seen = {}
    for k, (a, b) in enumerate(zip(raw.stations, defn.stations)):
        if k < defn.first_aerodynamic_station:
            assert b.airfoil.smoothing_deviation is None
            continue
        dev = b.airfoil.smoothing_deviation
        assert dev is not None and 0.0 < dev < 2.5e-3
        # a blunt trailing edge keeps its thickness to within twice the deviation
        assert abs(b.airfoil.trailing_edge_thickness - a.airfoil.trailing_edge_thickness) <= 2.0 * dev + 1e-12
        seen[b.airfoil_name] = dev
    print("\nNREL 5-MW airfoils smoothed, deviation / chord: "
          + ", ".join(f"{pathlib.Path(n).stem} {d:.2e}" for n, d in seen.items()))
