"""Each declaration and statement of a module named in KRL words, in source order.

``statement_kinds(module)`` gives ``[(line, kind), ...]`` for every routine header, data-list
header, declaration and statement (nested blocks included), pre-order, e.g.
``[(1, "DEF"), (2, "DECL"), (3, "PTP"), (4, "IF"), (5, "assignment"), ...]``. The grammar
construct examples (grammar/constructs/*/ok_*.expect) state, by hand from the reference,
which kinds their lines must build to; this is what they are compared with.
"""

from __future__ import annotations

from krl.ast import nodes as N

_FIXED = {
    N.Assign: "assignment", N.CallStmt: "call", N.If: "IF", N.Switch: "SWITCH", N.For: "FOR",
    N.While: "WHILE", N.Repeat: "REPEAT", N.Loop: "LOOP", N.Exit: "EXIT", N.Goto: "GOTO",
    N.Label: "label", N.Halt: "HALT", N.WaitFor: "WAIT FOR", N.WaitSec: "WAIT SEC",
    N.Continue: "CONTINUE", N.Return: "RETURN", N.OnErrorProceed: "ON_ERROR_PROCEED",
    N.InterruptDecl: "INTERRUPT DECL", N.Resume: "RESUME", N.AninOn: "ANIN ON",
    N.AninOff: "ANIN OFF", N.AnoutOn: "ANOUT ON", N.AnoutOff: "ANOUT OFF", N.MoveEmi: "MOVE_EMI",
    N.StrucDecl: "STRUC", N.EnumDecl: "ENUM", N.SignalDecl: "SIGNAL", N.ImportDecl: "IMPORT",
    N.ChannelDecl: "CHANNEL", N.ArrayInit: "element initialisation",
}


def kind_of(node: N.Node) -> str | None:
    """The KRL words for one declaration or statement node; None for other nodes."""
    if type(node) in _FIXED:
        return _FIXED[type(node)]
    if isinstance(node, N.VarDecl):
        return "DECL CONST" if node.is_const else "DECL"
    if isinstance(node, N.ExtDecl):
        return node.kind.upper()
    if isinstance(node, N.InterruptCtl):
        return f"INTERRUPT {node.action.upper()}"
    if isinstance(node, N.Brake):
        return "BRAKE F" if node.fast else "BRAKE"
    if isinstance(node, N.Trigger):
        return f"TRIGGER WHEN {node.kind}"
    if isinstance(node, N.ConditionalStop):
        return "STOP WHEN PATH"
    if isinstance(node, N.Motion):
        return node.kind.upper()
    if isinstance(node, N.SplineBlock):
        return node.kind.upper()
    if isinstance(node, N.KeywordStmt):
        return " ".join(node.words)
    if isinstance(node, N.DeclStmt):
        return "declaration after statements"
    if isinstance(node, N.Unsupported):
        return f"unsupported {node.rule}"
    if isinstance(node, N.Unparsed):
        return "not understood"
    if isinstance(node, N.Routine):
        return node.kind
    if isinstance(node, N.DataList):
        return "DEFDAT"
    return None


def statement_kinds(module: N.Module) -> list[tuple[int, str]]:
    """(line, kind) of every header, declaration and statement of ``module``, pre-order.
    A declaration or statement nested in another (the action of a TRIGGER or INTERRUPT
    DECL, the BRAKE of an interrupt) is not listed apart."""
    out: list[tuple[int, str]] = []
    nested: set[int] = set()
    for node in module.walk():
        if id(node) in nested:
            continue
        kind = kind_of(node)
        if kind is None:
            continue
        out.append((node.span.line, kind))
        if isinstance(node, (N.Trigger, N.InterruptDecl)):
            for child in node.walk():
                if child is not node:
                    nested.add(id(child))
        if isinstance(node, N.DeclStmt):
            nested.add(id(node.decl))
    return out
