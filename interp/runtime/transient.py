"""Values a parked pass changes and changes back (issue 76, "One general fast-forward"): the state
of a spin at each step of its pass.

A spin (interp/runtime/spin.py) is a pass whose reads are unchanged, so it writes what it wrote
before, also when it writes a variable twice with different values (``gIActSpeed = 0`` when the
spindle is off, then ``gIActSpeed = gDISpindleActSpeed * 10``: ChinaMilling's
``R2M_ChkSpindleSpeed``; docs/architecture.md "Transients" has the case and its figures): such a
pass is a spin when the values of the variables it changes are, at the end of
the pass, what they were at its start: the pass starts every time from the same state. Only the
state *within* the pass differs from step to step, and that is what other parts of the run read
while the task is parked (the end of its time slice: the idle watch, the automatic cell, a waiting
task's condition, a cyclic flag; a statement of another task wakes a parked pass first). So
:class:`Transients` keeps, for each such variable (a plain slot: ``period.plain``; any other, and
the pass is not parked), its value at the start of the pass and at each step where it changes;
parked, the task's state is put in place at the step it would stand at
(:meth:`Transients.put_at`, each IPO cycle), and before a catch-up at the pass's start. A change
moves the cyclic watch's version, as a statement's write would (the cyclic flags, the interrupt
conditions, the scheduler's steady cycles, which a pass with transients never takes).
"""

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
