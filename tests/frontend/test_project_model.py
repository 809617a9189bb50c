"""One project model (krl/project.py, issue 38): one module pairing, one list of KUKA's system
folders, one cell-file loader."""

from __future__ import annotations

from pathlib import Path

import pytest

from krl.project import SYSTEM_DIRS, is_submit_file, is_system_path, modules_of, system_folder_of
from krl.workspace import check_texts, module_files
from robot.controller import Controller
from robot.stimuli import load_cell


def test_modules_pair_src_or_sub_with_dat():
    files = ["/b/P/x.src", "/b/P/X.dat", "/b/P/x.sub", "/b/P/y.dat", "/b/Q/x.dat", "/b/P/sps.sub"]
    got = [(name, str(code) if code else None, str(dat) if dat else None) for name, code, dat in modules_of(files)]
    assert got == [("x", "/b/P/x.src", "/b/P/X.dat"),          # the first code file pairs
                   ("x", "/b/P/x.sub", None),                   # the second is a module of its own
                   ("y", None, "/b/P/y.dat"),
                   ("x", None, "/b/Q/x.dat"),                   # another folder, another module
                   ("sps", "/b/P/sps.sub", None)]
    assert is_submit_file("/b/P/SPS.SUB") and not is_submit_file("/b/P/x.src")


def test_the_workspace_and_krl_check_file_pair_alike(tmp_path):
    for name, text in (("x.src", "DEF x()\nEND\n"), ("x.dat", "DEFDAT x\nENDDAT\n"), ("x.sub", "DEF x()\nEND\n")):
        (tmp_path / name).write_text(text, encoding="utf-8")
    ws = check_texts({str(tmp_path / n): (tmp_path / n).read_text() for n in ("x.src", "x.dat", "x.sub")})
    units = [(Path(u.src.path).name if u.src else None, Path(u.dat.path).name if u.dat else None) for u in ws.units]
    assert units == [("x.src", "x.dat"), ("x.sub", None)]
    assert [p.name for p in module_files(tmp_path / "x.dat")] == ["x.src", "x.dat"]
    assert [p.name for p in module_files(tmp_path / "x.sub")] == ["x.sub"]


def test_one_list_of_system_folders():
    assert SYSTEM_DIRS == ("system", "tp", "mada", "steu")
    assert system_folder_of("KRC/R1/Mada/$machine.dat") == "mada"
    assert system_folder_of("KRC/R1/TP/P00.src") == "tp"
    assert system_folder_of("KRC/R1/Program/cell.src") is None
    assert is_system_path("R1/System/bas.src") and is_system_path("R1/Program/$custom.dat")
    assert not is_system_path("R1/Program/tp_like.src")


def test_the_controller_reads_no_cell_file(tmp_path):
    f = tmp_path / "cell.yaml"
    f.write_text("stimuli:\n  - when: {line: 3, reached: true}\n    set: {\"$IN[1]\": true}\n", encoding="utf-8")
    with pytest.raises(TypeError, match="load_cell"):
        Controller(mujoco=False, stimuli=str(f))
    cell = load_cell(f)
    assert cell.stimuli[0].reached_default
    ctl = Controller(mujoco=False, stimuli=cell)
    # `reached: true` is the robot's own in-position distance, set by the controller of the run
    assert ctl.signals.stimuli[0].reached_mm == ctl.machine.in_pos_car_mm
