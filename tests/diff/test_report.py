"""The pieces of the change report (krl/diff/report.py, interp/outcomes.py, issues 49 and 63) on
inputs whose answers were worked out by hand: which check findings are new or fixed, which entry
points a change touches, when two run outcomes differ, and what to retest on the robot."""

from __future__ import annotations

import shutil
from pathlib import Path

from interp.outcomes import _Events, ends_alike, event_kind, outcome_changes
from interp.outcomes import _outcome as outcome_of
from krl.diff.core import Diff, diff_sides
from krl.diff.load import side
from krl.diff.report import (
    Finding, Touched, _run_row, cause_remains, css_string, findings, findings_delta, retest, touched_entries,
)
from krl.programmap import build_map
from krl.workspace import workspaces_for

FIXTURE = Path(__file__).parents[1] / "programmap" / "fixtures" / "KRC"


def _f(file: str, message: str, text: str = "x = 1", code: str = "E101", routine: str = "main", line: int = 3) -> Finding:
    symbol = message.split("'")[1] if "'" in message else ""
    return Finding(code, "error", message, file, line, 1, text, symbol=symbol, routine=routine)


def test_the_same_missing_routines_are_neither_new_nor_fixed():
    """Issue 72, item 7: two versions of a Main.src call the same two routines the backup lacks
    (E1xx "unknown routine"), 7 calls in the old, 8 in the new, on lines that moved and whose
    arguments changed: the findings of one routine, code and symbol are the same findings (the
    one more call is one new finding), not "8 new" and "7 fixed"."""
    def calls(n: int, shift: int, arg: str) -> list:
        return [_f("R1/Main.src", f"unknown routine '{name}'", f"{name}({arg}{i})", code="E102", line=10 + shift + 5 * i)
                for i in range(n) for name in (("GRIP",) if i % 2 else ("UNGRIP",))]
    old, new = calls(7, 0, "a"), calls(8, 3, "b")
    files = ({"r1/main.src"}, {"r1/main.src"})
    introduced, removed = findings_delta(old, new, files)
    assert [(f.symbol, f.line) for f in introduced] == [("GRIP", 13 + 35)]
    assert removed == []


def test_findings_are_matched_by_file_code_symbol_routine_and_message():
    old = [_f("R1/a.src", "'n' is not declared"),
           _f("R1/a.src", "system variable '$x' (used 19 times in 2 files)"),
           _f("R1/b.src", "'gone' is not declared"),
           _f("Old/c.src", "'m' is not declared"),             # its folder renamed: the same finding
           _f("R1/d.src", "'k' is not declared", "k = 2"),      # its line edited: the same finding
           _f("R1/d.src", "'k' is not declared", "k = 2", routine="other")]   # in another routine: fixed
    new = [_f("R1/a.src", "'n' is not declared"),
           _f("R1/a.src", "system variable '$x' (used 26 times in 2 files)"),
           _f("New/c.src", "'m' is not declared"),
           _f("R1/d.src", "'k' is not declared", "k = 3"),
           _f("R1/e.src", "'fresh' is not declared"), _f("R1/e.src", "'fresh' is not declared")]
    files = ({"r1/a.src", "r1/b.src", "old/c.src", "r1/d.src", "src/e.src"},
             {"r1/a.src", "new/c.src", "r1/d.src", "r1/e.src", "src/e.src"})
    introduced, removed = findings_delta(old, new, files)
    assert [(f.file, f.text) for f in introduced] == [("R1/e.src", "x = 1"), ("R1/e.src", "x = 1")]
    assert [(f.file, f.text, f.routine) for f in removed] == [("R1/b.src", "x = 1", "main"), ("R1/d.src", "k = 2", "other")]
    # without the files, the renamed folder's finding is new and fixed
    introduced, removed = findings_delta(old, new)
    assert ("New/c.src", "Old/c.src") == (introduced[0].file, removed[1].file)
    # a finding of a file both sides have (src/e.src) never pairs with another file's of that name
    introduced, removed = findings_delta([_f("src/e.src", "'fresh' is not declared")], new[4:5], files)
    assert [f.file for f in introduced] == ["R1/e.src"] and [f.file for f in removed] == ["src/e.src"]


