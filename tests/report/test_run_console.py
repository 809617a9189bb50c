"""`krl run` on the console: the one-screen summary, --workspace, stimuli errors (issues 12, 13)."""

from __future__ import annotations

import textwrap
from pathlib import Path

from click.testing import CliRunner

from app import main

HOME = "{A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}"


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text).lstrip("\n"), encoding="utf-8")
    return path


def run(*args: str) -> tuple[int, str]:
    res = CliRunner().invoke(main, ["run", *args])
    return res.exit_code, res.output


def test_summary_of_a_completed_run(tmp_path):
    prog = write(tmp_path / "cell.src", f"""
        DEF cell()
          DECL KrlMsg_T m
          DECL KrlMsgPar_T par[3]
          DECL KrlMsgOpt_T opt
          DECL INT h
          m = {{MODUL[] "CELL", NR 7, MSG_TXT[] "gripper closed"}}
          h = SET_KRLMSG(#NOTIFY, m, par[], opt)
          PTP {HOME}
          PTP {{A1 10}}
          LIN_REL {{Z 20}}
          $OUT[3] = TRUE
          $OUT[4] = TRUE
          $OUT[3] = FALSE
        END
        """)
    code, out = run(str(prog))
    assert code == 0, out
    lines = out.splitlines()
    assert lines[0] == f"run {prog} (tree interpreter)"
    assert lines[1].startswith("  ended      completed at t=")
    assert "  messages   1" in lines
    assert "    t=0.000 s  KRL message: gripper closed" in lines
    # three motions were enqueued: PTP, PTP, LIN_REL
    assert "  motions    3 (LIN_REL 1, PTP 2)" in lines
    # $OUT[3] up, $OUT[4] up, $OUT[3] down: three changes of outputs
    assert "  I/O        3 change(s) ($OUT 3)" in lines
    assert len(lines) <= 24


def test_error_names_file_line_and_message_on_both_interpreters(tmp_path):
    prog = write(tmp_path / "div.src", """
        DEF div()
          DECL INT a, b
          b = 0
          a = 10 / b
        END
        """)
    for interp in ("tree", "vm"):
        code, out = run(str(prog), "--interp", interp)
        assert code == 1, out
        lines = out.splitlines()
        assert lines[1].startswith("  ended      stopped by a run-time error at t=0.000 s")
        assert lines[2] == f"             {prog}:4: division by zero"


def test_submit_error_is_on_the_console(tmp_path):
    # Before: only the trace file held the submit program's error; the console said
    # "time limit reached".
    prog = write(tmp_path / "main.src", """
        DEF main()
          LOOP
            WAIT SEC 0.1
          ENDLOOP
        END
        """)
    sub = write(tmp_path / "sps.sub", """
        DEF sps()
          DECL INT i, z
          z = 0
          LOOP
            i = 5 / z
          ENDLOOP
        END
        """)
    code, out = run(str(prog), "--submit", str(sub), "--max-sim-time", "0.5")
    assert code == 3, out
    # 0.5 s is reached in the 42nd IPO cycle of 12 ms: t = 0.504 s
    assert "  ended      stopped at the time limit (--max-sim-time) at t=0.504 s" in out
    assert f"  submit     sps stopped by a run-time error: {sub}:5: " in out


def test_control_characters_from_krl_never_reach_the_terminal(tmp_path):
    prog = write(tmp_path / "esc.src", """
        DEF esc()
          DECL KrlMsg_T m
          DECL KrlMsgPar_T par[3]
          DECL KrlMsgOpt_T opt
          DECL INT h, ofs
          DECL CHAR txt[40]
          DECL STATE_T st
          ofs = 0
          SWRITE(txt[], st, ofs, "a%cb%cc", 27, 155)
          m = {MODUL[] "X", NR 1, MSG_TXT[] " "}
          m.MSG_TXT[] = txt[]
          h = SET_KRLMSG(#NOTIFY, m, par[], opt)
          HALT
        END
        """)
    code, out = run(str(prog))
    assert code == 3, out
    assert "\x1b" not in out and "\x9b" not in out
    assert "KRL message: a\\x1bb\\x9bc" in out
    assert "  ended      stopped by HALT" in out


