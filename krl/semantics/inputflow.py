"""Where the cell's inputs flow in a checked program, and which values take its production path
(issue 85, "the automatic cell as an input search").

A KRL program reads a cell input directly (``IF PART_OK``, ``$IN[7]``, a ``SIGNAL`` group read as
an INT: reference §3.8 "SIGNAL") or through the variables assigned from it
(``ParcaTip = GI_ProductType`` and later ``IF ParcaTip == 10``). This module follows the second
kind of read with the checker's annotations (a Name's symbol and storage, a call's routine),
never by matching text:

* **copies** (:func:`flow`): a variable assigned, anywhere in the program, nothing but an input,
  or a variable that is such a copy, or a parameter passed such a value (``IN`` and ``OUT``
  alike: the callee reads the caller's value), holds that input's value. A variable assigned an
  expression of inputs (``n = GI_A * 10 + GI_B``) *depends* on them without being a copy.
  Variables are told apart by their storage (a frame slot of one routine, a data-list slot).
* **constraints**: the comparisons of a copy (or of an input read directly) with an INT, BOOL or
  negated INT constant in the conjunctions of ``IF``, ``WHILE``, ``REPEAT ... UNTIL``, ``WAIT
  FOR``, and the CASE values of a ``SWITCH`` on it.
* **error paths** (:func:`is_error_path`): a branch holding ``HALT`` or a call of KUKA's message
  routines (``MsgQuit``, ``MsgNotify``, ``Set_KrlMsg``: KUKA System Software 8 "Programming
  messages", interp/runtime/messages.py), directly or in a routine of the program it calls
  whose own statements (not its calls') hold one.

**The production values** (:func:`production_values`). The statements are read in the order of
the program's files; the first that constrains an input decides its value, and an input decided
keeps its value:

* a copy's ``IF`` whose THEN branch is not an error path: the values that make its condition
  TRUE (the THEN branch is the work the program does with that product), else the values that
  make it FALSE when the THEN branch is an error path and the ELSE branch is not;
* a copy's ``WAIT FOR``/``UNTIL`` TRUE, ``WHILE`` FALSE (the loop ends);
* a copy's ``SWITCH``: the first CASE whose body is not an error path;
* an input read *directly* only where one branch of an ``IF`` is an error path and the other is
  not: the value of the other (``IF NOT AIR_OK THEN HALT``). Every other direct read is a
  handshake the automatic cell answers when the program starves (interp/runtime/autocell.py).

What the production values read of each routine (its resolved callees, its conditions, which of
its branches are error paths) is a :class:`RoutineFacts` of the workspace: found once when the
caller keeps it (a run's automatic cell: interp/runtime/autocell.py ``routine_facts``, one per
checked workspace, read by each entry point's run).

Only a conjunction of such comparisons is solved (an ``OR``: its first operand that is one);
``x == c`` gives c, ``x > c`` c + 1, ``x < c`` c - 1, ``>=``/``<=`` c, ``<>`` c + 1, for FALSE the
first value the comparison rejects (0 when it does, else c + 1). A group's value must fit its bits.

**Flags set by interrupts** (:func:`interrupt_flags`): a variable that the handler of an
``INTERRUPT DECL ... WHEN cond DO handler()`` assigns a constant (in the handler's own statements)
takes that value when the interrupt fires, on the rising edge of ``cond`` (reference §5.16), so
an input ``cond`` reads reaches it: a state machine's ``IF StartFlag`` waits on the inputs of the
interrupt that sets ``StartFlag`` (issue 85 item 9; interp/runtime/autocell.py answers it).

**Clocks** (:func:`clock_slots`): the frame slots of each routine assigned a value read from the
clock (``$TIMER``, ``$DATE``, ``$ROBRUNTIME``: their reads are the clock, interp/runtime/sysvars.py
``_timer``/``_clock``), directly or through another such slot: a polling loop that keeps the
time in a local is still a loop that polls (interp/runtime/idle.py ``robot_starves``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from krl.ast import nodes as N
from krl.semantics.resolve import LOCAL, ROUTINE

#: KUKA's message routines whose call makes a branch an error path (module docstring)
MESSAGE_ROUTINES = frozenset({"MSGQUIT", "MSGNOTIFY", "SET_KRLMSG"})
#: the system variables whose read is the clock (interp/runtime/sysvars.py)
CLOCKS = frozenset({"$TIMER", "$DATE", "$ROBRUNTIME"})
#: fixed-point passes over the assignments (a chain of copies longer than this stays unknown)
MAX_PASSES = 16


@dataclass(frozen=True)
class Input:
    """A cell input: ``first`` its ``$IN`` number, ``last`` the last of a SIGNAL group (None: one
    bit), ``name`` the SIGNAL name or ""."""

    first: int
    last: int | None
    name: str = field(default="", compare=False)
    #: (file, line) of the SIGNAL declaration; () for ``$IN[n]``
    declared: tuple = field(default=(), compare=False)

    @property
    def address(self) -> str:
        return f"$IN[{self.first}]" if self.last is None else f"$IN[{self.first}..{self.last}]"

    @property
    def shown(self) -> str:
        return f"{self.name} {self.address}" if self.name else self.address

    def fits(self, value) -> bool:
        if self.last is None:
            return isinstance(value, bool)
        return isinstance(value, int) and not isinstance(value, bool) and \
            0 <= value < (1 << (self.last - self.first + 1))

    def bits(self, value) -> dict[str, bool]:
        """``$IN[n]`` -> its bit of `value` (a bit's BOOL, a group's INT, bit 0 on ``first``)."""
        if self.last is None:
            return {f"$IN[{self.first}]": bool(value)}
        return {f"$IN[{n}]": bool((int(value) >> i) & 1) for i, n in enumerate(range(self.first, self.last + 1))}


@dataclass
class Decision:
    """A value a producing cell gives ``input`` (a bit's BOOL, a group's INT), decided by the
    statement at ``file``:``line`` (``kind``: IF, WHILE, UNTIL, WAIT FOR, SWITCH), read through
    the variables ``through`` (their names; empty: read directly)."""

    input: Input
    value: object
    file: str
    line: int
    kind: str
    through: tuple = ()

    def describe(self) -> str:
        shown = ("TRUE" if self.value else "FALSE") if isinstance(self.value, bool) else str(self.value)
        via = f" (read as {', '.join(self.through)})" if self.through else ""
        name = self.file.replace("\\", "/").rsplit("/", 1)[-1]
        return f"{self.input.shown} := {shown}{via} for {name}:{self.line} ({self.kind})"


@dataclass
class Flow:
    """The inputs' flow through one checked workspace: ``copies`` (variable key -> Input),
    ``depends`` (variable key -> the Inputs its value is computed from), ``names`` (variable
    key -> its declared name), ``assigned`` (variable key -> [(file, line)] where an input's
    value is assigned to it)."""

    copies: dict = field(default_factory=dict)
    depends: dict = field(default_factory=dict)
    names: dict = field(default_factory=dict)
    assigned: dict = field(default_factory=dict)


# ------------------------------------------------------------------ reading names
def input_of(e) -> Input | None:
    """The input `e` reads directly: ``$IN[n]`` with a constant n, or a Name of a SIGNAL on
    ``$IN`` (the checker's symbol); else None."""
    if isinstance(e, N.Index) and isinstance(e.base, N.Name) and e.base.name.upper() == "$IN" \
            and len(e.indices) == 1 and isinstance(e.indices[0], N.IntLit):
        return Input(e.indices[0].value, None)
    if not isinstance(e, N.Name) or e.ann is None or e.ann.symbol is None:
        return None
    sym = e.ann.symbol
    decl = sym.decl
    if sym.kind != "signal" or not isinstance(decl, N.SignalDecl) or decl.start is None \
            or decl.start.sysvar.upper() != "$IN":
        return None
    last = decl.end.index if decl.end is not None else None
    path = sym.path or (decl.span.file if decl.span is not None else "")
    return Input(decl.start.index, last, sym.name, (path, decl.span.line) if path and decl.span else ())


def var_key(e, routine) -> tuple | None:
    """The key of the variable a Name (or the root of an element/field) is: its storage, a
    frame slot with its routine; None for an unplaced name or a signal."""
    while isinstance(e, (N.Index, N.Field)):
        e = e.base
    if not isinstance(e, N.Name) or e.ann is None or e.ann.place is None:
        return None
    if e.ann.symbol is not None and e.ann.symbol.kind == "signal":
        return None
    st = e.ann.place
    if st.kind == LOCAL:
        return ("local", id(routine), st.slot)
    return st.key


def _routines(ws):
    """(routine, file) of every routine of the workspace's files, in their order."""
    for unit in ws.units:
        src = unit.src
        if src is None or src.module is None:
            continue
        for r in src.module.routines:
            yield r, src.path


def _callee(call):
    c = call.ann.callee if call.ann is not None else None
    return c.routine if c is not None and c.kind == ROUTINE else None


def _read(e, routine, flow: Flow) -> tuple[Input | None, set]:
    """(the Input `e` is a copy of or None, the Inputs `e` depends on)."""
    direct = input_of(e)
    if direct is not None:
        return direct, {direct}
    key = var_key(e, routine) if isinstance(e, N.Name) else None
    if key is not None and key in flow.copies:
        return flow.copies[key], set(flow.depends.get(key, ()))
    deps: set = set()
    for sub in e.walk():
        d = input_of(sub)
        if d is not None:
            deps.add(d)
            continue
        k = var_key(sub, routine) if isinstance(sub, N.Name) else None
        if k is not None:
            deps |= flow.depends.get(k, set())
    return None, deps


def _moves(ws):
    """(file, line, target key, target name, source) of every assignment and every argument
    passed to a parameter of a routine of the program; a source is ``(expression, its
    routine)``, or for an ``OUT`` parameter passed a variable the parameter's key (the callee
    writes the caller's variable). An input passed to an ``OUT`` parameter is no copy: the callee
    reads the input itself, live (a direct read)."""
    for r, path in _routines(ws):
        for node in r.walk():
            if isinstance(node, N.Assign):
                key = var_key(node.target, r)
                if key is not None and isinstance(node.target, N.Name):
                    yield path, node.span.line, key, node.target.name, (node.value, r)
            elif isinstance(node, N.Call):
                callee = _callee(node)
                if callee is None:
                    continue
                for j, a in enumerate(node.args):
                    if a is None or j >= len(callee.params):
                        continue
                    param = ("local", id(callee), j)
                    if (callee.params[j].mode or "OUT").upper() == "IN":
                        yield path, node.span.line, param, callee.params[j].name, (a, r)
                    elif input_of(a) is None:
                        yield path, node.span.line, param, callee.params[j].name, (a, r)
                        key = var_key(a, r) if isinstance(a, N.Name) else None
                        if key is not None:
                            yield path, node.span.line, key, a.name, param


def _source(source, flow: "Flow") -> tuple:
    """:func:`_read` of a move's source (an expression or a parameter's key)."""
    if isinstance(source[0], N.Node):
        return _read(source[0], source[1], flow)
    return flow.copies.get(source), set(flow.depends.get(source, ()))


def flow(ws) -> Flow:
    """The :class:`Flow` of the checked workspace `ws` (module docstring: copies, dependences),
    a fixed point of at most :data:`MAX_PASSES` passes over its assignments and calls."""
    out = Flow()
    moves = list(_moves(ws))
    computed: set = set()       # variables assigned an expression of inputs that is no copy
    for _ in range(MAX_PASSES):
        changed = False
        for path, line, key, name, source in moves:
            copy, deps = _source(source, out)
            if not deps:
                continue
            if copy is None:
                computed.add(key)
            elif key not in out.copies:
                out.copies[key] = copy
                changed = True
            have = out.depends.setdefault(key, set())
            if not deps <= have:
                have |= deps
                changed = True
            out.names.setdefault(key, name)
            where = out.assigned.setdefault(key, [])
            if (path, line) not in where:
                where.append((path, line))
        if not changed:
            break
    # a variable assigned two inputs, or an input and an expression of inputs (``w = GI`` and
    # ``w = GI * 2``), copies neither
    out.copies = {k: v for k, v in out.copies.items() if out.depends.get(k) == {v} and k not in computed}
    return out


# ------------------------------------------------------------------ error paths
def _raises(stmts, routine_errors: dict, depth: int) -> bool:
    for node in (n for s in stmts or () for n in s.walk()):
        if isinstance(node, N.Halt):
            return True
        if isinstance(node, N.Call):
            if node.name.upper() in MESSAGE_ROUTINES:
                return True
            callee = _callee(node)
            if callee is not None and depth == 0 and routine_errors.get(id(callee)):
                return True
    return False


def is_error_path(stmts, routine_errors: dict) -> bool:
    """True when the statements `stmts` (a branch) hold ``HALT`` or a message call, or call a
    routine of the program whose own statements do (`routine_errors`: :func:`error_routines`)."""
    return _raises(stmts, routine_errors, 0)


def error_routines(ws) -> dict:
    """id(routine) -> True for each routine of `ws` whose own statements hold ``HALT`` or a
    message call (not through its calls)."""
    return {id(r): _raises(r.body, {}, 1) for r, _p in _routines(ws)}


# ------------------------------------------------------------------ the production values
_FLIP = {"==": "<>", "<>": "==", "<": ">=", ">=": "<", ">": "<=", "<=": ">"}
#: operands of one condition the solver reads (a longer AND/OR chain is not solved)
MAX_OPERANDS = 64


def _const(e):
    """The INT or BOOL constant `e` is (a negated INT literal included), else None."""
    if isinstance(e, (N.IntLit, N.BoolLit)):
        return e.value
    if isinstance(e, N.Unary) and e.op == "-" and isinstance(e.operand, N.IntLit):
        return -e.operand.value
    return None


def _operands(e, op: str) -> list:
    """The operands of a chain of one logical operator `op` (iterative: a chain is nested in
    ``left``), at most :data:`MAX_OPERANDS`; [] beyond."""
    out, todo = [], [e]
    while todo:
        x = todo.pop()
        if isinstance(x, N.Binary) and x.op == op:
            todo += [x.right, x.left]
        else:
            out.append(x)
        if len(out) + len(todo) > MAX_OPERANDS:
            return []
    return out


def _compare(v, op: str, c) -> bool:
    return {"==": v == c, "<>": v != c, "<": v < c, ">": v > c, "<=": v <= c, ">=": v >= c}[op]


def _value(op: str, c):
    """The value that makes ``x op c`` TRUE, the default (0, FALSE) where it does."""
    if isinstance(c, bool):
        return c if op == "==" else (not c if op == "<>" else None)
    default = 0
    if _compare(default, op, c):
        return default
    return {"==": c, "<>": c + 1, "<": c - 1, ">": c + 1, "<=": c, ">=": c}[op]


class _Solver:
    """Values of inputs that give one condition a truth value (module docstring); ``read(e)`` is
    (Input, names read through) or None for an operand it may set."""

    def __init__(self, read, decided: dict) -> None:
        self.read = read
        self.decided = decided          # Input -> value, fixed
        self.new: dict = {}             # Input -> (value, through)

    def value_of(self, atom):
        return self.new[atom][0] if atom in self.new else self.decided.get(atom)

    def literal(self, e, want: bool) -> bool:
        if isinstance(e, N.Unary) and e.op == "NOT":
            return self.solve(e.operand, not want)
        side = op = c = None
        if isinstance(e, N.Binary) and e.op in _FLIP:
            for a, b, o in ((e.left, e.right, e.op), (e.right, e.left, _FLIP_SIDES[e.op])):
                if _const(b) is not None and self.read(a) is not None:
                    side, op, c = self.read(a), o, _const(b)
                    break
        elif self.read(e) is not None:
            side, op, c = self.read(e), "==", True
        if side is None:
            return False
        atom, through = side
        if not want:
            op = _FLIP[op]
        if isinstance(c, bool) != (atom.last is None) or (isinstance(c, bool) and op not in ("==", "<>")):
            return False
        have = self.value_of(atom)
        if have is not None:
            return _compare(have, op, c)
        v = _value(op, c)
        if v is None or not atom.fits(v):
            return False
        self.new[atom] = (v, through)
        return True

    def solve(self, e, want: bool) -> bool:
        """True when `e` can be given the truth value `want` (the values it needs in ``new``)."""
        for op, every in (("AND", want), ("OR", not want)):
            if isinstance(e, N.Binary) and e.op == op:
                parts = _operands(e, op)
                if not parts:
                    return False
                if every:
                    return all(self.solve(p, want) for p in parts)
                for p in parts:
                    saved = dict(self.new)
                    if self.solve(p, want):
                        return True
                    self.new = saved
                return False
        return self.literal(e, want)


_FLIP_SIDES = {"==": "==", "<>": "<>", "<": ">", ">": "<", "<=": ">=", ">=": "<="}


def reachable(ws, roots, facts: "RoutineFacts | None" = None) -> list:
    """(routine, file) of the routines of `ws` that `roots` (Routines) run, with every routine
    a resolved call reaches from them (interrupt routines and TRIGGER actions included: they are
    calls), in the order of the workspace's files; every routine when `roots` is None. `facts`:
    the workspace's :class:`RoutineFacts`, when the caller keeps them."""
    facts = facts if facts is not None else RoutineFacts(ws)
    every = facts.every
    if roots is None:
        return every
    seen: set = set()
    todo = list(roots)
    while todo:
        r = todo.pop()
        if id(r) in seen:
            continue
        seen.add(id(r))
        todo += facts.callees(r)
    return [(r, p) for r, p in every if id(r) in seen]


_KINDS = {N.If: "IF", N.While: "WHILE", N.Repeat: "UNTIL", N.WaitFor: "WAIT FOR", N.Switch: "SWITCH"}


class RoutineFacts:
    """What :func:`production_values` reads of each routine of one checked workspace `ws`,
    whatever its roots: ``every`` ((routine, file) of each routine, in the files' order),
    ``errors`` (:func:`error_routines`), each routine's resolved callees and its IF, WHILE,
    REPEAT, WAIT FOR and SWITCH statements, and whether a branch is an error path; each found
    at its first use, once. A caller that runs many entry points of one workspace keeps one
    (interp/runtime/autocell.py ``routine_facts``: each run's production values walked every
    routine it reaches again). Ids key the memos: the workspace's ASTs must outlive it."""

    def __init__(self, ws) -> None:
        self.every = list(_routines(ws))
        self.errors = error_routines(ws)
        self._callees: dict = {}
        self._statements: dict = {}
        self._error_paths: dict = {}

    def callees(self, routine) -> list:
        """The routines the resolved calls of `routine` call, in its order."""
        got = self._callees.get(id(routine))
        if got is None:
            got = [c for c in (_callee(n) for n in routine.walk() if isinstance(n, N.Call)) if c is not None]
            self._callees[id(routine)] = got
        return got

    def statements(self, routine) -> list:
        """(node, kind) of each IF, WHILE, REPEAT ("UNTIL"), WAIT FOR and SWITCH of `routine`, in order."""
        got = self._statements.get(id(routine))
        if got is None:
            got = [(n, kind) for n in routine.walk() if (kind := _KINDS.get(n.__class__)) is not None]
            self._statements[id(routine)] = got
        return got

    def is_error_path(self, stmts) -> bool:
        """:func:`is_error_path` of the branch `stmts` (a list of the AST) with :attr:`errors`."""
        got = self._error_paths.get(id(stmts))
        if got is None:
            got = self._error_paths[id(stmts)] = is_error_path(stmts, self.errors)
        return got


def production_values(ws, roots=None, the_flow: Flow | None = None,
                      facts: RoutineFacts | None = None) -> list[Decision]:
    """The values a producing cell gives the inputs the routines `roots` run (every routine of
    the checked workspace `ws` when None) read through variables or guard an error path with
    (module docstring), as :class:`Decision` s in the order they were decided. `the_flow`
    (:func:`flow`) and `facts` (:class:`RoutineFacts`) of `ws`, when the caller keeps them:
    made here when None."""
    fl = the_flow if the_flow is not None else flow(ws)
    facts = facts if facts is not None else RoutineFacts(ws)
    decided: dict = {}
    out: list[Decision] = []
    for r, path in reachable(ws, roots, facts):
        for node, kind in facts.statements(r):
            _decide(node, kind, r, path, fl, facts, decided, out)
    return out


def _decide(node, kind: str, r, path, fl: Flow, facts: RoutineFacts, decided: dict, out: list) -> None:
    """The decisions of the statement `node` (of `kind`, in the routine `r` of the file `path`)
    added to `decided` (Input -> value) and `out` (:func:`production_values`)."""
    direct = False
    if kind == "IF":
        then_err, else_err = facts.is_error_path(node.then), facts.is_error_path(node.orelse)
        if then_err and else_err or (not then_err and not node.then):
            return
        want, direct = not then_err, then_err or else_err
    elif kind == "SWITCH":
        got = _switch_value(node, r, fl, decided, facts)
        if got is not None:
            decided[got[0]] = got[1]
            out.append(Decision(got[0], got[1], path, node.span.line, kind, got[2]))
        return
    else:
        want = kind != "WHILE"

    def read(e):
        return _reader(e, r, fl, direct)

    s = _Solver(read, decided)
    if s.solve(node.cond, want):
        for atom, (v, through) in s.new.items():
            decided[atom] = v
            out.append(Decision(atom, v, path, (node.cond.span or node.span).line, kind, through))


def _reader(e, routine, fl: Flow, direct: bool):
    """(Input, names) that `e` reads as a copy of an input, or directly when `direct`."""
    if isinstance(e, N.Name):
        key = var_key(e, routine)
        if key is not None and key in fl.copies:
            return fl.copies[key], (fl.names.get(key, e.name),)
    if direct:
        atom = input_of(e)
        if atom is not None:
            return atom, ()
    return None


def _switch_value(node, routine, fl: Flow, decided: dict, facts: RoutineFacts):
    """(Input, value, names) for a SWITCH on a copy of an undecided group input: its first CASE
    value whose body is not an error path; None otherwise."""
    got = _reader(node.selector, routine, fl, False)
    if got is None or got[0] in decided or got[0].last is None:
        return None
    for case in node.cases:
        if facts.is_error_path(case.body):
            continue
        for v in case.values:
            c = _const(v)
            if c is not None and got[0].fits(c):
                return got[0], c, got[1]
    return None


# ------------------------------------------------------------------ what an error depends on
def inputs_behind(ws, file: str, line: int, the_flow: Flow | None = None) -> list[Input]:
    """The inputs the statement at `file`:`line` depends on: those the names it reads hold or
    were computed from, those read by the conditions of the IFs, SWITCHes and loops around it,
    and those read by the conditions of the IFs and SWITCHes that assign the variables it reads
    (their control dependence), directly or through variables; [] when the line is no
    statement of the workspace."""
    fl = the_flow if the_flow is not None else flow(ws)
    target = _norm(file)
    found: list = []
    for r, path in _routines(ws):
        if _norm(path) != target:
            continue
        read: set = set()
        for node, outer in _with_enclosing(r):
            if isinstance(node, N.Stmt) and node.span is not None and node.span.line == line:
                for e in [x for c in outer for x in c.walk()] + list(node.walk()):
                    _add(found, _read(e, r, fl)[1] if isinstance(e, (N.Name, N.Index)) else ())
                    k = var_key(e, r) if isinstance(e, N.Name) else None
                    if k is not None:
                        read.add(k)
        if read:
            for r2, _p in _routines(ws):
                _guards(r2, read, fl, found)
    return found


def _with_enclosing(routine):
    """(node, the conditions of the IF, SWITCH, WHILE and REPEAT statements enclosing it) of
    every node of `routine`, pre-order (iterative: a deep nesting costs no recursion)."""
    stack = [(routine, ())]
    while stack:
        node, outer = stack.pop()
        yield node, outer
        cond = getattr(node, "selector", None) if isinstance(node, N.Switch) else \
            getattr(node, "cond", None) if isinstance(node, (N.If, N.While, N.Repeat)) else None
        inner = outer + (cond,) if cond is not None else outer
        stack.extend((c, inner) for c in reversed(list(node.children())))


def _guards(routine, keys: set, fl: Flow, found: list) -> None:
    """Adds to `found` the inputs of the conditions of `routine`'s IFs and SWITCHes whose
    branches assign one of the variables `keys`."""
    for node in routine.walk():
        if isinstance(node, N.If):
            cond, branches = node.cond, [node.then, node.orelse or []]
        elif isinstance(node, N.Switch):
            cond, branches = node.selector, [c.body for c in node.cases] + [node.default or []]
        else:
            continue
        if any(isinstance(n, N.Assign) and var_key(n.target, routine) in keys
               for b in branches for s in b for n in s.walk()):
            for e in cond.walk():
                if isinstance(e, (N.Name, N.Index)):
                    _add(found, _read(e, routine, fl)[1])


def _add(found: list, atoms) -> None:
    for a in sorted(atoms, key=lambda a: (a.first, a.last or 0)):
        if a not in found:
            found.append(a)


def _norm(path: str) -> str:
    return str(path).replace("\\", "/").lower()


# ------------------------------------------------------------------ clocks
def clock_slots(ws) -> dict:
    """id(routine) -> the frame slots of that routine assigned a value read from the clock
    (:data:`CLOCKS`), directly or through another such slot of it (module docstring)."""
    out: dict = {}
    for r, _p in _routines(ws):
        slots: set = set()
        assigns = [n for n in r.walk() if isinstance(n, N.Assign)]
        for _ in range(MAX_PASSES):
            before = len(slots)
            for a in assigns:
                key = var_key(a.target, r)
                if key is None or key[0] != "local" or key[2] in slots:
                    continue
                if any(_is_clock(e) or (isinstance(e, N.Name) and (var_key(e, r) or (0,))[0] == "local"
                                        and var_key(e, r)[2] in slots) for e in a.value.walk()):
                    slots.add(key[2])
            if len(slots) == before:
                break
        if slots:
            out[id(r)] = frozenset(slots)
    return out


def _is_clock(e) -> bool:
    return isinstance(e, N.Name) and e.name.upper() in CLOCKS


# ------------------------------------------------------------------ flags set by interrupts
@dataclass(frozen=True)
class Flag:
    """A variable an interrupt's handler sets: ``value`` (the constant assigned), ``decl`` (the
    INTERRUPT DECL node: its ``when`` reads inputs), ``routine`` (the routine declaring it),
    ``handler`` (the handler routine's name, as the runtime's interrupt table names it)."""

    value: object
    decl: object = field(compare=False)
    routine: object = field(compare=False)
    handler: str = ""


def interrupt_flags(ws) -> dict:
    """variable key (:func:`var_key`) -> [:class:`Flag`] for every ``INTERRUPT DECL`` of the
    checked workspace `ws` whose condition reads an input (directly) and whose handler, a routine
    of the program, assigns the variable an INT, BOOL or ENUM constant in its own statements
    (module docstring). Globals and data-list variables only (a handler cannot set another
    routine's locals)."""
    out: dict = {}
    for r, _path in _routines(ws):
        for node in r.walk():
            if not isinstance(node, N.InterruptDecl) or node.call is None or node.brake is not None:
                continue
            if not any(input_of(sub) is not None for sub in node.when.walk()):
                continue
            handler = _callee(node.call)
            if handler is None:
                continue
            for st in handler.walk():
                if not isinstance(st, N.Assign) or not isinstance(st.target, N.Name):
                    continue
                value = _const(st.value)
                if value is None and isinstance(st.value, N.EnumLit):
                    value = st.value
                key = var_key(st.target, handler)
                if value is None or key is None or key[0] == "local":
                    continue
                out.setdefault(key, []).append(Flag(value, node, r, handler.name.upper()))
    return out
