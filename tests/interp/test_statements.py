"""One test per statement kind; expected values worked out by hand from the reference."""

from __future__ import annotations

import math

import pytest

from interp.runtime.contexts import Context

from .helpers import run_krl

DAT = """
DEFDAT prog
  DECL INT N1, N2, N3, N4
  DECL REAL R1
  DECL BOOL B1
  DECL CHAR S1[20]
  DECL FRAME F1
ENDDAT
"""


def test_assign_int_division_and_rounding(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      N1 = 7 / 2
      N2 = -7 / 2
      N3 = 5 + 10.6
      N4 = -2.5
      R1 = 7 / 2.0
    END
    """, DAT)
    assert r.result.reason == "completed"
    assert (r.var("prog", "N1"), r.var("prog", "N2"), r.var("prog", "N3"), r.var("prog", "N4")) == (3, -3, 16, -3)
    assert r.var("prog", "R1") == 3.5


def test_char_int_and_string_assignment(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      S1[] = "AB"
      N1 = S1[1]
      S1[3] = 67
      N2 = STRLEN(S1[])
      B1 = S1[2] > 65
    END
    """, DAT)
    assert r.var("prog", "N1") == 65
    assert r.var("prog", "N2") == 3
    assert r.var("prog", "S1").text() == "ABC"
    assert r.var("prog", "B1") is True


def test_for_counter_after_loop_and_step(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      DECL INT i
      N1 = 0
      FOR i = 1 TO 4
        N1 = N1 + i
      ENDFOR
      N2 = i
      FOR i = 10 TO 1 STEP -3
        N3 = i
      ENDFOR
      N4 = i
    END
    """, DAT)
    assert r.var("prog", "N1") == 10      # 1+2+3+4
    assert r.var("prog", "N2") == 5       # first value failing i <= 4
    assert r.var("prog", "N3") == 1       # 10, 7, 4, 1
    assert r.var("prog", "N4") == -2


def test_while_repeat_loop_exit(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      N1 = 0
      WHILE N1 < 5
        N1 = N1 + 2
      ENDWHILE
      N2 = 0
      REPEAT
        N2 = N2 + 1
      UNTIL N2 >= 1
      N3 = 0
      LOOP
        N3 = N3 + 1
        IF N3 == 7 THEN
          EXIT
        ENDIF
      ENDLOOP
    END
    """, DAT)
    assert (r.var("prog", "N1"), r.var("prog", "N2"), r.var("prog", "N3")) == (6, 1, 7)


def test_if_else_and_switch(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      DECL INT k
      N1 = 0
      FOR k = 1 TO 4
        SWITCH k
          CASE 1, 2
            N1 = N1 + 10
          CASE 3
            N1 = N1 + 100
          DEFAULT
            N1 = N1 + 1000
        ENDSWITCH
      ENDFOR
      IF N1 > 2000 THEN
        N2 = 1
      ELSE
        N2 = 2
      ENDIF
      SWITCH #B
        CASE #A
          N3 = 1
        CASE #B
          N3 = 2
      ENDSWITCH
    END
    """, DAT)
    assert r.var("prog", "N1") == 1120
    assert r.var("prog", "N2") == 2
    assert r.var("prog", "N3") == 2


def test_goto_forward_backward_and_out_of_block(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      N1 = 0
    again:
      N1 = N1 + 1
      IF N1 < 3 THEN
        GOTO again
      ENDIF
      GOTO skip
      N1 = 100
    skip:
      N2 = N1
    END
    """, DAT)
    assert (r.var("prog", "N1"), r.var("prog", "N2")) == (3, 3)


