"""One run of a KRL program built from its description (interp/spec.py :class:`RunSpec`): the
runtime, its controller and the interpreter (used by `krl run`, `krl debug`, `krl pendant`, the
audit, the change report, the tests and the real-programs report).

:func:`run_setup` turns ``krl run``'s options (the parameters of the click command in
interp/cli.py, by name) into a :class:`RunSetup`: the RunSpec with the program found (in a
backup archive too), the submit programs (the backup's SPS.SUB at boot unless ``no_submit``),
the cell file read and the robot loaded. ``krl run``, ``krl debug``'s launch and the pendant go
through it, so they run the same thing; :func:`run_spec` builds a RunSpec from keywords (the
tools' and the tests' front door); :func:`make_runtime` builds the run of a spec, and
:func:`plan_cell` what of its controller depends on its program.
"""

from __future__ import annotations

import contextlib
import copy
import weakref
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

from interp.runtime import pgnoturns
from interp.runtime.autocell import handshake_rules, program_numbers
from interp.runtime.core import CellPlan, RunResult, RunStart, Runtime
from interp.runtime.errors import KrlRuntimeError, ResourceError
from interp.runtime.model import ProgramModel, RunData, load_model
from interp.runtime.memory import SignalRef
from interp.runtime.values import LEAVES, Struct
from interp.scene import choose_robot, start_axes
from interp.spec import RunSpec, SpecError, spec_values
from interp.tree import TreeInterpreter
from interp.vm import VM
from krl.archive import ArchiveError, is_archive
from krl.backups import BackupsError, holds_archives, one_backup
from krl.kssarchive import ARCHIVE_MANIFESTS
from krl.ast import nodes as N
from krl.semantics.resolve import UNRESOLVED
from krl.files import spelled, spelled_within
from krl.project import backup_of, boot_submit, find_backups
from krl.project import cell_program as backup_cell_program
from krl.source import is_krl_file
from krl.terminal import printable
from net.plc import cell_map
from robot.axismap import ROBOT_KEYS, AxisMap
from robot.cellpresets import PGNO_PARAMETERS, PresetError, pgno_rules
from robot.limits import normalise_mode
from robot.machine import MachineData, load_machine
from robot.mada import MachineDataError, load_robot, named_machine, robot_of_backup
from robot.named import named_robot
from robot.robotmodel import RobotModel
from robot.stimuli import Cell, StartError, StimulusError, load_cell, resolve_signals
from robot.trace import TRACE_REPEATS, TraceWriter


class EventObserver(Protocol):
    """What sees the controller's events on their way to the trace `inner` (interp/summary.py
    RunObserver, the change report's and the audit's observers): the part of
    robot.trace.TraceWriter the controller writes to."""
    inner: TraceWriter | None

    def write(self, kind: str, t: float, **fields: object) -> object: ...


@dataclass(frozen=True)
class RunSinks:
    """Where a run writes, apart from its spec (which is pure data): ``trace``, the run's trace
    writer (robot.trace.TraceWriter) or None, which the interpreters trace into; ``observer``,
    what sees the controller's events on their way to that trace (interp/summary.py
    RunObserver, built with ``inner=trace``) or None: the controller writes to it instead."""
    trace: TraceWriter | None = None
    observer: EventObserver | None = None

    def __post_init__(self) -> None:
        if self.observer is not None and self.observer.inner is not self.trace:
            raise ValueError("RunSinks: the observer passes the events on to the trace: RunObserver(inner=trace)")

    @property
    def events(self) -> TraceWriter | EventObserver | None:
        """Where the controller writes its events: the observer, else the trace."""
        return self.observer if self.observer is not None else self.trace


