"""Workspaces: file pairing, backup discovery (any case), global visibility, CLI, report."""

from __future__ import annotations

import json

from click.testing import CliRunner

from app.check import check as check_cmd
from krl.survey.report import check_report
from krl.workspace import check_texts, load_text, workspaces_for
from krl.project import find_backups, is_system_path


def make_backup(root, r1="R1", system="System", program="Program"):
    (root / "KRC" / r1 / system).mkdir(parents=True)
    (root / "KRC" / r1 / program / "Cell").mkdir(parents=True)
    (root / "KRC" / r1 / system / "$config.dat").write_text(
        "DEFDAT $CONFIG\n  INT gCount = 0\n  DECL E6AXIS XHOME = {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}\n"
        "  EXT BAS(BAS_COMMAND :IN, REAL :IN)\nENDDAT\n")
    (root / "KRC" / r1 / program / "Cell" / "Job.src").write_text(
        "DEF Job()\n  BAS(#INITMOV, 0)\n  PTP XHOME\n  gCount = gCount + Lib(2)\n  PTP XP1\nEND\n")
    (root / "KRC" / r1 / program / "Cell" / "JOB.DAT").write_text(
        "DEFDAT Job\n  DECL E6POS XP1 = {X 10, Y 0, Z 500, A 0, B 90, C 0, S 2, T 35}\nENDDAT\n")
    (root / "KRC" / r1 / program / "lib.src").write_text(
        "DEFFCT INT Lib(n :IN)\n  INT n\n  RETURN n * 2\nENDFCT\n")
    return root / "KRC"


def test_backup_discovery_any_case(tmp_path):
    a = make_backup(tmp_path / "a")
    b = make_backup(tmp_path / "b", r1="r1", system="SYSTEM", program="program")
    assert find_backups(tmp_path) == sorted([a, b])


def test_backup_checks_clean_and_pairs_dat(tmp_path):
    root = make_backup(tmp_path)
    [ws] = workspaces_for(tmp_path)
    diags = ws.check()
    assert not diags, [str(d) for d in diags]
    units = ws.modules
    assert units["JOB"].src is not None and units["JOB"].dat is not None
    assert ws.global_scope.lookup("gcount").module == "$CONFIG"
    assert is_system_path(str(root / "R1" / "System" / "$config.dat"))


def test_single_file_is_checked_in_its_backup(tmp_path):
    """krl/project.py rule 3: a file is checked as part of its program (the backup holding it),
    as krl run runs it; only its own module's diagnostics are reported."""
    root = make_backup(tmp_path)
    job = root / "R1" / "Program" / "Cell" / "Job.src"
    (root / "R1" / "Program" / "broken.src").write_text("DEF broken()\n  x = \nEND\n")
    [ws] = workspaces_for(job)
    assert len(ws.files) == 5           # $config.dat, Job.src, JOB.DAT, lib.src, broken.src
    # gCount ($config.dat) and Lib (another module) are found; broken.src's error is not Job's
    assert ws.check() == []
    [ws] = workspaces_for(root / "R1" / "Program" / "broken.src")
    assert {d.code for d in ws.check()} == {"E012"}     # statement missing a part


def test_cli_text_json_and_exit_codes(tmp_path):
    make_backup(tmp_path)
    runner = CliRunner()
    ok = runner.invoke(check_cmd, [str(tmp_path)])
    assert ok.exit_code == 0, ok.output
    bad = tmp_path / "bad.src"
    bad.write_text("DEF bad()\n  INT i\n  i = TRUE\nEND\n")
    res = runner.invoke(check_cmd, [str(bad)])
    assert res.exit_code == 1
    assert res.output.splitlines() == [
        f"{bad}:3:7: error[E201]: assignment: BOOL is not assignable to INT",
        " 3 |   i = TRUE",
        "   |       ^~~~",
        "1 error in 1 file"]
    res = runner.invoke(check_cmd, [str(bad), "--json"])
    obj = json.loads(res.output.splitlines()[0])
    assert obj["errors"] == 1 and obj["diagnostics"][0]["code"] == "E201"
    assert (obj["diagnostics"][0]["line"], obj["diagnostics"][0]["column"]) == (3, 7)


def test_report_on_small_backup(tmp_path):
    make_backup(tmp_path / "corpus")
    data, md = check_report(tmp_path / "corpus", tmp_path / "out")
    assert data["total"]["files"] == 4 and data["total"]["files_clean"] == 4
    assert json.loads((tmp_path / "out" / "check_report.json").read_text())["total"]["errors"] == 0
    assert "| backup |" in md


