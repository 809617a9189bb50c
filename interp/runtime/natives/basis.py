"""KUKA's BASIS routines that programs call (reference 4.8; KSS bas.src), KUKA Trace's among them: the
checker knows their signatures even when a backup's BASIS lacks them. KRL implements them:
the project's BASIS (interp/basis/bas.src, added to a program outside a backup and to a backup
whose System folder lacks bas.src) or the backup's own bas.src; a call binds to that routine
like any other.

The one source of their signatures is interp/basis/bas.src itself (issue 72): the routines a
program may call there (the module's main routine ``BAS`` and its ``GLOBAL`` routines) are read
from its headers and declarations (:func:`basis_signatures`), which follow KUKA's bas.src of a
KR C4 (KSS 8.3: ``GLOBAL DEFFCT ORI_TYPE SORI_TYP (PARAMS :IN)`` with ``DECL LDAT PARAMS``; the
corpus's ``khrzysio__KRC4_test`` ``R1/System/bas.src``), and the generated table
krl/semantics/data/functions.yaml is made from them.
"""

from __future__ import annotations

from pathlib import Path

from krl.ast import nodes as N
from krl.parsecache import load_file

from .registry import Family

#: the project's BASIS file whose routines this family declares
BAS_SRC = Path(__file__).resolve().parents[2] / "basis" / "bas.src"


def _param_text(routine: N.Routine, param: N.Param) -> str:
    """``TYPE NAME[] :MODE`` of one parameter, its type from the routine's declaration of it
    (reference 2.3: a parameter without a mode is :OUT). Raises ValueError when nothing
    declares it."""
    for decl in routine.decls:
        if isinstance(decl, N.VarDecl):
            for vn in decl.names:
                if vn.name.upper() == param.name.upper():
                    dims = f"[{','.join('' for _ in vn.dims)}]" if vn.dims else ""
                    return f"{decl.type.name.upper()} {param.name.upper()}{dims} :{param.mode or 'OUT'}"
    raise ValueError(f"{BAS_SRC.name}: {routine.name}: parameter {param.name} is not declared")


def signature_of(routine: N.Routine) -> str:
    """The table's signature text of `routine` (``RETURN_TYPE NAME(TYPE NAME :MODE, ...)``; a
    procedure without the return type). Raises ValueError for an undeclared parameter."""
    params = ", ".join(_param_text(routine, p) for p in routine.params)
    head = routine.name                  # as bas.src spells it (TraceStart)
    if routine.is_function:
        rt = routine.return_type
        size = f"[{rt.size}]" if rt.size is not None else ""
        head = f"{rt.name.upper()}{size} {head}"
    return f"{head}({params})"


def basis_signatures(path: Path = BAS_SRC) -> list[str]:
    """The signatures of what a program may call in the BASIS file `path`: its main routine
    (the one named as the file) and its GLOBAL routines, in file order. Raises ValueError
    when the file does not parse."""
    lf = load_file(path)
    if lf.module is None or any(d.is_error for d in lf.diagnostics):
        raise ValueError(f"{path}: the BASIS file does not parse")
    return [signature_of(r) for i, r in enumerate(lf.module.routines)
            if r.is_global or (i == 0 and r.name.upper() == path.stem.upper())]


BASIS = Family("BASIS")
for _signature in basis_signatures():
    BASIS.krl(_signature, BAS_SRC.name)
