"""What a stopped run shows (interp/debug/engine.py): its threads, their stacks, the scopes of
a frame and the variables under a scope or a structured value.

Threads (ids as the Debug Adapter Protocol numbers them): the robot program is thread
:data:`ROBOT_THREAD`; the submit programs :data:`SUBMIT_THREAD` + their index; a running
interrupt handler :data:`INTERRUPT_THREAD` + its number (+ 200 in a submit program), with
the frames it runs, apart from the frames it interrupted.

Scopes of a frame: ``("locals", frame)``, ``("module", module)``, ``("globals",)`` (the data
of ``$config.dat``), ``("sysvars",)`` (:data:`SHOWN_SYSVARS`), ``("io",)`` ($IN/$OUT 1..16
and every higher one that is TRUE), and ``("ref", ref, name)`` for the parts of a structure
or an array. An entry is ``(name, ref)``: a memory reference (interp/runtime/memory.py), a
plain value, or a :class:`Const`.
"""

from __future__ import annotations

from .values import children
from interp.runtime.errors import KrlRuntimeError

ROBOT_THREAD = 1
SUBMIT_THREAD = 2            # + index among the submit tasks
INTERRUPT_THREAD = 1000      # + interrupt number (1..128)

#: system variables shown in the "System variables" scope (any other: evaluate it)
SHOWN_SYSVARS = ("$POS_ACT", "$AXIS_ACT", "$VEL_ACT", "$OV_PRO", "$MODE_OP", "$PRO_MODE", "$ADVANCE",
                 "$TOOL", "$BASE", "$VEL", "$ACC", "$APO", "$ORI_TYPE", "$PRO_STATE", "$ERR")
IO_ALWAYS = 16               # $IN[1..16] and $OUT[1..16] always; higher numbers when TRUE
IO_SIZE = 8192

#: the scopes of a frame, as the Variables pane lists them
SCOPE_NAMES = ("Locals", "Module data", "Globals ($config.dat)", "System variables", "I/O")


class Invalid:
    """A value that cannot be read (its text: the run-time error's message)."""

    def __init__(self, text: str) -> None:
        self.text = f"<{text}>"


class Const:
    """A value with no reference of its own (an I/O element shown by number: ``ref`` is the
    array and ``index`` its element; an evaluated result: both None)."""

    def __init__(self, value, ref, index) -> None:
        self.value = value
        self.ref = ref
        self.index = index

    def peek(self):
        return self.value


def thread_list(rt) -> list:
    """(thread id, name, task, frames innermost first) of the robot program, each running
    interrupt handler and each submit program of the run ``rt``."""
    out = []
    subs = 0
    for task in rt.scheduler.tasks:
        if task.kind == "robot":
            base = ROBOT_THREAD
            name = f"robot program {task.name}"
        else:
            base = SUBMIT_THREAD + subs
            subs += 1
            name = f"submit interpreter {task.name}"
        if task.done:
            continue
        inner = []
        top = task.frame
        for c in reversed([c for c in task.contexts if c.kind == "interrupt"]):
            frames = []
            f = top
            while f is not None and top is not c.interrupted:
                frames.append(f)
                if f.caller is c.frame:
                    break
                f = f.caller
            handler = frames[-1].name if frames else "BRAKE"
            inner.append((INTERRUPT_THREAD + (c.number or 0) + (0 if task.kind == "robot" else 200),
                          f"interrupt {c.number} {handler}", task, frames))
            top = c.interrupted
        out.append((base, name, task, chain(top)))
        out.extend(reversed(inner))
    return out


def thread_of(rt, task) -> int:
    """The thread a stop of ``task`` belongs to: its innermost running interrupt's, else its
    own."""
    last = ROBOT_THREAD
    for tid, _n, t, _f in thread_list(rt):
        if t is task:
            last = tid
    return last


def chain(frame) -> list:
    """``frame`` and its callers, innermost first."""
    out = []
    while frame is not None:
        out.append(frame)
        frame = frame.caller
    return out


def depth(task) -> int:
    """Call depth of ``task`` counting the frames of every interrupted level."""
    if task is None or task.frame is None:
        return 0
    d = task.frame.depth + 1
    for c in task.contexts:
        if c.kind == "interrupt" and c.interrupted is not None:
            d += c.interrupted.depth + 1
    return d


def scopes(frame) -> list[tuple[str, tuple]]:
    """(name, scope) of the scopes of ``frame`` (see the module docstring)."""
    handles = (("locals", frame), ("module", frame.module), ("globals",), ("sysvars",), ("io",))
    return list(zip(SCOPE_NAMES, handles))


def entries(rt, scope: tuple) -> list:
    """(name, Ref or value) of the variables under ``scope``."""

    kind = scope[0]
    out = []
    if kind == "locals":
        frame = scope[1]
        if frame.layout is not None:
            for k, s in enumerate(frame.layout.slots):
                out.append((s.name, frame.var(k)))
    elif kind == "module":
        m = scope[1]
        if m is not None:
            out = _declared(m.data)
    elif kind == "globals":
        for m in rt.modules:
            if m is not None and m.name == "$CONFIG":
                out = _declared(m.data)
    elif kind == "sysvars":
        for name in SHOWN_SYSVARS:
            out.append((name, rt.sysvars.lookup(name)))
        out.append(("(simulated time s)", rt.controller.time))
    elif kind == "io":
        io = rt.controller.io
        for arr, get in (("$IN", io.get_in), ("$OUT", io.get_out)):
            for i in range(1, IO_SIZE + 1):
                v = get(i)
                if i <= IO_ALWAYS or v:
                    out.append((f"{arr}[{i}]", Const(bool(v), rt.sysvars.lookup(arr), i)))
    elif kind == "ref":
        _, ref, name = scope
        v = peek(ref)
        for label, step in children(v):
            if isinstance(ref, Const):     # an evaluated value: its parts are values
                part = v.f[step[1]] if step[0] == "field" else v.data[v.flat(step[1])]
                out.append((label, Const(part, None, None)))
            else:
                out.append((label, child(rt, ref, step, name)))
    return out


def _declared(data: dict) -> list:
    """(name as declared, ref) of a data list's variables (``ModuleRT.data`` is keyed by the
    upper-case name; each reference keeps the declared one)."""
    return [(getattr(ref, "name", None) or key, ref) for key, ref in data.items()]


def child(rt, ref, step, name):
    """The reference of one part (a ``["field", NAME]`` or ``["index", [i, ...]]`` step) of
    ``ref``."""
    if step[0] == "field":
        return rt.names.field(ref, step[1], name)
    return rt.names.index(ref, step[1], name)


def peek(ref):
    """The value under ``ref`` without side effects; :class:`Invalid` when it cannot be
    read."""

    if ref is None:
        return None
    if isinstance(ref, Const):
        return ref.value
    if not hasattr(ref, "peek"):
        return ref
    try:
        return ref.peek()
    except KrlRuntimeError as exc:
        return Invalid(exc.message)