def test_folder_with_backups_and_loose_files(tmp_path):
    make_backup(tmp_path / "a")
    (tmp_path / "loose").mkdir()
    (tmp_path / "loose" / "x.src").write_text("DEF x()\nEND\n")
    (tmp_path / "top.src").write_text("DEF top()\nEND\n")
    roots = sorted(ws.root for ws in workspaces_for(tmp_path))
    assert roots == sorted([str(tmp_path / "a" / "KRC"), str(tmp_path / "loose"), str(tmp_path)])


def test_cli_report_option(tmp_path):
    make_backup(tmp_path / "corpus")
    res = CliRunner().invoke(check_cmd, [str(tmp_path / "corpus"), "--report", str(tmp_path / "out")])
    assert res.exit_code == 0 and "| backup |" in res.output
    assert (tmp_path / "out" / "check_report.md").exists()


def test_module_given_as_src_and_dat_is_checked_once(tmp_path):
    """`krl check A.src A.dat`: module A is one workspace, each diagnostic printed once."""
    (tmp_path / "a.src").write_text("DEF a()\n  i = 1\nEND\n")
    (tmp_path / "a.dat").write_text("DEFDAT a\n  DECL INT n = TRUE\nENDDAT\n")
    res = CliRunner().invoke(check_cmd, [str(tmp_path / "a.src"), str(tmp_path / "a.dat")])
    lines = [ln for ln in res.output.splitlines() if ": error[" in ln]
    assert len(lines) == 2, res.output                      # E101 in a.src, E201 in a.dat
    assert sorted(ln.split(": error[")[1][:4] for ln in lines) == ["E101", "E201"]


def test_one_diagnostic_per_code_name_and_line():
    """An unknown type for every name of one DECL line is one E105, not one per name; in
    every parameter of EXT lines of several files it is one W105 for the backup (the
    software that provides the external routine declares its types)."""
    ws = check_texts({"m.src": "DEF m()\nEND\n",
                      "m.dat": "DEFDAT m\n  DECL NOTYPE a, b, c\nENDDAT\n"})
    found = [(d.line, d.code) for d in ws.diagnostics if "NOTYPE" in d.message]
    assert found == [(2, "E105")], found
    ext = "  EXT Foo(PKGTYPE :IN, PKGTYPE :IN, PKGTYPE :OUT)\n"
    ws = check_texts({"m.src": "DEF m()\nEND\n", "m.dat": f"DEFDAT m\n{ext}ENDDAT\n",
                      "n.src": "DEF n()\nEND\n", "n.dat": f"DEFDAT n\n\n{ext}ENDDAT\n"})
    found = [(d.path, d.line, d.code) for d in ws.diagnostics if "PKGTYPE" in d.message]
    assert found == [("m.dat", 2, "W105")], found
    assert "used 6 times in 2 files" in ws.diagnostics[0].message


def test_an_unchecked_copy_checks_alone_and_its_edits_leave_the_original(tmp_path):
    """Workspace.unchecked_copy (krl/survey/mutants.py judges seeded errors in one): the copy
    of a checked backup, checked, has the backup's diagnostics; a new line put in Job.src by
    ``replace`` is found at its line in the copy only, and taking it out again gives the copy
    the backup's diagnostics back."""
    make_backup(tmp_path)
    (tmp_path / "KRC" / "R1" / "Program" / "extra.src").write_text("DEF extra()\n  UNDECLARED = 1\nEND\n")
    [ws] = workspaces_for(tmp_path)
    job = next(f.path for f in ws.files if f.path.endswith("Job.src"))
    ws.check(resolve=False)
    before = [str(d) for d in ws.diagnostics]
    assert [d.code for d in ws.diagnostics] == ["E101"]      # extra.src's own finding
    copy = ws.unchecked_copy()
    assert not copy.checked and [f.path for f in copy.files] == [f.path for f in ws.files]
    assert [str(d) for d in copy.check(resolve=False)] == before
    text = (tmp_path / "KRC" / "R1" / "Program" / "Cell" / "Job.src").read_text()
    seeded = text.replace("  PTP XHOME\n", "  PTP XHOME\n  gCont = 1\n")
    assert copy.replace(load_text(seeded, job)) == "routines"
    assert [(d.code, d.line) for d in copy.diagnostics if d.path == job] == [("E101", 4)]
    assert [str(d) for d in ws.diagnostics] == before
    assert copy.replace(ws.loaded[job]) == "routines"
    assert [str(d) for d in copy.diagnostics] == before
