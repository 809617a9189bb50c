"""Inlay hints: the signal name and long text after ``$IN[n]`` / ``$OUT[n]``, and parameter
names before the arguments of a call.

I/O names come from the SIGNAL declarations of the workspace (reference 3.8: ``SIGNAL name
$OUT[n] [TO $OUT[m]]``; usually in $config.dat, also in $machine.dat and other data lists). The
long text of an input or output is the comment at the end of its SIGNAL line: that is where the
backups of the shared corpus keep it (``SIGNAL $EXT_START $IN[12] ;EXTERNER START``); the
corpus holds no separate long-text files (only .src/.dat/.sub), so no other source is read. A
signal group (``TO``) names each of its bits ``name[bit k]``, bit 0 the lowest I/O (3.8).

Only an index written as an INT literal gets a hint; ``$OUT[i]`` depends on the run.
"""

from __future__ import annotations

from dataclasses import dataclass

from krl.ast import nodes as N
from krl.lsp.analysis import Analysis
from krl.lsp.navigate import routine_target
from krl.lsp.text import line_tokens
from krl.syntax.folds import comment_start

IO = ("$IN", "$OUT")


@dataclass(frozen=True)
class Hint:
    """A hint at 1-based (line, column): label, kind ('io' or 'param'), tooltip."""
    line: int
    column: int
    label: str
    kind: str
    tooltip: str = ""


def comment_of(line: str) -> str:
    """The text after the first ``;`` outside a string, stripped ('' without a comment)."""
    i = comment_start(line)
    return line[i + 1:].strip() if i >= 0 else ""


def io_names(an: Analysis) -> dict[tuple[str, int], list[tuple[str, str]]]:
    """(``$IN``/``$OUT``, n) -> [(signal name, long text)] from every SIGNAL declaration."""
    cache = an.__dict__.get("_io_names")
    if cache is not None:
        return cache
    out: dict[tuple[str, int], list[tuple[str, str]]] = {}
    for path, fi in an.files.items():
        data = fi.source.module.data
        items = list(data.items) if data is not None else []
        for r in fi.source.module.routines:
            items.extend(r.decls)
        for d in items:
            if not isinstance(d, N.SignalDecl) or d.start is None or d.start.sysvar.upper() not in IO:
                continue
            text = comment_of(fi.lines[d.span.line - 1]) if 0 < d.span.line <= len(fi.lines) else ""
            io = d.start.sysvar.upper()
            first = d.start.index
            last = d.end.index if d.end is not None else first
            if last - first > 64:           # a group has at most 32 bits (INT); more is a bad file
                last = first + 64
            for n in range(first, last + 1):
                name = d.name if d.end is None else f"{d.name}[bit {n - first}]"
                out.setdefault((io, n), []).append((name, text))
    an.__dict__["_io_names"] = out
    return out


def _io_hint(fi, node: N.Index, names) -> Hint | None:
    base = node.base
    if not isinstance(base, N.Name) or base.name.upper() not in IO or len(node.indices) != 1:
        return None
    idx = node.indices[0]
    if not isinstance(idx, N.IntLit):
        return None
    got = names.get((base.name.upper(), idx.value))
    if not got:
        return None
    toks = line_tokens(fi.lines[base.span.line - 1], base.span.line)
    for i, t in enumerate(toks):
        if t.column == base.span.column and i + 3 < len(toks) and toks[i + 1].word == "[" and toks[i + 3].word == "]":
            end = toks[i + 3].column + 1
            break
    else:
        return None
    label = ", ".join(n for n, _ in got)
    texts = [x for _, x in got if x]
    if texts:
        label += ": " + "; ".join(texts)
    tooltip = "\n".join(f"SIGNAL {n}" + (f" ;{x}" if x else "") for n, x in got)
    return Hint(base.span.line, end, label, "io", tooltip)


def param_names(an: Analysis, c: N.Call) -> list[tuple[str | None, str | None, str]]:
    """(name, mode, type) of each parameter of the routine a call runs: the names of its DEF
    when the workspace has it (an EXT declaration may leave them out), else of the EXT
    declaration (None where it has none), else of the built-in tables."""
    sym = N.symbol_of(c)
    sig = getattr(sym, "signature", None)
    if sig is None:
        return []
    types = [str(p.type) for p in sig.params]
    decl = routine_target(an, sym, c.name).decl
    if isinstance(decl, N.Routine):
        named = [(p.name, p.mode) for p in decl.params]
    elif isinstance(decl, N.ExtDecl):
        named = [(p.name, p.mode) for p in decl.params]
    else:
        named = [(p.name, p.mode) for p in sig.params]
    return [(n, m, types[i] if i < len(types) else "?") for i, (n, m) in enumerate(named)]


def _param_hints(an: Analysis, c: N.Call) -> list[Hint]:
    out = []
    for (name, mode, typ), a in zip(param_names(an, c), c.args):
        if a is None or not name or (isinstance(a, N.Name) and a.name.upper() == name.upper()):
            continue
        out.append(Hint(a.span.line, a.span.column, f"{name}:", "param", f"{typ} {name}" + (f" :{mode}" if mode else "")))
    return out


def hints(an: Analysis, path: str, first_line: int = 1, last_line: int = 1 << 30) -> list[Hint]:
    """The hints of one file between two 1-based lines (inclusive), in file order."""
    fi = an.files.get(path)
    if fi is None:
        return []
    names = io_names(an)
    out: list[Hint] = []
    for n in fi.source.module.walk():
        if not first_line <= n.span.line <= last_line:
            continue
        if isinstance(n, N.Index):
            h = _io_hint(fi, n, names)
            if h is not None:
                out.append(h)
        elif isinstance(n, N.Call):
            out.extend(h for h in _param_hints(an, n) if first_line <= h.line <= last_line)
    out.sort(key=lambda h: (h.line, h.column))
    return out
