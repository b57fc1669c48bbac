"""The exactness tests on the other CPUs' code paths (issue 14).

Main once went red on an AVX-512 machine because two surfaces shared an edge only when the
BLAS kernels happened to round alike. The suite itself runs on whatever CPU the machine
has; this module re-runs every unit test file that asserts bit-for-bit equality
(``array_equal``) in subprocesses that steer numpy's SIMD dispatch
(``NPY_DISABLE_CPU_FEATURES``) and OpenBLAS's kernels (``OPENBLAS_CORETYPE``,
``OPENBLAS_NUM_THREADS``) onto the code paths of other x86-64 CPUs:

- ``avx2``: AVX2/FMA without AVX-512 (Zen 2/3, Haswell to Comet Lake), one BLAS thread;
- ``sse``: SSE4.2 only (the oldest x86-64 kernels), default threads.

On a machine without AVX-512 the plain suite covers AVX2 and these runs add the SSE path.
"""
import os
import pathlib
import subprocess
import sys

import pytest

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent

try:  # numpy 2.x moved the module
    from numpy._core._multiarray_umath import __cpu_baseline__, __cpu_dispatch__, __cpu_features__
except ImportError:  # numpy 1.26
    from numpy.core._multiarray_umath import __cpu_baseline__, __cpu_dispatch__, __cpu_features__

AVX512 = [f for f in __cpu_dispatch__ if f.startswith("AVX512")]
ABOVE_SSE42 = AVX512 + [f for f in ("AVX", "F16C", "FMA3", "AVX2")]

PATHS = {
    "avx2": ({"OPENBLAS_CORETYPE": "Haswell", "OPENBLAS_NUM_THREADS": "1"}, AVX512),
    "sse": ({"OPENBLAS_CORETYPE": "Prescott"}, ABOVE_SSE42),
}


def exactness_test_files() -> list[str]:
    """Every unit test file that asserts bit-for-bit equality (found, not listed, so a new
    one is covered without touching this module)."""
    me = pathlib.Path(__file__).name
    return sorted(str(p.relative_to(ROOT)) for p in HERE.glob("test_*.py")
                  if p.name != me and "array_equal" in p.read_text(encoding="utf-8"))


def _disable_list(features: list[str]) -> str:
    # numpy refuses to disable a baseline feature; features the CPU lacks are simply absent
    return " ".join(f for f in features if f not in __cpu_baseline__ and __cpu_features__.get(f, False))


def test_the_exactness_tests_are_found():
    files = exactness_test_files()
    assert "tests/unit/test_mold_blade.py" in files and len(files) >= 10, files


@pytest.mark.parametrize("path", sorted(PATHS))
def test_exactness_tests_pass_on_other_cpu_code_paths(path):
    blas, features = PATHS[path]
    env = dict(os.environ, **blas)
    disabled = _disable_list(features)
    if disabled:
        env["NPY_DISABLE_CPU_FEATURES"] = disabled
    env.pop("PYTEST_ADDOPTS", None)
    # the child must really be on the other path: numpy reports what it dispatches to
    probe = subprocess.run(
        [sys.executable, "-c", "import numpy, sys; from numpy.lib import NumpyVersion;"
         "m = __import__('numpy._core._multiarray_umath' if NumpyVersion(numpy.__version__) >= '2.0.0' "
         "else 'numpy.core._multiarray_umath', fromlist=['x']);"
         "print(' '.join(k for k, v in m.__cpu_features__.items() if v))"],
        env=env, capture_output=True, text=True, timeout=120)
    assert probe.returncode == 0, probe.stderr
    active = set(probe.stdout.split())
    assert not (active & set(disabled.split())), (path, active)
    files = exactness_test_files()
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider", *files],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=900)
    tail = "\n".join((run.stdout + run.stderr).splitlines()[-30:])
    assert run.returncode == 0, f"{path} ({disabled or 'nothing disabled'}; {blas}):\n{tail}"
    assert " passed" in run.stdout, tail
