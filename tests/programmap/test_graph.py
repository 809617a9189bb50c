"""The program map (krl graph, issue 26) on a hand-written backup whose calls, interrupts,
triggers, RUN commands, EKI channels, entry points and dead routines were counted by hand, and
on every KRC backup of the shared corpus against the checker's own resolution."""

from __future__ import annotations

import json
import re
from pathlib import Path
import xml.etree.ElementTree as ET

import pytest
from click.testing import CliRunner

from krl.ast import nodes as N
from app import main
from krl.programmap import build_map
from krl.programmap.render import to_dot, to_svg
from krl.project import find_backups
from krl.workspace import workspaces_for
from tests.system_tools import require

FIXTURE = Path(__file__).parent / "fixtures" / "KRC"


@pytest.fixture(scope="module")
def fixture_map():
    return build_map(workspaces_for(FIXTURE)[0])


def test_edges_counted_by_hand(fixture_map):
    got = sorted((e.source, e.kind, e.target, Path(e.path).name, e.line) for e in fixture_map.edges)
    assert got == sorted([
        ("CELL:CELL", "interrupt", "CELL:STOP_HANDLER", "cell.src", 2),   # INTERRUPT DECL 5 ... DO stop_handler()
        ("CELL:CELL", "call", "PICK:PICK", "cell.src", 4),
        ("PICK:PICK", "call", "PICK:HELPER_FCT", "pick.src", 6),          # a function in an expression
        ("PICK:PICK", "trigger", "PICK:GRIPPER_ON", "pick.src", 7),       # TRIGGER ... DO gripper_on()
        ("PICK:PICK", "run", "AUX:AUX", "pick.src", 9),                   # CWRITE($CMD, ..., "RUN /R1/aux()")
        ("PICK:PICK", "eki", "EKI:ChannelA", "pick.src", 10),             # EKI_Init("ChannelA")
        ("PICK:UNUSED_LOCAL", "call", "PICK:GRIPPER_ON", "pick.src", 19),
        ("ORPHAN:ORPHAN", "call", "ORPHAN:HELPER2", "orphan.src", 2),
        ("SPS:SPS", "call", "SPS:PLC_STEP", "sps.sub", 3),
    ])
    # BRAKE in stop_handler and DO BRAKE are statements, not calls; nothing is left unresolved
    assert fixture_map.unresolved == []


def test_entry_points_and_unreachable_routines_counted_by_hand(fixture_map):
    entries = {nid: (fixture_map.nodes[nid].entry_kind, fixture_map.nodes[nid].entry) for nid in fixture_map.entries}
    assert entries == {
        "CELL:CELL": ("cell", "cell program (Automatic External)"),
        "SPS:SPS": ("submit", "submit interpreter"),
        "BG:BG": ("selected", "selected by $custom.dat"),                 # also under R1/Program
        # the module mains under R1/Program an operator can select at the pendant
        "AUX:AUX": ("operator", "selectable at the pendant (R1/Program)"),
        "ORPHAN:ORPHAN": ("operator", "selectable at the pendant (R1/Program)"),
        "PICK:PICK": ("operator", "selectable at the pendant (R1/Program)"),
        # INTERRUPT DECL 5 ... DO stop_handler() in cell.src, which the controller starts
        "CELL:STOP_HANDLER": ("interrupt", "interrupt handler (declared by cell)"),
        # TRIGGER ... DO gripper_on() in pick, which cell calls
        "PICK:GRIPPER_ON": ("trigger", "trigger routine (TRIGGER in pick)"),
    }
    # orphan's helper2 is reached from the selectable orphan; only a local routine nobody calls
    assert [n.id for n in fixture_map.unreachable] == ["PICK:UNUSED_LOCAL"]
    # reach: cell calls pick, which RUNs aux and calls helper_fct; sps and bg the controller
    # starts; orphan and helper2 only an operator (nothing the controller starts calls them)
    reach = {nid: n.reach for nid, n in fixture_map.nodes.items() if n.kind == "routine"}
    assert reach == {"CELL:CELL": "controller", "CELL:STOP_HANDLER": "controller", "PICK:PICK": "controller",
                     "PICK:HELPER_FCT": "controller", "PICK:GRIPPER_ON": "controller", "AUX:AUX": "controller",
                     "BG:BG": "controller", "SPS:SPS": "controller", "SPS:PLC_STEP": "controller",
                     "ORPHAN:ORPHAN": "operator", "ORPHAN:HELPER2": "operator", "PICK:UNUSED_LOCAL": "dead"}
    assert fixture_map.operator_only == ["orphan"]
    # 12 routines + 1 channel; every routine knows its module and file:line
    assert sum(n.kind == "routine" for n in fixture_map.nodes.values()) == 12
    helper = fixture_map.nodes["PICK:HELPER_FCT"]
    assert (helper.name, helper.module, Path(helper.path).name, helper.line) == ("helper_fct", "pick", "pick.src", 12)


