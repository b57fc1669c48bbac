"""Uses of the parametric blade (Casey 1983, "Examples of Use").

- :func:`distribution` and :func:`blade_net` / :func:`channel_net`: (u, v) grids set up
  by supplementary distribution parameters (Figs. 9–10), and :func:`net_csv` to write
  them as structured point arrays;
- :func:`axial_section`: intersections with planes z = const (Fig. 8), solved in closed
  form on each straight line element (z is linear in v on a ruling);
- :func:`standardise`: hub-cut / shroud-cut of a blade by a new channel M (Fig. 11), the
  blade extrapolated linearly in v when M is wider (patch strings and the rounded LE/TE
  end patches alike); :func:`scaled_channel` makes M from the original channel;
- :func:`rulings`: the straight line generators for flank milling.
"""
from __future__ import annotations

import weakref
from dataclasses import dataclass
from functools import cached_property
from math import comb

import numpy as np

from ..errors import GeometryError
from ..files import atomic_write
from .bezier import BezierCurve, BezierString, PatchString, RuledPatch
from .channel import MeridionalChannel

#: Newton for ruling/channel intersections: a ruling is done after a step smaller than
#: this (parameter units; the error left is of the order of its square, the starts being
#: already close: see :func:`_cut_newton`).
CUT_QUADRATIC = 1e-6
CUT_MAX_ITERATIONS = 50


def distribution(count: int, cluster_start: float = 0.0, cluster_end: float = 0.0) -> np.ndarray:
    """``count`` parameters in [0, 1], clustered towards either end: the supplementary
    distribution parameters of Casey's nets. 0 gives equal spacing; s > 0 the two-sided
    tanh stretching t = 1/2 [1 + tanh(s (x - 1/2)) / tanh(s / 2)] weighted between the ends
    (Vinokur-type clustering)."""
    x = np.linspace(0.0, 1.0, int(count))
    a, b = float(cluster_start), float(cluster_end)
    if a == 0.0 and b == 0.0:
        return x
    s = a + b
    t = 0.5 * (1.0 + np.tanh(s * (x - 0.5)) / np.tanh(0.5 * s))
    # blend the symmetric stretching with one-sided forms according to the weights
    one_start = 1.0 + np.tanh(s * (x - 1.0)) / np.tanh(s)
    one_end = np.tanh(s * x) / np.tanh(s)
    if a == b:
        return t
    return one_start if b == 0.0 else (one_end if a == 0.0 else (a * one_start + b * one_end) / s)


def blade_net(surface: PatchString, u, v) -> np.ndarray:
    """Points (len(u), len(v), 3) of ``surface`` at u in [0, 1] (over the whole string)
    and v in [0, 1] (Casey 1983, Figs. 9–10)."""
    U = np.asarray(u, dtype=float) * surface.count
    V = np.asarray(v, dtype=float)
    return surface.evaluate(U[:, None], V[None, :])


def channel_net(channel: MeridionalChannel, u0: float, u1: float, u, v) -> np.ndarray:
    """(z, r) points (len(u), len(v), 2) of the channel between U = u0 and u1: the
    quasi-orthogonal grid of a throughflow calculation (Casey 1983, Fig. 9)."""
    U = u0 + (u1 - u0) * np.asarray(u, dtype=float)
    return channel.evaluate(U[:, None], np.asarray(v, dtype=float)[None, :])


def net_csv(net: np.ndarray, u=None, v=None) -> str:
    """A structured net (nu, nv, dim) as CSV text: i, j, u, v and the coordinates."""
    nu, nv, dim = net.shape
    names = ["x", "y", "z"][:dim] if dim == 3 else ["z", "r"][:dim]
    u = np.linspace(0, 1, nu) if u is None else np.asarray(u)
    v = np.linspace(0, 1, nv) if v is None else np.asarray(v)
    lines = ["i,j,u,v," + ",".join(names)]
    for i in range(nu):
        for j in range(nv):
            lines.append(f"{i},{j},{float(u[i])!r},{float(v[j])!r}," + ",".join(repr(float(c)) for c in net[i, j]))
    return "\n".join(lines) + "\n"


def write_net_csv(path, net: np.ndarray, u=None, v=None) -> None:
    atomic_write(path, net_csv(net, u, v))


