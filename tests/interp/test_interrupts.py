"""Interrupts (reference §5.16-§5.17): edges, priorities, scope, BRAKE and RESUME."""

from __future__ import annotations

import pytest

from .helpers import run_krl

DAT = """
DEFDAT prog
  DECL INT N1 = 0
  DECL INT SEQ = 0
  DECL BOOL GO = FALSE
  DECL E6POS PINT
ENDDAT
"""


def test_rising_edge_only(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      INTERRUPT DECL 10 WHEN $IN[3] DO Hit()
      INTERRUPT DECL 11 WHEN $IN[1025] DO Never()
      INTERRUPT ON
      WAIT SEC 0.5
    END
    DEF Hit()
      N1 = N1 + 1
    END
    DEF Never()
      N1 = N1 + 100
    END
    """, DAT, stimuli="stimuli:\n  - at: 0.1\n    set: {\"$IN[3]\": true}\n")
    assert r.result.reason == "completed"
    assert r.var("prog", "N1") == 1          # fired once; $IN[1025] was TRUE at ON: no edge
    entries = [e for e in r.kinds("interrupt") if e["phase"] == "entry"]
    assert [e["prio"] for e in entries] == [10]
    assert entries[0]["t"] == pytest.approx(0.108)   # the cycle after the stimulus


def test_priorities_and_nesting(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      INTERRUPT DECL 20 WHEN GO DO Mid()
      INTERRUPT DECL 30 WHEN GO DO Low()
      INTERRUPT DECL 5 WHEN $IN[4] DO High()
      INTERRUPT ON
      GO = TRUE
      WAIT SEC 0.3
    END
    DEF Mid()
      SEQ = SEQ * 10 + 2
      WAIT SEC 0.1
      SEQ = SEQ * 10 + 2
    END
    DEF Low()
      SEQ = SEQ * 10 + 3
    END
    DEF High()
      SEQ = SEQ * 10 + 1
    END
    """, DAT, stimuli="stimuli:\n  - at: 0.05\n    set: {\"$IN[4]\": true}\n")
    # GO fires 20 and 30 together: 20 first; during its WAIT, 5 (higher) nests; 30 waits
    assert r.var("prog", "SEQ") == 2123
    seq = [(e["prio"], e["phase"]) for e in r.kinds("interrupt")]
    assert seq == [(20, "entry"), (5, "entry"), (5, "exit"), (20, "exit"), (30, "entry"), (30, "exit")]


def test_disable_buffers_enable_releases(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      INTERRUPT DECL 12 WHEN GO DO Hit()
      INTERRUPT ON 12
      INTERRUPT DISABLE 12
      GO = TRUE
      SEQ = N1
      INTERRUPT ENABLE 12
      SEQ = SEQ * 10 + N1
    END
    DEF Hit()
      N1 = N1 + 1
    END
    """, DAT)
    assert r.var("prog", "SEQ") == 1          # 0 while disabled, then 1


def test_declaration_removed_on_return(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      MkIrq()
      INTERRUPT ON 40
    END
    DEF MkIrq()
      INTERRUPT DECL 40 WHEN GO DO MkIrq()
    END
    """, DAT)
    assert r.result.reason == "error"
    assert r.result.error.number == 1430 and r.result.line == 3


def test_brake_and_resume(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
      INTERRUPT DECL 21 WHEN $IN[12] DO Touch()
      SearchMove()
      N1 = 7
      PTP {A1 0}
    END
    DEF SearchMove()
      INTERRUPT ON 21
      PTP {A1 170}
      PTP {A1 -170}
      INTERRUPT OFF 21
      N1 = 99
    END
    DEF Touch()
      INTERRUPT OFF 21
      BRAKE
      PINT = $POS_INT
      SEQ = 1
      RESUME
    END
    """, DAT, stimuli="stimuli:\n  - at: 0.15\n    set: {\"$IN[12]\": true}\n")
    assert r.result.reason == "completed"
    assert r.var("prog", "N1") == 7           # RESUME skipped the rest of SearchMove
    assert r.var("prog", "SEQ") == 1
    motions = r.kinds("motion")
    # motion 2 (A1 170) never reached its end: RESUME abandons it with an end/abort event
    # (issue 15); motion 3 (A1 -170) was discarded; the next one is PTP {A1 0}
    ends2 = [e for e in motions if e["id"] == 2 and e["phase"] == "end"]
    assert [e.get("reason") for e in ends2] == ["abort"]
    assert not any(e["id"] == 3 and e["phase"] == "start" for e in motions)
    last = [e for e in motions if e["phase"] == "end"][-1]
    assert last["target"] == {"A1": 0.0}
    assert r.var("prog", "PINT").f["X"] != 0.0


def test_interrupt_brake_without_resume_continues(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
      INTERRUPT DECL 22 WHEN $IN[12] DO Pause()
      INTERRUPT ON 22
      PTP {A1 60}
      N1 = 1
    END
    DEF Pause()
      BRAKE
      WAIT SEC 0.2
    END
    """, DAT, stimuli="stimuli:\n  - at: 0.2\n    set: {\"$IN[12]\": true}\n")
    assert r.result.reason == "completed"
    assert any(e["id"] == 2 and e["phase"] == "end" for e in r.kinds("motion"))


def test_global_declaration_survives_the_return(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      MkIrq()
      INTERRUPT ON 41
      GO = TRUE
      WAIT SEC 0.05
    END
    DEF MkIrq()
      GLOBAL INTERRUPT DECL 41 WHEN GO DO Hit()
    END
    DEF Hit()
      N1 = N1 + 1
    END
    """, DAT)
    assert r.result.reason == "completed" and r.var("prog", "N1") == 1


def test_err_raise_reissues_the_stored_error(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      DECL INT u
      ON_ERROR_PROCEED
      N1 = u
      SEQ = $ERR.NUMBER
      ERR_RAISE($ERR)
      N1 = 5
    END
    """, DAT)
    assert r.var("prog", "SEQ") == 1422
    assert r.result.reason == "error" and r.result.error.number == 1422 and r.result.line == 6
