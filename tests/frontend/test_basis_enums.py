"""The BASIS enums the checker knows outside a backup (krl/semantics/data/types.yaml ``basis``)
are the ones KUKA's $config.dat declares: the project's interp/basis/$config.dat, whose ENUM lines
follow the corpus's (every $config.dat of ../shared/krl-corpus and ../shared/krl-history writes
``ENUM OUT_MODETYPE TRIGGER_,CONT_,STOP_``). Before, types.yaml listed
``[SYNC, ASYNC, PULSE, CONT, NONE]`` and a loose program's ``#CONT_`` was a false W205."""

from __future__ import annotations

import re
from pathlib import Path

import yaml

from krl.workspace import check_texts

ROOT = Path(__file__).resolve().parents[2]
ENUM = re.compile(r"^\s*(?:GLOBAL\s+)?ENUM\s+(\w+)\s+([\w,\s]+?)\s*(?:;.*)?$", re.IGNORECASE | re.MULTILINE)


def _config_enums() -> dict[str, list[str]]:
    text = (ROOT / "interp" / "basis" / "$config.dat").read_text(encoding="latin-1")
    return {m.group(1).upper(): [v.strip().upper() for v in m.group(2).split(",")] for m in ENUM.finditer(text)}


def test_the_basis_enums_are_those_of_the_projects_config_dat():
    tables = yaml.safe_load((ROOT / "krl" / "semantics" / "data" / "types.yaml").read_text(encoding="utf-8"))
    config = _config_enums()
    assert "OUT_MODETYPE" in config
    for name, values in tables["basis"]["enums"].items():
        if name.upper() in config:
            assert [v.upper() for v in values] == config[name.upper()], name


def test_kukas_out_mode_values_check_clean_outside_a_backup():
    src = ("DEF out_modes()\n"
           "  DECL ODAT od\n"
           "  od.OUT_MODE = #CONT_\n"
           "  od.OUT_MODE = #STOP_\n"
           "  od.OUT_MODE = #TRIGGER_\n"
           "END\n")
    ws = check_texts({"out_modes.src": src})
    assert [d for d in ws.diagnostics if d.code in ("W205", "E303")] == []
