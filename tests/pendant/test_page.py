"""The pendant page in a real Chromium on corpus backups (issue 36, "Done when"): select and
step in MSTEP with the pointer and the drawn robot following the trace, an input set by hand
releasing a WAIT FOR, a quit message acknowledged, a jog in T1, a backward step, the override's
effect on the motion time, and the run's trace equal to `krl run`'s.

Expected values come from the run's own trace (robot/trace.py, written by the controller) and from
`krl run`, not from the page: the page's numbers are read back from what it draws
(``window.pendant.renderedAxes()``: the joint angles of the three.js robot)."""

from __future__ import annotations

import json
import subprocess
import time

import pytest

from tests import forkserver
from tests.chromium import POLL_MS
from tests.conftest import REPO_ROOT
from tests.pendant.harness import (CELLS, KR120, MILLING, browser_page, cell_without, pendant_server, pose_at,
                                   read_trace, select, state, wait_drawn, wait_state)


PREPARE = "R1/Program/CELL/Other/PrepareMillingTools.src"
HOME = "R1/Program/CELL/Other/GoHomePos.src"
KR120_CELL = CELLS / "khrzysio__KRC4_test.yaml"
TOL_DEG = 0.01


#: the tests on the `kr120` page carry one xdist group: one worker makes the module's server and
#: page once (spread over three workers, each made its own: 5.3 s of wall each at load 7)
ON_KR120 = pytest.mark.xdist_group("pendant-kr120")


@pytest.fixture(scope="module")
def kr120(pw, shared_corpus, tmp_path_factory):
    """One server on the KR 120 backup (khrzysio__KRC4_test) with its cell, and one page."""
    trace = tmp_path_factory.mktemp("pendant") / "run.jsonl"
    with pendant_server(KR120, "--no-realtime", "--inputs", str(KR120_CELL), "--trace", str(trace)) as url, \
            browser_page(pw, url) as page:
        page.trace_path = trace
        yield page
        assert page.problems == []


def rendered(page) -> list[float]:
    return page.evaluate("() => window.pendant.renderedAxes()")


def start_to_step(page, n_before: int) -> dict:
    page.click("#start")
    return wait_state(page, f"s.state == 'stopped' && s.stop && s.stop.reason == 'step' && s.pointers.step > {n_before}")


def step_stops(page) -> list[dict]:
    return [e for e in read_trace(page.trace_path) if e["kind"] == "step_stop"]


def assert_drawn_as_traced(page, t: float) -> None:
    want = pose_at(read_trace(page.trace_path), t)
    page.wait_for_function(f"() => {{ const a = window.pendant.renderedAxes(); const w = {json.dumps(want)};"
                           f" return a && a.every((v, i) => Math.abs(v - w[i]) <= {TOL_DEG}); }}", polling=POLL_MS)
    got = rendered(page)
    assert all(abs(g - w) <= TOL_DEG for g, w in zip(got, want)), (got, want)


