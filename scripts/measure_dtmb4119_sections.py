"""Prints how closely the section cuts of the DTMB 4119 blade reproduce its table (the
worst error over the ten stations of each measured quantity, in units of D).

    .venv/bin/python scripts/measure_dtmb4119_sections.py
"""
import pathlib, sys; sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / 'bench')); from common import load_checkout; load_checkout()
import numpy as np
from bladesmith.geometry.propeller import Propeller
m = Propeller.from_toml(pathlib.Path(__file__).resolve().parent.parent / 'data' / 'propellers' / 'dtmb4119.toml').build()
lines = [l for l in open(pathlib.Path(__file__).resolve().parents[2] / 'shared' / 'data' / 'marine' / 'dtmb4119_geometry.csv').read().splitlines() if l and not l.startswith('#')]
hdr = lines[0].split(','); rows = [dict(zip(hdr, map(float, l.split(',')))) for l in lines[1:]]
D = m.definition.diameter; b = m.blade
w = dict(chord=0, pitch=0, t=0, f=0, skew=0, rake=0)
for r in rows:
    s = b.measure_section(r['r_R'] * b.radius); c = r['c_D'] * D
    w['chord'] = max(w['chord'], abs(s.chord - c) / D)
    if c > 0: w['pitch'] = max(w['pitch'], abs(s.pitch - r['P_D'] * D) / D)
    w['t'] = max(w['t'], abs(s.max_thickness - r['t0_c'] * c) / D)
    w['f'] = max(w['f'], abs(s.max_camber - r['f0_c'] * c) / D)
    w['skew'] = max(w['skew'], abs(np.radians(s.skew_deg - r['skew_deg']) * s.radius) / D)
    w['rake'] = max(w['rake'], abs(s.rake - r['rake_D'] * D) / D)
print({k: f"{v:.1e} D" for k, v in w.items()})
