"""Run the programs of the KRC backups in ../shared/krl-corpus and report how they end
(issue 6, "Real programs").

A *backup* is a folder with ``R1/System`` (or a flat export with ``System/$config.dat``); its
*programs* (entry points, :func:`entries_of`) are the ``.src`` files under its Program folders
(and ``cell.src``) whose main routine takes no parameters, and its ``SPS.SUB``. Each runs on
the bytecode VM (``--interp tree``: the tree interpreter; the same front end and runtime, and
the same cause and reason on every corpus entry point, side by side 2026-11-24) with the
backup's own System folder (BASIS, ``$config.dat``),
``--max-sim-time`` 60 s and 300 000 steps of the program's own, beside its SPS.SUB (an
SPS.SUB entry runs alone): the step limit counts the robot program's steps only
(:func:`step_limit`), so a submit cycling at its budget does not end the run before its time.

Each program runs twice (two columns of the report, issue 34): with its committed cell file
(:func:`cell_of`: ``corpus/cells``; ``--no-cells`` runs this column without), and with
``--inputs auto`` — the automatic cell (interp/runtime/autocell.py) and nothing hand-written.
``--columns cells`` or ``--columns auto`` runs one.

Every stop gets one *cause* (:func:`cause_of`, issue 22 "Every stop explained"):

* ``completed``;
* ``intended end``: the program's own ``HALT``, or a cycle loop stopped by the time or step
  limit while the cell answers it (a rule of the cell file or an answer of the automatic cell
  wrote an input in the last quarter of the run: the cycle was still running), or an
  ``SPS.SUB`` cycling at the limit (a submit program never ends, reference §9);
* ``program error``: a KRL run-time error of the program, at its file:line; also a motion
  whose target the backup's own robot cannot take (the run simulates the robot of the
  backup's ``$machine.dat``, and no axis configuration of the target — any status, turn,
  ±360° variant — lies within that machine data's software limits,
  robot/motionqueue.py ``MotionQueue.target_outside_limits``; the error says so,
  interp/runtime/motions.py ``TARGET_OUTSIDE_NOTE``): the real controller of that robot refuses it too;
* ``interpreter gap``: an error that is the simulator's (:data:`GAP_MESSAGES`: a feature not
  simulated; a target, a CP path or an axis range the simulated robot cannot follow when it is
  not the backup's own — the KR 6 R900 of a backup without machine data — or when only the
  path, not the target, leaves the limits),
  or an internal error;
* ``limit``: the time or step limit (or a deadlock) with no cell answering: the program starves
  for an input (named by the stop text, "waits: WAIT FOR ...") or loops on its own.

A run-time error of the backup's submit program (SPS.SUB) does not end the run: each row's
``submit`` lists those errors and the report counts them.

Routines of technology packages absent from the backup are stubbed (a ``message`` event
"stub: NAME"), and the report lists the stubs.

Usage: ``python -m interp.realprograms [CORPUS] [--json OUT] [--limit N] [--columns cells,auto]
[--interp vm|tree] [--jobs N] [--scheduler tcp://HOST:PORT] [--history new|old|both]`` (``--jobs``: worker
processes of this machine, one per core by default; ``--scheduler``: the runs go to a Dask cluster,
:func:`run_rows`; the same report; ``--history``: CORPUS is ../shared/krl-history and the programs are
those of each pair's side, in backups or not, :func:`history_entries`).
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import re
import sys
import time
from collections import Counter
from pathlib import Path

from interp.runtime.motions import TARGET_OUTSIDE_NOTE
from krl.durable import write_text
from interp.runtime.errors import NOT_UNDERSTOOD
from interp.runtime.kss import NOT_INSTALLED
from interp.runtime.program import parse_module
from krl import limits
from krl.parsecache import load_files
from krl.files import SHARED_CORPUS as DEFAULT_CORPUS
from krl.project import (
    backup_of, boot_submit, find_backups, header_folder, kuka_folder, machine_data_file, system_folder,
)
from interp.run import cell_of as cell_file, global_value, make_runtime, robot_for, run_spec, RunSinks
from krl.cluster import run_batches, SchedulerError
from krl.pool import default_jobs, run_tasks
from interp import run as _loaded

LEGITIMATE = ("deadlock", "halt", "max_sim_time", "max_steps")

#: the report's limits of a run: simulated time (s; a cell file may give a long job more,
#: :func:`time_limit`) and statements of the robot program (the step limit counts only those)
REPORT_SIM_TIME_S = 60.0
REPORT_STEPS = 300_000
#: the time limit of the --inputs auto column: ``krl run``'s own (s). Nothing hand-written says
#: how long a job takes; a program that starves costs nothing while it waits (the idle
#: fast-forward), one that works runs to its end. An SPS.SUB entry keeps REPORT_SIM_TIME_S.
AUTO_SIM_TIME_S = 600.0

#: the causes of a stop, in report order
CAUSES = ("completed", "intended end", "program error", "interpreter gap", "limit")

#: parts of a run-time error message that make it the simulator's gap, not the program's error
GAP_MESSAGES = ("target not reachable", "through a singularity", "software limit switch",
                "not supported", "unsupported", "not simulated",
                "not implemented", "internal error", NOT_UNDERSTOOD)

#: errors of a motion the robot cannot follow: the program's when the robot is the backup's own
#: and the target itself is out of its limits (:func:`cause_of`)
REACH_MESSAGES = ("target not reachable", "software limit switch")

#: the committed cell files of the corpus backups (issue 22)
CELLS = Path(__file__).resolve().parent.parent / "corpus" / "cells"


def cell_of(path: Path, corpus: Path = DEFAULT_CORPUS, cells: Path = CELLS) -> Path | None:
    """The committed cell file of a corpus program: ``corpus/cells/REPO/STEM.yaml`` (one
    program, lower-case stem), else ``corpus/cells/REPO.yaml`` (the backup), where REPO is the
    program's first folder under the corpus. None when there is none."""
    try:
        repo = path.resolve().relative_to(corpus.resolve()).parts[0]
    except (ValueError, IndexError):
        return None
    for cand in (cells / repo / f"{path.stem.lower()}.yaml", cells / f"{repo}.yaml"):
        if cand.is_file():
            return cand
    return None


