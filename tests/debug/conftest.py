"""The `krl debug` sessions of this folder's tests start as forks of one server per worker that
has imported the project (tests/forkserver.py): 1.5 s of CPU saved per session. A session
started with its own environment (``DapClient(env=...)``) or another checkout (``root``,
``python``) is a real process, as elsewhere in the suite."""

from __future__ import annotations

import os

import pytest

from interp.debug import client
from tests.forkserver import ForkServer

#: what `krl debug` and a launch import (interp/debug/session.py ``_prepare``, MuJoCo for the
#: controller's arm), imported once by the server
PRELOAD = ("app", "interp.debug.cli", "interp.debug.session", "interp.run", "robot.controller", "interp.tree",
           "interp.vm", "interp.debug.launch", "mujoco")


@pytest.fixture(scope="session")
def fork_server():
    # krl debug never draws the arm (interp/debug/cli.py): MuJoCo's GL back end is not loaded
    saved = os.environ.get("MUJOCO_GL")
    os.environ["MUJOCO_GL"] = "disable"
    try:
        server = ForkServer(PRELOAD)
    finally:
        if saved is None:
            del os.environ["MUJOCO_GL"]
        else:
            os.environ["MUJOCO_GL"] = saved
    yield server
    server.close()


@pytest.fixture(autouse=True)
def debug_sessions_fork(monkeypatch, fork_server):
    original = client.DapClient.__init__

    def init(self, timeout=60.0, transcript=None, root=client.ROOT, python=None, env=None):
        if python is None and env is None and root == client.ROOT:
            python = str(fork_server.launcher)
        original(self, timeout=timeout, transcript=transcript, root=root, python=python, env=env)

    monkeypatch.setattr(client.DapClient, "__init__", init)
