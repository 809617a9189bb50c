"""KUKA's system software at run time: stand-ins for what the controller has and a backup
does not carry (issue 34, "KUKA's system software, as the controller has it").

A backup is a copy of the controller's user files. The controller itself holds more: the
technology packages (ArcTech, SpotTech, GripperTech, ...), the system functions of KSS
(``IS_KEY_PRESSED``), the message library, ``P00``. A backup's programs, KUKA's templates and
its system files name them; a run of the backup needs a value for each. This module gives
one, *never silently*: the first use of each stand-in writes one note (a ``message`` event
``stub: ...``), every use is counted, and the run summary names each stand-in with its count
(:meth:`SystemSoftware.summary`).

**Which names.** Exactly the names the checker finds outside the backup — its one decision
(krl/semantics/outside.py ``Unresolved.classify``: W101/W105/W106/W107, docs/diagnostics.md
"Names the backup cannot know"): a name of a technology package of the platform tables
(kss.yaml ``packages``), a name used on a line KUKA's software wrote (a system file; the
template's INI fold such as KR C2's ``;FOLD ARCHTECHDIGITAL INI`` with ``IF ARC20==TRUE THEN``;
for a routine or a type, a KUKA inline form, whose module names the package: ``%MKUKATPGRP``),
a ``$`` name no table lists. No second rule: every name the checker calls KUKA's stands in,
in a backup or not, and any other name stays the program's error ("unknown name X", "routine
X not found"), as on a controller — also one the checker warns about only because a line of
the program not understood (a syntax error) mentions it (``Outside.kuka`` False: perhaps the program's own
declaration, in a file the controller could not load either). Besides, a routine the checker resolves whose body nothing of the program holds
stands in when outside.py's :func:`~krl.semantics.outside.provided_routine` says KUKA's software
provides it (a routine of the platform tables); a routine an ``EXT``/``EXTFCT`` declaration names
and no module defines is one of the checker's classified names (SpotTech's ``USERSPOT`` of every
module's data list; ``EXT P00 (...)`` of ``$config.dat``), and stands in with its declared
signature. The routines of EthernetKRL and RSI (functions.yaml
``lenient`` ``ethernet_krl``, ``rsi``) are the network partners' (issue 35), not stand-ins here.

**Which value** (docs/robot.md, "KUKA's software the backup lacks").

* A *variable* reads the zero value of the type its uses give it (``ARC20==TRUE``: BOOL;
  ``N > 3``: INT; an argument: the parameter's type): FALSE, 0, 0.0 — what the templates test
  for "package not installed" (``IF ARC20==TRUE THEN A20(ARC_INI)``: the ArcTech INI is
  skipped). A value the program writes is kept. The type comes from the checker's types of the
  other operand (comparison, arithmetic, assignment), the statement (an IF/WHILE/UNTIL/WAIT FOR
  condition, NOT, AND, OR: BOOL) or the parameter it is passed to.
* A variable of an *ENUM* type — one the backup declares, or one it does not
  (``IF ARC_OPTION==#ACTIVE THEN``: a stand-in ENUM type made of the literals its uses compare
  it with, assign to it or switch on) — and a variable whose uses give no type at all (an
  argument of a stand-in routine) read :data:`NOT_INSTALLED`, a value of that type equal to
  none of those literals: ``IF ARC_OPTION==#ACTIVE`` is FALSE, as on a controller without the
  package.
* A *procedure* runs as a no-op (the package would act on its own hardware: a weld source, a
  gun, a gripper; nothing of it is simulated); its arguments are evaluated first, in both
  interpreters.
* A *function* returns its documented value where there is one (:data:`DOCUMENTED`:
  ``IS_KEY_PRESSED`` is FALSE, no key of the KCP is held in a simulation), else the zero
  value of its declared return type (or of the type its use gives it; an ENUM or no type:
  :data:`NOT_INSTALLED`).
"""

from __future__ import annotations

import os
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from krl.ast import nodes as N
from krl.files import child
from krl.semantics import types as T
from krl.semantics.builtins import _read, load_builtins
from krl.semantics.outside import provided_routine
from krl.semantics.resolve import NATIVE, ROUTINE, UNRESOLVED

from .errors import KrlRuntimeError
from .memory import Slot
from .natives import REGISTRY
from .natives.registry import NO_VALUE
from .sysvars import sys_type
from .values import UNSET, Arr, EnumValue, Struct, copy_value, make_value, zero_value

