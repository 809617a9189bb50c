"""Signature help: the parameters (name, type, IN/OUT) of the routine whose argument list holds
the cursor, and which of them the cursor is on (reference 2.3: ``name(arg, ...)``; an
omitted mode is OUT)."""

from __future__ import annotations

from dataclasses import dataclass

from krl.ast import nodes as N
from krl.lsp import navigate as _nav
from krl.lsp.analysis import Analysis
from krl.lsp.text import NAME_WORDS, line_tokens


@dataclass(frozen=True)
class Signature:
    """``label`` with the [start, end) character offsets of each parameter in it."""
    label: str
    params: tuple[tuple[int, int], ...]
    active: int
    documentation: str = ""


def open_call(text: str, column: int):
    """(name token, index of the argument) of the innermost unclosed ``name(`` before the
    1-based `column` of one line, else None."""
    toks = [t for t in line_tokens(text) if t.column < column]
    depth = 0
    commas = 0
    for i in range(len(toks) - 1, -1, -1):
        w = toks[i].word
        if w in (")", "]", "}"):
            depth += 1
        elif w in ("[", "{"):
            if depth == 0:
                return None
            depth -= 1
        elif w == "(":
            if depth == 0:
                if i > 0 and toks[i - 1].word in NAME_WORDS:
                    return toks[i - 1], commas
                return None
            depth -= 1
        elif w == "," and depth == 0:
            commas += 1
    return None


def signature_at(an: Analysis, path: str, line: int, column: int) -> Signature | None:
    """The signature for the cursor at 1-based (line, column), else None."""
    fi = an.files.get(path)
    if fi is None or not 0 < line <= len(fi.lines):
        return None
    got = open_call(fi.lines[line - 1], column)
    if got is None:
        return None
    tok, arg = got
    t = _nav.resolve(an, path, line, tok.column)
    if t is None or t.kind != "routine" or t.symbol is None or t.symbol.signature is None:
        return None
    sig = t.symbol.signature
    names = [(p.name, p.mode) for p in sig.params]
    if isinstance(t.decl, (N.Routine, N.ExtDecl)) and len(t.decl.params) == len(names):
        names = [(p.name or n, p.mode) for p, (n, _m) in zip(t.decl.params, names)]
    head = f"{'DEFFCT ' + str(sig.returns) + ' ' if sig.returns is not None else 'DEF '}{t.name}("
    label = head
    spans = []
    for i, (p, (name, mode)) in enumerate(zip(sig.params, names)):
        if i:
            label += ", "
        part = f"{p.type} {name} :{mode or 'OUT'}"
        spans.append((len(label), len(label) + len(part)))
        label += part
    if sig.varargs:
        label += ", ..." if spans else "..."
    label += ")"
    active = min(arg, len(spans) - 1) if spans else 0
    if sig.varargs and arg >= len(spans):
        active = len(spans) - 1 if spans else 0
    doc = "a parameter without IN or OUT is OUT (reference 2.3)" if any(m is None for _, m in names) else ""
    return Signature(label, tuple(spans), active, doc)