@ON_KR120
def test_mstep_pointer_and_pose_advance_and_step_backward(kr120):
    """Two MSTEP steps: the advance-run pointer and the drawn robot follow the trace; then a
    backward step returns the robot to the first step's point (one run: the backward step
    starts where the two steps stopped, as an operator's would). In T2, where backward motion
    is allowed as in T1 (docs/pendant.md): the two PTPs take 1.3 and 0.4 s of simulated time
    at the programmed speed, in T1 14.8 and 4 s at $RED_T1, each simulated with the backup's
    SPS.SUB and drawn at 30 Hz (T1's limits are the jog test's)."""
    page = kr120
    s0 = select(page, PREPARE, mode="T2")
    entry = (s0["pointers"]["advanceRun"]["path"], s0["pointers"]["advanceRun"]["line"])
    assert entry[0].endswith("PrepareMillingTools.src")
    # the program view shows the advance-run pointer on its line
    page.wait_for_selector(f'#program-view .ln.advance[data-line="{entry[1]}"]')
    previous, poses, stops = entry, [], []
    for _ in range(2):
        s = start_to_step(page, state(page)["pointers"]["step"])
        here = (s["pointers"]["advanceRun"]["path"], s["pointers"]["advanceRun"]["line"])
        assert here != previous, "the advance-run pointer did not move"
        stop = step_stops(page)[-1]
        assert stop["mode"] == "MSTEP" and abs(stop["t"] - s["time"]) < 0.0015
        assert_drawn_as_traced(page, stop["t"])
        page.wait_for_selector(f'#program-view .ln.advance[data-line="{here[1]}"]')
        poses.append(rendered(page))
        stops.append(stop)
        previous = here
    assert max(abs(a - b) for a, b in zip(*poses)) > 1.0, "the robot did not move between the two stops"
    first, second = stops
    at_first = pose_at(read_trace(page.trace_path), first["t"])
    assert max(abs(a - b) for a, b in zip(at_first, pose_at(read_trace(page.trace_path), second["t"]))) > 1.0
    page.click("#backward")
    page.wait_for_function(f"() => {{ const a = window.pendant.renderedAxes(); const w = {json.dumps(at_first)};"
                           f" return a && a.every((v, i) => Math.abs(v - w[i]) <= {TOL_DEG}); }}", polling=POLL_MS)
    # the drawing may reach the point before the backward step's stop is in the trace (under
    # load it was not yet, once: "no backward step"): the trace is read until it is, 60 s at most
    deadline = time.monotonic() + 60.0
    while not [e for e in step_stops(page) if e["mode"] == "BSTEP"] and time.monotonic() < deadline:
        time.sleep(0.1)
    back = [e for e in step_stops(page) if e["mode"] == "BSTEP"]
    assert back, "no backward step in the trace"
    assert all(abs(a - b) <= TOL_DEG for a, b in zip(pose_at(read_trace(page.trace_path), back[-1]["t"]), at_first))


@ON_KR120
def test_jog_an_axis_in_t1(kr120):
    page = kr120
    s = select(page, PREPARE, mode="T1")
    a1, others = s["position"]["axes"][0], s["position"]["axes"][1:]
    page.select_option("#jog-system", "AXIS")
    page.select_option("#jog-step", "10")
    page.click('[data-jog="A1+"]')
    s = wait_state(page, f"Math.abs(s.position.axes[0] - {a1 + 10}) < 1e-3")
    assert all(abs(a - b) < 1e-3 for a, b in zip(s["position"]["axes"][1:], others)), "only A1 moves"
    jogged = s["position"]["axes"]
    page.wait_for_function(f"() => Math.abs(window.pendant.renderedAxes()[0] - {a1 + 10}) <= {TOL_DEG}", polling=POLL_MS)
    # the jog is a motion of the controller, within T1's limits: it is in the trace
    jog = [e for e in read_trace(page.trace_path) if e["kind"] == "motion" and e["phase"] == "start"][-1]
    assert abs(jog["target"]["A1"] - (a1 + 10)) < 1e-6 and jog["limits"]["flange"] == 250.0
    # out of T1 the jog key is refused, as on the robot
    page.select_option("#mode-op", "AUT")
    wait_state(page, "s.modeOp == 'AUT'")
    page.click("#drives")
    wait_state(page, "s.drives")
    page.click('[data-jog="A1+"]')
    page.wait_for_function("() => document.getElementById('errorbar').textContent.includes('only in T1')", polling=POLL_MS)
    assert state(page)["position"]["axes"] == jogged


def motion_time(events: list[dict], motion_id: int = 1) -> float:
    t = {e["phase"]: e["t"] for e in events if e["kind"] == "motion" and e["id"] == motion_id}
    return t["end"] - t["start"]


@ON_KR120
def test_override_changes_the_motion_time(kr120):
    page = kr120
    times = {}
    for ov in (100, 40):
        select(page, PREPARE, mode="AUT")
        page.locator("#override").fill(str(ov))
        wait_state(page, f"s.override == {ov}")
        start_to_step(page, state(page)["pointers"]["step"])
        events = read_trace(page.trace_path)
        start = next(e for e in events if e["kind"] == "motion" and e["phase"] == "start")
        assert start["type"] == "PTP"
        times[ov] = motion_time(events, start["id"])
    # a PTP's time grows as the override lowers the axis speeds ($OV_PRO, robot/limits.py)
    assert times[40] > 1.5 * times[100], times


