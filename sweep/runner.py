"""Running a sweep on Dask distributed, with a progress bar and the metrics table.

Execution is Dask's: an embedded ``LocalCluster`` (one single-threaded worker process per
core) by default, or any scheduler address (``tcp://host:8786``), or a ``Client`` the
caller made. Each variant is one task (:func:`.worker.task`); results come back as they
finish (``distributed.as_completed``). ``serial=True`` runs the same variants one after
another in this process, without Dask (the baseline the parallel run is measured against).

Resuming: before anything is submitted, every variant whose folder holds a record that
verifies (:func:`.variant.verify`) is taken as done, so a sweep killed mid-way rebuilds
only what had not finished. A variant that failed is done as well (its failure is
deterministic) unless ``retry_failed``. A task the cluster itself loses (a worker killed
twice, for instance) is recorded in the table as failed, with no record on disk, so the
next run builds it again.

Outputs in the sweep folder: ``variants/<key>/`` per variant (see :mod:`.variant`),
``sweep.json`` (the index: kind, base, parameters and, per variant, its index, key and
values; what Blender's "Load Sweep Variant" reads), ``metrics.parquet`` and
``metrics.csv`` (one row per design point, in design order). All written atomically.

Dask and pyarrow are imported here only (and only when used): the Blender extension
never needs them.
"""
from __future__ import annotations

import csv
import io
import json
import logging
import math
import os
import pathlib
import sys
import time

from ..geometry.files import atomic_write
from .spec import SweepSpec, Variant
from .variant import DEFINITION_FILE, IGES_FILE, METRICS, VARIANTS_FOLDER, run_variant, verify

INDEX_FILE = "sweep.json"
TABLE_FILE = "metrics.parquet"
CSV_FILE = "metrics.csv"
#: Seconds between progress lines when the output is not a terminal.
LOG_INTERVAL_S = 5.0
#: Seconds between redraws of the bar on a terminal.
BAR_INTERVAL_S = 0.2
BAR_WIDTH = 30


class Progress:
    """A live progress bar: done, failed, remaining and the rate (variants per second of
    this run), on one redrawn line on a terminal and as a line every LOG_INTERVAL_S
    otherwise. ``stream=None`` shows nothing."""

    def __init__(self, total: int, skipped: int = 0, stream=sys.stderr):
        self.total, self.skipped, self.stream = total, skipped, stream
        self.done = self.failed = 0
        self.start = time.perf_counter()
        self._last = -math.inf
        self.tty = bool(stream is not None and getattr(stream, "isatty", lambda: False)())

    def update(self, failed: bool) -> None:
        self.done += 1
        self.failed += bool(failed)
        self.show()

    def line(self) -> str:
        elapsed = time.perf_counter() - self.start
        rate = self.done / elapsed if elapsed > 0 else 0.0
        remaining = self.total - self.done
        eta = f"{remaining / rate:.0f}s" if rate > 0 else "?"
        filled = int(BAR_WIDTH * self.done / self.total) if self.total else BAR_WIDTH
        bar = "#" * filled + "-" * (BAR_WIDTH - filled)
        return (f"[{bar}] {self.done}/{self.total} done, {self.failed} failed, {remaining} remaining, "
                f"{rate:.2f}/s, eta {eta}" + (f" ({self.skipped} already done)" if self.skipped else ""))

    def show(self, final: bool = False) -> None:
        if self.stream is None:
            return
        now = time.perf_counter()
        interval = BAR_INTERVAL_S if self.tty else LOG_INTERVAL_S
        if not final and now - self._last < interval and self.done < self.total:
            return
        self._last = now
        text = self.line()
        if final and (text == getattr(self, "_shown", None) or getattr(self, "_shown_all", False)):
            return
        self._shown = text
        self._shown_all = self.done == self.total
        if self.tty:
            self.stream.write("\r" + text + ("\n" if final else ""))
        else:
            self.stream.write(text + "\n")
        self.stream.flush()