def make_runtime(spec: RunSpec, sinks: RunSinks | None = None) -> tuple[Runtime, object]:
    """Build the run `spec` describes (interp/spec.py), not started, writing to `sinks` (None:
    nowhere): its robot (``spec.robot``,
    else :func:`robot_for`), its program's files (krl.project.project_of, with the submit
    programs) loaded, checked and resolved, a complete controller for the cell :func:`plan_cell`
    derives from the spec and the program, and the interpreter (tree or VM) on each task.
    Returns ``(runtime, interpreter)``. With ``spec.check`` (``krl run`` without
    ``--no-check``) a program whose own module the checker rejects does not start (its run
    ends with that error). Raises :class:`robot.stimuli.StimulusError` for a preset the
    backup's ``$config.dat`` does not allow, :class:`robot.stimuli.StartError` for a start asked
    for (``--start``, a cell file's ``start:``) that cannot place the robot (XHOME the run chose
    itself is then not taken: :func:`plan_cell`), :class:`net.hub.NetError` when a network partner cannot start,
    robot.mada.MachineDataError for machine data that cannot make a model."""
    model = program_model(spec)
    spec = spec.with_(robot=model.machine) if spec.robot is None else spec
    rt = Runtime(model, lambda data: plan_cell(data, spec), spec, sinks or RunSinks(), interpreter=_interpreter)
    _watch_turns(rt, spec)
    return rt, rt.interpreter


def _watch_turns(rt: Runtime, spec: RunSpec):
    """The turns of P00's handshake the run's PLC answers (interp/runtime/pgnoturns.py): the
    number of ``--pgno`` or the cell file's preset, else the automatic cell's in turn."""
    main = spec.program.stem
    cell = spec.cell
    number = spec.pgno if spec.pgno is not None else (cell.pgno if cell is not None else None)
    numbers = [number] if number is not None else (program_numbers(rt) or [1]) if spec.auto else []
    return pgnoturns.watch(rt, _pgno_parameters(rt, main), numbers)


def program_model(spec: RunSpec) -> ProgramModel:
    """The model of the program of the run `spec` describes (interp/runtime/model.py: loaded
    once per process for the same files, program, check and robot, and shared by every run
    and tool that asks): its robot (``spec.robot``, else :func:`robot_for`), its files loaded,
    checked and resolved, its data lists initialised. Raises robot.mada.MachineDataError for
    machine data that cannot make a model."""
    if spec.robot is None:
        spec = spec.with_(robot=robot_for(spec.program, spec.workspace, None, "auto" if spec.auto else spec.cell))
    return load_model(spec)


def load_program(spec: RunSpec) -> RunData:
    """The program of the run `spec` describes, loaded, as a tool's own copy of its model
    (:func:`program_model`; interp/runtime/model.py RunData): no controller, network or trace
    (a tool that reads a data list's initial values: interp/reach.py, interp/cellinit.py,
    :func:`robot_for`'s probe). Raises robot.mada.MachineDataError for machine data that
    cannot make a model."""
    return program_model(spec).data(spec=spec)


def _fresh(items: list) -> list:
    """A run's own copies of a cell's stimuli or rules: their signals (which the run resolves)
    and their run state (a rule's pending answers) its own, the cell of the spec untouched."""
    out = []
    for x in items:
        y = copy.copy(x)
        y.set = dict(x.set)
        if isinstance(getattr(x, "due", None), list):
            y.due = list(x.due)
        out.append(y)
    return out


def _interpreter(rt: Runtime):
    """The interpreter of the run `rt` (its spec's ``interp``): the tree interpreter or the VM."""
    spec = rt.spec
    if spec.interp == "vm":
        return VM(rt, loop=spec.vm_loop)
    return TreeInterpreter(rt)


