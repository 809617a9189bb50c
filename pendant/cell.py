"""The pendant on a cell of several robots (issue 89; docs/pendant.md, "A cell of several robots"):
``krl pendant CELL.yaml`` runs the cell (interp/robotcell.py: every robot's program on one IPO
clock, the wires, the zones, the collisions) on a thread of its own, paced to the wall clock
unless ``--no-realtime``; the page chooses the robot whose program, pointers, I/O and position it
shows, and its 3D view draws every robot at its ``base`` moving together.

Keys: Start runs the cell (from its beginning, or on after Stop), Stop holds every robot at the
end of the IPO cycle (the cell's one clock stands), Cancel ends the cell run (Start begins a new
one), the robot chooser (``chooseRobot``) changes what the program view, the position and the I/O
show. The single robot's keys (jog, touch-up, the modes, the breakpoints, the watch list) are
refused in a cell: they act on one run's debug engine (interp/debug/engine.py), which a cell does
not have yet (docs/cells.md, "Not yet").

Threads: the cell runs on its thread; once per IPO cycle each robot's cyclic hook
(robot/signals.py ``add_cyclic``) publishes that robot's pose and pointers (:attr:`CellEngine.live`),
and the last robot's hook paces the cell, waits while it is stopped and serves the server's reads
(:meth:`CellEngine.read`: a state snapshot taken between two cycles, where nothing moves).
"""

from __future__ import annotations

import asyncio
import json
import queue
import threading
import time
from concurrent.futures import Future
from pathlib import Path

from interp.run import robot_for
from interp.robotcell import cell_runs, load_robot_cell, run_cell
from krl.limits import MAX_WEB_WATCHES

from .engine import EngineError
from .server import LIVE_HZ, OPERATIONS, STATE_HZ, Pendant
from .state import _io, signals_of
from .view import robot_view

#: the cell's time limit in the pendant (s of simulated time): a week, as a single run's
CELL_SIM_TIME_S = 7 * 24 * 3600.0
#: the operations a cell's page may send (the rest of pendant/server.py OPERATIONS is refused)
CELL_OPS = ("hello", "start", "stop", "cancel", "chooseRobot", "open", "logbook")


class _Cancelled(BaseException):
    """Raised in a robot's cycle hook to end the cell run (Cancel, the server's end)."""


