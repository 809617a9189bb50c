"""A cell of several robots (issue 89; docs/cells.md): each robot runs its own program on its own
controller (its machine data, its cell file, its submit interpreter), the robots are wired output
to input, and all run on one IPO clock.

The cell file (YAML, read by robot/stimuli.py ``read_cell_yaml``; docs/schemas/robot-cell.schema.json)::

    robots:
      R1: {program: handler/KRC/R1/Program/main.src, workspace: handler, inputs: r1.yaml}
      R2: {program: palletizer}          # a backup folder: its cell program
    wires:
      - R1 $OUT[10] -> R2 $IN[10]
      - R2 $OUT[11] -> R1 $IN[11]

Paths are relative to the cell file. A robot's keys: ``program`` (a ``.src``, or a backup folder
or archive: its cell program, as ``krl run`` takes it), ``workspace`` (the backup the program
belongs to), ``inputs`` (that robot's own cell file: stimuli, rules, its PLC; or ``auto``: the automatic
cell answers the inputs no wire drives, :func:`wired_inputs`), ``no_submit``
(true: without the backup's SPS.SUB). Limits: :data:`krl.limits.MAX_CELL_ROBOTS` robots,
:data:`krl.limits.MAX_CELL_WIRES` wires; an input is driven by one wire at most.

**One clock.** Every IPO cycle each robot's run takes its cycle (interp/runtime/core.py
``run_cycles``), in the order the file names them; then each wire carries its output's value
to its input. So a value written in cycle k is read from cycle k + 1 on: one IPO cycle (12 ms) of
latency between two controllers, the order of the robots in the file changing nothing. KUKA
publishes no figure for the latency of an I/O link between two controllers, and a signal
written by the program is sent at the end of the interpreter's cycle, so one IPO cycle is the
decision (docs/cells.md). A clock jump or an idle skip of a single run (interp/runtime/jump.py,
idle.py) is offered to the cell: the robots jump together, by the shortest span every one of
them offers, or not at all (no task runs in a jumped cycle, so no output, and no wire, changes).

**Deadlock.** A robot's own deadlock (its program waits in WAIT FOR and nothing of its own
controller can change: interp/runtime/scheduler.py ``Scheduler.deadlocked``) does not end it in a
cell: a partner may still set the input. The cell deadlocks when every robot still running is so
blocked for two cycles in a row with no wire changing an input; each such robot's run then ends
``deadlock``, naming its own wait and every other robot's (file:line).

**RoboTeam.** Robot k of the file is robot k of a ``$SYNC_LIST``; after each cycle the robots
waiting at a synchronised motion whose partners all wait at the same ``$SYNC_ID`` are released
(interp/cellsync.py) and start in the next cycle; a release counts as a change for the deadlock
test, and a sync wait is named like a WAIT FOR (interp/runtime/teamsync.py).

Raises :class:`CellError` for a cell file that does not make a cell (file:line).
"""

from __future__ import annotations

import contextlib
import os
from functools import partial
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

from interp.run import RunSetupError, RunSinks, make_runtime, run_setup
from interp.runtime.core import run_cycles
from interp.runtime.scheduler import RAN
from interp.cellplc import PLC, CellPlc, parse_plc
from interp.cellsync import join_team, release_synced
from interp.cellturns import TURN_CYCLES, TURN_CYCLES_MAX, WiredTurns, plain, take_turns, uncoupled, wired
from interp.cellcontacts import Collision, ContactWatch
from interp.cellworkspaces import WorkspaceWatch
from interp.cellzones import Conflict, Zone, ZoneWatch, numbers, parse_zones
from krl.limits import MAX_CELL_ROBOTS, MAX_CELL_RULES, MAX_CELL_WIRES, MAX_CELL_ZONES
from krl.terminal import printable
from robot.stimuli import StimulusError, read_cell_yaml

#: a wire: ``R1 $OUT[10] -> R2 $IN[10]``
_WIRE = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]{0,31})\s+\$OUT\[\s*(\d+)\s*\]\s*->\s*"
                   r"([A-Za-z_][A-Za-z0-9_]{0,31})\s+\$IN\[\s*(\d+)\s*\]\s*$", re.IGNORECASE)
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,31}$")
_ROBOT_KEYS = ("program", "workspace", "inputs", "no_submit", "base")
_CELL_KEYS = ("robots", "wires", "zones", "plc")
#: cycles every running robot must stay blocked, no wire changing, before the cell deadlocks
BLOCKED_CYCLES = 2


