"""Shared pytest set-up: paths, the hypothesis profiles, and the rules that keep a green run honest.

Hypothesis profiles (one place for the whole suite): ``ci`` by default, ``nightly`` with
HYPOTHESIS_PROFILE=nightly (``make nightly``). A test whose examples are expensive asks for a
budget with :func:`tests.budget.examples`, which scales with the profile; no test pins its own
fixed count or fixed examples.

Skips cannot hide failures: when CI=true, or when ../shared/krl-corpus is present, a test that
skips is reported as a failure, unless it carries ``@pytest.mark.may_skip("why")`` naming the
condition under which skipping is honest. Tests that take the corpus fixtures are marked
``corpus`` automatically. Every xfail is strict (pyproject.toml: xfail_strict) and names its bug.
"""

from __future__ import annotations

import inspect
import itertools
import os
import shutil
import sys
import tempfile
from pathlib import Path
import csv

import dask
import pytest
from _pytest.mark.expression import Expression
from distributed import LocalCluster
from distributed.utils import get_mp_context
from hypothesis import HealthCheck, settings

from krl import collector
from tests.cpu_profile import CpuProfile
from tests.chromium import DriverPauses, pw  # noqa: F401  (pw: the process's Playwright driver, a fixture)

REPO_ROOT = Path(__file__).resolve().parents[1]
SHARED = REPO_ROOT.parent / "shared"
SHARED_CORPUS = SHARED / "krl-corpus"
SHARED_HISTORY = SHARED / "krl-history"
SHARED_TRACES = SHARED / "real-traces"
SHARED_EVENT_LOGS = SHARED / "event-logs"

# The caches of what the tests run (the one store of the commands and language servers they start: krl/store.py) go to a
# temporary folder of the session, never to the user's cache folder. The process that made it (the
# controller of make test's workers, which inherit it) removes it at the end (pytest_unconfigure):
# each session left about 3 MB in /tmp.
_OWN_CACHE_DIR = None if "KRL_CACHE_DIR" in os.environ else tempfile.mkdtemp(prefix="krl-test-cache-")
if _OWN_CACHE_DIR is not None:
    os.environ["KRL_CACHE_DIR"] = _OWN_CACHE_DIR

