"""The outputs a backup's code writes, read from the checked AST, and the overlaps ``krl audit``
reports: an output written by two programs, under two names, or by a program and the PLC's
map (issue 49).

A *write* is a statement that sets a digital or analog output, found in the annotated AST of
every routine (the checker resolved each name; nothing is read from the text):

* ``$OUT[n] = ...``, ``$OUT_C[n] = ...`` (the same output, set at the advance run's pointer),
  ``$ANOUT[n] = ...`` with a constant index (reference 3.8, "I/O");
* an assignment to a name the checker resolved to a ``SIGNAL`` on ``$OUT``/``$ANOUT``: every
  output of its range (``SIGNAL GRP $OUT[16] TO $OUT[23]`` sets 16..23);
* ``PULSE($OUT[n], ...)`` and a signal as PULSE's first argument;
* the same forms as the action of a ``TRIGGER WHEN ... DO`` (the walk reaches them).

A write whose index is not a constant (``$OUT[ODAT_ACT.OUT_NO]``, P00's ``$OUT[PGNO_REQ]``) is
kept apart (``computed``): which output it sets is known only when it runs. ``ANOUT ON`` (a
cyclic analog output) is not counted.

Each write is run by the *tasks* whose entry points reach its routine along the program map's
edges (krl/programmap: calls, interrupts, triggers, RUN): the robot interpreter (every entry
point but the submit programs: the cell program, the programs it or an operator starts), or a
submit interpreter (an entry of kind ``submit``, or a program ``$config.dat`` selects for one:
kind ``selected``; reference section 9). Routines only KUKA's system software or nothing reaches
run in no task this audit can name. An output is flagged (:class:`Overlap`):

* **two programs** -- code of two tasks writes it (a submit program and the robot program,
  or two submit programs): they run at once, the last write wins. A ``RUN`` of ``$CMD`` starts its
  program in the robot interpreter (a .src: the submit program selecting the cell program
  with ``CWRITE($CMD, ..., "RUN /R1/CELL()")``) or a submit interpreter (a .sub: a robot
  program restarting ``RUN /R1/SPS()``), whatever task ran the CWRITE;
* **two names** -- it is written under two SIGNAL names (two declarations on one address);
* **PLC map** -- a write sets an output of the PLC's map, other than the map's own program.

The **PLC's map** of a backup, as far as the robot's outputs go, is what the controller drives
for the PLC of Automatic External: every system signal a KUKA data list declares on an output
(``SIGNAL $PERI_RDY $OUT[1012]`` in ``$machine.dat``: the controller writes it), and the
outputs of KUKA's P00 handshake (written by module P00): those ``$config.dat`` names --
``PGNO_REQ`` (the program-number request; P00 writes ``$OUT[PGNO_REQ]``, or
``$OUT[-PGNO_REQ]`` active low), ``APPL_RUN`` (application running) and, with
``REFLECT_PROG_NR=1``, the reflection of the number on ``PGNO_FBIT_REFL`` ..
``PGNO_FBIT_REFL+PGNO_LENGTH-1`` -- and the signals of P00's own data list (``SIGNAL ERR
$OUT[25] TO $OUT[32]``, the error code to the PLC). The corpus's own P00 writes exactly these
(rawpython__kukaKRLmagic/R1/TP/p00.src lines 38-43, 148-150, 166-170, 185-190;
khrzysio__KRC4_test/R1/TP/p00.dat line 11).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from krl.ast import nodes as N
from krl.programmap import ProgramMap
from krl.workspace import Workspace, is_kuka_file
from robot.datalist import DataListError, literal

__all__ = ["Write", "Output", "Overlap", "OutputReport", "FLAGS", "output_writes", "plc_outputs", "overlaps"]

#: the flags of an overlap, in report order (module docstring)
FLAGS = ("two programs", "two names", "PLC map")
#: the outputs a statement can set, by the system variable's name (``$OUT_C`` sets ``$OUT``)
_OUTPUTS = {"$OUT": "$OUT", "$OUT_C": "$OUT", "$ANOUT": "$ANOUT"}
#: the longest SIGNAL range expanded into its outputs (KRL allows 32 bits, reference 3.8)
_MAX_RANGE = 64
#: the entry kinds of the program map a submit interpreter starts (reference section 9)
_SUBMIT_KINDS = ("submit", "selected")
#: entry kinds that are no task of their own: KUKA's system programs (called by the others),
#: and handlers, reached through the interrupt or trigger edge of the routine that declares them
_NO_TASK = ("system", "interrupt", "trigger")


@dataclass(frozen=True)
class Write:
    """One statement that sets `signal` (``$OUT[n]`` or ``$ANOUT[n]``; "" for a computed
    index): its file and line, the module, the routine's node id in the program map, the SIGNAL
    name it writes by ("" for ``$OUT[n]`` itself), how it reads (``$OUT[5]``, ``GRIP``,
    ``PULSE GRIP``) and whether the file is KUKA's system software."""

    signal: str
    path: str
    line: int
    module: str
    routine: str
    name: str
    how: str
    kuka: bool = False


