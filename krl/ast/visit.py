"""One node-dispatch helper for every pass over the AST.

The tree interpreter, the bytecode compiler, the checker, the printer and the front end's
evaluator each handle statements and expressions with one method per node kind, named
``<prefix><ClassName>`` (``s_Assign``, ``e_Binary``, ...), and dispatch through the table
:func:`handlers` builds: ``table[type(node)](node, ...)``, one dict lookup, as CPython's
``ast.NodeVisitor`` without the ``getattr`` per node.

:data:`STATEMENTS` and :data:`EXPRESSIONS` are every statement and expression kind that
krl/ast/nodes.py declares. :func:`handlers` raises :class:`MissingHandler` when a kind has no
method (unless the pass names a ``default``), so a node kind added to the AST fails every
pass that has not learnt it when the pass is built (tests/frontend/test_visitor.py builds
each).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from krl.ast import nodes as N


def node_kinds(base: type) -> tuple[type, ...]:
    """Every class of krl/ast/nodes.py derived from `base` (not `base` itself), in
    declaration order."""
    return tuple(c for c in vars(N).values()
                 if isinstance(c, type) and issubclass(c, base) and c is not base
                 and c.__module__ == N.__name__)


#: every statement kind (an element of a routine's body)
STATEMENTS: tuple[type, ...] = node_kinds(N.Stmt)
#: every expression kind
EXPRESSIONS: tuple[type, ...] = node_kinds(N.Expr)


class MissingHandler(TypeError):
    """A pass has no method for some node kinds (the message names them)."""


def handlers(owner: object, prefix: str, kinds: Iterable[type],
             default: Callable | None = None) -> dict[type, Callable]:
    """``{kind: owner.<prefix><kind name>}`` for every kind of `kinds`.

    `owner` is an instance (bound methods) or a module (its functions). A kind without such
    an attribute gets `default`; without a default, :class:`MissingHandler` names every
    missing ``<prefix><kind name>``."""
    table: dict[type, Callable] = {}
    missing = []
    for kind in kinds:
        fn = getattr(owner, prefix + kind.__name__, None)
        if fn is None:
            if default is None:
                missing.append(prefix + kind.__name__)
                continue
            fn = default
        table[kind] = fn
    if missing:
        raise MissingHandler(f"{type(owner).__name__}: no handler {', '.join(missing)}")
    return table


__all__ = ["EXPRESSIONS", "MissingHandler", "STATEMENTS", "handlers", "node_kinds"]