def test_calls_in_out_by_reference(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      DECL INT a[3]
      N1 = 1
      N2 = 1
      a[2] = 5
      F1 = {X 1, Y 2, Z 3, A 0, B 0, C 0}
      Twice(N1, N2)
      Twice(a[2], a[2])
      N3 = a[2]
      Shift(F1.X)
      R1 = F1.X
      N4 = Sq(N3 + 1)
    END
    DEF Twice(x :IN, y :OUT)
      DECL INT x, y
      x = x * 2
      y = x
    END
    DEF Shift(v :OUT)
      DECL REAL v
      v = v + 0.5
    END
    DEFFCT INT Sq(v :IN)
      DECL INT v
      RETURN v * v
    ENDFCT
    """, DAT)
    assert r.var("prog", "N1") == 1        # :IN is a copy
    assert r.var("prog", "N2") == 2        # :OUT writes back
    assert r.var("prog", "N3") == 10       # array element by reference
    assert r.var("prog", "R1") == 1.5      # struct field by reference
    assert r.var("prog", "N4") == 121


def test_dat_state_persists_across_calls(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      Count()
      Count()
      Count()
      N2 = Counter
    END
    DEF Count()
      Counter = Counter + 1
    END
    """, """
    DEFDAT prog
      DECL INT Counter = 40
      DECL INT N2
    ENDDAT
    """)
    assert r.var("prog", "N2") == 43


def test_return_in_procedure_and_main(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      N1 = 1
      Early()
      RETURN
      N1 = 99
    END
    DEF Early()
      N2 = 5
      RETURN
      N2 = 6
    END
    """, DAT)
    assert r.result.reason == "completed"
    assert (r.var("prog", "N1"), r.var("prog", "N2")) == (1, 5)


def test_partial_aggregate_and_geometric_operator(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      F1 = {X 10, Y 20, Z 30, A 0, B 0, C 0}
      F1 = {Z 5}
      R1 = F1.X + F1.Z
      F1 = {X 100, Y 0, Z 0, A 90, B 0, C 0} : {X 10, Y 0, Z 0, A 0, B 0, C 0}
    END
    """, DAT)
    assert r.var("prog", "R1") == 15.0
    f = r.var("prog", "F1")
    assert f.f["X"] == pytest.approx(100.0) and f.f["Y"] == pytest.approx(10.0)


