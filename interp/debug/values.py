"""KRL values as a debugger shows them (DAP Variable ``value`` text and children).

Text follows the KRL reference's literal forms (§2): INT and REAL as numbers, BOOL as
TRUE/FALSE, ENUM as ``#NAME``, CHAR arrays as ``"text"``, structures as aggregates
``{X 1.0, Y 2.0}``; an unset value reads ``<value invalid>`` (the pendant's "value invalid").
"""

from __future__ import annotations

from interp.runtime.values import UNSET, Arr, EnumValue, Struct, is_char_array, type_name_of

MAX_VALUE_TEXT = 200        # characters of one value's text (longer text ends in "...")
MAX_CHILDREN = 1000         # children of one array or structure listed (the rest are not shown)


def value_text(v, limit: int = MAX_VALUE_TEXT) -> str:
    """The display text of a value (at most ``limit`` characters)."""
    out = _text(v, limit)
    return out if len(out) <= limit else out[:limit - 3] + "..."


def _text(v, limit: int) -> str:
    if v is UNSET or v is None:
        return "<value invalid>"
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(round(v, 6))
    if isinstance(v, EnumValue):
        return f"#{v.name}"
    if isinstance(v, str):
        return '"' + v + '"'
    if is_char_array(v):
        return '"' + v.text() + '"'
    if isinstance(v, Struct):
        parts = []
        size = 2
        for k, x in v.f.items():
            if x is UNSET:
                continue
            p = f"{k} {_text(x, limit)}"
            parts.append(p)
            size += len(p) + 2
            if size > limit:
                break
        return "{" + ", ".join(parts) + "}"
    if isinstance(v, Arr):
        return f"{type_name_of(v)}"
    return type_name_of(v)


def has_children(v) -> bool:
    return (isinstance(v, Struct) and bool(v.f)) or (isinstance(v, Arr) and not is_char_array(v))


def children(v) -> list[tuple[str, list]]:
    """``(label, path step)`` of the components of a structure or the elements of an array
    (row-major; a step is ``["field", NAME]`` or ``["index", [i, j, ...]]``), at most
    :data:`MAX_CHILDREN`."""
    out = []
    if isinstance(v, Struct):
        for k in v.f:
            out.append((k, ["field", k]))
            if len(out) >= MAX_CHILDREN:
                break
    elif isinstance(v, Arr):
        idx = [1] * len(v.dims)
        for _ in range(min(len(v.data), MAX_CHILDREN)):
            out.append(("[" + ",".join(map(str, idx)) + "]", ["index", list(idx)]))
            for d in range(len(idx) - 1, -1, -1):
                idx[d] += 1
                if idx[d] <= v.dims[d]:
                    break
                idx[d] = 1
    return out
