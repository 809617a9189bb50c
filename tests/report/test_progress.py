"""Progress of `krl validate` / `krl growth` (issue 13): a rich bar on a terminal, quiet when piped."""

from __future__ import annotations

import os
import pty
import subprocess
import sys

SNIPPET = ("import time\nfrom recovery.progress import steps\n"
           "for x in steps(['alpha', 'beta'], 'validating constructs'):\n    time.sleep(0.3)\n"
           "print('done')\n")


def run(stderr_tty: bool) -> tuple[str, bytes]:
    env = dict(os.environ, TERM="xterm", COLUMNS="100")
    env.pop("NO_COLOR", None)
    if not stderr_tty:
        p = subprocess.run([sys.executable, "-c", SNIPPET], capture_output=True, env=env, timeout=60)
        return p.stdout.decode(), p.stderr
    master, slave = pty.openpty()
    try:
        p = subprocess.Popen([sys.executable, "-c", SNIPPET], stdout=subprocess.PIPE, stderr=slave, env=env)
        os.close(slave)
        chunks = []
        while True:
            try:
                data = os.read(master, 4096)
            except OSError:      # EIO: the child closed the terminal
                break
            if not data:
                break
            chunks.append(data)
        out = p.stdout.read().decode()
        p.wait(timeout=60)
    finally:
        os.close(master)
    return out, b"".join(chunks)


def test_quiet_when_piped():
    out, err = run(stderr_tty=False)
    assert out == "done\n"
    assert err == b""


def test_bar_on_a_terminal():
    out, err = run(stderr_tty=True)
    assert out == "done\n"
    text = err.decode(errors="replace")
    assert "validating constructs: alpha" in text
    assert "2/2" in text or "1/2" in text
