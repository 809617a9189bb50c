"""KUKA's system software at run time: stand-ins for what the controller has and a backup
does not carry (issue 34, "KUKA's system software, as the controller has it").

A backup is a copy of the controller's user files. The controller itself holds more: the
technology packages (ArcTech, SpotTech, GripperTech, ...), the system functions of KSS
(``IS_KEY_PRESSED``), the message library, ``P00``. A backup's programs, KUKA's templates and
its system files name them; a run of the backup needs a value for each. This module gives
one, *never silently*: the first use of each stand-in writes one note (a ``message`` event
``stub: ...``), every use is counted, and the run summary names each stand-in with its count
(:meth:`SystemSoftware.summary`).

**Which names.** Only names with evidence that KUKA's software declares them — the checker's
decision (krl/semantics/outside.py, docs/diagnostics.md "Names the backup cannot know"; for a
``$`` name no table lists, only a use on a line KUKA's software wrote, as ``$CP_VEL_MODE = 5``
in a backup's ``bas.src``: one the program alone uses stays its error, W107): a
technology package of the platform tables (kss.yaml ``packages``), a line KUKA's software wrote
(a system file, the template's INI fold such as KR C2's ``;FOLD ARCHTECHDIGITAL INI`` with
``IF ARC20==TRUE THEN``, an inline form), a routine of the platform tables (functions.yaml,
kss.yaml: ``EXTFCTP BOOL IS_KEY_PRESSED(INT KEY :IN)`` of ``$operate.dat``), or an ``EXT``
declaration in a KUKA system file (``EXT P00 (...)`` of ``$config.dat``). A name the program
uses without such evidence stays the program's error ("unknown name X", "routine X not found"),
as on a controller. The routines of EthernetKRL and RSI (functions.yaml ``lenient``
``ethernet_krl``, ``rsi``) are the network partners' (issue 35), not stand-ins here.

**Which value.**

* A *variable* of a technology package that is not installed reads the zero value of the type
  its uses give it (``ARC20==TRUE``: BOOL; ``N > 3``: INT): FALSE, 0, 0.0 — what the
  templates test for "package not installed" (``IF ARC20==TRUE THEN A20(ARC_INI)``: the
  ArcTech INI is skipped). A value the program writes is kept. The type comes from the
  checker's types of the other operand (comparison, arithmetic, assignment) or the statement
  (an IF/WHILE/UNTIL/WAIT FOR condition, NOT, AND, OR: BOOL); with no such use the name is
  not stood in (the run stops at it, as before).
* A *procedure* of the system software runs as a no-op (the package would act on its own
  hardware: a weld source, a gun, a gripper; nothing of it is simulated).
* A *function* returns its documented value where there is one (:data:`DOCUMENTED`:
  ``IS_KEY_PRESSED`` is FALSE, no key of the KCP is held in a simulation), else the zero
  value of its declared return type (or of the type its use gives it).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from krl.ast import nodes as N
from krl.semantics import types as T
from krl.semantics.resolve import ROUTINE, UNRESOLVED

from .errors import KrlRuntimeError
from .memory import Slot
from .values import EnumValue, make_value

#: functions of KSS whose value in a simulation is documented: name -> (value, why)
DOCUMENTED: dict[str, tuple[object, str]] = {
    "IS_KEY_PRESSED": (False, "TRUE while the key is held on the KCP/smartPAD "
                              "($operate.dat EXTFCTP BOOL IS_KEY_PRESSED(INT KEY :IN)); "
                              "nobody presses a key in a simulation"),
}

#: the families of routines that the network partners implement (issue 35), never stood in
NETWORK_FAMILIES = ("ethernet_krl", "rsi")

#: KUKA's standard programs the project writes itself, used by a backup that lacks its own:
#: module name -> file (interp/basis/kuka)
STANDARD = {"P00": Path(__file__).resolve().parent.parent / "basis" / "kuka" / "p00.src"}


def standard_files(project) -> list[Path]:
    """The files of :data:`STANDARD` a run of `project` (krl.project.Project) adds: in a KRC
    backup, each standard program whose module the backup does not have (no file of that
    name; KUKA's ``P00`` lives in ``R1/TP/p00.src``). Outside a backup none: the project's
    BASIS holds what such a program may call."""
    if not project.backup:
        return []
    have = {Path(f).stem.upper() for f in project.files}
    return [f for name, f in STANDARD.items() if name not in have]

_BOOL_OPS = ("AND", "OR", "EXOR", "NOT")
_CMP = ("==", "<>", "<", ">", "<=", ">=")


@dataclass
class StandIn:
    """One stand-in: ``name`` as first used, ``what`` (variable, procedure, function,
    statement, type), ``value`` (what it reads or returns, as text), ``why`` (the evidence)."""

    name: str
    what: str
    value: str = ""
    why: str = ""


def _zero(t):
    """The zero value of type `t`: FALSE, 0, 0.0, a structure or array of zeros; None for
    any other type (an ENUM has no first value the checker keeps: not stood in)."""
    if t is T.BOOL:
        return False
    if t is T.INT:
        return 0
    if t is T.REAL:
        return 0.0
    if isinstance(t, (T.Struc, T.Array)):
        from .values import zero_value  # noqa: PLC0415

        try:
            return zero_value(t)
        except Exception:  # noqa: BLE001 - a type the zero value cannot build
            return make_value(t)
    return None


def _shown(v) -> str:
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, EnumValue):
        return f"#{v.name}"
    if isinstance(v, (int, float)):
        return repr(v)
    return "its zero value"


class SystemSoftware:
    """The stand-ins of one run (module docstring). ``uses``: name -> uses; ``standins``:
    name -> :class:`StandIn`, in order of first use."""

    def __init__(self, rt) -> None:
        self.rt = rt
        self.uses: Counter = Counter()
        self.standins: dict[str, StandIn] = {}
        self._refs: dict[str, Slot] = {}
        self._outside: dict | None = None
        self._types: dict | None = None
        #: id(main routine) -> name, of the standard programs of :data:`STANDARD` the run loaded
        self.standard: dict[int, str] = {}
        files = {str(f): name for name, f in STANDARD.items()}
        for m in rt.program.modules:
            src = m.files.get("src")
            if src is not None and str(src) in files and m.main is not None:
                self.standard[id(m.main)] = m.main.name

    def standard_call(self, routine) -> None:
        """A standard program of the project runs in place of the backup's own (counted; one
        note at the first call)."""
        name = routine.name
        self._record(name.upper(), StandIn(
            name, "standard program", "",
            f"the backup has no {name} of its own (KUKA's R1/TP/{name.lower()}.src); the project's "
            f"standard {name} runs ({STANDARD[name.upper()].relative_to(STANDARD[name.upper()].parents[3])})"))
    # ------------------------------------------------------------------ evidence
    def outside(self) -> dict:
        """(kind, UPPER name) -> why, for every name the checker found outside the backup."""
        if self._outside is None:
            out: dict = {}
            ws = self.rt.program.ws
            unresolved = ws.unresolved()
            if unresolved is not None:
                for (kind, key), (name, uses) in unresolved.uses.items():
                    if kind == "sysvar" and key not in unresolved.packages and not any(u.evidence for u in uses):
                        continue    # a $ name only the program uses: its error (docs/diagnostics.md W107)
                    why = unresolved._why(kind, name, uses)
                    if why:
                        out[(kind, key)] = why
            self._outside = out
        return self._outside

    def use_types(self) -> dict:
        """UPPER name -> the type its uses give an unresolved name or a call of an untyped
        routine (see the module docstring), from the checker's types."""
        if self._types is None:
            types: dict = {}
            for unit in self.rt.program.ws.units:
                for f in (unit.src, unit.dat):
                    if f is not None and f.module is not None:
                        _infer(f.module, types)
            self._types = types
        return self._types

    def _record(self, key: str, standin: StandIn) -> None:
        self.uses[key] += 1
        if key not in self.standins:
            self.standins[key] = standin
            if standin.what == "statement":
                self.rt.message(f"stub: {standin.name} (statement not simulated)")
                return
            if standin.what == "standard program":
                self.rt.message(f"stub: {standin.name} ({standin.why})")
                return
            value = f": {standin.value}" if standin.value else ""
            self.rt.message(f"stub: {standin.name} ({standin.what} of KUKA's system software not in "
                            f"the backup: {standin.why}){value}")

    # ------------------------------------------------------------------ variables
    def name_ref(self, name: str):
        """The stand-in variable for `name` (a name nothing declares; a ``$`` name no table
        of system variables lists), or None when it is the program's own unknown name."""
        key = name.upper()
        ref = self._refs.get(key)
        if ref is not None:
            return ref          # a variable is counted once: how often an interpreter looks it up is its own
        why = self.outside().get(("sysvar" if key[:1] == "$" else "name", key))
        if why is None:
            return None
        t = self.use_types().get(key)
        v = _zero(t) if t is not None else None
        if v is None:
            return None
        ref = self._refs[key] = Slot({"V": v}, "V", t, name)
        self._record(key, StandIn(name, "system variable" if key[:1] == "$" else "variable",
                                  f"reads {_shown(v)}", why))
        return ref

    # ------------------------------------------------------------------ routines
    def _evidence(self, key: str) -> str | None:
        """Why the routine `key` is KUKA's system software, or None."""
        why = self.outside().get(("routine", key))
        if why:
            return why
        from krl.semantics.builtins import load_builtins  # noqa: PLC0415

        b = load_builtins()
        if key in b.routines:
            return "a routine of the platform tables (krl/semantics/data)"
        sym = self._symbol(key)
        if sym is not None and sym.path:
            from krl.workspace import is_kuka_file  # noqa: PLC0415

            if is_kuka_file(sym.path):
                return f"declared by an EXT of KUKA's system file {sym.path.rsplit('/', 1)[-1]}"
        return None

    def _returns(self, key: str):
        """The declared return type of the routine `key`: its EXTFCT in the program's files,
        else its signature in the platform tables; None when neither says."""
        t = getattr(getattr(self._symbol(key), "signature", None), "returns", None)
        if t is not None and t is not T.UNKNOWN:
            return t
        from krl.semantics.builtins import load_builtins  # noqa: PLC0415

        info = load_builtins().routines.get(key)
        name = getattr(info, "returns", None)
        if not name or name == "ANY":
            return None
        from .sysvars import sys_type  # noqa: PLC0415

        return sys_type(name) or getattr(T, name.upper(), None)

    def _symbol(self, key: str):
        scope = getattr(self.rt.program.ws, "global_scope", None)
        return scope.routines.get(key) if scope is not None else None

    @staticmethod
    def network(key: str) -> bool:
        """True for a routine of EthernetKRL or RSI (the network partners', issue 35)."""
        from krl.semantics.builtins import DATA_DIR, _read  # noqa: PLC0415

        lenient = _read("functions.yaml").get("lenient") or {}
        return any(key in {str(n).upper() for n in lenient.get(f, ())} for f in NETWORK_FAMILIES)

    def call(self, name: str, is_function: bool):
        """A call of `name`, which no routine of the program implements: the stand-in's value
        (None for a procedure). Raises KrlRuntimeError "routine NAME not found" for a routine
        without evidence of KUKA's software, a network routine, a function whose value type
        is unknown, or outside a backup."""
        key = name.upper()
        st = self.standins.get(key)
        if st is not None and key not in DOCUMENTED and st.what != ("function" if is_function else "procedure"):
            st = None
        if st is None:
            why = self._evidence(key) if self.rt.program.backup else None
            if why is None or self.network(key):
                raise KrlRuntimeError(f"routine {name} not found")
            if not is_function:
                self._record(key, StandIn(name, "procedure", "no effect", why))
                return None
            if key in DOCUMENTED:
                v, doc = DOCUMENTED[key]
                self._record(key, StandIn(name, "function", f"returns {_shown(v)} ({doc})", why))
                return v
            t = self._returns(key)
            if t is None or t is T.UNKNOWN:
                t = self.use_types().get(key)
            v = _zero(t) if t is not None else None
            if v is None:
                raise KrlRuntimeError(f"routine {name} not found")
            self._record(key, StandIn(name, "function", f"returns {_shown(v)}", why))
            return v
        self.uses[key] += 1
        if not is_function:
            return None
        if key in DOCUMENTED:
            return DOCUMENTED[key][0]
        return _zero(self._returns(key) or self.use_types().get(key))

    def statement(self, what: str) -> None:
        """A statement of reference §5.20 that is recognised and not simulated."""
        key = "STMT " + what.upper()
        self._record(key, StandIn(what, "statement", "no effect", "not simulated"))

    # ------------------------------------------------------------------ report
    def summary(self) -> list[tuple[str, str, int]]:
        """(name, what, uses) of every stand-in of the run, most used first: the calls of a
        routine, the statements of a statement; a variable and a type count once (how often an
        interpreter looks a variable up is its own business: the two interpreters differ)."""
        out = [(st.name, st.what, self.uses[k]) for k, st in self.standins.items()]
        for name in sorted(self.rt.program.stubs):
            if name.upper() not in self.standins and not name.startswith("STMT "):
                out.append((name, "type", 1))
        return sorted(out, key=lambda x: (-x[2], x[0]))


