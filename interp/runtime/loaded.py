"""A program loaded for a run, apart from the run: :class:`LoadedProgram` (issue 76;
docs/architecture.md "How a run is built").

It holds now what a run's program *is* once loaded, before anything runs: the robot's machine
data, the I/O image its data lists' SIGNALs view, the data memory, the system variables with
their boot values and the machine data's, the program (its files loaded, checked and resolved,
every data list initialised: interp/runtime/program.py), the stand-ins for KUKA's software the
backup lacks (kss.py) and what a name denotes (names.py). No controller, no network hub, no
trace, no task: a tool that only reads a data list's initial values (interp/reach.py,
interp/cellinit.py, interp/run.py ``global_value``) builds this alone, and a run is built on it
(interp/run.py ``make_runtime``: ``LoadedProgram(spec)``, ``plan_cell(loaded, spec)``,
``Runtime(loaded, plan, spec, sinks)``). The split follows MuJoCo's ``MjModel``/``MjData``:
the model of the simulation, built once and read, apart from the simulation that runs on it;
here the loaded data memory is the run's own (one LoadedProgram serves one run).

Its parts read what they need through their owner (``rt``): the LoadedProgram while the
program loads, the run once :meth:`LoadedProgram.attach` hands them to it (a computed system
variable reads the run's controller, a stand-in's note goes to its message log).
"""

from __future__ import annotations

from robot.io import IOImage

from .kss import SystemSoftware
from .memory import DataMemory
from .names import Names
from .program import Program
from .sysvars import SysVars


class LoadedProgram:
    """The program of the run `spec` (interp/spec.py RunSpec, its robot given) loaded (module
    docstring): ``machine`` (robot.machine.MachineData), ``io`` (robot.io.IOImage: the
    controller takes it whole), ``memory`` (memory.DataMemory), ``sysvars`` (sysvars.SysVars),
    ``program`` (program.Program), ``modules`` (its modules by index), ``kss``
    (kss.SystemSoftware), ``names`` (names.Names); ``notes``: the messages given while it
    loads (a type the backup does not declare, a system variable not simulated), which the
    run's controller logs once it is built. Raises what loading a program raises
    (program.Program: none for bad KRL, which is recorded and stops the run when it starts)."""

    __slots__ = ("machine", "io", "memory", "sysvars", "program", "modules", "kss", "names", "notes", "run")

    #: a loaded program has no controller (its system variables ask: sysvars.py
    #: ``start_workspaces``)
    controller = None

    def __init__(self, spec) -> None:
        self.machine = spec.robot
        self.io = IOImage()
        self.notes: list[str] = []
        self.run = None
        self.memory = DataMemory()
        self.sysvars = SysVars(self)
        self.program = Program(self, spec.program, spec.workspace, [str(s) for s in spec.submit], spec.check)
        self.kss = SystemSoftware(self)
        self.modules = self.program.modules       # by Storage.owner / Callee.owner
        self.names = Names(self.program, self.sysvars, self.kss, self)

    def message(self, text: str) -> None:
        """A message while the program loads: kept in :attr:`notes` for the run's controller."""
        self.notes.append(text)

    def attach(self, run) -> None:
        """Hand the parts to `run` (interp/runtime/core.py Runtime, while it is built): from now
        on they read the run (its controller, its running task) and give their messages to it.
        Raises ValueError for a second run: the data memory is one run's."""
        if self.run is not None:
            raise ValueError("a loaded program serves one run")
        self.run = run
        for part in (self.sysvars, self.program, self.kss, self.names):
            part.serve(run)
