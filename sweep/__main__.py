"""``python -m bladesmith.sweep SPEC.toml`` where Bladesmith is importable as a package
(from a checkout: ``python scripts/sweep.py SPEC.toml``; see :mod:`.cli`)."""
import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
