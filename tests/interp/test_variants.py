"""The backups users actually have, generated from real ones (issue 59, interp/variants.py): the
generator on a backup written here (what each kind of variant removes or reshapes), and a
deterministic sample of the variants of every backup of ../shared/krl-corpus and
../shared/krl-history run as a new user runs them (``--inputs auto``): every run ends explained
and none stops on a name the checker classifies as installed software. ``make nightly`` runs every
variant (``python -m interp.variants``, its counts in the nightly's history).

Cost: the sample is :data:`SAMPLE` variants, every kind once first, then evenly spaced; each runs
:data:`ENTRIES` of its variant's entry points (its sps.sub first) for
:data:`interp.variants.SIM_TIME_S` simulated seconds on the VM. Every entry point of 12 variants was
309 runs, 52 s of CPU (2026-11-26): too much for make test; the nightly runs them all. The sample:
10 variants (9 before issue 72's busy-submit, 10 before issue 85's group-inputs, 11 with its
whole-backup variant, which test_outside_runs.py runs: :data:`DUPLICATE`), 19 runs (the
group-inputs variant runs its one program). Skipped only where ../shared is absent and CI is not
set (tests/conftest.py)."""

from __future__ import annotations

import contextlib
import io
import zipfile
from pathlib import Path

import pytest

from conformance.nightly.figures import read_night
from interp import variants as V
from krl.archive import backup_source
from krl.project import find_backups
from tests.conftest import SHARED_CORPUS, SHARED_HISTORY

from .helpers import write

#: the kinds of issue 85 (a controller archive, a folder of archive zips, a flat layout naming its
#: robot in MACHINE_DEF): run here on the backup written below (their corpus runs, 15-30 s of CPU
#: each, are the nightly's); the corpus sample takes the others
ISSUE_85 = ("archive", "archive-zips", "flat")
#: the kinds the corpus sample leaves to the tests of the backup written here (the five-axis
#: limits' search: a program of its own on any backup, its corpus runs the nightly's)
OWN_BACKUP = (*ISSUE_85, "a4fix-limits")
#: the kind the corpus sample leaves out: a "whole" variant is its backup copied as it is (the copy
#: shown whole by test_each_variant_removes_or_reshapes_what_it_says), so its runs are the runs of
#: tests/interp/test_outside_runs.py, which runs every entry point of every corpus backup (half of
#: each backup's in make test, the other half in make nightly) with the same bounds
#: (interp.variants SIM_TIME_S, STEPS, --inputs auto, the VM) and the same verdict (no stop on
#: installed software, no internal error): the sample's "whole" was ChinaMilling's, 2.4 s
DUPLICATE = ("whole",)
#: variants of the sample run in ``make test`` (one of each kind), and entry points of each
SAMPLE = len(V.KINDS) - len(OWN_BACKUP) - len(DUPLICATE)
ENTRIES = 2


def _backup(tmp: Path) -> Path:
    """A KR C4 archive tree: KRC/R1 with System (a $config.dat with a user part), TP with two
    packages, Mada; KRC/STEU beside it."""
    root = tmp / "KRC"
    write(root, "R1/System/$config.dat", "DEFDAT $CONFIG\n;FOLD BASISTECH GLOBALS\nDECL INT K1=1\n"
                                         ";ENDFOLD (BASISTECH GLOBALS)\n;FOLD USER GLOBALS\nDECL INT U1=2\n"
                                         "SIGNAL S1 $IN[3]\n;ENDFOLD (USER GLOBALS)\nENDDAT\n")
    write(root, "R1/System/sps.sub", "DEF sps( )\n  LOOP\n    WAIT SEC 1\n  ENDLOOP\nEND\n")
    write(root, "R1/TP/Spot/spot.dat", "DEFDAT spot PUBLIC\n  DECL GLOBAL INT SPOTN=0\nENDDAT\n")
    write(root, "R1/TP/Spot/spot.src", "DEF spot( )\nEND\n")
    write(root, "R1/TP/Grip/grip.src", "DEF grip( )\nEND\n")
    write(root, "R1/Mada/$robcor.dat", "DEFDAT $ROBCOR\nENDDAT\n")
    write(root, "R1/Program/prog.src", "DEF prog( )\n  $OUT[1] = TRUE\nEND\n")
    write(root, "STEU/Mada/$custom.dat", "DEFDAT $CUSTOM\nENDDAT\n")
    assert find_backups(tmp) == [root]
    return root