def row_from_trace(program: Path, events: list[dict]) -> dict:
    """A row as :func:`run_one` gives it, from the trace of a run of `program` with its cell
    (the conformance report runs programs through ``krl run``): the ``end`` event, the cell's
    answers (``io`` events whose source is ``cell``/``cell:...``), and the cause."""
    ends = [e for e in events if e.get("kind") == "end"]
    end = ends[-1] if ends else {}
    cell = [e["t"] for e in events if e.get("kind") == "io" and str(e.get("source", "")).startswith("cell")]
    robots = [e for e in events if e.get("kind") == "robot"]
    row = {"program": str(program), "reason": end.get("reason", "internal"), "text": end.get("text") or "",
           "file": end.get("file"), "line": end.get("line"), "sim_time": end.get("t", 0.0),
           "cell_answers": len(cell), "cell_last": max(cell) if cell else None,
           "robot_own": bool(robots) and _own_machine_data(program, robots[0].get("source"))}
    if row["reason"] == "program_end":
        row["reason"] = "completed"
    row["cause"] = cause_of(row)
    return row


def _own_machine_data(program: Path, source) -> bool:
    """True when `source` (the ``robot`` trace event's) is the machine data of the backup
    holding `program`: the run simulated the backup's own robot."""
    root = backup_of(Path(program).resolve())
    f = machine_data_file(root) if root is not None else None
    return f is not None and source is not None and Path(str(source)).resolve() == f.resolve()


def cause_of(row: dict) -> str:
    """The one cause of a run's stop (see the module docstring): a row of :func:`run_one`."""
    reason = row.get("reason")
    if reason == "completed":
        return "completed"
    if reason == "halt":
        return "intended end"
    if reason == "internal":
        return "interpreter gap"
    if reason == "error":
        text = (row.get("text") or "").lower()
        if row.get("robot_own") and TARGET_OUTSIDE_NOTE.lower() in text and any(m in text for m in REACH_MESSAGES):
            return "program error"
        return "interpreter gap" if any(g.lower() in text for g in GAP_MESSAGES) else "program error"
    last = row.get("cell_last")
    t = row.get("sim_time") or 0.0
    if row.get("cell_answers") and last is not None and last >= 0.75 * t:
        return "intended end"
    if str(row.get("program", "")).lower().endswith(".sub") and reason in ("max_sim_time", "max_steps"):
        return "intended end"
    return "limit"


def programs_of(root: Path, files: list[Path] | None = None) -> list[Path]:
    """The robot programs of the backup rooted at `root` (krl/project.py): the .src files
    under the robot's folder (R1, or a flat export's root) in a Program folder, named CELL,
    or at that folder's top, whose first routine is a DEF without parameters, KUKA's files left
    out (krl.project.kuka_folder: a system folder's, or KUKA's by their header lines). `files`: the
    files to choose from (a walk of the folder, krl.files.walk, as ``krl audit`` lists them;
    default every file below the robot's folder, sorted)."""
    system = system_folder(root)
    root = system.parent if system is not None else root
    cands = []
    for p in sorted(root.rglob("*")) if files is None else files:
        if p.suffix.lower() != ".src" or not p.is_file():
            continue
        try:
            rel = p.relative_to(root)
        except ValueError:                           # a listed file outside the robot's folder
            continue
        if kuka_folder(p, root) is not None:         # KUKA's (krl/project.py rule 7)
            continue
        parts = [x.upper() for x in rel.parts]
        if "PROGRAM" in parts or p.stem.upper() == "CELL" or p.parent == root:
            cands.append(p)
    return [p for p, yes in zip(cands, _are_programs(cands)) if yes]


#: (path, size, modification time) -> whether it is a program (:func:`_are_programs`), this process's
_PROGRAMS: dict[tuple, bool] = {}


