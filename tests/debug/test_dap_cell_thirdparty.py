"""`krl debug` on a cell of several robots driven by a DAP client krl-tools did not write: the
``DebugClient`` of @vscode/debugadapter-testsupport (the test support of VS Code's debug adapters,
npm; tests/debug/dapclient, installed by ``make test`` from its package-lock.json). Its script
(tests/debug/dapclient/cell.js) runs the cell of tests/debug/test_dap_cell.py, whose module
docstring derives by hand what each robot's thread shows: R2's breakpoint at pal.src:3 stops
R2's thread (10001), whose stack DebugClient reads by the stopped event's thread id; R1's
thread (1) stands at handler.src:5; $OUT[10] TRUE in R1, $IN[10] TRUE and $OUT[11] FALSE in R2;
a step in R2's thread stops at pal.src:4; the cell then completes (exit code 0)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.debug.test_dap_cell import _files
from tests.editors.npm import REPO, npm_ci

CLIENT = Path(__file__).resolve().parent / "dapclient"


# the VM only: the threads are the engine's, the same for both interpreters, and
# tests/debug/test_dap_cell.py runs the same stops on both (each krl debug costs ~2.5 s of CPU
# to start)
@pytest.mark.parametrize("interp", ["vm"])
def test_vscode_debug_client_sees_a_thread_per_robot(tmp_path, interp):
    npm_ci(CLIENT)
    _files(tmp_path)
    krl = Path(sys.executable).parent / "krl"
    env = {**os.environ, "PYTHONPATH": str(REPO) + (os.pathsep + os.environ["PYTHONPATH"]
                                                    if os.environ.get("PYTHONPATH") else "")}
    run = subprocess.run(["node", str(CLIENT / "cell.js"), str(krl), str(tmp_path), interp], cwd=CLIENT, env=env,
                         capture_output=True, text=True, timeout=240, check=False)
    assert run.returncode == 0 and run.stdout.strip().endswith("ok"), run.stdout[-3000:] + run.stderr[-3000:]
