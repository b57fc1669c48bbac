"""``python -m bladesmith.sweep SPEC.toml`` (see :mod:`.cli`)."""
import sys

from .cli import main

sys.exit(main())
