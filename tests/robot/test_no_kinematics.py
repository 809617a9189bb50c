"""A robot the model refuses never stops a tool that does not move it (issue 34): `krl cell init`,
`krl check`, `krl graph` and `krl diff` on a backup whose machine data cannot make a robot
($KINCLASS #SPECIAL, refused with the variable and its value) work as on any backup, and never
build the inverse kinematics; `krl run`, which moves the robot, names the refusal.

The backup is a copy (in tmp_path) of a corpus backup with its $machine.dat edited."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

import robot.kinematics
import robot.mada
from app import main

BACKUP = "rawpython__kukaKRLmagic"


@pytest.fixture()
def refused(tmp_path, shared_corpus) -> Path:
    root = tmp_path / "backup"
    shutil.copytree(shared_corpus / BACKUP, root)
    for p in root.rglob("*"):
        p.chmod(0o755 if p.is_dir() else 0o644)
    mada = root / "R1" / "Mada" / "$machine.dat"
    text = mada.read_text(encoding="latin-1")
    assert "$KINCLASS=#STANDARD" in text
    mada.write_text(text.replace("$KINCLASS=#STANDARD", "$KINCLASS=#SPECIAL"), encoding="latin-1")
    return root


@pytest.fixture()
def no_kinematics(monkeypatch):
    """Building any inverse kinematics, or reading any machine data, fails the test."""
    def refuse(*_a, **_k):
        raise AssertionError("a tool that does not move the robot built its kinematics")

    monkeypatch.setattr(robot.kinematics.Kinematics, "_choose_form", refuse)
    monkeypatch.setattr(robot.mada, "machine_from_values", refuse)


def _krl(*args: str):
    return CliRunner().invoke(main, list(args), catch_exceptions=False)


def test_run_names_the_variable_and_value_it_refuses(refused):
    res = _krl("run", str(refused / "R1" / "cell.src"), "--max-sim-time", "1")
    assert res.exit_code == 2
    assert "$machine.dat:" in res.output and "$KINCLASS=#SPECIAL" in res.output


def test_cell_init_needs_no_kinematics(refused, no_kinematics):
    res = _krl("cell", "init", str(refused))
    assert res.exit_code == 0, res.output
    assert res.output.startswith("# Starter cell file")
    assert "the backup's own robot" in res.output          # it has machine data of its own


def test_check_graph_diff_need_no_kinematics(refused, no_kinematics, tmp_path):
    res = _krl("check", str(refused))
    assert "Traceback" not in res.output and res.exit_code in (0, 1), res.output
    assert "files" in res.output.splitlines()[-1]
    dot = tmp_path / "map.dot"
    res = _krl("graph", str(refused), "-o", str(dot))
    assert res.exit_code == 0, res.output
    assert dot.read_text(encoding="utf-8").startswith(("digraph", "strict digraph"))
    other = tmp_path / "other"
    shutil.copytree(refused, other)
    cell = other / "R1" / "cell.src"
    cell.write_text(cell.read_text(encoding="latin-1") + "\nDEF added_by_test()\n  $OUT[77]=TRUE\nEND\n",
                    encoding="latin-1")
    res = _krl("diff", str(refused), str(other))
    assert res.exit_code in (0, 1), res.output
    assert "cell.src" in res.output
