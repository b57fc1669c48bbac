"""The numbers and maps of a curvature review, per surface, without Blender.

``surface_map``: the review tessellation (uniform per knot span, so every vertex sits at
known parameters on the exact surface) with curvature from the float64 model there.
``surface_numbers``: min/max principal curvature, total MVS and strain energy (Hosseini
2016 Eq. 6), and sign changes of the normal curvature along iso lines, with the lines
that have more than their family's baseline flagged (:func:`extra_sign_changes`).
``tip_cut_sign_changes``: the acceptance figure for a Hally-smoothed propeller tip.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import GeometryError
from ..nurbs import BSplineSurface
from .surface_curvature import (
    DEFAULT_QUADRATURE_POINTS,
    ISO_SAMPLES_PER_SPAN,
    QUANTITIES,
    SurfaceCurvature,
    extra_sign_changes,
    fairness_integrals,
    iso_line_sign_changes,
    span_parameters,
    surface_curvature_grid,
)

#: Default tessellation: samples per knot span and direction (a cubic span is three
#: Bezier control intervals, so 6 matches Blender's display at resolution 2).
DEFAULT_SAMPLES_PER_SPAN = 6
#: Default iso lines per direction whose sign changes are counted.
DEFAULT_ISO_LINES = 11


@dataclass(frozen=True, eq=False)
class SurfaceMap:
    """Tessellation of a surface with a curvature quantity at its vertices.

    us (nu,), vs (nv,): the parameters; points (nu, nv, 3); values (nu, nv) of
    ``quantity``; curvature: the full :class:`SurfaceCurvature` on the grid."""

    us: np.ndarray
    vs: np.ndarray
    points: np.ndarray
    values: np.ndarray
    quantity: str
    curvature: SurfaceCurvature

    def vertex_areas(self) -> np.ndarray:
        """Area each vertex stands for, |S_u × S_v| Δu Δv with the trapezoidal weights of
        the grid: the weights of area percentiles (robust limits)."""
        def trapezoid(t):
            d = np.diff(t)
            w = np.zeros_like(t)
            w[:-1] += 0.5 * d
            w[1:] += 0.5 * d
            return w

        return self.curvature.area_element * trapezoid(self.us)[:, None] * trapezoid(self.vs)[None, :]

    def edges(self) -> np.ndarray:
        """Grid edges as vertex index pairs into points.reshape(-1, 3)."""
        nu, nv = self.values.shape
        idx = np.arange(nu * nv).reshape(nu, nv)
        along_v = np.stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()], -1)
        along_u = np.stack([idx[:-1, :].ravel(), idx[1:, :].ravel()], -1)
        return np.concatenate([along_v, along_u])

    def quads(self) -> np.ndarray:
        """(nu-1)(nv-1) quads as vertex indices into points.reshape(-1, 3), ordered so the
        face normal follows S_u × S_v."""
        nu, nv = self.values.shape
        idx = np.arange(nu * nv).reshape(nu, nv)
        return np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], axis=-1).reshape(-1, 4)


def surface_map(surface: BSplineSurface, quantity: str = "mean", samples_per_span: int = DEFAULT_SAMPLES_PER_SPAN,
                sign: float = 1.0) -> SurfaceMap:
    """Curvature ``quantity`` (one of QUANTITIES) on a grid with ``samples_per_span``
    intervals per knot span; ``sign`` as in :func:`surface_curvature_grid`."""
    if quantity not in QUANTITIES:
        raise GeometryError(f"unknown curvature quantity {quantity!r}; expected one of {', '.join(QUANTITIES)}")
    us = span_parameters(surface.knots_u, surface.degree_u, samples_per_span)
    vs = span_parameters(surface.knots_v, surface.degree_v, samples_per_span)
    c = surface_curvature_grid(surface, us, vs, sign=sign, fairness=quantity == "mvs")
    return SurfaceMap(us, vs, c.points, c.quantity(quantity), quantity, c)


@dataclass(frozen=True)
class IsoLineCounts:
    """Sign changes of the normal curvature along the iso lines ``direction`` = values."""

    direction: str
    values: tuple
    counts: tuple
    extra: tuple

    @property
    def flagged(self) -> tuple:
        """Indices of the lines with extra sign changes."""
        return tuple(i for i, e in enumerate(self.extra) if e > 0)


@dataclass(frozen=True)
class SurfaceNumbers:
    """The numbers panel of one surface: principal curvature range (1/m, over the map),
    total MVS (1/m²) and strain energy (dimensionless), area (m²), iso-line counts."""

    name: str
    k_min: float
    k_max: float
    mvs: float
    strain_energy: float
    area: float
    iso_lines: tuple = field(default_factory=tuple)

    def as_dict(self) -> dict:
        return {
            "name": self.name, "k_min": self.k_min, "k_max": self.k_max, "mvs": self.mvs,
            "strain_energy": self.strain_energy, "area": self.area,
            "iso_lines": [
                {"direction": c.direction, "values": list(c.values), "counts": list(c.counts), "extra": list(c.extra)}
                for c in self.iso_lines
            ],
        }


def surface_numbers(surface: BSplineSurface, name: str = "", *, curvature: SurfaceCurvature | None = None,
                    iso_lines: int = DEFAULT_ISO_LINES, quadrature_points: int = DEFAULT_QUADRATURE_POINTS,
                    samples_per_span: int = DEFAULT_SAMPLES_PER_SPAN,
                    iso_samples_per_span: int = ISO_SAMPLES_PER_SPAN) -> SurfaceNumbers:
    """Numbers of one surface. ``curvature``: a grid curvature already computed (the map's),
    else one is computed with ``samples_per_span``. The principal range is taken over that
    grid (sign-independent as a set: min κ2 and max κ1 of the surface's own normal)."""
    if curvature is None:
        us = span_parameters(surface.knots_u, surface.degree_u, samples_per_span)
        vs = span_parameters(surface.knots_v, surface.degree_v, samples_per_span)
        curvature = surface_curvature_grid(surface, us, vs)
    ok = ~curvature.degenerate
    k_min = float(np.min(curvature.k2[ok])) if ok.any() else 0.0
    k_max = float(np.max(curvature.k1[ok])) if ok.any() else 0.0
    f = fairness_integrals(surface, quadrature_points)
    counts = []
    for direction, (lo, hi) in (("u", surface.domain_u), ("v", surface.domain_v)):
        values = np.linspace(lo, hi, int(iso_lines)) if iso_lines > 0 else np.zeros(0)
        c = iso_line_sign_changes(surface, direction, values, per_span=iso_samples_per_span) if values.size else np.zeros(0, int)
        counts.append(IsoLineCounts(direction, tuple(float(x) for x in values), tuple(int(x) for x in c),
                                    tuple(int(x) for x in extra_sign_changes(c))))
    return SurfaceNumbers(name, k_min, k_max, f.mvs, f.strain_energy, f.area, tuple(counts))


def tip_cut_sign_changes(smoothed_blade, samples: int = 801, zero_fraction: float | None = None) -> list[int]:
    """Sign changes of the in-plane curvature of every tip cut of a
    :class:`~..propeller.smoothing.SmoothedBlade`, measured on the tip surface's iso line
    u = i/(N_t - 1) (the cut as built) in the plane of the cut (normal ``cut.normal``),
    with :func:`~..propeller.cut_smoothing.curvature_sign_changes`."""
    from ..propeller.cut_smoothing import CURVATURE_ZERO_FRACTION, curvature_sign_changes, spline_signed_curvature

    zf = CURVATURE_ZERO_FRACTION if zero_fraction is None else zero_fraction
    tip = smoothed_blade.tip
    cuts = smoothed_blade.curves.cuts["tip"]
    n_t = len(smoothed_blade.curves.tip)
    t = np.linspace(*tip.domain_v, samples)
    out = []
    for i, cut in enumerate(cuts):
        k = spline_signed_curvature(tip.iso_curve("u", i / (n_t - 1)), t, cut.normal)
        out.append(curvature_sign_changes(k, zf))
    return out
