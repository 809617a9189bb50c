"""The pendant's handle on the run: the one run-control engine of ``krl debug``
(interp/debug/engine.py), on a thread of its own, driven through its Python API.

Nothing of run control is written here. Every key of the pendant is a call of the engine
(``resume``, ``pause``, ``backward_motion``, ``set_breakpoints``, ``move`` for a jog,
``edit``/``edit_now`` for the override, the operating and run modes, an input set by hand, a
message acknowledged, a touch-up) posted to the engine thread, where the program and the
simulated controller live; edits are recorded by the engine and made again in a replay.

Display: through the engine's ``on_runtime`` each run gets a per-IPO-cycle hook that
publishes :attr:`Pendant.live` (simulated time, $AXIS_ACT, blending, the pointers) and, when
the run is paced (``realtime``), waits until the wall clock has caught up with the simulated
clock, or until work is posted to the engine (a key, a snapshot: served at the next hook, not a
cycle later); a replay is never paced. The message window waits for the operator (the
engine builds its runs interactive: RunSpec.interactive), and the controller's own notes are
kept apart from the KRL messages.

The controller's own messages of the message window (:class:`SystemMessages`: run-time errors
with their number, text, module and line, the numbered messages of the controller and its
options, why a run ended) are kept by the pendant, not by a run: they stay across replays,
selections and page loads until the operator acknowledges them, as on the smartHMI
(docs/pendant.md, "The message window").
"""

from __future__ import annotations

import asyncio
import re
import threading
import time
from pathlib import Path

from interp.debug.cellrun import STRIDE
from interp.debug.engine import Engine as RunEngine, LaunchConfig, Refused, thread_main
from interp.debug.view import ROBOT_THREAD
from interp.runtime.writerules import admit
from robot.axismap import E6AXIS_KEYS

from .touchup import TouchUpError, touch_up as write_point
from krl.limits import MAX_KRL_MESSAGES, MAX_WEB_EXPRESSION_CHARS
from robot.limits import normalise_mode
from interp.runtime.motion import params_from
from robot.motion import NULLFRAME, MotionRequest
import numpy as np

#: the operating modes and run modes the keys offer (robot/limits.py, interp/runtime/runmode.py)
MODES_OP = ("T1", "T2", "AUT", "EXT")
RUN_MODES = ("GO", "MSTEP", "ISTEP")
#: jog: the coordinate systems and the largest increment of one press of a jog key (mm, deg)
JOG_SYSTEMS = ("AXIS", "WORLD", "BASE", "TOOL")
JOG_MAX_STEP = 100.0
#: the TCP path drawn: a point each PATH_STEP_MM of TCP motion, at most MAX_PATH_POINTS
PATH_STEP_MM = 2.0
MAX_PATH_POINTS = 50_000


class EngineError(Exception):
    """An action the engine refused (its message is the pendant's text)."""


#: the message types of the smartHMI's message window, by the kinds of interp/runtime/messages.py
#: (KUKA "Programming user-defined messages": notification, acknowledgement, status, wait, dialog)
MESSAGE_TYPES = {"NOTIFY": "notification", "QUIT": "acknowledgement", "STATE": "status", "WAITING": "wait",
                 "DIALOG": "dialog"}
#: an originator at the head of a numbered controller message ("EKI00010 ..."), else KSS
_ORIGIN = re.compile(r"^([A-Z]{2,8})\d{3,6}\b")