def test_the_variants_of_a_backup(tmp_path):
    root = _backup(tmp_path / "src")
    got = [(v.kind, v.detail) for v in V.variants_of(root)]
    assert got == [("whole", ""), ("no-TP", "R1/TP"), ("no-TP/", "R1/TP/Grip"), ("no-TP/", "R1/TP/Spot"),
                   ("no-package-dat", "R1/TP/Spot/spot.dat"), ("no-system", "R1/System/$config.dat"),
                   ("no-system", "R1/System/sps.sub"), ("no-system", "R1/Mada/$robcor.dat"),
                   ("config-user-part-missing", "R1/System/$config.dat"), ("busy-submit", "R1/System/sps.sub"),
                   ("program-only", ""), ("tree", "flat"), ("zip", ""), ("group-inputs", ""), ("a4fix-limits", ""),
                   ("archive", ""), ("archive-zips", "")]


def _made(variant, tmp: Path) -> set[str]:
    dest = tmp / variant.name.replace("/", "_").replace(" ", "_").replace("$", "")
    dest.mkdir()
    out = variant.make(dest)
    if out.suffix == ".zip":
        return {n for n in zipfile.ZipFile(out).namelist()}
    return {p.relative_to(dest).as_posix() for p in dest.rglob("*") if p.is_file()}


def test_each_variant_removes_or_reshapes_what_it_says(tmp_path):
    root = _backup(tmp_path / "src")
    whole = {p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file()}
    by = {(v.kind, v.detail): v for v in V.variants_of(root)}
    out = tmp_path / "out"
    out.mkdir()
    assert _made(by[("whole", "")], out) == whole
    assert _made(by[("no-TP", "R1/TP")], out) == {f for f in whole if not f.startswith("R1/TP/")}
    assert _made(by[("no-TP/", "R1/TP/Spot")], out) == whole - {"R1/TP/Spot/spot.dat", "R1/TP/Spot/spot.src"}
    assert _made(by[("no-package-dat", "R1/TP/Spot/spot.dat")], out) == whole - {"R1/TP/Spot/spot.dat"}
    assert _made(by[("no-system", "R1/Mada/$robcor.dat")], out) == whole - {"R1/Mada/$robcor.dat"}
    assert _made(by[("program-only", "")], out) == {"R1/Program/prog.src"}
    assert _made(by[("tree", "flat")], out) == {f[3:] if f.startswith("R1/") else f for f in whole}
    assert _made(by[("zip", "")], out) == {"KRC/" + f for f in whole}
    assert _made(by[("group-inputs", "")], out) == whole | {"R1/Program/krl_variant_groups.src",
                                                           "R1/Program/krl_variant_groups.dat"}
    assert _made(by[("a4fix-limits", "")], out) == whole | {"R1/Mada/$machine.dat", "R1/Program/krl_variant_a4.src",
                                                           "R1/Program/krl_variant_a4.dat"}
    mada = (out / "a4fix-limits" / "R1/Mada/$machine.dat").read_text()
    assert "$SOFTN_END[4]=-350.0" in mada and "$SOFTP_END[4]=350.0" in mada and "BOOL $DEF_A4FIX=TRUE" in mada
    # issue 85: the layout of ../shared/event-logs/README.md: KRC/R1, KRC/STEU, am.ini, C/ with templates
    c_folder = {"C/KRC/Roboter/Template/vorgabe.src", "C/KRC/Roboter/Template/vorgabe.dat",
                "C/KRC/Roboter/Template/cell.src", "C/KRC/Roboter/Config/User/Common/Profinet/PNIO_DEV.dat"}
    assert _made(by[("archive", "")], out) == {"KRC/" + f for f in whole} | c_folder | {"am.ini"}
    assert _made(by[("archive-zips", "")], out) == {"archives/a.zip", "archives/b.zip"}
    assert set(zipfile.ZipFile(out / "archive-zips" / "archives" / "b.zip").namelist()) == \
        {"KRC/" + f for f in whole} | c_folder | {"am.ini"}
    busy = by[("busy-submit", "R1/System/sps.sub")]
    assert _made(busy, out) == whole
    dest = out / "busy"
    dest.mkdir()
    busy.make(dest)
    assert (dest / "R1/System/sps.sub").read_text() == (
        "DEF sps( )\nDECL INT KRL_VARIANT_BUSY\n  KRL_VARIANT_BUSY = 0\n  LOOP\n    KRL_VARIANT_BUSY = KRL_VARIANT_BUSY + 1\n"
        "    WAIT SEC 1\n  ENDLOOP\nEND\n")
    v = by[("config-user-part-missing", "R1/System/$config.dat")]
    dest = out / "user"
    dest.mkdir()
    v.make(dest)
    text = (dest / "R1/System/$config.dat").read_text()
    assert "K1=1" in text and "U1" not in text and "SIGNAL S1" not in text
    assert ";FOLD USER GLOBALS" in text and ";ENDFOLD (USER GLOBALS)" in text


