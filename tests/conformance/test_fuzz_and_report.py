"""The differential fuzzer (small budget: 20 programs) and the report writer."""

from __future__ import annotations

import hashlib
import os
import json
import shutil

import pytest
from hypothesis import HealthCheck, given, settings

from conformance import fuzz as F
from tests.budget import examples
from conformance import harness as H
from conformance import report as R
from krl.syntax.parse import parse_file


@settings(max_examples=examples(10), deadline=None, suppress_health_check=list(HealthCheck))
@given(F.programs())
def test_generated_programs_parse(tmp_path_factory, prog):
    src, _ = prog
    d = tmp_path_factory.mktemp("fz")
    (d / "program.src").write_text(src, encoding="utf-8")
    res = parse_file(d / "program.src", keep_tree=False)
    assert res.ok, src


def test_fuzz_20_programs():
    """With the VM: tree == vm for 20 programs. Without it: the tree interpreter runs 20
    generated programs without an internal error (smoke test; the stats say which mode)."""
    st = H.interpreter_status()
    assert st == {"tree": None, "vm": None}, f"interpreter probe failed: {st}"
    stats = F.run_fuzz(20, save_cases=False)
    assert stats["programs"] >= 20 or stats["failures"], stats
    assert not stats["failures"], stats["failures"][0]
    assert stats["mode"] == "tree == vm" and stats["agree"] == stats["programs"]


def test_fuzz_failure_is_saved_as_a_case(tmp_path):
    d = F.save_case("DEF program()\nEND\n", None, "tree: internal error: X", root=tmp_path)
    case = H.load_case(d)
    assert case.pending and case.expect["fuzz"] is True and (d / "program.src").exists()


def test_report_files(tmp_path):
    assert H.interpreter_status()["tree"] is None, H.interpreter_status()

    pend_dir = tmp_path / "cases" / "999_pending_copy"
    shutil.copytree(H.CASES_DIR / "002_if_else", pend_dir)
    with open(pend_dir / "expect.yaml", "a", encoding="utf-8") as fh:
        fh.write('status: pending\nreason: "a copy marked pending for this test"\n')
    cases = [H.load_case(H.CASES_DIR / n) for n in ("001_assign_arith", "057_lin_c_dis")] + [H.load_case(pend_dir)]
    outcomes = R.run_cases(cases)
    tmp_path = tmp_path / "out"
    s = R.write_report(tmp_path, outcomes, {"programs": 3, "tree_ok": 3, "agree": None, "mode": "x",
                                            "failures": []}, [])
    j = json.loads((tmp_path / "summary.json").read_text())
    for k in ("cases", "passed", "tree_vm_agree", "fuzz_programs", "fuzz_agree", "real_programs", "real_agree"):
        assert k in j
    assert j["cases"] == 3 and s["pending"] == ["999_pending_copy"]
    assert s["pending_passing"] == ["999_pending_copy"]
    md = (tmp_path / "report.md").read_text()
    html = (tmp_path / "report.html").read_text()
    assert "057_lin_c_dis" in md and "999_pending_copy" in html and "a copy marked pending" in md
    assert (tmp_path / "plots" / "057_lin_c_dis.png").stat().st_size > 1000
    assert not (tmp_path / "plots" / "001_assign_arith.png").exists()


class RecordingCheck:
    """A stand-in for the fuzz property's check of one program: appends the program's hash and
    the checking process's id to `log` and fails the programs that contain `fails_on`. A
    module-level class, so that the worker processes receive it (pickled by reference)."""

    def __init__(self, log, fails_on=None):
        self.log, self.fails_on = log, fails_on

    def __call__(self, src, stim, interps):
        with open(self.log, "a", encoding="utf-8") as fh:
            fh.write(hashlib.sha1((src + (stim or "")).encode()).hexdigest() + f" {os.getpid()}\n")
        return f"tree: made to fail ({self.fails_on})" if self.fails_on and self.fails_on in src else None


#: the draws of the run without a failure, in one process and in two workers (30 until 2026-11-27:
#: 12.3 s of CPU in make test; the assertions are the same for any number)
DRAWS = 12


# the failing draw's shrinking, twice, is the suite's costliest call (165 s on a worker under load
# 16, 2026-11-26): make nightly takes it, make test the run without a failure
@pytest.mark.parametrize("fails_on", [None, pytest.param("B_AND", marks=pytest.mark.slow)])
def test_fuzz_in_worker_processes_is_the_run_in_one(monkeypatch, tmp_path, fails_on):
    """run_fuzz(jobs=2) checks the programs that run_fuzz(jobs=1) checks, in worker processes,
    and ends with the same stats, failure and shrunk minimal program (the check itself replaced
    by a recorder, so that this test is about the draws, not the interpreters)."""
    got = {}
    n = DRAWS if fails_on is None else 30        # 30: the draws that reach a B_AND program
    for jobs in (1, 2):
        log = tmp_path / f"checked-{jobs}.txt"
        monkeypatch.setattr(F, "_check_program", RecordingCheck(log, fails_on))
        stats = F.run_fuzz(n, interps=["tree", "vm"], save_cases=False, jobs=jobs)
        got[jobs] = stats, [line.split() for line in log.read_text().splitlines()]
    (one, checked_one), (two, checked_two) = got[1], got[2]
    assert one == two
    assert one["programs"] == n if fails_on is None else one["failures"]
    here = str(os.getpid())
    assert {pid for _h, pid in checked_one} == {here}
    if fails_on is None:
        # the same programs as one after the other (DRAWS draws; hypothesis may draw one text
        # twice), each checked once, all in the workers
        assert len(checked_one) == DRAWS
        assert {h for h, _ in checked_two} == {h for h, _ in checked_one}
        assert len(checked_two) == len({h for h, _ in checked_two})
        assert here not in {pid for _h, pid in checked_two}
    else:
        assert "B_AND" in one["failures"][0].split("--- minimal program ---")[1]
        # the draws up to the failure were checked in the workers, the shrinking here, the same way
        assert {h for h, _ in checked_one} <= {h for h, _ in checked_two}
        assert here in {pid for _h, pid in checked_two} and len({pid for _h, pid in checked_two}) > 1