# -- axial cross-sections ------------------------------------------------------------------------
def axial_section(surface: PatchString, z: float, samples_per_patch: int = 32) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The intersection of ``surface`` with the plane z = const (Casey 1983, Fig. 8).

    On the ruling at U, z(v) = (1-v) z_h(U) + v z_s(U) is linear, so v(U) is exact:
    v = (z - z_h) / (z_s - z_h). Returns (U, v, points) for the samples where
    0 <= v <= 1, in order of U."""
    U = np.linspace(0.0, surface.count, surface.count * samples_per_patch + 1)
    zh = surface.lower.evaluate(U)[:, 2]
    zs = surface.upper.evaluate(U)[:, 2]
    dz = zs - zh
    with np.errstate(divide="ignore", invalid="ignore"):
        v = (z - zh) / dz
    ok = np.isfinite(v) & (v >= 0.0) & (v <= 1.0)
    U, v = U[ok], v[ok]
    return U, v, surface.evaluate(U, v)


# -- standardisation -------------------------------------------------------------------------------
#: Rulings per patch of the blade surface searched along (at least CUT_SEARCH_MIN in all,
#: for the one-patch LE/TE end patches), and in the table from which every cut starts.
CUT_SEARCH_PER_PATCH = 4
CUT_SEARCH_MIN = 9
CUT_TABLE_PER_PATCH = 16
CUT_TABLE_MIN = 33
#: The v window searched along each ruling of the table, and its sampling step.
CUT_SEARCH_WINDOW = (-1.5, 2.5)
CUT_SEARCH_STEP = 0.1
#: The part of the window queried first (:func:`_search_cuts`): it holds the samples either
#: side of both cuts of the shipped presets' rulings for standardisation factors from 0.7
#: to 1.05 (measured; at 1.1 some rulings need more); a ruling it does not settle is
#: searched over the whole window, so the band sets the cost only, never the result.
CUT_SEARCH_BAND = (-0.15, 1.15)
#: Wall samples per channel patch for the inside/outside test of the search.
CUT_WALL_SAMPLES = 256
#: A table whose cut v jumps by more than this second difference between neighbouring
#: rulings is refused: the rulings graze the wall (two crossings merge, or one is lost).
CUT_JUMP = 0.05
#: Largest Newton step in v (the search already placed the start within CUT_SEARCH_STEP).
CUT_MAX_STEP = 0.25
#: A converged cut may not have moved further than this from its table start (in v).
CUT_MAX_DRIFT = 0.1


class CutError(GeometryError):
    """The rulings of a blade surface do not meet a wall of the new channel properly;
    ``wall`` is "hub" or "shroud", ``U`` the surface parameters concerned."""

    def __init__(self, message: str, wall: str, U=()):
        self.wall = wall
        self.U = np.atleast_1d(np.asarray(U, dtype=float))
        super().__init__(message)


def ruled_string(surface) -> PatchString:
    """A :class:`PatchString`, or a single :class:`RuledPatch` (the rounded LE/TE end
    patches) as a one-patch string: both are ruled, R(U, v) = (1-v) lower + v upper."""
    if isinstance(surface, RuledPatch):
        return PatchString(BezierString((surface.lower,)), BezierString((surface.upper,)))
    if isinstance(surface, PatchString):
        return surface
    raise GeometryError(f"expected a PatchString or RuledPatch, got {type(surface).__name__}")


_POWER_FORMS = weakref.WeakKeyDictionary()


class _PowerString:
    """A Bézier string rewritten in power form on each segment, for the many repeated
    evaluations of the cuts: R(U) = Σ_k a_k u^k with u = U - j on segment j (the same
    extrapolation at the ends as :class:`BezierString`), a_k = C(p,k) Σ_{i<=k} (-1)^(k-i)
    C(k,i) P_i (the Bernstein-to-monomial change of basis, The NURBS Book 2e Eqs. 1.7–1.8,
    Casey 1983 Eq. 7), and the coefficients of the derivatives k a_k. All segments and
    derivatives are one (p+1, (order+1) n dim) matrix, so an evaluation is one product of
    the powers of u with it and one gather of each point's own segment."""

    def __init__(self, string: BezierString, order: int = 1):
        p = string.max_degree
        elevated = string.elevated_to(p)
        M = np.zeros((p + 1, p + 1))
        for k in range(p + 1):
            for i in range(k + 1):
                M[k, i] = (-1) ** (k - i) * comb(p, k) * comb(k, i)
        a = np.stack([M @ seg.control_points for seg in elevated.segments], axis=1)  # (p+1, n, dim)
        blocks = [a]
        for _ in range(order):
            d = np.zeros_like(a)
            d[:-1] = a[1:] * np.arange(1, p + 1)[:, None, None]
            blocks.append(d)
            a = d
        self.count, self.dim, self.order, self.degree = string.count, string.dim, order, p
        self.matrix = np.ascontiguousarray(np.stack(blocks, axis=1).reshape(p + 1, -1))  # (p+1, (order+1) n dim)
        # per patch, for gathering only the patch each parameter lies in: (n, p+1, order+1, dim)
        self.by_patch = np.ascontiguousarray(np.stack(blocks, axis=1).transpose(2, 0, 1, 3))

    def derivatives(self, U, order: int = 0) -> list[np.ndarray]:
        U = np.asarray(U, dtype=float)
        j = np.floor(U).astype(np.intp)
        np.minimum(j, self.count - 1, out=j)
        np.maximum(j, 0, out=j)
        u = U - j
        powers = np.empty((U.size, self.degree + 1))
        powers[:, 0] = 1.0
        for k in range(1, self.degree + 1):
            np.multiply(powers[:, k - 1], u, out=powers[:, k])
        # only the patch each parameter lies in (multiplying by every patch's polynomial
        # costs count times more, and the standardised panel edit made it its hot spot)
        picked = np.einsum("kp,kpod->kod", powers, self.by_patch[j, :, :order + 1])  # (k, order+1, dim)
        return [picked[:, i] for i in range(order + 1)]


