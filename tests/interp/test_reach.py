"""`krl check --reach PROGRAM` (issue 64; interp/reach.py): the taught points the robot cannot reach
and the motions that collide with the cell, found without running the program. A hand-built
program: a point 2.65 m out (beyond the KR 6 R900's 0.9 m), a point whose T asks A1 >= 0 where the
point lies at A1 < 0, a LIN down through the cell's table, a PTP beside it; each reported at its
file:line, the free motions not."""

from __future__ import annotations

from click.testing import CliRunner

from app import main
from interp.reach import reach_check
from tests.interp.helpers import refuse_runs, write
from tests.robot.test_collision import R_WRIST

SRC = """DEF reachprog()
  PTP XHOME1
  PTP XP1
  LIN XP2
  LIN XP3
  PTP XFAR
  PTP XWRONG
END
"""
DAT = """DEFDAT reachprog
  DECL E6AXIS XHOME1={A1 0,A2 -90,A3 90,A4 0,A5 90,A6 0,E1 0,E2 0,E3 0,E4 0,E5 0,E6 0}
  DECL E6POS XP1={X 650,Y 250,Z 700,A 180,B 0,C 180,S 2,T 3,E1 0,E2 0,E3 0,E4 0,E5 0,E6 0}
  DECL E6POS XP2={X 650,Y 0,Z 700,A 180,B 0,C 180,S 2,T 3,E1 0,E2 0,E3 0,E4 0,E5 0,E6 0}
  DECL E6POS XP3={X 650,Y 0,Z 300,A 180,B 0,C 180,S 2,T 3,E1 0,E2 0,E3 0,E4 0,E5 0,E6 0}
  DECL E6POS XFAR={X 2650,Y 0,Z 300,A 180,B 0,C 180,S 2,T 2,E1 0,E2 0,E3 0,E4 0,E5 0,E6 0}
  DECL E6POS XWRONG={X 650,Y 250,Z 700,A 180,B 0,C 180,S 2,T 2,E1 0,E2 0,E3 0,E4 0,E5 0,E6 0}
ENDDAT
"""
CELL = "geometry:\n  - {name: table, box: [300, 300, 40], frame: [650, 0, 400, 0, 0, 0]}\n"


def test_reach_reports_points_and_motions_at_their_lines(tmp_path, monkeypatch):
    refuse_runs(monkeypatch)        # the program is loaded, not run: no controller (issue 76)
    prog = write(tmp_path, "reachprog.src", SRC)
    write(tmp_path, "reachprog.dat", DAT)
    cell = write(tmp_path, "cell.yaml", CELL)
    rep = reach_check(prog, inputs=cell)
    dat, src = tmp_path / "reachprog.dat", tmp_path / "reachprog.src"
    assert (rep.points, rep.motions) == (6, 6)
    assert rep.problems[0].startswith(f"{dat}:6: unreachable: XFAR on KR 6 R900 sixx: no configuration")
    assert rep.problems[1].startswith(f"{dat}:7: unreachable: XWRONG on KR 6 R900 sixx: with its S 2 and T 2: "
                                      f"software limit switch +A1")
    # the LIN from XP2 down to XP3 meets the table (its top at Z 420; the flange's sphere, R_WRIST
    # around the flange, first touches it with the flange at Z 420 + R_WRIST or a sample below)
    assert rep.problems[2].startswith(f"{src}:5: collision: LIN XP3: ") and "cell:table" in rep.problems[2]
    z = float(rep.problems[2].split("Z ")[1].split(" mm")[0])
    assert 420.0 < z <= 420.0 + R_WRIST
    assert len(rep.problems) == 3
    res = CliRunner().invoke(main, ["check", "--reach", str(prog), "--inputs", str(cell)])
    assert res.exit_code == 1 and res.output.splitlines()[-1] == (
        "reach: 6 taught point(s) and 6 motion(s) checked on KR 6 R900 sixx; 3 problem(s)")
    free = CliRunner().invoke(main, ["check", "--reach", str(prog), "--robot", "KR 210 R2700-2"])
    assert "XFAR" not in free.output and "collision" not in free.output
