"""Regenerating the unsmoothed DTMB 4119 model after a value is edited (issue 4: under
0.1 s at display resolution, Blender copies excluded): definition edit + validation, model
build (sections, radial splines, checks, hub), sampling the blade at 64x48 and the hub at
48x64, and the blade–hub intersection. Also the cost per point of b and its second
derivatives (what the Newton iterations of tip smoothing pay), with a plain numpy
evaluation of the same number of points of a helicoid as the baseline.
"""
from __future__ import annotations

import numpy as np

from common import ROOT, load_checkout, median_time, report

BUDGET_S = 0.1
N_XI, N_ETA = 64, 48
N_POINTS = 10**5


def main() -> dict:
    load_checkout()
    from bladesmith.geometry.propeller import Propeller

    base = Propeller.from_toml(ROOT / "data" / "propellers" / "dtmb4119.toml")
    pitch = np.array(base.radial.P_D)
    state = {"k": 0}

    def edit_and_build():
        state["k"] += 1
        p = base.with_values(radial_P_D=tuple(pitch * (1.0 + 1e-3 * (state["k"] % 7))))
        return p.build()

    model = edit_and_build()

    def sample(m=model):
        m.blade.sample(N_XI, N_ETA)
        m.hub.sample(48, 64)

    def regenerate():
        m = edit_and_build()
        sample(m)
        m.intersection(129)

    t_read = median_time(lambda: Propeller.from_toml(ROOT / "data" / "propellers" / "dtmb4119.toml"), repeat=7)
    t_build = median_time(edit_and_build, repeat=7)
    t_sample = median_time(sample, repeat=7)
    t_inter = median_time(lambda: model.intersection(129), repeat=7)
    t_total = median_time(regenerate, repeat=7)

    rng = np.random.default_rng(4119)
    xi = rng.uniform(0, 1, N_POINTS)
    eta = rng.uniform(model.blade.hub_ratio, 1.0, N_POINTS)
    t_eval = median_time(lambda: model.blade.evaluate(xi, eta), repeat=3)
    t_der = median_time(lambda: model.blade.derivatives(xi, eta, 2), repeat=3)

    def helicoid():
        r, t = eta, 2 * np.pi * xi
        return np.stack([r * np.sin(t), r * np.cos(t), 0.2 * t], axis=-1)

    t_base = median_time(helicoid, repeat=5)
    rows = [
        ("read + validate dtmb4119.toml", t_read, ""),
        ("edit P_D + validate + build model", t_build, ""),
        (f"sample blade {N_XI}x{N_ETA} + hub 48x64", t_sample, ""),
        ("blade-hub intersection, 129 points", t_inter, ""),
        ("regenerate total (edit..intersection)", t_total, f"{t_total / BUDGET_S:.2f} of the 0.1 s budget"),
        (f"b at {N_POINTS:,} scattered (xi, eta)", t_eval, f"{t_eval / t_base:.0f}x a numpy helicoid"),
        (f"b + 5 derivatives at {N_POINTS:,} points", t_der, f"{t_der / N_POINTS * 1e6:.2f} us/point"),
        ("baseline: numpy helicoid", t_base, ""),
    ]
    report("DTMB 4119 model (unsmoothed), regenerate at display resolution", rows)
    return {"regenerate_s": t_total, "build_s": t_build, "sample_s": t_sample, "derivatives_s": t_der}


if __name__ == "__main__":
    main()
