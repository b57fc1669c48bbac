"""Progress reporting shared by the operators (ARCHITECTURE.md, house style 7)."""
from __future__ import annotations


def progress_callback(wm):
    """``window_manager.progress_update`` as the plain callback ``geometry/`` takes:
    ``progress(fraction)`` or ``progress(stage, fraction)``, fraction in [0, 1]. The
    operator calls ``progress_begin(0, 100)`` before and ``progress_end()`` in ``finally``."""

    def update(*args) -> None:
        fraction = float(args[-1]) if args else 0.0
        wm.progress_update(int(100 * min(max(fraction, 0.0), 1.0)))

    return update

