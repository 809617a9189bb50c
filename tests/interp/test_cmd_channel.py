"""KUKA's command channel ``$CMD`` (issue 72, item 3): ``CWRITE($CMD, STAT, MODE, "STOP 1")``,
``"CANCEL 1"``, ``"RESET 1"``, ``"RUN /R1/CELL()"`` change the program state of the robot
interpreter that ``$PRO_STATE1`` reads, on the tree interpreter and the VM.

The expected states are KUKA's, not the simulator's: a program is selected with RUN (it leaves
``#P_FREE``), stopped with STOP (``#P_ACTIVE`` -> ``#P_STOP``), reset with RESET (``#P_STOP``/
``#P_END`` -> ``#P_RESET``) and deselected with CANCEL (``#P_STOP``/``#P_END``/``#P_RESET`` ->
``#P_FREE``); CANCEL and RESET of an active program are refused (STOP it first): the SPS logic of
https://industrialmonitordirect.com/blogs/knowledgebase/kuka-robot-program-abort-stopping-execution-like-fanuc-abort
and kroshu's external-control SDK (program_handler.src: RUN, then wait for the state to leave
#P_FREE; STOP, wait to leave #P_ACTIVE; CANCEL, wait for #P_FREE; RESET, wait for #P_RESET)."""

from __future__ import annotations

import pytest

from interp.run import make_runtime, run_spec
from interp.summary import ending_of

from .helpers import run_krl, write

#: the archive's reset logic (issue 72, item 3): on the reset input, stop and deselect the
#: cell program while it is selected, then select it again and raise a flag. NSTOP counts the
#: passes that had to stop and cancel; S_* keep $PRO_STATE1 at each point
RESET_SPS = """
DEF sps()
  DECL STATE_T STAT
  DECL MODUS_T MODE
  MODE = #SYNC
  S_BOOT = $PRO_STATE1
  CWRITE($CMD,STAT,MODE,"RUN /R1/CELL()")
  S_SELECTED = $PRO_STATE1
  LOOP
    IF $IN[5] AND NOT DONE THEN
      IF ($PRO_STATE1 <> #P_FREE) THEN
        CWRITE($CMD,STAT,MODE,"STOP 1")
        CWRITE($CMD,STAT,MODE,"CANCEL 1")
        NSTOP = NSTOP + 1
        S_CANCELLED = $PRO_STATE1
      ENDIF
      IF ($PRO_STATE1 == #P_FREE) THEN
        CWRITE($CMD,STAT,MODE,"RUN /R1/CELL()")
        DONE = TRUE
        S_AGAIN = $PRO_STATE1
      ENDIF
    ENDIF
  ENDLOOP
END
"""
RESET_DAT = """
DEFDAT sps
  DECL INT NSTOP = 0
  DECL BOOL DONE = FALSE
  DECL PRO_STATE S_BOOT, S_SELECTED, S_CANCELLED, S_AGAIN
ENDDAT
"""
CELL = """
DEF cell()
  LOOP
    WAIT SEC 0.1
  ENDLOOP
END
"""


def _stim(t: float) -> str:
    return f'stimuli:\n  - at: {t}\n    set: {{"$IN[5]": true}}\n'


def _run_sub(tmp_path, sub: str, dat: str, interp: str, stimuli: str, max_sim_time: float = 1.0):
    s = write(tmp_path, "sps.sub", sub)
    write(tmp_path, "sps.dat", dat)
    write(tmp_path, "cell.src", CELL)
    inputs = write(tmp_path, "stimuli.yaml", stimuli)
    rt, _ = make_runtime(run_spec(s, inputs=inputs, max_sim_time=max_sim_time, mujoco=False,
                                  check=False, interp=interp))
    return rt, rt.run()


def _var(rt, module: str, name: str):
    v = rt.program.module(module).data[name.upper()].get()
    return getattr(v, "name", v)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_cancel_deselects_the_cell_program(tmp_path, interp):
    """The archive's sps.sub run on its own (issue 72, item 3): it runs in the submit
    interpreter, so the robot interpreter has no program at boot (#P_FREE); RUN selects CELL
    (#P_RESET: selected, not started, since no start key or $EXT_START starts it); when the
    reset input comes, STOP 1 leaves a program that is not running as it is, CANCEL 1 deselects
    it (#P_FREE), and RUN selects it again: one pass, not one per cycle to the time limit."""
    rt, res = _run_sub(tmp_path, RESET_SPS, RESET_DAT, interp, _stim(0.2))
    assert res.reason == "max_sim_time", res.text
    assert _var(rt, "sps", "S_BOOT") == "P_FREE"
    assert _var(rt, "sps", "S_SELECTED") == "P_RESET"
    assert _var(rt, "sps", "NSTOP") == 1
    assert _var(rt, "sps", "S_CANCELLED") == "P_FREE"
    assert _var(rt, "sps", "DONE") is True
    assert _var(rt, "sps", "S_AGAIN") == "P_RESET"


