"""How an entry point of a backup ends, run with nothing hand-written: the run outcomes of the
change report (``krl report NEW --since OLD``, issue 49).

:func:`run_outcome` runs one program (a module whose main routine is a ``DEF`` without
parameters, or a ``.sub`` submit program) on the VM with ``--inputs auto`` (the automatic cell,
interp/runtime/autocell.py: each input a starving wait needs is set 0.5 s after it starves,
the PLC of Automatic External answers, the robot starts at ``XHOME``), the backup's own robot
(interp.run.robot_for) and its SPS.SUB beside it (interp.realprograms.submit_of), within
``max_sim_time`` simulated seconds (default interp.realprograms.REPORT_SIM_TIME_S, 60 s) and
no step limit (the robot interpreter's time slice, scheduler.ROBOT_BUDGET statements per IPO
cycle, bounds the statements by the time limit: a loop ends at the time limit, and a program
ends at its own error when it has one within the time). It returns a plain dict (JSON-ready):

* ``reason`` (RunResult.reason: completed, halt, error, max_sim_time, max_steps, deadlock, or
  ``internal`` for an error of the simulator), ``ending`` (the words of ``krl run``'s summary,
  interp.summary.ENDINGS), ``cause`` (interp.realprograms.cause_of: completed, intended end,
  program error, interpreter gap, limit), ``text``, ``file``, ``line`` (where it ended: for a
  program that completed, its END) and ``statement`` (that line's text);
* ``sim_time`` (s) and ``cycle_time`` (s): the simulated time from the start to the program's
  own end -- it completed, or stopped at its own HALT -- else None (a cyclic program stopped at
  the time limit has no cycle end; with ``--inputs auto`` every starving wait counts its 0.5 s);
* ``motions``: the motions started; ``events``: every motion error of the run (a target the
  planner refuses in the advance run, which ends the program, among them), each ``{t,
  kind, text, line}`` with ``kind`` one of :data:`EVENT_KINDS` (from the controller's message:
  ``reach`` a target no axis configuration reaches (workspace error), ``limit`` a software
  limit switch, ``singularity`` a CP path through a wrist singularity, ``speed`` a speed limit
  exceeded, ``motion`` any other); ``counts`` of each kind.

:func:`run_outcomes` runs several in worker processes (krl.pool: a run that crashes the
interpreter or passes :data:`RUN_TIMEOUT_S` of wall time is an ``internal`` outcome of its
own). :func:`outcome_changes` says what differs between two outcomes of one entry point, and
:func:`ends_alike` whether they end the same way (the same reason, cause, message and statement).
"""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any
from interp.realprograms import REPORT_SIM_TIME_S, _own_machine_data, cause_of, submit_of
from interp.run import make_runtime, robot_for, run_spec, RunSinks
from interp.runtime.scheduler import SUBMIT_BUDGET
from interp.summary import ending_of
from krl.source import read_source
from krl.pool import run_tasks
from interp.realprograms import loaded_with

__all__ = ["EVENT_KINDS", "RUN_TIMEOUT_S", "CYCLE_TOLERANCE_S", "END_CHANGES", "run_outcome", "run_outcomes",
           "outcome_changes", "ends_alike"]

#: the kinds of motion event a run outcome counts (see the module docstring)
EVENT_KINDS = ("reach", "limit", "singularity", "speed", "motion")
#: the controller's message words of each kind (robot/planner.py, robot/controller.py)
_EVENT_WORDS = (("reach", ("target not reachable", "workspace")), ("limit", ("software limit switch",)),
                ("singularity", ("singularity",)), ("speed", ("speed limit",)))
#: wall seconds one run may take in a worker before it is stopped (an ``internal`` outcome)
RUN_TIMEOUT_S = 600.0
#: cycle times closer than this (s: one IPO cycle of 12 ms, rounded up) are the same
CYCLE_TOLERANCE_S = 0.012


