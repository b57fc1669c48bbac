"""The reader: malformed files raise IgesError with a line number and a reason."""
from __future__ import annotations

import datetime as dt

import numpy as np
import pytest

from bladesmith.geometry.errors import IgesError
from bladesmith.iges import (
    BSplineCurve126,
    CompositeCurve,
    GenericEntity,
    Line,
    parse_iges,
    read_iges,
    to_string,
)
from bladesmith.iges.examples import trimmed_cylinder_band

STAMP = dt.datetime(2024, 1, 2, 3, 4, 5)


@pytest.fixture(scope="module")
def band_text():
    return to_string([trimmed_cylinder_band()[0]], timestamp=STAMP)


def lines_of(text):
    return text.split("\n")[:-1]


def join(lines):
    return "\n".join(lines) + "\n"


def first_line(lines, code):
    return next(i for i, ln in enumerate(lines) if ln[72] == code)


def edit_p(text, old, new):
    """Replace the first ``old`` in a Parameter Data line, keeping the 80-column layout."""
    lines = lines_of(text)
    k = next(i for i, ln in enumerate(lines) if ln[72] == "P" and old in ln[:64])
    data = lines[k][:64].rstrip().replace(old, new, 1)
    assert len(data) <= 64
    return join(lines[:k] + [data.ljust(64) + lines[k][64:]] + lines[k + 1 :])


def tampered(entities, old, new):
    """The file of ``entities`` with ``old`` replaced in the parameter data before line packing."""
    from bladesmith.iges import writer

    real = writer._pd

    def fake(entity, de, resolution):
        return real(entity, de, resolution).replace(old, new, 1)

    writer._pd = fake
    try:
        return to_string(entities, timestamp=STAMP)
    finally:
        writer._pd = real


def fails(text, match, line=None):
    with pytest.raises(IgesError, match=match) as info:
        parse_iges(text)
    if line is not None:
        assert info.value.line == line, str(info.value)
    else:
        assert info.value.line is not None, str(info.value)
    return info.value


