"""The program map as DOT, SVG, JSON and one interactive HTML page (``krl graph``).

DOT and SVG go through the ``graphviz`` Python binding (PyPI ``graphviz``), which quotes every
name and label; SVG runs Graphviz's ``dot`` (Debian package ``graphviz``). Labels from the
input (routine, module and file names) pass through :func:`graphviz.escape`, so a backslash
in a file name is text, not a DOT escape.

The HTML page (:func:`to_html`) is rendered in the project's one Jinja environment
(krl/render.py, autoescape on) from ``templates/graph.html.j2``: the map travels as JSON in a
``<script type="application/json">`` element written by Jinja's ``tojson`` (``<``, ``>``, ``&``
and ``'`` escaped, so no text from the backup can close it), and the vendored front end
``static/programmap.js`` (cytoscape and elkjs from the npm registry, bundled from
``web/package-lock.json`` by ``make programmap-js``; docs/diff.md) draws it: zoom and pan,
search, a routine's neighbourhood, modules and KUKA's system software collapsed, and a link
from each routine to its file:line. The page needs no network. Maps larger than
krl.limits.MAX_GRAPH_NODES are refused with :class:`GraphTooLarge`.
"""

from __future__ import annotations

import base64
from functools import lru_cache
from importlib.resources import files
from pathlib import Path
from urllib.parse import quote

import graphviz
from markupsafe import Markup

from krl.diagnostics.render import split_lines
from krl.limits import MAX_GRAPH_NODES, MAX_GRAPH_SOURCE_CHARS
from krl.source import read_source
from krl.programmap.graph import CONTROLLER_KINDS, ProgramMap
from krl.terminal import printable
from krl.render import render_html

__all__ = ["GraphTooLarge", "GraphvizMissing", "LINKS", "to_dot", "to_svg", "to_html", "to_text", "page_data",
           "logbook_marks", "file_href", "map_widget", "context"]

# how a routine links to its file:line: a file: URL (the file opens in the browser), a vscode:
# URL (the file opens at the line in VS Code), or no link
LINKS = ("file", "vscode", "none")

_EDGE_STYLE = {"call": {}, "interrupt": {"style": "dashed", "color": "#aa1111", "label": "interrupt"},
               "trigger": {"style": "dashed", "color": "#176b2c", "label": "trigger"},
               "run": {"style": "bold", "color": "#224466", "label": "RUN"},
               "eki": {"style": "dotted", "color": "#666666", "label": "EKI"}}


class GraphTooLarge(ValueError):
    """More nodes than krl.limits.MAX_GRAPH_NODES."""


class GraphvizMissing(RuntimeError):
    """Graphviz's ``dot`` is not installed (Debian: apt-get install graphviz)."""


def _short(path: str, root: str) -> str:
    try:
        return Path(path).relative_to(root).as_posix()
    except ValueError:
        return Path(path).name


def _label(*lines: str) -> str:
    """A DOT label of text lines: backslashes doubled (no DOT escape from the input), lines
    joined by DOT's centred line break, never read as an HTML-like label."""
    return graphviz.nohtml("\\n".join(ln.replace("\\", "\\\\") for ln in lines))


