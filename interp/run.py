"""One run of a KRL program: controller + runtime + interpreter (used by `krl run`, `krl debug`,
the tests and the real-programs report).

:func:`run_setup` turns ``krl run``'s options (the parameters of the click command in
interp/cli.py, by name) into a :class:`RunSetup`: the program found (in a backup archive
too), the submit programs (the backup's SPS.SUB at boot unless ``no_submit``), the robot. Both
``krl run`` and ``krl debug``'s launch go through it, so they run the same thing;
:meth:`RunSetup.make_runtime` builds the run (:func:`make_runtime`).
"""

from __future__ import annotations

import contextlib
import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

from interp.runtime.core import RunResult, Runtime
from interp.runtime.errors import KrlRuntimeError, ResourceError
from interp.runtime.memory import SignalRef
from interp.runtime.values import Struct
from krl.ast import nodes as N
from krl.semantics.resolve import UNRESOLVED
from krl.files import spelled, spelled_within
from krl.project import backup_of, boot_submit
from krl.source import is_krl_file
from krl.terminal import printable


def make_runtime(program, *, workspace=None, inputs=None, trace=None, max_sim_time=None,
                 max_steps=None, submit=None, mujoco: bool = True, controller=None,
                 robot_budget=None, interp: str = "tree", observer=None,
                 mode: str | None = None, check: bool = True,
                 vm_loop: str = "generated", run_mode: str | None = None,
                 pgno: int | None = None, robot=None, network=None, start: str | None = None,
                 halt_continues: int = 0, override: int | None = None) -> tuple[Runtime, object]:
    """Build the runtime and the interpreter (``interp``: tree or vm) for ``program``
    (not started yet). Its files (krl.project.project_of, with the `submit` programs) are
    loaded, checked and resolved first; with `check` (``krl run`` without ``--no-check``) a
    program whose own module the checker rejects does not start (its run ends with that
    error). `vm_loop`: the VM's dispatch loop, "generated" (interp/vm/loop.py, compiled when
    built) or "python" (loop.py as plain Python; tests compare the two). `observer` (an :class:`interp.summary.RunObserver`) sees the
    controller's events on their way to `trace`; it is not used with a given `controller`.
    `inputs`: the cell file (a path, or the Cell :func:`cell_of` read; read once per run).
    ``mode``: operating mode T1/T2/AUT/EXT (``$MODE_OP``; default AUT, robot/limits.py);
    ignored with a given `controller` (it has its own); None: EXT when the cell file (`inputs`)
    has the ``autoext`` preset, when the program is a cell program (:func:`cell_program`: the
    controller runs the handler of Automatic External in EXT) or with ``--inputs auto``, else
    AUT; ``rt.start`` (:class:`RunStart`) says who chose. ``pgno``: the program number the cell's PLC answers
    in P00's handshake (robot/cellpresets.py; overrides the cell file's ``pgno`` preset).
    ``run_mode``: ``$PRO_MODE`` at the start (GO, MSTEP, ISTEP, BSTEP; interp/runtime/runmode.py;
    default GO). ``robot``: the simulated robot (a MachineData or a path for
    :func:`robot.mada.load_robot`); default :func:`robot_for` (the cell file's ``robot``, else the
    backup's own robot, else the KR 6 R900). ``inputs``: a cell file, or ``"auto"`` (the
    automatic cell, interp/runtime/autocell.py: mode EXT unless `mode` says otherwise, P00's
    program numbers, the solver; the robot starts at ``XHOME`` when the program has one and
    no `start` is given). ``start``: where the robot stands at the start
    (:func:`start_axes`: an E6AXIS literal or a point name; default the cell file's
    ``start:``, else ``XHOME`` for a cell program or with ``--inputs auto`` when the program has
    one, else ``$AXIS_HOME[1]``). ``halt_continues``: ``--on-halt continue``, the
    times the operator presses Start again after a HALT (0: a HALT ends the run). ``override``:
    ``krl run --override``, the program override ``$OV_PRO`` (1..100 %) the operator set before
    the start (default 100; the program may change it). ``network``: the partners
    (net.settings.NetworkSettings; default the cell file's ``network:`` key): the run's network
    hub (net/hub.py) is attached to the controller either way; without partners its EKI
    channels stay "not connected". Raises
    :class:`robot.stimuli.StimulusError` for a bad cell file or a preset the backup's
    ``$config.dat`` does not allow, :class:`robot.stimuli.StartError` for a start position that cannot
    place the robot."""
    # costs 0.01 s at start-up (python -X importtime, 2026-11-25)
    from interp.tree import TreeInterpreter  # noqa: PLC0415

    auto = is_auto(inputs)
    if auto:
        inputs = None
    made, cell = controller is None, None
    if controller is None:
        # costs 0.34 s at start-up (python -X importtime, 2026-11-25)
        from robot.controller import Controller  # noqa: PLC0415

        if observer is not None:
            observer.inner = trace
        cell = cell_of(inputs)       # the cell file, read once for the robot and the controller
        controller = Controller(robot_for(program, workspace, robot, cell),
                                trace=observer if observer is not None else trace,
                                stimuli=cell, mujoco=mujoco,
                                mode_op=mode if mode is not None or not auto else "EX")
    rt = Runtime(program, workspace=workspace, controller=controller, trace=trace,
                 max_sim_time=max_sim_time, max_steps=max_steps, robot_budget=robot_budget,
                 submits=list(submit or ()), check=check)
    if run_mode is not None:
        rt.set_run_mode(run_mode)
    if override is not None:
        rt.sysvars.store["$OV_PRO"] = int(override)
    rt.halt_continues = halt_continues
    main = Path(program).stem
    cell_why = cell_program(rt)
    scene = rt.start = RunStart()
    if made:
        scene.mode_why = _mode_origin(rt, program, mode, cell, auto, cell_why)
    scene.mode = rt.mode_op
    where, scene.why = start, "--start"
    if where is None and getattr(controller, "start", None) is not None:
        where, scene.why = controller.start, "the cell file's start:"
    if where is None and (auto or cell_why) and isinstance(global_value(rt, main, "XHOME"), Struct):
        where = "XHOME"             # a cell starts at home, as P00's #CHK_HOME wants it
        scene.why = (f"the home position: {Path(program).name} is a cell program, and P00 #CHK_HOME wants "
                     f"it there; --start to choose another" if cell_why else
                     "the home position: --inputs auto starts a cell there; --start to choose another")
    if where is not None:
        # costs 0.003 s at start-up (python -X importtime, 2026-11-25)
        from interp.scene import start_axes  # noqa: PLC0415

        controller.place(start_axes(controller, lambda name: global_value(rt, main, name), where))
        scene.where = where
    else:
        scene.why = ""
    if observer is not None:
        # The interpreters trace into the user's trace only: without one the VM keeps its
        # quiet fast path (Runtime.quiet_limit); the observer needs the controller's events.
        rt.trace = trace
    number = pgno if pgno is not None else getattr(controller, "pgno", None)
    if number is not None:
        controller.rules += _pgno_rules(rt, Path(program).stem, number,
                                        "--pgno" if pgno is not None else "the cell file's pgno preset")
    if auto:
        # costs 0.02 s at start-up (python -X importtime, 2026-11-25)
        from interp.runtime.autocell import handshake_rules  # noqa: PLC0415

        rt.enable_autocell()
        if number is None:
            controller.rules += handshake_rules(rt, Path(program).stem, _pgno_parameters(rt, Path(program).stem))
    if controller.stimuli or controller.rules:
        # costs 0.01 s at start-up (python -X importtime, 2026-11-25)
        from robot.stimuli import resolve_signals  # noqa: PLC0415

        try:
            resolve_signals(controller.stimuli, lambda name: signal_of(rt, Path(program).stem, name),
                            controller.rules)
        except ResourceError:
            pass    # a data list past a limit: the program does not start (Runtime.main_routine says why)
    attach_network(rt, program, workspace, network if network is not None else getattr(controller, "cell_network", None))
    if interp == "vm":
        # costs 0.03 s at start-up (python -X importtime, 2026-11-25)
        from interp.vm import VM  # noqa: PLC0415

        interp = VM(rt, loop=vm_loop)
    else:
        interp = TreeInterpreter(rt)
    rt.add_task("robot", Path(program).stem, lambda: interp.run_program())
    for sub in submit or ():
        sp = Path(sub).resolve()
        rt.add_task("submit", sp.stem, lambda name=sp: interp.run_program(name))
    return rt, interp


