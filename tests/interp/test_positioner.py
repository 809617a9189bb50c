"""A two-axis positioner (tilt and turn, as KUKA's KP2) built from KUKA's documentation
(robot/data/kr16_2_positioner.dat: no public backup holds a positioner), its workpiece base linked
the way KSS's BASIS links it, moving the TCP in the world as an independent computation predicts at
10 points (issue 64), on the VM (make test) and the tree interpreter (make nightly).

The run goes through a real KR C4 BASIS: a copy of a corpus backup's R1/System (khrzysio's KSS 8
bas.src and $config.dat) with the positioner's machine data as R1/Mada/$machine.dat, and in
$config.dat the positioner registered as KSS 8 registers an external kinematic:
``MACHINE_DEF[2]`` with ``MECH_TYPE #EASYS``, ``COOP_KRC_INDEX 1`` and a calibrated ``ROOT``,
``MACHINE_FRAME_DAT[1].MACH_DEF_INDEX 2`` (base 1 is measured on it), ``BASE_DATA[1]`` the base
on the plate, ``TOOL_DATA[1]`` a 200 mm tool. The program uses KUKA's inline forms (``FDAT_ACT``,
``BAS(#PTP_PARAMS, 100)``): bas.src's ``FRAMES`` reads ``MACHINE_FRAME_DAT`` and calls
``EX_BASE``, which sets ``$BASE = EK(MACHINE_DEF[2].ROOT, MACHINE_DEF[2].MECH_TYPE, BASE_DATA[1])``.

The prediction is written here from the positioner's geometry, not from the machine-data chain:
the tilt axis is the horizontal line through (1300, 0, 700) along -Y of the root (TA1KR's C 90
turns Z onto -Y), the turn axis the vertical line through X 1300 (TA2A1's C -90 turns it back up)
tilted with it, the plate's face at Z 640 at E1 = E2 = 0 (700 - 180 + 120); so the plate is
``ROOT · Turn_about(tilt line, E1) · Turn_about(turn line, E2) · Trans(1300, 0, 640)``, and the
TCP must be ``plate · BASE_DATA[1] · P`` for the programmed P, at each motion's end (the axes read
back from the trace, through the KR 16-2's chain of tests/interp/test_track_turntable.py), to
0.01 mm. Each LIN's TCP, expressed in the base at the cycle's E1/E2, stays on the straight line
between its points (the path is straight in the moving base).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from interp.run import make_runtime, run_spec, RunSinks
from robot.machine import ROBOT_LIBRARY
from robot.trace import TraceWriter
from tests.interp.helpers import Run
from tests.interp.test_track_turntable import INTERPS, _rot, _T, flange, kuka

BACKUP = "khrzysio__KRC4_test"
ROOT = (-40.0, 25.0, 0.0, 3.0, 0.0, 0.0)          # MACHINE_DEF[2].ROOT, the calibrated root point
BASE1 = (30.0, -20.0, 15.0, 20.0, 0.0, 0.0)       # BASE_DATA[1], measured on the plate
TOOL1 = (0.0, 0.0, 200.0, 0.0, 0.0, 0.0)          # TOOL_DATA[1]
#: (E1 tilt, E2 turn, X, Y, Z in base 1): the TCP points down onto the plate ({A 0, B 0, C 180})
POINTS = [(0, 0, 0, 0, 150), (15, 30, 60, -40, 120), (40, -90, -50, 30, 180), (30, -60, 0, 80, 100),
          (-10, 120, 90, 0, 160), (5, 150, -70, -60, 140), (50, -150, 40, 50, 200), (35, -120, -30, -30, 110),
          (20, 60, 70, 70, 130), (25, 90, 0, -90, 170)]


def _frame(v) -> str:
    return "{X %r,Y %r,Z %r,A %r,B %r,C %r}" % tuple(float(x) for x in v)


def make_backup(tmp_path: Path, corpus: Path) -> Path:
    """The backup described in the module docstring; returns its program."""
    shutil.copytree(corpus / BACKUP / "R1" / "System", tmp_path / "R1" / "System")
    (tmp_path / "R1" / "Mada").mkdir(parents=True)
    shutil.copy(ROBOT_LIBRARY / "kr16_2_positioner.dat", tmp_path / "R1" / "Mada" / "$machine.dat")
    cfg = tmp_path / "R1" / "System" / "$config.dat"
    text = cfg.read_text(encoding="latin-1")
    for prefix, new in (
            ("MACHINE_DEF[2]=", f'MACHINE_DEF[2]={{NAME[] "KP2",COOP_KRC_INDEX 1,PARENT[] "WORLD",'
                                f'ROOT {_frame(ROOT)},MECH_TYPE #EASYS,GEOMETRY[] " "}}'),
            ("MACHINE_FRAME_DAT[1]=", 'MACHINE_FRAME_DAT[1]={MACH_DEF_INDEX 2,PARENT[] "KP2",GEOMETRY[] " "}'),
            ("BASE_DATA[1]=", f"BASE_DATA[1]={_frame(BASE1)}"),
            ("TOOL_DATA[1]=", f"TOOL_DATA[1]={_frame(TOOL1)}")):
        lines = [ln for ln in text.splitlines() if ln.startswith(prefix)]
        assert len(lines) == 1, prefix            # the backup declares each once
        text = text.replace(lines[0], new)
    cfg.write_text(text, encoding="latin-1")
    src = ["DEF kp2()", "  PTP {A1 0, A2 -90, A3 90, A4 0, A5 60, A6 0, E1 0, E2 0}"]
    dat = ["DEFDAT kp2", 'DECL FDAT FP={TOOL_NO 1,BASE_NO 1,IPO_FRAME #BASE,POINT2[] " "}',
           "DECL PDAT PPD={VEL 100.0,ACC 100.0,APO_DIST 100.0,APO_MODE #CDIS}",
           "DECL LDAT LCP={VEL 2.0,ACC 100.0,APO_DIST 100.0,APO_FAC 50.0,ORI_TYP #VAR,CIRC_TYP #BASE,JERK_FAC 50.0}"]
    for i, (e1, e2, x, y, z) in enumerate(POINTS):
        dat.append(f"DECL E6POS XP{i}={{X {x},Y {y},Z {z},A 0.0,B 0.0,C 180.0,E1 {e1},E2 {e2},E3 0.0,E4 0.0,"
                   f"E5 0.0,E6 0.0}}")
        if i % 2 == 0:
            src += ["  PDAT_ACT=PPD", "  FDAT_ACT=FP", "  BAS(#PTP_PARAMS,100)", f"  PTP XP{i}"]
        else:
            src += ["  LDAT_ACT=LCP", "  FDAT_ACT=FP", "  BAS(#CP_PARAMS,2.0)", f"  LIN XP{i}"]
    prog = tmp_path / "R1" / "Program" / "kp2.src"
    prog.parent.mkdir()
    prog.write_text("\n".join(src + ["END", ""]), encoding="utf-8")
    prog.with_suffix(".dat").write_text("\n".join(dat + ["ENDDAT", ""]), encoding="utf-8")
    return prog


def _about(point, direction, deg) -> np.ndarray:
    """A turn by `deg` about the line through `point` along `direction`."""
    R = _rot(direction, deg)
    p = np.asarray(point, dtype=float)
    return _T(R, p - R @ p)


def plate(e1: float, e2: float) -> np.ndarray:
    """The positioner's plate in $WORLD at tilt `e1` and turn `e2` (the module docstring)."""
    return (kuka(*ROOT) @ _about((1300, 0, 700), (0, -1, 0), e1) @ _about((1300, 0, 0), (0, 0, 1), e2)
            @ _T(p=(1300, 0, 640)))


