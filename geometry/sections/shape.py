"""Unit-chord section shapes: a closed, round-edged thickness form and a mean line.

Chordwise parameter (Hally 2013 §2). A section is traced by the eccentric angle
ψ = 2πξ ∈ [0, 2π), with chordwise position x = (1 + cos ψ)/2 measured from the leading
edge: ψ = 0 is the trailing edge (x = 1), ψ = π the leading edge (x = 0); (0, π) is the
pressure (lower) side, (π, 2π) the suction (upper) side. The cosine spacing clusters
points at both edges, and because x - 0 ~ (ψ - π)²/4 and 1 - x ~ ψ²/4, a thickness
growing like sqrt(x) or sqrt(1 - x) is a *regular* function of ψ: the edges are round.

Thickness. The signed half-thickness S(ψ) (negative on the pressure side, so that
S(2π - ψ) = -S(ψ)) is a periodic C2 cubic spline in ψ (scipy ``CubicSpline``,
``bc_type="periodic"``) through the tabulated (or sampled) ordinates, normalised so that the
maximum thickness max 2|S| is exactly 1 (the table's t/c is the maximum thickness).

Closing a finite trailing edge (Hally 2013 §2 requires a closed, blunt TE: b(0, η) =
b(1, η) with one unit normal there). A finite TE ordinate (NACA 66 mod: T/T0 = 0.0666) is
replaced by 0 and every other ordinate is kept; the periodic spline then runs through
S(0) = 0 with a finite, non-zero slope, i.e. the thickness goes to zero like
sqrt(1 - x) over the last node interval (x from 0.95 to 1 for NACA 66 mod): a round
trailing edge inside the chord, so the chord length is unchanged, the surface is C2 in ξ
through the TE and the normals of both sides agree there. The same treatment applies to
formula thicknesses (sampled at ``FORMULA_NODES`` ψ-uniform nodes) and airfoil files.

Mean line. F(x) is an interpolating quintic spline in x (scipy ``make_interp_spline``,
k = 5) through the tabulated ordinates, normalised to maximum 1 (the table's f/c is the
maximum camber); quintic so that the offset direction, which involves F', stays C2.
F(0) = F(1) = 0: the nose–tail line is the chord line.

Section point (unit chord, y towards the suction side), thickness t_c and camber f_c:
  m = f_c F(x), m' = f_c F'(x), w = 1/sqrt(1 + m'^2)
  X = x - t_c S(ψ) m' w,  Y = m + t_c S(ψ) w
i.e. the half-thickness is laid off normal to the mean line (standard NACA / DTMB
practice), so the points ψ and 2π - ψ are t_c 2|S| apart and their midpoint is on the
mean line.
"""
from __future__ import annotations

import pathlib
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import BSpline, CubicSpline, make_interp_spline

from ..errors import BladesmithError, DefinitionError
from . import naca, tables
from .airfoil_file import Airfoil, read_airfoil, smoothed_airfoil, thickness_and_camber

#: ψ-uniform nodes on [0, π] used to sample formula and airfoil-file thicknesses.
FORMULA_NODES = 48
#: Nodes (cosine-spaced in x) used to sample a mean line given by a formula or a file.
MEANLINE_NODES = 41
#: Degree of the mean-line spline in x.
MEANLINE_DEGREE = 5

THICKNESS_NAMES = ("naca66mod", "naca4", "elliptic", "table")
MEANLINE_NAMES = ("a=0.8", "a=0.8mod", "parabolic", "naca4", "none", "table", "airfoil")


def _psi_of_x(x: np.ndarray) -> np.ndarray:
    return np.arccos(np.clip(2.0 * np.asarray(x, dtype=np.float64) - 1.0, -1.0, 1.0))


def _x_of_psi(psi):
    return 0.5 * (1.0 + np.cos(psi))


