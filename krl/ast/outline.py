"""`krl parse --outline`: the symbols of a built module, one line each."""

from __future__ import annotations

from krl.ast import nodes as N

__all__ = ["symbol_outline"]


def symbol_outline(module) -> list[str]:
    """The symbols of a built module (krl.ast.nodes.Module), one entry ``LINE: KIND NAME`` each, in
    source order: routines (``DEF PICK(A :IN, B :OUT)``, ``DEFFCT INT SUM(...)``), the data list
    (``DEFDAT DEMO PUBLIC``) and declarations (``DECL INT COUNT``, ``STRUC PAIR``, ``ENUM COLOUR``,
    ``SIGNAL GRIP``, ``EXT NAME``, ``IMPORT``), nested under their routine or data list by two
    spaces. This is what `krl parse --outline` prints."""
    def decl(d, indent: str) -> list[str]:
        line = d.span.line if d.span is not None else 0
        g = "GLOBAL " if getattr(d, "is_global", False) else ""
        if isinstance(d, N.VarDecl):
            kind = ("CONST " if d.is_const else "") + "DECL " + d.type.name
            return [f"{line}: {indent}{g}{kind} {v.name}" + (f"[{','.join(map(str, v.dims))}]" if v.dims else "")
                    for v in d.names]
        if isinstance(d, N.StrucDecl):
            return [f"{line}: {indent}{g}STRUC {d.name}"]
        if isinstance(d, N.EnumDecl):
            return [f"{line}: {indent}{g}ENUM {d.name}"]
        if isinstance(d, N.SignalDecl):
            return [f"{line}: {indent}{g}SIGNAL {d.name}"]
        if isinstance(d, N.ExtDecl):
            return [f"{line}: {indent}{d.kind} {d.name}"]
        if isinstance(d, N.ImportDecl):
            return [f"{line}: {indent}IMPORT {d.type_name} {d.name}"]
        name = getattr(d, "name", "")
        return [f"{line}: {indent}{type(d).__name__.upper()} {name}".rstrip()] if name else []

    out: list[str] = []
    for r in module.routines:
        params = ", ".join(p.name + (f" :{p.mode}" if p.mode else "") for p in r.params)
        ret = f"{r.return_type.name} " if r.return_type is not None else ""
        g = "GLOBAL " if r.is_global else ""
        out.append(f"{r.span.line}: {g}{r.kind} {ret}{r.name}({params})")
        for d in r.decls:
            out += decl(d, "  ")
    if module.data is not None:
        dl = module.data
        out.append(f"{dl.span.line}: DEFDAT {dl.name}" + (" PUBLIC" if dl.public else ""))
        for d in dl.items:
            out += decl(d, "  ")
    return out