def _are_programs(paths: list[Path]) -> list[bool]:
    """:func:`is_program` of each of `paths`, the files not seen before (their path, size and
    modification time: :data:`_PROGRAMS`) read as one batch through the one store
    (krl.parsecache.load_files: the Java engine parses a batch where there is a JDK, each file
    within krl.limits.PARSE_TIMEOUT_S; in a worker process, ``krl audit``'s or a Dask worker's,
    which may not start the pool of parse workers, here: krl.workspace.load_here). One by one, a
    cold store parsed them with the Python engine: 21 s for the corpus's backups; and each
    listing read every module again (a pytest worker lists the corpus's programs three times
    at collection)."""
    keys = []
    for p in paths:
        try:
            st = os.stat(p)
            keys.append((str(p), st.st_size, st.st_mtime_ns))
        except OSError:
            keys.append(None)
    todo = [i for i, k in enumerate(keys) if k is None or k not in _PROGRAMS]
    read: dict[int, bool] = {}
    if todo:
        if len(_PROGRAMS) > 100_000:
            _PROGRAMS.clear()
        daemon = multiprocessing.current_process().daemon
        timeout = None if daemon or len(todo) == 1 else limits.PARSE_TIMEOUT_S
        for i, lf in zip(todo, load_files([str(paths[i]) for i in todo], timeout=timeout)):
            read[i] = _program_module(lf.module)
            if keys[i] is not None:
                _PROGRAMS[keys[i]] = read[i]
    return [read[i] if i in read else _PROGRAMS[k] for i, k in enumerate(keys)]


def loaded_with(program: str | Path) -> Path:
    """What a run of `program` loads and its worker process keeps (interp/runtime/program.py
    ``checked_workspace``): its backup (krl.project.backup_of), else its folder. The group of
    its run among others (krl.pool.run_tasks ``group``)."""
    p = Path(program)
    return backup_of(p) or p.parent


def _program_module(mod) -> bool:
    return bool(mod.routines) and not mod.routines[0].params and mod.routines[0].kind == "DEF"


def is_program(path: Path) -> bool:
    """True when the module `path`'s first routine is a DEF without parameters: a program an
    operator can select and start (it passes no arguments)."""
    mod, _errs = parse_module(str(path))
    return _program_module(mod)


def entries_of(root: Path, files: list[Path] | None = None) -> list[Path]:
    """The entry points of the backup at `root`: :func:`programs_of` (of `files`, if given),
    then its ``SPS.SUB`` (krl.project.boot_submit), as a controller starts it at boot."""
    progs = programs_of(root, files)
    sub = boot_submit(progs[0]) if progs else None
    return progs + ([sub] if sub is not None and sub not in progs else [])


def folder_entries(files: list[Path]) -> list[Path]:
    """The entry points of a folder of KRL files that is not a KRC backup (``krl audit``):
    among `files` (a walk of the folder, krl.files.walk), every .src module whose first
    routine is a DEF without parameters (:func:`is_program`) and that is not KUKA's by its own
    header lines (krl.project.header_folder: bas.src lying loose), and every .sub submit program
    (run alone, as an SPS.SUB entry of a backup is), in the order given."""
    srcs = [p for p in files if p.suffix.lower() == ".src" and p.is_file() and header_folder(p) is None]
    programs = {p for p, yes in zip(srcs, _are_programs(srcs)) if yes}
    return [p for p in files if (p.suffix.lower() == ".sub" and p.is_file()) or p in programs]


def loose_programs(folder: Path) -> list[Path]:
    """The programs of `folder` outside its backups (krl.project.find_backups): every ``.src``
    file below it, not inside a backup, whose first routine is a DEF without parameters (the
    programs of a repository that is not a controller backup, as ../shared/krl-history's
    sides mostly are), in path order."""
    roots = [b.resolve() for b in find_backups(folder)]
    out = []
    for p in sorted(folder.rglob("*")):
        if p.suffix.lower() != ".src" or not p.is_file():
            continue
        rp = p.resolve()
        if any(rp.is_relative_to(r) for r in roots):
            continue
        mod, _errs = parse_module(str(p))
        if mod.routines and not mod.routines[0].params and mod.routines[0].kind == "DEF":
            out.append(p)
    return out


def history_entries(history: Path, sides: tuple[str, ...] = ("new",)) -> list[Path]:
    """The entry points of ../shared/krl-history's pair sides `sides` (``old``, ``new``;
    layout ``OWNER__NAME/NN-SHA/SIDE``): of each side, the entry points of its backups
    (:func:`entries_of`), then its programs outside a backup (:func:`loose_programs`)."""
    out = []
    for side in sides:
        for folder in sorted(history.glob(f"*/*/{side}")):
            if not folder.is_dir():
                continue
            out += [p for root in find_backups(folder) for p in entries_of(root)]
            out += loose_programs(folder)
    return out