@dataclass
class RunStart:
    """How a run started (shown in the run summary): the operating mode (``mode``: T1, T2,
    AUT, EX) and who chose it (``mode_why``; "" for the default AUT), where the robot stood
    (``where``: an E6AXIS literal or a point name, None for ``$AXIS_HOME[1]``) and why
    (``why``)."""

    mode: str = "AUT"
    mode_why: str = ""
    where: str | None = None
    why: str = ""


def cell_program(rt: Runtime) -> str:
    """Why the run's program is a cell program, the handler of Automatic External, or "":
    its module's header ``&COMMENT HANDLER on external automatic`` (KUKA's cell.src), or a
    call of ``P00 (#INIT_EXT, ...)`` in its module (KUKA's P00 initialises Automatic External
    for the program that handles it). Read from the program's syntax tree."""
    m = rt.program.module_of(rt.program.main_path)
    src = m.unit.src if m is not None and m.unit is not None else None
    module = src.module if src is not None else None
    if module is None:
        return ""
    for h in module.headers:
        if h.upper().startswith("&COMMENT") and "HANDLER ON EXTERNAL AUTOMATIC" in " ".join(h.upper().split()):
            return f"its header {' '.join(h.split())}"
    for node in module.walk():
        if isinstance(node, N.Call) and node.name.upper() == "P00" and node.args \
                and isinstance(node.args[0], N.EnumLit) and node.args[0].name.upper() == "INIT_EXT":
            return f"it calls P00 (#INIT_EXT, ...) at line {node.span.line}"
    return ""


