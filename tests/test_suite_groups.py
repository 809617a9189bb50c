"""The suite's own set-up (tests/conftest.py): under ``--dist loadgroup`` (make test) a test
marked ``xdist_group(name)`` is sent to one worker with the rest of its group, so the group's
session and module fixtures are made once (pytest-xdist's rule: the node id suffixed with
``@name``, which tests/conftest.py applies where pytest 9 ignores xdist's own suffix)."""

from __future__ import annotations

import pytest
from _pytest.nodeid import NodeId      # pytest 9's node id (what a node's nodeid is read from)

from tests.conftest import _XdistGroups

pytestmark = [pytest.mark.xdist_group("suite-groups")]


@pytest.mark.parametrize("n", [1, 2])
def test_a_grouped_test_carries_its_group_under_loadgroup(request, n):
    if getattr(request.config.option, "loadgroup", False):
        assert request.node.nodeid.endswith("@suite-groups"), request.node.nodeid
    else:                            # one process, or another --dist: ids are pytest's own
        assert "@" not in request.node.nodeid


class Item:
    """What the grouping hook reads of a pytest item: its id, its xdist groups, ``wall_clock``."""

    def __init__(self, nodeid, groups, waits=False):
        self._id = NodeId.parse(nodeid)
        self._marks = [pytest.mark.xdist_group(g).mark for g in groups] + [pytest.mark.wall_clock.mark] * waits

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
