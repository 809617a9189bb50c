"""One run of a KRL program: controller + runtime + interpreter (used by `krl run`, the
tests and the real-programs report)."""

from __future__ import annotations

from pathlib import Path

from interp.runtime.core import RunResult, Runtime
from interp.runtime.errors import KrlRuntimeError, ResourceError


def make_runtime(program, *, workspace=None, inputs=None, trace=None, max_sim_time=None,
                 max_steps=None, submit=None, mujoco: bool = True, controller=None,
                 robot_budget=None, interp: str = "tree", observer=None,
                 mode: str | None = None, check: bool = True,
                 vm_loop: str = "generated", run_mode: str | None = None,
                 pgno: int | None = None, robot=None, network=None) -> tuple[Runtime, object]:
    """Build the runtime and the interpreter (``interp``: tree or vm) for ``program``
    (not started yet). Its files (krl.project.project_of, with the `submit` programs) are
    loaded, checked and resolved first; with `check` (``krl run`` without ``--no-check``) a
    program whose own module the checker rejects does not start (its run ends with that
    error). `vm_loop`: the VM's dispatch loop, "generated" (interp/vm/loop.py) or "source"
    (VM.run as written; tests compare the two). `observer` (an :class:`interp.summary.RunObserver`) sees the
    controller's events on their way to `trace`; it is not used with a given `controller`.
    `inputs`: the cell file (a path, or the Cell :func:`cell_of` read; read once per run).
    ``mode``: operating mode T1/T2/AUT/EXT (``$MODE_OP``; default AUT, robot/limits.py);
    ignored with a given `controller` (it has its own); None: AUT, or EXT when the cell file
    (`inputs`) has the ``autoext`` preset. ``pgno``: the program number the cell's PLC answers
    in P00's handshake (robot/cellpresets.py; overrides the cell file's ``pgno`` preset).
    ``run_mode``: ``$PRO_MODE`` at the start (GO, MSTEP, ISTEP, BSTEP; interp/runtime/runmode.py;
    default GO). ``robot``: the simulated robot (a MachineData or a path for
    :func:`robot.mada.load_robot`); default :func:`robot_for` (the cell file's ``robot``, else the
    backup's own robot, else the KR 6 R900). ``network``: the partners
    (net.settings.NetworkSettings; default the cell file's ``network:`` key): the run's network
    hub (net/hub.py) is attached to the controller either way; without partners its EKI
    channels stay "not connected". Raises
    :class:`robot.stimuli.StimulusError` for a bad cell file or a preset the backup's
    ``$config.dat`` does not allow."""
    from interp.tree import TreeInterpreter  # noqa: PLC0415

    if controller is None:
        from robot.controller import Controller  # noqa: PLC0415

        if observer is not None:
            observer.inner = trace
        cell = cell_of(inputs)       # the cell file, read once for the robot and the controller
        controller = Controller(robot_for(program, workspace, robot, cell),
                                trace=observer if observer is not None else trace,
                                stimuli=cell, mujoco=mujoco, mode_op=mode)
    rt = Runtime(program, workspace=workspace, controller=controller, trace=trace,
                 max_sim_time=max_sim_time, max_steps=max_steps, robot_budget=robot_budget,
                 submits=list(submit or ()), check=check)
    if run_mode is not None:
        rt.set_run_mode(run_mode)
    if observer is not None:
        # The interpreters trace into the user's trace only: without one the VM keeps its
        # quiet fast path (Runtime.quiet_limit); the observer needs the controller's events.
        rt.trace = trace
    number = pgno if pgno is not None else getattr(controller, "pgno", None)
    if number is not None:
        controller.rules += _pgno_rules(rt, Path(program).stem, number)
    if controller.stimuli or controller.rules:
        from robot.stimuli import resolve_signals  # noqa: PLC0415

        try:
            resolve_signals(controller.stimuli, lambda name: signal_of(rt, Path(program).stem, name),
                            controller.rules)
        except ResourceError:
            pass    # a data list past a limit: the program does not start (Runtime.main_routine says why)
    attach_network(rt, program, workspace, network if network is not None else getattr(controller, "cell_network", None))
    if interp == "vm":
        from interp.vm import VM  # noqa: PLC0415

        interp = VM(rt, loop=vm_loop)
    else:
        interp = TreeInterpreter(rt)
    rt.add_task("robot", Path(program).stem, lambda: interp.run_program())
    for sub in submit or ():
        sp = Path(sub).resolve()
        rt.add_task("submit", sp.stem, lambda name=sp: interp.run_program(name))
    return rt, interp