class _Events:
    """The controller's trace events a run outcome needs (the part of robot.trace.TraceWriter
    the controller calls); nothing is written anywhere."""

    def __init__(self) -> None:
        self.inner = None
        self.motions = 0
        self.errors: list[dict] = []

    def write(self, kind: str, t: float, **fields: Any) -> None:
        if kind == "motion" and fields.get("phase") == "start":
            self.motions += 1
        elif kind == "error":
            self.errors.append({"t": round(t, 3), "text": str(fields.get("text") or ""), "line": fields.get("line")})

    #: no pose events, no motion end points (robot/trace.py TraceWriter.takes_poses, takes_motion_points)
    takes_poses = False
    takes_motion_points = False


def event_kind(text: str) -> str:
    """The kind (:data:`EVENT_KINDS`) of a motion error, from its message."""
    low = text.lower()
    for kind, words in _EVENT_WORDS:
        if any(w in low for w in words):
            return kind
    return "motion"


def run_outcome(path: str, max_sim_time: float | None = None, interp: str = "vm") -> dict:
    """The outcome of one run of the program `path` (see the module docstring). Never raises
    for the program: an error of the simulator is an outcome with reason ``internal``."""

    p = Path(path)
    limit_s = REPORT_SIM_TIME_S if max_sim_time is None else max_sim_time
    events = _Events()
    try:
        robot = robot_for(p, inputs="auto")
        submit = submit_of(p)
        sub = p.suffix.lower() == ".sub"
        # no step limit: the time limit ends a loop (the time slice, ROBOT_BUDGET statements per
        # IPO cycle, bounds its statements), so a run ends at its own error when it has one
        # within the time (issue 85 item 5: the report's step limit, REPORT_STEPS, which the
        # page did not name, ended an old version before its own error)
        rt, _ = make_runtime(run_spec(p, mujoco=False, max_sim_time=limit_s, max_steps=None, submit=submit,
                                      check=False, inputs="auto", robot=robot, interp=interp,
                                      robot_budget=SUBMIT_BUDGET if sub else None), RunSinks(observer=events))
        res = rt.run()
    except Exception as exc:  # noqa: BLE001 - the simulator's error is an outcome, never the report's end
        return _outcome(path, "internal", f"{type(exc).__name__}: {exc}", None, None, 0.0, events, "")
    file, line = (res.file, res.line) if res.reason != "completed" else _program_end(rt)
    out = _outcome(path, res.reason, res.text or "", file, line, res.sim_time, events, robot.name)
    out["statement"] = _statement(file, line)
    out["ending"] = ending_of(res.reason, res.text)
    out["cause"] = cause_of({"program": str(p), "reason": res.reason, "text": res.text, "sim_time": res.sim_time,
                             "cell_answers": 0, "robot_own": _own_machine_data(p, robot.source)})
    return out


def _program_end(rt) -> tuple[str | None, int | None]:
    """(file, line) of the END of the run's program (its module's main routine): where a
    program that completed ended, not the last statement it executed, which may lie in a
    routine of another module it called last (issue 85 item 5: "completed at
    collmonlib.src:302")."""
    m = rt.program.module_of(rt.program.main_path)
    if m is None or m.main is None or not m.main.end_line:
        return rt.result.file, rt.result.line
    return m.path, m.main.end_line


def _statement(file: str | None, line: int | None) -> str:
    """The text of the line a run ended at, stripped ("" when unknown): two versions of a
    program end at the same statement when it moved to another line."""
    if not file or not line:
        return ""

    lines = (read_source(file).text or "").splitlines()
    return lines[line - 1].strip() if 0 < line <= len(lines) else ""


def _outcome(path: str, reason: str, text: str, file, line, sim_time: float, events: _Events, robot: str) -> dict:
    errors = [{**e, "kind": event_kind(e["text"])} for e in events.errors]
    if reason == "error" and event_kind(text) != "motion" and not any(e["text"] in text for e in errors):
        # a motion the planner refused in the advance run ends the program without a main-run
        # error event: it is the run's motion event all the same
        errors.append({"t": round(sim_time, 3), "text": text, "line": line, "kind": event_kind(text)})
    counts = Counter(e["kind"] for e in errors)
    own_end = reason in ("completed", "halt")
    return {"program": path, "reason": reason, "ending": reason, "cause": "interpreter gap" if reason == "internal" else "",
            "text": text, "file": file, "line": line, "sim_time": round(sim_time, 3),
            "cycle_time": round(sim_time, 3) if own_end else None, "motions": events.motions,
            "events": errors, "counts": {k: counts[k] for k in EVENT_KINDS if counts[k]}, "robot": robot}


