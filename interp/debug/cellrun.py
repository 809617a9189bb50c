"""The debugger on a cell of several robots (issue 89; docs/cells.md "The debugger"): ``krl
debug`` launched with a cell file (interp/robotcell.py) runs the whole cell on one IPO clock
under the one engine (interp/debug/engine.py), each robot's threads numbered apart.

Threads: robot k of the cell file (0-based, in the order ``robots:`` names them) has the thread
ids ``k * STRIDE +`` the ids of a single run (interp/debug/view.py: its robot program 1, its
submit programs 2.., its running interrupt handlers 1000..), named after the robot (``R2: robot
program PAL``). A stop stops every robot's every thread (``allThreadsStopped``: the cell's one
clock stands); stack, scopes, variables and evaluation of a thread read that robot's run;
continue and the steps resume the cell, a step following the task of its thread. Reverse
execution (stepBack, reverseContinue) is refused in a cell: it replays one run from its start
(the engine's module docstring), and a cell's replay is not built.

A front end's keys act on one robot (the pendant's chosen robot, pendant/engine.py): :meth:`aimed`
points the engine at it for one key and back at the stop's robot afterwards. A motion made at a
stop (a jog, the engine's ``move``) takes IPO cycles of the cell's one clock: the stopped task
gives them back (:meth:`wait_idle`) and, while it moves (:meth:`held`), every other robot
program of the cell holds at its next statement or IPO cycle, so that the cell stands as a stop
leaves it (their main runs finish the motions already planned, their submit programs run on, as
a single run's submit program does during a jog). A backward motion (#BSTEP) runs in the robot
program's own task: in a cell it needs the stop in that robot's program (:meth:`need_stop_in`).
"""

from __future__ import annotations

import contextlib
from pathlib import Path

from . import view
from .errors import Refused
from interp.robotcell import (CellError, cell_runs, is_robot_cell, load_robot_cell, run_cell,
                              summary_lines)
from interp.tree import TreeInterpreter
from robot.stimuli import StimulusError

#: thread ids of robot k: k * STRIDE + a single run's (view.py's largest is 1000 + 128 + 200)
STRIDE = 10000
#: the refusal of reverse execution in a cell
NO_REVERSE = "stepping back is not available in a cell of several robots (its replay is not built)"


def is_cell_launch(options: dict) -> bool:
    """Whether the launch's ``program`` is a cell file of several robots."""
    program = options.get("program")
    return program is not None and is_robot_cell(Path(program))


