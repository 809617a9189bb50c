"""BRAKE in an interrupt routine that returns without RESUME (reference §5.17): the held
motion continues from where the robot stands, along its path to its end point, and the
motions the advance run plans after it start where the robot then stands.

Expected facts, derived from the semantics and the machine limits (not from a trace):
the run completes; the braked motion ends at its target; it ends later than the same
motion without the interrupt by at least the time the robot stood still; every cycle keeps
the axis speed limits (robot/limits.py check_trace); the tree interpreter and the VM give the
same trace. ``$ADVANCE = 1`` makes the advance run plan the last motions after the interrupt
routine returned (the case that went wrong: they were planned from the standstill point)."""

from __future__ import annotations

import numpy as np
import pytest

from robot.limits import check_trace

from . import test_interrupt_watch as watch
from .helpers import run_krl

DT = 0.012
HOME = "PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}"
DAT = watch.BRAKER_DAT           # K, NB, NM and AT[20] in prog.dat


def _prog(moves: str, handler: str = "", irq_on: bool = True) -> str:
    return f"""
DEF prog()
  {HOME}
  $ADVANCE = 1
  INTERRUPT DECL 5 WHEN $IN[1] DO Stopper()
  {"INTERRUPT ON 5" if irq_on else ""}
{moves}
  WAIT SEC 0
END
DEF Stopper()
  INTERRUPT OFF 5
  BRAKE
{handler}
  NB = NB + 1
END
"""


def _stim(t: float) -> str:
    return f'stimuli:\n  - at: {t}\n    set: {{"$IN[1]": true}}\n'


def _phases(events) -> dict[int, dict[str, float]]:
    out: dict[int, dict[str, float]] = {}
    for e in events:
        if e["kind"] == "motion":
            out.setdefault(e["id"], {}).setdefault(e["phase"], e["t"])
    return out


def _poses(events) -> tuple[np.ndarray, np.ndarray]:
    ps = [(e["t"], e["axes"], e["tcp"]) for e in events if e["kind"] == "pose"]
    return np.array([p[0] for p in ps]), np.array([p[1] for p in ps], dtype=float), \
        np.array([p[2] for p in ps], dtype=float)


def _at(events, t: float) -> tuple[np.ndarray, np.ndarray]:
    """Axes and TCP of the pose written at time `t`."""
    T, Q, P = _poses(events)
    i = int(np.argmin(np.abs(T - t)))
    assert abs(T[i] - t) < 1e-9
    return Q[i], P[i]


def _standstill(events, t0: float, t1: float) -> float:
    """Time (s) the robot stood still (equal setpoints) within (t0, t1]."""
    T, Q, _ = _poses(events)
    m = (T > t0 + 1e-9) & (T <= t1 + 1e-9)
    idx = np.nonzero(m)[0]
    still = sum(1 for i in idx if i > 0 and np.array_equal(Q[i], Q[i - 1]))
    return still * DT


def _same_trace(a, b) -> None:
    keep = ("motion", "pose", "error", "message", "interrupt")
    ea = [e for e in a.events if e["kind"] in keep]
    eb = [e for e in b.events if e["kind"] in keep]
    assert ea == eb


def _runs(tmp_path, moves, handler, t_stim):
    """The unbraked run and the braked run on both interpreters."""
    base = run_krl(tmp_path, _prog(moves, handler, irq_on=False), DAT, stimuli=_stim(t_stim))
    tree = run_krl(tmp_path, _prog(moves, handler), DAT, stimuli=_stim(t_stim), interp="tree")
    vm = run_krl(tmp_path, _prog(moves, handler), DAT, stimuli=_stim(t_stim), interp="vm")
    assert base.result.reason == "completed", base.result.text
    for r in (tree, vm):
        assert r.result.reason == "completed", r.result.text
        assert r.var("prog", "NB") == 1           # the interrupt routine ran to its end
        assert not r.kinds("error")
    _same_trace(tree, vm)
    return base, tree