def test_a_busy_submit_needs_a_loop_of_its_main_routine():
    """busy_submit makes the first routine's own LOOP busy, keeps CRLF line ends, and gives None
    for a submit program without one (a LOOP only in a later routine is not its cycle)."""
    crlf = b"&ACCESS RVP\r\nDEF  SPS ( )\r\n  ;FOLD INI\r\n  X = 1\r\n  ;ENDFOLD\r\n  LOOP ; cycle\r\n    X = 2\r\n  ENDLOOP\r\nEND\r\n"
    got = V.busy_submit(crlf).decode()
    assert got.splitlines(keepends=True)[2] == "DECL INT KRL_VARIANT_BUSY\r\n"
    assert "  KRL_VARIANT_BUSY = 0\r\n  LOOP ; cycle\r\n    KRL_VARIANT_BUSY = KRL_VARIANT_BUSY + 1\r\n" in got
    assert V.busy_submit(b"DEF sps( )\n  WAIT SEC 1\nEND\nDEF other( )\n  LOOP\n  ENDLOOP\nEND\n") is None
    assert V.busy_submit(b"DEFDAT sps\nENDDAT\n") is None


def test_the_conditions_of_issue_72_are_variants(tmp_path):
    """A KR C4 backup whose $config.dat names its robot in MACHINE_DEF: no $machine.dat and no
    bas.src are variants of it (no-system), as is its submit interpreter kept busy."""
    root = tmp_path / "KRC"
    write(root, "R1/System/$config.dat", "DEFDAT $CONFIG\nDECL MACHINE_DEF_T MACHINE_DEF[1]\n"
                                         'MACHINE_DEF[1]={NAME[] "KR 10 R1440-2",MECH_TYPE #ROBOT}\nENDDAT\n')
    write(root, "R1/System/bas.src", "DEF bas( )\nEND\n")
    write(root, "R1/System/sps.sub", "DEF sps( )\n  LOOP\n  ENDLOOP\nEND\n")
    write(root, "R1/Mada/$machine.dat", "DEFDAT $MACHINE\nENDDAT\n")
    write(root, "R1/Program/prog.src", "DEF prog( )\nEND\n")
    got = {(v.kind, v.detail) for v in V.variants_of(root)}
    assert {("no-system", "R1/System/bas.src"), ("no-system", "R1/Mada/$machine.dat"),
            ("busy-submit", "R1/System/sps.sub")} <= got


