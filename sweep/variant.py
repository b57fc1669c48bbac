"""One variant of a sweep: its definition written, built, written as IGES and measured.

Plain data in (kind, definition dict, settings dict, key, folders), plain data out (the
metrics row, a dict of numbers and strings), so any Dask worker can run it. Imports only
``geometry/`` and ``iges/``.

The variant's folder ``<sweep>/variants/<key>/`` holds

- ``definition.toml``: the definition used, in the kind's format, file paths made
  relative to the folder (the Blender operators' ``definition=`` path loads it);
- the IGES file(s) (``variant.igs``);
- ``variant.json``: the record, written last: key, parameter values, settings, status,
  the metrics or the error (message, field, type), and each output's size and SHA-256.

Every file is written atomically (temporary file, then ``os.replace``), and the record
last, so a variant killed mid-way leaves no record and is built again on a resume;
:func:`verify` accepts a record only when every file it lists is there with its size and
hash.

Metrics (each row also has ``key``, ``variant``, the parameter values, ``status``,
``error``, ``error_field``, ``error_type``, ``build_time_s`` and ``iges_files``):

- propeller (Hally 2013): ``deviation_inside_m`` and ``deviation_outside_m`` (largest
  distance of the smoothed surfaces from the section-table blade inside and outside the
  smoothing zone, §7), ``tip_irregularity`` and ``tip_irregularity_ratio`` (the smoothing
  report's figure after smoothing and its ratio to before, when the pipeline gives one,
  else NaN: :func:`tip_irregularity`), ``tip_sign_changes`` (curvature sign changes summed over
  the tip surface's iso-curves through the tip cuts, §7: the inflections smoothing must
  not add), ``cuts_tip``/``cuts_leading_edge``/``cuts_trailing_edge``/``cuts_smoothed``,
  ``knots`` and ``control_points`` of the common knot vector (§9), ``shared_edge_gap_m``
  (largest gap between surfaces along their 8 shared edges), ``blade_area_m2`` and
  ``blade_volume_m3`` (:func:`area_and_volume`), ``hub_sector_area_m2`` (§10);
- wind blade (Hosseini & Moetakef-Imani 2016): ``mvs`` and ``strain_energy`` of the two
  mold halves (Eq. 6), ``worst_station_deviation`` (largest closest-point distance of a
  station's points from the skinned surfaces, fraction of its chord), ``control_points``;
- impeller (Casey 1983): ``edge_wall_distance_m`` (:func:`edge_wall_distance`) and
  ``passage_area_m2`` (:func:`outlet_passage_area`).
"""
from __future__ import annotations

import hashlib
import json
import math
import os
import pathlib
import time
import traceback

import numpy as np

from ..geometry.errors import BladesmithError, DefinitionError
from ..geometry.files import atomic_write
from ..geometry.nurbs import BSplineSurface
from .spec import FORMAT_VERSION

DEFINITION_FILE = "definition.toml"
IGES_FILE = "variant.igs"
RECORD_FILE = "variant.json"
VARIANTS_FOLDER = "variants"
#: Gauss–Legendre points per knot span and direction for areas and volumes (cubic
#: surfaces: the integrands are smooth polynomials of modest degree on every span).
QUADRATURE_POINTS = 6
#: Samples per patch of a channel wall for the starting feet of the wall distance.
WALL_SAMPLES_PER_PATCH = 64
#: Samples along each blade edge for the edge-to-wall distance.
EDGE_SAMPLES = 201

PROPELLER_METRICS = ("deviation_inside_m", "deviation_outside_m", "tip_irregularity", "tip_irregularity_ratio",
                     "tip_sign_changes",
                     "cuts_tip", "cuts_leading_edge", "cuts_trailing_edge", "cuts_smoothed", "knots",
                     "control_points", "shared_edge_gap_m", "blade_area_m2", "blade_volume_m3", "hub_sector_area_m2")
