"""The program map's tests load each backup's files through the session's one store
(``krl.parsecache.through_store``), as ``krl graph`` does (since 2026-11-28: before, it parsed every file
at each call; tests/report/test_store_reads.py): every corpus backup is loaded by
several of these modules (test_entries, test_graph, test_map_page, test_map_overview,
test_reach_corpus), and a file the session has parsed once is decoded, not parsed again
(the package's tests: 54.1 -> 26.5 s of CPU, -n 0, 2026-11-26)."""

from __future__ import annotations

import pytest

from krl.parsecache import through_store


@pytest.fixture(scope="module", autouse=True)
def _parses_from_the_store():
    with through_store():
        yield