def _power(string: BezierString) -> _PowerString:
    """The power form of ``string`` with its first two derivatives, cached per string."""
    found = _POWER_FORMS.get(string)
    if found is None:
        found = _PowerString(string, 2)
        _POWER_FORMS[string] = found
    return found


def _rulings_at(surface: PatchString, U) -> tuple[np.ndarray, np.ndarray]:
    """Hub-side points H (v = 0) and directions d = T - H of the rulings at U."""
    H = _power(surface.lower).derivatives(U)[0]
    return H, _power(surface.upper).derivatives(U)[0] - H


def _cut_newton(H, d, contour, v, s, wall: str, U) -> tuple[np.ndarray, np.ndarray]:
    """Newton on (v, s) for the rulings H + v d (k, 3) whose meridional trace (z, r)
    meets ``contour`` (a 2-D BezierString) at C(s): z(v) = C_z(s), r(v) = C_r(s)
    (z is linear in v on a ruling, r = |(x, y)|). Vectorised; only unconverged rulings
    iterate; steps in v limited to CUT_MAX_STEP, s kept on the wall. A ruling is done
    after a step below CUT_QUADRATIC: convergence is quadratic, so that step leaves an
    error of the order of its square (about 1e-12 in v; the meridional residual measured
    on the presets is below 1e-12 of the impeller size)."""
    v = np.array(v, dtype=float)
    s = np.array(s, dtype=float)
    wall_form = _power(contour)
    n = contour.count
    active = np.arange(v.size)
    for _ in range(CUT_MAX_ITERATIONS):
        if active.size == v.size:
            Ha, da, va, sa = H, d, v, s
        else:
            Ha, da, va, sa = H[active], d[active], v[active], s[active]
        P = Ha + va[:, None] * da
        r = np.hypot(P[:, 0], P[:, 1])
        C, dC = wall_form.derivatives(sa, 1)
        F0 = P[:, 2] - C[:, 0]
        F1 = r - C[:, 1]
        a, b = da[:, 2], -dC[:, 0]
        c, e = (P[:, 0] * da[:, 0] + P[:, 1] * da[:, 1]) / r, -dC[:, 1]
        det = a * e - b * c
        ok = det != 0.0
        safe = np.where(ok, det, 1.0)
        dv = np.where(ok, np.minimum(np.maximum((e * F0 - b * F1) / safe, -CUT_MAX_STEP), CUT_MAX_STEP), 0.0)
        ds = np.where(ok, (a * F1 - c * F0) / safe, 0.0)
        if active.size == v.size:
            v, s = va - dv, np.minimum(np.maximum(sa - ds, 0.0), n)
        else:
            v[active] = va - dv
            s[active] = np.minimum(np.maximum(sa - ds, 0.0), n)
        done = ok & (np.abs(dv) < CUT_QUADRATIC * (1.0 + np.abs(va))) & (np.abs(ds) < CUT_QUADRATIC * n)
        active = active[~done]
        if active.size == 0:
            return v, s
    raise CutError(f"the rulings at U = {_u_list(U, active)} do not meet the new {wall} wall (no intersection "
                   "near the expected one: extended, they pass by it or run nearly along it)",
                   wall, np.asarray(U)[active])


