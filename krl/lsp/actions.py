"""Quick fixes for the diagnostics that carry a ``help`` (krl/diagnostics):

* E101 ``'x' is not declared`` (help: declare it): ``DECL type x`` before the ENDDAT of the
  module's data list, or after the declarations of the routine (reference 2.5, 3.2). The type
  is the one the checker gave the other side where it knows it: the value assigned to ``x``, the
  variable ``x`` is assigned to, the other operand of a comparison or arithmetic, the parameter
  ``x`` is passed to, INT for a FOR counter, BOOL for a condition; else none is offered.
* E010 ``missing ENDIF for the IF at line n`` (help: add ENDIF before line m / the end of the
  file): the closer on its own line, indented like its opener.
* E002 ``'INTERRUPT5' is read as one name`` (help: KRL needs a space after INTERRUPT): the space.

A fix is made from the diagnostic's code, place and notes, the source text and the workspace's
facts (the undeclared name is the workspace's unresolved use at that place), never from the
words of its message or help.
"""

from __future__ import annotations

from dataclasses import dataclass

from krl.ast import nodes as N
from krl.diagnostics import Diagnostic
from krl.diagnostics.codes import E002, E010, E101
from krl.lsp.analysis import Analysis
from krl.lsp.text import line_tokens
from krl.semantics import types as T
from krl.syntax.blocks import CLOSER
from krl.syntax.messages import split_glued


@dataclass(frozen=True)
class Edit:
    """Insert or replace text: 1-based (line, column) to (end line, end column), exclusive."""
    path: str
    line: int
    column: int
    end_line: int
    end_column: int
    text: str


@dataclass(frozen=True)
class Fix:
    """A quick fix for one diagnostic."""
    title: str
    diagnostic: Diagnostic
    edits: tuple[Edit, ...]
    preferred: bool = False




def _parents(root: N.Node) -> dict[int, N.Node]:
    out: dict[int, N.Node] = {}
    for n in root.walk():
        for c in n.children():
            out[id(c)] = n
    return out


def _known(t) -> bool:
    return t is not None and t is not T.UNKNOWN and not isinstance(t, (T.EnumLitType, T.Array)) and t is not T.VOID


def infer_type(an: Analysis, path: str, line: int, column: int, name: str) -> T.KrlType | None:
    """The type the checker's annotations give the place of an undeclared name (see the module
    docstring), else None."""
    r = an.routine_at(path, line)
    if r is None:
        return None
    node = next((n for n in r.walk() if isinstance(n, N.Name) and n.span.line == line
                 and n.span.column == column and n.name.upper() == name.upper()), None)
    if node is None:
        return None
    parents = _parents(r)
    p = parents.get(id(node))
    if isinstance(p, N.Assign):
        other = p.value if p.target is node else p.target
        t = N.type_of(other)
        return t if _known(t) else None
    if isinstance(p, N.For) and p.var is node:
        return T.INT
    if isinstance(p, (N.If, N.While, N.Repeat, N.WaitFor)) and getattr(p, "cond", None) is node:
        return T.BOOL
    if isinstance(p, N.Binary):
        if p.op in ("AND", "OR", "EXOR"):
            return T.BOOL
        other = p.right if p.left is node else p.left
        t = N.type_of(other)
        return t if _known(t) else None
    if isinstance(p, N.Unary) and p.op == "NOT":
        return T.BOOL
    if isinstance(p, N.Call):
        sig = getattr(N.symbol_of(p), "signature", None)
        if sig is not None:
            for ps, a in zip(sig.params, p.args):
                if a is node:
                    return ps.type if _known(ps.type) else None
    return None


def _decl_text(name: str, t: T.KrlType) -> str:
    if isinstance(t, T.StrType):
        return f"DECL CHAR {name}[{t.length}]" if t.length > 1 else f"DECL CHAR {name}"
    return f"DECL {t} {name}"


def _indent(text: str) -> str:
    return text[:len(text) - len(text.lstrip())]


