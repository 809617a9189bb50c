"""What a statement, a system routine or a system variable reads and writes, declared once where
each is declared (issue 87 item 2, "statement facts once"; docs/architecture.md, "Where to add a
statement, a native, a system variable").

Three registries carry these facts and three readers take them from there:

* the statement table (krl/semantics/statements.py ``KINDS``): a :class:`Facts` per statement kind;
* the natives registry (interp/runtime/natives/registry.py ``Native``): ``reads``/``writes`` of
  each system routine the simulator implements;
* the system variables the run computes (interp/runtime/sysvars.py ``_LIVE``): what reading one
  reads (``reads=`` on each entry).

The readers: the advance-run rule (krl/semantics/advance.py: a kind's ``stops``; a native's
``stops``), the checker (krl/semantics/checker.py: a kind that writes :data:`ROBOT` is a motion
statement, E406 in a submit program, KRL reference §9/§8.2) and the fast-forward
(interp/runtime/passes.py, period.py: a kind's ``fast_forward``, ``stub_once``; a native's
``pure``; a system variable's class). tests/interp/test_facts.py fails when a kind, a
native or a system variable lacks them.

**What is read or written** (a frozenset of these):

* :data:`EXPRESSIONS` whatever the statement's own expressions read (variables, signals, system
  variables: what each name denotes is the resolver's, krl/semantics/advance.py ``accesses``);
  :data:`TARGET` the variables its target names (an assignment's, a FOR's counter, the
  variables passed to an ``:OUT`` parameter);
* :data:`ARGS` (a system routine) its arguments only;
* :data:`SIGNALS` the I/O image (``$IN``, ``$OUT``, analog channels, timers);
* :data:`CLOCK` the simulated time or a random number (a read of it is no idle moment:
  interp/runtime/idle.py; the runtime calls ``clock_read`` for a native or system variable that
  declares it, which nothing else does);
* :data:`ROBOT` the robot's motion: the advance run's queue, the path, the actual position;
* :data:`TASKS` the program's own state (interrupts, the error state, a task's end, the mode);
* :data:`WORLD` what lies outside the run (messages to the operator, a network partner, a
  command channel).

**How the fast-forward may treat a statement kind** (``fast_forward``):

* :data:`REPEAT` it may be a step of a pass the spin watch parks (interp/runtime/spin.py): its
  only effects are the writes the watch checks;
* :data:`BESIDE` it may not be in a parked pass, but another task may run it beside a parked
  period without waking it when it writes nothing the period reads (interp/runtime/period.py);
* :data:`WAKE` neither: a pass that runs it is never parked.
"""

from __future__ import annotations

from dataclasses import dataclass

EXPRESSIONS, TARGET, ARGS = "expressions", "target", "args"
SIGNALS, CLOCK, ROBOT, TASKS, WORLD = "signals", "clock", "robot", "tasks", "world"
#: every access a fact may name
ACCESSES = frozenset({EXPRESSIONS, TARGET, ARGS, SIGNALS, CLOCK, ROBOT, TASKS, WORLD})

REPEAT, BESIDE, WAKE = "repeat", "beside", "wake"
#: the fast-forward's treatments of a statement kind, from the most to the least it may skip
TREATMENTS = (REPEAT, BESIDE, WAKE)


@dataclass(frozen=True, slots=True)
class Facts:
    """A statement kind's facts: ``reads``/``writes`` (frozensets of :data:`ACCESSES`), ``stops``
    (why the advance run stops before every statement of the kind, e.g. "WAIT SEC"; "" when only
    what its expressions read decide: krl/semantics/advance.py), ``fast_forward`` (one of
    :data:`TREATMENTS`), ``stub_once`` (a stand-in call in its own expressions runs exactly once
    at its step: an assignment's, a call statement's, an IF's condition; interp/runtime/passes.py
    ``stub_step``) and ``name`` (the kind's words in a diagnostic: "TRIGGER"; "" when the
    statement's own ``kind`` names it, a motion's "PTP")."""
    reads: frozenset
    writes: frozenset
    stops: str = ""
    fast_forward: str = WAKE
    stub_once: bool = False
    name: str = ""

    def __post_init__(self) -> None:
        unknown = (self.reads | self.writes) - ACCESSES
        if unknown or self.fast_forward not in TREATMENTS:
            raise ValueError(f"facts name {sorted(unknown) or self.fast_forward!r}: not one of {sorted(ACCESSES)}, "
                             f"{TREATMENTS}")


def facts(reads=(), writes=(), **how) -> Facts:
    """:class:`Facts` from iterables of accesses (the table's shorthand)."""
    return Facts(frozenset(reads), frozenset(writes), **how)


#: what a system variable's read reads, one of these (interp/runtime/sysvars.py ``_LIVE``):
#: SIGNALS the I/O image; ROBOT the main run's motion (changes as the robot moves); TASKS the
#: tasks' state that changes with a task's end or the operating mode, or not at all; STATE other
#: state of the run (what a statement writes: $MOVE_ENABLE behind $COULD_START_MOTION, the
#: error state, an interrupt's position); CLOCK the simulated time; CONSTANT nothing that changes
STATE, CONSTANT = "state", "constant"
SYSVAR_READS = frozenset({SIGNALS, ROBOT, TASKS, STATE, CLOCK, CONSTANT})

__all__ = ["ACCESSES", "ARGS", "BESIDE", "CLOCK", "CONSTANT", "EXPRESSIONS", "Facts", "REPEAT", "ROBOT", "SIGNALS",
           "STATE", "SYSVAR_READS", "TARGET", "TASKS", "TREATMENTS", "WAKE", "WORLD", "facts"]
