"""The five-axis palletizer cell of issue 86 (examples/palletizer5, written from the issue's
description of a KR 470 PA-2 archive we cannot see): its first cycle, pick and place, on both
interpreters with its cell file, from the start to the PTP above the first place: the pick, the
product read and its load selected, the place's configuration searched.

Expected values by hand, from the example's own files and KUKA's Status/Turn definition:

* the stimulus at 0.2 s puts product 1 on ``GI_PRODUCT`` ($IN[33..36]: $IN[33]) and 2 layers on
  ``GI_LAYERS`` ($IN[37..40]: $IN[38]); the program reads them, so ``SELECT_LOAD`` takes the first
  branch of its IF chain (5 kg) and the SPS.SUB's heavy-product output $OUT[51] (weight > 20 kg)
  stays FALSE; once the vacuum holds, ``$LOAD`` is ``LOAD_DATA[2]``: the 85 kg gripper + 5 kg;
* the first place is the pattern's corner, XPLACE0 (1000, -1500, 600), approached from 300 mm above;
* ``FIND_OPTIMAL_ST`` picks T 34: A1 turns to atan2(1500, 1000) = 56.3 deg (>= 0), A2 is negative
  on this robot (limits -140..-5), A3 positive (0..155), and A6 = 56.3 + 120 - 180 = -3.7 deg
  (the flange must add the target's A 120 to the arm's heading; -3.7 + 360 is past +350), so the
  Turn bits (bit n set: axis n+1 negative) are A2's 2 and A6's 32; A4 and A5's bits are free on a
  five-axis palletizer (docs/robot.md) and the search keeps the first, lowest, Turn it finds. Its
  Status is 2, HOME's arm configuration (bit 2 is free: 2 before 6);
* the handshakes in order: GRIPPER_ON ($OUT[33]) after the LIN to XPICK, VACUUM_OK ($IN[42]) from
  the cell, PICK_DONE ($OUT[34]), PART_READY ($IN[41]) dropped by the cell.
"""

from __future__ import annotations

import io
import json

import pytest

from interp.run import RunSinks, make_runtime, run_spec
from robot.trace import TraceWriter
from tests.conftest import REPO_ROOT

CELL = REPO_ROOT / "examples" / "palletizer5"
#: simulated s: past the start of the PTP above the first place (at about 2.64 s)
SIM_S = 2.7


def _run(interp: str):
    out = io.StringIO()
    tw = TraceWriter(out)
    spec = run_spec(CELL / "R1" / "cell.src", inputs=CELL / "cell.yaml", interp=interp, mujoco=False,
                    max_sim_time=SIM_S, submit=[CELL / "R1" / "System" / "sps.sub"])
    rt, _ = make_runtime(spec, RunSinks(trace=tw))
    res = rt.run()
    tw.close()
    events = [json.loads(line) for line in out.getvalue().splitlines()]
    return rt, res, events


@pytest.fixture(scope="module")
def runs():
    return {it: _run(it) for it in ("tree", "vm")}


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_first_cycle_reads_the_group_inputs_and_searches_the_place_configuration(runs, interp):
    rt, res, events = runs[interp]
    assert res.reason == "max_sim_time"
    io_seq = [(e["signal"], e["value"]) for e in events if e["kind"] == "io"]
    assert io_seq[:3] == [("$OUT[37]", True), ("$IN[33]", True), ("$IN[38]", True)]
    order = [("$OUT[33]", True), ("$IN[42]", True), ("$OUT[34]", True), ("$IN[41]", False)]
    at = [io_seq.index(x) for x in order]
    assert at == sorted(at), io_seq
    assert ("$OUT[51]", True) not in io_seq             # a 5 kg bag is not heavy
    assert rt.sysvars.lookup("$LOAD").get().f["M"] == pytest.approx(90.0)
    starts = [e for e in events if e["kind"] == "motion" and e["phase"] == "start"]
    assert len(starts) == 5                             # HOME, above the pick, pick, up, above the place
    above = starts[4]["target"]
    assert (above["X"], above["Y"], above["Z"]) == (1000.0, -1500.0, 900.0)
    assert (above["S"], above["T"]) == (2, 34)


def test_both_interpreters_write_the_same_trace(runs):
    assert runs["tree"][2] == runs["vm"][2]
