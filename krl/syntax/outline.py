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


def symbol_outline(module) -> list[str]:
    """The symbols of a built module (krl.ast.nodes.Module), one entry ``LINE: KIND NAME`` each, in
    source order: routines (``DEF PICK(A :IN, B :OUT)``, ``DEFFCT INT SUM(...)``), the data list
    (``DEFDAT DEMO PUBLIC``) and declarations (``DECL INT COUNT``, ``STRUC PAIR``, ``ENUM COLOUR``,
    ``SIGNAL GRIP``, ``EXT NAME``, ``IMPORT``), nested under their routine or data list by two
    spaces. This is what `krl parse --outline` prints."""
    from krl.ast import nodes as N  # noqa: PLC0415

    def decl(d, indent: str) -> list[str]:
        line = d.span.line if d.span is not None else 0
        g = "GLOBAL " if getattr(d, "is_global", False) else ""
        if isinstance(d, N.VarDecl):
            kind = ("CONST " if d.is_const else "") + "DECL " + d.type.name
            return [f"{line}: {indent}{g}{kind} {v.name}" + (f"[{','.join(map(str, v.dims))}]" if v.dims else "")
                    for v in d.names]
        if isinstance(d, N.StrucDecl):
            return [f"{line}: {indent}{g}STRUC {d.name}"]
        if isinstance(d, N.EnumDecl):
            return [f"{line}: {indent}{g}ENUM {d.name}"]
        if isinstance(d, N.SignalDecl):
            return [f"{line}: {indent}{g}SIGNAL {d.name}"]
        if isinstance(d, N.ExtDecl):
            return [f"{line}: {indent}{d.kind} {d.name}"]
        if isinstance(d, N.ImportDecl):
            return [f"{line}: {indent}IMPORT {d.type_name} {d.name}"]
        name = getattr(d, "name", "")
        return [f"{line}: {indent}{type(d).__name__.upper()} {name}".rstrip()] if name else []

    out: list[str] = []
    for r in module.routines:
        params = ", ".join(p.name + (f" :{p.mode}" if p.mode else "") for p in r.params)
        ret = f"{r.return_type.name} " if r.return_type is not None else ""
        g = "GLOBAL " if r.is_global else ""
        out.append(f"{r.span.line}: {g}{r.kind} {ret}{r.name}({params})")
        for d in r.decls:
            out += decl(d, "  ")
    if module.data is not None:
        dl = module.data
        out.append(f"{dl.span.line}: DEFDAT {dl.name}" + (" PUBLIC" if dl.public else ""))
        for d in dl.items:
            out += decl(d, "  ")
    return out