def run_spec(program, *, workspace=None, inputs=None, robot=None, submit=(), max_sim_time=None,
             **fields) -> RunSpec:
    """The RunSpec of a run given by the tools and the tests: the front door of krl run
    (:func:`spec_of`) with values, not texts: `inputs` a cell file's path, a read Cell or
    ``"auto"``; `robot` a MachineData or a path (robot/mada.py ``load_robot``), else the one
    :func:`robot_for` picks; `fields` RunSpec's by name. Unlike krl run, no time limit unless
    `max_sim_time` (s) is given, and no SPS.SUB of a backup unless in `submit`. Reads the cell
    file once. Raises robot.stimuli.StimulusError, robot.mada.MachineDataError."""
    machine = robot if robot is None or isinstance(robot, MachineData) else load_robot(robot)
    return spec_of(Path(program), Path(workspace) if workspace is not None else None, inputs, machine,
                   submit=tuple(Path(s) for s in submit or ()), max_sim_time=max_sim_time, **fields)


def spec_of(program: Path, workspace: Path | None, inputs, robot, **fields) -> RunSpec:
    """The one way from a run's inputs to its RunSpec (krl run's, the debugger's and the
    pendant's :func:`run_setup`, the tools' :func:`run_spec`): the cell of `inputs` (a path,
    a read Cell, ``"auto"`` or None: read once), the robot (`robot`, a robot's path or a
    MachineData, else :func:`robot_for`'s), `fields` RunSpec's others. Raises
    robot.stimuli.StimulusError, robot.mada.MachineDataError, interp.spec.SpecError."""
    auto = is_auto(inputs)
    cell = None if auto else cell_of(inputs)    # the cell file, read once for the robot and the run
    machine = robot_for(program, workspace, robot, "auto" if auto else cell)
    return RunSpec(program, workspace=workspace, cell=cell, auto=auto, robot=machine, **fields)


def plan_cell(loaded: RunData, spec: RunSpec) -> CellPlan:
    """What of the controller of the run `spec` depends on its program, `loaded` (the run's own
    copy of its model: interp/runtime/model.py RunData; :func:`make_runtime`'s Runtime plans
    with it): the operating mode and who chose
    it (:func:`_mode_origin`), where the robot starts and why (:func:`start_axes`), the cell's
    stimuli and rules with the program's SIGNALs resolved (robot/stimuli.py), the PLC's rules
    of P00's program-number handshake (``--pgno``, the cell's preset, the automatic cell's), the
    network partners and the PLC's address map (:func:`plc_map`), the bodies the robot is
    checked against (the spec's geometry, else the cell's). Each run gets its own copy of
    the cell's stimuli and rules (they keep run state: fired, due)."""
    main = spec.program.stem
    cell = spec.cell
    stimuli = _fresh(cell.stimuli) if cell is not None else []
    rules = _fresh(cell.rules) if cell is not None else []
    cell_why = cell_program(loaded)
    mode, mode_why = _mode_origin(spec, cell, cell_why)
    scene = RunStart(mode=mode, mode_why=mode_why)
    where, scene.why = spec.start, "--start"
    if where is None and cell is not None and cell.start is not None:
        where, scene.why = cell.start, "the cell file's start:"
    if where is None and (spec.auto or cell_why) and isinstance(global_value(loaded, main, "XHOME"), Struct):
        where = "XHOME"             # a cell starts at home, as P00's #CHK_HOME wants it
        scene.why = (f"the home position: {spec.program.name} is a cell program, and P00 #CHK_HOME wants "
                     f"it there; --start to choose another" if cell_why else
                     "the home position: --inputs auto starts a cell there; --start to choose another")
    axes = None
    if where is not None:
        try:
            axes = _start_axes(loaded, spec.robot, mode, main, where)
            scene.where = where
        except StartError as exc:
            if spec.start is not None or (cell is not None and cell.start is not None):
                raise                   # asked for: a clear refusal (krl run exits 2)
            # the run's own choice of XHOME: a home the robot driven cannot take (the backup's, for
            # another robot) is no error of the program; the robot starts at $AXIS_HOME[1]
            scene.why = f"XHOME not taken ({exc}): the robot starts at $AXIS_HOME[1]; --start to choose another"
    else:
        scene.why = ""
    number = spec.pgno if spec.pgno is not None else (cell.pgno if cell is not None else None)
    if number is not None:
        rules += _pgno_rules(loaded, main, number, "--pgno" if spec.pgno is not None else "the cell file's pgno preset")
    elif spec.auto:
        rules += handshake_rules(loaded, main, _pgno_parameters(loaded, main))
    if stimuli or rules:
        try:
            resolve_signals(stimuli, lambda name: signal_of(loaded, main, name), rules)
        except ResourceError:
            pass    # a data list past a limit: the program does not start (Calls.main_routine says why)
    network = spec.network if spec.network is not None else (cell.network if cell is not None else None)
    geometry = spec.geometry if spec.geometry is not None else (cell.geometry if cell is not None else None)
    return CellPlan(mode_op=mode, start=scene, start_axes=axes, stimuli=stimuli, rules=rules, network=network,
                    plc_map=lambda: plc_map(loaded, main, stimuli, rules), geometry=geometry)


