"""The change report's run outcomes (interp/outcomes.py ``run_outcome``), issue 85 item 5, on
both interpreters: where a program that completed ended (its END, not the last statement it
executed in a routine of another module), and that no step limit the page does not name ends a
run before its own error."""

from __future__ import annotations

import pytest

import interp.outcomes as O

from .helpers import write

#: main.src calls helper() of lib.src as its last statement; it completes at its END, line 5
MAIN = "DEF main()\n  INT i\n  i = 1\n  helper()\nEND\n"
LIB = "DEF lib()\nEND\n\nGLOBAL DEF helper()\n  INT k\n  k = 2\nEND\n"
#: 30,000 passes of an empty FOR (30,000 steps of the robot interpreter: 30 IPO cycles of 1000,
#: 0.36 s), then a routine the backup lacks: the program's own error at line 6
OLD = "DEF old()\n  INT i\n  FOR i = 1 TO 30000\n    ;\n  ENDFOR\n  Station500_Reject()\nEND\n"


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_completed_program_ends_at_its_own_end(tmp_path, interp):
    """"completed at collmonlib.src:302": the last statement executed was in a called module."""
    main = write(tmp_path, "main.src", MAIN)
    write(tmp_path, "lib.src", LIB)
    out = O.run_outcome(str(main), max_sim_time=2.0, interp=interp)
    assert out["reason"] == "completed", out["text"]
    assert (out["file"], out["line"], out["statement"]) == (str(main), 5, "END")


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_no_step_limit_ends_a_run_before_its_own_error(tmp_path, interp, monkeypatch):
    """"the old version's end comes from an undisclosed --max-steps 300000 instead of its own
    error (routine Station500_Reject not found at 10.1 s)": rebuilt at a tenth of the scale (the
    report's step limit, if it has one, set to 20,000 statements here to keep the test cheap)."""
    monkeypatch.setattr(O, "REPORT_STEPS", 20_000, raising=False)
    old = write(tmp_path, "old.src", OLD)
    out = O.run_outcome(str(old), max_sim_time=10.0, interp=interp)
    assert (out["reason"], out["text"], out["line"]) == ("error", "routine Station500_Reject not found", 6)
    # 30,000 loop passes at the robot interpreter's 1000 steps per 12 ms IPO cycle
    assert 0.3 <= out["sim_time"] <= 0.4