@dataclass(frozen=True)
class Output:
    """An output the PLC's map names: `signal`, `name` (``$PERI_RDY``, ``PGNO_REQ``, ``ERR``),
    where it is declared, and `owner`: the module that writes it for the map ("P00"), or ""
    when only the controller does."""

    signal: str
    name: str
    path: str
    line: int
    owner: str = ""


@dataclass
class Overlap:
    """Outputs to review: `signals` (one, or a run of consecutive outputs that the same
    statements write with the same flags: ``$OUT[601..616]`` of one SIGNAL group), their
    `flags` (of :data:`FLAGS`), the writes, the `tasks` that run them (``robot``, ``submit
    NAME``), and the PLC map's Outputs among them when flagged so."""

    signals: list[str]
    flags: list[str]
    writes: list[Write]
    tasks: list[str]
    plc: list[Output] = field(default_factory=list)

    @property
    def signal(self) -> str:
        """``$OUT[5]``, or ``$OUT[601..616]`` for a run."""
        if len(self.signals) == 1:
            return self.signals[0]
        last = self.signals[-1].partition("[")[2].rstrip("]")
        return f"{self.signals[0][:-1]}..{last}]"


@dataclass
class OutputReport:
    """What :func:`overlaps` finds: every write (`writes`), those with a computed index
    (`computed`), the PLC's map (`plc_map`), the overlaps by output, and for each routine that
    writes, the entry points that reach it (`reached_by`: node id -> entry node ids) and the
    tasks they make (`tasks`: node id -> task names)."""

    writes: list[Write] = field(default_factory=list)
    computed: list[Write] = field(default_factory=list)
    plc_map: list[Output] = field(default_factory=list)
    overlaps: list[Overlap] = field(default_factory=list)
    reached_by: dict[str, list[str]] = field(default_factory=dict)
    tasks: dict[str, list[str]] = field(default_factory=dict)


def _signals(target: N.Expr) -> tuple[list[str], str, str] | None:
    """The outputs the expression `target` names when written, the SIGNAL name ("" for
    ``$OUT[n]``) and how it reads; ``([], "", text)`` for an output with a computed index; None
    when it names no output."""
    if isinstance(target, N.Index) and isinstance(target.base, N.Name):
        base = _OUTPUTS.get(target.base.name.upper())
        if base is None or len(target.indices) != 1:
            return None
        i = target.indices[0]
        if isinstance(i, N.IntLit):
            return [f"{base}[{i.value}]"], "", f"{target.base.name.upper()}[{i.value}]"
        return [], "", f"{target.base.name.upper()}[...]"
    if isinstance(target, N.Name):
        sym = N.symbol_of(target)
        decl = sym.decl if sym is not None and sym.kind == "signal" else None
        if isinstance(decl, N.SignalDecl) and decl.start is not None:
            base = _OUTPUTS.get(decl.start.sysvar.upper())
            if base is None:
                return None
            a = decl.start.index
            b = decl.end.index if decl.end is not None else a
            return ([f"{base}[{n}]" for n in range(a, min(b, a + _MAX_RANGE - 1) + 1)], decl.name.upper(),
                    target.name)
    return None