WIND_METRICS = ("mvs", "strain_energy", "worst_station_deviation", "control_points")
IMPELLER_METRICS = ("edge_wall_distance_m", "passage_area_m2")
#: Propeller settings that are lengths: fractions of D in the sweep file (as in the operator).
PROPELLER_LENGTHS = ("delta_c", "tip_smoothing_distance", "edge_smoothing_distance", "tolerance")
METRICS = {"propeller": PROPELLER_METRICS, "wind_blade": WIND_METRICS, "impeller": IMPELLER_METRICS}


# -- measures ----------------------------------------------------------------------------
def _gauss(knots: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(count)
    br = np.unique(knots)
    a, h = br[:-1, None], np.diff(br)[:, None]
    return (a + 0.5 * h * (x + 1.0)).ravel(), (0.5 * h * w).ravel()


def area_and_volume(surfaces, points: int = QUADRATURE_POINTS) -> tuple[float, float]:
    """Area and enclosed volume of a blade given by its surfaces with outward normals
    S_u × S_v (Hally 2013 Eq. 1).

    Area: Σ ∫∫ |S_u × S_v| du dv. Volume by the divergence theorem with the field
    F = (0, 0, z) (div F = 1): V = Σ ∫∫ z (S_u × S_v)_z du dv. The blade surfaces are
    open only at the root, whose edge lies on the hub cylinder r = R_hub (the corners
    and side curves start on the blade–hub intersection, §§4–5), and a cap on a
    cylinder has radial normals: F · n = 0 there, so the open root adds
    nothing and V is the volume of the blade from its root section to the tip. Gauss–Legendre
    quadrature per knot span."""
    area = volume = 0.0
    for S in surfaces:
        u, wu = _gauss(S.knots_u, points)
        v, wv = _gauss(S.knots_v, points)
        D = S.derivatives(u[:, None], v[None, :], 1)
        n = np.cross(D[..., 1, 0, :], D[..., 0, 1, :])
        W = wu[:, None] * wv[None, :]
        area += float(np.sum(W * np.linalg.norm(n, axis=-1)))
        volume += float(np.sum(W * D[..., 0, 0, 2] * n[..., 2]))
    return area, volume


def edge_wall_distance(model) -> float:
    """Largest meridional distance (m) of the reference blade's (and splitter's) hub and
    shroud edges (v = 0 and v = 1 of every blade surface, Casey 1983 §2) from the walls of
    the impeller's channel, at EDGE_SAMPLES points per edge: feet by Newton from the
    nearest of WALL_SAMPLES_PER_PATCH samples per wall patch
    (:func:`~bladesmith.geometry.compressor.standardisation.wall_distance`)."""
    from ..geometry.compressor.export import impeller_surfaces
    from ..geometry.compressor.standardisation import wall_distance

    worst = 0.0
    surfaces = [s for name, s in impeller_surfaces(model, blades=1) if name.split()[0] in ("blade", "splitter")]
    for v, which in ((0.0, "hub"), (1.0, "shroud")):
        wall = model.channel.wall(which)
        s_grid = np.linspace(0.0, wall.count, WALL_SAMPLES_PER_PATCH * wall.count + 1)
        W = wall.evaluate(s_grid)
        for S in surfaces:
            u = np.linspace(S.knots_u[S.degree_u], S.knots_u[-S.degree_u - 1], EDGE_SAMPLES)
            X = S.evaluate(u, np.full_like(u, v))
            zr = np.stack([X[:, 2], np.hypot(X[:, 0], X[:, 1])], axis=1)
            nearest = np.argmin(np.linalg.norm(zr[:, None, :] - W[None, :, :], axis=-1), axis=1)
            dist, _ = wall_distance(wall, zr, s_grid[nearest])
            worst = max(worst, float(dist.max()))
    return worst


def outlet_passage_area(model, definition) -> float:
    """The outlet passage area (m²): the cone frustum swept about the axis by the straight
    line from the trailing edge on the hub to the trailing edge on the shroud (the camber
    surface B at its last U, Casey 1983 §2), π (r_h + r_s) L, less the blockage of the
    blades there: Z blades (and Z splitters) of tangential thickness δ(1) (the last
    Bernstein coefficient of δ(m̄), Appendix A3) varying linearly from hub to shroud,
    Z (δ_h + δ_s) L / 2 each."""
    from ..geometry.compressor.export import impeller_surfaces

    camber = dict(impeller_surfaces(model, blades=1, include_camber=True))["blade 1 B"]
    u1 = camber.knots_u[-1]
    P = camber.evaluate(np.array([u1, u1]), np.array([0.0, 1.0]))
    zr = np.stack([P[:, 2], np.hypot(P[:, 0], P[:, 1])], axis=1)
    L = float(np.linalg.norm(zr[1] - zr[0]))
    gross = math.pi * float(zr[0, 1] + zr[1, 1]) * L
    blades = [definition.blade] + ([definition.splitter] if definition.splitter is not None else [])
    blockage = sum(model.count * 0.5 * (b.thickness_hub[-1] + b.thickness_shroud[-1]) * L for b in blades)
    return gross - blockage


def tip_sign_changes(model, blade) -> int:
    """Curvature sign changes summed over the tip surface's iso-curves through the tip
    cuts (Hally 2013 §7; :func:`~bladesmith.geometry.propeller.smoothing.tip_cut_fairness`)."""
    from ..geometry.propeller.smoothing import tip_cut_fairness

    return int(sum(c["sign_changes_surface"] for c in tip_cut_fairness(model.blade, blade.curves, blade.tip)))


def _number_or_nan(value) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        return math.nan
    return out


def tip_irregularity(report: dict) -> tuple[float, float]:
    """(smoothed, smoothed / unsmoothed) from the smoothing report's ``tip_irregularity``
    (a dict with "smoothed" and "ratio", or a plain number); NaN where the pipeline gives
    none."""
    value = report.get("tip_irregularity")
    if isinstance(value, dict):
        return _number_or_nan(value.get("smoothed")), _number_or_nan(value.get("ratio"))
    return _number_or_nan(value), math.nan


# -- definitions -------------------------------------------------------------------------
def _relative(target: pathlib.Path, folder: pathlib.Path) -> str:
    return os.path.relpath(target, folder).replace(os.sep, "/")


def localised_definition(kind: str, definition: dict, base_dir: pathlib.Path, folder: pathlib.Path) -> dict:
    """The definition with its file paths (airfoil files) made relative to ``folder``
    instead of the base definition's folder."""
    out = json.loads(json.dumps(definition))
    if kind == "propeller":
        from ..geometry.propeller.definition import _THICKNESS_FORMS

        sec = out.get("section", {})
        t = sec.get("thickness")
        if isinstance(t, str) and t not in _THICKNESS_FORMS and not pathlib.Path(t).is_absolute():
            sec["thickness"] = _relative(base_dir / t, folder)
    elif kind == "wind_blade":
        from ..geometry.mold.definition import shipped_airfoils

        shipped = shipped_airfoils()
        foils = out.get("stations", {}).get("airfoil", [])
        for i, a in enumerate(foils):
            if isinstance(a, str) and a != "circle" and a not in shipped and not pathlib.Path(a).is_absolute():
                foils[i] = _relative(base_dir / a, folder)
    return out


def definition_text(kind: str, definition: dict, header: str) -> str:
    if kind == "impeller":
        from ..geometry.compressor.definition import dumps_toml

        header = "\n".join("# " + line for line in header.splitlines())  # written as given there
    else:
        from ..geometry.propeller.definition import dumps_toml
    return dumps_toml(definition, header)


# -- building ----------------------------------------------------------------------------
class _SettingsError(DefinitionError):
    pass


def _settings_error(exc: DefinitionError, settings: dict | None = None) -> DefinitionError:
    """A settings error with its field named as in the sweep file (``settings.<name>``);
    for a propeller length the message adds the value as the sweep file gave it (a
    fraction of D; SmoothingSettings counts fractions of R)."""
    name = exc.field or "settings"
    message = str(exc).split(": ", 1)[-1] if exc.field else str(exc)
    if settings is not None and name in PROPELLER_LENGTHS:
        message += f" (a fraction of R; the sweep gave {name} = {settings[name]!r} as a fraction of D)"
    return _SettingsError(message, field=name if name.startswith("settings") else f"settings.{name}")


def _check_units(settings: dict) -> str:
    from ..iges.records import METRES_PER_UNIT, UNITS

    units = settings.get("units", "m")
    if not isinstance(units, str) or units.lower() not in UNITS or units.lower() not in METRES_PER_UNIT:
        raise _SettingsError(f"expected one of {sorted(UNITS)}, got {units!r}", field="settings.units")
    return units.lower()


def build_propeller(path: pathlib.Path, settings: dict, iges_path: pathlib.Path) -> dict:
    from ..geometry.propeller import Propeller, SmoothingSettings, smooth_blade
    from ..geometry.propeller.hub_sector import hub_sector
    from ..iges.propeller import write_propeller_iges
    from .spec import SETTINGS

    definition = Propeller.from_toml(path)
    D, R = definition.diameter, definition.radius
    units = _check_units(settings)
    values = {}
    for name in SETTINGS["propeller"]:
        if name == "units":
            continue
        v = settings[name]
        if name in PROPELLER_LENGTHS:
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise _SettingsError(f"expected a number (fraction of D), got {v!r}", field=f"settings.{name}")
            v = float(v) * D  # fractions of D (the operator's convention) -> metres
        values[name] = v
    try:
        smoothing = SmoothingSettings.from_metres(values, R)
    except DefinitionError as exc:
        raise _settings_error(exc, settings) from None
    model = definition.build()
    blade = smooth_blade(model, smoothing, measure=True)
    sector = hub_sector(model)
    write_propeller_iges(iges_path, model, blade, sector, units=units)
    report = blade.report
    area, volume = area_and_volume(blade.surfaces)
    irregularity, irregularity_ratio = tip_irregularity(report)
    return {
        "deviation_inside_m": report["deviation_m"]["max_inside"],
        "deviation_outside_m": report["deviation_m"]["max_outside"],
        "tip_irregularity": irregularity,
        "tip_irregularity_ratio": irregularity_ratio,
        "tip_sign_changes": tip_sign_changes(model, blade),
        "cuts_tip": report["cuts"]["tip"],
        "cuts_leading_edge": report["cuts"]["leading_edge"],
        "cuts_trailing_edge": report["cuts"]["trailing_edge"],
        "cuts_smoothed": report["cuts"]["smoothed"],
        "knots": report["knots"]["n_knots"],
        "control_points": report["knots"]["n_control"],
        "shared_edge_gap_m": max(e["max_gap"] for e in report["shared_edges"]),
        "blade_area_m2": area,
        "blade_volume_m3": volume,
        "hub_sector_area_m2": float(sector.area),
    }


def build_wind_blade(path: pathlib.Path, settings: dict, iges_path: pathlib.Path) -> dict:
    from ..geometry.mold import build_blade, load_blade
    from ..iges.mold import write_molds

    units = _check_units(settings)
    for name in ("single_surface", "parting_lines"):
        if not isinstance(settings[name], bool):
            raise _SettingsError(f"expected true or false, got {settings[name]!r}", field=f"settings.{name}")
    definition = load_blade(path)
    molds = build_blade(definition, single=settings["single_surface"])
    write_molds(iges_path, molds, units=units, parting_lines=settings["parting_lines"])
    return {
        "mvs": molds.fairness["two_part"]["mvs"],
        "strain_energy": molds.fairness["two_part"]["strain_energy"],
        "worst_station_deviation": max(s.deviation_two_part for s in molds.stations),
        "control_points": molds.control_points,
    }


def build_impeller(path: pathlib.Path, settings: dict, iges_path: pathlib.Path) -> dict:
    from ..geometry.compressor import ImpellerDefinition
    from ..geometry.compressor.export import impeller_surfaces
    from ..iges import surface_from_geometry, write_iges
    from ..iges.records import METRES_PER_UNIT

    units = _check_units(settings)
    definition = ImpellerDefinition.from_toml(path)
    model = definition.build()
    blades = settings["blades"]
    if isinstance(blades, bool) or not isinstance(blades, int) or not 1 <= blades <= model.count:
        raise _SettingsError(f"expected an integer in [1, {model.count}], got {blades!r}", field="settings.blades")
    scale = 1.0 / METRES_PER_UNIT[units]
    surfaces = impeller_surfaces(model, blades=blades)
    write_iges(iges_path, [surface_from_geometry(s, scale=scale) for _, s in surfaces], units=units)
    return {"edge_wall_distance_m": edge_wall_distance(model),
            "passage_area_m2": outlet_passage_area(model, definition)}


BUILDERS = {"propeller": build_propeller, "wind_blade": build_wind_blade, "impeller": build_impeller}


# -- records -----------------------------------------------------------------------------
def file_digest(path: pathlib.Path) -> dict:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return {"size": path.stat().st_size, "sha256": h.hexdigest()}


def read_record(folder: pathlib.Path) -> dict | None:
    try:
        return json.loads((folder / RECORD_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def verify(folder: pathlib.Path, key: str) -> dict | None:
    """The variant's record when it is complete: written for this key and format, and
    every file it lists present with its recorded size and SHA-256; else None."""
    record = read_record(folder)
    if not isinstance(record, dict) or record.get("key") != key or record.get("format") != FORMAT_VERSION:
        return None
    files = record.get("files")
    if not isinstance(files, dict) or DEFINITION_FILE not in files:
        return None
    for name, expected in files.items():
        path = folder / name
        try:
            if path.stat().st_size != expected["size"] or file_digest(path)["sha256"] != expected["sha256"]:
                return None
        except (OSError, KeyError, TypeError):
            return None
    return record


def empty_row(kind: str) -> dict:
    return {name: math.nan for name in METRICS[kind]}


def run_variant(kind: str, key: str, index: int, values: dict, definition: dict, settings: dict,
                base_dir: str, sweep_dir: str) -> dict:
    """Build one variant into ``<sweep_dir>/variants/<key>/`` and return its record (see
    the module docstring). Never raises for a failing variant: a BladesmithError is
    recorded with its message and field; anything else (a bug) with its traceback."""
    start = time.perf_counter()
    folder = pathlib.Path(sweep_dir) / VARIANTS_FOLDER / key
    folder.mkdir(parents=True, exist_ok=True)
    for stale in folder.glob(".*.tmp"):  # left by a run killed mid-write
        stale.unlink(missing_ok=True)
    base = pathlib.Path(base_dir)
    record = {"format": FORMAT_VERSION, "key": key, "kind": kind, "variant": index, "values": values,
              "settings": settings, "status": "ok", "error": "", "error_field": "", "error_type": "",
              "metrics": empty_row(kind), "files": {}}
    definition_path = folder / DEFINITION_FILE
    iges_path = folder / IGES_FILE
    try:
        local = localised_definition(kind, definition, base, folder)
        header = (f"Sweep variant {key} (variant {index} of the design): "
                  + ", ".join(f"{k} = {v!r}" for k, v in values.items()))
        atomic_write(definition_path, definition_text(kind, local, header))
        record["files"][DEFINITION_FILE] = file_digest(definition_path)
        metrics = BUILDERS[kind](definition_path, settings, iges_path)
        record["metrics"].update(metrics)
        record["files"][IGES_FILE] = file_digest(iges_path)
    except BladesmithError as exc:
        record.update(status="failed", error=str(exc), error_field=getattr(exc, "field", None) or "",
                      error_type=type(exc).__name__ if not isinstance(exc, _SettingsError) else "DefinitionError")
    except Exception as exc:  # a bug: recorded, never stops the sweep, shown in the table
        record.update(status="failed", error=f"{type(exc).__name__}: {exc}", error_type=type(exc).__name__,
                      traceback=traceback.format_exc())
    if record["status"] == "failed" and iges_path.exists():
        iges_path.unlink()  # no IGES of a variant that did not finish
    record["build_time_s"] = time.perf_counter() - start
    record["metrics"] = {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in record["metrics"].items()}
    atomic_write(folder / RECORD_FILE, json.dumps(record, indent=1, sort_keys=True))
    return record
