"""A third-party client drives one robot of a cell built from two corpus backups while the
other runs its own program (issue 89, done-when 2; docs/cells.md).

The cell is tests/interp/fixtures/cutpal's with the cutting robot driven from outside: CUT is
khrzysio__KRC4_test's controller (its machine data and its ``$config.dat``, copied into the test's
folder beside a two-line program: no backup file is changed), PAL runs ingeniado__KRC4-Robot-
Palletizer's main.src as in the fixture (pattern 3, its own cell file ``pal.yaml``). A cell
controller, py-openshowvar (PyPI; a client this project did not write), plays the cutter's side
of the hand-off over CUT's KukaVarProxy, by the backup's own signal names: it raises
``outStartCutSeq`` ($OUT[15], khrzysio $config.dat:837) as CutSequence.src:29 does, holds it until
the part is taken, and reads ``inCutSeqFinished`` ($IN[4], $config.dat:808).

What the palletizer's program does, read by hand (ingeniado's sources):

* main.src:45 ``VACIO = FALSE`` ($OUT[1], wired to CUT's $IN[4]): the client first reads FALSE;
* coge_20.src:59 ``WAIT FOR SACO_RDY ...`` ($IN[81], wired from CUT's $OUT[15]): released by the
  client's write, one IPO cycle later (the wire's latency, docs/cells.md);
* coge_20.src:68 ``VACIO=TRUE``, in the cycle the wait ends: the client reads
  ``inCutSeqFinished`` TRUE one cycle after that;
* saco_20_m2.src:169 ``VACIO=FALSE`` once the bag is placed: the client reads FALSE again, and
  saco_20_m2.src:194 counts the bag, ``N_SACO = N_SACO + 1`` ($OUT[17..25]: 1, so $OUT[17] rises);
* then coge_20 again, to :59, waiting for a second part that only CUT could request: with the
  client's program ended the cell deadlocks there, naming the wire.

About 10 s of simulated time, paced at 10x real time while the client is attached.
"""

from __future__ import annotations

import shutil
import threading
import time
from pathlib import Path

import pytest
from py_openshowvar import openshowvar

from interp.robotcell import cell_runs, load_robot_cell, run_cell

FIXTURE = Path(__file__).resolve().parents[1] / "interp" / "fixtures" / "cutpal"
REMOTE = """DEF remote()
  WAIT FOR inCutSeqFinished
  WAIT FOR NOT inCutSeqFinished
  WAIT FOR CYCLE_DONE
END
"""
REMOTE_DAT = """DEFDAT remote PUBLIC
  DECL GLOBAL BOOL CYCLE_DONE = FALSE
ENDDAT
"""


@pytest.fixture(scope="module")
def cell_file(tmp_path_factory, shared_corpus) -> Path:
    """The cell file, once for both interpreters (the workspaces then checked once)."""
    return _cell(tmp_path_factory.mktemp("cutpal_partner"), shared_corpus)


def _cell(tmp_path: Path, corpus: Path) -> Path:
    """The cell file: CUT driven from outside, PAL with its corpus program and its cell file."""
    khr = corpus / "khrzysio__KRC4_test" / "R1"
    for part in ("System", "Mada"):                # the controller's data, not its programs
        shutil.copytree(khr / part, tmp_path / "cut" / "R1" / part)
    (tmp_path / "cut" / "R1" / "Program").mkdir()
    (tmp_path / "cut" / "R1" / "Program" / "remote.src").write_text(REMOTE, encoding="utf-8")
    (tmp_path / "cut" / "R1" / "Program" / "remote.dat").write_text(REMOTE_DAT, encoding="utf-8")
    (tmp_path / "cut.yaml").write_text("network:\n  varproxy: 127.0.0.1:0\n  pace: 10\n", encoding="utf-8")
    pal = corpus / "ingeniado__KRC4-Robot-Palletizer"
    (tmp_path / "cell.yaml").write_text(
        "robots:\n"
        "  CUT: {program: cut/R1/Program/remote.src, workspace: cut, inputs: cut.yaml, no_submit: true}\n"
        f"  PAL: {{program: {pal / 'main.src'}, workspace: {pal}, inputs: {FIXTURE / 'pal.yaml'},"
        " base: [307, -2329, 1688, 180, 0, 0]}\n"
        "wires:\n  - CUT $OUT[15] -> PAL $IN[81]\n  - PAL $OUT[1] -> CUT $IN[4]\n", encoding="utf-8")
    return tmp_path / "cell.yaml"


def _until(client, name: str, want: bytes, deadline: float) -> None:
    while client.read(name, debug=False) != want:
        if time.monotonic() > deadline:
            raise TimeoutError(f"{name} never became {want!r}")
        time.sleep(0.01)