@pytest.mark.parametrize("interp", INTERPS)
def test_a_two_axis_positioner_carries_the_base_the_tcp_follows(tmp_path, shared_corpus, interp):
    prog = make_backup(tmp_path, shared_corpus)
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(prog, max_sim_time=120.0, mujoco=False, check=False, interp=interp),
                         RunSinks(trace=tw))
    run = Run(rt, rt.run(), tw)
    assert run.result.reason == "completed", run.result
    poses = [(e["t"], e["axes"]) for e in run.kinds("pose")]
    assert all(len(q) == 8 for _, q in poses)          # A1..A6, E1, E2
    at = dict(poses)
    motions = run.kinds("motion")
    ends = [e for e in motions if e["phase"] == "end"][1:]
    assert len(ends) == len(POINTS) == 10
    tool = kuka(*TOOL1)
    for (e1, e2, x, y, z), end in zip(POINTS, ends):
        q = at[end["t"]]
        assert (q[6], q[7]) == (pytest.approx(e1, abs=1e-6), pytest.approx(e2, abs=1e-6))
        expected = plate(q[6], q[7]) @ kuka(*BASE1) @ kuka(x, y, z, 0, 0, 180)
        np.testing.assert_allclose(flange(q[:6]) @ tool, expected, atol=1e-2)
    # each LIN: the TCP in the base of the cycle's E1/E2 stays on the line between its two points
    starts = [e for e in motions if e["phase"] == "start"][1:]
    checked = 0
    for i, (start, end) in enumerate(zip(starts, ends)):
        if start["type"] != "LIN":
            continue
        a, b = np.array(POINTS[i - 1][2:], dtype=float), np.array(POINTS[i][2:], dtype=float)
        for t, q in poses:
            if start["t"] <= t <= end["t"]:
                p = (np.linalg.inv(plate(q[6], q[7]) @ kuka(*BASE1)) @ flange(q[:6]) @ tool)[:3, 3]
                u = np.clip(np.dot(p - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
                assert np.linalg.norm(p - (a + u * (b - a))) < 1e-2, (i, t)
                checked += 1
    assert checked > 100
