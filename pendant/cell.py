"""The pendant on a cell of several robots (issue 89; docs/pendant.md, "A cell of several robots"):
``krl pendant CELL.yaml`` runs the cell on the pendant's one engine (pendant/engine.py, the debug
engine's run of a cell: interp/debug/cellrun.py, every robot's program on one IPO clock, the
wires, the zones, the collisions), paced to the wall clock unless ``--no-realtime``. The page
chooses a robot (``chooseRobot``); its program view, pointers, I/O, position, watch list and
the single robot's keys are then that robot's: the same handlers as for one robot
(pendant/server.py ``OPERATIONS``) acting on the engine pointed at the chosen robot
(``Engine.focus``). The 3D view draws every robot at its ``base`` moving together.

Per robot (each has its own controller): the operating mode, the run mode, the drives, the
workspace that breakpoints, touch-up and the files opened must lie in (its ``workspace``, else
its backup, else its program's folder). For the whole cell: Select is the cell file (the
cell's run stops at the first robot's first statement, as one robot's does), Start resumes every
robot (each robot's drives must be on), Stop stops the cell in the chosen robot's program, a
stop stops every robot (the cell's one clock stands). A jog, touch-up or an assignment at a stop
acts on the chosen robot wherever the cell stopped (interp/debug/cellrun.py: the other robot
programs hold while it moves); a backward motion needs the stop in the chosen robot's program.
"""

from __future__ import annotations

import asyncio
import json
from pathlib import Path

from interp.robotcell import load_robot_cell
from interp.run import robot_for
from krl.limits import MAX_WEB_WATCHES
from krl.project import backup_of

from .engine import MODES_OP, RUN_MODES, EngineError
from .server import Pendant
from .view import robot_view


def _root(robot) -> Path:
    """Where a robot's files lie for the keys that name one (breakpoint, touch-up, open)."""
    if robot.workspace is not None:
        return robot.workspace
    if robot.program.is_dir():
        return robot.program
    return backup_of(robot.program) or robot.program.parent


