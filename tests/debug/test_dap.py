"""`krl debug` driven over stdio by a DAP client (interp/debug/client.py) on conformance
programs. Every expected line number and value is read off the program text by hand (the
comments say how); stepBack is checked against the state recorded when the same statement
was first reached."""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest

from interp.debug.client import DapClient, DapError

CASES = Path(__file__).resolve().parents[2] / "conformance" / "cases"
CALL = CASES / "011_call_in_out" / "program.src"
WHILE = CASES / "007_while" / "program.src"
IRQ = CASES / "090_interrupt_during_motion"
DIV0 = CASES / "028_err_div_zero" / "program.src"
CIRC = CASES / "064_circ_c_dis" / "program.src"


def frames(c, thread=1):
    return [(f["name"], f["line"]) for f in c.stack(thread)]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_breakpoint_steps_variables_set_variable(interp):
    # 011_call_in_out: a = 1 (l.4), arr[2] = 5 (l.5), f.Z = 3 (l.6), Bump(a, arr[2], f.Z) (l.7);
    # Bump: x = x + 100 (l.16, x :IN), y = y + 1 (l.17), z = z + 10 (l.18)
    with DapClient() as c:
        st = c.start(CALL, breakpoints={CALL: [7]}, interp=interp)
        assert st["body"]["reason"] == "breakpoint" and st["body"]["threadId"] == 1
        assert frames(c) == [("program()", 7)]
        fid = c.stack()[0]["id"]
        local = c.scope_vars(fid, "Locals")
        assert local["a"] == "1" and local["f"].startswith("{X 1.0, Y 2.0, Z 3.0")
        assert c.value("arr[2]") == "5"
        assert c.value("a + arr[2] * 2") == "11"
        assert c.step("stepIn")["body"]["reason"] == "step"
        assert frames(c) == [("Bump()", 16), ("program()", 7)]
        assert c.scope_vars(c.stack()[0]["id"], "Locals") == {"x": "1", "y": "5", "z": "3.0"}
        c.step("next")
        assert frames(c)[0] == ("Bump()", 17)
        assert c.value("x") == "101"                      # the :IN copy changed
        assert c.value("a", c.stack()[1]["id"]) == "1"    # the caller's a did not
        c.step("stepOut")
        assert frames(c) == [("program()", 8)]
        assert (c.value("a"), c.value("arr[2]"), c.value("f.Z")) == ("1", "6", "13.0")
        # set a = 7: the IF of line 8 is then FALSE, so the breakpoint on line 9 is never hit
        locals_ref = next(s["variablesReference"] for s in
                          c.request("scopes", {"frameId": c.stack()[0]["id"]})["body"]["scopes"]
                          if s["name"] == "Locals")
        r = c.request("setVariable", {"variablesReference": locals_ref, "name": "a", "value": "3 + 4"})
        assert r["body"]["value"] == "7" and c.value("a") == "7"
        c.set_breakpoints(CALL, [9])
        c.request("continue", {"threadId": 1})
        assert c.wait_event("exited")["body"]["exitCode"] == 0
        assert not [e for e in c.events if e.get("event") == "stopped"]


def test_evaluate_errors_are_refused_with_krl_words():
    with DapClient() as c:
        c.start(CALL, stopOnEntry=True)
        assert frames(c) == [("program()", 4)]
        assert c.evaluate("a", ok=False)["message"] == "value invalid: a (1422)"   # a is not set yet
        assert "not a KRL expression" in c.evaluate("a +", ok=False)["message"]
        assert "after the expression" in c.evaluate("a = 1", ok=False)["message"]
        assert c.value("$MODE_OP") == "#AUT"              # krl run's default mode
        assert c.value("$PRO_MODE") == "#GO"