def _no_speed_violation(r) -> None:
    rep = check_trace(r.events)
    assert not [v for v in rep.violations if v.what in ("axis_speed", "path")], rep.violations


# the motion ids: 1 is HOME, 2 the braked motion, then the rest of the sequence
PTP_SEQ = "  PTP {A1 150}\n  PTP {A1 0}\n  PTP {A1 30}"
LIN_SEQ = "  LIN {X 400, Y 400, Z 600, A 0, B 90, C 0}\n  PTP {A1 0}\n  PTP {A1 30}"


@pytest.mark.parametrize("handler", ["", "  WAIT SEC 0.2"])
def test_ptp_braked_and_released_continues_and_the_next_ptp_completes(tmp_path, handler):
    base, r = _runs(tmp_path, PTP_SEQ, handler, 0.3)
    pb, ph = _phases(base.events), _phases(r.events)
    # motion 2 ends at its target; the next PTPs start where the robot stands and end at theirs
    q_end2, _ = _at(r.events, ph[2]["end"])
    assert q_end2 == pytest.approx([150, -90, 90, 0, 30, 0], abs=1e-6)
    q_end3, _ = _at(r.events, ph[3]["end"])
    assert q_end3 == pytest.approx([0, -90, 90, 0, 30, 0], abs=1e-6)
    q_end4, _ = _at(r.events, ph[4]["end"])
    assert q_end4 == pytest.approx([30, -90, 90, 0, 30, 0], abs=1e-6)
    # later than without the stop by at least the standstill (plus the ramps)
    still = _standstill(r.events, ph[2]["start"], ph[2]["end"])
    assert still >= (0.2 if handler else DT) - 1e-9
    assert ph[2]["end"] - pb[2]["end"] >= still + 2 * DT - 1e-9
    # the motions after it take their own unbraked durations
    for m in (3, 4):
        assert ph[m]["end"] - ph[m]["start"] == pytest.approx(pb[m]["end"] - pb[m]["start"], abs=1e-9)
    _no_speed_violation(r)


def test_lin_braked_and_released_stays_on_its_line_and_ends_at_its_target(tmp_path):
    base, r = _runs(tmp_path, LIN_SEQ, "  WAIT SEC 0.1", 0.4)
    pb, ph = _phases(base.events), _phases(r.events)
    _, p_start = _at(r.events, ph[2]["start"] - DT)
    _, p_end = _at(r.events, ph[2]["end"])
    assert p_end[:3] == pytest.approx([400, 400, 600], abs=1e-6)
    # every pose of the LIN lies on the straight line from its start to its target
    T, _, P = _poses(r.events)
    a, b = p_start[:3], np.array([400.0, 400.0, 600.0])
    d = (b - a) / np.linalg.norm(b - a)
    for t, p in zip(T, P):
        if ph[2]["start"] <= t <= ph[2]["end"]:
            v = p[:3] - a
            assert np.linalg.norm(v - (v @ d) * d) < 0.01
    still = _standstill(r.events, ph[2]["start"], ph[2]["end"])
    assert still >= 0.1 - 1e-9
    assert ph[2]["end"] - pb[2]["end"] >= still + 2 * DT - 1e-9
    q_end4, _ = _at(r.events, ph[4]["end"])
    assert q_end4[0] == pytest.approx(30, abs=1e-6)
    _no_speed_violation(r)