def _u_list(U, idx) -> str:
    vals = np.asarray(U, dtype=float)[idx]
    if vals.size <= 3:
        return ", ".join(f"{x:.4g}" for x in vals)
    return f"{vals.min():.4g} to {vals.max():.4g}"


_WALL_SEARCH = weakref.WeakKeyDictionary()


def _wall_search(channel: MeridionalChannel) -> dict:
    """Per wall of ``channel``: (s, C(s), outward unit normal, k-d tree of C), densely
    sampled, cached per channel object. The normal points out of the channel (away from
    the other wall along the channel's straight v lines)."""
    from scipy.spatial import cKDTree

    found = _WALL_SEARCH.get(channel)
    if found is not None:
        return found
    s = np.linspace(0.0, channel.count, channel.count * CUT_WALL_SAMPLES + 1)
    across = channel.shroud.evaluate(s) - channel.hub.evaluate(s)
    out = {}
    for which in ("hub", "shroud"):
        C = channel.wall(which).derivatives(s, 1)
        n = np.stack([-C[1, :, 1], C[1, :, 0]], axis=1)
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        sign = np.sign(np.sum(n * across, axis=1)) * (1.0 if which == "shroud" else -1.0)
        out[which] = (s, C[0], n * sign[:, None], cKDTree(C[0]))
    _WALL_SEARCH[channel] = out
    return out


@dataclass(frozen=True, eq=False)
class _CutTable:
    """v and s of the cut on a table of rulings at U, and their interpolating cubic
    splines in U: the Newton starts of every later cut."""

    U: np.ndarray
    v: np.ndarray
    s: np.ndarray

    @cached_property
    def _splines(self):
        from scipy.interpolate import CubicSpline

        return CubicSpline(self.U, np.stack([self.v, self.s], axis=1), bc_type="not-a-knot")

    def start(self, U) -> tuple[np.ndarray, np.ndarray]:
        vs = self._splines(np.clip(U, self.U[0], self.U[-1]))
        return vs[:, 0], np.clip(vs[:, 1], self.s.min(), self.s.max())