def test_conditional_hit_count_and_function_breakpoints():
    # 007_while: n = 1 (l.3); WHILE n < 20 (l.4): n = n * 3 (l.5) runs with n = 1, 3, 9
    with DapClient() as c:
        st = c.start(WHILE, breakpoints={WHILE: [{"line": 5, "condition": "n > 2"}]})
        assert st["body"]["reason"] == "breakpoint" and c.value("n") == "3"
        c.request("continue", {"threadId": 1})
        c.wait_event("stopped")
        assert c.value("n") == "9"
        c.set_breakpoints(WHILE, [{"line": 10}])           # IF n == 27
        c.request("continue", {"threadId": 1})
        c.wait_event("stopped")
        assert frames(c) == [("program()", 10)] and c.value("n") == "27"
    with DapClient() as c:
        st = c.start(WHILE, breakpoints={WHILE: [{"line": 5, "hitCondition": "3"}]})
        assert c.value("n") == "9"                         # the third pass: n = 9
    with DapClient() as c:
        st = c.start(CALL, function_breakpoints=["bump"])
        assert st["body"]["reason"] == "function breakpoint"
        assert frames(c) == [("Bump()", 16), ("program()", 7)]


def test_pause_a_running_program(tmp_path):
    # the robot program spins in a LOOP: pause stops it wherever it is
    prog = tmp_path / "spin.src"
    prog.write_text("DEF spin()\n  DECL INT n\n  n = 0\n  LOOP\n    n = n + 1\n  ENDLOOP\nEND\n")
    with DapClient() as c:
        c.initialize()
        c.request("launch", {"program": str(prog)})
        c.request("configurationDone")
        c.request("pause", {"threadId": 1})
        st = c.wait_event("stopped")
        assert st["body"]["reason"] == "pause"
        assert frames(c)[0][1] in (3, 4, 5)               # wherever it was: a statement of spin
        c.set_breakpoints(prog, [5])
        c.request("continue", {"threadId": 1})
        c.wait_event("stopped")
        n = int(c.value("n"))
        c.request("continue", {"threadId": 1})
        c.wait_event("stopped")
        assert frames(c) == [("spin()", 5)] and int(c.value("n")) == n + 1   # one pass of the LOOP


def test_interrupt_handler_is_a_thread_with_its_frame():
    # 090: the stimulus sets $IN[3] 0.3 s into LIN {Y 200} (l.8); the advance run waits at
    # WAIT SEC 0 (l.9); OnSensor's $OUT[1] = TRUE is line 14
    with DapClient() as c:
        st = c.start(IRQ / "program.src", inputs=str(IRQ / "stimuli.yaml"), function_breakpoints=["OnSensor"])
        assert st["body"]["reason"] == "function breakpoint"
        threads = {t["id"]: t["name"] for t in c.request("threads")["body"]["threads"]}
        assert threads == {1: "robot program program", 1005: "interrupt 5 OnSensor"}
        assert st["body"]["threadId"] == 1005
        assert frames(c, 1005) == [("OnSensor()", 14)]
        assert frames(c, 1) == [("program()", 9)]
        assert c.value("$OUT[1]") == "FALSE"
        c.step("next", 1005)
        assert c.value("$OUT[1]") == "TRUE"


def test_runtime_error_stop():
    # 028: a = 10, z = 0, $OUT[1] = TRUE, a = a / z (l.6): INT division by zero
    with DapClient() as c:
        st = c.start(DIV0)
        assert st["body"]["reason"] == "exception" and st["body"]["text"] == "division by zero"
        assert frames(c) == [("program()", 6)]
        fid = c.stack()[0]["id"]
        assert c.scope_vars(fid, "Locals") == {"a": "10", "z": "0"}
        assert c.scope_vars(fid, "I/O")["$OUT[1]"] == "TRUE"
        assert c.request("exceptionInfo", {"threadId": 1})["body"]["description"] == "division by zero"
        c.request("continue", {"threadId": 1})
        assert c.wait_event("exited")["body"]["exitCode"] == 1
    with DapClient() as c:                                  # the filter off: the run just ends
        c.initialize()
        c.request("launch", {"program": str(DIV0)})
        c.request("setExceptionBreakpoints", {"filters": []})
        c.request("configurationDone")
        assert c.wait_event("exited")["body"]["exitCode"] == 1
        assert "division by zero" in c.wait_event("output")["body"]["output"]