def _sort_key(signal: str) -> tuple:
    base, _, rest = signal.partition("[")
    return (base, int(rest.rstrip("]")) if rest.rstrip("]").isdigit() else 0)


def output_writes(ws: Workspace, pm: ProgramMap) -> tuple[list[Write], list[Write]]:
    """(writes with a constant output, writes with a computed index) of every routine of the
    checked workspace `ws` (files without syntax errors), in file and line order; `pm` is its
    program map (the routine ids)."""
    writes: list[Write] = []
    computed: list[Write] = []
    for u in ws.units:
        if u.src is None or not u.src.ok:
            continue
        kuka = is_kuka_file(u.src.path)
        for r in u.src.module.routines:
            node = pm.node_of(r)
            rid = node.id if node is not None else ""
            for x in r.walk():
                target, how = None, ""
                if isinstance(x, N.Assign):
                    target = x.target
                elif isinstance(x, N.Call) and x.name.upper() == "PULSE" and x.args and x.args[0] is not None:
                    target, how = x.args[0], "PULSE "
                found = _signals(target) if target is not None else None
                if found is None:
                    continue
                signals, name, text = found
                line = x.span.line
                if not signals:
                    computed.append(Write("", u.src.path, line, u.name, rid, name, how + text, kuka))
                writes += [Write(sig, u.src.path, line, u.name, rid, name, how + text, kuka) for sig in signals]
    return writes, computed


def _int_value(ws: Workspace, name: str) -> tuple[int, str, int] | None:
    """(value, file, line) of the global INT `name` ($config.dat), when its initialiser is a
    literal INT (robot.datalist.literal: the front end's evaluator); None otherwise."""
    sym = ws.global_scope.values.get(name) if ws.global_scope is not None else None
    decl = sym.decl if sym is not None else None
    if not isinstance(decl, N.VarDecl) or decl.init is None:
        return None
    try:
        v = literal(decl.init, f"{sym.path}:{decl.span.line}")
    except DataListError:
        return None
    if not isinstance(v, int) or isinstance(v, bool):
        return None
    return v, sym.path, decl.span.line


def _range(d: N.SignalDecl) -> list[str]:
    base = _OUTPUTS.get(d.start.sysvar.upper()) if d.start is not None else None
    if base is None:
        return []
    b = d.end.index if d.end is not None else d.start.index
    return [f"{base}[{n}]" for n in range(d.start.index, min(b, d.start.index + _MAX_RANGE - 1) + 1)]


def plc_outputs(ws: Workspace) -> list[Output]:
    """The outputs of the PLC's map of the backup in `ws` (module docstring): system signals on
    ``$OUT``/``$ANOUT`` in KUKA's data lists, the signals of P00's data list, then P00's outputs
    named by ``$config.dat``."""
    out: list[Output] = []
    for u in ws.units:
        dl = u.dat.module.data if u.dat is not None else None
        if dl is None or not is_kuka_file(u.dat.path):
            continue
        p00 = u.name.upper() == "P00"
        for d in dl.items:
            if isinstance(d, N.SignalDecl) and (d.name.startswith("$") or p00):
                out += [Output(sig, d.name.upper(), u.dat.path, d.span.line, "P00" if p00 else "")
                        for sig in _range(d)]
    for name in ("PGNO_REQ", "APPL_RUN"):
        v = _int_value(ws, name)
        if v is not None and v[0] != 0:
            out.append(Output(f"$OUT[{abs(v[0])}]", name, v[1], v[2], "P00"))
    reflect, first, length = (_int_value(ws, n) for n in ("REFLECT_PROG_NR", "PGNO_FBIT_REFL", "PGNO_LENGTH"))
    if reflect is not None and reflect[0] == 1 and first is not None and length is not None and first[0] > 0:
        for i in range(max(0, min(length[0], 16))):
            out.append(Output(f"$OUT[{first[0] + i}]", f"PGNO_FBIT_REFL+{i}", first[1], first[2], "P00"))
    return out