def _package_and_root() -> tuple[str, str]:
    package = __package__.rsplit(".", 1)[0]
    return package, str(pathlib.Path(__file__).resolve().parent.parent)


def write_index(spec: SweepSpec, variants: list[Variant]) -> None:
    index = {
        "kind": spec.kind, "base": str(spec.base), "spec": str(spec.path), "settings": spec.settings,
        "parameters": [{"name": q.name, "field": q.field, "action": q.action} for q in spec.parameters],
        "design": {k: v for k, v in spec.design.items() if k != "rows"},
        "variants": [{"variant": v.index, "key": v.key, "values": v.values} for v in variants],
    }
    atomic_write(spec.output / INDEX_FILE, json.dumps(index, indent=1))


def _lost(kind: str, v: Variant, exc: BaseException) -> dict:
    """The record of a task the cluster lost (not written: the next run retries it)."""
    return {"key": v.key, "kind": kind, "variant": v.index, "values": v.values, "status": "failed",
            "error": f"{type(exc).__name__}: {exc}", "error_field": "", "error_type": type(exc).__name__,
            "metrics": {m: None for m in METRICS[kind]}, "files": {}, "build_time_s": math.nan}


def run_sweep(spec: SweepSpec, *, scheduler: str | None = None, workers: int | None = None, client=None,
              serial: bool = False, retry_failed: bool = False, stream=sys.stderr, dashboard: bool = False) -> dict:
    """Run the sweep; returns counts and times: ``variants`` (design points), ``unique``
    (distinct keys), ``skipped`` (already done and verified), ``built`` (run now),
    ``failed`` (rows failed in the table), ``seconds`` (wall time of this run),
    ``table`` (the Parquet path), ``rows`` (the table's rows, as dicts)."""
    t0 = time.perf_counter()
    variants = spec.variants()
    spec.output.mkdir(parents=True, exist_ok=True)
    (spec.output / VARIANTS_FOLDER).mkdir(exist_ok=True)
    write_index(spec, variants)

    unique: dict[str, Variant] = {}
    for v in variants:
        unique.setdefault(v.key, v)
    records: dict[str, dict] = {}
    todo = []
    for key, v in unique.items():
        record = verify(spec.output / VARIANTS_FOLDER / key, key)
        if record is not None and (record["status"] == "ok" or not retry_failed):
            records[key] = record
        else:
            todo.append(v)
    progress = Progress(len(todo), skipped=len(records), stream=stream)
    progress.show(final=not todo)
    args = lambda v: (spec.kind, v.key, v.index, v.values, v.definition, v.settings,  # noqa: E731
                      str(spec.base.parent), str(spec.output))
    if todo and serial:
        for v in todo:
            records[v.key] = run_variant(*args(v))
            progress.update(records[v.key]["status"] != "ok")
    elif todo:
        _run_on_dask(spec, todo, args, records, progress, scheduler, workers, client, dashboard)
    progress.show(final=True)
    rows = table_rows(spec, variants, records)
    write_table(spec, rows)
    return {"variants": len(variants), "unique": len(unique), "skipped": len(unique) - len(todo),
            "built": len(todo), "failed": sum(r["status"] != "ok" for r in rows),
            "seconds": time.perf_counter() - t0, "table": str(spec.output / TABLE_FILE), "rows": rows}


class _ByValue:
    """A function that pickles by value (cloudpickle) even where Dask first tries the
    standard pickle, which would name its module, unknown to a worker that has no
    Bladesmith on its path."""

    def __init__(self, function):
        self.function = function

    def __call__(self, *args):
        return self.function(*args)

    def __reduce__(self):
        import cloudpickle

        return cloudpickle.loads, (cloudpickle.dumps(self.function),)


