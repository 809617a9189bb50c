"""Two robots of a cell touching each other (issue 89, interp/cellcontacts.py on the cell's one
MuJoCo scene, robot/cellscene.py): reported once per contact episode with the time, both robots'
bodies and both programs' motion lines; robots placed apart report none.

The contact, worked out by hand. Two KR 6 R900 (robot/data, ../shared/docs/robot-model.md §9): at
HOME (0, -90, 90, 0, 0, 0) the forearm lies along +X at Z 890 mm, its wrist links A4..A6 a capsule
of radius r = 78.885 mm (robot/capsules.py's rule: 85.38 x (0.901456 m reach) ** 0.7627) from
X 25 to the flange point at X 525 (link 6: a sphere there). R2 stands at X D turned 180° about Z:
at HOME its wrist capsule runs from X D - 525 to D - 25, facing R1. R1 turns A1 from 90° to 0:
its flange point at angle θ is (525 cos θ, 525 sin θ, 890), the point of R1's capsule nearest to
R2's end point (D - 525, 0, 890) while 525 < (D - 525) cos θ. The two touch when
    525² + (D - 525)² - 2 · 525 · (D - 525) · cos θ = (2 r)²
For D = 1150: cos θ = (275625 + 390625 - 157.77²) / (2 · 525 · 625) = 0.97731, θ = 12.23°; at
A1 = 0 the overlap is 2 r - (1150 - 1050) = 57.77 mm. For D = 1250 the gap at A1 = 0 is
1250 - 1050 - 157.77 = 42.2 mm: no contact.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np
import pytest
from click.testing import CliRunner
from jsonschema import Draft202012Validator
from scipy.spatial.transform import Rotation

from app import main
from robot.cellscene import CellScene, Placement, RobotModels, pairs_in_reach
from robot.collision import parse_geometry
from robot.frames import frame_to_matrix
from robot.machine import load_machine
from robot.mada import load_robot
from robot.mjcf import ArmModel, build_mjcf, mjcf_assets
from interp.cellcontacts import _kept_cycles
from interp.robotcell import cell_runs, load_robot_cell, run_cell, summary_lines

R_WRIST = 85.38 * 0.901456 ** 0.7627          # mm, robot/capsules.py's documented rule
START = 'start: "{A1 90, A2 -90, A3 90, A4 0, A5 0, A6 0}"\n'
HOME = "PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}"
AWAY = "PTP {A1 90, A2 -90, A3 90, A4 0, A5 0, A6 0}"
# R1 turns to R2 (line 2), away (line 3), and to R2 again (line 4); R2 stands at HOME
R1 = f"DEF r1()\n  {HOME}\n  {AWAY}\n  {HOME}\nEND\n"
R2 = "DEF r2()\n  WAIT SEC 0.1\nEND\n"


def _theta(d: float) -> float:
    """A1 (deg) at which R1's wrist first touches R2's standing at X `d` (module docstring)."""
    far = d - 525.0
    return math.degrees(math.acos((525.0 ** 2 + far ** 2 - (2 * R_WRIST) ** 2) / (2 * 525.0 * far)))


def _cell(tmp_path, d: float, r2_inputs: str = "") -> object:
    (tmp_path / "r1.src").write_text(R1)
    (tmp_path / "r2.src").write_text(R2)
    (tmp_path / "r1.yaml").write_text(START)
    text = (f"robots:\n  R1: {{program: r1.src, inputs: r1.yaml}}\n"
            f"  R2: {{program: r2.src, base: [{d}, 0, 0, 180, 0, 0]{', inputs: r2.yaml' if r2_inputs else ''}}}\n")
    if r2_inputs:
        (tmp_path / "r2.yaml").write_text(r2_inputs)
    (tmp_path / "cell.yaml").write_text(text)
    return load_robot_cell(tmp_path / "cell.yaml")


def _run(cell, interp):
    with cell_runs(cell, interp, 30.0, mujoco=False) as runs:
        return run_cell(cell, runs)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_two_arms_turned_to_each_other_collide_once_per_episode(tmp_path, interp):
    res = _run(_cell(tmp_path, 1150), interp)
    assert res.reason == "completed"
    first, again = res.collisions                # R1 meets R2, leaves, meets it again: two episodes
    theta = _theta(1150)
    assert theta == pytest.approx(12.23, abs=0.01)
    for c, line in ((first, 2), (again, 4)):
        assert c.first[0] == "R1" and c.first[2].endswith(f"r1.src:{line}")
        assert c.second == ("R2", c.second[1], None)                      # R2 stands, its program ended
        assert {c.first[1], c.second[1]} <= {"link_4", "link_5", "link_6"}  # the wrists
        # the first cycle past θ: A1 falls at most one IPO cycle at its top speed (KR 6: 360°/s x 12 ms)
        assert theta - 360 * 0.012 <= c.axes["R1"][0] <= theta
        assert c.axes["R2"] == pytest.approx([0, -90, 90, 0, 0, 0])
        assert c.distance_mm < 0
    assert first.time < again.time
    lines = [line for line in summary_lines(res) if line.startswith("collision")]
    assert lines[0].startswith("collision  R1 link_") and "r1.src:2) touches R2 link_" in lines[0]
    assert "(at rest) at " in lines[0]
    out = res.as_json()
    assert json.loads(json.dumps(out)) == out
    assert [c["robots"][0]["motion"].endswith("r1.src:2") for c in out["collisions"]] == [True, False]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_two_robots_placed_apart_report_no_collision(tmp_path, interp):
    res = _run(_cell(tmp_path, 1250), interp)
    assert res.reason == "completed" and res.collisions == []
    # the same turns happened: R1 ended at HOME, 42 mm short of R2's wrist
    assert res.robots[0].runtime.controller.actual.axis_act()[0] == pytest.approx(0.0, abs=1e-6)
    assert 1250 - 1050 - 2 * R_WRIST == pytest.approx(42.2, abs=0.1)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_robot_touching_its_partners_cell_body_is_reported(tmp_path, interp):
    """R2's own cell file has a fence at X 700 of its world (X 500..600 of the cell's: R2 is turned
    at X 1250); R1's wrist reaches X 525 + 78.9 at A1 0, into it. R2 itself stays 46 mm short of its
    fence (its wrist ends at X 603.9 of its world, the fence begins at 650): its own run goes on."""
    fence = "geometry:\n  - {name: fence, box: [100, 100, 100], frame: [700, 0, 890, 0, 0, 0]}\nfloor: false\n"
    res = _run(_cell(tmp_path, 1250, fence), interp)
    assert res.reason == "completed"
    assert [(c.first[0], c.second[:2]) for c in res.collisions] == [("R1", ("R2", "cell:fence"))] * 2


def test_krl_run_prints_the_collision_and_writes_the_cells_json_result(tmp_path):
    """The command line: the summary's collision line and ``run.cell.json`` beside the robots'
    streams, valid against docs/schemas/cell-result.schema.json, with the episodes above."""
    _cell(tmp_path, 1150)
    trace = tmp_path / "run.jsonl"
    out = CliRunner().invoke(main, ["run", str(tmp_path / "cell.yaml"), "--trace", str(trace)])
    assert out.exit_code == 0, out.output
    lines = [line for line in out.output.splitlines() if line.startswith("collision  ")]
    assert len(lines) == 2 and "R1 link_" in lines[0] and "(r1.src:2) touches R2 link_" in lines[0]
    result = json.loads((tmp_path / "run.cell.json").read_text(encoding="utf-8"))
    schema = json.loads((Path(__file__).resolve().parents[2] / "docs/schemas/cell-result.schema.json").read_text())
    assert not list(Draft202012Validator(schema).iter_errors(result))
    assert [c["robots"][1]["robot"] for c in result["collisions"]] == ["R2", "R2"]
    assert [r["reason"] for r in result["robots"]] == ["completed", "completed"]
    assert _theta(1150) - 360 * 0.012 <= result["collisions"][0]["robots"][0]["axes"][0] <= _theta(1150)


def test_robots_out_of_each_others_reach_are_not_checked():
    """robot/cellscene.py ``_pairs_in_reach`` skips a pair only when it can never touch. The KR 6
    R900 reaches its wrist point 901.46 mm from A1's axis (../shared/docs/robot-model.md: 25 + 455
    + sqrt(420² + 35²)) and its flange 80 mm past it: two robots facing each other can bring their
    flanges together up to 2 x 981.46 mm apart, so the pair is kept there; 6 m apart they cannot
    meet and the scene's check of them is skipped (ContactWatch keeps no scene)."""
    machine = load_machine()
    near = CellScene([Placement("R1", machine), Placement("R2", machine, (2 * 981.46, 0, 0, 180, 0, 0))])
    far = CellScene([Placement("R1", machine), Placement("R2", machine, (6000, 0, 0, 180, 0, 0))])
    assert near.pairs == [(0, 1)] and far.pairs == []
    # the same from each robot's model alone (what a cell asks before it builds its scene)
    assert pairs_in_reach([Placement("R1", machine), Placement("R2", machine, (2 * 981.46, 0, 0, 180, 0, 0))]) == [(0, 1)]
    assert pairs_in_reach([Placement("R1", machine), Placement("R2", machine, (6000, 0, 0, 180, 0, 0))]) == []


