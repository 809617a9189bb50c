"""The pendant tells why (issue 46), in a real Chromium: a run-time error's number, text, module
and line in the message window, kept across a reload and shown in a second browser; "ended" not
drawn in the colour of an error; the robot and the position panel before a program is selected;
the programs list after a reload; jogging in T2; long program lines.

Expected values are derived from the fixtures' own text (the line that fails, KSS message 1422
"value invalid" of krl-reference §10.2), from the robot's documented machine data
(shared/robots/kr6_r900.yaml: $AXIS_HOME and the flange pose there) and, for the corpus backup,
from the program's files as tests/interp/test_realprograms.py reads them (ChinaMilling's
BlockCalibration stops at Get3Basepoints.src:21)."""

from __future__ import annotations

import json

import pytest
import yaml

from tests.chromium import POLL_MS
from tests.conftest import REPO_ROOT
from tests.pendant.harness import CELLS, MILLING, browser_page, pendant_server, select, state, wait_state


# the module's tests share its pendant server (a module fixture) and three of them a page of it:
# one xdist group, so that one worker starts them once (spread over the three workers, each
# started its own)
pytestmark = [pytest.mark.xdist_group("pendant-why")]

ERROR_PROGRAM = """DEF err1422()
  DECL INT n
  $OUT[5] = TRUE
  n = n + 1
END
"""
ERROR_LINE = 4                # n = n + 1: n was never assigned
LONG_TAIL = "the end of a long line"
LONG_PROGRAM = ("DEF longline()\n  ; " + "x" * 260 + " " + LONG_TAIL + "\n  $OUT[6] = TRUE\nEND\n")
ERR_COLOUR = "rgb(255, 77, 77)"        # pendant.css --err


def machine_data() -> dict:
    """The KR 6 R900's documented data (the project's robot for a folder without a backup)."""
    shared = REPO_ROOT.parent / "shared" / "robots" / "kr6_r900.yaml"
    path = shared if shared.is_file() else REPO_ROOT / "robot" / "data" / "kr6_r900.yaml"
    return yaml.safe_load(path.read_text())


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    root = tmp_path_factory.mktemp("why")
    (root / "err1422.src").write_text(ERROR_PROGRAM)
    (root / "longline.src").write_text(LONG_PROGRAM)
    return root


@pytest.fixture(scope="module")
def server(pw, workspace):
    with pendant_server(workspace, "--no-realtime", "--mode", "AUT") as url:
        yield url


@pytest.fixture(scope="module")
def module_page(server, pw):
    """One page of the module's server for the tests that need neither a fresh page nor a
    reload (a page load is about 0.8 s of Chromium's CPU, a cgroup, 2026-11-29)."""
    with browser_page(pw, server) as page:
        yield page


@pytest.fixture
def shared_page(module_page):
    """:func:`module_page` with nothing selected (whatever a test before left) and no problem
    of a test before counted."""
    module_page.click("#cancel")
    wait_state(module_page, "s.state == 'none'")
    module_page.problems.clear()
    return module_page


def message_rows(page) -> list[dict]:
    return page.evaluate("""() => [...document.querySelectorAll('#messages li')].map((li) => ({
        kind: li.dataset.kind, handle: li.dataset.handle,
        type: li.querySelector('.kind').textContent, number: li.querySelector('.number').textContent,
        text: li.querySelector('.text').textContent, src: li.querySelector('.src').textContent,
        origin: li.querySelector('.origin').textContent, time: li.querySelector('.time').textContent}))""")


def wait_message(page, text_part: str) -> dict:
    page.wait_for_function("(t) => [...document.querySelectorAll('#messages li .text')].some((e) => "
                           "e.textContent.includes(t))", arg=text_part, polling=POLL_MS)
    return next(r for r in message_rows(page) if text_part in r["text"])


def badge_colour(page) -> str:
    return page.evaluate("() => getComputedStyle(document.getElementById('st-state')).backgroundColor")