def _reach(pm: ProgramMap) -> dict[str, dict[str, str]]:
    """For each node of the map, the entry points that reach it and the task each runs it in
    ({node id: {entry id: task}}, entries in the map's order): from every entry along the edges
    (calls, interrupts, triggers) in the entry's task (:func:`_task`); a ``run`` edge
    (``CWRITE($CMD, ..., "RUN /R1/X()")``) starts its target in a task of its own kind
    (:func:`_started`), whatever task ran the CWRITE. Entries that are no task of their own reach in no task ("")."""
    out: dict[str, list] = {}
    for e in pm.edges:
        out.setdefault(e.source, []).append(e)
    seen: dict[str, dict[str, str]] = {}
    for entry in pm.entries:
        first = _task(pm, entry) or ""
        todo = deque([(entry, first)])
        mark = {(entry, first)}
        while todo:
            nid, task = todo.popleft()
            seen.setdefault(nid, {}).setdefault(entry, task)
            for e in out.get(nid, ()):
                nxt = (e.target, _started(pm, e.target) if e.kind == "run" else task)
                if nxt not in mark:
                    mark.add(nxt)
                    todo.append(nxt)
    return seen


def _started(pm: ProgramMap, nid: str) -> str:
    """The task a ``RUN`` of $CMD starts its program in: a submit interpreter for a ``.sub``
    file, else the robot interpreter."""
    n = pm.nodes[nid]
    return f"submit {n.module.upper()}" if n.path.lower().endswith(".sub") else "robot"


def _task(pm: ProgramMap, entry: str) -> str | None:
    """The task an entry point of the map runs in: ``robot``, ``submit MODULE``, or None."""
    n = pm.nodes[entry]
    if n.entry_kind in _SUBMIT_KINDS:
        return f"submit {n.module.upper()}"
    return None if n.entry_kind in _NO_TASK else "robot"


def overlaps(ws: Workspace, pm: ProgramMap) -> OutputReport:
    """The writes of the checked workspace `ws` and the outputs to review (module docstring),
    in output order; `pm` is its program map."""
    rep = OutputReport()
    rep.writes, rep.computed = output_writes(ws, pm)
    rep.plc_map = plc_outputs(ws)
    reach = _reach(pm)
    for rid in {w.routine for w in rep.writes + rep.computed if w.routine}:
        got = reach.get(rid, {})
        rep.reached_by[rid] = list(got)
        rep.tasks[rid] = sorted({t for t in got.values() if t})
    by: dict[str, list[Write]] = {}
    for w in rep.writes:
        by.setdefault(w.signal, []).append(w)
    plc: dict[str, Output] = {}
    for o in rep.plc_map:
        plc.setdefault(o.signal, o)
    for sig in sorted(by, key=_sort_key):
        writes = by[sig]
        tasks = sorted({t for w in writes for t in rep.tasks.get(w.routine, ())})
        flags = []
        if len(tasks) >= 2:
            flags.append("two programs")
        if len({w.name for w in writes if w.name}) >= 2:
            flags.append("two names")
        o = plc.get(sig)
        if o is not None and any(w.module.upper() != o.owner for w in writes):
            flags.append("PLC map")
        if not flags:
            continue
        last = rep.overlaps[-1] if rep.overlaps else None
        if last is not None and last.flags == flags and last.tasks == tasks and _next(last.signals[-1], sig) \
                and _same(last.writes, writes):
            last.signals.append(sig)
            last.writes += writes
            last.plc += [o] if "PLC map" in flags else []
        else:
            rep.overlaps.append(Overlap([sig], flags, writes, tasks, [o] if "PLC map" in flags else []))
    for ov in rep.overlaps:                    # one row per statement (a run's bits share it)
        ov.writes = list(dict.fromkeys(Write("", w.path, w.line, w.module, w.routine, w.name, w.how, w.kuka)
                                       for w in ov.writes))
    return rep


def _next(a: str, b: str) -> bool:
    """True when output `b` follows output `a` (``$OUT[5]``, ``$OUT[6]``)."""
    ka, kb = _sort_key(a), _sort_key(b)
    return ka[0] == kb[0] and kb[1] == ka[1] + 1


def _same(a: list[Write], b: list[Write]) -> bool:
    """True when the statements of `a` and `b` are the same (file, line, name, how)."""
    return {(w.path, w.line, w.name, w.how) for w in a} == {(w.path, w.line, w.name, w.how) for w in b}
