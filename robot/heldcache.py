"""What a loader of robot models keeps: :class:`HeldCache`, the models it made by key, the
most recently used ones held here and every other one for as long as something else holds it.

A program model is found by its robot's identity (interp/runtime/model.py ``load_model``), so a
loader must give the same robot the same object while a model built on it lives. Cleared past
16 entries as they were before, robot/mada.py ``load_mada``'s models were made again while the
checked workspace and its models stayed cached: a worker of the suite that had read more than
16 machine data files since built the corpus backups' program models a second time near the
run's end (tests/vm/test_differential.py: ChinaMilling twice, kukaKRLmagic once in a whole make
test of 8b21b73, 2026-11-28, tests/cpu_profile.py). With weak references a model is made again
only when nothing holds the one made before (a program model on it went with its workspace).
"""

from __future__ import annotations

import weakref
from collections import OrderedDict


class HeldCache:
    """Values by key: the `recent` most recently used held here (strong references), any other
    one found while something else holds it (a weak reference: the values must support them,
    as a dataclass without slots does). Not thread-safe (as the dictionaries it replaces)."""

    def __init__(self, recent: int) -> None:
        self.recent = recent
        self._strong: OrderedDict = OrderedDict()
        self._weak: weakref.WeakValueDictionary = weakref.WeakValueDictionary()

    def get(self, key):
        """The value kept for `key` (now the most recently used), else None."""
        value = self._strong.get(key)
        if value is None:
            value = self._weak.get(key)
            if value is None:
                return None
            self._strong[key] = value
            self._trim()
        self._strong.move_to_end(key)
        return value

    def put(self, key, value) -> None:
        """Keep `value` for `key` (the most recently used)."""
        self._strong[key] = value
        self._strong.move_to_end(key)
        self._weak[key] = value
        self._trim()

    def __len__(self) -> int:
        """How many values are found now (held here or elsewhere)."""
        return len(self._weak)

    def clear(self) -> None:
        self._strong.clear()
        self._weak.clear()

    def _trim(self) -> None:
        while len(self._strong) > self.recent:
            self._strong.popitem(last=False)


__all__ = ["HeldCache"]
