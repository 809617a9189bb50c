"""Re-check one module after an edit, reusing the rest of the last check.

Measured on a 400-file workspace (``python -m krl.lsp.bench --workspace``): a full check spends
its time in the routine bodies (checker) and the resolver, not in parsing (the parse cache
re-parses only the routine an edit touches) nor in the declarations. So an edit of a .src/.sub
file whose *interface* stays the same -- its routines' names, kinds, GLOBAL marks, parameters
with their modes and declared types, return types -- re-checks only that file's routines:

* the file's new routines take the place of the old ones in the routine symbols of the global
  and module scopes (the other files' annotations keep pointing at the same symbols);
* the routines get new local scopes and are checked with the declarer and checker of the last
  check (``Workspace.phases``), against the unchanged module and global scopes;
* the unresolved-name report (krl/semantics/outside.py ``Unresolved.finish``: errors per use,
  warnings once per backup with counts over all files) is made again from the recorded uses,
  the file's old uses replaced by its new ones, so it reads exactly as after a full check.

A file that gains or loses a syntax error is handled the same way (its routines are then typed
but not reported, as ``krl check`` does, and the words of the files that do not parse, which
soften the unresolved-name report, are gathered again). Everything else -- a .dat file, a change
of the interface, a file added or removed -- checks the whole workspace again (every module that
may depend on the change). The resolver (storage places for the interpreters) is not run for the edited
file: the editor features read the checker's annotations (``ann.symbol``, ``ann.type``) only;
:meth:`krl.lsp.analysis.Analysis.resolved` runs it for a feature that needs it.
"""

from __future__ import annotations

from functools import lru_cache

from krl.ast import nodes as N
from krl.diagnostics import DiagnosticSink
from krl.lsp.analysis import Analysis, FileInfo
from krl.lsp.parsing import Parsed
from krl.semantics.symbols import Scope


def _type_key(t: N.TypeRef | None):
    return None if t is None else (t.name.upper(), t.size)


def interface(module: N.Module) -> tuple:
    """What other modules can see of a .src file: per routine its kind, name, GLOBAL mark,
    return type and parameters (name, mode, open dimensions, declared type and dimensions)."""
    out = []
    for r in module.routines:
        decl_of: dict[str, tuple] = {}
        for d in r.decls:
            if isinstance(d, N.VarDecl):
                for v in d.names:
                    decl_of.setdefault(v.name.upper(), (_type_key(d.type), tuple(v.dims), d.is_const))
        params = tuple((p.name.upper(), p.mode, p.dims, decl_of.get(p.name.upper())) for p in r.params)
        out.append((r.kind, r.name.upper(), r.is_global, _type_key(r.return_type), params))
    return tuple(out)


