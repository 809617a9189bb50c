"""Two corpus backups in one cell (issue 89, first Done-when; interp/robotcell.py): khrzysio's
cutting robot (khrzysio__KRC4_test, Program/CELL/Frame/Cut_FrameRight.src) hands each cut
profile to ingeniado's palletizer (ingeniado__KRC4-Robot-Palletizer, main.src, pattern 3:
SACO_20_M2, which picks with Program/SACO_20/coge_20.src). The cell file
tests/interp/fixtures/cutpal/cell.yaml refers to both backups in place.

What the programs say, read by hand:

* Cut_FrameRight.src:70 CutLeft and :75 CutRight each call CutSequence once (CutLeft.src:93,
  CutRight.src:93): two requests. CutSequence.src:29-31 raises outStartCutSeq ($OUT[15]) for
  1 s, then :35 WAIT FOR inCutSeqFinished ($IN[4]); then the program goes on to its end.
* coge_20.src:59 WAIT FOR SACO_RDY ($IN[81]): one bag per hand-off; then :68 VACIO = TRUE
  ($OUT[1]), :69 LIN XC1 (the pick), :75 LIN POS_AUX1, :86 PTP XHOME; SACO_20_M2 places it and
  calls coge_20 again, which reaches :59 again after :41 PTP XHOME and :56 PTP POS_AUX1.

So in one production cycle of the cutter: two hand-offs, the palletizer's wait at
coge_20.src:59 released twice by the wire from $OUT[15]; each pick's LIN XC1, LIN POS_AUX1 and
PTP XHOME twice, the approach (:41, :56) three times (the third bag's, which never comes);
the cutter's five LINs at each saw (CutLeft.src/CutRight.src :89-91, :96-97). Once the cutter
has completed, the palletizer waits at coge_20.src:59 for a part only the cutter could give:
the cell ends ``deadlock`` there, the cutter ``completed``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from interp.robotcell import cell_runs, load_robot_cell, run_cell

FIXTURE = Path(__file__).resolve().parent / "fixtures" / "cutpal"


def _run(name: str, interp: str, limit: float):
    """The cell's result and, per robot, the times its outputs rose ([(t, $OUT[n])])."""
    cell = load_robot_cell(FIXTURE / name)
    with cell_runs(cell, interp, limit, mujoco=False) as runs:
        res = run_cell(cell, runs)
        rises = {r.name: [(round(t, 3), s) for t, s, v, *_ in r.runtime.controller.io.log
                          if v is True and s.startswith("$OUT[")] for r in runs}
    return res, rises


def _where(text: str) -> tuple[str, int]:
    """(file name, line) of a wait's text ``WAIT FOR at FILE:LINE``."""
    path, line = text.split(" at ", 1)[1].split(" ")[0].rsplit(":", 1)
    return Path(path).name, int(line)


# the tree interpreter's run of the whole cycle (about 3x the VM's CPU) in make nightly; both
# interpreters' miswired runs here
@pytest.mark.parametrize("interp", ["vm", pytest.param("tree", marks=pytest.mark.slow)])
def test_the_cutter_and_the_palletizer_run_a_production_cycle(shared_corpus, interp):
    res, rises = _run("cell.yaml", interp, 70.0)
    cut, pal = res.robots
    assert cut.runtime.result.reason == "completed", cut.runtime.result
    # the palletizer then waits for a third bag, which only the (completed) cutter could offer
    end = pal.runtime.result
    assert res.reason == "deadlock" and end.reason == "deadlock"
    assert (Path(end.file).name, end.line) == ("coge_20.src", 59)
    assert "its inputs from the cell: CUT $OUT[15] -> PAL $IN[81]" in end.text
    # two hand-offs: two requests of the cutter, the palletizer's wait for a bag released twice
    # by them, two picks (VACIO, coge_20.src:68) and two pick reports (PULSE SACO_COGIDO, :78)
    requests = [t for t, s in rises["CUT"] if s == "$OUT[15]"]
    assert len(requests) == 2
    assert [(_where(text), [str(w) for w in wires]) for text, _s, wires in pal.released] == \
        [(("coge_20.src", 59), ["CUT $OUT[15] -> PAL $IN[81]"])] * 2
    picks = [t for t, s in rises["PAL"] if s == "$OUT[1]"]
    assert len(picks) == 2 and len([t for t, s in rises["PAL"] if s == "$OUT[3]"]) == 2
    # each pick one IPO cycle after the request: the wire's one-cycle latency (docs/cells.md)
    assert picks == pytest.approx([t + 0.012 for t in requests])
    # the saw table: the palletizer's LIN XC1 (coge_20.src:69) enters it at the second hand-off
    # while the cutter stands there (at rest, CutSequence.src:35, after CutRight.src:91 LIN xCut);
    # at the first the cutter is at its left saw (CutLeft.src), 2 m away: no conflict
    (c,) = res.conflicts
    assert c.zone == "saw_table" and requests[1] < c.time < requests[1] + 2.0
    assert dict((name, where and (Path(where.rsplit(":", 1)[0]).name, int(where.rsplit(":", 1)[1])))
                for name, where in (c.first, c.second)) == {"CUT": None, "PAL": ("coge_20.src", 69)}


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_pair_miswired_deadlocks_naming_both_waits(shared_corpus, interp):
    """miswired.yaml: the palletizer's acknowledgement into the cutter's $IN[5], not $IN[4]. The
    first hand-off happens (the request is wired right); then the cutter waits at
    CutSequence.src:35 for an input nothing drives and the palletizer, its bag placed, at
    coge_20.src:59 for the next request: each names its own wait and the other's (both backups'
    file:line), though the palletizer's submit interpreter runs on (it cannot write an input)."""
    res, rises = _run("miswired.yaml", interp, 60.0)
    assert res.reason == "deadlock"
    cut, pal = res.robots
    for r, own, other in ((cut, ("CutSequence.src", 35), ("coge_20.src", 59)),
                          (pal, ("coge_20.src", 59), ("CutSequence.src", 35))):
        end = r.runtime.result
        assert end.reason == "deadlock" and (Path(end.file).name, end.line) == own
        waits = [_where(part) for part in end.text.split("; ")]
        assert waits == [own, other]
    assert "PAL $OUT[1] -> CUT $IN[5]" in cut.runtime.result.text
    assert len([t for t, s in rises["CUT"] if s == "$OUT[15]"]) == 1
