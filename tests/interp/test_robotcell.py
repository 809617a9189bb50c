"""A cell of several robots (issue 89, interp/robotcell.py): two programs handing a part over
through wired I/O run on one IPO clock; miswired, the cell deadlocks and names each wait.

Expected times are worked out by hand from the reference's rules: a WAIT SEC t ends in the
first IPO cycle (12 ms) at or after t, and a wire carries an output written in cycle k to its
input for cycle k + 1 (interp/robotcell.py's decision, docs/cells.md).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from click.testing import CliRunner
from jsonschema import Draft202012Validator

from app import main
from interp import robotcell
from interp.robotcell import (BLOCKED_CYCLES, CellError, cell_runs, is_robot_cell, load_robot_cell, robot_trace, run_cell,
                             summary_lines)
from interp.run import RunSinks, make_runtime, run_setup
from krl.limits import MAX_CELL_ROBOTS

HANDLER = """DEF handler()
  $OUT[10] = FALSE
  WAIT SEC 0.5
  $OUT[10] = TRUE
  WAIT FOR $IN[11]
  $OUT[10] = FALSE
END
"""
# the palletizer moves away once it has the part, while the handler goes on
PALLETIZER = """DEF pal()
  WAIT FOR $IN[10]
  WAIT SEC 0.2
  $OUT[11] = TRUE
  PTP {A1 30, A2 -90, A3 90, A4 0, A5 0, A6 0}
END
"""
GOOD = """robots:
  R1: {program: handler.src}
  R2: {program: pal.src}
wires:
  - R1 $OUT[10] -> R2 $IN[10]
  - R2 $OUT[11] -> R1 $IN[11]
