"""Benchmark of the pendant (issue 36): the simulation's real-time factor without and with the
page open, and the page's latency from an input to its visible change, in one run.

    python -m pendant.bench [BACKUP] [--program P] [--inputs CELL] [--seconds S] [--rounds R] [--toggles N]
                            [--baseline CHECKOUT] [--no-latency | --latency-only] [--no-unpaced]

Each condition gets a ``krl pendant`` of its own (a subprocess) with the program selected in
GO/AUT. With the page open, headless Chromium loads the page first and the program is started
only once the page has drawn the robot, so a slow page load (a loaded machine) never eats the
run and a fast run (a quiet machine) never ends before the page is up. The program is started
by a short websocket connection, and the simulated time and the server's CPU time are read by
short connections while it runs (``closed``: no client connected between them), until
``--seconds`` have passed or the program has ended: the window is the span between the first
and the last reading that found it running, so a run that ends early still gives an exact
factor over a shorter window (one under MIN_WINDOW_S is an error, with its reason).

The real-time factor is simulated time over wall time in that window; simulated time per CPU
second of the server process says what the page costs the server, whatever the machine's load.
Both conditions run paced (real time) and unpaced (``--no-realtime``: the simulation's
throughput); closed and open alternate ``--rounds`` times and the medians are compared.

The latency is measured in the page while the program runs at real time: an input key pressed,
until the animation frame that first shows the new value (``performance.now()`` at the click
and in that frame), ``--toggles`` times, with its parts: until the server's answer (``done``)
arrived, until the new state was on the page, and the server's own part (the key's arrival to
its answer: less sensitive to a loaded machine than what the browser adds). Prints one line per figure, the ratios, the
load and the date; a benchmark, not a test (nothing asserts a time).
"""

from __future__ import annotations

import argparse
import asyncio
import concurrent.futures
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from krl.cputime import tree_cpu_s

from .client import CHROMIUM_FLAGS, ROOT, PendantClientError, act_state, connect, pendant_server
from playwright.sync_api import sync_playwright
DEFAULT_BACKUP = ROOT.parent / "shared" / "krl-corpus" / "khrzysio__KRC4_test"
# 142.6 s of simulated time with its cell (corpus/cells/khrzysio__KRC4_test.yaml): long enough
# for the paced window and the latency toggles on any machine
DEFAULT_PROGRAM = "R1/Program/CELL/Frame/Mill_FrameAut3.src"
DEFAULT_CELL = ROOT / "corpus" / "cells" / "khrzysio__KRC4_test.yaml"
#: the shortest window that gives a factor; the reading interval of an unpaced run (s)
MIN_WINDOW_S = 2.0
UNPACED_READING_S = 0.5
#: time limits of the page (a selection checks a whole backup: minutes on a loaded machine)
PAGE_WAIT_MS = 600_000


class BenchError(Exception):
    """The benchmark could not measure (its reason)."""


async def _act(ws, rid: int, op: str, **args) -> dict:
    """``client.act_state``, a refusal being the benchmark's error."""
    try:
        return await act_state(ws, rid, op, **args)
    except PendantClientError as exc:
        raise BenchError(str(exc)) from exc


async def _select(url: str, program: str) -> None:
    """Select ``program`` in GO (it stands at its first statement); the connection closes again."""
    async with await connect(url) as ws:
        await _act(ws, 1, "runMode", value="GO")
        state = await _act(ws, 2, "select", program=program)
        if state.get("state") != "stopped":
            raise BenchError(f"{program}: after Select the program is {state.get('state')!r}, not stopped")


async def _start(url: str) -> None:
    """Drives on and Start; the connection closes again (no client)."""
    async with await connect(url) as ws:
        await _act(ws, 1, "drives", on=True)
        await _act(ws, 2, "start")


async def _reading(url: str) -> tuple[str, float | None]:
    """(the program's state, the simulated time) now, by a short connection."""
    async with await connect(url) as ws:
        s = await _act(ws, 1, "watch", exprs=[])
        t = s.get("time")
        return str(s.get("state")), float(t) if isinstance(t, (int, float)) else None


def _in_thread(coro):
    """``asyncio.run(coro)`` on a thread of its own (Playwright's sync API holds this one's loop)."""
    with concurrent.futures.ThreadPoolExecutor(1) as ex:
        return ex.submit(asyncio.run, coro).result()


def _window(url: str, pid: int, seconds: float, every: float) -> tuple[float, float, float]:
    """(simulated s, wall s, the server's CPU s) between the first and the last reading that
    found the program running, read each ``every`` s until ``seconds`` have passed or it ended."""
    def reading():
        state, sim = _in_thread(_reading(url))
        return state, sim, time.perf_counter(), tree_cpu_s(pid)
    first = reading()
    if first[0] != "running" or first[1] is None:
        raise BenchError(f"the program is {first[0]!r} a second after Start (not running): nothing to measure")
    last = first
    while last[2] - first[2] < seconds:
        time.sleep(min(every, max(0.0, seconds - (last[2] - first[2]))))
        r = reading()
        if r[0] != "running" or r[1] is None:
            print(f"  (the window ends early: the program is {r[0]!r} after {r[2] - first[2]:.1f} s)", flush=True)
            break
        last = r
    wall = last[2] - first[2]
    if wall < MIN_WINDOW_S:
        raise BenchError(f"the program ran only {wall:.2f} s after the first reading (at least {MIN_WINDOW_S:g} s "
                         "are needed): choose a longer program")
    return last[1] - first[1], wall, last[3] - first[3]