def test_workspace_always_wins_over_an_ancestor_backup(tmp_path):
    # An unrelated folder above the workspace holds System/$config.dat and a GLOBAL routine.
    write(tmp_path / "System" / "$config.dat", "DEFDAT $CONFIG\nENDDAT\n")
    write(tmp_path / "evil.src", """
        GLOBAL DEF helper()
          $OUT[9] = TRUE
        END
        """)
    ws = tmp_path / "job"
    prog = write(ws / "prog.src", """
        DEF prog()
          helper()
        END
        """)
    # --workspace: the ancestor is not adopted, so helper does not exist: the checker
    # refuses to start the program, and with --no-check the run stops at the call.
    code, out = run(str(prog), "--workspace", str(ws))
    assert code == 1, out
    assert f"{prog}:2:3: error[E106]: routine 'helper' is not declared" in out.splitlines()
    code, out = run(str(prog), "--workspace", str(ws), "--no-check")
    assert code == 1, out
    assert f"             {prog}:2: routine helper not found" in out.splitlines()
    assert "$OUT" not in out
    # without --workspace the backup above is found, and the console says so
    code, out = run(str(prog))
    assert code == 0, out
    assert f"  workspace  {tmp_path} (KRC backup found above the program)" in out
    assert "  I/O        1 change(s) ($OUT 1)" in out


def test_stimuli_error_is_a_message_not_an_internal_error(tmp_path):
    prog = write(tmp_path / "p.src", "DEF p()\n  WAIT FOR $IN[1]\nEND\n")
    stim = write(tmp_path / "s.yaml", "stimulus:\n  - at: 0.1\n    set: {'$IN[1]': true}\n")
    code, out = run(str(prog), "--inputs", str(stim))
    assert code == 2
    assert f"error: {stim}:1: unknown top-level key 'stimulus'" in out
    assert "internal error" not in out


def test_stimulus_by_signal_name(tmp_path):
    prog = write(tmp_path / "p.src", """
        DEF p()
          WAIT FOR PART_OK
          WAIT FOR CODE == 5
          $OUT[1] = TRUE
        END
        """)
    write(tmp_path / "p.dat", """
        DEFDAT p
          SIGNAL PART_OK $IN[3]
          SIGNAL CODE $IN[10] TO $IN[13]
        ENDDAT
        """)
    stim = write(tmp_path / "s.yaml", """
        stimuli:
          - at: 0.1
            set: {PART_OK: true}
          - at: 0.2
            set: {code: 5}
        """)
    code, out = run(str(prog), "--inputs", str(stim), "--max-sim-time", "2")
    assert code == 0, out
    # PART_OK -> $IN[3]; CODE 5 = 0b0101 -> $IN[10] and $IN[12] rise ($IN[11], $IN[13] stay FALSE)
    assert "  I/O        4 change(s) ($IN by stimulus 3, $OUT 1)" in out


def test_a_wait_for_an_input_nobody_sets_gets_a_hint(tmp_path):
    """The program waits for $IN[5] and nothing can set it (no stimulus, no interrupt, no
    submit program): the run ends deadlocked at line 3, then a hint names --inputs."""
    prog = write(tmp_path / "cell.src", """
        DEF cell()
          $OUT[1] = TRUE
          WAIT FOR $IN[5]
        END
        """)
    code, out = run(str(prog), "--max-sim-time", "0.5")
    assert code == 3, out
    lines = out.splitlines()
    assert lines[2] == f"             {prog}:3: deadlocked WAIT FOR"
    # issue 22: the summary names the input the WAIT FOR starves on and a cell rule releasing it
    assert lines[3] == f"  starves    WAIT FOR at {prog}:3 waits on $IN[5]"
    assert lines[4].startswith("  a rule     that releases it, in a cell file given with --inputs")
    assert "- {when: \"TRUE\", after: 1.0, set: {'$IN[5]': true}}" in lines[6]
    stim = write(tmp_path / "stim.yaml", """
        stimuli:
          - at: 0.1
            set: {"$IN[5]": true}
        """)
    code, out = run(str(prog), "--max-sim-time", "0.5", "--inputs", str(stim))
    assert code == 0, out
    assert "hint" not in out


def test_stimulus_by_a_global_signal_of_another_module(tmp_path):
    """A GLOBAL SIGNAL declared in another module's public data list is seen by the program
    (the run loads that list on demand), so the stimuli may name it too."""
    prog = write(tmp_path / "p.src", """
        DEF p()
          WAIT FOR DOOR_OK
          $OUT[1] = TRUE
        END
        """)
    write(tmp_path / "cell.dat", """
        DEFDAT cell PUBLIC
          GLOBAL SIGNAL DOOR_OK $IN[7]
        ENDDAT
        """)
    stim = write(tmp_path / "s.yaml", """
        stimuli:
          - at: 0.1
            set: {DOOR_OK: true}
        """)
    code, out = run(str(prog), "--inputs", str(stim), "--max-sim-time", "2")
    assert code == 0, out
    assert "  I/O        2 change(s) ($IN by stimulus 1, $OUT 1)" in out