def _start_axes(loaded: RunData, machine: MachineData, mode: str, main: str, where: str):
    """:func:`interp.scene.start_axes` of the robot `machine` in `mode` for the start `where`
    of the program `main` of `loaded`, computed once per checked workspace, robot, mode, start
    and values of the points it read (``XHOME``: the program's data list, else ``$config.dat``;
    :meth:`Program.derived`): a robot model built and the start parsed and solved at each
    run of a backup's entry points was a tenth of each start (2026-11-29). A start that reads a
    point holding a structure in a structure is computed each time. Each run gets its own
    array. Raises robot.stimuli.StartError."""
    memo = loaded.program.derived(("start axes", where, mode), lambda _program: [])

    def value_of(name: str):
        return global_value(loaded, main, name)
    for held, reads, axes in memo:
        if held() is machine and all(_flat(value_of(name)) == seen for name, seen in reads):
            return axes.copy()
    reads = []

    def reading(name: str):
        value = value_of(name)
        reads.append((name, _flat(value)))
        return value
    axes = start_axes(RobotModel(machine, mode=mode), reading, where)
    if all(seen is not None for _name, seen in reads) and len(memo) < _START_MEMOS:
        memo.append((weakref.ref(machine), tuple(reads), axes.copy()))
    return axes


#: the starts kept per checked workspace, start and mode (one per robot and points' values)
_START_MEMOS = 8


def _flat(value):
    """The components of `value`, a Struct of leaves (values.LEAVES), as a tuple to compare;
    None for anything else."""
    if not isinstance(value, Struct) or not LEAVES.issuperset(map(type, value.f.values())):
        return None
    return tuple(value.f.items())


def cell_program(loaded: RunData) -> str:
    """Why the run's program is a cell program, the handler of Automatic External, or "":
    its module's header ``&COMMENT HANDLER on external automatic`` (KUKA's cell.src), or a
    call of ``P00 (#INIT_EXT, ...)`` in its module (KUKA's P00 initialises Automatic External
    for the program that handles it). Read from the program's syntax tree, once per module of
    a checked workspace (interp/runtime/program.py ``Program.derived``: the walk of the
    palletizer's main module was a tenth of each of its runs' start)."""
    m = loaded.program.module_of(loaded.program.main_path)
    src = m.unit.src if m is not None and m.unit is not None else None
    module = src.module if src is not None else None
    if module is None:
        return ""
    return loaded.program.derived(("cell program", m.index), lambda _program: _cell_program_why(module))


def _cell_program_why(module: N.Module) -> str:
    """:func:`cell_program`'s answer for the syntax tree `module` of the run's program."""
    for h in module.headers:
        if h.upper().startswith("&COMMENT") and "HANDLER ON EXTERNAL AUTOMATIC" in " ".join(h.upper().split()):
            return f"its header {' '.join(h.split())}"
    for node in module.walk():
        if isinstance(node, N.Call) and node.name.upper() == "P00" and node.args \
                and isinstance(node.args[0], N.EnumLit) and node.args[0].name.upper() == "INIT_EXT":
            return f"it calls P00 (#INIT_EXT, ...) at line {node.span.line}"
    return ""