def _drive(net, pal, got: dict) -> None:
    """The cell controller's side of the hand-off, in its own thread (as a PLC would do it)."""
    try:
        client = openshowvar(*net.wait_address("varproxy"))
        deadline = time.monotonic() + 60
        got["before"] = client.read("inCutSeqFinished", debug=False)
        while "coge_20.src:59" not in (pal.runtime.robot.waiting or "") and time.monotonic() < deadline:
            time.sleep(0.01)           # the palletizer at coge_20.src:59 before the request
        got["pal_waiting"] = pal.runtime.robot.waiting
        got["raised"] = client.write("outStartCutSeq", "TRUE", debug=False)
        _until(client, "inCutSeqFinished", b"TRUE", deadline)     # the palletizer holds the bag
        got["lowered"] = client.write("outStartCutSeq", "FALSE", debug=False)
        _until(client, "inCutSeqFinished", b"FALSE", deadline)    # and has placed it
        got["request_after"] = client.read("$OUT[15]", debug=False)
        got["done"] = client.write("CYCLE_DONE", "TRUE", debug=False)      # the cutter's program ends
        client.close()
    except BaseException as exc:      # reported in the test's thread
        got["error"] = exc


def _rises(r) -> list[tuple[float, str, bool, str]]:
    return [(round(t, 3), s, v, str(src)) for t, s, v, src in r.runtime.controller.io.log]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_client_drives_the_cutter_while_the_palletizer_runs_its_program(cell_file, interp):
    cell = load_robot_cell(cell_file)
    got: dict = {}
    with cell_runs(cell, interp, 40.0, mujoco=False) as runs:
        cut, pal = runs
        th = threading.Thread(target=_drive, args=(cut.runtime.controller.network, pal, got), daemon=True)
        th.start()
        res = run_cell(cell, runs)
        th.join(60)
        cut_log, pal_log = _rises(cut), _rises(pal)
    assert "error" not in got, got.get("error")
    # what the client read and wrote against the palletizer's program
    assert got["before"] == b"FALSE"                                  # main.src:45
    assert "coge_20.src:59" in got["pal_waiting"]
    assert got["raised"] == b"TRUE" and got["lowered"] == b"FALSE" and got["request_after"] == b"FALSE"
    assert got["done"] == b"TRUE"
    # the run's side: the client's write lands between two IPO cycles (KukaVarProxy answers at the
    # start of the next cycle, docs/network.md) and the wire carries it at that boundary: the
    # palletizer reads it in the cycle CUT's log stamps it with; PAL's vacuum comes back one cycle
    # later (a program's write in cycle k is read from k + 1 on, docs/cells.md)
    (t_up, *_), (t_down, *_) = [e for e in cut_log if e[1] == "$OUT[15]"]
    assert [e[2] for e in cut_log if e[1] == "$OUT[15]"] == [True, False]
    # written by the client, through the backup's SIGNAL name: the partner's writes (issue 89)
    assert [e[3] for e in cut_log if e[1] == "$OUT[15]"] == ["varproxy", "varproxy"]
    (t_req, _, _, src), *_ = [e for e in pal_log if e[1] == "$IN[81]"]
    assert t_req == pytest.approx(t_up) and src == "wire CUT $OUT[15]"
    vacio = [(t, v) for t, s, v, _ in pal_log if s == "$OUT[1]"]
    assert vacio[0] == (pytest.approx(t_req), True)                  # coge_20.src:68, the same cycle
    assert vacio[1][1] is False and t_down < vacio[1][0]              # saco_20_m2.src:169, after the ack
    ack = [(t, v, src) for t, s, v, src in cut_log if s == "$IN[4]"]
    assert ack == [(pytest.approx(vacio[0][0] + 0.012), True, "wire PAL $OUT[1]"),
                   (pytest.approx(vacio[1][0] + 0.012), False, "wire PAL $OUT[1]")]
    assert any(s == "$OUT[17]" and v is True for _, s, v, _ in pal_log)  # N_SACO = 1, saco_20_m2.src:194
    # the palletizer's wait ended once, by the wire; then it waits for a second part
    (text, _s, wires), = pal.released
    assert "coge_20.src:59" in text and [str(w) for w in wires] == ["CUT $OUT[15] -> PAL $IN[81]"]
    assert cut.runtime.result.reason == "completed"
    end = pal.runtime.result
    assert res.reason == "deadlock" and end.reason == "deadlock", end.text
    assert (Path(end.file).name, end.line) == ("coge_20.src", 59)
    assert "CUT $OUT[15] -> PAL $IN[81]" in end.text
