"""The comparisons of conformance/harness.py on synthetic traces: each check must be able to
fail, and its message must say where."""

from __future__ import annotations

import math
from pathlib import Path

import yaml

from conformance import harness as H


def _case(tmp_path: Path, src: str, expect: dict) -> H.Case:
    (tmp_path / "program.src").write_text(src, encoding="utf-8")
    (tmp_path / "expect.yaml").write_text(yaml.safe_dump(expect), encoding="utf-8")
    return H.load_case(tmp_path)


SRC = """DEF program()
  DECL INT i
  FOR i = 1 TO 2
    $OUT[1] = TRUE
  ENDFOR
  Sub()
END

DEF Sub()
  $OUT[2] = TRUE
END
"""


def _stmt(line, t=0.0, ctx="main", file="program.src"):
    return {"t": t, "kind": "stmt", "file": f"/x/{file}", "line": line, "context": ctx}


def _run(events, code=0):
    return H.RunResult("tree", events, code)


def test_leaf_lines_skip_control_and_declarations(tmp_path):
    c = _case(tmp_path, SRC, {"flow": []})
    assert H.leaf_lines(c.program) == {4, 6, 10}


def test_expand_flow_repeat_and_tokens():
    assert H.expand_flow([{"repeat": [4], "times": 2}, "call sub", "interrupt 5", "interrupt 5 exit"]) == \
        ["4", "4", "call SUB", "interrupt 5 entry", "interrupt 5 exit"]


def test_flow_passes_and_fails_with_a_diff(tmp_path):
    c = _case(tmp_path, SRC, {"flow": [4, 4, 6, "call SUB", 10, "return SUB"], "end": {"reason": "completed"}})
    ev = [{"t": 0, "kind": "call", "name": "program"}, _stmt(3), _stmt(4), _stmt(4), _stmt(6),
          {"t": 0, "kind": "call", "name": "Sub"}, _stmt(10), {"t": 0, "kind": "return", "name": "Sub"},
          {"t": 0, "kind": "end", "reason": "completed"}]
    assert H.check_case(c, _run(ev)).passed
    bad = [e for e in ev if not (e.get("kind") == "stmt" and e.get("line") == 4)][:2] + ev[3:]
    cr = H.check_case(c, _run(bad))
    assert not cr.passed
    assert "first difference at position" in cr.diff_text() and "-4" in cr.diff_text()


def test_interrupt_entry_implies_the_handler_call(tmp_path):
    c = _case(tmp_path, SRC, {"flow": [6, "interrupt 5 entry", 10, "interrupt 5 exit"]})
    ev = [_stmt(6), {"t": 0, "kind": "interrupt", "prio": 5, "name": "Sub", "phase": "entry"},
          {"t": 0, "kind": "call", "name": "Sub"}, _stmt(10, ctx="interrupt"),
          {"t": 0, "kind": "return", "name": "Sub"},
          {"t": 0, "kind": "interrupt", "prio": 5, "name": "Sub", "phase": "exit"}]
    assert H.check_case(c, _run(ev)).passed


def test_io_timing_tolerance_is_one_ipo_cycle(tmp_path):
    c = _case(tmp_path, SRC, {"io": [{"signal": "$OUT[1]", "value": True, "t": 0.5}]})
    ok = [{"t": 0.512, "kind": "io", "signal": "$OUT[1]", "value": True, "source": "program"}]
    late = [{"t": 0.525, "kind": "io", "signal": "$OUT[1]", "value": True, "source": "program"}]
    assert H.check_case(c, _run(ok)).passed
    cr = H.check_case(c, _run(late))
    assert not cr.passed and "expected t=0.500" in cr.diff_text()


def test_unexpected_output_fails(tmp_path):
    c = _case(tmp_path, SRC, {"io": [{"signal": "$OUT[1]", "value": True}]})
    ev = [{"t": 0, "kind": "io", "signal": "$OUT[1]", "value": True, "source": "program"},
          {"t": 0, "kind": "io", "signal": "$OUT[9]", "value": True, "source": "program"}]
    assert not H.check_case(c, _run(ev)).passed


def test_io_anchor_relative_to_a_motion(tmp_path):
    c = _case(tmp_path, SRC, {"io": [{"signal": "$OUT[1]", "value": True, "after": {"motion": 2, "phase": "end"},
                                      "dt": -0.2}]})
    mot = [{"t": 0.3, "kind": "motion", "id": 2, "phase": "start", "point": [0, 0, 0, 0, 0, 0]},
           {"t": 1.3, "kind": "motion", "id": 2, "phase": "end", "point": [0, 0, 0, 0, 0, 0]}]
    good = mot + [{"t": 1.104, "kind": "io", "signal": "$OUT[1]", "value": True, "source": "trigger"}]
    bad = mot + [{"t": 1.3, "kind": "io", "signal": "$OUT[1]", "value": True, "source": "trigger"}]
    assert H.check_case(c, _run(good)).passed
    assert not H.check_case(c, _run(bad)).passed