@pytest.mark.parametrize("moves,targets", [
    ("  PTP {A1 60} C_PTP\n  PTP {A1 120, A2 -60} C_PTP\n  PTP {A1 0, A2 -90}\n  PTP {A1 30}",
     {4: [0, -90, 90, 0, 30, 0], 5: [30, -90, 90, 0, 30, 0]}),
    ("  $APO.CDIS = 50\n  LIN_REL {Y 200} C_DIS\n  LIN_REL {Z -150}\n  " + HOME + "\n  PTP {A1 30}",
     {4: [0, -90, 90, 0, 30, 0], 5: [30, -90, 90, 0, 30, 0]}),
], ids=["C_PTP", "C_DIS"])
def test_braked_in_the_middle_of_a_blend_continues_the_sequence(tmp_path, moves, targets):
    base0 = run_krl(tmp_path, _prog(moves, irq_on=False), DAT, stimuli=_stim(9.0))
    pb = _phases(base0.events)
    assert "blend_start" in pb[2] and pb[2]["blend_end"] > pb[2]["blend_start"]
    t_mid = round(0.5 * (pb[2]["blend_start"] + pb[2]["blend_end"]) / DT) * DT
    base, r = _runs(tmp_path, moves, "  WAIT SEC 0.1", t_mid - 0.006)
    ph = _phases(r.events)
    entry = [e["t"] for e in r.kinds("interrupt") if e["phase"] == "entry"][0]
    assert pb[2]["blend_start"] < entry < pb[2]["blend_end"]   # braked inside the blend
    for m, q in targets.items():
        assert _at(r.events, ph[m]["end"])[0] == pytest.approx(q, abs=1e-6)
    # motion 2 (blended) and motion 3: the endpoint of the approximated one is passed on
    still = _standstill(r.events, ph[2]["start"], ph[3]["end"])
    assert still >= 0.1 - 1e-9
    assert ph[3]["end"] - pb[3]["end"] >= still - 1e-9
    _no_speed_violation(r)


def test_interrupt_routine_that_moves_then_returns_replans_the_held_motion(tmp_path):
    base, r = _runs(tmp_path, PTP_SEQ, "  PTP_REL {A2 5}", 0.3)
    ph = _phases(r.events)
    starts = [e for e in r.kinds("motion") if e["phase"] == "start"]
    rel = [e["id"] for e in starts if e["target"] == {"A2": 5.0}]
    last = [e["id"] for e in starts if e["target"] == {"A1": 30.0}]
    assert len(rel) == 1 and len(last) == 1
    # the routine's PTP_REL runs while motion 2 is held; motion 2 then goes on from there to
    # its target (re-planned), and the rest of the sequence follows
    assert ph[2]["start"] < ph[rel[0]]["start"] < ph[rel[0]]["end"] < ph[2]["end"]
    assert _at(r.events, ph[2]["end"])[0] == pytest.approx([150, -90, 90, 0, 30, 0], abs=1e-6)
    assert _at(r.events, ph[last[0]]["end"])[0] == pytest.approx([30, -90, 90, 0, 30, 0], abs=1e-6)
    _no_speed_violation(r)


#: the report's program: the interrupt test's (a BRAKE routine returning without RESUME, an
#: interrupt on $PRO_MOVE) with a second PTP after its loop
BRAKER = watch.BRAKER.replace("  ENDLOOP\nEND", "  ENDLOOP\n  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}\nEND")
assert BRAKER != watch.BRAKER


def test_the_ptp_planned_while_the_released_motion_runs_starts_where_it_ends(tmp_path):
    """The report's program: the loop plans the second PTP right after the interrupt
    routine returned (the robot stands at A1 ~21 deg then, the first PTP still runs). It
    used to be planned from the standstill point and failed at its first cycle with
    "speed limit exceeded A1: CP path through a singularity"."""
    runs = [run_krl(tmp_path, BRAKER, DAT, stimuli=_stim(0.1), interp=i) for i in ("tree", "vm")]
    for r in runs:
        assert r.result.reason == "completed", r.result.text
        ph = _phases(r.events)
        assert r.var("prog", "NM") == 2 and r.var("prog", "NB") == 1
        assert r.var("prog", "K") <= 100000     # the loop ended on NM: motion 1 ran again
        assert _at(r.events, ph[1]["end"])[0] == pytest.approx([150, -90, 90, 0, 0, 0], abs=1e-6)
        assert _at(r.events, ph[2]["end"])[0] == pytest.approx([0, -90, 90, 0, 0, 0], abs=1e-6)
        _no_speed_violation(r)
    _same_trace(*runs)
