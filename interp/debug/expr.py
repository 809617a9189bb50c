"""KRL expressions typed in a debugger (watch, conditional breakpoint, set variable): parsed
with the project's parser (grammar rule ``expression``, krl/syntax), built into the AST by
the project's builder (krl/ast/build.py), resolved in the scopes of a frame by the front
end's resolver (krl/semantics/resolve.py, as ``Runtime.ref_from_text`` does) and evaluated
by the tree interpreter's ``eval`` on the run's Runtime (both interpreters share it). The
text is never executed as anything but a KRL expression.
"""

from __future__ import annotations

from antlr4 import CommonTokenStream, InputStream, Token
from antlr4.error.ErrorListener import ErrorListener

from krl.limits import MAX_MESSAGE_CHARS

MAX_EXPRESSION_CHARS = 4096     # a typed expression longer than this is refused


class ExpressionError(Exception):
    """The text is not a KRL expression, or names something the frame cannot see."""


class _Raise(ErrorListener):
    def syntaxError(self, recognizer, offending, line, column, msg, e):  # noqa: N802 - ANTLR API
        raise ExpressionError(f"not a KRL expression (column {column + 1}): {msg}"[:MAX_MESSAGE_CHARS])


def parse_expression(text: str):
    """The AST (krl.ast.nodes Expr) of the KRL expression ``text``; raises
    :class:`ExpressionError` for anything else (a statement, trailing text, a syntax error, a
    size past krl/limits.py)."""
    from krl.ast.build import Builder  # noqa: PLC0415
    from krl.diagnostics import DiagnosticSink  # noqa: PLC0415
    from krl.syntax.blocks import first_past_limit  # noqa: PLC0415
    from krl.syntax.parse import default_bundle  # noqa: PLC0415

    text = text.strip()
    if not text:
        raise ExpressionError("empty expression")
    if len(text) > MAX_EXPRESSION_CHARS or "\n" in text or "\r" in text:
        raise ExpressionError(f"an expression is one line of at most {MAX_EXPRESSION_CHARS} characters")
    bundle = default_bundle()
    lexer = bundle.lexer_cls(InputStream(text))
    lexer.removeErrorListeners()
    lexer.addErrorListener(_Raise())
    tokens = CommonTokenStream(lexer)
    tokens.fill()
    past = first_past_limit(tokens.tokens, bundle)
    if past is not None:
        raise ExpressionError(past.message)
    parser = bundle.parser_cls(tokens)
    parser.removeErrorListeners()
    parser.addErrorListener(_Raise())
    tree = parser.expression()
    if tokens.LA(1) != Token.EOF:
        raise ExpressionError(f"unexpected text after the expression: {tokens.LT(1).text[:40]!r}")
    sink = DiagnosticSink()
    expr = Builder("<expression>", sink, list(bundle.parser_cls.symbolicNames), False).expr(tree)
    if sink.items:
        raise ExpressionError(sink.items[0].message)
    return expr


def resolve_in_frame(rt, expr, frame) -> None:
    """Annotate every name and call of ``expr`` with its storage as seen from ``frame``
    (a Frame; None: the program's global scope)."""
    resolver = rt.program.ws.resolver
    if frame is not None and frame.layout is not None:
        layout = frame.layout
        local = {id(s.symbol) if s.symbol is not None else s.name.upper(): k for k, s in enumerate(layout.slots)}
        resolver.expr(expr, layout.scope, local, layout.owner)
    else:
        resolver.expr(expr, rt.program.ws.global_scope, None, -1)
    # a system variable the program itself never names gets its slot now (Program.sysrefs)
    refs = rt.program.sysrefs
    refs.extend([None] * (len(rt.program.ws.system_names) - len(refs)))


def compile_in_frame(rt, text: str, frame):
    """Parse and resolve ``text`` for ``frame``; the expression AST."""
    expr = parse_expression(text)
    resolve_in_frame(rt, expr, frame)
    return expr
