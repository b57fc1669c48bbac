"""The extension as users get it: ``make extension`` builds four platform zips that
validate and each carry exactly their scipy wheels, one for Python 3.11 (Blender 4.2 LTS to
5.0) and one for Python 3.13 (Blender 5.1 and 5.2 LTS); the linux-x64 zip installs into a
clean Blender user directory, enables, builds the tip-smoothed DTMB 4119, exports IGES that
OpenCASCADE reads without a fail or warning message, and disables. Then the README's
scripting recipe runs against the installed extension and must exit on its own.

The install runs in a subprocess (``BLENDER_USER_RESOURCES`` must be set before bpy starts)
against bpy 4.5 LTS (this venv), bpy 5.0 (``.venv-bpy5``, Python 3.11) and bpy 5.2 LTS
(``.venv-bpy52``, Python 3.13), the extra venvs created here on first use as
``make venv-bpy5`` / ``make venv-bpy52`` do (BLADESMITH_SKIP_BPY5=1 / BLADESMITH_SKIP_BPY52=1
skip those halves). scipy must come from the bundled wheel: the driver hides every other
scipy, and the extra venvs have none.
"""
import glob
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import time

import pytest

pytest.importorskip("bpy")

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
PLATFORMS = ("windows_x64", "macos_arm64", "macos_x64", "linux_x64")
#: The issue's bound for the scripting recipe, add-on left registered.
RECIPE_LIMIT_S = 30


def _python313() -> str:
    """Blender 5.1+ runs Python 3.13: $PYTHON313, python3.13 on PATH, or pyenv's."""
    candidates = [os.environ.get("PYTHON313"), shutil.which("python3.13"),
                  *sorted(glob.glob(os.path.expanduser("~/.pyenv/versions/3.13*/bin/python3.13")))]
    for candidate in filter(None, candidates):
        if subprocess.run([candidate, "-c", ""], capture_output=True).returncode == 0:
            return candidate
    pytest.fail("Python 3.13 not found (needed for the bpy 5.2 LTS half; set PYTHON313)")


#: bpy version -> (venv folder, requirements file, the Python that makes it)
EXTRA_VENVS = {
    "5.0": (".venv-bpy5", "requirements-bpy5.txt", lambda: sys.executable),
    "5.2": (".venv-bpy52", "requirements-bpy52.txt", _python313),
}


def _venv_python(version: str) -> pathlib.Path:
    """The bpy ``version`` venv's python, created (once; stamped with the requirements)."""
    folder, requirements, base_python = EXTRA_VENVS[version]
    venv, requirements = ROOT / folder, ROOT / requirements
    python = venv / "bin" / "python"
    stamp = venv / ".installed"
    if not (stamp.exists() and stamp.read_text() == requirements.read_text()):
        subprocess.run([base_python(), "-m", "venv", "--clear", str(venv)], check=True)
        subprocess.run([str(python), "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
                        "-r", str(requirements)], check=True, timeout=1800)
        stamp.write_text(requirements.read_text())
    return python


