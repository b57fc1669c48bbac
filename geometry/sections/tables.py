"""Tabulated section data shipped with Bladesmith (unit chord, x/c from the leading edge).

Source of every table: MIT OpenProp v3 (B. Epps, 2010), ``SourceCode/GeometryFoil2D.m``
(mirror GitHub joaoantoniocardoso/OpenProp, commit 521e1c07c81d), as transcribed in
``shared/data/marine/naca66mod_thickness_a08_meanline.txt``. Original references:
Brockett (1966), DTMB Report 1780 (NACA 66, DTRC modified thickness); Abbott & von
Doenhoff (1959), *Theory of Wing Sections* (NACA a = 0.8 mean line).
"""
from __future__ import annotations

import numpy as np

#: NACA 66 (DTRC modified) thickness form: x/c and T/T0 (T0 = maximum thickness at
#: x/c = 0.45). The trailing edge is finite (T/T0 = 0.0666); see
#: :mod:`bladesmith.geometry.sections.shape` for how it is closed.
NACA66MOD_X = np.array([
    0.0000, 0.0125, 0.0250, 0.0500, 0.0750, 0.1000, 0.1500, 0.2000, 0.3000,
    0.4000, 0.4500, 0.5000, 0.6000, 0.7000, 0.8000, 0.9000, 0.9500, 1.0000,
])
NACA66MOD_T = np.array([
    0.0000, 0.2088, 0.2932, 0.4132, 0.5050, 0.5814, 0.7042, 0.8000, 0.9274,
    0.9904, 1.0000, 0.9924, 0.9306, 0.8070, 0.6220, 0.3754, 0.2286, 0.0666,
])

#: Abscissae (x/c) of the NACA a = 0.8 mean-line tables (Abbott & von Doenhoff).
A08_X = np.array([
    0.0, 0.5, 0.75, 1.25, 2.5, 5.0, 7.5, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0,
    45.0, 50.0, 55.0, 60.0, 65.0, 70.0, 75.0, 80.0, 85.0, 90.0, 95.0, 100.0,
]) / 100.0

#: NACA a = 0.8 mean line, CLi = 1: f/c (OpenProp 'NACA a=0.8 (v1)'); max 0.06790.
A08_F = np.array([
    0.0, 0.287, 0.404, 0.616, 1.077, 1.841, 2.483, 3.043, 3.985, 4.748, 5.367,
    5.863, 6.248, 6.528, 6.709, 6.790, 6.770, 6.644, 6.405, 6.037, 5.514, 4.771,
    3.683, 2.435, 1.163, 0.0,
]) / 100.0

#: Its slope df/dx (the value at x = 0 is an extrapolation; the true slope is singular).
A08_DFDX = np.array([
    0.54823, 0.48535, 0.44925, 0.40359, 0.34104, 0.27718, 0.23868, 0.21050, 0.16892,
    0.13734, 0.11101, 0.08775, 0.06634, 0.04601, 0.02613, 0.00620, -0.01433, -0.03611,
    -0.06010, -0.08790, -0.12311, -0.18412, -0.23921, -0.25583, -0.24904, -0.20385,
])

#: NACA a = 0.8 (modified) mean line as used for DTMB sections, CLi = 1: f/c; max 0.06651.
A08MOD_F = np.array([
    0.0, 0.281, 0.396, 0.603, 1.055, 1.803, 2.432, 2.981, 3.903, 4.651, 5.257,
    5.742, 6.120, 6.394, 6.571, 6.651, 6.631, 6.508, 6.274, 5.913, 5.401, 4.673,
    3.607, 2.452, 1.226, 0.0,
]) / 100.0

A08MOD_DFDX = np.array([
    0.53699, 0.47539, 0.44004, 0.39531, 0.33404, 0.27149, 0.23378, 0.20618, 0.16546,
    0.13452, 0.10873, 0.08595, 0.06498, 0.04507, 0.02559, 0.00607, -0.01404, -0.03537,
    -0.05887, -0.08610, -0.12058, -0.18034, -0.23430, -0.24521, -0.24521, -0.24521,
])
