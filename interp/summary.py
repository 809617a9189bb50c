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
from pathlib import Path
from typing import Any

from krl.kssarchive import packages_text
from krl.terminal import clip, printable, printable_path
from krl.ast import nodes as N
from interp.run import global_value, signal_of
from interp.runtime.cmdchannel import STOPPED
from robot.controller import Controller, holds
from krl.ast.printer import expr as printed

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
#: the start of the text of a ``halt`` that a STOP command to $CMD made, not a HALT statement
#: (interp/runtime/cmdchannel.py ProgramControl._stop_robot)
CMD_STOP = STOPPED


def ending_of(reason: str, text: str | None = None) -> str:
    """The words of how a run ended (:data:`ENDINGS`, else `reason` itself); a ``halt`` whose
    `text` says a STOP written to $CMD stopped it is "stopped by a STOP command ($CMD)", not "by
    HALT" (issue 85 item 5)."""
    if reason == "halt" and (text or "").startswith(CMD_STOP):
        return "stopped by a STOP command ($CMD)"
    return ENDINGS.get(reason, reason)


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
    (``write``, ``write_pose``, ``takes_poses``); every call is forwarded to `inner` first.
    It takes the poses only for `inner` (a summary has no use for them).
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

    @property
    def takes_poses(self) -> bool:
        return self.inner is not None and self.inner.takes_poses

    @property
    def takes_motion_points(self) -> bool:
        """The motion events' end points and limits only for `inner` (robot/trace.py)."""
        return self.inner is not None and getattr(self.inner, "takes_motion_points", True)

    def write_pose(self, t: float, axes: Any, tcp_T: Any) -> None:
        self.inner.write_pose(t, axes, tcp_T)

    def use_actual(self, stream: Any, tcp: Any) -> None:
        """The actual poses for `inner` (robot/trace.py ``TraceWriter.use_actual``)."""
        if self.inner is not None and getattr(self.inner, "use_actual", None) is not None:
            self.inner.use_actual(stream, tcp)


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
    ending = ending_of(result.reason, result.text)
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
        out.extend(_behind_lines(result, run))
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
    out.append(f"  time       {result.sim_time:.3f} s simulated, {result.steps} steps{_by_task(run)}")
    out.extend(cycle_lines(result, run))
    return out


def settled_end(run: Any) -> tuple[float, float] | None:
    """(the setpoints' end, the settled end), s, of the run's robot (the Runtime `run`): the last
    IPO cycle its setpoint changed, and the first from which the actual-value model's axes stayed
    within each axis' positioning window ``$IN_POS_MA`` (robot/actualvalue.py: KUKA Machine Data
    §2.1.119, the axis "in position"; the real KR 3 R540's measured axes lag its setpoints by
    36-48 ms, ../shared/real-traces README). None for a robot without an actual-value model or a
    run whose robot never moved."""
    st = getattr(getattr(run, "controller", None), "act_stream", None)
    if st is None:
        return None
    st.finish()
    if st.last_change is None:
        return None
    return st.last_change, st.settled_at()


def cycle_lines(result: Any, run: Any) -> list[str]:
    """The cycle time (issue 73): until the program ended and the robot settled, whichever is
    later, with both ends and which one it is (:func:`settled_end`); none without a model."""
    ends = settled_end(run)
    if ends is None:
        return []
    setpoints, settled = ends
    cycle = max(result.sim_time, settled)
    which = "the robot settled" if settled >= result.sim_time else "the program ended"
    return [f"  cycle time {cycle:.3f} s, until {which}: the setpoints ended at {setpoints:.3f} s, the robot "
            f"settled at {settled:.3f} s (+{1000 * (settled - setpoints):.0f} ms: every axis within $IN_POS_MA "
            f"of the actual-value model), the program ended at {result.sim_time:.3f} s"]