def state(c):
    fid = c.stack()[0]["id"]
    return (frames(c), c.value("$POS_ACT"), c.value("$AXIS_ACT"), c.value("$VEL.CP"),
            c.scope_vars(fid, "I/O"), c.request("krl/pointers")["body"])


def test_step_back_returns_exactly_to_an_earlier_state():
    # 064: PTP (l.4), $VEL.CP = 0.1 (l.5), $APO.CDIS = 15 (l.6), CIRC ... C_DIS (l.7), LIN (l.8)
    with DapClient() as c:
        c.start(CIRC, breakpoints={CIRC: [7]})
        before = state(c)
        assert before[0] == [("program()", 7)] and c.value("$VEL.CP") == "0.1"
        c.step("next")
        assert frames(c) == [("program()", 8)]
        after = state(c)
        assert after[5]["step"] == before[5]["step"] + 1
        c.request("stepBack", {"threadId": 1})
        assert c.wait_event("stopped")["body"]["reason"] == "step"
        assert state(c) == before
        # reverseContinue from line 8 goes back to the breakpoint on line 7
        c.step("next")
        c.request("reverseContinue", {"threadId": 1})
        assert c.wait_event("stopped")["body"]["reason"] == "breakpoint"
        assert state(c) == before


def test_mstep_and_backward_motion_over_dap():
    # 064 in #MSTEP (T1): a stop after each motion, each reached exactly (C_DIS suppressed):
    # PTP to A5 90 (l.4), CIRC to X 605 Y 0 Z 810 (l.7), LIN to Y -100 (l.8)
    with DapClient() as c:
        st = c.start(CIRC, runMode="MSTEP", mode="T1")
        assert st["body"]["description"].startswith("MSTEP")
        assert frames(c) == [("program()", 4)]
        assert c.value("$AXIS_ACT.A5") == "90.0" and c.value("$AXIS_ACT.A2") == "-90.0"
        assert c.request("krl/pointers")["body"]["mainRun"] is None     # the robot stands
        start = [float(c.value(f"$POS_ACT.{k}")) for k in "XYZ"]
        c.request("continue", {"threadId": 1})
        c.wait_event("stopped")
        assert frames(c) == [("program()", 7)]
        assert [round(float(c.value(f"$POS_ACT.{k}")), 3) for k in "XYZ"] == [605.0, 0.0, 810.0]
        c.request("continue", {"threadId": 1})
        c.wait_event("stopped")
        assert [round(float(c.value(f"$POS_ACT.{k}")), 3) for k in "XYZ"] == [605.0, -100.0, 810.0]
        c.request("krl/backwardStep", {})                   # back along the LIN
        assert [round(float(c.value(f"$POS_ACT.{k}")), 1) for k in "XYZ"] == [605.0, 0.0, 810.0]
        c.request("krl/backwardStep", {})                   # back along the CIRC
        assert max(abs(float(c.value(f"$POS_ACT.{k}")) - v) for k, v in zip("XYZ", start)) < 0.1
        c.request("krl/backwardStep", {})                   # back along the PTP: the home axes
        assert c.value("$AXIS_ACT.A5") == "0.0"
        r = c.request("krl/backwardStep", {}, ok=False)
        assert not r["success"] and "no executed motion left" in r["message"]


def test_launch_refuses_bad_arguments(tmp_path):
    with DapClient() as c:
        c.initialize()
        with pytest.raises(DapError, match="none.src: no such file"):
            c.request("launch", {"program": str(tmp_path / "none.src")})
        with pytest.raises(DapError, match="mode"):
            c.request("launch", {"program": str(CALL), "mode": "T3"})


def test_submit_interpreter_is_a_thread():
    # 100_submit_io: the robot program waits at WAIT FOR $OUT[5] (l.2); sps.sub sets $OUT[5]
    # (l.4) once the stimulus has set $IN[2] at t = 0.2 s
    case = CASES / "100_submit_io"
    with DapClient() as c:
        st = c.start(case / "program.src", inputs=str(case / "stimuli.yaml"), submit=[str(case / "sps.sub")],
                     breakpoints={case / "sps.sub": [4]})
        assert st["body"]["reason"] == "breakpoint" and st["body"]["threadId"] == 2
        threads = {t["id"]: t["name"] for t in c.request("threads")["body"]["threads"]}
        assert threads == {1: "robot program program", 2: "submit interpreter sps"}
        assert frames(c, 2) == [("sps()", 4)]
        assert frames(c, 1) == [("program()", 2)]
        assert c.value("$IN[2]") == "TRUE" and c.value("$OUT[5]") == "FALSE"
        assert c.request("krl/pointers")["body"]["time"] >= 0.2


