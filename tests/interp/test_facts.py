"""Statement facts once (issue 87 item 2): every statement kind, every system routine the simulator
implements and every system variable it computes declares what it reads and writes
(krl/semantics/facts.py), and the advance-run rule, the checker and the fast-forward take them from
there. Each check below is a function over a registry, so that it is also shown failing on a
registry that lacks a fact (a native that reads the clock without saying so)."""

from __future__ import annotations

import types

import pytest

from interp.runtime import passes, period
from interp.runtime.natives import REGISTRY
from interp.runtime.natives.registry import Family, build
from interp.runtime.sysvars import _LIVE, _computed
from krl.ast import nodes as N
from krl.ast.visit import STATEMENTS
from krl.semantics import statements as S
from krl.semantics.facts import ARGS, CLOCK, REPEAT, ROBOT, SYSVAR_READS, WAKE, Facts
from krl.workspace import check_texts

#: what the code of a native names when it reads the simulated time or draws a random number
CLOCK_WORDS = frozenset({"clock_read", "time", "random"})


def kinds_lacking(kinds: dict) -> list[str]:
    """The statement classes of the AST whose row in `kinds` has no facts."""
    return sorted(cls.__name__ for cls in STATEMENTS
                  if cls not in kinds or not isinstance(kinds[cls].facts, Facts))


def _names(code) -> set:
    out = set(code.co_names)
    for c in code.co_consts:
        if isinstance(c, types.CodeType):
            out |= _names(c)
    return out


def natives_lacking(registry: dict) -> list[str]:
    """The implemented routines of `registry` without their facts, or whose implementation reads
    the clock (its code names one of CLOCK_WORDS) while its facts do not say CLOCK."""
    out = []
    for name, native in registry.items():
        if native.fn is None:
            continue            # a stand-in or a KRL routine of the BASIS: no implementation here
        if native.reads is None or native.writes is None:
            out.append(f"{name}: no facts")
            continue
        code = getattr(native.fn, "__code__", None)
        words = _names(code) & CLOCK_WORDS if code is not None else set()
        if words and CLOCK not in native.reads:
            out.append(f"{name}: reads the clock ({', '.join(sorted(words))}) without saying so")
    return out


def sysvars_lacking(live: dict) -> list[str]:
    """The computed system variables of `live` that do not declare what a read of them reads."""
    return sorted(k for k, make in live.items() if getattr(make, "reads", None) not in SYSVAR_READS)


def test_every_statement_kind_has_its_facts():
    assert kinds_lacking(S.KINDS) == []
    without = dict(S.KINDS)
    without[N.WaitSec] = S.StatementKind(False, S.GUARDED, ("wait_sec",))
    assert kinds_lacking(without) == ["WaitSec"]


def test_every_implemented_native_has_its_facts():
    assert natives_lacking(REGISTRY) == []


def test_a_native_that_reads_the_clock_without_saying_so_fails():
    """The case of issue 87: a new native reads the simulated time and nothing says so."""
    fam = Family("test")

    @fam.native("REAL NOW_S()")
    def _now(rt, a):
        return rt.controller.time

    @fam.native("REAL NOW_MS()", reads=(ARGS,))
    def _now_ms(rt, a):
        return 1000 * rt.controller.time

    @fam.native("REAL NOW_T()", reads=(CLOCK,))
    def _now_t(rt, a):
        return rt.controller.time

    got = natives_lacking(build([fam]))
    assert got == ["NOW_S: no facts", "NOW_MS: reads the clock (time) without saying so"]


def test_a_declared_clock_read_is_a_clock_read():
    """A native whose facts say CLOCK reads the clock for the idle watch at every call: the
    registry makes that call (``Family.add``), the implementation does not."""
    fam = Family("test")
    fam.add("REAL TICK()", lambda rt, a: 7.0, reads=(CLOCK,))
    fam.add("REAL SEVEN()", lambda rt, a: 7.0, pure=True)
    reg = build([fam])

    class Rt:
        reads = 0

        def clock_read(self):
            self.reads += 1

    rt = Rt()
    assert reg["TICK"].fn(rt, []) == 7.0 and rt.reads == 1
    assert reg["SEVEN"].fn(rt, []) == 7.0 and rt.reads == 1
    assert reg["SEVEN"].pure and not reg["TICK"].pure
    assert REGISTRY["FRAND"].reads >= {CLOCK} and not REGISTRY["FRAND"].pure


def test_every_computed_system_variable_declares_what_it_reads():
    assert sysvars_lacking(_LIVE) == []
    assert sysvars_lacking({**_LIVE, "$NEW": lambda sv, t, name: None}) == ["$NEW"]
    with pytest.raises(TypeError):
        _computed(lambda sv: 0.0)           # no reads=: refused where it is declared
    with pytest.raises(ValueError):
        _computed(lambda sv: 0.0, reads="time")


def test_the_readers_take_the_facts_from_the_table():
    """The fast-forward's statement classes and system-variable classes are the facts' (the
    KRL reference's: a loop that only polls is a pass, a motion runs beside a period), and the
    checker's E406 names what writes the robot's motion."""
    assert N.Motion not in passes.ALLOWED and N.Motion in period.HARMLESS
    assert set(passes.ALLOWED) == {c for c, k in S.KINDS.items() if k.facts.fast_forward == REPEAT}
    assert {N.WaitSec, N.Halt, N.InterruptDecl} <= {c for c, k in S.KINDS.items() if k.facts.fast_forward == WAKE}
    assert passes.MOTION_NAMES == {k for k, m in _LIVE.items() if m.reads == ROBOT}
    assert {"$POS_ACT", "$AXIS_ACT", "$VEL_ACT"} <= passes.MOTION_NAMES
    assert passes.CLOCK_NAMES == {"$DATE", "$ROBRUNTIME"}
    sps = "DEF sps()\n  LOOP\n    BRAKE\n    TRIGGER WHEN DISTANCE=0 DELAY=0 DO $OUT[1]=TRUE\n  ENDLOOP\nEND\n"
    ws = check_texts({"sps.sub": sps})
    e406 = [d.message for d in ws.diagnostics if d.code == "E406"]
    assert len(e406) == 2 and "BRAKE" in e406[0] and "TRIGGER" in e406[1]