class CellError(ValueError):
    """A cell file of several robots that does not make a cell; the message names file:line."""


@dataclass(frozen=True)
class Wire:
    """``source`` robot's ``$OUT[output]`` drives ``target`` robot's ``$IN[input]``."""
    source: str
    output: int
    target: str
    input: int

    def __str__(self) -> str:
        return f"{self.source} $OUT[{self.output}] -> {self.target} $IN[{self.input}]"

    @property
    def label(self) -> str:
        """The source of the input changes it makes (robot/io.py ``set_in``): ``wire R1 $OUT[10]``."""
        return f"wire {self.source} $OUT[{self.output}]"


@dataclass(frozen=True)
class CellRobot:
    """One robot of the cell: its ``name`` and what ``krl run`` would be given for it."""
    name: str
    program: Path
    workspace: Path | None = None
    inputs: Path | str | None = None    # a cell file, or "auto"
    no_submit: bool = False
    #: its robot root in the cell's world (X, Y, Z mm, A, B, C deg; interp/cellzones.py)
    base: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@dataclass(frozen=True)
class RobotCell:
    """A cell file of several robots, read (module docstring)."""
    source: Path
    robots: tuple[CellRobot, ...]
    wires: tuple[Wire, ...]
    zones: tuple[Zone, ...] = ()
    #: the PLC between the robots (interp/cellplc.py), None without ``plc:``
    plc: CellPlc | None = None


#: the document :func:`is_robot_cell` last found a cell in, kept for :func:`load_robot_cell` to
#: take once: ``[(the file's key (:func:`_file_key`), document)]`` (``krl run CELL`` asks both of
#: the same file: one YAML parse where two were made before 2026-11-29, 3 ms each for a cell of
#: four robots); a file changed in between has another key and is read again
_FOUND: list = []


def _file_key(path: Path) -> tuple:
    """What tells the file `path` apart from itself changed: its absolute path, device, inode,
    size and modification and change times (ns). Raises OSError for a file it cannot stat."""
    st = path.stat()
    return str(path.absolute()), st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns


def is_robot_cell(path: Path) -> bool:
    """True when `path` is a YAML file whose document has a ``robots:`` key (a cell of several
    robots, not a program or one robot's cell file); reads it only when it ends .yaml/.yml."""
    if path.suffix.lower() not in (".yaml", ".yml") or not path.is_file():
        return False
    try:
        key = _file_key(path)
        doc = read_cell_yaml(path)
    except (StimulusError, OSError):
        return False
    found = isinstance(doc, dict) and "robots" in doc
    _FOUND[:] = [(key, doc)] if found else []
    return found


def _cell_yaml(path: Path):
    """The document of the cell file `path`: the one :func:`is_robot_cell` just read of the same
    file unchanged, taken (once), else read (robot/stimuli.py ``read_cell_yaml``; its errors)."""
    try:
        key, doc = _FOUND.pop()
    except IndexError:
        key = doc = None
    try:
        if key is not None and key == _file_key(path):
            return doc
    except OSError:
        pass
    return read_cell_yaml(path)


def _at(source: Path, obj, key=None) -> str:
    lines = getattr(obj, "key_lines", {})
    line = lines.get(key) if key is not None else None
    line = line or getattr(obj, "line", 0)
    return f"{printable(source)}:{line}" if line else printable(source)


def _path(base: Path, value, where: str, what: str) -> Path:
    if not isinstance(value, str) or not value.strip():
        raise CellError(f"{where}: '{what}' is a path (a string)")
    p = Path(os.path.normpath(base.absolute() / value))
    if not p.exists():
        raise CellError(f"{where}: {what} {printable(value)}: no such file or folder")
    return p