def readme_recipe() -> str:
    """The bpy-module scripting recipe exactly as the README gives it."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    match = re.search(r"<!-- tested recipe: bpy module -->\s*```python\n(.*?)```", text, re.S)
    assert match, "README.md lost its tested bpy-module recipe"
    return match.group(1)


@pytest.fixture(scope="module")
def zips(tmp_path_factory):
    out = tmp_path_factory.mktemp("dist")
    start = time.perf_counter()
    run = subprocess.run([sys.executable, str(ROOT / "scripts" / "build_extension.py"), "--output-dir", str(out)],
                         capture_output=True, text=True, timeout=1200)
    assert run.returncode == 0, run.stdout + run.stderr
    print(f"\nbuild: {time.perf_counter() - start:.1f} s\n{run.stdout}")
    return {p: next(out.glob(f"bladesmith-*-{p}.zip")) for p in PLATFORMS}


def test_four_platform_zips_validate_with_their_wheels(zips):
    # build_extension.py validates each zip and checks its wheels and exclusions; here the
    # outcome is checked once more from outside.
    import zipfile

    for platform, path in zips.items():
        names = zipfile.ZipFile(path).namelist()
        wheels = sorted(n for n in names if n.endswith(".whl"))
        assert len(wheels) == 2 and all(w.startswith("wheels/scipy-") for w in wheels), (platform, wheels)
        assert "-cp311-cp311-" in wheels[0] and "-cp313-cp313-" in wheels[1], (platform, wheels)
        assert not [n for n in names if n.split("/")[0] in ("tests", "bench", "docs", "scripts", "out")]


def _install_and_run(python, zip_path, tmp_path):
    sys.path.insert(0, str(ROOT / "tests" / "iges"))
    from occ_support import read_with_occ  # noqa: PLC0415

    user_dir = tmp_path / "blender_user"
    user_dir.mkdir()
    iges, result = tmp_path / "dtmb4119.igs", tmp_path / "result.json"
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(user_dir))
    start = time.perf_counter()
    run = subprocess.run([str(python), str(HERE / "install_driver.py"), str(zip_path), str(iges), str(result)],
                         capture_output=True, text=True, timeout=600, env=env, cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    r = json.loads(result.read_text())
    print(f"\n{r['blender']}: {time.perf_counter() - start:.1f} s, steps {r['steps']}")
    assert r["install"] == ["FINISHED"]
    assert r["addon_file"] == str(user_dir / "extensions" / "user_default" / "bladesmith" / "__init__.py")
    assert r["enabled_after_enable"]
    assert r["scipy"]["file"].startswith(str(user_dir)), r["scipy"]  # the bundled wheel, nothing else
    assert r["propeller"] == ["FINISHED"] and "DTMB 4119 blade" in r["objects"]
    assert r["export"] == ["FINISHED"]
    assert not r["enabled_after_disable"] and not r["operator_after_disable"]
    occ = read_with_occ(iges)
    assert occ.load_messages == [] and occ.transfer_messages == []
    assert len(occ.faces) >= 6  # Hally §11: five blade surfaces and the trimmed hub sector
    _run_readme_recipe(python, env, tmp_path)
    return r


def _run_readme_recipe(python, env, tmp_path):
    """The README's recipe, against the installed extension, leaves the add-on registered
    and returns: it must finish (and so exit) within RECIPE_LIMIT_S."""
    work = tmp_path / "recipe"
    work.mkdir()
    (work / "make_propeller.py").write_text(readme_recipe())
    start = time.perf_counter()
    try:
        run = subprocess.run([str(python), "make_propeller.py"], capture_output=True, text=True,
                             timeout=RECIPE_LIMIT_S, env=env, cwd=work)
    except subprocess.TimeoutExpired:
        pytest.fail(f"the README recipe did not finish within {RECIPE_LIMIT_S} s")
    print(f"recipe: {time.perf_counter() - start:.1f} s")
    assert run.returncode == 0, run.stdout + run.stderr
    assert (work / "dtmb4119.igs").stat().st_size > 0 and (work / "dtmb4119.blend").stat().st_size > 0


def test_install_bpy45(zips, tmp_path):
    r = _install_and_run(sys.executable, zips["linux_x64"], tmp_path)
    assert r["blender"].startswith("4.5") and r["scipy"]["version"] == "1.15.3"


@pytest.mark.skipif(os.environ.get("BLADESMITH_SKIP_BPY5") == "1", reason="BLADESMITH_SKIP_BPY5=1")
def test_install_bpy50(zips, tmp_path):
    r = _install_and_run(_venv_python("5.0"), zips["linux_x64"], tmp_path)
    assert r["blender"].startswith("5.0") and r["scipy"]["version"] == "1.15.3"


@pytest.mark.skipif(os.environ.get("BLADESMITH_SKIP_BPY52") == "1", reason="BLADESMITH_SKIP_BPY52=1")
def test_install_bpy52(zips, tmp_path):
    r = _install_and_run(_venv_python("5.2"), zips["linux_x64"], tmp_path)
    assert r["blender"].startswith("5.2") and r["scipy"]["version"] == "1.18.1"
    assert r["numpy"].startswith("2."), r["numpy"]


def test_installed_without_scipy_still_enables(zips, tmp_path):
    """The installed extension (module bl_ext.user_default.bladesmith) with every scipy hidden."""
    user_dir = tmp_path / "blender_user"
    user_dir.mkdir()
    result = tmp_path / "result.json"
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(user_dir))
    run = subprocess.run([sys.executable, str(HERE / "install_driver.py"), str(zips["linux_x64"]),
                          str(tmp_path / "unused.igs"), str(result), "no-scipy"],
                         capture_output=True, text=True, timeout=600, env=env, cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    r = json.loads(result.read_text())
    assert r["install"] == ["FINISHED"] and r["enabled_after_enable"]
    assert r["preferences"] == "BladesmithPreferences"
    assert r["poll"] is False and "scipy cannot be imported" in r["call"]
    assert not r["enabled_after_disable"] and not r["operator_after_disable"]
