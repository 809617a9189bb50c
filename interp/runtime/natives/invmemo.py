"""INVERSE's answers kept for one run (issue 86): :class:`InverseMemo`.

A program's status/turn search (KUKA's ``Find_Optimal_ST`` pattern: 8 S x 64 T through
``INVERSE`` for every point it computes) asks one TOOLPOS with every S and T, and a palletizer
asks the same points again on every pallet. ``INVERSE``'s answer (its E6AXIS and STATUS) is a
function of the exact inputs that decide it on the simulated robot (natives/geometry.py
``_inverse``'s plain path: a robot model without external axes and with a null ``$ROBROOT``):
the robot model, TOOLPOS's X..C, ``$TOOL``, ``$BASE`` (each as its floats' bits), START_AXIS's
robot axes (their bits) and the S and T asked (as ints). The memo keeps the answers by exactly
these, so a kept answer is the one the call would compute, bit for bit (tests/interp/
test_inverse_memo.py compares the two on every kinematic family, unreachable and out-of-limit
poses included).

One memo is made per run (natives/context.py ``NativeContext``): nothing is shared between runs.
Its size is bounded: at most :data:`POSES` poses (TOOLPOS, $TOOL, $BASE and START's bits), each
with at most :data:`ANSWERS` answers (one per S/T pair asked); a pose's table is cleared when it
is full, and every table when the poses are (the memo then refills from the next calls): at
most 64 x 512 answers, each a STATUS and, for a solution, one E6AXIS structure.
"""

from __future__ import annotations

#: poses kept (TOOLPOS, $TOOL, $BASE, START_AXIS): a palletizer's pattern of this many places
#: keeps its answers between pallets
POSES = 64
#: answers kept per pose: one per S/T pair (8 x 64 in a full status/turn search)
ANSWERS = 512


class InverseMemo:
    """The answers of ``INVERSE`` in one run (module docstring): :meth:`table` gives the dict of
    one pose's answers, (S, T) -> (STATUS, the E6AXIS of a solution or None); :meth:`keep` enters
    one."""

    __slots__ = ("model", "tables", "last")

    def __init__(self) -> None:
        self.model = None
        self.tables: dict[bytes, dict] = {}
        #: the last call's pose on the memo's path (natives/geometry.py ``_again``): (the objects
        #: that decide its answer but S and T, its table, its flange pose, its START, the getter of
        #: START's robot axes), or None
        self.last: tuple | None = None

    def table(self, model, key: bytes) -> dict:
        """The answers of the pose `key` (the bits of TOOLPOS's X..C, $TOOL, $BASE and START's robot
        axes) on the robot `model` (another model clears the memo)."""
        tables = self.tables
        if model is not self.model:
            tables.clear()
            self.model = model
            self.last = None
        got = tables.get(key)
        if got is None:
            if len(tables) >= POSES:
                tables.clear()
                self.last = None
            got = tables[key] = {}
        return got

    @staticmethod
    def keep(table: dict, st: tuple, answer: tuple) -> None:
        """Enter `answer` for the S/T pair `st` into the pose's `table` (cleared first when full)."""
        if len(table) >= ANSWERS:
            table.clear()
        table[st] = answer


__all__ = ["ANSWERS", "InverseMemo", "POSES"]
