"""Helpers shared by the benchmarks: median timings and ratios measured in one run."""
from __future__ import annotations

import importlib.util
import pathlib
import shutil
import statistics
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent


def load_checkout(name: str = "bladesmith"):
    """Import the checkout as the package ``bladesmith`` (as the tests do)."""
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(
            name, ROOT / "__init__.py", submodule_search_locations=[str(ROOT)]
        )
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


def load_commit(commit: str, tmp: pathlib.Path, name: str):
    """The package at ``commit`` of this repository, unpacked with ``git archive`` into
    ``tmp / name`` and imported as ``name`` (a baseline to time in the same run); returns
    ``name``, or None without git or the commit."""
    if shutil.which("git") is None:
        return None
    target = tmp / name
    target.mkdir()
    try:
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", commit], check=True,
                                 capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", str(target)], input=archive, check=True, capture_output=True)
    except (subprocess.CalledProcessError, OSError):
        return None
    spec = importlib.util.spec_from_file_location(name, target / "__init__.py",
                                                  submodule_search_locations=[str(target)])
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return name


def median_time(fn, repeat: int = 5, warmup: int = 1) -> float:
    """Median wall time of ``fn()`` in seconds over ``repeat`` runs after ``warmup`` runs."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def report(title: str, rows: list[tuple[str, float, str]]) -> None:
    """Print ``(label, seconds, note)`` rows under a title."""
    print(f"\n== {title}")
    width = max(len(label) for label, _, _ in rows)
    for label, seconds, note in rows:
        print(f"  {label:<{width}}  {seconds * 1e3:10.2f} ms  {note}")
