"""When an interrupt condition, or a cyclic flag's expression, must be evaluated again
(reference §5.16, "the condition is monitored"; issue 39; §5.15 and issue 48 for cyclic flags,
:class:`CyclicWatch` at the end).

An armed interrupt's condition is polled at every statement boundary and every IPO cycle of
its task (interrupts.py ``Interrupts.check``). Its value can only change when something it reads
changes, so each condition gets a *watch* class from the names it reads (krl/semantics/advance.py
:func:`~krl.semantics.advance.reads`, and each name's Storage from the resolver):

* :data:`CONSTANT` — it reads nothing that changes in a run: literals and the constant system
  variables (sysvars.py ``CONSTANT_NAMES``). Its value is the one taken at ``INTERRUPT ON``.
* :data:`IO` — it reads also ``$IN``, ``$OUT``, ``$ANIN``, ``$ANOUT`` or a SIGNAL over one
  of them: evaluated again when the I/O image changed (robot/io.py ``IOImage.version``).
* :data:`CLOCK` — it reads a timer (``$TIMER``, ``$TIMER_FLAG``, ``$TIMER_STOP``, a SIGNAL
  over another live array): evaluated again when the I/O image changed or the time advanced.
* *probed* names — computed scalar system variables of the run's state (sysvars.py
  ``PROBED_NAMES``: ``$PRO_STATE1``, ``$PRO_MOVE``, ``$MODE_OP``, ...) add to any class their
  current values, read straight from the system variable: the watch string is
  ``CLASS:NAME,NAME``. Those of sysvars.py ``EPOCH_PROBED`` are read once per state epoch.
* :data:`SETTLES` — it reads variables too (a data list's, a global, the declaring frame's,
  stored system variables such as ``$CYCFLAG``; :func:`settles`): evaluated again when the I/O
  image changed, a statement ran or a cyclic flag changed (:meth:`CyclicWatch.written`).
* :data:`ALWAYS` — anything else (a function call, a computed structured system variable such
  as ``$POS_ACT``, a name the resolver did not place, variables beside a timer): evaluated at
  every poll.

:func:`stamp_key` gives the key a poll compares with the key of the condition's last
evaluation: equal keys mean every value the condition reads is the same, so the poll keeps its
value (no edge), as evaluating at every poll would.
"""

from __future__ import annotations

from krl.ast import nodes as N
from krl.semantics.advance import reads
from krl.semantics.builtins import load_builtins
from krl.semantics.resolve import SYSTEM

from .sysvars import _LIVE, CONSTANT_NAMES, PROBED_NAMES

CONSTANT, IO, CLOCK, ALWAYS = "K", "I", "T", ""
SETTLES = "V"
_ORDER = {CONSTANT: 0, IO: 1, CLOCK: 2, ALWAYS: 3}
_IO_ARRAYS = frozenset({"$IN", "$OUT", "$ANIN", "$ANOUT"})
_CLOCK_ARRAYS = frozenset({"$TIMER", "$TIMER_FLAG", "$TIMER_STOP"})


def _name_watch(node: N.Name, probes: list) -> str:
    place = getattr(node.ann, "place", None) if node.ann is not None else None
    if place is None:
        return ALWAYS
    if place.kind == SYSTEM:
        key = place.name.upper()
        if key not in load_builtins().sysvars:
            return ALWAYS             # a data list's value (SysVars._unsimulated): a variable
        if key in PROBED_NAMES and key not in probes:
            probes.append(key)
        if key in PROBED_NAMES or key in CONSTANT_NAMES:
            return CONSTANT
        return IO if key in _IO_ARRAYS else CLOCK if key in _CLOCK_ARRAYS else ALWAYS
    sym = place.symbol
    if sym is not None and sym.kind == "signal":
        decl = sym.decl
        start = getattr(decl, "start", None)
        if isinstance(decl, N.SignalDecl) and start is not None:
            return IO if start.sysvar.upper() in _IO_ARRAYS else CLOCK
    return ALWAYS


