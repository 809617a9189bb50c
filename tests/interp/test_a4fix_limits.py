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
