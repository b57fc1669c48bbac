"""What a Dask worker runs for one variant: make the package importable, then
:func:`~.variant.run_variant`.

This module is sent to the workers by value (``cloudpickle.register_pickle_by_value``),
so a worker needs no import path set up for Bladesmith beforehand: :func:`task` imports
the package when it is installed, and otherwise loads the checkout at ``root`` (which must
exist on the worker's machine: the sweep folder and the checkout are expected on a shared
file system for a remote cluster) the way the tests and scripts do, as a package with
relative imports.
"""
from __future__ import annotations


def load_package(package: str, root: str):
    """The Bladesmith package, imported by name when possible, else loaded from ``root``."""
    import importlib
    import importlib.util
    import os
    import sys

    if package in sys.modules:
        return sys.modules[package]
    init = os.path.join(root, "__init__.py")
    if os.path.isfile(init):
        spec = importlib.util.spec_from_file_location(package, init, submodule_search_locations=[root])
        module = importlib.util.module_from_spec(spec)
        sys.modules[package] = module
        spec.loader.exec_module(module)
        return module
    return importlib.import_module(package)


def task(package: str, root: str, *args):
    """Run one variant on a worker; returns its record (plain data)."""
    import importlib

    load_package(package, root)
    return importlib.import_module(f"{package}.sweep.variant").run_variant(*args)