class CellDebug:
    """The runs of a cell under the engine: launched by :meth:`open`, run by :meth:`run`."""

    def __init__(self, path: Path, cell, runs: list) -> None:
        self.path = path
        self.cell = cell
        self.runs = runs
        self.trees = [TreeInterpreter(r.runtime) for r in runs]
        self.holding = False                   # a motion at the stop: the other robot programs hold
        #: how the cell ended (interp/robotcell.py CellResult), once it has
        self.result = None

    @classmethod
    def open(cls, engine, options: dict) -> "CellDebug":
        """Build the cell's runs for `engine` (kept until the session ends: its cleanup stack).
        Raises :class:`Refused` for a cell file that does not make a cell (file:line)."""
        path = Path(options["program"])
        try:
            cell = load_robot_cell(path)
            runs = engine.cleanup.enter_context(cell_runs(
                cell, options.get("interp_kind") or "vm", float(options.get("max_sim_time") or 600.0),
                Path(options["trace_path"]) if options.get("trace_path") else None))
        except (CellError, StimulusError, OSError) as exc:
            raise Refused(str(exc)) from None
        return cls(path, cell, runs)

    def index_of(self, rt) -> int:
        return next(k for k, r in enumerate(self.runs) if r.runtime is rt)

    def thread_list(self) -> list:
        """(thread id, name, task, frames) of every robot's threads (module docstring)."""
        return [(k * STRIDE + tid, f"{r.name}: {name}", task, frames)
                for k, r in enumerate(self.runs) for tid, name, task, frames in view.thread_list(r.runtime)]

    def thread_of(self, rt, task) -> int:
        """The thread a stop of `task` (of robot run `rt`) belongs to."""
        return self.index_of(rt) * STRIDE + view.thread_of(rt, task)

    def use(self, engine, k: int) -> None:
        """Point the engine at robot k's run (its runtime and tree interpreter)."""
        engine.rt, engine.tree = self.runs[k].runtime, self.trees[k]

    def focus(self, engine, thread: int | None) -> None:
        """Point the engine at the run of `thread` (None: the stopped task's robot)."""
        if thread is None:
            task = engine.stop_task
            k = next((i for i, r in enumerate(self.runs) if task in r.runtime.scheduler.tasks), 0)
        else:
            k = thread // STRIDE
        if 0 <= k < len(self.runs):
            self.use(engine, k)

    def stopped_in(self, engine) -> int | None:
        """The robot (index) whose task the engine stopped in; None while it runs."""
        task = engine.stop_task
        if engine.state != "stopped" or task is None:
            return None
        return next((i for i, r in enumerate(self.runs) if task in r.runtime.scheduler.tasks), None)

    def need_stop_in(self, engine, what: str) -> None:
        """Refused unless the cell stands in the robot program of the robot the engine points at
        (a key that runs in that program's task). Raises :class:`Refused` naming both robots."""
        k, here = self.stopped_in(engine), self.index_of(engine.rt)
        task = engine.stop_task
        if k == here and task is not None and task.kind == "robot":
            return
        where = f"{self.runs[k].name}'s" if k is not None else "no robot"
        raise Refused(f"{what}: the cell stands in {where} program, not in {self.runs[here].name}'s robot program "
                      f"(stop the cell with {self.runs[here].name} chosen)")

    @contextlib.contextmanager
    def aimed(self, engine, k: int):
        """The engine pointed at robot k for one front end's key, at the stop's robot (or the
        robot it pointed at) afterwards: the stop's bookkeeping reads the stop's own run."""
        saved = engine.rt, engine.tree
        self.use(engine, k)
        try:
            yield
        finally:
            engine.rt, engine.tree = saved

    @contextlib.contextmanager
    def held(self):
        """While a motion is made at the stop: the cell's other robot programs hold (module docstring)."""
        self.holding = True
        try:
            yield
        finally:
            self.holding = False

    def wait_idle(self, engine, rt) -> None:
        """At a stop: IPO cycles of the cell's clock until `rt`'s main run stands, given back by
        the stopped task (whichever robot's it is; it runs nothing meanwhile)."""
        k = self.stopped_in(engine)
        sched = self.runs[k if k is not None else self.index_of(rt)].runtime.scheduler
        while not rt.controller.is_idle():
            sched.yield_cycle()

    def _hold(self, engine, k: int, task) -> None:
        """A robot program's hook while a motion is made at the stop: its cycles go by, it does not run."""
        if task is engine.stop_task or getattr(task, "kind", None) != "robot":
            return
        sched = self.runs[k].runtime.scheduler
        while self.holding:
            sched.yield_cycle()

    def _hooks(self, engine, k: int) -> None:
        def wrap(fn):
            def hook(*args):
                if self.holding:
                    self._hold(engine, k, args[0])
                self.use(engine, k)
                return fn(*args)
            return hook
        self.runs[k].runtime.stepping.set_hooks(stmt=wrap(engine.on_statement), step=wrap(engine.on_step_stop),
                                                error=wrap(engine.on_error), cycle=wrap(engine.on_cycle))

    def run(self, engine, terminate) -> None:
        """Run the cell under `engine` to its end (or `terminate`, the engine's exception):
        its summary as output, then ``exited`` with the cell's exit code (krl run's)."""
        for k in range(len(self.runs)):
            self._hooks(engine, k)
            if engine.on_runtime is not None:
                engine.on_runtime(self.runs[k].runtime)
        self.use(engine, 0)
        engine.state = "running"
        try:
            res = run_cell(self.cell, self.runs)
        except terminate:
            engine.state = "ended"
            engine.emit("terminated")
            return
        engine.state = "ended"
        self.result = res
        for line in summary_lines(res, self.path.parent):
            engine.output(line)
        engine.emit("exited", {"exitCode": res.exit_code})
        engine.emit("terminated")


__all__ = ["CellDebug", "NO_REVERSE", "STRIDE", "is_cell_launch"]