def test_a_zip_variant_is_read_as_krl_run_reads_a_backup_archive(tmp_path):
    root = _backup(tmp_path / "src")
    zipped = next(v for v in V.variants_of(root) if v.kind == "zip")
    made = zipped.make(tmp_path)
    with backup_source(made) as (folder, _shown):
        assert [b.name for b in find_backups(folder)] == ["KRC"]


def test_a_flat_export_becomes_an_archive_tree(tmp_path):
    flat = tmp_path / "flat"
    write(flat, "System/$config.dat", "DEFDAT $CONFIG\nENDDAT\n")
    write(flat, "Program/p.src", "DEF p( )\nEND\n")
    [tree] = [v for v in V.variants_of(flat) if v.kind == "tree"]
    assert tree.detail == "KRC/R1"
    assert _made(tree, tmp_path) == {"KRC/R1/System/$config.dat", "KRC/R1/Program/p.src"}


@pytest.mark.parametrize("interp", ("tree", "vm"))
def test_the_group_inputs_variant_runs_its_program_to_the_end(tmp_path, interp):
    """Issue 85 item 1 as a variant: only the added program runs; the automatic cell answers its
    WAIT FOR and gives the groups the values of the first IF (900, 10), so the weight is set and
    the SWITCH takes CASE 10: the program completes (without the production search it stopped at
    "value invalid: weight", line 12)."""
    root = _backup(tmp_path / "src")
    v = next(v for v in V.variants_of(root) if v.kind == "group-inputs")
    got = V.run_variant(v, interp=interp)
    assert [(r["entry"], r["cause"], r["reason"]) for r in got["runs"]] == [
        ("R1/Program/krl_variant_groups.src", "completed", "completed")]


#: the model the five-axis palletizer's machine data name ($TRAFONAME[], without KUKA's #)
PA5_MODEL = next(line.split('"')[1].lstrip("#") for line in V.PA5_MACHINE.read_text().splitlines()
                 if line.startswith("$TRAFONAME[]"))


@pytest.mark.parametrize("interp", ("tree", "vm"))
def test_the_a4fix_limits_variant_finds_a_configuration_inside_the_data_s_a4_limits(tmp_path, interp):
    """Issue 85 item 2 as a variant: the backup drives the five-axis palletizer whose machine data
    say A4 -350 .. 350; the added program reads those limits in KRL, keeps the configurations
    whose A4 (0, $DEF_A4FIX) lies inside them and moves to the first: it completes (read as
    0 .. 0, as before issue 85, none was kept and it stopped at "software limit switch +A1")."""
    root = _backup(tmp_path / "src")
    v = next(v for v in V.variants_of(root) if v.kind == "a4fix-limits")
    got = V.run_variant(v, interp=interp)
    assert [(r["entry"], r["cause"], r["reason"], r["robot"]) for r in got["runs"]] == [
        ("R1/Program/krl_variant_a4.src", "completed", "completed", PA5_MODEL)]


def test_the_sample_covers_every_kind_and_is_deterministic(tmp_path):
    root = _backup(tmp_path / "src")
    variants = V.variants_of(root) * 3
    a, b = V.sample(variants, 14), V.sample(variants, 14)
    assert a == b and len(a) == 14
    assert {v.kind for v in a} == set(V.KINDS) - {"flat"}      # the backup has no $machine.dat: no flat


#: the robot library's KR 180 R3200 PA machine data ($TRAFONAME[]="#KR180R3200 PA C4 FLR")
MACHINE_DAT = Path(__file__).resolve().parents[2] / "robot" / "data" / "kr180_r3200_pa.dat"
MODEL = "KR180R3200 PA C4 FLR"