def normalise(text: str) -> str:
    t = re.sub(r"-?\d+(\.\d+)?", "N", text or "")
    t = re.sub(r"/\S+", "PATH", t)
    return t[:90]


def submit_of(path: Path) -> list[Path]:
    """The backup's SPS.SUB (krl.project.boot_submit), started beside the program as
    the controller does at boot (reference §9); empty outside a backup, and for the SPS.SUB
    itself run as the entry point."""
    sub = boot_submit(path)
    if sub is not None and Path(sub).resolve() == Path(path).resolve():
        return []
    return [sub] if sub is not None else []


def step_limit(max_steps: int, max_sim_time: float, n_submits: int, ipo_cycle_s: float) -> int:
    """The step limit of a run: `max_steps` of the robot program. Since issue 59 the limit counts
    the robot interpreter's steps only (docs/architecture.md "The step limit"): a submit program
    is an endless cyclic loop by design (reference §9), bounded per IPO cycle by its time slice,
    so its steps are bounded by the time limit. Until then the steps of every task counted and
    this added what `n_submits` submit programs may execute within `max_sim_time` s (at
    ``SUBMIT_BUDGET`` per IPO cycle of `ipo_cycle_s` s); the arguments are kept for the callers
    that measure against an older checkout (tools/whole_run_bench.py)."""
    return max_steps


def time_limit(path: Path, cell, default: float) -> float:
    """The simulated-time limit (s) of a run of `path`: `default`, or the longer time its cell
    file (a path or a Cell: interp.run.cell_of) says the program needs (``sim_time``,
    robot/stimuli.py)."""
    if cell is None:
        return default
    return max(default, cell_file(cell).sim_time.get(path.stem.upper(), 0.0))


def report_run(path: Path, cell: Path | None, max_sim_time: float = REPORT_SIM_TIME_S,
               max_steps: int = REPORT_STEPS, auto: bool = False, auto_sim_time: float | None = None) -> tuple:
    """``(robot, submit programs, simulated-time limit s, step limit)`` of the report's run of
    `path` with its cell file (a path or a Cell: interp.run.cell_of), or with ``--inputs auto``
    (`auto`; this report and the conformance report's real programs): the cell's robot, else
    the backup's own, else (auto) the library robot that reaches the backup's points, else the
    KR 6 R900 (interp.run.robot_for); the backup's SPS.SUB (none for the SPS.SUB itself: it
    runs as the program, at a submit interpreter's pace); :func:`time_limit` (auto: the longer
    `auto_sim_time`, default :data:`AUTO_SIM_TIME_S`, for a robot program) and :func:`step_limit`
    (the robot program's `max_steps`)."""
    cell = None if auto else cell_file(cell)
    robot = robot_for(path, inputs="auto" if auto else cell)
    submit = submit_of(path)
    sub = path.suffix.lower() == ".sub"
    if auto:
        t = max_sim_time if sub else max(max_sim_time, AUTO_SIM_TIME_S if auto_sim_time is None else auto_sim_time)
    else:
        t = time_limit(path, cell, max_sim_time)
    return robot, submit, t, step_limit(max_steps, t, len(submit) + sub, robot.ipo_cycle_s)


#: the kinds of motion event a row counts (:func:`motion_event_kind`), from the controller's
#: messages (robot/errors.py, robot/kinematics.py, robot/planner.py, robot/controller.py)
MOTION_EVENT_KINDS = ("reach", "limit", "singularity", "motion")
_MOTION_EVENT_WORDS = (("reach", ("target not reachable", "workspace error")),
                       ("limit", ("software limit switch",)),
                       ("singularity", ("singularity",)))
#: motion events a row lists (all are counted), and program-number requests it keeps the times of
MAX_ROW_EVENTS = 100
MAX_ROW_REQUESTS = 1000


def motion_event_kind(text: str) -> str:
    """The kind (:data:`MOTION_EVENT_KINDS`) of a motion error, from the controller's message:
    ``reach`` a workspace error (no axis configuration reaches the target, robot/errors.py
    WorkspaceError), ``limit`` a software limit switch (SoftLimitError), ``singularity`` a CP
    path through a wrist singularity (robot/planner.py, or an axis past its speed limit on the
    path, robot/controller.py), ``motion`` any other."""
    low = (text or "").lower()
    for kind, words in _MOTION_EVENT_WORDS:
        if any(w in low for w in words):
            return kind
    return "motion"


