"""What people expect of a project (issue 14): a LICENSE that matches the manifest and
full citations of the four papers in the README."""
import pathlib
import tomllib

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_license_file_matches_the_manifest():
    manifest = tomllib.loads((ROOT / "blender_manifest.toml").read_text(encoding="utf-8"))
    assert manifest["license"] == ["SPDX:GPL-3.0-or-later"]
    text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert "GNU GENERAL PUBLIC LICENSE" in text[:200] and "Version 3, 29 June 2007" in text[:200]
    assert "(at your option) any later version" in text


def test_readme_cites_the_four_papers_in_full():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    references = readme[readme.index("## References"):]
    for needed in ("DRDC Atlantic TM 2013-178", "Journal of Engineering for Power", "AFM 93-08",
                   "Journal of Mechanics", "Hally", "Casey", "Hvid", "Hosseini", "Moetakef-Imani"):
        assert needed in references, needed