class CellEngine:
    """The cell's run on its own thread (module docstring). ``state``: none (not started),
    running, stopped, ended; ``live``: {time, robots: {name: {axes, pointers}}}; ``result``:
    interp/robotcell.py CellResult once ended (``error``: the text of a run that could not be
    built)."""

    def __init__(self, cell_file: Path, *, realtime: bool = True, interp: str = "vm") -> None:
        self.cell = load_robot_cell(cell_file)
        self.realtime, self.interp = realtime, interp
        self.state = "none"
        self.live: dict = {}
        self.result = None
        self.error: str | None = None
        self.runs: list = []
        self.thread: threading.Thread | None = None
        self._go = threading.Event()
        self._cancel = False
        self._reads: queue.Queue = queue.Queue()
        self._pace0: tuple[float, float] | None = None

    @property
    def selected(self) -> bool:
        return self.state in ("running", "stopped")

    def start(self) -> None:
        """Start the cell (a new run when none runs), or let a stopped one go on."""
        if self.thread is None or not self.thread.is_alive():
            self._cancel, self.result, self.error, self.live = False, None, None, {}
            self._go.set()
            self.state = "running"
            self.thread = threading.Thread(target=self._main, name="krl-pendant-cell", daemon=True)
            self.thread.start()
            return
        self._pace0 = None
        self.state = "running"
        self._go.set()

    def stop(self) -> None:
        """Hold the cell at the end of the IPO cycle."""
        if self.state == "running":
            self._go.clear()
            self.state = "stopped"

    def cancel(self, timeout: float = 30.0) -> None:
        """End the cell run (the thread ends at its next cycle)."""
        thread = self.thread
        self._cancel = True
        self._go.set()
        if thread is not None:
            thread.join(timeout)
        self.thread = None
        if self.state != "none":
            self.state = "ended"

    def read(self, fn, timeout: float = 60.0):
        """``fn(runs)`` between two IPO cycles of the running cell (on its thread), else at once."""
        thread = self.thread
        if thread is None or not thread.is_alive():
            return fn(self.runs)
        fut: Future = Future()
        self._reads.put((fn, fut))
        return fut.result(timeout)

    # ------------------------------------------------------------------ the cell's thread
    def _main(self) -> None:
        try:
            with cell_runs(self.cell, self.interp, CELL_SIM_TIME_S) as runs:
                self.runs = runs
                last = runs[-1].runtime.controller
                for r in runs:
                    r.runtime.controller.signals.add_cyclic(
                        lambda ctl, name=r.name: self._cycle(ctl, name, ctl is last))
                self.result = run_cell(self.cell, runs)
        except _Cancelled:
            pass
        except Exception as exc:  # noqa: BLE001 - the page shows why the cell did not run
            self.error = f"{type(exc).__name__}: {exc}"[:500]
        finally:
            self.state = "ended"
            self._serve_reads()

    def _cycle(self, ctl, name: str, last: bool) -> None:
        """A robot's cycle hook: its live pose; the last robot's also paces, waits and serves."""
        run = next(r for r in self.runs if r.name == name)
        robot, req = run.runtime.robot, ctl.current_request()
        robots = dict(self.live.get("robots", {}))
        robots[name] = {"axes": [round(float(v), 4) for v in ctl.actual.axis_act()],
                        "pointers": {"advanceRun": {"path": robot.file, "line": robot.line}
                                     if robot is not None and robot.at is not None else None,
                                     "mainRun": {"path": req.file, "line": req.line}
                                     if req is not None and req.line else None}}
        self.live = {"time": round(ctl.time, 6), "robots": robots}
        if not last:
            return
        self._serve_reads()
        while not self._go.is_set():
            self._go.wait(0.05)
            self._serve_reads()
        if self._cancel:
            raise _Cancelled()
        self._pace(ctl.time)

    def _pace(self, t: float) -> None:
        if not self.realtime:
            return
        now = time.perf_counter()
        if self._pace0 is None:
            self._pace0 = (now, t)
            return
        ahead = (t - self._pace0[1]) - (now - self._pace0[0])
        if ahead > 0:
            time.sleep(min(ahead, 0.5))
        elif ahead < -0.25:
            self._pace0 = (now, t)

    def _serve_reads(self) -> None:
        while True:
            try:
                fn, fut = self._reads.get_nowait()
            except queue.Empty:
                return
            try:
                fut.set_result(fn(self.runs))
            except Exception as exc:  # noqa: BLE001 - handed to the reader
                fut.set_exception(exc)