def _search_cuts(surface: PatchString, channel: MeridionalChannel, U: np.ndarray) -> dict:
    """Hub and shroud cuts (v, s) of the rulings at U, found by sampling (see
    :func:`_cut_tables`).

    The wall side of every sample is a k-d tree query, the cost of the search. The walk
    only needs the samples from the inside one nearest v = 1/2 out to the first one past
    each wall, so that is what is queried first: both walls at that sample (the ruling's
    middle, which is inside for any channel the rulings cross properly), the hub below it
    and the shroud above it within CUT_SEARCH_BAND; the whole window only for the rulings
    this does not settle (the middle outside, or no sample past a wall in the band). The
    samples not queried are NaN, which the walk below reads as neither inside nor past a
    wall, and never reaches on a settled ruling: the result is the one of querying the
    whole window, bit for bit."""
    H, d = _rulings_at(surface, U)
    V = np.arange(CUT_SEARCH_WINDOW[0], CUT_SEARCH_WINDOW[1] + 0.5 * CUT_SEARCH_STEP, CUT_SEARCH_STEP)
    search = _wall_search(channel)
    side = {which: np.full((U.size, V.size), np.nan) for which in ("hub", "shroud")}
    foot = {which: np.full((U.size, V.size), np.nan) for which in ("hub", "shroud")}

    def query(rows, cols, walls=("hub", "shroud")):
        if rows.size == 0 or cols.size == 0:
            return
        X = H[rows][:, None, :] + V[cols][None, :, None] * d[rows][:, None, :]
        zr = np.stack([X[..., 2], np.hypot(X[..., 0], X[..., 1])], axis=-1).reshape(-1, 2)
        block = np.ix_(rows, cols)
        for which in walls:
            s_w, C_w, n_w, tree = search[which]
            _, idx = tree.query(zr)
            side[which][block] = np.sum((zr - C_w[idx]) * n_w[idx], axis=1).reshape(rows.size, cols.size)
            foot[which][block] = s_w[idx].reshape(rows.size, cols.size)

    key = np.abs(V - 0.5)
    middle = int(np.argmin(key))
    band = np.nonzero((V >= CUT_SEARCH_BAND[0]) & (V <= CUT_SEARCH_BAND[1]))[0]
    rows = np.arange(U.size)
    settled = np.zeros(U.size, dtype=bool)
    # the walk starts at the middle sample whenever it is inside: its key is the only
    # smallest one (else no shortcut), and the band is contiguous through it
    if np.count_nonzero(key == key[middle]) == 1 and middle in band and np.all(np.diff(band) == 1):
        below, above = band[band < middle], band[band > middle]
        query(rows, np.array([middle]))
        with np.errstate(invalid="ignore"):
            started = rows[(side["hub"][:, middle] < 0.0) & (side["shroud"][:, middle] < 0.0)]
        query(started, below, ("hub",))
        query(started, above, ("shroud",))
        with np.errstate(invalid="ignore"):
            settled[started] = ((side["hub"][np.ix_(started, below)] >= 0.0).any(axis=1)
                                & (side["shroud"][np.ix_(started, above)] >= 0.0).any(axis=1))
    query(rows[~settled], np.arange(V.size))
    with np.errstate(invalid="ignore"):
        inside = (side["hub"] < 0.0) & (side["shroud"] < 0.0)
    missing = ~inside.any(axis=1)
    if missing.any():
        raise CutError(f"the rulings at U = {_u_list(U, missing)} do not pass through the new channel",
                       "shroud", U[missing])
    ref = np.argmin(np.where(inside, np.abs(V - 0.5)[None, :], np.inf), axis=1)
    k = np.arange(V.size)[None, :]
    rows = np.arange(U.size)
    out = {}
    for which in ("hub", "shroud"):
        g = side[which]
        with np.errstate(invalid="ignore"):
            past = g >= 0.0
        if which == "shroud":
            hit = past & (k > ref[:, None])
            hi = np.argmax(hit, axis=1)
            lo = hi - 1
        else:
            hit = past & (k < ref[:, None])
            lo = V.size - 1 - np.argmax(hit[:, ::-1], axis=1)
            hi = lo + 1
        found = hit.any(axis=1)
        if not found.all():
            raise CutError(
                f"the rulings at U = {_u_list(U, ~found)} do not reach the new {which} wall "
                f"(searched v in [{CUT_SEARCH_WINDOW[0]}, {CUT_SEARCH_WINDOW[1]}] along them)", which, U[~found])
        g0, g1 = g[rows, lo], g[rows, hi]
        t = g0 / (g0 - g1)
        v0 = V[lo] + t * CUT_SEARCH_STEP
        s0 = np.where(t < 0.5, foot[which][rows, lo], foot[which][rows, hi])
        v, s = _cut_newton(H, d, channel.wall(which), v0, s0, which, U)
        strayed = np.abs(v - v0) > 2.0 * CUT_SEARCH_STEP
        if strayed.any():
            raise CutError(f"the cut of the rulings at U = {_u_list(U, strayed)} with the {which} wall is "
                           "ill-conditioned (they run nearly along it)", which, U[strayed])
        out[which] = (v, s)
    return out


