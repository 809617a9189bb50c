"""Values a parked pass changes and changes back within the pass (issue 76; docs/architecture.md
"Transients": ``gIActSpeed = 0``, then ``gIActSpeed = gDISpindleActSpeed * 10``): such a pass is a
spin when each such variable is back at its start value at the pass's end. :class:`Transients`
keeps, for each (a plain slot: ``period.plain``; any other, and the pass is not parked), its value
at the pass's start and at each step where it changes; parked, the step the task would stand at
is put in place each IPO cycle (:meth:`Transients.put_at`), and before a catch-up the start."""

from __future__ import annotations

from .idle import freeze
from .period import place_of, plain, put
from .values import copy_value


class Transients:
    """During a recording: the places the pass changed (``refs``: place -> reference), their
    values before their first write in the second pass (``start``) and the changes of the second
    pass (``changes``: (step index, place, value)). After it (:meth:`seal`): ``order`` (the
    places), ``steps`` (per step, the values in that order, shared between equal steps)."""

    __slots__ = ("refs", "start", "changes", "order", "steps")

    def __init__(self) -> None:
        self.refs: dict = {}
        self.start: dict = {}
        self.changes: list = []
        self.order: tuple = ()
        self.steps: list = []

    def first_write(self, ref) -> None:
        """`ref` is about to be written in the second pass: its value there, if its first."""
        key = place_of(ref)
        if key not in self.start:
            self.start[key] = copy_value(ref.peek())
            self.refs.setdefault(key, None)

    def changed(self, ref, index: int) -> bool:
        """A write changed `ref`, checked at step `index` of the pass (-1: the first pass): noted,
        True; False when it cannot be put back (not a plain slot: the pass is no spin)."""
        if not plain(ref):
            return False
        key = place_of(ref)
        self.refs[key] = ref
        if index >= 0:
            self.changes.append((index, key, copy_value(ref.peek())))
        return True

    def seal(self, n: int) -> bool:
        """The second pass of `n` steps ended: True when every changed variable is back at its
        start value (the pass repeats); the per-step values are built."""
        keys = tuple(k for k, r in self.refs.items() if r is not None)
        for k in keys:
            if k not in self.start or freeze(self.refs[k].peek()) != freeze(self.start[k]):
                return False
        self.order = keys
        cur = {k: self.start[k] for k in keys}
        at = {}
        for index, key, value in self.changes:
            at.setdefault(index, []).append((key, value))
        row = tuple(cur[k] for k in keys)
        steps = []
        for j in range(n):
            for key, value in at.get(j, ()):
                cur[key] = value
                row = None
            if row is None:
                row = tuple(cur[k] for k in keys)
            steps.append(row)
        self.steps = steps
        return True

    def put_at(self, j: int, cyclic_watch) -> None:
        """Put the values of step `j` in place (j = 0: the pass's start); a change moves
        `cyclic_watch`'s version (watch.py CyclicWatch)."""
        changed = False
        row = self.steps[j]
        for key, value in zip(self.order, row):
            ref = self.refs[key]
            if freeze(ref.peek()) != freeze(value):
                put(ref, value)
                changed = True
        if changed:
            cyclic_watch.version += 1