def set_mode_op(rt: Runtime, mode: str) -> None:
    """Select the operating mode `mode` (T1, T2, AUT, EX) before the run starts: ``$MODE_OP``,
    the controller's and its robot model's (T1's reduced speeds, robot/limits.py)."""
    # costs 0.01 s at start-up (python -X importtime, 2026-11-25)
    from robot.limits import normalise_mode  # noqa: PLC0415

    m = normalise_mode(mode)
    rt.mode_op = rt.controller.mode_op = rt.controller.model.mode = m


def _mode_origin(rt: Runtime, program, mode, cell, auto: bool, cell_why: str) -> str:
    """Who chose the operating mode of a run whose controller make_runtime built (said in the
    run summary), selecting Automatic External for a cell program nobody chose a mode for:
    ``--mode``; the cell file's ``autoext`` preset; the cell program (:func:`cell_program`:
    the controller runs its handler in Automatic External); ``--inputs auto``; "" for the
    default AUT."""
    if mode is not None:
        return "--mode"
    if cell is not None and cell.autoext:
        return "the cell file's autoext preset"
    if cell_why:
        set_mode_op(rt, "EX")
        return (f"{Path(program).name} is a cell program ({cell_why}): the controller runs it in "
                f"Automatic External; --mode to choose another")
    if auto:
        return "--inputs auto: the automatic cell is the PLC of Automatic External; --mode to choose another"
    return ""


def attach_network(rt: Runtime, program, workspace, settings) -> None:
    """The run's network hub (net/hub.py) on `rt`'s controller, with `settings` (None: no
    partner). Raises net.hub.NetError when a partner's server cannot start."""
    # costs 0.06 s at start-up (python -X importtime, 2026-11-25)
    from net.hub import Network  # noqa: PLC0415

    # costs 0.003 s at start-up (python -X importtime, 2026-11-25)
    from interp.runtime.netvars import RuntimeSink  # noqa: PLC0415

    old = getattr(rt.controller, "network", None)
    if old is not None:
        old.close()
    prog = spelled_within(program, workspace)
    root = backup_of(prog, spelled(workspace) if workspace else None)
    net = Network(settings, program=prog, backup=root, sink=RuntimeSink(rt))
    try:
        net.attach(rt.controller, plc_map=lambda: plc_map(rt, Path(program).stem))
    except OSError as exc:
        net.close()
        # costs 0.06 s at start-up (python -X importtime, 2026-11-25)
        from net.hub import NetError  # noqa: PLC0415

        raise NetError(f"a network partner cannot start: {exc.strerror or exc}") from None


