"""What `krl run` prints: a one-screen summary of how a run went (issue 13).

:class:`RunObserver` stands between the controller and the trace file: it forwards every
event unchanged and keeps what a person needs to read afterwards — the KRL messages raised
(MsgNotify, SET_KRLMSG, IR_STOPM routines, controller messages), the errors of the main run,
the motions by type, the I/O changes by signal kind. :func:`summary_lines` renders it with
the :class:`~interp.runtime.core.RunResult` and the outcome of every submit task.

Every text from the program or the input passes through :func:`krl.terminal.printable`
(docs/security.md): a string built by SWRITE or a file name never reaches the terminal with
its control characters.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any

from krl.terminal import clip, printable, printable_path

#: messages shown on the console; the rest are counted ("... N more").
MAX_MESSAGES = 8

#: controller messages that are notes of the simulator, not of the program: counted apart.
SIMULATOR_NOTES = ("not simulated:", "stub:")

ENDINGS = {
    "completed": "completed",
    "halt": "stopped by HALT",
    "error": "stopped by a run-time error",
    "deadlock": "deadlocked",
    "max_steps": "stopped at the step limit (--max-steps)",
    "max_sim_time": "stopped at the time limit (--max-sim-time)",
}


@dataclass
class Note:
    """One line of the message list: simulated time (s), where it came from, the text."""

    t: float
    source: str
    text: str


@dataclass
class RunObserver:
    """A trace writer in front of another (or of none): records the controller's events.

    Implements the part of :class:`robot.trace.TraceWriter` the controller uses
    (``write``, ``write_pose``); every call is forwarded to `inner` first.
    """

    inner: Any = None
    notes: list[Note] = field(default_factory=list)
    motion_types: dict[int, str] = field(default_factory=dict)
    io: Counter = field(default_factory=Counter)
    motion_errors: int = 0

    def write(self, kind: str, t: float, **fields: Any) -> Any:
        ev = self.inner.write(kind, t, **fields) if self.inner is not None else None
        if kind == "motion":
            self.motion_types.setdefault(int(fields.get("id", 0)), str(fields.get("type", "?")))
        elif kind == "io":
            signal = str(fields.get("signal", "?"))
            base = signal.split("[", 1)[0]
            src = fields.get("source") or "program"
            self.io[f"{base} by {src}" if src != "program" else base] += 1
        elif kind == "message":
            self.notes.append(Note(t, "message", str(fields.get("text", ""))))
        elif kind == "error":
            line = fields.get("line")
            where = f" (line {line})" if line else ""
            if fields.get("id") is not None:
                self.motion_errors += 1
            num = f" [{fields['number']}]" if fields.get("number") else ""
            self.notes.append(Note(t, "error", f"{fields.get('text', '')}{num}{where}"))
        return ev

    def write_pose(self, t: float, axes: Any, tcp_T: Any) -> None:
        if self.inner is not None:
            self.inner.write_pose(t, axes, tcp_T)


def _where(file: str | None, line: int | None) -> str:
    if not file:
        return ""
    return f"{printable_path(file)}:{line}" if line else printable_path(file)


def _clip(text: str) -> str:
    return clip(printable(text))


def summary_lines(result: Any, observer: RunObserver, *, program: str, interp: str,
                  submits: list[Any] = (), workspace: str | None = None,
                  robot: str | None = None) -> list[str]:
    """The console summary of one run, about a screen (at most ~20 lines).

    `result` is the run's RunResult; `submits` the scheduler's submit tasks (``name``,
    ``outcome``, ``file``, ``line``); `workspace` a note on the folder the program's modules
    came from (shown when it is not the program's own folder); `robot` the simulated robot
    and where its data came from (issue 22).
    """
    out = [f"run {printable_path(program)} ({interp} interpreter)"]
    if workspace:
        out.append(f"  workspace  {printable(workspace)}")
    where = _where(result.file, result.line)
    ending = ENDINGS.get(result.reason, result.reason)
    if result.reason == "completed":
        out.append(f"  ended      {ending} at t={result.sim_time:.3f} s")
    else:
        # how the run ended is the one message the user came for: shown whole (printable), never
        # clipped like the list of KRL messages below
        detail = printable(result.text) if result.text else ""
        num = ""
        if result.error is not None and getattr(result.error, "number", None):
            num = f" [{result.error.number}]"
        ctx = f" ({result.context})" if result.context and result.context != "main" else ""
        out.append(f"  ended      {ending} at t={result.sim_time:.3f} s")
        if where and detail.endswith(f" at {where}"):
            detail = detail[:-len(f" at {where}")]      # the place is already in front
        if where or detail:
            out.append(f"             {where}{ctx}{': ' if where and detail else ''}{detail}{num}")
        if result.reason in ("max_sim_time", "max_steps", "deadlock") and "WAIT FOR" in (result.text or ""):
            out.append("  hint       nothing set the inputs that WAIT FOR reads: give them with "
                       "--inputs STIMULI.yaml (- at: 1.0 / set: {\"$IN[n]\": true}; robot/stimuli.py)")
    for task in submits:
        reason, err = getattr(task, "outcome", (None, None)) or (None, None)
        if reason == "error" and err is not None:
            w = _where(getattr(err, "file", None) or task.file, getattr(err, "line", None) or task.line)
            num = f" [{err.number}]" if getattr(err, "number", None) else ""
            out.append(f"  submit     {printable(task.name)} stopped by a run-time error: "
                       f"{w}: {_clip(err.message)}{num}")
        elif reason is not None and reason != "completed":
            out.append(f"  submit     {printable(task.name)}: {ENDINGS.get(reason, reason)}")
    if robot:
        out.append(f"  robot      {printable(robot)}")
    notes = [n for n in observer.notes if not n.text.startswith(SIMULATOR_NOTES)]
    sim = Counter(n.text.split(":", 1)[0] for n in observer.notes if n.text.startswith(SIMULATOR_NOTES))
    if notes:
        out.append(f"  messages   {len(notes)}")
        for n in notes[:MAX_MESSAGES]:
            tag = "error: " if n.source == "error" else ""
            out.append(f"    t={n.t:.3f} s  {tag}{_clip(n.text)}")
        if len(notes) > MAX_MESSAGES:
            out.append(f"    ... {len(notes) - MAX_MESSAGES} more (see --trace)")
    else:
        out.append("  messages   none")
    if sim:
        out.append(f"  simulator  {sum(sim.values())} note(s): "
                   + ", ".join(f"{k} {v}" for k, v in sorted(sim.items())) + " (see --trace)")
    kinds = Counter(observer.motion_types.values())
    motions = len(observer.motion_types)
    detail = ", ".join(f"{k} {v}" for k, v in sorted(kinds.items()))
    errs = f"; {observer.motion_errors} motion error(s)" if observer.motion_errors else ""
    out.append(f"  motions    {motions}{f' ({detail})' if motions else ''}{errs}")
    changes = sum(observer.io.values())
    detail = ", ".join(f"{k} {v}" for k, v in sorted(observer.io.items()))
    out.append(f"  I/O        {changes} change(s){f' ({detail})' if changes else ''}")
    out.append(f"  time       {result.sim_time:.3f} s simulated, {result.steps} steps")
    return out