def _robot(source: Path, name, body) -> CellRobot:
    where = _at(source, body)
    if not isinstance(name, str) or not _NAME.match(name):
        raise CellError(f"{where}: robot name {printable(name)!s}: letters, digits and _, at most 32")
    if not isinstance(body, dict):
        raise CellError(f"{where}: robot {name}: a mapping with 'program'")
    unknown = [k for k in body if k not in _ROBOT_KEYS]
    if unknown:
        raise CellError(f"{_at(source, body, unknown[0])}: robot {name}: unknown key {printable(unknown[0])!s} "
                        f"(known: {', '.join(_ROBOT_KEYS)})")
    if "program" not in body:
        raise CellError(f"{where}: robot {name}: 'program' is missing")
    base = source.parent
    ws = body.get("workspace")
    inputs = body.get("inputs")
    no_submit = body.get("no_submit", False)
    if not isinstance(no_submit, bool):
        raise CellError(f"{_at(source, body, 'no_submit')}: robot {name}: no_submit is true or false")
    root = numbers(body["base"], 6, _at(source, body, "base"), f"robot {name}'s base [X, Y, Z, A, B, C]",
                   CellError) if "base" in body else CellRobot.base
    return CellRobot(name, _path(base, body["program"], _at(source, body, "program"), "program"),
                     _path(base, ws, _at(source, body, "workspace"), "workspace") if ws is not None else None,
                     _inputs(base, inputs, _at(source, body, "inputs")),
                     no_submit, root)


def _inputs(base: Path, value, where: str) -> Path | str | None:
    """A robot's ``inputs``: its cell file's path, ``"auto"`` (the automatic cell answers what no
    wire drives: :func:`wired_inputs`) or None."""
    if value is None or value == "auto":
        return value
    return _path(base, value, where, "inputs")


def wired_inputs(cell: "RobotCell", name: str) -> tuple[int, ...]:
    """The ``$IN`` numbers of robot `name` that a wire of `cell` drives, sorted: its partners' to
    set, so the automatic cell of that robot (``inputs: auto``, interp/runtime/autocell.py)
    neither gives nor answers them."""
    return tuple(sorted({w.input for w in cell.wires if w.target == name}))


def _wires(source: Path, doc, names: set[str]) -> tuple[Wire, ...]:
    items = doc.get("wires", [])
    if not isinstance(items, list):
        raise CellError(f"{_at(source, doc, 'wires')}: 'wires' is a list of 'R1 $OUT[n] -> R2 $IN[m]'")
    if len(items) > MAX_CELL_WIRES:
        raise CellError(f"{_at(source, doc, 'wires')}: {len(items)} wires, more than the limit of {MAX_CELL_WIRES}")
    wires, driven = [], {}
    for k, text in enumerate(items):
        where = f"{_at(source, doc, 'wires')} (wire {k + 1})"
        m = _WIRE.match(text) if isinstance(text, str) else None
        if m is None:
            raise CellError(f"{where}: {printable(text)!s}: a wire is 'R1 $OUT[n] -> R2 $IN[m]'")
        w = Wire(m[1], int(m[2]), m[3], int(m[4]))
        for robot in (w.source, w.target):
            if robot not in names:
                raise CellError(f"{where}: {w}: no robot {robot} in 'robots'")
        if w.source == w.target:
            raise CellError(f"{where}: {w}: a wire joins two robots")
        if (w.target, w.input) in driven:
            raise CellError(f"{where}: {w}: {w.target} $IN[{w.input}] is driven by {driven[w.target, w.input]} already")
        driven[w.target, w.input] = w
        wires.append(w)
    return tuple(wires)


def load_robot_cell(path: Path) -> RobotCell:
    """The cell of several robots in the YAML file `path` (module docstring). Raises
    :class:`CellError` (file:line) for one that does not make a cell."""
    path = Path(path)
    try:
        doc = _cell_yaml(path)
    except StimulusError as exc:
        raise CellError(str(exc)) from None
    if not isinstance(doc, dict) or not isinstance(doc.get("robots"), dict) or not doc["robots"]:
        raise CellError(f"{printable(path)}: a cell of several robots has 'robots:', a mapping of name to robot")
    unknown = [k for k in doc if k not in _CELL_KEYS]
    if unknown:
        raise CellError(f"{_at(path, doc, unknown[0])}: unknown key {printable(unknown[0])!s} "
                        f"(known: {', '.join(_CELL_KEYS)})")
    if len(doc["robots"]) > MAX_CELL_ROBOTS:
        raise CellError(f"{_at(path, doc, 'robots')}: {len(doc['robots'])} robots, more than the limit of "
                        f"{MAX_CELL_ROBOTS}")
    robots = tuple(_robot(path, name, body) for name, body in doc["robots"].items())
    plc = parse_plc(doc, lambda obj, key=None: _at(path, obj, key), MAX_CELL_RULES, CellError)
    names = {r.name for r in robots}
    if plc is not None and PLC in names:
        raise CellError(f"{_at(path, doc['robots'], PLC)}: robot {PLC}: {PLC} is the cell's PLC (plc:), not a robot")
    return RobotCell(path, robots, _wires(path, doc, names | ({PLC} if plc is not None else set())),
                     parse_zones(doc, lambda obj, key: _at(path, obj, key), MAX_CELL_ZONES, CellError), plc)


