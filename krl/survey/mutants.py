"""Seeded semantic errors in real programs: the checker's recall (issue 14).

:func:`mutants` takes valid programs of the KRC backups of a corpus (user programs under
``R1/Program`` that parse and check without an error in the context of their backup, and are
not listed in corpus/known-invalid.csv) and writes one semantic error into each copy, as one
new line (the original files are read in place and never changed):

==========================  =====================================================  =========
kind                        inserted line                                          expected
==========================  =====================================================  =========
misspelled_variable         ``v = vv_misspelt`` (a visible variable, one letter     E101
                            dropped or doubled)
wrong_argument_count        a call of a routine of the backup with one argument     E301
                            too many
real_into_enum              ``e = 2.5`` for an ENUM variable ``e``                 E201
write_to_input              ``$IN[n] = TRUE``                                      E501
undeclared_routine          a call of a routine of the program, misspelt           E106
aggregate_type_mismatch     ``s = {c TRUE}`` for a numeric component ``c`` (or     E201
                            ``{c 1.5}`` for a BOOL one) of a structure variable
assignment_to_const         ``k = k`` for a CONST ``k``                            E502
if_condition_not_bool       ``IF i THEN ENDIF`` (two lines) for an INT ``i``       E204
goto_missing_label          ``GOTO NO_SUCH_LABEL_n``                               E401
duplicate_declaration       ``DECL INT x`` before ENDDAT for a variable ``x`` of   E102
                            the data list
exit_outside_loop           ``EXIT`` at the top level of a routine                 E403
return_value_in_procedure   ``RETURN 0`` in a DEF                                  E404
operator_type_mismatch      ``b = i AND TRUE`` for an INT ``i``, BOOL ``b``         E203
wait_for_not_bool           ``WAIT FOR i`` for an INT or REAL ``i``                E204
function_as_statement       a DEFFCT of the backup called as a statement            E304
argument_type_mismatch      ``TRUE`` for an INT or REAL parameter of a routine      E303
for_counter_not_int         ``FOR r = 1 TO 2`` / ``ENDFOR`` for a REAL ``r``        E208
==========================  =====================================================  =========

A statement line is inserted before a statement of a routine body (at any depth of IF, loops
and SWITCH; EXIT only at the top level) that starts its line and lies outside KUKA's template folds (krl/semantics/outside.py: names used there
are presumed declared by installed software). Every choice comes from ``random.Random(seed)``
over sorted candidates: the same corpus and seed give the same mutants.

A mutant is **found** when the checker reports an error with the expected code at the
inserted line of the mutated file (the mutated files parsed in one batch, as ``krl check`` parses a
backup's: krl.workspace ``load_here``; each checked in its backup: a routine's new line by the
language server's re-check of an edit, ``Workspace.replace``, in a copy of the backup checked
once, a data list's new declaration by a check of the backup). ``python -m krl.survey.mutants ../shared/krl-corpus``
prints the recall; tests/frontend/test_seeded_errors.py requires every mutant to be found.
"""

from __future__ import annotations

import random
import sys
from dataclasses import dataclass, field
from pathlib import Path

from krl.ast import nodes as N
from krl.diagnostics.codes import E101, E102, E106, E201, E203, E204, E208, E301, E303, E304, E401, E403, E404, E501, E502
from krl.diagnostics.render import split_lines
from krl.semantics import types as T
from krl.semantics.builtins import load_builtins
from krl.semantics.outside import template_lines
from krl.survey.report import known_invalid
from krl.semantics.symbols import Symbol
from krl.limits import PARSE_TIMEOUT_S
from krl.source import SourceText, read_source
from krl.parsecache import through_store
from krl.workspace import LoadedFile, SourceFile, Workspace, load_here, load_text, load_workspace
from krl.project import find_backups, is_system_path
from krl.terminal import printable

KINDS = ("misspelled_variable", "wrong_argument_count", "real_into_enum", "write_to_input",
         "undeclared_routine", "aggregate_type_mismatch", "assignment_to_const",
         "if_condition_not_bool", "goto_missing_label", "duplicate_declaration",
         "exit_outside_loop", "return_value_in_procedure", "operator_type_mismatch",
         "wait_for_not_bool", "function_as_statement", "argument_type_mismatch",
         "for_counter_not_int")
