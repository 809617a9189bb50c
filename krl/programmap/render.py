"""The program map as DOT, SVG, JSON and one HTML page (``krl graph``).

DOT and SVG go through the ``graphviz`` Python binding (PyPI ``graphviz``), which quotes every
name and label; SVG runs Graphviz's ``dot`` (Debian package ``graphviz``). Labels from the
input (routine, module and file names) pass through :func:`graphviz.escape`, so a backslash
in a file name is text, not a DOT escape. The HTML page is rendered in the project's one Jinja
environment (krl/render.py, autoescape on) from ``templates/graph.html.j2``; the SVG is put in
the page as an ``<img>`` data URI, so nothing of it runs as the page's markup. Maps larger than
krl.limits.MAX_GRAPH_NODES are refused with :class:`GraphTooLarge`.
"""

from __future__ import annotations

import base64
from pathlib import Path

import graphviz

from krl.limits import MAX_GRAPH_NODES
from krl.programmap.graph import ProgramMap
from krl.render import render_html

__all__ = ["GraphTooLarge", "GraphvizMissing", "to_dot", "to_svg", "to_html"]

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
    """The map as a graphviz.Digraph: entry points double-bordered, dead routines grey."""
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
        if n.dead:
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


def to_html(pm: ProgramMap, svg: str | None = None) -> str:
    """One HTML page: the drawing (when `svg` is given or dot is installed), the entry points,
    the dead routines and the edges, as tables."""
    if svg is None:
        try:
            svg = to_svg(pm)
        except GraphvizMissing:
            svg = ""
    return render_html("krl.programmap", "graph.html.j2", title=f"Program map: {pm.root}", **context(pm, svg))


def context(pm: ProgramMap, svg: str) -> dict:
    """The template values of the map section (shared with the change report)."""
    return {"map": pm, "image": svg_data_uri(svg) if svg else "",
            "short": lambda p: _short(p, pm.root)}
