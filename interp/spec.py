"""One run described once: :class:`RunSpec` (issues 62 and 76; docs/architecture.md "One run
specification").

A run of a KRL program is one typed, frozen value of pure data: the program and its files, the
cell, the robot and where its data came from, the limits, the modes, where the robot starts, the
submit programs, the network partners, the interpreter, whether an operator answers the message
window and whether the run fast-forwards. Where the run writes (its trace, an observer of the
controller) is no part of it: those sinks go to ``make_runtime`` beside it (interp/run.py
``RunSinks``). Each front door builds it once and validates it there — ``krl run`` and the
debugger's launch (interp/run.py ``run_setup``, from krl run's options), the pendant (through
the debugger's engine), the audit and the change report (interp/outcomes.py,
interp/realprograms.py, through ``run_spec``: the same ``spec_of``), the conformance suites
(through ``krl run``) — and ``interp.run.make_runtime(spec, sinks)`` builds the run from it: a
complete controller and runtime that nobody patches afterwards.

The schema is here, once: each field's metadata is an :class:`Option` (its flag, help text,
type, choices, range, default; a number's units in its help) or says why the field is none; with
:data:`DOOR_OPTIONS` (krl run's options that are no field: the trace, how submit programs are
found) it makes krl run's click options (interp/cli.py ``run_command``) and the debugger's
launch schema (interp/debug/launch.py ``launch_schema``), and :func:`spec_values` turns krl
run's options into the fields (tests/interp/test_run_schema.py compares the three). Nothing
downstream restates a default. The shape follows MuJoCo's ``MjModel``/``MjData`` split (what a
simulation *is*, fixed; what it *does*, the state) and Cargo's and Django's settings (read once
into one typed value at the front door, passed down whole).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import Field, dataclass, field, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING

from krl.limits import MAX_HALT_CONTINUES
from net.settings import NetworkSettings
from robot.machine import MachineData
from robot.stimuli import Cell
from robot.trace import TRACE_REPEATS

if TYPE_CHECKING:
    # read by typing.get_type_hints with its module (tests/interp/test_run_schema.py); imported
    # here only for the checker: robot/collision.py (4.5 ms) loads when a run checks collisions
    from robot.collision import CellGeometry

#: ``krl run --max-sim-time``: the simulated time a run may take (s)
RUN_SIM_TIME_S = 600.0
#: the program run mode at the start ($PRO_MODE)
RUN_MODE = "GO"
#: the interpreter
INTERP = "tree"
#: the VM's dispatch loop: "generated" (interp/vm/loop.py, compiled when built) or "python"
VM_LOOP = "generated"
#: the interpreters a run may use
INTERPS = ("tree", "vm")
#: the run modes
RUN_MODES = ("GO", "MSTEP", "ISTEP", "BSTEP")
#: the operating modes ``--mode`` offers ($MODE_OP; robot/limits.py: EXT is Automatic External)
MODES = ("T1", "T2", "AUT", "EXT")
#: what the spin watch does with a spin (interp/runtime/spin.py): park it, nothing, or shadow it
SPINS = ("park", "off", "shadow")
#: ``--on-halt continue`` without a count: the operator presses Start again at most this often
HALT_CONTINUES = 10


class SpecError(ValueError):
    """A run specification that does not describe a run (a usage error)."""


def halt_continues_of(text: str | None) -> int:
    """The times the operator presses Start again after a HALT, of ``--on-halt``'s text:
    ``stop`` 0, ``continue`` :data:`HALT_CONTINUES`, ``continue:N`` N (1 <= N <=
    krl.limits.MAX_HALT_CONTINUES). Raises :class:`SpecError` for anything else."""
    t = (text or "stop").strip().lower()
    if t == "stop":
        return 0
    if t == "continue":
        return HALT_CONTINUES
    if t.startswith("continue:") and t[9:].isdigit() and 1 <= int(t[9:]) <= MAX_HALT_CONTINUES:
        return int(t[9:])
    raise SpecError(f"--on-halt {text!r}: stop, continue or continue:N (N 1..{MAX_HALT_CONTINUES})")


def _not(flag: bool) -> bool:
    return not flag


@dataclass(frozen=True)
class Option:
    """How a setting of a run is given: as an option of ``krl run`` (interp/cli.py builds its
    click option from this) and as an attribute of ``krl debug``'s launch configuration
    (interp/debug/launch.py builds its JSON schema from this: the long option in camelCase).

    ``flag``: the long option (``--max-sim-time``), "" for the argument PROGRAM; ``param``:
    click's parameter name (the key of ``run_setup``'s options; "" for the field's name);
    ``help``: the help text; ``kind``: the type of the value given (str, int, float, Path; bool
    for a flag); ``choices`` (matched case-insensitively unless ``case_sensitive``);
    ``minimum``/``maximum``: an integer's range (a number's units are said in ``help``);
    ``multiple``: repeatable (a tuple; an array in the launch); ``metavar``, ``show_default``:
    as click's. ``default``: the value when the option is not given; for a field's option
    :func:`option` takes it from the field (through ``to_field`` backwards: a flag's False).
    ``to_field``: the field's value of the option's (``--no-check``: check is its negation;
    ``--on-halt``: the count), None: the same value. ``door``: the front door resolves the
    value into the spec (interp/run.py ``_setup``: a path found in an archive, a cell file
    read, a robot loaded) rather than ``to_field``."""
    flag: str
    help: str
    param: str = ""
    kind: type = str
    choices: tuple[str, ...] = ()
    case_sensitive: bool = True
    minimum: int | None = None
    maximum: int | None = None
    multiple: bool = False
    metavar: str | None = None
    show_default: bool = False
    default: object = None
    to_field: Callable[..., object] | None = None
    door: bool = False

    def field_value(self, value: object) -> object:
        """The spec's value of the option's `value` (``to_field``, else the value itself)."""
        return self.to_field(value) if self.to_field is not None else value


#: a field's metadata key: its :class:`Option`, or why it is not one (:data:`NOT_AN_OPTION`)
OPTION = "option"
NOT_AN_OPTION = "not_an_option"


def option(value: object, flag: str, help: str, **meta: object) -> Field:
    """A RunSpec field set by the krl run option `flag` (and the launch attribute of its name):
    its default `value`, its :class:`Option` (``meta``: Option's fields). A flag's option
    default is False; any other option's is the field's default (``meta["default"]`` for an
    option whose value is not the field's: ``--on-halt stop``)."""
    meta.setdefault("default", False if meta.get("kind") is bool else value)
    return field(default=value, metadata={OPTION: Option(flag, help, **meta)})


def internal(default: object, why: str) -> Field:
    """A RunSpec field that is no option of krl run or the launch: `why` (the front door or a
    tool sets it)."""
    return field(default=default, metadata={NOT_AN_OPTION: why})


#: krl run's options that are no field of the spec, by click name: where the run writes (its
#: trace is a sink: interp/run.py RunSinks, RunSetup.trace_writer) and how the submit
#: programs are found (the front door's: interp/run.py ``_setup``)
DOOR_OPTIONS: dict[str, Option] = {
    "trace_path": Option("--trace", "Write the JSONL trace here.", param="trace_path", kind=Path),
    "no_submit": Option("--no-submit", "Run without the backup's SPS.SUB.", kind=bool, default=False),
    "trace_repeats": Option(
        "--trace-repeats",
        "A spin in the trace: a pass of events repeated with nothing changed but time (the same "
        "events and values, the same state of the run) is written this many times, then counted "
        "in a `repeat` event; a loop whose state changes keeps every event; 0 writes every event.",
        kind=int, minimum=0, default=TRACE_REPEATS, show_default=True),
}

#: krl run's parameters in the order of ``krl run --help`` and the launch schema: a RunSpec
#: field's name or a :data:`DOOR_OPTIONS` key
RUN_OPTIONS = ("program", "interp", "workspace", "cell", "trace_path", "max_sim_time", "max_steps", "submit",
               "no_submit", "mode", "run_mode", "pgno", "check", "robot", "start", "override", "halt_continues",
               "trace_repeats")


@dataclass(frozen=True, slots=True)
class RunSpec:
    """One run (module docstring): pure data, every field typed. Paths as the user spelled them.
    Each field says how it is given (its metadata: an :class:`Option` of krl run and the launch,
    or why it is none); the run's sinks (its trace, an observer) are no part of it
    (interp/run.py ``RunSinks``).

    ``program``: the .src (or a .sub) run as the robot program; ``workspace``: the folder of its
    modules (None: the program's folder, a KRC backup above it found: krl/project.py);
    ``submit``: the submit programs run beside it; ``booted``: the one of them that is the
    backup's SPS.SUB started as at boot (said in the run summary), else None.
    ``cell``: the cell file read once (robot.stimuli.Cell: stimuli, rules, presets, start,
    network) or None; ``auto``: ``--inputs auto`` (interp/runtime/autocell.py) instead of a cell.
    ``robot``: the simulated robot (robot.machine.MachineData, its ``source`` says where its data
    came from); None: interp/run.py ``robot_for`` picks it when the run is built.
    ``max_sim_time`` (s) and ``max_steps`` (the robot interpreter's steps): None for no limit.
    ``mode``: the operating mode asked for (T1, T2, AUT, EXT) or None (derived: a cell program,
    the cell's autoext preset and ``--inputs auto`` run in EXT, else AUT); ``run_mode``:
    $PRO_MODE at the start; ``halt_continues``: the times the operator presses Start again after
    a HALT; ``override``: the program override $OV_PRO (1..100 %) the operator set before the
    start (``krl run --override``; None: the controller's 100, the program may change it);
    ``pgno``: the program number the cell's PLC answers in P00's handshake; ``start``:
    where the robot starts (an E6AXIS literal or a point name; None: the cell's ``start:``, else
    XHOME for a cell, else $AXIS_HOME[1]).
    ``network``: the partners (net.settings.NetworkSettings; None: the cell's ``network:``).
    ``geometry``: the bodies, tool and floor the robot is checked against at every IPO cycle
    (robot/collision.py CellGeometry; None: the cell's ``geometry:``/``tool:``/``floor:``, else
    no collision check).
    ``interp``: tree or vm; ``vm_loop``: the VM's loop; ``check``: a program whose own module
    the checker rejects does not start; ``mujoco``: the arm's MuJoCo model; ``robot_budget``:
    the robot program's time slice in steps (None: the robot interpreter's, a .sub's is the
    submit interpreter's).
    ``interactive``: an operator answers the message window (the pendant: a QUIT message waits
    for its acknowledgement, interp/runtime/messages.py); ``fast_forward``: the run skips
    what repeats unchanged (the idle watch, interp/runtime/idle.py, and the spin watch,
    interp/runtime/spin.py, and the clock jumps, interp/runtime/jump.py; False: every cycle
    and pass is run, as the tests compare); ``clock_jumps`` False: the fast-forward without
    the clock jumps;
    ``spins``: with the fast-forward, what the spin watch does with a spin: ``park`` it, ``off``
    (the idle watch alone) or ``shadow`` (parked and run on, each pass compared with what
    parking gave: tests/interp/test_spin.py)."""

    program: Path = field(metadata={OPTION: Option(
        "", "The KRL program to run: a .src file (its main routine); with a backup .zip as workspace, its path "
        "in the archive or its module name.", kind=Path, door=True)})
    workspace: Path | None = option(
        None, "--workspace", "Folder of the program's modules, or a KRC backup .zip (default: the program's folder; "
        "a KRC backup is detected).", kind=Path, door=True)
    submit: tuple[Path, ...] = option(
        (), "--submit", "A submit program (.sub) to run beside the robot program (repeatable). Default: in a KRC "
        "backup, its SPS.SUB, as the controller starts it at boot.", kind=Path, multiple=True, door=True)
    booted: Path | None = internal(None, "the front door finds the backup's SPS.SUB (krl.project boot_submit)")
    cell: Cell | None = option(
        None, "--inputs", "A cell file (stimuli, rules, presets: robot/stimuli.py), or `auto`: the automatic cell "
        "sets the inputs the program starves for (interp/runtime/autocell.py; docs/robot.md).",
        param="inputs", kind=Path, door=True)
    auto: bool = internal(False, "--inputs auto (the option of the field cell)")
    wired: tuple[int, ...] = internal((), "a robot of a cell of several (interp/robotcell.py): the $IN numbers "
                                "its partners' wires drive, never the automatic cell's to answer")
    robot: MachineData | None = option(
        None, "--robot", "The robot to simulate: a robot YAML, a $machine.dat, a KRC backup folder or .zip "
        "(default: the robot the --inputs cell file names, else the backup's own robot from its "
        "R1/Mada/$machine.dat, else the KR 6 R900).", kind=Path, door=True)
    max_sim_time: float | None = option(
        RUN_SIM_TIME_S, "--max-sim-time", "Simulated-time limit (s).", kind=float, show_default=True)
    max_steps: int | None = option(
        None, "--max-steps", "Limit of the robot program's executed statements and loop iterations (its interrupt "
        "routines and TRIGGER actions included; a submit program's are not counted). Default: none, the time "
        "limit bounds the run (docs/architecture.md, \"The step limit\").", kind=int)
    mode: str | None = option(
        None, "--mode", "Operating mode ($MODE_OP): T1 limits TCP and flange to 250 mm/s and PTP to $RED_T1; AUT "
        "is the unattended virtual controller (docs/robot.md). Default AUT; EXT for a cell program (&COMMENT "
        "HANDLER on external automatic, or a call of P00 (#INIT_EXT, ...)), with --inputs auto, or when the "
        "--inputs cell file has the autoext preset.", choices=MODES, case_sensitive=False)
    run_mode: str = option(
        RUN_MODE, "--run-mode", "Program run mode ($PRO_MODE): MSTEP stops after each motion, ISTEP after each "
        "statement (no advance run, no approximation); BSTEP runs forward as MSTEP, then retraces the motions "
        "backward (T1/T2 only). Each stop is a step_stop trace event and the run goes on, as if Start were "
        "pressed again (docs/robot.md).", choices=RUN_MODES, case_sensitive=False, show_default=True)
    halt_continues: int = option(
        0, "--on-halt", "After a HALT: stop the run, or `continue`: the operator presses Start again (at most N "
        "times, default 10; then the HALT ends the run).", param="on_halt", default="stop", metavar="stop|continue[:N]",
        show_default=True, to_field=halt_continues_of)
    override: int | None = option(
        None, "--override", "The program override $OV_PRO (%) the operator set before the start (default 100): "
        "every motion takes its time at 100 % divided by it, as on a KR C4 (docs/robot.md).", kind=int,
        minimum=1, maximum=100, metavar="PCT")
    pgno: int | None = option(
        None, "--pgno", "Program number the cell's PLC answers in P00's handshake (PGNO_* of the backup's "
        "$config.dat; robot/cellpresets.py, docs/robot.md).", kind=int, minimum=1, maximum=65535)
    start: str | None = option(
        None, "--start", "Where the robot stands at the start: an E6AXIS literal (\"{A1 0, A2 -90, A3 90, A4 0, "
        "A5 0, A6 0}\") or a point of the program such as XHOME (default: the cell file's start:, for a cell "
        "program or with --inputs auto XHOME, else $AXIS_HOME[1]).", metavar="AXIS_OR_POINT")
    network: NetworkSettings | None = internal(None, "the cell file's network: key, or a test's partners")
    geometry: CellGeometry | None = internal(None, "the cell file's geometry:, or a bench's (--collision)")
    interp: str = option(INTERP, "--interp", "Interpreter.", param="interp_kind", choices=INTERPS,
                         show_default=True)
    vm_loop: str = internal(VM_LOOP, "the VM's loop: the tests and the benches compare the two")
    check: bool = option(
        True, "--no-check", "Start the program even when the front end's checker finds errors in its own module "
        "(by default, like the controller, such a program does not start: exit 1). A name nothing declares is "
        "then a run-time error where it is evaluated.", param="no_check", kind=bool, to_field=_not)
    mujoco: bool = internal(True, "the tools run without the arm's MuJoCo model")
    robot_budget: int | None = internal(None, "a test's time slice of the robot program")
    interactive: bool = internal(False, "the pendant's: an operator answers the message window")
    fast_forward: bool = internal(True, "the tests and the benches compare runs with and without it")
    clock_jumps: bool = internal(True, "the tests compare runs with and without the clock jumps alone")
    spins: str = internal(SPINS[0], "the tests compare runs with the spin watch off or shadowing")

    def __post_init__(self) -> None:
        # normalised once here, so that nothing downstream converts them again
        object.__setattr__(self, "program", Path(self.program))
        if self.workspace is not None:
            object.__setattr__(self, "workspace", Path(self.workspace))
        object.__setattr__(self, "submit", tuple(Path(s) for s in self.submit))
        object.__setattr__(self, "run_mode", str(self.run_mode or RUN_MODE).upper())
        if self.interp not in INTERPS:
            raise SpecError(f"interpreter {self.interp!r}: one of {', '.join(INTERPS)}")
        if self.run_mode not in RUN_MODES:
            raise SpecError(f"run mode {self.run_mode!r}: one of {', '.join(RUN_MODES)}")
        if self.max_sim_time is not None and not self.max_sim_time > 0:
            raise SpecError(f"max_sim_time {self.max_sim_time}: a positive number of seconds")
        if self.max_steps is not None and self.max_steps < 1:
            raise SpecError(f"max_steps {self.max_steps}: at least 1")
        if self.halt_continues < 0:
            raise SpecError(f"halt_continues {self.halt_continues}: not negative")
        if self.override is not None and not 1 <= self.override <= 100:
            raise SpecError(f"override {self.override}: 1..100 %")
        if self.spins not in SPINS:
            raise SpecError(f"spins {self.spins!r}: one of {', '.join(SPINS)}")
        if self.auto and self.cell is not None:
            raise SpecError("a cell file and --inputs auto: one or the other")

    def with_(self, **changes: object) -> "RunSpec":
        """This run with `changes` (a debugger's own step limit, the pendant's operator): a new spec."""
        return replace(self, **changes)


def run_options() -> list[tuple[str, Option]]:
    """krl run's parameters in :data:`RUN_OPTIONS` order: (the RunSpec field's name, or the
    :data:`DOOR_OPTIONS` key; its :class:`Option`)."""
    by_field = {f.name: f.metadata[OPTION] for f in fields(RunSpec) if OPTION in f.metadata}
    return [(name, by_field[name] if name in by_field else DOOR_OPTIONS[name]) for name in RUN_OPTIONS]


def param_of(name: str, opt: Option) -> str:
    """The click parameter name of the option `opt` of the field (or door option) `name`."""
    return opt.param or name


def spec_values(options: dict) -> dict:
    """The RunSpec fields given by krl run's `options` (by click name), each converted by its
    option (``to_field``); a missing option, or None for an option with a default, takes the
    option's default. The fields the front door resolves (``door``: the program, the
    workspace, the cell, the robot, the submit programs) are left to it. Raises
    :class:`SpecError` (an ``--on-halt`` that is none)."""
    out = {}
    for f in fields(RunSpec):
        opt = f.metadata.get(OPTION)
        if opt is None or opt.door:
            continue
        value = options.get(param_of(f.name, opt))
        out[f.name] = opt.field_value(opt.default if value is None else value)
    return out
