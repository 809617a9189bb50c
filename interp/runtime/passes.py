"""A pass of a task's loop and what it reads and writes: the recorded pass (:class:`Pass`, which a
period extends), a parked task (:class:`Parked`), the classes of names and statements the spin
watch (spin.py) and its periods (period.py) share, and a pass's comparisons of running timers with
constants (:func:`timer_compares`, :func:`crosses`, :func:`clock_reads`)."""

from __future__ import annotations

from krl.ast import nodes as N
from krl.semantics.advance import accesses
from krl.semantics.facts import CLOCK, REPEAT, ROBOT, SIGNALS, STATE, TASKS
from krl.semantics.resolve import LOCAL, NATIVE, ROUTINE, STUB, SYSTEM, UNRESOLVED
from krl.semantics.statements import KINDS, kinds_where

from .idle import root
from .memory import Slot
from .natives import REGISTRY
from .sysvars import _LIVE, CONSTANT_NAMES, STORED_STATE, live_reading

#: built-ins whose only effects are on their arguments and that read nothing that changes by itself:
#: declared ``pure`` in the natives registry (not FRAND, CWRITE, PULSE, EKI_* ...: a pass calling one
#: is never parked; a stand-in of KUKA's software is, its calls counted per step: :func:`stub_uses`)
PURE_NATIVES = frozenset(name for name, native in REGISTRY.items() if native.pure)

#: system variables the main run changes as the robot moves (``reads=ROBOT`` in sysvars.py ``_LIVE``):
#: probed as the state variables are (spin.py ``SpinWatch._hold``)
MOTION_NAMES = live_reading(ROBOT)
#: the I/O image's system variables (``reads=SIGNALS``): they change between steps only at the
#: controller's events
IO_NAMES = live_reading(SIGNALS)
#: system variables the run's tasks change (``reads=TASKS`` or ``STATE``: $PRO_STATE1, $MODE_OP ...)
#: and the stored ones whose components change beside a statement's write (``$TRACE``): probed
STATE_NAMES = live_reading(TASKS, STATE) | STORED_STATE
#: system variables whose reads read the clock ($DATE, $ROBRUNTIME: ``reads=CLOCK``)
CLOCK_NAMES = live_reading(CLOCK)

#: the statements a spin may execute: the kinds whose facts say REPEAT (krl/semantics/statements.py)
ALLOWED = kinds_where(lambda f: f.fast_forward == REPEAT)

#: the longest pass recorded, in steps
MAX_PASS_STEPS = 2048


class Pass:
    """A recorded spin: ``events`` ((file, line, loop iteration?, depth below the loop's frame)
    per step, the loop iteration that ends the pass last), per step ``infos`` (StmtInfo), ``at``
    (the statement the task stands at after it), ``frames`` (its innermost frame) and ``images``
    (its frames as the idle watch images them); ``io`` (it reads I/O), ``motion`` (the robot's
    position or motion, among its probes), ``cyclic`` (``$CYCFLAG``), ``probes`` (the state
    variables it reads)."""

    __slots__ = ("events", "infos", "at", "frames", "images", "io", "motion", "cyclic", "probes", "refs",
                 "stub_lines", "stubs", "trans", "compares", "clocked", "reads", "decides", "seen")
    periodic = False

    def __init__(self, events, infos, at, frames, images) -> None:
        self.events = events
        self.infos = infos
        self.at = at
        self.frames = frames
        self.images = images
        self.io = False
        self.motion = False
        self.cyclic = False
        self.probes: tuple = ()
        self.refs = None            # the references of the probes, found when first read
        self.stub_lines: dict = {}  # (file, line) -> UPPER names of the stand-ins it calls, one per call
        self.stubs = None           # per step: those names (from stub_lines, when first asked)
        self.trans = None           # the values it changes and puts back (interp/runtime/transient.py)
        # ((timer, operator, constant), ...): its reads of $TIMER, each a comparison with a
        # constant (:func:`timer_compares`); None: it reads $TIMER otherwise, or $TIMER_FLAG
        self.compares: tuple | None = ()
        self.clocked = False        # it reads a clock variable ($DATE, ...: CLOCK_NAMES)
        # with a running timer compared: the task's clock reads to each step (:func:`clock_reads`)
        self.reads: tuple | None = None
        # what decides it (:func:`touched`; None: not known) and its image where it parked
        # (period.py ``PeriodicSpins._image``)
        self.decides = self.seen = None

    @property
    def steps(self) -> int:
        return len(self.events)