class RunEvents:
    """The controller's events a row keeps (the part of robot.trace.TraceWriter the controller
    calls; nothing is written anywhere): the motions started, every motion error (``{t, kind,
    text, file, line}``: the motion statement's place, from its ``motion`` start event) and the
    times P00's program-number request output rose (`request`: ``(signal, active value)``, set
    before the run; KUKA's P00 writes ``$OUT[PGNO_REQ]``, TRUE when PGNO_REQ > 0, FALSE on
    ``$OUT[-PGNO_REQ]`` when it is negative)."""

    def __init__(self) -> None:
        self.inner = None
        self.request: tuple[str, bool] | None = None
        self.motions = 0
        self.errors: list[dict] = []
        self.counts: Counter = Counter()
        self.requests: list[float] = []
        #: the motions started before each kept request (a handshake interval in which none
        #: started is no production cycle: audit/report.py ``_cycle``)
        self.request_motions: list[int] = []
        self.n_requests = 0
        self._where: dict[int, tuple] = {}
        self._out: dict[str, object] = {}

    def write(self, kind: str, t: float, **fields) -> None:
        if kind == "motion" and fields.get("phase") == "start":
            self.motions += 1
            self._where[fields.get("id")] = (fields.get("file"), fields.get("line"))
        elif kind == "error":
            self.add(t, str(fields.get("text") or ""), *self._where.get(fields.get("id"), (None, fields.get("line"))))
        elif kind == "io" and self.request is not None and fields.get("signal") == self.request[0]:
            value, before = fields.get("value"), self._out.get(self.request[0])
            self._out[self.request[0]] = value
            if value == self.request[1] and before != value:
                self.n_requests += 1
                if len(self.requests) < MAX_ROW_REQUESTS:
                    self.requests.append(round(t, 3))
                    self.request_motions.append(self.motions)

    #: no pose events, no motion end points (robot/trace.py TraceWriter.takes_poses, takes_motion_points)
    takes_poses = False
    takes_motion_points = False

    def add(self, t: float, text: str, file, line) -> None:
        kind = motion_event_kind(text)
        self.counts[kind] += 1
        if len(self.errors) < MAX_ROW_EVENTS:
            self.errors.append({"t": round(t, 3), "kind": kind, "text": text, "file": file, "line": line})


def _request_signal(rt, path: Path) -> tuple[str, bool] | None:
    """P00's program-number request output as the program sees ``PGNO_REQ`` ($config.dat):
    ``($OUT[n], active value)``, None when it is 0 or not declared."""

    req = global_value(rt, path.stem, "PGNO_REQ")
    if not isinstance(req, int) or isinstance(req, bool) or req == 0:
        return None
    return f"$OUT[{abs(req)}]", req > 0


#: the words of a run-time error's message: the names it mentions
_WORD = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]*")


def outside_stops(rt) -> list[str]:
    """The run-time errors of the run `rt` (its robot program's, its submit programs') that
    stop on a name the checker classifies outside the program and calls KUKA's
    (krl/semantics/outside.py ``Unresolved.classify``: W101/W105/W106/W107, ``Outside.kuka``),
    as ``NAME at file:line: why``: an error about such a name (its ``name``: "unknown name X",
    "routine X not found", "X is not an array"), or, for an error that carries no name ("value
    invalid: X[2]"), whose message holds it as a word; or on the value a stand-in of such a
    name reads (``#NOT_INSTALLED`` in the message: a stand-in of an unknown type used where
    another type is needed), as ``a stand-in's value at file:line: message``. Issues 46 and 59: the
    run stands in for every such name (interp/runtime/kss.py), so this is always empty unless
    the checker and the run disagree."""
    unresolved = rt.program.ws.unresolved()
    outside = unresolved.classify() if unresolved is not None else {}
    by_name: dict = {}
    for (_kind, key), o in outside.items():
        if o.kuka:
            by_name.setdefault(key, o)
    errors = []
    if rt.result is not None and rt.result.reason == "error" and rt.result.error is not None:
        errors.append((rt.result.error, rt.result.file, rt.result.line))
    for task in rt.scheduler.tasks:
        reason, err = task.outcome or (None, None)
        if task.kind == "submit" and reason == "error" and err is not None:
            errors.append((err, err.file or task.file, err.line or task.line))
    out = []
    for err, file, line in errors:
        if f"#{NOT_INSTALLED}" in (err.message or ""):
            # the literal only a stand-in of installed software reads (interp/runtime/kss.py):
            # the stop is on its value, whatever name it came from
            out.append(f"a stand-in's value at {file}:{line}: {err.message}")
            continue
        words = [err.name] if getattr(err, "name", None) else _WORD.findall(err.message or "")
        for word in dict.fromkeys(w.upper() for w in words):
            o = by_name.get(word)
            if o is not None:
                out.append(f"{o.name} at {file}:{line}: {o.why}")
    return out


