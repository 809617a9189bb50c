"""`krl run`'s progress on a terminal (issue 86 item 4, interp/progress.py): with standard
error a real pseudo-terminal (the pty module, not a mock), the status line shows the simulated
time, the motions and the rate, and the run ends with a line saying how fast it went; with
standard error a pipe, nothing is written there and standard output, the summary, is the same
byte for byte.

The program: a LOOP of two PTPs between two axis points for 20 s of simulated time (its limit).
The terminal run is a child process (its standard error a pty), a fork of the worker's fork
server (tests/forkserver.py: a process of its own holding the descriptors it is given, without
the imports that took about 1.5 s of CPU at its start), on the VM; the status line reads the controller's clock and the motions, not the interpreter,
and the piped side is checked on both interpreters in this process (click's runner: not a
terminal).
"""

from __future__ import annotations

import os
import pty
import re
import select
import subprocess

import pytest

from click.testing import CliRunner

from app import main
from tests.conftest import REPO_ROOT
from tests.forkserver import krl_command

PROGRAM = """DEF moves()
  BAS(#INITMOV, 0)
  LOOP
    PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
    PTP {A1 60, A2 -80, A3 80, A4 10, A5 40, A6 20}
  ENDLOOP
END
"""
ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


def _krl_run(src, interp: str) -> tuple[int, str, str]:
    """(exit code, stdout, stderr with the terminal's control sequences removed) of krl run in a
    child process whose standard error is a pseudo-terminal."""
    cmd = [*krl_command(), "run", str(src), "--interp", interp, "--max-sim-time", "20"]
    env = dict(os.environ, PYTHONPATH=str(REPO_ROOT), TERM="xterm", COLUMNS="120")
    master, slave = pty.openpty()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=slave, env=env)
    os.close(slave)
    err = b""
    while True:
        ready, _, _ = select.select([master], [], [], 0.2)
        if ready:
            try:
                data = os.read(master, 65536)
            except OSError:          # the child closed the terminal
                break
            if not data:
                break
            err += data
        elif proc.poll() is not None:
            break
    os.close(master)
    out = proc.stdout.read().decode()
    proc.stdout.close()
    return proc.wait(timeout=60), out, ANSI.sub("", err.decode())


def test_progress_and_speed_on_a_terminal(tmp_path):
    src = tmp_path / "moves.src"
    src.write_text(PROGRAM, encoding="utf-8")
    code, out, err = _krl_run(src, "vm")
    assert code == 3, out           # stopped at the time limit
    motions = int(re.search(r"^  motions    (\d+) \(PTP \d+\)$", out, re.M).group(1))
    assert motions > 2
    # the status line: simulated time of the limit, motions, the rate against real time
    shown = re.findall(r"running ([\d.]+) of 20 s simulated, (\d+) motion\(s\)(?:, [\d.]+x real time)?", err)
    assert shown, err
    assert shown[0] == ("0.0", "0")                      # shown from the start
    # the last line, after the summary: how fast it ran
    last = err.rstrip().splitlines()[-1].strip()
    m = re.fullmatch(r"krl run: 20\.0 s simulated in ([\d.]+) s \(([\d.]+) s CPU\): "
                     r"(?:[\d.]+x|-) real time, (?:[\d.]+x|-) per CPU second", last)
    assert m, last
    # not a terminal: the same summary byte for byte, nothing on standard error
    piped = CliRunner().invoke(main, ["run", str(src), "--interp", "vm", "--max-sim-time", "20"])
    assert (piped.exit_code, piped.stdout, piped.stderr) == (code, out, "")


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_nothing_on_standard_error_when_it_is_not_a_terminal(tmp_path, interp):
    src = tmp_path / "moves.src"
    src.write_text(PROGRAM, encoding="utf-8")
    res = CliRunner().invoke(main, ["run", str(src), "--interp", interp, "--max-sim-time", "20"])
    assert res.exit_code == 3, res.output
    assert res.stderr == "" and "krl run:" not in res.output and "running" not in res.output
    assert "  time       20.004 s simulated" in res.stdout   # 1667 IPO cycles of 12 ms: the first at or past 20 s