def _maps(tmp_path: Path, edit) -> tuple:
    old, new = tmp_path / "old" / "KRC", tmp_path / "new" / "KRC"
    shutil.copytree(FIXTURE, old)
    shutil.copytree(FIXTURE, new)
    edit(new)
    with side(old) as a, side(new) as b:
        d = diff_sides(a, b)
    return d, build_map(workspaces_for(old)[0]), build_map(workspaces_for(new)[0])


def test_a_changed_routine_touches_the_programs_that_reach_it(tmp_path):
    def edit(root: Path):
        p = root / "R1" / "Program" / "pick.src"
        p.write_text(p.read_text().replace("  RETURN x\n", "  RETURN x + 1\n"))
    d, old, new = _maps(tmp_path, edit)
    assert [(r["name"], r["change"]) for r in d.routines] == [("helper_fct", "changed")]
    touched = touched_entries(d, old, new)
    # cell calls pick, which calls helper_fct; pick is an operator's program too. aux (RUN
    # from pick), orphan, bg and sps do not reach helper_fct
    assert [(t.id, t.kind) for t in touched] == [("CELL:CELL", "cell"), ("PICK:PICK", "operator")]
    assert all(t.old and t.new and t.why == "routine helper_fct changed" for t in touched)


def test_a_changed_value_touches_the_programs_that_use_it(tmp_path):
    def edit(root: Path):
        p = root / "R1" / "System" / "$config.dat"
        p.write_text(p.read_text().replace("DECL INT shared\n", "DECL INT shared=1\n"))
    d, old, new = _maps(tmp_path, edit)
    assert [(e["name"], e["change"]) for e in d.values] == [("shared", "added")]
    touched = touched_entries(d, old, new)
    # plc_step (sps.sub) writes shared: the submit program; nothing else uses it
    assert [(t.id, t.kind) for t in touched] == [("SPS:SPS", "submit")]
    assert "used by plc_step" in touched[0].why


def test_a_routine_using_two_changed_values_names_the_first_by_file_and_name(tmp_path):
    """The values a routine uses are a set, whose order is the process's string hashes: the
    change report named one or the other of two changed values a routine uses, from run to run
    (ChinaMilling's history pair 01-449a17dd: "grUSedRPM ... changed, used by ResetVars" or
    "gnLastToolNr ..."). Here plc_step uses alpha and zeta, both given a value: the reason names
    alpha, the first by name, whatever order the routine's uses come in."""
    old, new = tmp_path / "old" / "KRC", tmp_path / "new" / "KRC"
    for root, init in ((old, ""), (new, "=1")):
        shutil.copytree(FIXTURE, root)
        sub = root / "R1" / "System" / "sps.sub"
        sub.write_text(sub.read_text().replace("shared = shared + 1", "shared = zeta + alpha"))
        cfg = root / "R1" / "System" / "$config.dat"
        cfg.write_text(cfg.read_text().replace("DECL INT shared\n", f"DECL INT shared\nDECL INT zeta{init}\nDECL INT alpha{init}\n"))
    with side(old) as a, side(new) as b:
        d = diff_sides(a, b)
    assert sorted((e["name"], e["change"]) for e in d.values) == [("alpha", "added"), ("zeta", "added")]
    maps = [build_map(workspaces_for(old)[0]), build_map(workspaces_for(new)[0])]
    for pm in maps:     # the uses in the reverse of their sorted order
        step = next(n for n in pm.nodes.values() if n.name == "plc_step")
        assert {name for _path, name in step.uses} >= {"ALPHA", "ZETA"}
        step.uses = sorted(step.uses, reverse=True)
    touched = touched_entries(d, *maps)
    assert [(t.id, t.kind) for t in touched] == [("SPS:SPS", "submit")]
    assert touched[0].why.startswith("alpha (") and touched[0].why.endswith(" added, used by plc_step")