class CellPendant(Pendant):
    """:class:`pendant.server.Pendant` serving a cell of several robots (module docstring): the
    same page, connections and limits; the cell's engine instead of one program's."""

    def __init__(self, cell_file: Path, *, realtime: bool = True) -> None:
        super().__init__(cell_file.parent, realtime=realtime, shown_root=str(cell_file))
        self.engine = CellEngine(cell_file, realtime=realtime)
        self.cell = self.engine.cell
        self.chosen = self.cell.robots[0].name
        self._views: list | None = None
        self._sent_pointers = None

    def robot(self) -> dict:
        return self.views()[0]

    def views(self) -> list[dict]:
        """Every robot as the page draws it (pendant/view.py ``robot_view``: its machine data, its
        own cell file's bodies) with its ``base`` in the cell's world and its program."""
        if self._views is None:
            # the machine data a run of each robot would simulate (interp/run.py robot_for)
            out = []
            for r in self.cell.robots:
                inputs = str(r.inputs) if r.inputs is not None else None
                machine = robot_for(str(r.program), str(r.workspace) if r.workspace else None, None, inputs)
                view = robot_view(machine, inputs)
                out.append({**view, "robot": r.name, "base": list(r.base), "program": str(r.program),
                            "robroot": list(view["robroot"])})
            self._views = out
        return self._views

    def programs(self) -> list[str]:
        return [str(r.program) for r in self.cell.robots]

    async def handle(self, ws, msg: dict) -> None:
        op = msg.get("op")
        if op not in CELL_OPS:
            if op in OPERATIONS:
                raise EngineError(f"{str(op)[:40]}: not taken in a cell of several robots (docs/pendant.md)")
            raise EngineError(f"unknown action {str(op)[:40]!r}")
        loop = asyncio.get_running_loop()
        if op == "hello":
            await ws.send_text(json.dumps({"type": "init", "workspace": self.shown_root, "programs": [],
                                           "modules": [], "robot": self.robot(), "modes": [], "runModes": [],
                                           "readonly": True, "cell": {"robots": self.views(), "chosen": self.chosen}},
                                          default=str))
            await self._send_chosen(ws)
        elif op == "start":
            self.engine.start()
        elif op == "stop":
            self.engine.stop()
        elif op == "cancel":
            await loop.run_in_executor(None, self.engine.cancel)
        elif op == "chooseRobot":
            name = msg.get("robot")
            if name not in {r.name for r in self.cell.robots}:
                raise EngineError(f"no robot {str(name)[:40]!r} in the cell")
            self.chosen = name
            for page in list(self.clients):
                await self._send_chosen(page)
        else:                                          # a file's view, the logbook: as for one robot
            return await Pendant.handle(self, ws, msg)
        await self.push_state()

    async def _send_chosen(self, ws) -> None:
        program = next(r.program for r in self.cell.robots if r.name == self.chosen)
        await ws.send_text(await self.module_text(str(program)))

    async def state(self, fresh: dict | None = None) -> dict:
        """The chosen robot's view of the cell: the cell's state and time, the chosen robot's
        program, pointers, I/O and position, how each robot ended (once the cell has)."""
        eng, chosen = self.engine, self.chosen
        program = str(next(r.program for r in self.cell.robots if r.name == chosen))
        out = {"state": eng.state, "cell": {"chosen": chosen, "robots": [r.name for r in self.cell.robots]},
               "program": program, "programLabel": Path(program).name, "drives": True,
               "messages": [],
               "modeOp": "AUT", "runMode": "GO"}
        live = eng.live.get("robots", {}).get(chosen)
        if live is not None:
            out["pointers"] = live["pointers"]
            out["time"] = eng.live["time"]
        if eng.runs:
            try:
                out.update(await asyncio.get_running_loop().run_in_executor(None, eng.read, lambda runs: _robot_state(runs, chosen)))
            except Exception:  # noqa: BLE001 - a cell between two reads: the state without them
                pass
        if eng.state == "ended":
            out["outcome"] = _outcome(eng)
        return out

    async def ticker(self) -> None:
        """Display rate: every robot's live pose while the cell runs, the state now and then."""
        every, sent, last, shown = max(1, int(LIVE_HZ / STATE_HZ)), 0, None, None
        while True:
            await asyncio.sleep(1.0 / LIVE_HZ)
            if not self.clients:
                continue
            live = self.engine.live
            if live and live is not last:
                last = live
                chosen = live["robots"].get(self.chosen, {})
                await self.broadcast({"type": "live", "time": live["time"], "robots": live["robots"],
                                      "axes": chosen.get("axes"), "pointers": chosen.get("pointers"), "path": []})
                sent += 1
                if sent % every == 0:
                    await self.push_state()
            if self.engine.state != shown:          # started, stopped, ended: at once
                shown = self.engine.state
                await self.push_state()


def _robot_state(runs: list, name: str) -> dict:
    """The chosen robot's I/O and position (pendant/state.py's shapes), read between two cycles."""
    run = next(r for r in runs if r.name == name)
    rt = run.runtime
    ctl = rt.controller
    pos = ctl.actual.pos_act()
    return {"io": _io(rt, signals_of(rt)), "time": round(ctl.time, 3),
            "position": {"axes": [round(float(v), 4) for v in ctl.actual.axis_act()],
                         "pos": {k: round(float(v), 3) for k, v in pos.items()}, "base": None, "tool": None}}


def _outcome(eng: CellEngine) -> dict:
    """How the cell ended: its reason and, per robot, how its run ended; the collisions."""
    res = eng.result
    if res is None:
        return {"reason": "error" if eng.error else "cancelled", "text": eng.error or "", "path": None, "line": None}
    text = "; ".join(f"{r.name} {r.runtime.result.reason}" for r in res.robots)
    text += "".join(f"; collision {c}" for c in res.collisions)
    return {"reason": res.reason, "text": text[:MAX_WEB_WATCHES * 50], "path": None, "line": None}


__all__ = ["CELL_OPS", "CellEngine", "CellPendant"]