def _closed_thickness_spline(x_nodes: np.ndarray, t_nodes: np.ndarray, what: str, source=None) -> CubicSpline:
    """Periodic C2 signed half-thickness S(ψ), closed at the TE, normalised to max thickness 1."""
    psi = _psi_of_x(x_nodes)
    order = np.argsort(psi)
    psi, t = psi[order], np.asarray(t_nodes, dtype=np.float64)[order]
    inner = (psi > 1e-12) & (psi < np.pi - 1e-12)
    psi, t = psi[inner], t[inner]
    if psi.size < 2 or np.any(np.diff(psi) <= 0):
        raise DefinitionError(f"{what}: chordwise stations must be distinct and inside (0, 1)", field="section.thickness", path=source)
    if np.any(t <= 0):
        i = int(np.argmax(t <= 0))
        raise DefinitionError(
            f"{what}: thickness {t[i]:g} at x/c = {0.5 * (1 + np.cos(psi[i])):.6g} is not positive; "
            "the section would self-intersect",
            field="section.thickness",
            path=source,
        )
    # Pressure side (0, π) negative; mirror to (π, 2π); closed TE (0) and LE (π).
    nodes = np.concatenate([[0.0], psi, [np.pi], 2.0 * np.pi - psi[::-1], [2.0 * np.pi]])
    values = np.concatenate([[0.0], -0.5 * t, [0.0], 0.5 * t[::-1], [0.0]])
    spline = CubicSpline(nodes, values, bc_type="periodic")
    # maximum thickness: an extremum of S on (0, π)
    d = spline.derivative()
    cand = np.concatenate([d.roots(extrapolate=False), psi])
    cand = cand[(cand > 0) & (cand < np.pi)]
    s_min = float(np.min(spline(cand)))
    # the spline must keep the sign of each side between the nodes too
    roots = spline.roots(extrapolate=False)
    bad = roots[(roots > 1e-9) & (roots < np.pi - 1e-9)]
    if bad.size:
        raise DefinitionError(
            f"{what}: the interpolated thickness becomes negative near x/c = {_x_of_psi(bad[0]):.4g}; "
            "the section would self-intersect",
            field="section.thickness",
            path=source,
        )
    return CubicSpline(nodes, values / (-2.0 * s_min), bc_type="periodic")


#: Passes of Hvid's ad hoc curvature smoother when a definition asks for its airfoil to be
#: smoothed: the paper's fx66-s-196 jobcard (§3.2.1). Fewer passes stay closer to the file.
DEFAULT_SMOOTH_PASSES = 4
#: Largest number of passes a definition may ask for.
MAX_SMOOTH_PASSES = 50


