"""The impeller build memory (geometry/compressor/memo.py, issue 18 panel speed): an edit
rebuilds only what it changes, and what it keeps is what a full rebuild would give, to the
last bit, for every setting the panel edits (a key that missed a value would fail here)."""
import dataclasses
import pathlib

import numpy as np
import pytest

from bladesmith.geometry.compressor import ImpellerDefinition
from bladesmith.geometry.compressor.export import impeller_surfaces
from bladesmith.geometry.compressor.memo import MEMORY

PRESETS = pathlib.Path(__file__).resolve().parents[2] / "data" / "impellers"


def edited(d: ImpellerDefinition, section: str, **changes) -> ImpellerDefinition:
    return dataclasses.replace(d, **{section: dataclasses.replace(getattr(d, section), **changes)})


def surfaces(d: ImpellerDefinition):
    return impeller_surfaces(d.build(), 1, include_camber=True)


EDITS = [
    ("blade", {"count": 14}), ("blade", {"leading_edge_ratio": 2.5}), ("blade", {"trailing_edge_ratio": 2.0}),
    ("blade", {"tolerance": 2e-6}), ("blade", {"patches": 70}), ("blade", {"patch_spacing": "blade"}),
    ("blade", {"thickness_hub": (0.004, 0.003, 0.002)}), ("blade", {"beta_hub": (-30.0, -20.0, -25.0, -35.0)}),
    ("splitter", {"pitch_fraction": 0.4}), ("splitter", {"leading_edge_hub": 2.2}),
]


@pytest.mark.parametrize("section, changes", EDITS, ids=[next(iter(c)) + "@" + s for s, c in EDITS])
def test_memory_gives_what_a_full_rebuild_gives(section, changes):
    base = ImpellerDefinition.from_toml(PRESETS / "intermediate_flow.toml")
    surfaces(base)  # the memory now holds the master's pieces
    d = edited(base, section, **changes)
    kept = surfaces(d)
    full = surfaces(dataclasses.replace(d, memoise=False))
    assert [name for name, _ in kept] == [name for name, _ in full]
    for (name, a), (_, b) in zip(kept, full):
        assert np.array_equal(a.control_points, b.control_points) and np.array_equal(a.knots_u, b.knots_u), name


def test_element_type_edit_matches_a_full_rebuild():
    """low_flow's axial elements turned to arbitrary ones and back (element type)."""
    base = ImpellerDefinition.from_toml(PRESETS / "low_flow.toml")
    surfaces(base)
    d = edited(base, "blade", elements="arbitrary")
    for variant in (d, base):
        kept, full = surfaces(variant), surfaces(dataclasses.replace(variant, memoise=False))
        assert all(np.array_equal(a.control_points, b.control_points) for (_, a), (_, b) in zip(kept, full))


def test_an_edit_keeps_what_it_does_not_change():
    MEMORY.clear()
    d = ImpellerDefinition.from_toml(PRESETS / "high_flow.toml")
    first = d.build()
    assert d.build().blade is first.blade  # the same values: the same pieces
    recount = edited(d, "blade", count=14).build()
    assert recount.blade is first.blade and recount.channel is first.channel
    rounded = edited(d, "blade", trailing_edge_ratio=2.0).build()
    assert rounded.blade is not first.blade and rounded.blade.camber is first.blade.camber  # B, S, P kept
    assert rounded.blade.trailing_edge is not first.blade.trailing_edge