def is_auto(inputs) -> bool:
    """True for ``--inputs auto``: the automatic cell (interp/runtime/autocell.py) instead of
    a cell file. A file of that name is written ``./auto``."""
    return isinstance(inputs, (str, Path)) and str(inputs) == "auto"


def plc_map(rt: Runtime, main: str):
    """The PLC's address map (net/plc.py) derived from the cell: the inputs and outputs its
    rules, stimuli and program-number handshake (``PGNO_*`` of $config.dat) use, and the
    SIGNALs of the global declarations on ``$IN``/``$OUT``."""
    # costs 0.01 s at start-up (python -X importtime, 2026-11-25)
    from net.plc import derive_map  # noqa: PLC0415
    # costs 0.007 s at start-up (python -X importtime, 2026-11-25)
    from robot.cellpresets import PGNO_PARAMETERS  # noqa: PLC0415

    ctl = rt.controller
    indices: list[int] = []
    for name in PGNO_PARAMETERS:
        v = global_value(rt, main, name)
        if isinstance(v, int) and not isinstance(v, bool) and name != "PGNO_TYPE":
            indices.append(abs(v))
    fbit, length = global_value(rt, main, "PGNO_FBIT"), global_value(rt, main, "PGNO_LENGTH")
    if isinstance(fbit, int) and isinstance(length, int):
        indices.append(abs(fbit) + max(0, min(length, 64)))
    texts = [str(st.set) for st in ctl.stimuli] + [f"{r.text} {r.set}" for r in ctl.rules]
    for text in texts:
        indices += [int(x) for x in re.findall(r"\$(?:IN|OUT)\[(\d{1,4})\]", text)]
    signals = {}
    scope = rt.program.ws.global_scope
    for sym in (scope.values.values() if scope is not None else ()):
        if sym.kind != "signal":
            continue
        found = signal_of(rt, main, sym.name)
        if found is not None and found[0] in ("$IN", "$OUT"):
            base, a, b = found
            signals[sym.name.upper()] = (base, a, b if b is not None else a)
    return derive_map(indices, signals)


def _pgno_parameters(rt: Runtime, main: str) -> dict:
    """The ``PGNO_*`` parameters the program `main` sees ($config.dat), those with an INT value."""
    # costs 0.007 s at start-up (python -X importtime, 2026-11-25)
    from robot.cellpresets import PGNO_PARAMETERS  # noqa: PLC0415

    params = {}
    for name in PGNO_PARAMETERS:
        value = global_value(rt, main, name)
        if isinstance(value, int) and not isinstance(value, bool):
            params[name] = value
    return params


def _pgno_rules(rt: Runtime, main: str, number: int, origin: str = "--pgno") -> list:
    """The PLC's rules of P00's program-number handshake answering `number`, with the
    ``PGNO_*`` parameters the program sees ($config.dat). `origin` names where the number came
    from in the error (``--pgno``, the cell file's preset)."""
    # costs 0.007 s at start-up (python -X importtime, 2026-11-25)
    from robot.cellpresets import PresetError, pgno_rules  # noqa: PLC0415
    # costs 0.01 s at start-up (python -X importtime, 2026-11-25)
    from robot.stimuli import StimulusError  # noqa: PLC0415

    try:
        return pgno_rules(_pgno_parameters(rt, main), number)
    except PresetError as exc:
        raise StimulusError(f"{origin} {number}: {exc}") from None


def global_value(rt: Runtime, main: str, name: str):
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
        return rt.storage_ref(storage, None).get()
    except KrlRuntimeError:
        return None


def cell_of(inputs):
    """The cell file `inputs` read by its one loader (robot.stimuli.load_cell), or `inputs`
    itself when it is a Cell already, or None. Raises robot.stimuli.StimulusError."""
    if not inputs:
        return None
    # costs 0.01 s at start-up (python -X importtime, 2026-11-25)
    from robot.stimuli import Cell, load_cell  # noqa: PLC0415

    return inputs if isinstance(inputs, Cell) else load_cell(inputs)