def _outcome(reason="completed", text="", line=9, cycle=17.844, counts=None, file=None, statement=""):
    return {"reason": reason, "text": text, "line": line, "cycle_time": cycle, "counts": counts or {}, "file": file,
            "statement": statement}


def test_two_outcomes_differ_in_how_they_end_their_cycle_time_or_their_motion_events():
    assert outcome_changes(_outcome(), _outcome()) == []
    # one IPO cycle (12 ms) is the same cycle time; two are not
    assert outcome_changes(_outcome(cycle=17.844), _outcome(cycle=17.832)) == []
    assert outcome_changes(_outcome(cycle=17.844), _outcome(cycle=17.820)) == ["cycle time"]
    # both stopped by the time limit at the same statement (moved by an edit above it): alike;
    # one running there and the other waiting: not the same message (issue 72)
    limit = dict(reason="max_sim_time", cycle=None, file="/a/x.src", statement="LOOP")
    assert outcome_changes(_outcome(line=70, text="simulated time limit 60.0 s reached", **limit),
                           _outcome(line=72, text="simulated time limit 60.0 s reached", **limit)) == []
    assert outcome_changes(_outcome(line=70, text="simulated time limit 60.0 s reached", **limit),
                           _outcome(line=72, text="simulated time limit 60.0 s reached while the robot program waits",
                                    **limit)) == ["ends differently"]
    # an error where it completed; an error message naming other folders is the same message
    err = dict(reason="error", cycle=None, text="software limit switch -A1 at /a/old/x.src:12")
    assert outcome_changes(_outcome(), _outcome(**err)) == ["ends differently", "cycle time"]
    assert outcome_changes(_outcome(**err), _outcome(**{**err, "text": "software limit switch -A1 at /b/new/x.src:12"})) == []
    assert outcome_changes(_outcome(counts={"reach": 1}), _outcome()) == ["motion events"]
    # a deadlock at the same statement, moved from line 40 to 44 by an edit above it: the same
    # place; at another statement: not
    wait = dict(reason="deadlock", cycle=None, text="waits: WAIT FOR $IN[5] at /a/old/x.src:40", file="/a/old/x.src",
                statement="WAIT FOR $IN[5]")
    assert outcome_changes(_outcome(line=40, **wait), _outcome(
        line=44, **{**wait, "file": "/b/new/x.src", "text": "waits: WAIT FOR $IN[5] at /b/new/x.src:44"})) == []
    assert outcome_changes(_outcome(line=40, **wait), _outcome(line=44, **{**wait, "statement": "WAIT FOR $IN[6]"})) == [
        "ends at another statement"]
    assert outcome_changes(None, _outcome()) == ["only in the new backup"]


def test_ends_alike_only_with_the_same_cause_statement_and_message():
    """Issue 72, item 7: the old Main.src stops at the step limit at line 52 (t = 3.684 s), the
    new one waits at line 129 until the time limit: the report must not say "the same"."""
    old = {**_outcome(reason="max_steps", text="step limit 300000 reached", line=52, cycle=None, file="/a/Main.src",
                      statement="nCount = nCount + 1"), "cause": "limit", "ending": "stopped at the step limit",
           "sim_time": 3.684}
    new = {**_outcome(reason="max_sim_time", line=129, cycle=None, file="/b/Main.src", statement="WAIT FOR $IN[7]",
                      text="simulated time limit 60.0 s reached while the robot program waits: WAIT FOR at "
                           "/b/Main.src:129"), "cause": "limit", "ending": "stopped at the time limit",
           "sim_time": 60.0}
    assert outcome_changes(old, new) == ["ends differently"]
    assert not ends_alike(old, new)
    # the same wait in both, moved from line 125 to 129: alike; another WAIT FOR: not
    moved = {**new, "line": 125, "file": "/a/Main.src", "text": new["text"].replace("/b/Main.src:129", "/a/Main.src:125")}
    assert outcome_changes(moved, new) == [] and ends_alike(moved, new)
    other = {**moved, "statement": "WAIT FOR $IN[8]"}
    assert outcome_changes(other, new) == ["ends at another statement"] and not ends_alike(other, new)
    # the report's row says "the same" exactly when the ends are alike
    for a, b in ((old, new), (other, new), (moved, new)):
        t = Touched("MAIN:MAIN", "Main", "Main", "program", "/a/Main.src", "/b/Main.src", "changed",
                    old_outcome=a, new_outcome=b, changes=outcome_changes(a, b), ends_alike=ends_alike(a, b))
        assert _run_row(t, lambda *x: "", {})["same_end"] is ends_alike(a, b)