class Parked:
    """A parked task: its pass or period, the step of it the task parked at (``pos0``: 0 for a
    pass, a boundary of a period), the steps it has taken since (``done``), the I/O version it saw
    and the values of the state variables its pass reads."""

    __slots__ = ("spin", "done", "io_version", "probed", "expect", "pos0", "seen", "fed", "served")

    def __init__(self, spin, done: int, io_version: int, probed: tuple, pos0: int = 0) -> None:
        self.spin = spin
        self.done = done
        self.io_version = io_version
        self.probed = probed
        self.expect = 0
        self.pos0 = pos0
        self.seen = -1              # a shadow: the IPO cycle its task was last given
        self.fed = (None, 0)        # (an automatic cell's recording, the steps of the pass fed to it)
        self.served = None          # the robot's motion as its pass read it: name -> value (spin.py wake)

    def step(self) -> int:
        """The step of the pass (the period) the task stands at: the last one counted."""
        return (self.pos0 + self.done - 1) % self.spin.steps


def stub_step(node, info, on_line) -> bool:
    """A stand-in call in statement `node` (StmtInfo `info`, the statements of its line
    `on_line`) can be counted by its step: the statement is alone on its line and its kind's facts
    say ``stub_once`` (krl/semantics/statements.py: it runs exactly once at its step)."""
    return info is not None and KINDS[node.__class__].facts.stub_once and len(on_line or ()) == 1


def stub_uses(spin: Pass, start: int, count: int, into) -> None:
    """Add to the counter `into` (kss.py ``SystemSoftware.uses``) the stand-in calls of the
    `count` steps of `spin` from step `start` on (cyclically), which parking counted, not ran."""
    if not spin.stub_lines or count <= 0:
        return
    steps = spin.stubs
    if steps is None:
        lines = spin.stub_lines
        steps = spin.stubs = tuple([() if tick else lines.get((f, line), ()) for f, line, tick, _d in spin.events])
    n = len(steps)
    whole, rest = divmod(count, n)
    if whole:
        for names in steps:
            for name in names:
                into[name] += whole
    for i in range(start, start + rest):
        for name in steps[i % n]:
            into[name] += 1


def analyse(nodes, events, statements, facts: dict) -> "Pass | None":
    """What a recorded pass reads: `nodes`, the statements it executed, `events` its steps;
    `statements` (``SpinWatch.statements``) the statements at a StmtInfo's line; `facts`, id(node)
    -> :func:`node_facts`, kept by the caller. None when it is not a spin."""
    io = motion = cyclic = clocked = False
    probes = []
    stub_lines = {}
    compares: set | None = set()
    for node in nodes:
        if node is None:
            continue
        f = facts.get(id(node), False)
        if f is False:
            f = facts[id(node)] = node_facts(node, statements)
        if f is None:
            return None
        io, motion, cyclic, clocked = io or f[0], motion or f[1], cyclic or f[2], clocked or f[3]
        for key in f[4]:
            if key not in probes:
                probes.append(key)
        for where, name in f[5]:
            stub_lines[where] = stub_lines.get(where, ()) + (name,)
        compares = None if compares is None or f[6] is None else compares | set(f[6])
    spin = Pass(tuple(events), None, None, None, None)
    spin.io, spin.motion, spin.cyclic, spin.probes = io, motion, cyclic, tuple(probes)
    spin.stub_lines = stub_lines
    spin.compares = None if compares is None else tuple(sorted(compares, key=repr))
    spin.clocked = clocked
    return spin


