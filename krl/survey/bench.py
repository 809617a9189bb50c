"""Checking cost against parsing cost over the KRC backups of a corpus, measured in one run.

``python -m krl.survey.bench [CORPUS]`` loads and checks every backup of CORPUS (default
../shared/krl-corpus) in this process and prints one JSON line:
``{"backups": n, "parse_s": ..., "check_s": ..., "check_vs_parse": check_s / parse_s}``.
The goal is ``check_vs_parse`` well under 1 (checking costs less than parsing). A benchmark,
not a test: wall-clock ratios on a shared machine belong here (tests never compare durations).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from krl.files import SHARED_CORPUS as DEFAULT_CORPUS
from krl.project import find_backups
from krl.workspace import load_workspace


def measure(corpus: Path) -> dict:
    """Parse and check every backup of ``corpus``; seconds of each phase and their ratio."""

    parse_s = check_s = 0.0
    backups = find_backups(corpus)
    for b in backups:
        ws = load_workspace([b], str(b))
        ws.check()
        parse_s += ws.parse_seconds
        check_s += ws.check_seconds
    return {"backups": len(backups), "parse_s": round(parse_s, 3), "check_s": round(check_s, 3),
            "check_vs_parse": round(check_s / parse_s, 3) if parse_s else None}


if __name__ == "__main__":
    print(json.dumps(measure(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_CORPUS)))
