"""The program map of a checked workspace: routines, what calls what, entry points, unreachable routines.

:func:`build_map` reads a :class:`krl.workspace.Workspace` after ``ws.check()``. Every edge
comes from the checker's annotations (``node.ann.symbol``, krl/semantics/checker.py), never
from the text: a call whose name the checker did not resolve is listed in ``unresolved``, not
drawn. Edge kinds:

* ``call`` -- a procedure or function call (reference 2.3), also a parameterless function
  named without parentheses; an EXT declaration leads to the routine it declares;
* ``interrupt`` -- ``INTERRUPT DECL n WHEN ... DO handler()`` (5.16): from the routine that
  declares the interrupt to its handler;
* ``trigger`` -- ``TRIGGER WHEN ... DO routine()`` (5.18);
* ``run`` -- ``CWRITE($CMD, ..., "RUN /R1/NAME()")`` (KUKA CWRITE, ``$CMD`` channel): the
  program it starts;
* ``eki`` -- ``EKI_Init("name")``, ``EKI_Open("name")``... (KUKA.Ethernet KRL): to a channel
  node ``EKI name``.

Entry points (``Node.entry`` says why, ``Node.entry_kind`` which of these kinds; the first
that applies is named), in two classes (issue 49): what the controller starts by itself and what
only an operator can select.

Started by the controller:

* ``cell`` -- the cell program (module ``CELL``, or a main routine ``DEF CELL()``), which
  Automatic External starts;
* ``plc`` -- the program numbers the cell program's ``SWITCH`` selects: every routine called
  in a ``CASE`` branch (KUKA's cell.src: ``SWITCH PGNO ... CASE 1 ... EXAMPLE1()``; one program
  may have several numbers, the first is named); a routine called in most branches (at least
  three, more than half) is a step of the cell's own sequence (``CellProgramStart()``), not a
  program;
* ``submit`` -- every submit interpreter (``.sub`` file: ``sps.sub``; reference section 9);
* ``selected`` -- every program a system data list (``$config.dat``, ``$custom.dat``,
  ``$option.dat``) names as ``"/R1/NAME()"`` (``$PRO_I_O``, ``$PRO_I_O_PROC_IDn``: the
  extended submit interpreters, reference section 9);
* ``interrupt`` -- an interrupt handler (the routine an ``INTERRUPT DECL`` calls) whose
  declaring routine runs: the controller starts it when its condition fires (reference 5.16);
  an interrupt declared only in a routine nothing runs never fires;
* ``trigger`` -- a routine a ``TRIGGER WHEN ... DO`` of a routine that runs calls (5.18).

Selected by an operator:

* ``operator`` -- the main routine of every module under ``R1/Program`` (krl.project
  .program_folder) that is a ``DEF`` without parameters: the programs an operator can select
  at the pendant (a selected program starts its main routine with no arguments; the same rule
  as interp.realprograms.programs_of), so a KR C2 backup without cell.src has its user
  programs as entries.

And ``system`` -- the main routines of KUKA's own files (krl.workspace.is_kuka_file: the
controller, its inline forms and technology packages call them); ``module`` -- for a folder
that is not a KRC backup, the main routine of every module and every GLOBAL routine (nothing
says who starts or calls them: code outside the folder may).

Each node has a *reach* (``Node.reach``, :data:`REACH`): ``controller`` when a routine the
controller starts reaches it along the edges (calls, interrupts, triggers, RUN); ``operator``
when only operator-selectable programs reach it; ``module`` in a folder that is not a backup;
``dead`` when nothing reaches a routine of the backup's own (``Node.unreachable``); ``unknown``
for such a routine whose name a line not understood uses (the checker resolves nothing on that
line, so whether it calls the routine is not known: never called dead), and what it reaches; ``unused`` for a
routine of KUKA's system software nothing calls (a library: never dead). A module whose
routines are reached only by operator selection is listed by :attr:`ProgramMap.operator_only`.
"""

from __future__ import annotations

import re
from collections import deque
from dataclasses import dataclass, field

from pathlib import Path

from krl.ast import nodes as N
from krl.ast import printer
from krl.project import backup_of, program_folder
from krl.workspace import Workspace, is_kuka_file, not_understood