def node_facts(node, statements) -> "tuple | None":
    """What statement `node` contributes to :func:`analyse`: (reads I/O, reads the robot's motion,
    reads $CYCFLAG, reads a clock variable, the state variables it reads, its stand-in calls
    ((file, line), NAME), its timer comparisons (:func:`timer_compares`)); None when a pass that
    runs it is not a spin."""
    io = motion = cyclic = clocked = False
    probes = []
    stubs = []
    acc, cond = accesses(node)
    if isinstance(node, N.For):
        acc = acc + [("w", node.var)]
    for mode, x in acc + cond:
        if mode == "call":
            callee = getattr(x.ann, "callee", None) if x.ann is not None else None
            if callee is None:
                return None
            if callee.kind == STUB or (callee.kind == NATIVE and callee.native is None):
                # a stand-in (kss.py): reads nothing, the same value at every call
                info = getattr(node.ann, "info", None) if node.ann is not None else None
                if not stub_step(node, info, statements(info) if info is not None else None):
                    return None
                stubs.append(((info.file, info.line), callee.name.upper()))
                continue
            if callee.kind != ROUTINE and (callee.kind != NATIVE or callee.name.upper() not in PURE_NATIVES):
                return None
            continue
        place = getattr(x.ann, "place", None) if x.ann is not None else None
        sym = place.symbol if place is not None else None
        if sym is not None and sym.kind == "signal":
            io = True
            continue
        if place is None or place.kind not in (SYSTEM, UNRESOLVED):
            continue
        key = place.name.upper()
        if key in CLOCK_NAMES:
            clocked = True
        if key in IO_NAMES:
            io = True
        elif key in MOTION_NAMES:
            motion = True           # read like any other state: probed (spin.py ``_hold``)
            if key not in probes:
                probes.append(key)
        elif key == "$CYCFLAG":
            cyclic = True
        elif key in STATE_NAMES and key not in probes:
            probes.append(key)
    return io, motion, cyclic, clocked, tuple(probes), tuple(stubs), timer_compares(node)


#: the comparison operators of :func:`timer_compares`, as Python's
COMPARE = {"<": int.__lt__, ">": int.__gt__, "<=": int.__le__, ">=": int.__ge__, "==": int.__eq__, "<>": int.__ne__}
_MIRROR = {"<": ">", ">": "<", "<=": ">=", ">=": "<=", "==": "==", "<>": "<>"}


def _constant(e):
    """The INT value of literal `e` (``5000``, ``-12``); None for anything else."""
    if e.__class__ is N.Unary and e.op == "-":
        v = _constant(e.operand)
        return None if v is None else -v
    return e.value if e.__class__ is N.IntLit else None


def _timer_index(e):
    """The timer's number of ``$TIMER[k]`` (k a literal); None for anything else."""
    if e.__class__ is not N.Index or e.base.__class__ is not N.Name or len(e.indices) != 1:
        return None
    place = getattr(e.base.ann, "place", None) if e.base.ann is not None else None
    if place is None or place.kind not in (SYSTEM, UNRESOLVED) or place.name.upper() != "$TIMER":
        return None
    return _constant(e.indices[0]) if e.indices[0] is not None else None


def timer_compares(node) -> "tuple | None":
    """The comparisons of a running timer with an INT constant in statement `node`'s own
    expressions (``IF $TIMER[1] > 3000 THEN``: ``((1, '>', 3000),)``, the timer's side first); None
    when it reads ``$TIMER`` or ``$TIMER_FLAG`` in any other way (a write's target is no read)."""
    out = []
    stack = _expressions(node)
    while stack:
        e = stack.pop()
        if e.__class__ is N.Binary and e.op in COMPARE:
            for a, b, op in ((e.left, e.right, e.op), (e.right, e.left, _MIRROR[e.op])):
                k, c = _timer_index(a), _constant(b)
                if k is not None and c is not None:
                    out.append((k, op, c))
                    break
            else:
                stack += [e.left, e.right]
            continue
        if e.__class__ is N.Name:
            place = getattr(e.ann, "place", None) if e.ann is not None else None
            if place is not None and place.kind in (SYSTEM, UNRESOLVED) and \
                    place.name.upper() in ("$TIMER", "$TIMER_FLAG"):
                return None
            continue
        stack += e.children()
    return tuple(out)


