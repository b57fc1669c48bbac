"""Hosseini & Moetakef-Imani (2016): the S823 comparisons of Figs. 5, 7b, 8, 10 and 11.

Our numbers (S823 at unit chord, flat section, mold direction +y; least-squares error
Σ|Q_r - C(t_r)|² of Eq. 3 over the 199 data points). n = control points per half.

Figs. 5 / 7b / 8 (section)::

     n  two-part LSQ   single(n)     single(2n-1)  λ_upper  λ_lower
     5  5.188e-02      4.956e-01     1.072e-02     0.7785   1.2181
     6  7.434e-03      3.097e-01     1.411e-03     0.8831   1.2611
     8  6.815e-04      5.768e-02     4.018e-04     0.9871   0.8409
    10  7.729e-05      1.128e-02     9.398e-05     1.0638   1.0874
    12  1.864e-05      3.023e-03     1.834e-05     1.1048   1.1276
    14  4.649e-06      1.036e-03     5.216e-06     1.1040   1.0800
    16  1.123e-06      5.894e-04     1.756e-06     1.0924   1.0886
    18  3.634e-07      2.808e-04     6.365e-07     1.0784   1.0918
    20  1.321e-07      1.336e-04     2.509e-07     1.0657   1.0831

- Fig. 5: the two-part error falls at every step of the sweep.
- Fig. 7b: the optimised magnitudes vary with n (0.78 -> 1.10 -> 1.07 upper).
- Fig. 8 (test_fig8_at_equal_total_control_points): with the same total of distinct
  control points (single 2n - 1, S shared) the two-part error is lower only from n = 10
  (10, 14-20; n = 12 is within 2 %): at low counts the fixed tangent at S costs more than
  the split gains. With the same count per curve (single curve n, each half n; the
  separate test_fig8_per_curve_reading_...) it is lower at every n. The paper's "lower
  at every count" therefore holds for the per-curve count, not for equal totals.

Figs. 10-11 (the S823 small blade, data/blades/s823_small.toml, aero zone: two-part =
upper + lower, single = one surface with 2n - 1 control points per section)::

     n   MVS two-part  MVS single   SE two-part  SE single
     6   1.32e+06      4.94e+06     304.3        348.7
     8   1.08e+07      9.60e+06     394.6        382.0
    10   1.50e+07      2.97e+07     481.5        486.9
    12   3.28e+07      4.80e+07     546.2        527.4
    14   4.83e+07      5.88e+07     561.0        539.5
    16   6.14e+07      6.86e+07     567.9        549.7
    18   7.26e+07      7.57e+07     570.3        556.0
    20   8.01e+07      7.89e+07     569.7        558.6

- MVS: two-part lower at 6 of 8 counts (not at n = 8 and 20).
- Strain energy: two-part lower only at n = 6 and 10; above that the single surface is
  1-4 % lower. The paper's Fig. 11 claim is NOT reproduced for n >= 12 with these data.

The same comparison on NREL 5-MW (data/blades/nrel5mw.toml: six airfoil families from
DU 40 to NACA 64, twist 13.3° to 0°; aero zone)::

     n   MVS two-part  MVS single   SE two-part  SE single
     6   6.20e+04      6.42e+05     717.6        1044.2
     8   1.56e+05      4.91e+05     892.3        986.8
    10   2.57e+05      3.22e+05     969.0        940.1
    12   2.98e+05      2.79e+05     983.7        954.6
    14   2.76e+05      3.22e+05     979.5        978.4
    16   2.55e+05      3.84e+05     978.8        990.4
    20   2.84e+05      3.83e+05     986.6        991.0

- MVS: two-part lower at 6 of 7 counts (not at n = 12), by up to 10x at n = 6.
- Strain energy: lower at n = 6, 8, 16 and 20; within 3 % above at 10-14.
Here, with the airfoil changing from station to station, the paper's Fig. 10 holds at
all but one count. A likely reason (not isolated here): the single surface's common
knots are averaged over sections whose silhouette points S sit at chord-length
parameters 0.480-0.506 (S823 blade: 0.492-0.494), so its leading edge moves across knot
spans from station to station, while each half always ends at S.

Why, measured on one section (S823, unit chord, ``curve_fairness``: the curve forms of
Eq. 6, CV = ∫(dκ/ds)² ds, BE = ∫κ² ds; "interp" is the cubic interpolant of the 199
points, CV 6.70e+05, BE 62.41)::

     n   twist 0°: CV two / single    BE two / single    twist 16°: CV two / single
     6   8.94e+03 / 2.34e+04          35.48 / 38.20      5.39e+03 / 2.34e+04
     8   4.21e+04 / 4.54e+04          45.01 / 41.86      8.99e+04 / 4.54e+04
    10   8.21e+04 / 1.41e+05          54.33 / 53.36      7.97e+04 / 1.41e+05
    12   1.67e+05 / 2.27e+05          60.92 / 57.81      1.73e+05 / 2.27e+05
    16   2.82e+05 / 3.24e+05          62.52 / 60.27      3.02e+05 / 3.24e+05
    20   3.17e+05 / 3.73e+05          62.31 / 61.24      4.05e+05 / 3.73e+05
    30   2.93e+05 / 3.84e+05          62.14 / 61.73      4.61e+05 / 3.84e+05

1. Strain energy measures resolution before fairness. Both fits converge to the data's
   own bending energy (62.4) as n grows, and the two-part fit gets there sooner: from
   n = 8 it is the closer of the two at every count. The single surface's lower strain
   energy is the leading-edge curvature peak it has not yet resolved (at n = 20 its
   largest curvature is 65.3 against the interpolant's 74.7 and the two-part's 73.6).
   A comparison at an equal count therefore favours whichever fit is coarser.
2. With S at the leading-edge extreme (twist 0°), the two-part section has the lower
   curvature variation at every count, as Fig. 10 says. With twist the mold direction
   is no longer the chord normal, S moves off the curvature peak onto its flank, and
   from n = 20 the two-part fit, which follows that flank more closely, has the higher
   variation. The blade's stations are twisted by 2.5-16°, hence the mixed MVS rows.
3. Neither integral converges with n, because the re-panelled S823 data carry their own
   curvature ripple (the interpolant's CV is 2x that of any fit). Fairness comparisons of
   fits to such data are comparisons at a stated accuracy, not of the method alone.
The tests assert what holds and pin the measured outcome of what does not.
"""
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.mold import build_blade, fit_single, fit_two_part, load_preset, section_points, split_section
from bladesmith.geometry.fairing.surface_fairness import curve_fairness
from bladesmith.geometry.nurbs import interpolate, parameterize
from bladesmith.geometry.sections.airfoil_file import read_airfoil

