"""A woken pass parked again without being recorded (issue 86 item 2; interp/runtime/spin.py
``SpinWatch._replays``): a pass whose reads did not change since the pass it repeats writes what
it wrote, the robot moving or not. A parked submit program is woken before anything that may
change what it reads (the robot program going on after a motion or a WAIT SEC, an input about to
change); at its next boundary, when the values of what its pass names (passes.py ``touched``:
data-list variables, signals, I/O elements), its probes (``$POS_ACT`` and the other motion
variables among them, read like any other) and its frames are those it parked with, it is parked
again at once; else it is recorded as before.

Each run is made with the spin watch and without it (tests/interp/helpers.py ``same_run``): the
I/O log, the end and the steps must be the same, no catch-up may leave its pass and no change be
missed; the times are worked out from the programs (12 ms IPO cycles)."""

from __future__ import annotations

import pytest

from interp.runtime.period import REPLAY_FAILS
from krl.semantics.resolve import UNRESOLVED, Storage

from .helpers import run_beside, same_run

INTERPS = ("tree", "vm")

#: back and forth eight times, each motion followed by statements (each wakes the parked submit
#: program: the robot program goes on after its motion); the fifth pair sets the flag the submit
#: program reads, the others change only what it does not read
PROG = """
DEF prog()
  INT i
  FOR i = 1 TO 8
    PTP {A1 30, A2 -90, A3 90, A4 0, A5 30, A6 0}
    COUNT = COUNT + 1
    $OUT[30] = NOT $OUT[30]
    PTP {A1 -30, A2 -90, A3 90, A4 0, A5 30, A6 0}
    IF i == 5 THEN
      MODE = 3
    ENDIF
  ENDFOR
END
"""

DAT = """
DEFDAT prog PUBLIC
  DECL GLOBAL INT COUNT = 0
  DECL GLOBAL INT MODE = 0
ENDDAT
"""

#: reads an input, the robot program's MODE and a signal; writes outputs and a local
SPS = """
DEF sps()
  DECL INT LAST
  LAST = -1
  LOOP
    $OUT[20] = $IN[5]
    IF MODE <> LAST THEN
      LAST = MODE
    ENDIF
    $OUT[21] = MODE > 2
    $OUT[22] = $OUT[20] AND NOT $OUT[21]
  ENDLOOP
END
"""

#: reads the TCP's position: what it writes changes where the TCP crosses Y = 0 (A1 = 0)
SPS_POS = """
DEF sps()
  LOOP
    IF $POS_ACT.Y > 0.0 THEN
      $OUT[23] = TRUE
    ELSE
      $OUT[23] = FALSE
    ENDIF
  ENDLOOP
END
"""

#: moves, then stands while WAIT SECs end (each wakes the submit program: the position stands)
PROG_REST = """
DEF prog()
  INT i
  FOR i = 1 TO 3
    PTP {A1 30, A2 -90, A3 90, A4 0, A5 30, A6 0}
    WAIT SEC 0.1
    WAIT SEC 0.1
    WAIT SEC 0.1
    PTP {A1 -30, A2 -90, A3 90, A4 0, A5 30, A6 0}
    WAIT SEC 0.1
    WAIT SEC 0.1
  ENDFOR
END
"""

STIM = "- at: 2.0\n  set: {\"$IN[5]\": true}\n"


def _changes(log, name: str) -> list:
    return [(round(t, 3), v) for t, n, v, _s in log if n == name]


@pytest.mark.parametrize("interp", INTERPS)
def test_a_woken_pass_whose_reads_stand_is_parked_again_with_the_same_io(tmp_path, interp):
    rt, res = same_run(tmp_path, PROG, SPS, DAT, interp, stimuli=STIM, max_sim_time=30.0)
    assert res.reason == "completed"
    log = rt.controller.io.log
    # the robot program toggles $OUT[30] after each of its eight first motions
    assert len(_changes(log, "$OUT[30]")) == 8
    # the submit program: $IN[5] from the stimulus's cycle (2.004 s: cycle 167), MODE 3 once the
    # robot program set it (after its tenth motion), $OUT[22] up between the two
    assert _changes(log, "$OUT[20]") == [(2.004, True)]
    (t21, v21), = _changes(log, "$OUT[21]")
    assert v21 is True and t21 > 2.004
    assert _changes(log, "$OUT[22]") == [(2.004, True), (t21, False)]
    sw = rt.ff.spin
    # woken whenever the robot program goes on after a motion, or before $IN[5] changes: parked
    # again without a recording at every wake but the two where what it reads changed ($IN[5],
    # MODE; the robot program's COUNT and $OUT[30] are not among its reads), recorded there
    assert sw.why.get("not replayed: changed") == 2, sw.why
    assert sw.wakes >= 8 and sw.replays == sw.wakes - 2, (sw.replays, sw.wakes, sw.why)