def recheck(prev: Analysis, path: str, parsed: Parsed) -> Analysis | None:
    """A new Analysis with `path` re-checked on its own (see the module docstring), or None
    when the whole workspace must be checked again."""
    ws = prev.ws
    phases = ws.phases
    fi = prev.files.get(path)
    if not phases or fi is None or ws.global_scope is None:
        return None
    sf = fi.source
    old_mod, new_mod = sf.module, parsed.module
    if old_mod.kind != "src" or new_mod.kind != "src" or parsed.unreadable or fi.parsed.unreadable:
        return None
    if old_mod.data is not None or new_mod.data is not None or interface(old_mod) != interface(new_mod):
        return None
    unit = next((u for u in ws.units if u.src is sf), None)
    if unit is None or unit.scope is None:
        return None
    syms = phases["routine_symbols"]
    pairs = list(zip(old_mod.routines, new_mod.routines))
    if any(id(r_old) not in syms for r_old, _ in pairs):
        return None
    declarer, checker = phases["declarer"], phases["checker"]
    from krl.workspace import ADVISORY  # noqa: PLC0415

    # the new routines take the old ones' places
    for r_old, r_new in pairs:
        sym = syms.pop(id(r_old))
        syms[id(r_new)] = sym
        if sym.decl is r_old:
            sym.decl = r_new
        ws.routine_scopes.pop(id(r_old), None)
    sf.module = new_mod
    sf.status, sf.ok = parsed.status, parsed.ok
    # the words of files that do not parse (a name among them may be declared there: W101)
    old_failed = set(ws.failed_words)
    ws.failed_words = set()
    for p, other in prev.files.items():
        got = parsed if p == path else other.parsed
        if not got.ok:
            ws.failed_words.update(got.failed_words)

    # this file's parse and body diagnostics go; the unresolved report is made again below
    old_parse = {id(d) for d in fi.parsed.diagnostics}
    body_ids, report_ids = phases["body"], phases["unresolved"]
    drop = {id(d) for d in ws.sink.items if d.path == path and (id(d) in body_ids or id(d) in old_parse)}
    unresolved = declarer.unresolved
    old_uses = _uses_of(unresolved, path)
    for key in list(unresolved.uses):
        name, uses = unresolved.uses[key]
        uses[:] = [u for u in uses if u.path != path]
        if not uses:
            del unresolved.uses[key]

    body = DiagnosticSink()
    declarer.sink = checker.sink = body
    try:
        soft = _kuka(path)
        for _r_old, r in pairs:
            declarer.soft_types = soft
            local = Scope("routine", r.name, unit.scope)
            declarer.declare_types(local, r.decls, path=path, module=unit.name)
            declarer.fill_types(local, r.decls)
            declarer.declare_values(local, r.decls, unit.name, path)
            declarer.complete_signature(syms[id(r)], local)
            ws.routine_scopes[id(r)] = local
        checker.system_file = declarer.soft_types = soft
        checker.submit = path.lower().endswith(".sub")
        if parsed.ok:           # a file with syntax errors: only its syntax errors are reported
            for _r_old, r in pairs:
                checker.check_routine(r, ws.routine_scopes[id(r)], path)
        checker.system_file = declarer.soft_types = checker.submit = False
        report = None
        if _uses_of(unresolved, path) != old_uses or ws.failed_words != old_failed:   # else as before
            report = DiagnosticSink()
            unresolved.finish(report)
    finally:
        declarer.sink = checker.sink = ws.sink
        checker.system_file = declarer.soft_types = checker.submit = False

    def shown(items):
        return [d for d in items if not (d.code in ADVISORY and _kuka(d.path))]
    sink = ws.sink
    sink.remove(drop | (report_ids if report is not None else set()))
    sink.extend(parsed.diagnostics)
    n = len(sink.items)
    sink.extend(shown(body.items))
    m = len(sink.items)
    phases["body"] = {i for i in body_ids if i not in drop} | {id(d) for d in sink.items[n:m]}
    if report is not None:
        sink.extend(shown(report.items))
        phases["unresolved"] = {id(d) for d in sink.items[m:]}
    ws.sink = declarer.sink = checker.sink = sink
    ws.resolver = None                      # storage of the new routines not placed: Analysis.resolved()

    an = Analysis(prev.root, ws, dict(prev.files))
    an.files[path] = FileInfo(path, parsed, sf, _lines(parsed.text))
    if not parsed.ok:
        an.annotate_partial(only=path)
    return an


def _uses_of(unresolved, path: str) -> list:
    """The recorded uses of unresolved names in one file: (kind, name, line, column, evidence)."""
    return sorted((key, u.line, u.column, u.evidence) for key, (_name, uses) in unresolved.uses.items()
                  for u in uses if u.path == path)


@lru_cache(maxsize=65536)
def _kuka(path: str) -> bool:
    from krl.workspace import is_kuka_file  # noqa: PLC0415
    return is_kuka_file(path)


def _lines(text: str) -> list[str]:
    from krl.diagnostics.render import split_lines  # noqa: PLC0415
    return split_lines(text)