class SystemMessages:
    """The controller's own messages in the message window, kept by the pendant for as long as
    it serves (across runs, replays, selections and page loads) until the operator
    acknowledges them: each a dict ``handle`` ("S1", "S2", ...: a KRL message's handle is an
    INT), ``kind`` (QUIT: acknowledgement, NOTIFY: notification), ``origin`` (KSS, EKI, ...),
    ``number`` (or None), ``text``, ``module`` (the file name), ``path``, ``line``, ``time``
    (simulated s), ``thread`` (robot program, a submit program). At most MAX_KRL_MESSAGES (the
    oldest go first). Thread-safe: the engine thread adds, the server's loop acknowledges."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._items: list[dict] = []
        self._next = 1

    def add(self, kind: str, text: str, *, number: int | None = None, origin: str = "KSS",
            path: str | None = None, line: int | None = None, time: float = 0.0, thread: str | None = None) -> dict:
        """Show a message; the same message again (a replay reaching it, the end of the run
        that stopped at it) is not shown twice while the first is shown."""
        text = str(text)[:500]
        row = {"kind": kind, "origin": origin, "number": number, "text": text,
               "module": Path(path).name if path else "", "path": path, "line": line,
               "time": round(float(time), 3), "thread": thread}
        with self._lock:
            for old in self._items:
                if all(old[k] == row[k] for k in ("kind", "number", "text", "path", "line", "time")):
                    return old
            row["handle"] = f"S{self._next}"
            self._next += 1
            self._items.append(row)
            del self._items[:-MAX_KRL_MESSAGES]
            return row

    def acknowledge(self, handle: str) -> None:
        """The operator's OK. Raises :class:`EngineError` for a message not shown."""
        with self._lock:
            for i, m in enumerate(self._items):
                if m["handle"] == handle:
                    del self._items[i]
                    return
        raise EngineError(f"no message {str(handle)[:20]}")

    def acknowledge_all(self) -> int:
        """"Confirm all": every message shown; how many."""
        with self._lock:
            n = len(self._items)
            self._items.clear()
            return n

    def rows(self) -> list[dict]:
        with self._lock:
            return [dict(m) for m in self._items]


def run_time_error(rt, task, err) -> dict:
    """Where and what a run-time error is, for the message window: number, text, path, line,
    thread (the innermost statement of ``task`` when the error does not carry its place yet)."""
    path = err.file or getattr(task, "file", None)
    line = err.line if err.line is not None else getattr(task, "line", None)
    kind = getattr(task, "kind", "robot")
    name = getattr(task, "name", "")
    return {"number": err.number, "text": err.message, "path": str(path) if path else None, "line": line,
            "time": rt.controller.time, "thread": f"{'submit' if kind == 'submit' else 'robot'} program {name}".strip()}


