"""KRL expressions typed in a debugger (watch, conditional breakpoint, set variable), seen
from a frame of the running program.

No KRL is read here: the front end's expression API (krl/semantics/expression.py) parses the
text, checks it in the frame's scope (the routine's, else the program's global scope) and
places its names as the resolver places the routine's own; the tree interpreter's ``eval``
evaluates it on the run's Runtime (both interpreters share it). The text is never executed as
anything but a KRL expression.
"""

from __future__ import annotations

from krl.semantics.expression import ExpressionError, check, parse, place

#: the front end's parser of one expression (the debugger checks a breakpoint condition's
#: syntax when it is set, before any frame exists)
parse_expression = parse


def compile_in_frame(rt, text: str, frame):
    """The checked AST of ``text`` with every name placed as ``frame`` (a Frame; None: the
    program's global scope) sees it; raises :class:`ExpressionError` for text that is no
    expression or does not check there."""
    expr = parse(text)
    program = rt.program
    layout = frame.layout if frame is not None else None
    scope = layout.scope if layout is not None and layout.scope is not None else program.ws.global_scope
    check(expr, scope)
    place(expr, program.ws.resolver, scope, layout)
    # a system variable the program itself never names gets its slot now (Program.sysrefs)
    refs = program.sysrefs
    refs.extend([None] * (len(program.ws.system_names) - len(refs)))
    return expr


__all__ = ["ExpressionError", "compile_in_frame", "parse_expression"]
