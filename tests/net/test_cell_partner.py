"""A third-party client drives one robot of a cell of several robots (issue 89, done-when 2):
py-openshowvar (PyPI, a client this project did not write) sets a global of robot R1 through
KukaVarProxy; R1 then sets the output wired to R2's input, and R2, which waited for it, moves.
"""

from __future__ import annotations

import threading
import time

import pytest
from py_openshowvar import openshowvar

from interp.robotcell import cell_runs, load_robot_cell, run_cell

SERVICE = """DEF svc()
  READY = TRUE
  WAIT FOR GO_ON
  $OUT[7] = TRUE
  DONE = 1
  WAIT FOR BYE
END
"""
SERVICE_DAT = """DEFDAT svc PUBLIC
  DECL GLOBAL BOOL GO_ON = FALSE
  DECL GLOBAL BOOL READY = FALSE
  DECL GLOBAL BOOL BYE = FALSE
  DECL GLOBAL INT DONE = 0
ENDDAT
"""
OTHER = """DEF other()
  WAIT FOR $IN[7]
  PTP {A1 20, A2 -90, A3 90, A4 0, A5 0, A6 0}
END
"""
CELL = """robots:
  R1: {program: svc.src, inputs: svc.yaml}
  R2: {program: other.src}
wires:
  - R1 $OUT[7] -> R2 $IN[7]
"""


def _until(client, name: str, want: bytes, deadline: float) -> None:
    while client.read(name, debug=False) != want:
        if time.monotonic() > deadline:
            raise TimeoutError(f"{name} never became {want!r}")
        time.sleep(0.02)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_py_openshowvar_drives_one_robot_while_the_other_waits_for_it(tmp_path, interp):
    for name, text in (("svc.src", SERVICE), ("svc.dat", SERVICE_DAT), ("other.src", OTHER), ("cell.yaml", CELL),
                       ("svc.yaml", "network:\n  varproxy: 127.0.0.1:0\n")):
        (tmp_path / name).write_text(text, encoding="utf-8")
    cell = load_robot_cell(tmp_path / "cell.yaml")
    got: dict = {}
    with cell_runs(cell, interp, 60.0, mujoco=False) as runs:
        r1, r2 = runs
        net = r1.runtime.controller.network

        def partner():
            try:
                client = openshowvar(*net.wait_address("varproxy"))
                deadline = time.monotonic() + 30
                _until(client, "READY", b"TRUE", deadline)
                got["r2_waiting"] = r2.runtime.robot.waiting
                got["written"] = client.write("GO_ON", "TRUE", debug=False)
                _until(client, "DONE", b"1", deadline)
                got["done"] = True
                client.write("BYE", "TRUE", debug=False)
                client.close()
            except BaseException as exc:      # reported in the test's thread
                got["error"] = exc

        th = threading.Thread(target=partner, daemon=True)
        th.start()
        res = run_cell(cell, runs)
        th.join(30)
    assert "error" not in got, got.get("error")
    assert got["written"] == b"TRUE" and got["done"]
    assert got["r2_waiting"] and "other.src:2" in got["r2_waiting"]    # R2 waited for R1 meanwhile
    assert res.reason == "completed", [r.runtime.result.text for r in res.robots]
    (t_out, name, value, _), = r1.runtime.controller.io.log
    (t_in, name_in, value_in, source), = r2.runtime.controller.io.log
    assert (name, value, name_in, value_in, source) == ("$OUT[7]", True, "$IN[7]", True, "wire R1 $OUT[7]")
    assert t_in == pytest.approx(t_out + 0.012)
    (text, _, wires), = r2.released
    assert [str(w) for w in wires] == ["R1 $OUT[7] -> R2 $IN[7]"]
    assert r2.runtime.result.sim_time > t_in           # it moved after the release