def run_one(path: Path, max_sim_time: float, max_steps: int, cell: Path | None = None,
            auto: bool = False, interp: str = "tree", auto_sim_time: float | None = None) -> dict:
    """One run of the report (module docstring): with the cell file `cell` (a path or a Cell:
    interp.run.cell_of), or with ``--inputs auto`` (`auto`; then `cell` is not used), on the
    interpreter `interp`. The row holds how it ended, its cause, the stand-ins of KUKA's
    software (``stubs``, name -> uses), the cell's answers (``cell_answers``, ``cell_last`` s;
    ``answers``: the automatic cell's, described), the idle time skipped, the stops on a
    name the checker classifies outside the program (``outside_stops``, :func:`outside_stops`),
    and what the controller saw (:class:`RunEvents`): ``motions`` started, the motion errors
    (``events``, at most :data:`MAX_ROW_EVENTS`; ``event_counts`` by kind, every one) and the
    times (s) P00 asked the PLC for a program number (``requests``, at most
    :data:`MAX_ROW_REQUESTS`; ``requests_total``; ``request_motions``: the motions started
    before each of them).
    `auto_sim_time`: the time limit of an ``--inputs auto`` run of a robot program (default
    :data:`AUTO_SIM_TIME_S`; a bounded sweep gives less, ``krl audit --max-sim-time``)."""
    t0 = time.time()
    shown = None if auto else cell
    events = RunEvents()
    try:
        cell = None if auto else cell_file(cell)   # the cell file, read once for the robot, the limits and the run
        inputs = "auto" if auto else cell
        robot, submit, max_sim_time, limit = report_run(path, cell, max_sim_time, max_steps, auto,
                                                        auto_sim_time)
        own = _own_machine_data(path, robot.source)
        # --no-check: the report says how each real program runs, also those the checker rejects
        # (an SPS.SUB entry runs at the submit interpreter's pace: scheduler.program_budget)
        rt, _ = make_runtime(run_spec(path, mujoco=False, max_sim_time=max_sim_time, max_steps=limit,
                                      submit=submit, check=False, inputs=inputs, robot=robot, interp=interp),
                             RunSinks(observer=events))
        events.request = _request_signal(rt, path)
        res = rt.run()
        stubs = {name: n for name, _what, n in rt.kss.summary()}
        stops = outside_stops(rt)
        rules = rt.controller.signals.rules
        fired = [r.last_fired for r in rules if r.last_fired is not None]
        answers = rt.autocell.answers if rt.autocell is not None else []
        fired += [a.t for a in answers]
    except Exception as exc:  # noqa: BLE001 - an internal error is a bug to report
        row = {"program": str(path), "mode": "auto" if auto else "cells", "reason": "internal",
               "text": f"{type(exc).__name__}: {exc}",
               "seconds": round(time.time() - t0, 2), "cell": str(shown) if shown else None}
        row["cause"] = cause_of(row)
        return row
    row = {"program": str(path), "mode": "auto" if auto else "cells", "interp": interp,
           "reason": res.reason, "text": res.text,
           "number": res.error.number if res.error is not None else None,
           "file": res.file, "line": res.line, "sim_time": round(res.sim_time, 3),
           "steps": res.steps, "stubs": stubs, "submit": submit_errors(rt),
           "seconds": round(time.time() - t0, 2),
           "cell": str(shown) if shown else None,
           "cell_answers": sum(r.fired for r in rules) + len(answers),
           "cell_last": round(max(fired), 3) if fired else None,
           "answers": [a.describe() for a in answers],
           "idle_s": round(rt.ff.idle.skipped * rt.controller.dt, 3),
           "robot": robot.name, "robot_own": own, "outside_stops": stops}
    if res.reason == "error" and motion_event_kind(res.text) != "motion" \
            and not any(e["text"] and e["text"] in (res.text or "") for e in events.errors):
        # a target the planner refuses in the advance run ends the program without a main-run
        # error event: it is the run's motion event all the same
        events.add(res.sim_time, res.text or "", res.file, res.line)
    row.update(motions=events.motions, events=events.errors,
               event_counts={k: events.counts[k] for k in MOTION_EVENT_KINDS if events.counts[k]},
               requests=events.requests, request_motions=events.request_motions,
               requests_total=events.n_requests)
    row["cause"] = cause_of(row)
    return row


def submit_errors(rt) -> list[str]:
    """The run-time errors that stopped the run's submit programs, ``NAME: message at
    file:line`` each (the robot program runs on; the run summary shows them the same way)."""
    out = []
    for task in rt.scheduler.tasks:
        reason, err = task.outcome or (None, None)
        if task.kind == "submit" and reason == "error" and err is not None:
            out.append(f"{task.name}: {err.message} at {err.file or task.file}:{err.line or task.line}")
    return out


def causes(rows: list[dict]) -> Counter:
    """Programs by cause, in :data:`CAUSES` order."""
    by = Counter(r.get("cause") or cause_of(r) for r in rows)
    return Counter({k: by[k] for k in CAUSES if by[k]})


def report_columns(rows: list[dict]) -> str:
    """The two columns side by side (issue 34): each program's cause with its committed cell
    file and with ``--inputs auto``, and the totals of each column."""
    by_prog: dict[str, dict] = {}
    for r in rows:
        by_prog.setdefault(r["program"], {})[r.get("mode", "cells")] = r
    cols = [c for c in ("cells", "auto") if any(c in v for v in by_prog.values())]
    head = {"cells": "with corpus/cells", "auto": "with --inputs auto"}
    out = []
    for c in cols:
        sub = [v[c] for v in by_prog.values() if c in v]
        by = causes(sub)
        out.append(f"{head[c]}: {len(sub)} programs: " + ", ".join(f"{k} {v}" for k, v in by.items())
                   + f"; completed or intended end {by['completed'] + by['intended end']}")
    out.append("")
    out.append(f"  {'program':34s} " + " ".join(f"{head[c]:44s}" for c in cols))
    for prog, v in by_prog.items():
        cells = []
        for c in cols:
            r = v.get(c)
            if r is None:
                cells.append(f"{'-':44s}")
                continue
            where = f"{Path(r['file']).name}:{r['line']}" if r.get("file") and r.get("line") else ""
            cells.append(f"{(r.get('cause') or cause_of(r)):15s} {where[:28]:28s}")
        out.append(f"  {Path(prog).name[:34]:34s} " + " ".join(cells))
    return "\n".join(out)


