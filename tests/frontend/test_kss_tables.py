"""The KSS platform table (krl/semantics/data/kss.yaml): facts with their sources.

The table is derived from KUKA system files of the corpus by krl/survey/derive_tables.py;
these tests check it against the files it names (read in place) and that the checker
uses it: a backup without $operate.dat still knows KSS system variables and types.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml

from krl.semantics.builtins import DATA_DIR, load_builtins
from krl.workspace import check_texts, is_kuka_file
from krl.survey.derive_tables import derive, render

# read at each collection (four processes in make test): libyaml's loader 0.57 -> 0.10 s of CPU
TABLE = yaml.load((DATA_DIR / "kss.yaml").read_text(encoding="utf-8"), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))


def test_every_entry_names_its_source():
    for section in ("types", "variables", "routines", "packages", "programs"):
        assert TABLE[section], section
        for key, info in TABLE[section].items():
            assert re.fullmatch(r"[^:]+\.(dat|src):\d+", info["source"], re.IGNORECASE), (section, key, info)


@pytest.mark.corpus
def test_sources_declare_what_the_table_says(corpus):
    """Each entry's source line declares that name (a sample of every section)."""
    for section in ("types", "variables", "routines", "packages", "package_routines"):
        for key, info in list(TABLE[section].items())[::7]:
            path, line = info["source"].rsplit(":", 1)
            text = (corpus / path).read_text(encoding="latin-1").splitlines()[int(line) - 1]
            bare = key.lstrip("$")
            assert re.search(rf"(?<![\w$])\$?{re.escape(bare)}(?!\w)", text, re.IGNORECASE), (key, text)


@pytest.mark.corpus
def test_table_is_the_derivation_of_the_corpus(corpus):
    assert render(derive(corpus)) == (DATA_DIR / "kss.yaml").read_text(encoding="utf-8")


def test_kss_names_resolve_without_operate_dat():
    """$TORQ_DIFF2 and STRUC ENERGY_DATA_STRUC come from KUKA's $operate.dat (kss.yaml);
    the reference tables do not have them. A backup without $operate.dat uses them."""
    b = load_builtins()
    assert "$TORQ_DIFF2" in b.kss_variables and "operate.dat" in b.sources["$TORQ_DIFF2"]
    ws = check_texts({"t.src": "DEF t()\n  DECL ENERGY_DATA_STRUC e\n  REAL r\n"
                               "  r = $TORQ_DIFF2[1] + e.ENERGY\nEND\n"})
    assert [d for d in ws.diagnostics] == []


def test_backup_declaration_wins_over_the_table():
    """A backup's own $operate.dat-like declaration shadows the table's type."""
    ws = check_texts({"$operate.dat": "DEFDAT $OPERATE PUBLIC\n  DECL BOOL $TORQ_DIFF2\nENDDAT\n",
                      "t.src": "DEF t()\n  REAL r\n  r = $TORQ_DIFF2[1]\nEND\n"})
    assert [d.code for d in ws.diagnostics] == ["E109"]   # BOOL there, not an array


def test_hook_programs_are_kuka_files_and_their_routines_known():
    """masref_user.src under R1/Program is KUKA's hook program: System/masref_main.src calls its
    GLOBAL routines. The table records the file and the routines, each with its source."""
    b = load_builtins()
    assert b.packages["MASREFSTARTG1"][0] == "KSS hook program masref_user.src"
    assert "masref_user.src:8" in b.packages["MASREFSTARTG1"][1]
    assert "masref_main.src" in TABLE["programs"]["MASREF_USER.SRC"]["called_from"]
    assert is_kuka_file("KRC/R1/Program/masref_user.src")
    assert not is_kuka_file("KRC/R1/Program/my_masref_user.src")
    assert not is_kuka_file("KRC/R1/masref_user.src")