def _with_page(url: str, work):
    """Run ``work(page)`` with the page open in headless Chromium, once it has drawn the robot."""

    with sync_playwright() as pw, tempfile.TemporaryDirectory() as profile:
        ctx = pw.chromium.launch_persistent_context(profile, executable_path="/usr/bin/chromium", headless=True,
                                                    args=CHROMIUM_FLAGS, bypass_csp=True,
                                                    viewport={"width": 1400, "height": 900})
        try:
            page = ctx.new_page()
            page.goto(url)
            page.wait_for_function("() => window.pendant && window.pendant.robot && window.pendant.frames > 0",
                                   timeout=PAGE_WAIT_MS)
            return work(page)
        finally:
            ctx.close()


def _browser_cpu() -> float:
    """CPU s of the browser's processes so far (Playwright's Chromium among this process's
    descendants)."""
    return tree_cpu_s(name="chrom")


def _server_args(cell: Path | None, realtime: bool) -> list[str]:
    """The arguments of ``krl pendant`` in a measurement: AUT, the cell, paced or not."""
    return ["--mode", "AUT", *(["--inputs", str(cell)] if cell is not None else []),
            *([] if realtime else ["--no-realtime"])]


def rtf(root, backup, program, cell, seconds, realtime: bool, page: bool) -> tuple:
    """(simulated s per wall s, simulated s per CPU s of the server, the window's wall s, and
    with the page open the frames it drew and the browser's CPU s, each per wall s)."""
    every = seconds if realtime else UNPACED_READING_S

    def measure(pg=None):
        _in_thread(_start(url))
        time.sleep(1.0)                                # past the start-up
        if pg is None:
            sim, wall, cpu = _window(url, proc.pid, seconds, every)
            return sim / wall, sim / max(cpu, 1e-9), wall, None, None
        f0, b0, t0 = pg.evaluate("() => window.pendant.frames"), _browser_cpu(), time.perf_counter()
        sim, wall, cpu = _window(url, proc.pid, seconds, every)
        f1, b1, t1 = pg.evaluate("() => window.pendant.frames"), _browser_cpu(), time.perf_counter()
        return sim / wall, sim / max(cpu, 1e-9), wall, (f1 - f0) / (t1 - t0), (b1 - b0) / (t1 - t0)
    with pendant_server(backup, *_server_args(cell, realtime), root=root) as (proc, url):
        _in_thread(_select(url, program))
        return _with_page(url, measure) if page else measure()


# an input key pressed until the frame that shows its new value (ms), with the times at which
# the server's answer (done) and the last state before it reached the page (``window.pendant``
# ``lastDone``, ``lastChange``) and the server's own part, from the key's arrival to its answer
# (``lastServerMs``: the ``ms`` of ``done``; null when the answer came after the change showed);
# null when nothing changed within 30 s
LATENCY_JS = """async (n) => {
  const P = window.pendant;
  const btn = document.querySelector(`[data-input="${n}"]`);
  const before = btn.textContent;
  const t0 = performance.now();
  btn.click();
  return await new Promise((resolve) => {
    let r = null;
    const check = () => {
      const t = performance.now();
      if (r === null) {
        const now = document.querySelector(`[data-input="${n}"]`);
        if (now && now.textContent !== before)
          r = {visible: t - t0, state: (P.lastChange > t0 ? P.lastChange : t) - t0};
      }
      if (r !== null && P.lastDone > t0) {          // the answer too (it may come after the change showed)
        resolve({...r, done: Math.min(P.lastDone - t0, r.visible),
                 server: typeof P.lastServerMs === 'number' ? P.lastServerMs : null});
      } else if (t - t0 > 30000) resolve(null);
      else requestAnimationFrame(check);
    };
    requestAnimationFrame(check);
  });
}"""


def latency(root, backup, program, cell, toggles: int, index: int) -> tuple[list[dict], int]:
    """The toggles' times (ms) while the program ran at real time, and how many were skipped
    (the program not running at that toggle, or no change seen)."""
    def work(page):
        page.select_option("#mode-op", "AUT")
        page.select_option("#run-mode", "GO")
        page.select_option("#programs", program)
        page.click("#select")
        page.wait_for_function("() => window.pendant.state && window.pendant.state.state == 'stopped' "
                               "&& window.pendant.state.program", timeout=PAGE_WAIT_MS)
        page.click("#drives")
        page.wait_for_function("() => window.pendant.state.drives", timeout=PAGE_WAIT_MS)
        page.click("#start")
        page.wait_for_function("() => window.pendant.state.state != 'stopped' || !window.pendant.state.time",
                               timeout=PAGE_WAIT_MS)
        page.wait_for_function("() => window.pendant.state.state != 'running' || window.pendant.state.time > 1",
                               timeout=PAGE_WAIT_MS)
        page.click('#tabs button[data-tab="io"]')
        out, skipped = [], 0
        for _ in range(toggles):
            if page.evaluate("() => window.pendant.state.state") != "running":
                skipped += 1
                continue
            r = page.evaluate(LATENCY_JS, index)
            if r is None:
                skipped += 1
            else:
                out.append(r)
            page.wait_for_timeout(100)
        return out, skipped
    with pendant_server(backup, *_server_args(cell, True), root=root) as (_proc, url):
        return _with_page(url, work)