def _by_task(run: Any) -> str:
    """Which task used the steps, when the run had more than one (the robot program and its
    submit programs): `` (cell 50004000, sps 5000400)``; the step limit counts the robot
    program's (docs/architecture.md "The step limit")."""
    by = run.steps_by_task() if run is not None and hasattr(run, "steps_by_task") else []
    if len(by) < 2:
        return ""
    return " (" + ", ".join(f"{printable(name)} {n}" for name, n in by) + ")"


def _run_lines(rt: Any) -> list[str]:
    """The lines of issue 34: what holds the robot on its path at the end (robot/controller.py
    ``holds``, issue 85), start, stand-ins, answers, idle time (see summary_lines)."""
    if rt is None:
        return []
    out = []
    ctl = getattr(rt, "controller", None)
    for hold in (holds(ctl) if isinstance(ctl, Controller) else []):
        # what holds the robot still on its path at the end (issue 85 item 9)
        out.append(f"  held       {printable(hold)}")
    held = getattr(getattr(rt, "motions", None), "held", None)
    if held is not None:
        # a motion at $OV_PRO = 0 (interp/runtime/motions.py hold_at_zero_override, issue 85 item 9c)
        file, line, since = held
        out.append(f"  held       motion at {printable(str(file))}:{line} held: $OV_PRO = 0 since t = {since:.3f} s "
                   "(the robot stands until the override rises; KSS: 0..100 %)")
    scene = getattr(rt, "start", None)
    if scene is not None and scene.mode_why:
        shown = "EXT" if scene.mode == "EX" else scene.mode
        out.append(f"  mode       {shown} ({printable(scene.mode_why)})")
    if scene is not None and scene.where:
        why = f" ({printable(scene.why)})" if scene.why and scene.why not in ("--start", "the cell file's start:") \
            else ""
        out.append(f"  start      {printable(scene.where)}{why}")
    elif scene is not None and scene.why:
        out.append(f"  start      {printable(scene.why)}")    # a home not taken (interp/run.py plan_cell)
    kss = getattr(rt, "kss", None)
    stubs = kss.summary() if kss is not None else []
    if stubs:
        shown = ", ".join(f"{printable(name)} ({what}" + ("" if "variable" in what or what == "type" else
                                                          f", {n} call{'s' if n != 1 else ''}") + ")"
                          for name, what, n in stubs[:12])
        more = f", ... {len(stubs) - 12} more" if len(stubs) > 12 else ""
        out.append(f"  stubs      {len(stubs)}: {shown}{more}")
    ws = getattr(getattr(rt, "program", None), "ws", None)
    packages = getattr(ws, "installed_packages", ())
    if packages:
        out.append(f"  packages   {printable(packages_text(packages))} (installed: the archive's am.ini)")
    auto = getattr(rt, "autocell", None)
    if auto is not None:
        answers = auto.answers
        given = pgno_given(rt)
        plc = f"; P00's program number given {given} time(s), the PLC's answers" if given else ""
        out.append(f"  auto cell  {len(answers)} answer(s), each {auto.delay:g} s after the program starved{plc}"
                   + (":" if answers else "" if given else " (nothing starved that inputs could release)"))
        for a in answers[:MAX_ANSWERS]:
            out.append(f"    {printable(a.describe())}")
        if len(answers) > MAX_ANSWERS:
            out.append(f"    ... {len(answers) - MAX_ANSWERS} more (see --trace)")
        given = auto.production
        if given:
            out.append(f"  production {len(given)} input(s) given from the start, as a producing cell gives them "
                       f"(the program's production path):")
            for d in given[:MAX_ANSWERS]:
                out.append(f"    {printable(d.describe())}")
            if len(given) > MAX_ANSWERS:
                out.append(f"    ... {len(given) - MAX_ANSWERS} more")
    idle = getattr(getattr(rt, "scheduler", None), "idle", None)
    if idle is not None and idle.jumps:
        dt = rt.controller.dt
        out.append(f"  idle       {idle.skipped * dt:.3f} s fast-forwarded in {idle.jumps} jump(s): nothing "
                   f"changed until the next event")
    return out


