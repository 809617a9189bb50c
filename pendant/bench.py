"""Benchmark of the pendant (issue 36): the simulation's real-time factor without and with the
page open, and the page's latency from an input to its visible change, in one run.

    python -m pendant.bench [BACKUP] [--program P] [--inputs CELL] [--seconds S] [--rounds R] [--toggles N]

For each condition the program is selected anew and run in GO/AUT at real time by
``krl pendant`` (a subprocess), started by a short websocket connection: "closed" with no
client connected while it is measured (a short connection reads the simulated time at both
ends of the window), "open" with the page rendered by headless Chromium meanwhile. The real-time factor is simulated time over wall time across ``--seconds`` of running;
the two conditions alternate ``--rounds`` times and the medians are compared.
The same two conditions are then run unpaced (``--no-realtime``): there the factor is the
simulation's throughput, and its drop is what the page costs the simulation. The latency is
measured in the page while the program runs at real time: an input key pressed, until the
page shows the new value (``performance.now()`` at the click and in the animation frame that
first shows it), ``--toggles`` times. Prints one line per figure and the ratios; a benchmark,
not a test (nothing asserts a time).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from urllib.parse import urlsplit

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_BACKUP = ROOT.parent / "shared" / "krl-corpus" / "khrzysio__KRC4_test"
DEFAULT_PROGRAM = "R1/Program/CELL/Other/PrepareMillingTools.src"
DEFAULT_CELL = ROOT / "corpus" / "cells" / "khrzysio__KRC4_test.yaml"
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync"]


def _server(backup: Path, cell: Path | None, realtime: bool):
    cmd = [sys.executable, "-m", "krl.cli", "pendant", str(backup), "--no-browser", "--mode", "AUT"]
    if cell is not None:
        cmd += ["--inputs", str(cell)]
    if not realtime:
        cmd.append("--no-realtime")
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, cwd=ROOT)
    return proc, proc.stdout.readline().strip()


async def _connect(url: str):
    import websockets  # noqa: PLC0415

    u = urlsplit(url)
    token = u.query.split("token=", 1)[1]
    return await websockets.connect(f"ws://{u.hostname}:{u.port}/ws?token={token}", max_size=None,
                                    additional_headers={"Origin": f"http://{u.hostname}:{u.port}"})


async def _act(ws, rid: int, op: str, **args) -> dict:
    """One action; the state pushed after it."""
    await ws.send(json.dumps({"op": op, "id": rid, **args}))
    state = None
    while True:
        m = json.loads(await ws.recv())
        if m["type"] == "state":
            state = m
        if m.get("id") == rid and m["type"] in ("done", "error"):
            if m["type"] == "error":
                raise RuntimeError(m["text"])
            while state is None:
                m = json.loads(await ws.recv())
                state = m if m["type"] == "state" else None
            return state


async def _start(url: str, program: str) -> None:
    """Select ``program`` in GO and start it; the connection is closed again (no client)."""
    async with await _connect(url) as ws:
        await _act(ws, 1, "runMode", value="GO")
        await _act(ws, 2, "select", program=program)
        await _act(ws, 3, "drives", on=True)
        await _act(ws, 4, "start")


async def _sim_time(url: str) -> float:
    """The simulated time now, by a short connection."""
    async with await _connect(url) as ws:
        return float((await _act(ws, 1, "watch", exprs=[]))["time"])


def _in_thread(coro):
    """``asyncio.run(coro)`` on a thread of its own (Playwright's sync API holds this one's loop)."""
    import concurrent.futures  # noqa: PLC0415

    with concurrent.futures.ThreadPoolExecutor(1) as ex:
        return ex.submit(asyncio.run, coro).result()


def _window(url: str, pid: int, seconds: float) -> tuple[float, float, float]:
    """(simulated s, wall s, the server's CPU s) over ``seconds`` of running, with no client of
    this script connected meanwhile."""
    import psutil  # noqa: PLC0415

    proc = psutil.Process(pid)

    def cpu() -> float:
        c = proc.cpu_times()
        return c.user + c.system
    s0, t0, c0 = _in_thread(_sim_time(url)), time.perf_counter(), cpu()
    time.sleep(seconds)
    s1, t1, c1 = _in_thread(_sim_time(url)), time.perf_counter(), cpu()
    return s1 - s0, t1 - t0, c1 - c0


def _with_page(url: str, work):
    """Run ``work(page)`` with the page open in headless Chromium."""
    from playwright.sync_api import sync_playwright  # noqa: PLC0415

    with sync_playwright() as pw, tempfile.TemporaryDirectory() as profile:
        ctx = pw.chromium.launch_persistent_context(profile, executable_path="/usr/bin/chromium", headless=True,
                                                    args=FLAGS, bypass_csp=True,
                                                    viewport={"width": 1400, "height": 900})
        try:
            page = ctx.new_page()
            page.goto(url)
            page.wait_for_function("() => window.pendant && window.pendant.robot", timeout=300_000)
            return work(page)
        finally:
            ctx.close()


def rtf(backup, program, cell, seconds, realtime: bool, page: bool) -> tuple[float, float]:
    """(simulated s per wall s, simulated s per CPU s of the server process)."""
    proc, url = _server(backup, cell, realtime)
    try:
        _in_thread(_start(url, program))
        time.sleep(1.0)                                # past the start-up
        if not page:
            sim, wall, cpu = _window(url, proc.pid, seconds)
        else:
            def work(pg):
                pg.wait_for_function("() => window.pendant.state && window.pendant.state.state == 'running'",
                                     timeout=120_000)
                return _window(url, proc.pid, seconds)
            sim, wall, cpu = _with_page(url, work)
        return sim / wall, sim / max(cpu, 1e-9)
    finally:
        proc.terminate()
        proc.wait(60)


LATENCY_JS = """async (n) => {
  const btn = document.querySelector(`[data-input="${n}"]`);
  const before = btn.textContent;
  const t0 = performance.now();
  btn.click();
  return await new Promise((resolve) => {
    const check = () => {
      const now = document.querySelector(`[data-input="${n}"]`);
      if (now && now.textContent !== before) resolve(performance.now() - t0);
      else requestAnimationFrame(check);
    };
    requestAnimationFrame(check);
  });
}"""


def latency(backup, program, cell, toggles: int, index: int) -> list[float]:
    proc, url = _server(backup, cell, True)
    try:
        def work(page):
            page.select_option("#mode-op", "AUT")
            page.select_option("#run-mode", "GO")
            page.select_option("#programs", program)
            page.click("#select")
            page.wait_for_function("() => window.pendant.state && window.pendant.state.state == 'stopped'",
                                   timeout=600_000)
            page.click("#drives")
            page.click("#start")
            page.wait_for_function("() => window.pendant.state.state == 'running' && window.pendant.state.time > 1",
                                   timeout=600_000)
            page.click('#tabs button[data-tab="io"]')
            out = []
            for _ in range(toggles):
                out.append(page.evaluate(LATENCY_JS, index))
                page.wait_for_timeout(100)
            return out
        return _with_page(url, work)
    finally:
        proc.terminate()
        proc.wait(30)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("backup", nargs="?", type=Path, default=DEFAULT_BACKUP)
    ap.add_argument("--program", default=DEFAULT_PROGRAM)
    ap.add_argument("--inputs", type=Path, default=DEFAULT_CELL)
    ap.add_argument("--seconds", type=float, default=15.0)
    ap.add_argument("--no-latency", action="store_true", help="measure the real-time factors only")
    ap.add_argument("--rounds", type=int, default=2, help="alternations of page closed and open per pacing")
    ap.add_argument("--toggles", type=int, default=20)
    ap.add_argument("--input", type=int, default=16, help="the input toggled (one the program does not read)")
    a = ap.parse_args(argv)
    print(f"load: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}; "
          f"{time.strftime('%Y-%m-%d %H:%M')}; {a.backup.name} {a.program}", flush=True)
    res = {}
    for realtime in (True, False):
        # the two conditions alternate, --rounds times each, so that a shared machine's changing
        # load falls on both alike; the median of each is compared
        runs = {False: [], True: []}
        for _ in range(a.rounds):
            for page in (False, True):
                runs[page].append(rtf(a.backup, a.program, a.inputs, a.seconds, realtime, page))
        for page in (False, True):
            r = statistics.median(x[0] for x in runs[page])
            per_cpu = statistics.median(x[1] for x in runs[page])
            res[(realtime, page)] = (r, per_cpu)
            each = ", ".join(f"{x[0]:.3f}" for x in runs[page])
            print(f"real-time factor, {'paced' if realtime else 'unpaced'}, page {'open' if page else 'closed'}: "
                  f"{r:.3f} (rounds: {each}; simulated s per CPU s of the server: {per_cpu:.3f})", flush=True)
        for k, what in ((0, "real-time factor"), (1, "simulated s per server CPU s")):
            drop = 1 - res[(realtime, True)][k] / res[(realtime, False)][k]
            print(f"  {'paced' if realtime else 'unpaced'}: with the page open the {what} drops by {drop:+.1%}",
                  flush=True)
    print(f"load at the end: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}", flush=True)
    if a.no_latency:
        return 0
    lat = latency(a.backup, a.program, a.inputs, a.toggles, a.input)
    lat.sort()
    print(f"input -> visible change (ms, {len(lat)} toggles at real time): median {statistics.median(lat):.1f}, "
          f"p95 {lat[int(0.95 * (len(lat) - 1))]:.1f}, max {lat[-1]:.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
