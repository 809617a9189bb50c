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

from krl.limits import MAX_GRAPH_NODES, MAX_GRAPH_SOURCE_CHARS
from krl.source import read_source
from krl.programmap.graph import ProgramMap
from krl.render import render_html

__all__ = ["GraphTooLarge", "GraphvizMissing", "LINKS", "to_dot", "to_svg", "to_html", "page_data"]

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
    """The map as a graphviz.Digraph: entry points double-bordered, unreachable routines grey."""
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


def _href(path: str, line: int, links: str) -> str:
    """The link of a routine at `path`:`line`: "" when `links` is "none" or the file is not on
    this machine (a map read from an archive names files inside the archive)."""
    p = Path(path)
    if links == "none" or not p.is_absolute() or not p.is_file():
        return ""
    if links == "vscode":
        return "vscode://file" + quote(p.as_posix()) + f":{line}"
    return p.as_uri()


def page_data(pm: ProgramMap, links: str = "file") -> dict:
    """The map as the page's JSON: nodes (id, name, module, kind, file shown relative to the
    root, line, href, system, entry, entry_kind, unreachable, and ``source``: the routine's own
    lines, DEF to END, up to krl.limits.MAX_GRAPH_SOURCE_CHARS in all) and edges (source,
    target, kind, file, line)."""
    texts: dict[str, list[str]] = {}
    budget = MAX_GRAPH_SOURCE_CHARS
    nodes = []
    for n in pm.nodes.values():
        source = []
        if n.path and n.kind == "routine" and budget > 0:
            if n.path not in texts:
                texts[n.path] = (read_source(n.path).text or "").splitlines() if Path(n.path).is_file() else []
            source = texts[n.path][n.line - 1:max(n.end, n.line)]
            budget -= sum(len(x) + 1 for x in source)
            if budget < 0:
                source = []
        nodes.append({"id": n.id, "name": n.name, "module": n.module, "kind": n.kind,
                      "file": _short(n.path, pm.root) if n.path else "", "line": n.line,
                      "href": _href(n.path, n.line, links) if n.path else "", "system": n.kuka,
                      "entry": n.entry, "entry_kind": n.entry_kind, "unreachable": n.unreachable,
                      "source": source})
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


def to_html(pm: ProgramMap, links: str = "file") -> str:
    """The interactive page (see the module docstring), with the entry points, the unreachable
    routines and the edges as tables below the map. `links`: one of :data:`LINKS`."""
    if len(pm.nodes) > MAX_GRAPH_NODES:
        raise GraphTooLarge(f"the program map has {len(pm.nodes)} nodes (limit MAX_GRAPH_NODES = {MAX_GRAPH_NODES})")
    return render_html("krl.programmap", "graph.html.j2", title=f"Program map: {pm.root}",
                       data=page_data(pm, links), script=_script(), **context(pm, None))


def context(pm: ProgramMap, svg: str | None) -> dict:
    """The template values of the map section (shared with the change report); `svg` None: no
    drawing in the section (the interactive page draws it), "" for Graphviz missing."""
    return {"map": pm, "image": None if svg is None else svg_data_uri(svg) if svg else "",
            "short": lambda p: _short(p, pm.root)}
