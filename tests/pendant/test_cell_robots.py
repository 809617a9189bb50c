"""The pendant on a cell of several robots (issue 89, "A web page test in a real browser shows both
robots moving in the pendant's 3D view"; pendant/cell.py): `krl pendant CELL.yaml` in Chromium
(Playwright) draws both robots, each at its base; the robot chooser switches the program view to
the other robot's program and the single robot's keys to it (its mode, its drives, a jog key moves
it alone); after Start both robots' drawn joints follow their programs over time, and each robot's
TCP path is drawn at its base.

Expected values by hand from the programs: R1 turns A1 from 0 to 60 deg and back, R2 (turned 180
deg at X 2000, apart from R1) turns A1 from 0 to -60 and A2 to -60; both start at $AXIS_HOME (A1 0,
A2 -90); R2's A1 jogged by the page's A1+ key at its default step (1 deg) stands at 1. The drawn
values are read back from the three.js robots (``renderedAxesOf``). R1's A1 turns at 10 %
``$VEL_AXIS`` (60 deg in about 1.8 s instead of 0.4; R2, in T1, turns at ``$RED_T1``'s 7 %): the
page must catch both robots mid-motion in one of its frames, and with R1 at full speed a machine
at load 18 drew none in that window (the wait timed out, 2026-11-29)."""

from __future__ import annotations

import math

import pytest

from tests.chromium import POLL_MS
from tests.pendant.harness import browser_page, pendant_server, wait_state

pytestmark = pytest.mark.may_skip("chromium is missing and cannot be installed (not root, or apt-get has no network)")

R1 = """DEF r1()
  $VEL_AXIS[1]=10
  PTP {A1 60, A2 -90, A3 90, A4 0, A5 0, A6 0}
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
END
"""
R2 = """DEF r2()
  PTP {A1 -60, A2 -60, A3 90, A4 0, A5 0, A6 0}
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
END
"""
#: the KR 6 R900's flange at HOME in its $WORLD (../shared/docs/robot-model.md §9's test vector: X 525,
#: Z 890; §4.4: the wrist point at X 445, the flange 80 mm past it); the page's TCP path takes a point
#: each 2 mm (pendant/engine.py PATH_STEP_MM), so its last lies within 2 mm of where a motion ends
FLANGE_X, FLANGE_Z = 525.0, 890.0
STEP = 2.0
CELL = """robots:
  R1: {program: r1.src}
  R2: {program: r2.src, base: [2000, 0, 0, 180, 0, 0]}
"""


