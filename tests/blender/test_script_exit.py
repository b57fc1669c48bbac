"""Scripts exit (issue 14): in the ``bpy`` module, interpreter exit with an operator class
still registered deadlocks in bpy's own teardown. A script that registers the add-on,
uses it and simply returns (no ``unregister()``) must still exit promptly: the add-on
unregisters itself at exit when it runs inside the module."""
import pathlib
import subprocess
import sys
import textwrap

import pytest

pytest.importorskip("bpy")

ROOT = pathlib.Path(__file__).resolve().parents[2]
#: Generous: the script itself takes about 2 s; the deadlock never ends.
EXIT_LIMIT_S = 60

SCRIPT = textwrap.dedent(f"""
    import importlib.util, sys
    spec = importlib.util.spec_from_file_location("bladesmith", {str(ROOT / "__init__.py")!r},
                                                  submodule_search_locations=[{str(ROOT)!r}])
    module = importlib.util.module_from_spec(spec)
    sys.modules["bladesmith"] = module
    spec.loader.exec_module(module)
    import bpy
    module.register()
    print(sorted(bpy.ops.bladesmith.add_propeller(preset="DTMB4119")))
    # returns with the add-on still registered
""")


def test_a_script_that_leaves_the_addon_registered_exits(tmp_path):
    script = tmp_path / "leave_registered.py"
    script.write_text(SCRIPT)
    try:
        run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                             timeout=EXIT_LIMIT_S, cwd=tmp_path)
    except subprocess.TimeoutExpired:
        pytest.fail(f"the script did not exit within {EXIT_LIMIT_S} s (bpy teardown deadlock)")
    assert run.returncode == 0, run.stdout + run.stderr
    assert "['FINISHED']" in run.stdout


def test_unregister_twice_is_harmless(addon):
    # the exit hook calls unregister() only while registered; a user's own unregister first is fine
    import bladesmith

    bladesmith._unregister_if_registered()
    assert not bladesmith._registered
    bladesmith._unregister_if_registered()
    bladesmith.register()
    assert bladesmith._registered
