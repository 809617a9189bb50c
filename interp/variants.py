"""The backups users actually have, generated from real ones (issue 59): each variant of a backup
is the backup with one piece of KUKA's software removed, or in another shape, and every entry
point of every variant runs as a new user runs it (``--inputs auto``, nothing hand-written).

A backup is a partial copy of a controller: KUKA's system software and its technology packages
are installed whether or not their files were exported. Real backups come without ``TP/``,
without ``System/`` files, as ``R1/Program`` only, with ``$config.dat``'s user part missing, as
KR C2 or KR C4 trees, as ``.zip`` files. :func:`variants_of` derives these from a backup, in turn:

* ``whole``: the backup as it is;
* ``no-TP``: without its ``TP/`` folder; ``no-TP/NAME``: without one technology package folder
  of it (``TP/GripperSpotTech``); ``no-package-dat FILE``: without one data list of a package
  (``TP/GripperSpotTech/Spot_Data.dat``, ``TP/p00.dat``);
* ``no-system FILE``: without one file of its ``System/`` or ``Mada`` folders
  (``System/bas.src``, ``System/$config.dat``: the folder is then no backup, its programs run
  as loose programs on the project's BASIS, unless a KR C4 archive's ``STEU/$config.dat`` keeps
  it one: its robot then gets the BASIS ``$config.dat``, interp/runtime/kss.py; ``Mada/$machine.dat``: a KR C4 backup then names
  its robot only in ``$config.dat``'s ``MACHINE_DEF``, issue 72);
* ``config-user-part-missing``: ``$config.dat`` with the lines of its USER folds deleted (the
  fold markers kept);
* ``busy-submit FILE``: its SPS.SUB's loop made busy, a counter counting every pass
  (:func:`busy_submit`): a submit interpreter that never rests while the robot program waits,
  so the run is never idle and the automatic cell must see the robot program starve on its own
  (issue 72: a KR C2 cell whose SPS.SUB runs 2.49 million statements in 300 s);
* ``program-only``: ``R1/Program`` alone;
* ``tree KRC/R1`` or ``tree flat``: the other of the two layouts KUKA's archives use (a KR C2 or
  KR C4 archive's ``KRC/R1/...`` with ``KRC/STEU``, or a flat export of R1 with ``System/`` at the
  top, krl/project.py);
* ``zip``: the backup as a ``.zip`` archive, read as ``krl run --workspace BACKUP.zip`` reads it
  (krl/archive.py);
* ``group-inputs``: the backup with one program added to its Program folder (:data:`GROUPS_NAME`,
  :func:`group_inputs_program`) that reads SIGNAL groups of its own data list through variables
  (an assignment, an ``OUT`` parameter), sets a weight in a chain of IFs on them, selects on one
  with a ``SWITCH`` whose DEFAULT halts, and waits for a handshake bit first (issue 85 item 1: a
  palletizer's ``ParcaAgirlik``); only that program runs (the backup's own are ``whole``'s). With
  the automatic cell's production search (krl/semantics/inputflow.py) it completes; without, it
  stops at "value invalid".
* ``archive``: the backup as a KSS 8 controller archive writes it (issue 85 item 3; the layout of
  ../shared/event-logs/README.md): ``KRC/R1``, ``KRC/STEU``, ``am.ini``, and a ``C`` folder with
  KUKA-shaped templates in ``C/KRC/Roboter/Template`` (:data:`TEMPLATES`: a ``CELL`` among
  them) and a binary configuration file with a KRL name; its entry points are those of the
  programs krl/backups.py finds (``C`` is none: a template run is a failure to see);
* ``archive-zips``: that archive zipped twice into one folder (``a.zip``, ``b.zip``), as
  controller archives are kept: read as every command reads a folder of archives (krl/backups.py);
* ``a4fix-limits``: the backup driving a five-axis palletizer (KR 180 R3200 PA5 of the robot
  library, ``$DEF_A4FIX``) whose ``$machine.dat`` says ``$SOFTN_END[4]=-350``,
  ``$SOFTP_END[4]=350`` (the issue's KSS 8.7.8 archive), with one program added
  (:data:`A4_NAME`, :func:`a4_limits_program`) that searches a target's Status/Turn as the
  palletizer's own program does: INVERSE over 64 S/T, keeping the configurations whose A4 lies
  strictly inside those limits read in KRL, then a PTP with the first kept (issue 85 item 2).
  Only that program runs. With the machine data's limits read it completes; read as 0 .. 0 it
  keeps none, falls back to S 2, T 0 and stops at "software limit switch +A1";
* ``flat MACHINE_DEF``: the robot folder's KRL files lying flat in one folder without its
  machine data, ``$config.dat``'s ``MACHINE_DEF[1]`` naming the robot the machine data named
  (issue 85 item 6: a robot named only there must be the one driven, as in ``KRC/R1``); made
  for backups whose ``$machine.dat`` names a model and whose ``$config.dat`` has MACHINE_DEF[1].

:func:`run_variant` materialises a variant in a temporary folder (removed after) and runs every
entry point of it (interp.realprograms.entries_of for a backup, else its loose programs) on the
VM with ``--inputs auto`` for :data:`SIM_TIME_S` simulated seconds (the robot program's steps
bounded by :data:`STEPS`), reading each run's end against the checker's classification of the
same workspace (interp.realprograms.outside_stops). A run ends *explained* when its cause
(interp.realprograms.cause_of) is completed, an intended end, the program's error at its line, a
limit, or a simulator gap the report names (a target the stand-in robot cannot reach once the
variant removed the machine data); it *fails* when it stops on a name the checker classifies as
installed software (an "outside stop") or ends in an internal error.

:func:`mapping_backups` (``--mapping-corpus OUT``) writes the generated cells of issue 76: KUKA's
KR C2 (ChinaMilling) and KR C4 (the palletizer, ``TORQUE_MONITORING()``) SPS.SUB templates with
20 or 200 user mapping lines, IFs on signals, user routine calls, ``$FLAG[1] =
IS_KEY_PRESSED(17)`` and an override clamp in EXT/AUT (:func:`mapping_submit`), for
``tools/whole_run_bench.py --corpus OUT``.

``python -m interp.variants [FOLDER ...] [--sample N] [--jobs N | --scheduler tcp://HOST:PORT] [--json OUT] [--log LOG]`` (default: the
backups of ../shared/krl-corpus and ../shared/krl-history) prints the counts of variants and runs,
the runs by cause and every failing run; exit status 1 when a run fails. ``make nightly`` runs
all of them (``variants.json``, its counts in the nightly's history: conformance/nightly);
``make test`` a deterministic sample (tests/interp/test_variants.py).
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import sys
import tempfile
import zipfile
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from interp import realprograms as rp
from krl.durable import write_text
from krl.backups import opened, programs_in
from krl.files import SHARED_CORPUS
from krl.project import find_backups, submit_program
from krl.semantics.outside import template_lines
from krl.source import is_krl_file
from krl.cluster import SchedulerError, run_batches
from krl.pool import run_tasks
from robot.machine import ROBOT_LIBRARY

__all__ = ["SIM_TIME_S", "STEPS", "Variant", "a4_limits_program", "backups", "busy_submit", "group_inputs_program",
           "run_variant",
           "sample", "some_entries", "variants_of"]

#: the bound of each run: simulated seconds (a program that starves is fast-forwarded) and steps
#: of the robot program (the step limit counts no submit program's)
SIM_TIME_S = 20.0
STEPS = 100_000

#: ../shared/krl-history beside the corpus
SHARED_HISTORY = SHARED_CORPUS.parent / "krl-history"

#: the kinds of variant, in the order :func:`variants_of` lists them
KINDS = ("whole", "no-TP", "no-TP/", "no-package-dat", "no-system", "config-user-part-missing", "busy-submit",
         "program-only", "tree", "zip", "group-inputs", "a4fix-limits", "archive", "archive-zips", "flat")

#: the program (and data list) the ``group-inputs`` variant adds (a name no backup uses)
GROUPS_NAME = "krl_variant_groups"
#: its inputs: two SIGNAL groups and a handshake bit, above every input the corpus uses
GROUPS_INPUTS = (2001, 2012, 2013, 2016, 2017)
#: the program (and data list) the ``a4fix-limits`` variant adds, and its robot's machine data
#: (the robot library's five-axis palletizer: A4 fixed at 0 by ``$DEF_A4FIX``, its data's A4
#: limits 0.0 there, set to the issue's archive's -350/350 when the variant is made)
A4_NAME = "krl_variant_a4"
PA5_MACHINE = ROBOT_LIBRARY / "kr180_r3200_pa5.dat"
A4_LIMITS = (("$SOFTN_END[4]=0.0", "$SOFTN_END[4]=-350.0"), ("$SOFTP_END[4]=0.0", "$SOFTP_END[4]=350.0"))
#: the program each kind adds: only it runs (the backup's own are ``whole``'s)
ADDED = {"group-inputs": GROUPS_NAME, "a4fix-limits": A4_NAME}

#: what the ``archive`` variants put in ``C`` besides the backup (written here, shaped as KUKA's
#: module templates of ``C/KRC/Roboter/Template`` are: the controller offers them when a module is
#: created and never runs them), and a binary file with a KRL name (a PROFINET configuration's
#: bytes: its real name is not known here)
TEMPLATES = (("C/KRC/Roboter/Template/vorgabe.src", "DEF vorgabe( )\r\n  INI\r\n  PTP HOME\r\nEND\r\n"),
             ("C/KRC/Roboter/Template/vorgabe.dat", "DEFDAT vorgabe\r\nENDDAT\r\n"),
             ("C/KRC/Roboter/Template/cell.src", "DEF CELL( )\r\n  LOOP\r\n  ENDLOOP\r\nEND\r\n"))
BINARY = "C/KRC/Roboter/Config/User/Common/Profinet/PNIO_DEV.dat"
AM_INI = "[Archive]\r\nID=variant\r\n[Version]\r\nVersion=V8.7.8\r\n"
_MACHINE_DEF = re.compile(r'(MACHINE_DEF\[1\]\s*=\s*\{\s*NAME\[\]\s*")[^"]*(")', re.I)
_MODEL = re.compile(r'^\s*\$(?:MODEL_NAME|TRAFONAME)\[\]\s*=\s*"#?([^"]+)"', re.I | re.M)

#: the counter :func:`busy_submit` adds to an SPS.SUB's main routine (a name no backup uses)
BUSY_NAME = "KRL_VARIANT_BUSY"
_DEF = re.compile(r"^\s*(?:GLOBAL\s+)?DEF\s+[A-Za-z_$][A-Za-z0-9_$]*\s*\(", re.I)
_LOOP = re.compile(r"^\s*LOOP\s*(?:;.*)?$", re.I)
_END = re.compile(r"^\s*END\s*(?:;.*)?$", re.I)


@dataclass(frozen=True)
class Variant:
    """One variant of the backup at `backup` (its root, krl/project.py): `kind` (:data:`KINDS`)
    and `detail` (the removed path relative to the backup root, or the tree's shape)."""

    backup: Path
    kind: str
    detail: str = ""

    @property
    def name(self) -> str:
        return f"{self.kind} {self.detail}".strip()

    def make(self, dest: Path) -> Path:
        """Write the variant into the empty folder `dest`; returns the path to read it from (a
        folder, or the ``.zip`` file)."""
        src = self.backup
        if self.kind == "zip":
            return _zip(src, dest / (src.name + ".zip"))
        if self.kind == "archive":
            return _archive(src, dest)
        if self.kind == "archive-zips":
            made = _archive(src, dest / "archive")
            (dest / "archives").mkdir()
            for name in ("a.zip", "b.zip"):
                _zip_contents(made, dest / "archives" / name)
            shutil.rmtree(made)
            return dest / "archives"
        if self.kind == "flat":
            return _flat(src, dest)
        if self.kind == "program-only":
            prog = _robot(src) / _child_name(_robot(src), "program")
            _copy(prog, dest / "R1" / prog.name)
            return dest
        if self.kind == "tree":
            robot = _robot(src)
            if self.detail == "flat":
                _copy(robot, dest)
                for other in _siblings(src, robot):
                    _copy(other, dest / other.name)
            else:
                _copy(robot, dest / "KRC" / "R1")
                for other in _siblings(src, robot):
                    _copy(other, dest / "KRC" / other.name)
            return dest
        _copy(src, dest)
        if self.kind == "whole":
            return dest
        if self.kind == "group-inputs":
            robot = _robot(dest)
            folder = robot / (_child_name(robot, "program") or "Program")
            folder.mkdir(parents=True, exist_ok=True)
            src_text, dat_text = group_inputs_program()
            (folder / f"{GROUPS_NAME}.src").write_text(src_text, encoding="latin-1")
            (folder / f"{GROUPS_NAME}.dat").write_text(dat_text, encoding="latin-1")
            return dest
        if self.kind == "a4fix-limits":
            _a4fix_limits(dest)
            return dest
        if self.kind == "config-user-part-missing":
            cfg = dest / self.detail
            cfg.write_bytes(_without_user_folds(cfg.read_bytes()))
            return dest
        if self.kind == "busy-submit":
            sub = dest / self.detail
            busy = busy_submit(sub.read_bytes())
            if busy is None:
                raise ValueError(f"{self.detail}: no LOOP in its main routine to make busy")
            sub.write_bytes(busy)
            return dest
        target = dest / self.detail
        if target.is_dir():
            shutil.rmtree(target)
        elif target.exists():
            target.unlink()
        return dest


def _robot(root: Path) -> Path:
    """The robot's folder of a backup root: ``R1`` (``KRC/R1``), else the root (a flat export)."""
    r1 = _child_name(root, "r1")
    return root / r1 if r1 else root


def _child_name(folder: Path, name: str) -> str:
    """The name of `folder`'s sub-folder `name` in any letter case, "" when there is none."""
    for p in sorted(folder.iterdir()) if folder.is_dir() else ():
        if p.name.lower() == name and p.is_dir() and not p.is_symlink():
            return p.name
    return ""


def _siblings(root: Path, robot: Path) -> list[Path]:
    """The folders beside the robot's folder in a ``KRC/R1`` backup (``STEU``), none in a flat one."""
    if robot == root:
        return []
    return [p for p in sorted(root.iterdir()) if p.is_dir() and not p.is_symlink() and p != robot]


def _copy(src: Path, dest: Path) -> None:
    """Copy the regular files of `src` below `dest` (links are never followed nor copied)."""
    dest.mkdir(parents=True, exist_ok=True)
    for p in sorted(src.rglob("*")):
        if p.is_symlink() or not p.is_file():
            continue
        q = dest / p.relative_to(src)
        q.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(p, q)


def _zip(src: Path, archive: Path) -> Path:
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as zf:
        for p in sorted(src.rglob("*")):
            if p.is_file() and not p.is_symlink():
                zf.write(p, (Path(src.name) / p.relative_to(src)).as_posix())
    return archive


def _zip_contents(folder: Path, archive: Path) -> Path:
    """`folder`'s files zipped with entries relative to it (a controller's archive.zip)."""
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as zf:
        for p in sorted(folder.rglob("*")):
            if p.is_file() and not p.is_symlink():
                zf.write(p, p.relative_to(folder).as_posix())
    return archive


def _archive(src: Path, dest: Path) -> Path:
    """The backup `src` laid out as a KSS 8 controller archive in `dest` (the ``archive`` kind)."""
    robot = _robot(src)
    _copy(robot, dest / "KRC" / "R1")
    for other in _siblings(src, robot):
        _copy(other, dest / "KRC" / other.name)
    for rel, text in (*TEMPLATES, ("am.ini", AM_INI)):
        (dest / rel).parent.mkdir(parents=True, exist_ok=True)
        (dest / rel).write_bytes(text.encode("latin-1"))
    (dest / BINARY).parent.mkdir(parents=True, exist_ok=True)
    (dest / BINARY).write_bytes(bytes(range(256)) * 4)
    return dest


def _named_model(robot: Path) -> str:
    """The model the robot folder's ``Mada/$machine.dat`` names (``$MODEL_NAME[]``, else
    ``$TRAFONAME[]``, without KUKA's ``#``), "" when none, or when its ``$config.dat`` has no
    ``MACHINE_DEF[1]`` to name it in."""
    mada = _child_name(robot, "mada")
    system = _child_name(robot, "system")
    mach = next((p for p in sorted((robot / mada).iterdir()) if p.name.lower() == "$machine.dat"), None) \
        if mada else None
    cfg = next((p for p in sorted((robot / system).iterdir()) if p.name.lower() == "$config.dat"), None) \
        if system else None
    if mach is None or cfg is None or not _MACHINE_DEF.search(cfg.read_bytes().decode("latin-1")):
        return ""
    found = _MODEL.search(mach.read_bytes().decode("latin-1"))
    return found.group(1).strip() if found else ""


def _flat(src: Path, dest: Path) -> Path:
    """The robot folder's KRL files of `src` in the one folder `dest` (the first of a name), its
    machine data left out, ``MACHINE_DEF[1]`` naming the model they named (the ``flat`` kind)."""
    robot = _robot(src)
    model = _named_model(robot)
    dest.mkdir(parents=True, exist_ok=True)
    seen: set[str] = set()
    for p in sorted(robot.rglob("*")):
        rel = p.relative_to(robot)
        if p.is_symlink() or not p.is_file() or not is_krl_file(p) or rel.parts[0].lower() == "mada":
            continue
        if p.name.lower() in seen:
            continue
        seen.add(p.name.lower())
        data = p.read_bytes()
        if p.name.lower() == "$config.dat":
            data = _MACHINE_DEF.sub(lambda m: m.group(1) + model + m.group(2), data.decode("latin-1"), 1).encode("latin-1")
        (dest / p.name).write_bytes(data)
    return dest


def _without_user_folds(data: bytes) -> bytes:
    """`data` (a ``$config.dat``) with the lines inside its USER folds deleted, the fold lines
    kept (krl/semantics/outside.py ``template_lines``: the lines the user wrote)."""
    text = data.decode("latin-1")
    user = template_lines(text)[2]
    lines = text.splitlines(keepends=True)
    keep = [line for no, line in enumerate(lines, 1)
            if no not in user or line.lstrip().upper().startswith((";FOLD", ";ENDFOLD"))]
    return "".join(keep).encode("latin-1")


def group_inputs_program() -> tuple[str, str]:
    """The ``.src`` and ``.dat`` texts of the ``group-inputs`` variant's program (module
    docstring): a product width (12 bits) and type (4 bits) read from SIGNAL groups through
    variables, the weight of the product chosen by IFs on both (900 x 10: 55, 1200 x 12: 70)
    and read unconditionally (``value invalid`` when no IF was taken), a SWITCH on the type
    whose DEFAULT halts."""
    a, b, c, d, ready = GROUPS_INPUTS
    dat = "\n".join([f"DEFDAT {GROUPS_NAME}",
                     f"SIGNAL KRL_VARIANT_WIDTH $IN[{a}] TO $IN[{b}] ;product width",
                     f"SIGNAL KRL_VARIANT_TYPE $IN[{c}] TO $IN[{d}] ;product type",
                     f"SIGNAL KRL_VARIANT_READY $IN[{ready}] ;product ready",
                     "DECL INT KRL_VARIANT_LOAD=0", "ENDDAT", ""])
    src = "\n".join([f"DEF {GROUPS_NAME}( )", "  DECL INT width, kind, weight",
                     "  WAIT FOR KRL_VARIANT_READY", "  width = KRL_VARIANT_WIDTH", "  KrlVariantType(kind)",
                     "  IF (width == 900) AND (kind == 10) THEN", "    weight = 55", "  ENDIF",
                     "  IF (width == 1200) AND (kind == 12) THEN", "    weight = 70", "  ENDIF",
                     "  KRL_VARIANT_LOAD = 130 + weight", "  SWITCH kind", "  CASE 10, 12",
                     "    KRL_VARIANT_LOAD = KRL_VARIANT_LOAD + 1", "  DEFAULT", "    HALT", "  ENDSWITCH", "END", "",
                     "DEF KrlVariantType(k :OUT)", "  DECL INT k", "  k = KRL_VARIANT_TYPE", "END", ""])
    return src, dat


def _a4fix_limits(dest: Path) -> None:
    """Make the copy of a backup at `dest` the ``a4fix-limits`` variant (module docstring): its
    robot's ``Mada/$machine.dat`` the five-axis palletizer's with A4 limits of -350/350, the
    search program in its Program folder."""
    robot = _robot(dest)
    mada = robot / (_child_name(robot, "mada") or "Mada")
    mada.mkdir(parents=True, exist_ok=True)
    for old in [p for p in mada.iterdir() if p.name.lower() == "$machine.dat"]:
        old.unlink()
    text = PA5_MACHINE.read_text(encoding="utf-8")
    for old, new in A4_LIMITS:
        if text.count(old) != 1:
            raise ValueError(f"{PA5_MACHINE.name}: no single {old!r} to set")
        text = text.replace(old, new)
    (mada / "$machine.dat").write_text(text, encoding="latin-1")
    folder = robot / (_child_name(robot, "program") or "Program")
    folder.mkdir(parents=True, exist_ok=True)
    src_text, dat_text = a4_limits_program()
    (folder / f"{A4_NAME}.src").write_text(src_text, encoding="latin-1")
    (folder / f"{A4_NAME}.dat").write_text(dat_text, encoding="latin-1")


def a4_limits_program() -> tuple[str, str]:
    """The ``.src`` and ``.dat`` texts of the ``a4fix-limits`` variant's program (module
    docstring): the target of the axes A1 -40, A2 -80, A3 100, A4 0, A5 30, A6 10 (FORWARD), its
    64 configurations of S 0..7 and the turn bits of A1..A3 (T 0..7) through INVERSE, the first
    whose A4 is strictly inside ``$SOFTN_END[4]`` .. ``$SOFTP_END[4]`` kept (else S 2, T 0),
    then a PTP to it; ``KRL_VARIANT_KEPT`` counts the configurations kept."""
    dat = "\n".join([f"DEFDAT {A4_NAME}", "DECL INT KRL_VARIANT_KEPT=0", "DECL INT KRL_VARIANT_S=-1",
                     "DECL INT KRL_VARIANT_T=0", "ENDDAT", ""])
    src = "\n".join([
        f"DEF {A4_NAME}( )", "  DECL E6POS target, p", "  DECL E6AXIS ax, start", "  INT s, t, st",
        "  $TOOL = $NULLFRAME", "  $BASE = $NULLFRAME", "  PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}",
        "  start = $AXIS_ACT", "  target = FORWARD({A1 -40, A2 -80, A3 100, A4 0, A5 30, A6 10}, st)",
        "  FOR s = 0 TO 7", "    FOR t = 0 TO 7", "      p = target", "      p.S = s", "      p.T = t",
        "      ax = INVERSE(p, start, st)", "      IF st == 0 THEN",
        "        IF (ax.A4 > $SOFTN_END[4]) AND (ax.A4 < $SOFTP_END[4]) THEN",
        "          KRL_VARIANT_KEPT = KRL_VARIANT_KEPT + 1", "          IF KRL_VARIANT_S < 0 THEN",
        "            KRL_VARIANT_S = s", "            KRL_VARIANT_T = t", "          ENDIF", "        ENDIF",
        "      ENDIF", "    ENDFOR", "  ENDFOR", "  IF KRL_VARIANT_S < 0 THEN", "    KRL_VARIANT_S = 2",
        "    KRL_VARIANT_T = 0", "  ENDIF", "  p = target", "  p.S = KRL_VARIANT_S", "  p.T = KRL_VARIANT_T",
        "  PTP p", "END", ""])
    return src, dat


def busy_submit(data: bytes) -> bytes | None:
    """`data` (a submit program) with its main routine's first ``LOOP`` made busy: the counter
    :data:`BUSY_NAME` declared first in the routine, set to 0 before the loop and counted up at
    the start of every pass (a pass that changes the state is never parked nor idle:
    interp/runtime/spin.py, idle.py); None when the first routine has no ``LOOP`` of its own
    before its ``END``. Line ends and the other lines are kept."""
    text = data.decode("latin-1")
    lines = text.splitlines(keepends=True)
    nl = "\r\n" if "\r\n" in text else "\n"
    start = next((i for i, line in enumerate(lines) if _DEF.match(line)), None)
    if start is None:
        return None
    for i in range(start + 1, len(lines)):
        if _END.match(lines[i]):
            return None
        if _LOOP.match(lines[i]):
            indent = lines[i][: len(lines[i]) - len(lines[i].lstrip())]
            out = lines[: start + 1] + [f"DECL INT {BUSY_NAME}{nl}"] + lines[start + 1: i] \
                + [f"{indent}{BUSY_NAME} = 0{nl}", lines[i], f"{indent}  {BUSY_NAME} = {BUSY_NAME} + 1{nl}"] \
                + lines[i + 1:]
            return "".join(out).encode("latin-1")
    return None


#: the user PLC fold of KUKA's SPS.SUB templates (KR C2 and KR C4 alike)
_USER_PLC = re.compile(r"^\s*;FOLD\s+USER\s+PLC\b", re.I)
#: the user subroutine fold of the templates, else the file's end
_USER_SUB = re.compile(r"^\s*;FOLD\s+USER\s+SUBROUTINE\b", re.I)


def mapping_lines(n: int, calls: int) -> tuple[list[str], list[str]]:
    """The user PLC of a cell's SPS.SUB as integrators write it (issue 76): `n` mapping lines
    (``$OUT[n] = $OUT[m]``, ``$OUT[n] = $IN[m] AND NOT $IN[k]``), every tenth an ``IF`` on
    signals, `calls` calls of user routines (each a few mappings and an ``IF`` of its own),
    the KR C4 template's key flag (``$FLAG[1] = IS_KEY_PRESSED(17)``: KSS, $operate.dat) and an
    override clamp in EXT and AUT (``$OV_PRO`` held at 75 %). Returns (the loop's lines, the
    routines' lines). Signal numbers 200-999: no template's own."""
    body = ["$FLAG[1] = IS_KEY_PRESSED(17)",
            "IF ($MODE_OP == #EX) OR ($MODE_OP == #AUT) THEN",
            "  IF $OV_PRO > 75 THEN",
            "    $OV_PRO = 75",
            "  ENDIF",
            "ENDIF"]
    for i in range(n):
        out = 200 + i
        if i % 10 == 9:
            body += [f"IF $IN[{300 + i}] AND NOT $OUT[{200 + i - 1}] THEN", f"  $OUT[{out}] = TRUE",
                     "ELSE", f"  $OUT[{out}] = $FLAG[{10 + i % 50}]", "ENDIF"]
        elif i % 2:
            body.append(f"$OUT[{out}] = $IN[{300 + i}] AND NOT $IN[{600 + i}]")
        else:
            body.append(f"$OUT[{out}] = $OUT[{out - 1 if i else 999}]")
    body += [f"KRL_MAP_USER{k}()" for k in range(calls)]
    subs: list[str] = []
    for k in range(calls):
        subs += ["", f"DEF KRL_MAP_USER{k}()", f"  $OUT[{900 + k}] = $IN[{950 + k}]",
                 f"  IF $IN[{960 + k}] THEN", f"    $FLAG[{100 + k}] = NOT $OUT[{900 + k}]", "  ENDIF", "END"]
    return body, subs


def mapping_submit(data: bytes, n: int, calls: int = 1) -> bytes | None:
    """`data` (a KUKA SPS.SUB template, KR C2 or KR C4) with :func:`mapping_lines` ``(n, calls)``
    written into its ``USER PLC`` fold and the routines into its ``USER SUBROUTINE`` fold (else
    appended); None when it has no ``USER PLC`` fold. Line ends and the other lines are kept."""
    text = data.decode("latin-1")
    lines = text.splitlines(keepends=True)
    nl = "\r\n" if "\r\n" in text else "\n"
    at = next((i for i, line in enumerate(lines) if _USER_PLC.match(line)), None)
    if at is None:
        return None
    body, subs = mapping_lines(n, calls)
    indent = lines[at][: len(lines[at]) - len(lines[at].lstrip())]
    lines[at + 1:at + 1] = [f"{indent}{b}{nl}" for b in body]
    sub_at = next((i for i, line in enumerate(lines) if _USER_SUB.match(line)), None)
    tail = [f"{s}{nl}" for s in subs]
    if sub_at is None:
        lines += ([nl] if lines and not lines[-1].endswith(("\n", "\r")) else []) + tail
    else:
        lines[sub_at + 1:sub_at + 1] = tail
    return "".join(lines).encode("latin-1")


#: the backups :func:`mapping_backups` extends: KUKA's KR C2 SPS.SUB template (ChinaMilling, KRC/R1
#: layout) and the KR C4 one with ``TORQUE_MONITORING()`` (the palletizer)
MAPPING_BASES = ("HugoDanielson__ChinaMilling", "ingeniado__KRC4-Robot-Palletizer")


def mapping_backups(dest: Path, sizes: tuple[int, ...] = (20, 200), corpus: Path = SHARED_CORPUS) -> list[Path]:
    """Write into `dest` one copy of each backup of :data:`MAPPING_BASES` (under `corpus`) per
    size of `sizes`, its SPS.SUB made a cell's (:func:`mapping_submit` with that many mapping lines
    and ``1 + size // 50`` routine calls); returns the copies' roots (``NAME-mapN``). The
    generated SPS.SUBs of issue 76's "Done when" (tools/whole_run_bench.py ``--corpus dest``)."""
    out = []
    for base in MAPPING_BASES:
        src = corpus / base
        for n in sizes:
            root = dest / f"{base}-map{n}"
            if root.exists():
                shutil.rmtree(root)
            _copy(src, root)
            sub = next((submit_program(b) for b in find_backups(root) if submit_program(b)), None)
            made = mapping_submit(sub.read_bytes(), n, 1 + n // 50) if sub is not None else None
            if made is None:
                raise ValueError(f"{base}: no SPS.SUB with a USER PLC fold")
            sub.write_bytes(made)
            out.append(root)
    return out


def variants_of(backup: Path) -> list[Variant]:
    """Every variant of the backup rooted at `backup` (module docstring), in :data:`KINDS` order."""
    out = [Variant(backup, "whole")]
    robot = _robot(backup)
    rel = lambda p: p.relative_to(backup).as_posix()      # noqa: E731
    tp = _child_name(robot, "tp")
    if tp:
        out.append(Variant(backup, "no-TP", rel(robot / tp)))
        out += [Variant(backup, "no-TP/", rel(p)) for p in sorted((robot / tp).iterdir())
                if p.is_dir() and not p.is_symlink()]
        out += [Variant(backup, "no-package-dat", rel(p)) for p in sorted((robot / tp).rglob("*"))
                if p.is_file() and p.suffix.lower() == ".dat"]
    for folder in ("system", "mada"):
        name = _child_name(robot, folder)
        if name:
            out += [Variant(backup, "no-system", rel(p)) for p in sorted((robot / name).iterdir())
                    if p.is_file() and is_krl_file(p)]
    system = _child_name(robot, "system")
    cfg = next((p for p in sorted((robot / system).iterdir()) if p.name.lower() == "$config.dat"), None) \
        if system else None
    if cfg is not None and template_lines(cfg.read_bytes().decode("latin-1"))[2]:
        out.append(Variant(backup, "config-user-part-missing", rel(cfg)))
    sub = submit_program(backup)          # R1/SPS.SUB, else System/SPS.SUB (krl.project)
    if sub is not None and busy_submit(sub.read_bytes()) is not None:
        out.append(Variant(backup, "busy-submit", rel(sub)))
    if _child_name(robot, "program"):
        out.append(Variant(backup, "program-only"))
    out.append(Variant(backup, "tree", "flat" if robot != backup else "KRC/R1"))
    out.append(Variant(backup, "zip"))
    out.append(Variant(backup, "group-inputs"))
    out.append(Variant(backup, "a4fix-limits"))
    out.append(Variant(backup, "archive"))
    out.append(Variant(backup, "archive-zips"))
    if _named_model(robot):
        out.append(Variant(backup, "flat", "MACHINE_DEF"))
    return out


def backups(folders: list[Path]) -> list[Path]:
    """The backup roots below `folders` (krl/project.py ``find_backups``), in order."""
    out: list[Path] = []
    for f in folders:
        if f.is_dir():
            out += find_backups(f)
    return out


def sample(variants: list[Variant], n: int) -> list[Variant]:
    """`n` variants evenly spaced over `variants` (their order: by backup, then kind), always
    one of each kind present first, the k-th kind's taken k/len(KINDS) of the way through its
    variants (so that they come from different backups): a deterministic sample that covers
    every kind."""
    if n >= len(variants):
        return list(variants)
    by_kind: dict = {}
    for v in variants:
        by_kind.setdefault(v.kind, []).append(v)
    chosen = [vs[len(vs) * k // len(KINDS)] for k, kind in enumerate(KINDS)
              if (vs := by_kind.get(kind))][:n]
    rest = [v for v in variants if v not in chosen]
    k = n - len(chosen)
    if k > 0 and rest:
        step = len(rest) / k
        chosen += [rest[int(i * step)] for i in range(k)]
    return chosen


def some_entries(entries: list[Path], n: int) -> list[Path]:
    """`n` of `entries` (0: all): the submit interpreter's (``sps.sub``: it runs KUKA's folds and
    the packages' PLC parts, what a variant removes first) and evenly spaced programs."""
    if not n or n >= len(entries):
        return entries
    subs = [e for e in entries if e.suffix.lower() == ".sub"][:n]
    rest = [e for e in entries if e not in subs]
    k = n - len(subs)
    return subs + [rest[int(i * len(rest) / k)] for i in range(k)] if k > 0 and rest else subs


def _entries(folder: Path) -> list[Path]:
    """The entry points of a materialised variant: of its backups (interp.realprograms
    ``entries_of``); of a folder that is no backup any more (its ``System/$config.dat`` removed,
    ``R1/Program`` alone), the programs the same rule finds there (``programs_of``: a Program
    folder's, KUKA's system folders left out), else every program of the folder."""
    roots = find_backups(folder)
    if roots:
        return [p for r in roots for p in rp.entries_of(r)]
    progs = rp.programs_of(folder)
    if progs:
        return progs
    files = sorted(p for p in folder.rglob("*") if p.is_file() and not p.is_symlink())
    return rp.folder_entries(files)


def run_variant(variant: Variant, sim_time: float = SIM_TIME_S, steps: int = STEPS, interp: str = "vm",
                entries: int = 0) -> dict:
    """Materialise `variant` and run every entry point of it (module docstring), or `entries` of
    them (:func:`some_entries`; 0: all). Returns
    ``{"variant", "backup", "runs": [{"entry", "cause", "reason", "text", "outside_stops"}]}``;
    never raises for the material: an error of the simulator is a run with cause "internal"."""
    runs = []
    with tempfile.TemporaryDirectory(prefix="krl-variant-") as tmp:
        made = variant.make(Path(tmp))
        try:
            # as every command reads a backup (krl/backups.py): a .zip extracted, a folder of
            # archives each, the programs of each (a controller archive's C/ is none)
            with opened(made) as parts:
                found = [(part, e) for part, root, _e in programs_in(parts) for e in _entries(Path(root))]
                if variant.kind in ADDED:
                    found = [(part, e) for part, e in found if e.stem.lower() == ADDED[variant.kind]]
                shown = {e: Path(part.shown(str(e))) for part, e in found}
                for entry in some_entries([e for _p, e in found], entries):
                    row = rp.run_one(entry, sim_time, steps, auto=True, interp=interp, auto_sim_time=sim_time)
                    internal = row["reason"] == "internal"
                    runs.append({"entry": _rel(shown[entry], made),
                                 "cause": "internal" if internal else row["cause"],
                                 "reason": row["reason"], "text": row.get("text") or "",
                                 "robot": row.get("robot", ""), "outside_stops": row.get("outside_stops") or []})
        except Exception as exc:  # noqa: BLE001 - a variant that cannot be read is a finding, not the end
            runs.append({"entry": "", "cause": "internal", "reason": "internal",
                         "text": f"{type(exc).__name__}: {exc}", "outside_stops": []})
    return {"variant": variant.name, "kind": variant.kind, "backup": str(variant.backup), "runs": runs}


def _rel(entry: Path, made: Path) -> str:
    """An entry point's path as the variant shows it, below the folder or ``.zip`` made
    (``KRC/R1/cell.src``, ``a.zip/KRC/R1/cell.src`` in a folder of archives)."""
    return entry.relative_to(made).as_posix() if made in entry.parents else entry.as_posix()


def _task(backup: str, kind: str, detail: str, sim_time: float, steps: int, interp: str) -> dict:
    """A worker's task (krl.pool): one variant's runs."""
    return run_variant(Variant(Path(backup), kind, detail), sim_time, steps, interp)


def summarise(results: list[dict]) -> dict:
    """Counts of `results` (:func:`run_variant`'s): variants, runs, runs by cause, the failing
    runs (an outside stop or an internal error), as ``{"variants", "runs", "causes", "failures"}``."""
    causes: Counter = Counter()
    failures = []
    for res in results:
        for run in res["runs"]:
            causes[run["cause"]] += 1
            if run["outside_stops"] or run["cause"] == "internal":
                failures.append({"variant": res["variant"], "backup": res["backup"], "entry": run["entry"],
                                 "text": run["text"], "outside_stops": run["outside_stops"]})
    return {"variants": len(results), "runs": sum(causes.values()), "causes": dict(sorted(causes.items())),
            "outside_stops": sum(len(f["outside_stops"]) for f in failures),
            "internal": causes.get("internal", 0), "failures": failures}


def _logged(log: Path | None, interp: str) -> dict:
    """The results `log` (``--log``) holds for `interp`, keyed by (backup, variant name); a line
    cut by a stop mid-write is left out (its variant runs again)."""
    if log is None or not log.exists():
        return {}
    found = {}
    for line in log.read_text(encoding="utf-8").splitlines():
        try:
            res = json.loads(line)
        except ValueError:
            continue
        if isinstance(res, dict) and res.get("interp") == interp and isinstance(res.get("runs"), list):
            found[(res.get("backup"), res.get("variant"))] = res
    return found


def _outcomes(args, tasks):
    """The sweep's outcomes: on the cluster at ``--scheduler`` (one variant per task) or in
    local worker processes (krl.pool)."""
    if args.scheduler:
        return run_batches(args.scheduler, _task, tasks, batch_files=1, name="krl-variants")
    return run_tasks(_task, tasks, jobs=args.jobs)


def _sweep(args, variants: list, tasks: list, results: list) -> None:
    """Run `tasks`, putting each variant's result in `results`, its line in ``--log``.
    Raises SchedulerError (krl.cluster)."""
    for done, o in enumerate(_outcomes(args, tasks), len(variants) - len(tasks) + 1):
        v = variants[o.key]
        results[o.key] = o.value if o.status == "done" else {
            "variant": v.name, "kind": v.kind, "backup": str(v.backup),
            "runs": [{"entry": "", "cause": "internal", "reason": "internal", "text": o.detail or o.status,
                      "outside_stops": []}]}
        if args.log is not None:
            with args.log.open("a", encoding="utf-8") as log:
                log.write(json.dumps({**results[o.key], "interp": args.interp}) + "\n")
        failing = summarise([results[o.key]])["failures"]
        print(f"[{done}/{len(variants)}] {v.backup} [{v.name}]: {len(results[o.key]['runs'])} runs"
              + (f", {len(failing)} failing" if failing else ""), file=sys.stderr, flush=True)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m interp.variants", description=__doc__.split("\n\n")[0])
    ap.add_argument("folders", nargs="*", type=Path, help="folders holding backups (default: the shared corpus "
                                                          "and history)")
    ap.add_argument("--sample", type=int, default=0, help="run this many variants (evenly spaced; 0: all)")
    ap.add_argument("--jobs", type=int, default=None, help="worker processes (default: one per core)")
    ap.add_argument("--interp", choices=("vm", "tree"), default="vm")
    ap.add_argument("--json", type=Path, default=None, help="write the results here")
    ap.add_argument("--log", type=Path, default=None,
                    help="append each variant's result to this file as one JSON line as it ends; the variants "
                         "it already holds are not run again (a stopped sweep resumes)")
    ap.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                    help="run the variants on this Dask distributed scheduler's cluster, one variant per task "
                         "(its workers see the backups at the same paths); a lost worker's variants run again "
                         "on the others; a lost scheduler is waited for at the same address (up to "
                         "KRL_RECONNECT_S, 120 s) and the sweep goes on; past that it ends (exit 2): run it "
                         "again with the same --log and it resumes")
    ap.add_argument("--mapping-corpus", type=Path, default=None, metavar="OUT",
                    help="write the generated cells' backups (mapping_backups) into OUT and stop")
    args = ap.parse_args(argv)
    if args.mapping_corpus is not None:
        for root in mapping_backups(args.mapping_corpus):
            print(root)
        return 0

    folders = args.folders or [SHARED_CORPUS, SHARED_HISTORY]
    variants = [v for b in backups(folders) for v in variants_of(b)]
    if args.sample:
        variants = sample(variants, args.sample)
    results: list = [None] * len(variants)
    logged = _logged(args.log, args.interp)
    for k, v in enumerate(variants):
        results[k] = logged.get((str(v.backup), v.name))
    tasks = [(k, (str(v.backup), v.kind, v.detail, SIM_TIME_S, STEPS, args.interp))
             for k, v in enumerate(variants) if results[k] is None]
    if logged:
        print(f"{len(variants) - len(tasks)} variants read from {args.log}", file=sys.stderr, flush=True)
    try:
        _sweep(args, variants, tasks, results)
    except SchedulerError as exc:
        print(f"error: {exc}" + (f" (resume: run again with --log {args.log})" if args.log else ""),
              file=sys.stderr)
        return 2
    s = summarise(results)
    print(f"variants {s['variants']} of {len(backups(folders))} backups, runs {s['runs']}: "
          + ", ".join(f"{k} {n}" for k, n in s["causes"].items()))
    print(f"stops on a name the checker classifies as installed software: {s['outside_stops']}; "
          f"internal errors: {s['internal']}")
    for f in s["failures"]:
        print(f"  {f['backup']} [{f['variant']}] {f['entry']}: {f['text']} {f['outside_stops']}")
    if args.json is not None:
        write_text(args.json, json.dumps({"summary": {k: v for k, v in s.items() if k != "failures"},
                                          "failures": s["failures"], "results": results}, indent=1))
    return 1 if s["failures"] else 0


if __name__ == "__main__":
    sys.exit(main())