def test_the_scene_copies_a_robots_axes_from_its_own_arm():
    """robot/cellscene.py ``follow``/``copy``: the scene takes a robot's joint values straight from
    its own MuJoCo arm (robot/mjcf.py ArmModel, what robot/readback.py reads its axes back from),
    and places it as ``set_axes`` of the axes read back does (the KR 6 R900 and a KR 16-2 on its
    KL 1500 track, an external linear axis: every joint's value the same, to rounding)."""
    rng = np.random.default_rng(89)
    for machine in (load_machine(), load_robot("kr16_2_kl1500")):
        arm = ArmModel(machine)
        a = CellScene([Placement("R1", machine), Placement("R2", machine, (1150, 0, 0, 180, 0, 0))])
        b = CellScene([Placement("R1", machine), Placement("R2", machine, (1150, 0, 0, 180, 0, 0))])
        index = a.follow("R2", arm)
        n = len(arm.axes_deg())
        for _ in range(20):
            q = rng.uniform(-90, 90, n)
            arm.set_axes(q)
            a.copy("R2", arm.data.qpos[index])
            b.set_axes("R2", arm.axes_deg())
            assert np.allclose(a.data.qpos, b.data.qpos, atol=1e-12)
        assert abs(a.data.qpos - b.data.qpos).max() < 1e-12 and np.any(a.data.qpos != 0)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_partners_cell_body_far_behind_it_is_in_its_reach(tmp_path, interp):
    """A robot's reach includes its own cell's bodies, measured from its base: R2 stands 3 m
    away on X (not turned) with a fence of its cell file 3 m behind it, at X 0, Z 890 of the cell,
    where R1's arm stands at HOME (its A3 at X 25, Z 855, the forearm on from there at Z 890:
    ../shared/docs/robot-model.md). The two robots' own arms cannot meet (1.96 m < 3 m), the
    fence and R1 touch from the first cycle. Before 2026-11-28 a world body's distance was
    measured from the cell's origin (0.89 m here, not 3.0 m), the pair counted out of reach and
    the contact never checked."""
    (tmp_path / "r1.src").write_text("DEF r1()\n  WAIT SEC 0.05\nEND\n")
    (tmp_path / "r2.src").write_text("DEF r2()\n  WAIT SEC 0.05\nEND\n")
    (tmp_path / "r2.yaml").write_text("geometry:\n  - {name: fence, box: [100, 100, 100], frame: [-3000, 0, 890, 0, 0, 0]}\n"
                                      "floor: false\n")
    (tmp_path / "cell.yaml").write_text("robots:\n  R1: {program: r1.src}\n"
                                        "  R2: {program: r2.src, base: [3000, 0, 0, 0, 0, 0], inputs: r2.yaml}\n")
    res = _run(load_robot_cell(tmp_path / "cell.yaml"), interp)
    assert res.reason == "completed"
    assert [(c.first[0], c.second[:2], c.time) for c in res.collisions] == [("R1", ("R2", "cell:fence"), pytest.approx(0.012))]