def test_before_selection_the_robot_stands_at_its_start(server, pw):
    """A fresh page, nothing selected: the robot drawn at $AXIS_HOME, the position panel with
    those axes and $POS_ACT there; the same pose the run has at its first statement."""
    md = machine_data()
    home, flange = md["home_deg"], md["home_flange_pose_mm_deg"]
    with browser_page(pw, server) as page:
        page.click("#cancel")                      # whatever another test left selected
        s = wait_state(page, "s.state == 'none' && s.position")
        assert s["position"]["axes"] == pytest.approx(home, abs=1e-6)
        pos = s["position"]["pos"]
        assert [pos[k] for k in "XYZ"] == pytest.approx(flange[:3], abs=0.01)
        assert pos["B"] == pytest.approx(flange[4], abs=0.01)
        page.wait_for_function(f"() => {{ const a = window.pendant.renderedAxes(); const w = {json.dumps(home)};"
                               f" return a && a.every((v, i) => Math.abs(v - w[i]) <= 0.01); }}", polling=POLL_MS)
        panel = page.evaluate("() => [1,2,3,4,5,6].map((i) => document.querySelector(`#position [data-axis='${i}']`)"
                              ".textContent)")
        assert [float(v) for v in panel] == pytest.approx(home, abs=1e-3)
        x = page.evaluate("() => document.querySelector(\"#position [data-pos='X']\").textContent")
        assert float(x) == pytest.approx(flange[0], abs=0.01)
        # the run itself starts there ($TOOL and $BASE null: the program does not set them)
        s = select(page, "longline.src", run_mode="GO", mode="AUT")
        assert s["position"]["axes"] == pytest.approx(home, abs=1e-6)
        assert {k: s["position"]["pos"][k] for k in "XYZABC"} == pytest.approx({k: pos[k] for k in "XYZABC"}, abs=1e-3)
        page.click("#cancel")
        assert page.problems == []


def test_a_run_time_error_is_in_the_message_window_and_stays(server, pw):
    """err1422.src reads n before it is assigned (line 4): KSS 1422 "value invalid". The message
    window shows its type, number, text, module and line; the status line too; a reload and a
    second browser show the same message; OK acknowledges it on both."""
    with browser_page(pw, server) as page:
        select(page, "err1422.src", run_mode="GO", mode="AUT")
        page.click("#start")
        s = wait_state(page, "s.state == 'stopped' && s.stop && s.stop.reason == 'exception'")
        assert (s["stop"]["number"], s["stop"]["line"], s["stop"]["module"]) == (1422, ERROR_LINE, "err1422.src")
        row = wait_message(page, "value invalid")
        assert (row["kind"], row["type"], row["number"], row["origin"]) == ("QUIT", "acknowledgement", "1422", "KSS")
        assert row["src"] == f"err1422.src line {ERROR_LINE}"
        badge = page.locator("#st-state").inner_text()
        assert "1422" in badge and "value invalid" in badge and f"err1422.src line {ERROR_LINE}" in badge
        page.reload()
        page.wait_for_function("() => window.pendant && window.pendant.robot", polling=POLL_MS)
        again = wait_message(page, "value invalid")
        assert again == row
        with browser_page(pw, server) as other:
            assert wait_message(other, "value invalid") == row
            # Start again: the error ends the run; the message is shown once, "ended" is not red
            page.click("#start")
            s = wait_state(page, "s.state == 'ended'")
            assert s["outcome"]["reason"] == "error" and s["outcome"]["line"] == ERROR_LINE
            assert [r["handle"] for r in message_rows(page) if "value invalid" in r["text"]] == [row["handle"]]
            assert badge_colour(page) != ERR_COLOUR
            page.locator(f'#messages li[data-handle="{row["handle"]}"] [data-ack]').click()
            for p in (page, other):
                p.wait_for_function("() => !document.querySelector('#messages li')", polling=POLL_MS)
            assert other.problems == []
        assert page.problems == []


def test_ended_is_not_drawn_as_an_error(shared_page):
    page = shared_page
    select(page, "longline.src", run_mode="GO", mode="AUT")
    page.click("#start")
    s = wait_state(page, "s.state == 'ended'")
    assert s["outcome"]["reason"] == "completed"
    assert page.locator("#st-state").inner_text() == "ended"
    assert badge_colour(page) != ERR_COLOUR
    # after the end the mode switch is free again; Reset starts the program in the new mode
    page.select_option("#mode-op", "T1")
    wait_state(page, "s.state == 'ended' && s.modeOp == 'T1'")
    page.click("#reset")
    s = wait_state(page, "s.state == 'stopped' && s.stop && s.stop.reason == 'entry'")
    assert s["modeOp"] == "T1"
    page.click("#cancel")
    assert page.problems == []