def watch_of(expr, skip: frozenset = frozenset()) -> str:
    """The watch class of condition `expr` (a resolved expression AST; module docstring);
    `skip`: the ids of Name nodes left out (the timers of :func:`timer_watch`)."""
    worst = CONSTANT
    probes: list = []
    acc = reads(expr)
    if skip:
        acc = [(mode, node) for mode, node in acc if id(node) not in skip]
    for mode, node in acc:
        w = ALWAYS if mode != "r" else _name_watch(node, probes)
        if _ORDER[w] > _ORDER[worst]:
            worst = w
            if worst == ALWAYS:
                break
    if worst == ALWAYS:
        # a condition over variables (and I/O, constants, probed state): SETTLES
        probes = []
        for mode, node in acc:
            w = _name_watch(node, probes) if mode == "r" else ALWAYS
            if w == CLOCK or (w == ALWAYS and not _settles_name(node)):
                return ALWAYS
        worst = SETTLES
    return worst + (":" + ",".join(probes) if probes else "")


_RELOPS = frozenset({"<", "<=", ">", ">=", "==", "<>"})


def _timer_of(e) -> "tuple[int, N.Name] | None":
    """``(n, the $TIMER name)`` of ``$TIMER[n]`` with a literal index n, else None."""
    if e.__class__ is not N.Index or e.base.__class__ is not N.Name or len(e.indices) != 1 \
            or e.indices[0].__class__ is not N.IntLit:
        return None
    place = getattr(e.base.ann, "place", None) if e.base.ann is not None else None
    if place is None or place.kind != SYSTEM or place.name.upper() != "$TIMER":
        return None
    return e.indices[0].value, e.base


def _number(e) -> "float | None":
    """The value of a number literal (``-`` before it allowed), else None."""
    sign = 1
    if e.__class__ is N.Unary and e.op in ("-", "+"):
        sign = -1 if e.op == "-" else 1
        e = e.operand
    if e.__class__ is N.IntLit or e.__class__ is N.RealLit:
        return sign * e.value
    return None


def timer_watch(expr) -> "tuple[str, tuple[tuple[int, float], ...]] | None":
    """A condition that reads the clock only by comparing running timers with numbers
    (``WAIT FOR VACOESTATO OR ($TIMER[1] >= 2000)``): ``(watch string of the rest of it,
    ((n, bound), ...) for each comparison ``$TIMER[n] op bound`` or ``bound op $TIMER[n]``)``,
    n and bound literals, op one of ``< <= > >= == <>``. None when a timer is read otherwise
    (an index computed, compared with a variable, in arithmetic) or none is. Such a comparison
    can change its value only once the timer reaches the bound (:func:`timer_due`; issue 48)."""
    tests = []
    matched = set()
    for e in expr.walk():
        if e.__class__ is not N.Binary or e.op not in _RELOPS:
            continue
        for t, b in ((e.left, e.right), (e.right, e.left)):
            tm = _timer_of(t)
            bound = _number(b) if tm is not None else None
            if bound is not None:
                tests.append((tm[0], float(bound)))
                matched.add(id(tm[1]))
                break
    if not tests or any(e.__class__ is N.Name and id(e) not in matched and e.name.upper() in _CLOCK_ARRAYS
                        for e in expr.walk()):      # (a timer read that is no such comparison)
        return None
    return watch_of(expr, frozenset(matched)), tuple(tests)