def _parsed_apart(placements: list) -> mujoco.MjModel:
    """The scene of `placements` built as before 2026-11-29: each robot's MJCF (robot/mjcf.py
    ``build_mjcf``, its cell's bodies and tool, no floor) parsed on its own, its keyframe deleted,
    its contact bits set (robot/cellscene.py's module docstring) and attached at its base."""
    spec = mujoco.MjSpec()
    everyone = (1 << len(placements)) - 1
    for k, p in enumerate(placements):
        geometry = replace(p.geometry, floor=None) if p.geometry is not None else None
        xml, assets = build_mjcf(p.machine, cell=geometry), mjcf_assets(p.machine, geometry)
        child = mujoco.MjSpec.from_string(xml, assets=assets) if assets else mujoco.MjSpec.from_string(xml)
        for key in list(child.keys):
            child.delete(key)
        for g in child.geoms:
            g.contype = 0 if g.name.startswith("cell:") else 1 << k
            g.conaffinity = everyone & ~(1 << k)
        spec.option.timestep, spec.option.integrator = child.option.timestep, child.option.integrator
        T = frame_to_matrix(*p.base)
        x, y, z, w = Rotation.from_matrix(T[:3, :3]).as_quat()
        spec.attach(child, prefix=f"{p.name}/", frame=spec.worldbody.add_frame(pos=T[:3, 3] / 1000.0, quat=[w, x, y, z]))
    return spec.compile()