@dataclass
class RobotRun:
    """One robot's run in the cell: its ``runtime`` (interp/runtime/core.py Runtime), the time
    it waited in WAIT FOR (``waited``, s) and, per wait that a wire ended, who released it
    (``released``: (wait text, seconds, the wire))."""
    name: str
    runtime: object
    waited: float = 0.0
    released: list = field(default_factory=list)


@dataclass
class CellResult:
    """How the cell ended: ``reason`` (completed when every robot's program completed,
    else deadlock, error, halt or a limit: the first robot's that is not completed), the
    simulated ``time`` (s), each robot's :class:`RobotRun` (its runtime's ``result``), the
    conflicts in the cell's zones (interp/cellzones.py) and between the robots' own workspaces
    (interp/cellworkspaces.py), in the order they began, and the collisions between robots
    (interp/cellcontacts.py)."""
    reason: str
    time: float
    robots: list[RobotRun]
    conflicts: list[Conflict] = field(default_factory=list)
    collisions: list[Collision] = field(default_factory=list)
    #: each robot's base in the cell's world (X, Y, Z mm, A, B, C deg)
    bases: dict = field(default_factory=dict)
    #: the cell's PLC (interp/cellplc.py: its ``io.log``), None without one
    plc: CellPlc | None = None

    def as_json(self) -> dict:
        """The cell's JSON result (docs/schemas/cell-result.schema.json): how it ended, each
        robot's base and end (reason, file, line, time, its time in WAIT FOR), the zones' conflicts and
        the collisions between robots, the PLC's I/O changes when the cell has one (times in s)."""
        return {"reason": self.reason, "time": round(self.time, 6),
                "robots": [{"name": r.name, "base": list(self.bases.get(r.name, (0.0,) * 6)),
                            "reason": r.runtime.result.reason, "file": r.runtime.result.file,
                            "line": r.runtime.result.line, "time": round(r.runtime.result.sim_time, 6),
                            "waited": round(r.waited, 6)} for r in self.robots],
                "conflicts": [{"zone": c.zone, "time": round(c.time, 6),
                               "robots": [{"robot": x[0], "motion": x[1]} for x in (c.first, c.second)]}
                              for c in self.conflicts],
                "collisions": [c.as_json() for c in self.collisions],
                **({"plc": [{"time": round(t, 6), "signal": name, "value": v, "source": src}
                            for t, name, v, src in self.plc.io.log]} if self.plc is not None else {})}

    @property
    def exit_code(self) -> int:
        """krl run's exit code of the cell: the worst of the robots' (1 error, 3 stopped, 0 completed)."""
        codes = [r.runtime.result.exit_code for r in self.robots]
        return 1 if 1 in codes else max(codes)


def robot_trace(trace: Path, name: str) -> Path:
    """The trace of robot `name` of a cell run with ``--trace`` `trace`: one stream per robot,
    ``run.jsonl`` -> ``run.R1.jsonl``."""
    return trace.with_name(f"{trace.stem}.{name}{trace.suffix}")


def cell_result_path(trace: Path) -> Path:
    """Where a cell run with ``--trace`` `trace` writes its JSON result (:meth:`CellResult.as_json`):
    ``run.jsonl`` -> ``run.cell.json``, beside the robots' streams."""
    return trace.with_name(f"{trace.stem}.cell.json")