def check_smooth_passes(value, path, field: str) -> int:
    """A definition's ``smooth_passes``: a whole number from 1 to :data:`MAX_SMOOTH_PASSES`,
    else a DefinitionError naming ``path``, ``field`` and the value."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 1 <= value <= MAX_SMOOTH_PASSES:
        raise DefinitionError(f"expected a whole number of passes from 1 to {MAX_SMOOTH_PASSES}, got {value!r}",
                              path=path, field=field)
    return int(value)


def _smoothed(airfoil: Airfoil, source=None, passes: int = DEFAULT_SMOOTH_PASSES) -> Airfoil:
    """``airfoil`` smoothed by Hvid's smoothfoil (``passes`` passes of the ad hoc
    smoother); a failure names the airfoil file."""
    try:
        return smoothed_airfoil(airfoil, passes=int(passes))
    except BladesmithError as exc:  # SmoothingNotConverged (a GeometryError) among them
        raise DefinitionError(
            f"the airfoil {airfoil.path!r} could not be smoothed (Hvid 1993 smoothfoil): {exc}",
            field="section.smooth_airfoil",
            path=source,
        ) from exc


def _meanline_spline(x_nodes, f_nodes, what: str, source=None) -> BSpline:
    x = np.asarray(x_nodes, dtype=np.float64)
    f = np.asarray(f_nodes, dtype=np.float64)
    if abs(x[0]) > 1e-12 or abs(x[-1] - 1.0) > 1e-12 or np.any(np.diff(x) <= 0):
        raise DefinitionError(f"{what}: stations must increase from x/c = 0 to 1", field="section.meanline", path=source)
    if abs(f[0]) > 1e-9 or abs(f[-1]) > 1e-9:
        raise DefinitionError(
            f"{what}: the mean line must be 0 at both ends, got {f[0]:g} and {f[-1]:g}", field="section.meanline",
            path=source,
        )
    f = f.copy()
    f[0] = f[-1] = 0.0
    k = min(MEANLINE_DEGREE, len(x) - 1)
    spline = make_interp_spline(x, f, k=k)
    # maximum |F| from the roots of F'
    d = spline.derivative()
    xs = np.linspace(0.0, 1.0, 2001)
    i = int(np.argmax(np.abs(spline(xs))))
    peak = abs(float(spline(xs[i])))
    if peak == 0.0:
        raise DefinitionError(f"{what}: the mean line is zero everywhere", field="section.meanline", path=source)
    # refine the extremum by Newton on F' (F is smooth there)
    xm = xs[i]
    dd = d.derivative()
    for _ in range(50):
        step = float(d(xm) / dd(xm))
        xm -= step
        if abs(step) < 1e-15:
            break
    if 0.0 < xm < 1.0 and abs(xm - xs[i]) < 1e-2:
        peak = max(peak, abs(float(spline(xm))))
    return BSpline(spline.t, spline.c / peak, spline.k)


@dataclass(frozen=True, eq=False)
class SectionShape:
    """A unit-chord section form (see the module docstring for the conventions).

    thickness: the periodic spline S(ψ) (signed half-thickness, max thickness 1).
    meanline: the spline F(x) (max 1), or None for an uncambered section.
    name: "thickness / meanline" for messages.
    smoothing_deviation: with ``smooth_airfoil``, the smoothed outline's largest distance
    from the file's, as a fraction of chord (see ``Airfoil.smoothing_deviation``); else None.
    """

    thickness: CubicSpline
    meanline: BSpline | None
    name: str = ""
    smoothing_deviation: float | None = None
    _camber_derivatives: tuple = field(default=(), repr=False)

    def __post_init__(self):
        if self.meanline is not None:
            ders = tuple(self.meanline.derivative(k) for k in range(1, 4))
            object.__setattr__(self, "_camber_derivatives", ders)

    # -- construction ----------------------------------------------------------------
    @classmethod
    def from_spec(cls, thickness: str, meanline: str, base_dir=None, thickness_table=None, meanline_table=None,
                  source=None, smooth_airfoil: bool = False, smooth_passes: int = DEFAULT_SMOOTH_PASSES):
        """Build from the [section] names of a propeller definition.

        thickness: "naca66mod", "naca4", "elliptic", "table" (``thickness_table`` = (x_c,
        T/T0)) or the path of an airfoil .dat file (relative to ``base_dir``).
        meanline: "a=0.8" (formula), "a=0.8mod" (table), "parabolic", "naca4" (max at 0.4),
        "none", "table" (``meanline_table`` = (x_c, f/f0)) or "airfoil" (the mean line of
        the airfoil file given as thickness).
        source: the definition file, named in error messages.
        smooth_airfoil: smooth the airfoil file's outline first (Hvid 1993 smoothfoil with
        its default jobcard, :func:`.airfoil_file.smoothed_airfoil`); only for an airfoil
        file. A smoothing that does not converge is a DefinitionError naming the file.
        smooth_passes: passes of the ad hoc smoother (default the paper's 4).
        """
        airfoil: Airfoil | None = None
        key = thickness.strip()
        if smooth_airfoil and key in THICKNESS_NAMES:
            raise DefinitionError(
                f"smooth_airfoil smooths an airfoil file's outline, but thickness = {thickness!r} is not an "
                "airfoil .dat file",
                field="section.smooth_airfoil",
                path=source,
            )
        if key == "naca66mod":
            S = _closed_thickness_spline(tables.NACA66MOD_X, tables.NACA66MOD_T, "naca66mod", source)
        elif key in ("naca4", "elliptic"):
            xs = _x_of_psi(np.linspace(0.0, np.pi, FORMULA_NODES + 1))
            fn = naca.naca4_thickness if key == "naca4" else naca.elliptic_thickness
            S = _closed_thickness_spline(xs, fn(xs), key, source)
        elif key == "table":
            if thickness_table is None:
                raise DefinitionError("thickness = 'table' needs thickness_x_c and thickness_t", field="section.thickness", path=source)
            S = _closed_thickness_spline(np.asarray(thickness_table[0]), np.asarray(thickness_table[1]), "thickness table", source)
        else:
            path = pathlib.Path(key)
            if base_dir is not None and not path.is_absolute():
                path = pathlib.Path(base_dir) / path
            if not path.is_file():
                raise DefinitionError(
                    f"thickness = {thickness!r}: not one of {', '.join(THICKNESS_NAMES[:3])}, and no airfoil file "
                    f"{str(path)!r} exists",
                    field="section.thickness",
                    path=source,
                )
            try:
                airfoil = read_airfoil(path)
            except DefinitionError as exc:  # name the definition and its field, then the file's problem
                raise DefinitionError(f"thickness = {thickness!r}: {exc}", field="section.thickness",
                                      path=source) from None
            if smooth_airfoil:
                airfoil = _smoothed(airfoil, source, smooth_passes)
            xs = _x_of_psi(np.linspace(0.0, np.pi, FORMULA_NODES + 1))
            t, _ = thickness_and_camber(airfoil, xs)
            try:
                S = _closed_thickness_spline(xs, t, f"airfoil {path.name}", source)
            except DefinitionError:
                raise

        mkey = meanline.strip()
        if mkey == "none":
            F = None
        elif mkey == "a=0.8":
            F = _meanline_spline(tables.A08_X, naca.a_series_meanline(tables.A08_X, 0.8), "a=0.8", source)
        elif mkey == "a=0.8mod":
            F = _meanline_spline(tables.A08_X, tables.A08MOD_F, "a=0.8mod", source)
        elif mkey in ("parabolic", "naca4"):
            xs = _x_of_psi(np.linspace(np.pi, 0.0, MEANLINE_NODES))
            fn = naca.parabolic_meanline if mkey == "parabolic" else naca.naca4_meanline
            F = _meanline_spline(xs, fn(xs), mkey, source)
        elif mkey == "table":
            if meanline_table is None:
                raise DefinitionError("meanline = 'table' needs meanline_x_c and meanline_f", field="section.meanline", path=source)
            F = _meanline_spline(np.asarray(meanline_table[0]), np.asarray(meanline_table[1]), "mean-line table", source)
        elif mkey == "airfoil":
            if airfoil is None:
                raise DefinitionError("meanline = 'airfoil' needs an airfoil file as thickness", field="section.meanline", path=source)
            xs = _x_of_psi(np.linspace(np.pi, 0.0, MEANLINE_NODES))
            _, f = thickness_and_camber(airfoil, xs)
            f[0] = f[-1] = 0.0
            F = _meanline_spline(xs, f, f"airfoil {airfoil.path}", source) if np.max(np.abs(f)) > 1e-9 else None
        else:
            raise DefinitionError(
                f"meanline = {meanline!r}: expected one of {', '.join(MEANLINE_NAMES)}", field="section.meanline",
                path=source,
            )
        name = f"{thickness} (smoothed) / {meanline}" if smooth_airfoil else f"{thickness} / {meanline}"
        deviation = airfoil.smoothing_deviation if airfoil is not None else None
        return cls(thickness=S, meanline=F, name=name, smoothing_deviation=deviation)

    # -- evaluation ------------------------------------------------------------------
    def half_thickness(self, psi, nu: int = 0) -> np.ndarray:
        """d^nu S/dψ^nu: signed half-thickness (negative on the pressure side, ψ in (0, π))."""
        return self.thickness(np.mod(psi, 2.0 * np.pi), nu)

    def camber(self, x, nu: int = 0) -> np.ndarray:
        """d^nu F/dx^nu (0 <= nu <= 4) of the normalised mean line; zeros if uncambered."""
        x = np.asarray(x, dtype=np.float64)
        if self.meanline is None:
            return np.zeros_like(x)
        fn = self.meanline if nu == 0 else (self._camber_derivatives[nu - 1] if nu <= 3 else self.meanline.derivative(nu))
        return fn(x)

    def thickness_at(self, x) -> np.ndarray:
        """Normalised thickness T(x) (max 1) at chordwise x."""
        return -2.0 * self.half_thickness(_psi_of_x(x))

    def points(self, psi, thickness_ratio: float, camber_ratio: float) -> np.ndarray:
        """Unit-chord section points (X, Y), shape psi.shape + (2,), for maximum thickness
        / chord ``thickness_ratio`` and maximum camber / chord ``camber_ratio``."""
        psi = np.asarray(psi, dtype=np.float64)
        x = _x_of_psi(psi)
        S = thickness_ratio * self.half_thickness(psi)
        m = camber_ratio * self.camber(x)
        mp = camber_ratio * self.camber(x, 1)
        w = 1.0 / np.sqrt(1.0 + mp * mp)
        return np.stack([x - S * mp * w, m + S * w], axis=-1)

    def outline(self, count: int, thickness_ratio: float, camber_ratio: float) -> np.ndarray:
        """``count`` points ψ-uniform from the TE over the pressure side, LE, suction side
        (not repeating the TE): (count, 2)."""
        psi = np.linspace(0.0, 2.0 * np.pi, count, endpoint=False)
        return self.points(psi, thickness_ratio, camber_ratio)


def _crossing_matrix(P: np.ndarray) -> np.ndarray:
    """Boolean (..., n, n): edge i (P_i -> P_i+1) properly crosses edge j, for closed
    polygons P (..., n, 2); adjacent edges are excluded."""
    P = np.asarray(P, dtype=np.float64)
    ax, ay = P[..., 0], P[..., 1]
    bx, by = np.roll(ax, -1, axis=-1), np.roll(ay, -1, axis=-1)
    ex, ey = bx - ax, by - ay
    # side of the end points of edge j relative to the line of edge i (and vice versa)
    s_a = ex[..., :, None] * (ay[..., None, :] - ay[..., :, None]) - ey[..., :, None] * (ax[..., None, :] - ax[..., :, None])
    s_b = ex[..., :, None] * (by[..., None, :] - ay[..., :, None]) - ey[..., :, None] * (bx[..., None, :] - ax[..., :, None])
    straddle = (s_a * s_b) < 0
    cross = straddle & np.swapaxes(straddle, -1, -2)
    n = P.shape[-2]
    idx = np.arange(n)
    near = np.abs(idx[:, None] - idx[None, :])
    cross &= ~((near <= 1) | (near == n - 1))
    return cross


def polygon_self_intersections(points: np.ndarray) -> np.ndarray:
    """Index pairs (i, j), i < j, of non-adjacent edges of the closed polygon ``points``
    (n, 2) that cross: (k, 2) int array, empty for a simple polygon."""
    cross = np.triu(_crossing_matrix(points))
    return np.argwhere(cross)


def polygons_are_simple(points: np.ndarray) -> np.ndarray:
    """For closed polygons (..., n, 2): True where no two non-adjacent edges cross."""
    return ~np.any(_crossing_matrix(points), axis=(-1, -2))
