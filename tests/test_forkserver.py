"""The suite's fork server (tests/forkserver.py) runs a command as the command's own process
does: each case is run both ways, as ``python -m app ...`` and through the launcher, and the
two must print and end alike (the expected values are the real process's)."""

from __future__ import annotations

import signal
import subprocess
import sys

from interp.debug.client import DapClient
from tests.forkserver import krl_command, shared

REAL = [sys.executable, "-m", "app"]


def _both(args: list[str], cwd) -> tuple[subprocess.CompletedProcess, subprocess.CompletedProcess]:
    run = lambda cmd: subprocess.run([*cmd, *args], capture_output=True, text=True, cwd=cwd, timeout=120)  # noqa: E731
    return run(REAL), run(krl_command())


def test_output_exit_code_and_folder_are_the_commands(tmp_path):
    (tmp_path / "bad.src").write_text("DEF bad()\n  x = 1\nEND\n")
    for args in (["--version"], ["check", "bad.src"], ["check", "missing.src"], ["no-such-command"]):
        real, forked = _both(args, tmp_path)
        assert (forked.returncode, forked.stdout, forked.stderr) == (real.returncode, real.stdout, real.stderr), args
    assert real.returncode == 2                     # click's usage error, the last case


def test_sigterm_reaches_the_command():
    # a krl debug session, ready (it answered initialize), gets SIGTERM: it ends as the real
    # process ends (app/__init__.py: every krl command ends on SIGTERM the same way)
    ends = []
    for python in (None, str(shared().launcher)):
        c = DapClient(python=python)
        try:
            c.initialize()
            c.proc.send_signal(signal.SIGTERM)
            ends.append(c.proc.wait(60))
        finally:
            c.close()
    assert ends[1] == ends[0]
