"""`krl run --interp vm` writes the same trace as `--interp tree`, event for event: the
embedded corpus programs, the real programs of the corpus and the paper's example. The
conformance cases are compared event for event where they are checked
(tests/conformance/test_cases.py ``test_case``)."""

from __future__ import annotations

import functools
from pathlib import Path

import pytest

from interp.realprograms import submit_of
from tests.interp.test_paper import STIMULI, _shift_base, _variant

from .differential import CORPUS, FIRST_BACKUP, PAPER, compare, first_difference, real_programs, run_trace


def _check(program, **kw):
    (tree, vm), diff, n = compare(program, **kw)
    assert diff is None, f"first difference at event {diff[0]}:\n tree {diff[1]}\n vm   {diff[2]}"
    assert (tree.reason, tree.text, tree.file, tree.line, tree.context) == \
        (vm.reason, vm.text, vm.file, vm.line, vm.context)
    # both refusing a program alike compares nothing: the program must start and run a statement
    assert "cannot start" not in (tree.text or ""), f"{program}: {tree.text}"
    assert tree.steps >= 1, f"{program}: no statement ran ({tree.reason} {tree.text})"


@pytest.mark.parametrize("program", CORPUS, ids=lambda p: p.name)
def test_corpus_program(program):
    _check(program)


@pytest.mark.skipif(not PAPER.exists(), reason="../shared/examples absent")
@pytest.mark.parametrize("brake_at", [None, 1.0])
def test_paper_example(tmp_path, brake_at):
    stim = STIMULI + (f"  - at: {brake_at}\n    set: {{\"$IN[2]\": false}}\n" if brake_at else "")
    inputs = tmp_path / "stimuli.yaml"
    inputs.write_text(stim)
    _check(_variant(tmp_path), inputs=inputs, before=_shift_base, max_sim_time=60)
    _check(PAPER, inputs=inputs, before=_shift_base, max_sim_time=60)


def _submit_of(program):
    return submit_of(program)


@functools.cache
def _real() -> list:
    """The corpus's real programs, listed when a shard runs, not at collection (listing reads every
    candidate module: about 2.7 s of CPU in each pytest worker)."""
    return real_programs()


SHARDS = 8
# How many programs of each shard (the real programs [k::8]) really ran: at least 20 statements, or reached a
# motion. Today's figures (2026-11-21; max_sim_time 20 s, 100 000 statements): 60 of the 87
# programs; the other 27 are files with syntax errors (10 unfinished khrzysio programs listed
# in corpus/known-invalid.csv and one more), programs that stop at an early genuine error, and
# one empty program. A change that makes programs stop earlier fails here.
RAN_AT_LEAST = [10, 7, 6, 8, 8, 6, 8, 7]
MIN_STATEMENTS = 20


def _ran(result, events) -> bool:
    return result.steps >= MIN_STATEMENTS or any(e["kind"] == "motion" for e in events)


#: make test runs shard 4 (the real programs [4::8]: every eighth program, 11 of the 87, every
#: backup: ChinaMilling 3, Palletizer 3, khrzysio 4, rawpython 1 -- shards 0-3 hold no rawpython
#: program; 8 of the 11 run 20+ statements or reach a motion), make nightly all eight (the same
#: check on each shard). CPU of each shard (-n 0, load 4-8, 2026-11-26): 9.9 7.1 8.6 11.4 6.6 2.5
#: 5.3 4.9 s; make test ran shards 0 and 4 until 2026-11-29 (16.5 s; 12.6 s in a whole run)
SHARDS_IN_MAKE_TEST = (4,)


@pytest.mark.corpus
@pytest.mark.parametrize("shard", [pytest.param(k, marks=FIRST_BACKUP if k in SHARDS_IN_MAKE_TEST else pytest.mark.slow)
                                   for k in range(SHARDS)])
def test_real_programs(shared_corpus, shard):
    """tree == vm on every real program of the shard, and enough of them really ran. ``make
    test`` runs shard 4 alone (:data:`SHARDS_IN_MAKE_TEST`: every eighth program, every backup of
    the corpus among them), ``make nightly`` all eight."""
    real = _real()
    assert len(real) == 87, f"{len(real)} real programs found (87 expected: is ../shared/krl-corpus complete?)"
    ran, problems = [], []
    for program in real[shard::SHARDS]:
        kw = dict(max_sim_time=20, max_steps=100_000, submit=_submit_of(program))
        tree, tree_ev = run_trace(program, "tree", **kw)
        vm, vm_ev = run_trace(program, "vm", **kw)
        name = "/".join(program.parts[-3:])
        diff = first_difference(tree_ev, vm_ev)
        if diff is not None:
            problems.append(f"{name}: first difference at event {diff[0]}:\n tree {diff[1]}\n vm   {diff[2]}")
        elif (tree.reason, tree.text, tree.file, tree.line) != (vm.reason, vm.text, vm.file, vm.line):
            problems.append(f"{name}: tree ended {tree.reason} {tree.text!r}, vm {vm.reason} {vm.text!r}")
        if _ran(tree, tree_ev):
            ran.append(name)
    assert not problems, "\n".join(problems)
    print(f"shard {shard}: {len(ran)} of {len(real[shard::SHARDS])} programs ran")
    assert len(ran) >= RAN_AT_LEAST[shard], (
        f"only {len(ran)} programs of shard {shard} ran {MIN_STATEMENTS}+ statements or reached a "
        f"motion (today: {RAN_AT_LEAST[shard]}): {ran}")


def test_mixed_program():
    """GOTO out of nested FOR, SWITCH on CHAR and ENUM, functions returning structures,
    recursion, whole-array copy, SWRITE, REPEAT/EXIT, RETURN inside FOR, interrupts with
    DISABLE/ENABLE and :OUT handler arguments, ON_ERROR_PROCEED, a FOR counter overflow."""
    here = Path(__file__).parent / "programs"
    _check(here / "mixed.src", inputs=here / "mixed.yaml")
