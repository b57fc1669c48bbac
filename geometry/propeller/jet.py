"""Second-order forward-mode derivatives in two variables (ξ, η), vectorised.

A :class:`Jet` carries a value and its partial derivatives up to second order,
(f, f_ξ, f_η, f_ξξ, f_ξη, f_ηη), as numpy arrays (or the float 0.0 where a derivative
vanishes identically, e.g. the η-derivatives of a function of ξ alone, which saves work and
lets arrays of ξ and η broadcast against each other). Arithmetic applies the chain rule
exactly, so surfaces built from jets have analytic first and second derivatives.
"""
from __future__ import annotations

import numpy as np


def _is_zero(a) -> bool:
    return type(a) is float and a == 0.0


def _mul(a, b):
    if _is_zero(a) or _is_zero(b):
        return 0.0
    return a * b


def _add(*terms):
    out = 0.0
    for t in terms:
        if _is_zero(t):
            continue
        out = t if _is_zero(out) else out + t
    return out


class Jet:
    __slots__ = ("v", "a", "b", "aa", "ab", "bb")

    def __init__(self, v, a=0.0, b=0.0, aa=0.0, ab=0.0, bb=0.0):
        self.v, self.a, self.b, self.aa, self.ab, self.bb = v, a, b, aa, ab, bb

    # -- construction -------------------------------------------------------------
    @classmethod
    def of_first(cls, f0, f1, f2, d: float = 1.0) -> "Jet":
        """f(u) with u = d·ξ (+ const): derivatives f1, f2 with respect to u."""
        return cls(f0, f1 * d, 0.0, f2 * (d * d), 0.0, 0.0)

    @classmethod
    def of_second(cls, f0, f1, f2) -> "Jet":
        """f(η) with its derivatives."""
        return cls(f0, 0.0, f1, 0.0, 0.0, f2)

    def compose(self, f0, f1, f2) -> "Jet":
        """g(self) given g, g', g'' evaluated at self.v."""
        return Jet(
            f0,
            _mul(f1, self.a),
            _mul(f1, self.b),
            _add(_mul(f2, _mul(self.a, self.a)), _mul(f1, self.aa)),
            _add(_mul(f2, _mul(self.a, self.b)), _mul(f1, self.ab)),
            _add(_mul(f2, _mul(self.b, self.b)), _mul(f1, self.bb)),
        )

    # -- arithmetic ---------------------------------------------------------------
    def __add__(self, o):
        if isinstance(o, Jet):
            return Jet(self.v + o.v, _add(self.a, o.a), _add(self.b, o.b), _add(self.aa, o.aa), _add(self.ab, o.ab), _add(self.bb, o.bb))
        return Jet(self.v + o, self.a, self.b, self.aa, self.ab, self.bb)

    __radd__ = __add__

    def __neg__(self):
        return Jet(-self.v, _mul(-1.0, self.a) if not _is_zero(self.a) else 0.0,
                   -self.b if not _is_zero(self.b) else 0.0, -self.aa if not _is_zero(self.aa) else 0.0,
                   -self.ab if not _is_zero(self.ab) else 0.0, -self.bb if not _is_zero(self.bb) else 0.0)

    def __sub__(self, o):
        return self + (-o)

    def __rsub__(self, o):
        return (-self) + o

    def __mul__(self, o):
        if not isinstance(o, Jet):
            return Jet(self.v * o, _mul(self.a, o), _mul(self.b, o), _mul(self.aa, o), _mul(self.ab, o), _mul(self.bb, o))
        u, w = self, o
        return Jet(
            u.v * w.v,
            _add(_mul(u.a, w.v), _mul(u.v, w.a)),
            _add(_mul(u.b, w.v), _mul(u.v, w.b)),
            _add(_mul(u.aa, w.v), _mul(2.0, _mul(u.a, w.a)), _mul(u.v, w.aa)),
            _add(_mul(u.ab, w.v), _mul(u.a, w.b), _mul(u.b, w.a), _mul(u.v, w.ab)),
            _add(_mul(u.bb, w.v), _mul(2.0, _mul(u.b, w.b)), _mul(u.v, w.bb)),
        )

    __rmul__ = __mul__

    def reciprocal(self) -> "Jet":
        r = 1.0 / self.v
        return self.compose(r, -r * r, 2.0 * r * r * r)

    def __truediv__(self, o):
        if isinstance(o, Jet):
            return self * o.reciprocal()
        return self * (1.0 / o)

    def __rtruediv__(self, o):
        return self.reciprocal() * o

    # -- functions ----------------------------------------------------------------
    def sqrt(self) -> "Jet":
        s = np.sqrt(self.v)
        with np.errstate(divide="ignore", invalid="ignore"):
            d1 = 0.5 / s
            d2 = -0.25 / (s * self.v)
        return self.compose(s, d1, d2)

    def sin(self) -> "Jet":
        s, c = np.sin(self.v), np.cos(self.v)
        return self.compose(s, c, -s)

    def cos(self) -> "Jet":
        s, c = np.sin(self.v), np.cos(self.v)
        return self.compose(c, -s, -c)

    def stack_into(self, out: np.ndarray, component: int, order: int) -> None:
        """Write into ``out[..., k, l, component]`` (the BSplineSurface.derivatives layout)."""
        out[..., 0, 0, component] = self.v
        if order >= 1:
            out[..., 1, 0, component] = self.a
            out[..., 0, 1, component] = self.b
        if order >= 2:
            out[..., 2, 0, component] = self.aa
            out[..., 1, 1, component] = self.ab
            out[..., 0, 2, component] = self.bb