#: functions of KSS whose value in a simulation is documented: name -> (value, why), the
#: stand-ins the natives registry declares with a ``value`` (interp/runtime/natives/packages.py)
DOCUMENTED: dict[str, tuple[object, str]] = {
    name: (native.value, native.stand_in) for name, native in REGISTRY.items()
    if native.stand_in and native.value is not NO_VALUE}

#: the value of a stand-in of an ENUM type, or of no type its uses give: the package is not
#: installed. Its name is not a literal any use compares it with (``NOT_INSTALLED_`` ... then).
NOT_INSTALLED = "NOT_INSTALLED"

#: the families of routines that the network partners implement (issue 35), never stood in
NETWORK_FAMILIES = ("ethernet_krl", "rsi")

_BASIS = Path(__file__).resolve().parent.parent / "basis"


@dataclass(frozen=True)
class Standard:
    """A program of KUKA's software the project writes itself: ``file`` (interp/basis), where
    KUKA keeps it on the controller (``kuka``), what it is (``what``, the run summary's word
    for it) and the run's note's name for it (``called``)."""

    file: Path
    kuka: str
    what: str
    called: str


#: KUKA's programs the project writes itself, used by a backup that lacks its own (a module of
#: that name): module name -> :class:`Standard`. P00, KUKA's standard program of the PLC
#: handshake; COLLMONLIB, KSS 8's collision-detection library whose USE_CM_PRO_VALUES every
#: spline inline form calls (``$COLLMON_TOL_PRO[1] = USE_CM_PRO_VALUES(0)``; without it the
#: stand-in's value stopped the form: the variants sweep's ``no-system R1/System/collmonlib.src``);
#: BAS, the BASIS package (issue 72): interp/basis/bas.src models the BAS commands
#: (BAS(#INITMOV), #TOOL, #BASE, #PTP_PARAMS, #CP_PARAMS, ...) over the ``$config.dat`` data
#: every KUKA ``$config.dat`` declares (TOOL_DATA, BASE_DATA, LOAD_DATA, DEF_VEL_PTP, PDAT_ACT,
#: ...; interp/basis/README.md), as the reference describes them (6.9 "What BAS(...) does to
#: system variables": "A simulator should ship a bas.src-compatible BASIS (it is plain KRL) plus
#: $config.dat defaults, rather than hard-coding these effects"; 6.4 for #TOOL and #BASE)
STANDARD = {
    "P00": Standard(_BASIS / "kuka" / "p00.src", "R1/TP/p00.src", "standard program", "standard P00"),
    "BAS": Standard(_BASIS / "bas.src", "R1/System/bas.src", "BASIS model", "model of KUKA's BASIS"),
    "COLLMONLIB": Standard(_BASIS / "collmonlib.src", "R1/System/collmonlib.src", "collision detection model",
                           "model of KUKA's collision-detection library"),
}

#: the BASIS data list that comes with the BASIS model: merged after the backup's own
#: ``$config.dat`` as outside a backup (krl/project.py rule 4): the backup's declarations hold,
#: this one's fill in what the model reads and the backup lacks (DEF_ADAP_ACC, DEF_LOAD_DATA)
BASIS_CONFIG = _BASIS / "$config.dat"


def standard_files(project) -> list[Path]:
    """The files of :data:`STANDARD` a run of `project` (krl.project.Project) adds: in a KRC
    backup, each standard program whose module the backup does not have (no code file of
    that name: a data list alone pairs with the project's code; KUKA's ``P00`` lives in
    ``R1/TP/p00.src``, ``BAS`` in ``R1/System/bas.src``), and with the BASIS model the BASIS ``$config.dat`` (:data:`BASIS_CONFIG`) first. Outside a backup
    none: the project's BASIS holds what such a program may call (krl/project.py rule 4).

    The BASIS ``$config.dat`` also comes when the robot's System folder has no ``$config.dat``
    of its own (an archive whose ``STEU/$config.dat`` made it a backup: krl/project.py rule 1):
    every KUKA controller has one there, and the backup's own bas.src reads its DEF_* defaults
    (BAS(#INITMOV): ``$CIRC_TYPE = DEF_CIRC_TYP``; reference 6.9), which were stand-ins before
    and stopped the program ("#NOT_INSTALLED is not a value of CIRC_TYPE", the variants sweep's
    ``no-system R1/System/$config.dat``)."""
    if not project.backup:
        return []
    have = set()
    for f in project.files:      # by string operations: at every run's start (pathlib's parse: 1.5 ms)
        stem, ext = os.path.splitext(os.path.basename(f))
        if ext.lower() in (".src", ".sub"):
            have.add(stem.upper())
    missing = [s.file for name, s in STANDARD.items() if name not in have]
    if STANDARD["BAS"].file in missing or not _has_config(project.system):
        missing.insert(0, BASIS_CONFIG)
    return missing