__all__ = ["Node", "Edge", "ProgramMap", "build_map", "routine_id", "REACH", "CONTROLLER_KINDS"]

#: the reach of a node (see the module docstring), in the order the map's tables list them
REACH = ("controller", "operator", "module", "unknown", "dead", "unused")
#: the entry kinds the controller starts by itself
CONTROLLER_KINDS = ("cell", "plc", "submit", "selected", "interrupt", "trigger")

_RUN = re.compile(r"^\s*RUN\s+(?:/R1/)?([A-Za-z_$][A-Za-z0-9_$]*)\s*\(", re.I)
_SELECTED = re.compile(r"^\s*/R1/([A-Za-z_$][A-Za-z0-9_$]*)\s*\(", re.I)


@dataclass
class Node:
    """A routine (kind ``routine``) or an EKI channel (kind ``channel``). ``path``/``line``:
    where it is declared (1-based); ``entry``: why it is an entry point, else ""; ``entry_kind``:
    which kind of entry point (see the module docstring), else ""; ``reach``: one of
    :data:`REACH` (``unreachable`` is ``reach == "dead"``); ``kuka``: in KUKA's system
    software (krl.workspace.is_kuka_file)."""
    id: str
    name: str
    module: str = ""
    path: str = ""
    line: int = 0
    kind: str = "routine"
    entry: str = ""
    entry_kind: str = ""
    unreachable: bool = False
    reach: str = ""
    kuka: bool = False
    main: bool = False
    runnable: bool = False         # a module main that is a DEF without parameters: a program of its own
    is_global: bool = False        # GLOBAL DEF / DEFFCT
    end: int = 0                   # the END/ENDFCT line
    # the data it reads or writes: (declaring file, NAME upper-case) of every name the checker
    # resolved to a variable, constant or signal declared in a file (a data list, $config.dat)
    uses: set[tuple[str, str]] = field(default_factory=set, repr=False)


@dataclass(frozen=True)
class Edge:
    """From routine `source` to `target` (node ids); `path`:`line`:`column` of the called name."""
    source: str
    target: str
    kind: str
    path: str
    line: int
    column: int = 0


@dataclass
class ProgramMap:
    """Nodes by id, edges in source order, entry node ids, and the calls the checker left
    unresolved: (source id, name, path, line)."""
    root: str
    nodes: dict[str, Node] = field(default_factory=dict)
    edges: list[Edge] = field(default_factory=list)
    entries: list[str] = field(default_factory=list)
    unresolved: list[tuple[str, str, str, int]] = field(default_factory=list)
    # the files with lines not understood (krl.workspace.NotUnderstood): named first by every form
    not_understood: list = field(default_factory=list)

    def node_of(self, routine: N.Routine) -> Node | None:
        """The node of a Routine of the workspace."""
        return self.nodes.get(self._by_decl.get(id(routine), ""))

    def outgoing(self, node_id: str) -> list[Edge]:
        return [e for e in self.edges if e.source == node_id]

    def incoming(self, node_id: str) -> list[Edge]:
        return [e for e in self.edges if e.target == node_id]

    @property
    def unreachable(self) -> list[Node]:
        """The dead routines: of the backup's own, reached by no entry point."""
        return [n for n in self.nodes.values() if n.unreachable]

    @property
    def operator_only(self) -> list[str]:
        """The modules of the backup's own that only operator selection reaches: some routine
        has reach ``operator`` and none ``controller`` (module names, in map order)."""
        by: dict[str, set[str]] = {}
        for n in self.nodes.values():
            if n.kind == "routine" and not n.kuka:
                by.setdefault(n.module, set()).add(n.reach)
        return [m for m, r in by.items() if "operator" in r and "controller" not in r]

    def as_json(self) -> dict:
        """``{"root", "nodes": [...], "edges": [...], "entries": [...], "unreachable": [...],
        "operator_only": [...], "unresolved": [...]}`` (docs/diff.md, "krl graph"; docs/schemas/graph.schema.json)."""
        return {
            "root": self.root,
            "nodes": [{"id": n.id, "name": n.name, "module": n.module, "kind": n.kind, "path": n.path,
                       "line": n.line, "system": n.kuka, "entry": n.entry, "entry_kind": n.entry_kind,
                       "unreachable": n.unreachable, "reach": n.reach} for n in self.nodes.values()],
            "edges": [{"source": e.source, "target": e.target, "kind": e.kind, "path": e.path,
                       "line": e.line, "column": e.column} for e in self.edges],
            "entries": list(self.entries),
            "unreachable": [n.id for n in self.unreachable],
            "operator_only": self.operator_only,
            "unresolved": [{"source": s, "name": n, "path": p, "line": ln} for s, n, p, ln in self.unresolved],
            "not_understood": [{"file": p.path, "lines": [{"line": n, "message": m} for n, m in p.lines],
                                "understood": p.understood, "total": p.total, "noun": p.noun}
                               for p in self.not_understood],
        }

    _by_decl: dict = field(default_factory=dict, repr=False)


