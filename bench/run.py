"""Runs every bench/bench_*.py module's main() and prints its figures.

Benchmarks are never part of pass/fail (ARCHITECTURE.md); they print medians and ratios
against baselines measured in the same run. Run one with ``python bench/run.py NAME``.
"""
import importlib
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def main(selected: list[str]) -> None:
    for path in sorted(HERE.glob("bench_*.py")):
        name = path.stem
        if selected and not any(s in name for s in selected):
            continue
        saved, sys.argv = sys.argv, [sys.argv[0]]  # modules that parse sys.argv see no options
        try:
            importlib.import_module(name).main()
        finally:
            sys.argv = saved


if __name__ == "__main__":
    main(sys.argv[1:])