def attach_network(rt: Runtime, program, workspace, settings) -> None:
    """The run's network hub (net/hub.py) on `rt`'s controller, with `settings` (None: no
    partner). Raises net.hub.NetError when a partner's server cannot start."""
    from krl.project import backup_of  # noqa: PLC0415
    from net.hub import Network  # noqa: PLC0415

    from interp.runtime.netvars import RuntimeSink  # noqa: PLC0415

    old = getattr(rt.controller, "network", None)
    if old is not None:
        old.close()
    root = backup_of(Path(program).resolve(), Path(workspace).resolve() if workspace else None)
    net = Network(settings, program=Path(program).resolve(), backup=root, sink=RuntimeSink(rt))
    amap = None
    if settings is not None and (settings.modbus is not None or settings.opcua is not None):
        amap = plc_map(rt, Path(program).stem)
    try:
        net.attach(rt.controller, amap)
    except OSError as exc:
        net.close()
        from net.hub import NetError  # noqa: PLC0415

        raise NetError(f"a network partner cannot start: {exc.strerror or exc}") from None


def plc_map(rt: Runtime, main: str):
    """The PLC's address map (net/plc.py) derived from the cell: the inputs and outputs its
    rules, stimuli and program-number handshake (``PGNO_*`` of $config.dat) use, and the
    SIGNALs of the global declarations on ``$IN``/``$OUT``."""
    import re  # noqa: PLC0415

    from net.plc import derive_map  # noqa: PLC0415
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


def _pgno_rules(rt: Runtime, main: str, number: int) -> list:
    """The PLC's rules of P00's program-number handshake answering `number`, with the
    ``PGNO_*`` parameters the program sees ($config.dat)."""
    from robot.cellpresets import PGNO_PARAMETERS, PresetError, pgno_rules  # noqa: PLC0415
    from robot.stimuli import StimulusError  # noqa: PLC0415

    params = {}
    for name in PGNO_PARAMETERS:
        value = global_value(rt, main, name)
        if isinstance(value, int) and not isinstance(value, bool):
            params[name] = value
    try:
        return pgno_rules(params, number)
    except PresetError as exc:
        raise StimulusError(f"--pgno {number}: {exc}") from None


def global_value(rt: Runtime, main: str, name: str):
    """The value of the variable `name` as the program `main` sees it (its data list, then the
    global declarations: $config.dat), or None when there is none or it has no value."""
    prog = rt.program
    module = prog.module_of(prog.main_path) if main.upper() == prog.main_path.stem.upper() else prog.module(main)
    scope = prog.ws.units[module.index].scope if module is not None else prog.ws.global_scope
    sym = scope.lookup(name) if scope is not None else None
    if sym is None or sym.kind not in ("var", "const"):
        return None
    try:
        return rt.storage_ref(prog.ws.resolver.storage(name, sym, None, module.index if module else -1), None).get()
    except KrlRuntimeError:
        return None


def cell_of(inputs):
    """The cell file `inputs` read by its one loader (robot.stimuli.load_cell), or `inputs`
    itself when it is a Cell already, or None. Raises robot.stimuli.StimulusError."""
    if not inputs:
        return None
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
    from krl.project import backup_of  # noqa: PLC0415
    from robot.machine import MachineData, load_machine  # noqa: PLC0415
    from robot.mada import load_robot, robot_of_backup  # noqa: PLC0415

    if isinstance(robot, MachineData):
        return robot
    if robot is None and inputs:
        robot = cell_of(inputs).robot
    if robot is not None:
        return load_robot(robot)
    root = backup_of(Path(program).resolve(), Path(workspace).resolve() if workspace else None)
    found = robot_of_backup(root) if root is not None else None
    return found if found is not None else load_machine()


def signal_of(rt: Runtime, main: str, name: str) -> tuple[str, int, int | None] | None:
    """``(base, first, last)`` of the SIGNAL `name` seen by the program `main`: its data list,
    then the global declarations of every module ($config.dat, public data lists loaded on
    demand, as the program's own name lookup does). None if there is no such SIGNAL."""
    from interp.runtime.memory import SignalRef  # noqa: PLC0415

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
