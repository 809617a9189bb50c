"""Rename a variable, constant, parameter, signal, routine or label across the .src, .dat and
$config.dat files of a workspace.

The places come from the checker's annotations (krl/lsp/occurrences.py), so a local ``i`` and
another routine's ``i`` stay apart. A rename is refused (:class:`Refused`, with the reason in
KRL words) when:

* the name is a system variable, a built-in, a STRUC/ENUM type or component (not renamed), or a
  routine only declared by EXT (its DEF is outside the backup);
* the name is ambiguous: declared twice (E102: the workspace's ``declared_twice`` facts), or
  named in a file that does not parse (its uses there are not known);
* the new name is not one KRL identifier (a keyword, a ``$`` name, more than 24 characters:
  reference 1.2, E103);
* the new name is already declared in a scope that sees the declaration: the declaring scope,
  a scope above it (it would hide that name) or a scope below it (that name would hide the
  renamed one there), reference 2.7.
"""

from __future__ import annotations

import re

from krl.ast import nodes as N
from krl.lsp.analysis import Analysis
from krl.lsp.navigate import Place, Target
from krl.lsp.occurrences import DECL, occurrences
from krl.lsp.text import line_tokens
from krl.semantics.checker import MAX_IDENT
from krl.semantics.symbols import Scope

KINDS = {"value": "variable", "routine": "routine", "label": "label"}


class Refused(Exception):
    """A rename that cannot be done; the message says why."""


def check_new_name(new: str) -> None:
    """Raise Refused unless `new` is one KRL identifier (not a keyword, not a $ name)."""
    toks = line_tokens(new)
    if new.startswith("$"):
        raise Refused(f"'{new}' is a system name ($): a program cannot declare it")
    if len(toks) != 1 or toks[0].text != new:
        raise Refused(f"'{new}' is not one KRL name")
    if toks[0].word != "IDENTIFIER":
        raise Refused(f"'{new}' is a KRL keyword")
    if len(new) > MAX_IDENT:
        raise Refused(f"'{new}' has {len(new)} characters (KRL names have at most {MAX_IDENT})")


def renamable(an: Analysis, t: Target | None) -> Target:
    """`t` when it may be renamed, else Refused with the reason."""
    if t is None:
        raise Refused("no variable, routine or label here")
    if t.kind == "sysvar" or t.name.startswith("$"):
        raise Refused(f"'{t.name}' is a system variable: its name is fixed by the controller")
    if t.kind not in KINDS:
        raise Refused(f"'{t.name}' is a {'STRUC/ENUM type' if t.kind == 'type' else 'structure component' if t.kind == 'comp' else 'ENUM value'}: renaming it is not supported")
    if t.kind == "value" and (t.symbol is None or t.symbol.decl is None):
        raise Refused(f"'{t.name}' is built in")
    if t.kind == "routine":
        if not isinstance(t.decl, N.Routine):
            raise Refused(f"routine '{t.name}' is {'built in' if t.decl is None else 'only declared by EXT here'}: "
                          "its DEF is not in this backup")
        fi = an.files.get(t.path)
        if fi is not None and fi.source.module.routines and fi.source.module.routines[0] is t.decl:
            raise Refused(f"'{t.name}' is the main routine of its module: its name is the file's name (reference 2.1)")
    return t


def _ambiguous(an: Analysis, t: Target) -> None:
    key = t.name.upper()
    for f in an.ws.declared_twice():        # the semantic model's facts (E102), never its words
        if f.kind != "component" and f.name.upper() == key:
            raise Refused(f"'{t.name}' is declared more than once ({f.span.file.rsplit('/', 1)[-1]} line {f.span.line}): "
                          "which one is meant is ambiguous")
    pat = re.compile(r"(?<![\w$])" + re.escape(t.name) + r"(?![\w$])", re.IGNORECASE)
    for path, fi in an.files.items():
        if not fi.source.ok and any(pat.search(x) for x in fi.lines):
            raise Refused(f"'{t.name}' is named in {path.rsplit('/', 1)[-1]}, which has syntax errors: "
                          "its uses there are not known")


def _declaring_scope(an: Analysis, t: Target) -> Scope | None:
    """The scope whose table holds `t` (values or routines)."""
    key = t.name.upper()
    for sc in _scopes(an):
        if t.kind == "value" and sc.values.get(key) is t.symbol:
            return sc
        if t.kind == "routine":
            got = sc.routines.get(key)
            if got is not None and got.decl is t.decl:
                return sc
    return None


def _scopes(an: Analysis) -> list[Scope]:
    out = [an.ws.global_scope, *(u.scope for u in an.ws.units), *an.ws.routine_scopes.values()]
    return [s for s in out if s is not None]


def _sees(inner: Scope, outer: Scope) -> bool:
    s: Scope | None = inner
    while s is not None:
        if s is outer:
            return True
        s = s.parent
    return False


def _named(sc: Scope, name: str) -> str:
    """What `name` is in scope `sc` itself (not its parents): '' when nothing."""
    key = name.upper()
    if key in sc.values:
        return "a " + {"param": "parameter", "const": "constant", "signal": "signal"}.get(sc.values[key].kind, "variable")
    if key in sc.routines:
        return "a routine"
    if key in sc.types:
        return "a type"
    return ""


def _where(sc: Scope) -> str:
    return {"routine": f"routine {sc.name}", "module": f"module {sc.name}", "global": "the global data ($config.dat, GLOBAL)",
            "basis": "the BASIS system data", "system": "the system tables"}.get(sc.kind, sc.kind)


def _clash(an: Analysis, t: Target, new: str) -> None:
    if t.kind == "label":
        for n in t.owner.walk():
            if isinstance(n, N.Label) and n.name.upper() == new.upper():
                raise Refused(f"routine {t.owner.name} already has a label '{n.name}'")
        return
    home = _declaring_scope(an, t)
    if home is None:
        raise Refused(f"where '{t.name}' is declared is not known")
    s: Scope | None = home
    while s is not None:                       # the declaring scope and those above it
        what = _named(s, new)
        if what:
            verb = "already names" if s is home else "would hide"
            raise Refused(f"'{new}' {verb} {what} of {_where(s)}")
        s = s.parent
    for sc in _scopes(an):                     # scopes below: their name would hide the renamed one
        if sc is not home and _sees(sc, home):
            what = _named(sc, new)
            if what:
                raise Refused(f"'{new}' is {what} of {_where(sc)}, which would hide the renamed '{t.name}' there")


def plan(an: Analysis, t: Target | None, new: str) -> dict[str, list[Place]]:
    """The places (by file) to replace with `new`; Refused when the rename is not safe."""
    t = renamable(an, t)
    check_new_name(new)
    _ambiguous(an, t)
    occ = occurrences(an, t)
    if not any(o.kind == DECL for o in occ):
        raise Refused(f"the declaration of '{t.name}' is not in this backup")
    if new.upper() != t.name.upper():
        _clash(an, t, new)
    out: dict[str, list[Place]] = {}
    for o in occ:
        lines = an.files[o.place.path].lines
        text = lines[o.place.line - 1][o.place.column - 1:o.place.column - 1 + o.place.length]
        if text.upper() != t.name.upper():          # a span that does not hold the name: refuse, never guess
            raise Refused(f"could not place '{t.name}' at {o.place.path.rsplit('/', 1)[-1]} line {o.place.line}")
        out.setdefault(o.place.path, [])
        if o.place not in out[o.place.path]:
            out[o.place.path].append(o.place)
    return out
