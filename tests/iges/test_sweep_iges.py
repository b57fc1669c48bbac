"""A sweep variant's IGES (issue 23), here a propeller written in millimetres, is read by
OpenCASCADE with zero fail and warning messages, as five blade faces and the hub sector,
and gmsh imports it without an error or warning."""
import pathlib
import textwrap

import pytest

pytest.importorskip("OCP")

from occ_support import read_with_occ  # noqa: E402

from bladesmith.sweep.spec import load_spec  # noqa: E402
from bladesmith.sweep.variant import run_variant  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_propeller_variant_iges_reads_cleanly(tmp_path):
    spec_path = tmp_path / "sweep.toml"
    spec_path.write_text(textwrap.dedent(f"""
        base = "{ROOT / 'data' / 'propellers' / 'skewed_demo.toml'}"
        output = "out"
        [settings]
        delta_c = 0.04
        tolerance = 1e-4
        filter_iterations = 10
        units = "mm"
        [parameters]
        skew_scale = {{ field = "radial.skew_deg", action = "scale", values = [1.3] }}
        [design]
        type = "grid"
        """))
    spec = load_spec(spec_path)
    (v,) = spec.variants()
    record = run_variant("propeller", v.key, 0, v.values, v.definition, v.settings, str(spec.base.parent),
                         str(spec.output))
    assert record["status"] == "ok", record["error"]
    res = read_with_occ(spec.output / "variants" / v.key / "variant.igs")
    assert res.load_messages == [] and res.transfer_messages == []
    assert len(res.faces) == 6

    gmsh = pytest.importorskip("gmsh")
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.logger.start()
        gmsh.model.occ.importShapes(str(spec.output / "variants" / v.key / "variant.igs"))
        gmsh.model.occ.synchronize()
        assert len(gmsh.model.getEntities(2)) == 6
        # meshing the same writer's propellers is tests/iges/test_propeller_iges.py's (minutes
        # at a CFD user's sizing); here the import alone
        complaints = [line for line in gmsh.logger.get() if line.startswith(("Error", "Warning"))]
        assert complaints == []
    finally:
        gmsh.logger.stop()
        gmsh.finalize()
