"""`krl run --interp vm` writes the same trace as `--interp tree`, event for event: the
embedded corpus programs, the conformance cases and the paper's example."""

from __future__ import annotations

from pathlib import Path

import pytest

from .differential import CASES, CORPUS, PAPER, case_options, compare, real_programs


def _check(program, **kw):
    (tree, vm), diff, n = compare(program, **kw)
    assert diff is None, f"first difference at event {diff[0]}:\n tree {diff[1]}\n vm   {diff[2]}"
    assert (tree.reason, tree.text, tree.file, tree.line, tree.context) == \
        (vm.reason, vm.text, vm.file, vm.line, vm.context)
    assert n >= 1


@pytest.mark.parametrize("program", CORPUS, ids=lambda p: p.name)
def test_corpus_program(program):
    _check(program)


@pytest.mark.parametrize("program", CASES, ids=lambda p: p.parent.name)
def test_conformance_case(program):
    _check(program, **case_options(program))


@pytest.mark.skipif(not PAPER.exists(), reason="../shared/examples absent")
@pytest.mark.parametrize("brake_at", [None, 1.0])
def test_paper_example(tmp_path, brake_at):
    from tests.interp.test_paper import STIMULI, _shift_base, _variant

    stim = STIMULI + (f"  - at: {brake_at}\n    set: {{\"$IN[2]\": false}}\n" if brake_at else "")
    inputs = tmp_path / "stimuli.yaml"
    inputs.write_text(stim)
    _check(_variant(tmp_path), inputs=inputs, before=_shift_base, max_sim_time=60)
    _check(PAPER, inputs=inputs, before=_shift_base, max_sim_time=60)


def _submit_of(program):
    from interp.realprograms import submit_of

    return submit_of(program)


REAL = real_programs()


@pytest.mark.skipif(not REAL, reason="../shared/krl-corpus absent")
@pytest.mark.parametrize("program", REAL, ids=lambda p: "/".join(p.parts[-3:]))
def test_real_program(program):
    _check(program, max_sim_time=20, max_steps=100_000, submit=_submit_of(program))


def test_mixed_program():
    """GOTO out of nested FOR, SWITCH on CHAR and ENUM, functions returning structures,
    recursion, whole-array copy, SWRITE, REPEAT/EXIT, RETURN inside FOR, interrupts with
    DISABLE/ENABLE and :OUT handler arguments, ON_ERROR_PROCEED, a FOR counter overflow."""
    here = Path(__file__).parent / "programs"
    _check(here / "mixed.src", inputs=here / "mixed.yaml")
