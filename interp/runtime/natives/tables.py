"""Write the front end's table of built-in routines, krl/semantics/data/functions.yaml, from
the natives registry (interp/runtime/natives/__init__.py ``REGISTRY``). The table is
generated and checked in, as CPython checks in what its generators make: the checker reads
the table and never imports the runtime, and tests/interp/test_natives.py fails when the
checked-in file is not what this makes.

Usage: ``python -m interp.runtime.natives.tables [--check]`` (``--check``: exit status 1,
nothing written, when the file is stale).
"""

from __future__ import annotations

import sys
from pathlib import Path

from krl.semantics.builtins import DATA_DIR

from . import REGISTRY
from .registry import functions_yaml

TARGET = DATA_DIR / "functions.yaml"


def main(argv: list[str]) -> int:
    text = functions_yaml(REGISTRY)
    current = TARGET.read_text(encoding="utf-8") if TARGET.exists() else ""
    if "--check" in argv:
        if current != text:
            print(f"{TARGET} is stale: run python -m interp.runtime.natives.tables", file=sys.stderr)
            return 1
        return 0
    if current != text:
        Path(TARGET).write_text(text, encoding="utf-8")
        print(f"wrote {TARGET}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
