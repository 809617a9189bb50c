"""Collision against the cell (issue 64; robot/collision.py): the cell file's ``geometry:`` and
``tool:``, MuJoCo's contacts at every IPO cycle; a run stops at the colliding motion naming both
bodies, the line and the TCP. Hand-built cells: a LIN down through a box, a tool through a fixture,
A3 folded into the floor, each stopped at the right motion and where the geometry says (worked out
here from the sizes: the box's top, the tool's length, the flange's capsule radius); a free path
beside them runs to its end. Both interpreters.

The flange's capsule radius is robot/capsules.py's rule for the wrist, written out here from its
documented constants (docs/robot.md, "Collision and reach against the cell"): 85.38 mm times the
reach in metres to the power 0.7627; the KR 6 R900's reach to the wrist point by hand from its
machine data (robot-model.md §4: $LENGTH_A 25, $LENGTH_B 455, $TX3P3 X 420 and Z 35): 79 mm."""

from __future__ import annotations

import math
import struct

import pytest

from robot.collision import GeometryError, parse_geometry
from robot.stimuli import StimulusError, load_cell
from tests.interp.helpers import run_krl

TOOL_DOWN = "A 180, B 0, C 180"
PROG = f"""
DEF cellrun()
  PTP {{A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0}}
  LIN {{X 445, Y 250, Z 700, {TOOL_DOWN}}}
  LIN {{X 650, Y 250, Z 700, {TOOL_DOWN}}}
  LIN {{X 650, Y 250, Z 500, {TOOL_DOWN}}}
  LIN {{X 650, Y 0, Z 700, {TOOL_DOWN}}}
  LIN {{X 650, Y 0, Z 300, {TOOL_DOWN}}}
  $OUT[3] = TRUE
END
"""
#: the radius of the wrist's capsules (link_4..link_6: the flange's sphere) of the KR 6 R900, mm
R_WRIST = 85.38 * ((25 + 455 + math.hypot(420, 35)) / 1000.0) ** 0.7627
#: a box whose top is at Z 420 under the second half of the path (Y -150..150)
BOX = "  - {name: table, box: [300, 300, 40], frame: [650, 0, 400, 0, 0, 0]}\n"


def _error(run):
    return next(e for e in run.events if e["kind"] == "error")


