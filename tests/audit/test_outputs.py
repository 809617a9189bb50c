"""The outputs a backup writes and the overlaps `krl audit` reports (audit/outputs.py), on a small
KRC backup written here: every expected row below is read off the files of BACKUP by hand (the
comments say how), not from the code under test."""

from __future__ import annotations

from pathlib import Path

import pytest

from audit.outputs import overlaps, plc_outputs
from krl.programmap import build_map
from krl.workspace import workspaces_for

BACKUP = {
    # the PLC's map: P00's parameters (PGNO_REQ 33, APPL_RUN 34; no reflection) and four SIGNALs
    "R1/System/$config.dat": """DEFDAT $CONFIG PUBLIC
INT PGNO=0
INT PGNO_REQ=33
INT APPL_RUN=34
INT REFLECT_PROG_NR=0
INT PGNO_FBIT_REFL=999
INT PGNO_LENGTH=8
SIGNAL GRIP $OUT[5]
SIGNAL CLAMP $OUT[5]
SIGNAL LAMP $OUT[7]
SIGNAL STATUSBYTE $OUT[30] TO $OUT[35]
ENDDAT
""",
    # a system signal on an output (the controller writes it) and one on an input
    "STEU/Mada/$machine.dat": """DEFDAT $MACHINE PUBLIC
SIGNAL $PERI_RDY $OUT[12]
SIGNAL $EXT_START $IN[1026]
ENDDAT
""",
    # P00's own data list: its error code to the PLC
    "R1/TP/p00.dat": """DEFDAT P00
SIGNAL ERR $OUT[25] TO $OUT[32]
ENDDAT
""",
    # the submit program: lamp output every cycle, and it starts the cell program (RUN)
    "R1/System/sps.sub": """DEF SPS()
  DECL STATE_T STAT
  DECL MODUS_T MODE
  MODE = #SYNC
  CWRITE($CMD, STAT, MODE, "RUN /R1/CELL()")
  LOOP
    $OUT[7] = TRUE
  ENDLOOP
END
""",
    "R1/cell.src": """DEF CELL()
  LOOP
    SWITCH PGNO
    CASE 1
      a()
    CASE 2
      b()
    ENDSWITCH
  ENDLOOP
END
""",
    "R1/Program/a.src": """DEF a()
  GRIP = TRUE
  PULSE(LAMP, TRUE, 0.5)
END
""",
    "R1/Program/b.src": """DEF b()
  DECL INT i
  CLAMP = FALSE
  $OUT[12] = TRUE
  STATUSBYTE = 3
  i = 3
  $OUT[i] = TRUE
  TRIGGER WHEN DISTANCE=0 DELAY=0 DO $OUT_C[13]=TRUE
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
END
""",
}


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    root = tmp_path_factory.mktemp("audit") / "backup"
    for rel, text in BACKUP.items():
        f = root / rel
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text(text.replace("\n", "\r\n"), encoding="latin-1")
    (ws,) = workspaces_for(root)
    pm = build_map(ws)
    return root, ws, pm, overlaps(ws, pm)


def _where(root: Path, rows) -> set:
    return {(Path(w.path).relative_to(root).as_posix(), w.line) for w in rows}


def test_every_write_with_its_output_and_place(report):
    root, _ws, _pm, rep = report
    got = {(w.signal, Path(w.path).relative_to(root).as_posix(), w.line, w.name, w.how) for w in rep.writes}
    assert got == {
        ("$OUT[7]", "R1/System/sps.sub", 7, "", "$OUT[7]"),
        ("$OUT[5]", "R1/Program/a.src", 2, "GRIP", "GRIP"),
        ("$OUT[7]", "R1/Program/a.src", 3, "LAMP", "PULSE LAMP"),
        ("$OUT[5]", "R1/Program/b.src", 3, "CLAMP", "CLAMP"),
        ("$OUT[12]", "R1/Program/b.src", 4, "", "$OUT[12]"),
        # STATUSBYTE is $OUT[30] TO $OUT[35]: six outputs, one statement
        *{(f"$OUT[{n}]", "R1/Program/b.src", 5, "STATUSBYTE", "STATUSBYTE") for n in range(30, 36)},
        # $OUT_C sets the same output as $OUT, here in a TRIGGER's action
        ("$OUT[13]", "R1/Program/b.src", 8, "", "$OUT_C[13]"),
    }
    # $OUT[i]: which output is known only when it runs
    assert [(Path(w.path).name, w.line, w.how) for w in rep.computed] == [("b.src", 7, "$OUT[...]")]


def test_the_plc_map(report):
    _root, ws, _pm, _rep = report
    got = {(o.signal, o.name, Path(o.path).name, o.line, o.owner) for o in plc_outputs(ws)}
    assert got == {
        ("$OUT[12]", "$PERI_RDY", "$machine.dat", 2, ""),            # $EXT_START is an input: not an output
        *{(f"$OUT[{n}]", "ERR", "p00.dat", 2, "P00") for n in range(25, 33)},
        ("$OUT[33]", "PGNO_REQ", "$config.dat", 3, "P00"),
        ("$OUT[34]", "APPL_RUN", "$config.dat", 4, "P00"),          # REFLECT_PROG_NR=0: no reflection
    }


def test_the_tasks_of_each_write(report):
    _root, _ws, pm, rep = report
    by = {(Path(w.path).name, w.line): rep.tasks[w.routine] for w in rep.writes}
    # sps.sub runs in the submit interpreter; a() and b() are the cell program's (CASE 1, 2),
    # which sps.sub starts with RUN /R1/CELL(): in the robot interpreter, not the submit's
    assert by[("sps.sub", 7)] == ["submit SPS"]
    assert by[("a.src", 2)] == by[("b.src", 3)] == ["robot"]
    reached = {pm.nodes[e].name for w in rep.writes if Path(w.path).name == "a.src" for e in rep.reached_by[w.routine]}
    assert {"CELL", "a", "SPS"} <= reached      # SPS reaches a() through the RUN edge


def test_the_overlaps(report):
    root, _ws, _pm, rep = report
    rows = {o.signal: o for o in rep.overlaps}
    assert list(rows) == ["$OUT[5]", "$OUT[7]", "$OUT[12]", "$OUT[30..34]"]
    # GRIP and CLAMP are both $OUT[5]; a() and b() run in one task (the robot's)
    assert rows["$OUT[5]"].flags == ["two names"]
    assert _where(root, rows["$OUT[5]"].writes) == {("R1/Program/a.src", 2), ("R1/Program/b.src", 3)}
    # the submit program's $OUT[7] and a()'s PULSE(LAMP): two tasks at once, one name only
    assert rows["$OUT[7]"].flags == ["two programs"] and rows["$OUT[7]"].tasks == ["robot", "submit SPS"]
    # $PERI_RDY's output, which only the controller writes
    assert rows["$OUT[12]"].flags == ["PLC map"] and [p.name for p in rows["$OUT[12]"].plc] == ["$PERI_RDY"]
    # STATUSBYTE's 30..35 over P00's ERR (30..32), PGNO_REQ (33) and APPL_RUN (34); 35 is free
    row = rows["$OUT[30..34]"]
    assert row.flags == ["PLC map"] and row.signals == [f"$OUT[{n}]" for n in range(30, 35)]
    assert [p.name for p in row.plc] == ["ERR", "ERR", "ERR", "PGNO_REQ", "APPL_RUN"]
    assert _where(root, row.writes) == {("R1/Program/b.src", 5)}
    # the TRIGGER's $OUT[13] has one writer: nothing to review
    assert "$OUT[13]" not in rows
