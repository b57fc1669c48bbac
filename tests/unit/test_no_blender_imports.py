"""geometry/, iges/ and sweep/ never import Blender modules (ARCHITECTURE.md): checked statically
over every file, and dynamically by importing them with bpy made unimportable."""
import ast
import pathlib
import subprocess
import sys
import textwrap

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
BLENDER_MODULES = {"bpy", "mathutils", "bmesh", "gpu", "gpu_extras", "bl_ui", "bpy_extras", "bgl", "blf", "aud"}


def python_files():
    for folder in ("geometry", "iges", "sweep"):
        yield from sorted((ROOT / folder).rglob("*.py"))


@pytest.mark.parametrize("path", list(python_files()), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_blender_import_statement(path):
    tree = ast.parse(path.read_text(), filename=str(path))
    for node in ast.walk(tree):
        names = []
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [node.module]
        elif isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", "")) in (
            "import_module",
            "__import__",
        ):
            names = [a.value for a in node.args if isinstance(a, ast.Constant) and isinstance(a.value, str)]
        for name in names:
            assert name.split(".")[0] not in BLENDER_MODULES, f"{path}:{node.lineno} imports {name}"


def test_packages_import_with_blender_absent(tmp_path):
    """Every module under geometry/ and iges/ imports in a fresh interpreter where
    importing bpy or mathutils fails."""
    modules = []
    for path in python_files():
        rel = path.relative_to(ROOT).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        modules.append(".".join(["bladesmith", *parts]))
    script = textwrap.dedent(
        f"""
        import importlib, importlib.util, sys
        for name in {sorted(BLENDER_MODULES)!r}:
            sys.modules[name] = None  # any import of it raises ImportError
        spec = importlib.util.spec_from_file_location(
            "bladesmith", {str(ROOT / "__init__.py")!r}, submodule_search_locations=[{str(ROOT)!r}])
        module = importlib.util.module_from_spec(spec)
        sys.modules["bladesmith"] = module
        spec.loader.exec_module(module)
        for name in {modules!r}:
            importlib.import_module(name)
        print("imported", len({modules!r}))
        """
    )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert f"imported {len(modules)}" in result.stdout
