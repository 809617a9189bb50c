"""A program that raises the same acknowledgement message again and again with the robot
still (issue 85, item 9: KUKA's template cell.src whose CASEs are empty never gets a valid
program number; P00's #PGNO_FAULT message was written 27,787 times in 30 s simulated at about
1.2x real time, and the run did not end within a wall limit), on both interpreters.

On the controller a QUIT message (KUKA's MsgLib MsgQuit: SET_KRLMSG(#QUIT, ...), then wait
while EXISTS_KRLMSG) holds the program until the operator acknowledges it; a run has no
operator and acknowledges it at once. The same message back MAX_QUIT_REPEATS times in a row
with no motion between is the controller waiting for the operator: the run ends there, saying
so, after a handful of passes instead of at the time limit."""

from __future__ import annotations

import pytest

from krl.limits import MAX_QUIT_REPEATS

from .helpers import run_krl

#: the template's loop, written here: a number read without a request (one of n, no input
#: set), the SWITCH's three empty CASEs, and the fault branch's quit message, MsgQuit's way
LOOPING = """
DEF prog()
  DECL INT I
  LOOP
    PGNO = 0
    FOR I = 0 TO 7
      IF $IN[33 + I] THEN
        PGNO = I + 1
      ENDIF
    ENDFOR
    SWITCH PGNO
      CASE 1
      CASE 2
      CASE 3
      DEFAULT
        fault()
    ENDSWITCH
  ENDLOOP
END

DEF fault()
  DECL KRLMSG_T MSG
  DECL KRLMSGPAR_T PAR[3]
  DECL KRLMSGOPT_T OPT
  DECL INT H
  MSG = {MODUL[] "P00", NR 3, MSG_TXT[] "ProgramNotAvailable"}
  H = SET_KRLMSG(#QUIT, MSG, PAR[], OPT)
  WHILE EXISTS_KRLMSG(H)
    WAIT SEC 0.012
  ENDWHILE
  N = N + 1
END
"""
DAT = "DEFDAT prog\n  DECL INT PGNO = 0\n  DECL INT N = 0\nENDDAT\n"


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_same_quit_message_again_and_again_ends_the_run_explained(tmp_path, interp):
    r = run_krl(tmp_path, LOOPING, DAT, max_sim_time=30.0, trace=False, interp=interp)
    res = r.result
    assert res.reason == "deadlock", res.text
    assert res.sim_time < 0.1                        # a handful of passes, not 30 s
    assert r.var("prog", "N") == MAX_QUIT_REPEATS - 1    # the last acknowledgement ends the run
    assert "'ProgramNotAvailable' (P00 3)" in res.text
    assert f"acknowledged {MAX_QUIT_REPEATS} times in a row" in res.text
    assert "the controller waits for the operator" in res.text


MOVING = LOOPING.replace("        fault()\n", "        fault()\n        PTP {A1 5}\n        PTP {A1 -5}\n").replace(
    "  DECL INT I\n", "  DECL INT I\n  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}\n")


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_message_between_motions_is_no_operator_loop(tmp_path, interp):
    """The same message with a motion between each: the program does something each time,
    the run goes on to its time limit."""
    r = run_krl(tmp_path, MOVING, DAT, max_sim_time=8.0, trace=False, interp=interp)
    assert r.result.reason == "max_sim_time", r.result.text
    assert r.var("prog", "N") > MAX_QUIT_REPEATS
