"""The turns of P00's program-number handshake (issue 85, item 9; interp/runtime/pgnoturns.py),
on both interpreters.

Rebuilt from the issue's description: KUKA's template cell.src whose three CASEs are empty (each
acknowledges its number and calls nothing) never moves the robot; with a number the program has
no CASE for, P00's #PGNO_FAULT message comes back again and again (27,787 times in 30 s on the
held-out backup). Before, both ran to the time limit (30 s: 98 standard-P00 calls and 48 messages
for --pgno 5; with --inputs auto, 252 calls, and the summary said "nothing starved that inputs
could release" after 250 numbers the automatic cell itself had given). Now the run ends once each
number the PLC gives came back with nothing changed. Counts by hand: with the numbers 1, 2, 3 in
turn, number n first comes back at its second answer, so the third number's second answer (the
sixth) ends the run; a fixed number ends it at its second answer."""

from __future__ import annotations

from pathlib import Path

import pytest

from interp.run import make_runtime, run_spec, RunSinks
from interp.summary import pgno_given

from .helpers import write
from .test_kss import P00_CONFIG

INTERPS = ("tree", "vm")

#: KUKA's template loop (its CASE bodies acknowledge and call nothing: the calls are comments)
TEMPLATE = """
&COMMENT HANDLER on external automatic
DEF cell( )
  DECL CHAR DMY[3]
  DMY[]="---"
  P00 (#INIT_EXT,#PGNO_GET,DMY[],0 )
  LOOP
    P00 (#EXT_PGNO,#PGNO_GET,DMY[],0 )
    SWITCH PGNO
    CASE 1
      P00 (#EXT_PGNO,#PGNO_ACKN,DMY[],0 )
      ;EXAMPLE1 ( )
    CASE 2
      P00 (#EXT_PGNO,#PGNO_ACKN,DMY[],0 )
      ;EXAMPLE2 ( )
    CASE 3
      P00 (#EXT_PGNO,#PGNO_ACKN,DMY[],0 )
      ;EXAMPLE3 ( )
    DEFAULT
      P00 (#EXT_PGNO,#PGNO_FAULT,DMY[],0 )
    ENDSWITCH
  ENDLOOP
END
"""


def _run(tmp: Path, text: str, interp: str, max_sim_time: float = 30.0, **kw):
    write(tmp, "R1/System/$config.dat", P00_CONFIG)
    prog = write(tmp, "R1/Program/cell.src", text)
    rt, _ = make_runtime(run_spec(prog, mujoco=False, check=False, interp=interp, max_sim_time=max_sim_time,
                                  mode="EXT", **kw), RunSinks())
    return rt, rt.run()


@pytest.mark.parametrize("interp", INTERPS)
def test_the_template_with_empty_cases_ends_after_one_turn_of_its_numbers(tmp_path, interp):
    rt, res = _run(tmp_path, TEMPLATE, interp, inputs="auto")
    assert res.reason == "deadlock", res.text
    assert pgno_given(rt) == 6
    assert ("the PLC's program numbers 1 (its CASE at cell.src:9 starts no motion), 2 (its CASE at cell.src:12 "
            "starts no motion), 3 (its CASE at cell.src:15 starts no motion) came back") in res.text
    assert res.sim_time < 2.0


@pytest.mark.parametrize("interp", INTERPS)
def test_a_number_without_a_case_ends_at_its_second_fault(tmp_path, interp):
    rt, res = _run(tmp_path, TEMPLATE, interp, pgno=5)
    assert res.reason == "deadlock", res.text
    assert pgno_given(rt) == 2
    assert "number 5 (no CASE: the DEFAULT, P00's #PGNO_FAULT)" in res.text
    assert "its SWITCH PGNO has CASEs 1, 2, 3" in res.text


@pytest.mark.parametrize("interp", INTERPS)
def test_a_case_that_moves_or_counts_is_no_repeated_turn(tmp_path, interp):
    """CASE 1 counts its turns and moves at the fourth: the state differs from turn to turn
    (N), so the run goes on; once it moves, every turn plans a motion: to the time limit."""
    moving = TEMPLATE.replace("      ;EXAMPLE1 ( )\n", "      N = N + 1\n      IF N >= 4 THEN\n"
                              "        PTP {A1 10, A2 -90, A3 90, A4 0, A5 0, A6 0}\n        PTP {A1 -10}\n      ENDIF\n")
    write(tmp_path, "R1/Program/cell.dat", "DEFDAT cell\n  DECL INT N = 0\nENDDAT\n")
    rt, res = _run(tmp_path, moving, interp, max_sim_time=8.0, pgno=1)
    assert res.reason == "max_sim_time", res.text
    assert rt.program.module("cell").data["N"].get() > 4



#: a submit program the fast-forward parks from its first pass: each pass writes what it wrote and
#: reads nothing the cell changes
PARKED_SPS = "DEF sps( )\n  INT n\n  LOOP\n    n = 3\n  ENDLOOP\nEND\n"


@pytest.mark.parametrize("interp", INTERPS)
def test_the_turns_read_a_parked_submit_programs_frames(tmp_path, interp):
    """The turns compare the run's state at each answer (pgnoturns.py ``state_of``), a parked
    submit task's frames among it (idle.py ``frames_of``). 963f296 fixed an AttributeError there
    that only a parked task reached (seen on khrzysio's CELL.src with --inputs auto). With an SPS
    that changes nothing beside it, the template ends as it does alone."""
    sps = write(tmp_path, "R1/System/sps.sub", PARKED_SPS)
    rt, res = _run(tmp_path, TEMPLATE, interp, inputs="auto", submit=(str(sps),))
    assert rt.ff.spin.parks >= 1
    assert res.reason == "deadlock", res.text
    assert pgno_given(rt) == 6