def _cut_tables(surface: PatchString, channel: MeridionalChannel) -> dict:
    """The hub and shroud cuts on a table of rulings, found robustly (Casey 1983 step d:
    the part of each ruling "truly confined" to the new channel).

    Search, on CUT_SEARCH_PER_PATCH rulings per patch: each ruling is sampled over
    CUT_SEARCH_WINDOW; a sample is inside when it lies on the inner side of both walls
    (nearest wall sample and its outward normal, a k-d tree query). From the inside sample
    nearest v = 1/2 the search walks towards the shroud (v up) and the hub (v down) to the
    first sample outside that wall; the crossing is placed by linear interpolation of the
    signed offsets and refined by Newton (:func:`_cut_newton`). Table: CUT_TABLE_PER_PATCH
    rulings per patch, each refined by Newton from the search interpolated in U. A ruling
    that never leaves through a wall inside the window, a Newton solution far from its
    start, or a table whose cut jumps (the rulings graze the wall, so two crossings merged
    or one was missed) is refused with :class:`CutError`."""
    n = surface.count
    Uc = np.linspace(0.0, n, max(CUT_SEARCH_PER_PATCH * n + 1, CUT_SEARCH_MIN))
    coarse = _search_cuts(surface, channel, Uc)
    U = np.linspace(0.0, n, max(CUT_TABLE_PER_PATCH * n + 1, CUT_TABLE_MIN))
    H, d = _rulings_at(surface, U)
    out = {}
    for which in ("hub", "shroud"):
        vc, sc = coarse[which]
        v0, s0 = np.interp(U, Uc, vc), np.interp(U, Uc, sc)
        v, s = _cut_newton(H, d, channel.wall(which), v0, s0, which, U)
        strayed = np.abs(v - v0) > CUT_MAX_DRIFT
        jump = np.zeros(U.size, dtype=bool)
        jump[1:-1] = np.abs(np.diff(v, 2)) > CUT_JUMP
        bad = strayed | jump
        if bad.any():
            raise CutError(f"the rulings at U = {_u_list(U, bad)} graze the new {which} wall: the cut jumps",
                           which, U[bad])
        out[which] = _CutTable(U, v, s)
    return out


