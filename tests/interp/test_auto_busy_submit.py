"""The automatic cell answers a robot program that starves beside a busy submit interpreter
(issue 72, item 1), on the tree interpreter and the VM.

A KR C2 lathe-loading cell: its gripper check ``TRIGGER WHEN DISTANCE=0 DELAY=0 DO H50(...)
PRIO=-1`` and then ``WAIT FOR $IN[21]==TRUE``, beside an SPS.SUB that loops continuously and
changes its own state every pass (so the run is never idle). Earlier WAIT FORs were answered; the
one after the TRIGGER was not, for 300 s. Two ways a TRIGGER stands before such a wait, each a
test: its switching point on a motion after the WAIT FOR (the TRIGGER waits for the next motion
while the program waits), and its action, a routine with statements of its own, run while the
WAIT FOR's advance-run stop waits for the main run. Both waits must be answered as any other:
:data:`AUTO_DELAY_S` after the cell sees the robot program starve (a window of
``WINDOW_CYCLES`` IPO cycles of 12 ms, twice: once for the marks, once for its frames), and the
program must run to its END."""

from __future__ import annotations

import pytest

from interp.run import make_runtime, run_spec
from interp.runtime.autocell import AUTO_DELAY_S
from interp.runtime.idle import WINDOW_CYCLES

from .helpers import write

#: a submit program that never rests: a counter changes every pass (never idle, never parked)
BUSY_SPS = """
DEF sps()
  LOOP
    K = K + 1
    IF K > 100000 THEN
      K = 0
    ENDIF
  ENDLOOP
END
"""
BUSY_DAT = """
DEFDAT sps
  DECL INT K = 0
ENDDAT
"""
#: the robot program: a TRIGGER, then (``{after}``) the starving WAIT FOR and a motion, in one
#: of two orders
PROG = """
DEF prog()
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  WAIT FOR $IN[20]
  TRIGGER WHEN DISTANCE=0 DELAY=0 DO H50(1) PRIO=-1
{after}
  NDONE = 1
END
DEF H50(n:IN)
  INT n
  NH = NH + n
END
"""
WAIT = "  WAIT FOR InPinza1Abierta==TRUE"
MOTION = "  PTP {A1 10, A2 -90, A3 90, A4 0, A5 0, A6 0}"
#: the TRIGGER before the WAIT FOR, its motion after it (line 5: the starving WAIT FOR)
TRIGGER_FIRST = PROG.replace("{after}", f"{WAIT}\n{MOTION}")
#: the TRIGGER on the motion before the WAIT FOR: its action runs during the WAIT FOR's
#: advance-run stop (line 6: the starving WAIT FOR)
TRIGGER_ON_MOTION = PROG.replace("{after}", f"{MOTION}\n{WAIT}")
DAT = """
DEFDAT prog
  SIGNAL InPinza1Abierta $IN[21]
  DECL INT NDONE = 0
  DECL INT NH = 0
ENDDAT
"""


def _run(tmp_path, src: str, interp: str):
    p = write(tmp_path, "prog.src", src)
    write(tmp_path, "prog.dat", DAT)
    s = write(tmp_path, "sps.sub", BUSY_SPS)
    write(tmp_path, "sps.dat", BUSY_DAT)
    rt, _ = make_runtime(run_spec(p, inputs="auto", submit=[s], max_sim_time=20.0, mujoco=False,
                                  check=False, interp=interp))
    return rt, rt.run()


@pytest.mark.parametrize("src,line", [(TRIGGER_FIRST, 5), (TRIGGER_ON_MOTION, 6)],
                         ids=["trigger-waits-for-motion", "trigger-ran"])
@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_wait_after_trigger_is_answered_beside_a_busy_submit(tmp_path, interp, src, line):
    rt, res = _run(tmp_path, src, interp)
    answered = [(a.line, a.kind, a.sets) for a in rt.autocell.answers]
    # both waits are answered, each on its own line and input: $IN[20], then InPinza1Abierta
    assert answered == [(3, "WAIT FOR", {"$IN[20]": True}), (line, "WAIT FOR", {"$IN[21]": True})], res.text
    assert res.reason == "completed", res.text
    assert rt.program.module("prog").data["NDONE"].get() == 1
    assert rt.program.module("prog").data["NH"].get() == 1          # the TRIGGER's action ran once
    # the second answer comes as soon as the first: within two windows and the cell's delay of
    # the first answer's effect (plus the motion to A1 10 and back, under 2 s on a KR 6)
    first, second = rt.autocell.answers
    window = WINDOW_CYCLES * rt.controller.dt
    assert second.t - first.t <= 2.0 + 2 * window + AUTO_DELAY_S + 0.1
    # the busy submit interpreter ran all along (it is what kept the run from idling)
    assert rt.program.module("sps").data["K"].get() > 0