def timer_due(tests, io, cycle: int, dt_ms: float) -> "int | None":
    """The first IPO cycle, after `cycle`, at which a comparison of `tests` (:func:`timer_watch`)
    may change its value: the running timer reaches its bound (at most one cycle early; never
    late). None: none can (every timer of them stopped or past its bound). A timer index out
    of range gives `cycle` + 1 (evaluate: the read raises there)."""
    due = None
    stop, ms = io.timer_stop, io.timer_ms
    for n, bound in tests:
        if not 1 <= n < len(stop):
            return cycle + 1
        if stop[n] or ms[n] > bound:
            continue
        k = cycle + max(1, int((bound - ms[n]) // dt_ms))
        if due is None or k < due:
            due = k
    return due


def timer_reads(tests, io) -> int:
    """The reads of a running timer an evaluation of the condition makes (each one a clock
    read: interp/runtime/sysvars.py ``_timer``; no short circuit)."""
    stop = io.timer_stop
    return sum(1 for n, _ in tests if 1 <= n < len(stop) and not stop[n])


#: probed system variables the controller's step changes while the robot moves
STEP_PROBED = frozenset({"$PRO_MOVE", "$VEL_ACT"})


def steady(watch: str) -> bool:
    """True when a condition of watch string `watch` keeps its value while only the controller
    steps (the robot moving; nothing runs, the I/O image and the cyclic flags unchanged)."""
    cls, names = split_watch(watch)
    return cls in (CONSTANT, IO, SETTLES) and not STEP_PROBED.intersection(names)


def split_watch(watch: str) -> tuple[str, tuple[str, ...]]:
    """``(class, probed system variable names)`` of a watch string."""
    cls, _, names = watch.partition(":")
    return cls, tuple(names.split(",")) if names else ()


def watch_of_decl(st) -> str:
    """The watch class of INTERRUPT DECL `st`'s condition (``st.when``), kept on its
    annotation (``st.ann.extra["watch"]``) after the first call."""
    ann = st.annotate()
    w = ann.extra.get("watch")
    if w is None:
        w = ann.extra["watch"] = watch_of(st.when)
    return w


def stamp_key(watch: str, io_version: int, now: float, probes=(), written=None):
    """The key of a condition of class `watch` (without probes) at a poll that sees the I/O image
    at `io_version`, the simulated time `now` (s), the probed system variables' readers `probes`
    (zero-argument callables) and what may have written a variable since (`written`:
    :meth:`CyclicWatch.written`); None: evaluate (class ALWAYS, or SETTLES without `written`).
    contexts.py ``InterruptTable.poll`` computes the same key inline (test_interrupt_watch.py)."""
    if watch == CONSTANT:
        key = 0
    elif watch == IO:
        key = io_version
    elif watch == CLOCK:
        key = (io_version, now)
    elif watch == SETTLES and written is not None:
        key = (io_version, written)
    else:
        return None
    return (key, tuple(p() for p in probes)) if probes else key


def _settles_name(node) -> bool:
    """A name whose value changes only when a statement, the I/O image or a cyclic flag writes
    it (:func:`settles`)."""
    place = getattr(node.ann, "place", None) if node.ann is not None else None
    if place is None:
        return False
    if place.kind != SYSTEM:
        sym = place.symbol
        if sym is not None and sym.kind == "signal":
            decl = sym.decl
            start = getattr(decl, "start", None)
            return isinstance(decl, N.SignalDecl) and start is not None and start.sysvar.upper() in _IO_ARRAYS
        return not place.name.startswith("$")  # a $ name the resolver did not place: its lookup decides
    key = place.name.upper()
    # computed from the run (the robot, the clock, the program's state) unless constant or I/O
    return not (key in _LIVE and key not in CONSTANT_NAMES and key not in _IO_ARRAYS)


def settles(expr) -> bool:
    """True when expression `expr` reads only what a statement or the I/O image changes:
    variables, the I/O arrays (a SIGNAL over one of them), stored system variables ($CYCFLAG,
    $FLAG, those a system data list declares) and constants; no call, no timer, no computed
    system variable. Its value then stays until a statement runs, the I/O image changes or a
    cyclic flag changes (:class:`CyclicWatch`)."""
    return all(mode == "r" and _settles_name(node) for mode, node in reads(expr))


class CyclicWatch:
    """When a cyclic flag's expression (``$CYCFLAG[n] = expr``, cyclic.py) must be evaluated
    again: one that :func:`settles` gives the same value until a statement runs (the steps
    executed), the I/O image changes or a cyclic flag changed (:attr:`version`); while
    :meth:`key` is the same the evaluation is left out. Not while an ``ANIN ON`` is on."""

    __slots__ = ("controller", "clock", "stepping", "spin", "version", "anin")

    def __init__(self, controller, clock, stepping, spin) -> None:
        """`controller` (its I/O image's version), `clock` (RunClock: the steps), `stepping` (a
        debugger watching), `spin` (the spin watch: the steps counted without running them)."""
        self.controller = controller
        self.clock = clock
        self.stepping = stepping
        self.spin = spin
        self.version = 0
        self.anin = False       # an ANIN ON is on (interp/runtime/cyclic.py Cyclic.on/off)

    def written(self):
        """What may have written a variable since: ``(steps executed, cyclic flag changes and
        outside changes)``; None when something else may (a debugger, an ``ANIN ON``). A network
        partner that writes into the run announces it first (core.py ``Runtime.changed_outside``,
        which moves :attr:`version`)."""
        if self.stepping.watching or self.anin:
            return None
        return (self.clock.steps - self.spin.skipped, self.version)

    def key(self):
        """The key of the present moment, or None: evaluate."""
        w = self.written()
        return None if w is None else (self.controller.io.version, w)


def reader(ref):
    """The zero-argument reader of system variable `ref` that an interrupt's or a WAIT FOR's
    watch key probes: a computed variable's getter, else its peek."""
    getter = getattr(ref, "getter", None)
    return getter if getter is not None else ref.peek
