"""IGES 5.3 entities as plain data records.

One frozen dataclass per entity type (IGES 5.3 §4). A record holds exactly what the
entity's Parameter Data section holds (IGES 5.3 §2.2.4.5), with references to other
entities as Python object references, both on write and after reading (the reader
resolves Directory Entry pointers into objects). Flags that follow from the data
(planar, closed, polynomial, periodic) are not stored: the writer derives them, so
they are always truthful.

Records normalise their fields to read-only float64 arrays and tuples but do not judge
consistency; :func:`bladesmith.iges.validate.validate_entity` does that, and the
writer calls it for every entity before a single byte is written.

Coordinates are in the file's units (Global section field 14); lengths in Bladesmith
are metres, so the default unit flag is 6 (metres).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..geometry.errors import IgesError


def _floats(value, what: str, ndim: int | None = None, last: int | None = None) -> np.ndarray:
    """A read-only float64 copy of ``value``; IgesError if it is not numeric or of the wrong rank."""
    try:
        a = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise IgesError(f"{what}: expected numbers, got {value!r:.80} ({exc})") from None
    if ndim is not None and a.ndim != ndim:
        raise IgesError(f"{what}: expected a {ndim}-D array, got shape {a.shape}")
    if last is not None and (a.ndim == 0 or a.shape[-1] != last):
        raise IgesError(f"{what}: expected a last dimension of {last}, got shape {a.shape}")
    a.flags.writeable = False
    return a


def _points3(value, what: str, ndim: int) -> np.ndarray:
    """Points with 2 or 3 coordinates as a read-only (..., 3) array (z = 0 for 2-D points)."""
    a = _floats(value, what, ndim)
    if a.shape[-1] == 2:
        a = np.concatenate([a, np.zeros(a.shape[:-1] + (1,))], axis=-1)
    elif a.shape[-1] != 3:
        raise IgesError(f"{what}: expected 2 or 3 coordinates per point, got shape {a.shape}")
    a.flags.writeable = False
    return a


def _real(value, what: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise IgesError(f"{what}: expected a real number, got {value!r:.80}") from None
    return x


def _int(value, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise IgesError(f"{what}: expected an integer, got {value!r:.80}")
    return int(value)


@dataclass(frozen=True)
class DirectoryInfo:
    """Raw Directory Entry fields of a record that was read (IGES 5.3 §2.2.4.4).

    Kept for diagnostics only; the writer derives its own Directory Entry.
    """

    sequence: int  # sequence number of the first DE line (odd)
    line: int  # 1-based line of the first DE line in the file
    parameter_line: int  # 1-based line of the first PD line
    form: int
    status: str
    level: int
    color: int


@dataclass(frozen=True, eq=False, kw_only=True)
class Entity:
    """Base of all records: the Directory Entry fields a record may carry.

    label: entity label, DE field 18 (at most 8 characters).
    subscript: entity subscript number, DE field 19.
    transform: a :class:`TransformationMatrix` (type 124) applied to this entity, DE field 7.
    directory: raw DE values when read from a file (ignored on write).
    """

    type_number: ClassVar[int] = 0
    label: str = ""
    subscript: int = 0
    transform: "TransformationMatrix | None" = None
    directory: DirectoryInfo | None = field(default=None, repr=False)

    def __post_init__(self):
        if not isinstance(self.label, str):
            raise IgesError(f"label must be a string, got {self.label!r:.80}")
        object.__setattr__(self, "subscript", _int(self.subscript, "subscript"))

    @property
    def form(self) -> int:
        """The form number written in DE field 15."""
        return 0

    def references(self) -> tuple["Entity", ...]:
        """Entities this one points to from its parameter data, in parameter order."""
        return ()

    def describe(self) -> str:
        lab = f" '{self.label}'" if self.label else ""
        return f"{type(self).__name__} (type {self.type_number}){lab}"


@dataclass(frozen=True, eq=False)
class TransformationMatrix(Entity):
    """Transformation Matrix entity, type 124 (IGES 5.3 §4.21): x' = R x + T.

    rotation: (3, 3) R; translation: (3,) T. Form 0: R orthonormal with det +1;
    form 1: det -1.
    """

    type_number: ClassVar[int] = 124
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    matrix_form: int = 0

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(self, "rotation", _floats(self.rotation, "rotation", 2))
        object.__setattr__(self, "translation", _floats(self.translation, "translation", 1))
        object.__setattr__(self, "matrix_form", _int(self.matrix_form, "matrix_form"))

    @property
    def form(self) -> int:
        return self.matrix_form

    def apply(self, points: np.ndarray) -> np.ndarray:
        return np.asarray(points) @ self.rotation.T + self.translation


@dataclass(frozen=True, eq=False)
class CircularArc(Entity):
    """Circular Arc entity, type 100 (IGES 5.3 §4.3).

    In its definition plane z = ``z``: ``center``, ``start`` and ``end`` are (x, y)
    points; the arc runs counter-clockwise from start to end (a full circle when they
    coincide). Parameter: the angle, from that of ``start`` to that of ``end``.
    """

    type_number: ClassVar[int] = 100
    center: np.ndarray = None
    start: np.ndarray = None
    end: np.ndarray = None
    z: float = 0.0

    def __post_init__(self):
        super().__post_init__()
        for name in ("center", "start", "end"):
            object.__setattr__(self, name, _floats(getattr(self, name), name, 1, 2))
        object.__setattr__(self, "z", _real(self.z, "z"))

    @property
    def radius(self) -> float:
        return float(np.hypot(*(self.start - self.center)))

    @property
    def angles(self) -> tuple[float, float]:
        """(start angle, end angle) with end > start, end - start <= 2 pi."""
        a0 = math.atan2(self.start[1] - self.center[1], self.start[0] - self.center[0])
        a1 = math.atan2(self.end[1] - self.center[1], self.end[0] - self.center[0])
        while a1 <= a0:
            a1 += 2.0 * math.pi
        return a0, a1


@dataclass(frozen=True, eq=False)
class CompositeCurve(Entity):
    """Composite Curve entity, type 102 (IGES 5.3 §4.4): curves joined end to start."""

    type_number: ClassVar[int] = 102
    curves: tuple = ()

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(self, "curves", tuple(self.curves))

    def references(self):
        return self.curves


@dataclass(frozen=True, eq=False)
class Line(Entity):
    """Line entity, type 110 (IGES 5.3 §4.13): P(t) = start + t (end - start), 0 <= t <= 1.

    line_form: 0 bounded segment, 1 semi-bounded, 2 unbounded.
    """

    type_number: ClassVar[int] = 110
    start: np.ndarray = None
    end: np.ndarray = None
    line_form: int = 0

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(self, "start", _points3(self.start, "start", 1))
        object.__setattr__(self, "end", _points3(self.end, "end", 1))
        object.__setattr__(self, "line_form", _int(self.line_form, "line_form"))

    @property
    def form(self) -> int:
        return self.line_form


@dataclass(frozen=True, eq=False)
class ParametricSpline(Entity):
    """Parametric Spline Curve entity, type 112 (IGES 5.3 §4.14).

    spline_type: CTYPE (1 linear, 2 quadratic, 3 cubic, 4 Wilson-Fowler, 5 modified
    Wilson-Fowler, 6 B-spline). continuity: H. ndim: 2 planar, 3 non-planar.
    breakpoints: (N+1,) T(1..N+1).
    coefficients: (N, 3, 4): segment i, coordinate, (A, B, C, D) with
    x(s) = A + B s + C s^2 + D s^3 and s = t - T(i).
    terminal: (3, 4) value, first, second/2! and third/3! derivative at T(N+1).
    """

    type_number: ClassVar[int] = 112
    spline_type: int = 3
    continuity: int = 2
    ndim: int = 3
    breakpoints: np.ndarray = None
    coefficients: np.ndarray = None
    terminal: np.ndarray = None

    def __post_init__(self):
        super().__post_init__()
        for name in ("spline_type", "continuity", "ndim"):
            object.__setattr__(self, name, _int(getattr(self, name), name))
        object.__setattr__(self, "breakpoints", _floats(self.breakpoints, "breakpoints", 1))
        object.__setattr__(self, "coefficients", _floats(self.coefficients, "coefficients", 3))
        object.__setattr__(self, "terminal", _floats(self.terminal, "terminal", 2))


@dataclass(frozen=True, eq=False)
class ParametricSplineSurface(Entity):
    """Parametric Spline Surface entity, type 114 (IGES 5.3 §4.15).

    breakpoints_u: (M+1,), breakpoints_v: (N+1,).
    coefficients: (M, N, 3, 16): patch (i, j), coordinate, the 16 coefficients
    A..R in file order, coefficient k multiplying s^(k % 4) t^(k // 4) with
    s = u - TU(i), t = v - TV(j). The file's extra row and column of arbitrary
    patch values are written as zeros and dropped on reading.
    """

    type_number: ClassVar[int] = 114
    spline_type: int = 3
    patch_type: int = 1
    breakpoints_u: np.ndarray = None
    breakpoints_v: np.ndarray = None
    coefficients: np.ndarray = None

    def __post_init__(self):
        super().__post_init__()
        for name in ("spline_type", "patch_type"):
            object.__setattr__(self, name, _int(getattr(self, name), name))
        object.__setattr__(self, "breakpoints_u", _floats(self.breakpoints_u, "breakpoints_u", 1))
        object.__setattr__(self, "breakpoints_v", _floats(self.breakpoints_v, "breakpoints_v", 1))
        object.__setattr__(self, "coefficients", _floats(self.coefficients, "coefficients", 4))


@dataclass(frozen=True, eq=False)
class SurfaceOfRevolution(Entity):
    """Surface of Revolution entity, type 120 (IGES 5.3 §4.18).

    The generatrix C(t), a <= t <= b, rotated right-handedly about ``axis`` (a
    :class:`Line`, from its start towards its end) from ``start_angle`` to
    ``end_angle`` (radians). Parameter space: u = t of the generatrix, v = angle.
    """

    type_number: ClassVar[int] = 120
    axis: Line = None
    generatrix: Entity = None
    start_angle: float = 0.0
    end_angle: float = 2.0 * math.pi

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(self, "start_angle", _real(self.start_angle, "start_angle"))
        object.__setattr__(self, "end_angle", _real(self.end_angle, "end_angle"))

    def references(self):
        return (self.axis, self.generatrix)


@dataclass(frozen=True, eq=False)
class BSplineCurve126(Entity):
    """Rational B-Spline Curve entity, type 126 (IGES 5.3 §4.23).

    degree: M. knots: (K+M+2,) T(-M)..T(N+M). control_points: (K+1, 3) Euclidean
    (2-D points get z = 0). weights: (K+1,) or None for all ones (polynomial).
    start, end: V(0), V(1), the parameter range used; None means the knot domain
    [T(0), T(N)].
    """

    type_number: ClassVar[int] = 126
    degree: int = 3
    knots: np.ndarray = None
    control_points: np.ndarray = None
    weights: np.ndarray | None = None
    start: float | None = None
    end: float | None = None

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(self, "degree", _int(self.degree, "degree"))
        object.__setattr__(self, "knots", _floats(self.knots, "knots", 1))
        P = _points3(self.control_points, "control_points", 2)
        object.__setattr__(self, "control_points", P)
        w = np.ones(P.shape[0]) if self.weights is None else self.weights
        object.__setattr__(self, "weights", _floats(w, "weights", 1))
        for name in ("start", "end"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, _real(value, name))

    @property
    def parameter_range(self) -> tuple[float, float]:
        """(V(0), V(1)); the knot domain when not given."""
        p, U = self.degree, self.knots
        n = self.control_points.shape[0]
        a = self.start if self.start is not None else float(U[p]) if 0 <= p < U.size else math.nan
        b = self.end if self.end is not None else float(U[n]) if 0 <= n < U.size else math.nan
        return a, b

    @property
    def is_polynomial(self) -> bool:
        """PROP3: all weights equal (IGES 5.3 §4.23: then the curve is polynomial)."""
        w = self.weights
        return bool(w.size == 0 or np.all(w == w[0]))


@dataclass(frozen=True, eq=False)
class BSplineSurface128(Entity):
    """Rational B-Spline Surface entity, type 128 (IGES 5.3 §4.24).

    degree_u, degree_v: M1, M2. knots_u: (K1+M1+2,), knots_v: (K2+M2+2,).
    control_points: (K1+1, K2+1, 3), first index along u (the file lists them with
    the u index varying fastest). weights: (K1+1, K2+1) or None for all ones.
    u_range, v_range: (U(0), U(1)), (V(0), V(1)); None means the knot domains.
    """

    type_number: ClassVar[int] = 128
    degree_u: int = 3
    degree_v: int = 3
    knots_u: np.ndarray = None
    knots_v: np.ndarray = None
    control_points: np.ndarray = None
    weights: np.ndarray | None = None
    u_range: tuple | None = None
    v_range: tuple | None = None

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(self, "degree_u", _int(self.degree_u, "degree_u"))
        object.__setattr__(self, "degree_v", _int(self.degree_v, "degree_v"))
        object.__setattr__(self, "knots_u", _floats(self.knots_u, "knots_u", 1))
        object.__setattr__(self, "knots_v", _floats(self.knots_v, "knots_v", 1))
        P = _points3(self.control_points, "control_points", 3)
        object.__setattr__(self, "control_points", P)
        w = np.ones(P.shape[:2]) if self.weights is None else self.weights
        object.__setattr__(self, "weights", _floats(w, "weights", 2))
        for name in ("u_range", "v_range"):
            value = getattr(self, name)
            if value is not None:
                if len(value) != 2:
                    raise IgesError(f"{name}: expected (start, end), got {value!r:.80}")
                object.__setattr__(self, name, (_real(value[0], name), _real(value[1], name)))

    def _range(self, given, knots, degree, n):
        if given is not None:
            return given
        if 0 <= degree < knots.size and 0 <= n < knots.size:
            return float(knots[degree]), float(knots[n])
        return math.nan, math.nan

    @property
    def parameter_range_u(self) -> tuple[float, float]:
        return self._range(self.u_range, self.knots_u, self.degree_u, self.control_points.shape[0])

    @property
    def parameter_range_v(self) -> tuple[float, float]:
        return self._range(self.v_range, self.knots_v, self.degree_v, self.control_points.shape[1])

    @property
    def is_polynomial(self) -> bool:
        w = self.weights
        return bool(w.size == 0 or np.all(w == w.flat[0]))


@dataclass(frozen=True, eq=False)
class CurveOnSurface(Entity):
    """Curve on a Parametric Surface entity, type 142 (IGES 5.3 §4.19).

    surface: the surface S. parameter_curve: B, a curve in S's (u, v) parameter space
    (x = u, y = v, z = 0). model_curve: C in model space, or None.
    creation: CRTN (0 unspecified, 1 projection, 2 intersection, 3 isoparametric).
    preferred: PREF (0 unspecified, 1 S o B, 2 C, 3 either).
    """

    type_number: ClassVar[int] = 142
    surface: Entity = None
    parameter_curve: Entity | None = None
    model_curve: Entity | None = None
    creation: int = 0
    preferred: int = 1

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(self, "creation", _int(self.creation, "creation"))
        object.__setattr__(self, "preferred", _int(self.preferred, "preferred"))

    def references(self):
        return tuple(e for e in (self.surface, self.parameter_curve, self.model_curve) if e is not None)


@dataclass(frozen=True, eq=False)
class TrimmedSurface(Entity):
    """Trimmed (Parametric) Surface entity, type 144 (IGES 5.3 §4.20).

    surface: the untrimmed surface. outer: a :class:`CurveOnSurface` bounding it, or
    None when the outer boundary is the boundary of the parameter domain (N1 = 0).
    inner: holes, each a :class:`CurveOnSurface`.
    """

    type_number: ClassVar[int] = 144
    surface: Entity = None
    outer: CurveOnSurface | None = None
    inner: tuple = ()

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(self, "inner", tuple(self.inner))

    def references(self):
        out = [self.surface]
        if self.outer is not None:
            out.append(self.outer)
        out.extend(self.inner)
        return tuple(out)


@dataclass(frozen=True, eq=False)
class GenericEntity(Entity):
    """An entity of a type this package does not model, kept as its raw parameters.

    Read only: pointers inside cannot be told from integers, so it cannot be rewritten.
    """

    entity_type: int = 0
    entity_form: int = 0
    parameters: tuple = ()

    @property
    def form(self) -> int:
        return self.entity_form

    def describe(self) -> str:
        return f"GenericEntity (type {self.entity_type})"


#: Records the writer accepts, by IGES type number.
WRITABLE = {
    cls.type_number: cls
    for cls in (
        TransformationMatrix, CircularArc, CompositeCurve, Line, ParametricSpline,
        ParametricSplineSurface, SurfaceOfRevolution, BSplineCurve126, BSplineSurface128,
        CurveOnSurface, TrimmedSurface,
    )
}

#: Curve records (may appear inside composites, as generatrices and trimming curves).
CURVE_TYPES = (CircularArc, CompositeCurve, Line, ParametricSpline, BSplineCurve126)
#: Surface records that may carry trimming curves.
SURFACE_TYPES = (ParametricSplineSurface, SurfaceOfRevolution, BSplineSurface128)


def type_number_of(entity: Entity) -> int:
    return entity.entity_type if isinstance(entity, GenericEntity) else entity.type_number


#: Unit flag (Global field 14) and unit name (field 15) by the names ``write_iges`` accepts
#: (IGES 5.3 §2.2.4.3.15, Table 3).
UNITS = {
    "in": (1, "IN"), "inch": (1, "IN"), "mm": (2, "MM"), "ft": (4, "FT"), "mi": (5, "MI"),
    "m": (6, "M"), "km": (7, "KM"), "mil": (8, "MIL"), "um": (9, "UM"), "cm": (10, "CM"),
    "uin": (11, "UIN"),
}
#: Metres per unit, for every key of :data:`UNITS`.
METRES_PER_UNIT = {
    "in": 0.0254, "inch": 0.0254, "mm": 1e-3, "ft": 0.3048, "mi": 1609.344, "m": 1.0, "km": 1e3,
    "mil": 2.54e-5, "um": 1e-6, "cm": 1e-2, "uin": 2.54e-8,
}

#: Unit name for each flag, the inverse of :data:`UNITS` (flag 3: the name in field 15 rules).
UNIT_NAMES = {flag: name for flag, name in UNITS.values()}


@dataclass(frozen=True)
class GlobalSection:
    """The 26 fields of the Global section (IGES 5.3 §2.2.4.3), in order.

    Dates are the 15-character form YYYYMMDD.HHNNSS (fields 18 and 25). Strings are
    plain text (the writer encodes them as Hollerith constants).
    """

    parameter_delimiter: str = ","
    record_delimiter: str = ";"
    product_id: str = ""
    file_name: str = ""
    native_system_id: str = "Bladesmith"
    preprocessor_version: str = "bladesmith.iges 1.0"
    integer_bits: int = 32
    single_max_power: int = 38
    single_digits: int = 6
    double_max_power: int = 308
    double_digits: int = 17
    receiver_product_id: str = ""
    model_scale: float = 1.0
    unit_flag: int = 6
    unit_name: str = "M"
    line_weight_gradations: int = 1
    max_line_weight: float = 0.0
    created: str = ""
    resolution: float = 1e-7
    max_coordinate: float = 0.0
    author: str = ""
    organization: str = ""
    version_flag: int = 11
    drafting_standard: int = 0
    modified: str = ""
    application_protocol: str = ""

    @property
    def units(self) -> str:
        """The unit name in lower case ('m', 'mm', 'in', ...)."""
        return self.unit_name.lower() if self.unit_flag == 3 else UNIT_NAMES.get(self.unit_flag, "?").lower()


#: (attribute, kind) of the Global section fields in file order; kind: s string, i integer, r real.
GLOBAL_FIELDS = (
    ("parameter_delimiter", "s"), ("record_delimiter", "s"), ("product_id", "s"), ("file_name", "s"),
    ("native_system_id", "s"), ("preprocessor_version", "s"), ("integer_bits", "i"),
    ("single_max_power", "i"), ("single_digits", "i"), ("double_max_power", "i"),
    ("double_digits", "i"), ("receiver_product_id", "s"), ("model_scale", "r"), ("unit_flag", "i"),
    ("unit_name", "s"), ("line_weight_gradations", "i"), ("max_line_weight", "r"), ("created", "s"),
    ("resolution", "r"), ("max_coordinate", "r"), ("author", "s"), ("organization", "s"),
    ("version_flag", "i"), ("drafting_standard", "i"), ("modified", "s"), ("application_protocol", "s"),
)
