"""The step limit and the time the user asks for (issue 59, case 5), rebuilt from the issue's
description: a cell whose SPS.SUB counts every pass (so it is never a spin), asked for 600 s of
simulated time, stopped at 110 s on "step limit 10000000 reached" in its sps.sub. The step limit
counted every task's statements: the cell's polling loop at its time slice (1000 steps per 12 ms
IPO cycle) and the SPS at its own (100) reach 10 million in 109 s. --max-sim-time is the user's
request; the step limit stops a runaway robot program, not a submit program doing its job
(docs/architecture.md, "The step limit").
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from interp.run import make_runtime, run_spec, RunSinks
from app import main
from robot.trace import TraceWriter

from .helpers import write

INTERPS = ("tree", "vm")


def _run(prog: Path, interp: str, **kw):
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(prog, mujoco=False, check=False, interp=interp, **kw), RunSinks(trace=tw))
    res = rt.run()
    return rt, res, tw.events


CELL_SRC = """
&ACCESS RVP
&COMMENT HANDLER on external automatic
DEF cell( )
  LOOP
    IF $IN[40] THEN
      $OUT[40] = TRUE
    ENDIF
  ENDLOOP
END
"""

SPS_COUNTS = """
&ACCESS RVP
&COMMENT PLC on control
DEF  SPS ( )
  LOOP
    ;FOLD USER PLC
    N_PASS = N_PASS + 1
    IF N_PASS > 1000000 THEN
      N_PASS = 0
    ENDIF
    ;ENDFOLD (USER PLC)
  ENDLOOP
END
"""


def _counting_cell(tmp: Path) -> Path:
    write(tmp, "R1/System/$config.dat",
          "DEFDAT $CONFIG\n;FOLD USER GLOBALS\nDECL INT N_PASS = 0\n;ENDFOLD (USER GLOBALS)\nENDDAT\n")
    write(tmp, "R1/System/sps.sub", SPS_COUNTS)
    return write(tmp, "R1/Program/cell.src", CELL_SRC)


def test_a_counting_sps_beside_a_polling_cell_runs_the_time_asked(tmp_path):
    """The time the user asked is the run's bound: 150 s, past the 109 s at which a default step
    limit of all tasks' statements stopped the issue's 600 s run (10 000 000 steps at 1000 + 100
    a 12 ms cycle: 9091 cycles); 150 s proves it as 600 s did, at a quarter of the CPU. The
    summary says which task used the steps."""
    prog = _counting_cell(tmp_path)
    out = CliRunner().invoke(main, ["run", str(prog), "--interp", "vm", "--max-sim-time", "150"])
    assert out.exit_code == 3, out.output
    assert "stopped at the time limit (--max-sim-time) at t=150.0" in out.output
    assert "step limit" not in out.output
    steps = next(line for line in out.output.splitlines() if line.strip().startswith("time"))
    # the cell polls at its time slice (1000 steps per 12 ms cycle), the SPS at its own (100):
    # 150 s is 12 500 cycles, 12.5 million steps of the cell's and 1.25 million of the SPS's,
    # 13.75 million in all (more than the old limit of 10 million)
    assert re.search(r"cell 125\d{5}\b", steps) and re.search(r"sps 125\d{4}\b", steps), steps


@pytest.mark.parametrize("interp", INTERPS)
def test_the_step_limit_counts_the_robot_interpreter_only(tmp_path, interp):
    """An explicit step limit stops a robot program that runs away, never a submit program that
    cycles: the SPS counts 100 steps per cycle for 2 s (about 16 700 steps) beside a robot
    program that waits; a limit of 5000 steps does not end the run, which ends at its time."""
    prog = _counting_cell(tmp_path)
    write(tmp_path, "R1/Program/waits.src", "DEF waits( )\n  WAIT SEC 10\nEND\n")
    sps = [tmp_path / "R1/System/sps.sub"]
    rt, res, _events = _run(tmp_path / "R1/Program/waits.src", interp, max_sim_time=2.0, max_steps=5000, submit=sps)
    assert res.reason == "max_sim_time", res.text
    by = dict(rt.steps_by_task())
    assert by["sps"] > 16_000 and by["waits"] < 10
    # the cell's polling loop is the robot program's: the same limit stops it
    rt, res, _events = _run(prog, interp, max_sim_time=2.0, max_steps=5000, submit=sps)
    assert (res.reason, res.text) == ("max_steps", "step limit 5000 reached")
    assert dict(rt.steps_by_task())["cell"] == 5001