class Engine:
    """One selected program at a time, run by a debug engine on its own thread.

    ``on_event(name, body)`` receives the engine's events (``stopped``, ``krl/pointers``,
    ``output``, ``exited``, ``terminated``) on the engine thread; it must only hand them on."""

    def __init__(self, on_event, *, realtime: bool = True) -> None:
        self.on_event = on_event
        self.realtime = realtime
        self.system = SystemMessages()
        self._errors_shown: set[int] = set()    # the run-time errors of this run shown (id)
        self.core: RunEngine | None = None
        self.thread = None
        self.live: dict = {}
        self.snapshots = 0                     # state snapshots taken (pendant/state.py snapshot: their seq)
        self.notes: list[dict] = []
        self.signals: dict | None = None       # per run (a cell's robots): its SIGNALs (pendant/state.py)
        #: the TCP path of this run: (X, Y, Z mm in $WORLD, blending); in a cell of several robots
        #: each point is a robot's, in that robot's own $WORLD, its name a fifth element
        self.path: list[tuple] = []
        self.run_no = 0                        # counts the runs built (a replay starts a new path)
        self._base_inv = self._base_T = None
        #: a cell's robots' last path points and $BASE (INV_POS($BASE) and $BASE, 4x4), by name
        self._cell_last: dict[str, tuple] = {}
        self._cell_base: dict[str, tuple] = {}
        self._pace0: tuple[float, float] | None = None
        self._posted = threading.Event()        # work posted to the engine: the pacing wait ends
        #: a cell of several robots (interp/debug/cellrun.py): the robot (index) the keys and the
        #: state act on, the pendant's chosen robot; None for one robot's run
        self.focus: int | None = None

    # ------------------------------------------------------------------ lifecycle
    def select(self, program: str, *, workspace: str | None, inputs: str | None, mode: str | None,
               run_mode: str, trace: str | None, breakpoints: dict[str, list[int]] | None = None,
               **options) -> None:
        """Select ``program`` (a .src path, or a cell file of several robots: interp/debug/cellrun.py)
        and launch it (krl run's setup: the backup's SPS.SUB at boot, its robot, the cell file;
        ``options``: more of krl run's, ``interp_kind``) and stop at its first statement, as
        the program pointer stands on the first line after Select. Raises
        :class:`EngineError` (the checker's errors, a bad cell file)."""
        self.cancel()
        core = RunEngine(on_event=self._event, on_runtime=self._on_runtime, interactive=True)
        self.core, self.signals = core, None
        self.thread = thread_main(core, "krl-pendant-engine")
        options = {"workspace": workspace, "inputs": inputs, "mode": mode, "run_mode": run_mode,
                   "trace_path": trace, "max_sim_time": 7 * 24 * 3600.0, **options}
        try:
            self.call(core.launch, LaunchConfig.of(program, stop_on_entry=True, **options), timeout=900.0)
            for path, lines in (breakpoints or {}).items():
                self.call(core.set_breakpoints, path, [{"line": n} for n in lines])
            self.call(core.configuration_done)
        except EngineError:
            self.cancel()                            # nothing stays selected
            raise
        deadline = time.monotonic() + 900.0          # the run starts: wait for its entry stop
        while core.state not in ("stopped", "ended") and not core.done and time.monotonic() < deadline:
            time.sleep(0.01)

    def cancel(self, timeout: float = 30.0) -> None:
        """Cancel the selected program: the run ends at once."""
        core, thread = self.core, self.thread
        if core is None:
            return
        core.close()
        if thread is not None:
            thread.join(timeout)
        self.core = self.thread = None
        self.live = {}

    @property
    def selected(self) -> bool:
        return self.core is not None and not self.core.done

    @property
    def state(self) -> str:
        return self.core.state if self.core is not None else "none"

    def call(self, fn, *args, timeout: float = 120.0):
        """Run ``fn(*args)`` on the engine thread; its result. Raises :class:`EngineError`."""
        core = self.core
        if core is None or core.done:
            raise EngineError("no program is selected")
        try:
            fut = core.post(fn, *args)
            self._posted.set()
            return fut.result(timeout)
        except Refused as exc:
            raise EngineError(str(exc)) from None
        except TimeoutError:
            raise EngineError("the controller did not answer in time") from None

    def do(self, fn, timeout: float = 120.0):
        """Run ``fn(core)`` on the engine thread (the pendant's own work: keys, the snapshot)."""
        return self.call(lambda: self._aimed(fn, self.core), timeout=timeout)

    def _aimed(self, fn, core):
        """``fn(core)`` with the engine pointed at the chosen robot of a cell (:attr:`focus`)."""
        cell, k = getattr(core, "cell", None), self.focus
        if cell is None or k is None:
            return fn(core)
        with cell.aimed(core, k):
            return fn(core)

    async def do_async(self, fn, timeout: float = 120.0):
        """:meth:`do` awaited on the event loop: the engine thread's result wakes the loop
        directly (no executor thread blocks on it, so a key costs no thread hand-over beyond the
        engine's own). Raises :class:`EngineError`."""
        core = self.core
        if core is None or core.done:
            raise EngineError("no program is selected")
        try:
            fut = core.post(lambda: self._aimed(fn, core))
            self._posted.set()
            return await asyncio.wait_for(asyncio.wrap_future(fut), timeout)
        except Refused as exc:
            raise EngineError(str(exc)) from None
        except asyncio.TimeoutError:
            raise EngineError("the controller did not answer in time") from None

    # ------------------------------------------------------------------ each run
    def _event(self, name: str, body: dict) -> None:
        """The engine's event (engine thread): at the end of a run, why it ended goes to the
        message window (a run-time error once: it was shown where it stopped the program); then
        handed on."""
        core = self.core
        if name == "exited" and core is not None and core.cell is not None:
            for r in core.cell.runs:                   # a cell: how each robot's run ended
                res = r.runtime.result
                if res is not None and res.reason != "completed":
                    self.system.add("NOTIFY", f"{r.name}: program ended: {res.reason}" + (f": {res.text}" if res.text else ""),
                                    origin="krl", path=res.file, line=res.line, time=res.sim_time)
        elif name == "exited" and core is not None and core.rt is not None:
            res = getattr(core.rt, "result", None)
            if res is not None and res.reason == "error" and res.error is not None:
                err = res.error
                if id(err) in self._errors_shown:
                    self.on_event(name, body)          # shown where it stopped the program
                    return
                self.system.add("QUIT", err.message, number=err.number, path=res.file, line=res.line,
                                time=res.sim_time, thread=None if res.context in (None, "main") else res.context)
            elif res is not None and res.reason != "completed":
                self.system.add("NOTIFY", f"program ended: {res.reason}" + (f": {res.text}" if res.text else ""),
                                origin="krl", path=res.file, line=res.line, time=res.sim_time)
        self.on_event(name, body)

    def _on_runtime(self, rt) -> None:
        """A run is built (the first, or a replay; its message window waits for the operator:
        the engine is interactive): run-time errors and numbered controller messages go to the
        message window, the simulator's notes are kept, the display and the pacing hook once
        per IPO cycle."""
        hooks = rt.stepping
        inner_error = hooks.error_hook

        self._errors_shown = set()

        def error_hook(task, frame, err):
            self._errors_shown.add(id(err))
            e = run_time_error(rt, task, err)
            self.system.add("QUIT", e["text"], number=e["number"], path=e["path"], line=e["line"], time=e["time"],
                            thread=e["thread"])
            if inner_error is not None:
                inner_error(task, frame, err)
        hooks.set_hooks(stmt=hooks.stmt_hook, step=hooks.step_hook, error=error_hook, cycle=hooks.cycle_hook)
        ctl = rt.controller
        ctl.signals.add_cyclic(self._cycle)
        self._pace0 = None
        self.notes = []
        self.path = []
        self._cell_last, self._cell_base = {}, {}
        self.run_no += 1

        def message(text, motion_id=None, number=None):
            if number is not None:
                m = _ORIGIN.match(str(text))
                self.system.add("QUIT", text, number=number, origin=m.group(1) if m else "KSS", time=ctl.time)
            elif motion_id is not None:
                # the main run's own message about a motion ("approximation not possible": a
                # KSS warning, krl-reference §6.8): a notification at the motion's line
                req = ctl.current_request()
                at = req if req is not None and getattr(req, "id", None) == motion_id else None
                self.system.add("NOTIFY", text, path=getattr(at, "file", None), line=getattr(at, "line", None),
                                time=ctl.time)
            elif not (text.startswith("KRL message: ") or text.startswith("KRL dialog")):
                self.notes.append({"time": round(ctl.time, 3), "text": str(text)[:300]})
                del self.notes[:-MAX_KRL_MESSAGES]
        ctl.log.watch_messages(message)

    def _cycle(self, ctl) -> None:
        """Once per IPO cycle (engine thread): publish the live pose, pace to the wall clock."""
        core = self.core
        if core is not None and getattr(core, "cell", None) is not None:
            self._cell_cycle(core, ctl)
            return
        if core is None or core.rt is None or ctl is not core.rt.controller:
            return
        req = ctl.current_request()
        blending = _blending(ctl)
        self._record_path(ctl, blending)
        self.live = {
            "time": round(ctl.time, 6), "axes": [float(v) for v in ctl.actual.axis_act()],
            "blending": blending, "run": self.run_no, "pointers": _pointers(core.rt.robot, req)}
        self._pace(core, ctl)

    def _cell_cycle(self, core, ctl) -> None:
        """A cell's robot's cycle: its TCP path (:meth:`_record_cell_path`), its live pose and
        pointers in ``live["robots"]``; the cell's last robot's cycle (the cell's clock's) paces.
        The chosen robot's pose is ``axes``."""
        runs = core.cell.runs
        k = next((i for i, r in enumerate(runs) if r.runtime.controller is ctl), None)
        if k is None:
            return
        rt = runs[k].runtime
        self._record_cell_path(runs[k].name, ctl)
        robots = dict(self.live.get("robots", {}))
        robots[runs[k].name] = {"axes": [round(float(v), 4) for v in ctl.actual.axis_act()],
                                "pointers": _pointers(rt.robot, ctl.current_request())}
        chosen = robots.get(runs[self.focus or 0].name, {})
        self.live = {"time": round(ctl.time, 6), "robots": robots, "run": self.run_no,
                     "axes": chosen.get("axes", []), "pointers": chosen.get("pointers"), "blending": False}
        if k == len(runs) - 1:
            self._pace(core, ctl)

    def _pace(self, core, ctl) -> None:
        """Wait until the wall clock has caught up with the simulated clock (``realtime``)."""
        if core.target is not None or core.scan is not None or not self.realtime:
            self._pace0 = None
            return
        now = time.perf_counter()
        if self._pace0 is None or core.state == "stopped" and not core.busy:
            self._pace0 = (now, ctl.time)
            return
        ahead = (ctl.time - self._pace0[1]) - (now - self._pace0[0])
        if ahead > 0 and self._posted.wait(ahead):
            # work was posted (a key, a snapshot): the wait ends at once and the engine serves
            # it at the next hook (the tasks' next statement or cycle), where it would be served
            # after the sleep too, so the simulated run is the same; the simulation is ahead of
            # the wall clock for a moment, and the next cycles wait the longer
            self._posted.clear()
        elif ahead < -0.25:
            self._pace0 = (now, ctl.time)    # fell behind (a stop, a slow cycle): pace from here

    def _record_path(self, ctl, blending: bool) -> None:
        """The TCP in $WORLD once it has moved PATH_STEP_MM, or when an approximation starts
        or ends (at most MAX_PATH_POINTS points: the oldest are dropped). It is the pose the
        controller computed in this cycle (its TCP in $BASE and that $BASE, the numbers the
        trace's pose events hold), so the path costs the simulation a matrix product a cycle."""
        actual = ctl.actual
        base_inv = actual.base_inv_T
        if base_inv is not self._base_inv:
            self._base_inv, self._base_T = base_inv, np.linalg.inv(base_inv)
        point = _world_point(self._base_T, actual.tcp, blending)
        if _far_enough(self.path[-1] if self.path else None, point):
            self._add_point(point)

    def _record_cell_path(self, name: str, ctl) -> None:
        """Robot `name`'s TCP path in a cell: as :meth:`_record_path` does for one robot, the
        point in that robot's own $WORLD (the page places it at the robot's base, as it draws the
        robot: docs/pendant.md), the robot's name its fifth element, the step kept per robot."""
        actual = ctl.actual
        base_inv = actual.base_inv_T
        known = self._cell_base.get(name)
        if known is None or known[0] is not base_inv:
            known = self._cell_base[name] = (base_inv, np.linalg.inv(base_inv))
        point = _world_point(known[1], actual.tcp, _blending(ctl))
        if _far_enough(self._cell_last.get(name), point):
            self._cell_last[name] = point
            self._add_point((*point, name))

    def _add_point(self, point: tuple) -> None:
        self.path.append(point)
        if len(self.path) > MAX_PATH_POINTS:
            del self.path[:len(self.path) - MAX_PATH_POINTS]


