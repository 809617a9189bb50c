"""`krl debug`: serve the Debug Adapter Protocol on stdin/stdout (docs/editors.md)."""

from __future__ import annotations

import os
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
    # the simulated arm is never drawn here: MuJoCo's rendering back end (GLFW) is not loaded
    # (0.03-0.05 s CPU of the launch, 2026-11-24); a user's own MUJOCO_GL is kept
    os.environ.setdefault("MUJOCO_GL", "disable")

    out = sys.stdout.buffer
    sys.stdout = sys.stderr         # a stray print must not corrupt the protocol stream
    code = DebugSession(FdReader(sys.stdin.fileno()), out).serve()
    out.flush()
    sys.exit(code)


commands = [debug]
