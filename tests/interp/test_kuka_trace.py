"""KUKA Trace in a run (issue 60): TraceStart and TraceStop (KUKA's bas.src; the project's BASIS
outside a backup) write $TRACE, and the run's trace marks each recording with `recording` events,
identically in both interpreters; `krl check` accepts the recorded programs of ../shared/real-traces.

Expected values: the KRL of KUKA's TraceStart (every KSS 8 bas.src of the corpus: stop, set
CONFIG and NAME, start, wait for the state, WAIT SEC 0.012) and TraceStop (WAIT SEC 0.012, stop);
the recorded programs start their first motion 24 ms after TraceStart (PROG.TXT: TIME 0.024).
"""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from app import main
from tests.interp.helpers import run_krl

PROG = """
DEF prog()
  BAS(#INITMOV, 0)
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  TraceStart("New_KSS_8.5_1.xml", "first")
  PTP {A1 10}
  TraceStop()
  $OUT[2] = $TRACE.STATE == #T_END
  TraceStart("other.xml", "second")
  $OUT[3] = $TRACE.STATE == #TRIGGERED
  PTP {A1 0}
  TraceStop()
END
"""


def _recording_events(run):
    return [(e["phase"], e.get("name"), e.get("config"), e["t"]) for e in run.kinds("recording")]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_trace_start_and_stop_mark_the_recordings(tmp_path, interp):
    run = run_krl(tmp_path, PROG, interp=interp)
    assert run.result.reason == "completed", run.result
    marks = _recording_events(run)
    assert [m[:3] for m in marks] == [("start", "first", "New_KSS_8.5_1.xml"), ("stop", "first", "New_KSS_8.5_1.xml"),
                                      ("start", "second", "other.xml"), ("stop", "second", "other.xml")]
    assert run.io("$OUT[2]") == [(pytest.approx(marks[1][3]), True)]
    assert run.io("$OUT[3]")[0][1] is True
    starts = [e["t"] for e in run.kinds("motion") if e["phase"] == "start"]
    # the first motion of a recording starts two cycles after TraceStart started it (WAIT SEC 0.012)
    assert starts[1] - marks[0][3] == pytest.approx(0.024)
    # TraceStop waits for the motion before it: the recording stops after its end
    ends = [e["t"] for e in run.kinds("motion") if e["phase"] == "end"]
    assert marks[1][3] > ends[1]


def test_both_interpreters_write_the_same_trace(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    tree = run_krl(tmp_path / "a", PROG, interp="tree")
    vm = run_krl(tmp_path / "b", PROG, interp="vm")
    drop = ("stmt", "call", "return")
    strip = lambda evs: [{k: v for k, v in e.items() if k != "file"} for e in evs if e["kind"] not in drop]  # noqa: E731
    assert strip(tree.events) == strip(vm.events)


KUKAS = """
DEF prog()
  BAS(#INITMOV, 0)
  TraceStart("cfg.xml", "kukas")
  PTP {A1 5, A2 -90, A3 90, A4 0, A5 0, A6 0}
  TraceStop()
END

GLOBAL DEF TraceStart(StringDef :IN, StringName :IN)
DECL CHAR StringDef[], StringName[]
   $TRACE.MODE = #T_STOP
   WAIT FOR $TRACE.STATE == #T_END
   $TRACE.CONFIG[] = StringDef[]
   $TRACE.NAME[] = StringName[]
   $TRACE.MODE = #T_START
   WAIT FOR $TRACE.STATE <> #T_END
   WAIT SEC 0.012
END

GLOBAL DEF TraceStop()
   WAIT SEC 0.012
   $TRACE.MODE = #T_STOP
   WAIT FOR $TRACE.STATE == #T_END
END
"""


def test_a_programs_own_trace_start_marks_too(tmp_path):
    """A program bringing KUKA's TraceStart (a backup's bas.src: the same $TRACE writes) marks the
    recording through $TRACE as the project's BASIS does."""
    run = run_krl(tmp_path, KUKAS, interp="vm")
    assert [m[:3] for m in _recording_events(run)] == [("start", "kukas", "cfg.xml"), ("stop", "kukas", "cfg.xml")]


def test_the_recorded_programs_check(real_traces, tmp_path):
    for name in ("PTP_vel_test", "PTP_acc_test", "Circular", "movement_test_lin"):
        res = CliRunner().invoke(main, ["check", str(real_traces / "KRL Programs" / f"{name}.src")])
        assert res.exit_code == 0, res.output
        assert "no errors" in res.output