def test_loose_folder_makes_every_main_routine_an_entry(tmp_path):
    (tmp_path / "a.src").write_text("DEF a()\n  b()\nEND\nDEF b()\nEND\nDEF never()\nEND\n")
    (tmp_path / "c.src").write_text("DEF c()\nEND\n")
    pm = build_map(workspaces_for(tmp_path)[0])
    assert sorted(pm.entries) == ["A:A", "C:C"]
    assert [n.id for n in pm.unreachable] == ["A:NEVER"]
    assert {pm.nodes[e].entry_kind for e in pm.entries} == {"module"}


def test_dot_has_one_arrow_per_edge_and_no_port_syntax(fixture_map):
    dot = to_dot(fixture_map)
    arrows = re.findall(r"^\s*(n\d+) -> (n\d+)", dot, re.M)
    assert len(arrows) == 9
    assert dot.count("peripheries=2") == 8        # the eight entry points
    assert "EKI ChannelA" in dot


def test_cli_graph_json_and_errors(tmp_path):
    r = CliRunner().invoke(main, ["graph", str(FIXTURE), "--format", "json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    assert len(doc["edges"]) == 9 and doc["unreachable"] == ["PICK:UNUSED_LOCAL"]
    r = CliRunner().invoke(main, ["graph", str(tmp_path / "nope")])
    assert r.exit_code == 2 and "error[E001]: no such file or folder" in r.output


def _resolved_calls(ws, pm):
    """(source id, target id, line) for every call the checker resolved to a routine of the
    workspace, found by walking the ASTs here (independently of the map's own walk)."""
    out = []
    for u in ws.units:
        if u.src is None or not u.src.ok:
            continue
        for r in u.src.module.routines:
            src = pm.node_of(r)
            for node in r.walk():
                if not isinstance(node, N.Call) or node.ann is None or node.ann.symbol is None:
                    continue
                decl = node.ann.symbol.decl
                if not isinstance(decl, N.Routine):
                    g = ws.global_scope.routines.get(node.name.upper())
                    decl = g.decl if g is not None else None
                if isinstance(decl, N.Routine):
                    out.append((src.id, pm.node_of(decl).id, node.span.line))
    return out


def test_corpus_backups_have_an_edge_for_every_call_the_checker_resolves(shared_corpus):
    backups = find_backups(shared_corpus)
    assert len(backups) >= 4
    for b in backups:
        ws = workspaces_for(b, timeout=60)[0]
        pm = build_map(ws)
        edges = {(e.source, e.target, e.line) for e in pm.edges if e.kind in ("call", "interrupt", "trigger")}
        resolved = _resolved_calls(ws, pm)
        assert resolved, b
        assert set(resolved) <= edges, (b, sorted(set(resolved) - edges)[:5])
        # no edge to a name the checker did not resolve, and every edge ends at a node
        assert all(e.source in pm.nodes and e.target in pm.nodes for e in pm.edges)
        for src, name, path, line in pm.unresolved:
            assert not any(e.source == src and e.line == line and pm.nodes[e.target].name.upper() == name.upper()
                           for e in pm.edges), (b, name, path, line)
        # each call edge's line names its target (a check of the lines, from the text)
        for e in pm.edges:
            if e.kind == "call":
                text = Path(e.path).read_text(encoding="latin-1").splitlines()[e.line - 1]
                assert pm.nodes[e.target].name.upper() in text.upper(), (b, e)


def test_svg_drawn_by_graphviz(fixture_map):
    require("dot")
    svg = ET.fromstring(to_svg(fixture_map))
    ns = {"s": "http://www.w3.org/2000/svg"}
    groups = svg.findall(".//s:g", ns)
    assert sum(g.get("class") == "node" for g in groups) == 13       # 12 routines + the EKI channel
    assert sum(g.get("class") == "edge" for g in groups) == 9
    texts = {t.text for t in svg.findall(".//s:text", ns)}
    assert {"helper_fct", "EKI ChannelA", "interrupt", "trigger", "RUN"} <= texts

