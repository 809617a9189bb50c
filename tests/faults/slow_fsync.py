"""Run ``krl ARGS`` with the process's first fsync slowed, as the probe of issue 74 did ("fsync
slowed to 4 s"): a test's handle to stop a real ``krl`` process inside its write with a real
signal. Not a hook of the product: this script wraps ``os.fsync`` before the command starts.

Usage: ``python tests/faults/slow_fsync.py SECONDS MARKER ARGS...``: the first fsync of the
process (the temporary file's, before it is renamed into place) runs, then MARKER is created
and the process sleeps SECONDS, then the command goes on.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

_real_fsync = os.fsync
_calls = [0]
_SECONDS, _MARKER = float(sys.argv[1]), Path(sys.argv[2])


def _slow_fsync(fd: int) -> None:
    _real_fsync(fd)
    _calls[0] += 1
    if _calls[0] == 1:
        _MARKER.touch()
        time.sleep(_SECONDS)


if __name__ == "__main__":
    os.fsync = _slow_fsync
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
    from app import main  # noqa: E402 - after the patch, as the command would start

    sys.argv = ["krl", *sys.argv[3:]]
    main()