def test_quit_message_is_acknowledged(pw, shared_corpus, tmp_path):
    """ChinaMilling's PokeOutputs.src: MsgQuit("Output Value not initialized!") then HALT; the
    program waits in MsgLib's EXISTS_KRLMSG loop until the operator acknowledges."""
    trace = tmp_path / "run.jsonl"
    with pendant_server(MILLING, "--no-realtime", "--trace", str(trace)) as url, browser_page(pw, url) as page:
        select(page, "KRC/R1/System/PokeOutputs.src", run_mode="GO", mode="AUT")
        page.click("#start")
        s = wait_state(page, "s.messages && s.messages.some(m => m.kind == 'QUIT')")
        msg = next(m for m in s["messages"] if m["kind"] == "QUIT")
        assert msg["text"] == "Output Value not initialized!"
        li = page.locator(f'#messages li[data-handle="{msg["handle"]}"]')
        assert li.locator(".text").inner_text() == "Output Value not initialized!"
        # the program still waits for the acknowledgement while simulated time goes on
        t_shown = s["time"]
        s = wait_state(page, f"s.time > {t_shown + 1.0}")
        assert s["state"] == "running" and any(m["handle"] == msg["handle"] for m in s["messages"])
        li.locator("[data-ack]").click()
        s = wait_state(page, "s.state == 'ended' || (s.state == 'stopped' && s.stop && s.stop.reason == 'pause')")
        assert not any(m["handle"] == msg["handle"] for m in s["messages"])
        assert page.problems == []
    end = [e for e in read_trace(trace) if e["kind"] == "end"]
    assert end and end[-1]["reason"] == "halt" and end[-1]["t"] > t_shown + 1.0


def test_input_by_hand_releases_wait_for(pw, shared_corpus, tmp_path):
    """PrepareMillingTools waits at Spindle.src:140 (WAIT FOR inHsdToolReleased, $IN[8]) after
    opening the tool release; the cell without its answer leaves the input to the operator."""
    cell = cell_without(KR120_CELL, "inHsdToolReleased", tmp_path / "cell.yaml")
    trace = tmp_path / "run.jsonl"
    with pendant_server(KR120, "--no-realtime", "--inputs", str(cell), "--trace", str(trace)) as url, \
            browser_page(pw, url) as page:
        select(page, PREPARE, run_mode="GO", mode="AUT")
        page.click("#start")
        s = wait_state(page, "s.pointers.advanceRun && s.pointers.advanceRun.path.endsWith('Spindle.src')"
                             " && s.pointers.advanceRun.line == 140")
        t_wait = s["time"]
        s = wait_state(page, f"s.time > {t_wait + 2.0}")
        assert s["pointers"]["advanceRun"]["line"] == 140 and s["state"] == "running"
        # while it waits the pose still comes at 30 Hz, unchanged: no frame is drawn for it (the
        # page draws when a joint moved or the path grew, pendant/web/src/main.js)
        frames, t_live = page.evaluate("() => [window.pendant.frames, window.pendant.live.time]")
        s = wait_state(page, f"s.time > {s['time'] + 1.0} && window.pendant.live.time > {t_live + 1.0}")
        assert s["pointers"]["advanceRun"]["line"] == 140
        assert page.evaluate("() => window.pendant.frames") == frames
        page.click('#tabs button[data-tab="io"]')
        row = page.locator('#inputs tr[data-io="$IN[8]"]')
        assert "inHsdToolReleased" in row.inner_text()
        row.locator("[data-input]").click()
        s = wait_state(page, "!(s.pointers.advanceRun && s.pointers.advanceRun.path.endsWith('Spindle.src')"
                             " && s.pointers.advanceRun.line == 140)")
        assert page.problems == []
    ev = [e for e in read_trace(trace) if e["kind"] == "io" and e["signal"] == "$IN[8]"]
    assert ev and ev[0]["value"] is True and ev[0]["source"] == "operator" and ev[0]["t"] > t_wait + 2.0


