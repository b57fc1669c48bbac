"""A small bounded memory of built pieces of an impeller, keyed by the values they were
built from, so that a panel edit rebuilds only what it changes (issue 18/22: a blade-count
edit leaves the blade; an end-rounding edit leaves B, S and P; a splitter edit leaves the
main blade; a tolerance edit revisits patch counts it has built before).

Keys are tuples of plain values (the definition's numbers as written, the ``repr`` of its
tables), so a hit means "built from the same numbers"; the one exception, the
standardisation, is keyed by the ids of the blades and the channel it trims with, which
its kept value holds alive (so the ids cannot be reused while the key exists). The pieces
kept are immutable model objects, shared by every model built from them. Failures are not
kept: a refused value is refused again. The keys hold the definition's values only, not
module constants: code (a test) that changes a constant of :mod:`.blade` or
:mod:`.channel` and rebuilds must call ``MEMORY.clear()`` (or build a definition with
``memoise=False``).
"""
from __future__ import annotations

from collections import OrderedDict

#: Pieces kept (least recently used dropped first); a high_flow blade at 65 patches and
#: its caps take about 0.5 MB.
MAX_ENTRIES = 96


class BuildMemory:
    """Least-recently-used map from value keys to built pieces."""

    def __init__(self, max_entries: int = MAX_ENTRIES):
        self.max_entries = int(max_entries)
        self._items: OrderedDict = OrderedDict()
        self.hits = 0
        self.misses = 0

    def get(self, key, build):
        """The piece kept under ``key``, or ``build()`` kept under it."""
        try:
            value = self._items[key]
        except KeyError:
            self.misses += 1
            value = build()
            self._items[key] = value
            if len(self._items) > self.max_entries:
                self._items.popitem(last=False)
            return value
        self.hits += 1
        self._items.move_to_end(key)
        return value

    def clear(self) -> None:
        self._items.clear()
        self.hits = self.misses = 0

    def __len__(self) -> int:
        return len(self._items)


#: The memory :meth:`.definition.ImpellerDefinition.build` uses.
MEMORY = BuildMemory()
