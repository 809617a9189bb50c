"""Reactive rules of a cell file: a PLC that answers the program (issue 22, "The cell").

A rule of the ``rules:`` list of a stimuli file (robot/stimuli.py)::

    rules:
      - when: "$OUT[986] AND NOT PART_READY"   # a KRL boolean expression (one line)
        after: 0.2                             # s after the condition became TRUE
        set: {PART_READY: true, "$IN[12]": true}

fires on the *rising edge* of its condition (FALSE in one IPO cycle, TRUE in the next; before
the first cycle the condition counts as FALSE, so a condition TRUE at the start fires once at
the first cycle) and sets its values in the first IPO cycle at least ``after`` seconds later,
and at least one IPO cycle later (a PLC answers no earlier than its next scan). Edges seen while
an earlier answer is still pending queue up; each is answered.

The condition is KRL text from an untrusted file. It is read only by the front end's
expression API (krl/semantics/expression.py): parsed once, at load time, by the project's own
parser (grammar rule ``expression``) into the project's AST, and only this subset is accepted
(reference §4.1 for the operators):

* literals: ``TRUE``, ``FALSE``, INT and REAL constants;
* ``$IN[n]``, ``$OUT[n]``, ``$ANIN[n]``, ``$ANOUT[n]`` with a constant index;
* a SIGNAL name — declared in ``$config.dat``, a data list of the program or the machine data
  (``SIGNAL PART_OK $IN[3]``, ``SIGNAL $EXT_START $IN[12]``); a group
  (``SIGNAL CODE $IN[1] TO $IN[4]``) reads as an INT, bit 0 on the first input;
* ``NOT``, unary ``-``/``+``, ``AND``, ``OR``, ``EXOR``, ``==``, ``<>``, ``<``, ``>``, ``<=``, ``>=``,
  brackets.

Anything else (a call, a variable, a string, an enum, a structure component) is refused at load
time with the rule's ``file:line``. When the run knows the program's signals, the condition is
type-checked by the front end's checker (the messages of ``krl check``) and compiled once by the
front end's evaluator (:func:`compile_condition`), which reads the signals from the I/O image;
its text never reaches ``eval``.
Limits: :data:`krl.limits.MAX_CELL_RULES` rules, :data:`krl.limits.MAX_RULE_TOKENS` tokens in one
condition.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from krl.ast import nodes as N
from krl.limits import MAX_RULE_TOKENS
from krl.semantics import expression as X
from krl.semantics import types as T
from krl.semantics.symbols import Scope, Symbol, system_scopes

from .io import N_ANALOG, N_DIGITAL, IOImage

#: the operators of the subset (reference §4.1)
BOOL_OPS = ("AND", "OR", "EXOR")
COMPARISONS = ("==", "<>", "<", ">", "<=", ">=")
SIGNAL_ARRAYS = {"$IN": N_DIGITAL, "$OUT": N_DIGITAL, "$ANIN": N_ANALOG, "$ANOUT": N_ANALOG}

Lookup = Callable[[str], "tuple[str, int, int | None] | None"]
Eval = Callable[[IOImage], Any]


class ConditionError(ValueError):
    """A rule condition outside the subset, or naming an unknown signal. ``column`` (1-based,
    in the condition's text) when known."""

    def __init__(self, message: str, column: int | None = None) -> None:
        super().__init__(message)
        self.column = column


def parse_condition(text: str) -> N.Expr:
    """The AST of the condition `text` (one line of KRL), checked against the subset.

    Raises :class:`ConditionError` for text that is no KRL expression, more than
    :data:`~krl.limits.MAX_RULE_TOKENS` tokens, or a construct outside the subset."""
    try:
        expr = X.parse(text, max_tokens=MAX_RULE_TOKENS, path="<rule>")
    except X.ExpressionError as exc:
        raise ConditionError(exc.message, exc.column) from None
    check_subset(expr)
    return expr


def _col(node: N.Node) -> int | None:
    return node.span.column if node.span is not None else None


def check_subset(expr: N.Expr) -> None:
    """Raise :class:`ConditionError` for the first node of `expr` outside the subset."""
    work = [expr]
    while work:
        e = work.pop()
        if isinstance(e, (N.BoolLit, N.IntLit, N.RealLit)):
            continue
        if isinstance(e, N.Name):
            continue
        if isinstance(e, N.Index):
            _signal_index(e)
            continue
        if isinstance(e, N.Unary):
            if e.op not in ("NOT", "-", "+"):
                raise ConditionError(f"operator {e.op} is not allowed in a rule condition", _col(e))
            work.append(e.operand)
            continue
        if isinstance(e, N.Binary):
            if e.op not in BOOL_OPS + COMPARISONS:
                raise ConditionError(f"operator {e.op} is not allowed in a rule condition "
                                     f"(allowed: NOT, {', '.join(BOOL_OPS + COMPARISONS)})", _col(e))
            work.extend((e.left, e.right))
            continue
        what = {N.Call: "a function call", N.StrLit: "a string", N.EnumLit: "an enum constant",
                N.Field: "a structure component", N.Aggregate: "an aggregate"}.get(type(e), type(e).__name__)
        raise ConditionError(f"{what} is not allowed in a rule condition (only inputs, outputs, "
                             f"SIGNAL names, constants and boolean/comparison operators)", _col(e))


def _signal_index(e: N.Index) -> tuple[str, int]:
    base = e.base.name.upper() if isinstance(e.base, N.Name) else ""
    if base not in SIGNAL_ARRAYS:
        raise ConditionError("only $IN[n], $OUT[n], $ANIN[n] and $ANOUT[n] may be indexed in a rule "
                             "condition", _col(e))
    if len(e.indices) != 1 or not isinstance(e.indices[0], N.IntLit):
        raise ConditionError(f"{base}[...] needs one constant index in a rule condition", _col(e))
    n = e.indices[0].value
    if not 1 <= n <= SIGNAL_ARRAYS[base]:
        raise ConditionError(f"{base}[{n}]: index outside 1..{SIGNAL_ARRAYS[base]}", _col(e))
    return base, n


def signal_of(text: str) -> tuple[str, int]:
    """``("$IN", 3)`` for the text ``$IN[3]`` (any case and spacing): the text is read by the
    front end (krl/semantics/expression.py) as a KRL expression that must be one of
    $IN/$OUT/$ANIN/$ANOUT indexed by one constant in range. Raises :class:`ConditionError`."""
    try:
        expr = X.parse(text, max_tokens=MAX_RULE_TOKENS, path="<signal>")
    except X.ExpressionError as exc:
        raise ConditionError(exc.message, exc.column) from None
    if not isinstance(expr, N.Index):
        raise ConditionError("not an indexed signal ($IN[n], $OUT[n], $ANIN[n], $ANOUT[n])", _col(expr))
    return _signal_index(expr)


def names_of(expr: N.Expr) -> list[str]:
    """The signals a condition reads, in order: ``$IN[n]``-style and SIGNAL names (upper case)."""
    out: list[str] = []
    work = [expr]
    while work:
        e = work.pop()
        if isinstance(e, N.Name):
            out.append(e.name.upper())
        elif isinstance(e, N.Index):
            base, n = _signal_index(e)
            out.append(f"{base}[{n}]")
        elif isinstance(e, N.Unary):
            work.append(e.operand)
        elif isinstance(e, N.Binary):
            work.extend((e.right, e.left))
    return list(dict.fromkeys(out))


# ------------------------------------------------------------------ evaluation (the front end's)
def _reader(io_of: Callable[[], IOImage], base: str, first: int, last: int | None) -> X.Reader:
    """A reader of input or output `first` (to `last`: a group, an INT with bit 0 on
    `first`) of the signal array `base` in the I/O image ``io_of()``."""
    if base == "$ANIN":
        return lambda: io_of().get_anin(first)
    if base == "$ANOUT":
        return lambda: io_of().get_anout(first)
    get = "get_in" if base == "$IN" else "get_out"
    if last is None:
        return lambda: getattr(io_of(), get)(first)
    bits = range(first, last + 1)

    def group() -> int:
        g = getattr(io_of(), get)
        return sum(1 << i for i, n in enumerate(bits) if g(n))
    return group


class _IOEnv(X.Env):
    """What a rule condition reads (krl.semantics.expression.Env): the signal arrays with a
    constant index and the SIGNAL names `signals` gives, from the I/O image of the cycle."""

    def __init__(self, signals: dict[str, tuple[str, int, int | None]]) -> None:
        self.signals = signals
        self.io: IOImage | None = None

    def refuse(self, node: N.Node, what: str):
        raise ConditionError(f"{what} is not allowed in a rule condition", _col(node))

    def name(self, node: N.Name) -> X.Reader:
        key = node.name.upper()
        if key in SIGNAL_ARRAYS:
            return lambda: None          # the array of an element read (:meth:`index`)
        base, first, last = self.signals[key]
        return _reader(lambda: self.io, base, first, last)

    def index(self, node: N.Index, base: X.Reader, indices: list) -> X.Reader:
        array, n = _signal_index(node)
        return _reader(lambda: self.io, array, n, None)


def compile_condition(expr: N.Expr, lookup: Lookup) -> Eval:
    """A function of the I/O image giving the condition's BOOL value, compiled once from the
    AST by the front end's evaluator (krl/semantics/expression.py) after its checker typed it.

    `lookup(NAME)` resolves a SIGNAL name to ``(base, first, last)`` (interp/run.py
    ``signal_of``). Raises :class:`ConditionError` for an unknown name, operands of the wrong
    type (the checker's message: ``'AND' cannot be applied to BOOL and INT``) or a condition
    that is not BOOL."""
    system = system_scopes()[0]
    scope = Scope("rule", "<rule>", system)
    signals: dict[str, tuple[str, int, int | None]] = {}
    for e in expr.walk():
        if not isinstance(e, N.Name) or e.name.upper() in SIGNAL_ARRAYS or e.name.upper() in signals:
            continue
        found = lookup(e.name.upper())
        if found is None:
            raise ConditionError(f"unknown signal {e.name.upper()} (neither $IN/$OUT/$ANIN/$ANOUT[n] nor "
                                 f"a SIGNAL declared in $config.dat, the machine data or the program's "
                                 f"data list)", _col(e))
        base, first, last = found
        if base not in SIGNAL_ARRAYS:
            raise ConditionError(f"{e.name.upper()} is a SIGNAL on {base}, not on an input or output", _col(e))
        signals[e.name.upper()] = found
        typ = T.REAL if base in ("$ANIN", "$ANOUT") else (T.INT if last is not None else T.BOOL)
        scope.define("values", Symbol(e.name, "signal", typ, "rule"))
    try:
        typ = X.check(expr, scope)
    except X.ExpressionError as exc:
        raise ConditionError(exc.message, exc.column) from None
    if typ != T.BOOL:
        raise ConditionError(f"the condition is {typ}, not BOOL", _col(expr))
    env = _IOEnv(signals)
    read = X.compile_expression(expr, env)

    def condition(io: IOImage):
        env.io = io
        return read()
    return condition


@dataclass
class Rule:
    """One reactive rule. ``when``: the condition's AST; ``text``: its source text (for
    messages); ``after``: delay in s; ``set``: signal -> value (``$IN[n]``/``$ANIN[n]``, or a
    SIGNAL name until the run resolves it); ``where``: ``file:line`` of the rule; ``source``:
    the I/O event source its changes carry (``cell``; a preset names itself); ``on_fire``: called
    as ``on_fire(rule, t)`` after each answer is written (the automatic cell's program numbers
    in turn, interp/runtime/autocell.py)."""

    when: N.Expr
    text: str
    set: dict[str, Any]
    after: float = 0.0
    where: str = ""
    source: str = "cell"
    condition: Eval | None = field(default=None, repr=False)
    last: bool = field(default=False, repr=False)
    due: list[float] = field(default_factory=list, repr=False)
    fired: int = field(default=0, repr=False)
    last_fired: float | None = field(default=None, repr=False)   # s, the last answer written
    on_fire: Callable[["Rule", float], None] | None = field(default=None, repr=False, compare=False)

    def holds(self, io: IOImage) -> bool:
        """The condition's value now (False before the run resolved it)."""
        return bool(self.condition(io)) if self.condition is not None else False


def step_rules(rules: list[Rule], io: IOImage, t: float, dt: float, seen=None):
    """One IPO cycle of the cell (Controller.step, after the timed stimuli): first every answer
    that is due at `t` is written, then every condition is evaluated; a rising edge schedules
    the rule's values for ``max(t + after, t + dt)`` (s). A condition reads only the I/O image:
    `seen`, what the last call returned (the image's version and the number of rules then, and
    the earliest answer due then: s, inf for none), equal to that now means no condition can
    have changed, and none is evaluated; before that earliest answer no rule's answers are
    looked at (only this function schedules them). Returns the value to pass as `seen` next
    time."""
    eps = 1e-9
    n = len(rules)
    answered = seen is None or seen[1] != n or t >= seen[2] - eps
    if answered:
        for r in rules:
            while r.due and t >= r.due[0] - eps:
                r.due.pop(0)
                r.fired += 1
                r.last_fired = t
                for name, v in r.set.items():
                    io.set_signal(name, v, r.source)
                if r.on_fire is not None:
                    r.on_fire(r, t)
    version = io.version
    if seen is not None and version == seen[0] and n == seen[1]:
        return (version, n, _next_due(rules)) if answered else seen
    for r in rules:
        now = r.holds(io)
        if now and not r.last:
            r.due.append(t + max(r.after, dt))
        r.last = now
    return (version, n, _next_due(rules))


def _next_due(rules: list[Rule]) -> float:
    """The earliest answer due of `rules` (s; inf for none): each rule's first (a rule's are in
    time order; a NaN, which is never due, is passed over as :func:`step_rules` never writes it)."""
    nxt = math.inf
    for r in rules:
        if r.due:
            d = r.due[0]
            if d < nxt:
                nxt = d
    return nxt


def rules_may_fire(rules: list[Rule], io: IOImage) -> bool:
    """True if a rule has an answer pending, or its condition rose since the last cycle (it
    will fire in the next one) — the cell may still change an input."""
    return any(r.due or (not r.last and r.holds(io)) for r in rules)

