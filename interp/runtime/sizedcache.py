"""A process's cache of loaded programs bounded by their estimated memory: :class:`SizedCache`,
a segmented LRU (issue 87: "make test and the variants sweep load each backup's model once").

Segmented LRU (Karedla, Love and Wherry, "Caching strategies to improve disk system
performance", IEEE Computer 27(3), 1994): a new entry goes to the *probationary* segment; an
entry asked for again moves to the *protected* segment, which holds at most
:data:`PROTECTED_SHARE` of the budget (its least recently used entry goes back to probation past
it). Past the budget the least recently used probationary entry goes first, then the protected
ones. A stream of programs loaded once (a test's own folder, a sweep's variant) therefore passes
through probation without evicting the backups and conformance cases that many runs load: with
the plain LRU of 8 entries before, the palletizer backup's checked workspace was loaded up to 4
times by one worker of the suite, conformance case 001's up to 10 times (tests/cpu_profile.py).

An entry asked for again while it is the last one asked for or put (the runs of one program one
after the other: a conformance case on both interpreters, a sweep's three runs) is *correlated*,
not reused, and stays in probation (the "correlated reference period" of O'Neil, O'Neil and
Weikum's LRU-K, SIGMOD 1993, and of Johnson and Shasha's 2Q, VLDB 1994, at its shortest): promoted
on such asks, every conformance case a worker ran (on both interpreters) filled the protected
segment, and a backup loaded by a test after them (the palletizer, 25 MB charged) left the
probationary rest before the next test asked for it (tests/cpu_profile.py on a sequence of test
files as one worker runs them, 2026-11-28: the palletizer's workspace loaded by
tests/net/test_cell_corpus_partner.py and again by tests/conformance/test_real.py; once since).
"""

from __future__ import annotations

from collections import OrderedDict

#: the share of the budget the protected segment may hold (SLRU's usual split)
PROTECTED_SHARE = 0.8


class SizedCache:
    """Values by key, each with its estimated cost in bytes, the total kept at most `budget`
    bytes (module docstring; an entry costing more than the budget is kept alone until the next
    one comes). Not thread-safe: its callers hold a lock (interp/runtime/model.py ``_LOCK``)
    or run in one thread."""

    def __init__(self, budget: int) -> None:
        self.budget = budget
        self._probation: OrderedDict = OrderedDict()    # key -> (value, cost)
        self._protected: OrderedDict = OrderedDict()
        self._used = [0, 0]                             # bytes held: probation, protected
        self._last = None                               # the key last asked for or put

    def __len__(self) -> int:
        return len(self._probation) + len(self._protected)

    def keys(self) -> list:
        """The keys held, probationary first, each segment least recently used first."""
        return [*self._probation, *self._protected]

    @property
    def used(self) -> int:
        """The estimated bytes held."""
        return self._used[0] + self._used[1]

    def get(self, key):
        """The value kept for `key` (now the most recently used; protected unless it was the
        last key asked for or put: module docstring), else None."""
        last, self._last = self._last, key
        got = self._protected.get(key)
        if got is not None:
            self._protected.move_to_end(key)
            return got[0]
        if key == last and key in self._probation:      # a correlated ask: stays on probation
            self._probation.move_to_end(key)
            return self._probation[key][0]
        got = self._probation.pop(key, None)
        if got is None:
            return None
        self._used[0] -= got[1]
        self._protected[key] = got
        self._used[1] += got[1]
        while self._used[1] > self.budget * PROTECTED_SHARE and len(self._protected) > 1:
            k, old = self._protected.popitem(last=False)
            self._used[1] -= old[1]
            self._probation[k] = old
            self._used[0] += old[1]
        self._trim()
        return got[0]

    def put(self, key, value, cost: int) -> None:
        """Keep `value` for `key` at `cost` estimated bytes (a probationary entry), evicting
        past the budget (module docstring)."""
        self.drop(key)
        self._last = key
        self._probation[key] = (value, cost)
        self._used[0] += cost
        self._trim(keep=key)

    def recost(self, key, cost: int) -> None:
        """Charge `key`, when held, `cost` estimated bytes in place of its charge so far (a
        workspace's models built after it was put: interp/runtime/program.py ``charge_models``),
        in its place in its segment, evicting past the budget as :meth:`put` does (never `key`
        itself); nothing when it is not held."""
        for i, seg in enumerate((self._probation, self._protected)):
            got = seg.get(key)
            if got is not None:
                seg[key] = (got[0], cost)
                self._used[i] += cost - got[1]
                self._trim(keep=key)
                return

    def drop(self, key) -> None:
        """Forget `key` (nothing when it is not held)."""
        for i, seg in enumerate((self._probation, self._protected)):
            got = seg.pop(key, None)
            if got is not None:
                self._used[i] -= got[1]

    def clear(self) -> None:
        self._probation.clear()
        self._protected.clear()
        self._used = [0, 0]
        self._last = None

    def _trim(self, keep=None) -> None:
        for i, seg in enumerate((self._probation, self._protected)):
            while self.used > self.budget:
                k = next((k for k in seg if k != keep), None)   # the least recent but `keep`
                if k is None:
                    break
                self._used[i] -= seg.pop(k)[1]


__all__ = ["PROTECTED_SHARE", "SizedCache"]