def _has_config(system: Path | None) -> bool:
    """Whether the robot's System folder `system` holds a ``$config.dat`` (any letter case)."""
    return system is not None and child(system, "$config.dat") is not None

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


def _zero(t, absent: str | int | None = None):
    """The value of a stand-in of type `t`: FALSE, 0 (`absent` when it is an INT: an index,
    :data:`FIRST_INDEX`), 0.0, a structure or array of zeros; for an ENUM `absent` (the stand-in
    ENUM's value for "not installed"), else :data:`NOT_INSTALLED` made unequal to its literals;
    None for any other type."""
    if isinstance(t, T.Enum):
        return EnumValue(absent or _not_installed(t.values), t)
    if t is T.BOOL:
        return False
    if t is T.INT:
        return absent if isinstance(absent, int) else 0
    if t is T.REAL:
        return 0.0
    if isinstance(t, (T.Struc, T.Array)):
        try:
            return _enums_not_installed(zero_value(t), t)
        except Exception:  # noqa: BLE001 - a type the zero value cannot build
            return make_value(t)
    return None


def _enums_not_installed(v, t):
    """`v` (a zero value of `t`) with its ENUM leaves, which :func:`zero_value` leaves unset,
    reading "not installed" (:data:`NOT_INSTALLED`)."""
    if isinstance(v, Struct):
        for k, (_, ft) in t.fields.items():
            v.f[k] = _enums_not_installed(v.f[k], ft)
    elif isinstance(v, Arr):
        v.data[:] = [_enums_not_installed(x, t.elem) for x in v.data]
    elif isinstance(t, T.Enum) and v is UNSET:
        v = EnumValue(_not_installed(t.values), t)
    return v


def _not_installed(literals) -> str:
    """:data:`NOT_INSTALLED`, made unequal to every name of `literals` (UPPER)."""
    name = NOT_INSTALLED
    while name in literals:
        name += "_"
    return name


def standin_enum(name: str, literals) -> tuple[T.Enum, str]:
    """(type, value) of the stand-in ENUM of the variable `name` whose type the backup does not
    declare: the literals its uses compare it with, assign or switch on (UPPER), plus the value
    that says "not installed" (:data:`NOT_INSTALLED`, unequal to every one of them), and that
    value."""
    literals = frozenset(x.upper() for x in literals)
    absent = _not_installed(literals)
    return T.Enum(f"{name.upper()} (stand-in ENUM)", literals | {absent}), absent


def _shown(v) -> str:
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, EnumValue):
        return f"#{v.name}"
    if isinstance(v, (int, float)):
        return repr(v)
    return "its zero value"


class StandInSlot(Slot):
    """A stand-in variable. Its type is what its uses suggest, not what the missing software
    declares, so it takes every value the program writes: one its type cannot hold makes it a
    variable of that value's type (a name the checker classifies as installed software never
    ends a run, issue 59: ``oFreqconverterCtlw = gsSpindleWord.WaitForCommand`` with the
    package's data list removed assigns one stand-in's component to another)."""

    __slots__ = ()

    def set(self, v) -> None:
        try:
            Slot.set(self, v)
        except KrlRuntimeError:
            if v is UNSET:
                raise                   # an unset value is the program's error, as for any variable
            self.type = None
            self.c[self.k] = copy_value(v)