ROOT = pathlib.Path(__file__).resolve().parents[2]
COUNTS = [5, 6, 8, 10, 12, 14, 16, 18, 20]
BLADE_COUNTS = [6, 8, 10, 12, 14, 16, 18, 20]


@pytest.fixture(scope="module")
def sweep():
    foil = read_airfoil(ROOT / "data" / "blades" / "airfoils" / "s823.dat")
    xy = foil.outline
    Q = section_points(xy, 1.0, 1.0, 0.0, 0.0, wrap=False)
    sp = split_section(Q, xy[:, 0], 1.0, (0.0, 1.0, 0.0), wrap=False)
    rows = []
    for n in COUNTS:
        f = fit_two_part(sp, n_control=n)
        rows.append((n, f.lsq_error, fit_single(Q, n_control=n).lsq_error, fit_single(Q, n_control=2 * n - 1).lsq_error,
                     f.magnitude_upper, f.magnitude_lower))
    print("\n  n  two-part     single(n)    single(2n-1) λ_up    λ_lo")
    for r in rows:
        print(f"{r[0]:3d}  {r[1]:.3e}    {r[2]:.3e}    {r[3]:.3e}    {r[4]:.4f}  {r[5]:.4f}")
    return np.array(rows)


def test_fig5_error_falls_with_control_points(sweep):
    assert np.all(np.diff(sweep[:, 1]) < 0)


def test_fig7b_optimised_magnitude_varies_with_count(sweep):
    for col in (4, 5):
        assert np.ptp(sweep[:, col]) > 0.2 * np.mean(sweep[:, col])


def test_fig8_at_equal_total_control_points(sweep):
    """Fig. 8 as the paper's figure must be read: both fits with the same 2n - 1 distinct
    control points (S shared by the halves). The two-part fit is lower from n = 14 and at
    n = 10, higher at n = 5-8: the paper's "lower at every count" does not hold here."""
    lower = sweep[:, 1] < sweep[:, 3]
    assert not lower[0] and lower[COUNTS.index(10)] and np.all(lower[COUNTS.index(14):])


def test_fig8_per_curve_reading_two_part_below_single_with_n_each(sweep):
    """The per-curve reading (each half n, the single curve n: the two-part fit has about
    twice the control points): lower at every count. Kept apart from the equal-total test
    because it compares unequal totals."""
    assert np.all(sweep[:, 1] < sweep[:, 2])


@pytest.fixture(scope="module")
def blade_sweep():
    return _fairness_sweep("S823_SMALL", BLADE_COUNTS)


