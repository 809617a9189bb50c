"""A cell that answers by itself: ``krl run --inputs auto`` (issue 34).

When the program starves — a WAIT FOR, a polling loop or a handshake that nothing answers —
the automatic cell sets the inputs that make the awaited condition come true, after
:data:`AUTO_DELAY_S`, as a PLC that has been waiting for the robot to ask would.

**When.** The run is idle (interp/runtime/idle.py: nothing changed for a window of IPO
cycles), or the robot program waits in a WAIT FOR that nothing else can release (the
scheduler's deadlock test). A WAIT FOR is answered at once; for a polling loop the cell first
*watches* one more window, recording every statement the tasks execute and the frame it runs
in (the full statement hook, :meth:`interp.runtime.core.Runtime.before_statement`, in both
interpreters), then answers.

**What.** The candidates are the conditions the starving tasks evaluate, with the frame they
are evaluated in, ranked: the robot program before the submit programs; the innermost routine
first; a condition that ends the wait (``WAIT FOR``, ``REPEAT ... UNTIL``, ``WHILE``) before a
branch (``IF``) before a selection (``SWITCH``); a condition answered fewer times before; then
the order of execution. The first candidate the cell can solve is answered:

* the *target*: ``WAIT FOR``/``UNTIL`` TRUE, ``WHILE`` FALSE (the loop ends), ``IF`` the other
  branch, ``SWITCH`` the value of a CASE other than the one taken (the CASEs in turn, one per
  answer, so a program-number SWITCH runs each program);
* the *inputs it reads*: the names and ``$IN[...]`` of the condition as the front end resolved
  them (each Name's storage, a parameter through the frame's binding to the caller's SIGNAL,
  an index evaluated in the frame) — one ``$IN`` bit, or a SIGNAL group read as an INT;
* the *solution*: the fewest inputs changed (one, then two, ... of up to
  :data:`MAX_ATOMS` inputs; a group takes the constants the condition compares it with, the
  CASE values, 0 and 1) for which the condition, evaluated with the runtime's operators on the
  frame's other values, gives the target. A condition that calls a routine, or reads nothing the
  cell can set (outputs, variables), is not solved.

The answer is a stimulus at ``now + AUTO_DELAY_S`` whose I/O events carry ``source: auto``; it
is recorded (:class:`Answer`) for the run summary ("at 12.4 s, $IN[17]
bPermisoEntradaBPAbajo := TRUE releases C1_pickConveyorBP.src:42"), written to the trace as an
``answer`` event when it takes effect, and ``krl cell init --from-run TRACE`` turns the answers
into rules (interp/cellinit.py). Inputs set by the cell keep their value until an answer
changes them (a later ``WAIT FOR NOT PART_OK`` is answered in turn).

**KUKA's handshakes.** Beside the solver, the cell plays the PLC of the standard Automatic
External interface (robot/cellpresets.py): the operating mode is EXT (unless ``--mode``), and
when the backup's ``$config.dat`` declares P00's program-number parameters (``PGNO_*``) the
PLC answers P00's request with a program number — the CASE values of the program's
``SWITCH PGNO`` (the ``$config.dat`` variable, by the checker's symbol) in turn, else 1.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from pathlib import Path

from krl.ast import nodes as N

from krl.limits import AUTO_MAX_INPUTS, AUTO_MAX_TRIES
from krl.terminal import printable
from robot.io import ALWAYS_TRUE_INPUT

from .convert import binary_op, unary_op
from .errors import KrlRuntimeError
from .memory import ProxyRef, SignalRef
from .scheduler import break_quiet
from .values import EnumValue
from robot.cellpresets import PresetError, pgno_bits, pgno_rules
from robot.stimuli import Stimulus
from krl.source import read_source
from krl.semantics.inputflow import error_routines, flow, inputs_behind, interrupt_flags, production_values, var_key


def input_flow(program):
    """krl/semantics/inputflow.py ``flow`` of the program's checked workspace, once per
    workspace (interp/runtime/program.py ``Program.derived``)."""
    return program.derived("input_flow", lambda pr: flow(pr.ws))

#: s between the moment the cell sees the program starve and its answer (a PLC scan, the
#: sensor and the bus: a stated figure, not a measured one)
AUTO_DELAY_S = 0.5
#: inputs of one condition the solver combines; assignments it evaluates (krl/limits.py)
MAX_ATOMS = AUTO_MAX_INPUTS
MAX_TRIES = AUTO_MAX_TRIES

#: s between the FALSE and the TRUE the cell gives an interrupt's inputs that hold already (two IPO
#: cycles: the controller sees the FALSE in one, the rising edge in the next)
EDGE_S = 0.024

_KIND_RANK = {"WAIT FOR": 0, "UNTIL": 0, "WHILE": 0, "IF": 1, "SWITCH": 2}


class Unsolvable(Exception):
    """The condition reads something the cell cannot set or evaluate."""


@dataclass
class Answer:
    """One answer of the automatic cell: when it takes effect (s), what it sets (``items``:
    ``(signal, name, value)`` with signal ``$IN[n]`` or a group ``$IN[a..b]``, the name the
    condition reads it by or "", a BOOL or the group's INT), the ``$IN[n]`` bits that makes
    (``sets``), the statement it releases (file, line, kind), the condition's text and the
    handler of the interrupt it goes through (``via``: a flag that handler sets, or "")."""

    t: float
    items: list
    sets: dict[str, bool]
    file: str
    line: int
    kind: str
    text: str = ""
    via: str = ""           # the handler of the interrupt whose WHEN the inputs make TRUE, or ""

    def describe(self) -> str:
        """``at 12.4 s, $IN[17] NAME := TRUE releases FILE:LINE (WAIT FOR)``."""
        parts = []
        for sig, name, v in self.items:
            shown = ("TRUE" if v else "FALSE") if isinstance(v, bool) else str(v)
            parts.append(f"{sig}{' ' + name if name else ''} := {shown}")
        via = f", through the interrupt of {self.via}" if self.via else ""
        return f"at {self.t:.3f} s, {', '.join(parts)} releases {Path(self.file).name}:{self.line} ({self.kind}{via})"

    @property
    def names(self) -> dict[str, str]:
        """signal -> name, for the signals the condition named."""
        return {sig: name for sig, name, _ in self.items if name}


@dataclass
class _Candidate:
    task: object
    frame: object
    node: N.Node
    kind: str
    expr: N.Expr
    order: int
    depth: int = 0
    via: str = ""           # the handler of the interrupt whose inputs answer it (_through_interrupts)


@dataclass
class _Atom:
    """An input the cell can set: one ``$IN`` bit (``last`` None) or a group."""

    first: int
    last: int | None
    name: str = ""

    @property
    def key(self) -> tuple:
        return (self.first, self.last)

    def signals(self, value) -> dict[str, bool]:
        if self.last is None:
            return {f"$IN[{self.first}]": bool(value)}
        return {f"$IN[{n}]": bool((int(value) >> i) & 1) for i, n in enumerate(range(self.first, self.last + 1))}


class AutoCell:
    """The automatic cell of one run (module docstring)."""

    def __init__(self, program, controller, names, scheduler, robot, tracing, delay: float = AUTO_DELAY_S,
                 programs=(), wired: frozenset = frozenset()) -> None:
        """For the run of `program` (program.Program: the statements), `controller`
        (robot/controller.py: the inputs read, the stimuli its answers become), `names`
        (names.Names: a condition's references), `scheduler` (scheduler.py Scheduler: the tasks
        watched) and the robot task `robot()` gives, writing ``answer`` events to `tracing`
        (tracing.py); an answer takes effect `delay` s after the run went idle. The inputs the
        `programs` (paths: the robot program, its submit programs) need for their production path
        are given at once (:meth:`give_production`). `wired`: the ``$IN`` numbers a partner robot's
        wire drives (a robot of a cell of several, interp/robotcell.py): the partner's to set,
        never given nor answered here (an input, or a group with one bit, among them)."""
        self.program = program
        self.controller = controller
        self.names = names
        self.scheduler = scheduler
        self.robot = robot
        self.tracing = tracing
        self.delay = delay
        self.answers: list[Answer] = []
        self._would: tuple = (None, None, False)   # :meth:`would_answer`'s last (key, frame, answer)
        self.recording: dict | None = None     # (task id, file, line, frame id) -> (task, info, frame, order)
        self.counts: dict = {}                 # (file, line) -> answers given
        self.rotation: dict = {}               # id(Switch node) -> next CASE index
        self._index: dict | None = None
        self._resolved: dict = {}               # a statement's file -> its resolved path
        self._scheduled: list = []              # the stimuli of its answers not yet applied
        self.production: list = []              # krl/semantics/inputflow.py Decisions it gave at the start
        self.wired = frozenset(wired)           # $IN numbers the cell's wires drive: not its own
        if programs:
            self.give_production(programs)

    def give_production(self, programs) -> None:
        """Gives, before the first statement, the values a producing cell gives the inputs
        the `programs` (paths: the robot program, its submit programs) read through variables or
        guard an error path with (krl/semantics/inputflow.py ``production_values``); each
        ``$IN`` bit set carries the source ``auto:production``."""
        prog = self.program
        roots = []
        for p in programs:
            m = prog.module_of(p)
            if m is not None and m.main is not None:
                roots.append(m.main)
        errors = prog.derived("error_routines", lambda pr: error_routines(pr.ws))
        walks = prog.derived("routine_walks", lambda pr: {})     # inputflow.py _walked: filled as asked
        self.production = list(prog.derived(("production_values", tuple(id(r) for r in roots)),
                                            lambda pr: tuple(production_values(pr.ws, roots, input_flow(pr), errors,
                                                                               walks))))
        self.production = [d for d in self.production if not self._driven(d.input.first, d.input.last)]
        io = self.controller.io
        for d in self.production:
            for sig, bit in d.input.bits(d.value).items():
                io.set_in(int(sig[4:-1]), bit, "auto:production")

    def _driven(self, first: int, last: int | None) -> bool:
        """True when an input of ``$IN[first]`` (to ``$IN[last]``, a group) is a wire's."""
        return bool(self.wired) and any(n in self.wired for n in range(first, (last or first) + 1))

    def behind(self, file: str, line: int) -> list:
        """The inputs (krl/semantics/inputflow.py Input) the statement at `file`:`line` depends
        on, each with the value it has now: [(Input, value)] (a run that ends on an error there
        says which inputs would change it)."""
        io = self.controller.io
        out = []
        for a in inputs_behind(self.program.ws, file, line, input_flow(self.program)):
            v = io.get_in(a.first) if a.last is None else \
                sum(1 << i for i, n in enumerate(range(a.first, a.last + 1)) if io.get_in(n))
            out.append((a, v))
        return out

    # ------------------------------------------------------------------ statements
    def record(self, task, info) -> None:
        """Called for every statement and loop iteration while the cell watches (Runtime)."""
        self.record_frame(task, info, task.frame)

    def record_frame(self, task, info, frame) -> None:
        """:meth:`record` of a statement `task` runs in `frame` (a parked spin's statements:
        interp/runtime/spin.py)."""
        rec = self.recording
        if rec is None or info is None:
            return
        key = (id(task), info.file, info.line, id(frame))
        if key not in rec:
            rec[key] = (task, info.file, info.line, frame, len(rec))

    def _statements(self, key_file: str) -> dict:
        """line -> the statements (IF, WHILE, REPEAT and its UNTIL, WAIT FOR, SWITCH) on that line
        of the program's file `key_file` (resolved), indexed when first asked for."""
        if self._index is None:
            self._index = {}
            for unit in self.program.ws.units:
                src = unit.src
                if src is not None and src.module is not None:
                    self._index.setdefault(str(Path(src.path).resolve()), []).append(src.module)
        idx = self._index.get(key_file)
        if isinstance(idx, list):
            modules, idx = idx, {}
            for module in modules:
                for node in module.walk():
                    if isinstance(node, (N.If, N.While, N.Repeat, N.WaitFor, N.Switch)) and node.span is not None:
                        idx.setdefault(node.span.line, []).append(node)
                    if isinstance(node, N.Repeat) and node.cond is not None and node.cond.span is not None:
                        idx.setdefault(node.cond.span.line, []).append(node)
            self._index[key_file] = idx
        return idx if idx is not None else {}

    def _nodes_at(self, file: str, line: int) -> list:
        if not file:
            return []
        key = self._resolved.get(file)
        if key is None:
            key = self._resolved[file] = str(Path(file).resolve())
        return self._statements(key).get(line, [])

    def pending(self) -> bool:
        """True while an answer has not taken effect yet."""
        for st in self._scheduled:      # (a loop: read at every moving IPO cycle, IdleWatch.moved)
            if not st.fired:
                return True
        return False

    def _wait_of(self, robot) -> list[_Candidate]:
        """The WAIT FOR the robot program `robot` (a Task, or None) waits in now, as the one
        candidate :meth:`answer` solves first; none when it waits in no WAIT FOR."""
        cands: list[_Candidate] = []
        if robot is not None and robot.waiting and robot.file:
            for node in self._nodes_at(robot.file, robot.line):
                if isinstance(node, N.WaitFor):
                    cands.append(_Candidate(robot, robot.frame, node, "WAIT FOR", node.cond, 0, 1 << 20))
        return cands

    def would_answer(self, robot) -> bool:
        """Whether :meth:`answer` would answer the WAIT FOR the robot program `robot` (a Task)
        waits in now, its inputs as they are, without answering it: a robot of a cell whose wait
        reads inputs alone is *blocked* there (its scheduler's ``deadlocked``) only when this is
        False, and a wait the cell can answer is answered when it would be in a run alone (the
        idle watch's window), not at once. Remembered for the wait's statement, its frame and the
        inputs' version (the condition of such a wait reads inputs and constants alone)."""
        key, frame = (robot.file, robot.line, self.controller.io.version), robot.frame
        if self._would[0] != key or self._would[1] is not frame:
            self._would = (key, frame, any(self._solvable(c) for c in self._wait_of(robot)))
        return self._would[2]

    def _solvable(self, c: _Candidate) -> bool:
        try:
            return self._solve(c) is not None
        except Unsolvable:
            return False

    # ------------------------------------------------------------------ answering
    def answer(self, watch) -> str:
        """The run is idle (or its WAIT FOR deadlocked): answer. Returns ``"answered"``,
        ``"watching"`` (a polling loop: the statements of one more window are recorded
        first) or ``"none"`` (nothing the cell can solve)."""
        robot = self.robot()
        cands = self._wait_of(robot)
        if not cands:
            if self.recording is None:
                self.recording = {}
                for t in self.scheduler.tasks:
                    break_quiet(t)
                return "watching"
            rec, self.recording = self.recording, None
            cands = self._candidates(rec)
        cands.sort(key=self._rank)
        for c in cands:
            try:
                got = self._solve(c)
            except Unsolvable:
                continue
            if got is None:
                continue
            atoms, values = got[0], got[1]
            if len(got) > 2:        # an interrupt's WHEN that holds: first FALSE, for its rising edge
                self._schedule(c, atoms, got[2])
                self._schedule(c, atoms, values, EDGE_S)
            else:
                self._schedule(c, atoms, values)
            return "answered"
        return "none"

    def _candidates(self, rec: dict) -> list[_Candidate]:
        out = []
        seen = set()
        for task, file, line, frame, order in rec.values():
            for node in self._nodes_at(file, line):
                key = (id(node), id(frame))
                if key in seen:
                    continue
                seen.add(key)
                depth = frame.depth if frame is not None else 0
                if isinstance(node, N.WaitFor):
                    out.append(_Candidate(task, frame, node, "WAIT FOR", node.cond, order, depth))
                elif isinstance(node, N.Repeat):
                    out.append(_Candidate(task, frame, node, "UNTIL", node.cond, order, depth))
                elif isinstance(node, N.While):
                    out.append(_Candidate(task, frame, node, "WHILE", node.cond, order, depth))
                elif isinstance(node, N.If):
                    out.append(_Candidate(task, frame, node, "IF", node.cond, order, depth))
                elif isinstance(node, N.Switch):
                    out.append(_Candidate(task, frame, node, "SWITCH", node.selector, order, depth))
        return out

    def _rank(self, c: _Candidate) -> tuple:
        return (0 if c.task.kind == "robot" else 1, -c.depth, _KIND_RANK.get(c.kind, 3),
                self.counts.get((c.node.span.file, c.node.span.line), 0), c.order)

    # ------------------------------------------------------------------ the solver
    def _solve(self, c: _Candidate):
        """(atoms, values) that give the candidate its target, or None."""
        atoms: dict = {}
        consts: list = []
        ev = _Eval(self.controller.io, self.names, c.frame, atoms, consts)
        current = ev.value(c.expr, {})
        if c.kind == "SWITCH":
            targets = self._case_values(c, ev, current)
            if not targets:
                return None

            def ok(v):
                return v in targets
        elif c.kind in ("WAIT FOR", "UNTIL"):
            def ok(v):
                return v is True
        elif c.kind == "WHILE":
            def ok(v):
                return v is False
        else:
            want = not current if isinstance(current, bool) else None
            if want is None:
                return None

            def ok(v):
                return v is want
        if ok(current) and c.kind != "SWITCH":
            return None         # it holds already: not what starves
        found = [a for a in atoms.values() if not self._driven(a.first, a.last)][:MAX_ATOMS]
        if not found:
            return self._through_interrupts(c, ev, ok) if c.kind != "SWITCH" else None
        alts = [self._alternatives(a, ev, consts, c) for a in found]
        tries = 0
        for k in range(1, len(found) + 1):
            for combo in itertools.combinations(range(len(found)), k):
                for vals in itertools.product(*(alts[i] for i in combo)):
                    tries += 1
                    if tries > MAX_TRIES:
                        return None
                    over = {found[i].key: v for i, v in zip(combo, vals)}
                    try:
                        got = ev.value(c.expr, over)
                    except (KrlRuntimeError, Unsolvable, TypeError):
                        continue
                    if ok(got):
                        if c.kind == "SWITCH":
                            self.rotation[id(c.node)] = self.rotation.get(id(c.node), 0) + 1
                        return [found[i] for i in combo], list(vals)
        return None

    def _through_interrupts(self, c: _Candidate, ev: "_Eval", ok):
        """(atoms, values) for a condition that reads no input but a flag an interrupt's handler
        sets (krl/semantics/inputflow.py ``interrupt_flags``): the inputs that make the
        interrupt's WHEN condition TRUE, when the flag's value gives the condition its target
        and the interrupt is on; None else, or when the WHEN holds already (no rising edge)."""
        flags = self.program.derived("interrupt_flags", lambda pr: interrupt_flags(pr.ws))
        if not flags:
            return None
        on = {i.name.upper() for t in self.scheduler.tasks for i in t.irqs.irqs.values() if i.on}
        for e in c.expr.walk():
            key = var_key(e, None) if isinstance(e, N.Name) else None
            for flag in flags.get(key, ()) if key is not None else ():
                if flag.handler not in on:
                    continue
                value = EnumValue(flag.value.name) if isinstance(flag.value, N.EnumLit) else flag.value
                ev.vars = {key: value}
                try:
                    got = ev.value(c.expr, {})
                except (KrlRuntimeError, Unsolvable, TypeError):
                    continue
                finally:
                    ev.vars = {}
                if not ok(got):
                    continue
                sub = _Candidate(c.task, c.frame, flag.decl, "WAIT FOR", flag.decl.when, c.order, c.depth)
                try:
                    solved = self._solve(sub)
                    if solved is None and ev.value(flag.decl.when, {}) is True:
                        # it holds: the inputs that make it FALSE, then their values now again
                        off = self._solve(_Candidate(c.task, c.frame, flag.decl, "WHILE", flag.decl.when,
                                                     c.order, c.depth))
                        if off is not None:
                            solved = (off[0], [ev.current(a) for a in off[0]], off[1])
                except (Unsolvable, KrlRuntimeError, TypeError):
                    continue
                if solved is not None:
                    c.via = flag.handler
                    return solved
        return None

    def _case_values(self, c: _Candidate, ev: "_Eval", current) -> list:
        """The CASE values of a SWITCH other than the one taken now, the next in turn first."""
        values = []
        for case in c.node.cases:
            for v in case.values:
                try:
                    x = ev.value(v, {})
                except (KrlRuntimeError, Unsolvable):
                    continue
                if x != current and x not in values:
                    values.append(x)
        if not values:
            return []
        i = self.rotation.get(id(c.node), 0) % len(values)
        return [values[i]]

    def _alternatives(self, atom: _Atom, ev: "_Eval", consts: list, c: _Candidate) -> list:
        cur = ev.current(atom)
        if atom.last is None:
            return [not cur]
        width = atom.last - atom.first + 1
        cands = []
        if c.kind == "SWITCH":
            cands += self._case_values(c, ev, None)
        cands += [x for x in consts if isinstance(x, int) and not isinstance(x, bool)]
        cands += [x + 1 for x in consts if isinstance(x, int) and not isinstance(x, bool)]
        cands += [1, 0]
        out = []
        for x in cands:
            if isinstance(x, int) and not isinstance(x, bool) and 0 <= x < (1 << width) and x != cur and x not in out:
                out.append(x)
        return out

    def _schedule(self, c: _Candidate, atoms: list, values: list, later: float = 0.0) -> None:
        ctl = self.controller
        tracing = self.tracing

        sets: dict[str, bool] = {}
        items = []
        for a, v in zip(atoms, values):
            sets.update(a.signals(v))
            sig = f"$IN[{a.first}]" if a.last is None else f"$IN[{a.first}..{a.last}]"
            items.append((sig, a.name, bool(v) if a.last is None else int(v)))
        at = ctl.time + self.delay + later
        span = c.node.span
        answer = Answer(at, items, sets, span.file, span.line, c.kind, _text(c.expr), c.via)
        key = (span.file, span.line)
        self.counts[key] = self.counts.get(key, 0) + 1

        def fired(t, answer=answer):
            answer.t = t
            self.answers.append(answer)
            trace = tracing.writer
            if trace is not None:
                trace.write("answer", t, sets={sig: v for sig, _, v in answer.items},
                            names=answer.names or None,
                            file=answer.file, line=answer.line, statement=answer.kind,
                            condition=answer.text or None)

        # the answers that took effect leave the controller's stimuli (it looks at each one
        # at every IPO cycle); what they did is in self.answers
        self._scheduled = [st for st in self._scheduled if not st.fired]
        ctl.signals.stimuli[:] = [st for st in ctl.signals.stimuli if not (st.source == "auto" and st.fired)]
        st = Stimulus(set=dict(sets), at=at, source="auto", on_fire=fired,
                      where=f"--inputs auto: {Path(span.file).name}:{span.line}")
        self._scheduled.append(st)
        ctl.signals.stimuli.append(st)


def program_numbers(loaded) -> list[int]:
    """The CASE values (INT constants, in source order) of every ``SWITCH PGNO`` of the
    program's files, where PGNO is the variable of ``$config.dat`` (the checker's symbol, not
    the spelling); empty when there is none. Found once per checked workspace
    (interp/runtime/program.py ``Program.derived``); a new list each call."""
    return list(loaded.program.derived("program_numbers", _program_numbers))


def _program_numbers(program) -> tuple[int, ...]:
    out: list[int] = []
    for value, _span in pgno_cases(program):
        if value not in out:
            out.append(value)
    return tuple(out)


def pgno_cases(program) -> list[tuple[int, object]]:
    """(value, span) of every INT constant CASE of every ``SWITCH PGNO`` of the program's files
    (interp/runtime/program.py Program), in source order, where PGNO is the variable of
    ``$config.dat`` (the checker's symbol, not the spelling); empty when there is none. Found
    once per checked workspace (``Program.derived``: a walk over every node, 0.6 s on
    ChinaMilling, was paid by each of its entry points); a new list each call."""
    return list(program.derived("pgno_cases", _pgno_cases))


def _pgno_cases(program) -> tuple[tuple[int, object], ...]:
    ws = program.ws
    scope = getattr(ws, "global_scope", None)
    sym = scope.values.get("PGNO") if scope is not None else None
    if sym is None:
        return []
    out = []
    for unit in ws.units:
        src = unit.src
        if src is None or src.module is None:
            continue
        for node in src.module.walk():
            if not isinstance(node, N.Switch) or not isinstance(node.selector, N.Name):
                continue
            ann = node.selector.ann
            if ann is None or ann.symbol is not sym:
                continue
            out += [(v.value, v.span) for case in node.cases for v in case.values if isinstance(v, N.IntLit)]
    return tuple(out)


def handshake_rules(loaded, main: str, params: dict) -> list:
    """The PLC's rules of P00's program-number handshake (robot/cellpresets.py) for the
    automatic cell: the numbers of :func:`program_numbers` in turn (each request gets the
    next one; 1 when the program selects none), or [] when the backup's ``$config.dat`` lacks
    a parameter or does not allow the preset."""

    numbers = program_numbers(loaded) or [1]
    try:
        rules = pgno_rules(params, numbers[0])
    except PresetError:
        return []
    request = rules[0]
    turn = {"i": 0}
    fixed = {k: v for k, v in request.set.items()}

    def next_number(rule, t):
        turn["i"] = (turn["i"] + 1) % len(numbers)
        try:
            bits = pgno_bits(numbers[turn["i"]], params["PGNO_TYPE"], params["PGNO_LENGTH"])
        except PresetError:
            return
        new = dict(fixed)
        fbit = params["PGNO_FBIT"]
        odd = False
        for i, b in enumerate(bits):
            new[f"$IN[{fbit + i}]"] = b
            odd = odd != b
        par = params["PGNO_PARITY"]
        if par > 0:
            new[f"$IN[{par}]"] = odd
        elif par < 0:
            new[f"$IN[{-par}]"] = not odd
        rule.set = new

    for r in rules:
        r.source = "auto:pgno"
        r.where = "--inputs auto: P00's program number"
    request.on_fire = next_number
    return rules


def _text(e: N.Expr) -> str:
    """The source text of the line holding `e` (printable, at most 120 characters)."""
    span = e.span
    if span is None or not span.file:
        return ""
    try:
        lines = read_source(span.file).text.splitlines()
        return printable(lines[span.line - 1].split(";", 1)[0].strip())[:120]
    except Exception:  # noqa: BLE001 - the text is a courtesy
        return ""


class _Eval:
    """Evaluates a condition in a frame with some inputs replaced (the solver's)."""

    def __init__(self, io, names, frame, atoms: dict, consts: list) -> None:
        self.io = io                # robot.io.IOImage: the inputs' values now
        self.names = names          # names.Names: the condition's references
        self.frame = frame
        self.atoms = atoms
        self.consts = consts
        self.vars: dict = {}        # variable key (inputflow.var_key) -> the value it is taken to have

    def current(self, atom: _Atom):
        io = self.io
        if atom.last is None:
            return io.get_in(atom.first)
        return sum(1 << i for i, n in enumerate(range(atom.first, atom.last + 1)) if io.get_in(n))

    def value(self, e, over: dict):
        c = e.__class__
        if c in (N.IntLit, N.RealLit, N.BoolLit, N.StrLit):
            if c is N.IntLit and e.value not in self.consts:
                self.consts.append(e.value)
            return e.value
        if c is N.EnumLit:
            return EnumValue(e.name)
        if c is N.Unary:
            return unary_op(e.op, self.value(e.operand, over))
        if c is N.Binary:
            return binary_op(e.op, self.value(e.left, over), self.value(e.right, over))
        if c is N.Name and self.vars:
            key = var_key(e, None)
            if key in self.vars:
                return self.vars[key]
        if c in (N.Name, N.Index, N.Field):
            ref = self.ref(e, over)
            atom = _atom_of(ref)
            if atom is not None:
                if c is N.Name and not atom.name:
                    atom.name = getattr(ref, "name", "") if isinstance(ref, SignalRef) else ""
                self.atoms.setdefault(atom.key, atom)
                if atom.key in over:
                    return over[atom.key]
                return self.current(atom)
            v = ref.get()
            return v
        raise Unsolvable(type(e).__name__)

    def ref(self, e, over: dict):
        names = self.names
        if e.__class__ is N.Name:
            st = e.ann.place if e.ann is not None else None
            if st is None:
                raise Unsolvable(e.name)
            return names.storage_ref(st, self.frame)
        if isinstance(e, N.Index):
            base = self.ref(e.base, over)
            idx = []
            for i in e.indices:
                v = self.value(i, over) if i is not None else None
                if v is not None and (not isinstance(v, int) or isinstance(v, bool)):
                    raise Unsolvable("index")
                idx.append(v)
            return names.index(base, idx, getattr(e.base, "name", "?"))
        if isinstance(e, N.Field):
            return names.field(self.ref(e.base, over), e.name, "?")
        raise Unsolvable(type(e).__name__)


def _atom_of(ref) -> _Atom | None:
    """The input a reference reads: a ``$IN`` element, a SIGNAL on ``$IN``; else None."""
    if isinstance(ref, SignalRef) and getattr(ref.proxy, "name", "").upper() == "$IN":
        return _Atom(ref.a, ref.b, ref.name)
    if isinstance(ref, ProxyRef) and getattr(ref.proxy, "name", "").upper() == "$IN" \
            and ref.index != ALWAYS_TRUE_INPUT:
        return _Atom(ref.index, None)
    return None