EXPECTED = {"misspelled_variable": E101, "wrong_argument_count": E301, "real_into_enum": E201,
            "write_to_input": E501, "undeclared_routine": E106, "aggregate_type_mismatch": E201,
            "assignment_to_const": E502, "if_condition_not_bool": E204,
            "goto_missing_label": E401, "duplicate_declaration": E102,
            "exit_outside_loop": E403, "return_value_in_procedure": E404,
            "operator_type_mismatch": E203, "wait_for_not_bool": E204,
            "function_as_statement": E304, "argument_type_mismatch": E303,
            "for_counter_not_int": E208}


@dataclass
class Mutant:
    """One seeded error: `path` (the mutated file), the 1-based `line` of the inserted text,
    its `kind` and `expected` code, and the file's new text."""
    kind: str
    path: str
    line: int
    inserted: str
    text: str
    expected: str
    backup: str = ""
    found: bool = False
    reported: list = field(default_factory=list)    # diagnostics at the line: "CODE message"


@dataclass
class _Program:
    backup: Workspace
    src: SourceFile
    dat: SourceFile | None
    text: str
    dat_text: str


def _visible(ws: Workspace, r: N.Routine) -> list[Symbol]:
    """The program's own variables visible in routine `r` (locals, parameters, its module's
    data list, the backup's globals declared in files of R1/Program or $config.dat), sorted."""
    out: dict[str, Symbol] = {}
    scope = ws.routine_scope(r)
    while scope is not None and scope.kind in ("routine", "module", "global"):
        for k, sym in scope.values.items():
            if (sym.kind in ("var", "param", "const") and sym.decl is not None and k not in out
                    and not k.startswith("$")):
                out[k] = sym
        scope = scope.parent
    return [out[k] for k in sorted(out)]


def _misspell(name: str, rng: random.Random) -> str:
    i = rng.randrange(1, len(name)) if len(name) > 1 else 0
    if len(name) >= 4 and rng.random() < 0.5:
        return name[:i] + name[i + 1:]                   # a letter dropped
    return (name[:i] + name[i] + name[i:])[:24]          # a letter doubled


def _free(ws: Workspace, scope, name: str) -> bool:
    packages = load_builtins().packages
    return (scope.lookup(name) is None and scope.lookup_routine(name) is None
            and name.upper() not in packages and name.upper() not in ws.failed_words)


def _programs(corpus: Path) -> list[tuple[Workspace, list[_Program]]]:
    invalid = known_invalid()
    out = []
    for b in find_backups(corpus):
        with through_store():   # each file's parse from the one store, as krl check reads it
            ws = load_workspace([b], str(b))
        ws.check(resolve=False)
        err_paths = {d.path for d in ws.diagnostics if d.is_error}
        progs = []
        for u in sorted(ws.units, key=lambda u: u.src.path if u.src else ""):
            if u.src is None or not u.src.ok or is_system_path(u.src.path) or u.src.path in err_paths:
                continue
            if u.dat is not None and (not u.dat.ok or u.dat.path in err_paths):
                continue
            rel = Path(u.src.path).resolve().relative_to(corpus.resolve()).as_posix()
            if rel in invalid or "program" not in [p.lower() for p in Path(rel).parts[:-1]]:
                continue
            if not u.src.module.routines:
                continue
            text = read_source(u.src.path).text
            dat_text = read_source(u.dat.path).text if u.dat is not None else ""
            progs.append(_Program(ws, u.src, u.dat, text, dat_text))
        out.append((ws, progs))
    return out


def _statements(body: list[N.Stmt], depth: int):
    """(statement, nesting depth) of a body and its nested blocks, in source order."""
    for s in body:
        yield s, depth
        blocks = []
        if isinstance(s, N.If):
            blocks = [s.then, s.orelse or []]
        elif isinstance(s, (N.While, N.Repeat, N.Loop, N.For)):
            blocks = [s.body]
        elif isinstance(s, N.Switch):
            blocks = [c.body for c in s.cases] + [s.default or []]
        for b in blocks:
            yield from _statements(b, depth + 1)


