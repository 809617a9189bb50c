"""The project's BASIS outside a backup (krl/project.py rule 4, issue 34): its $config.dat merges
with a folder's own $config.dat as a backup's would, and a folder's own BASIS module replaces
the project's."""

from __future__ import annotations

from pathlib import Path

import pytest

from interp.run import make_runtime, run_spec
from interp.runtime.program import BASIS_DIR, basis_files
from krl.project import project_of

OWN_CONFIG = """DEFDAT $CONFIG
  DECL INT MY_COUNT = 3
  DECL INT DEF_FLW_PTP = 7
ENDDAT
"""
PROG = """DEF prog()
  BAS(#INITMOV, 0)
  MY_COUNT = MY_COUNT + DEF_FLW_PTP
  $OUT[1] = MY_COUNT == 10
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
END
"""


def _folder(tmp_path: Path, config: str | None) -> Path:
    (tmp_path / "prog.src").write_text(PROG, encoding="utf-8")
    if config is not None:
        (tmp_path / "$config.dat").write_text(config, encoding="utf-8")
    return tmp_path / "prog.src"


def test_the_basis_config_merges_with_the_folders_own(tmp_path):
    prog = _folder(tmp_path, OWN_CONFIG)
    files = basis_files(project_of(prog))
    assert [f.name for f in files] == sorted(p.name for p in BASIS_DIR.iterdir() if p.is_file())
    assert files[0].name.lower() == "$config.dat" and files[0].parent == BASIS_DIR


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_bas_initmov_runs_on_a_folder_with_its_own_config(tmp_path, interp):
    """BAS(#INITMOV) in the project's bas.src reads BASIS variables the folder's $config.dat
    does not declare (DEF_VEL_PTP, ...): they come from the BASIS $config.dat. The folder's own
    declaration of a BASIS name (DEF_FLW_PTP = 7) wins, as the first declaration of a system
    data list does: 3 + 7 = 10."""
    rt, _ = make_runtime(run_spec(_folder(tmp_path, OWN_CONFIG), mujoco=False, interp=interp))
    res = rt.run()
    assert res.reason == "completed", res.text
    assert rt.controller.io.get_out(1) is True


def test_a_folders_own_bas_module_replaces_the_projects(tmp_path):
    prog = _folder(tmp_path, None)
    (tmp_path / "bas.src").write_text("DEF bas(cmd :IN, n :IN)\n  DECL INT cmd, n\nEND\n", encoding="utf-8")
    names = [f.name for f in basis_files(project_of(prog))]
    assert "bas.src" not in names and "$config.dat" in names
