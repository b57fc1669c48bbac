"""The product's performance figures as one markdown table (``make bench``).

Calls ``figures()`` of every ``bench/bench_*.py`` module that defines it (or of those
whose names contain one of the command-line words) and prints

    | figure | value | baseline | goal | met? |

with the machine, its load before and after, and the date above the table. A figure is a
dict with keys ``figure`` (the row name), ``value`` (float), ``unit`` ("ms", "s" or "x"
for a ratio), ``baseline`` (what it was compared with in the same run, or "") and
``goal`` (e.g. "<= 50 ms"). "met?" compares the value with the goal in the goal's unit;
a goal it cannot read leaves "?". A module that fails prints its error in the table and
the others still run. Benchmarks never decide pass or fail (ARCHITECTURE.md, house
style 10): this script always exits 0 unless it is misused.

    python bench/summary.py [NAME ...] [--output FILE]
"""
from __future__ import annotations

import argparse
import datetime as _dt
import importlib
import os
import pathlib
import platform
import re
import sys
import time
import traceback

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

#: Seconds per unit of the figures' values and goals.
UNIT_SECONDS = {"ms": 1e-3, "s": 1.0}
_GOAL = re.compile(r"^\s*(<=|>=|<|>|≤|≥)\s*([-+0-9.eE]+)\s*(ms|s|x)?\s*$")


def cpu_name() -> str:
    try:
        for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def load() -> str:
    try:
        return ", ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "unknown"


def format_value(value: float, unit: str) -> str:
    if value != value:  # NaN
        return "n/a"
    if unit == "x":
        return f"{value:.2f}x"
    if unit == "ms":
        return f"{value:.1f} ms" if value < 100 else f"{value:.0f} ms"
    if unit == "s":
        return f"{value:.3f} s" if value < 10 else f"{value:.1f} s"
    return f"{value:g} {unit}".strip()


def met(value: float, unit: str, goal: str) -> str:
    """'yes' / 'no' when ``goal`` reads as a bound in a unit comparable with ``unit``."""
    m = _GOAL.match(goal or "")
    if not m or value != value:
        return "?"
    op, bound, goal_unit = m.group(1), float(m.group(2)), m.group(3) or unit
    if goal_unit == unit:
        x, b = value, bound
    elif goal_unit in UNIT_SECONDS and unit in UNIT_SECONDS:
        x, b = value * UNIT_SECONDS[unit], bound * UNIT_SECONDS[goal_unit]
    else:
        return "?"
    ok = {"<=": x <= b, "≤": x <= b, "<": x < b, ">=": x >= b, "≥": x >= b, ">": x > b}[op]
    return "yes" if ok else "no"


def collect(selected: list[str]) -> list[dict]:
    rows = []
    for path in sorted(HERE.glob("bench_*.py")):
        name = path.stem
        if selected and not any(s in name for s in selected):
            continue
        try:
            module = importlib.import_module(name)
        except Exception as exc:  # a bench that cannot even import is reported, not fatal
            rows.append({"figure": f"{name}: import failed", "value": float("nan"), "unit": "",
                         "baseline": f"{type(exc).__name__}: {exc}"[:120], "goal": ""})
            continue
        if not hasattr(module, "figures"):
            continue
        start = time.perf_counter()
        print(f"[{name}] measuring ...", file=sys.stderr, flush=True)
        try:
            figures = list(module.figures())
        except Exception as exc:
            traceback.print_exc()
            figures = [{"figure": f"{name}: failed", "value": float("nan"), "unit": "",
                        "baseline": f"{type(exc).__name__}: {exc}"[:120], "goal": ""}]
        print(f"[{name}] {time.perf_counter() - start:.1f} s", file=sys.stderr, flush=True)
        for f in figures:
            rows.append({**f, "module": name})
    return rows


def table(rows: list[dict]) -> str:
    def cell(text) -> str:
        return str(text).replace("|", "\\|").replace("\n", " ")

    lines = ["| figure | value | baseline | goal | met? |", "|---|---|---|---|---|"]
    for r in rows:
        value, unit = float(r.get("value", float("nan"))), r.get("unit", "")
        lines.append("| " + " | ".join(cell(x) for x in (
            r.get("figure", "?"), format_value(value, unit), r.get("baseline", ""), r.get("goal", ""),
            met(value, unit, r.get("goal", "")),
        )) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="The benchmarks' figures as one markdown table.")
    ap.add_argument("names", nargs="*", help="only modules whose names contain one of these")
    ap.add_argument("--output", help="also write the table (with its heading) to this file")
    args = ap.parse_args(argv)
    before = load()
    started = _dt.datetime.now(_dt.timezone.utc)
    saved_argv = sys.argv
    sys.argv = [sys.argv[0]]  # modules that parse sys.argv see no options
    try:
        rows = collect(args.names)
    finally:
        sys.argv = saved_argv
    import numpy
    import scipy

    heading = (
        f"Measured {started:%Y-%m-%d %H:%M} UTC on {cpu_name()}, {os.cpu_count()} logical CPUs, "
        f"load average (1, 5, 15 min) {before} before and {load()} after; Python "
        f"{platform.python_version()}, numpy {numpy.__version__}, scipy {scipy.__version__}. "
        f"Values are medians; baselines were measured in the same run."
    )
    text = heading + "\n\n" + table(rows) + "\n"
    print()
    print(text)
    if args.output:
        pathlib.Path(args.output).write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