class CellPendant(Pendant):
    """:class:`pendant.server.Pendant` serving a cell of several robots (module docstring): the
    same page, connections, limits and keys; the cell's run on its engine, per chosen robot."""

    def __init__(self, cell_file: Path, *, realtime: bool = True, interp: str = "vm") -> None:
        self.cell_file = Path(cell_file)
        self.cell = load_robot_cell(self.cell_file)
        self.chosen = self.cell.robots[0].name
        #: per robot: its mode, run mode, drives, workspace and (once selected) program
        self._per = {r.name: {"mode": "AUT", "run_mode": "GO", "drives": False, "root": _root(r), "program": None}
                     for r in self.cell.robots}
        self._selected = False
        super().__init__(self.cell_file.parent, realtime=realtime, shown_root=str(self.cell_file),
                         program=str(self.cell_file))
        self.interp = interp
        self.engine.focus = 0
        self._views: list | None = None

    # ------------------------------------------------------------------ the chosen robot's
    def _of(self, key: str):
        return self._per[self.chosen][key]

    mode = property(lambda self: self._of("mode"), lambda self, v: self._set("mode", v))
    run_mode = property(lambda self: self._of("run_mode"), lambda self, v: self._set("run_mode", v))
    drives = property(lambda self: self._of("drives"), lambda self, v: self._set("drives", v))
    #: the chosen robot's workspace (Pendant.__init__'s assignment is the cell file's folder: kept apart)
    root = property(lambda self: self._of("root"), lambda self, v: setattr(self, "_cell_root", v))

    @property
    def program(self) -> str | None:
        """The chosen robot's program once the cell is selected (the cell's run is built)."""
        return self._of("program") if self._selected else None

    @program.setter
    def program(self, value) -> None:
        self._selected = value is not None

    def _set(self, key: str, value) -> None:
        if hasattr(self, "_per"):
            self._per[self.chosen][key] = value

    def _need_drives(self, start: bool = False) -> None:
        """The chosen robot's drives; Start moves every robot: each robot's drives."""
        off = [n for n, p in self._per.items() if not p["drives"]] if start else \
            ([self.chosen] if not self.drives else [])
        if off:
            raise EngineError(f"the drives of {', '.join(off)} are off: choose the robot and switch them on first")

    # ------------------------------------------------------------------ static data
    def robot(self) -> dict:
        return self.views()[0]

    def views(self) -> list[dict]:
        """Every robot as the page draws it (pendant/view.py ``robot_view``: its machine data, its
        own cell file's bodies) with its ``base`` in the cell's world and its program."""
        if self._views is None:
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

    # ------------------------------------------------------------------ the cell's own keys
    async def handle(self, ws, msg: dict) -> None:
        """The cell's keys (hello, select, chooseRobot); every other key is one robot's
        (pendant/server.py), acting on the chosen robot."""
        op = msg.get("op")
        if op == "hello":
            await ws.send_text(json.dumps({"type": "init", "workspace": self.shown_root, "programs": [],
                                           "modules": [], "robot": self.robot(), "modes": MODES_OP,
                                           "runModes": RUN_MODES, "readonly": False,
                                           "cell": {"robots": self.views(), "chosen": self.chosen}}, default=str))
            if self.program is not None:
                await self.send_module(ws, self.program)
        elif op == "select":
            await self.select(str(self.cell_file))
        elif op == "chooseRobot":
            names = [r.name for r in self.cell.robots]
            if msg.get("robot") not in names:
                raise EngineError(f"no robot {str(msg.get('robot'))[:40]!r} in the cell")
            self.chosen = msg["robot"]
            self.engine.focus = names.index(self.chosen)
            # its state first: the page follows its pointers, not the last robot's, into its program
            await self.push_state()
            if self.program is not None:
                await self.broadcast_module(self.program)
            return
        else:
            return await Pendant.handle(self, ws, msg)
        await self.push_state()

    async def select(self, program: str) -> None:
        """Select the cell (whatever `program`: a cell runs its robots' own): its run is built and
        stops at the first robot's first statement; each robot's mode is its run's."""
        loop = asyncio.get_running_loop()
        await self.broadcast({"type": "event", "event": "selecting", "body": {"program": str(self.cell_file)}})
        bps = {p: sorted(v) for p, v in self.breakpoints.items()}
        await loop.run_in_executor(None, lambda: self.engine.select(
            str(self.cell_file), workspace=None, inputs=None, mode=None, run_mode="GO", trace=None,
            breakpoints=bps, interp_kind=self.interp))
        runs = await self.engine.do_async(lambda core: [
            (r.name, str(r.runtime.program.main_path), r.runtime.mode_op, r.runtime.stepping.run_mode)
            for r in core.cell.runs])
        for name, path, mode, run_mode in runs:
            self._per[name].update(program=path, mode="EXT" if mode == "EX" else mode, run_mode=run_mode, drives=False)
        self.program = str(self.cell_file)
        await self.broadcast_module(self.program)

    async def state(self, fresh: dict | None = None) -> dict:
        """The chosen robot's state (pendant/server.py), with the cell's robots and, once the
        cell has ended, how it ended (each robot's end, the collisions)."""
        s = await super().state(fresh)
        s["cell"] = {"chosen": self.chosen, "robots": [r.name for r in self.cell.robots]}
        core = self.engine.core
        res = core.cell.result if core is not None and core.cell is not None else None
        if s.get("state") == "ended" and res is not None:
            text = "; ".join(f"{r.name} {r.runtime.result.reason}" for r in res.robots)
            text += "".join(f"; collision {c}" for c in res.collisions)
            s["outcome"] = {"reason": res.reason, "text": text[:MAX_WEB_WATCHES * 50], "path": None, "line": None}
        return s


__all__ = ["CellPendant"]