def digraph(pm: ProgramMap) -> graphviz.Digraph:
    """The map as a graphviz.Digraph: entry points double-bordered, routines only operator
    selection reaches dashed amber, dead routines grey, routines of unknown reach dotted."""
    if len(pm.nodes) > MAX_GRAPH_NODES:
        raise GraphTooLarge(f"the program map has {len(pm.nodes)} nodes (limit MAX_GRAPH_NODES = {MAX_GRAPH_NODES})")
    g = graphviz.Digraph("program_map", graph_attr={"rankdir": "LR", "fontname": "Helvetica"},
                         node_attr={"shape": "box", "fontname": "Helvetica", "fontsize": "10"},
                         edge_attr={"fontname": "Helvetica", "fontsize": "8"})
    # DOT names are n0, n1, ... (a routine id's ':' would be read as a port); labels say the rest
    names = {nid: f"n{i}" for i, nid in enumerate(pm.nodes)}
    for n in pm.nodes.values():
        if n.kind == "channel":
            g.node(names[n.id], _label(f"EKI {n.name}"), shape="cds")
            continue
        attrs = {}
        if n.entry:
            attrs.update(peripheries="2", color="#224466", tooltip=_label(n.entry))
        if n.reach == "operator" and not n.kuka:
            attrs.update(color="#b36b00", style="dashed")
        elif n.reach == "unknown":
            attrs.update(style="dotted")
        if n.unreachable:
            attrs.update(style="filled", fillcolor="#eeeeee", fontcolor="#777777")
        g.node(names[n.id], _label(n.name, f"{n.module} {_short(n.path, pm.root)}:{n.line}"), **attrs)
    seen = set()
    for e in pm.edges:
        key = (e.source, e.target, e.kind)
        if key in seen:
            continue                    # one arrow per pair and kind
        seen.add(key)
        g.edge(names[e.source], names[e.target], **_EDGE_STYLE.get(e.kind, {}))
    return g


def to_text(pm: ProgramMap) -> list[str]:
    """The map's reachability as lines for a terminal: the counts, what the controller starts
    (by kind, with file:line), the modules only an operator starts, the dead routines and those
    of unknown reach. Text from the backup passes through krl.terminal.printable."""
    p = printable
    routines = [n for n in pm.nodes.values() if n.kind == "routine"]
    own = [n for n in routines if not n.kuka]
    where = lambda n: f"{p(_short(n.path, pm.root))}:{n.line}"  # noqa: E731
    out = []
    for part in pm.not_understood:          # first, once each: the rest of each file is mapped (issue 63)
        out.append(p(part.headline("mapped", lambda f: _short(f, pm.root))))
        out += ["  " + p(line) for line in part.details(lambda f: _short(f, pm.root))]
    out.append(f"{p(pm.root)}: {len(routines)} routines ({len(own)} of its own, {len(routines) - len(own)} of "
               f"KUKA's system software), {len(pm.edges)} edges")
    controller = [pm.nodes[i] for i in pm.entries if pm.nodes[i].entry_kind in CONTROLLER_KINDS]
    modules = [pm.nodes[i] for i in pm.entries if pm.nodes[i].entry_kind == "module"]
    operator = [pm.nodes[i] for i in pm.entries if pm.nodes[i].entry_kind == "operator"]
    if modules:
        out.append(f"a folder, not a KRC backup: {len(modules)} entry points (module mains, GLOBAL routines), "
                   f"{sum(n.reach == 'module' for n in own)} routines reached")
    reached = sum(n.reach == "controller" for n in own)
    if controller or not modules:
        out.append(f"started by the controller: {len(controller)} entry points, {reached} routines of its own reached")
    for n in controller:
        kind = n.entry_kind
        if kind == "plc":
            kind = "plc " + n.entry.removeprefix("PLC program number ").split(" (", 1)[0]
        extra = ""
        if kind in ("interrupt", "trigger", "selected"):
            extra = "  (" + p(n.entry.split("(", 1)[1]) if "(" in n.entry else ""
        out.append(f"  {kind:<10} {p(n.name)}  {where(n)}{extra}")
    mains = context(pm, None)["operator_mains"]
    only = sum(n.reach == "operator" for n in own)
    if operator or not modules:
        out.append(f"only an operator starts: {len(mains)} modules, {only} routines")
        out += [f"  {p(n.name)}  {where(n)}" for n in mains]
    dead = pm.unreachable
    out.append(f"dead: {len(dead)} routines" + ("" if dead else " (none)"))
    out += [f"  {p(n.module)}:{p(n.name)}  {where(n)}" for n in dead]
    unknown = [n for n in own if n.reach == "unknown"]
    if unknown:
        out.append(f"unknown reach (named on a line not understood): {len(unknown)} routines")
        out += [f"  {p(n.module)}:{p(n.name)}  {where(n)}" for n in unknown]
    return out


