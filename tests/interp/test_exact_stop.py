"""Exact stop as the KR C4 ends a motion (issue 60; robot/exactstop.py), in both interpreters.

Expected values come from the real controller's motion log (PROG.TXT of every real recording of
../shared/real-traces, KSS 8.5), not from the code under test:
- a motion's END signal comes in IPO cycle ``floor(t_f / 12 ms) + 3``, ``t_f`` the end of its
  interpolation (154 of 154 real motions);
- the next motion STARTs 60 ms (5 cycles) after END (100 of 100);
- Linear_vertical's ``WAIT SEC 2`` between two LINs: START came 167 + 5 cycles after END (the wait
  began 4 cycles after END, ran its ceil(2 / 0.012) = 167 cycles, the motion started one cycle later);
- an output written after an exact-stop motion (an advance-run stop) is written when the main run is
  done with the motion: 4 cycles after END.
"""

from __future__ import annotations

import math

import pytest
from click.testing import CliRunner

from app import main
from robot.exactstop import DONE_CYCLES, END_DELAY_CYCLES, RESTART_CYCLES
from robot.trace import read_trace
from tests.interp.helpers import run_krl

DT = 0.012

PROG = """
DEF prog()
  BAS(#INITMOV, 0)
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  PTP {A1 30}
  PTP {A1 -20}
  WAIT SEC 2
  PTP {A1 0}
  $OUT[4] = TRUE
END
"""


def _motions(run):
    out: dict[int, dict] = {}
    for e in run.kinds("motion"):
        d = out.setdefault(e["id"], {})
        d[e["phase"]] = e["t"]
        if e["phase"] == "end":
            d["reached"] = e["reached"]
    return [out[k] for k in sorted(out)]


def test_the_controllers_rules_as_constants():
    assert (END_DELAY_CYCLES, DONE_CYCLES, RESTART_CYCLES) == (3, 4, 5)


def test_end_restart_wait_and_output_as_the_real_controller(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    run = run_krl(tmp_path / "a", PROG, interp="tree")
    vm = run_krl(tmp_path / "b", PROG, interp="vm")
    assert run.result.reason == vm.result.reason == "completed", (run.result, vm.result)
    m = _motions(run)
    assert _motions(vm) == m and vm.io("$OUT[4]") == run.io("$OUT[4]")     # tree = VM
    assert len(m) == 4
    for k in m:
        # END in cycle floor(t_f / 12 ms) + 3 (t_f: the end of the interpolation)
        assert k["end"] == pytest.approx((math.floor(k["reached"] / DT + 1e-6) + 3) * DT, abs=1e-6)
        assert k["start"] <= k["reached"] < k["end"]
    # the next motion 60 ms after END
    assert m[1]["start"] - m[0]["end"] == pytest.approx(0.060, abs=1e-6)
    assert m[2]["start"] - m[1]["end"] == pytest.approx(0.060, abs=1e-6)
    # WAIT SEC 2 between: 4 + 167 + 1 cycles (Linear_vertical)
    assert m[3]["start"] - m[2]["end"] == pytest.approx((4 + 167 + 1) * DT, abs=1e-6)
    # the output after the last motion: 4 cycles after its END
    (t_out, value), = run.io("$OUT[4]")
    assert value is True and t_out == pytest.approx(m[3]["end"] + 4 * DT, abs=1e-6)
    # the pause between two exact stops, end of interpolation to the next start: 84-96 ms
    pause = m[1]["start"] - m[0]["reached"]
    assert 0.084 - 1e-6 <= pause <= 0.096 + 1e-6



def test_krl_run_override_scales_every_motions_time(tmp_path):
    """``krl run --override 50``: $OV_PRO 50 % from the start; a PTP takes its time at 100 %
    divided by 0.5 (the override scales the time, as the END signals of every recording made at
    85 % show: docs/robot.md)."""
    prog = tmp_path / "prog.src"
    prog.write_text("DEF prog()\n  BAS(#INITMOV, 0)\n  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}\n"
                    "  PTP {A1 40}\nEND\n", encoding="utf-8")
    times = {}
    for pct in (100, 50):
        out = tmp_path / f"t{pct}.jsonl"
        res = CliRunner().invoke(main, ["run", str(prog), "--override", str(pct), "--trace", str(out)])
        assert res.exit_code == 0, res.output
        ev = [e for e in read_trace(out) if e["kind"] == "motion" and e["id"] == 2]
        start = next(e["t"] for e in ev if e["phase"] == "start")
        times[pct] = next(e["reached"] for e in ev if e["phase"] == "end") - start
    assert times[50] == pytest.approx(times[100] / 0.5, abs=2e-6)
    res = CliRunner().invoke(main, ["run", str(prog), "--override", "0"])
    assert res.exit_code == 2 and "--override" in res.output
