"""`krl audit` on a small folder of programs written here, and on bad input (issue 49; GUIDE
"Untrusted input"): how each entry point ends, the report's JSON against its schema, markup
from a file (its text and its name) inert in the page, and usage errors that name the folder
or the limit with exit code 2 and no traceback.

Every expected value is read off the files of PROGRAMS (the comments say how)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner
from jsonschema import Draft202012Validator

import audit.fleet as F
from audit.report import _cycle, health
from app import main

REPO = Path(__file__).resolve().parents[2]

# the tests of the module's one audit (`audited`) go to one xdist worker (make test: --dist
# loadgroup; spread over two workers, each made it: 0.45 s of CPU each, 2026-11-27)
pytestmark = pytest.mark.xdist_group("audit-cli")
PWNED = "<script>window.pwned=1</script>"
PROGRAMS = {
    "good.src": "DEF good()\n  DECL INT n\n  n = 1\nEND\n",
    # line 4 divides by b = 0: a run-time error there
    "div.src": "DEF div()\n  DECL INT a, b\n  b = 0\n  a = 1 / b\nEND\n",
    # an endless loop without motion: the step limit ends it
    "spin.src": "DEF spin()\n  LOOP\n  ENDLOOP\nEND\n",
    # the IF of line 3 has no ENDIF (E010 at 3:3); markup in a comment
    "bad.src": f"DEF bad()\n  ; {PWNED}\n  IF x THEN\nEND\n",
    # markup in a file's name
    "<i>mark.src": "DEF mark()\n  $OUT[3] = TRUE\nEND\n",
    # issue 63: two programs stopped by one line (div.src:4, through the call): one cause, two
    # sites; an interrupt routine (good2's INTERRUPT DECL, line 2, calls ir_door) is no entry
    # point on its own
    "twice.src": "DEF twice()\n  div()\nEND\n",
    "good2.src": "DEF good2()\n  INTERRUPT DECL 3 WHEN $IN[1] DO ir_door()\nEND\n",
    "ir_door.src": "DEF ir_door()\n  DECL INT a, b\n  a = 1 / b\nEND\n",
}


def _audit(args: list[str]):
    return CliRunner().invoke(main, ["audit", *args])


@pytest.fixture(scope="module")
def audited(tmp_path_factory):
    fleet = tmp_path_factory.mktemp("fleet")
    for name, text in PROGRAMS.items():
        (fleet / "cell" / name).parent.mkdir(exist_ok=True)
        (fleet / "cell" / name).write_text(text.replace("\n", "\r\n"), encoding="latin-1")
    out = tmp_path_factory.mktemp("out")
    res = _audit([str(fleet), "--out", str(out), "--max-steps", "10000", "--jobs", "1"])
    return fleet, out, res, json.loads((out / "audit.json").read_text(encoding="utf-8"))


def test_how_each_entry_point_ends(audited):
    fleet, _out, res, data = audited
    assert res.exit_code == 1, res.output            # a program error: attention
    assert "Traceback" not in res.output
    (u,) = data["units"]
    # the folder named is the unit: named with its parent (issue 63: a backup's folder is often
    # just "KRC"); a program folder names no robot
    assert (u["name"], u["kind"], u["root"]) == (f"{fleet.parent.name}/{fleet.name}", "folder", str(fleet))
    assert (u["title"], u["robot"]) == (u["name"], "")
    got = {e["program"]: (e["cause"], e["reason"], e["file"], e["line"]) for e in u["entries"]}
    # bad.src's DEF line parses, so it is a program (issue 63: what parsed is used); its IF has
    # no ENDIF, so its blocks are in doubt from line 3 on: the run does not enter it and says so,
    # a gap of the simulator (the E010 is a finding, below)
    assert got == {
        "cell/good.src": ("completed", "completed", "cell/good.src", 3),
        "cell/<i>mark.src": ("completed", "completed", "cell/<i>mark.src", 2),
        "cell/div.src": ("program error", "error", "cell/div.src", 4),
        "cell/spin.src": ("limit", "max_steps", "cell/spin.src", 2),
        "cell/bad.src": ("interpreter gap", "error", "cell/bad.src", 3),
        "cell/twice.src": ("program error", "error", "cell/div.src", 4),
        "cell/good2.src": ("completed", "completed", "cell/good2.src", 2),
    }
    assert u["handlers"] == [{"program": "cell/ir_door.src",
                              "why": "an interrupt routine: good2 calls it by INTERRUPT DECL ... DO at cell/good2.src:2"}]
    # by cause: div.src:4 stops two programs (one row, two sites); the three that complete are
    # one cause
    causes = [(c["cause"], c["file"], c["line"], c["count"], c["programs"]) for c in u["causes"]]
    assert causes == [
        ("program error", "cell/div.src", 4, 2, ["cell/div.src", "cell/twice.src"]),
        ("interpreter gap", "cell/bad.src", 3, 1, ["cell/bad.src"]),
        ("limit", "cell/spin.src", 2, 1, ["cell/spin.src"]),
        ("completed", None, None, 3, ["cell/<i>mark.src", "cell/good.src", "cell/good2.src"]),
    ]
    errors = [(f["code"], f["file"], f["line"], f["column"]) for f in u["findings"] if f["severity"] == "error"]
    assert errors == [("E010", "cell/bad.src", 3, 3)]
    assert u["status"] == "attention"
    assert [(r["level"], r["text"]) for r in u["reasons"]] == [
        ("attention", "2 of 7 entry points end in a program error (1 cause)"),
        ("review", "1 check error"),
        ("review", "1 of 7 entry points stop at a limit of the audit (starving or looping)"),
        ("review", "1 of 7 entry points stop at a gap of the simulator (1 cause)"),
    ]
    # the terminal: one line for the folder, then the totals
    # (good.src, good2.src and <i>mark.src complete; div.src and twice.src; spin.src and
    # bad.src; bad.src's E010)
    assert res.output.splitlines()[0] == (
        f"attention {fleet.parent.name}/{fleet.name}: 1 check error, 7 entry points (3 completed or intended end, "
        f"2 program errors, 2 limit or gap), 0 motion errors, 0 outputs to review")
    # what it read: the 8 files written above (ir_door.src is no entry point: an interrupt's handler)
    assert res.output.splitlines()[1] == "0 backups, 1 program folder (8 files), 7 entry points: 1 attention, 0 review, 0 ok"


def test_the_json_follows_its_schema(audited):
    _fleet, _out, _res, data = audited
    schema = json.loads((REPO / "docs" / "schemas" / "audit.schema.json").read_text(encoding="utf-8"))
    Draft202012Validator(schema).validate(data)
    with pytest.raises(Exception, match="status"):
        Draft202012Validator(schema).validate({**data, "units": [{**data["units"][0], "status": "fine"}]})


def test_markup_from_the_files_is_inert_in_the_page(audited):
    _fleet, out, _res, _data = audited
    page = (out / "audit.html").read_text(encoding="utf-8")
    assert PWNED not in page and "<i>mark" not in page
    assert "; &lt;script&gt;window.pwned=1&lt;/script&gt;" in page        # bad.src:2 in the evidence of 3
    assert "cell/&lt;i&gt;mark.src" in page


def test_not_a_folder_is_a_usage_error(tmp_path):
    res = _audit([str(tmp_path / "missing"), "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and isinstance(res.exception, SystemExit)
    assert f"krl audit: error: {tmp_path / 'missing'}: not a folder" in res.output
    assert "Traceback" not in res.output and not (tmp_path / "o").exists()


def test_more_units_than_the_limit_is_a_usage_error(tmp_path, monkeypatch):
    # two KRC backups (each a folder with R1/System/$config.dat): two units
    for name in ("a", "b"):
        (tmp_path / name / "R1" / "System").mkdir(parents=True)
        (tmp_path / name / "R1" / "System" / "$config.dat").write_text("DEFDAT $CONFIG\nENDDAT\n")
    monkeypatch.setattr(F, "MAX_AUDIT_BACKUPS", 1)
    res = _audit([str(tmp_path), "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and "Traceback" not in res.output
    assert "more than 1 backups and program folders below" in res.output and "MAX_AUDIT_BACKUPS" in res.output
    assert not (tmp_path / "o").exists()


def test_a_backup_folder_named_krc_is_named_by_its_parent_and_robot(tmp_path):
    # issue 63: the depalletizer's backup was a folder "KRC", and the audit called it "KRC". A
    # KRC backup (R1/System/$config.dat) whose machine data name the robot (the spelling of
    # KUKA's $machine.dat: CHAR $TRAFONAME[32], then its value), audited by its own folder
    krc = tmp_path / "depalletizer" / "KRC"
    (krc / "R1" / "System").mkdir(parents=True)
    (krc / "R1" / "Mada").mkdir()
    (krc / "R1" / "System" / "$config.dat").write_text("DEFDAT $CONFIG\nENDDAT\n")
    (krc / "R1" / "Mada" / "$machine.dat").write_text(
        'DEFDAT $MACHINE PUBLIC\nCHAR $V_R1MADA[32]\n$V_R1MADA[]="V42.51.27.12/KUKA8.5"\n'
        'CHAR $TRAFONAME[32]\n$TRAFONAME[]="#KR210R2700_2 C4 FLR"\nENDDAT\n')
    out = tmp_path / "out"
    res = _audit([str(krc), "--out", str(out), "--jobs", "1"])
    assert "Traceback" not in res.output, res.output
    (u,) = json.loads((out / "audit.json").read_text(encoding="utf-8"))["units"]
    assert (u["name"], u["kind"], u["robot"]) == ("depalletizer/KRC", "backup", "KR210R2700_2 C4 FLR")
    assert u["title"] == "depalletizer/KRC (KR210R2700_2 C4 FLR)"
    assert (u["machine"]["kss"], u["machine"]["controller"]) == ("KSS 8.5", "KR C4")
    # its two data lists hold no program: nothing ran, so "review", not "ok"
    assert res.output.splitlines()[0].startswith("review    depalletizer/KRC (KR210R2700_2 C4 FLR): ")


#: issue 85, item 5: a cell of KUKA's Automatic External whose robot is named only by
#: $config.dat's MACHINE_DEF[1] (no $machine.dat), and whose cell program selects pick (CASE 1),
#: which moves only on $IN[10], an input nothing sets: P00 asks for numbers, pick runs, the
#: robot never moves (0 picks)
CELL_CONFIG = """DEFDAT $CONFIG
DECL MACHINE_DEF_T MACHINE_DEF[2]
MACHINE_DEF[1]={NAME[] "KR 10 R1440-2",COOP_KRC_INDEX 1,PARENT[] "WORLD",MECH_TYPE #ROBOT}
INT PGNO_TYPE=1
INT PGNO_LENGTH=8
INT PGNO_FBIT=33
INT PGNO_PARITY=41
INT PGNO_VALID=42
INT PGNO_REQ=33
INT APPL_RUN=34
INT PGNO_ERROR=0
INT PGNO
EXT P00 (P00_COMMAND :IN,FUNCT_TYPE :IN,CHAR[] :OUT,INT :IN )
ENDDAT
"""
CELL_SRC = """&COMMENT HANDLER on external automatic
DEF CELL ( )
  DECL CHAR DMY[3]
  P00 (#INIT_EXT,#PGNO_GET,DMY[],0 )
  LOOP
    P00 (#EXT_PGNO,#PGNO_GET,DMY[],0 )
    SWITCH PGNO
      CASE 1
        P00 (#EXT_PGNO,#PGNO_ACKN,DMY[],0 )
        pick ( )
      DEFAULT
        P00 (#EXT_PGNO,#PGNO_FAULT,DMY[],0 )
    ENDSWITCH
  ENDLOOP
END
"""
PICK_SRC = "DEF pick ( )\n  IF $IN[10] THEN\n    PTP {A1 10}\n  ENDIF\nEND\n"


def test_no_cell_cycle_without_a_pick_and_no_machine_data_claimed(tmp_path):
    krc = tmp_path / "cell" / "KRC"
    for rel, text in (("R1/System/$config.dat", CELL_CONFIG), ("R1/cell.src", CELL_SRC),
                      ("R1/Program/pick.src", PICK_SRC)):
        (krc / rel).parent.mkdir(parents=True, exist_ok=True)
        (krc / rel).write_text(text)
    out = tmp_path / "out"
    res = _audit([str(krc), "--out", str(out), "--jobs", "1", "--max-sim-time", "1"])
    assert "Traceback" not in res.output, res.output
    (u,) = json.loads((out / "audit.json").read_text(encoding="utf-8"))["units"]
    cell = u["cell"]
    assert (cell["program"], cell["selects"], cell["motions"]) == ("R1/cell.src", ["pick"], 0)
    # P00 asked more than once (the handshakes happened), but no pick: no cycle time
    assert cell["requests"] >= 2 and cell["cycle"] is None and u["tally"]["cell_cycle"] is None
    assert "cell cycle" not in res.output.splitlines()[0]
    page = (out / "audit.html").read_text(encoding="utf-8")
    assert f"no production cycle: P00 asked the PLC for a program number {cell['requests']} times" in page
    # the robot's name comes from $config.dat, and the backup has no machine data
    assert (u["robot"], u["machine"]["robot_from"]) == ("KR 10 R1440-2", "$config.dat MACHINE_DEF[1]")
    assert "robot KR 10 R1440-2 (named in $config.dat MACHINE_DEF[1], not by machine data)" in page
    assert "(its machine data" not in page


def test_a_cell_cycle_is_a_handshake_interval_in_which_the_robot_moved():
    """audit/report.py _cycle: requests at 0, 0.24, 0.48, 2.0, 2.24 s, the motions started
    before each 0, 0, 0, 3, 3: only 0.48 -> 2.0 s is a production cycle (1.52 s)."""
    got = _cycle([0.0, 0.24, 0.48, 2.0, 2.24], [0, 0, 0, 3, 3], 5)
    assert (got["cycles"], got["mean"], got["min"], got["max"]) == (1, 1.52, 1.52, 1.52)
    assert _cycle([0.0, 0.24, 0.48], [0, 0, 0], 3) is None


def test_a_unit_whose_files_hold_no_entry_point_is_not_ok():
    """A folder whose modules are all routines with parameters (the corpus's SunFIow__KRL_Pathmaker:
    four `DEF Dragon_Path (startPos: IN)`) ran nothing: "ok" would say it was seen to work."""
    status, reasons = health({"files": 4, "errors": 0, "entries": [], "causes": [], "outputs": {}})
    assert status == "review"
    assert [r["text"] for r in reasons] == [
        "no entry point: none of its 4 files holds a program (a module whose first routine is a DEF "
        "without parameters), so none of it ran"]
    assert health({"files": 1, "errors": 0, "entries": [{"cause": "completed", "robot_own": False,
                                                         "event_counts": {}}],
                   "causes": [], "outputs": {}})[0] == "ok"