def _run_on_dask(spec, todo, args, records, progress, scheduler, workers, client, dashboard) -> None:
    import cloudpickle
    from distributed import Client, LocalCluster, as_completed

    from . import worker

    # the task goes to the workers by value: they need no import path for Bladesmith
    cloudpickle.register_pickle_by_value(worker)
    task = _ByValue(worker.task)
    package, root = _package_and_root()
    own_client = own_cluster = None
    try:
        if client is None:
            if scheduler:
                client = own_client = Client(scheduler)
            else:
                n = workers or os.cpu_count() or 1
                # silence_logs: a lost worker is recorded in the table; the cluster's own
                # shutdown chatter is not the user's business
                own_cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                           dashboard_address=":8787" if dashboard else None,
                                           silence_logs=logging.CRITICAL)
                client = own_client = Client(own_cluster)
        futures = {}
        for v in todo:
            f = client.submit(task, package, root, *args(v), key=f"variant-{v.key}", pure=False)
            futures[f] = v
        for future in as_completed(futures):
            v = futures[future]
            try:
                record = future.result()
            except Exception as exc:  # the cluster lost the task: in the table, retried next run
                record = _lost(spec.kind, v, exc)
            records[v.key] = record
            progress.update(record["status"] != "ok")
    finally:
        if own_client is not None:
            own_client.close()
        if own_cluster is not None:
            own_cluster.close()


def table_rows(spec: SweepSpec, variants: list[Variant], records: dict) -> list[dict]:
    """One row per design point: variant, key, the parameter values, status, error,
    error_field, error_type, build_time_s, the kind's metrics, and the paths of the
    definition and IGES file relative to the sweep folder."""
    rows = []
    for v in variants:
        r = records[v.key]
        row = {"variant": v.index, "key": v.key}
        row.update({q.name: v.values[q.name] for q in spec.parameters})
        row.update({"status": r["status"], "error": r.get("error", ""), "error_field": r.get("error_field", ""),
                    "error_type": r.get("error_type", ""), "build_time_s": r.get("build_time_s", math.nan)})
        metrics = r.get("metrics", {})
        row.update({m: (math.nan if metrics.get(m) is None else metrics[m]) for m in METRICS[spec.kind]})
        files = r.get("files", {})
        row["definition"] = f"{VARIANTS_FOLDER}/{v.key}/{DEFINITION_FILE}" if DEFINITION_FILE in files else ""
        row["iges_files"] = f"{VARIANTS_FOLDER}/{v.key}/{IGES_FILE}" if IGES_FILE in files else ""
        rows.append(row)
    return rows


def _column(values: list):
    import pyarrow as pa

    def numeric(x):
        return isinstance(x, (int, float)) and not isinstance(x, bool)

    if all(isinstance(x, int) and not isinstance(x, bool) for x in values):
        return pa.array(values, type=pa.int64())
    if all(numeric(x) or x is None for x in values):
        return pa.array([math.nan if x is None else float(x) for x in values], type=pa.float64())
    if all(isinstance(x, bool) for x in values):
        return pa.array(values, type=pa.bool_())
    return pa.array(["" if x is None else str(x) for x in values], type=pa.string())


def write_table(spec: SweepSpec, rows: list[dict]) -> None:
    """The metrics table as Parquet (pyarrow) and as CSV, both atomically."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    columns = list(rows[0]) if rows else ["variant", "key", "status"]
    table = pa.table({c: _column([r.get(c) for r in rows]) for c in columns})
    sink = pa.BufferOutputStream()
    pq.write_table(table, sink)
    atomic_write(spec.output / TABLE_FILE, sink.getvalue().to_pybytes())
    text = io.StringIO()
    w = csv.writer(text, lineterminator="\n")
    w.writerow(columns)
    for r in rows:
        w.writerow(["" if (isinstance(r[c], float) and math.isnan(r[c])) else
                    (repr(float(r[c])) if isinstance(r[c], float) else r[c]) for c in columns])
    atomic_write(spec.output / CSV_FILE, text.getvalue())
