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


#: answers of the automatic cell listed one by one; the rest are counted
MAX_ANSWERS = 8


def summary_lines(result: Any, observer: RunObserver, *, program: str, interp: str,
                  submits: list[Any] = (), workspace: str | None = None,
                  starving: list[str] = (), robot: str | None = None, run: Any = None) -> list[str]:
    """The console summary of one run, about a screen (at most ~25 lines).

    `result` is the run's RunResult; `submits` the scheduler's submit tasks (``name``,
    ``outcome``, ``file``, ``line``); `workspace` a note on the folder the program's modules
    came from (shown when it is not the program's own folder); `starving` the lines of
    :func:`starvation_lines` (they replace the generic hint); `robot` the simulated robot
    and where its data came from (issue 22); `run` the Runtime (issue 34): where the robot
    started, each stand-in of KUKA's software with its count
    (interp/runtime/kss.py), the answers of ``--inputs auto`` (interp/runtime/autocell.py),
    the idle time skipped (interp/runtime/idle.py).
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
        if starving:
            out.extend(starving)
        elif result.reason in ("max_sim_time", "max_steps", "deadlock") and "WAIT FOR" in (result.text or ""):
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
    out.extend(_run_lines(run))
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


def _run_lines(rt: Any) -> list[str]:
    """The lines of issue 34: start, stand-ins, answers, idle time (see summary_lines)."""
    if rt is None:
        return []
    out = []
    if getattr(rt, "start", None):
        out.append(f"  start      {printable(rt.start)}")
    kss = getattr(rt, "kss", None)
    stubs = kss.summary() if kss is not None else []
    if stubs:
        shown = ", ".join(f"{printable(name)} ({what}" + ("" if "variable" in what or what == "type" else
                                                          f", {n} call{'s' if n != 1 else ''}") + ")"
                          for name, what, n in stubs[:12])
        more = f", ... {len(stubs) - 12} more" if len(stubs) > 12 else ""
        out.append(f"  stubs      {len(stubs)}: {shown}{more}")
    auto = getattr(rt, "autocell", None)
    if auto is not None:
        answers = auto.answers
        out.append(f"  auto cell  {len(answers)} answer(s), each {auto.delay:g} s after the program starved"
                   + (":" if answers else " (nothing starved that inputs could release)"))
        for a in answers[:MAX_ANSWERS]:
            out.append(f"    {printable(a.describe())}")
        if len(answers) > MAX_ANSWERS:
            out.append(f"    ... {len(answers) - MAX_ANSWERS} more (see --trace)")
    idle = getattr(getattr(rt, "scheduler", None), "idle", None)
    if idle is not None and idle.jumps:
        dt = rt.controller.dt
        out.append(f"  idle       {idle.skipped * dt:.3f} s fast-forwarded in {idle.jumps} jump(s): nothing "
                   f"changed until the next event")
    return out


# ------------------------------------------------------------------ a starving WAIT FOR
def _wait_node(rt: Any, file: str, line: int):
    """The WAIT FOR statement of the program's files at `file`:`line`, or None."""
    from pathlib import Path  # noqa: PLC0415

    from krl.ast import nodes as N  # noqa: PLC0415

    target = str(Path(file).resolve())
    for m in rt.program.modules:
        src = m.unit.src
        if src is None or str(Path(src.path).resolve()) != target:
            continue
        for node in src.module.walk():
            if isinstance(node, N.WaitFor) and node.span.line == line:
                return node
    return None


def _input_of(rt: Any, main: str, e: Any) -> str | None:
    """``$IN[n]``, or the SIGNAL name on one input, that `e` reads; None for anything else."""
    from krl.ast import nodes as N  # noqa: PLC0415
    from interp.run import global_value, signal_of  # noqa: PLC0415

    if isinstance(e, N.Name):
        found = signal_of(rt, main, e.name)
        if found is not None and found[0] == "$IN" and found[2] is None:
            return e.name.upper()
        return None
    if isinstance(e, N.Index) and isinstance(e.base, N.Name) and e.base.name.upper() == "$IN" \
            and len(e.indices) == 1:
        i = e.indices[0]
        n = i.value if isinstance(i, N.IntLit) else (global_value(rt, main, i.name) if isinstance(i, N.Name) else None)
        if isinstance(n, int) and not isinstance(n, bool):
            return f"$IN[{abs(n)}]" if isinstance(i, N.IntLit) or n > 0 else None
    return None


def _release(rt: Any, main: str, e: Any, want: bool) -> dict[str, bool] | None:
    """Input values that make the condition `e` equal `want`: one way, the first operand of
    an OR; None when the condition is not over inputs alone in a way this reads."""
    from krl.ast import nodes as N  # noqa: PLC0415

    name = _input_of(rt, main, e)
    if name is not None:
        return {name: want}
    if isinstance(e, N.Unary) and e.op == "NOT":
        return _release(rt, main, e.operand, not want)
    if isinstance(e, N.Binary):
        if e.op in ("==", "<>"):
            for side, lit in ((e.left, e.right), (e.right, e.left)):
                if isinstance(lit, N.BoolLit):
                    return _release(rt, main, side, (lit.value == want) == (e.op == "=="))
            return None
        if (e.op == "AND" and want) or (e.op == "OR" and not want):
            a, b = _release(rt, main, e.left, want), _release(rt, main, e.right, want)
            return {**a, **b} if a is not None and b is not None else None
        if e.op in ("AND", "OR"):
            return _release(rt, main, e.left, want) or _release(rt, main, e.right, want)
    return None


def _inputs_read(rt: Any, main: str, e: Any) -> list[str]:
    """The inputs (``$IN[n]``, SIGNAL names on one input) the condition `e` reads, in order."""
    return list(dict.fromkeys(n for n in (_input_of(rt, main, node) for node in e.walk()) if n is not None))


def starvation_lines(rt: Any) -> list[str]:
    """When the run ended in a WAIT FOR that nothing released (time or step limit, deadlock):
    the inputs it waits on and a cell rule (robot/cellrules.py) that would release it, as
    summary lines. Empty otherwise. Names come from the program's files: printable."""
    res = rt.result
    task = rt.robot
    if res is None or task is None or res.reason not in ("max_sim_time", "max_steps", "deadlock") \
            or "WAIT FOR" not in (res.text or "") or not task.file:
        return []
    node = _wait_node(rt, task.file, task.line)
    if node is None:
        return []
    main = rt.program.main_path.stem
    from interp.run import signal_of  # noqa: PLC0415

    names = []
    for n in _inputs_read(rt, main, node.cond):
        sig = None if n.startswith("$") else signal_of(rt, main, n)
        names.append(f"{n} ($IN[{sig[1]}])" if sig else n)
    release = _release(rt, main, node.cond, True)
    where = _where(task.file, task.line)
    out = [f"  starves    WAIT FOR at {where} waits on "
           + (", ".join(printable(n) for n in names) if names else "no input (outputs or variables only)")]
    if release:
        sets = ", ".join(f"{printable(k) if k.isidentifier() else repr(printable(k))}: {str(v).lower()}"
                         for k, v in release.items())
        out.append("  a rule     that releases it, in a cell file given with --inputs (robot/cellrules.py):")
        out.append("               rules:")
        out.append(f"                 - {{when: \"TRUE\", after: 1.0, set: {{{sets}}}}}   "
                   f"# when: the program's output that asks for it")
    return out
