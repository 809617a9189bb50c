"""krl plot of a cell's result (robot/cellplot.py, issue 89): every robot's TCP path in the cell's
world, each stream's pose placed by the robot's base. By hand: R1 (at the origin) starts at the
KR 6 R900's HOME flange (525, 0, 890) (../shared/docs/robot-model.md §9); R2 stands at X 2000 turned
180° about Z, so its HOME flange is at (2000 - 525, 0, 890) and the end point of its PTP, which its
own trace gives in its $BASE = $WORLD, (x, y, z) is at (2000 - x, -y, z) of the cell's world."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from app import main
from robot.cellplot import cell_paths

R1 = "DEF r1()\n  PTP {A1 60, A2 -90, A3 90, A4 0, A5 0, A6 0}\nEND\n"
R2 = "DEF r2()\n  PTP {A1 -60, A2 -60, A3 90, A4 0, A5 0, A6 0}\nEND\n"
CELL = "robots:\n  R1: {program: r1.src}\n  R2: {program: r2.src, base: [2000, 0, 0, 180, 0, 0]}\n"


def test_krl_plot_draws_every_robot_of_a_cell_in_the_cells_world(tmp_path):
    (tmp_path / "r1.src").write_text(R1)
    (tmp_path / "r2.src").write_text(R2)
    (tmp_path / "cell.yaml").write_text(CELL)
    trace = tmp_path / "run.jsonl"
    ran = CliRunner().invoke(main, ["run", str(tmp_path / "cell.yaml"), "--trace", str(trace), "--interp", "vm"])
    assert ran.exit_code == 0, ran.output
    paths = cell_paths(tmp_path / "run.cell.json")
    assert list(paths) == ["R1", "R2"]
    assert paths["R1"][0] == pytest.approx([525, 0, 890], abs=1e-3)
    assert paths["R2"][0] == pytest.approx([1475, 0, 890], abs=1e-3)
    end = next(json.loads(line)["point"] for line in (tmp_path / "run.R2.jsonl").read_text().splitlines()
               if '"phase":"end"' in line.replace(" ", ""))
    assert paths["R2"][-1] == pytest.approx([2000 - end[0], -end[1], end[2]], abs=1e-3)
    out = CliRunner().invoke(main, ["plot", str(tmp_path / "run.cell.json")])
    assert out.exit_code == 0, out.output
    assert (tmp_path / "run.cell.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    (tmp_path / "run.R2.jsonl").unlink()
    gone = CliRunner().invoke(main, ["plot", str(tmp_path / "run.cell.json")])
    assert gone.exit_code == 1 and "run.R2.jsonl" in gone.output and "Traceback" not in gone.output
