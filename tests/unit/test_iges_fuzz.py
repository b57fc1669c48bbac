"""Fuzz the reader: >= 10,000 seeded random mutations of valid files.

Every outcome must be either a model (whose geometry conversion also only raises the
project's own errors) or an IgesError carrying a line number when the file has lines.
Any other exception is a bug. The whole run stays well under a minute.
"""
from __future__ import annotations

import datetime as dt
import random
import re
import time

import numpy as np

from bladesmith.geometry.errors import BladesmithError, IgesError
from bladesmith.iges import (
    CircularArc,
    CompositeCurve,
    Line,
    TransformationMatrix,
    curve_from_geometry,
    parse_iges,
    surface_from_geometry,
    to_string,
)
from bladesmith.iges.examples import (
    bicubic_spline_114,
    cubic_spline_112,
    random_curve,
    random_surface,
    trimmed_cylinder_band,
    trimmed_plane_with_hole,
)

CASES = 10_000
SEED = 20240517
STAMP = dt.datetime(2024, 5, 17)
_NUMBER = re.compile(r"-?\d+(\.\d*)?(E[+-]\d+)?")


def base_files() -> list[str]:
    rng = np.random.default_rng(1)
    band, _ = trimmed_cylinder_band()
    plane, _ = trimmed_plane_with_hole()
    moved = Line([0, 0, 0], [1, 2, 3], transform=TransformationMatrix(np.eye(3), [1.0, 2.0, 3.0]))
    models = [
        [band],
        [plane],
        [surface_from_geometry(random_surface(rng, shape=(4, 4), degrees=(2, 3)))],
        [curve_from_geometry(random_curve(rng, n_control=5)), CircularArc([0, 0], [1, 0], [0, 1])],
        [cubic_spline_112(rng, 2), bicubic_spline_114(rng, (0.0, 1.0), (0.0, 0.5, 1.0)), moved],
        [CompositeCurve([Line([0, 0, 0], [1, 0, 0]), Line([1, 0, 0], [1, 1, 0])])],
    ]
    return [to_string(m, timestamp=STAMP, author="fuzz, the; author") for m in models]


def mutate(text: str, r: random.Random) -> str:
    lines = text.split("\n")
    for _ in range(r.choice((1, 1, 1, 2, 3))):
        kind = r.randrange(12)
        if not lines:
            lines = [""]
        k = r.randrange(len(lines))
        line = lines[k]
        if kind == 0 and line:  # flip one character to any byte
            i = r.randrange(len(line))
            lines[k] = line[:i] + chr(r.randrange(256)) + line[i + 1 :]
        elif kind == 1 and line:  # flip to a character that matters
            i = r.randrange(len(line))
            lines[k] = line[:i] + r.choice(",;H.-+E D0123456789P ") + line[i + 1 :]
        elif kind == 2:  # truncate the file
            flat = "\n".join(lines)
            flat = flat[: r.randrange(len(flat) + 1)]
            lines = flat.split("\n")
        elif kind == 3 and len(lines) > 1:  # delete a line
            del lines[k]
        elif kind == 4:  # duplicate a line
            lines.insert(k, line)
        elif kind == 5 and len(lines) > 1:  # swap two lines
            j = r.randrange(len(lines))
            lines[k], lines[j] = lines[j], lines[k]
        elif kind in (6, 7):  # replace a number with an absurd or broken one
            nums = list(_NUMBER.finditer(line[:72]))
            if nums:
                m = r.choice(nums)
                new = r.choice(["999999999", "-1", "0", "2147483648", "1.E999", "-0.0", "1.5", "3", "7",
                                "1" * 30, "", "1H", "9H,,,,", "nan", "1D2", "4", "41", "99999"])
                lines[k] = line[: m.start()] + new + line[m.end() :]
        elif kind == 8 and len(line) >= 72:  # break a Directory Entry field or a back-pointer
            start = r.choice((0, 8, 24, 48, 64, 65))
            field = str(r.choice([0, 1, 2, 3, 5, 7, 9, 99, 100001, -3, 41]))
            lines[k] = line[:start] + field.rjust(8)[:8] + line[start + 8 :]
        elif kind == 9:  # shift the columns
            i = r.randrange(len(line) + 1)
            lines[k] = line[:i] + r.choice(" ,0") + line[i:] if r.random() < 0.5 else line[:i] + line[i + 1 :]
        elif kind == 10:  # a pointer to another entity (possibly itself or a non-entity line)
            m = re.match(r"(\d+),", line)
            if m and line[72:73] == "P":
                lines[k] = re.sub(r",(\d+),", lambda _: f",{r.randrange(1, 45)},", line, count=1)
        else:  # garbage appended or line endings changed
            if r.random() < 0.5:
                lines.append("".join(chr(r.randrange(32, 127)) for _ in range(r.randrange(90))))
            else:
                return "\r\n".join(lines)
    return "\n".join(lines)


def test_fuzz_reader_only_raises_iges_errors():
    r = random.Random(SEED)
    bases = base_files()
    for b in bases:  # the unmutated files are valid
        parse_iges(b).to_geometry()
    outcomes = {"parsed": 0, "refused": 0}
    t0 = time.perf_counter()
    for case in range(CASES):
        data = mutate(r.choice(bases), r)
        if r.random() < 0.3:
            data = data.encode("latin-1")
        try:
            model = parse_iges(data)
        except IgesError as exc:
            outcomes["refused"] += 1
            assert exc.line is not None or "empty" in str(exc), (case, str(exc))
            assert str(exc)
            continue
        except Exception as exc:  # pragma: no cover - the failure we are looking for
            raise AssertionError(f"case {case}: foreign exception {type(exc).__name__}: {exc}\n{data!r}") from exc
        outcomes["parsed"] += 1
        try:
            model.to_geometry()
        except BladesmithError:
            pass
        except Exception as exc:  # pragma: no cover
            raise AssertionError(f"case {case}: to_geometry raised {type(exc).__name__}: {exc}\n{data!r}") from exc
    elapsed = time.perf_counter() - t0
    print(f"fuzz: {CASES} mutated files in {elapsed:.1f} s: {outcomes}")
    assert sum(outcomes.values()) == CASES >= 10_000
    assert outcomes["refused"] > CASES // 2  # the mutations do break files
    assert outcomes["parsed"] > 100  # and some survive (e.g. changed values): conversion exercised
