"""The submit interpreter: cyclic, time-sliced, sharing memory with the robot program."""

from __future__ import annotations

import pytest

from .helpers import run_krl

SHARED = """
DEFDAT shared PUBLIC
  DECL GLOBAL INT Ticks = 0
  DECL GLOBAL BOOL Ready = FALSE
ENDDAT
"""

SPS = """
DEF sps()
  LOOP
    Ticks = Ticks + 1
    IF Ticks >= 50 THEN
      Ready = TRUE
    ENDIF
    WAIT SEC 0.012
  ENDLOOP
END
"""


def test_submit_shares_a_global(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      WAIT FOR Ready
      $OUT[1] = TRUE
      $FLAG[3] = TRUE
    END
    """, files={"shared.dat": SHARED, "sps.sub": SPS}, submit=["sps.sub"])
    assert r.result.reason == "completed"
    # one pass per IPO cycle: Ticks reaches 50 in the 50th pass (t = 49 * 0.012 s); the robot
    # task runs before the submit task in each cycle, so it sees Ready one cycle later
    assert r.io("$OUT[1]")[0][0] == pytest.approx(50 * 0.012)
    assert any(e["kind"] == "stmt" and e.get("context") == "submit" for e in r.events)


def test_submit_time_slice_without_wait(tmp_path):
    busy = SPS.replace("    WAIT SEC 0.012\n", "")
    r = run_krl(tmp_path, """
    DEF prog()
      WAIT FOR Ready
    END
    """, files={"shared.dat": SHARED, "sps.sub": busy}, submit=["sps.sub"])
    assert r.result.reason == "completed"
    # 100 steps per cycle (loop iteration + 2-3 statements each): Ticks 50 within 2 cycles
    assert r.result.sim_time <= 0.024 + 1e-9
