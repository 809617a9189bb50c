"""`krl debug`: serve the Debug Adapter Protocol on stdin/stdout (docs/editors.md)."""

from __future__ import annotations

import sys

import click
from interp.debug.session import DebugSession
from interp.debug.wire import FdReader


@click.command("debug")
def debug() -> None:
    """Debug a KRL program over the Debug Adapter Protocol on stdin/stdout.

    An editor starts it (docs/editors.md: VS Code, nvim-dap) and sends a `launch` request
    with program, workspace, inputs, mode (T1/T2/AUT/EXT), runMode (GO/MSTEP/ISTEP/BSTEP),
    stopOnEntry and interp (tree/vm). Nothing but protocol messages is written to stdout.
    """
    out = sys.stdout.buffer
    sys.stdout = sys.stderr         # a stray print must not corrupt the protocol stream
    code = DebugSession(FdReader(sys.stdin.fileno()), out).serve()
    out.flush()
    sys.exit(code)


commands = [debug]