def report(rows: list[dict]) -> str:
    n = len(rows)
    by_cause = causes(rows)
    head = [f"{n} programs by cause: " + ", ".join(f"{k} {v}" for k, v in by_cause.items()),
            f"  completed or intended end: {by_cause['completed'] + by_cause['intended end']}"]
    by = Counter(r["reason"] for r in rows)
    ok = by["completed"]
    legit = sum(by[k] for k in LEGITIMATE)
    waits = sum(1 for r in rows if r["reason"] in ("max_sim_time", "max_steps") and "waits: WAIT FOR" in r["text"])
    lines = [f"{n} programs: {ok} completed, {legit} legitimate stops "
             f"({', '.join(f'{k} {by[k]}' for k in LEGITIMATE if by[k])}), "
             f"{by['error']} errors, {by['internal']} internal errors",
             f"  ({waits} of the limit stops wait in WAIT FOR for an input that no stimulus sets; "
             f"the others loop, e.g. re-issuing a message while the cell inputs are absent)", ""]
    lines = head + [""] + lines
    lines.append("By program (cause, where):")
    for r in rows:
        where = f"{Path(r['file']).name}:{r['line']}" if r.get("file") and r.get("line") else ""
        lines.append(f"  {r.get('cause') or cause_of(r):15s} {Path(r['program']).name:28s} {where:26s} "
                     f"{(r.get('text') or '')[:70]}")
    lines.append("")
    errs = Counter(normalise(r["text"]) for r in rows if r["reason"] in ("error", "internal"))
    if errs:
        lines.append("Failures by message:")
        for msg, c in errs.most_common():
            lines.append(f"  {c:4d}  {msg}")
    subs = Counter(normalise(s.split(": ", 1)[-1]) for r in rows for s in r.get("submit", []))
    n_sub = sum(1 for r in rows if r.get("submit"))
    lines.append("")
    lines.append(f"Submit-interpreter errors: {n_sub} of {n} runs" + (":" if subs else ""))
    for msg, c in subs.most_common():
        lines.append(f"  {c:4d}  {msg}")
    stubs: Counter = Counter()
    runs: Counter = Counter()
    for r in rows:
        for s, c in (r.get("stubs") or {}).items():
            stubs[s] += c
            runs[s] += 1
    if stubs:
        lines.append("")
        lines.append("Stand-ins of KUKA's software the backups lack (uses, in how many runs; "
                     "interp/runtime/kss.py): " + ", ".join(f"{s} ({c} in {runs[s]})" for s, c in stubs.most_common()))
    stops = [s for r in rows for s in r.get("outside_stops") or ()]
    lines.append("")
    lines.append(f"Stops on a name the checker classifies outside the program (issue 46): {len(stops)}"
                 + (":" if stops else ""))
    lines += [f"  {s}" for s in stops]
    answers = sum(len(r.get("answers") or ()) for r in rows)
    if any(r.get("mode") == "auto" for r in rows):
        lines.append("")
        lines.append(f"Answers of --inputs auto: {answers} in {sum(1 for r in rows if r.get('answers'))} runs; "
                     f"idle time fast-forwarded: {sum(r.get('idle_s') or 0 for r in rows):.1f} s")
    return "\n".join(lines)


