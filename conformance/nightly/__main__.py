"""``python -m conformance.nightly [reports/nightly]``: record the nights, write the index."""

import sys
from pathlib import Path

from .history import HistoryError
from .index import write_index

if __name__ == "__main__":
    try:
        print(write_index(Path(sys.argv[1] if len(sys.argv) > 1 else "reports/nightly")))
    except HistoryError as exc:
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)
