"""How a system function of KRL is declared: once, with its KRL signature, beside its
implementation (issue 47, "Natives: one registry").

A family module of this package (maths.py, strings.py, eki.py, ...) makes one :class:`Family`
and declares each of its routines on it, in one of three ways:

* ``@FAMILY.native("REAL ABS(REAL X :IN)")`` above ``def _abs(ctx, args)`` (or
  ``FAMILY.add(signature, fn)`` for an implementation a factory makes): the simulator's
  implementation, ``fn(ctx, args) -> value`` (None for a procedure); ``ctx`` is the calling
  run's :class:`~interp.runtime.natives.context.NativeContext`, the calls a native may make
  (never the runtime itself). ``args`` is a list of
  references (interp/runtime/memory.py ``Ref``; an expression argument is a
  :class:`~interp.runtime.natives.args.ValueRef`, an omitted one None): :IN arguments are read
  with ``get()``, :OUT ones written with ``set()``. It raises
  :class:`~interp.runtime.errors.KrlRuntimeError` to stop the program as the controller would.
* ``FAMILY.krl(signature, "bas.src")``: KRL implements it, a routine of the project's BASIS
  (interp/basis/FILE; a backup brings its own): a call binds to that routine like any other
  (a backup whose own BASIS lacks it: the stand-in policy below).
* ``FAMILY.stand_in(signature, returns="...")``: nothing implements it in the simulator; a call
  goes to the stand-in policy for KUKA's software (interp/runtime/kss.py), and ``returns`` says,
  in words, what the call gives (its documented value, or that the run stops).

The signature is written as in ``EXTFCTP``/``EXTP`` declarations (reference 2.6, 4.5-4.8):
``RETURN_TYPE NAME(TYPE NAME[size] :MODE, ...)`` for a function, ``NAME(...)`` for a procedure,
``...`` last for a variable argument list, ``CHAR NAME[]`` for an open CHAR array. A family
made with ``lenient=KEY`` holds routines of one technology package whose declarations live on
the controller: each is declared by its name alone (any arguments, an unchecked result) and
listed under ``lenient: KEY`` of the table.

:func:`build` joins the families that interp/runtime/natives/__init__.py lists into the
registry (a second declaration of a name, or a malformed signature, raises ValueError when the
package is imported). The front end's table krl/semantics/data/functions.yaml is generated
from it (:func:`functions_yaml`, ``python -m interp.runtime.natives.tables``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import wraps

from krl.semantics.builtins import parse_signature
from krl.semantics.facts import ACCESSES, ARGS, CLOCK

FUNCTIONS = "functions"
PROCEDURES = "procedures"


#: the ``value`` of a stand-in that has no documented value (the zero value of its type)
NO_VALUE = None
#: the facts of a pure routine (``pure=True``): it reads and writes its arguments only
PURE = frozenset({ARGS})


@dataclass(frozen=True, slots=True)
class Native:
    """One system routine of the tables: ``name`` (upper case), ``signature`` (the table's
    text; for a lenient name ``ANY NAME(...)``), ``section`` (FUNCTIONS, PROCEDURES, or the
    lenient key of its package), ``family`` (the declaring module's family name) and how it
    runs: ``fn`` (the simulator's implementation), ``krl`` (the BASIS file whose KRL routine
    implements it) or ``stand_in`` (what a call gives when nothing implements it, in words).
    The facts each reader of the routine needs, declared here once (issues 62, 87):

    * ``reads``/``writes``: what a call reads and writes besides its expressions, frozensets of
      krl/semantics/facts.py's accesses (ARGS its arguments, CLOCK the simulated time or a
      random number, SIGNALS, ROBOT, TASKS, WORLD); None for a routine the simulator does not
      implement (a stand-in reads nothing, gives the same value at every call: interp/runtime/kss.py;
      a KRL routine's facts are its statements'). A call of one that reads CLOCK reads the clock
      for the idle watch (:meth:`Family.add` wraps it: interp/runtime/idle.py), nothing else does;
      tests/interp/test_facts.py fails for an implemented routine without them;
    * ``pure`` (a property): it reads and writes its arguments only (a spin that calls it may
      be parked: interp/runtime/spin.py);
    * ``stops``: a call stops the advance run (reference §6.10: PULSE; the front end's
      krl/semantics/advance.py reads it from the generated table's ``advance_stop``);
    * ``value``: a stand-in's documented value (``IS_KEY_PRESSED``: FALSE), :data:`NO_VALUE`
      for the zero value of its result type (interp/runtime/kss.py)."""

    name: str
    signature: str
    section: str
    family: str
    fn: Callable | None = None
    krl: str = ""
    stand_in: str = ""
    reads: frozenset | None = None
    writes: frozenset | None = None
    stops: bool = False
    value: object = NO_VALUE

    @property
    def pure(self) -> bool:
        """Its only effects are on its arguments and it reads nothing that changes by itself."""
        return self.reads is not None and self.reads <= PURE and self.writes <= PURE

    @property
    def is_function(self) -> bool:
        """True for a function (a signature with a return type; a lenient name may be used
        either way)."""
        return self.section != PROCEDURES


class Family:
    """The routines one module of this package declares (its family: math, strings, EKI, ...).
    ``lenient``: the key of a package whose routines are known by name only (functions.yaml
    ``lenient``); its declarations take a bare name instead of a signature. ``reads``/``writes``:
    the facts (:class:`Native`) of its implemented routines that do not declare their own."""

    def __init__(self, name: str, lenient: str = "", *, reads=None, writes=None) -> None:
        self.name = name
        self.lenient = lenient
        self.facts = (reads, writes)
        self.entries: list[Native] = []

    def _entry(self, signature: str, **how) -> Native:
        if self.lenient:
            name = signature.strip().upper()
            if not name.replace("_", "").isalnum():
                raise ValueError(f"{self.name}: a lenient routine is declared by its name alone, not {signature!r}")
            entry = Native(name, f"ANY {name}(...)", self.lenient, self.name, **how)
        else:
            is_function = len(signature.split("(", 1)[0].split()) > 1     # a return type before the name
            try:
                sig = parse_signature(signature, is_function)
            except ValueError as exc:
                raise ValueError(f"{self.name}: {exc}") from None
            entry = Native(sig.name, " ".join(signature.split()), FUNCTIONS if is_function else PROCEDURES,
                           self.name, **how)
        self.entries.append(entry)
        return entry

    def native(self, signature: str, *, pure: bool = False, stops: bool = False, reads=None,
               writes=None) -> Callable[[Callable], Callable]:
        """Decorator: the function below implements the routine of `signature` (`stops`, `reads`,
        `writes`: :class:`Native`; `pure` the shorthand for reads and writes :data:`PURE`)."""
        def register(fn: Callable) -> Callable:
            self.add(signature, fn, pure=pure, stops=stops, reads=reads, writes=writes)
            return fn
        return register

    def add(self, signature: str, fn: Callable, *, pure: bool = False, stops: bool = False, reads=None,
            writes=None) -> Callable:
        """`fn` implements the routine of `signature` (a factory's function); returns `fn`.
        Raises ValueError for facts that name no access (krl/semantics/facts.py)."""
        if not callable(fn):
            raise ValueError(f"{self.name}: {signature!r}: the implementation is not callable")
        if pure:
            reads = writes = PURE
        elif reads is None and writes is None:
            reads, writes = self.facts
        if reads is not None or writes is not None:     # (one given: the other is empty)
            reads, writes = frozenset(reads or ()), frozenset(writes or ())
            if (reads | writes) - ACCESSES:
                raise ValueError(f"{self.name}: {signature!r}: facts must be among {sorted(ACCESSES)}")
        run = fn
        if reads is not None and CLOCK in reads:
            @wraps(fn)
            def run(ctx, args, _fn=fn):
                ctx.clock_read()            # it reads the clock: no idle moment (interp/runtime/idle.py)
                return _fn(ctx, args)
        self._entry(signature, fn=run, reads=reads, writes=writes, stops=stops)
        return fn

    def krl(self, signature: str, file: str) -> None:
        """KRL implements the routine of `signature`: a routine of the BASIS file `file`
        (interp/basis; a backup's own BASIS has it too)."""
        self._entry(signature, krl=file)

    def stand_in(self, signature: str, returns: str, *, value: object = NO_VALUE) -> None:
        """Nothing in the simulator implements the routine of `signature`: a call goes to the
        stand-in policy for KUKA's software (interp/runtime/kss.py); `returns` says what it
        gives, `value` is its documented value (default: its result type's zero value)."""
        if not returns.strip():
            raise ValueError(f"{self.name}: {signature!r}: a stand-in says what a call gives")
        self._entry(signature, stand_in=returns, value=value)


def build(families) -> dict[str, Native]:
    """The registry: every routine of `families` by upper-case name, in declaration order.
    Raises ValueError for a name declared twice."""
    out: dict[str, Native] = {}
    for fam in families:
        for entry in fam.entries:
            if entry.name in out:
                raise ValueError(f"{entry.name} is declared by {out[entry.name].family} and by {fam.name}")
            out[entry.name] = entry
    return out


_HEADER = """\
# GENERATED from the natives registry (interp/runtime/natives/, one module per family):
# do not edit. Regenerate with `python -m interp.runtime.natives.tables`;
# tests/interp/test_natives.py fails when this file is not what the registry makes.
#
# Built-in functions and procedures (reference 4.5-4.8), written as signatures in the
# EXTFCTP/EXTP style: "RETURN_TYPE NAME(TYPE NAME[size] :MODE, ...)" for functions,
# "NAME(...)" for procedures. "..." at the end means a variable argument list.
# An open CHAR array parameter is written "CHAR NAME[]". ANY: the result type is not
# documented; such routines may be used either way.
"""

_LENIENT = """
# Routines of KUKA system modules and technology options that a backup or a project
# calls but does not contain (their declarations live on the controller). Only the names
# are known here: any arguments are accepted and the result (if used) has no checked type.
"""


_BASIS = """
# The routines of KUKA's BASIS package (bas.src: the natives KRL implements in interp/basis/bas.src,
# read from it by interp/runtime/natives/basis.py): the checker declares them in the $BASIS scope
# (krl/semantics/symbols.py).
"""


_ADVANCE_STOP = """
# Routines whose call stops the advance run (reference 6.10; the front end's
# krl/semantics/advance.py): the natives declared with stops=True.
"""


def _quoted(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def functions_yaml(registry: dict[str, Native]) -> str:
    """The text of krl/semantics/data/functions.yaml for `registry`: its functions, its
    procedures, each lenient package's names, the BASIS routines (bas.src) and the routines that
    stop the advance run, in declaration order."""
    out = [_HEADER, "functions:\n"]
    out += [f"  - {_quoted(n.signature)}\n" for n in registry.values() if n.section == FUNCTIONS]
    out.append("\nprocedures:\n")
    out += [f"  - {_quoted(n.signature)}\n" for n in registry.values() if n.section == PROCEDURES]
    out += [_LENIENT, "lenient:\n"]
    keys = list(dict.fromkeys(n.section for n in registry.values() if n.section not in (FUNCTIONS, PROCEDURES)))
    for key in keys:
        names = [n.name for n in registry.values() if n.section == key]
        out.append(f"  {key}:\n")
        out += [f"    - {name}\n" for name in names]
    out += [_BASIS, "basis:\n"]
    out += [f"  - {n.name}\n" for n in registry.values() if n.krl == "bas.src"]
    out += [_ADVANCE_STOP, "advance_stop:\n"]
    out += [f"  - {n.name}\n" for n in registry.values() if n.stops]
    return "".join(out)


__all__ = ["FUNCTIONS", "NO_VALUE", "PROCEDURES", "Family", "Native", "build", "functions_yaml"]
