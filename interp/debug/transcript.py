"""A recorded `krl debug` session on a real program of the shared corpus (docs/editors.md,
"A session"): a new user sets a breakpoint, steps through a motion in #MSTEP, watches
``$POS_ACT`` and an output, and steps back. The session runs through the DAP client
(interp/debug/client.py) over stdio, exactly as an editor drives it.

Usage: ``python -m interp.debug.transcript [PROGRAM]`` (default: the corpus's
luigipacheco__kuka_krl_python/example.src). Prints the transcript as Markdown.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

from krl.files import SHARED_CORPUS

from .client import DapClient

PROGRAM = SHARED_CORPUS / "luigipacheco__kuka_krl_python" / "example.src"
BREAK_LINE = 27        # $OUT[5] = TRUE, after the first PTP
WATCH = ("$POS_ACT", "$OUT[5]")


def _short(msg: dict, roots: tuple) -> str:
    body = {k: v for k, v in msg.items() if k not in ("seq", "type")}
    text = json.dumps(body, separators=(", ", ": "))
    for root in roots:
        text = text.replace(root, "<corpus>")
    return text


def record(program: Path = PROGRAM) -> list[str]:
    """The transcript lines (Markdown) of the session on ``program``."""
    # the corpus's folder, as given and as resolved, is shown as <corpus>
    roots = tuple(sorted({str(SHARED_CORPUS), os.path.realpath(SHARED_CORPUS)}, key=len, reverse=True))
    lines: list[str] = []

    def note(text: str) -> None:
        lines.append("")
        lines.append(text)
        lines.append("")

    log: list = []
    with DapClient(transcript=log) as c:
        def flush() -> None:
            for direction, msg in log:
                if msg.get("type") == "event" and msg.get("event") in ("output",):
                    continue
                lines.append(f"    {direction} {_short(msg, roots)}")
            log.clear()

        def watch() -> None:
            for expr in WATCH:
                c.evaluate(expr)
            c.request("krl/pointers")
            flush()

        note("The editor starts `krl debug`, initializes and launches the program in T1 with "
             "#MSTEP (the pendant's motion step), with a breakpoint on line "
             f"{BREAK_LINE} (`$OUT[5] = TRUE`):")
        c.initialize()
        c.request("launch", {"program": str(program), "mode": "T1", "runMode": "MSTEP"})
        c.set_breakpoints(program, [BREAK_LINE])
        c.request("configurationDone")
        c.wait_event("stopped")
        flush()
        note("The first stop is #MSTEP's: the PTP of line 26 has ended. Continue to the breakpoint:")
        c.request("continue", {"threadId": 1})
        c.wait_event("stopped")
        c.stack()
        flush()
        note("Watch `$POS_ACT` and the output `$OUT[5]` (still FALSE), and the two pointers:")
        watch()
        note("Step over line 27 (the output is set) and over the PTP of line 28: in #MSTEP the "
             "step ends when the motion has ended, with the robot at the programmed point:")
        c.step("next")
        c.step("next")
        c.stack()
        flush()
        watch()
        note("Step back: the run is replayed to the start of line 28, before the PTP: the robot "
             "is back where it was, the output still TRUE; one more step back undoes line 27:")
        c.request("stepBack", {"threadId": 1})
        c.wait_event("stopped")
        c.stack()
        flush()
        watch()
        c.request("stepBack", {"threadId": 1})
        c.wait_event("stopped")
        c.stack()
        flush()
        watch()
        c.request("disconnect", {})
        flush()
    return lines


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    program = Path(argv[0]) if argv else PROGRAM
    if not program.is_file():
        print(f"no program {program} (the shared corpus is beside the repository)", file=sys.stderr)
        return 2
    print("\n".join(record(program)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