def _behind_lines(result: Any, rt: Any) -> list[str]:
    """For a run of the automatic cell that ends on an error or a HALT: the inputs the
    statement it ended at depends on (interp/runtime/autocell.py ``AutoCell.behind``), with the
    values they had: the inputs that would change how it ends."""
    auto = getattr(rt, "autocell", None)
    if auto is None or result.reason not in ("error", "halt") or not result.file or not result.line:
        return []
    got = auto.behind(result.file, result.line)
    if not got:
        return []
    shown = ", ".join(f"{printable(a.shown)} = {('TRUE' if v else 'FALSE') if a.last is None else v}"
                      for a, v in got[:8])
    more = f", ... {len(got) - 8} more" if len(got) > 8 else ""
    return [f"  inputs     it depends on {shown}{more}: other values of these inputs would change it"]


# ------------------------------------------------------------------ a starving WAIT FOR
def _wait_node(rt: Any, file: str, line: int):
    """The WAIT FOR statement of the program's files at `file`:`line`, or None."""

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


def _group_of(rt: Any, main: str, e: Any) -> tuple[str, int, int] | None:
    """``(NAME, first, last)`` of the group SIGNAL on inputs (``SIGNAL X $IN[513] TO $IN[544]``:
    an INT, bit 0 on the first) that `e` names; None for anything else."""

    if not isinstance(e, N.Name):
        return None
    found = signal_of(rt, main, e.name)
    if found is None or found[0] != "$IN" or found[2] is None:
        return None
    return e.name.upper(), found[1], found[2]


def _release(rt: Any, main: str, e: Any, want: bool) -> dict[str, bool | int] | None:
    """Input values that make the condition `e` equal `want`: one way, the first operand of
    an OR; a group SIGNAL compared for equality with an INT literal takes that INT (a cell
    file sets a group by name with an INT: robot/stimuli.py); None when the condition is not
    over inputs alone in a way this reads."""

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
                group = _group_of(rt, main, side)
                if group is not None and isinstance(lit, N.IntLit) and want == (e.op == "==") \
                        and 0 <= lit.value < (1 << (group[2] - group[1] + 1)):
                    return {group[0]: lit.value}
            return None
        if (e.op == "AND" and want) or (e.op == "OR" and not want):
            a, b = _release(rt, main, e.left, want), _release(rt, main, e.right, want)
            return {**a, **b} if a is not None and b is not None else None
        if e.op in ("AND", "OR"):
            return _release(rt, main, e.left, want) or _release(rt, main, e.right, want)
    return None


def _inputs_read(rt: Any, main: str, e: Any) -> list[str]:
    """The inputs the condition `e` reads, in order, as the run summary names them: ``$IN[n]``,
    a SIGNAL on one input with it (``PartOk ($IN[5])``), a group SIGNAL on inputs with its range
    (``PartCode ($IN[513..544])``)."""
    out = []
    for node in e.walk():
        n = _input_of(rt, main, node)
        if n is not None and not n.startswith("$"):
            n = f"{n} ($IN[{signal_of(rt, main, n)[1]}])"
        elif n is None:
            group = _group_of(rt, main, node)
            n = f"{group[0]} ($IN[{group[1]}..{group[2]}])" if group is not None else None
        if n is not None:
            out.append(n)
    return list(dict.fromkeys(out))


#: what a condition over a system variable of the controller waits for, and what satisfies it
#: in a run: variable -> (what, krl run's option, the cell file's key). KSS 8.x "Operating and
#: Programming Instructions for System Integrators", Automatic External: $I_O_ACTCONF is TRUE
#: when EXT is selected and $I_O_ACT is TRUE; $IN_HOME is TRUE while the robot stands within
#: $H_POS_TOL of $H_POS (docs/robot.md, "The operator's path through a cell program").
ANSWERS = {
    "$I_O_ACTCONF": ("Automatic External ($MODE_OP #EX and $I_O_ACT)", "--mode EXT", "autoext: true"),
    "$EXT": ("Automatic External ($MODE_OP #EX)", "--mode EXT", "autoext: true"),
    "$IN_HOME": ("the robot in its home position ($H_POS, within $H_POS_TOL)", "--start XHOME", "start: XHOME"),
    "$EXT_START": ("the PLC's external start ($EXT_START: the program number valid with it, PGNO_VALID=0, "
                   "is not simulated)", "", ""),
}

