"""Uses of the parametric blade (Casey 1983, "Examples of Use").

- :func:`distribution` and :func:`blade_net` / :func:`channel_net`: (u, v) grids set up
  by supplementary distribution parameters (Figs. 9–10), and :func:`net_csv` to write
  them as structured point arrays;
- :func:`axial_section`: intersections with planes z = const (Fig. 8), solved in closed
  form on each straight line element (z is linear in v on a ruling);
- :func:`standardise`: hub-cut / shroud-cut of a blade by a new channel M (Fig. 11), the
  blade extrapolated linearly in v when M is wider;
- :func:`rulings`: the straight line generators for flank milling.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError
from ..files import atomic_write
from .bezier import PatchString
from .channel import MeridionalChannel

#: Newton tolerance (parameter units) for ruling/channel intersections.
CUT_TOLERANCE = 1e-14
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
            lines.append(f"{i},{j},{u[i]!r},{v[j]!r}," + ",".join(repr(float(c)) for c in net[i, j]))
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
def _ruling_cut(surface: PatchString, contour, U: np.ndarray, v0: np.ndarray) -> np.ndarray:
    """v on the rulings at U where the meridional trace (z, r) of the ruling meets the
    (z, r) ``contour`` (a BezierString): Newton on (v, s), vectorised over U."""
    H = surface.lower.evaluate(U)
    T = surface.upper.evaluate(U)
    d = T - H
    s_grid = np.linspace(0.0, contour.count, contour.count * 200 + 1)
    C = contour.evaluate(s_grid)
    P = H + v0[:, None] * d
    zr = np.stack([P[:, 2], np.hypot(P[:, 0], P[:, 1])], axis=1)
    s = s_grid[np.argmin(np.linalg.norm(zr[:, None, :] - C[None, :, :], axis=2), axis=1)]
    v = v0.copy()
    for _ in range(CUT_MAX_ITERATIONS):
        P = H + v[:, None] * d
        r = np.hypot(P[:, 0], P[:, 1])
        Cs, dC = contour.derivatives(s, 1)
        F0 = P[:, 2] - Cs[:, 0]
        F1 = r - Cs[:, 1]
        a, b = d[:, 2], -dC[:, 0]
        c, e = (P[:, 0] * d[:, 0] + P[:, 1] * d[:, 1]) / r, -dC[:, 1]
        det = a * e - b * c
        dv = (e * F0 - b * F1) / det
        ds = (a * F1 - c * F0) / det
        v -= dv
        s = np.clip(s - ds, 0.0, contour.count)
        if np.max(np.abs(dv)) < CUT_TOLERANCE and np.max(np.abs(ds)) < CUT_TOLERANCE * contour.count:
            break
    else:
        raise GeometryError("a ruling does not meet the new channel wall")
    return v


@dataclass(frozen=True, eq=False)
class StandardisedSurface:
    """A blade surface confined to a new channel M (Casey 1983, Fig. 11): the original
    patch equations with the (u, v) net modified, v running on each ruling from
    ``v_hub(U)`` to ``v_shroud(U)`` (outside [0, 1] the ruled surface is extrapolated
    linearly). Points are R(U, v_hub + w (v_shroud - v_hub)) for w in [0, 1]."""

    surface: PatchString
    channel: MeridionalChannel

    def bounds(self, U) -> tuple[np.ndarray, np.ndarray]:
        U = np.atleast_1d(np.asarray(U, dtype=float))
        vh = _ruling_cut(self.surface, self.channel.hub, U, np.zeros_like(U))
        vs = _ruling_cut(self.surface, self.channel.shroud, U, np.ones_like(U))
        return vh, vs

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


def standardise(surface: PatchString, channel: MeridionalChannel) -> StandardisedSurface:
    """Hub-cut or shroud-cut of ``surface`` by the new channel (Casey 1983, Fig. 11)."""
    return StandardisedSurface(surface, channel)


def scaled_channel(channel: MeridionalChannel, shroud_factor: float) -> MeridionalChannel:
    """A channel with the same hub and the shroud moved along v: new shroud =
    hub + shroud_factor (shroud - hub) (0.8: 20 % narrower, a shroud cut; 1.1: 10 % wider).
    Exact on the polygons, since each patch is linear in v."""
    from .bezier import BezierCurve, BezierString

    segs = tuple(
        BezierCurve((1 - shroud_factor) * h.control_points + shroud_factor * s.control_points)
        for h, s in zip(channel.hub.segments, channel.shroud.segments)
    )
    return MeridionalChannel(PatchString(channel.hub, BezierString(segs)))


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
