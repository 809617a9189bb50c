"""One run described once: :class:`RunSpec` (issue 62; docs/architecture.md "One run specification").

A run of a KRL program is one typed, frozen value: the program and its files, the cell, the
robot and where its data came from, the limits, the modes, where the robot starts, the submit
programs, the network partners, the interpreter, and where the run writes (its trace, an
observer of the controller). Each front door builds it once and validates it there —
``krl run`` and the debugger's launch (interp/run.py ``run_setup``, from krl run's options), the
pendant (through the debugger's engine), the audit and the change report (interp/outcomes.py,
interp/realprograms.py), the conformance suites (through ``krl run``) — and
``interp.run.make_runtime(spec)`` builds the run from it: a complete controller and runtime that
nobody patches afterwards. Nothing downstream restates a default: each lives here, and krl run's
options take theirs from here (interp/cli.py). The shape follows MuJoCo's ``MjModel``/``MjData``
split (what a simulation *is*, fixed; what it *does*, the state) and Cargo's and Django's
settings (read once into one typed value at the front door, passed down whole).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

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


class SpecError(ValueError):
    """A run specification that does not describe a run (a usage error)."""


@dataclass(frozen=True, slots=True)
class RunSpec:
    """One run (module docstring). Paths as the user spelled them.

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
    ``trace``: the run's trace writer (robot.trace.TraceWriter) or None; ``observer``: what
    sees the controller's events on their way to the trace (interp/summary.py RunObserver)."""

    program: Path
    workspace: Path | None = None
    submit: tuple[Path, ...] = ()
    booted: Path | None = None
    cell: Any = None
    auto: bool = False
    robot: Any = None
    max_sim_time: float | None = None
    max_steps: int | None = None
    mode: str | None = None
    run_mode: str = RUN_MODE
    halt_continues: int = 0
    override: int | None = None
    pgno: int | None = None
    start: str | None = None
    network: Any = None
    geometry: Any = None
    interp: str = INTERP
    vm_loop: str = VM_LOOP
    check: bool = True
    mujoco: bool = True
    robot_budget: int | None = None
    trace: Any = field(default=None, compare=False)
    observer: Any = field(default=None, compare=False)

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
        if self.auto and self.cell is not None:
            raise SpecError("a cell file and --inputs auto: one or the other")

    def with_(self, **changes) -> "RunSpec":
        """This run with `changes` (a debugger's own step limit, a replay's trace): a new spec."""
        return replace(self, **changes)
