"""The values of a KRL data list, read through the project's own front end (reference §2.5).

Used for a backup's machine data (``R1/Mada/$machine.dat``, ``$robcor.dat``): the file is
parsed by krl/syntax and built into the AST by krl/ast (or that AST taken from the one store,
krl/parsecache.py, when a file of the same content was parsed before); every declaration's initialiser and
every array element line (``$SOFTP_END[3]=168.0``) is evaluated from the AST. Only literal
values are allowed there, as in any data list: numbers, booleans, strings, enumeration
values (``#STANDARD``), a sign before a number, and aggregates (``{X 0.0, Y 0.0}``), evaluated
by the front end's evaluator (krl/semantics/expression.py). No text is evaluated, and a file is
parsed once: its syntax errors are the ones that parse gave.

:func:`read_data_list` returns ``name -> DataValue`` (upper-case names). A value is a Python
scalar, a dict (an aggregate, component names upper-case) or, for an array, a dict
``index -> value`` (1-based). Every value keeps the file and line it came from.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from krl.ast import nodes as N
from krl.limits import MAX_FILE_BYTES
from krl.parsecache import load_file
from krl.semantics import expression as X
from krl.semantics.values import KrlRuntimeError


class DataListError(ValueError):
    """A data list that cannot be read; the message names file:line:col."""


@dataclass
class DataValue:
    """One variable of a data list: ``value`` (scalar, dict or, for an array, ``{index:
    value}``), ``line`` of its declaration, ``lines`` of the array elements by index."""

    name: str
    value: Any
    file: str
    line: int
    lines: dict[int, int] = field(default_factory=dict)

    def where(self, index: int | None = None) -> str:
        """``file:line`` of the value (of element ``index`` of an array)."""
        line = self.lines.get(index, self.line) if index is not None else self.line
        return f"{self.file}:{line}"


class _LiteralEnv(X.Env):
    """A data list's initialiser reads no variable (krl.semantics.expression.Env): literals,
    signs and aggregates only; enumeration values as ``"#NAME"``."""

    def __init__(self, where: str) -> None:
        self.where = where

    def refuse(self, node: N.Node, what: str):
        raise DataListError(f"{self.where}: only literal values are allowed in a data list ({what})")

    def enum(self, node: N.EnumLit) -> X.Reader:
        v = "#" + node.name.lstrip("#").upper()
        return lambda: v


def literal(e: N.Expr, where: str) -> Any:
    """The value of a literal initialiser ``e`` (reference §2.5: only literals in a data list),
    by the front end's evaluator (krl/semantics/expression.py).

    Returns int, float, bool, str, ``"#NAME"`` for an enumeration value, or a dict for an
    aggregate (component names upper-case). Raises :class:`DataListError` for anything else,
    or for an operator that fails (a sign before a value that is not a number).
    """
    try:
        return X.evaluate(e, _LiteralEnv(where))
    except KrlRuntimeError as exc:
        raise DataListError(f"{where}: {exc.message}") from None


def read_data_list(path: str | Path, shown: str | None = None) -> dict[str, DataValue]:
    """Parse the data list ``path`` and evaluate its declarations (module docstring).

    Args:
        path: the ``.dat`` file.
        shown: the name the values' places use (default: ``path``), e.g. a path inside a
            backup archive.
    Returns:
        upper-case variable name -> :class:`DataValue`; a variable declared without a value
        and never set holds None (an array: the elements set).
    Raises:
        DataListError: the file cannot be read, has syntax errors, is not a data list, or
            holds an initialiser that is not a literal (message: file:line:col).
    """
    p = Path(path)
    name = shown or str(p)
    try:
        if p.stat().st_size > MAX_FILE_BYTES:
            raise DataListError(f"{name}: larger than {MAX_FILE_BYTES} bytes")
    except OSError as exc:
        raise DataListError(f"{name}: cannot be read ({exc.strerror})") from None
    loaded = load_file(p)        # the parse of this content from the one store (krl/store.py)
    if not loaded.ok:
        err = next((d for d in loaded.diagnostics if d.severity == "error"), None)
        if err is not None:
            raise DataListError(f"{name}:{err.line}:{err.column}: {err.message}")
        raise DataListError(f"{name}: not read ({loaded.status})")
    if loaded.module.data is None:
        raise DataListError(f"{name}:1:1: not a data list (no DEFDAT)")
    return _values(loaded.module, name)


def _values(module: N.Module, name: str) -> dict[str, DataValue]:
    out: dict[str, DataValue] = {}
    for item in module.data.items:
        line = item.span.line
        where = f"{name}:{line}:{item.span.column}"
        if isinstance(item, N.VarDecl):
            for vn in item.names:
                key = vn.name.upper()
                if key in out:
                    continue                      # the first declaration holds the name
                if vn.dims and not (item.type.name.upper() == "CHAR" and len(vn.dims) == 1):
                    value: Any = {}
                else:
                    value = literal(item.init, where) if item.init is not None else None
                out[key] = DataValue(key, value, name, line)
        elif isinstance(item, N.ArrayInit):
            dv = out.get(item.name.upper())
            if dv is None:
                continue                          # an element of an undeclared array: not ours
            value = literal(item.value, where)
            if item.indices == [None]:            # CHAR name[]="text"
                dv.value, dv.line = value, line
            elif len(item.indices) == 1 and isinstance(dv.value, dict):
                dv.value[int(item.indices[0])] = value
                dv.lines[int(item.indices[0])] = line
    return out


__all__ = ["DataListError", "DataValue", "literal", "read_data_list"]