#: beside a running robot program: CANCEL and RESET of the active program are refused (RET1 not
#: CMD_OK, the state stays #P_ACTIVE), STOP stops it (#P_STOP), RESET resets it (#P_RESET),
#: CANCEL deselects it (#P_FREE); the robot program stays stopped (no one starts it again)
STOPPER = """
DEF sps()
  DECL STATE_T STAT
  DECL MODUS_T MODE
  MODE = #SYNC
  LOOP
    IF $IN[5] AND NOT DONE THEN
      S_RUNNING = $PRO_STATE1
      CWRITE($CMD,STAT,MODE,"CANCEL 1")
      R_CANCEL_ACTIVE = STAT.RET1
      CWRITE($CMD,STAT,MODE,"RESET 1")
      R_RESET_ACTIVE = STAT.RET1
      S_REFUSED = $PRO_STATE1
      CWRITE($CMD,STAT,MODE,"STOP 1")
      R_STOP = STAT.RET1
      S_STOPPED = $PRO_STATE1
      CWRITE($CMD,STAT,MODE,"RESET 1")
      S_RESET = $PRO_STATE1
      CWRITE($CMD,STAT,MODE,"CANCEL 1")
      R_CANCEL = STAT.RET1
      S_FREE = $PRO_STATE1
      DONE = TRUE
    ENDIF
  ENDLOOP
END
"""
STOPPER_DAT = """
DEFDAT sps
  DECL BOOL DONE = FALSE
  DECL PRO_STATE S_RUNNING, S_REFUSED, S_STOPPED, S_RESET, S_FREE
  DECL CMD_STAT R_CANCEL_ACTIVE, R_RESET_ACTIVE, R_STOP, R_CANCEL
ENDDAT
"""
ROBOT = """
DEF prog()
  LOOP
    N = N + 1
    WAIT SEC 0.012
  ENDLOOP
END
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_stop_reset_cancel_of_the_running_robot_program(tmp_path, interp):
    r = run_krl(tmp_path, ROBOT, "DEFDAT prog\n  DECL INT N = 0\nENDDAT\n",
                files={"sps.sub": STOPPER, "sps.dat": STOPPER_DAT}, submit=["sps.sub"],
                stimuli=_stim(0.3), max_sim_time=2.0, trace=False,
                interp=interp)
    rt = r.rt
    got = {k: _var(rt, "sps", k) for k in ("S_RUNNING", "R_CANCEL_ACTIVE", "R_RESET_ACTIVE", "S_REFUSED",
                                           "R_STOP", "S_STOPPED", "S_RESET", "R_CANCEL", "S_FREE")}
    assert got == {"S_RUNNING": "P_ACTIVE", "R_CANCEL_ACTIVE": "CMD_ABORT", "R_RESET_ACTIVE": "CMD_ABORT",
                   "S_REFUSED": "P_ACTIVE", "R_STOP": "CMD_OK", "S_STOPPED": "P_STOP", "S_RESET": "P_RESET",
                   "R_CANCEL": "CMD_OK", "S_FREE": "P_FREE"}
    # the robot program stopped where STOP 1 found it, about 0.3 s in (25 passes of 12 ms),
    # and nothing starts it again: the run ends there
    assert r.result.reason == "halt", r.result.text
    assert "STOP 1" in r.result.text
    assert 0.3 <= r.result.sim_time < 0.35
    assert 20 <= r.var("prog", "N") <= 30


#: a submit program that keeps the robot interpreter's state of every pass
WATCHER = """
DEF sps()
  LOOP
    S_LAST = $PRO_STATE1
  ENDLOOP
END
"""
WATCHER_DAT = """
DEFDAT sps
  DECL PRO_STATE S_LAST
ENDDAT
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_robot_program_stays_selected_at_its_end(tmp_path, interp):
    """At its END the robot program is #P_END: still selected, not #P_FREE (KUKA's $PRO_STATE);
    the submit program sees it in the run's last IPO cycle. (A run-time error ends the run at
    once: no submit program runs after it.)"""
    r = run_krl(tmp_path, "DEF prog()\n  WAIT SEC 0.1\nEND\n", files={"sps.sub": WATCHER, "sps.dat": WATCHER_DAT},
                submit=["sps.sub"], max_sim_time=2.0, trace=False, interp=interp)
    assert r.result.reason == "completed", r.result.text
    assert _var(r.rt, "sps", "S_LAST") == "P_END"


