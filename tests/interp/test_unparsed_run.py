"""A run that reaches a line the grammar does not accept (an ``Unparsed`` statement, issue 63).

Two kinds of line, told apart by the checker's own finding on it:

* a line in a form KRL rejects whatever the controller's full grammar holds (a name alone on
  its line, ``==`` for an assignment: krl/diagnostics/codes.py ``PROGRAM_SYNTAX_CODES``) is the
  program's error: the run stops at it with the checker's words, and the sweeps count it as the
  program's error. The case is rebuilt from real material: khrzysio__KRC4_test's milling and
  cutting programs hold a ``TODO`` placeholder line (Cut_LeafLong.src:22), which
  grammar/CHANGES.md ("calls need parentheses") and ``krl check`` (E012) call invalid, while the
  run said "the controller runs it" and the variants sweep counted 112 runs of it as the
  simulator's gap;
* any other line the grammar does not accept may be a construct the recovered grammar lacks:
  the run stops there as the simulator's gap ("line not understood by krl-tools").

Expected values by reading the programs: the outputs before the line are set, the run stops on
the line's number, tree and VM alike. A line KRL rejects also takes what was the audit's
example of a line not understood: rawpython__kukaKRLmagic's ``print('1')`` (E017).
"""

from __future__ import annotations

import pytest

from interp.realprograms import cause_of
from interp.run import make_runtime, run_spec, RunSinks
from robot.trace import TraceWriter

from .helpers import write

INTERPS = ("tree", "vm")


def _run(tmp_path, body: str, interp: str):
    prog = write(tmp_path, "prog.src", "DEF prog( )\n  DECL INT n\n  $OUT[1] = TRUE\n" + body + "  $OUT[2] = TRUE\nEND\n")
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(prog, mujoco=False, check=False, interp=interp), RunSinks(trace=tw))
    res = rt.run()
    io = [(e["signal"], e["value"]) for e in tw.events if e["kind"] == "io"]
    return res, io


@pytest.mark.parametrize("interp", INTERPS)
@pytest.mark.parametrize("line, words", [
    ("  TODO\n", "syntax error E012: `TODO` alone is not a statement; to call the routine write `TODO()`"),
    ("  n == 1\n", "syntax error E013: `==` compares; to assign use `=`"),
    # rawpython__kukaKRLmagic's sample_program.src:26 (Python in a .src)
    ("  print('1')\n", "syntax error E017: `'` is not KRL here: strings use double quotes (\"text\")"),
])
def test_a_line_krl_rejects_stops_the_run_as_the_programs_error(tmp_path, interp, line, words):
    res, io = _run(tmp_path, line, interp)
    assert (res.reason, res.line, res.text) == ("error", 4, words)
    assert io == [("$OUT[1]", True)]
    assert cause_of({"reason": res.reason, "text": res.text}) == "program error"


@pytest.mark.parametrize("interp", INTERPS)
def test_a_line_the_grammar_may_lack_stops_the_run_as_the_simulators_gap(tmp_path, interp):
    """An unknown clause after a WAIT FOR: E002, a construct the grammar may lack, no finding
    that says KRL rejects it: the simulator's gap."""
    res, io = _run(tmp_path, "  WAIT FOR $IN[1]   DELAY=1\n", interp)
    assert (res.reason, res.line) == ("error", 4)
    assert res.text == ("line not understood by krl-tools (the controller runs it; the simulation stops here): "
                        "WAIT FOR $IN[1] DELAY=1")
    assert io == [("$OUT[1]", True)]
    assert cause_of({"reason": res.reason, "text": res.text}) == "interpreter gap"