"""


def _cell(tmp_path: Path, text: str = GOOD, handler: str = HANDLER, pal: str = PALLETIZER) -> Path:
    (tmp_path / "handler.src").write_text(handler, encoding="utf-8")
    (tmp_path / "pal.src").write_text(pal, encoding="utf-8")
    path = tmp_path / "cell.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def _run(path: Path, interp: str, limit: float = 30.0):
    cell = load_robot_cell(path)
    with cell_runs(cell, interp, limit, mujoco=False) as runs:
        return run_cell(cell, runs)


def _io(run) -> list:
    return [(round(t, 6), name, value) for t, name, value, *_ in run.runtime.controller.io.log]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_hand_off_between_two_robots_runs_on_one_clock(tmp_path, interp):
    res = _run(_cell(tmp_path), interp)
    r1, r2 = res.robots
    assert res.reason == "completed" and res.exit_code == 0
    # R1 writes $OUT[10] in the cycle at 0.504 s (WAIT SEC 0.5: cycle 42); R2 reads it at 0.516 s,
    # its WAIT SEC 0.2 ends in the cycle at 0.720 s (0.716 -> cycle 60), where it writes $OUT[11];
    # R1 reads that at 0.732 s and ends there
    assert r1.runtime.result.sim_time == pytest.approx(0.732)
    assert r2.runtime.result.reason == "completed" and r2.runtime.result.sim_time > 0.720 + 0.1   # it moved on
    assert r2.waited == pytest.approx(0.516) and r1.waited == pytest.approx(0.732 - 0.504)
    (text, seconds, wires), = r2.released
    assert text.endswith("pal.src:2") and seconds == pytest.approx(0.516 - 0.0)
    assert [str(w) for w in wires] == ["R1 $OUT[10] -> R2 $IN[10]"]
    assert [str(w) for w in r1.released[0][2]] == ["R2 $OUT[11] -> R1 $IN[11]"]
    # the input changes come from the wire, one cycle after the output
    ins = [(t, v) for t, name, v in _io(r2) if name == "$IN[10]"]
    outs = [(t, v) for t, name, v in _io(r1) if name == "$OUT[10]"]
    assert outs[-2][1] is True and ins[0] == (pytest.approx(outs[-2][0] + 0.012), True)


def test_tree_and_vm_agree_robot_by_robot(tmp_path):
    path = _cell(tmp_path)
    tree, vm = _run(path, "tree"), _run(path, "vm")
    for a, b in zip(tree.robots, vm.robots):
        assert _io(a) == _io(b)
        ra, rb = a.runtime.result, b.runtime.result
        assert (ra.reason, ra.line, ra.sim_time, a.waited) == (rb.reason, rb.line, rb.sim_time, b.waited)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_miswired_interlock_deadlocks_and_names_the_wait(tmp_path, interp):
    res = _run(_cell(tmp_path, GOOD.replace("R1 $IN[11]", "R1 $IN[12]")), interp)
    r1, r2 = res.robots
    assert res.reason == "deadlock" and res.exit_code == 3
    assert r2.runtime.result.reason == "completed"
    e = r1.runtime.result
    end = r2.runtime.result.sim_time
    assert e.reason == "deadlock" and e.file.endswith("handler.src") and e.line == 5
    assert "R1 WAIT FOR at" in e.text and "handler.src:5" in e.text and "R2 $OUT[11] -> R1 $IN[12]" in e.text
    # the wire's source can set nothing any more: its robot's program ended, its end named as a run
    # names it (the last statement it executed: pal.src's PTP, line 5)
    assert f"R2 $OUT[11] -> R1 $IN[12] (R2 ended: completed at {tmp_path / 'pal.src'}:5)" in e.text
    # R2 ends; from then on R1 alone is blocked, and the cell ends it after BLOCKED_CYCLES such
    # cycles (and the cycle that sees its stop), not at the time limit
    assert end < e.sim_time <= end + 0.012 * (BLOCKED_CYCLES + 2) + 1e-9


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_two_robots_waiting_for_each_other_deadlock_naming_both(tmp_path, interp):
    first_waits = HANDLER.replace("  $OUT[10] = TRUE\n  WAIT FOR $IN[11]\n", "  WAIT FOR $IN[11]\n  $OUT[10] = TRUE\n")
    res = _run(_cell(tmp_path, handler=first_waits), interp)
    texts = [r.runtime.result.text for r in res.robots]
    assert [r.runtime.result.reason for r in res.robots] == ["deadlock", "deadlock"]
    for text in texts:
        assert "handler.src:4" in text and "pal.src:2" in text
    assert texts[0].startswith("cell deadlocked: R1") and texts[1].startswith("cell deadlocked: R2")


@pytest.mark.parametrize("text, message", [
    (GOOD + "  - R2 $OUT[3] -> R3 $IN[3]\n", "no robot R3"),
    (GOOD + "  - R2 $OUT[12] -> R1 $IN[11]\n", "R1 $IN[11] is driven by R2 $OUT[11] -> R1 $IN[11] already"),
    (GOOD + "  - R1 $OUT[1] -> R1 $IN[2]\n", "a wire joins two robots"),
    (GOOD + "  - R1 OUT 1 to R2\n", "a wire is 'R1 $OUT[n] -> R2 $IN[m]'"),
    (GOOD.replace("R2: {program: pal.src}", "R2: {program: nothing.src}"), "cell.yaml:3: program nothing.src: no such"),
    (GOOD.replace("R2: {program: pal.src}", "R2: {program: pal.src, speed: 3}"), "cell.yaml:3: robot R2: unknown key speed"),
    ("robots:\n" + "".join(f"  R{k}: {{program: pal.src}}\n" for k in range(MAX_CELL_ROBOTS + 1)),
     f"more than the limit of {MAX_CELL_ROBOTS}"),
])
def test_a_cell_file_that_makes_no_cell_is_refused_at_its_line(tmp_path, text, message):
    with pytest.raises(CellError, match=None) as err:
        load_robot_cell(_cell(tmp_path, text))
    assert message in str(err.value) and "cell.yaml" in str(err.value)


def test_krl_run_takes_a_cell_and_writes_a_trace_per_robot(tmp_path):
    path = _cell(tmp_path, GOOD.replace("R1 $IN[11]", "R1 $IN[12]"))
    trace = tmp_path / "run.jsonl"
    out = CliRunner().invoke(main, ["run", str(path), "--trace", str(trace), "--max-sim-time", "5"])
    assert out.exit_code == 3, out.output
    lines = out.output.splitlines()
    assert lines[0].startswith("cell       2 robots: deadlock at ")
    assert lines[1].startswith("R1         deadlock at ") and "handler.src:5" in lines[1]
    for name in ("R1", "R2"):
        events = [json.loads(line) for line in robot_trace(trace, name).read_text(encoding="utf-8").splitlines()]
        assert events[-1]["kind"] == "end"
    assert events[-1]["reason"] == "completed"
    bad = CliRunner().invoke(main, ["run", str(_cell(tmp_path, GOOD + "  - R9 $OUT[1] -> R1 $IN[1]\n"))])
    assert bad.exit_code == 2 and "no robot R9" in bad.output and "Traceback" not in bad.output


def test_the_cell_files_json_schema_takes_what_the_reader_takes(tmp_path):
    schema = json.loads((Path(__file__).resolve().parents[2] / "docs/schemas/robot-cell.schema.json").read_text())
    check = Draft202012Validator(schema)
    assert not list(check.iter_errors(yaml.safe_load(GOOD)))
    load_robot_cell(_cell(tmp_path))            # the reader takes it too
    auto = GOOD.replace("program: pal.src", "program: pal.src, inputs: auto")    # tests/interp/test_cell_auto.py
    assert not list(check.iter_errors(yaml.safe_load(auto)))
    load_robot_cell(_cell(tmp_path, auto))
    for bad in (GOOD.replace("program: pal.src", "program: pal.src, speed: 3"), GOOD + "  - R1 OUT 1 to R2\n",
                GOOD + "extra: 1\n"):
        assert list(check.iter_errors(yaml.safe_load(bad))), bad
        with pytest.raises(CellError):
            load_robot_cell(_cell(tmp_path, bad))


def test_four_robots_waiting_their_turn_stay_on_one_clock(tmp_path):
    """Four robots in a ring, robot k waiting k x 20 s before it signals the next: a robot that
    waits (WAIT SEC, WAIT FOR) must not run ahead of the others (a single run's idle watch jumps
    its own clock; a cell's robots jump together or not at all). WAIT SEC 20k ends in the cycle at
    20.004, 40.008, 60.000, 80.004 s (1667, 3334, 5000, 6667 cycles of 12 ms); each input follows
    its partner's output one cycle later."""
    ring = "robots:\n" + "".join(f"  R{k}: {{program: r{k}.src}}\n" for k in range(1, 5)) + "wires:\n" + \
        "".join(f"  - R{k} $OUT[5] -> R{k % 4 + 1} $IN[5]\n" for k in range(1, 5))
    for k in range(1, 5):
        (tmp_path / f"r{k}.src").write_text(f"DEF r{k}()\n  WAIT SEC {20 * k}\n  $OUT[5] = TRUE\n  WAIT FOR $IN[5]\nEND\n")
    (tmp_path / "ring.yaml").write_text(ring)
    res = _run(tmp_path / "ring.yaml", "vm", 100.0)
    outs = {r.name: [t for t, name, *_ in r.runtime.controller.io.log if name == "$OUT[5]"] for r in res.robots}
    ins = {r.name: [t for t, name, *_ in r.runtime.controller.io.log if name == "$IN[5]"] for r in res.robots}
    assert outs == {"R1": [pytest.approx(20.004)], "R2": [pytest.approx(40.008)], "R3": [pytest.approx(60.0)],
                    "R4": [pytest.approx(80.004)]}
    for k in range(1, 5):
        assert ins[f"R{k % 4 + 1}"] == [pytest.approx(outs[f"R{k}"][0] + 0.012)]
    assert res.reason == "completed" and res.time == pytest.approx(80.016)
    assert res.robots[0].waited == pytest.approx(80.016 - 20.004)


# Shared zones (interp/cellzones.py). The KR 6 R900's flange, by the test vectors of
# ../shared/docs/robot-model.md §9: HOME (0, -90, 90, 0, 0, 0) at (525, 0, 890) mm, "tool down"
# (A5 90) at (445, 0, 810). R2 stands at X 970 turned 180° about Z: its HOME is at (445, 0, 890)
# and its tool down at (525, 0, 810) in the cell's world. The zone x 500..540, z 800..900 holds
# R1 at HOME and R2 tool down, neither robot's other pose.
ZONE_CELL = """robots:
  R1: {program: r1.src}
  R2: {program: r2.src, base: [970, 0, 0, 180, 0, 0]}
wires:
  - R1 $OUT[1] -> R2 $IN[1]
zones:
  handoff: {min: [500, -50, 800], max: [540, 50, 900]}
"""
TOOL_DOWN = "PTP {A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0}"
LEAVES = f"DEF r1()\n  WAIT SEC 1\n  {TOOL_DOWN}\n  $OUT[1] = TRUE\nEND\n"


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_two_robots_in_a_shared_zone_at_once_are_reported_with_both_lines(tmp_path, interp):
    (tmp_path / "r1.src").write_text(LEAVES)
    (tmp_path / "r2.src").write_text(f"DEF r2()\n  {TOOL_DOWN}\nEND\n")     # no interlock: enters at once
    (tmp_path / "cell.yaml").write_text(ZONE_CELL)
    res = _run(tmp_path / "cell.yaml", interp)
    (c,) = res.conflicts
    assert c.zone == "handoff" and c.first == ("R1", None)                 # R1 still at HOME, at rest
    assert c.second[0] == "R2" and c.second[1].endswith("r2.src:2")
    assert 0.0 < c.time < 1.0                                               # while R1 waits its second
    assert "conflict   handoff: R1 (at rest) and R2 (" in "\n".join(summary_lines(res))


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_an_interlocked_zone_has_no_conflict(tmp_path, interp):
    (tmp_path / "r1.src").write_text(LEAVES)
    (tmp_path / "r2.src").write_text(f"DEF r2()\n  WAIT FOR $IN[1]\n  {TOOL_DOWN}\nEND\n")
    (tmp_path / "cell.yaml").write_text(ZONE_CELL)
    res = _run(tmp_path / "cell.yaml", interp)
    assert res.reason == "completed" and res.conflicts == []
    # the poses by hand, read back at the end: R1 tool down, R2 tool down in the zone
    ends = {r.name: r.runtime.controller.actual.pos_act(base=(0, 0, 0, 0, 0, 0)) for r in res.robots}
    assert [ends["R1"][k] for k in "XYZ"] == pytest.approx([445, 0, 810], abs=1e-3)
    assert [ends["R2"][k] for k in "XYZ"] == pytest.approx([445, 0, 810], abs=1e-3)   # its own world


@pytest.mark.parametrize("text, message", [
    (ZONE_CELL.replace("max: [540, 50, 900]", "max: [40, 50, 900]"), "zone handoff: min is above max"),
    (ZONE_CELL.replace("{min: [500, -50, 800], max: [540, 50, 900]}", "[1, 2]"), "zone handoff: {min"),
    (ZONE_CELL.replace("[970, 0, 0, 180, 0, 0]", "[970, 0]"), "robot R2's base [X, Y, Z, A, B, C]"),
])
def test_a_bad_zone_or_base_is_refused_at_its_line(tmp_path, text, message):
    (tmp_path / "r1.src").write_text(LEAVES)
    (tmp_path / "r2.src").write_text(LEAVES)
    (tmp_path / "cell.yaml").write_text(text)
    with pytest.raises(CellError) as err:
        load_robot_cell(tmp_path / "cell.yaml")
    assert message in str(err.value) and "cell.yaml:" in str(err.value)


MOVER = """DEF mover()
  PTP {{A1 {a}, A2 -90, A3 90, A4 0, A5 45, A6 0}}
  $OUT[3] = TRUE
  WAIT SEC 0.1
  LIN {{X 500, Y {y}, Z 700, A 0, B 90, C 0}}
  $OUT[3] = FALSE
  PTP {{A1 -{a}, A2 -80, A3 100, A4 0, A5 30, A6 0}}
END
"""


@pytest.mark.parametrize("interp,apart", [("tree", 1300), ("vm", 1300), ("vm", 4000)])
def test_an_unwired_robots_trace_and_io_in_a_cell_are_its_own_run_alone(tmp_path, interp, apart):
    """A robot no wire, zone or partner's motion reaches runs in a cell as it runs alone: its
    trace stream (every event and pose, on the same clock) and its I/O are the single run's
    (``krl run`` of its program), however the cell steps its robots (interp/robotcell.py). R2
    stands 1.3 m away facing R1 (turned 180°), within reach (robot/cellscene.py: 2 x 981 mm), so
    the cell checks their bodies in every cycle one moved; at HOME their wrists are 1300 - 2 x 525
    - 2 x 78.9 = 92 mm apart and their motions never bring them together. 4 m apart nothing
    couples them and they take turns of several cycles (interp/cellturns.py)."""
    for name, a, y in (("r1", 30, 100), ("r2", 20, -100)):
        (tmp_path / f"{name}.src").write_text(MOVER.replace("mover", name).format(a=a, y=y), encoding="utf-8")
    (tmp_path / "cell.yaml").write_text("robots:\n  R1: {program: r1.src}\n"
                                        f"  R2: {{program: r2.src, base: [{apart}, 0, 0, 180, 0, 0]}}\n", encoding="utf-8")
    cell = load_robot_cell(tmp_path / "cell.yaml")
    with cell_runs(cell, interp, 30.0, trace=tmp_path / "cell.jsonl", mujoco=False) as runs:
        res = run_cell(cell, runs)
    assert res.reason == "completed" and res.collisions == []
    for r in res.robots:
        alone = tmp_path / f"alone.{r.name}.jsonl"
        with run_setup({"program": tmp_path / f"{r.name.lower()}.src", "interp_kind": interp, "max_sim_time": 30.0,
                        "trace_path": alone}) as setup:
            writer = setup.trace_writer()
            rt, _ = make_runtime(setup.spec.with_(mujoco=False), RunSinks(trace=writer))
            end = rt.run()
            writer.close()
        assert (end.reason, end.sim_time) == (r.runtime.result.reason, r.runtime.result.sim_time)
        assert _io(r) == [(round(t, 6), n, v) for t, n, v, *_ in rt.controller.io.log]
        assert [(t, n, v) for t, n, v in _io(r) if n == "$OUT[3]"][0][2] is True
        ours = robot_trace(tmp_path / "cell.jsonl", r.name).read_text(encoding="utf-8").splitlines()
        theirs = alone.read_text(encoding="utf-8").splitlines()
        assert len(ours) > 50 and ours == theirs


def test_a_cell_asked_for_then_loaded_is_read_once_and_again_when_changed(tmp_path, monkeypatch):
    """``krl run CELL`` asks is_robot_cell, then loads the cell: one YAML read of the file for
    both, the cell the same as loaded alone; a file rewritten in between (another wire, another
    size) is read again, and a document is taken once (a second load reads again)."""
    path = _cell(tmp_path)
    alone = load_robot_cell(path)
    reads = []
    real = robotcell.read_cell_yaml
    monkeypatch.setattr(robotcell, "read_cell_yaml", lambda p: reads.append(p) or real(p))
    assert is_robot_cell(path) and load_robot_cell(path) == alone and len(reads) == 1
    assert load_robot_cell(path) == alone and len(reads) == 2
    assert is_robot_cell(path) and len(reads) == 3
    path.write_text(GOOD.replace("$IN[11]\n", "$IN[12]\n"), encoding="utf-8")
    changed = load_robot_cell(path)
    assert len(reads) == 4 and [w.input for w in changed.wires] == [10, 12] != [w.input for w in alone.wires]
    assert not is_robot_cell(tmp_path / "handler.src") and load_robot_cell(path) == changed and len(reads) == 5