def to_dot(pm: ProgramMap) -> str:
    """The DOT source of the map."""
    return digraph(pm).source


def to_svg(pm: ProgramMap) -> str:
    """The map drawn by Graphviz's dot, as SVG text. Raises GraphvizMissing."""
    try:
        return digraph(pm).pipe(format="svg", encoding="utf-8")
    except graphviz.ExecutableNotFound:
        raise GraphvizMissing("Graphviz's 'dot' is not installed (Debian: apt-get install graphviz)") from None


def svg_data_uri(svg: str) -> str:
    return "data:image/svg+xml;base64," + base64.b64encode(svg.encode("utf-8")).decode("ascii")


def file_href(path: str, line: int, links: str) -> str:
    """The link of `path`:`line` (a routine, a finding): "" when `links` is "none" or the file
    is not on this machine (a map read from an archive names files inside the archive); a
    relative path is taken from the current folder (symbolic links kept, as the user named it)."""
    p = Path(path)
    if links == "none" or not p.is_file():
        return ""
    p = p.absolute()
    if links == "vscode":
        return "vscode://file" + quote(p.as_posix()) + f":{line}"
    return p.as_uri()


def page_data(pm: ProgramMap, links: str = "file", marks: dict[str, str] | None = None) -> dict:
    """The map as the page's JSON: nodes (id, name, module, kind, file shown relative to the
    root, line, href, system, entry, entry_kind, unreachable, reach, and ``source``: the routine's own
    lines, DEF to END, up to krl.limits.MAX_GRAPH_SOURCE_CHARS in all; ``logbook``: what the
    controller's logbook says of it, from `marks`, node id -> text, "" for none) and edges
    (source, target, kind, file, line)."""
    texts: dict[str, list[str]] = {}
    budget = MAX_GRAPH_SOURCE_CHARS
    nodes = []
    for n in pm.nodes.values():
        source = []
        if n.path and n.kind == "routine" and budget > 0:
            if n.path not in texts:
                texts[n.path] = split_lines(read_source(n.path).text or "") if Path(n.path).is_file() else []
            source = texts[n.path][n.line - 1:max(n.end, n.line)]
            budget -= sum(len(x) + 1 for x in source)
            if budget < 0:
                source = []
        nodes.append({"id": n.id, "name": n.name, "module": n.module, "kind": n.kind,
                      "file": _short(n.path, pm.root) if n.path else "", "line": n.line,
                      "href": file_href(n.path, n.line, links) if n.path else "", "system": n.kuka,
                      "entry": n.entry, "entry_kind": n.entry_kind, "unreachable": n.unreachable,
                      "reach": n.reach, "source": source, "logbook": (marks or {}).get(n.id, "")})
    return {
        "root": pm.root, "links": links, "nodes": nodes,
        "edges": [{"source": e.source, "target": e.target, "kind": e.kind, "file": _short(e.path, pm.root),
                   "line": e.line} for e in pm.edges],
    }


@lru_cache(maxsize=1)
def _script() -> Markup:
    """The vendored front end, as the page's script (it never holds ``</script``)."""
    text = (files("krl.programmap") / "static" / "programmap.js").read_text(encoding="utf-8")
    if "</script" in text.lower():
        raise ValueError("static/programmap.js holds '</script': it cannot be put in the page")
    return Markup(text)


def map_widget(pm: ProgramMap, links: str = "file", marks: dict[str, str] | None = None) -> Markup:
    """The interactive map as one block of the page (``templates/_map_widget.html.j2``: the
    tools, the drawing, the details and source panels, the legend, the map's JSON and the
    script), for the map's own page and the change report. `marks`: node id -> what the
    controller's logbook says of the routine (:func:`logbook_marks`; drawn with a red halo, the
    text in its details). Raises GraphTooLarge."""
    if len(pm.nodes) > MAX_GRAPH_NODES:
        raise GraphTooLarge(f"the program map has {len(pm.nodes)} nodes (limit MAX_GRAPH_NODES = {MAX_GRAPH_NODES})")
    return Markup(render_html("krl.programmap", "_map_widget.html.j2", data=page_data(pm, links, marks),
                              script=_script(), marked=bool(marks)))


