"""B-spline and NURBS tensor-product surfaces.

Evaluation follows Piegl & Tiller, The NURBS Book 2e: Alg. A3.5/A3.6 (non-rational
point and derivatives) and A4.3/A4.4 (rational).

Two evaluation paths give the same numbers (the tests check both against scipy):

- few points: per pair, the basis functions of A2.2/A2.3 and one gather of the
  (p+1)(q+1) active control points;
- many points (more than a few per patch): each polynomial patch is converted once to
  its Taylor (power-basis) coefficients about the patch's midpoint, cached on the
  surface, and every pair costs one gather of that small table plus a batched matmul
  with the monomials. This is what lets numpy keep up with scipy's compiled
  ``NdBSpline`` on scattered points (see ``bench/``).

Full parameter grids use the cheaper row-then-column contraction (``evaluate_grid``).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from math import comb

import numpy as np

from ..errors import GeometryError
from .basis import (
    basis_function_derivatives,
    basis_functions,
    check_parameters,
    domain_of,
    find_span,
    monomial_derivatives as _monomial_derivatives,
    taylor_matrices as _taylor_matrices,
    validate_degree,
    validate_knots,
)
from .curve import BSplineCurve, validate_points, validate_weights

#: Parameter pairs evaluated per chunk: bounds the temporary (chunk, p+1, q+1, dim) gather
#: and keeps it in cache.
EVAL_CHUNK = 1 << 13
#: Span lookup of the table path: uniform bins per knot of the vector (see _SpanLookup),
#: at most SPAN_BINS_MAX bins.
SPAN_BINS_PER_KNOT = 16
SPAN_BINS_MAX = 1 << 16
#: The patch table is used when there are at least this many points per patch...
TABLE_MIN_POINTS_PER_PATCH = 4
#: ...and the table is no larger than this many bytes.
TABLE_MAX_BYTES = 64 << 20


def rational_surface_derivatives(Aders: np.ndarray, wders: np.ndarray) -> np.ndarray:
    """Derivatives of S = A/w from those of A and w (NURBS Book Alg. A4.4).

    ``Aders``: S + (d+1, d+1, dim), ``wders``: S + (d+1, d+1). Returns S + (d+1, d+1, dim)
    with entries k+l <= d filled (others zero).
    """
    d = Aders.shape[-2] - 1
    SKL = np.zeros_like(Aders)
    w0 = wders[..., 0, 0][..., None]
    for k in range(d + 1):
        for l in range(d - k + 1):
            v = Aders[..., k, l, :].copy()
            for j in range(1, l + 1):
                v -= comb(l, j) * wders[..., 0, j][..., None] * SKL[..., k, l - j, :]
            for i in range(1, k + 1):
                v -= comb(k, i) * wders[..., i, 0][..., None] * SKL[..., k - i, l, :]
                v2 = np.zeros_like(v)
                for j in range(1, l + 1):
                    v2 += comb(l, j) * wders[..., i, j][..., None] * SKL[..., k - i, l - j, :]
                v -= comb(k, i) * v2
            SKL[..., k, l, :] = v / w0
    return SKL


@dataclass(frozen=True, eq=False)
class BSplineSurface:
    """A tensor-product B-spline surface, rational when ``weights`` is given.

    degree_u, degree_v: p, q >= 1.
    knots_u: (nu+p+1,), knots_v: (nv+q+1,).
    control_points: (nu, nv, dim) Euclidean points; the first index runs along u.
    weights: (nu, nv) positive, or None.
    """

    degree_u: int
    degree_v: int
    knots_u: np.ndarray
    knots_v: np.ndarray
    control_points: np.ndarray
    weights: np.ndarray | None = None

    def __post_init__(self):
        p = validate_degree(self.degree_u, "degree_u")
        q = validate_degree(self.degree_v, "degree_v")
        P = validate_points(self.control_points)
        if P.ndim != 3 or P.shape[2] < 1:
            raise GeometryError(f"control_points: expected shape (nu, nv, dim), got {P.shape}")
        if P.shape[0] < p + 1 or P.shape[1] < q + 1:
            raise GeometryError(
                f"control_points: degrees ({p}, {q}) need at least ({p + 1}, {q + 1}) control points, "
                f"got {P.shape[:2]}"
            )
        object.__setattr__(self, "degree_u", p)
        object.__setattr__(self, "degree_v", q)
        object.__setattr__(self, "control_points", P)
        object.__setattr__(self, "knots_u", validate_knots(self.knots_u, p, P.shape[0], "knots_u"))
        object.__setattr__(self, "knots_v", validate_knots(self.knots_v, q, P.shape[1], "knots_v"))
        if self.weights is not None:
            object.__setattr__(self, "weights", validate_weights(self.weights, P.shape[:2]))

    # -- properties ---------------------------------------------------------------
    @property
    def dim(self) -> int:
        return self.control_points.shape[2]

    @property
    def shape(self) -> tuple[int, int]:
        """(nu, nv): control points along u and along v."""
        return self.control_points.shape[:2]

    @property
    def is_rational(self) -> bool:
        return self.weights is not None

    @property
    def domain_u(self) -> tuple[float, float]:
        return domain_of(self.knots_u, self.degree_u)

    @property
    def domain_v(self) -> tuple[float, float]:
        return domain_of(self.knots_v, self.degree_v)

    @property
    def homogeneous(self) -> np.ndarray:
        """(w*P, w): shape (nu, nv, dim+1)."""
        w = np.ones(self.shape) if self.weights is None else self.weights
        return np.concatenate([self.control_points * w[..., None], w[..., None]], axis=2)

    @classmethod
    def from_homogeneous(cls, degree_u, degree_v, knots_u, knots_v, Pw, rational: bool | None = None):
        """Build from homogeneous points (w*P, w). ``rational=None`` keeps weights only if not all 1."""
        Pw = np.asarray(Pw, dtype=np.float64)
        w = Pw[..., -1]
        if np.any(w <= 0) or not np.all(np.isfinite(w)):
            raise GeometryError("homogeneous control points have non-positive or non-finite weights")
        P = Pw[..., :-1] / w[..., None]
        if rational is None:
            rational = not np.all(w == 1.0)
        return cls(degree_u, degree_v, knots_u, knots_v, P, w if rational else None)

    def size(self) -> float:
        """Diagonal of the control net's bounding box: the length scale for tolerances."""
        P = self.control_points.reshape(-1, self.dim)
        return float(np.linalg.norm(P.max(axis=0) - P.min(axis=0)))

    def transposed(self) -> "BSplineSurface":
        """The same surface with u and v swapped."""
        w = None if self.weights is None else self.weights.T
        return BSplineSurface(
            self.degree_v, self.degree_u, self.knots_v, self.knots_u,
            self.control_points.transpose(1, 0, 2), w,
        )

    # -- evaluation ---------------------------------------------------------------
    def _net(self) -> np.ndarray:
        return self.homogeneous if self.is_rational else self.control_points

    @cached_property
    def _patch_table(self):
        """Taylor coefficients of every patch about its midpoint (see module docstring):
        (span midpoints in u, in v, table of shape (n_spans_u * n_spans_v, (p+1)(q+1), dim'))."""
        p, q = self.degree_u, self.degree_v
        net = self._net()
        nu, nv = self.shape
        mid_u, Tu = _taylor_matrices(self.knots_u, p, nu)
        mid_v, Tv = _taylor_matrices(self.knots_v, q, nv)
        windows = np.lib.stride_tricks.sliding_window_view(net, (p + 1, q + 1), axis=(0, 1))
        # v power first: table[patch, b, a, :] multiplies (v - m_v)^b (u - m_u)^a, so that a
        # pair's gathered (q+1, (p+1) dim') block is contracted with the v monomials by one
        # batched product and the (p+1, dim') result with the u monomials, with no
        # (n, (p+1)(q+1)) outer product of the monomials
        table = np.einsum("iac,jbd,ijecd->ijbae", Tu, Tv, windows, optimize=True)
        table = np.ascontiguousarray(table.reshape(Tu.shape[0] * Tv.shape[0], q + 1, (p + 1) * net.shape[2]))
        table.flags.writeable = False
        return mid_u, mid_v, table

    @cached_property
    def _span_lookups(self):
        return _SpanLookup(self.knots_u, self.degree_u), _SpanLookup(self.knots_v, self.degree_v)

    def _use_patch_table(self, n_points: int) -> bool:
        p, q = self.degree_u, self.degree_v
        n_patches = (self.shape[0] - p) * (self.shape[1] - q)
        table_bytes = n_patches * (p + 1) * (q + 1) * (self.dim + 1) * 8
        return n_points >= TABLE_MIN_POINTS_PER_PATCH * n_patches and table_bytes <= TABLE_MAX_BYTES

    def _table_derivatives(self, u: np.ndarray, v: np.ndarray, order: int) -> np.ndarray:
        p, q = self.degree_u, self.degree_v
        mid_u, mid_v, table = self._patch_table
        span_u, span_v = self._span_lookups
        n_spans_v = mid_v.size
        dim = table.shape[2] // (p + 1)
        out = np.zeros((u.size, order + 1, order + 1, dim))
        for s in range(0, u.size, EVAL_CHUNK):
            uc, vc = u[s : s + EVAL_CHUNK], v[s : s + EVAL_CHUNK]
            iu = span_u(uc) - p
            iv = span_v(vc) - q
            G = np.take(table, iu * n_spans_v + iv, axis=0)  # (n, q+1, (p+1) dim')
            Mu = _monomial_derivatives(uc - mid_u[iu], p, order)
            Mv = _monomial_derivatives(vc - mid_v[iv], q, order)
            for l in range(order + 1):
                row = np.einsum("nb,nbk->nk", Mv[l], G).reshape(uc.size, p + 1, dim)
                for k in range(order + 1 - l):
                    out[s : s + EVAL_CHUNK, k, l] = np.einsum("na,nad->nd", Mu[k], row)
        return out

    def _homogeneous_derivatives(self, u: np.ndarray, v: np.ndarray, order: int) -> np.ndarray:
        """Derivatives of the homogeneous surface at flat arrays u, v: (N, d+1, d+1, dim')."""
        if self._use_patch_table(u.size):
            return self._table_derivatives(u, v, order)
        return self._gather_derivatives(u, v, order)

    def _gather_derivatives(self, u: np.ndarray, v: np.ndarray, order: int) -> np.ndarray:
        p, q = self.degree_u, self.degree_v
        net = self._net()
        nv = net.shape[1]
        flat = net.reshape(-1, net.shape[2])
        out = np.zeros((u.size, order + 1, order + 1, flat.shape[1]))
        ia = np.arange(p + 1)[:, None] * nv + np.arange(q + 1)[None, :]
        for s in range(0, u.size, EVAL_CHUNK):
            uc, vc = u[s : s + EVAL_CHUNK], v[s : s + EVAL_CHUNK]
            su = find_span(self.knots_u, p, uc)
            sv = find_span(self.knots_v, q, vc)
            gather = flat[((su - p) * nv + (sv - q))[:, None, None] + ia]  # (n, p+1, q+1, dim)
            if order == 0:
                Nu = basis_functions(self.knots_u, p, uc, su)
                Nv = basis_functions(self.knots_v, q, vc, sv)
                # contract v first: (n, p+1, dim), then u
                row = np.einsum("nb,nabd->nad", Nv, gather)
                out[s : s + EVAL_CHUNK, 0, 0] = np.einsum("na,nad->nd", Nu, row)
            else:
                Du = basis_function_derivatives(self.knots_u, p, uc, su, order)
                Dv = basis_function_derivatives(self.knots_v, q, vc, sv, order)
                row = np.einsum("nlb,nabd->nlad", Dv, gather)
                full = np.einsum("nka,nlad->nkld", Du, row)
                k, l = np.indices((order + 1, order + 1))
                full[:, k + l > order] = 0.0
                out[s : s + EVAL_CHUNK] = full
        return out

    def derivatives(self, u, v, order: int = 1) -> np.ndarray:
        """S and its partial derivatives: shape B + (order+1, order+1, dim) where B is the
        broadcast shape of u and v; entry [k, l] is d^(k+l)S/du^k dv^l for k+l <= order
        (zero above). NURBS Book Alg. A3.6, and A4.4 for rational surfaces."""
        if order < 0:
            raise GeometryError(f"derivative order must be >= 0, got {order}")
        u = check_parameters(u, self.knots_u, self.degree_u, "u")
        v = check_parameters(v, self.knots_v, self.degree_v, "v")
        u, v = np.broadcast_arrays(u, v)
        shape = u.shape
        H = self._homogeneous_derivatives(u.ravel(), v.ravel(), order)
        if self.is_rational:
            H = rational_surface_derivatives(H[..., :-1], H[..., -1])
        return H.reshape(shape + H.shape[1:])

    def evaluate(self, u, v) -> np.ndarray:
        """Points S(u, v) at broadcast parameter arrays: shape B + (dim,)
        (NURBS Book Alg. A3.5 / A4.3)."""
        u = check_parameters(u, self.knots_u, self.degree_u, "u")
        v = check_parameters(v, self.knots_v, self.degree_v, "v")
        u, v = np.broadcast_arrays(u, v)
        shape = u.shape
        H = self._homogeneous_derivatives(u.ravel(), v.ravel(), 0)[:, 0, 0]
        if self.is_rational:
            H = H[:, :-1] / H[:, -1:]
        return H.reshape(shape + (self.dim,))

    __call__ = evaluate

    def evaluate_grid(self, us, vs) -> np.ndarray:
        """Points on the grid us x vs: shape (len(us), len(vs), dim).

        Contracts the net with the v basis once per column and with the u basis once per
        row, which is much cheaper than evaluating the pairs one by one.
        """
        us = check_parameters(np.ravel(us), self.knots_u, self.degree_u, "u")
        vs = check_parameters(np.ravel(vs), self.knots_v, self.degree_v, "v")
        Mu = self.basis_matrix_u(us)  # (len(us), nu)
        Mv = self.basis_matrix_v(vs)  # (len(vs), nv)
        net = self._net()
        H = np.einsum("ia,abd->ibd", Mu, net)
        H = np.einsum("jb,ibd->ijd", Mv, H)
        if self.is_rational:
            H = H[..., :-1] / H[..., -1:]
        return H

    def basis_matrix_u(self, us) -> np.ndarray:
        """Dense collocation matrix N_i,p(u_k): shape (len(us), nu)."""
        return _collocation(self.knots_u, self.degree_u, self.shape[0], np.ravel(us))

    def basis_matrix_v(self, vs) -> np.ndarray:
        """Dense collocation matrix N_j,q(v_k): shape (len(vs), nv)."""
        return _collocation(self.knots_v, self.degree_v, self.shape[1], np.ravel(vs))

    def normal(self, u, v) -> np.ndarray:
        """Unit normal S_u x S_v / |S_u x S_v| (3-D surfaces)."""
        D = self.derivatives(u, v, 1)
        n = np.cross(D[..., 1, 0, :], D[..., 0, 1, :])
        return n / np.linalg.norm(n, axis=-1, keepdims=True)

    def iso_curve(self, direction: str, value: float) -> BSplineCurve:
        """The isoparametric curve u = value (``direction='u'``, a curve in v) or v = value
        (a curve in u), exactly, as a B-spline curve: the net contracted with one basis row."""
        net = self._net()
        if direction == "u":
            row = self.basis_matrix_u([value])[0]
            Pw = np.einsum("a,abd->bd", row, net)
            degree, knots = self.degree_v, self.knots_v
        elif direction == "v":
            row = self.basis_matrix_v([value])[0]
            Pw = np.einsum("b,abd->ad", row, net)
            degree, knots = self.degree_u, self.knots_u
        else:
            raise GeometryError(f"direction must be 'u' or 'v', got {direction!r}")
        if self.is_rational:
            return BSplineCurve.from_homogeneous(degree, knots, Pw, rational=True)
        return BSplineCurve(degree, knots, Pw)


