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


def test_the_grouping_rule_is_xdists():
    """Several groups: their names sorted, joined by ``_`` (pytest-xdist 3.8, remote.py)."""

    class Item:
        def __init__(self, nodeid, groups):
            self._id = NodeId.parse(nodeid)
            self._marks = [pytest.mark.xdist_group(g).mark for g in groups]

        @property
        def nodeid(self):
            return str(self._id)

        def iter_markers(self, name):
            return iter(m for m in self._marks if m.name == name)

    class Config:
        class option:
            loadgroup = True

    items = [Item("tests/a.py::t[1]", ["zeta", "alpha"]), Item("tests/a.py::u", []),
             Item("tests/a.py::v@given", ["x"])]
    _XdistGroups().pytest_collection_modifyitems(Config(), items)
    assert [i.nodeid for i in items] == ["tests/a.py::t[1]@alpha_zeta", "tests/a.py::u", "tests/a.py::v@given"]
    Config.option.loadgroup = False
    again = [Item("tests/a.py::t", ["g"])]
    _XdistGroups().pytest_collection_modifyitems(Config(), again)
    assert again[0].nodeid == "tests/a.py::t"