class SystemSoftware:
    """The stand-ins of one run (module docstring). ``uses``: name -> uses; ``standins``:
    name -> :class:`StandIn`, in order of first use."""

    #: ``counted(uses)``: adds the calls of the steps the run's fast-forward counted without
    #: running them (spin.py ``parked_stub_uses``; :meth:`attach`); None for a model's load or a tool's copy
    counted = None

    def __init__(self, program, message) -> None:
        """The stand-ins of `program` (program.Program), which give their notes to `message`
        (``message(text)``)."""
        self.program, self.message = program, message
        self.uses: Counter = Counter()
        self.standins: dict[str, StandIn] = {}
        self._refs: dict[str, Slot] = {}
        self._outside: dict | None = None
        self._types: dict | None = None
        self._absent: dict[str, str | int] = {}  # UPPER name -> "not installed" of its stand-in ENUM, or 1 (an index)
        #: id(routine) -> module name, of the main and GLOBAL routines of the standard programs
        #: of :data:`STANDARD` the run loaded (COLLMONLIB is called by its global functions)
        self.standard: dict[int, str] = {}
        files = {str(s.file): name for name, s in STANDARD.items()}
        # only a backup runs them in place of its own (standard_files); outside one the project's
        # BASIS is the program's System folder (krl/project.py rule 4), no stand-in
        for m in program.modules if program.backup else ():
            src = m.files.get("src")
            if src is not None and str(src) in files and m.main is not None:
                for r in m.routines.values():
                    if r is m.main or r.is_global:
                        self.standard[id(r)] = files[str(src)]

    def copy(self, program, message) -> "SystemSoftware":
        """These stand-ins as a run's own (interp/runtime/model.py ``ProgramModel``): the uses
        and notes of the model's load kept (a note is not given twice), each stand-in
        variable's value copied; `program`, `message` as for the constructor. This
        object is only read."""
        k = SystemSoftware.__new__(SystemSoftware)
        k.program, k.message = program, message
        k.uses = Counter(self.uses)
        k.standins = dict(self.standins)
        k._refs = {key: StandInSlot({"V": copy_value(r.c["V"])}, "V", r.type, r.name) for key, r in self._refs.items()}
        k._outside, k._types, k._absent = self._outside, self._types, self._absent
        k.standard = self.standard
        return k

    def standard_call(self, routine) -> None:
        """A standard program of the project runs in place of the backup's own (counted: the
        calls from outside it; one note at the first call)."""
        name = self.standard[id(routine)]
        std = STANDARD[name]
        self._record(name, StandIn(
            name, std.what, "",
            f"the backup has no {name} of its own (KUKA's {std.kuka}); the project's "
            f"{std.called} runs ({std.file.relative_to(_BASIS.parent.parent)})"))
    # ------------------------------------------------------------------ evidence
    def outside(self) -> dict:
        """(kind, UPPER name) -> why, for every name the checker found outside the backup and
        calls KUKA's (krl/semantics/outside.py ``Unresolved.classify``, ``Outside.kuka``: the
        checker's one decision; a name only a line not understood mentions may be the
        program's own, declared there: it stays the program's error)."""
        if self._outside is None:
            self._outside = kuka_names(self.program)
        return self._outside

    def use_types(self) -> dict:
        """UPPER name -> the type its uses give an unresolved name or a call of an untyped
        routine (see the module docstring), from the checker's types; a name of an ENUM type
        the backup does not declare gets its stand-in ENUM (:func:`standin_enum`)."""
        if self._types is None:
            self._types, self._absent = self.program.derived("kss.use_types", _use_types_of)
        return self._types

    def _typed_zero(self, key: str, t=None):
        """(type, value) of the stand-in `key`: the zero value of `t` (the declared type of a
        function) or of the type its uses give it; else the "not installed" value of a stand-in
        ENUM of no literal (its uses give no type: an argument of a stand-in routine)."""
        if t is None or t is T.UNKNOWN:
            t = self.use_types().get(key)
        v = _zero(t, self._absent.get(key)) if t is not None else None
        if v is None:
            t, absent = standin_enum(key, ())
            v = _zero(t, absent)
        return t, v

    def _record(self, key: str, standin: StandIn) -> None:
        self.uses[key] += 1
        if key not in self.standins:
            self.standins[key] = standin
            if standin.what == "statement":
                self.message(f"stub: {standin.name} (statement not simulated)")
                return
            if standin.what in {s.what for s in STANDARD.values()}:
                self.message(f"stub: {standin.name} ({standin.why})")
                return
            value = f": {standin.value}" if standin.value else ""
            where = "the backup" if self.program.backup else "the program's files"
            self.message(f"stub: {standin.name} ({standin.what} of KUKA's system software not in "
                            f"{where}: {standin.why}){value}")

    # ------------------------------------------------------------------ variables
    def name_ref(self, name: str):
        """The stand-in variable for `name` (a name nothing declares; a ``$`` name no table
        of system variables lists), or None when it is the program's own unknown name."""
        key = name.upper()
        ref = self._refs.get(key)
        if ref is not None:
            return ref          # a variable is counted once: how often an interpreter looks it up is its own
        why = self.outside().get(("sysvar" if key[:1] == "$" else "name", key))
        declared = None
        if why is None:
            declared = self._basis_type(key)
            if declared is None:
                return None
            why = ("KUKA's BASIS declares it in $config.dat (krl/semantics/data/types.yaml basis), which "
                   "the program's files do not hold")
        t, v = self._typed_zero(key, declared)
        ref = self._refs[key] = StandInSlot({"V": v}, "V", t, name)
        shown = f"reads {_shown(v)}"
        if isinstance(v, EnumValue):
            others = sorted(x for x in t.values if x != v.name)
            shown += (" (the package is not installed: equal to none of "
                      + ", ".join(f"#{x}" for x in others) + ")" if others else
                      " (the package is not installed; its uses give it no type)")
        self._record(key, StandIn(name, "system variable" if key[:1] == "$" else "variable", shown, why))
        return ref

    def _basis_type(self, key: str):
        """The declared type of `key` when the checker resolved it to KUKA's BASIS tables (the
        basis scope: a global of KUKA's template ``$config.dat`` such as ``DEF_VEL_FACT``) and no
        data list of the program declares it (a folder without ``System/$config.dat`` runs on the
        project's smaller BASIS, interp/basis); else None."""
        scope = getattr(self.program.ws, "global_scope", None)
        basis = scope.parent if scope is not None else None
        sym = basis.values.get(key) if basis is not None and basis.kind == "basis" else None
        t = getattr(sym, "type", None)
        return t if t is not None and t is not T.UNKNOWN else None

    # ------------------------------------------------------------------ routines
    def _evidence(self, key: str) -> str | None:
        """Why the routine `key` is KUKA's system software, or None: the checker's
        classification (an unresolved name with evidence, a routine an EXT names and no module
        defines), else a routine of the platform tables the simulator does not implement."""
        why = self.outside().get(("routine", key))
        if why:
            return why
        return provided_routine(key) or None

    def _returns(self, key: str):
        """The declared return type of the routine `key`: its EXTFCT in the program's files,
        else its signature in the platform tables; None when neither says."""
        t = getattr(getattr(self._symbol(key), "signature", None), "returns", None)
        if t is not None and t is not T.UNKNOWN:
            return t
        info = load_builtins().routines.get(key)
        name = getattr(info, "returns", None)
        if not name or name == "ANY":
            return None
        return sys_type(name) or getattr(T, name.upper(), None)

    def _symbol(self, key: str):
        """The routine symbol of `key`: the global scope's, else an EXT/EXTFCT of a module's
        data list (its declared signature)."""
        ws = self.program.ws
        scope = getattr(ws, "global_scope", None)
        sym = scope.routines.get(key) if scope is not None else None
        if sym is None:
            for unit in getattr(ws, "units", ()):
                sym = unit.scope.routines.get(key) if unit.scope is not None else None
                if sym is not None:
                    break
        return sym

    @staticmethod
    def network(key: str) -> bool:
        """True for a routine of EthernetKRL or RSI (the network partners', issue 35)."""
        lenient = _read("functions.yaml").get("lenient") or {}
        return any(key in {str(n).upper() for n in lenient.get(f, ())} for f in NETWORK_FAMILIES)

    def call(self, name: str, is_function: bool):
        """A call of `name`, which no routine of the program implements: the stand-in's value
        (None for a procedure). Raises KrlRuntimeError "routine NAME not found" for a routine
        without evidence of KUKA's software (the checker's error E106) or a network routine."""
        key = name.upper()
        st = self.standins.get(key)
        if st is not None and key not in DOCUMENTED and st.what != ("function" if is_function else "procedure"):
            st = None
        if st is None:
            why = self._evidence(key)
            if why is None or self.network(key):
                raise KrlRuntimeError(f"routine {name} not found", name=name)
            if not is_function:
                self._record(key, StandIn(name, "procedure", "no effect", why))
                return None
            if key in DOCUMENTED:
                v, doc = DOCUMENTED[key]
                self._record(key, StandIn(name, "function", f"returns {_shown(v)} ({doc})", why))
                return v
            v = self._value(key)
            self._record(key, StandIn(name, "function", f"returns {_shown(v)}", why))
            return v
        self.uses[key] += 1
        if not is_function:
            return None
        if key in DOCUMENTED:
            return DOCUMENTED[key][0]
        return self._value(key)

    def _value(self, key: str):
        """What the stand-in function `key` returns: the zero value of its declared type, else
        of the type its uses give it, else :data:`NOT_INSTALLED` (:meth:`_typed_zero`)."""
        return self._typed_zero(key, self._returns(key))[1]

    def statement(self, what: str) -> None:
        """A statement of reference §5.20 that is recognised and not simulated."""
        key = "STMT " + what.upper()
        self._record(key, StandIn(what, "statement", "no effect", "not simulated"))

    # ------------------------------------------------------------------ report
    def attach(self, counted) -> None:
        """The run's spin watch built (spin.py): `counted(uses)` (:attr:`counted`)."""
        self.counted = counted

    def summary(self) -> list[tuple[str, str, int]]:
        """(name, what, uses) of every stand-in of the run, most used first: the calls of a
        routine, the statements of a statement; a variable and a type count once (how often an
        interpreter looks a variable up is its own business: the two interpreters differ). A
        procedure's calls include those of the steps the spin watch counted without running
        them (interp/runtime/passes.py ``stub_uses``): the count of a run without the watch."""
        uses = Counter(self.uses)
        if self.counted is not None:    # the calls of the steps a parked task was counted (spin.py)
            self.counted(uses)
        out = [(st.name, st.what, uses[k]) for k, st in self.standins.items()]
        for name in sorted(self.program.stubs):
            if name.upper() not in self.standins and not name.startswith("STMT "):
                out.append((name, "type", 1))
        return sorted(out, key=lambda x: (-x[2], x[0]))