# CI draws the same examples every run (derandomize: a red run is the code's, never the draw's);
# the nightly draws new ones, and what it finds becomes a fixed regression test
settings.register_profile("ci", max_examples=50, deadline=None, print_blob=True, derandomize=True,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("nightly", max_examples=2000, deadline=None, print_blob=True,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

CORPUS_FIXTURES = {"shared_corpus", "corpus", "shared_history", "real_traces", "event_logs"}


def corpus_present() -> bool:
    return (SHARED_CORPUS / "MANIFEST.csv").exists()


def skips_are_failures() -> bool:
    """In CI, or wherever the shared corpus is present, everything is expected to run."""
    return os.environ.get("CI", "").lower() == "true" or corpus_present()


@pytest.fixture(scope="session")
def shared_corpus() -> Path:
    """The real corpus, read in place. Absent: the test skips (a failure under CI=true)."""
    if not corpus_present():
        pytest.skip("../shared/krl-corpus is not present")
    return SHARED_CORPUS


def history_pairs() -> list[str]:
    """The pair folders of ../shared/krl-history (``owner__name/NN-sha``), as its MANIFEST.csv
    lists them; [] when it is absent."""

    manifest = SHARED_HISTORY / "MANIFEST.csv"
    if not manifest.exists():
        return []
    with manifest.open(newline="", encoding="utf-8") as f:
        return [f"{row['repo'].replace('/', '__')}/{row['pair']}" for row in csv.DictReader(f)]


def earlier_pair(pair: str) -> bool:
    """`pair` (``owner__name/NN-sha``) is older than its repository's newest pair of
    ../shared/krl-history (the pairs are numbered in commit order; an earlier pair holds earlier
    versions of the same files). A sweep over every pair keeps each repository's newest pair in
    ``make test`` (every repository, so every kind of material) and the earlier ones in
    ``make nightly`` (marked ``slow``: tests/interp/test_outside_runs.py, tests/diff/test_history.py)."""
    repo, name = pair.split("/", 1)
    return name != max(p.split("/", 1)[1] for p in history_pairs() if p.split("/", 1)[0] == repo)


#: A history pair whose new side holds more than this many bytes is compared in ``make nightly``
#: only: today paulovictor237/KUKA-Script's (1.9-2.4 MB a side, 12.5 s of CPU for its newest
#: pair's diff and oracle, 2026-11-28); every other repository's newest pair holds under 0.7 MB.
LARGE_PAIR_BYTES = 1_000_000


def large_pair(pair: str) -> bool:
    """`pair` (``owner__name/NN-sha``)'s new side holds more than :data:`LARGE_PAIR_BYTES`."""
    new = SHARED_HISTORY / pair / "new"
    return sum(f.stat().st_size for f in new.rglob("*") if f.is_file()) > LARGE_PAIR_BYTES


@pytest.fixture(scope="session")
def shared_history() -> Path:
    """The real version histories, read in place. Absent: the test skips (a failure under CI=true)."""
    if not (SHARED_HISTORY / "MANIFEST.csv").exists():
        pytest.skip("../shared/krl-history is not present")
    return SHARED_HISTORY


@pytest.fixture(scope="session")
def real_traces() -> Path:
    """The KUKA Trace recordings of a real KR 3 R540 and of OfficeLite (issue 60), read in place.
    Absent: the test skips (a failure under CI=true)."""
    if not (SHARED_TRACES / "MAP.csv").exists():
        pytest.skip("../shared/real-traces is not present")
    return SHARED_TRACES


@pytest.fixture(scope="session")
def event_logs() -> Path:
    """Three event logs of a real KSS 8.7.8 archive with its am.ini and ArchiveInfo.xml (issue 75),
    read in place. Absent: the test skips (a failure under CI=true)."""
    if not (SHARED_EVENT_LOGS / "MANIFEST.csv").exists():
        pytest.skip("../shared/event-logs is not present")
    return SHARED_EVENT_LOGS


#: what the Dask cluster's worker processes import (:class:`_DaskCluster`): the modules of the functions
#: that the tests send them (krl/cluster.py ``run_batches``: recovery/scan.py ``scan_bytes``,
#: interp/realprograms.py ``run_one``, conformance/report.py, app/check.py ``check_group``,
#: audit/fleet.py), and Dask's own
DASK_PRELOAD = ("distributed", "numpy", "recovery.scan", "interp.realprograms", "conformance.report", "app.check",
                "audit.fleet")


class _DaskCluster:
    """One Dask LocalCluster (two worker processes, one thread each, on loopback) for the tests
    that compare a run on Dask with the local run (tests/audit/test_dask.py,
    tests/conformance/test_on_dask.py, tests/recovery/test_distributed.py; xdist group "dask", so
    that one worker runs them one after the other). Started by the first of them, kept while the
    next test asks for it or is of that group, closed after the last (pytest_runtest_teardown below): an idle
    cluster costs CPU too (docs/architecture.md, "The test suite": 2.5 s per 30 s). Its worker
    processes are forks of multiprocessing's fork server, which imports :data:`DASK_PRELOAD` once,
    not fresh interpreters that each import Dask and the project (Dask's default, ``spawn``):
    docs/architecture.md, "The test suite", has the figures. The workers are not this
    process's children: tests/cpu_profile.py's ``children`` no longer counts them."""

    cluster = None

    @classmethod
    def get(cls):
        if cls.cluster is None:
            with dask.config.set({"distributed.worker.multiprocessing-method": "forkserver"}):
                # Dask's own preload (distributed and its optional packages), replaced by ours before the
                # fork server starts (at the first worker's start)
                get_mp_context().set_forkserver_preload(list(DASK_PRELOAD))
                cls.cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                           dashboard_address=":0", silence_logs=50)
        return cls.cluster

    @classmethod
    def close(cls) -> None:
        if cls.cluster is not None:
            cls.cluster.close()
            cls.cluster = None


@pytest.fixture
def dask_cluster():
    """The Dask LocalCluster of consecutive tests (_DaskCluster)."""
    return _DaskCluster.get()


def _near_dask(item: pytest.Item | None) -> bool:
    """`item` asks for the cluster or is of the tests that do (xdist group "dask")."""
    return item is not None and ("dask_cluster" in getattr(item, "fixturenames", ())
                                 or any(m.args[:1] == ("dask",) for m in item.iter_markers("xdist_group")))


@pytest.hookimpl(trylast=True)
def pytest_runtest_teardown(item: pytest.Item, nextitem: pytest.Item | None) -> None:
    if _DaskCluster.cluster is not None and not _near_dask(nextitem):
        _DaskCluster.close()
    _forget_own_programs(item)


def _forget_own_programs(item: pytest.Item) -> None:
    """Drop from this process's cache of checked workspaces (interp/runtime/program.py
    ``forget_below``) the programs of the test's own ``tmp_path``: no other test asks for them,
    and kept they pushed out the corpus backups that later tests ask for again (a whole make
    test of 9aa4715: 1,041 of the three workers' 1,489 workspace loads were such folders; the palletizer
    backup was loaded 5 times by one worker). Read, never imported here."""
    program = sys.modules.get("interp.runtime.program")
    tmp = getattr(item, "funcargs", {}).get("tmp_path")
    if program is not None and tmp is not None:
        program.forget_below(tmp)


def pytest_configure(config: pytest.Config) -> None:
    config.pluginmanager.register(_XdistGroups(), "krl-xdist-groups")
    config.pluginmanager.register(DriverPauses(), "krl-playwright-driver")   # one driver per process (tests/chromium.py)
    if os.environ.get("KRL_TEST_CPU"):       # where the suite's CPU goes (tests/cpu_profile.py)
        config.pluginmanager.register(CpuProfile(os.environ["KRL_TEST_CPU"]), "krl-cpu-profile")
    config.addinivalue_line("markers", "may_skip(reason): skipping is honest under the named "
                                       "condition even in CI (say which)")
    config.addinivalue_line("markers", "wall_clock: the test waits on the wall clock (a real-time partner, a "
                                       "timeout that must pass); make test runs these on one worker, first")


def pytest_unconfigure(config: pytest.Config) -> None:
    if _OWN_CACHE_DIR is not None:
        shutil.rmtree(_OWN_CACHE_DIR, ignore_errors=True)


def pytest_collection_finish(session: pytest.Session) -> None:
    """What collection loaded (every test module and what it imports: the project, numpy, scipy,
    MuJoCo, Dask) lives as long as the worker: it goes to the collector's permanent generation
    (krl.collector.keep), so that the worker's full collections walk only what the tests make.
    Measured on tests/interp/test_spin.py, test_store.py, tests/lsp/test_cache.py and
    tests/conformance/test_cases.py in one process (-n 0, 2026-11-28): the collector's CPU
    10.1 -> 6.7 s of 57 s, its three full collections 3.9 -> 0.24 s."""
    collector.keep()


def deselects_slow(markexpr: str) -> bool:
    """The ``-m`` expression `markexpr` deselects every test marked ``slow``, whatever its other
    marks: false for each truth of its other names with ``slow`` true (``not slow``, make test's;
    ``slow or not slow``, make nightly's, keeps them). An expression with arguments
    (``slow(reason=...)``) counts as keeping them."""
    if not markexpr:
        return False
    expr = Expression.compile(markexpr)
    others = sorted(expr.idents() - {"slow"})

    def keeps(truth: dict[str, bool]) -> bool:
        def matcher(name: str, /, **kwargs) -> bool:
            if kwargs:
                raise LookupError(name)
            return truth.get(name, False)
        return expr.evaluate(matcher)

    try:
        return not any(keeps({"slow": True, **dict(zip(others, values))})
                       for values in itertools.product((False, True), repeat=len(others)))
    except LookupError:
        return False


#: the test functions marked ``slow`` that this process did not parametrize, because the run's
#: ``-m`` deselects them (pytest_pycollect_makeitem)
UNGENERATED: list[str] = []


@pytest.hookimpl(tryfirst=True)
def pytest_pycollect_makeitem(collector: pytest.Collector, name: str, obj: object):
    """A test function marked ``slow`` (its own mark or its class's or module's) is not made into
    items, nor its parametrizations generated, when the run's ``-m`` expression deselects every
    slow test (make test's ``not slow``): the three workers of make test each generated 2,977 such
    items only to deselect them. make nightly (``slow or not slow``) collects them all."""
    if not inspect.isfunction(obj) or not collector.funcnamefilter(name):
        return None
    slow = (any(getattr(m, "name", None) == "slow" for m in getattr(obj, "pytestmark", ()))
            or collector.get_closest_marker("slow") is not None)
    if slow and _deselects_slow(collector.config):
        UNGENERATED.append(f"{collector.nodeid}::{name}")
        return []
    return None


def _deselects_slow(config: pytest.Config) -> bool:
    """:func:`deselects_slow` of the run's ``-m``, computed once per process."""
    if not hasattr(config, "_krl_deselects_slow"):
        config._krl_deselects_slow = deselects_slow(config.getoption("markexpr"))
    return config._krl_deselects_slow


def pytest_report_collectionfinish(config: pytest.Config) -> str | None:
    if UNGENERATED:
        return f"{len(UNGENERATED)} test functions marked slow not generated (-m {config.getoption('markexpr')!r})"
    return None


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        if CORPUS_FIXTURES & set(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.corpus)


def _own_module_fixtures(item: pytest.Item) -> list[str]:
    """The module-scoped fixtures of `item`'s own module (not a conftest's) that it uses."""
    info = getattr(item, "_fixtureinfo", None)
    if info is None:
        return []
    module = item.nodeid.split("::")[0]
    return [name for name in info.names_closure
            for defs in [info.name2fixturedefs.get(name) or ()] if defs
            and defs[-1].scope == "module" and defs[-1].baseid == module]


#: the xdist group of every test marked ``wall_clock`` (:class:`_XdistGroups`)
WALL_CLOCK_GROUP = "wall-clock"
#: the prefix of the xdist group of a conformance case's tests (:func:`_conformance_case`,
#: :class:`_XdistGroups`)
CASE_GROUP_PREFIX = "conformance-case-"
#: the conformance cases' folder: conformance/harness.py ``CASES_DIR``, not imported here (1.1 s
#: of CPU in pytest's controller, which runs no test); tests/test_suite_groups.py checks they agree
CASES_DIR = REPO_ROOT / "conformance" / "cases"


def _conformance_case(item: pytest.Item) -> str | None:
    """The name of the conformance case `item` is parametrized with (a parameter that is a case
    of conformance/harness.py, its folder or a file in it: ``test_case[001_assign_arith]``,
    ``test_quiet_steps_sweep[001_assign_arith]``), else None."""
    spec = getattr(item, "callspec", None)
    for value in (spec.params.values() if spec is not None else ()):
        path = getattr(value, "path", value)
        if isinstance(path, Path):
            folder = path if path.parent.name == CASES_DIR.name else path.parent
            if folder.parent.name == CASES_DIR.name and folder.parent.resolve() == _CASES_REAL:
                return folder.name
    return None


_CASES_REAL = CASES_DIR.resolve()


class _XdistGroups:
    """``--dist loadgroup`` (make test): the tests marked ``xdist_group(name)`` go to one worker,
    so that the session and module fixtures they share are made once; so do the tests of a module
    that use a module-scoped fixture of that module (their group: the module's path, dotted). pytest-xdist 3.8 marks
    them by suffixing ``item._nodeid`` with ``@name``, which pytest 9 no longer reads (a node's
    id is ``item._id``): without this the groups were spread over both workers and each made
    the group's fixtures (the corpus audit, the documents' run) again. Same suffix, same rule
    (the names of all the item's groups, sorted, joined by ``_``)."""

    @pytest.hookimpl(trylast=True)
    def pytest_collection_modifyitems(self, config: pytest.Config, items: list[pytest.Item]) -> None:
        if not getattr(config.option, "loadgroup", False):    # xdist sets it in its workers (--dist loadgroup)
            return
        # the tests that wait on the wall clock (marked ``wall_clock``: a real-time partner's
        # cycle, a timeout that must pass) are one group, first in the queue: one worker waits
        # through them while the others keep both cores busy. Spread over the three workers
        # they waited at once: in the profile of 21c2cf8 the RSI modules ran on all three
        # workers together and the machine used 0.5-1.1 of its two cores for 80 s
        waiting = [item for item in items if item.get_closest_marker("wall_clock") is not None]
        if waiting:
            chosen = set(map(id, waiting))
            items[:] = waiting + [item for item in items if id(item) not in chosen]
        for item in items:
            names = sorted({str(m.args[0] if m.args else m.kwargs.get("name", "default"))
                            for m in item.iter_markers("xdist_group")})
            if item.get_closest_marker("wall_clock") is not None:
                names = [WALL_CLOCK_GROUP]
            elif not names and _own_module_fixtures(item):
                # the tests of a module that share a module fixture of its own go to one worker,
                # so it is made once: spread over the workers, a fresh clone's suite made the
                # OPC UA run three times, the pendant's trace, tracebench's figures and the
                # recovery's made examples twice each (about 20 s of CPU, 2026-11-28)
                names = [item.nodeid.split("::")[0].replace("/", ".")]
            elif not names and _conformance_case(item) is not None:
                # the tests of one conformance case, whatever their module, go to one worker one
                # after the other, so its program is loaded once (the worker's cache of checked
                # workspaces: interp/runtime/program.py): spread over the workers, the suite
                # loaded the cases 349 times, 120 of them again by the same worker (case 001
                # 8 times; tests/cpu_profile.py, a whole make test of 2026-11-28)
                names = [f"{CASE_GROUP_PREFIX}{_conformance_case(item)}"]
            if names and "@" not in item.nodeid and hasattr(item, "_id"):
                item._id = type(item._id).parse(f"{item.nodeid}@{'_'.join(names)}")


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call):
    outcome = yield
    rep = outcome.get_result()
    if (rep.skipped and not hasattr(rep, "wasxfail") and skips_are_failures()
            and item.get_closest_marker("may_skip") is None):
        reason = rep.longrepr[2] if isinstance(rep.longrepr, tuple) else str(rep.longrepr)
        rep.outcome = "failed"
        rep.longrepr = (f"skipped where it must run (CI=true or ../shared/krl-corpus present): {reason}\n"
                        "Fix the missing dependency, or mark the test may_skip with the honest condition.")


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector):
    outcome = yield
    rep = outcome.get_result()
    if rep.skipped and skips_are_failures():
        reason = rep.longrepr[2] if isinstance(rep.longrepr, tuple) else str(rep.longrepr)
        rep.outcome = "failed"
        rep.longrepr = f"module skipped where it must run (CI=true or ../shared/krl-corpus present): {reason}"


def pytest_terminal_summary(terminalreporter, exitstatus, config) -> None:
    """Close with the counts, so a log shows at a glance what really ran."""
    if config.option.collectonly:
        return
    stats = terminalreporter.stats
    # the figures a test states (``record_property("summary", text)``: the variants of issue 59
    # count their runs), printed whether the test passed or not, from any xdist worker
    for key in ("passed", "failed"):
        for rep in stats.get(key, []):
            for name, value in getattr(rep, "user_properties", ()):
                if name == "summary" and getattr(rep, "when", "call") == "call":
                    terminalreporter.write_line(f"{rep.nodeid}: {value}")
    counts = {k: len(stats.get(k, [])) for k in ("passed", "failed", "error", "skipped", "xfailed", "xpassed")}
    terminalreporter.write_line(
        "test counts: " + ", ".join(f"{v} {k}" for k, v in counts.items()) +
        f" (skips count as failures: {'yes' if skips_are_failures() else 'no'})")
