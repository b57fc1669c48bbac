"""Fuzz through the import operator: seeded mutations of valid files (the strict reader's
fuzz bases plus the import cases) go through ``bpy.ops.import_scene.iges``. Each ends in
an import or a refusal reported by the operator; a refusal leaves the scene as it was;
nothing else escapes and no case hangs. The in-suite count fits a few seconds; the
10,000-case run is ``python scripts/fuzz_iges_import.py --operator --cases 10000``."""
import importlib.util
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
CASES = 120


def _fuzz():
    if "fuzz_iges_import" not in sys.modules:
        spec = importlib.util.spec_from_file_location("fuzz_iges_import", ROOT / "scripts" / "fuzz_iges_import.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules["fuzz_iges_import"] = module
        spec.loader.exec_module(module)
    return sys.modules["fuzz_iges_import"]


def test_mutated_files_through_the_import_operator(addon, tmp_path):
    out = _fuzz().run(CASES, seed=7, operator=True, hang=60.0, tmp=tmp_path, register=False)
    print(out)
    assert out["foreign"] == 0 and out["hangs"] == 0 and out["scene_changed"] == 0, out
    assert out["imported"] + out["refused"] == CASES
    assert out["imported"] > 10 and out["refused"] > 10  # both outcomes are exercised