def robot_for(program, workspace=None, robot=None, inputs=None):
    """The robot a run of `program` simulates (issue 22): `robot` when given (a MachineData,
    or a path: robot YAML, ``$machine.dat``, backup folder or .zip, robot/mada.py
    ``load_robot``); else the robot the cell file `inputs` names (``robot:``, one of the
    project's robot library); else the robot of the KRC backup holding the program (the backup
    root of krl.project.backup_of, its ``R1/Mada/$machine.dat``); else the KR 6 R900 of
    robot/data/kr6_r900.yaml. Raises robot.mada.MachineDataError for machine data that
    cannot make a model (file:line), robot.stimuli.StimulusError for a bad cell file."""
    # costs 0.49 s at start-up (python -X importtime, 2026-11-25)
    from robot.machine import MachineData, load_machine  # noqa: PLC0415
    # costs 0.53 s at start-up (python -X importtime, 2026-11-25)
    from robot.mada import load_robot  # noqa: PLC0415

    if isinstance(robot, MachineData):
        return robot
    if robot is None and inputs and not is_auto(inputs):
        robot = cell_of(inputs).robot
    if robot is not None:
        return load_robot(robot)
    root = backup_of(spelled_within(program, workspace), spelled(workspace) if workspace else None)
    found = _backup_robot(root) if root is not None else None
    if found is None and is_auto(inputs):
        # costs 0.003 s at start-up (python -X importtime, 2026-11-25)
        from interp.scene import choose_robot  # noqa: PLC0415

        def probe():
            rt, _ = make_runtime(program, workspace=workspace, mujoco=False, check=False, robot=load_machine())
            main = Path(program).stem
            return rt, lambda name: global_value(rt, main, name)
        choice = choose_robot(Path(program), probe, workspace)
        if choice is not None:
            return choice.machine
    return found if found is not None else load_machine()


def _backup_robot(root: Path):
    """robot.mada ``robot_of_backup(root)`` (its data lists' parses come from the one store,
    robot/datalist.py)."""
    # costs 0.53 s at start-up (python -X importtime, 2026-11-25)
    from robot.mada import robot_of_backup  # noqa: PLC0415

    return robot_of_backup(root)


def signal_of(rt: Runtime, main: str, name: str) -> tuple[str, int, int | None] | None:
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
        ref = rt.storage_ref(prog.ws.resolver.storage(name, sym, None, module.index if module else -1), None)
    except (KrlRuntimeError, IndexError):   # IndexError: a system signal ($EXT_START) the table types
        return None
    if not isinstance(ref, SignalRef):
        return None
    return ref.proxy.name.upper(), ref.a, ref.b


def run_program(program, **kw) -> RunResult:
    rt, _ = make_runtime(program, **kw)
    return rt.run()


class RunSetupError(Exception):
    """``krl run``'s options do not make a run (a usage error: exit 2); the message names the
    file."""