def test_pause_while_waiting_and_step_back_from_there(tmp_path):
    # WAIT SEC 1000 (l.4): pause stops the program inside the wait
    prog = tmp_path / "waits.src"
    prog.write_text("DEF waits()\n  DECL INT n\n  n = 5\n  WAIT SEC 1000\n  n = 6\nEND\n")
    with DapClient() as c:
        c.initialize()
        c.request("launch", {"program": str(prog), "maxSimTime": 100000})
        c.request("configurationDone")
        c.request("pause", {"threadId": 1})
        st = c.wait_event("stopped")
        for _ in range(3):                                  # paused at a statement, before the wait: go on
            if st["body"].get("description") == "paused while waiting":
                break
            c.request("continue", {"threadId": 1})
            c.request("pause", {"threadId": 1})
            st = c.wait_event("stopped")
        assert st["body"]["reason"] == "pause" and st["body"]["description"] == "paused while waiting"
        assert frames(c) == [("waits()", 4)] and c.value("n") == "5"
        t = c.request("krl/pointers")["body"]["time"]
        assert 0 < t < 1000
        c.request("stepBack", {"threadId": 1})              # back to the start of line 4, t = 0
        c.wait_event("stopped")
        assert frames(c) == [("waits()", 4)] and c.request("krl/pointers")["body"]["time"] == 0.0


def test_a_malformed_message_ends_the_session_without_a_traceback():
    c = DapClient()
    try:
        c.proc.stdin.write(b"Content-Length: 12x\r\n\r\n{}")
        c.proc.stdin.flush()
        c.proc.stdin.close()
        assert c.proc.wait(timeout=60) == 0
        err = c.proc.stderr.read().decode()
        assert "krl debug: protocol error: bad Content-Length '12x'" in err and "Traceback" not in err
    finally:
        c.close()


def test_a_krc_backup_zip_as_workspace(tmp_path):
    backup = tmp_path / "backup.zip"
    with zipfile.ZipFile(backup, "w") as zf:
        zf.writestr("KRC/R1/Program/prog.src", "DEF prog()\n  DECL INT n\n  n = 41\n  n = n + 1\nEND\n")
    with DapClient() as c:
        st = c.start("prog", workspace=str(backup), stopOnEntry=True)     # a module name, as krl run takes it
        assert st["body"]["reason"] == "entry" and frames(c) == [("prog()", 3)]
        assert c.stack()[0]["source"]["path"].endswith("KRC/R1/Program/prog.src")
        c.step("next")
        assert c.value("n") == "41"


def _locals_ref(c):
    scopes = c.request("scopes", {"frameId": c.stack()[0]["id"]})["body"]["scopes"]
    return next(s["variablesReference"] for s in scopes if s["name"] == "Locals")


def test_step_back_after_set_variable_returns_the_edited_state(tmp_path):
    # z = 0 (l.3); a = 1 (l.4); a = 10 / z (l.5); a = a + 1 (l.6). At l.4 the user sets Z = 2
    # (the name in another letter case): l.5 divides by 2, and stepping back must replay the
    # edit, not run into the division by zero it avoided.
    prog = tmp_path / "divide.src"
    prog.write_text("DEF divide()\n  DECL INT a, z\n  z = 0\n  a = 1\n  a = 10 / z\n  a = a + 1\nEND\n")
    with DapClient() as c:
        c.start(prog, breakpoints={prog: [4]})
        assert c.scope_vars(c.stack()[0]["id"], "Locals") == {"a": "<value invalid>", "z": "0"}
        r = c.request("setVariable", {"variablesReference": _locals_ref(c), "name": "Z", "value": "1 + 1"})
        assert r["body"]["value"] == "2"
        assert c.step("next")["body"]["reason"] == "step" and frames(c) == [("divide()", 5)]
        c.step("next")
        assert frames(c) == [("divide()", 6)] and (c.value("a"), c.value("Z")) == ("5", "2")
        c.request("stepBack", {"threadId": 1})
        assert c.wait_event("stopped")["body"]["reason"] == "step"
        assert frames(c) == [("divide()", 5)] and (c.value("a"), c.value("z")) == ("1", "2")
        c.request("stepBack", {"threadId": 1})                 # back to the stop of the edit
        c.wait_event("stopped")
        assert frames(c) == [("divide()", 4)] and c.value("z") == "2"
        c.request("continue", {"threadId": 1})
        assert c.wait_event("exited")["body"]["exitCode"] == 0
        assert not [e for e in c.events if e.get("event") == "stopped"]