def _mode_origin(spec: RunSpec, cell, cell_why: str) -> tuple[str, str]:
    """The operating mode of the run (T1, T2, AUT, EX: robot/limits.py) and who chose it (said
    in the run summary): ``--mode``; the cell file's ``autoext`` preset; the cell program
    (:func:`cell_program`: the controller runs its handler in Automatic External); ``--inputs
    auto``; "" for the default AUT."""
    if spec.mode is not None:
        return normalise_mode(spec.mode), "--mode"
    if cell is not None and cell.autoext:
        return "EX", "the cell file's autoext preset"
    if cell_why:
        return "EX", (f"{spec.program.name} is a cell program ({cell_why}): the controller runs it in "
                      f"Automatic External; --mode to choose another")
    if spec.auto:
        return "EX", "--inputs auto: the automatic cell is the PLC of Automatic External; --mode to choose another"
    return "AUT", ""


def is_auto(inputs) -> bool:
    """True for ``--inputs auto``: the automatic cell (interp/runtime/autocell.py) instead of
    a cell file. A file of that name is written ``./auto``."""
    return isinstance(inputs, (str, Path)) and str(inputs) == "auto"


def plc_map(rt: RunData | Runtime, main: str, stimuli: list, rules: list):
    """The PLC's address map (net/plc.py ``cell_map``) of the run `rt`'s cell: the inputs and
    outputs its `stimuli` and `rules` use (their signals as the front end parsed them), the
    program-number handshake's (``PGNO_*`` of $config.dat), and the SIGNALs of the global
    declarations on ``$IN``/``$OUT``."""
    handshake = []
    for name in PGNO_PARAMETERS:
        v = global_value(rt, main, name)
        if isinstance(v, int) and not isinstance(v, bool) and name != "PGNO_TYPE":
            handshake.append(abs(v))
    fbit, length = global_value(rt, main, "PGNO_FBIT"), global_value(rt, main, "PGNO_LENGTH")
    if isinstance(fbit, int) and isinstance(length, int):
        handshake.append(abs(fbit) + max(0, min(length, 64)))
    signals = {}
    scope = rt.program.ws.global_scope
    for sym in (scope.values.values() if scope is not None else ()):
        if sym.kind != "signal":
            continue
        found = signal_of(rt, main, sym.name)
        if found is not None and found[0] in ("$IN", "$OUT"):
            base, a, b = found
            signals[sym.name.upper()] = (base, a, b if b is not None else a)
    return cell_map(stimuli, rules, handshake, signals)


def _pgno_parameters(rt: RunData | Runtime, main: str) -> dict:
    """The ``PGNO_*`` parameters the program `main` sees ($config.dat), those with an INT value."""
    params = {}
    for name in PGNO_PARAMETERS:
        value = global_value(rt, main, name)
        if isinstance(value, int) and not isinstance(value, bool):
            params[name] = value
    return params


def _pgno_rules(rt: RunData | Runtime, main: str, number: int, origin: str = "--pgno") -> list:
    """The PLC's rules of P00's program-number handshake answering `number`, with the
    ``PGNO_*`` parameters the program sees ($config.dat). `origin` names where the number came
    from in the error (``--pgno``, the cell file's preset)."""
    try:
        return pgno_rules(_pgno_parameters(rt, main), number)
    except PresetError as exc:
        raise StimulusError(f"{origin} {number}: {exc}") from None


def global_value(rt: RunData | Runtime, main: str, name: str):
    """The value of the variable `name` as the program `main` sees it (its data list, then the
    global declarations: $config.dat), or None when there is none or it has no value."""
    prog = rt.program
    module = prog.module_of(prog.main_path) if main.upper() == prog.main_path.stem.upper() else prog.module(main)
    scope = prog.ws.units[module.index].scope if module is not None else prog.ws.global_scope
    sym = scope.lookup(name) if scope is not None else None
    if sym is None or sym.kind not in ("var", "const"):
        return None
    storage = prog.ws.resolver.storage(name, sym, None, module.index if module else -1)
    if storage.kind == UNRESOLVED:
        return None             # a name of the tables no data list declares: no value (no stand-in made)
    try:
        return rt.names.storage_ref(storage, None).get()
    except KrlRuntimeError:
        return None