def _crossing(run, t, level):
    """The TCP's Z at the stop (time t) is the first at or below `level`: the cycle before was above."""
    zs = [e["tcp"][2] for e in run.events if e["kind"] == "pose" and e["t"] <= t]
    return zs[-2] > level + 1e-6 and zs[-1] <= level + 1e-6


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_lin_through_a_box_stops_at_that_lin(tmp_path, interp):
    run = run_krl(tmp_path, PROG, stimuli="geometry:\n" + BOX, interp=interp)
    assert run.result.reason == "error", run.result
    err = _error(run)
    assert err["line"] == 7                       # the LIN down onto the table, not the one beside it
    # the wrist's capsule (link_5: wrist point to flange) or the flange's sphere (link_6) meets it
    assert "collision: " in err["text"] and "cell:table" in err["text"]
    assert "link_5" in err["text"] or "link_6" in err["text"], err["text"]
    assert "at the motion of line 7" in err["text"] and "TCP X 650.0, Y 0.0, Z " in err["text"]
    # the flange's sphere (R_WRIST around the flange) meets the top (Z 420): the TCP (the flange,
    # no $TOOL) stops at the first IPO cycle (2 m/s: 24 mm) at or below Z 420 + R_WRIST (499)
    assert _crossing(run, err["t"], 420 + R_WRIST)
    assert not run.io("$OUT[3]")


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_tool_through_a_fixture_is_stopped(tmp_path, interp):
    """The tool (a 200 mm box on the flange) meets the fixture where the flange alone would not."""
    cell = ("geometry:\n  - {name: fixture, cylinder: [30, 100], frame: [650, 250, 350, 0, 0, 0]}\n"
            "tool: {box: [40, 40, 200], frame: [0, 0, 100, 0, 0, 0]}\n")
    run = run_krl(tmp_path, PROG, stimuli=cell, interp=interp)
    err = _error(run)
    assert err["line"] == 5 and {"tool", "cell:fixture"} <= set(err["text"].split(" at ")[0].split()), err["text"]
    # the tool's end (200 mm below the flange) meets the cylinder's top (Z 400)
    assert _crossing(run, err["t"], 400 + 200)
    # without the tool the same path passes the fixture (the flange's sphere ends at Z 500 - R_WRIST,
    # 421, above 400)
    free = run_krl(tmp_path, PROG, stimuli=cell.split("tool:")[0], interp=interp)
    assert free.result.reason == "completed", free.result


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a3_into_the_floor_is_stopped(tmp_path, interp):
    """A3 folds the forearm down: with the upper arm near horizontal (A2 -10) it strikes the floor, Z 0."""
    src = """
DEF floor()
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  PTP {A1 0, A2 -10, A3 0, A4 0, A5 0, A6 0}
  PTP {A1 0, A2 -10, A3 150, A4 0, A5 0, A6 0}
  $OUT[3] = TRUE
END
"""
    for floor, z in (("true", 0.0), ("250", 250.0)):      # the floor at Z 0, or raised to Z 250
        run = run_krl(tmp_path, src, stimuli=f"floor: {floor}\n", interp=interp)
        err = _error(run)
        assert err["line"] == 4 and "floor" in err["text"], err
        # the forearm points down: its end, the flange's sphere (R_WRIST around the flange, the
        # TCP), is its lowest point, and meets the floor the cycle the TCP reaches it + R_WRIST
        assert _crossing(run, err["t"], z + R_WRIST)
        assert not run.io("$OUT[3]")


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_free_path_is_not_stopped(tmp_path, interp):
    cell = "geometry:\n" + BOX.replace("frame: [650, 0, 400", "frame: [650, 0, 100") + \
        "tool: {box: [40, 40, 100], frame: [0, 0, 50, 0, 0, 0]}\n"
    run = run_krl(tmp_path, PROG, stimuli=cell, interp=interp)
    assert run.result.reason == "completed", run.result
    assert run.io("$OUT[3]") and not [e for e in run.events if e["kind"] == "error"]


def test_geometry_errors_name_the_entry(tmp_path):
    with pytest.raises(GeometryError, match="geometry body 1: exactly one of box, cylinder, mesh"):
        parse_geometry([{"name": "a", "frame": [0] * 6}], None, None, tmp_path)
    with pytest.raises(GeometryError, match="box sizes must be above 0"):
        parse_geometry([{"box": [1, 0, 1]}], None, None, tmp_path)
    with pytest.raises(GeometryError, match="an .stl file of the cell file's folder"):
        (tmp_path.parent / "outside.stl").write_bytes(b"solid x\nendsolid x\n")
        parse_geometry([{"mesh": "../outside.stl"}], None, None, tmp_path)
    bad = tmp_path / "c.yaml"
    bad.write_text("tool: {box: [1, 2]}\n", encoding="utf-8")
    with pytest.raises(StimulusError, match=r"c.yaml:1.*'tool': box must be a list of 3 numbers"):
        load_cell(bad)


def test_a_mesh_body_collides(tmp_path):
    """A body given as an STL (a 200 mm cube written here, in mm) stops the LIN as the box does."""
    tris = []
    v = [(x, y, z) for x in (-100, 100) for y in (-100, 100) for z in (-100, 100)]
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),
             (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    for f in faces:
        tris.append(struct.pack("<12fH", 0, 0, 0, *v[f[0]], *v[f[1]], *v[f[2]], 0))
    (tmp_path / "cube.stl").write_bytes(b"\0" * 80 + struct.pack("<I", len(tris)) + b"".join(tris))
    run = run_krl(tmp_path, PROG, stimuli="geometry:\n  - {name: cube, mesh: cube.stl, frame: [650, 0, 320, 0, 0, 0]}\n")
    err = _error(run)
    assert err["line"] == 7 and "cell:cube" in err["text"]
    assert _crossing(run, err["t"], 420 + R_WRIST)