#: issue 85, item 5: the SPS's reset logic beside a running robot program, in Automatic
#: External: on the reset input, STOP 1, CANCEL 1, then RUN /R1/CELL() selects the cell program
#: again; the PLC of Automatic External starts a selected program ($EXT_START), so CELL runs
RESELECT_SPS = """
DEF sps()
  DECL STATE_T STAT
  DECL MODUS_T MODE
  MODE = #SYNC
  LOOP
    IF $IN[5] AND NOT DONE THEN
      CWRITE($CMD,STAT,MODE,"STOP 1")
      CWRITE($CMD,STAT,MODE,"CANCEL 1")
      CWRITE($CMD,STAT,MODE,"RUN /R1/CELL()")
      R_RUN = STAT.RET1
      DONE = TRUE
    ENDIF
  ENDLOOP
END
"""
RESELECT_DAT = """
DEFDAT sps
  DECL BOOL DONE = FALSE
  DECL CMD_STAT R_RUN
ENDDAT
"""
#: the cell program the RUN selects: counts its passes of 0.1 s each in M
COUNTING_CELL = """
DEF cell()
  LOOP
    M = M + 1
    S = $PRO_STATE1
    WAIT SEC 0.1
  ENDLOOP
END
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_reselected_program_runs_in_automatic_external(tmp_path, interp):
    """"After the SPS's STOP 1/CANCEL 1/RUN /R1/CELL() the run ends 'stopped by HALT', so the
    reselected program is never seen running": prog runs until the reset input at 0.3 s; then
    CELL starts from its first line and runs to the time limit (2 s): about 17 passes of 0.1 s
    (1.7 s / 0.1 s; WAIT SEC rounds to IPO cycles), prog's count stays where STOP found it."""
    write(tmp_path, "cell.src", COUNTING_CELL)
    write(tmp_path, "cell.dat", "DEFDAT cell\n  DECL INT M = 0\n  DECL PRO_STATE S\nENDDAT\n")
    write(tmp_path, "sps.sub", RESELECT_SPS)
    write(tmp_path, "sps.dat", RESELECT_DAT)
    prog = write(tmp_path, "prog.src", ROBOT)
    write(tmp_path, "prog.dat", "DEFDAT prog\n  DECL INT N = 0\nENDDAT\n")
    inputs = write(tmp_path, "stimuli.yaml", _stim(0.3))
    rt, _ = make_runtime(run_spec(prog, inputs=inputs, max_sim_time=2.0, mujoco=False, check=False,
                                  interp=interp, submit=[tmp_path / "sps.sub"], mode="EXT"))
    res = rt.run()
    assert _var(rt, "sps", "R_RUN") == "CMD_OK"
    assert res.reason == "max_sim_time", res.text
    assert 20 <= _var(rt, "prog", "N") <= 30                    # 0.3 s of 12 ms passes
    assert 15 <= _var(rt, "cell", "M") <= 18                    # CELL ran for the 1.7 s left
    assert res.file.endswith("cell.src")                        # and the run ended in it
    assert _var(rt, "cell", "S") == "P_ACTIVE"                   # selected, then started


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_stopped_robot_program_without_a_start_names_what_stopped_it(tmp_path, interp):
    """Outside Automatic External no PLC starts the program RUN selects (the operator's start
    key): the run ends where STOP 1 stopped it, and says what the SPS did after it."""
    write(tmp_path, "cell.src", COUNTING_CELL)
    r = run_krl(tmp_path, ROBOT, "DEFDAT prog\n  DECL INT N = 0\nENDDAT\n",
                files={"sps.sub": RESELECT_SPS, "sps.dat": RESELECT_DAT}, submit=["sps.sub"],
                stimuli=_stim(0.3), max_sim_time=2.0, trace=False, interp=interp)
    assert r.result.reason == "halt", r.result.text
    assert r.result.text == "the robot program was stopped by 'STOP 1' written to $CMD at sps.sub:7; then " \
                            "CANCEL 1, RUN /R1/CELL()"


def test_a_stop_by_cmd_is_no_halt_in_the_words_of_the_run():
    """The run's ending words (interp/summary.py ending_of): a halt a STOP command made is "stopped
    by a STOP command ($CMD)", a HALT statement's stays "stopped by HALT" (issue 85 item 5)."""
    assert ending_of("halt", "the robot program was stopped by 'STOP 1' written to $CMD at sps.sub:7") \
        == "stopped by a STOP command ($CMD)"
    assert ending_of("halt", "") == "stopped by HALT"
    assert ending_of("max_sim_time") == "stopped at the time limit (--max-sim-time)"
