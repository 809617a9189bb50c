"""`krl audit ../shared/krl-corpus` (issue 49): it covers every backup and program folder of the
corpus, and what it finds is what reading the backups' code gives. Every expected value below
was derived by reading the corpus's files (the comments cite them), not from the audit's output.

The run is the session's one audit of the corpus (conftest.py: SIM_TIME simulated seconds per
entry point)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from krl.files import SHARED_CORPUS

# a long sweep (every entry point of the corpus, 48 s of CPU): `make nightly`; make test keeps the
# audit of real backups in tests/audit/test_cli.py and test_dask.py
pytestmark = [pytest.mark.corpus, pytest.mark.slow, pytest.mark.xdist_group("audit-corpus"), pytest.mark.timeout(3600)]

KRL = (".src", ".dat", ".sub")


def _units_on_disk(corpus: Path) -> dict[str, str]:
    """name -> "backup" / "folder" for the corpus, from the files alone: a backup is the folder
    above a ``System`` folder holding ``$config.dat`` (above ``R1`` when System is in R1); a
    top-level folder with KRL files outside every backup is a program folder."""
    backups = set()
    for folder, dirs, files in os.walk(corpus):
        dirs[:] = [d for d in dirs if not (Path(folder) / d).is_symlink()]
        if Path(folder).name.lower() == "system" and any(f.lower() == "$config.dat" for f in files):
            root = Path(folder).parent
            backups.add(root.parent if root.name.lower() == "r1" else root)
    out = {b.relative_to(corpus).as_posix(): "backup" for b in backups}
    for top in sorted(p for p in corpus.iterdir() if p.is_dir()):
        for folder, dirs, files in os.walk(top):
            dirs[:] = [d for d in dirs if not (Path(folder) / d).is_symlink()]
            if any(b == Path(folder) or b in Path(folder).parents for b in backups):
                continue
            if any(f.lower().endswith(KRL) for f in files):
                out[top.name] = "folder"
                break
    return out


def _unit(data: dict, name: str) -> dict:
    (u,) = [u for u in data["units"] if u["name"] == name]
    return u


def test_every_backup_and_program_folder_is_audited(corpus_audit):
    data, _html, res = corpus_audit
    assert res.exit_code == 1, res.output           # some backup needs attention (below)
    assert "Traceback" not in res.output
    expected = _units_on_disk(SHARED_CORPUS)
    assert {u["name"]: u["kind"] for u in data["units"]} == expected
    assert data["summary"]["backups"] == 4 and data["summary"]["folders"] == len(expected) - 4
    # no unit failed to load, no run was an internal error of the simulator
    assert [u["name"] for u in data["units"] if u["error"]] == []
    assert [e["program"] for u in data["units"] for e in u["entries"] if e["reason"] == "internal"] == []
    # one line per unit on the terminal, then the totals
    lines = res.output.splitlines()
    assert sum(any(line.split(None, 1)[1].startswith(u["title"] + ":") for u in data["units"])
               for line in lines if line.split(None, 1)[0] in ("attention", "review", "ok")) == len(expected)


def test_rawpython_entry_points_end_as_their_code_says(corpus_audit):
    data, _html, _res = corpus_audit
    u = _unit(data, "rawpython__kukaKRLmagic")
    entries = {e["program"]: e for e in u["entries"]}
    # R1/cell.src (DEF CELL()) and the two modules of R1/Program, each a DEF without parameters;
    # R1/System holds no sps.sub
    assert set(entries) == {"R1/cell.src", "R1/Program/sample_program.src",
                            "R1/Program/sample_program_with_globals.src"}
    assert entries["R1/cell.src"]["kind"] == "cell"
    # sample_program.src:26 is `print('1')`: a single-quoted string is not KRL, a line not
    # understood; the module runs from what parsed (issue 63) and stops before it: `switch i`
    # (line 24) reads i, which no line assigns (INT i, line 7): value invalid, 1422
    bad = entries["R1/Program/sample_program.src"]
    assert (bad["cause"], bad["reason"], bad["file"], bad["line"]) == \
        ("program error", "error", "R1/Program/sample_program.src", 24)
    assert "value invalid: i" in bad["text"]
    # sample_program_with_globals() is empty (lines 4-6): it completes at once
    done = entries["R1/Program/sample_program_with_globals.src"]
    assert (done["cause"], done["run_time"], done["motions"]) == ("completed", 0.0, 0)
    # cell.src loops on P00's handshake (LOOP P00(#EXT_PGNO,#PGNO_GET) SWITCH PGNO ...) and its
    # CASE branches call nothing but P00 (EXAMPLE1() etc. are commented out, lines 39-52): KUKA's
    # template loop, which selects no production program. Its loop would time the handshake
    # alone (two answers of the PLC, 0.12 s each: 0.240 s), not a cycle of the cell, so no
    # cycle time is reported (issue 63)
    cell = entries["R1/cell.src"]
    assert cell["cycle"] is None and u["cell"]["selects"] == [] and u["tally"]["cell_cycle"] is None
    assert cell["cause"] == "intended end"     # the PLC answered until the end
    # no motion error: the cell program's one motion is PTP XHOME, where the automatic cell
    # starts the robot; the others do not move
    assert u["tally"]["motion_errors"] == 0
    assert u["status"] == "attention"
    assert any(r["level"] == "attention" and r["text"] == "1 of 3 entry points end in a program error (1 cause)"
               for r in u["reasons"])
    # named by its robot: $TRAFONAME[]="#KR120R2700_2 C4 FLR" (R1/Mada/$machine.dat:427),
    # $V_R1MADA[]="V42.49.14.8/KUKA8.6" (line 5)
    assert (u["robot"], u["machine"]["kss"], u["machine"]["controller"]) == ("KR120R2700_2 C4 FLR", "KSS 8.6", "KR C4")
    assert u["title"] == "rawpython__kukaKRLmagic (KR120R2700_2 C4 FLR)"
    assert any(f["file"] == "R1/Program/sample_program.src" and f["line"] == 26 and f["severity"] == "error"
               for f in u["findings"])


def test_a_cell_cycle_only_where_the_cell_program_selects_programs(corpus_audit):
    # issue 63: the programs each cell program's SWITCH selects, read in the files (a routine
    # called in a CASE branch; P00, called in every branch, is the handshake): the Palletizer's
    # main.src (lines 64-122) selects ten (named as their DEF lines spell them), ChinaMilling's
    # cell.src millingcn() (lines 43 and 52), khrzysio's R1/CELL.src eight in its 22 branches
    # (lines 41-200; CellProgramStart and CellProgramEnd, in 21 branches, are the cell's own
    # steps; Cut_LeafLong and the like are commented out after a HALT), kukaKRLmagic's none
    # (its calls are commented out)
    data, _html, _res = corpus_audit
    selects = {u["name"]: u["cell"]["selects"] for u in data["units"] if u["cell"] is not None}
    assert selects == {
        "ingeniado__KRC4-Robot-Palletizer": ["caja_g_m3", "caja_g_m4", "saco_20_M2", "saco_20_m3", "saco_20_m4",
                                             "saco_20_m6", "saco_25_M1", "saco_25_M3", "SACO_5_m2", "saco_5_m4"],
        "HugoDanielson__ChinaMilling/KRC": ["millingcn"],
        "khrzysio__KRC4_test": ["Cut_FrameLeft", "Cut_FrameRight", "Cut_FrameThreshold", "Cut_FrameUpper",
                                "GetProcessData", "GoHomePos", "Mill_FrameGlue", "PrepareMillingTools"],
        "rawpython__kukaKRLmagic": [],
    }
    for u in data["units"]:
        if u["cell"] is not None and not u["cell"]["selects"]:
            assert u["cell"]["cycle"] is None and u["tally"]["cell_cycle"] is None


def test_rawpython_outputs(corpus_audit):
    data, _html, _res = corpus_audit
    o = _unit(data, "rawpython__kukaKRLmagic")["outputs"]
    # the only outputs written with a constant address are P00's error code ERR ($OUT[25] TO
    # $OUT[32], R1/TP/p00.dat:11) at p00.src:385, 405, 425 -- P00's own map outputs; the O_...
    # signals of $config.dat are never assigned, the rest of bas.src/p00.src index $OUT by a
    # variable
    assert o["writes"] == 3 * 8 and o["overlaps"] == []
    # the PLC map: 21 system signals on outputs in STEU/Mada/$machine.dat (lines 20-26, 31, 32,
    # 34-36, 44-47, 85, 97-100), ERR's 8 outputs, PGNO_REQ=33 and APPL_RUN=34
    # (R1/System/$config.dat); REFLECT_PROG_NR=0: no reflection outputs
    assert o["plc_map"] == 21 + 8 + 2


def test_the_plc_map_overlaps_found_by_reading_the_backups(corpus_audit):
    data, _html, _res = corpus_audit
    # the palletizer: SIGNAL N_PROGRAMA_EJECUTANDOSE $OUT[26] TO $OUT[34] (System/$config.dat:764)
    # is written by main.src (its cell program) at the 12 CASE branches, and $config.dat gives
    # P00's PGNO_REQ=33 (line 604) and APPL_RUN=34 (line 606): two outputs of the PLC's map
    pal = _unit(data, "ingeniado__KRC4-Robot-Palletizer")["outputs"]["overlaps"]
    assert [(o["signal"], o["flags"]) for o in pal] == [("$OUT[33..34]", ["PLC map"])]
    assert [(p["name"], p["file"], p["line"]) for p in pal[0]["plc"]] == [
        ("PGNO_REQ", "System/$config.dat", 604), ("APPL_RUN", "System/$config.dat", 606)]
    assert [(w["file"], w["line"], w["name"]) for w in pal[0]["writes"]] == [
        ("main.src", n, "N_PROGRAMA_EJECUTANDOSE") for n in (54, 66, 72, 78, 84, 90, 96, 102, 108, 114, 120, 126)]
    # ChinaMilling: GLOBAL SIGNAL oSpindleRpm $OUT[1] TO $OUT[16] ";for test"
    # (R1/TP/Milling/R2M_SpindleVariables.dat:174), written at amm_main.src:203, 205, 234 and 303
    # (milling_abort's spindle fast stop), lies
    # over Automatic External's outputs of STEU/Mada/$machine.dat -- $RC_RDY1 $OUT[10] (21),
    # $PERI_RDY 11 (36), $STOPMESS 12 (33), $IN_HOME 14 (37), $I_O_ACTCONF 15 (27), $PRO_ACT 16
    # (100) -- and PGNO_REQ=13 (R1/System/$config.dat:707)
    cm = {o["signal"]: o for o in _unit(data, "HugoDanielson__ChinaMilling/KRC")["outputs"]["overlaps"]}
    row = cm["$OUT[10..16]"]
    assert row["flags"] == ["PLC map"]
    assert [(p["name"], p["line"]) for p in row["plc"]] == [
        ("$RC_RDY1", 21), ("$PERI_RDY", 36), ("$STOPMESS", 33), ("PGNO_REQ", 707), ("$IN_HOME", 37),
        ("$I_O_ACTCONF", 27), ("$PRO_ACT", 100)]
    assert [(w["file"], w["line"]) for w in row["writes"]] == [
        ("R1/TP/Milling/amm_main.src", n) for n in (203, 205, 234, 303)]
    # and $OUT[4095] under two names: DO_PulseTCCloseCover (R2M_SpindleVariables.dat:17), pulsed
    # at amm_periphery.src:164, and BM_OutputSignal $OUT[4095] TO $OUT[4096] ($config.dat:736),
    # set at sps.sub:47; both run in the submit interpreter (sps.sub calls amm_periphery)
    assert cm["$OUT[4095]"]["flags"] == ["two names"]
    assert {(w["file"], w["line"], w["name"]) for w in cm["$OUT[4095]"]["writes"]} == {
        ("R1/TP/Milling/amm_periphery.src", 164, "DO_PULSETCCLOSECOVER"),
        ("R1/System/sps.sub", 47, "BM_OUTPUTSIGNAL")}
    assert set(cm) == {"$OUT[10..16]", "$OUT[4095]"}
    # KRC4_test: outHsdCleaning $OUT[26] and outHsdScavenge $OUT[28] (R1/System/$config.dat:843,
    # 845), set by Spindle.src (141, 170; 105), lie inside P00's ERR $OUT[25] TO $OUT[32]
    # (R1/TP/p00.dat:11), which P00 writes at p00.src:385, 405, 425
    k4 = {o["signal"]: o for o in _unit(data, "khrzysio__KRC4_test")["outputs"]["overlaps"]}
    assert set(k4) == {"$OUT[26]", "$OUT[28]"}
    assert k4["$OUT[26]"]["flags"] == k4["$OUT[28]"]["flags"] == ["two names", "PLC map"]
    assert {(w["file"], w["line"]) for w in k4["$OUT[28]"]["writes"]} == {
        ("R1/Program/Objects/Spindle.src", 105), ("R1/TP/p00.src", 385), ("R1/TP/p00.src", 405),
        ("R1/TP/p00.src", 425)}
    assert [(p["name"], p["file"], p["line"]) for p in k4["$OUT[26]"]["plc"]] == [("ERR", "R1/TP/p00.dat", 11)]


def test_the_palletizers_entry_points(corpus_audit):
    data, _html, _res = corpus_audit
    u = _unit(data, "ingeniado__KRC4-Robot-Palletizer")
    root = SHARED_CORPUS / "ingeniado__KRC4-Robot-Palletizer"
    # every module under Program/ (each begins DEF NAME( ), read above), main.src (DEF CELL( ),
    # the cell program of this flat export) and System/sps.sub
    expected = {p.relative_to(root).as_posix() for p in root.glob("Program/*/*.src")} | {"main.src", "System/sps.sub"}
    assert {e["program"] for e in u["entries"]} == expected and len(expected) == 23
    kinds = {e["program"]: e["kind"] for e in u["entries"]}
    assert kinds["main.src"] == "cell" and kinds["System/sps.sub"] == "submit"