def _line_trace(bend_mm=0.0):
    ev = [{"t": 0.0, "kind": "motion", "id": 1, "phase": "start", "point": [0, 0, 0, 0, 0, 0]},
          {"t": 0.0, "kind": "motion", "id": 1, "phase": "end", "point": [0, 0, 0, 0, 0, 0]},
          {"t": 0.012, "kind": "motion", "id": 2, "phase": "start", "point": [100, 0, 0, 0, 0, 0]}]
    for k in range(11):
        y = bend_mm * math.sin(math.pi * k / 10)
        ev.append({"t": 0.012 * (k + 1), "kind": "pose", "axes": [0] * 6, "tcp": [10.0 * k, y, 0, 0, 0, 0]})
    ev.append({"t": 0.132, "kind": "motion", "id": 2, "phase": "end", "point": [100, 0, 0, 0, 0, 0]})
    return ev


def test_straightness_detects_a_bent_path(tmp_path):
    c = _case(tmp_path, SRC, {"motion": [{"check": "straight", "id": 2, "tol_mm": 0.01}]})
    assert H.check_case(c, _run(_line_trace(0.0))).passed
    cr = H.check_case(c, _run(_line_trace(0.05)))
    assert not cr.passed and "max distance from the line" in cr.diff_text()


def _blend_trace(radius):
    """Corner at (100, 0, 0); the path leaves the first segment `radius` mm before it."""
    ev = [{"t": 0.0, "kind": "motion", "id": 1, "phase": "start", "point": [0, 0, 0, 0, 0, 0]}]
    pts = []
    for k in range(50):
        pts.append([2.0 * k, 0.0, 0.0])
    # quadratic Bezier from (100-r, 0) via the corner to (100, r)
    for k in range(1, 20):
        u = k / 20
        a, b, cc = (100 - radius, 0), (100, 0), (100, radius)
        pts.append([(1 - u) ** 2 * a[0] + 2 * u * (1 - u) * b[0] + u * u * cc[0],
                    (1 - u) ** 2 * a[1] + 2 * u * (1 - u) * b[1] + u * u * cc[1], 0.0])
    for k in range(0, 40):
        pts.append([100.0, radius + 2.0 * k, 0.0])
    t_bs = 0.012 * (int((100 - radius) / 2) + 1)
    t_be = 0.012 * (50 + 20)
    for k, p in enumerate(pts):
        ev.append({"t": 0.012 * (k + 1), "kind": "pose", "axes": [0] * 6, "tcp": p + [0, 0, 0]})
    ev += [{"t": t_bs, "kind": "motion", "id": 1, "phase": "blend_start", "point": [100, 0, 0, 0, 0, 0]},
           {"t": t_bs, "kind": "motion", "id": 2, "phase": "start", "point": [100, 100, 0, 0, 0, 0]},
           {"t": t_be, "kind": "motion", "id": 1, "phase": "blend_end", "point": [100, 0, 0, 0, 0, 0]},
           {"t": t_be, "kind": "motion", "id": 1, "phase": "end", "point": [100, 0, 0, 0, 0, 0]}]
    ev.sort(key=lambda e: e["t"])
    return ev


def test_blend_zone_and_distances(tmp_path):
    c = _case(tmp_path, SRC, {"motion": [{"check": "blend", "id": 1, "start_mm": 20, "end_mm": 20,
                                          "zone_mm": 20, "tol_mm": 1.0}]})
    assert H.check_case(c, _run(_blend_trace(20))).passed, H.check_case(c, _run(_blend_trace(20))).diff_text()
    cr = H.check_case(c, _run(_blend_trace(30)))
    assert not cr.passed and "blend starts" in cr.diff_text()


def test_exact_stop_fails_on_a_blend(tmp_path):
    c = _case(tmp_path, SRC, {"motion": [{"check": "exact_stop", "id": 1}]})
    cr = H.check_case(c, _run(_blend_trace(20)))
    assert not cr.passed and "approximated" in cr.diff_text()


def test_end_and_crash(tmp_path):
    c = _case(tmp_path, SRC, {"end": {"reason": "error", "number": 1422, "line": 4}})
    ev = [{"t": 0, "kind": "end", "reason": "error", "number": 1422, "line": 4}]
    assert H.check_case(c, _run(ev)).passed
    assert not H.check_case(c, _run([{"t": 0, "kind": "end", "reason": "completed"}])).passed
    crashed = H.RunResult("tree", [], 2, crash="internal error: KeyError")
    assert not H.check_case(c, crashed).passed


