"""Test harness of the pendant: `krl pendant` started as the user starts it (a subprocess, its
first line the URL with the token), and the page in Debian's Chromium driven by Playwright
(PyPI playwright given /usr/bin/chromium as its executable, with pendant/client.py's flags).

Waits are conditions on the page's state (``window.pendant``), with generous time limits for a
loaded machine; no assertion depends on how long anything took.
"""

from __future__ import annotations

import json
from contextlib import contextmanager
from pathlib import Path

import yaml

from pendant import client
from tests import forkserver
from tests.chromium import POLL_MS, shared_browser
from tests.conftest import REPO_ROOT, SHARED_CORPUS

KR120 = SHARED_CORPUS / "khrzysio__KRC4_test"
PALLETIZER = SHARED_CORPUS / "ingeniado__KRC4-Robot-Palletizer"
MILLING = SHARED_CORPUS / "HugoDanielson__ChinaMilling"
CELLS = REPO_ROOT / "corpus" / "cells"
WAIT_MS = 300_000         # a selection loads and checks a whole backup: minutes on a loaded machine


@contextmanager
def pendant_server(target: Path, *args: str, stderr: Path | None = None):
    """`krl pendant TARGET --no-browser ARGS...` (pendant/client.py), a fork of the worker's
    fork server (tests/forkserver.py: the import of the project, 1.5 s of CPU, made once): yields
    the URL it printed first; its stderr is shown on failure (and kept in the file `stderr`
    when given)."""
    with client.pendant_server(target, *args, root=REPO_ROOT, stderr=stderr,
                               python=str(forkserver.shared().launcher)) as (_proc, url):
        yield url


@contextmanager
def browser_page(pw, url: str, viewport=(1400, 900), scale: float = 0.25):
    """A page in a fresh browser context (no cookie, storage or cache of another page) with the
    page loaded and its robot drawn; page errors are collected in ``page.problems``.
    ``scale``: the device pixel ratio. The 3D view is software-rendered WebGL (no GPU): at 0.25
    its canvas has a sixteenth of the pixels, with the same CSS layout and scene (the tests read
    the scene, ``renderedAxes``, the state and the trace; 33.7 -> 20.0 s of Chromium's CPU for
    test_page's two MSTEP runs at 0.5 instead of 1, 2026-11-26; a frame of the KR 6 R900's page
    20.1/15.1 -> 12.3 ms of Chromium's CPU at 0.25 instead of 0.5, a cgroup; test_page's
    WAIT FOR and unpaced-trace tests 12.0 -> 9.5 s, medians of three beside 0.5, 2026-11-29); the
    tests that compare pixels (test_screenshots, test_cell_view) draw at 1."""
    # bypass_csp: Playwright's wait_for_function evaluates its predicate, which the page's
    # Content-Security-Policy (script-src 'self') forbids; the page itself runs under it
    ctx = shared_browser(pw).new_context(bypass_csp=True, viewport={"width": viewport[0], "height": viewport[1]},
                                   device_scale_factor=scale)
    # every Playwright wait and action (a click waits for its element) gets the loaded
    # machine's time limit, not Playwright's 30 s
    ctx.set_default_timeout(WAIT_MS)
    try:
        page = ctx.new_page()
        page.problems = []
        page.on("pageerror", lambda e: page.problems.append(f"page error: {e}"))
        page.on("console", lambda m: page.problems.append(f"console: {m.text}") if m.type == "error" else None)
        page.goto(url)
        page.wait_for_function("() => window.pendant && window.pendant.robot", timeout=WAIT_MS, polling=POLL_MS)
        yield page
    finally:
        ctx.close()


def state(page) -> dict:
    return page.evaluate("() => window.pendant.state")


def wait_state(page, predicate_js: str, timeout: int = WAIT_MS) -> dict:
    """Wait until ``predicate_js`` (a JS expression over ``s``, the page's state) holds (a state that
    lasts: it is looked at every :data:`tests.chromium.POLL_MS`)."""
    page.wait_for_function(f"() => {{ const s = window.pendant.state; return !!s && ({predicate_js}); }}",
                           timeout=timeout, polling=POLL_MS)
    return state(page)


def act(page, op: str, **args) -> None:
    """Send an operator action through the page's own connection and wait for its answer (a
    refusal raises)."""
    page.evaluate("([op, args]) => window.pendant.send(op, args)", [op, args])


def select(page, program: str, *, run_mode: str = "MSTEP", mode: str = "T1") -> dict:
    """Choose the modes and select ``program`` with the page's own controls; the state at the
    program's first statement."""
    page.select_option("#mode-op", mode)
    wait_state(page, f"s.modeOp == '{mode}'")
    page.select_option("#run-mode", run_mode)
    wait_state(page, f"s.runMode == '{run_mode}'")
    page.select_option("#programs", program)
    page.click("#select")
    s = wait_state(page, f"s.state == 'stopped' && s.stop && s.stop.reason == 'entry' && s.program && "
                         f"s.program.endsWith({json.dumps(Path(program).name)})")
    if not s.get("drives"):
        page.click("#drives")
        s = wait_state(page, "s.drives")
    return s


def wait_drawn(page) -> None:
    """Wait until the 3D view has drawn a frame of what the page holds now: a frame is asked for
    and drawn (the page renders on demand, pendant/web/src/main.js)."""
    before = page.evaluate("() => { window.pendant.requestRender(); return window.pendant.frames; }")
    page.wait_for_function(f"() => !window.pendant.renderPending() && window.pendant.frames > {before}",
                           polling=POLL_MS)


#: path -> (the whole lines of its last reading, their events)
_TRACES: dict[Path, tuple[bytes, list[dict]]] = {}


def read_trace(path: Path) -> list[dict]:
    """The events of the JSONL trace `path` (a new list). The lines read before are not parsed
    again while the file still begins with them: the tests read the growing trace of a
    module's server many times, in a loop while they wait (test_page's backward step: 6 s of
    the test process's CPU under load, 2026-11-26, when an unchanged file was the only one not
    parsed again; the whole growing trace parsed at each reading was 0.47 of the test process's
    samples, 2026-11-29). A file rewritten from its start is parsed whole."""
    data = path.read_bytes()
    done, events = _TRACES.get(path, (b"", []))
    if not data.startswith(done):
        done, events = b"", []
    cut = data.rfind(b"\n") + 1            # whole lines are kept; a line being written is parsed each time
    if cut > len(done):
        events = events + _events(data[len(done):cut])
        done = data[:cut]
        _TRACES[path] = (done, events)
    return events + _events(data[cut:])


def _events(chunk: bytes) -> list[dict]:
    return [json.loads(line) for line in chunk.decode().splitlines() if line.strip()]


def pose_at(events: list[dict], t: float) -> list[float]:
    """The axes of the last pose event at or before ``t`` (s)."""
    last = None
    for e in events:
        if e["kind"] == "pose" and e["t"] <= t + 1e-9:
            last = e["axes"]
    assert last is not None, f"no pose at or before t={t}"
    return last


def cell_without(cell: Path, signal: str, out: Path) -> Path:
    """The cell file ``cell`` without the rules that set ``signal`` (written to ``out``)."""
    doc = yaml.safe_load(cell.read_text())
    doc["rules"] = [r for r in doc.get("rules", []) if signal not in (r.get("set") or {})]
    out.write_text(yaml.safe_dump(doc))
    return out