def _options(robot: CellRobot, interp: str, max_sim_time: float, trace: Path | None) -> dict:
    return {"program": robot.program, "workspace": robot.workspace, "inputs": robot.inputs,
            "no_submit": robot.no_submit, "interp_kind": interp, "max_sim_time": max_sim_time,
            "trace_path": robot_trace(trace, robot.name) if trace is not None else None}


@contextlib.contextmanager
def cell_runs(cell: RobotCell, interp: str = "vm", max_sim_time: float = 600.0, trace: Path | None = None,
              **fields):
    """The runs of `cell`'s robots, built (interp/run.py ``run_setup``, ``make_runtime``) and not
    started: a list of :class:`RobotRun` for the ``with`` block (a backup archive stays extracted
    meanwhile; each robot's trace, :func:`robot_trace` of `trace`, is closed at its end).
    `fields`: RunSpec fields for every robot (a test's ``mujoco=False``). Raises
    :class:`CellError` for a robot whose run cannot be set up (naming the robot), OSError for a
    trace that cannot be written."""
    with contextlib.ExitStack() as stack:
        runs = []
        for robot in cell.robots:
            try:
                setup = stack.enter_context(run_setup(_options(robot, interp, max_sim_time, trace)))
            except RunSetupError as exc:
                raise CellError(f"{printable(cell.source)}: robot {robot.name}: {exc}") from None
            writer = setup.trace_writer()
            if writer is not None:
                stack.callback(writer.close)
            rt, _ = make_runtime(setup.spec.with_(wired=wired_inputs(cell, robot.name), **fields),
                                 RunSinks(trace=writer))
            # a deadlock is the cell's to decide, and a clock jump or the idle watch's skip
            # (interp/runtime/idle.py) would move this robot's clock alone: offered to the cell
            rt.scheduler.hold()
            runs.append(RobotRun(robot.name, rt))
        yield runs


def summary_lines(res: CellResult, folder: Path | None = None) -> list[str]:
    """What ``krl run CELL`` prints: one line for the cell, one per robot (how it ended, where,
    when; the time it waited in WAIT FOR and, for each wait a partner ended, who released it);
    the files under `folder` (the cell file's) named relative to it."""
    out = [f"cell       {len(res.robots)} robots: {res.reason} at {res.time:.3f} s"]
    if folder is not None:
        prefix = str(Path(os.path.normpath(folder.absolute()))) + os.sep
        return [line.replace(prefix, "") for line in summary_lines(res)]
    for r in res.robots:
        e = r.runtime.result
        where = f" at {e.file}:{e.line}" if e.file else ""
        out.append(f"{r.name:<10} {e.reason}{where} ({e.sim_time:.3f} s){': ' + e.text if e.text else ''}")
        out.append(f"{'':<10} waited {r.waited:.3f} s in WAIT FOR")
        for text, seconds, wires in r.released:
            out.append(f"{'':<10}   {seconds:.3f} s {text}, released by {', '.join(map(str, wires))}")
    out.extend(f"conflict   {c}" for c in res.conflicts)
    out.extend(f"collision  {c}" for c in res.collisions)
    return out