# ---------------------------------------------------------------------- use types
#: the value of a stand-in a use takes as an array index (``$CYCFLAG[cycEmStop]`` with the
#: package's data list removed): every KRL array begins at 1, 0 is an index of none
FIRST_INDEX = 1

#: the numbers stand-ins used as interrupt numbers read, one each in the order of their names: the
#: users' priorities from the last (reference 5.16: 1, 2, 4..39 and 81..128 are the users'), so
#: that two interrupts of a package stay two and a program's own low numbers are left alone; 0,
#: an INT stand-in's value, is no priority ("interrupt priority 0 outside 1..128" stopped a
#: milling package's INTERRUPT DECL with its data list removed: the variants sweep, 2026-11-27)
STANDIN_INTERRUPTS = tuple(range(128, 80, -1))

#: a dimension of a stand-in array that a use indexes with a value only the run knows (a FOR
#: counter): the size it gets (its constant indices may ask for more). KRL arrays have the size
#: their declaration gives, and the declaration is what the backup lacks: a decision (docs/robot.md)
STANDIN_DIM = 256


class _Shape:
    """What the uses of an unresolved name (or of one of its components or elements) say of its
    type: ``t`` the type they give it (BOOL when one is a condition, INT an index: ``index``;
    else the first other operand's, assigned value's or parameter's type, REAL over INT),
    ``literals`` the ENUM literals they compare it with, assign to it or switch on, ``dims`` the
    largest constant index of each dimension it is indexed with (negative: also indexed by a
    value only the run knows) and ``elem`` the shape of its elements, ``fields`` the shapes of
    the components selected from it."""

    __slots__ = ("t", "index", "interrupt", "literals", "dims", "elem", "fields")

    def __init__(self) -> None:
        self.t = None
        self.index = False
        self.interrupt = False      # an interrupt's number (INTERRUPT DECL/ON/OFF/...)
        self.literals: set = set()
        self.dims: list | None = None
        self.elem: "_Shape | None" = None
        self.fields: dict = {}


