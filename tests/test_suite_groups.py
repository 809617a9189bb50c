"""The suite's own set-up (tests/conftest.py): under ``--dist loadgroup`` (make test) a test
marked ``xdist_group(name)`` is sent to one worker with the rest of its group, so the group's
session and module fixtures are made once (pytest-xdist's rule: the node id suffixed with
``@name``, which tests/conftest.py applies where pytest 9 ignores xdist's own suffix)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest
from _pytest.nodeid import NodeId      # pytest 9's node id (what a node's nodeid is read from)

from conformance.harness import CASES_DIR, load_cases
from tests.conftest import CASE_GROUP_PREFIX, _XdistGroups, deselects_slow
from tests.conftest import CASES_DIR as CONFTEST_CASES_DIR

pytestmark = [pytest.mark.xdist_group("suite-groups")]


@pytest.mark.parametrize("n", [1, 2])
def test_a_grouped_test_carries_its_group_under_loadgroup(request, n):
    if getattr(request.config.option, "loadgroup", False):
        assert request.node.nodeid.endswith("@suite-groups"), request.node.nodeid
    else:                            # one process, or another --dist: ids are pytest's own
        assert "@" not in request.node.nodeid


class Item:
    """What the grouping hook reads of a pytest item: its id, its xdist groups, ``wall_clock``."""

    def __init__(self, nodeid, groups, waits=False, fixtures=(), params=None):
        self._id = NodeId.parse(nodeid)
        if params is not None:           # a parametrized test's: pytest's CallSpec2 ``params``
            self.callspec = SimpleNamespace(params=params)
        self._marks = [pytest.mark.xdist_group(g).mark for g in groups] + [pytest.mark.wall_clock.mark] * waits
        # the fixtures it uses, as (name, scope, where defined): pytest's FuncFixtureInfo's two fields
        self._fixtureinfo = SimpleNamespace(
            names_closure=[name for name, _scope, _where in fixtures],
            name2fixturedefs={name: [SimpleNamespace(scope=scope, baseid=where)] for name, scope, where in fixtures})

    @property
    def nodeid(self):
        return str(self._id)

    def iter_markers(self, name):
        return iter(m for m in self._marks if m.name == name)

    def get_closest_marker(self, name):
        return next(self.iter_markers(name), None)


class Config:
    class option:
        loadgroup = True


def test_the_grouping_rule_is_xdists():
    """Several groups: their names sorted, joined by ``_`` (pytest-xdist 3.8, remote.py)."""

    items = [Item("tests/a.py::t[1]", ["zeta", "alpha"]), Item("tests/a.py::u", []),
             Item("tests/a.py::v@given", ["x"])]
    _XdistGroups().pytest_collection_modifyitems(Config(), items)
    assert [i.nodeid for i in items] == ["tests/a.py::t[1]@alpha_zeta", "tests/a.py::u", "tests/a.py::v@given"]
    Config.option.loadgroup = False
    again = [Item("tests/a.py::t", ["g"])]
    _XdistGroups().pytest_collection_modifyitems(Config(), again)
    Config.option.loadgroup = True
    assert again[0].nodeid == "tests/a.py::t"


def test_the_tests_that_wait_on_the_wall_clock_are_one_group_first():
    """``wall_clock`` (tests/conftest.py): every marked test, whatever its own groups, in the one
    group ``wall-clock``, moved to the front of the queue in their order; the others keep theirs."""

    items = [Item("tests/a.py::t", []), Item("tests/b.py::rsi", ["rsi-corpus"], waits=True),
             Item("tests/c.py::u", ["g"]), Item("tests/d.py::timeout", [], waits=True)]
    _XdistGroups().pytest_collection_modifyitems(Config(), items)
    assert [i.nodeid for i in items] == ["tests/b.py::rsi@wall-clock", "tests/d.py::timeout@wall-clock",
                                         "tests/a.py::t", "tests/c.py::u@g"]


def test_the_tests_sharing_a_module_fixture_of_their_module_are_one_group():
    """A test that uses a module-scoped fixture of its own module goes to the group named by its
    module's path (dotted) (the fixture made once); a conftest's module fixture, a function fixture or an
    explicit group leave it as it was."""

    own = ("made", "module", "tests/a.py")
    items = [Item("tests/a.py::t", [], fixtures=[own, ("tmp_path", "function", "")]),
             Item("tests/a.py::u[2]", [], fixtures=[own]),
             Item("tests/a.py::v", [], fixtures=[("tmp_path", "function", "")]),
             Item("tests/b.py::w", [], fixtures=[("client", "module", "tests")]),
             Item("tests/c.py::x", ["docs"], fixtures=[("page", "module", "tests/c.py")]),
             Item("tests/d.py::y", [], waits=True, fixtures=[("run", "module", "tests/d.py")])]
    _XdistGroups().pytest_collection_modifyitems(Config(), items)
    assert [i.nodeid for i in items] == ["tests/d.py::y@wall-clock", "tests/a.py::t@tests.a.py",
                                         "tests/a.py::u[2]@tests.a.py", "tests/a.py::v", "tests/b.py::w",
                                         "tests/c.py::x@docs"]


def test_the_tests_of_one_conformance_case_are_one_group():
    """A test parametrized with a conformance case (the harness's Case, its program.src, its
    folder), whatever its module, goes to the case's group (its program loaded once by one
    worker); another path, an explicit group or a module fixture of its own module leaves it as
    it was."""

    case = load_cases()[0]
    other = load_cases()[1]
    group = f"@{CASE_GROUP_PREFIX}{case.name}"
    assert case.path.parent == CASES_DIR and CONFTEST_CASES_DIR.resolve() == CASES_DIR.resolve()
    items = [Item(f"tests/a.py::t[{case.name}]", [], params={"case": case}),
             Item(f"tests/b.py::s[{case.name}]", [], params={"program": case.program, "options": {}}),
             Item(f"tests/b.py::u[{case.name}-5]", [], params={"folder": case.path, "max_steps": 5}),
             Item(f"tests/c.py::v[{other.name}]", [], params={"program": other.program}),
             Item("tests/c.py::w[corpus]", [], params={"program": CASES_DIR.parent / "README.md"}),
             Item("tests/c.py::x[7]", [], params={"n": 7}),
             Item(f"tests/d.py::y[{case.name}]", ["docs"], params={"case": case}),
             Item(f"tests/e.py::z[{case.name}]", [], fixtures=[("made", "module", "tests/e.py")],
                  params={"case": case})]
    _XdistGroups().pytest_collection_modifyitems(Config(), items)
    assert [i.nodeid for i in items] == [
        f"tests/a.py::t[{case.name}]{group}", f"tests/b.py::s[{case.name}]{group}",
        f"tests/b.py::u[{case.name}-5]{group}", f"tests/c.py::v[{other.name}]@{CASE_GROUP_PREFIX}{other.name}",
        "tests/c.py::w[corpus]", "tests/c.py::x[7]", f"tests/d.py::y[{case.name}]@docs",
        f"tests/e.py::z[{case.name}]@tests.e.py"]


@pytest.mark.parametrize(("markexpr", "deselects"), [
    ("not slow", True),                       # make test's: the slow functions are not generated
    ("slow or not slow", False),              # make nightly's: all of them
    ("", False),
    ("slow", False),
    ("not slow and not corpus", True),
    ("corpus or not slow", False),            # a slow test that reads the corpus is kept
    ("not (slow or corpus)", True),
    ("slow and corpus", False),
    ("not slow(reason='x')", False),          # arguments: counted as keeping them
])
def test_slow_tests_are_left_ungenerated_only_when_m_deselects_every_one(markexpr, deselects):
    assert deselects_slow(markexpr) is deselects