def test_on_error_proceed_and_err(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      DECL INT u
      ON_ERROR_PROCEED
      N1 = u
      N2 = $ERR.NUMBER
      ERR_CLEAR($ERR)
      N3 = $ERR.NUMBER
    END
    """, DAT)
    assert r.result.reason == "completed"
    assert (r.var("prog", "N2"), r.var("prog", "N3")) == (1422, 0)


def test_on_error_proceed_flag_belongs_to_the_running_context(tmp_path):
    """An interrupt routine (or TRIGGER action) that runs before the statement after
    ON_ERROR_PROCEED neither takes nor sees the flag: it is the interrupted flow's."""
    taken = []

    def hook(rt):
        def stmt(task, _info):      # before the program's statement, the robot task running
            if taken:
                return
            rt.errstate.on_error_proceed()
            task.contexts.append(Context("interrupt", prio=3, number=3))
            taken.append(rt.errstate.take_error_proceed())
            task.contexts.pop()
            taken.append(rt.errstate.take_error_proceed())
            taken.append(rt.errstate.take_error_proceed())
        rt.stepping.set_hooks(stmt=stmt)

    r = run_krl(tmp_path, """
    DEF prog()
      N1 = 1
    END
    """, DAT, before=hook)
    assert r.result.reason == "completed"
    assert taken == [False, True, False]


def test_swrite_sread_and_string_functions(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      DECL STATE_T st
      DECL INT ofs
      DECL CHAR buf[40]
      ofs = 0
      SWRITE(buf[], st, ofs, "%0.4d-%5.2f|%s", 42, 3.14159, "ok")
      S1[] = buf[]
      ofs = 0
      SREAD("17 2.5", st, ofs, "%d %f", N1, R1)
      N2 = STRFIND(1, buf[], "OK", #NOT_CASE_SENS)
      B1 = STRCOMP("abc", "ABC", #NOT_CASE_SENS)
    END
    """, DAT)
    assert r.var("prog", "S1").text() == "0042- 3.14|ok"
    assert r.var("prog", "N1") == 17 and r.var("prog", "R1") == 2.5
    assert r.var("prog", "N2") == 12
    assert r.var("prog", "B1") is True


def test_wait_sec_timing(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      $OUT[1] = TRUE
      WAIT SEC 0.1
      $OUT[2] = TRUE
      WAIT SEC 0
      $OUT[3] = TRUE
    END
    """)
    t1 = r.io("$OUT[1]")[0][0]
    t2 = r.io("$OUT[2]")[0][0]
    t3 = r.io("$OUT[3]")[0][0]
    assert t1 == 0.0
    assert t2 == pytest.approx(0.108)    # ceil(0.1 / 0.012) = 9 cycles
    assert t3 == t2


def test_wait_for_input_from_stimulus(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      WAIT FOR $IN[5]
      $OUT[1] = TRUE
    END
    """, stimuli="stimuli:\n  - at: 0.5\n    set: {\"$IN[5]\": true}\n")
    assert r.result.reason == "completed"
    assert r.io("$OUT[1]")[0][0] == pytest.approx(0.504)


def test_halt_ends_with_stopped(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      $OUT[1] = TRUE
      HALT
      $OUT[2] = TRUE
    END
    """)
    assert r.result.reason == "halt" and r.result.exit_code == 3
    assert r.result.line == 3
    end = r.kinds("end")[-1]
    assert end["reason"] == "halt" and end["line"] == 3
    assert r.io("$OUT[2]") == []


def test_endless_loop_hits_limits(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      LOOP
      ENDLOOP
    END
    """, max_sim_time=0.5, trace=False)
    assert r.result.reason == "max_sim_time" and r.result.exit_code == 3
    r2 = run_krl(tmp_path, """
    DEF prog()
      LOOP
        N1 = 1
      ENDLOOP
    END
    """, DAT, max_steps=5000, trace=False)
    assert r2.result.reason == "max_steps"


def test_deadlocked_wait(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      WAIT FOR $IN[7]
    END
    """)
    assert r.result.reason == "deadlock" and r.result.exit_code == 3
    end = r.kinds("end")[-1]
    assert end["line"] == 2 and "WAIT FOR" in end["text"]


def test_continue_suppresses_advance_run_stop(tmp_path):
    src = """
    DEF prog()
      PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
      PTP {A1 40}
      {CONT}$OUT[1] = TRUE
      PTP {A1 0}
    END
    """
    stop = run_krl(tmp_path, src.replace("{CONT}", ""))
    cont = run_krl(tmp_path, src.replace("{CONT}", "CONTINUE\n      "))
    ends = [e for e in stop.kinds("motion") if e["id"] == 2 and e["phase"] == "end"]
    # without CONTINUE the output waits for the main run: set when motion 2 has ended
    assert stop.io("$OUT[1]")[0][0] >= ends[0]["t"] > 0.1
    # with CONTINUE the advance run sets it while motion 2 is still planned / executing
    assert cont.io("$OUT[1]")[0][0] < 0.05


def test_trigger_fires_at_the_right_cycle(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
      TRIGGER WHEN DISTANCE=0 DELAY=48 DO $OUT[2]=TRUE
      TRIGGER WHEN DISTANCE=1 DELAY=0 DO Mark()
      PTP {A1 30}
    END
    DEF Mark()
      $OUT[3] = TRUE
    END
    """)
    start = [e for e in r.kinds("motion") if e["id"] == 2 and e["phase"] == "start"][0]["t"]
    end = [e for e in r.kinds("motion") if e["id"] == 2 and e["phase"] == "end"][0]
    assert r.io("$OUT[2]")[0][0] == pytest.approx(start + 0.048)
    # DISTANCE=1 of an exact stop: the cycle the robot reaches the end point (its END signal
    # comes 24-36 ms later, robot/exactstop.py)
    reached = math.ceil(end["reached"] / 0.012 - 1e-6) * 0.012
    assert r.io("$OUT[3]")[0] == (pytest.approx(reached), True)
    assert end["t"] - reached == pytest.approx(0.024, abs=0.0121)
    srcs = [e.get("source") for e in r.events if e["kind"] == "io" and e["signal"] == "$OUT[2]"]
    assert srcs == ["trigger"]
    assert any(e["kind"] == "stmt" and e.get("context") == "trigger" for e in r.events)


def test_pulse(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      PULSE($OUT[4], TRUE, 0.06)
      WAIT SEC 0.2
    END
    """)
    assert r.io("$OUT[4]") == [(0.0, True), (pytest.approx(0.06), False)]