def run_cell(cell: RobotCell, runs: list[RobotRun]) -> CellResult:
    """Run `runs` (:func:`cell_runs` of `cell`) on one IPO clock to their ends (module
    docstring): the cell's result."""
    ios = {r.name: r.runtime.controller.io for r in runs}
    plc = cell.plc
    if plc is not None:
        ios[PLC] = plc.io
    wires = [(ios[w.source], w, ios[w.target]) for w in cell.wires]
    # each running robot: (its RobotRun, its cycles, its robot program's task)
    live = [(r, run_cycles(r.runtime), r.runtime.robot) for r in runs]
    ctls = [r.runtime.controller for r in runs]
    named = {r.name: c for r, c in zip(runs, ctls)}     # each robot's controller
    waits: dict[str, tuple[str, float] | None] = {r.name: None for r in runs}
    old = sys.getrecursionlimit()
    sys.setrecursionlimit(max(old, 20000))
    blocked_for, changed, synced = 0, [], []
    zones, workspaces, team, contacts = _watches(cell, runs)
    # what a cycle checks: the zones only when the cell has some, the contacts only when two
    # robots are within reach of each other (a robot's own workspaces may appear any time)
    checks = [zones.check] if cell.zones else []
    turns = uncoupled(cell, runs)               # its robots may take turns (interp/cellturns.py)
    wiring = WiredTurns(cell.wires) if not turns and wired(cell, runs) else None  # or wired turns
    # in a turn and catching up, poses are kept for the contact check (interp/cellcontacts.py)
    record, keeper = (contacts.record, contacts.keeper) if (turns or wiring is not None) \
        and contacts.scene is not None else (None, None)
    ended: dict[str, int] = {}                  # robots that ended in a turn: their last cycle
    # the last cycle's offers (any; every running robot's: a jump); robots past the cycle
    offered, every, ahead = True, True, set()
    # robots that stopped their turn at an offer to jump: the offer, answered with the others' cycle
    pending, turn = {}, TURN_CYCLES             # (and the next turn's cycles)
    try:
        while live:
            went = None
            if turns and not (ahead or pending or offered) and all(plain(item[0]) for item in live):
                went = take_turns(live, turn, ended, partial(_turn_watch, waits, keeper), pending)
            elif wiring is not None and not (ahead or pending or every or changed or synced):
                # no input changed at this boundary: each robot's blocked state still holds
                went = wiring.take(live, turn, ended, partial(_turn_watch, waits, keeper), pending)
            if went is not None:
                live = went
                kept = True     # this cycle ran in a turn (or catching up, below): its poses kept
                if not live:
                    break
                # the cycle the robots furthest behind stand at, read with the others past it
                x = min(item[0].runtime.controller.cycle for item in live)
                ahead = _past(live, ended, x)
                # every robot ran through: the next turn twice as long; one cut short: the first length
                turn = min(2 * turn, TURN_CYCLES_MAX) if not ahead and not pending else TURN_CYCLES
            else:
                kept = bool(ahead)
                live, ahead, x, offers = _cycle(live, ahead, ended, (bool(ahead) or (plc is not None and plc.busy()),
                                                                     pending), record, waits, (changed, synced))
                offered, every = offers > 0, offers == len(live) > 0
            # the poses this cycle reached: stamped as each robot's trace stamps them, at the cycle's end
            # (its own $WORKSTATEn changes then too); the PLC's inputs the wires set now, and its scan, too
            reached = max([c.time for c in ctls if c.cycle <= x]) if ahead else max([c.time for c in ctls])
            # a robot standing at its offer is read as the plain robot it was in the cycle before
            past = ahead | set(pending) if pending else ahead
            if plc is not None:
                plc.io.now = reached
            # a wire from a robot ahead (or ended after this cycle) is carried when this cycle reaches it
            changed = _carry(wires, past, x, wiring, named) if wires else []
            if plc is not None:
                plc.scan(reached, runs[0].runtime.controller.dt)
            synced = release_synced(runs, team, past)
            workspaces.check(reached, past)
            for check in checks:
                check(reached)
            contacts.after(reached, kept, bool(ahead))
            if live and not past and not changed and not synced and not (plc is not None and plc.busy()) \
                    and all(r.runtime.scheduler.blocked for r, _, _ in live):
                blocked_for += 1
                if blocked_for >= BLOCKED_CYCLES:
                    _deadlock([r for r, _, _ in live], cell.wires, runs)
            else:
                blocked_for = 0
    finally:
        sys.setrecursionlimit(old)
    contacts.flush()        # the poses kept in a turn in which the last robots ended
    return _result(cell, runs, waits, (zones, workspaces, contacts))