def _shape_of(shapes: dict, e):
    """The shape of expression `e` when it is an unresolved name, an element or a component of
    one (``X``, ``X[i]``, ``X.C``, ``X[i].C``), or a call of a routine no program has; else None."""
    if isinstance(e, N.Name):
        st = e.ann.place if e.ann is not None else None
        if st is not None and st.kind == UNRESOLVED:
            return shapes.setdefault(e.name.upper(), _Shape())
        return None
    if isinstance(e, N.Call):
        c = e.ann.callee if e.ann is not None else None
        if c is not None and c.kind != ROUTINE:
            return shapes.setdefault(e.name.upper(), _Shape())
        return None
    if isinstance(e, N.Index):
        base = _shape_of(shapes, e.base)
        if base is None or base.fields or any(i is None for i in e.indices):
            return None
        if base.dims is None:
            base.dims = [0] * len(e.indices)
        if len(base.dims) != len(e.indices):
            return None
        for k, i in enumerate(e.indices):
            if isinstance(i, N.IntLit):
                base.dims[k] = max(abs(base.dims[k]), i.value) * (-1 if base.dims[k] < 0 else 1)
            elif base.dims[k] >= 0:
                base.dims[k] = -max(1, base.dims[k])     # a variable index: negative marks it
        if base.elem is None:
            base.elem = _Shape()
        return base.elem
    if isinstance(e, N.Field):
        base = _shape_of(shapes, e.base)
        if base is None or base.dims is not None:
            return None
        return base.fields.setdefault(e.name.upper(), _Shape())
    return None


