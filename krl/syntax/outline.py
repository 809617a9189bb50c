"""A compact, line-by-line outline of a parse tree, for checking tree shapes.

Each line-level node (any rule whose name ends in `Line`: statementLine, declarationLine,
dataItemLine, headerLine, ...) and each routine or data-list header gives one outline
entry `LINE: sexpr`, where sexpr lists rule names only (tokens are left out), with chains
of single-child rules joined by `/`:

    7: statement/motionStatement/motion/sptpMotion(expression/primaryExpression/... withClause(...))
"""

from __future__ import annotations

from antlr4 import ParserRuleContext


def node_name(ctx: ParserRuleContext) -> str:
    name = type(ctx).__name__
    if name.endswith("Context"):
        name = name[: -len("Context")]
    return name[:1].lower() + name[1:]


def _rule_children(ctx: ParserRuleContext) -> list[ParserRuleContext]:
    return [c for c in (ctx.children or []) if isinstance(c, ParserRuleContext)]


def sexpr(ctx: ParserRuleContext, depth: int = 4) -> str:
    """Rule names of `ctx` and its descendants down to `depth` levels."""
    names = [node_name(ctx)]
    children = _rule_children(ctx)
    while len(children) == 1:
        ctx = children[0]
        names.append(node_name(ctx))
        children = _rule_children(ctx)
    head = "/".join(names)
    if depth <= 0 or not children:
        return head
    return head + "(" + " ".join(sexpr(c, depth - 1) for c in children) + ")"


_HEADER_RULES = ("procedureDefinition", "functionDefinition", "dataList")


def outline(tree: ParserRuleContext, depth: int = 4) -> list[str]:
    """Outline entries of a parse tree, in source order."""
    out: list[str] = []

    def walk(ctx: ParserRuleContext) -> None:
        name = node_name(ctx)
        if name.endswith("Line"):
            kids = _rule_children(ctx)
            if kids:
                out.append(f"{ctx.start.line}: " + " ".join(sexpr(k, depth) for k in kids))
        elif name in _HEADER_RULES:
            kids = [k for k in _rule_children(ctx) if not node_name(k).endswith(("Body", "Line"))]
            out.append(f"{ctx.start.line}: {name}(" + " ".join(sexpr(k, 1) for k in kids) + ")")
        for child in _rule_children(ctx):
            walk(child)

    walk(tree)
    return out
