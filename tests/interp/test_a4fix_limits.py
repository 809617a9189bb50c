"""A five-axis palletizer's A4 limits read in KRL (issue 85 item 2): the machine data say
``$SOFTN_END[4]=-350``, ``$SOFTP_END[4]=350`` and ``$DEF_A4FIX=TRUE``. The controller's
``$SOFTN_END``/``$SOFTP_END`` are the machine data's values (reference §8.2), so KRL reads -350 and
350 on both interpreters, and ``krl robot show`` names them with ``$machine.dat`` as their source;
the model's own fixing of A4 at 0 (robot/kinematics/palletizer5.py) is a separate fact, said as
such. A program's own Status/Turn search that checks A4 against those limits accepts A4 = 0.

The machine data are robot/data/kr180_r3200_pa5.dat with its A4 limits set as in the issue's
archive (written to the test's folder)."""

from __future__ import annotations

import pytest

from interp.run import RunSinks, make_runtime, run_spec
from robot.machine import ROBOT_LIBRARY
from robot.mada import load_mada
from robot.show import show_lines
from tests.interp.helpers import Run, write

PA5 = ROBOT_LIBRARY / "kr180_r3200_pa5.dat"

SRC = """
DEF lim4()
  lo4 = $SOFTN_END[4]
  hi4 = $SOFTP_END[4]
  lo1 = $SOFTN_END[1]
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  a4 = $AXIS_ACT.A4
  inside = (a4 > $SOFTN_END[4]) AND (a4 < $SOFTP_END[4])
END
"""
DAT = """
DEFDAT lim4
  REAL lo4, hi4, lo1, a4
  BOOL inside
ENDDAT
"""


@pytest.fixture(scope="module")
def pa5_350(tmp_path_factory):
    text = PA5.read_text(encoding="utf-8")
    for old, new in (("$SOFTN_END[4]=0.0", "$SOFTN_END[4]=-350.0"), ("$SOFTP_END[4]=0.0", "$SOFTP_END[4]=350.0")):
        assert text.count(old) == 1
        text = text.replace(old, new)
    assert "BOOL $DEF_A4FIX=TRUE" in text
    f = tmp_path_factory.mktemp("pa5") / "$machine.dat"
    f.write_text(text, encoding="utf-8")
    return load_mada(f)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_krl_reads_the_machine_data_s_a4_limits(tmp_path, pa5_350, interp):
    prog = write(tmp_path, "lim4.src", SRC)
    write(tmp_path, "lim4.dat", DAT)
    rt, _ = make_runtime(run_spec(prog, max_sim_time=30.0, mujoco=False, check=False, interp=interp,
                                  robot=pa5_350), RunSinks())
    run = Run(rt, rt.run(), None)
    assert run.result.reason == "completed", run.result
    v = lambda name: run.var("lim4", name)      # noqa: E731
    assert (v("lo4"), v("hi4"), v("lo1")) == (-350.0, 350.0, -185.0)   # the file's values
    assert v("a4") == 0.0 and v("inside") is True


def test_robot_show_names_the_data_s_a4_limits_and_the_fixing_apart(pa5_350):
    lines = show_lines(pa5_350)
    a4 = next(line for line in lines if line.split()[:1] == ["A4"])
    assert "-350.0 ..   350.0" in a4 and "held at 0 by $DEF_A4FIX" in a4, a4
    # the model still holds A4 at 0: a target with A4 = 30 is outside its limits
    assert pa5_350.joints[3].limit_deg == (0.0, 0.0)


SEARCH_SRC = """
DEF search()
  DECL E6POS target, p
  DECL E6AXIS ax, start
  INT s, t, st
  $TOOL = $NULLFRAME
  $BASE = $NULLFRAME
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}
  start = $AXIS_ACT
  target = FORWARD({A1 -40, A2 -80, A3 100, A4 0, A5 30, A6 10}, st)
  accepted = 0
  found_s = -1
  FOR s = 0 TO 7
    FOR t = 0 TO 7
      p = target
      p.S = s
      p.T = t
      ax = INVERSE(p, start, st)
      IF st == 0 THEN
        IF (ax.A4 > $SOFTN_END[4]) AND (ax.A4 < $SOFTP_END[4]) THEN
          accepted = accepted + 1
          IF found_s < 0 THEN
            found_s = s
            found_t = t
          ENDIF
        ENDIF
      ENDIF
    ENDFOR
  ENDFOR
  IF found_s < 0 THEN
    found_s = 2
    found_t = 0
  ENDIF
  p = target
  p.S = found_s
  p.T = found_t
  PTP p
  a1 = $AXIS_ACT.A1
END
"""
SEARCH_DAT = """
DEFDAT search
  INT accepted, found_s, found_t
  REAL a1
ENDDAT
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_program_s_own_status_turn_search_finds_a_configuration(tmp_path, pa5_350, interp):
    """The issue's chain: a Status/Turn search of a target that keeps the configurations whose A4
    lies strictly inside $SOFTN_END[4] .. $SOFTP_END[4] (the issue's program tries all 512 S/T;
    this one the 64 of S and the turn bits of A1..A3, to stay cheap). Read as 0 .. 0 it kept none, the
    program fell back to S 2, T 0 (A1 >= 0 asked of a target at A1 = -40) and stopped at
    "software limit switch +A1"; read as -350 .. 350 it keeps the configurations the robot
    reaches and the PTP ends at A1 = -40 (the target's axes, by hand)."""
    prog = write(tmp_path, "search.src", SEARCH_SRC)
    write(tmp_path, "search.dat", SEARCH_DAT)
    rt, _ = make_runtime(run_spec(prog, max_sim_time=60.0, mujoco=False, check=False, interp=interp,
                                  robot=pa5_350), RunSinks())
    run = Run(rt, rt.run(), None)
    assert run.result.reason == "completed", run.result
    v = lambda name: run.var("search", name)      # noqa: E731
    assert v("accepted") > 0 and v("found_s") >= 0
    assert v("found_t") & 1                       # the found turn asks A1 < 0 (reference §8.1)
    assert v("a1") == pytest.approx(-40.0, abs=1e-6)
