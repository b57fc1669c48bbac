"""bpy.ops.bladesmith.load_sweep_variant (issue 23): a variant of a sweep folder into the
scene through the kind's own add operator; a propeller keeps the sweep's smoothing
settings; bad folders, indices and failed variants leave the scene unchanged."""
import pathlib
import textwrap

import bpy
import pytest

pytest.importorskip("pyarrow")

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _sweep(tmp_path, base: str, parameter: str, settings: str = ""):
    from bladesmith.sweep.runner import run_sweep
    from bladesmith.sweep.spec import load_spec

    path = tmp_path / "sweep.toml"
    path.write_text(textwrap.dedent(f"""
        base = "{ROOT / 'data' / base}"
        output = "out"
        {settings}
        [parameters]
        {parameter}
        [design]
        type = "grid"
        """))
    result = run_sweep(load_spec(path), serial=True, stream=None)
    return tmp_path / "out", result["rows"]


def test_load_impeller_variant_and_refusals(addon, scene, tmp_path):
    folder, rows = _sweep(tmp_path, "impellers/high_flow.toml",
                          'count = { field = "blade.count", values = [12, 0] }')
    assert [r["status"] for r in rows] == ["ok", "failed"]
    assert bpy.ops.bladesmith.load_sweep_variant(directory=str(folder), variant=0) == {"FINISHED"}
    root = bpy.context.active_object
    assert "count = 12" in root["definition_toml"]
    before = len(bpy.data.objects)
    with pytest.raises(RuntimeError, match="not in the sweep"):
        bpy.ops.bladesmith.load_sweep_variant(directory=str(folder), variant=7)
    with pytest.raises(RuntimeError, match="not a sweep folder"):
        bpy.ops.bladesmith.load_sweep_variant(directory=str(tmp_path), variant=0)
    with pytest.raises(RuntimeError, match="blade.count"):  # the failed variant: add_impeller refuses it
        bpy.ops.bladesmith.load_sweep_variant(directory=str(folder), key=rows[1]["key"][:6])
    assert len(bpy.data.objects) == before


def test_load_propeller_variant_with_its_smoothing(addon, scene, tmp_path):
    folder, rows = _sweep(tmp_path, "propellers/dtmb4119.toml",
                          'pitch_scale = { field = "radial.P_D", action = "scale", values = [1.05] }',
                          "[settings]\ndelta_c = 0.04\ntolerance = 1e-4\nfilter_iterations = 10\n"
                          "tip_smoothing_distance = 0.06")
    assert rows[0]["status"] == "ok"
    assert bpy.ops.bladesmith.load_sweep_variant(directory=str(folder), variant=0) == {"FINISHED"}
    root = next(o for o in bpy.context.scene.objects if o.bladesmith_propeller.is_propeller)
    s = root.bladesmith_propeller
    assert s.smooth_tip and s.tip_smoothing_distance == pytest.approx(0.06) and s.delta_c == pytest.approx(0.04)
    assert s.radial[0].P_D == pytest.approx(1.105 * 1.05)