def test_the_programs_list_shows_the_selected_program_after_a_reload(server, pw):
    """longline.src sorts after err1422.src: after a reload (and in a second browser) the list
    shows the selected program, not the list's first."""
    with browser_page(pw, server) as page:
        page.click("#cancel")
        wait_state(page, "s.state == 'none'")
        page.reload()
        page.wait_for_function("() => window.pendant && window.pendant.robot", polling=POLL_MS)
        wait_state(page, "s.state == 'none'")
        assert page.evaluate("() => document.querySelector('#programs').value") == "err1422.src"
        select(page, "longline.src", run_mode="GO", mode="AUT")
        page.reload()
        page.wait_for_function("() => window.pendant && window.pendant.robot", polling=POLL_MS)
        wait_state(page, "s.programLabel == 'longline.src'")
        page.wait_for_function("() => document.querySelector('#programs').value == 'longline.src'", polling=POLL_MS)
        with browser_page(pw, server) as other:
            other.wait_for_function("() => document.querySelector('#programs').value == 'longline.src'", polling=POLL_MS)
        page.click("#cancel")
        assert page.problems == []


def test_jogging_in_t2_says_jog_only_in_t1(shared_page):
    page = shared_page
    select(page, "longline.src", run_mode="GO", mode="T1")
    page.select_option("#mode-op", "T2")
    s = wait_state(page, "s.modeOp == 'T2'")
    assert not s["drives"]                     # the mode switch switched them off
    axes = s["position"]["axes"]
    for drives in (False, True):
        if drives:
            page.click("#drives")
            wait_state(page, "s.drives")
        page.evaluate("() => { document.getElementById('errorbar').textContent = ''; }")
        page.click('[data-jog="A1+"]')
        page.wait_for_function("() => document.getElementById('errorbar').textContent != ''", polling=POLL_MS)
        bar = page.locator("#errorbar").inner_text()
        assert "only in T1" in bar and "drives" not in bar, bar
    assert state(page)["position"]["axes"] == axes
    page.click("#cancel")
    assert page.problems == []


def test_long_lines_are_shown_whole(shared_page):
    """A line longer than the program panel wraps inside it: nothing of it is cut off or hidden
    behind a horizontal scroll."""
    page = shared_page
    select(page, "longline.src", run_mode="GO", mode="AUT")
    line = page.locator('#program-view .ln[data-line="2"] .tx')
    assert line.inner_text().endswith(LONG_TAIL)
    box = page.evaluate("""() => {
        const v = document.getElementById('program-view');
        const t = document.querySelector('#program-view .ln[data-line="2"] .tx');
        const vr = v.getBoundingClientRect(), tr = t.getBoundingClientRect();
        return {viewRight: vr.right, textRight: tr.right, scroll: v.scrollWidth, client: v.clientWidth,
                lineHeight: document.querySelector('#program-view .ln[data-line="3"]').getBoundingClientRect().height,
                textHeight: tr.height};
    }""")
    assert box["textRight"] <= box["viewRight"] + 0.5 and box["scroll"] <= box["client"], box
    assert box["textHeight"] > 2 * box["lineHeight"], "the long line did not wrap"
    page.click("#cancel")
    assert page.problems == []


def test_a_corpus_programs_run_time_error_in_the_message_window(pw, shared_corpus):
    """HugoDanielson__ChinaMilling's BlockCalibration.src with its cell: Get3Basepoints.src:21's
    LIN leaves the KR 210 R2700-2's software limits (tests/interp/test_realprograms.py): the
    message window shows the text, the module and the line, and keeps them after a reload."""
    prog = "KRC/R1/Program/KukaMiling/Subprogs/BaseCalib/BlockCalibration.src"
    with pendant_server(MILLING, "--no-realtime", "--inputs", str(CELLS / "HugoDanielson__ChinaMilling.yaml")) as url, \
            browser_page(pw, url) as page:
        select(page, prog, run_mode="GO", mode="AUT")
        page.click("#start")
        wait_state(page, "s.state == 'stopped' && s.stop && s.stop.reason == 'exception'")
        row = wait_message(page, "software limit switch -A5")
        assert row["src"] == "Get3Basepoints.src line 21" and row["kind"] == "QUIT"
        page.reload()
        page.wait_for_function("() => window.pendant && window.pendant.robot", polling=POLL_MS)
        assert wait_message(page, "software limit switch -A5") == row
        assert page.problems == []
