"""A KR C4 backup without ``$machine.dat`` that names its robot only in ``$config.dat``'s
``MACHINE_DEF[1]`` (issue 72 item 6): the robot's identity comes from there.

The case as the issue saw it (a cell nobody here has seen): ``MACHINE_DEF[1]={NAME[] "KR 10
R1440-2",...}`` and no ``R1/Mada``: ``krl robot show`` exited 2 ("no R1/Mada/$machine.dat"),
``krl run`` drove a KR 6 R900 without saying why not the named robot, and the report's cover
said "robot not named". KR 10 R1440-2 is neither in the catalogue (``krl robot list``: KR 10
R1420, KR 10 R1100-2, ...) nor in the public descriptions of ../shared/robots, so the stand-in
(the KR 6 R900 sixx, robot/data/kr6_r900.yaml) is driven and every place says so; a model the
catalogue has (KR 10 R1420) is driven itself. ``MACHINE_DEF`` is KUKA's ``MACHINE_DEF_T`` of a
KR C4's ``$config.dat`` (``STRUC MACHINE_DEF_T CHAR NAME[24], ...``; the corpus's palletizer
``System/$config.dat`` lines 65 and 415, where ``NAME[] "Robot"`` names no model).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from app import main
from interp.run import robot_for

CONFIG = """DEFDAT  $CONFIG
STRUC MACHINE_DEF_T CHAR NAME[24],INT COOP_KRC_INDEX,CHAR PARENT[24],FRAME ROOT,ESYS MECH_TYPE,CHAR GEOMETRY[255]
DECL MACHINE_DEF_T MACHINE_DEF[16]
MACHINE_DEF[1]={NAME[] "%s",COOP_KRC_INDEX 1,PARENT[] "WORLD",ROOT {X 0.0,Y 0.0,Z 0.0,A 0.0,B 0.0,C 0.0},MECH_TYPE #ROBOT,GEOMETRY[] " "}
MACHINE_DEF[2]={NAME[] " ",COOP_KRC_INDEX 0,PARENT[] " ",ROOT {X 0.0,Y 0.0,Z 0.0,A 0.0,B 0.0,C 0.0},MECH_TYPE #NONE,GEOMETRY[] " "}
ENDDAT
"""

CELL = "DEF cell()\n  $OUT[1] = TRUE\nEND\n"

STAND_IN = ("KR 10 R1440-2, the robot the backup names ({cfg}:4 MACHINE_DEF[1]), is neither in the "
            "catalogue (krl robot list) nor in the robot library: the KR 6 R900 sixx stands in")


def _backup(tmp: Path, name: str) -> Path:
    """A KR C4 backup: R1/System/$config.dat naming `name` in MACHINE_DEF[1], no R1/Mada."""
    (tmp / "R1" / "System").mkdir(parents=True)
    (tmp / "R1" / "Program").mkdir(parents=True)
    (tmp / "R1" / "System" / "$config.dat").write_text(CONFIG % name)
    (tmp / "R1" / "Program" / "cell.src").write_text(CELL)
    return tmp


def test_robot_show_says_the_named_robot_is_missing_and_which_stands_in(tmp_path):
    b = _backup(tmp_path, "KR 10 R1440-2")
    res = CliRunner().invoke(main, ["robot", "show", str(b)])
    assert res.exit_code == 0, res.output
    lines = res.output.splitlines()
    assert lines[0] == "robot      KR 6 R900 sixx"
    assert f"named      {STAND_IN.format(cfg=b / 'R1' / 'System' / '$config.dat')}" in lines


def test_the_run_summary_says_it_too(tmp_path):
    b = _backup(tmp_path, "KR 10 R1440-2")
    res = CliRunner().invoke(main, ["run", str(b / "R1" / "Program" / "cell.src"), "--max-sim-time", "1"])
    assert res.exit_code == 0, res.output
    [robot] = [line for line in res.output.splitlines() if line.startswith("  robot ")]
    assert robot.startswith("  robot      KR 6 R900 sixx (")
    assert robot.endswith("; " + STAND_IN.format(cfg=b / "R1" / "System" / "$config.dat"))


def test_the_report_cover_names_the_robot_and_the_stand_in(tmp_path):
    b = _backup(tmp_path / "b", "KR 10 R1440-2")
    out = tmp_path / "r.html"
    res = CliRunner().invoke(main, ["report", str(b), "-o", str(out)])
    assert res.exit_code == 0, res.output
    html = out.read_text(encoding="utf-8")
    assert "robot not named" not in html and "<th>robot</th><td>not named" not in html
    # the printed cover's robot row (HTML-escaped: the $config.dat path is the backup's)
    assert "KR 10 R1440-2 (named by $config.dat MACHINE_DEF[1]; neither in the catalogue nor in the " \
           "robot library: the runs drive the KR 6 R900 sixx in its place)" in html


def test_a_named_robot_of_the_catalogue_is_the_one_driven(tmp_path):
    b = _backup(tmp_path, "KR 10 R1420")
    machine = robot_for(b / "R1" / "Program" / "cell.src")
    assert machine.name == "KR 10 R1420"
    res = CliRunner().invoke(main, ["robot", "show", str(b)])
    assert res.exit_code == 0, res.output
    cfg = b / "R1" / "System" / "$config.dat"
    assert res.output.splitlines()[0] == "robot      KR 10 R1420"
    assert f"named      KR 10 R1420, the robot the backup names ({cfg}:4 MACHINE_DEF[1])" in res.output.splitlines()


@pytest.mark.parametrize("name", ["Robot", " "])
def test_a_name_that_is_no_kuka_model_names_no_robot(tmp_path, name):
    """The palletizer's ``NAME[] "Robot"`` (and an empty name) is no model: as before, no robot."""
    b = _backup(tmp_path, name)
    res = CliRunner().invoke(main, ["robot", "show", str(b)])
    assert res.exit_code == 2
    assert "no R1/Mada/$machine.dat" in res.output
    assert robot_for(b / "R1" / "Program" / "cell.src").name == "KR 6 R900 sixx"


def test_the_history_backup_without_machine_data_drives_the_robot_it_names(shared_history):
    """The one backup of ../shared that has no R1/Mada but a model in MACHINE_DEF[1]:
    rawpython__kukaKRLmagic 03-e616379d/new ($config.dat:402, "KR 120 R2700-2", as the backup's
    older versions' $machine.dat name it); --inputs auto chose the 4-axis KR 180 palletizer by
    reach before. The catalogue has the KR 120 R2700-2."""
    b = shared_history / "rawpython__kukaKRLmagic" / "03-e616379d" / "new"
    machine = robot_for(b / "R1" / "cell.src", inputs="auto")
    assert machine.name == "KR 120 R2700-2"
    assert machine.named == f"KR 120 R2700-2, the robot the backup names ({b / 'R1' / 'System' / '$config.dat'}:402 MACHINE_DEF[1])"


def _flat(tmp: Path, name: str) -> Path:
    """The files of :func:`_backup` lying flat in one folder (issue 85 item 6): $config.dat naming
    `name` in MACHINE_DEF[1] beside cell.src, no System, Program or Mada folder."""
    tmp.mkdir(parents=True, exist_ok=True)
    (tmp / "$config.dat").write_text(CONFIG % name)
    (tmp / "cell.src").write_text(CELL)
    return tmp


def test_a_flat_layout_names_its_robot_as_the_backup_does(tmp_path):
    """Issue 85 item 6: the robot named in MACHINE_DEF[1] was used for R1/System/$config.dat but
    not for the same files lying flat: `krl robot show` exited 2 ("no R1/Mada/$machine.dat") and
    the run drove the KR 6 R900 sixx without a word. KR 10 R1420 is in the catalogue."""
    b = _flat(tmp_path / "flat", "KR 10 R1420")
    res = CliRunner().invoke(main, ["robot", "show", str(b)])
    assert res.exit_code == 0, res.output
    assert res.output.splitlines()[0] == "robot      KR 10 R1420"
    assert (f"named      KR 10 R1420, the robot the backup names ({b / '$config.dat'}:4 MACHINE_DEF[1])"
            in res.output.splitlines())
    assert robot_for(b / "cell.src").name == "KR 10 R1420"
    assert robot_for(b / "cell.src", workspace=b).name == "KR 10 R1420"


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_flat_layout_runs_the_robot_it_names(tmp_path, interp):
    """The run of the flat cell (issue 85 item 6) drives KR 10 R1420, on both interpreters; a
    flat cell naming a model of neither catalogue nor library says the KR 6 R900 stands in."""
    b = _flat(tmp_path / "flat", "KR 10 R1420")
    res = CliRunner().invoke(main, ["run", str(b / "cell.src"), "--interp", interp, "--max-sim-time", "1"])
    assert res.exit_code == 0, res.output
    [robot] = [line for line in res.output.splitlines() if line.startswith("  robot ")]
    assert robot.startswith("  robot      KR 10 R1420 ("), robot
    other = _flat(tmp_path / "other", "KR 10 R1440-2")
    res = CliRunner().invoke(main, ["run", str(other / "cell.src"), "--interp", interp, "--max-sim-time", "1"])
    [robot] = [line for line in res.output.splitlines() if line.startswith("  robot ")]
    assert robot.endswith("; " + STAND_IN.format(cfg=other / "$config.dat")), robot