def _load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def _pct(xs: list[float], q: float) -> float:
    xs = sorted(xs)
    return xs[round(q * (len(xs) - 1))]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("backup", nargs="?", type=Path, default=DEFAULT_BACKUP)
    ap.add_argument("--program", default=DEFAULT_PROGRAM)
    ap.add_argument("--inputs", type=Path, default=DEFAULT_CELL)
    ap.add_argument("--seconds", type=float, default=15.0, help="the window of each measurement (s)")
    ap.add_argument("--no-latency", action="store_true", help="measure the real-time factors only")
    ap.add_argument("--latency-only", action="store_true", help="measure the latency only")
    ap.add_argument("--no-unpaced", action="store_true", help="measure the paced run only")
    ap.add_argument("--rounds", type=int, default=2, help="alternations of page closed and open per pacing")
    ap.add_argument("--toggles", type=int, default=20)
    ap.add_argument("--input", type=int, default=16, help="the input toggled (one the program does not read)")
    ap.add_argument("--baseline", type=Path, default=None, metavar="CHECKOUT",
                    help="also measure the krl pendant of another checkout (built: make parser vm-loop), "
                         "alternating with this one in every round")
    a = ap.parse_args(argv)
    a.roots = [ROOT] + ([a.baseline.resolve()] if a.baseline is not None else [])
    print(f"load: {_load()}; {time.strftime('%Y-%m-%d %H:%M %Z')}; {os.cpu_count()} cores; "
          f"{a.backup.name} {a.program}; krl pendant of {', '.join(map(str, a.roots))}", flush=True)
    try:
        if not a.latency_only:
            _factors(a)
        if not a.no_latency:
            _latency(a)
    except (BenchError, PendantClientError) as exc:
        print(f"pendant.bench: {exc}", file=sys.stderr)
        return 1
    print(f"load at the end: {_load()}", flush=True)
    return 0


def _factors(a) -> None:
    for realtime in (True, False) if not a.no_unpaced else (True,):
        # the conditions (each checkout with the page closed and open) alternate, --rounds times
        # each, so that a shared machine's changing load falls on all alike; medians compared
        runs = {(root, page): [] for root in a.roots for page in (False, True)}
        for _ in range(a.rounds):
            for root in a.roots:
                for page in (False, True):
                    runs[(root, page)].append(rtf(root, a.backup, a.program, a.inputs, a.seconds, realtime, page))
        pacing = "paced" if realtime else "unpaced"
        for root in a.roots:
            res = {}
            who = f" [{root}]" if len(a.roots) > 1 else ""
            for page in (False, True):
                xs = runs[(root, page)]
                res[page] = (statistics.median(x[0] for x in xs), statistics.median(x[1] for x in xs))
                each = ", ".join(f"{x[0]:.3f}/{x[1]:.2f} in {x[2]:.1f} s" for x in xs)
                fps = (f"; the page drew {statistics.median(x[3] for x in xs):.1f} frames/s with "
                       f"{statistics.median(x[4] for x in xs):.2f} browser CPU s/s") if page else ""
                print(f"{pacing}, page {'open' if page else 'closed'}{who}: real-time factor {res[page][0]:.3f}, "
                      f"simulated s per server CPU s {res[page][1]:.3f} (rounds: {each}{fps})", flush=True)
            for k, what in ((0, "real-time factor"), (1, "simulated s per server CPU s")):
                drop = 1 - res[True][k] / res[False][k]
                print(f"  {pacing}{who}: with the page open the {what} drops by {drop:+.1%}", flush=True)


def _latency(a) -> None:
    for root in a.roots:
        lat, skipped = latency(root, a.backup, a.program, a.inputs, a.toggles, a.input)
        if not lat:
            raise BenchError(f"no toggle was measured while the program ran ({skipped} skipped)")
        who = f" [{root}]" if len(a.roots) > 1 else ""
        for key, what in (("visible", "input -> visible change"),
                          ("state", "  of which: until the new state was on the page"),
                          ("done", "  of which: until the server's answer arrived"),
                          ("server", "  of which: in the server (key received -> answer sent)")):
            xs = [r[key] for r in lat if r.get(key) is not None]
            if not xs:
                print(f"{what}{who}: not measured (the server of {root} does not send it)", flush=True)
                continue
            print(f"{what}{who} (ms, {len(xs)} toggles at real time{f', {skipped} skipped' if skipped else ''}): "
                  f"median {statistics.median(xs):.1f}, p95 {_pct(xs, 0.95):.1f}, max {max(xs):.1f}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
