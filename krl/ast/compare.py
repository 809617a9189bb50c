"""Position-free comparison of ASTs (krl/ast/nodes.py).

Node ``==`` already ignores ``span`` and ``ann``; :func:`same_tree` adds two things a
formatter check needs:

* with ``fold_keywords=True``, a string field that spells a reserved word (a type name such
  as ``int``/``INT``, an approximation ``c_ptp``) compares case-insensitively, since KRL is
  case-insensitive (reference 1.1) and the formatter may change keyword case. Names of
  variables, routines, components and string contents still compare exactly: identifiers
  cannot spell a reserved word, and :class:`~krl.ast.nodes.StrLit` values are never folded;
* with ``fold_case=True`` (the backup diff, krl/diff), every name compares case-insensitively
  too: ``Count`` and ``COUNT`` are one variable (reference 1.1); string contents
  (:class:`~krl.ast.nodes.StrLit`) still compare exactly;
* :func:`first_difference` names the path of the first differing field, for test messages.
"""

from __future__ import annotations

import dataclasses

from krl.ast import nodes as N
from krl.syntax.parse import default_bundle, keyword_types

__all__ = ["same_tree", "first_difference", "structure"]


def _keywords() -> frozenset[str]:

    bundle = default_bundle()
    return frozenset(bundle.symbolic[t].replace("_F", " F") if bundle.symbolic[t] == "BRAKE_F"
                     else bundle.symbolic[t] for t in keyword_types(bundle))


_KW: frozenset[str] | None = None


#: a node class -> the names of its compared fields (``dataclasses.fields``, ``compare=True``),
#: in declaration order: looked up once per class, not once per node
_FIELDS: dict[type, tuple[str, ...]] = {}


def _compared_fields(cls: type) -> tuple[str, ...]:
    names = _FIELDS.get(cls)
    if names is None:
        names = _FIELDS[cls] = tuple(f.name for f in dataclasses.fields(cls) if f.compare)
    return names


def structure(node, fold_keywords: bool = False, fold_case: bool = False):
    """A nested tuple of the node's compared fields (no spans, no annotations); iterative,
    so deep trees do not hit the recursion limit. `fold_case`: every string outside a
    StrLit upper-case (names, keywords, approximation words)."""
    global _KW
    if fold_keywords and _KW is None:
        _KW = _keywords()
    kw = _KW or frozenset()
    node_cls, strlit, fields_of = N.Node, N.StrLit, _compared_fields
    # post-order build with an explicit stack: a work item is (value, meta); meta is None for a
    # value still to visit, "keep" for a StrLit's own string, or (kind, n) for a node or
    # sequence whose n parts are the last n results (kind None: a sequence, a tuple)
    out_stack: list = []
    push, pop = out_stack.append, out_stack.pop
    work: list = [(node, None)]
    while work:
        item, meta = work.pop()
        if meta is not None and meta != "keep":
            kind, n = meta
            if n:
                vals = out_stack[-n:]
                del out_stack[-n:]
            else:
                vals = []
            push((kind, *vals) if kind is not None else tuple(vals))
            continue
        if isinstance(item, str):
            push(item.upper() if fold_case and meta != "keep" else item)
        elif isinstance(item, node_cls):
            names = fields_of(type(item))
            work.append((None, (type(item).__name__, len(names))))
            is_lit = isinstance(item, strlit)
            fold = fold_keywords and not is_lit
            keep = "keep" if is_lit else None
            for name in reversed(names):
                v = getattr(item, name)
                if fold and isinstance(v, str) and v.upper() in kw:
                    v = v.upper()
                work.append((v, keep))
        elif isinstance(item, (list, tuple)):
            work.append((None, (None, len(item))))
            work.extend((v, None) for v in reversed(item))
        else:
            push(item)
    return out_stack[0]


def same_tree(a, b, fold_keywords: bool = False, fold_case: bool = False) -> bool:
    """True when the two ASTs are equal without positions (and, with `fold_keywords`, up to
    the case of reserved words; with `fold_case`, up to the case of every name)."""
    if not (fold_keywords or fold_case):
        return a == b
    return structure(a, fold_keywords, fold_case) == structure(b, fold_keywords, fold_case)


def first_difference(a, b, fold_keywords: bool = False) -> str | None:
    """The first differing position as a readable path, or None when equal."""
    sa, sb = structure(a, fold_keywords), structure(b, fold_keywords)
    path: list[str] = []
    work = [(sa, sb, "")]
    while work:
        x, y, where = work.pop(0)
        if x == y:
            continue
        if isinstance(x, tuple) and isinstance(y, tuple) and len(x) == len(y):
            work = [(xi, yi, f"{where}/{i}") for i, (xi, yi) in enumerate(zip(x, y))] + work
            continue
        path.append(f"{where}: {x!r:.200} != {y!r:.200}")
        break
    return path[0] if path else None
