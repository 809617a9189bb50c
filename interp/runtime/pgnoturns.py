"""The turns of P00's program-number handshake: a cell program that the PLC's numbers keep
running without ever moving the robot ends, explained (issue 85, item 9).

KUKA's cell program (``cell.src``) loops: ``P00 (#EXT_PGNO, #PGNO_GET, ...)`` requests a number
from the PLC, ``SWITCH PGNO`` runs the CASE of that number (which acknowledges it and calls the
user's program) or its DEFAULT (``P00 (#EXT_PGNO, #PGNO_FAULT, ...)``: the message
"ProgramNotAvailable" and the request withdrawn), and the loop requests again (KUKA System
Software 8, Automatic External: program number transfer; the corpus's own P00,
khrzysio__KRC4_test/R1/TP/p00.src:173-345). The PLC of a run (``--pgno N``, a cell file's
``pgno:``, the automatic cell's numbers in turn: robot/cellpresets.py, autocell.py
``handshake_rules``) answers each request the same way every time. So when the PLC gives a
number again and, since it gave it last, no motion was planned and the run's state
(idle.py ``state_of``, the message handle aside) is what it was then, the next turns repeat
this one: the template's empty CASEs, or a number the program has no CASE for, answered with
#PGNO_FAULT again and again (27,787 messages in 30 s on a held-out backup). Once every number
the PLC gives has come back so, the run ends ``deadlock`` saying which numbers, which CASE
each selects (its line) or that none does, and how to give another.

:func:`watch` hooks the PLC's request rules of a run; :class:`Turns` holds what it saw.
"""

from __future__ import annotations

from pathlib import Path

from robot.cellpresets import PresetError, pgno_bits

from .autocell import pgno_cases
from .idle import state_of


class Turns:
    """What the PLC's program-number answers of one run saw: ``given`` (answers written),
    ``last`` (number -> (state, motions planned) when it was given last), ``repeated`` (the
    numbers given again with nothing changed since, in a row) and the numbers in turn
    (``numbers``) with the CASE line of each (``cases``: number -> file:line)."""

    def __init__(self, state, planned, stop, numbers: list[int], cases: dict[int, str], decode) -> None:
        self.state = state          # () -> the run's state (idle.py state_of, the message handle aside)
        self.planned = planned      # () -> the motion queue's next id (motions planned so far)
        self.stop = stop            # (text) -> end the run ``deadlock`` with `text`, unless it ends already
        self.numbers = numbers
        self.cases = cases
        self.decode = decode        # a request rule's set -> the number it gives, or None
        self.given = 0
        self.last: dict = {}
        self.repeated: list[int] = []

    def fired(self, rule, t: float) -> None:
        """The PLC wrote a program number (robot/cellrules.py ``Rule.on_fire``)."""
        self.given += 1
        number = self.decode(rule.set)
        if number is None:
            return
        state = self.state()
        mark = self.planned()
        before = self.last.get(number)
        self.last[number] = (state, mark)
        if before is None or before[1] != mark or before[0] != state:
            self.repeated = []
            return
        if number not in self.repeated:
            self.repeated.append(number)
        if set(self.repeated) >= set(self.numbers):
            self.stop(self.text())

    def text(self) -> str:
        """Why the run ends: the numbers, what each selects, what would change it."""
        parts = []
        for n in self.repeated:
            where = self.cases.get(n)
            parts.append(f"{n} (its CASE at {where} starts no motion)" if where else
                         f"{n} (no CASE: the DEFAULT, P00's #PGNO_FAULT)")
        known = ", ".join(str(n) for n in sorted(self.cases)) or "none"
        return (f"the PLC's program number{'s' if len(parts) > 1 else ''} {', '.join(parts)} came back with no "
                f"motion and nothing else changed since {'each' if len(parts) > 1 else 'it'} was given last: the cell program repeats this turn "
                f"for ever (its SWITCH PGNO has CASEs {known}; --pgno N or a cell file's pgno: to give another)")


def case_lines(program) -> dict[int, str]:
    """number -> ``file:line`` of its first CASE in every ``SWITCH PGNO`` of the program's files
    (autocell.py ``pgno_cases``: the ``$config.dat`` variable PGNO, by the checker's symbol)."""
    out: dict[int, str] = {}
    for value, span in pgno_cases(program):
        if value not in out and span is not None:
            out[value] = f"{Path(span.file).name}:{span.line}"
    return out


def watch(rt, params: dict, numbers: list[int]) -> Turns | None:
    """Hook the PLC's program-number rules of the run `rt` (those whose source ends in
    ``:pgno`` and that write the number's bits) for the `numbers` it gives in turn (``--pgno
    N``: [N]); `params`: the ``PGNO_*`` values of the backup's ``$config.dat``. None when the
    run has no such rule."""
    rules = [r for r in rt.controller.signals.rules if str(r.source).endswith(":pgno") and len(r.set) > 1]
    if not rules or not numbers:
        return None
    codes = {}
    fbit = params.get("PGNO_FBIT")
    for n in numbers:
        try:
            bits = pgno_bits(n, params["PGNO_TYPE"], params["PGNO_LENGTH"])
        except (PresetError, KeyError):
            return None
        codes[tuple(bits)] = n

    def decode(sets: dict):
        bits = tuple(bool(sets.get(f"$IN[{fbit + i}]", False)) for i in range(params["PGNO_LENGTH"]))
        return codes.get(bits)

    def stop(text: str) -> None:
        if rt.scheduler.stop is None:
            rt.scheduler.stop = ("deadlock", text, rt.scheduler.tasks[0])

    # (the last message's handle aside from the state: a message each turn)
    turns = Turns(lambda: state_of(rt)[:-1], lambda: rt.controller.queue.next_id, stop, list(numbers),
                  case_lines(rt.program), decode)
    for r in rules:
        inner = r.on_fire

        def fired(rule, t, inner=inner):
            turns.fired(rule, t)            # (first: the automatic cell's sets the next number)
            if inner is not None:
                inner(rule, t)
        r.on_fire = fired
    return turns