def _cycle(live: list, ahead: set, ended: dict, step: tuple, record, waits: dict, last: tuple) -> tuple:
    """One cycle of the cell taken cycle by cycle (:func:`run_cell`), or, with robots `ahead`,
    the cycle of the robots furthest behind (catching up; `ended`: the robots that ended in a
    turn). `step`: (hold, pending) for :func:`_step`; `record`: the contact watch's, keeping each
    pose while catching up (or None); `waits` the WAIT FOR bookkeeping, given `last` (the wires
    that changed an input and the robots released together at the last boundary). Returns (the
    robots still running, the robots past the cycle taken, that cycle, how many robots offered)."""
    if ahead:       # catching up: the robots furthest behind take their cycle
        x = min(item[0].runtime.controller.cycle for item in live)
        here = [item for item in live if item[0].runtime.controller.cycle == x]
    else:
        here = live
    now = here[0][0].runtime.controller.time     # this cycle's time, every robot's
    going, offers = _step(here, *step)
    for item in here:
        if ahead and record is not None:
            record(item[0])
        if item[2].waiting is not None or waits[item[0].name] is not None:
            # the inputs this cycle read: the last cycle's wires; its synchronised motions
            _count_wait(item, waits, *last, now)
    if not ahead:
        return going, ahead, max(item[0].runtime.controller.cycle for item in going) if going else 0, offers
    gone = {id(item) for item in here} - {id(item) for item in going}
    live = [item for item in live if id(item) not in gone]
    x = max(item[0].runtime.controller.cycle for item in here)
    return live, _past(live, ended, x), x, offers


def _result(cell: RobotCell, runs: list[RobotRun], waits: dict, watches: tuple) -> CellResult:
    """The cell's result once `runs` have ended: a wait a run ended in counted to its end; the
    conflicts of the zones and workspaces and the collisions of `watches` (zones, workspaces,
    contacts)."""
    zones, workspaces, contacts = watches
    for r in runs:
        if waits[r.name] is not None:
            r.waited += r.runtime.controller.time - waits[r.name][1]
    ends = [r.runtime.result for r in runs]
    first = next((e for e in ends if e.reason != "completed"), None)
    conflicts = sorted(zones.conflicts + workspaces.conflicts, key=lambda c: c.time)
    return CellResult(first.reason if first is not None else "completed", max(e.sim_time for e in ends), runs,
                      conflicts, contacts.collisions, {r.name: r.base for r in cell.robots}, cell.plc)


def _watches(cell: RobotCell, runs: list[RobotRun]) -> tuple:
    """The cell's watches of `runs`: its zones, the robots' own workspaces, the RoboTeam (robot k
    of the file is robot k of a ``$SYNC_LIST``) and the contacts between the robots."""
    bases = {r.name: r.base for r in cell.robots}
    return (ZoneWatch(cell.zones, runs, bases), WorkspaceWatch(runs, bases), join_team(runs),
            ContactWatch(runs, bases))


def _step(live: list, hold: bool = False, pending: dict | None = None) -> tuple[list, int]:
    """One IPO cycle of every run of `live` ((RobotRun, its cycles, ...), in the cell's order), or a
    jump of all; the runs not ended. A run that offers to advance several cycles at once (a clock
    jump or the idle watch's skip: ``Scheduler.cycles``) waits for the others: when every run
    offers and not every run is blocked (the cell's deadlock test needs their cycles), each
    advances the shortest offer, all staying on one clock; else each takes an ordinary cycle.
    `hold`: no jump (the cell's PLC has an answer pending: it scans every cycle; robots are
    catching up with others past them). `pending`: the offers of runs that stopped their turn
    at one (interp/cellturns.py), taken for their next. Returns (the runs not ended, how many runs
    offered)."""
    going, offers = [], None
    for item in live:
        try:
            offer = pending.pop(item[0].name) if pending and item[0].name in pending else next(item[1])
        except StopIteration:
            continue
        going.append(item)
        if offer is not None and offer is not RAN:
            if offers is None:
                offers = []
            offers.append((offer, item))
    if offers:
        jump = min(o for o, _ in offers) if len(offers) == len(going) and not hold \
            and not all(item[0].runtime.scheduler.blocked for item in going) else 0
        for _, item in offers:
            try:
                item[1].send(jump)
            except StopIteration:
                going.remove(item)
    return going, len(offers) if offers else 0


def _turn_watch(waits: dict, keeper, item) -> tuple:
    """What the cell does after each of robot `item`'s cycles in its turn (interp/cellturns.py
    ``take_turns``): ``(wait, keep)``, its WAIT FOR bookkeeping (:func:`_count_wait` after the
    cycle that began at `t` s; True while its wait is counted) and its cycle kept for the
    contact check (`keeper(run)`'s parts, or None without a `keeper`)."""
    r = item[0]
    name = r.name

    def wait(t: float, changed: list) -> bool:
        _count_wait(item, waits, changed, [], t)
        return waits[name] is not None
    return wait, (keeper(r) if keeper is not None else None)