def cell_of(inputs):
    """The cell file `inputs` read by its one loader (robot.stimuli.load_cell), or `inputs`
    itself when it is a Cell already, or None. Raises robot.stimuli.StimulusError."""
    if not inputs:
        return None
    return inputs if isinstance(inputs, Cell) else load_cell(inputs)


def robot_for(program, workspace=None, robot=None, inputs=None):
    """The robot a run of `program` simulates (issue 22): `robot` when given (a MachineData,
    or a path: robot YAML, ``$machine.dat``, backup folder or .zip, robot/mada.py
    ``load_robot``); else the robot the cell file `inputs` names (``robot:``, one of the
    project's robot library); else the robot of the KRC backup holding the program (the backup
    root of krl.project.backup_of, its ``R1/Mada/$machine.dat``; without one, the robot its
    ``$config.dat`` names in ``MACHINE_DEF[1]`` when the catalogue or the library has it,
    robot/named.py); else the KR 6 R900 of robot/data/kr6_r900.yaml (or the robot --inputs auto
    chooses), which says so when it stands in for a robot the backup names (``named``). Raises robot.mada.MachineDataError for machine data that
    cannot make a model (file:line), robot.stimuli.StimulusError for a bad cell file."""
    if isinstance(robot, MachineData):
        return robot
    if robot is None and inputs and not is_auto(inputs):
        robot = cell_of(inputs).robot
    if robot is not None:
        return load_robot(robot)
    root = backup_of(spelled_within(program, workspace), spelled(workspace) if workspace else None)
    found = robot_of_backup(root) if root is not None else None
    # no machine data: the robot the backup's $config.dat names (MACHINE_DEF[1]; robot/named.py),
    # driven when the catalogue or the library has it, else said to be missing where it stands in;
    # outside a backup, the $config.dat lying flat in the program's folder (issue 85 item 6)
    folder = root if root is not None else Path(workspace) if workspace else Path(program).parent
    named = named_robot(folder) if found is None else None
    if named is not None and named.known:
        return named_machine(named)
    if found is None and is_auto(inputs):

        def probe():
            loaded = load_program(RunSpec(Path(program), workspace=Path(workspace) if workspace else None,
                                          mujoco=False, check=False, robot=load_machine()))
            main = Path(program).stem
            return loaded, lambda name: global_value(loaded, main, name)
        choice = choose_robot(Path(program), probe, workspace)
        if choice is not None:
            return choice.machine if named is None else named_machine(named, choice.machine)
    if found is not None:
        return found
    return load_machine() if named is None else named_machine(named)


def signal_of(rt: RunData | Runtime, main: str, name: str) -> tuple[str, int, int | None] | None:
    """``(base, first, last)`` of the SIGNAL `name` seen by the program `main`: its data list,
    then the global declarations of every module ($config.dat, public data lists loaded on
    demand, as the program's own name lookup does). None if there is no such SIGNAL."""
    prog = rt.program
    module = prog.module_of(prog.main_path) if main.upper() == prog.main_path.stem.upper() else prog.module(main)
    scope = prog.ws.units[module.index].scope if module is not None else prog.ws.global_scope
    sym = scope.lookup(name) if scope is not None else None
    if sym is None or sym.kind != "signal":
        return None
    try:
        ref = rt.names.storage_ref(prog.ws.resolver.storage(name, sym, None, module.index if module else -1), None)
    except (KrlRuntimeError, IndexError):   # IndexError: a system signal ($EXT_START) the table types
        return None
    if not isinstance(ref, SignalRef):
        return None
    return ref.proxy.name.upper(), ref.a, ref.b


