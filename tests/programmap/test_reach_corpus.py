"""Reachability on every KRC backup of the shared corpus (issue 49): what the controller starts,
what only an operator can select, what nothing reaches.

The expected values were read by hand from each backup's code (docs/diff.md, "Dead routines
of the corpus backups" says what each reading found):

* the PLC's program numbers from the ``SWITCH`` of the cell program (main.src, cell.src,
  CELL.src);
* the modules only an operator starts: the selectable programs of ``R1/Program`` (``Program/``)
  that neither the cell program, nor SPS.SUB, nor anything they call names;
* the dead routines: routines whose name no code outside a dead routine uses (a module main
  with parameters nothing calls, a local routine of such a module, a GLOBAL routine nobody
  calls). Routines only a line not understood names are ``unknown``, never dead; the rest of a
  file with syntax errors is mapped (issue 63).

And, independently of the map's own walk, a text check: every line of the backup's code that
names a dead routine (comments and strings left out) is its own header, a declaration
(``EXT``/``EXTP``), a line inside a dead routine, or -- for a local routine -- in another file.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from krl.programmap import build_map
from krl.project import find_backups
from krl.workspace import workspaces_for

PALLETIZER = {
    "backup": "ingeniado__KRC4-Robot-Palletizer",
    # main.src: CASE 1 SACO_5_M2 () ... CASE 10 SACO_20_M6 (); CASE 0 and DEFAULT only move home
    "plc": {1: "SACO_5_M2", 2: "SACO_20_M3", 3: "SACO_20_M2", 4: "SACO_20_M4", 5: "SACO_5_M4",
            6: "SACO_25_M1", 7: "CAJA_G_M3", 8: "CAJA_G_M4", 9: "SACO_25_M3", 10: "SACO_20_M6"},
    # EXT-declared in main.src (or not at all) but called by no CASE branch and by nothing else
    "operator_only": ["CAJA_G_M1", "CAJA_G_M2", "SACO_20_M1", "SACO_20_M5", "SACO_25_M2", "SACO_5_M1", "SACO_5_M3"],
    "dead": [],
    "unknown": [],
}

CHINA_MILLING = {
    "backup": "HugoDanielson__ChinaMilling/KRC",
    # cell.src: CASE 1 millingcn(), CASE 2 nothing, CASE 3 millingcn()
    "plc": {1: "MILLINGCN"},
    # Main.src and Main_2.src, the production programs, are selected at the pendant; sps.sub
    # calls only BasisTech_PLC_LOOP and R2M_ChkSpindleSpeed (KUKA's)
    "operator_only_includes": ["MAIN", "MAIN_2", "STATION1", "TACTTIMER"],
    "dead": [
        "Main:IpProgramStop",                        # Main_2's INTERRUPT names Main_2's own IpProgramStop
        # job programs with a parameter (lnActSt :IN) that no station program calls, and the
        # trigger routines of their own TRIGGER lines
        "St1_Job1_Side1:St1_Job1_Side1", "St1_Job1_Side1:endOfJob",
        "St1_Job1_Side2:St1_Job1_Side2",
        "St1_Job2_Side1:St1_Job2_Side1", "St1_Job2_Side1:endOfJob",
        "St1_Job2_Side2:St1_Job2_Side2",
        "St1_Job3_Side1:St1_Job3_Side1", "St1_Job3_Side1:endOfJob",
        "St1_Job3_Side2:St1_Job3_Side2",
        "St1_Test_Mill:St1_Test_Mill", "St1_Test_Mill:endOfJob",
        # the "St2 - Copy" folder: copies of st2_job1/st2_job2 nothing calls
        "st2_job1_copy:st2_job1_copy", "st2_job1_copy:endOfJob", "st2_job1_copy:calculatePickPos",
        "st2_job2_copy:st2_job2_copy", "st2_job2_copy:endOfJob", "st2_job2_copy:calculatePlacePos",
        # moves to and from station 4 (and 20 -> 34) that MoveTo's SWITCH does not call
        "st1_st4:st1_st4", "st1_st4:SetStNumber", "st2_st4:st2_st4", "st2_st4:SetStNumber",
        "st20_st34:st20_st34", "st20_st34:SetStNumber", "st3_st4:st3_st4", "st3_st4:SetStNumber",
        "st4_st1:st4_st1", "st4_st1:SetStNumber", "st4_st2:st4_st2", "st4_st2:SetStNumber",
        "st4_st20:st4_st20", "st4_st20:SetStNumber", "st4_st3:st4_st3", "st4_st3:SetStNumber",
        # called only from the dead St1 jobs above
        "GetMillingSpeed:GetMillingSpeed",
        "Timer_500:Timer_100_Reset",                 # GLOBAL, called nowhere
        "getMillingTool:getMillingTool",             # a function nothing calls
        "Functions:getOrigin", "Functions:DistFrame", "Functions:Pow", "Functions:ChgTool",
    ],
    "unknown": [],
}

KRC4_TEST = {
    "backup": "khrzysio__KRC4_test",
    # CELL.src: CASE 1 GetProcessData(), 10 PrepareMillingTools(), 20..23 Cut_Frame*(), 45
    # Mill_FrameGlue(), 200 GoHomePos()
    "plc": {1: "GETPROCESSDATA", 10: "PREPAREMILLINGTOOLS", 20: "CUT_FRAMELEFT", 21: "CUT_FRAMERIGHT",
            22: "CUT_FRAMEUPPER", 23: "CUT_FRAMETHRESHOLD", 45: "MILL_FRAMEGLUE", 200: "GOHOMEPOS"},
    # the CASE branches 30, 31, 42, 43, 50..55 of these programs are commented out
    "operator_only_includes": ["MILL_FRAMEAUT3", "MILL_FRAMEHINGE", "CUT_LEAFLONG", "MILL_LEAFGLUE",
                               "TEST_TOOLMEASURE"],
    "dead": [
        # ToolMagazine.src: ChangeToolV2 (local) nothing calls; PutDownTool/TakeUpTool only it
        "ToolMagazine:PutDownTool", "ToolMagazine:TakeUpTool", "ToolMagazine:ChangeToolV2",
        "StandardLib:PowReal", "StandardLib:Ceil", "StandardLib:SortArray_stDim3",   # GLOBAL, unused
        "DrillHole2step:DrillHole2step",             # DrillHole2step(stHole:IN): nothing calls it
        # Test/Print: print helpers with parameters that nothing calls (PrintReal is called)
        "PrintAxis:PrintAxis", "PrintBool:PrintBool", "PrintDim3:PrintDim3", "PrintInt:PrintInt",
        "PrintPos:PrintPos", "PrintText:PrintText",
    ],
    # the unfinished programs with a TODO line (corpus/known-invalid.csv): their TODO line is not
    # understood, the rest is mapped, so what they call is reached by the operator's selection of
    # them (Mill_FrameHook3.src:16 SetScrewData(...), Mill_LeafAut3.src:28 LeafDataAut3(...),
    # Mill_LeafHook3.src:51 LeafMillKey(...)); no TODO line names a routine
    "unknown": [],
    "operator_reached": ["Mill_FrameHook3:SetScrewData", "LeafDataAut3:LeafDataAut3", "LeafMillKey:LeafMillKey"],
}

KUKA_KRL_MAGIC = {
    "backup": "rawpython__kukaKRLmagic",
    "plc": {},
    "operator_only": ["SAMPLE_PROGRAM", "SAMPLE_PROGRAM_WITH_GLOBALS"],
    # kuka_internals.src: a stub; EXTP DELETE_BACKWARD_BUFFER in R1/operate.dat, no call
    "dead": ["kuka_internals:DELETE_BACKWARD_BUFFER"],
    # sample_program.src has lines not understood (print('1'): known-invalid); the rest is mapped:
    # line 47 calls SampleFuncGlobal(), line 55 declares print_interrupt() as an interrupt
    # handler, lines 107-120 call move(...): the operator's program reaches them
    "unknown": [],
    "operator_reached": ["sample_program:print_interrupt", "sample_program:move",
                         "sample_program_with_globals:SampleFuncGlobal"],
}

BACKUPS = [PALLETIZER, CHINA_MILLING, KRC4_TEST, KUKA_KRL_MAGIC]


@pytest.fixture(scope="module", params=BACKUPS, ids=lambda b: b["backup"].split("__")[1].split("/")[0])
def case(request, shared_corpus):
    root = shared_corpus / request.param["backup"]
    return request.param, root, build_map(workspaces_for(root, timeout=60)[0])


def test_every_corpus_backup_is_covered(shared_corpus):
    found = {b.resolve() for b in find_backups(shared_corpus)}
    assert found == {(shared_corpus / b["backup"]).resolve() for b in BACKUPS}


def test_plc_programs_operator_only_modules_and_dead_routines(case):
    expected, _root, pm = case
    plc = {n.name.upper(): n.entry for n in pm.nodes.values() if n.entry_kind == "plc"}
    assert {int(why.split()[3]): name for name, why in plc.items()} == expected["plc"]
    only = [m.upper() for m in pm.operator_only]
    if "operator_only" in expected:
        assert sorted(only) == sorted(expected["operator_only"])
    else:
        assert set(expected["operator_only_includes"]) <= set(only)
    # a PLC program is never operator-only; every module main an operator starts is selectable
    assert not set(expected["plc"].values()) & set(only)
    assert sorted(f"{n.module}:{n.name}" for n in pm.unreachable) == sorted(expected["dead"])
    unknown = sorted(f"{n.module}:{n.name}" for n in pm.nodes.values() if n.reach == "unknown")
    if "unknown" in expected:
        assert unknown == sorted(expected["unknown"])
    else:
        assert set(expected["unknown_includes"]) <= set(unknown)
    reach = {f"{n.module}:{n.name}": n.reach for n in pm.nodes.values()}
    for name in expected.get("operator_reached", ()):
        assert reach[name] == "operator", name
    # what the controller starts is reached by the controller, the cell program first
    assert all(pm.nodes[nid].reach == "controller" for nid in pm.entries
               if pm.nodes[nid].entry_kind in ("cell", "plc", "submit", "selected"))


_ROUTINE = re.compile(r"^\s*(?:GLOBAL\s+)?DEF(?:FCT\s+\S+)?\s+([A-Za-z_$][\w$]*)\s*\(", re.I)
_END = re.compile(r"^\s*END(?:FCT)?\b", re.I)


def _code(line: str) -> str:
    """A line without its comment and string literals."""
    return re.sub(r'"[^"]*"', '""', line.split(";", 1)[0])


def test_no_code_outside_dead_routines_names_a_dead_routine(case):
    expected, root, pm = case
    files = [p for p in root.rglob("*") if p.is_file() and p.suffix.lower() in (".src", ".sub", ".dat")]
    dead = {(Path(n.path).resolve(), n.name.upper()) for n in pm.unreachable}
    # the routines of each file and their lines, found in the text here (DEF .. END)
    spans: dict[Path, list[tuple[str, int, int]]] = {}
    texts: dict[Path, list[str]] = {}
    for f in files:
        lines = f.read_text(encoding="latin-1").splitlines()
        texts[f.resolve()] = lines
        start = name = None
        for i, ln in enumerate(lines, 1):
            m = _ROUTINE.match(_code(ln))
            if m:
                start, name = i, m.group(1).upper()
            elif name is not None and _END.match(_code(ln)):
                spans.setdefault(f.resolve(), []).append((name, start, i))
                name = None
    for n in pm.unreachable:
        own = Path(n.path).resolve()
        first = spans[own][0][0] if spans.get(own) else None
        is_global = first == n.name.upper() or re.match(r"\s*GLOBAL\b", texts[own][n.line - 1], re.I)
        word = re.compile(rf"(?<![\w$]){re.escape(n.name)}(?![\w$])", re.I)
        for f, lines in texts.items():
            if not is_global and f != own:
                continue               # a local routine: another file's name is another routine
            for i, ln in enumerate(lines, 1):
                code = _code(ln)
                if not word.search(code) or (f == own and i == n.line):
                    continue
                if re.match(r"\s*(DEFDAT|EXTP?|EXTFCTP?)\b", code, re.I):
                    continue           # the data list of the same name, a declaration
                inside = [r for r, a, b in spans.get(f, []) if a <= i <= b]
                assert inside and (f, inside[0]) in dead, (
                    f"{expected['backup']}: {n.module}:{n.name} is called at {f}:{i}: {ln.strip()}")
