"""Completion: STRUC components after ``.`` (the type of the expression before it, from the
symbol tables), system variables after ``$``, ENUM values after ``#``, otherwise the grammar's keywords and the names in
scope at the cursor (locals, the module's data list, globals, built-in routines and types)."""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import lru_cache

from krl.limits import MAX_LSP_COMPLETIONS
from krl.lsp.analysis import Analysis
from krl.lsp.navigate import chain_type
from krl.lsp.text import line_tokens
from krl.semantics import types as T
from krl.semantics.symbols import Scope
from krl.syntax.parse import default_bundle

_WORD_BEFORE = re.compile(r"[\w$]*$")


class CK:
    """Kinds of completion items: names of LSP's ``CompletionItemKind`` (the server's shell,
    krl/lsp/convert.py, makes the protocol's item)."""
    Constant = "Constant"
    Variable = "Variable"
    Function = "Function"
    Struct = "Struct"
    Enum = "Enum"
    TypeParameter = "TypeParameter"
    EnumMember = "EnumMember"
    Field = "Field"
    Keyword = "Keyword"


@dataclass(frozen=True)
class Completion:
    """One completion item: the text offered, its kind (a :class:`CK` name), a detail."""
    label: str
    kind: str
    detail: str | None = None


@lru_cache(maxsize=1)
def keywords() -> tuple[str, ...]:
    """The grammar's keywords (the lexer's literal tokens that are words)."""
    out = []
    for lit in default_bundle().literal:
        w = lit.strip("'")
        if w and (w[0].isalpha() or w[0] == "_") and w != "<INVALID>":
            out.append(w)
    return tuple(sorted(set(out)))


def _scope_names(scope: Scope, dollar: bool) -> list[Completion]:
    out: list[Completion] = []
    seen: set[str] = set()
    s: Scope | None = scope
    while s is not None:
        for key, sym in s.values.items():
            if key in seen or key.startswith("$") != dollar:
                continue
            seen.add(key)
            kind = CK.Constant if sym.kind == "const" else CK.Variable
            out.append(Completion(label=sym.name, kind=kind, detail=str(sym.type)))
        if not dollar:
            for key, sym in s.routines.items():
                if key not in seen:
                    seen.add(key)
                    out.append(Completion(label=sym.name, kind=CK.Function,
                                                detail="function" if sym.signature and sym.signature.is_function else "procedure"))
            for key, typ in s.types.items():
                if key not in seen:
                    seen.add(key)
                    out.append(Completion(label=getattr(typ, "name", key), kind=CK.Struct if isinstance(typ, T.Struc)
                                                else CK.Enum if isinstance(typ, T.Enum) else CK.TypeParameter))
        s = s.parent
    return out


def _enum_values(scope: Scope, word: str) -> list[Completion]:
    """ENUM values after ``#``: the values of every ENUM type in scope, inner scopes first."""
    out: list[Completion] = []
    seen: set[str] = set()
    s: Scope | None = scope
    up = word.upper()
    while s is not None and len(out) < MAX_LSP_COMPLETIONS:
        for typ in s.types.values():
            if isinstance(typ, T.Enum):
                for v in sorted(typ.values):
                    if v.startswith(up) and v not in seen:
                        seen.add(v)
                        out.append(Completion(label=v, kind=CK.EnumMember, detail=typ.name))
        s = s.parent
    return out[:MAX_LSP_COMPLETIONS]


def complete(an: Analysis, path: str, line: int, column: int) -> list[Completion]:
    """Completion items at 1-based (line, column) of `path` (the cursor is before `column`)."""
    fi = an.files.get(path)
    if fi is None or not 0 < line <= len(fi.lines):
        return []
    prefix = fi.lines[line - 1][:column - 1]
    scope = an.scope_at(path, line)
    if scope is None:
        return []
    word = _WORD_BEFORE.search(prefix).group(0)
    before = prefix[:len(prefix) - len(word)]
    if before.rstrip().endswith("."):
        toks = line_tokens(before.rstrip(), line)
        if len(toks) >= 2 and toks[-1].word == ".":
            try:
                base = chain_type(scope, toks, len(toks) - 2)
            except RecursionError:
                base = None
            if isinstance(base, T.Struc):
                return [Completion(label=name, kind=CK.Field, detail=str(ct))
                        for name, ct in base.fields.values() if name.upper().startswith(word.upper())]
        return []
    if ";" in prefix:
        toks = line_tokens(prefix, line)
        code_end = toks[-1].column + len(toks[-1].text) - 1 if toks else 0
        if ";" in prefix[code_end:]:
            return []           # the cursor is in a comment
    if before.endswith("#"):
        return _enum_values(scope, word)
    items = _scope_names(scope, word.startswith("$"))
    if not word.startswith("$"):
        items += [Completion(label=k, kind=CK.Keyword) for k in keywords()]
    up = word.upper()
    items = [i for i in items if i.label.upper().startswith(up)]
    return items[:MAX_LSP_COMPLETIONS]
