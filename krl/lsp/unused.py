"""Variables never read: a hint (LSP DiagnosticTag.Unnecessary, shown faded) on the declaration
of a local variable or constant of a routine, or of a module's data list (not GLOBAL), that no
statement reads -- only assigned, or not used at all.

The uses are the checker's annotations (as krl/lsp/occurrences.py reads them: a name is written
when it is an assignment's target, a FOR counter or an argument for an OUT parameter, else
read): a local is visible in its routine only and a module variable in its module's .src and
.dat (reference 2.7), so the files of that module hold every use. Not hinted: parameters (the
caller's interface), signals, IMPORT names, GLOBAL and $config.dat variables (other programs and
the controller's HMI may read them), and files that do not parse (their uses are not known).
These hints are no ``krl check`` diagnostics.

What each routine and data-list item declares and uses is kept per AST node (``Analysis.memo``,
handed from one analysis to the next while the workspace's symbols stay the same), so that after
an edit only the routines it changed are walked again.
"""

from __future__ import annotations

from dataclasses import dataclass

from krl.ast import nodes as N
from krl.lsp.analysis import Analysis
from krl.lsp.navigate import Place
from krl.lsp.occurrences import written_names
from krl.semantics.symbols import Symbol


@dataclass(frozen=True)
class Unused:
    """A declaration nobody reads: its place, name and whether something assigns it."""
    place: Place
    name: str
    written: bool

    @property
    def message(self) -> str:
        return f"'{self.name}' is assigned but never read" if self.written else f"'{self.name}' is declared but never used"


@dataclass(slots=True)
class _Facts:
    """What one routine or data-list item declares (candidates for a hint) and uses."""
    decls: list            # (line, column, name, symbol) of declared variables and constants
    read: set              # ids of the symbols it reads
    written: set           # ... and writes


def _facts_of(node: N.Node) -> _Facts:
    writes = written_names(node)
    out = _Facts([], set(), set())
    for n in node.walk():
        if isinstance(n, N.VarName):
            sym = N.symbol_of(n)
            if isinstance(sym, Symbol) and sym.kind in ("var", "const") and sym.scope in ("routine", "module") \
                    and isinstance(sym.decl, N.VarDecl):
                out.decls.append((n.span.line, n.span.column, n.name, sym))
        elif isinstance(n, (N.Name, N.Call)):
            sym = N.symbol_of(n)
            if isinstance(sym, Symbol) and sym.kind != "routine":
                (out.written if id(n) in writes else out.read).add(id(sym))
    return out


def _facts(an: Analysis, node: N.Node) -> _Facts:
    got = an.memo.get(id(node))
    if got is None or got[0] is not node or got[1] != node.span.line:
        got = an.memo[id(node)] = (node, node.span.line, _facts_of(node))
    return got[2]


def _tops(module: N.Module) -> list[N.Node]:
    return [*module.routines, *(module.data.items if module.data is not None else ())]


def _module_files(an: Analysis, path: str) -> list[str]:
    for u in an.ws.units:
        files = [f.path for f in (u.src, u.dat) if f is not None]
        if path in files:
            return files
    return [path]


def never_read(an: Analysis, path: str) -> list[Unused]:
    """The declarations in `path` that nothing reads (see the module docstring), in file order."""
    fi = an.files.get(path)
    if fi is None or not fi.source.ok:
        return []
    mine = [_facts(an, n) for n in _tops(fi.source.module)]
    candidates: dict[int, tuple] = {}
    for f in mine:
        for line, column, name, sym in f.decls:
            candidates.setdefault(id(sym), (line, column, name, sym))
    if not candidates:
        return []
    module_files = _module_files(an, path)
    if any(p in an.files and not an.files[p].source.ok for p in module_files):
        return []
    read: set[int] = set()
    written: set[int] = set()
    for p in module_files:
        other = an.files.get(p)
        if other is None:
            continue
        for n in _tops(other.source.module):
            f = _facts(an, n)
            read |= f.read
            written |= f.written
    if len(an.memo) > 4 * max(64, sum(len(_tops(x.source.module)) for x in an.files.values())):
        live = {id(n) for x in an.files.values() for n in _tops(x.source.module)}
        for k in [k for k in an.memo if k not in live]:
            del an.memo[k]
    out = [Unused(Place(path, line, column, len(name)), name, key in written)
           for key, (line, column, name, _sym) in candidates.items() if key not in read]
    return sorted(out, key=lambda u: (u.place.line, u.place.column))