def _blending(ctl) -> bool:
    """True while the controller `ctl` runs inside an approximation (its blend is set)."""
    return getattr(ctl, "_blend", None) is not None


def _world_point(base_T: np.ndarray, tcp: np.ndarray, blending: bool) -> tuple:
    """(X, Y, Z mm in $WORLD rounded to 0.1 mm, blending) of the TCP `tcp` (4x4 in $BASE) in
    the $BASE `base_T` (4x4)."""
    w = base_T[:3, :3] @ tcp[:3, 3] + base_T[:3, 3]
    return round(float(w[0]), 1), round(float(w[1]), 1), round(float(w[2]), 1), blending


def _far_enough(last: tuple | None, point: tuple) -> bool:
    """True when `point` is a new point of the path after `last` (None: the first): moved
    PATH_STEP_MM from it, or an approximation started or ended."""
    if last is None:
        return True
    (lx, ly, lz, lb), (x, y, z, b) = last[:4], point[:4]
    return lb != b or (x - lx) ** 2 + (y - ly) ** 2 + (z - lz) ** 2 >= PATH_STEP_MM ** 2


def _pointers(robot, req) -> dict:
    """The advance run's and the main run's places (path, line) of a run's robot program."""
    return {"advanceRun": {"path": robot.file, "line": robot.line} if robot is not None and robot.at is not None else None,
            "mainRun": {"path": req.file, "line": req.line} if req is not None and req.line else None}