def run_rows(corpus: Path, max_sim_time: float = REPORT_SIM_TIME_S, max_steps: int = REPORT_STEPS, *,
             cells: bool = True, limit: int = 0, columns: tuple[str, ...] = ("cells",), interp: str = "tree",
             scheduler: str | None = None, jobs: int = 1, progress=None,
             history: tuple[str, ...] = ()) -> list[dict]:
    """The report's rows: :func:`run_one` of each entry point of the backups below `corpus`
    (:func:`entries_of`; at most `limit` of them, 0: all), in the corpus's order, once per
    column of `columns` ("cells": with its committed cell file unless `cells` is False;
    "auto": with ``--inputs auto``), on `interp`. `scheduler`: the address of a Dask scheduler
    (``tcp://HOST:8786``) whose workers make the runs (krl/cluster.py; they read the corpus at
    the same paths); the rows are the same as here, ``seconds`` aside. Without a scheduler,
    `jobs` > 1 runs them in that many worker processes of this machine (krl/pool.py: each run is
    independent, so the rows are the same as one after the other, ``seconds`` aside).
    `progress(column, row)` is called as each row arrives (in completion order when the runs
    are parallel; the rows returned are always in the corpus's order). `history`: `corpus` is
    ../shared/krl-history, and the programs are those of its pair sides `history`
    (:func:`history_entries`). Raises krl.cluster.SchedulerError when the scheduler cannot be
    used."""
    if history:
        programs = history_entries(corpus, history)
    else:
        programs = [p for root in find_backups(corpus) for p in entries_of(root)]
    if limit:
        programs = programs[:limit]
    tasks = []
    for p in programs:
        for col in columns:
            cell = None if not cells or col == "auto" else cell_of(p, corpus)
            tasks.append((len(tasks), (p, max_sim_time, max_steps, cell, col == "auto", interp)))
    if scheduler is None and jobs <= 1:
        rows = []
        for _i, args in tasks:
            rows.append(run_one(*args))
            if progress:
                progress("auto" if args[4] else "cells", rows[-1])
        return rows
    if scheduler is None:

        # a backup's programs in one worker after the other: it loads the backup once
        outcomes = run_tasks(run_one, tasks, jobs=jobs, timeout=None, group=lambda k: loaded_with(tasks[k][1][0]))
    else:

        outcomes = run_batches(scheduler, run_one, tasks, batch_files=1, name="krl-realprograms")
    got: dict[int, dict] = {}
    for o in outcomes:
        path, _t, _s, cell, auto, _interp = tasks[o.key][1]
        if o.status == "done":
            row = o.value
        else:           # the worker failed (not the program): said as run_one says an internal error
            row = {"program": str(path), "reason": "internal", "text": o.detail, "seconds": 0.0,
                   "cell": str(cell) if cell else None, "mode": "auto" if auto else "cells"}
            row["cause"] = cause_of(row)
        got[o.key] = row
        if progress:
            progress("auto" if auto else "cells", row)
    return [got[i] for i in range(len(tasks))]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("corpus", nargs="?", default=str(DEFAULT_CORPUS))
    ap.add_argument("--json", default=None, help="write one JSON object per program")
    ap.add_argument("--limit", type=int, default=0)
    ap.add_argument("--max-sim-time", type=float, default=REPORT_SIM_TIME_S)
    ap.add_argument("--max-steps", type=int, default=REPORT_STEPS)
    ap.add_argument("--no-cells", action="store_true", help="run the cells column without the committed cell files")
    ap.add_argument("--columns", default="cells,auto",
                    help="which runs: cells (the committed cell files), auto (--inputs auto), or both (default)")
    ap.add_argument("--interp", choices=("tree", "vm"), default="vm",
                    help="the interpreter of the runs (default vm: the same causes, less CPU)")
    ap.add_argument("--jobs", type=int, default=None, metavar="N",
                    help="worker processes of this machine (default: one per core; 1: one run after "
                         "the other in this process); the same report")
    ap.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                    help="make the runs on this Dask distributed scheduler's cluster (its workers "
                         "see the corpus at the same paths); the same report as the local run")
    ap.add_argument("--history", default=None, choices=("new", "old", "both"),
                    help="CORPUS is ../shared/krl-history: run the programs of each pair's new "
                         "(old, both) side, its backups' entry points and its programs outside a backup")
    a = ap.parse_args(argv)
    corpus = Path(a.corpus)
    history = {"new": ("new",), "old": ("old",), "both": ("old", "new"), None: ()}[a.history]
    cols = [c.strip() for c in a.columns.split(",") if c.strip()]
    if not cols or any(c not in ("cells", "auto") for c in cols):
        ap.error("--columns takes cells, auto or cells,auto")
    if a.jobs is not None and a.jobs < 1:
        ap.error("--jobs takes a number of worker processes, 1 or more")
    if not corpus.is_dir():
        print(f"no corpus at {corpus}; nothing to do")
        return 0

    def progress(col: str, r: dict) -> None:
        sub = f"  [submit: {r['submit'][0][:60]}]" if r.get("submit") else ""
        shown = Path(r["program"])
        shown = shown.relative_to(corpus) if shown.is_relative_to(corpus) else shown
        print(f"{col:5s} {r['cause']:15s} {r['reason']:13s} {r.get('seconds', 0):6.1f}s "
              f"{shown}  {r['text'][:80]}{sub}", file=sys.stderr)

    try:
        rows = run_rows(corpus, a.max_sim_time, a.max_steps, cells=not a.no_cells, limit=a.limit,
                        columns=tuple(cols), interp=a.interp, scheduler=a.scheduler,
                        jobs=a.jobs if a.jobs is not None else default_jobs(), progress=progress,
                        history=history)
    except SchedulerError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if a.json:
        write_text(a.json, "".join(json.dumps(r) + "\n" for r in rows))
    if len(cols) > 1:
        print(report_columns(rows))
        print()
    for col in cols:
        if len(cols) > 1:
            print(f"== {col}")
        print(report([r for r in rows if r.get("mode") == col]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