def routine_id(module: str, name: str) -> str:
    """The node id of routine `name` of `module`: ``MODULE:NAME``, upper-case."""
    return f"{module.upper()}:{name.upper()}"


def build_map(ws: Workspace) -> ProgramMap:
    """The program map of `ws` (checked here if it is not yet; see the module docstring)."""
    ws.check(resolve=False)     # the map reads the checker's symbols, never a storage place
    pm = ProgramMap(ws.root, not_understood=not_understood(ws))
    mains: dict[str, str] = {}            # MODULE -> node id of its main routine
    for u in ws.units:
        if u.src is None:
            continue
        kuka = is_kuka_file(u.src.path)
        for i, r in enumerate(u.src.module.routines):
            nid = routine_id(u.name, r.name)
            if nid in pm.nodes:
                continue                   # a duplicate routine (E102): the first one stands
            pm.nodes[nid] = Node(nid, r.name, u.name, u.src.path, r.span.line, kuka=kuka, main=i == 0,
                                 runnable=i == 0 and _selectable(r), is_global=r.is_global,
                                 end=r.end_line or r.span.line)
            pm._by_decl[id(r)] = nid
            if i == 0:
                mains[u.name.upper()] = nid
    for u in ws.units:
        if u.src is None:
            continue
        for r in u.src.module.routines:         # a file with syntax errors: what parsed (issue 63)
            src = pm._by_decl.get(id(r))
            if src is not None:
                _edges(pm, ws, src, r, u.src.path, mains)
    _entries(pm, ws, mains)
    return pm


def _target(pm: ProgramMap, ws: Workspace, sym) -> str | None:
    decl = sym.decl if sym is not None else None
    if not isinstance(decl, N.Routine) and sym is not None and ws.global_scope is not None:
        g = ws.global_scope.routines.get(sym.name.upper())     # EXT x() -> the GLOBAL DEF x
        if g is not None and isinstance(g.decl, N.Routine):
            decl = g.decl
    return pm._by_decl.get(id(decl)) if isinstance(decl, N.Routine) else None


def _edges(pm: ProgramMap, ws: Workspace, src: str, r: N.Routine, path: str, mains: dict) -> None:
    kinds: dict[int, str] = {}
    for node in r.walk():
        if isinstance(node, N.InterruptDecl) and node.brake is None:
            kinds[id(node.call)] = "interrupt"
        elif isinstance(node, N.Trigger) and isinstance(node.action, N.CallStmt):
            kinds[id(node.action.call)] = "trigger"
    for node in r.walk():
        if isinstance(node, N.Call):
            sym = N.symbol_of(node)
            line = node.span.line
            if sym is None:
                if node.name.upper() not in ("BRAKE", "BRAKE_F"):
                    pm.unresolved.append((src, node.name, path, line))
                continue
            target = _target(pm, ws, sym)
            if target is not None:
                pm.edges.append(Edge(src, target, kinds.get(id(node), "call"), path, line, node.span.column))
            elif sym.decl is None:
                _builtin(pm, src, node, path, mains)
        elif isinstance(node, N.Name):
            sym = N.symbol_of(node)
            if sym is not None and sym.kind == "routine":
                target = _target(pm, ws, sym)
                if target is not None:
                    pm.edges.append(Edge(src, target, "call", path, node.span.line, node.span.column))
            elif sym is not None and sym.path and sym.kind in ("var", "const", "signal"):
                pm.nodes[src].uses.add((sym.path, sym.name.upper()))


