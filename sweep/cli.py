"""The sweep command: ``python scripts/sweep.py SPEC.toml`` from a checkout (or
``python -m bladesmith.sweep SPEC.toml`` where Bladesmith is importable as a package).

Exit status: 0 when the sweep ran (failing variants are recorded, not fatal), 2 when the
sweep file itself is invalid.
"""
from __future__ import annotations

import argparse
import sys

from ..geometry.errors import BladesmithError


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="sweep", description="Run a Bladesmith design sweep on Dask.")
    p.add_argument("spec", help="the sweep file (TOML): base definition, parameters, design")
    p.add_argument("--out", help="the sweep folder (default: the sweep file's `output`)")
    p.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://host:8786 "
                   "(default: an embedded LocalCluster, one worker process per core)")
    p.add_argument("--workers", type=int, help="LocalCluster worker processes (default: the number of cores)")
    p.add_argument("--serial", action="store_true", help="run the variants one after another in this process, "
                   "without Dask")
    p.add_argument("--retry-failed", action="store_true", help="build variants that failed before again")
    p.add_argument("--dashboard", action="store_true", help="serve the LocalCluster's dashboard on :8787")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    return p


def main(argv=None) -> int:
    args = parser().parse_args(argv)
    from .runner import run_sweep
    from .spec import load_spec

    try:
        spec = load_spec(args.spec, output=args.out)
    except BladesmithError as exc:
        print(f"sweep: {exc}", file=sys.stderr)
        return 2
    if args.workers is not None and args.workers < 1:
        print(f"sweep: --workers must be >= 1, got {args.workers}", file=sys.stderr)
        return 2
    try:
        result = run_sweep(spec, scheduler=args.scheduler, workers=args.workers, serial=args.serial,
                           retry_failed=args.retry_failed, stream=None if args.quiet else sys.stderr,
                           dashboard=args.dashboard)
    except BladesmithError as exc:  # the design's values do not fit the fields (before anything is built)
        print(f"sweep: {exc}", file=sys.stderr)
        return 2
    print(f"{result['variants']} variants ({result['unique']} distinct): {result['skipped']} already done, "
          f"{result['built']} built now, {result['failed']} failed; {result['seconds']:.1f} s")
    print(f"metrics: {result['table']} (and metrics.csv)")
    return 0
