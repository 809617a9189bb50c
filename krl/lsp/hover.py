"""Hover text: the declared type and where a name is declared; for system variables the type
and what the built-in tables (krl/semantics/data: sysvars.yaml, kss.yaml) say about them."""

from __future__ import annotations

import os
from functools import lru_cache

import yaml

from krl.ast import nodes as N
from krl.lsp.analysis import Analysis
from krl.lsp.navigate import Target, definition
from krl.semantics import types as T
from krl.semantics.builtins import DATA_DIR, load_builtins

_KIND = {"var": "variable", "const": "constant", "param": "parameter", "signal": "signal",
         "sysvar": "system variable", "routine": "routine"}


def _where(an: Analysis, t: Target) -> str:
    place = definition(an, t)
    if place is None:
        return ""
    try:
        rel = os.path.relpath(place.path, an.root if os.path.isdir(an.root) else os.path.dirname(an.root))
    except ValueError:
        rel = place.path
    return f"declared in `{rel}` line {place.line}"


def _sig(sym) -> str:
    sig = getattr(sym, "signature", None)
    if sig is None:
        return sym.name if sym is not None else "?"
    params = ", ".join(f"{p.type} {p.name}" + (f":{p.mode}" if p.mode else "") for p in sig.params)
    if sig.varargs:
        params += ", ..." if params else "..."
    if sig.returns is not None:
        return f"DEFFCT {sig.returns} {sig.name}({params})"
    return f"DEF {sig.name}({params})"


def _type_text(typ: T.KrlType) -> str:
    if isinstance(typ, T.Struc):
        comps = ", ".join(f"{t} {n}" for n, t in typ.fields.values())
        return f"STRUC {typ.name} {comps}"
    if isinstance(typ, T.Enum):
        return f"ENUM {typ.name} " + ", ".join(sorted(typ.values))
    return str(typ)


def _decl_of(sym) -> str:
    typ = sym.type
    dims = ""
    if isinstance(typ, T.Array):
        dims = "[" + ",".join(str(d) if d else "" for d in typ.dims) + "]"
        typ = typ.elem
    words = "DECL CONST" if sym.kind == "const" else "SIGNAL" if sym.kind == "signal" else "DECL"
    return f"{words} {typ} {sym.name}{dims}"


@lru_cache(maxsize=1)
def meanings() -> dict[str, tuple[str, str]]:
    """UPPER name -> (meaning, reference section) from krl/semantics/data/sysvar_meanings.yaml."""
    try:
        data = yaml.safe_load((DATA_DIR / "sysvar_meanings.yaml").read_text(encoding="utf-8")) or {}
    except (OSError, yaml.YAMLError):
        return {}
    return {str(k).upper(): (str(v.get("meaning", "")), str(v.get("ref", ""))) for k, v in data.items()
            if isinstance(v, dict)}


def sysvar_text(name: str) -> list[str]:
    """What the tables say about a system variable: meaning, access, advance-run stops, source."""
    b = load_builtins()
    key = name.upper()
    info = b.sysvars.get(key) or b.kss_variables.get(key)
    if info is None:
        return []
    out = []
    meaning, ref = meanings().get(key, ("", ""))
    if meaning:
        out.append(meaning + (f" (reference {ref})" if ref else ""))
    out.append("write-protected (read only)" if info.access == "RO" else "read and write")
    stops = [w for w, on in (("reading", info.stop_read), ("writing", info.stop_write)) if on]
    if stops:
        out.append(" and ".join(stops) + " it stops the advance run")
    if key in b.sysvars:
        out.append("from the reference's system variable table (krl/semantics/data/sysvars.yaml)")
    else:
        src = b.sources.get(key)
        out.append("declared in KUKA's system data lists" + (f" ({src})" if src else "")
                   + " (krl/semantics/data/kss.yaml)")
    return out


def hover_text(an: Analysis, t: Target) -> str:
    """Markdown for a target (see the module docstring)."""
    lines: list[str] = []
    if t.kind in ("value", "sysvar") and t.symbol is not None:
        sym = t.symbol
        lines.append(f"```krl\n{_decl_of(sym)}\n```")
        kind = _KIND.get(sym.kind, sym.kind)
        scope = {"routine": "local", "module": "module data", "global": "global", "global-sys": "global", "basis": "global (BASIS)"}.get(sym.scope, sym.scope)
        lines.append(f"{kind} ({scope}) of type `{sym.type}`")
        if t.kind == "sysvar" or sym.name.startswith("$"):
            lines.extend(sysvar_text(sym.name))
        if isinstance(sym.decl, N.ImportDecl) and sym.alias is not None:
            lines.append(f"imported from {'..'.join(sym.decl.path[1:])}")
    elif t.kind == "routine":
        lines.append(f"```krl\n{_sig(t.symbol) if t.symbol is not None else t.name}\n```")
        if isinstance(t.decl, N.Routine):
            lines.append(("global " if t.decl.is_global else "") + ("function" if t.decl.kind == "DEFFCT" else "procedure"))
        elif t.decl is None:
            lines.append("built-in routine")
    elif t.kind == "type" and t.type is not None:
        lines.append(f"```krl\n{_type_text(t.type)}\n```")
        if t.decl is None:
            lines.append("built-in type")
    elif t.kind == "comp":
        lines.append(f"```krl\n{t.type} {t.name}\n```")
        lines.append(f"component of STRUC `{t.owner}`")
    elif t.kind == "label":
        lines.append(f"label `{t.name}` of routine `{t.owner.name}`")
    elif t.kind == "enumval":
        lines.append(f"`#{t.name}`: value of ENUM `{t.type}`")
    where = _where(an, t)
    if where:
        lines.append(where)
    return "\n\n".join(lines)
