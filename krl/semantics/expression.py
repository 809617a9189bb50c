"""One KRL expression outside a program's text: parse it, check it in a scope, evaluate it.

The front end's one way to read a KRL expression that a user or a file gives on its own: a
debugger's watch, condition or set-variable value (interp/debug), the pendant's watch list, the
condition of a cell rule and a stimulus's signal (robot/cellrules.py), a data-list initialiser
(robot/datalist.py, interp/runtime/program.py). Nothing else in the project parses or evaluates
KRL expressions.

The API (reference §4 for expressions)::

    from krl.semantics import expression as X

    e = X.parse("$OUT[3] AND NOT PART_OK")     # the AST (krl.ast.nodes), or ExpressionError
    t = X.check(e, scope)                      # its type in `scope` (krl.semantics.symbols.Scope)
    X.place(e, resolver, scope, layout)        # every name's storage, as seen from `layout`
    v = X.evaluate(e, env)                     # its value, reading variables through `env`

* :func:`parse` runs the project's parser (grammar rule ``expression``, krl/syntax) and AST
  builder (krl/ast) on one line of text: at most :data:`krl.limits.MAX_EXPRESSION_CHARS`
  characters and `max_tokens` tokens, nesting and terms within krl/limits.py. The text is
  never read as anything but a KRL expression.
* :func:`check` types it with the checker (krl/semantics/checker.py) in a scope: the same
  rules and messages as ``krl check``; the first error is an :class:`ExpressionError`.
* :func:`place` gives each name its storage as the resolver (krl/semantics/resolve.py) places
  a routine's names, for the runtime's evaluation in a frame of a running program (the tree
  interpreter evaluates it: interp/debug).
* :func:`evaluate` / :func:`compile_expression` are the front end's evaluator for values
  outside a running program: the operators are krl/semantics/values.py's (the interpreters'),
  and every variable, element, component, call and aggregate is read through an :class:`Env`
  that the caller gives. The base :class:`Env` reads none (a constant expression).

Errors: :class:`ExpressionError` (message, 1-based column when known) for text that is no
expression or does not check; :class:`krl.semantics.values.KrlRuntimeError` while evaluating.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NoReturn

from krl.ast import nodes as N
from krl.ast.build import build_expression
from krl.ast.visit import EXPRESSIONS, handlers
from krl.diagnostics import DiagnosticSink
from krl.limits import MAX_EXPRESSION_CHARS, MAX_EXPRESSION_TOKENS
from krl.semantics import types as T
from krl.semantics.checker import Checker, Declarer
from krl.semantics.symbols import Scope
from krl.semantics.values import EnumValue, KrlRuntimeError, binary_op, unary_op
from krl.syntax.parse import default_bundle, parse_expression

Reader = Callable[[], Any]


class ExpressionError(ValueError):
    """Text that is not one KRL expression, or an expression that does not check: ``message``
    and ``column`` (1-based, in the text; None when unknown)."""

    def __init__(self, message: str, column: int | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.column = column


# ------------------------------------------------------------------ parse

def parse(text: str, *, max_tokens: int = MAX_EXPRESSION_TOKENS, path: str = "<expression>") -> N.Expr:
    """The AST of the KRL expression `text` (one line; leading and trailing blanks ignored).

    Raises :class:`ExpressionError` for an empty text, more than
    :data:`~krl.limits.MAX_EXPRESSION_CHARS` characters or `max_tokens` tokens, a line break,
    a syntax error, text after the expression, or nesting past krl/limits.py."""
    text = text.strip()
    if not text:
        raise ExpressionError("empty expression", 1)
    if len(text) > MAX_EXPRESSION_CHARS:
        raise ExpressionError(f"an expression is at most {MAX_EXPRESSION_CHARS} characters", 1)
    bundle = default_bundle()
    parsed = parse_expression(text, max_tokens, bundle)
    if parsed.error is not None:
        col, msg = parsed.error
        raise ExpressionError(f"not a KRL expression: {msg}", col)
    expr = build_expression(parsed.tree, path, bundle.symbolic)
    if expr is None:
        raise ExpressionError("not a KRL expression", 1)
    return expr


# ------------------------------------------------------------------ check

def check(expr: N.Expr, scope: Scope, *, expected: T.KrlType | None = None) -> T.KrlType:
    """The type of `expr` in `scope` (a Scope of a checked workspace, or
    ``krl.semantics.symbols.system_scopes()[0]``), annotating it as ``krl check`` annotates a
    program's expressions (``ann.type``, ``ann.symbol``). `expected`: the type the value is
    for (an enum literal takes it, an aggregate is checked against it). Raises
    :class:`ExpressionError` with the checker's first error (its E-code's message); warnings
    (a name only installed software may declare) are not errors."""
    sink = DiagnosticSink()
    checker = Checker(sink, Declarer(sink))
    if isinstance(expr, N.Aggregate) and expected is not None:
        t = checker.set_type(expr, checker.aggregate(expr, scope, expected))
    else:
        t = checker.expr(expr, scope, expected)
    for d in sink.items:
        if d.is_error:
            raise ExpressionError(d.message, d.column or None)
    return t


# ------------------------------------------------------------------ place

def place(expr: N.Expr, resolver, scope: Scope | None, layout=None) -> None:
    """Give every Name and Call of the checked `expr` its storage and callee (``ann.place``,
    ``ann.callee``) as the workspace's `resolver` (krl/semantics/resolve.py ``Resolver``) places
    the names of a routine whose frame is `layout` (a ``Layout``; None: the names of the
    global scope, no frame). `scope`: where names are looked up (``layout.scope``)."""
    if layout is not None:
        resolver.expr(expr, layout.scope if scope is None else scope, resolver.locals_of(layout), layout.owner)
    else:
        resolver.expr(expr, scope, None, -1)


# ------------------------------------------------------------------ evaluate

class Env:
    """What an evaluated expression may read. Each method is called once per node when the
    expression is compiled and returns a *reader*, a function of no arguments that gives the
    node's value each time the expression is evaluated (so a condition evaluated every IPO
    cycle is compiled once). The base class reads no variable, calls nothing and has no
    frames: a constant expression; subclasses say what they can read (:meth:`refuse` words
    the error)."""

    def refuse(self, node: N.Node, what: str) -> NoReturn:
        """The error for something this environment cannot read (override to word it)."""
        raise KrlRuntimeError(f"{what} is not allowed here")

    def name(self, node: N.Name) -> Reader:
        self.refuse(node, f"the variable {node.name}")

    def index(self, node: N.Index, base: Reader, indices: list[Reader | None]) -> Reader:
        self.refuse(node, "an array element")

    def field(self, node: N.Field, base: Reader) -> Reader:
        self.refuse(node, f"the structure component .{node.name}")

    def call(self, node: N.Call, args: list[Reader | None]) -> Reader:
        self.refuse(node, f"a call of {node.name}")

    def compose(self, node: N.Binary) -> Callable[[Any, Any], Any]:
        """The geometric operator ``:`` (reference §4.3) as a function of its two operands."""
        self.refuse(node, "the geometric operator ':'")

    def enum(self, node: N.EnumLit) -> Reader:
        v = EnumValue(node.name)
        return lambda: v

    def aggregate(self, node: N.Aggregate, items: list[tuple[str, Reader]]) -> Reader:
        """An aggregate's value; the base: a dict UPPER component name -> value."""
        return lambda: {k: r() for k, r in items}