def _past(live: list, ended: dict, x: int) -> set:
    """The names of the robots past cycle `x`: running ahead of it, or ended in a turn at or
    after it (interp/cellturns.py: each was plain in cycle `x`). A robot whose controller ended
    at cycle `last` took its last cycle to `last`: cycle by cycle it is still running when the
    others reach `last`, and ends in the step after (before 2026-11-28 it counted as gone at
    `last`, and a partner blocked in WAIT FOR was deadlocked one cycle early)."""
    return {item[0].name for item in live if item[0].runtime.controller.cycle > x} | \
        {name for name, last in ended.items() if last >= x}


def _count_wait(item, waits: dict, changed: list, synced: list, now: float) -> None:
    """The cell's WAIT FOR bookkeeping of robot `item` ((RobotRun, cycles, task)) after its cycle
    that began at `now` (s): :func:`_watch_wait`, with the wires that changed its inputs for the
    cycle and the robots its synchronised motion was released with."""
    r, _, task = item
    if task.waiting is None and waits[r.name] is None:
        return              # not waiting, before or now: nothing to count
    _watch_wait(r, waits, changed + [f"{o.name} (same $SYNC_ID)" for o in synced if o is not r]
                if synced and any(o is r for o in synced) else changed, now)


def _carry(wires, ahead: set, x: int = 0, wiring=None, ctls=None) -> list[Wire]:
    """Each wire's output to its input, where they differ, after cycle `x`, but for a wire from a
    robot of `ahead` (its output is of a later cycle), unless that robot stands past `x` (the
    cycle of its controller in `ctls`, robot -> controller) and `wiring` (interp/cellturns.py
    WiredTurns, or None) logged its outputs in its turn: then its output's value after `x`. (A
    wire's target never stands past its source's changes: WiredTurns bounds it by them.) The
    wires that changed one."""
    changed = []
    for source, wire, target in wires:
        if ahead and wire.source in ahead:
            if wiring is None or ctls[wire.source].cycle <= x:
                continue
            value = wiring.logged(wire, x)
            if value is None:
                continue
        else:
            value = source.get_out(wire.output)
        if target.get_in(wire.input) != value:
            target.set_in(wire.input, value, source=wire.label)
            changed.append(wire)
    return changed


def _watch_wait(r: RobotRun, waits: dict, changed: list, t: float) -> None:
    """Count `r`'s time in WAIT FOR (its robot program's ``waiting``, a sync wait's too) after the
    cycle at `t` (s); a wait that ended in this cycle is released by the wires into `r` that
    changed its inputs for this cycle (`changed`: Wire), or by the partners its synchronised
    motion was released with (`changed`: their texts)."""
    now = r.runtime.robot.waiting
    before = waits[r.name]
    if before is not None and before[0] != now:
        r.waited += t - before[1]
        into = [w for w in changed if not isinstance(w, Wire) or w.target == r.name]
        if now is None and into:
            r.released.append((before[0], t - before[1], into))
        before = waits[r.name] = None
    if now is not None and before is None:
        waits[r.name] = (now, t)


def _deadlock(runs: list[RobotRun], wires: tuple[Wire, ...], every: list[RobotRun] = ()) -> None:
    """End every blocked run of `runs` with ``deadlock``, each naming its wait, the wires into its
    robot (a wire from a robot of `every` whose run has ended naming that end: its source can
    set nothing any more), and the other blocked robots' waits."""
    ended = {o.name: o.runtime.result for o in every if all(o is not r for r in runs)}

    def wire(w: Wire) -> str:
        end = ended.get(w.source)
        if end is None:
            return str(w)
        return f"{w} ({w.source} ended: {end.reason}{f' at {end.file}:{end.line}' if end.file else ''})"
    for r in runs:
        into = [wire(w) for w in wires if w.target == r.name]
        others = "; ".join(f"{o.name} {o.runtime.scheduler.blocked}" for o in runs if o is not r)
        sched = r.runtime.scheduler
        text = (f"cell deadlocked: {r.name} {sched.blocked} (its inputs from the cell: "
                f"{', '.join(into) if into else 'none wired'})" + (f"; {others}" if others else ""))
        sched.end_deadlocked(text)
