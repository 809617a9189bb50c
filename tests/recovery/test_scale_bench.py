"""recovery/scale_bench.py's sampler sees the memory of the whole process tree."""

from __future__ import annotations

import sys

from recovery.scale_bench import measure

HOLD = "import time; x = bytearray({n} * 2**20); x[::4096] = b'1' * len(x[::4096]); time.sleep(1.0)"


def test_measure_sees_the_main_process_and_its_children():
    """A parent touching 60 MB and a child touching 40 MB, both alive for a second: the peaks
    by kind and the tree's total at one moment include them (RSS also counts the interpreter,
    so only lower bounds are exact); the exit status and the wall time are the command's."""
    child = HOLD.format(n=40)
    parent = (f"import subprocess, sys; p = subprocess.Popen([sys.executable, '-c', {child!r}]); "
              + HOLD.format(n=60) + "; p.wait(); sys.exit(3)")
    got = measure([sys.executable, "-c", parent])
    assert got["exit"] == 3
    assert got["seconds"] >= 1.0
    peak = got["peak_mb"]
    assert peak["main"] >= 60 and peak["worker"] >= 40 and peak["java"] == 0
    assert peak["total"] >= 100
