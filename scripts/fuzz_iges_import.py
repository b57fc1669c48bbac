"""Fuzz the IGES import: seeded random mutations of valid files through the lenient reader
and importer (no bpy), or through ``bpy.ops.import_scene.iges`` (``--operator``).

Every outcome must be a successful import or a BladesmithError; with ``--operator`` a
refusal must leave the scene exactly as it was. Any other exception, or a case taking
longer than ``--hang`` seconds (SIGALRM), is a failure. Prints counts and the slowest case.

    python scripts/fuzz_iges_import.py --cases 10000 [--operator] [--seed N]
"""
from __future__ import annotations

import argparse
import importlib.util
import pathlib
import random
import signal
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]


def _load(name, path):
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, path, submodule_search_locations=None)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


def load_package():
    if "bladesmith" not in sys.modules:
        spec = importlib.util.spec_from_file_location("bladesmith", ROOT / "__init__.py",
                                                      submodule_search_locations=[str(ROOT)])
        module = importlib.util.module_from_spec(spec)
        sys.modules["bladesmith"] = module
        spec.loader.exec_module(module)


def base_files() -> list[str]:
    """The strict-reader fuzz's valid files plus the hand-written import cases."""
    load_package()
    fuzz = _load("iges_fuzz_cases", ROOT / "tests" / "unit" / "test_iges_fuzz.py")
    cases = _load("import_cases", ROOT / "tests" / "unit" / "import_cases.py")
    out = list(fuzz.base_files())
    out += [cases.subfigure_instance()[0], cases.nested_composites(3)[0], cases.plane_face_with_hole()[0],
            cases.tabulated_cylinder_face()[0], cases.trimmed_with_transforms()[0],
            cases.composite_with_transform()[0], cases.cylinder_face()[0]]
    try:  # an OpenCASCADE-written B-rep solid on the analytic surfaces 190-198
        import tempfile

        vs_occ = _load("iges_vs_occ", ROOT / "tests" / "iges" / "test_import_vs_occ.py")
        with tempfile.TemporaryDirectory() as tmp:
            path = pathlib.Path(tmp) / "primitives.igs"
            vs_occ._primitives_brep_iges(path)
            out.append(path.read_text())
    except ImportError:
        pass  # no OCP here: the other bases still run
    return out


def mutate(text: str, r: random.Random) -> str:
    fuzz = _load("iges_fuzz_cases", ROOT / "tests" / "unit" / "test_iges_fuzz.py")
    return fuzz.mutate(text, r)


def _remove_new(bpy, before):
    """Delete what an import made, so the next case starts from the same scene."""
    for name in set(bpy.data.objects.keys()) - before[0]:
        bpy.data.objects.remove(bpy.data.objects[name], do_unlink=True)
    for name in set(bpy.data.meshes.keys()) - before[1]:
        bpy.data.meshes.remove(bpy.data.meshes[name])
    for name in set(bpy.data.curves.keys()) - before[2]:
        bpy.data.curves.remove(bpy.data.curves[name])


class Hang(Exception):
    pass


def _alarm(signum, frame):
    raise Hang()


def run(cases: int, seed: int, operator: bool, hang: float, tmp: pathlib.Path, register: bool = True) -> dict:
    load_package()
    from bladesmith.geometry.errors import BladesmithError
    from bladesmith.iges.importer import import_model
    from bladesmith.iges.reader import parse_iges

    if operator:
        import bpy

        if register:
            sys.modules["bladesmith"].register()
        bpy.ops.wm.read_factory_settings(use_empty=True)
    r = random.Random(seed)
    bases = base_files()
    out = {"imported": 0, "refused": 0, "hangs": 0, "foreign": 0, "scene_changed": 0}
    slowest = (0.0, None)
    signal.signal(signal.SIGALRM, _alarm)
    path = tmp / "fuzz.igs"
    try:
        for case in range(cases):
            data = mutate(r.choice(bases), r)
            t0 = time.perf_counter()
            signal.setitimer(signal.ITIMER_REAL, hang)
            try:
                if operator:
                    path.write_bytes(data.encode("latin-1", "replace"))
                    before = set(bpy.data.objects.keys()), set(bpy.data.meshes.keys()), set(bpy.data.curves.keys())
                    try:
                        bpy.ops.import_scene.iges(filepath=str(path))
                        out["imported"] += 1
                        _remove_new(bpy, before)
                    except RuntimeError as exc:  # the operator's CANCELLED with an error report
                        after = set(bpy.data.objects.keys()), set(bpy.data.meshes.keys()), set(bpy.data.curves.keys())
                        if after != before:
                            out["scene_changed"] += 1
                            print(f"case {case}: scene changed after refusal: {exc}")
                        if "Traceback" in str(exc) or "Error:" not in str(exc):
                            out["foreign"] += 1
                            print(f"case {case}: {exc}")
                        out["refused"] += 1
                else:
                    try:
                        import_model(parse_iges(data, strict=False), len(data))
                        out["imported"] += 1
                    except BladesmithError:
                        out["refused"] += 1
            except Hang:
                out["hangs"] += 1
                print(f"case {case}: longer than {hang} s")
                (tmp / f"hang_{case}.igs").write_text(data, encoding="latin-1", errors="replace")
            except Exception as exc:  # noqa: BLE001 - the failure this script looks for
                out["foreign"] += 1
                print(f"case {case}: foreign {type(exc).__name__}: {exc}")
                (tmp / f"foreign_{case}.igs").write_text(data, encoding="latin-1", errors="replace")
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0)
            dt = time.perf_counter() - t0
            if dt > slowest[0]:
                slowest = (dt, case)
    finally:
        if operator and register:
            sys.modules["bladesmith"].unregister()
    out["slowest_s"] = round(slowest[0], 3)
    out["slowest_case"] = slowest[1]
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=20261124)
    ap.add_argument("--operator", action="store_true", help="through bpy.ops.import_scene.iges")
    ap.add_argument("--hang", type=float, default=20.0, help="seconds after which a case counts as a hang")
    ap.add_argument("--tmp", default="/tmp/bladesmith_fuzz")
    a = ap.parse_args(argv)
    tmp = pathlib.Path(a.tmp)
    tmp.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    out = run(a.cases, a.seed, a.operator, a.hang, tmp)
    print(f"{a.cases} cases ({'operator' if a.operator else 'importer'}) in {time.perf_counter() - t0:.1f} s: {out}")
    return 0 if out["hangs"] == out["foreign"] == out["scene_changed"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