def _expressions(node) -> list:
    """The expressions statement `node` evaluates itself (not those of the statements it holds):
    an assignment's value and its target's indices (the target's own name is written), a
    SWITCH's case values."""
    out = []
    for c in node.children():
        if node.__class__ is N.Assign and c is node.target:
            while c.__class__ in (N.Index, N.Field):
                out += [i for i in c.indices if i is not None] if c.__class__ is N.Index else []
                c = c.base
            if c.__class__ is not N.Name:
                out.append(c)
        elif isinstance(c, N.Expr):
            out.append(c)
        elif c.__class__ is N.Case:
            out += c.values
    return out


class StatementIndex:
    """The statements of a loaded program by the file and line of their StmtInfo (the VM has
    its own): ``index(info)`` is a tuple, None when there is none; a file indexed when first asked
    for. A fact of the checked workspace's ASTs alone: one per workspace (``Program.derived``)."""

    def __init__(self, program) -> None:
        self.ws = program.ws
        self.files: dict | None = None

    def __call__(self, info):
        files = self.files
        if files is None:
            # filled before it is shared: the runs of one model may ask from two threads at once
            files = {}
            for unit in self.ws.units:
                src = unit.src
                if src is not None and src.module is not None:
                    files.setdefault(str(src.path), []).append(src.module)
            self.files = files
        nodes = files.get(info.file)
        if isinstance(nodes, list):
            modules, nodes = nodes, {}
            for module in modules:
                for node in module.walk():
                    ann = node.ann
                    i = getattr(ann, "info", None) if ann is not None else None
                    if i is not None:
                        key = (i.file, i.line)
                        nodes[key] = nodes.get(key, ()) + (node,)
            files[info.file] = nodes
        return nodes.get((info.file, info.line)) if nodes is not None else None


def step_plan(nodes, tick: bool, targets: dict) -> tuple:
    """``(allowed, writers)`` of a recorded step whose statements are `nodes` (None: none known):
    whether they may be in a pass (:data:`ALLOWED`; a loop iteration is), and those of them that
    write something but an I/O or a constant system variable (:func:`written`, kept in `targets`
    by id; a FOR's iteration writes its counter)."""
    ok = tick or (nodes is not None and all(isinstance(n, ALLOWED) for n in nodes))
    writers = []
    for n in nodes or ():
        if not tick or isinstance(n, N.For):
            names = targets.get(id(n))
            if names is None:
                names = targets[id(n)] = written(n)
            for name in names:
                place = getattr(name.ann, "place", None) if name.ann is not None else None
                if place is None or place.kind not in (SYSTEM, UNRESOLVED) or \
                        (place.name.upper() not in IO_NAMES and place.name.upper() not in CONSTANT_NAMES):
                    writers.append(n)
                    break
    return ok, tuple(writers)


def written(node) -> tuple:
    """The names statement `node` writes: its assignment target, a FOR's counter, and every
    variable passed to a built-in (its :OUT arguments; an :IN one is written by nothing, so
    counting it only costs a comparison)."""
    out = []
    acc, cond = accesses(node)
    for mode, x in acc + cond:
        if mode == "w":
            out.append(x)
        elif mode == "call":
            callee = getattr(x.ann, "callee", None) if x.ann is not None else None
            if callee is not None and callee.kind == NATIVE:
                out += [r for r in map(root, x.args) if r is not None]
    if isinstance(node, N.For):
        r = root(node.var)
        if r is not None:
            out.append(r)
    return tuple(out)


def clock_reads(spin: Pass, m: int) -> int:
    """The clock reads of `spin`'s task from the hook of its boundary's step to the hook of the
    `m`-th step after it (``Pass.reads``; 0 without reads)."""
    reads = spin.reads
    if reads is None or m <= 0:
        return 0
    n = len(reads)
    whole, rest = divmod(m, n)
    return whole * reads[-1] + (reads[rest - 1] if rest else 0)