# ---------------------------------------------------------------------- the keys (engine thread)

def chosen_frame(core: RunEngine):
    """Where a key's KRL text is evaluated or assigned: None (the stop's frame), or in a cell
    stopped in another robot's program, the innermost frame of the chosen robot's robot program
    (interp/debug/engine.py Frame). Raises :class:`Refused` when that program has ended."""
    cell = getattr(core, "cell", None)
    if cell is None or core.state != "stopped" or cell.stopped_in(core) == cell.index_of(core.rt):
        return None
    k = cell.index_of(core.rt)
    frames = core.stack(k * STRIDE + ROBOT_THREAD)
    if not frames:
        raise Refused(f"{cell.runs[k].name}'s robot program has ended")
    return frames[0]


def evaluate(core: RunEngine, text: str):
    """A watched expression's value: in the stopped frame, in the chosen robot's program in a
    cell (:func:`chosen_frame`), or in the robot program's innermost frame while it runs."""
    frame = chosen_frame(core)
    return core.evaluate(text, frame) if frame is not None else core.evaluate_now(text)


def override(core: RunEngine, value) -> int:
    """$OV_PRO (0..100 %, the controller's write rules: interp/runtime/writerules.py): applies
    to the motions planned from then on."""
    if not isinstance(value, int) or isinstance(value, bool):
        raise Refused("override: an integer 0..100")
    refusal = admit("$OV_PRO", value, "program")
    if refusal is not None:
        raise Refused(f"override: {refusal.message}")

    def apply(engine):
        engine.rt.sysvars.set_override(value)
        return value
    return core.edit_now(f"$OV_PRO = {value}", apply)


