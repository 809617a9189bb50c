"""Call hierarchy (LSP ``textDocument/prepareCallHierarchy``, ``callHierarchy/incomingCalls``,
``callHierarchy/outgoingCalls``) read from the program map (krl/programmap), the graph
``krl graph`` draws: calls, interrupt handlers, TRIGGER calls and CWRITE RUN commands, all
resolved by the checker. An item is a routine: its range the DEF..END lines, its selection
range the name on the DEF line, its ``data`` the map's node id (``MODULE:NAME``). The results are
plain (:class:`CallItem`, :class:`CallPlace`, 1-based); the server's shell (krl/lsp/convert.py)
makes the protocol's items.
"""

from __future__ import annotations

from dataclasses import dataclass

from krl.ast import nodes as N
from krl.lsp.analysis import Analysis
from krl.lsp.navigate import resolve
from krl.lsp.text import find_name
from krl.programmap import ProgramMap, build_map

__all__ = ["CallItem", "CallPlace", "program_map", "prepare", "incoming", "outgoing"]


@dataclass(frozen=True)
class CallPlace:
    """`length` characters at 1-based (line, column) of `path`."""
    path: str
    line: int
    column: int
    length: int


@dataclass(frozen=True)
class CallItem:
    """A routine of the call hierarchy: lines `line` .. `end_line` (through `end_column`, the
    end of its END line), its name at `name_column` of its DEF line, its map node id."""
    name: str
    path: str
    line: int
    end_line: int
    end_column: int
    name_column: int
    detail: str
    node_id: str


def program_map(an: Analysis) -> ProgramMap:
    """The map of the analysis' workspace, built once per analysis."""
    pm = getattr(an, "_program_map", None)
    if pm is None:
        pm = build_map(an.ws)
        an._program_map = pm
    return pm


def _routine_of(an: Analysis, pm: ProgramMap, path: str, line: int, column: int) -> N.Routine | None:
    t = resolve(an, path, line, column)
    if t is not None and t.kind == "routine" and isinstance(t.decl, N.Routine):
        return t.decl
    r = an.routine_at(path, line)           # the cursor on a DEF line
    if r is not None and r.span.line == line:
        return r
    return None


def item(an: Analysis, pm: ProgramMap, node_id: str) -> CallItem | None:
    """The call hierarchy item of a routine node, or None (a channel, or a file not loaded)."""
    n = pm.nodes.get(node_id)
    if n is None or n.kind != "routine" or n.path not in an.files:
        return None
    lines = an.files[n.path].lines
    end_line = n.line
    fi = an.files[n.path]
    for r in fi.source.module.routines:
        if pm.node_of(r) is n:
            end_line = r.end_line or n.line
            col = find_name(lines, n.line, n.name) or 1
            break
    else:
        col = 1
    end_text = lines[end_line - 1] if 0 < end_line <= len(lines) else ""
    return CallItem(n.name, n.path, n.line, end_line, len(end_text) + 1, col,
                    f"{n.module}" + (" (never reached)" if n.unreachable else ""), n.id)


def prepare(an: Analysis, path: str, line: int, column: int) -> list[CallItem]:
    """The routine at 1-based (line, column): a call of it or its DEF line; [] elsewhere."""
    pm = program_map(an)
    r = _routine_of(an, pm, path, line, column)
    n = pm.node_of(r) if r is not None else None
    it = item(an, pm, n.id) if n is not None else None
    return [it] if it is not None else []


def _ranges(an: Analysis, edges) -> list[CallPlace]:
    out = []
    for e in edges:
        lines = an.files[e.path].lines if e.path in an.files else []
        name_len = len(lines[e.line - 1]) if 0 < e.line <= len(lines) else 0
        length = 0
        if lines and e.column:
            text = lines[e.line - 1][e.column - 1:]
            while length < len(text) and (text[length].isalnum() or text[length] in "_$"):
                length += 1
        out.append(CallPlace(e.path, e.line, e.column or 1, length or name_len))
    return out


def _grouped(an: Analysis, edges, other: str) -> list[tuple[CallItem, list[CallPlace]]]:
    """(item of the routine at the `other` end, ranges of the calls) per routine, in edge order."""
    pm = program_map(an)
    by_node: dict[str, list] = {}
    for e in edges:
        by_node.setdefault(getattr(e, other), []).append(e)
    out = []
    for nid, group in by_node.items():
        it = item(an, pm, nid)
        if it is not None:
            out.append((it, _ranges(an, group)))
    return out


def incoming(an: Analysis, node_id: str) -> list[tuple[CallItem, list[CallPlace]]]:
    """The routines that call, declare an interrupt handled by, trigger or RUN `node_id`, each
    with the places of those calls (in the caller)."""
    return _grouped(an, program_map(an).incoming(node_id), "source")


def outgoing(an: Analysis, node_id: str) -> list[tuple[CallItem, list[CallPlace]]]:
    """The routines `node_id` calls (and its interrupt handlers, TRIGGER and RUN targets), each
    with the places of those calls (in `node_id`)."""
    return _grouped(an, program_map(an).outgoing(node_id), "target")