@pytest.fixture(scope="module")
def krl_run_trace(shared_corpus, tmp_path_factory) -> str:
    """The trace `krl run` writes for the pendant's run below (the same program, cell and
    mode), made once for both pacings."""
    ref = tmp_path_factory.mktemp("krl-run") / "run.jsonl"
    # a fork of the worker's fork server, as the pendant servers are (tests/forkserver.py: the
    # command's start without the import of the project)
    run = subprocess.run([*forkserver.krl_command(), "run", str(KR120 / HOME), "--inputs", str(KR120_CELL),
                          "--mode", "AUT", "--trace", str(ref)], cwd=REPO_ROOT, capture_output=True, text=True,
                         timeout=900, check=False)
    assert run.returncode == 0, run.stdout + run.stderr
    assert read_trace(ref)[-1]["kind"] == "end" and read_trace(ref)[-1]["reason"] == "completed"
    return ref.read_text()


@pytest.mark.parametrize("pacing", [pytest.param("unpaced", marks=ON_KR120), "paced"])
def test_the_pendant_run_gives_krl_runs_trace(pw, shared_corpus, request, tmp_path, pacing, krl_run_trace):
    """The same program, cell and modes: the trace of the run under the pendant (GO, AUT, run to
    its end from the page) is byte for byte the trace of `krl run`; unpaced on the module's page
    (its server: the same backup and cell, --no-realtime; the modes chosen on the page), and
    paced at real time (5.3 s simulated) by a server started in AUT, where the page's state
    requests end the pacing waits early and are served at the engine's next hook
    (pendant/engine.py)."""
    if pacing == "unpaced":
        page = request.getfixturevalue("kr120")
        run_to_its_end(page, HOME)
        page.click("#cancel")                  # the run's trace is closed with it (else at the server's end)
        wait_state(page, "s.state == 'none'")
        trace = page.trace_path
    else:
        trace = tmp_path / "pendant.jsonl"
        with pendant_server(KR120, "--inputs", str(KR120_CELL), "--trace", str(trace), "--mode", "AUT") as url, \
                browser_page(pw, url) as page:
            run_to_its_end(page, HOME)
    assert trace.read_text() == krl_run_trace


def run_to_its_end(page, program: str) -> None:
    """Select ``program`` (GO, AUT) and start it; back when the run has ended."""
    select(page, program, run_mode="GO", mode="AUT")
    page.click("#start")
    wait_state(page, "s.state == 'ended' || s.state == 'none'", timeout=900_000)
    assert page.problems == []


@ON_KR120
def test_breakpoint_from_the_program_view(kr120):
    """A breakpoint set by clicking a line number stops the run there (GO), as the engine's
    breakpoints do for `krl debug`."""
    page = kr120
    select(page, PREPARE, run_mode="GO", mode="T1")
    page.locator('#program-view .ln[data-line="20"] .no').click()
    page.wait_for_selector('#program-view .ln.bp[data-line="20"]')
    page.click("#start")
    s = wait_state(page, "s.state == 'stopped' && s.stop && s.stop.reason == 'breakpoint'")
    assert s["pointers"]["advanceRun"]["path"].endswith("PrepareMillingTools.src")
    assert s["pointers"]["advanceRun"]["line"] == 20
    page.locator('#program-view .ln[data-line="20"] .no').click()       # and off again
    page.wait_for_selector('#program-view .ln.bp', state="detached")


@ON_KR120
def test_software_webgl_draws_without_multisampling(kr120):
    """Chromium without a GPU (``--disable-gpu``: the suite's flags, pendant/client.py) draws WebGL
    with SwiftShader; the page asks that context for no multisampling (docs/pendant.md, "The 3D
    view without a GPU"), and the context it got has none."""
    gl = kr120.evaluate("() => window.pendant.gl")
    assert "SwiftShader" in gl["renderer"], gl
    assert gl["software"] is True and gl["antialias"] is False, gl
    # the page draws with that context: a frame asked for is drawn
    wait_drawn(kr120)
