"""Design sweep (issue 23): the same Latin-hypercube propeller sweep run serially in one
process and on a LocalCluster, OpenCASCADE reading a sample of its IGES files, and a sweep
killed at about half way and resumed.

``python bench/bench_sweep.py --samples 200`` is the issue's acceptance run
(bench/sweep_propeller_lhs.toml: pitch scale, skew scale and d_t); ``make bench`` runs it
with 20 variants. Prints wall times, the ratio, the load average (the machine may be
shared), the OCC message count, and the kill/resume counts and times.
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time

from common import ROOT, load_checkout

SPEC = ROOT / "bench" / "sweep_propeller_lhs.toml"
OCC_SAMPLE = 20


def _spec_with_samples(folder: pathlib.Path, samples: int) -> pathlib.Path:
    text = SPEC.read_text().replace("samples = 200", f"samples = {samples}")
    text = text.replace('base = "../data/', f'base = "{ROOT}/data/')
    path = folder / "spec.toml"
    path.write_text(text)
    return path


def _records(out: pathlib.Path) -> int:
    return sum(1 for _ in (out / "variants").glob("*/variant.json")) if (out / "variants").is_dir() else 0


def occ_messages(paths) -> tuple[int, int]:
    """(files read, fail + warning messages) with OpenCASCADE's IGES reader."""
    sys.path.insert(0, str(ROOT / "tests" / "iges"))
    from occ_support import read_with_occ

    messages = 0
    for p in paths:
        res = read_with_occ(p)
        messages += len(res.load_messages) + len(res.transfer_messages)
    return len(paths), messages


def main(samples: int = 20, workers: int = 2, kill: bool = True) -> dict:
    load_checkout()
    from bladesmith.sweep.runner import run_sweep
    from bladesmith.sweep.spec import load_spec

    tmp = pathlib.Path(tempfile.mkdtemp(prefix="bench_sweep_"))
    spec_path = _spec_with_samples(tmp, samples)
    load = os.getloadavg()
    print(f"load average before: {load[0]:.1f} {load[1]:.1f} {load[2]:.1f} on {os.cpu_count()} cores")

    serial = run_sweep(load_spec(spec_path, output=tmp / "serial"), serial=True, stream=None)
    print(f"serial, one process: {serial['built']} variants in {serial['seconds']:.1f} s "
          f"({serial['failed']} failed)")
    cluster = run_sweep(load_spec(spec_path, output=tmp / "cluster"), workers=workers, stream=None)
    print(f"LocalCluster, {workers} workers: {cluster['built']} variants in {cluster['seconds']:.1f} s "
          f"({cluster['failed']} failed); serial / cluster = {serial['seconds'] / cluster['seconds']:.2f}")
    load = os.getloadavg()
    print(f"load average after: {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}")

    igs = sorted((tmp / "cluster" / "variants").glob("*/variant.igs"))
    sample = random.Random(23).sample(igs, min(OCC_SAMPLE, len(igs)))
    try:
        n, messages = occ_messages(sample)
        print(f"OpenCASCADE read {n} of {len(igs)} IGES files: {messages} fail/warning messages")
    except ImportError:
        n, messages = 0, -1
        print("OpenCASCADE (OCP) not installed: IGES sample not read")

    result = {"serial_s": serial["seconds"], "cluster_s": cluster["seconds"], "occ_files": n,
              "occ_messages": messages}
    if kill:
        out = tmp / "killed"
        cmd = [sys.executable, str(ROOT / "scripts" / "sweep.py"), str(spec_path), "--out", str(out),
               "--workers", str(workers), "--quiet"]
        start = time.perf_counter()
        proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        while _records(out) < samples // 2 and proc.poll() is None:
            time.sleep(0.2)
        os.killpg(proc.pid, signal.SIGKILL)  # the command and its LocalCluster's workers
        proc.wait()
        first = time.perf_counter() - start
        time.sleep(1.0)
        done_before = _records(out)
        stamps = {p: p.stat().st_mtime_ns for p in (out / "variants").glob("*/variant.json")}
        resumed = run_sweep(load_spec(spec_path, output=out), workers=workers, stream=None)
        rebuilt = sum(1 for p, t in stamps.items() if p.stat().st_mtime_ns != t)
        print(f"killed after {first:.1f} s with {done_before} of {samples} records; resume: "
              f"{resumed['skipped']} skipped, {resumed['built']} built, {rebuilt} finished variants rebuilt, "
              f"{resumed['seconds']:.1f} s")
        again = run_sweep(load_spec(spec_path, output=out), workers=workers, stream=None)
        print(f"second resume: {again['built']} built, {again['seconds']:.1f} s")
        same = json.dumps([r["key"] for r in resumed["rows"]]) == json.dumps([r["key"] for r in cluster["rows"]])
        print(f"resumed table has the same variants as the uninterrupted run: {same}")
        result.update(killed_records=done_before, resume_built=resumed["built"], resume_rebuilt=rebuilt,
                      resume_s=resumed["seconds"])
    shutil.rmtree(tmp, ignore_errors=True)
    return result


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=20)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--no-kill", action="store_true")
    a = ap.parse_args()
    main(a.samples, a.workers, not a.no_kill)