def _type_of(e):
    t = e.ann.type if e is not None and e.ann is not None else None
    return None if t is None or t is T.UNKNOWN else t


def _note(shape, t) -> None:
    if shape is None or t is None or not isinstance(t, (T.Simple, T.Enum, T.Struc)):
        return
    if shape.t is None or (shape.t is T.INT and t is T.REAL):
        shape.t = t


def _cond(shape) -> None:
    """A use as a condition (IF, WHILE, NOT, AND ...): BOOL, whatever other uses say (a
    condition of another type is an error, an assignment of another type is not:
    :class:`StandInSlot`)."""
    if shape is not None:
        shape.t = T.BOOL


def _literal(shape, e) -> None:
    """An ENUM literal `e` compared with, assigned to or switched on by an unresolved name (when
    its type is an ENUM the backup does not declare: :func:`standin_enum`)."""
    if shape is not None and isinstance(e, N.EnumLit):
        shape.literals.add(e.name.upper())


def _param_types(call: N.Call, ws) -> list:
    """The declared types of the parameters of `call`'s routine (a routine of the program, or
    a built-in of the platform tables), None where unknown."""
    c = call.ann.callee if call.ann is not None else None
    if c is None:
        return []
    if c.kind == ROUTINE and c.routine is not None:
        scope = ws.routine_scope(c.routine) if ws is not None else None
        out = []
        for p in c.routine.params:
            sym = scope.lookup(p.name) if scope is not None else None
            out.append(getattr(sym, "type", None) if sym is not None and not p.dims else None)
        return out
    if c.kind == NATIVE:
        info = load_builtins().routines.get(c.name.upper())
        if info is None:
            return []
        return [None if p.dims else (sys_type(p.type_name) or getattr(T, p.type_name.upper(), None))
                for p in info.params]
    return []


def kuka_names(program) -> dict:
    """(kind, UPPER name) -> why, for every name the checker found outside the backup and calls
    KUKA's (krl/semantics/outside.py ``Unresolved.classify``, ``Outside.kuka``: the checker's one
    decision, issue 46), in `program`'s checked workspace; made once per workspace
    (interp/runtime/program.py ``Program.derived``) and read by the stand-ins (:meth:`SystemSoftware.outside`) and
    interp/runtime/program.py ``Program.declared_type``. Read-only."""
    def make(prog) -> dict:
        un = prog.ws.unresolved()
        found = un.classify() if un is not None else {}
        return {key: o.why for key, o in found.items() if o.kuka}
    return program.derived("kuka_names", make)


