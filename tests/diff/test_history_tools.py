"""krl check, krl fmt and krl graph on every pair of ../shared/krl-history (issue 37), both sides,
read in place (fmt works on a copy in a temporary folder).

* check: both sides checked, no internal error, every file accounted for (checked or named in a
  diagnostic), and the JSON names each side's files.
* fmt: the formatted old side is the same program (``krl diff`` old -> formatted: no change,
  nothing but the files that did not parse left uncompared), and a second fmt changes nothing.
* graph: the map of each side ends every edge at a node, names why each entry point is one, and
  no routine is both an entry point and unreachable; the JSON validates against its schema.

The sweep reads every pair seven times over (about twice the cost of tests/diff/test_history.py,
which stays in ``make test``): it is marked slow and runs in ``make nightly``.
"""

from __future__ import annotations

import json
import shutil

import pytest
from click.testing import CliRunner

from app import main
from tests.conftest import history_pairs
from tests.diff.oracle import krl_files
from tests.test_json_schemas import validate

PAIRS = history_pairs() or ["(absent)"]
pytestmark = pytest.mark.slow


@pytest.fixture(autouse=True)
def patient_parse(monkeypatch):
    """A file's parse time limit well above krl.limits.PARSE_TIMEOUT_S (a loaded machine)."""
    monkeypatch.setattr("krl.limits.PARSE_TIMEOUT_S", 900)
    monkeypatch.setattr("krl.diff.load.PARSE_TIMEOUT_S", 900)


def _no_crash(r) -> None:
    assert "Traceback" not in r.output and "internal error" not in r.output and "E901" not in r.output, r.output


@pytest.mark.parametrize("pair", PAIRS)
def test_check_on_both_sides(shared_history, pair):
    for s in ("old", "new"):
        side = shared_history / pair / s
        r = CliRunner().invoke(main, ["check", "--format", "json", str(side)])
        _no_crash(r)
        assert r.exit_code in (0, 1), r.output
        docs = [json.loads(line) for line in r.stdout.splitlines() if line.startswith("{")]
        assert docs
        for doc in docs:
            validate("check", doc)
        checked = sum(doc["files"] for doc in docs)
        assert checked == len(krl_files(side)), (s, checked)


@pytest.mark.parametrize("pair", PAIRS)
def test_fmt_keeps_the_program(shared_history, pair, tmp_path):
    old = shared_history / pair / "old"
    work = tmp_path / "fmt"
    shutil.copytree(old, work)
    r = CliRunner().invoke(main, ["fmt", str(work)])
    _no_crash(r)
    assert r.exit_code in (0, 2), r.output           # 2: a file that does not parse is left as it is
    r = CliRunner().invoke(main, ["diff", "--format", "json", str(old), str(work)])
    _no_crash(r)
    doc = json.loads(r.stdout)
    assert not doc["changed"], {k: doc[k] for k in ("points", "frames", "values", "routines", "declarations", "motions")}
    assert doc["not_compared"] == []                 # a file fmt did not touch has the same text
    r = CliRunner().invoke(main, ["fmt", "--check", str(work)])
    assert r.exit_code in (0, 2), r.output           # formatting again changes nothing


@pytest.mark.parametrize("pair", PAIRS)
def test_graph_on_both_sides(shared_history, pair):
    for s in ("old", "new"):
        r = CliRunner().invoke(main, ["graph", "--format", "json", str(shared_history / pair / s)])
        _no_crash(r)
        if r.exit_code == 2:                          # a folder of several programs: named
            assert "programs (KRC backups or folders): " in r.output and "name one of them" in r.output
            continue
        assert r.exit_code == 0, r.output
        doc = json.loads(r.stdout)
        validate("graph", doc)
        ids = {n["id"] for n in doc["nodes"]}
        assert all(e["source"] in ids and e["target"] in ids for e in doc["edges"])
        for n in doc["nodes"]:
            assert bool(n["entry"]) == bool(n["entry_kind"]) == (n["id"] in doc["entries"])
            assert not (n["entry"] and n["unreachable"])
        routines = [n for n in doc["nodes"] if n["kind"] == "routine"]
        assert not routines or doc["entries"]