def crosses(spin: Pass, io, dt_ms: int, steps: int = 1) -> bool:
    """One of `spin`'s timer comparisons (``Pass.compares``) changes its value within the next
    `steps` controller steps, each advancing the running timers of I/O image `io` by `dt_ms`
    (robot/io.py)."""
    for k, op, c in spin.compares or ():
        if 1 <= k < len(io.timer_stop) and not io.timer_stop[k]:
            t = io.timer_ms[k]
            f = COMPARE[op]
            now = f(t, c)
            for m in range(1, steps + 1):
                if f(t + m * dt_ms, c) != now:
                    return True
    return False


def served(spin: Pass, refs, probed: tuple) -> "dict | None":
    """The values of the robot's motion (:data:`MOTION_NAMES`) among `spin`'s probes (their
    references `refs`; `probed` unused): what a catch-up's steps read (sysvars.py
    ``SysVars.served``); None when it reads none."""
    if not spin.motion:
        return None
    return {k: r.peek() for k, r in zip(spin.probes, refs) if k in MOTION_NAMES}


def only_motion_changed(spin: Pass, now: tuple, before: tuple) -> bool:
    """Of `spin`'s probes, only the robot's motion changed from `before` to `now`."""
    return all(a == b or k in MOTION_NAMES for k, a, b in zip(spin.probes, now, before))


def copy_with(spin: Pass, rec) -> Pass:
    """`spin` (an analysis, shared by passes of the same steps) with what recording `rec` holds of
    this one (StmtInfos, positions, frames, images, transients, clock reads)."""
    out = Pass(spin.events, rec.infos, rec.at, rec.frames, rec.images)
    out.io, out.motion, out.cyclic, out.probes = spin.io, spin.motion, spin.cyclic, spin.probes
    out.stub_lines = spin.stub_lines
    out.trans = rec.trans if rec.trans.order else None
    out.compares, out.clocked = spin.compares, spin.clocked
    out.reads = tuple(rec.creads) if rec.creads and rec.creads[-1] else None
    out.decides = spin.decides
    return out


def touched(nodes, ref_of) -> "tuple | None":
    """What the statements `nodes` of a pass read or write that outlives it and its probes do not
    image: ``(references, whole, order)``: the references (`ref_of(place, index or None)`) of the
    data-list variables and signals they name and of each I/O element named by a literal index
    (``$OUT[49]``); `whole` when they name the I/O image otherwise (``$IN[N]``); `order` the
    references' positions, the I/O's first (period.py ``_stands``). None when a name cannot be
    placed or is a computed system variable the probes leave out (the clock). Locals are in the
    frames' image. Two passes that start over the same values of these, probes and frames run the
    same steps and write the same values (period.py ``PeriodicSpins._replays``)."""
    refs: dict = {}
    whole = False
    for node in nodes:
        at: dict = {}       # id(the name of an I/O element a literal index names) -> the index
        for child in node.children():
            if isinstance(child, N.Expr):
                for e in child.walk():
                    if e.__class__ is N.Index and e.base.__class__ is N.Name and len(e.indices) == 1 and \
                            e.indices[0].__class__ is N.IntLit:
                        at[id(e.base)] = e.indices[0].value
        acc, cond = accesses(node)
        for mode, x in acc + cond + ([("w", root(node.var))] if isinstance(node, N.For) else []):
            if mode == "call":
                continue
            place = getattr(x.ann, "place", None) if x is not None and x.ann is not None else None
            if place is None:
                return None
            if place.kind == LOCAL:
                continue
            key = place.name.upper()
            if place.kind in (SYSTEM, UNRESOLVED) and key in _LIVE:       # computed: classed
                if key not in IO_NAMES:
                    if key not in CONSTANT_NAMES and key not in MOTION_NAMES and key not in STATE_NAMES:
                        return None
                elif id(x) in at:
                    k = at[id(x)]
                    if (key, k) not in refs:
                        refs[(key, k)] = ref_of(place, k)
                else:
                    whole = True
                continue
            where = (place.kind, getattr(place, "owner", None), place.slot, key)
            if where not in refs:
                refs[where] = ref_of(place, None)
    if None in refs.values():
        return None
    refs = tuple(refs.values())
    return refs, whole, tuple(sorted(range(len(refs)), key=lambda i: refs[i].__class__ is Slot))