def run_outcomes(paths: list[str], max_sim_time: float | None = None, jobs: int | None = None,
                 progress: Callable[[str, dict], None] | None = None) -> dict[str, dict]:
    """{path: outcome} of every program of `paths` (:func:`run_outcome`), in `jobs` worker
    processes (krl.pool.run_tasks; 1: in this process). `progress(path, outcome)` is called as
    each run ends."""

    out: dict[str, dict] = {}
    tasks = [(p, (p, max_sim_time)) for p in dict.fromkeys(paths)]

    # a backup's programs in one worker after the other: it loads the backup once
    for o in run_tasks(run_outcome, tasks, jobs=jobs, timeout=RUN_TIMEOUT_S, in_process=jobs == 1,
                       group=loaded_with):
        if o.status == "done":
            res = o.value
        else:
            detail = o.detail or (f"the run took more than {RUN_TIMEOUT_S:.0f} s of wall time"
                                  if o.status == "timeout" else o.status)
            res = _outcome(o.key, "internal", detail, None, None, 0.0, _Events(), "")
        out[o.key] = res
        if progress is not None:
            progress(o.key, res)
    return out


def _text(message: str) -> str:
    """A message without the folders of the file names it holds (the two backups' differ) and
    without the line numbers after them (an edit above moves them; the place is compared by
    its statement)."""
    text = re.sub(r"[^\s:]*[/\\]", "", message or "")
    return re.sub(r"(\.(?:src|sub|dat)):\d+", r"\1:N", text, flags=re.I)


def _place(o: dict) -> tuple:
    """Where a run ended: its file's name and statement (the line, when the text is unknown)."""
    name = Path(o["file"]).name.lower() if o.get("file") else ""
    return (name, o.get("statement") or o.get("line"))


#: the words of :func:`outcome_changes` that say two runs of an entry point end differently
#: (:func:`ends_alike`)
END_CHANGES = ("ends differently", "ends at another statement")


def outcome_changes(old: dict | None, new: dict | None) -> list[str]:
    """What differs between the outcomes `old` and `new` of one entry point, in words ([] when
    nothing does): how it ends -- its reason and cause and its message ("ends differently"),
    then, unless both completed, the file and statement it ended at ("ends at another
    statement"; the same statement moved to another line is the same place) -- the cycle time
    (beyond :data:`CYCLE_TOLERANCE_S`), the motion events of each kind. Two runs stopped by the
    run's limits end alike only at the same limit, statement and message: a run stopped by the
    step limit in a loop and one that waits in a WAIT FOR until the time limit do not (issue 72)."""
    if old is None or new is None:
        return ["only in the old backup" if new is None else "only in the new backup"] if old or new else []
    out = []
    if (old["reason"], old.get("cause", ""), _text(old["text"])) != (new["reason"], new.get("cause", ""), _text(new["text"])):
        out.append(END_CHANGES[0])
    elif old["reason"] != "completed" and _place(old) != _place(new):
        out.append(END_CHANGES[1])
    a, b = old.get("cycle_time"), new.get("cycle_time")
    if (a is None) != (b is None) or (a is not None and round(abs(a - b), 6) > CYCLE_TOLERANCE_S):
        out.append("cycle time")
    if old.get("counts", {}) != new.get("counts", {}):
        out.append("motion events")
    return out


def ends_alike(old: dict | None, new: dict | None) -> bool:
    """Both outcomes exist and end the same way (:func:`outcome_changes` finds no change of
    :data:`END_CHANGES`): what the change report shows as "the same"."""
    if old is None or new is None:
        return False
    return not any(c in END_CHANGES for c in outcome_changes(old, new))