#: the names a module's logbook mark lists (the most recorded first; the rest counted): a
#: crafted logbook may name any number of variables of one module
MAX_MARK_NAMES = 20


def logbook_marks(pm: ProgramMap, named: dict[str, int]) -> dict[str, str]:
    """Node id -> text for the main routine of each module the logbook names: `named` maps
    ``MODULE`` or ``MODULE.variable`` (krl/logbook/links.py ``names``) to its records' count;
    the text lists them (``logbook: B3.b3_parcasirasi (5 records), B3 (2 records)``)."""
    mains = {n.module.upper(): n.id for n in pm.nodes.values() if n.kind == "routine" and n.main and not n.kuka}
    out: dict[str, list[str]] = {}
    for names, count in sorted(named.items(), key=lambda x: (-x[1], x[0])):
        nid = mains.get(names.split(".", 1)[0].upper())
        if nid is not None:
            out.setdefault(nid, []).append(f"{names} ({count} record{'s' if count != 1 else ''})")
    return {nid: ", ".join(items[:MAX_MARK_NAMES] + ([f"and {len(items) - MAX_MARK_NAMES} more"]
                                                     if len(items) > MAX_MARK_NAMES else []))
            for nid, items in out.items()}


def to_html(pm: ProgramMap, links: str = "file", marks: dict[str, str] | None = None) -> str:
    """The interactive page (see the module docstring), with the entry points by class, the
    modules only an operator starts, the dead routines and the edges as tables below the map.
    `links`: one of :data:`LINKS`; `marks`: see :func:`map_widget`."""
    widget = map_widget(pm, links, marks)
    return render_html("krl.programmap", "graph.html.j2", title=f"Program map: {pm.root}",
                       widget=widget, **context(pm, None))


#: the entry point tables of the map section: title, entry kinds (krl/programmap/graph.py)
ENTRY_GROUPS = (("Started by the controller", ("cell", "plc", "submit", "selected", "interrupt", "trigger")),
                ("Selected by an operator (R1/Program)", ("operator",)),
                ("Main routines of modules (a folder that is not a backup)", ("module",)),
                ("KUKA's system software", ("system",)))


def context(pm: ProgramMap, svg: str | None) -> dict:
    """The template values of the map section ``_map_body.html.j2`` (shared with the change
    report): the map, its drawing (`svg` None: none, the interactive page draws it; "" for
    Graphviz missing), the routines of the backup's own (``own``) by reach (``by_reach``), the
    entry points by :data:`ENTRY_GROUPS` (``entry_groups``: title and nodes), the main routine
    of each module only an operator starts (``operator_mains``), ``short(path)``."""
    own = [n for n in pm.nodes.values() if n.kind == "routine" and not n.kuka]
    by_reach: dict[str, list] = {}
    for n in own:
        by_reach.setdefault(n.reach, []).append(n)
    entries = [pm.nodes[nid] for nid in pm.entries]
    groups = [(title, [n for n in entries if n.entry_kind in kinds]) for title, kinds in ENTRY_GROUPS]
    first: dict[str, object] = {}
    for n in own:
        first.setdefault(n.module, n)
    return {"map": pm, "image": None if svg is None else svg_data_uri(svg) if svg else "",
            "short": lambda p: _short(p, pm.root), "own": own, "by_reach": by_reach,
            "kuka_routines": sum(n.kind == "routine" and n.kuka for n in pm.nodes.values()),
            "entry_groups": [(t, ns) for t, ns in groups if ns],
            "operator_mains": [first[m] for m in pm.operator_only]}