@dataclass(frozen=True, eq=False)
class StandardisedSurface:
    """A blade surface confined to a new channel M (Casey 1983, Fig. 11): the original
    patch equations with the (u, v) net modified, v running on each ruling from
    ``v_hub(U)`` to ``v_shroud(U)`` (outside [0, 1] the ruled surface is extrapolated
    linearly). Points are R(U, v_hub + w (v_shroud - v_hub)) for w in [0, 1].

    ``surface``: a :class:`PatchString` (or, through :func:`standardise`, a
    :class:`RuledPatch` end patch as a one-patch string). The cuts start from a table of
    rulings (:func:`_cut_tables`, computed once) and are refined by Newton (meridional
    residual below 1e-12 of the impeller size). :mod:`.standardisation` turns it into a
    B-spline surface."""

    surface: PatchString
    channel: MeridionalChannel

    @cached_property
    def _tables(self) -> dict:
        return _cut_tables(self.surface, self.channel)

    def _rulings(self, U: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:func:`_rulings_at` of the surface, remembering the last parameters: the fit of
        the trimmed edges asks for the hub and then the shroud cut at the same U (the
        arrays are only read)."""
        key = U.tobytes()
        last = self.__dict__.get("_last_rulings")
        if last is not None and last[0] == key:
            return last[1], last[2]
        H, d = _rulings_at(self.surface, U)
        self.__dict__["_last_rulings"] = (key, H, d)
        return H, d

    def _cut(self, U, which: str):
        U = np.atleast_1d(np.asarray(U, dtype=float))
        v0, s0 = self._tables[which].start(U)
        H, d = self._rulings(U)
        v, s = _cut_newton(H, d, self.channel.wall(which), v0, s0, which, U)
        drift = np.abs(v - v0) > CUT_MAX_DRIFT
        if drift.any():
            raise CutError(f"the cut of the rulings at U = {_u_list(U, drift)} with the {which} wall left its branch",
                           which, U[drift])
        return v, s, H, d

    def cut(self, U, which: str) -> tuple[np.ndarray, np.ndarray]:
        """(v, s) of the rulings at U on wall ``which``: the ruling parameter and the wall's
        own parameter of the meridional intersection point."""
        return self._cut(U, which)[:2]

    def bounds(self, U) -> tuple[np.ndarray, np.ndarray]:
        return self.cut(U, "hub")[0], self.cut(U, "shroud")[0]

    def edge(self, U, which: str) -> np.ndarray:
        """Points (k, 3) of the hub or shroud edge: R(U, v_which(U)), on the new wall."""
        v, _, H, d = self._cut(U, which)
        return H + v[:, None] * d

    def evaluate(self, U, w) -> np.ndarray:
        U = np.atleast_1d(np.asarray(U, dtype=float))
        vh, vs = self.bounds(U)
        w = np.asarray(w, dtype=float)
        V = vh[:, None] + w[None, :] * (vs - vh)[:, None]
        return self.surface.evaluate(np.broadcast_to(U[:, None], V.shape), V)

    def net(self, u, w) -> np.ndarray:
        return self.evaluate(np.asarray(u, dtype=float) * self.surface.count, w)

    def as_patches(self, samples: int = 2) -> PatchString:
        """The ruled surface re-parameterised in v to cover [min v_hub, max v_shroud]
        (exact, for display and export; its edges are not the channel cut)."""
        U = np.linspace(0.0, self.surface.count, self.surface.count * 16 + 1)
        vh, vs = self.bounds(U)
        return self.surface.extended(float(vh.min()), float(vs.max()))


def standardise(surface, channel: MeridionalChannel) -> StandardisedSurface:
    """Hub-cut or shroud-cut of ``surface`` (a patch string, or a rounded LE/TE end patch)
    by the new channel (Casey 1983, Fig. 11)."""
    return StandardisedSurface(ruled_string(surface), channel)


def scaled_channel(channel: MeridionalChannel, shroud_factor: float, hub_factor: float = 1.0) -> MeridionalChannel:
    """A channel with the walls moved along the channel's straight v lines (Casey's
    standardisation, Fig. 11): new shroud = hub + shroud_factor (shroud - hub) (0.8: 20 %
    narrower, a shroud cut; 1.1: 10 % wider) and new hub = shroud + hub_factor (hub - shroud)
    (a hub cut when < 1), both from the original walls. Exact on the polygons, since each
    patch is linear in v; a factor of 1 keeps that wall's polygons bit for bit."""

    sf, hf = float(shroud_factor), float(hub_factor)
    pairs = []
    for h, s in zip(channel.hub.segments, channel.shroud.segments):
        p = max(h.degree, s.degree)
        pairs.append((h.elevate(p - h.degree), s.elevate(p - s.degree)))
    if sf == 1.0:
        shroud = channel.shroud
    else:
        shroud = BezierString(tuple(BezierCurve((1 - sf) * h.control_points + sf * s.control_points) for h, s in pairs))
    if hf == 1.0:
        hub = channel.hub
    else:
        hub = BezierString(tuple(BezierCurve((1 - hf) * s.control_points + hf * h.control_points) for h, s in pairs))
    return MeridionalChannel(PatchString(hub, shroud))


# -- flank milling ---------------------------------------------------------------------------------
def rulings(surface: PatchString, u) -> np.ndarray:
    """The straight line generators at u in [0, 1]: (k, 2, 3) hub and shroud end points,
    the tool axis lines for flank milling (Casey 1983, "Manufacture of Impellers")."""
    U = np.asarray(u, dtype=float) * surface.count
    return np.stack([surface.lower.evaluate(U), surface.upper.evaluate(U)], axis=1)


def ruling_hub_angles(surface: PatchString, channel: MeridionalChannel, u) -> np.ndarray:
    """Angle (rad) between each ruling and the hub wall's meridional tangent at its foot,
    in the meridional plane: near 90 deg means the element is nearly normal to the hub."""
    L = rulings(surface, u)
    d = L[:, 1] - L[:, 0]
    P = L[:, 0]
    r = np.hypot(P[:, 0], P[:, 1])
    dm = np.stack([d[:, 2], (P[:, 0] * d[:, 0] + P[:, 1] * d[:, 1]) / r], axis=1)
    s_grid = np.linspace(0.0, channel.count, channel.count * 400 + 1)
    C = channel.hub.evaluate(s_grid)
    s = s_grid[np.argmin(np.linalg.norm(np.stack([P[:, 2], r], 1)[:, None] - C[None], axis=2), axis=1)]
    t = channel.hub.derivatives(s, 1)[1]
    cos = np.sum(dm * t, axis=1) / (np.linalg.norm(dm, axis=1) * np.linalg.norm(t, axis=1))
    return np.arccos(np.clip(cos, -1.0, 1.0))
