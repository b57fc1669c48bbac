"""Loads the checkout as the package ``bladesmith``, whatever the folder is called.

The repository root is the extension package, so the tests import it the way Blender
does: as a package with relative imports (installed extensions live under
``bl_ext.<repo>.bladesmith``; here it is plain ``bladesmith``).
"""
import importlib.util
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
SHARED_DATA = ROOT.parent / "shared" / "data"


def load_checkout(name: str = "bladesmith"):
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(
        name, ROOT / "__init__.py", submodule_search_locations=[str(ROOT)]
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


load_checkout()
