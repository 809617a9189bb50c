"""The message window with KUKA's own message library (issue 36): the backup's MsgLib.src
(khrzysio__KRC4_test, a copy in a temporary folder with one program added that calls it) under
the pendant's engine: MsgNotify shows and does not wait, MsgQuit waits for the acknowledgement,
MsgDialog waits for a softkey and the program reads the answer back; under `krl run` (nobody to
answer) the quit is acknowledged and the dialog answered with its first softkey at once."""

from __future__ import annotations

import shutil
import subprocess
import threading
import time

from pendant import engine as keys
from pendant.engine import Engine
from tests.conftest import REPO_ROOT
from tests.forkserver import krl_command
from tests.pendant.harness import KR120

PROGRAM = """DEF msgtest()
  DECL INT nAnswer
  MsgNotify("notify %1", "Test", 7)
  MsgQuit("quit me", "Test")
  MsgDialog(nAnswer, "which one?", "Test", , "Yes", "No", "Maybe")
  $OUT[77] = nAnswer == 6
  $OUT[78] = nAnswer == 1
END
"""


def _backup(tmp_path):
    root = tmp_path / "backup"
    shutil.copytree(KR120, root, ignore=shutil.ignore_patterns("Program"))
    (root / "R1" / "msgtest.src").write_text(PROGRAM)
    return root


def _wait(pred, what: str, timeout: float = 600.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        v = pred()
        if v:
            return v
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def test_quit_and_dialog_wait_for_the_operator(shared_corpus, tmp_path):
    root = _backup(tmp_path)
    ended = threading.Event()
    eng = Engine(lambda name, body: ended.set() if name == "terminated" else None, realtime=False)
    try:
        eng.select(str(root / "R1" / "msgtest.src"), workspace=str(root), inputs=None, mode="T1", run_mode="GO",
                   trace=None)
        eng.do(lambda core: core.resume())

        def shown():
            return eng.do(lambda core: [(m.handle, m.kind, m.text, list(m.softkeys)) for m in core.rt.messages.shown])
        quit_ = _wait(lambda: [m for m in shown() if m[1] == "QUIT"], "the quit message")[0]
        kinds = {m[1]: m for m in shown()}
        assert kinds["NOTIFY"][2] == "notify 7" and quit_[2] == "quit me"
        t0 = eng.do(lambda core: core.rt.controller.time)
        _wait(lambda: eng.do(lambda core: core.rt.controller.time) > t0 + 1.0, "time to go on")
        assert not [m for m in shown() if m[1] == "DIALOG"], "MsgQuit did not wait"
        eng.do(lambda core: keys.message(core, quit_[0]))
        dialog = _wait(lambda: [m for m in shown() if m[1] == "DIALOG"], "the dialog")[0]
        # MsgLib puts its first softkey into SK[7], its second into SK[6], ... (MsgLib.src:397-513);
        # the answer is the index into that array (EXISTS_KRLDLG)
        assert dialog[2] == "which one?" and dialog[3] == ["", "", "", "", "Maybe", "No", "Yes"]
        eng.do(lambda core: keys.message(core, dialog[0], 6))
        assert ended.wait(600)
        outs = eng.do(lambda core: (core.rt.controller.io.get_out(77), core.rt.controller.io.get_out(78)))
        assert outs == (True, False)            # the program read softkey 6 ("No") back
    finally:
        eng.cancel()


def test_krl_run_answers_for_nobody(shared_corpus, tmp_path):
    root = _backup(tmp_path)
    trace = tmp_path / "t.jsonl"
    # `krl run` as a fork of the worker's fork server (tests/forkserver.py): a process of its own
    # with no pendant, without the project's import at its start
    run = subprocess.run([*krl_command(), "run", str(root / "R1" / "msgtest.src"), "--trace", str(trace)],
                         cwd=REPO_ROOT, capture_output=True, text=True, timeout=900, check=False)
    assert run.returncode == 0, run.stdout + run.stderr
    assert '"signal":"$OUT[78]","value":true' in trace.read_text()   # answer 1, as krl run always gave


APPROX = """DEF approx()
  $ADVANCE = 0
  $APO.CPTP = 50
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  PTP {A1 10} C_PTP
  PTP {A1 20}
END
"""


def test_the_main_runs_warning_is_a_kss_notification_at_its_motion(tmp_path):
    """With $ADVANCE = 0 the approximated PTP of line 5 cannot be approximated (krl-reference
    §6.8: the KSS warns "approximation not possible"): the message window shows a notification
    of KSS at approx.src line 5, and it stays after the run has ended and is cancelled."""
    (tmp_path / "approx.src").write_text(APPROX)
    ended = threading.Event()
    eng = Engine(lambda name, body: ended.set() if name == "terminated" else None, realtime=False)
    try:
        eng.select(str(tmp_path / "approx.src"), workspace=str(tmp_path), inputs=None, mode="T1", run_mode="GO",
                   trace=None)
        eng.do(lambda core: core.resume())
        assert ended.wait(600)
    finally:
        eng.cancel()
    rows = eng.system.rows()
    assert [(r["kind"], r["origin"], r["text"], r["module"], r["line"]) for r in rows] == [
        ("NOTIFY", "KSS", "approximation not possible", "approx.src", 5)]