def _anchors(p: _Program, top_level: bool = False) -> list[tuple[N.Routine, N.Stmt]]:
    """(routine, statement) pairs where a line may be inserted before the statement."""
    ini, inline, _user = template_lines(p.text)
    lines = split_lines(p.text)
    out = []
    for r in p.src.module.routines:
        for s, depth in _statements(r.body, 0):
            if top_level and depth:
                continue
            ln = s.span.line
            if not ln or ln in ini or ln in inline or ln - 1 in ini or ln - 1 in inline:
                continue
            if lines[ln - 1][:max(s.span.column - 1, 0)].strip():
                continue
            if isinstance(s, N.Label):
                continue
            out.append((r, s))
    return out


def _statement(kind: str, p: _Program, r: N.Routine, rng: random.Random) -> list[str] | None:
    """The inserted line(s) for `kind` in routine `r`, or None when the program has no material."""
    ws = p.backup
    scope = ws.routine_scope(r)
    if scope is None:
        return None
    syms = [s for s in _visible(ws, r) if s.kind in ("var", "param")]

    def of_type(pred) -> list[Symbol]:
        return [s for s in syms if pred(s.type)]

    if kind == "misspelled_variable":
        cands = of_type(lambda t: t in (T.INT, T.REAL, T.BOOL))
        rng.shuffle(cands)
        for s in cands:
            bad = _misspell(s.name, rng)
            if _free(ws, scope, bad):
                return [f"{s.name} = {bad}"]
        return None
    if kind == "wrong_argument_count":
        routines = sorted({k: v for k, v in _routines(ws).items()
                           if v.signature is not None and not v.signature.is_function
                           and not v.signature.varargs}.items())
        if not routines:
            return None
        _k, sym = routines[rng.randrange(len(routines))]
        n = len(sym.signature.params) + 1
        return [f"{sym.name}({', '.join(['0'] * n)})"]
    if kind == "real_into_enum":
        cands = of_type(lambda t: isinstance(t, T.Enum))
        cands += [s for s in _globals(ws) if isinstance(s.type, T.Enum) and s.kind == "var"]
        return [f"{rng.choice(cands).name} = 2.5"] if cands else None
    if kind == "write_to_input":
        return [f"$IN[{rng.randrange(1, 4097)}] = TRUE"]
    if kind == "undeclared_routine":
        called = sorted({c.name for c in p.src.module.walk() if isinstance(c, N.Call)
                         and scope.lookup_routine(c.name) is not None and len(c.name) > 2})
        rng.shuffle(called)
        for name in called:
            bad = _misspell(name, rng)
            if _free(ws, scope, bad):
                return [f"{bad}()"]
        return None
    if kind == "aggregate_type_mismatch":
        cands = [s for s in syms + [g for g in _globals(ws) if g.kind == "var"]
                 if isinstance(s.type, T.Struc) and any(ft in (T.INT, T.REAL, T.BOOL)
                                                      for _n, ft in s.type.fields.values())]
        if not cands:
            return None
        s = rng.choice(cands)
        fields = [(n, ft) for n, ft in s.type.fields.values() if ft in (T.INT, T.REAL, T.BOOL)]
        fname, ft = fields[rng.randrange(len(fields))]
        return [f"{s.name} = {{{fname} {'1.5' if ft == T.BOOL else 'TRUE'}}}"]
    if kind == "assignment_to_const":
        cands = [s for s in _visible(ws, r) if s.kind == "const"]
        cands += [g for g in _globals(ws) if g.kind == "const"]
        if not cands:
            return None
        c = rng.choice(cands)
        return [f"{c.name} = {c.name}"]
    if kind == "if_condition_not_bool":
        cands = of_type(lambda t: t in (T.INT, T.REAL))
        return [f"IF {rng.choice(cands).name if cands else rng.randrange(1, 9)} THEN", "ENDIF"]
    if kind == "goto_missing_label":
        return [f"GOTO NO_SUCH_LABEL_{rng.randrange(1000)}"]
    if kind == "exit_outside_loop":
        return ["EXIT"]
    if kind == "return_value_in_procedure":
        return ["RETURN 0"] if r.kind == "DEF" else None
    if kind == "wait_for_not_bool":
        cands = of_type(lambda t: t in (T.INT, T.REAL))
        return [f"WAIT FOR {rng.choice(cands).name}"] if cands else None
    if kind == "for_counter_not_int":
        cands = of_type(lambda t: t == T.REAL)
        cands = [c for c in cands if c.kind == "var"]
        return [f"FOR {rng.choice(cands).name} = 1 TO 2", "ENDFOR"] if cands else None
    if kind in ("function_as_statement", "argument_type_mismatch"):
        routines = sorted(_routines(ws).items())
        if kind == "function_as_statement":
            cands = [v for _k, v in routines if v.signature is not None and v.signature.is_function]
        else:
            cands = [v for _k, v in routines if v.signature is not None and v.signature.params
                     and v.signature.params[0].type in (T.INT, T.REAL)
                     and v.signature.params[0].mode != "OUT"]
        if not cands:
            return None
        sym = rng.choice(cands)
        n = len(sym.signature.params)
        if kind == "function_as_statement":
            return [f"{sym.name}({', '.join(['0'] * min(n, 1))})"]
        return [f"{sym.name}(TRUE)"]
    if kind == "operator_type_mismatch":
        ints = of_type(lambda t: t == T.INT)
        bools = of_type(lambda t: t == T.BOOL)
        if not ints or not bools:
            return None
        return [f"{rng.choice(bools).name} = {rng.choice(ints).name} AND TRUE"]
    return None