def _named_backup(tmp: Path) -> Path:
    """A KR C4 backup whose $machine.dat names its model (:data:`MODEL`, of the robot library) and
    whose $config.dat has a MACHINE_DEF[1] naming none ("Robot", as the corpus's palletizer's)."""
    root = tmp / "KRC"
    write(root, "R1/System/$config.dat", "DEFDAT $CONFIG\nSTRUC MACHINE_DEF_T CHAR NAME[24],ESYS MECH_TYPE\n"
                                         "DECL MACHINE_DEF_T MACHINE_DEF[2]\n"
                                         'MACHINE_DEF[1]={NAME[] "Robot",MECH_TYPE #ROBOT}\nENDDAT\n')
    (root / "R1" / "Mada").mkdir(parents=True)
    (root / "R1" / "Mada" / "$machine.dat").write_bytes(MACHINE_DAT.read_bytes())
    write(root, "R1/Program/prog.src", "DEF prog( )\n  $OUT[1] = TRUE\nEND\n")
    write(root, "STEU/Mada/$custom.dat", "DEFDAT $CUSTOM\nENDDAT\n")
    return root


def test_a_flat_variant_names_the_robot_in_machine_def(tmp_path):
    """Issue 85 item 6 as a variant: the robot folder's files flat in one folder, no machine data,
    MACHINE_DEF[1] naming the model the machine data named ($TRAFONAME without KUKA's #)."""
    root = _named_backup(tmp_path / "src")
    [flat] = [v for v in V.variants_of(root) if v.kind == "flat"]
    assert flat.name == "flat MACHINE_DEF"
    assert _made(flat, tmp_path) == {"$config.dat", "prog.src"}
    assert f'MACHINE_DEF[1]={{NAME[] "{MODEL}",MECH_TYPE #ROBOT}}' in (tmp_path / "flat_MACHINE_DEF" / "$config.dat").read_text()


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_issue_85_variants_run_their_backup_only(tmp_path, interp):
    """The archive's C/ templates are never an entry point (one CELL among them), each archive of
    the folder of zips runs its own programs, and the flat layout drives the robot MACHINE_DEF
    names (:data:`MODEL`, as the machine data the archive kinds keep), on both interpreters:
    prog.src completes in each."""
    root = _named_backup(tmp_path / "src")
    by = {v.kind: v for v in V.variants_of(root)}
    got = {kind: [(r["entry"], r["cause"], r["robot"]) for r in V.run_variant(by[kind], interp=interp)["runs"]]
           for kind in ISSUE_85}
    assert got == {"archive": [("KRC/R1/Program/prog.src", "completed", MODEL)],
                   "archive-zips": [("a.zip/KRC/R1/Program/prog.src", "completed", MODEL),
                                    ("b.zip/KRC/R1/Program/prog.src", "completed", MODEL)],
                   "flat": [("prog.src", "completed", MODEL)]}


@pytest.mark.corpus
@pytest.mark.skipif(not (SHARED_CORPUS / "MANIFEST.csv").exists(), reason="../shared/krl-corpus absent")
def test_a_sample_of_the_variants_of_every_backup_ends_explained(record_property):
    variants = [v for b in V.backups([SHARED_CORPUS, SHARED_HISTORY]) for v in V.variants_of(b)
                if v.kind not in OWN_BACKUP + DUPLICATE]
    chosen = V.sample(variants, SAMPLE)
    results = [V.run_variant(v, entries=ENTRIES) for v in chosen]
    s = V.summarise(results)
    record_property("summary", f"variants {s['variants']} of {len(variants)}, runs {s['runs']}: "
                               + ", ".join(f"{k} {n}" for k, n in s["causes"].items())
                               + f"; stops on installed software {s['outside_stops']}, internal {s['internal']}")
    assert {v.kind for v in chosen} == set(V.KINDS) - set(OWN_BACKUP) - set(DUPLICATE)
    assert s["runs"] >= SAMPLE
    assert not s["failures"], s["failures"]