def test_step_back_replays_an_input_set_by_hand(tmp_path):
    # n = 1 (l.3); WAIT FOR $IN[3] (l.4); n = 2 (l.5): $IN[3] set at the stop on l.4
    prog = tmp_path / "waitin.src"
    prog.write_text("DEF waitin()\n  DECL INT n\n  n = 1\n  WAIT FOR $IN[3]\n  n = 2\nEND\n")
    with DapClient() as c:
        c.start(prog, breakpoints={prog: [4]}, maxSimTime=30)
        assert c.value("$IN[3]") == "FALSE"
        assert c.request("krl/setInput", {"index": 3, "value": True})["body"]["value"] is True
        c.step("next")
        assert frames(c) == [("waitin()", 5)]
        c.request("stepBack", {"threadId": 1})
        c.wait_event("stopped")
        assert frames(c) == [("waitin()", 4)] and c.value("$IN[3]") == "TRUE"
        c.step("next")                                       # the WAIT FOR passes again at once
        assert frames(c) == [("waitin()", 5)] and c.request("krl/pointers")["body"]["time"] == 0.0


def test_step_back_replays_a_backward_motion():
    # 064 in #MSTEP (T1): PTP (l.4), CIRC to X 605 Y 0 Z 810 (l.7), LIN to Y -100 (l.8)
    with DapClient() as c:
        c.start(CIRC, runMode="MSTEP", mode="T1")
        c.request("continue", {"threadId": 1})
        c.wait_event("stopped")                              # the CIRC has ended
        assert [round(float(c.value(f"$POS_ACT.{k}")), 3) for k in "XYZ"] == [605.0, 0.0, 810.0]
        c.request("krl/backwardStep", {})                    # back along the CIRC, to its start
        back = [c.value(f"$POS_ACT.{k}") for k in "XYZ"]
        assert round(float(back[0]), 3) != 605.0
        c.step("next")                                       # to the LIN's statement
        assert frames(c) == [("program()", 8)] and [c.value(f"$POS_ACT.{k}") for k in "XYZ"] == back
        c.step("next")                                       # the LIN {Y -100}, to its end
        assert round(float(c.value("$POS_ACT.Y")), 3) == -100.0
        c.request("stepBack", {"threadId": 1})               # before the LIN: where the retrace left it
        c.wait_event("stopped")
        assert frames(c) == [("program()", 8)] and [c.value(f"$POS_ACT.{k}") for k in "XYZ"] == back


@pytest.mark.parametrize("when", ["stopped", "running", "terminate"])
def test_disconnect_ends_the_adapter_cleanly(tmp_path, when):
    prog = tmp_path / "spin.src"
    prog.write_text("DEF spin()\n  DECL INT n\n  n = 0\n  LOOP\n    n = n + 1\n  ENDLOOP\nEND\n")
    c = DapClient()
    try:
        c.initialize()
        c.request("launch", {"program": str(prog), "stopOnEntry": when != "running"})
        c.request("configurationDone")
        if when != "running":
            c.wait_event("stopped")
        c.request("terminate" if when == "terminate" else "disconnect", {})
        assert c.proc.wait(timeout=60) == 0
        err = c.proc.stderr.read().decode()
        assert "Fatal" not in err and "Traceback" not in err
    finally:
        c.close()
