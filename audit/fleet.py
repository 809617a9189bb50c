"""``krl audit FOLDER...``: every KRC backup and program folder of the folders, checked and run,
in one report (issue 49). The job, from the folders to the report's data; docs/audit.md says
what each field means.

1. **List** (on the client, :func:`units_of`): the one walk of each folder that ``krl check``
   makes (krl.project.folder_groups: links never followed, MAX_FOLDER_DEPTH): one *unit* per
   KRC backup (a controller archive's ``KRC``: its ``C`` and ``Log Files`` are no unit, rule 8),
   then one per top-level folder of the files outside every backup (a *program folder*). A
   controller archive ``.zip``, and each ``.zip`` of a folder of them, is extracted for the
   audit (krl/backups.py ``opened``, with its event logs and manifest) and gives its units the
   same way, named as the user sees them (``fleet/cell_a.zip/KRC``); an archive refused is a
   unit with an ``error``. At most :data:`krl.limits.MAX_AUDIT_BACKUPS` units, else
   :class:`AuditError`.
2. **Check** (a task per unit, :func:`check_unit`): the unit loaded and checked as
   ``krl check`` does (krl.workspace.load_workspaces through the one store, the workspace's
   ``krl.toml``), its program map (krl.programmap.build_map: the entry kind of each
   program), the outputs its code writes and their overlaps (audit/outputs.py), and its entry
   points: in a backup the real-programs report's (interp.realprograms.entries_of: the
   programs under R1/Program, cell.src, the SPS.SUB), in a program folder every module whose
   main routine is a DEF without parameters and every .sub (interp.realprograms
   .folder_entries), both among the files of the walk; at most MAX_AUDIT_ENTRIES per unit.
3. **Run** (a task per entry point): interp.realprograms.run_one with ``--inputs auto`` (the
   automatic cell answers every wait, P00's handshake included), on the VM, up to
   `max_sim_time` simulated seconds (an SPS.SUB entry at most the real-programs report's
   60 s: a submit program never ends) and `max_steps` statements of the program's own; how
   it ends (cause, reason, file:line), the motion errors the controller raised and the times
   P00 asked for a program number.
4. **Report** (on the client, audit/report.py): the rows in the folders' order, whatever
   order the tasks finished in, so the report is the same with any number of workers, on this
   machine (krl.pool: killable worker processes, ``jobs``) or on a Dask cluster (krl.cluster,
   ``scheduler``).

A unit whose check fails (a worker that dies, a check past its time) is a unit with an
``error``; a run that fails is a row whose reason says so: the audit never stops on one backup.
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path

from krl.limits import AUDIT_RUN_TIMEOUT_S, MAX_AUDIT_BACKUPS, MAX_AUDIT_ENTRIES, MAX_AUDIT_FINDINGS, PARSE_TIMEOUT_S
from krl.terminal import printable
from krl.archive import ArchiveError, Shown
from krl.backups import BackupsError, Opened, opened, programs_in
from krl.logbook.record import ARCHIVE_FILES
from krl.project import system_folder
from krl.parsecache import through_store
from krl.programmap import build_map
from krl.semantics.config import config_for
from krl.workspace import load_workspaces, machine_identity
from audit.outputs import overlaps
from audit.report import rel_path as _rel, report_data
from interp.realprograms import entries_of, folder_entries, REPORT_SIM_TIME_S, run_one
from krl.pool import run_tasks
from krl.cluster import run_batches, SchedulerError
from interp import realprograms as R
from interp import run as _loaded  # noqa: F401  (forked workers start with the runtime imported)

__all__ = ["AuditError", "Unit", "units_of", "check_unit", "run_entry", "run_audit"]


class AuditError(Exception):
    """The folders cannot be audited (not a folder, more units than MAX_AUDIT_BACKUPS, a
    scheduler that cannot be used): a usage error whose message names the folder or the limit."""


@dataclass
class Unit:
    """A KRC backup (`backup`) or a program folder: its `root` (as walked from the folder the
    user named, `folder`), and its entries in the walk (krl.files.Entry)."""

    root: str
    folder: str
    entries: list
    backup: bool
    shown: Shown = field(default_factory=Shown)
    error: str = ""

    @property
    def name(self) -> str:
        """The unit's path relative to the folder the user named; when the folder named is the
        unit, its own name with its parent's (``depalletizer/KRC``: a backup's folder is often
        just ``KRC``, issue 63)."""
        try:
            rel = Path(self.shown(self.root)).relative_to(self.folder).as_posix()
        except ValueError:
            rel = ""
        if rel and rel != ".":
            return rel
        parts = Path(self.folder).absolute().parts
        parts = Path(*parts).resolve().parts if parts[-1] in (".", "..") else parts
        return "/".join(p for p in parts[-2:] if p != "/") or self.folder


def units_of(folders: list[str], parts: dict[str, list[Opened]] | None = None) -> list[Unit]:
    """The units of `folders` (module docstring, step 1), in the folders' order; a root named
    twice is audited once. `parts`: each folder's parts (krl/backups.py ``opened``: its archives
    extracted), default the folder itself. Raises AuditError."""
    out: list[Unit] = []
    seen: set[str] = set()
    for folder in folders:
        own = (parts or {}).get(folder) or [Opened(Path(folder), Shown(), folder)]
        if not any(p.error or p.folder.is_dir() for p in own):
            raise AuditError(f"{printable(folder)}: not a folder (krl audit takes folders of KRC backups "
                             f"and KRL programs, controller archives and folders of them)")
        refused = [Unit(p.source, folder, [], False, error=f"not read: {p.error}") for p in own if p.error]
        progs = programs_in(own)
        if not refused and not progs:      # nothing audited is no audit passed (issue 85)
            raise AuditError(f"{printable(folder)}: no KRC backup, controller archive or KRL program in it")
        for part, root, entries in [*((u, None, None) for u in refused), *progs]:
            unit = part if isinstance(part, Unit) else None
            if unit is None:
                key = str(Path(part.shown(root)).resolve()) if part.archive else str(Path(root).resolve())
                if key in seen:
                    continue
                seen.add(key)
                unit = Unit(root, folder, entries, system_folder(Path(root)) is not None, part.shown)
            out.append(unit)
            if len(out) > MAX_AUDIT_BACKUPS:
                raise AuditError(f"more than {MAX_AUDIT_BACKUPS} backups and program folders below "
                                 f"{', '.join(printable(f) for f in folders)} (limit MAX_AUDIT_BACKUPS, "
                                 f"docs/security.md): audit fewer folders at a time")
    return out


def check_unit(root: str, entries: list, backup: bool) -> dict:
    """On a worker: the static half of a unit (module docstring, step 2) as a JSON-ready dict:
    ``files``, ``errors``, ``warnings``, ``codes`` (code -> count), ``findings`` (errors first,
    at most MAX_AUDIT_FINDINGS: code, severity, message, file relative to `root`, line,
    column), ``findings_left_out``, ``programs`` (``{path, kind, why}``: each entry point with
    the program map's entry kind), ``programs_left_out``, ``outputs`` (audit/outputs.py).
    The files are parsed in this process (a Dask worker may not start the killable pool; the
    caller's timeout bounds the task)."""

    with through_store():
        ws = load_workspaces([(root, entries)], None)[0]
    diags = config_for(ws.root, root).apply(ws.check(resolve=False))   # the runs load their own
    errors = [d for d in diags if d.is_error]
    warnings = [d for d in diags if not d.is_error]
    codes: dict[str, int] = {}
    for d in diags:
        codes[d.code] = codes.get(d.code, 0) + 1
    shown = (errors + warnings)[:MAX_AUDIT_FINDINGS]
    pm = build_map(ws)
    kinds = {str(Path(n.path)): (n.entry_kind, n.entry) for n in pm.nodes.values() if n.main and n.path}
    files = [e.path for e in entries if e.kind == "file"]
    progs, handlers = _not_handlers(entries_of(Path(root), files) if backup else folder_entries(files), pm, root)
    rep = overlaps(ws, pm)
    names = {nid: pm.nodes[nid].name for nid in pm.nodes}

    def write(w) -> dict:
        return {"file": _rel(w.path, root), "line": w.line, "module": w.module, "name": w.name, "how": w.how,
                "system": w.kuka, "tasks": rep.tasks.get(w.routine, []),
                "reached_by": [names[e] for e in rep.reached_by.get(w.routine, [])]}

    return {
        "files": len(ws.files), "errors": len(errors), "warnings": len(warnings),
        "codes": dict(sorted(codes.items())),
        "findings": [{"code": d.code, "severity": d.severity, "message": d.message, "file": _rel(d.path, root),
                      "line": d.line, "column": d.column} for d in shown],
        "findings_left_out": len(diags) - len(shown),
        "programs": [{"path": str(p), "kind": kinds.get(str(Path(p)), ("", ""))[0],
                      "why": kinds.get(str(Path(p)), ("", ""))[1]} for p in progs[:MAX_AUDIT_ENTRIES]],
        "programs_left_out": max(0, len(progs) - MAX_AUDIT_ENTRIES),
        "handlers": handlers,
        # the programs the cell program's SWITCH selects (the map's "plc" entries): its cycle
        # is a production cycle only when it selects one (issue 63)
        "cell_selects": sorted({n.name for n in pm.nodes.values() if n.entry_kind == "plc"}, key=str.upper),
        "machine": machine_identity(ws.files),
        "outputs": {
            "writes": len(rep.writes), "computed": len(rep.computed), "plc_map": len(rep.plc_map),
            "overlaps": [{"signal": o.signal, "signals": o.signals, "flags": o.flags, "tasks": o.tasks,
                          "plc": [{"name": x.name, "signal": x.signal, "file": _rel(x.path, root), "line": x.line}
                                  for x in o.plc],
                          "writes": [write(w) for w in o.writes]} for o in rep.overlaps],
        },
    }


def _not_handlers(progs: list, pm, root: str) -> tuple[list, list[dict]]:
    """(the programs of `progs` to run, the interrupt and trigger routines among them): a module
    whose main routine an ``INTERRUPT DECL ... DO`` or a ``TRIGGER ... DO`` of the map `pm`
    calls is an interrupt routine, run by the program that declares it when its condition
    fires, never on its own (issue 63: run alone, such routines were counted as program
    errors); each with ``{path, why}``."""

    called: dict[str, object] = {}
    for e in pm.edges:
        if e.kind in ("interrupt", "trigger"):
            called.setdefault(e.target, e)
    mains = {str(Path(n.path)): n for n in pm.nodes.values() if n.main and n.path and n.kind == "routine"}
    keep, handlers = [], []
    for p in progs:
        n = mains.get(str(Path(p)))
        e = called.get(n.id) if n is not None else None
        if e is None:
            keep.append(p)
            continue
        how = "an interrupt routine" if e.kind == "interrupt" else "a trigger's routine"
        what = "INTERRUPT DECL ... DO" if e.kind == "interrupt" else "TRIGGER WHEN ... DO"
        handlers.append({"path": str(p), "why": f"{how}: {pm.nodes[e.source].name} calls it by {what} at "
                                                f"{_rel(e.path, root)}:{e.line}"})
    return keep, handlers


def run_entry(path: str, max_sim_time: float, max_steps: int, interp: str) -> dict:
    """On a worker: one entry point run with ``--inputs auto`` (interp.realprograms.run_one) up
    to `max_sim_time` simulated seconds; an SPS.SUB entry at most the real-programs report's
    REPORT_SIM_TIME_S (a submit program never ends: its cycle is what the report shows)."""

    return run_one(Path(path), min(max_sim_time, REPORT_SIM_TIME_S), max_steps, None, True, interp,
                   auto_sim_time=max_sim_time)


def _outcomes(fn: Callable, tasks: list, *, jobs: int | None, scheduler: str | None, timeout: float | None,
              name: str, group: Callable | None = None):
    """The outcomes (krl.pool.Outcome) of `fn` over `tasks` (``(key, args)``), in completion
    order: in `jobs` killable worker processes (krl.pool.run_tasks, each task at most
    `timeout` s of wall time; `group`: its ``group``, the unit of a run, so that a worker runs
    one unit's entry points after the other and loads each unit once), or on the Dask cluster
    at `scheduler` (krl.cluster.run_batches, one task per batch). Raises
    krl.cluster.SchedulerError."""
    if scheduler is not None:

        return run_batches(scheduler, fn, tasks, batch_files=1, timeout=timeout, name=name)

    return run_tasks(fn, tasks, jobs=jobs, timeout=timeout, group=group)


def run_audit(folders: list[str], *, jobs: int | None = None, scheduler: str | None = None,
              max_sim_time: float | None = None, max_steps: int | None = None, interp: str = "vm",
              run_timeout: float = AUDIT_RUN_TIMEOUT_S, progress: Callable[[str, int, int, str], None] | None = None
              ) -> dict:
    """The audit of `folders` (module docstring) as the report's data (audit/report.py
    :func:`~audit.report.report_data`). `max_sim_time`: simulated seconds per entry point
    (default interp.realprograms.AUTO_SIM_TIME_S, ``krl run``'s 600 s); `max_steps`:
    statements of the program's own (default REPORT_STEPS); `run_timeout`: wall seconds one
    run may take before its worker is killed. `progress(phase, done, total, label)` is called
    as the phases ("check", "run") advance. Raises AuditError (also for a scheduler that
    cannot be used)."""

    with ExitStack() as stack:
        try:
            parts = {f: stack.enter_context(opened(f, ARCHIVE_FILES)) for f in folders}
        except (ArchiveError, BackupsError) as exc:
            raise AuditError(str(exc)) from None
        return _audit(folders, units_of(folders, parts), jobs=jobs, scheduler=scheduler, max_sim_time=max_sim_time,
                      max_steps=max_steps, interp=interp, run_timeout=run_timeout, progress=progress)


def _audit(folders: list[str], units: list[Unit], *, jobs, scheduler, max_sim_time, max_steps, interp, run_timeout,
           progress) -> dict:
    """:func:`run_audit` of the listed `units` (their archives extracted while it runs)."""
    max_sim_time = R.AUTO_SIM_TIME_S if max_sim_time is None else max_sim_time
    max_steps = R.REPORT_STEPS if max_steps is None else max_steps
    say = progress or (lambda *_a: None)
    checked: list[dict | None] = [{"error": u.error} if u.error else None for u in units]
    tasks = [(i, (u.root, u.entries, u.backup)) for i, u in enumerate(units) if not u.error]
    # a unit's deadline: the per-file parse limit times its files (as krl check --scheduler)
    most = max((sum(e.kind == "file" for e in u.entries) for u in units), default=1)
    try:
        say("check", 0, len(tasks), "")
        for k, o in enumerate(_outcomes(check_unit, tasks, jobs=jobs, scheduler=scheduler,
                                        timeout=PARSE_TIMEOUT_S * max(most, 1), name="krl-audit-check"), 1):
            if o.status == "done":
                checked[o.key] = o.value
            else:
                why = f"took longer than {PARSE_TIMEOUT_S * max(most, 1):g} s" if o.status == "timeout" else o.detail
                checked[o.key] = {"error": f"not checked: {why}"}
            say("check", k, len(tasks), units[o.key].name)
        runs = [(i, p["path"]) for i, c in enumerate(checked) for p in c.get("programs", ())]
        rows: dict[int, dict] = {}
        say("run", 0, len(runs), "")
        run_tasks = [(k, (path, max_sim_time, max_steps, interp)) for k, (_i, path) in enumerate(runs)]
        for k, o in enumerate(_outcomes(run_entry, run_tasks, jobs=jobs, scheduler=scheduler, timeout=run_timeout,
                                        name="krl-audit-run", group=lambda key: runs[key][0]), 1):
            path = runs[o.key][1]
            if o.status == "done":
                rows[o.key] = o.value
            elif o.status == "timeout":
                rows[o.key] = {"program": path, "reason": "wall_time", "cause": "limit",
                               "text": f"stopped at the audit's wall-clock limit: the run took more than "
                                       f"{run_timeout:g} s (AUDIT_RUN_TIMEOUT_S, --run-timeout)"}
            else:
                rows[o.key] = {"program": path, "reason": "internal", "cause": "interpreter gap", "text": o.detail}
            say("run", k, len(runs), _rel(path, units[runs[o.key][0]].root))
    except SchedulerError as exc:
        raise AuditError(str(exc)) from None
    by_unit: list[list[dict]] = [[] for _ in units]
    for k, (i, _path) in enumerate(runs):
        by_unit[i].append(rows[k])
    settings = {"inputs": "auto", "interp": interp, "max_sim_time": max_sim_time, "max_steps": max_steps,
                "run_timeout": run_timeout}
    return report_data(folders, units, checked, by_unit, settings)