def _routines(ws: Workspace) -> dict:
    g = ws.global_scope
    return {k: v for k, v in g.routines.items() if isinstance(v.decl, N.Routine)
            and not is_system_path(v.path)} if g is not None else {}


def _globals(ws: Workspace) -> list[Symbol]:
    g = ws.global_scope
    if g is None:
        return []
    return [g.values[k] for k in sorted(g.values) if g.values[k].decl is not None
            and not is_system_path(g.values[k].path) and not k.startswith("$")]


def _dat_mutant(p: _Program, rng: random.Random) -> tuple[int, str, str] | None:
    """duplicate_declaration: (line, inserted, new dat text) or None."""
    if p.dat is None or p.dat.module.data is None:
        return None
    names = [v.name for d in p.dat.module.data.items if isinstance(d, N.VarDecl) for v in d.names]
    lines = split_lines(p.dat_text)
    end = [i for i, ln in enumerate(lines) if ln.strip().upper().startswith("ENDDAT")]
    if not names or not end:
        return None
    line = f"DECL INT {rng.choice(sorted(names))}"
    i = end[-1]
    return i + 1, line, "\n".join(lines[:i] + [line] + lines[i:])   # the last LF is the last line's (split_lines)


def load_programs(corpus: str | Path) -> list[_Program]:
    """The valid user programs of the corpus's backups, each with its checked backup (parsing
    every backup is the expensive part: reuse the result for several :func:`mutants` calls)."""
    return [p for _ws, progs in _programs(Path(corpus)) for p in progs]


def mutants(corpus: str | Path, per_kind: int = 6, seed: int = 14, programs: list | None = None,
            check: bool = True) -> list[Mutant]:
    """Up to `per_kind` mutants of each kind (see the module docstring), deterministic for a
    corpus and `seed`. With `check`, each mutant is checked: :attr:`Mutant.found` says whether
    the checker reports its expected error at its line. `programs`: from :func:`load_programs`."""
    rng = random.Random(seed)
    out: list[Mutant] = []
    of: list[_Program] = []         # the program of each mutant
    if programs is None:
        programs = load_programs(corpus)
    for kind in KINDS:
        order = list(range(len(programs)))
        rng.shuffle(order)
        made = 0
        for i in order:
            if made >= per_kind:
                break
            p = programs[i]
            if kind == "duplicate_declaration":
                got = _dat_mutant(p, rng)
                if got is None:
                    continue
                line, inserted, text = got
                m = Mutant(kind, p.dat.path, line, inserted, text, EXPECTED[kind], p.backup.root)
            else:
                anchors = _anchors(p, top_level=kind == "exit_outside_loop")
                if not anchors:
                    continue
                r, s = anchors[rng.randrange(len(anchors))]
                new = _statement(kind, p, r, rng)
                if new is None:
                    continue
                lines = split_lines(p.text)
                at = s.span.line - 1
                text = "\n".join(lines[:at] + new + lines[at:])   # as the file ends (split_lines keeps its last LF)
                m = Mutant(kind, p.src.path, s.span.line, new[0], text, EXPECTED[kind], p.backup.root)
            out.append(m)
            made += 1
            of.append(p)
    if check:
        # the mutated files parsed in one batch, as krl check parses a backup's (load_here: the
        # Java engine's worker for a batch of at least JAVA_BATCH_BYTES, the same ASTs): one by
        # one, the Python engine's parses were half of the judging (tests/frontend/
        # test_seeded_errors.py 20.0 -> 16.2 s of CPU, medians of three, a cgroup, 2026-11-29)
        sources = [SourceText(m.path, m.text, "", len(m.text.encode("utf-8", "surrogatepass"))) for m in out]
        judges: dict[int, Workspace] = {}       # id(backup) -> its copy, checked once
        for m, p, loaded in zip(out, of, load_here(sources, PARSE_TIMEOUT_S)):
            if m.path == p.src.path:
                ws = judges.get(id(p.backup))
                if ws is None:
                    ws = judges[id(p.backup)] = p.backup.unchecked_copy()
                    ws.check(resolve=False)
                judge_in(m, ws, loaded, p.backup.loaded[m.path])
            else:
                judge(m, p, loaded)
    return out