def test_truncated(band_text):
    lines = lines_of(band_text)
    fails(join(lines[:-1]), r"Terminate")
    fails(join(lines[: len(lines) // 2]), r"Terminate")
    fails(band_text[: len(band_text) // 3], r"80 columns|Terminate")
    with pytest.raises(IgesError, match="empty"):
        parse_iges("")


def test_wrong_column_layout(band_text):
    lines = lines_of(band_text)
    k = first_line(lines, "D") + 2
    fails(join(lines[:k] + [" " + lines[k]] + lines[k + 1 :]), r"expected 80 columns, got 81", line=k + 1)
    fails(join(lines[:k] + [lines[k][:70]] + lines[k + 1 :]), r"expected 80 columns", line=k + 1)
    shifted = lines[k][1:73] + " " + lines[k][73:]
    fails(join(lines[:k] + [shifted] + lines[k + 1 :]), r"column 73|sequence|Directory Entry", line=None)
    fails(join(lines[:k] + [lines[k][:73] + "0000099"] + lines[k + 1 :]), r"sequence number", line=k + 1)


def test_section_order_and_counts(band_text):
    lines = lines_of(band_text)
    d = first_line(lines, "D")
    p = first_line(lines, "P")
    swapped = lines[:d] + lines[p : p + 1] + lines[d:p] + lines[p + 1 :]
    fails(join(swapped), r"section D after section P|sequence number")
    t = lines[-1]
    fails(join(lines[:-1] + ["S      1G      3D     99" + t[24:]]), r"Terminate section", line=len(lines))


def test_bad_numbers(band_text):
    lines = lines_of(band_text)
    p = first_line(lines, "P")
    bad = lines[p].replace("0.0", "0.x", 1)
    e = fails(join(lines[:p] + [bad] + lines[p + 1 :]), r"expected a finite real number", line=p + 1)
    assert "parameter" in str(e)
    fails(edit_p(band_text, "0.0,0.0,0.0,0.0,0.0,1.0", "0.0,0.0,0.0,0.0,1.E999,1.0"), r"finite real", line=p + 1)
    d = first_line(lines, "D")
    fails(join(lines[:d] + ["     11X" + lines[d][8:]] + lines[d + 1 :]), r"Directory Entry field 1", line=d + 1)


def test_dangling_pointers(band_text):
    lines = lines_of(band_text)
    # the 144 record: "144,5,1,1,17,21;" -> outer boundary pointer to DE 99
    k = next(i for i, ln in enumerate(lines) if ln.startswith("144,"))
    fields = lines[k][:64].rstrip().rstrip(";").split(",")
    fields[4] = "99"
    rec = ",".join(fields) + ";"
    fails(join(lines[:k] + [f"{rec:<64}" + lines[k][64:]] + lines[k + 1 :]), r"dangling pointer 99", line=k + 1)
    fields[4] = "4"  # even: not the first line of a DE pair
    rec = ",".join(fields) + ";"
    fails(join(lines[:k] + [f"{rec:<64}" + lines[k][64:]] + lines[k + 1 :]), r"dangling pointer 4")
    d = first_line(lines, "D")
    fails(join(lines[:d] + [lines[d][:8] + "    9999" + lines[d][16:]] + lines[d + 1 :]),
          r"outside the Parameter Data section", line=d + 1)
    p = first_line(lines, "P")
    fails(join(lines[:p] + [lines[p][:65] + "      9" + lines[p][72:]] + lines[p + 1 :]), r"points back to DE",
          line=p + 1)


def test_absurd_counts():
    c = BSplineCurve126(2, [0, 0, 0, 0.5, 1, 1, 1], np.arange(12.0).reshape(4, 3))
    fails(tampered([c], "126,3,2,", "126,999999999,2,"), r"K = 999999999")
    fails(tampered([c], "126,3,2,", "126,3,99999,"), r"M \(degree\) = 99999 is outside")
    fails(tampered([c], "126,3,2,", "126,-3,2,"), r"outside 0")
    comp = CompositeCurve([Line([0, 0, 0], [1, 0, 0]), Line([1, 0, 0], [1, 1, 0])])
    fails(tampered([comp], "102,2,", "102,2000000000,"), r"N \(number of curves\) = 2000000000 needs")


def test_recursive_references():
    comp = CompositeCurve([Line([0, 0, 0], [1, 0, 0]), Line([1, 0, 0], [1, 1, 0])])
    # the composite is DE 5; make it contain itself
    e = fails(tampered([comp], "102,2,1,3;", "102,2,1,5;"), r"recursive reference")
    assert e.line is not None
    # a trimmed surface whose boundary's surface is the trimmed surface itself
    band, _ = trimmed_cylinder_band()
    fails(tampered([band], "142,0,5,", "142,0,41,"), r"recursive reference")


def test_type_mismatch_and_wrong_kinds(band_text):
    lines = lines_of(band_text)
    k = next(i for i, ln in enumerate(lines) if ln.startswith("144,"))
    rec = "144,1,1,1,17,21;"  # surface pointer to the axis line
    fails(join(lines[:k] + [f"{rec:<64}" + lines[k][64:]] + lines[k + 1 :]), r"surface must be one of")


def test_unsupported_entities_are_read_generically(band_text):
    lines = lines_of(band_text)
    d = first_line(lines, "D")
    p = first_line(lines, "P")
    # turn the axis line (DE 1) into a type 116 point: 116 is not modelled
    new_d = [lines[d].replace("     110", "     116", 1), lines[d + 1].replace("     110", "     116", 1)]
    new_p = lines[p].replace("110,", "116,", 1)
    text = join(lines[:d] + new_d + lines[d + 2 : p] + [new_p] + lines[p + 1 :])
    with pytest.raises(IgesError, match=r"axis must be one of"):
        parse_iges(text)
    # and on its own a 116 is just a generic record
    lone = to_string([Line([0, 0, 0], [1, 2, 3])], timestamp=STAMP)
    lone = lone.replace("     110", "     116").replace("110,", "116,", 1)
    model = parse_iges(lone)
    assert isinstance(model.entities[0], GenericEntity) and model.entities[0].parameters[:2] == ("0.0", "0.0")


def test_hollerith_and_delimiters(band_text):
    lines = lines_of(band_text)
    g = first_line(lines, "G")
    fails(join(lines[:g] + ["99H" + lines[g][3:]] + lines[g + 1 :]), r"Global section|Hollerith", line=None)
    fails(join(lines[:g] + ["1H,;1H" + lines[g][6:]] + lines[g + 1 :]), r"Global section")


def test_other_delimiters_and_defaults_are_accepted():
    text = to_string([Line([0, 0, 0], [1, 2, 3])], timestamp=STAMP)
    lines = lines_of(text)
    g = [ln for ln in lines if ln[72] == "G"]
    body = "".join(ln[:72] for ln in g)
    body = body.replace("1H,,1H;,", "1H/,1H#/", 1).replace(",", "/").replace(";", "#")
    new_g = [f"{body[i:i + 72]:<72}G{k + 1:07d}" for k, i in enumerate(range(0, len(body), 72))]
    p = [ln for ln in lines if ln[72] == "P"]
    new_p = [ln[:64].replace(",", "/").replace(";", "#") + ln[64:] for ln in p]
    t = lines[-1]
    t = t[:8] + f"G{len(new_g):7d}" + t[16:]
    rest = [ln for ln in lines if ln[72] in "SD"]
    text2 = join([rest[0]] + new_g + rest[1:] + new_p + [t])
    m = parse_iges(text2)
    assert m.header.parameter_delimiter == "/" and np.array_equal(m.entities[0].end, [1, 2, 3])


def test_crlf_line_endings(band_text):
    m = parse_iges(band_text.replace("\n", "\r\n").encode("ascii"))
    assert len(m.entities) == len(parse_iges(band_text).entities) == 21


def test_read_iges_reports_the_path(tmp_path):
    path = tmp_path / "bad.igs"
    path.write_text("garbage\n")
    with pytest.raises(IgesError, match=r"bad\.igs, line 1: expected 80 columns"):
        read_iges(path)
    with pytest.raises(IgesError, match="cannot read"):
        read_iges(tmp_path / "missing.igs")