def test_motion_events_are_named_by_the_controllers_messages():
    assert event_kind("workspace error: target not reachable (XP3)") == "reach"
    assert event_kind("software limit switch -A3") == "limit"
    assert event_kind("CP path through a singularity: A4 would turn 170 deg") == "singularity"
    assert event_kind("speed limit exceeded A1: CP path through a singularity") == "singularity"
    assert event_kind("first motion must be PTP") == "motion"


def test_a_motion_refused_in_the_advance_run_is_the_runs_motion_event():
    # kukaKRLmagic's sample_program (history pair 01-53e3f517, old side): the planner refuses
    # line 81's target before any main-run motion error is written; the run ends with it
    o = outcome_of("p.src", "error", "software limit switch +A3 (the target itself: ...)", "p.src", 81, 0.0, _Events(), "")
    assert o["counts"] == {"limit": 1} and o["events"][0]["line"] == 81
    # an error that is no motion's is not a motion event
    assert outcome_of("p.src", "error", "unknown name P_Button", "p.src", 46, 0.0, _Events(), "")["counts"] == {}


def test_the_retest_list_is_derived_from_the_changes():
    # issue 63: a diff written by hand; each row below follows from one rule of
    # krl/diff/report.py retest (no program map: no touched program, every changed routine a row)
    d = Diff("old", "new")
    d.frames = [{"file": "R1/System/$config.dat", "name": "TOOL_DATA[1]", "kind": "TOOL_DATA", "change": "changed",
                 "delta": {"Z": 5.5}, "line": 231},
                {"file": "R1/System/$config.dat", "name": "BASE_DATA[2]", "kind": "BASE_DATA", "change": "removed",
                 "delta": {}, "line": 240}]
    d.points = [{"file": "R1/Program/a.dat", "name": "XP1", "kind": "E6POS", "change": "changed", "delta": {"X": 1.0},
                 "line": 4, "status_turn_changed": True},
                {"file": "R1/Program/a.dat", "name": "XP2", "kind": "E6POS", "change": "added", "delta": {}, "line": 5,
                 "status_turn_changed": False},
                {"file": "R1/Mada/$machine.dat", "name": "$ROBROOT", "kind": "FRAME", "change": "changed",
                 "delta": {"A": 90.0}, "line": 97, "status_turn_changed": False}]
    d.values = [{"file": "R1/Mada/$machine.dat", "name": "$BRK_DEL", "change": "added", "line": 297},
                {"file": "R1/Program/a.dat", "name": "nCount", "change": "changed", "line": 9}]
    d.routines = [{"file": "R1/Program/a.src", "module": "a", "name": "pick", "change": "changed", "line": 12},
                  {"file": "R1/Program/a.src", "module": "a", "name": "old_one", "change": "removed", "line": 40}]
    d.motions = [{"file": "R1/Program/a.src", "routine": "pick", "motion": "PTP", "point": "XP1", "line": 20,
                  "changed": {"velocity": [100, 50]}},
                 {"file": "R1/Program/a.src", "routine": "pick", "motion": "LIN", "point": "XP2", "line": 22,
                  "changed": {"approximation": ["C_DIS", None]}}]
    d.declarations = [{"file": "R1/System/$config.dat", "scope": "", "name": "bGripOpen", "kind": "signal",
                       "change": "retyped", "before": "$IN[3]", "after": "$IN[4]", "line": 700}]
    rows = [(r["area"], r["file"], r["line"]) for r in retest(d, [])]
    assert rows == [
        ("routine", "R1/Program/a.src", 12),            # pick changed; old_one removed: no row
        ("tool", "R1/System/$config.dat", 231),         # TOOL_DATA[1]; BASE_DATA[2] removed: no row
        ("machine data", "R1/Mada/$machine.dat", 97),   # $ROBROOT and $BRK_DEL, one row for the file
        ("points", "R1/Program/a.dat", 4),              # XP1 and XP2, one row for the file
        ("motions", "R1/Program/a.src", 20),            # both motions of pick, one row
        ("signal", "R1/System/$config.dat", 700),
    ]
    by = {r["area"]: r for r in retest(d, [])}
    assert "$ROBROOT, $BRK_DEL" in by["machine data"]["what"]
    assert "approach XP1, XP2 in T1" in by["points"]["what"] and "XP1: status/turn changed" in by["points"]["what"]
    assert by["motions"]["why"] == "changed: approximation, velocity" and "line(s) 20, 22" in by["motions"]["what"]


