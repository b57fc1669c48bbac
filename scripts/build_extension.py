"""Build the Bladesmith extension: one zip per platform, each carrying its scipy wheel.

Run by ``make extension`` with the project venv (it needs the ``bpy`` wheel only to find
Blender's extension CLI, ``bl_pkg/cli/blender_ext.py``; bpy itself is not imported).

Steps:
1. download the pinned scipy wheel for every platform with pip (binary only, explicit
   platform, Python and ABI tags) into ``wheels/``; files already there are reused;
2. write the wheel list and the platform list into ``blender_manifest.toml``;
3. ``blender_ext.py validate`` the source tree;
4. ``blender_ext.py build --split-platforms`` into ``dist/``;
5. ``blender_ext.py validate`` every zip and check it holds exactly its platform's wheels
   and nothing from the excluded folders.

Blender bundles numpy but not scipy, and Blender installs from a zip only the wheels that
match its own Python, so each zip carries one scipy wheel per Python ABI:

- cp311 (Blender 4.2 LTS to 5.0, numpy 1.26.x): scipy 1.15.3, importable with
  numpy >= 1.23.5, < 2.5;
- cp313 (Blender 5.1 and 5.2 LTS, numpy >= 2.2 as the bpy 5.2 wheel requires): scipy 1.18.1,
  importable with numpy >= 2.0, < 2.8.

scipy needs nothing else.
"""
from __future__ import annotations

import argparse
import importlib.util
import pathlib
import re
import subprocess
import sys
import time
import zipfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
MANIFEST = ROOT / "blender_manifest.toml"
WHEEL_DIR = ROOT / "wheels"
DIST_DIR = ROOT / "dist"

#: Python ABI -> (Python version for pip, scipy version), one wheel of each per platform.
SCIPY: dict[str, tuple[str, str]] = {
    "cp311": ("3.11", "1.15.3"),
    "cp313": ("3.13", "1.18.1"),
}

#: Blender platform name -> pip ``--platform`` tags, most specific first. pip expands a
#: macOS tag to every older macOS; manylinux tags are listed explicitly.
PLATFORMS: dict[str, tuple[str, ...]] = {
    "windows-x64": ("win_amd64",),
    # scipy publishes no arm64 wheel for macOS 11; 12.0 (OpenBLAS) is the oldest there is.
    "macos-arm64": ("macosx_12_0_arm64",),
    "macos-x64": ("macosx_10_15_x86_64",),
    "linux-x64": ("manylinux_2_28_x86_64", "manylinux_2_17_x86_64", "manylinux2014_x86_64"),
}

#: Top-level paths that must never reach a zip (the manifest's paths_exclude_pattern).
EXCLUDED_TOP_LEVEL = ("tests/", "bench/", "docs/", "scripts/", "out/", "dist/", ".venv", ".git/", ".ci/")