def run_program(spec: RunSpec) -> RunResult:
    """Build the run `spec` describes and run it (:func:`make_runtime`)."""
    rt, _ = make_runtime(spec)
    return rt.run()


class RunSetupError(Exception):
    """``krl run``'s options do not make a run (a usage error: exit 2); the message names the
    file."""


@dataclass(frozen=True)
class RunSetup:
    """What ``krl run``, ``krl debug``'s launch and ``krl pendant`` run (:func:`run_setup`): the
    run's :class:`~interp.spec.RunSpec` (``spec``, validated: its program, robot, cell and
    submit programs found and read), how a path is shown (``shown``: an archive's temporary
    folder as the archive), and where its trace goes (``trace_path``, ``trace_repeats``)."""
    spec: RunSpec
    shown: Callable[[str], str] = field(default=lambda text: text)
    trace_path: Path | None = None
    trace_repeats: int = TRACE_REPEATS

    @property
    def program(self) -> Path:
        return self.spec.program

    @property
    def workspace(self) -> Path | None:
        return self.spec.workspace

    @property
    def booted(self) -> Path | None:
        return self.spec.booted

    @property
    def machine(self):
        return self.spec.robot

    @property
    def interp(self) -> str:
        return self.spec.interp

    def trace_writer(self):
        """The run's trace (robot.trace.TraceWriter) at ``trace_path``, or None: bounded by
        ``trace_repeats`` (0 writes every event), headed by the simulated robot and where its
        data came from. One rule for krl run, krl debug and krl pendant, so their traces of one
        run are the same bytes."""
        if not self.trace_path:
            return None
        trace = TraceWriter(self.trace_path, repeats=self.trace_repeats or None)
        m = self.spec.robot
        keys = AxisMap.of(m).model_keys
        trace.write("robot", 0.0, name=m.name, source=self.shown(m.source), trafoname=m.trafoname or None,
                    axes=list(keys) if keys != ROBOT_KEYS else None)
        return trace

    def make_runtime(self, sinks: RunSinks | None = None, **changes) -> tuple:
        """(Runtime, interpreter) of this run, not started (:func:`make_runtime`), writing to
        `sinks`; ``changes``: fields of its spec that differ (the pendant's interactive
        message window)."""
        return make_runtime(self.spec.with_(**changes) if changes else self.spec, sinks)


def _cell_of_folder(folder: Path) -> Path | None:
    """The cell program (krl.project ``cell_program``) of the one KRC backup at or below `folder`."""
    root = backup_of(folder, folder)
    roots = [root] if root is not None else find_backups(folder)
    return backup_cell_program(roots[0]) if len(roots) == 1 else None


def _no_cell(path: Path, command: str = "krl run") -> str:
    return (f"{printable(path)} holds no KRC backup with a cell program (R1/cell.src); name the program "
            f"in it: {command} --workspace {printable(path)} PROGRAM")


def program_in(folder: Path, program: Path) -> Path | None:
    """PROGRAM inside an extracted archive: its relative path (any letter case of the file
    name), else the .src (then .sub) file whose stem is its name; None when there is none."""
    direct = folder / program
    if not program.is_absolute() and ".." not in program.parts and direct.is_file():
        return direct
    stem = program.stem.lower()
    candidates = sorted(p for p in folder.rglob("*") if p.is_file() and is_krl_file(p) and p.stem.lower() == stem)
    for suffix in (".src", ".sub"):
        for p in candidates:
            if p.suffix.lower() == suffix:
                return p
    return None