# ---------------------------------------------------------------------- use types
def _unresolved(e) -> str | None:
    """The UPPER name of an unresolved Name, or of a call of a routine no program has."""
    if isinstance(e, N.Name):
        st = e.ann.place if e.ann is not None else None
        if st is not None and st.kind == UNRESOLVED:
            return e.name.upper()
        return None
    if isinstance(e, N.Call):
        c = e.ann.callee if e.ann is not None else None
        if c is not None and c.kind != ROUTINE:
            return e.name.upper()
    return None


def _type_of(e):
    t = e.ann.type if e is not None and e.ann is not None else None
    return None if t is None or t is T.UNKNOWN else t


def _note(types: dict, name: str | None, t) -> None:
    if name is None or t is None or not isinstance(t, (T.Simple, T.Enum, T.Struc)):
        return
    old = types.get(name)
    if old is None or (old is T.INT and t is T.REAL):
        types[name] = t


def _infer(module: N.Module, types: dict) -> None:
    """Add to `types` what the uses in `module` say of the type of each unresolved name."""
    stack: list = [module]
    while stack:
        node = stack.pop()
        if isinstance(node, (N.If, N.While, N.Repeat, N.WaitFor)):
            _note(types, _unresolved(node.cond), T.BOOL)
        elif isinstance(node, N.Unary) and node.op == "NOT":
            _note(types, _unresolved(node.operand), T.BOOL)
        elif isinstance(node, N.Binary):
            left, right = _unresolved(node.left), _unresolved(node.right)
            if node.op in _BOOL_OPS:
                _note(types, left, T.BOOL)
                _note(types, right, T.BOOL)
            else:
                _note(types, left, _type_of(node.right))
                _note(types, right, _type_of(node.left))
        elif isinstance(node, N.Assign):
            _note(types, _unresolved(node.value), _type_of(node.target))
            _note(types, _unresolved(node.target), _type_of(node.value))
        stack.extend(c for c in node.children() if c is not None)
