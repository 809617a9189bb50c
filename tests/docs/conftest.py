"""The documents' transcripts, run once per test session (tests/docs/transcripts.py): the
comparison (test_transcripts.py) and the checks of what the README's example writes
(test_change_report.py) read the same run."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.docs import transcripts as T


@pytest.fixture(scope="session")
def document_runs(tmp_path_factory, shared_corpus):
    """run(doc) -> (results, the folder the commands ran in), each document run once."""
    done: dict[Path, tuple[list, Path]] = {}

    def run(doc: Path):
        if doc not in done:
            root = tmp_path_factory.mktemp("docs-" + doc.stem.lower())
            results = T.run_document(doc, root)
            done[doc] = (results, root / "krl-tools")
        return done[doc]
    return run