def judge_in(m: Mutant, ws: Workspace, loaded: LoadedFile, original: LoadedFile) -> None:
    """Check the mutated .src/.sub file `loaded` in its backup `ws` (checked, the file's
    `original` in place) by the language server's re-check of an edit (krl.workspace
    ``Workspace.replace``: for a body's new line, that file's routines alone; its diagnostics
    those of a full check of the backup, tests/lsp/test_edits.py), set m.found / m.reported,
    and put the original back. Against a check of the backup per mutant (:func:`judge`): the
    judging of the 96 such mutants of the corpus 2.2-2.7 -> 0.5-0.6 s of CPU, three
    copies checked included (2026-11-29)."""
    ws.replace(loaded)
    try:
        _found(m, [d for d in ws.diagnostics_of(m.path) if d.line == m.line])
    finally:
        ws.replace(original)


def _found(m: Mutant, at: list) -> None:
    m.reported = [f"{d.code} {d.message}" for d in at]
    m.found = any(d.is_error and d.code == m.expected for d in at)


def judge(m: Mutant, p: _Program, loaded: LoadedFile | None = None) -> None:
    """Check the mutated file in the context of its backup (the other files as parsed) and
    set m.found / m.reported; `loaded`: the mutated text already parsed and built (else parsed
    here, krl.workspace.load_text). A changed data list's declarations are the backup's
    interface: :meth:`Workspace.replace` would check the whole backup twice (the mutant in, then
    out); this checks it once, its routine bodies and values only in the mutant's module."""
    base = p.backup
    ws = Workspace(base.root)
    ws.files = [f for f in base.files if f.path != m.path]
    ws.failed_words = base.failed_words
    ws.unreadable = base.unreadable
    ws.template = dict(base.template)
    ws.add_loaded(loaded if loaded is not None else load_text(m.text, m.path), notify=False)
    ws.check_only = {p.src.path} | ({p.dat.path} if p.dat is not None else set())
    diags = ws.check(resolve=False)     # the checker alone: no storage placed
    _found(m, [d for d in diags if d.path == m.path and d.line == m.line])


def main(argv: list[str]) -> int:
    if not argv or not Path(argv[0]).is_dir():
        print("usage: python -m krl.survey.mutants CORPUS_FOLDER [PER_KIND]", file=sys.stderr)
        return 2
    ms = mutants(argv[0], int(argv[1]) if len(argv) > 1 else 6)
    found = sum(m.found for m in ms)
    kinds = len({m.kind for m in ms})
    print(f"checker recall: {found}/{len(ms)} seeded errors found at their line "
          f"({100.0 * found / max(len(ms), 1):.1f} %), {kinds} kinds")
    for m in ms:
        if not m.found:
            print(printable(f"  missed {m.kind}: {m.path}:{m.line}: {m.inserted} -> {m.reported}"))
    return 0 if found == len(ms) else 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main(sys.argv[1:]))