def run_mode(core: RunEngine, value: str) -> str:
    """$PRO_MODE (GO, MSTEP, ISTEP): applies from the next statement."""
    if value not in RUN_MODES:
        raise Refused(f"run mode {value!r}: one of {', '.join(RUN_MODES)}")

    def apply(engine):
        engine.rt.stepping.set_run_mode(value)
        return value
    return core.edit_now(f"$PRO_MODE = #{value}", apply)


def mode_op(core: RunEngine, value: str) -> str:
    """The operating mode, changed while the program stands (on the robot, turning the mode
    selector stops the program and switches the drives off)."""

    if value not in MODES_OP:
        raise Refused(f"operating mode {value!r}: one of {', '.join(MODES_OP)}")
    if core.state == "running":
        raise Refused("operating mode: stop the program first")
    m = normalise_mode(value)

    def apply(engine):
        engine.rt.select_mode(m)
        return value
    return core.edit(f"$MODE_OP = #{value}", apply)


def set_input(core: RunEngine, index, value: bool) -> bool:
    """``$IN[index]`` set by hand (source ``operator``), running or stopped; the cell's rules
    stay active (the debugger engine's ``set_input``, also while the program runs)."""
    return core.set_input(index, value, now=True)


def message(core: RunEngine, handle, answer=None) -> None:
    """Acknowledge a message, or press softkey ``answer`` of a dialog (interp/runtime/messages.py)."""
    def apply(engine):
        win = engine.rt.messages
        try:
            if answer is not None:
                win.answer(handle, answer)
            else:
                win.acknowledge(handle)
        except ValueError as exc:
            raise Refused(str(exc)) from None
    what = f"answer {answer} to message {handle}" if answer is not None else f"acknowledge message {handle}"
    core.edit_now(what, apply)


def acknowledge_all(core: RunEngine) -> int:
    """"Confirm all" for the program's messages: every notification and acknowledgement
    message shown (status, wait and dialog messages stay: the program clears them, a dialog
    is answered); how many."""
    def apply(engine):
        win = engine.rt.messages
        handles = [m.handle for m in win.shown if m.kind in ("NOTIFY", "QUIT")]
        for h in handles:
            win.acknowledge(h)
        return len(handles)
    return core.edit_now("confirm all messages", apply)