@contextlib.contextmanager
def run_setup(options: dict) -> Iterator[RunSetup]:
    """The run that ``krl run``'s `options` describe (keys: the click parameters' names of
    interp/cli.py ``run``: program, workspace, inputs, submit, no_submit, robot, ...; the others
    are kept in :attr:`RunSetup.options`). A ``workspace`` that is a KRC backup archive is
    checked and extracted for the duration of the ``with`` block (krl/archive.py), the program
    named by its path or module name in it. A ``program`` that is a backup folder or archive
    (without ``workspace``) runs its cell program (krl.project ``cell_program``: ``R1/cell.src``)
    as the controller selects it in Automatic External. Without ``submit`` and ``no_submit``, the backup's
    SPS.SUB runs beside the program, as the controller starts it at boot (krl.project
    ``boot_submit``). Raises :class:`RunSetupError`."""
    program = Path(options["program"])
    workspace = Path(options["workspace"]) if options.get("workspace") is not None else None
    with located(program, workspace) as (found, folder, shown):
        yield _setup(found, folder, options, shown=shown)


@contextlib.contextmanager
def located(program: Path, workspace: Path | None,
            command: str = "krl run") -> Iterator[tuple[Path, Path | None, Callable[[str], str]]]:
    """``with located(program, workspace) as (program, workspace, shown)``: the program file and
    its workspace folder that ``krl run PROGRAM [--workspace W]`` names (:func:`run_setup`): a
    backup folder or archive given whole is its cell program; a backup ``.zip`` or a folder of
    controller archives is extracted for the block (krl/backups.py ``one_backup``), `shown`
    turning its temporary paths in a text into the user's. Raises :class:`RunSetupError` (its
    hints name `command`)."""
    whole = workspace is None and (is_archive(program) or program.is_dir())
    if whole:
        # a backup or controller archive given whole: its cell program, as the controller selects it
        workspace = program
        if not is_archive(workspace) and not holds_archives(workspace):
            program = _cell_of_folder(workspace)
            if program is None:
                raise RunSetupError(_no_cell(workspace, command))
    if workspace is not None and (is_archive(workspace) or (workspace.is_dir() and holds_archives(workspace))):
        # a backup .zip, or a folder of controller archives: its one backup (krl/backups.py)
        try:
            with one_backup(workspace, ARCHIVE_MANIFESTS) as (part, _root, _entries):
                folder = part.folder
                found = _cell_of_folder(folder) if whole else program_in(folder, program)
                if found is None and whole:
                    raise RunSetupError(_no_cell(workspace, command))
                if found is None:
                    raise RunSetupError(f"no program {printable(program)} in {printable(workspace)}")
                source = part.source if part.archive else str(workspace)
                yield found, folder, lambda text: text.replace(str(folder), source)
        except (ArchiveError, BackupsError) as exc:
            raise RunSetupError(printable(exc)) from None
        return
    yield program, workspace, lambda text: text


def _setup(program: Path, workspace, options: dict, shown=lambda text: text) -> RunSetup:
    """The RunSetup of krl run's `options` (their click names) for `program` in `workspace`:
    every file named found, the cell file read, the robot loaded, the spec made and checked
    once (interp/spec.py). Raises RunSetupError."""
    if not program.exists():
        # a FIFO, socket or device exists: the reader (krl.source) refuses it with its reason
        raise RunSetupError(f"{shown(printable(program))}: no such file")
    if workspace is not None and not workspace.is_dir():
        raise RunSetupError(f"{shown(printable(workspace))}: no such folder")
    inputs = Path(options["inputs"]) if options.get("inputs") is not None else None
    submit = [Path(s) for s in options.get("submit") or ()]
    for sub in submit:
        if not sub.is_file():
            raise RunSetupError(f"{shown(printable(sub))}: no such submit program")
    booted = None
    if not submit and not options.get("no_submit"):
        booted = boot_submit(program, workspace)
        submit = [booted] if booted is not None else []
    try:
        spec = spec_of(program, workspace, inputs, options.get("robot"), submit=tuple(submit), booted=booted,
                       **spec_values(options))
    except (MachineDataError, StimulusError, SpecError) as exc:
        raise RunSetupError(shown(printable(exc))) from None
    return RunSetup(spec, shown, options.get("trace_path"), options.get("trace_repeats", TRACE_REPEATS))