def _collocation(knots: np.ndarray, degree: int, n_control: int, params: np.ndarray) -> np.ndarray:
    params = check_parameters(params, knots, degree)
    span = find_span(knots, degree, params)
    N = basis_functions(knots, degree, params, span)
    M = np.zeros((params.size, n_control))
    rows = np.arange(params.size)[:, None]
    M[rows, span[:, None] - degree + np.arange(degree + 1)] = N
    return M


class _SpanLookup:
    """find_span (NURBS Book Alg. A2.1) for many parameters through a table of uniform
    bins: bin j starts from the span of the start of bin j - 1 (safe against rounding of
    the bin index), and each parameter steps up while U[span + 1] <= u. When the bins are
    fine enough that no two distinct knots lie within two neighbouring bins (up to
    :data:`SPAN_BINS_MAX` bins), one step decides: span = the stepped span of the bin
    where u >= its next knot. The result is exactly that of :func:`.basis.find_span` for
    parameters in the domain; a binary search per parameter (``searchsorted``) costs
    several times more on scattered parameters."""

    def __init__(self, knots: np.ndarray, degree: int):
        a, b = domain_of(knots, degree)
        inner = np.unique(knots[(knots >= a) & (knots <= b)])
        n_bins = SPAN_BINS_PER_KNOT * len(knots)
        gap = float(np.min(np.diff(inner))) if inner.size > 1 else b - a
        # three bins per smallest gap: a window of two bins then holds at most one knot
        fine = int(np.ceil(3.0 * (b - a) / gap)) if gap > 0 else SPAN_BINS_MAX + 1
        self.one_step = fine <= SPAN_BINS_MAX
        if self.one_step:
            n_bins = max(n_bins, fine)
        n_bins = int(min(SPAN_BINS_MAX, n_bins))
        width = (b - a) / n_bins
        self.knots = knots
        self.start = a
        self.scale = 1.0 / width
        self.n_bins = n_bins
        edges = a + width * np.arange(-1, n_bins - 1)
        edges[0] = a
        self.first = find_span(knots, degree, np.clip(edges, a, b))
        self.last = int(find_span(knots, degree, np.array([b]))[0])
        if self.one_step:
            # the next knot above each bin's first span, and the span that starts there
            top = np.minimum(self.first + 1, len(knots) - 1)
            self.next_knot = np.where(self.first < self.last, knots[top], np.inf)
            self.stepped = find_span(knots, degree, np.clip(np.minimum(self.next_knot, b), a, b))

    def __call__(self, u: np.ndarray) -> np.ndarray:
        j = ((u - self.start) * self.scale).astype(np.intp)
        np.clip(j, 0, self.n_bins - 1, out=j)
        if self.one_step:
            return np.where(u >= self.next_knot[j], self.stepped[j], self.first[j])
        span = self.first[j]
        knots, last = self.knots, self.last
        while True:
            step = knots[span + 1] <= u
            step &= span < last
            if not step.any():
                return span
            span += step