def test_robots_of_one_model_share_its_parse_and_the_scene_is_the_same():
    """robot/cellscene.py RobotModels: the robots' MJCF built once for the reach test and the
    scene, one MuJoCo spec per distinct model attached as a copy for each robot of it. Four robots
    (two KR 6 R900, a KR 16-2 on its track, a KR 6 with a fence and a tool of its own cell): two
    parses for four robots, and the compiled scene equal, array by array, to the one built with
    each robot parsed on its own (before 2026-11-29), after the reach test compiled each distinct
    model alone; the reach test's pairs the scene's."""
    kr6, track = load_machine(), load_robot("kr16_2_kl1500")
    cell = parse_geometry([{"name": "fence", "box": [100, 2000, 1500], "frame": [-800, 0, 750, 0, 0, 0]}],
                          {"box": [40, 40, 120], "frame": [0, 0, 60, 0, 0, 0]}, None, None)
    placements = [Placement("R1", kr6), Placement("R2", track, (1800, 0, 0, 180, 0, 0)),
                  Placement("R3", kr6, (0, 1800, 0, -90, 0, 0)), Placement("R4", kr6, (1800, 1800, 0, 90, 0, 0), cell)]
    models = RobotModels(placements)
    assert models.specs[0] is models.specs[2] and len({id(s) for s in models.specs}) == 3
    # as interp/cellcontacts.py asks: the reach test (each distinct model compiled alone) first
    reach = pairs_in_reach(placements, models)
    scene, before = CellScene(placements, models), _parsed_apart(placements)
    arrays = [n for n in dir(before) if not n.startswith("_") and isinstance(getattr(before, n), np.ndarray)]
    assert len(arrays) > 100 and before.ngeom == scene.model.ngeom > 28
    assert [n for n in arrays if not np.array_equal(getattr(before, n), getattr(scene.model, n), equal_nan=True)] == []
    assert [scene.model.geom(g).name for g in range(before.ngeom)] == [before.geom(g).name for g in range(before.ngeom)]
    assert reach == scene.pairs == [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]


def test_the_kept_cycles_are_counted_from_the_marks_of_their_runs():
    # three cycles from 5, two caught up from 9, the last (10) kept again: the robot ended there
    # (interp/cellcontacts.py ContactWatch.keeper: a mark for each run of consecutive cycles)
    assert _kept_cycles([(0, 5), (3, 9), (5, 10)], 6).tolist() == [5, 6, 7, 9, 10, 10]
    # a turn that kept nothing leaves its mark with no cycle
    assert _kept_cycles([(0, 5), (2, 8), (2, 20)], 3).tolist() == [5, 6, 20]
    assert _kept_cycles([], 0).tolist() == []
