"""Variables never read: a hint (LSP DiagnosticTag.Unnecessary, shown faded) on the declaration
of a local variable or constant of a routine, or of a module's data list (not GLOBAL), that no
statement reads -- only assigned, or not used at all.

The uses are the checker's (krl/lsp/occurrences.py): a local is visible in its routine only and
a module variable in its module's .src and .dat (reference 2.7), so the files of that module
hold every use. Not hinted: parameters (the caller's interface), signals, IMPORT names, GLOBAL
and $config.dat variables (other programs and the controller's HMI may read them), and files
that do not parse (their uses are not known). These hints are no ``krl check`` diagnostics.
"""

from __future__ import annotations

from dataclasses import dataclass

from krl.lsp.analysis import Analysis
from krl.lsp.navigate import Place
from krl.lsp.occurrences import DECL, READ, WRITE, file_occurrences


@dataclass(frozen=True)
class Unused:
    """A declaration nobody reads: its place, name and whether something assigns it."""
    place: Place
    name: str
    written: bool

    @property
    def message(self) -> str:
        return f"'{self.name}' is assigned but never read" if self.written else f"'{self.name}' is declared but never used"


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
    mine = file_occurrences(an, path)
    candidates = {}
    for o in mine:
        if o.kind != DECL or o.key[0] != "value":
            continue
        sym = _symbol(an, path, o)
        if sym is None or sym.kind not in ("var", "const") or sym.scope not in ("routine", "module") \
                or type(sym.decl).__name__ != "VarDecl":
            continue
        candidates.setdefault(o.key, (o, sym))
    if not candidates:
        return []
    module_files = _module_files(an, path)
    if any(p in an.files and not an.files[p].source.ok for p in module_files):
        return []
    kinds: dict[tuple, set[str]] = {}
    for key, (o, sym) in candidates.items():
        files = [path] if sym.scope == "routine" else module_files
        for p in files:
            for x in file_occurrences(an, p):
                if x.key == key:
                    kinds.setdefault(key, set()).add(x.kind)
    out = [Unused(o.place, o.name, WRITE in kinds.get(key, set()))
           for key, (o, _sym) in candidates.items() if READ not in kinds.get(key, set())]
    return sorted(out, key=lambda u: (u.place.line, u.place.column))


def _symbol(an: Analysis, path: str, o):
    """The symbol of a value declaration occurrence (its VarName's annotation)."""
    from krl.ast import nodes as N  # noqa: PLC0415
    for n in an.files[path].nodes_on(o.place.line):
        if isinstance(n, N.VarName) and n.span.column == o.place.column:
            return N.symbol_of(n)
    return None