def jog(core: RunEngine, system: str, axis, step) -> list:
    """One jog increment in T1 with the program stopped: AXIS (``axis`` 1..6 for A1..A6, 7..12 for
    E1..E6, ``step`` deg or mm) or
    WORLD/BASE/TOOL (``axis`` X, Y, Z, A, B, C, ``step`` mm or deg), as a PTP (axis) or a
    relative LIN under T1's speed limits (robot/limits.py), made by the engine's ``move``."""
    core.need_stopped()
    rt = core.rt
    if rt.mode_op != "T1":
        raise Refused(f"jog: only in T1 (operating mode {rt.mode_op})")
    if system not in JOG_SYSTEMS:
        raise Refused(f"jog: coordinate system one of {', '.join(JOG_SYSTEMS)}")
    if not isinstance(step, (int, float)) or isinstance(step, bool) or not 0 < abs(step) <= JOG_MAX_STEP:
        raise Refused(f"jog: a step of at most {JOG_MAX_STEP:g} mm or deg")
    params = params_from(rt.sysvars.store).with_(ov_pro=100.0)
    if system == "AXIS":
        # the robot's axes and its external axes by their E6AXIS component (robot/axismap.py):
        # 1..6 are A1..A6, 7..12 E1..E6, as KRL's E6AXIS orders them
        amap = rt.controller.model.axes
        keys = E6AXIS_KEYS
        if not isinstance(axis, int) or isinstance(axis, bool) or not 1 <= axis <= len(keys) \
                or keys[axis - 1] not in amap.model_keys:
            raise Refused("jog: axis " + ", ".join(f"{i + 1} ({k})" for i, k in enumerate(keys)
                                                   if k in amap.model_keys))
        target = amap.krl_components(rt.controller.actual.axis_setpoint())
        target = {k: v for k, v in target.items() if k in amap.model_keys}
        target[keys[axis - 1]] += float(step)
        req = MotionRequest("PTP", target, params)
    else:
        comp = str(axis).upper()
        if comp not in ("X", "Y", "Z", "A", "B", "C"):
            raise Refused("jog: component X, Y, Z, A, B or C")
        if system == "WORLD":
            params = params.with_(base=NULLFRAME)
        req = MotionRequest("LIN", {comp: float(step)}, params, relative=True,
                            rel_frame="TOOL" if system == "TOOL" else "BASE")
    return core.move(req)


def touch_up(core: RunEngine, path: str, name: str) -> dict:
    """Touch up the point ``name`` of the data list ``path`` (inside the workspace: the server
    checked it) with the actual position, in T1/T2 with the program stopped; the running
    program's copy of the point gets the same values (an edit of the engine)."""
    core.need_stopped()
    rt = core.rt
    if rt.mode_op not in ("T1", "T2"):
        raise Refused("touch-up: only in T1 or T2")
    if not name or len(name) > 24 or not name.replace("_", "").replace("$", "").isalnum():
        raise Refused("touch-up: a point name")
    try:
        new = write_point(Path(path), name, rt.controller.actual.pos_act(), [float(v) for v in rt.controller.actual.axis_act()])
    except TouchUpError as exc:
        raise Refused(str(exc)) from None
    except OSError as exc:
        raise Refused(f"touch-up: cannot write the data list ({exc.strerror})") from None
    frame = chosen_frame(core)
    for k, v in new.items():
        try:
            core.assign(f"{name}.{k}", repr(v), frame)
        except Refused:
            break                          # not visible from here: the file holds the new point
    return {"name": name, "values": new}


def set_watch(core: RunEngine, expr: str, value: str) -> str:
    """``expr = value`` (KRL texts) at the stop: the engine's assign."""
    if len(expr) > MAX_WEB_EXPRESSION_CHARS or len(value) > MAX_WEB_EXPRESSION_CHARS:
        raise Refused(f"at most {MAX_WEB_EXPRESSION_CHARS} characters")
    return core.assign(expr, value, chosen_frame(core))


__all__ = ["Engine", "EngineError", "JOG_SYSTEMS", "MESSAGE_TYPES", "MODES_OP", "RUN_MODES", "SystemMessages",
           "acknowledge_all", "chosen_frame", "evaluate", "jog", "message", "mode_op",
           "override", "run_mode", "set_input", "set_watch", "touch_up"]
