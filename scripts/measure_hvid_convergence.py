"""Convergence of the Hvid smoother with the defaults a user gets (issue 21 acceptance):
``.venv/bin/python scripts/measure_hvid_convergence.py``.

"Default" is what ``bpy.ops.bladesmith.smooth_curve()`` does with no arguments: AUTO kind
(smoothfoil for an imported airfoil, distribution f'(0) = f'(1) = 0.5, f(1/2) = 0.5,
f'(1/2) = 0.1; smooth2D with α = 3 otherwise), the jobcard (nsmooth 180, ntrial 10,
tolx 1e-10, tolf 1e-9, 4 ad hoc passes) and smoothing type 2, or type 1 on a closed curve.
The CURVE column is kind='CURVE' on the same airfoil file. Deviations are the true
(closest-point) distance, as a fraction of the reference length (chord, or the bounding
box diagonal for smooth2D).
"""
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
import conftest  # noqa: E402,F401  (loads the checkout as ``bladesmith``)

from bladesmith.geometry.fairing import PolynomialDistribution, SmoothingNotConverged, SmoothingSettings, smooth2d, smoothfoil  # noqa: E402
from bladesmith.geometry.fairing.hvid import is_closed  # noqa: E402
from bladesmith.geometry.nurbs import BSplineCurve  # noqa: E402
from bladesmith.geometry.sections.airfoil_file import read_airfoil  # noqa: E402

AIRFOILS = ROOT.parent / "shared" / "data" / "airfoils"
DISTRIBUTION = PolynomialDistribution(0.5, 0.5, 0.5, 0.1)  # the operator's defaults
ALPHA = 3.0


def bezier_circle(a=1.0, b=1.0):
    """Blender's Bezier circle (radius 1, 4 points, handle 0.5523) scaled to a × b, as the
    cyclic cubic that object_to_geometry reads from it."""
    h = 0.552284749831
    P = []
    for k, t in enumerate(np.linspace(0, 2 * np.pi, 5)):
        p, d = np.array([a * np.cos(t), b * np.sin(t)]), h * np.array([-a * np.sin(t), b * np.cos(t)])
        P += ([p - d] if k else []) + [p] + ([p + d] if k < 4 else [])
    return BSplineCurve(3, np.array([0.0] * 4 + [1.0] * 3 + [2.0] * 3 + [3.0] * 3 + [4.0] * 4), np.array(P))


def curve_default(data):
    closed = is_closed(data)
    return smooth2d(data, ALPHA, SmoothingSettings(smoothing_type=1 if closed else 2), closed=closed)


def cell(run):
    try:
        r = run()
    except SmoothingNotConverged as exc:
        return f"FAILS ({exc.reason})"
    return f"{len(r.history)} it. ({r.reason}), {r.deviation.true:.2e}"


def main():
    rows = [("Bezier circle (Blender's)", lambda: curve_default(bezier_circle()), None),
            ("Bezier ellipse 2:1", lambda: curve_default(bezier_circle(2.0, 1.0)), None),
            ("Bezier ellipse 5:1", lambda: curve_default(bezier_circle(5.0, 1.0)), None)]
    for path in sorted(AIRFOILS.glob("*.dat")):
        foil = read_airfoil(path)
        rows.append((path.stem, lambda f=foil: smoothfoil(f, DISTRIBUTION, SmoothingSettings()),
                     lambda f=foil: curve_default(f.outline)))
    print(f"| curve | default (iterations, deviation) | kind='CURVE' |")
    print("|---|---|---|")
    for name, default, curve in rows:
        print(f"| {name} | {cell(default)} | {cell(curve) if curve else '(same)'} |")


if __name__ == "__main__":
    main()