@pytest.mark.parametrize("interp", INTERPS)
def test_a_replayed_pass_is_where_an_executed_one_would_be(tmp_path, interp):
    """Shadow mode: the woken pass parked again is not parked but shadowed, and at the end of every
    cycle the statement and frames parking would give are those the task has."""
    rt, res = run_beside(tmp_path, PROG, SPS, DAT, interp=interp, shadow=True, stimuli=STIM, max_sim_time=30.0)
    assert res.reason == "completed"
    sw = rt.ff.spin
    assert sw.replays >= 6 and sw.shadow_checks > 500
    assert sw.shadow_errors == 0, sw.why


@pytest.mark.parametrize("interp", INTERPS)
def test_a_pass_reading_the_position_runs_again_when_it_changed(tmp_path, interp):
    rt, res = same_run(tmp_path, PROG_REST, SPS_POS, "DEFDAT prog PUBLIC\nENDDAT\n", interp, max_sim_time=30.0)
    assert res.reason == "completed"
    log = rt.controller.io.log
    # A1 turns clockwise seen from above: Y < 0 at A1 +30, > 0 at -30, 0 at the start (A1 0).
    # Crossed in each motion but the first (0 -> +30): five changes, the first to TRUE
    ch = _changes(log, "$OUT[23]")
    assert [v for _t, v in ch] == [True, False, True, False, True]
    sw = rt.ff.spin
    # at rest, each WAIT SEC's end wakes the pass and it is parked again (the position stands);
    # moving, the position it reads changed: it is recorded again, never parked again as it was.
    # After three failed replays in a row its next parks are not imaged (period.py REPLAY_FAILS,
    # _to_image): still recorded again at each wake; a replay at rest starts the count again, so
    # each of the six motions fails REPLAY_FAILS replays at least
    assert sw.replays >= 10, (sw.replays, sw.wakes, sw.why)
    changed, left = sw.why.get("not replayed: changed", 0), sw.why.get("not imaged: replays failed", 0)
    assert changed >= 6 * REPLAY_FAILS and left > 0, sw.why
    assert changed + left >= 5 * 10, sw.why    # (a motion is 0.34-0.47 s: 28-39 cycles)


class _Broken:
    """A run's names whose lookups fail with an error of the simulator's own, not a run-time
    error of the program (a bug: it must reach the caller)."""

    def storage_ref(self, place, frame):
        raise TypeError("not a run-time error")


def test_a_name_the_run_cannot_place_is_not_replayed_and_other_errors_are_not_swallowed(tmp_path):
    """period.py ``_place_ref``: the run-time errors of placing a name (names.py: "unknown
    name", an index outside the array) mean "not replayed" (None); any other error is raised."""
    rt, res = run_beside(tmp_path, PROG, SPS, DAT, interp="vm", stimuli=STIM, max_sim_time=1.0)
    assert res.reason == "max_sim_time"
    sw = rt.ff.spin
    out = Storage(UNRESOLVED, name="$OUT")
    assert sw._place_ref(out, 22) is not None and sw._place_ref(out, 22).peek() is False     # $OUT[22]
    # $OUT has 8192 elements (robot/io.py N_DIGITAL): the 8193rd is an index outside the array
    assert sw._place_ref(out, 8193) is None
    assert sw._place_ref(Storage(UNRESOLVED, name="NO_SUCH_NAME_ANYWHERE"), None) is None
    sw.names = _Broken()
    with pytest.raises(TypeError, match="not a run-time error"):
        sw._place_ref(out, 22)