@dataclass
class RunSetup:
    """What one run of ``krl run`` runs (:func:`run_setup`): ``program`` (the .src file),
    ``workspace``, ``inputs`` (cell file), ``submit`` (the submit programs beside it),
    ``booted`` (the backup's SPS.SUB when it was started as at boot, else None), ``machine``
    (the simulated robot, robot.machine.MachineData), ``options`` (the rest of krl run's
    options by their click names: interp_kind, max_sim_time, max_steps, mode, run_mode, pgno,
    no_check, trace_path, trace_repeats, start, halt_continues, override), ``shown`` (a path as the
    user named it: an archive's temporary folder is shown as the archive), ``cell`` (the cell
    file `inputs` read once, robot.stimuli.Cell; ``"auto"`` for the automatic cell; None without one)."""
    program: Path
    workspace: Path | None
    inputs: Path | None
    submit: list
    booted: Path | None
    machine: object
    options: dict
    shown: Callable[[str], str] = field(default=lambda text: text)
    cell: object = None

    @property
    def interp(self) -> str:
        return self.options.get("interp_kind") or "tree"

    @property
    def check(self) -> bool:
        return not self.options.get("no_check")

    def trace_writer(self):
        """The run's trace (robot.trace.TraceWriter) at option ``trace_path``, or None: bounded
        by ``trace_repeats`` (default robot.trace.TRACE_REPEATS; 0 writes every event), headed by
        the simulated robot and where its data came from. One rule for krl run, krl debug and
        krl pendant, so their traces of one run are the same bytes."""
        # costs 0.25 s at start-up (python -X importtime, 2026-11-25)
        from robot.trace import TRACE_REPEATS, TraceWriter  # noqa: PLC0415

        path = self.options.get("trace_path")
        if not path:
            return None
        repeats = self.options.get("trace_repeats", TRACE_REPEATS)
        trace = TraceWriter(path, repeats=repeats or None)
        m = self.machine
        # costs 0.004 s at start-up (python -X importtime, 2026-11-26)
        from robot.axismap import ROBOT_KEYS, AxisMap  # noqa: PLC0415

        keys = AxisMap.of(m).model_keys
        trace.write("robot", 0.0, name=m.name, source=self.shown(m.source), trafoname=m.trafoname or None,
                    axes=list(keys) if keys != ROBOT_KEYS else None)
        return trace

    def make_runtime(self, trace=None, observer=None, **override) -> tuple:
        """(Runtime, interpreter) of this run, not started (:func:`make_runtime`); ``override``:
        keyword arguments of make_runtime that differ (a debugger's step limit)."""
        o = self.options
        kw = dict(workspace=self.workspace, inputs=self.cell if self.cell is not None else self.inputs, trace=trace,
                  max_sim_time=o.get("max_sim_time", 600.0), max_steps=o.get("max_steps"),
                  submit=[str(s) for s in self.submit], interp=self.interp, observer=observer,
                  mode=o.get("mode"), check=self.check, run_mode=str(o.get("run_mode") or "GO").upper(),
                  pgno=o.get("pgno"), robot=self.machine, start=o.get("start"),
                  halt_continues=o.get("halt_continues", 0), override=o.get("override"))
        kw.update(override)
        return make_runtime(self.program, **kw)


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
    named by its path or module name in it. Without ``submit`` and ``no_submit``, the backup's
    SPS.SUB runs beside the program, as the controller starts it at boot (krl.project
    ``boot_submit``). Raises :class:`RunSetupError`."""
    # costs 0.01 s at start-up (python -X importtime, 2026-11-25)
    from krl.archive import ArchiveError, backup_source, is_archive  # noqa: PLC0415
    program = Path(options["program"])
    workspace = Path(options["workspace"]) if options.get("workspace") is not None else None
    if is_archive(program):
        raise RunSetupError(f"{printable(program)} is a backup archive; name the program to run in it: "
                            f"krl run --workspace {printable(program)} PROGRAM")
    if workspace is not None and is_archive(workspace):
        try:
            with backup_source(workspace) as (folder, _shown):
                found = program_in(folder, program)
                if found is None:
                    raise RunSetupError(f"no program {printable(program)} in {printable(workspace)}")
                yield _setup(found, folder, options,
                             shown=lambda text: text.replace(str(folder), str(workspace)))
        except ArchiveError as exc:
            raise RunSetupError(printable(exc)) from None
        return
    yield _setup(program, workspace, options)


def _setup(program: Path, workspace, options: dict, shown=lambda text: text) -> RunSetup:
    # costs 0.53 s at start-up (python -X importtime, 2026-11-25)
    from robot.mada import MachineDataError  # noqa: PLC0415
    # costs 0.01 s at start-up (python -X importtime, 2026-11-25)
    from robot.stimuli import StimulusError  # noqa: PLC0415

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
        cell = inputs if is_auto(inputs) else cell_of(inputs)   # the cell file, read once for the robot and the run
        machine = robot_for(program, workspace, options.get("robot"), cell)
    except (MachineDataError, StimulusError) as exc:
        raise RunSetupError(shown(printable(exc))) from None
    rest = {k: v for k, v in options.items()
            if k not in ("program", "workspace", "inputs", "submit", "no_submit", "robot")}
    return RunSetup(program, workspace, inputs, submit, booted, machine, rest, shown, cell)