class _Compiler:
    """The expression walk (one handler per expression kind, krl/ast/visit.py; the table is the
    class's, made once: a run initialises every data-list value through here, 140 000 of them
    for a KRC backup's 36 entry points, and a table per expression cost 11 µs each)."""

    __slots__ = ("env",)
    _table: dict = {}

    def __init__(self, env: Env) -> None:
        self.env = env

    def build(self, e: N.Expr) -> Reader:
        return self._table[e.__class__](self, e)

    def _literal(self, e) -> Reader:
        v = e.value
        return lambda: v

    e_IntLit = e_RealLit = e_BoolLit = e_StrLit = _literal

    def e_EnumLit(self, e: N.EnumLit) -> Reader:
        return self.env.enum(e)

    def e_Aggregate(self, e: N.Aggregate) -> Reader:
        return self.env.aggregate(e, [(it.name.upper(), self.build(it.value)) for it in e.items])

    def e_ChannelName(self, e: N.ChannelName) -> Reader:
        # a channel (COPEN(:SER_3, HANDLE)) is an argument of a channel routine, no value
        self.env.refuse(e, f"the channel :{e.name}")

    def e_Name(self, e: N.Name) -> Reader:
        return self.env.name(e)

    def e_Index(self, e: N.Index) -> Reader:
        return self.env.index(e, self.build(e.base), [None if i is None else self.build(i) for i in e.indices])

    def e_Field(self, e: N.Field) -> Reader:
        return self.env.field(e, self.build(e.base))

    def e_Call(self, e: N.Call) -> Reader:
        return self.env.call(e, [None if a is None else self.build(a) for a in e.args])

    def e_Unary(self, e: N.Unary) -> Reader:
        f, op = self.build(e.operand), e.op
        return lambda: unary_op(op, f())

    def e_Binary(self, e: N.Binary) -> Reader:
        # a left-nested chain (up to MAX_EXPRESSION_TERMS terms): built and evaluated in a
        # loop, left before right, so its length costs no stack
        left, chain = N.left_chain(e)
        first = self.build(left)
        steps = [(self.env.compose(b) if b.op == ":" else _operator(b.op), self.build(b.right)) for b in chain]

        def chain_value():
            a = first()
            for fn, right in steps:
                a = fn(a, right())
            return a
        return chain_value


_Compiler._table = handlers(_Compiler, "e_", EXPRESSIONS)


def _operator(op: str) -> Callable[[Any, Any], Any]:
    return lambda a, b: binary_op(op, a, b)


def compile_expression(expr: N.Expr, env: Env | None = None) -> Reader:
    """A reader of `expr`'s value (both operands of every operator evaluated, left first; the
    operators of krl/semantics/values.py), reading through `env` (default: :class:`Env`, a
    constant expression). Raises KrlRuntimeError for what `env` refuses."""
    return _Compiler(env if env is not None else Env()).build(expr)


def evaluate(expr: N.Expr, env: Env | None = None) -> Any:
    """The value of `expr` now (:func:`compile_expression`, then read once). Raises
    KrlRuntimeError (what `env` refuses, a run-time error of an operator)."""
    return compile_expression(expr, env)()


__all__ = ["Env", "ExpressionError", "Reader", "check", "compile_expression", "evaluate", "parse", "place"]