def _use_types_of(program) -> tuple[dict, dict]:
    """(UPPER name -> type, UPPER name -> "not installed" literal of its stand-in ENUM or
    :data:`FIRST_INDEX` for an index) of
    :meth:`SystemSoftware.use_types`: a walk over every file of `program`'s checked workspace
    (0.22 s on a KRC backup), made once per workspace (Program.derived); read-only. A name its
    uses index is an array, one they select components from a structure (:func:`_typed`)."""
    shapes: dict = {}
    ws = program.ws
    for unit in ws.units:
        for f in (unit.src, unit.dat):
            if f is not None and f.module is not None:
                _infer(f.module, shapes, ws)
    types: dict = {}
    absent: dict = {}
    for name, shape in shapes.items():
        t, none = _typed(name, shape)
        if t is not None:
            types[name] = t
        if none is not None:
            absent[name] = none
    numbers = iter(STANDIN_INTERRUPTS)
    for name in sorted(n for n, shape in shapes.items() if shape.interrupt):
        absent[name] = next(numbers, STANDIN_INTERRUPTS[-1])
    return types, absent


def _typed(name: str, shape: _Shape) -> tuple:
    """(type, "not installed" literal, :data:`FIRST_INDEX` or None) of a stand-in from its
    `shape`: an array of its
    elements' type (each dimension as large as its largest constant index, at least
    :data:`STANDIN_DIM` when a value only the run knows indexes it too), a structure of its
    components' types, else the type its uses give it (INT reading 1 for an index), else a
    stand-in ENUM of the literals they name; (None, None) when they say nothing."""
    if shape.dims is not None:
        elem = _typed(name, shape.elem)[0] if shape.elem is not None else None
        dims = tuple(d if d > 0 else max(STANDIN_DIM, -d) for d in shape.dims)
        return T.Array(elem if elem is not None else T.INT, dims), None
    if shape.fields:
        fields = {}
        for comp, sub in shape.fields.items():
            ft = _typed(f"{name}.{comp}", sub)[0]
            fields[comp] = (comp, ft if ft is not None else T.INT)
        return T.Struc(f"{name} (stand-in STRUC)", fields), None
    if shape.t is not None:
        return shape.t, (FIRST_INDEX if shape.index else None)
    if shape.literals:
        return standin_enum(name, shape.literals)
    return None, None


def _infer(module: N.Module, shapes: dict, ws=None) -> None:
    """Add to `shapes` what the uses in `module` say of each unresolved name (:class:`_Shape`)."""
    stack: list = [module]
    while stack:
        node = stack.pop()
        if isinstance(node, (N.Index, N.Field)):
            _shape_of(shapes, node)         # an element or a component: its name's shape
            for i in node.indices if isinstance(node, N.Index) else ():
                index = _shape_of(shapes, i) if i is not None else None
                if index is not None:       # an index: INT, whatever other uses say, reading 1
                    index.t, index.index = T.INT, True
        elif isinstance(node, (N.If, N.While, N.Repeat, N.WaitFor)):
            _cond(_shape_of(shapes, node.cond))
        elif isinstance(node, N.Unary) and node.op == "NOT":
            _cond(_shape_of(shapes, node.operand))
        elif isinstance(node, N.Binary):
            left, right = _shape_of(shapes, node.left), _shape_of(shapes, node.right)
            if node.op in _BOOL_OPS:
                _cond(left)
                _cond(right)
            else:
                _note(left, _type_of(node.right))
                _note(right, _type_of(node.left))
                if node.op in ("==", "<>"):
                    _literal(left, node.right)
                    _literal(right, node.left)
        elif isinstance(node, (N.Assign, N.WithAssign)):      # a WITH part assigns as well (6.1)
            target = _shape_of(shapes, node.target)
            _note(_shape_of(shapes, node.value), _type_of(node.target))
            _note(target, _type_of(node.value))
            _literal(target, node.value)
        elif isinstance(node, N.Switch):
            sel = _shape_of(shapes, node.selector)
            _note(sel, _type_of(next((v for c in node.cases for v in c.values), None)))
            for c in node.cases:
                for v in c.values:
                    _literal(sel, v)
        elif isinstance(node, N.For):           # the bounds and step of FOR are INT (5.4)
            for e in (node.start, node.end, node.step):
                _note(_shape_of(shapes, e), T.INT)
        elif isinstance(node, (N.InterruptDecl, N.InterruptCtl)):     # an interrupt's number (5.16)
            prio = _shape_of(shapes, node.prio)
            if prio is not None:
                prio.t, prio.interrupt = T.INT, True
        elif isinstance(node, N.Call) and node.args:
            params = _param_types(node, ws)
            for a, t in zip(node.args, params):
                if a is not None:
                    _note(_shape_of(shapes, a), t)
        stack.extend(c for c in node.children() if c is not None)
