"""Many curves on the blade evaluated at once (speed of Hally 2013 §§8–9).

Tip smoothing evaluates about a hundred curves (the cuts of §6, the smoothed cuts of §7,
the transfinite-interpolation curves of §8) at the same parameters, several times while
the common knot sequence of §9 is built. One call per curve costs far more in overhead
than in arithmetic (the curves have 20–100 nodes), so the curves are grouped by kind and
each group is evaluated in one vectorised call:

- the cut splines t -> (ξ, η) or t -> (X, Y) in the tip chart (:class:`~.corners.SplineCurve`)
  through :func:`~..nurbs.curve.evaluate_splines` (one span table for all of them);
- the curves of Eqs. 37–41 that share their four boundaries (:class:`~.edge_curves.TFICurve`)
  through one call of :func:`~.edge_curves.tfi_q` on a (curves, parameters) grid;
- anything else one by one.

The results equal the one-by-one evaluation to round-off (the TFI curves bit for bit).
"""
from __future__ import annotations

import numpy as np

from ..nurbs.curve import evaluate_splines
from .corners import ReversedCurve, SplineCurve, from_tip_chart
from .edge_curves import TFICurve, tfi_q

#: Degree of the cut splines (scipy ``make_interp_spline`` with k = 3).
SPLINE_DEGREE = 3


def _batchable_spline(c) -> bool:
    if type(c) is not SplineCurve:
        return False
    s = c.spline
    return s.k == SPLINE_DEGREE and s.c.ndim == 2 and s.c.shape[1] == 2


def curve_parameters(curves, t) -> np.ndarray:
    """Blade parameters (K, n, 2) of K curves (the ``parameters`` protocol of
    :mod:`.corners`) at the same t (n,) in [0, 1]."""
    t = np.asarray(t, dtype=np.float64)
    out = np.empty((len(curves), t.size, 2))
    splines = {True: [], False: []}  # by whether the spline lives in the tip chart
    tfi: dict = {}
    for k, c in enumerate(curves):
        if _batchable_spline(c):
            splines[c.xi_ref is not None].append(k)
        elif type(c) is TFICurve:
            key = (id(c.bottom), id(c.transition), id(c.first), id(c.second), c.u_j)
            tfi.setdefault(key, []).append(k)
        else:
            out[k] = c.parameters(t)
    for chart, idx in splines.items():
        if not idx:
            continue
        group = [curves[k] for k in idx]
        P = evaluate_splines([c.spline.t for c in group], [c.spline.c for c in group], SPLINE_DEGREE, t)
        if chart:
            P = from_tip_chart(P, np.array([c.xi_ref for c in group])[:, None])
        else:
            P[..., 1] = np.minimum(P[..., 1], 1.0)
        out[idx] = P
    for idx in tfi.values():
        group = [curves[k] for k in idx]
        u = np.array([c.u for c in group])[:, None]
        f_u = np.array([c.f_u for c in group])[:, None]
        f_v = np.array([c.f_v for c in group])[:, None]
        bump = 4.0 * t * (1.0 - t)
        # the arithmetic of TFICurve.parameters, on a (curves, t) grid
        out[idx] = tfi_q(group[0], u + bump * (f_u - u), t + bump * (f_v - 0.5))
    return out


def curve_displacement(curve, t, exact):
    """``curve.displacement(t)`` given the exact points b(p(t)) (n, 3) there, which a
    smoothed cut (:class:`~.cut_smoothing.BlendedOffset`) would otherwise evaluate again."""
    if isinstance(curve, ReversedCurve):
        return curve_displacement(curve.base, 1.0 - np.asarray(t, dtype=np.float64), exact)
    offset = getattr(curve, "offset", None)
    if isinstance(curve, SplineCurve) and offset is not None and hasattr(offset, "on_exact"):
        return offset.on_exact(np.asarray(t, dtype=np.float64), exact)
    return curve.displacement(t)