def blender_ext_cli() -> pathlib.Path:
    """The extension CLI that ships inside the ``bpy`` wheel (found without importing bpy)."""
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit("build_extension: the bpy wheel is not installed in this Python")
    for location in spec.submodule_search_locations:
        found = sorted(pathlib.Path(location).glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
        if found:
            return found[-1]
    raise SystemExit("build_extension: bl_pkg/cli/blender_ext.py not found inside the bpy wheel")


def run(args: list, **kwargs) -> subprocess.CompletedProcess:
    print("+", " ".join(str(a) for a in args), flush=True)
    return subprocess.run([str(a) for a in args], check=True, **kwargs)


def wheel_for(platform: str, abi: str) -> pathlib.Path | None:
    """The scipy wheel in ``wheels/`` for ``abi`` whose platform tag belongs to ``platform``."""
    version = SCIPY[abi][1]
    for wheel in sorted(WHEEL_DIR.glob(f"scipy-{version}-{abi}-{abi}-*.whl")):
        tag = wheel.name[: -len(".whl")].split("-", 4)[4]
        if any(_tag_matches(tag, wanted) for wanted in PLATFORMS[platform]):
            return wheel
    return None


def _tag_matches(tag: str, wanted: str) -> bool:
    for part in tag.split("."):
        if part == wanted:
            return True
        if wanted.startswith("macosx_") and part.startswith("macosx_"):
            # pip accepts any macOS version up to the wanted one, for the same architecture.
            _, major, minor, arch = wanted.split("_", 3)
            p_major, p_minor, p_arch = part.split("_", 3)[1:]
            if p_arch == arch and (int(p_major), int(p_minor)) <= (int(major), int(minor)):
                return True
    return False


def _wanted(name: str) -> bool:
    return any(name.startswith(f"scipy-{version}-{abi}-") for abi, (_, version) in SCIPY.items())


def download_wheels() -> dict[str, list[pathlib.Path]]:
    """platform -> its wheels, one per ABI of :data:`SCIPY`, downloaded when missing."""
    WHEEL_DIR.mkdir(exist_ok=True)
    for stale in WHEEL_DIR.glob("*.whl"):
        if not _wanted(stale.name):
            print(f"removing stale wheel {stale.name}")
            stale.unlink()
    wheels = {}
    for platform, tags in PLATFORMS.items():
        wheels[platform] = []
        for abi, (python, version) in SCIPY.items():
            wheel = wheel_for(platform, abi)
            if wheel is None:
                platform_args = [arg for tag in tags for arg in ("--platform", tag)]
                run([sys.executable, "-m", "pip", "download", "--quiet", "--disable-pip-version-check",
                     f"scipy=={version}", "--no-deps", "--only-binary=:all:",
                     *platform_args, "--python-version", python, "--implementation", "cp",
                     "--abi", abi, "--dest", WHEEL_DIR])
                wheel = wheel_for(platform, abi)
                if wheel is None:
                    raise SystemExit(f"build_extension: pip downloaded no scipy {abi} wheel for {platform}")
            wheels[platform].append(wheel)
    return wheels


def update_manifest(wheels: dict[str, pathlib.Path]) -> None:
    """Write ``platforms`` and ``wheels`` (top-level keys, before the first table)."""
    text = MANIFEST.read_text()
    lines = [
        "platforms = [" + ", ".join(f'"{p}"' for p in PLATFORMS) + "]",
        "wheels = [",
        *(f'  "./wheels/{wheel.name}",' for p in PLATFORMS for wheel in wheels[p]),
        "]",
    ]
    block = "# Written by scripts/build_extension.py (make extension).\n" + "\n".join(lines) + "\n"
    pattern = re.compile(r"# Written by scripts/build_extension\.py.*?\nwheels = \[.*?\]\n", re.S)
    if pattern.search(text):
        new = pattern.sub(lambda _: block, text)
    else:
        first_table = text.index("\n[")
        new = text[:first_table] + "\n" + block + text[first_table:]
    if new != text:
        MANIFEST.write_text(new)
        print("updated blender_manifest.toml")


def validate(cli: pathlib.Path, path: pathlib.Path) -> None:
    run([sys.executable, cli, "validate", path])


def check_zip(path: pathlib.Path, platform: str, wheels: list[pathlib.Path]) -> None:
    names = zipfile.ZipFile(path).namelist()
    bundled = sorted(n for n in names if n.endswith(".whl"))
    expected = sorted(f"wheels/{w.name}" for w in wheels)
    if bundled != expected:
        raise SystemExit(f"build_extension: {path.name} holds wheels {bundled}, expected exactly {expected}")
    leaked = [n for n in names if n.startswith(EXCLUDED_TOP_LEVEL) or "__pycache__" in n]
    if leaked:
        raise SystemExit(f"build_extension: {path.name} holds excluded files, e.g. {leaked[:5]}")
    if "blender_manifest.toml" not in names or "__init__.py" not in names:
        raise SystemExit(f"build_extension: {path.name} lacks blender_manifest.toml or __init__.py at its root")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output-dir", type=pathlib.Path, default=DIST_DIR)
    args = parser.parse_args(argv)
    start = time.perf_counter()
    cli = blender_ext_cli()
    wheels = download_wheels()
    update_manifest(wheels)
    validate(cli, ROOT)
    out = args.output_dir.resolve()
    out.mkdir(parents=True, exist_ok=True)
    for old in out.glob("bladesmith-*.zip"):
        old.unlink()
    run([sys.executable, cli, "build", "--source-dir", ROOT, "--output-dir", out, "--split-platforms"])
    for platform, platform_wheels in wheels.items():
        (zip_path,) = out.glob(f"bladesmith-*-{platform.replace('-', '_')}.zip")
        validate(cli, zip_path)
        check_zip(zip_path, platform, platform_wheels)
        print(f"{zip_path.name}: {zip_path.stat().st_size / 1e6:.1f} MB, {platform}, "
              + ", ".join(w.name for w in platform_wheels))
    print(f"built {len(wheels)} zips in {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