def _fairness_sweep(preset: str, counts) -> np.ndarray:
    """Rows (n, MVS two-part, MVS single, SE two-part, SE single) of the blade ``preset``,
    fitted with n control points per half (no adaptation)."""
    d = load_preset(preset)
    rows = []
    for n in counts:
        f = build_blade(d, control_points=n, adapt=False, tolerance=1.0).fairness
        rows.append((n, f["two_part"]["mvs"], f["single"]["mvs"], f["two_part"]["strain_energy"],
                     f["single"]["strain_energy"]))
    print(f"\n {preset}  n  MVS two-part  MVS single  SE two-part  SE single")
    for r in rows:
        print(f"{r[0]:3d}  {r[1]:.3e}   {r[2]:.3e}  {r[3]:.1f}   {r[4]:.1f}")
    return np.array(rows)


def test_fig10_mvs_two_part_lower_at_most_counts(blade_sweep):
    lower = blade_sweep[:, 1] < blade_sweep[:, 2]
    assert lower.sum() >= 6


def test_fig11_strain_energy_measured_outcome(blade_sweep):
    # lower at low counts only; recorded, not the paper's claim (see the module docstring)
    lower = blade_sweep[:, 3] < blade_sweep[:, 4]
    assert lower[0]
    assert np.all(np.abs(blade_sweep[:, 3] / blade_sweep[:, 4] - 1) < 0.15)


# -- the section-level measurements behind the Figs. 10-11 discussion -------------------
SECTION_COUNTS = [6, 8, 10, 12, 16, 20, 30]


def _section_fairness(twist_deg):
    xy = read_airfoil(ROOT / "data" / "blades" / "airfoils" / "s823.dat").outline
    Q = section_points(xy, 1.0, 1.0, twist_deg, 0.3, wrap=False)
    ref = curve_fairness(interpolate(Q, 3, params=parameterize(Q)))
    sp = split_section(Q, xy[:, 0], 1.0, (0.0, 1.0, 0.0), wrap=False)
    rows = []
    for n in SECTION_COUNTS:
        f = fit_two_part(sp, n_control=n)
        a, b = curve_fairness(f.upper), curve_fairness(f.lower)
        c = curve_fairness(fit_single(Q, n_control=2 * n - 1).curve)
        rows.append((n, a.curvature_variation + b.curvature_variation, c.curvature_variation,
                     a.bending_energy + b.bending_energy, c.bending_energy))
    print(f"\n twist {twist_deg}: interp CV {ref.curvature_variation:.3e} BE {ref.bending_energy:.2f}")
    for r in rows:
        print(f"{r[0]:3d}  CV {r[1]:.3e} / {r[2]:.3e}   BE {r[3]:.2f} / {r[4]:.2f}")
    return ref, np.array(rows)


def test_fig10_section_curvature_variation_lower_with_s_at_the_le_extreme():
    _, rows = _section_fairness(0.0)
    assert np.all(rows[:, 1] < rows[:, 2])


def test_fig10_twist_moves_s_off_the_peak_measured_outcome():
    # pinned measurement (docstring point 2): lower at low counts, higher from n = 20
    _, rows = _section_fairness(16.0)
    lower = rows[:, 1] < rows[:, 2]
    assert lower[SECTION_COUNTS.index(6)] and lower[SECTION_COUNTS.index(12)]
    assert not lower[SECTION_COUNTS.index(20)] and not lower[SECTION_COUNTS.index(30)]


def test_fig11_two_part_strain_energy_is_the_better_resolved():
    # docstring point 1: from n = 8 the two-part bending energy is nearer the data's own
    ref, rows = _section_fairness(0.0)
    from_8 = rows[1:]
    assert np.all(np.abs(from_8[:, 3] - ref.bending_energy) < np.abs(from_8[:, 4] - ref.bending_energy))
    # and both converge to it
    assert abs(rows[-1, 3] / ref.bending_energy - 1) < 0.01 and abs(rows[-1, 4] / ref.bending_energy - 1) < 0.02


NREL_COUNTS = [6, 8, 10, 12, 14, 16, 20]


@pytest.fixture(scope="module")
def nrel_sweep():
    return _fairness_sweep("NREL5MW", NREL_COUNTS)


def test_fig10_nrel5mw_mvs_two_part_lower_at_most_counts(nrel_sweep):
    lower = nrel_sweep[:, 1] < nrel_sweep[:, 2]
    assert lower.sum() >= 6 and nrel_sweep[0, 1] < 0.2 * nrel_sweep[0, 2]


def test_fig11_nrel5mw_strain_energy_measured_outcome(nrel_sweep):
    lower = nrel_sweep[:, 3] < nrel_sweep[:, 4]
    assert lower[NREL_COUNTS.index(6)] and lower[NREL_COUNTS.index(8)] and lower[NREL_COUNTS.index(20)]
    assert np.all(nrel_sweep[:, 3] / nrel_sweep[:, 4] < 1.04)