def _builtin(pm: ProgramMap, src: str, call: N.Call, path: str, mains: dict) -> None:
    """EKI channel and CWRITE RUN edges of a built-in call."""
    name = call.name.upper()
    args = [a for a in call.args if a is not None]
    if name.startswith("EKI_") and args and isinstance(args[0], N.StrLit):
        cid = f"EKI:{args[0].value}"
        if cid not in pm.nodes:
            pm.nodes[cid] = Node(cid, args[0].value, "EKI", kind="channel")
        pm.edges.append(Edge(src, cid, "eki", path, call.span.line, call.span.column))
    elif name == "CWRITE" and args and isinstance(args[0], N.Name) and args[0].name.upper() == "$CMD":
        for a in args[1:]:
            m = _RUN.match(a.value) if isinstance(a, N.StrLit) else None
            if m is not None and m.group(1).upper() in mains:
                pm.edges.append(Edge(src, mains[m.group(1).upper()], "run", path, call.span.line, call.span.column))


def _strings(e) -> list[str]:
    if e is None:
        return []
    return [n.value for n in e.walk() if isinstance(n, N.StrLit)]


def _entries(pm: ProgramMap, ws: Workspace, mains: dict) -> None:
    """Entry points and each node's reach (module docstring): the controller's entries first,
    the handlers of the interrupts and triggers their routines declare, then the programs an
    operator selects, then KUKA's own main routines and (outside a backup) every module main."""
    def add(nid: str | None, kind: str, why: str) -> None:
        if nid is not None and nid in pm.nodes and not pm.nodes[nid].entry:
            pm.nodes[nid].entry, pm.nodes[nid].entry_kind = why, kind
            pm.entries.append(nid)

    root = backup_of(ws.root) if ws.root else None
    backup = root is not None or any(f.path.replace("\\", "/").lower().endswith("/system/$config.dat")
                                     for f in ws.files)
    cells = [nid for nid, n in pm.nodes.items() if n.main and n.kind == "routine"
             and (n.module.upper() == "CELL" or n.name.upper() == "CELL")]
    for nid in cells:
        add(nid, "cell", "cell program (Automatic External)")
    for nid in cells:
        for number, target, line in _case_programs(pm, ws, nid):
            add(target, "plc", f"PLC program number {number} (cell program, line {line})")
    for u in ws.units:
        if u.src is not None and u.src.path.lower().endswith(".sub"):
            add(mains.get(u.name.upper()), "submit", "submit interpreter")
    for u in ws.units:
        dl = u.dat.module.data if u.dat is not None else None
        if dl is None or not dl.name.startswith("$"):
            continue
        for d in dl.items:
            value = d.init if isinstance(d, N.VarDecl) else d.value if isinstance(d, N.ArrayInit) else None
            for s in _strings(value):
                m = _SELECTED.match(s)
                if m is not None:
                    add(mains.get(m.group(1).upper()), "selected", f"selected by {dl.name.lower()}.dat")
    out: dict[str, list[Edge]] = {}
    for e in pm.edges:
        out.setdefault(e.source, []).append(e)
    _reach(pm, out, list(pm.entries), "controller")
    programs = program_folder(root) if root is not None else None
    operator = [nid for nid, n in pm.nodes.items()
                if n.kind == "routine" and n.runnable and not n.kuka and programs is not None
                and _inside(n.path, programs)]
    for nid in operator:
        add(nid, "operator", "selectable at the pendant (R1/Program)")
    _reach(pm, out, [nid for nid in operator if not pm.nodes[nid].reach], "operator")
    modules = []
    for nid, n in pm.nodes.items():
        if n.kind == "routine" and n.main and (n.kuka or not backup):
            add(nid, "system" if n.kuka else "module",
                "KUKA system program" if n.kuka else "main routine of a module")
            if not n.kuka:
                modules.append(nid)
        elif n.kind == "routine" and n.is_global and not backup and not n.kuka:
            # a folder that is not a backup is a library as much as a program: code outside it
            # (the backup it goes into, its sps.sub) may call what its modules export
            add(nid, "module", "GLOBAL routine of a module")
            modules.append(nid)
    _reach(pm, out, [nid for nid in modules if not pm.nodes[nid].reach], "module")
    named = _named_in_unparsed(ws)
    _reach(pm, out, [nid for nid, n in pm.nodes.items()
                     if not n.reach and n.kind == "routine" and not n.kuka and n.name.upper() in named], "unknown")
    for n in pm.nodes.values():
        if not n.reach:
            # KUKA's system software is a library the controller, its inline forms and technology
            # packages call (bas.src's SVEL_CP, collmonlib.src): what this backup does not call of
            # it is unused, not dead
            n.reach = "unused" if n.kuka or n.kind == "channel" else "dead"
        n.unreachable = n.kind == "routine" and n.reach == "dead"


