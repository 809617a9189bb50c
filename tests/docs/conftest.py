"""The documents' transcripts, run once per test session (tests/docs/transcripts.py): the
comparison (test_transcripts.py) and the checks of what the README's example writes
(test_change_report.py) read the same run. Their `krl` is a fork of the worker's fork server
(tests/forkserver.py ``krl_folder``): the README's and docs' command lines as written, each
without the import of the project at its start."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.docs import transcripts as T
from tests.forkserver import krl_folder


@pytest.fixture(scope="session")
def document_runs(tmp_path_factory, shared_corpus):
    """run(doc) -> (results, the folder the commands ran in), each document run once."""
    done: dict[Path, tuple[list, Path]] = {}
    forked = krl_folder(tmp_path_factory.mktemp("docs-bin"))

    def run(doc: Path):
        if doc not in done:
            root = tmp_path_factory.mktemp("docs-" + doc.stem.lower())
            results = T.run_document(doc, root, first_on_path=forked)
            done[doc] = (results, root / "krl-tools")
        return done[doc]
    return run