def _undeclared_at(an: Analysis, d: Diagnostic) -> str | None:
    """The name the workspace found undeclared where `d` stands (its unresolved uses,
    krl/semantics/outside.py), else None (E101 of a parameter: no use)."""
    un = an.ws.unresolved()
    for (kind, _key), (name, uses) in (un.uses.items() if un is not None else ()):
        if kind == "name" and any(u.path == d.path and u.line == d.line and u.column == d.column for u in uses):
            return name
    return None


def _declare(an: Analysis, d: Diagnostic) -> list[Fix]:
    name = _undeclared_at(an, d)
    if name is None:
        return []
    t = infer_type(an, d.path, d.line, d.column, name)
    if t is None:
        return []
    decl = _decl_text(name, t)
    fixes = []
    unit = next((u for u in an.ws.units if u.src is not None and u.src.path == d.path), None)
    if unit is not None and unit.dat is not None and unit.dat.path in an.files and unit.dat.ok:
        lines = an.files[unit.dat.path].lines
        end = next((i for i in range(len(lines), 0, -1)
                    if [x.word for x in line_tokens(lines[i - 1], i)][:1] == ["ENDDAT"]), 0)
        if end:
            fixes.append(Fix(f"Declare '{decl}' in {unit.dat.path.rsplit('/', 1)[-1]}", d,
                             (Edit(unit.dat.path, end, 1, end, 1, f"  {decl}\n"),), True))
    r = an.routine_at(d.path, d.line)
    if r is not None:
        lines = an.files[d.path].lines
        last = max([x.span.line for x in r.decls] + [r.span.line])
        body = [s.span.line for s in r.body if s.span.line > last]
        indent = _indent(lines[body[0] - 1]) if body else "  "
        fixes.append(Fix(f"Declare '{decl}' in {r.name}", d, (Edit(d.path, last + 1, 1, last + 1, 1, f"{indent}{decl}\n"),),
                         not fixes))
    return fixes


def _close(an: Analysis, d: Diagnostic) -> list[Fix]:
    """E010 spans the block's opener (krl/syntax/blocks.py); its note, when it has one, is where
    a closer of an outer block was reached: the missing closer goes before that line, else at
    the end of the file."""
    lines = an.files[d.path].lines
    opener = lines[d.line - 1][d.column - 1:d.end_column - 1].upper() if 0 < d.line <= len(lines) else ""
    closer = CLOSER.get(opener)
    if closer is None:
        return []
    indent = _indent(lines[d.line - 1])
    if d.notes:
        at = d.notes[0].line
        edit = Edit(d.path, at, 1, at, 1, f"{indent}{closer}\n")
    else:
        last = len(lines)
        while last > 1 and not lines[last - 1].strip():
            last -= 1
        tail = lines[last - 1] if lines else ""
        edit = Edit(d.path, last, len(tail) + 1, last, len(tail) + 1, f"\n{indent}{closer}")
    return [Fix(f"Insert {closer}", d, (edit,), True)]


def _split(an: Analysis, d: Diagnostic) -> list[Fix]:
    """An E002 that spans a keyword glued to what follows (``INTERRUPT5``): the space it needs."""
    lines = an.files[d.path].lines
    word = lines[d.line - 1][d.column - 1:d.end_column - 1] if 0 < d.line <= len(lines) else ""
    got = split_glued(word)
    if got is None:
        return []
    col = d.column + len(got[0])
    return [Fix(f"Write '{got[0]} {got[1]}'", d, (Edit(d.path, d.line, col, d.line, col, " "),), True)]


def fixes(an: Analysis, path: str, first_line: int, last_line: int) -> list[Fix]:
    """The quick fixes of the diagnostics of `path` on 1-based lines first..last."""
    out: list[Fix] = []
    for d in an.diagnostics_for(path):
        if not d.help or not first_line <= d.line <= last_line:
            continue
        if d.code == E101:
            out.extend(_declare(an, d))
        elif d.code == E010:
            out.extend(_close(an, d))
        elif d.code == E002:
            out.extend(_split(an, d))
    return out
