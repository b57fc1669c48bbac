"""Make tests/iges/occ_support.py importable by the third-party reader tests."""
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
