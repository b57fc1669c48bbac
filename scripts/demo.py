"""The README's main job, headless: ``make demo`` (or ``.venv/bin/python scripts/demo.py``).

Until the propeller pipeline exists (issues 4 and 5), it builds a demonstration blade-like
bicubic NURBS surface (twisted, cambered, with a non-uniform knot vector and weights) plus
its leading-edge curve, shows them exactly in Blender, and writes:

- ``OUT/demo.blend``: the scene, whose objects carry their exact float64 data;
- ``OUT/demo.igs``: IGES written from the float64 model (when the IGES writer is present).

It prints what it did: counts, sizes and the largest distance between Blender's evaluated
mesh and the float64 surface.
"""
from __future__ import annotations

import argparse
import importlib.util
import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent


def load_addon():
    spec = importlib.util.spec_from_file_location(
        "bladesmith", ROOT / "__init__.py", submodule_search_locations=[str(ROOT)]
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules["bladesmith"] = module
    spec.loader.exec_module(module)
    return module


def demo_surface():
    """A twisted, cambered blade-like patch: chordwise u, spanwise v, rational."""
    import numpy as np

    from bladesmith.geometry.nurbs import BSplineSurface

    nu, nv = 9, 7
    s = np.linspace(0.0, 1.0, nu)
    span = np.linspace(0.2, 1.0, nv)
    net = np.empty((nu, nv, 3))
    for j, r in enumerate(span):
        chord = 0.35 * (1.2 - r) ** 0.5
        twist = np.radians(60.0 - 35.0 * r)
        x = (s - 0.5) * chord
        y = 0.08 * chord * np.sin(np.pi * s)  # camber
        net[:, j, 0] = x * np.cos(twist) - y * np.sin(twist)
        net[:, j, 1] = x * np.sin(twist) + y * np.cos(twist)
        net[:, j, 2] = r
    knots_u = [0, 0, 0, 0, 0.12, 0.3, 0.5, 0.7, 0.88, 1, 1, 1, 1]
    knots_v = [0, 0, 0, 0, 0.25, 0.45, 0.7, 1, 1, 1, 1]
    weights = np.ones((nu, nv))
    weights[4, :] = 1.4
    return BSplineSurface(3, 3, knots_u, knots_v, net, weights)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out", help="output folder (created)")
    args = parser.parse_args(argv)
    out = pathlib.Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)

    import bpy
    import numpy as np

    addon = load_addon()
    addon.register()
    from bladesmith.geometry.nurbs.projection import closest_point_surface
    from bladesmith.operators.nurbs_objects import curve_to_object, surface_to_object

    bpy.ops.wm.read_factory_settings(use_empty=True)
    start = time.perf_counter()
    surface = demo_surface()
    surface_object = surface_to_object(surface, "DemoBlade")
    leading_edge = surface.iso_curve("u", 0.5)
    curve_to_object(leading_edge, "DemoBladeMidChord")

    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = surface_object.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    vertices = np.array([v.co[:] for v in mesh.vertices], dtype=np.float64)
    evaluated.to_mesh_clear()
    _, _, distances = closest_point_surface(surface, vertices)
    print(
        f"surface: {surface.shape[0]}x{surface.shape[1]} control points, degree "
        f"({surface.degree_u}, {surface.degree_v}), rational; Blender mesh {len(vertices)} vertices, "
        f"largest distance to the float64 surface {distances.max():.2e} m "
        f"({distances.max() / surface.size():.1e} of the net size)"
    )

    blend = out / "demo.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    print(f"wrote {blend}")
    from bladesmith.iges import curve_from_geometry, surface_from_geometry, write_iges

    igs = out / "demo.igs"
    write_iges(igs, [surface_from_geometry(surface, label="BLADE"), curve_from_geometry(leading_edge, label="MIDCHORD")],
               units="m")
    print(f"wrote {igs}")
    print(f"done in {time.perf_counter() - start:.2f} s")
    addon.unregister()
    return 0


if __name__ == "__main__":
    sys.exit(main())