#: the P00 parameters of $config.dat whose inputs carry the PLC's program number
_PGNO_INPUTS = ("PGNO_VALID", "PGNO_PARITY")


def _waiting(rt: Any, file: str, line: int, halted: bool):
    """(routine, kind, condition) the robot task waits on at `file`:`line`: a WAIT FOR on that
    line; else (a HALT, a statement in a busy loop) the innermost REPEAT ... UNTIL or WHILE
    around it — kind ``UNTIL``/``WHILE``; None when there is none."""

    target = str(Path(file).resolve())
    for m in rt.program.modules:
        src = m.unit.src if m.unit is not None else None
        if src is None or src.module is None or str(Path(src.path).resolve()) != target:
            continue
        for routine in src.module.routines:
            path = _path_to(routine, line)
            if path is None:
                continue
            hit = path[-1]
            if isinstance(hit, N.WaitFor) and not halted:
                return routine, "WAIT FOR", hit.cond
            for node in reversed(path):
                if isinstance(node, N.Repeat):
                    return routine, "UNTIL", node.cond
                if isinstance(node, N.While):
                    return routine, "WHILE", node.cond
            return None
    return None


def _path_to(node: Any, line: int) -> list | None:
    """The nodes from `node` down to the first statement that stands on `line`, or None."""

    for child in node.children():
        if child is None or not isinstance(child, N.Node):
            continue
        if isinstance(child, N.Stmt) and child.span.line == line:
            return [node, child]
        got = _path_to(child, line)
        if got is not None:
            return [node, *got]
    return None


def _index(rt: Any, main: str, e: Any):
    """The INT value of an index expression of literals, constants and variables of the data
    lists (``PGNO_VALID*(-1)``), or None."""

    if isinstance(e, N.IntLit):
        return e.value
    if isinstance(e, N.Name):
        v = global_value(rt, main, e.name)
        return v if isinstance(v, int) and not isinstance(v, bool) else None
    if isinstance(e, N.Unary) and e.op in ("-", "+"):
        v = _index(rt, main, e.operand)
        return None if v is None else (-v if e.op == "-" else v)
    if isinstance(e, N.Binary) and e.op in ("+", "-", "*"):
        a, b = _index(rt, main, e.left), _index(rt, main, e.right)
        if a is None or b is None:
            return None
        return a + b if e.op == "+" else a - b if e.op == "-" else a * b
    return None


def _reads(rt: Any, main: str, cond: Any) -> tuple[list[str], list[int]]:
    """(system variables, input numbers) the condition `cond` reads, each once, in order."""

    names: list[str] = []
    inputs: list[int] = []
    for node in cond.walk():
        if isinstance(node, N.Index) and isinstance(node.base, N.Name) and node.base.name.upper() == "$IN" \
                and len(node.indices) == 1:
            n = _index(rt, main, node.indices[0])
            if n is not None and n != 0 and abs(n) not in inputs:
                inputs.append(abs(n))
        elif isinstance(node, N.Name) and node.name.startswith("$") and node.name.upper() not in names:
            names.append(node.name.upper())
        elif isinstance(node, N.Name):
            sig = signal_of(rt, main, node.name)
            if sig is not None and sig[0] == "$IN" and sig[2] is None and sig[1] not in inputs:
                inputs.append(sig[1])
    return names, inputs