def test_tree_vm_comparison_finds_differences():
    ev = _line_trace(0.0) + [{"t": 0.5, "kind": "io", "signal": "$OUT[1]", "value": True, "source": "program"},
                             _stmt(4, 0.5), {"t": 0.6, "kind": "end", "reason": "completed"}]
    a = H.RunResult("tree", ev, 0)
    assert all(c.ok for c in H.compare_runs(a, H.RunResult("vm", list(ev), 0)))
    late = [dict(e, t=0.512) if e.get("kind") == "io" else e for e in ev]
    bad = {c.name for c in H.compare_runs(a, H.RunResult("vm", late, 0)) if not c.ok}
    assert bad == {"tree_vm.io"}
    bent = [dict(e, tcp=[e["tcp"][0], e["tcp"][1] + 0.001] + e["tcp"][2:]) if e.get("kind") == "pose" else e
            for e in ev]
    bad = {c.name for c in H.compare_runs(a, H.RunResult("vm", bent, 0)) if not c.ok}
    assert bad == {"tree_vm.path"}
    other_flow = [dict(e, line=5) if e.get("kind") == "stmt" else e for e in ev]
    bad = {c.name for c in H.compare_runs(a, H.RunResult("vm", other_flow, 0)) if not c.ok}
    assert bad == {"tree_vm.flow"}


def test_expectations_that_check_nothing_fail(tmp_path):
    c = _case(tmp_path, SRC, {"title": "x"})
    assert not H.check_case(c, _run([{"t": 0, "kind": "end", "reason": "completed"}])).passed


def _stop_trace(stand_at: float | None, gap: bool):
    """A LIN from (0,0,0) to (200,0,0), 2 mm a cycle; with `stand_at`, the TCP stands at X
    `stand_at` for 100 cycles (as consecutive poses, or, with `gap`, as the gap a bounded trace
    leaves for a standstill: robot/trace.py's repeat events)."""
    ev = [{"t": 0.0, "kind": "motion", "id": 1, "phase": "start", "point": [0, 0, 0, 0, 0, 0]},
          {"t": 0.0, "kind": "motion", "id": 1, "phase": "end", "point": [0, 0, 0, 0, 0, 0]},
          {"t": 0.0, "kind": "motion", "id": 2, "phase": "start", "point": [200, 0, 0, 0, 0, 0]}]
    t, x, stood = 0.0, 0.0, False
    while x < 200.0:
        t += 0.012
        if stand_at is not None and not stood and x >= stand_at:
            if not gap:
                for _ in range(100):
                    ev.append({"t": t, "kind": "pose", "axes": [0] * 6, "tcp": [x, 0, 0, 0, 0, 0]})
                    t += 0.012
            else:
                ev.append({"t": t, "kind": "pose", "axes": [0] * 6, "tcp": [x, 0, 0, 0, 0, 0]})
                t += 100 * 0.012
            stood = True
        x += 2.0
        ev.append({"t": t, "kind": "pose", "axes": [0] * 6, "tcp": [min(x, 200.0), 0, 0, 0, 0, 0]})
    ev.append({"t": t, "kind": "motion", "id": 2, "phase": "end", "point": [200, 0, 0, 0, 0, 0]})
    return ev


def test_stops_at_holds_the_stop_position_and_its_time(tmp_path):
    """STOP WHEN PATH (case 122): the TCP stands at the expected point long enough, and nowhere
    else; point null: it stands nowhere inside the motion."""
    c = _case(tmp_path, SRC, {"motion": [{"check": "stops_at", "id": 2, "point": [150.0, 0.0, 0.0],
                                          "tol_mm": 1.2, "min_seconds": 1.0}]})
    for gap in (False, True):
        assert H.check_case(c, _run(_stop_trace(150.0, gap))).passed, H.check_case(c, _run(_stop_trace(150.0, gap))).diff_text()
        cr = H.check_case(c, _run(_stop_trace(100.0, gap)))          # stands elsewhere
        assert not cr.passed and "standstills: [100.0, 0.0, 0.0]" in cr.diff_text()
    cr = H.check_case(c, _run(_stop_trace(None, False)))              # never stands
    assert not cr.passed and "standstills: none" in cr.diff_text()
    (tmp_path / "never").mkdir()
    never = _case(tmp_path / "never", SRC, {"motion": [{"check": "stops_at", "id": 2, "point": None}]})
    assert H.check_case(never, _run(_stop_trace(None, False))).passed
    cr = H.check_case(never, _run(_stop_trace(150.0, True)))
    assert not cr.passed and "stands at [150.0, 0.0, 0.0]" in cr.diff_text()
