"""Run a design sweep from a checkout: ``python scripts/sweep.py SPEC.toml [--scheduler tcp://host:8786]``.

The repository root is the package ``bladesmith``; this script loads the checkout under
that name (as the tests do, whatever the folder is called) and runs
:mod:`bladesmith.sweep.cli`. It needs numpy and scipy, and Dask and pyarrow
(requirements-sweep.txt); it never imports Blender.
"""
from __future__ import annotations

import importlib.util
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent


def load_checkout(name: str = "bladesmith"):
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, ROOT / "__init__.py", submodule_search_locations=[str(ROOT)])
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


if __name__ == "__main__":
    load_checkout()
    from bladesmith.sweep.cli import main

    sys.exit(main())
