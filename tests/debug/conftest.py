"""The `krl debug` sessions of this folder's tests start as forks of the worker's fork server,
which has imported the project (tests/forkserver.py): 1.5 s of CPU saved per session. A
session started with its own environment (``DapClient(env=...)``) or another checkout
(``root``, ``python``) is a real process, as elsewhere in the suite."""

from __future__ import annotations

import pytest

from interp.debug import client
from tests import forkserver


@pytest.fixture(autouse=True)
def debug_sessions_fork(monkeypatch):
    original = client.DapClient.__init__

    def init(self, *args, **kw):
        # DapClient's defaults stay its own: only a session of this checkout, this interpreter
        # and the suite's environment is forked
        if not args and all(kw.get(k) is None for k in ("python", "env", "root")):
            kw["python"] = str(forkserver.shared().launcher)
        original(self, *args, **kw)

    monkeypatch.setattr(client.DapClient, "__init__", init)