def _reach(pm: ProgramMap, out: dict[str, list[Edge]], roots: list[str], reach: str) -> None:
    """Give every node `roots` reach along the edges, not reached yet, the reach `reach`; a
    handler reached through an interrupt or trigger edge becomes an entry of that kind (not from
    a routine whose reach is ``unknown``: whether it runs is not known)."""
    todo = deque(nid for nid in roots if not pm.nodes[nid].reach)
    for nid in todo:
        pm.nodes[nid].reach = reach
    while todo:
        src = todo.popleft()
        for e in out.get(src, ()):
            t = pm.nodes[e.target]
            if e.kind in ("interrupt", "trigger") and not t.entry and reach != "unknown":
                what = "interrupt handler (declared by" if e.kind == "interrupt" else "trigger routine (TRIGGER in"
                t.entry, t.entry_kind = f"{what} {pm.nodes[src].name})", e.kind
                pm.entries.append(t.id)
            if not t.reach:
                t.reach = reach
                todo.append(t.id)


def _named_in_unparsed(ws: Workspace) -> set[str]:
    """The words (upper case) of the lines not understood of the workspace's files: a name
    among them may be called there, and the checker resolves nothing on those lines (the rest
    of each file is checked and mapped, issue 63)."""
    return set(ws.failed_words)


def _selectable(main: N.Routine | None) -> bool:
    """True when the module main `main` is a DEF without parameters (a program the pendant can
    select and start: it passes no arguments)."""
    return main is not None and main.kind == "DEF" and not main.params


def _inside(path: str, folder: Path) -> bool:
    try:
        Path(path).relative_to(folder)
    except ValueError:
        return False
    return True


def _case_programs(pm: ProgramMap, ws: Workspace, cell_id: str) -> list[tuple[str, str, int]]:
    """(program number, routine id, line) of each routine called in a CASE branch of a SWITCH
    of the cell program's routines (its module's routines: the main one and its helpers)."""
    cell = pm.nodes[cell_id]
    out = []
    for u in ws.units:
        if u.src is None or u.src.path != cell.path:
            continue
        for r in u.src.module.routines:
            for sw in (x for x in r.walk() if isinstance(x, N.Switch)):
                branches = []
                for case in sw.cases:
                    number = ", ".join(printer.expr(v) for v in case.values)
                    calls = {}
                    for st in case.body:
                        for call in (x for x in st.walk() if isinstance(x, N.Call)):
                            target = _target(pm, ws, N.symbol_of(call))
                            if target is not None and not pm.nodes[target].kuka:
                                calls.setdefault(target, call.span.line)
                    branches.append((number, calls))
                # a routine called in most branches (at least three, more than half) is a step
                # of the cell's own sequence (CellProgramStart(), CellProgramEnd()), not a
                # program; one program may have several numbers (CASE 1 and CASE 3: millingcn())
                seen: dict[str, int] = {}
                for _n, calls in branches:
                    for t in calls:
                        seen[t] = seen.get(t, 0) + 1
                step = {t for t, k in seen.items() if k >= 3 and 2 * k > len(branches)}
                out += [(number, t, line) for number, calls in branches for t, line in calls.items() if t not in step]
    return out
