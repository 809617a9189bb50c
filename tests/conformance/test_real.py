"""Real programs of the KRC backups in ../shared/krl-corpus (skipped cleanly when absent).

tree == vm for each program, each run ends with an `end` event and no internal error (a KRL
run-time error or a legitimate stop is a clean outcome; the corpus report of issue 6 classifies
those), each trace keeps the motion limits (issue 15), and each program of the CI sample really runs statements. CI runs an evenly spaced
sample of 4 programs (8 until 2026-11-27; tests/vm/test_differential.py compares every fourth
real program, tree against VM, event for event) among those not listed in corpus/known-invalid.csv (those cannot start:
their files have syntax errors); the whole corpus runs in the `slow` sweep."""

from __future__ import annotations

import functools

import pytest

from conformance import harness as H
from conformance import report as R
from interp.realprograms import cell_of
from interp.runtime.program import parse_module
from recovery.pipeline import load_known_invalid

#: how many programs of the corpus CI runs (evenly spaced among the startable ones)
SAMPLE_SIZE = 4


@functools.cache
def _programs() -> list:
    """(program, backup root) of every runnable corpus program; made when a test needs it, not
    at collection (listing the programs reads every candidate module: about 4 s of CPU in each
    pytest worker, for a list only one worker's four tests use)."""
    return R.real_programs()


def _has_statements(program) -> bool:
    """The program's main routine (its first) has at least one statement."""

    module, errors = parse_module(str(program))
    return not errors and bool(module.routines) and bool(module.routines[0].body)


def _startable(programs):
    """Programs that can start and have something to run: not in corpus/known-invalid.csv (their
    files have syntax errors) and with a non-empty main routine (a backup may hold an empty
    template, such as CollDetect_UserAction.src)."""

    invalid = set(load_known_invalid())
    return [(p, root) for p, root in programs
            if p.relative_to(R.DEFAULT_CORPUS).as_posix() not in invalid and _has_statements(p)]


@functools.cache
def _sample() -> list:
    startable = _startable(_programs())
    return startable[:: max(1, len(startable) // SAMPLE_SIZE)][:SAMPLE_SIZE]


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    """The whole corpus's programs are listed only when the slow sweep is selected (``make
    nightly``; ``make test`` deselects it by ``-m 'not slow'``)."""
    if metafunc.definition.name == "test_real_program_all":
        progs = [p for p, _ in _programs()] if "not slow" not in metafunc.config.getoption("markexpr") else []
        metafunc.parametrize("prog", progs, ids=lambda p: p.stem)


# Known disagreements, listed like the pending cases (strict xfail naming the bug). Keep the
# reason precise; remove the entry when it passes (a strict xfail that passes fails the suite).
KNOWN: dict[str, str] = {}


def _check(prog, request=None, must_run: bool = False):
    st = H.interpreter_status()
    broken = {k: v for k, v in st.items() if v is not None}
    assert not broken, f"interpreter probe failed: {broken}"
    if request is not None and prog.stem in KNOWN:
        request.node.add_marker(pytest.mark.xfail(reason=f"known: {KNOWN[prog.stem]}", strict=True))
    interps = H.available_interpreters()

    cell = cell_of(prog, R.DEFAULT_CORPUS)    # the committed cell file (corpus/cells, issue 22)
    runs = {it: H.run_program(prog, it, max_sim_time=10.0, max_steps=100_000, wall_timeout=120.0,
                              check=False, stimuli=cell)   # the interpreters compared on all real code
            for it in interps}
    for it, r in runs.items():
        prob = H.clean_run_problem(r)
        assert prob is None, f"{prog} on {it}: {prob}"
        bad = [c for c in H.check_limits(r.events) if not c.ok]  # issue 15
        assert not bad, f"{prog} on {it}: {bad[0].detail}"
    if must_run:
        for it, r in runs.items():
            stmts = [e for e in r.events if e.get("kind") == "stmt"]
            assert stmts, f"{prog} on {it} ran no statement: {[e for e in r.events if e.get('kind') == 'end']}"
    if "vm" in runs:
        bad = [c for c in H.compare_runs(runs["tree"], runs["vm"]) if not c.ok]
        assert not bad, "\n".join(f"[{c.name}] {c.detail}" for c in bad)


@pytest.mark.corpus
@pytest.mark.parametrize("index", range(SAMPLE_SIZE), ids=lambda i: f"sample{i}")
def test_real_program_sample(shared_corpus, index, request):
    sample = _sample()
    assert len(sample) == SAMPLE_SIZE, f"the corpus gives {len(sample)} startable programs, not {SAMPLE_SIZE}"
    _check(sample[index][0], request, must_run=True)


@pytest.mark.corpus
@pytest.mark.slow
def test_real_program_all(shared_corpus, prog, request):
    _check(prog, request)