def test_both_robots_of_a_cell_move_in_the_3d_view(pw, tmp_path):
    (tmp_path / "r1.src").write_text(R1, encoding="ascii")
    (tmp_path / "r2.src").write_text(R2, encoding="ascii")
    (tmp_path / "cell.yaml").write_text(CELL, encoding="ascii")
    with pendant_server(tmp_path / "cell.yaml") as url, browser_page(pw, url) as page:
        assert page.evaluate("() => Object.keys(window.pendant.cellRobots)") == ["R1", "R2"]
        # both drawn at HOME before the start; R2's root at X 2 m of the cell's world, turned 180 deg
        for name in ("R1", "R2"):
            assert page.evaluate(f"() => window.pendant.renderedAxesOf('{name}')")[:2] == pytest.approx([0, -90])
        root = page.evaluate("() => { const r = window.pendant.cellRobots.R2.robot; r.updateMatrixWorld(true);"
                             " const e = r.matrixWorld.elements; return [e[12], e[13], e[14], e[0]]; }")
        # three's world is KUKA's $WORLD turned -90 deg about X: X stays X, Z is three's Y
        assert root[0] == pytest.approx(2.0) and root[3] == pytest.approx(-1.0)
        # the chooser: R2's program in the program view, the keys act on R2 (T1, its drives, a jog)
        wait_state(page, "s.state == 'stopped' && s.stop.reason == 'entry'")
        page.select_option("#cell-robot", "R2")
        page.wait_for_function("() => window.pendant.module && window.pendant.module.path.endsWith('r2.src')", polling=POLL_MS)
        wait_state(page, "s.cell && s.cell.chosen == 'R2'")
        page.select_option("#mode-op", "T1")
        wait_state(page, "s.modeOp == 'T1'")
        page.click("#drives")
        wait_state(page, "s.drives")
        page.click('#jog-keys button[data-jog="A1+"]')
        s = wait_state(page, "Math.abs(s.position.axes[0] - 1) < 1e-6")
        page.wait_for_function("() => Math.abs(window.pendant.renderedAxesOf('R2')[0] - 1) < 1e-3", polling=POLL_MS)
        assert page.evaluate("() => window.pendant.renderedAxesOf('R1')")[:2] == pytest.approx([0, -90])
        page.select_option("#cell-robot", "R1")             # R1's drives too: Start moves every robot
        wait_state(page, "s.cell.chosen == 'R1' && s.modeOp == 'AUT' && !s.drives")
        page.click("#drives")
        wait_state(page, "s.drives")
        page.click("#start")
        # the robots move together (paced to the wall clock): both leave HOME on their own axes
        # both poses read in the one evaluation that sees them leave HOME: read after it, a loaded
        # machine had drawn R1 on its way back (A1 6.7, make test with four workers, 2026-11-28)
        mid = page.wait_for_function("() => { const p = window.pendant; const a = p.renderedAxesOf('R1'), "
                                     "b = p.renderedAxesOf('R2'); "
                                     "return a[0] > 10 && b[0] < -10 && b[1] > -85 ? [a, b] : null; }").json_value()
        assert 10 < mid[0][0] <= 60 + 1e-6 and mid[0][1] == pytest.approx(-90)      # R1 turns A1 alone
        assert -60 - 1e-6 <= mid[1][0] < -10 and -90 < mid[1][1] <= -60 + 1e-6     # R2 turns A1 and A2
        s = wait_state(page, "s.state == 'ended'")
        assert s["outcome"]["reason"] == "completed"
        for name in ("R1", "R2"):            # both back at HOME, drawn there
            page.wait_for_function(f"() => Math.abs(window.pendant.renderedAxesOf('{name}')[0]) < 1e-3", polling=POLL_MS)
        # each robot's TCP path drawn at its base (the page's points in the cell's world, mm): a point
        # each IPO cycle at least while A1 turns 60 deg and back at most at its 360 deg/s (2 x 14 cycles)
        page.wait_for_function("() => { const p = window.pendant.cellPathOf; const a = p && p('R1'), "
                               "b = p && p('R2'); return a && b && a.length >= 28 && b.length >= 28 && "
                               "Math.abs(a[a.length - 1][1]) <= 2 && Math.abs(b[b.length - 1][1]) <= 2; }", polling=POLL_MS)
        r1, r2 = (page.evaluate(f"() => window.pendant.cellPathOf('{n}')") for n in ("R1", "R2"))
        # R1 turns A1 alone: its TCP stays on the circle of radius 525 mm about its A1 axis at Z 890
        assert all(abs((x * x + y * y) ** 0.5 - FLANGE_X) < 0.5 and abs(z - FLANGE_Z) < 0.5 for x, y, z in r1)
        # at A1 60 deg: KUKA's A1 turns clockwise seen from above (robot-model.md §4.3: $AXIS_DIR's
        # d1 = -1; §9's A1 30 gives Y -299), so its Y reaches -525 sin 60 deg
        assert min(y for _, y, _ in r1) == pytest.approx(-FLANGE_X * 3 ** 0.5 / 2, abs=STEP)
        # R2 starts at HOME (its path begins with the jog of A1 by 1 deg: within 525 x 1 deg = 9.2 mm
        # of it) and ends there, its flange facing R1: X 2000 - 525 of the cell's world
        home2 = (2000 - FLANGE_X, 0.0, FLANGE_Z)
        assert math.dist(r2[0], home2) <= FLANGE_X * math.radians(1) + 0.1
        assert math.dist(r2[-1], home2) <= STEP and math.dist(r1[-1], (FLANGE_X, 0.0, FLANGE_Z)) <= STEP
        assert min(x for x, _, _ in r2) > 1000 and max(x for x, _, _ in r1) < 1000
        assert page.problems == []