def _pgno_inputs(rt: Any, main: str) -> dict[int, str]:
    """Input number -> what it carries in P00's program-number handshake (the ``PGNO_*``
    parameters of $config.dat): the valid bit, the parity bit, the number's bits."""

    out: dict[int, str] = {}
    for name in _PGNO_INPUTS:
        v = global_value(rt, main, name)
        if isinstance(v, int) and not isinstance(v, bool) and v:
            out[abs(v)] = name
    fbit, length = global_value(rt, main, "PGNO_FBIT"), global_value(rt, main, "PGNO_LENGTH")
    if isinstance(fbit, int) and isinstance(length, int) and fbit > 0:
        for i in range(max(0, min(length, 64))):
            out.setdefault(fbit + i, f"PGNO_FBIT+{i}")
    return out


def wait_lines(rt: Any) -> list[str]:
    """When the run ended waiting — at the time or step limit, in a deadlock, or at a HALT
    inside a loop that waits (P00's #CHK_HOME) — and what it waits on is the controller's
    state or P00's program-number handshake (KUKA's P00, the project's standard P00, or any
    program): what it waits for and the option or cell-file key that answers it, as summary
    lines. Empty otherwise. Names come from the program's files: printable."""
    res = rt.result
    task = rt.robot
    if res is None or task is None or not task.file \
            or res.reason not in ("max_sim_time", "max_steps", "deadlock", "halt"):
        return []
    main = rt.program.main_path.stem
    pgno = _pgno_inputs(rt, main)
    halted = res.reason == "halt"
    for file, line in _stack(rt, task):
        found = _waiting(rt, file, line, halted)
        halted = False                  # a caller stands at a call, not at the HALT
        if found is None:
            continue
        routine, kind, cond = found
        names, inputs = _reads(rt, main, cond)
        where = f"{routine.name} ({_where(file, line)})"
        shown = printable(_show(cond))
        for n in names:
            if n in ANSWERS:
                what, option, key = ANSWERS[n]
                out = [f"  waits      in {where} for {what}: {kind} {shown}"]
                if option:
                    out.append(f"  answer     {option}, or the cell file's `{key}`")
                return out
        carried = [f"$IN[{i}] ({pgno[i]})" for i in inputs if i in pgno]
        if carried and not pgno_given(rt):
            return [f"  waits      in {where} for the PLC's program number (P00's handshake): {kind} {shown} "
                    f"reads {', '.join(carried)} of $config.dat",
                    "  answer     --pgno N (a number the cell program's SWITCH PGNO has a CASE for), or the "
                    "cell file's `pgno: N`, or --inputs auto"]
    return []


def pgno_given(rt: Any) -> int:
    """How many program numbers the run's PLC wrote in P00's handshake (``--pgno``, the cell
    file's preset, the automatic cell's: the rules of robot/cellpresets.py that write the number)."""
    signals = getattr(getattr(rt, "controller", None), "signals", None)
    return sum(r.fired for r in getattr(signals, "rules", ()) if str(r.source).endswith(":pgno") and len(r.set) > 1)


def _stack(rt: Any, task: Any) -> list[tuple[str, int]]:
    """(file, line) where the task stopped, then where each caller stands (the run's
    ``RunResult.stack``), innermost first."""
    out = [(task.file, task.line)]
    for file, line in getattr(rt.result, "stack", ())[1:]:
        out.append((file, line))
    return out


def _show(e: Any) -> str:

    try:
        return printed(e)
    except Exception:  # noqa: BLE001 - a node the printer does not know
        return "its condition"


def starvation_lines(rt: Any) -> list[str]:
    """When the run ended in a WAIT FOR that nothing released (time or step limit, deadlock):
    the inputs it waits on and a cell rule (robot/cellrules.py) that would release it, as
    summary lines; a wait on the controller's state or P00's handshake is said by
    :func:`wait_lines`. Empty otherwise. Names come from the program's files: printable."""
    waits = wait_lines(rt)
    if waits:
        return waits
    res = rt.result
    task = rt.robot
    if res is None or task is None or res.reason not in ("max_sim_time", "max_steps", "deadlock") \
            or "WAIT FOR" not in (res.text or "") or not task.file:
        return []
    node = _wait_node(rt, task.file, task.line)
    if node is None:
        return []
    main = rt.program.main_path.stem

    names = _inputs_read(rt, main, node.cond)
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
