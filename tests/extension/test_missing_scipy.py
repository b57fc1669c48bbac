"""Without scipy the add-on still registers: the preferences and a sidebar panel say why,
and every operator is a disabled stand-in (poll False, the reason as poll message).

Runs in a subprocess so that hiding scipy cannot disturb the rest of the session.
"""
import json
import pathlib
import subprocess
import sys

import pytest

pytest.importorskip("bpy")

HERE = pathlib.Path(__file__).resolve().parent


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    out = tmp_path_factory.mktemp("missing_scipy") / "result.json"
    run = subprocess.run([sys.executable, str(HERE / "missing_scipy_driver.py"), str(out)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    return json.loads(out.read_text())


def test_registers_without_scipy(result):
    assert result["registered"], result.get("error")
    assert not result["scipy_loaded"]


def test_preferences_and_panel_say_why(result):
    assert result["preferences_registered"] and result["preferences_idname"] == "bladesmith"
    assert result["panel_category"] == "Bladesmith"
    for lines in (result["panel_lines"], result["preferences_lines"]):
        icon, title = lines[0]
        assert icon == "ERROR" and "scipy cannot be imported" in title
        text = " ".join(t for _, t in lines)
        assert "import of scipy halted" in text  # the real reason is shown
        assert "Install from Disk" in text


def test_operators_are_disabled_with_the_reason(result):
    assert set(result["polls"]) >= {"bladesmith.add_propeller", "export_scene.iges", "import_scene.iges",
                                    "bladesmith.add_wind_blade", "bladesmith.add_impeller"}
    assert not any(result["polls"].values()), result["polls"]
    for idname, message in result["calls"].items():
        assert "poll()" in message and "scipy cannot be imported" in message, (idname, message)


def test_unregisters_cleanly(result):
    assert result["types_after_unregister"] == []
    assert result["types_after_second_cycle"] == []