@pytest.fixture(scope="module")
def first_sweep(tmp_path_factory) -> tuple[Path, Path, Path, str]:
    """One sweep of two variants of the backup written here, as ``make nightly`` runs it (``--json``
    into a night's folder) and with ``--log``: (the backup's folder, the night's folder, the log,
    what it printed). The nightly's figures and the resumed sweep read it (one sweep for both:
    each made its own, and the nightly's test ran the two variants a third time, 2026-11-28)."""
    tmp = tmp_path_factory.mktemp("sweep")
    day = tmp / "2026-11-26"
    day.mkdir()
    _backup(tmp / "src")
    log = tmp / "sweep.jsonl"
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert V.main([str(tmp / "src"), "--sample", "2", "--jobs", "1", "--log", str(log),
                       "--json", str(day / "variants.json")]) == 0
    return tmp / "src", day, log, printed.getvalue()


def test_the_nightly_reads_the_counts_of_the_variants(first_sweep):
    """make nightly writes variants.json (python -m interp.variants --json): its counts are figures
    of the night, in its history (conformance/nightly)."""
    _src, day, _log, _printed = first_sweep
    night = read_night(day)
    # each variant: prog.src completes, the SPS.SUB cycles to the time limit (an intended end)
    assert night.figures["variants.variants"] == 2 and night.figures["variants.runs"] == 4
    assert night.figures["variants.outside_stops"] == 0 and night.figures["variants.cause.completed"] == 2
    assert night.figures["variants.cause.intended_end"] == 2


def test_some_entries_takes_the_submit_interpreter_first():
    entries = [Path(f"R1/Program/p{i}.src") for i in range(6)] + [Path("R1/System/sps.sub")]
    assert V.some_entries(entries, 0) == entries
    assert V.some_entries(entries, 3) == [Path("R1/System/sps.sub"), Path("R1/Program/p0.src"),
                                          Path("R1/Program/p3.src")]


def test_a_stopped_sweep_resumes_from_its_log(first_sweep, tmp_path, capsys):
    """--log appends each variant's result as it ends; a second sweep with the same log runs only
    the variants it does not hold (a line cut by a stop mid-write runs again) and counts all."""
    src, _day, first_log, printed = first_sweep
    lines = first_log.read_text().splitlines()
    assert len(lines) == 2
    assert "variants 2 of 1 backups, runs 4" in printed
    log = tmp_path / "sweep.jsonl"
    log.write_text(lines[0] + "\n" + lines[1][: len(lines[1]) // 2] + "\n")  # the second cut mid-write
    assert V.main([str(src), "--sample", "3", "--jobs", "1", "--log", str(log)]) == 0
    second = capsys.readouterr()
    assert "1 variants read from" in second.err
    assert len([ln for ln in log.read_text().splitlines() if ln.endswith("}")]) == 3
    assert "variants 3 of 1 backups, runs 6" in second.out


def test_mapping_submit_writes_the_user_plc_of_a_cell():
    """issue 76's generated SPS.SUB: into the USER PLC fold of the project's KR C4-style template
    (corpus/system/sps.sub), 20 mapping lines (two of them, i = 9 and 19, an IF of five lines),
    the key flag and the override clamp (6 lines) and one routine call: 18 + 10 + 6 + 1 = 35
    lines; the routine (7 lines with its blank) appended, the file's lines otherwise kept."""
    src = (Path(__file__).resolve().parents[2] / "corpus" / "system" / "sps.sub").read_bytes()
    out = V.mapping_submit(src, 20, 1).decode("latin-1").splitlines()
    lines = src.decode("latin-1").splitlines()
    assert len(out) == len(lines) + 35 + 7
    at = next(i for i, s in enumerate(out) if s.strip().upper().startswith(";FOLD USER PLC"))
    assert out[at + 1].strip() == "$FLAG[1] = IS_KEY_PRESSED(17)"
    assert out[at + 7].strip() == "$OUT[200] = $OUT[999]"
    assert "DEF KRL_MAP_USER0()" in out
    assert V.mapping_submit(b"DEF A()\nEND\n", 20) is None