def test_a_backup_name_in_the_printed_foot_cannot_leave_its_css_string():
    # the foot of each printed page names the backups inside the page's <style> (a CSS string):
    # a quote, a backslash, a newline or "</style>" from a folder name is escaped, letters stay
    text = 'cell "A"\\x\n</style><script>alert(1)</script> Ä'
    out = str(css_string(text))
    assert out.startswith('"') and out.endswith('"') and out.count('"') == 2
    inner = out[1:-1]
    assert "<" not in inner and ">" not in inner and "\n" not in inner
    assert inner.startswith("cell \\000022A\\000022\\00005cx\\00000a\\00003c/style\\00003e")
    assert inner.endswith(" \\0000c4")


def test_one_of_two_identical_occurrences_gone_is_not_fixed():
    """Issue 85, item 5: the old backup used an undeclared name twice in one routine (two
    identical findings: same file, code, symbol, routine, message), the new once. One
    occurrence went; the cause (the undeclared name) remains: not "fixed". A finding whose
    every occurrence went is fixed."""
    old = [_f("R1/a.src", "'nPart' is not declared", "nPart = 1", line=4),
           _f("R1/a.src", "'nPart' is not declared", "nPart = nPart + 1", line=9),
           _f("R1/a.src", "'gone' is not declared", "gone = 2", line=12)]
    new = [_f("R1/a.src", "'nPart' is not declared", "nPart = nPart + 1", line=8)]
    files = ({"r1/a.src"}, {"r1/a.src"})
    introduced, removed = findings_delta(old, new, files)
    assert introduced == []
    fixed, fewer = cause_remains(removed, new)
    assert [(f.symbol, f.line) for f in fixed] == [("gone", 12)]
    assert [f.symbol for f in fewer] == ["nPart"]       # which of the two went: either line


def test_a_users_global_of_config_dat_is_not_machine_data():
    """Issue 85, item 5: a value of $config.dat in its USER GLOBALS fold (the programmers' own
    global, KUKA's template keeps them there) changed: a "global data" row, not "machine data";
    a value of $config.dat outside the USER folds (KUKA's configuration) stays machine data."""
    config = ("DEFDAT $CONFIG\n"                              # 1
              "INT PGNO_TYPE=1\n"                             # 2  KUKA's
              ";FOLD USER GLOBALS\n"                          # 3
              "DECL INT nPartCount=0\n"                       # 4  the programmers'
              ";ENDFOLD (USER GLOBALS)\n"                     # 5
              "ENDDAT\n")
    d = Diff("old", "new")
    d.values = [{"file": "R1/System/$config.dat", "name": "nPartCount", "change": "changed", "line": 4},
                {"file": "R1/System/$config.dat", "name": "PGNO_TYPE", "change": "changed", "line": 2}]
    rows = retest(d, [], texts=lambda file: config if file == "R1/System/$config.dat" else None)
    got = [(r["area"], r["line"]) for r in rows]
    assert got == [("machine data", 2), ("global data", 4)]
    assert "nPartCount" in rows[1]["what"] and "PGNO_TYPE" not in rows[1]["what"]
    # without the file's text nothing tells them apart: both stay machine data (one row)
    assert [r["area"] for r in retest(d, [])] == ["machine data"]
