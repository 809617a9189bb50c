"""A program's model, shared by many runs, and a run's own data: :class:`ProgramModel` and
:class:`RunData` (issue 87 item 1; docs/architecture.md "How a run is built").

It holds now the split MuJoCo makes between ``MjModel`` (the model of the simulation, built
once and only read) and ``MjData`` (the state of one simulation, made from the model and
written by it alone; MuJoCo's documentation, "Overview", "Separation of model and data"):

* :class:`ProgramModel`: the program of a run loaded once (interp/runtime/program.py: its files
  loaded, checked and resolved, the code and the checked workspace; every data list
  initialised), the robot's machine data, the system variables with their boot values and the
  machine data's, the I/O image at boot, the data memory its data lists take, the stand-ins of
  KUKA's software (kss.py) the load used and the notes it gave. Once loaded it is *frozen*
  (:meth:`ProgramModel._freeze`): its attributes cannot be set, each data list's values and the
  system variables are held in tuples and read-only mappings, so that a write to any of them
  raises (TypeError, AttributeError) instead of reaching another run.
* :class:`RunData`: what one run (interp/runtime/core.py Runtime) or one tool (interp/reach.py,
  interp/cellinit.py, interp/run.py ``plan_cell``) owns: the I/O image, the data memory, the
  system variables, the program's data lists (values copied, references its own: a data list
  when the owner first reads it, program.py ``ModuleRT.copy``), the stand-ins and what a name
  denotes (names.py), each copied from the model (:meth:`ProgramModel.data`; the copiers of
  its frozen values: frozen.py) for that owner and never handed to another.

One model serves any number of runs, one after the other or at once (threads): the runs share
its code and read its images, which nothing writes. :func:`load_model` keeps the models of a
process with their checked workspace (program.py ``checked_workspace``: the files, their sizes
and times; kept within krl/limits.py ``MODEL_CACHE_BYTES``, each model charged
``MODEL_BASE_BYTES`` to its workspace's entry: program.py ``charge_models``), one per robot (at most
:data:`MODELS_PER_WORKSPACE`): every program of a backup's files runs on one model (which
program runs, its interpreter, its limits, its cell and whether it is checked are the run's:
:meth:`ProgramModel.data`); a model goes with its workspace.

The robot is part of the model, not of the run: the load reads its machine data (the system
variables' boot values: ``$VEL``, ``$ACC``, ``$ADVANCE``, ``$H_POS``, the soft limits, ``$ROBROOT``;
the Mada data list's robot variables follow them: program.py ``Program._robot_values``), as the
controller reads its machine data at boot. What is costly is shared across robots: a model on a
workspace already checked takes 0.04-0.07 s to build (the palletizer backup, KRC4_test's
SPS.SUB), its workspace 0.4 s (parses from the store) to 3 s.

Not frozen, because they are memos of the code that any run fills in the same way: the
checked workspace's ``run_facts`` (program.py ``Program.derived``) and the facts the
interpreters and the fast-forward note on the AST (``ann.extra``).
"""

from __future__ import annotations

import threading
from collections import Counter
from types import MappingProxyType

from krl.files import spelled_within
from robot.io import IOImage

from .errors import KrlRuntimeError
from .frozen import StoreImage, freeze
from .kss import SystemSoftware
from .memory import DataMemory, Slot
from .names import Names
from .program import Program, charge_models, checked_workspace, program_files
from .sysvars import SysVars

#: the models a process keeps per checked workspace, one per robot (a backup run on its own
#: robot and on another: ``--robot``, ``--inputs auto``'s probe on the KR 6 R900); past it the
#: least recently used goes (it is built again on the cached workspace when asked for)
MODELS_PER_WORKSPACE = 4
#: the key of a checked workspace's models in its ``run_facts`` (program.py ``Program.derived``)
_MODELS = "program models"
#: the models this process loaded, by the checked workspace's folder and the robot's name
#: (``"<folder> on <robot>"``): how often each backup's model was built on each robot (the suite's
#: profile reports it per worker: tests/cpu_profile.py; issue 87: "make test loads each backup's
#: model once"; a backup run with ``--inputs auto`` and no machine data has two: the probe's on
#: the KR 6 R900, interp/run.py ``robot_for``, and the chosen robot's)
LOADS: Counter = Counter()
_LOCK = threading.Lock()
#: the I/O image's state (robot/io.py IOImage): what a run copies of the model's
_IO_STATE = ("_in", "_out", "_anin", "_anout", "timer_ms", "timer_stop")


class RunData:
    """One owner's copy of a model (module docstring): ``model`` (the :class:`ProgramModel`),
    ``machine`` (robot.machine.MachineData, the model's), ``io`` (robot.io.IOImage: a run's
    controller takes it whole), ``memory`` (memory.DataMemory), ``sysvars`` (sysvars.SysVars),
    ``program`` (program.Program), ``modules`` (its modules by index), ``kss``
    (kss.SystemSoftware), ``names`` (names.Names) and ``notes``: the messages given while no
    controller exists (the model's load's first), which a run's controller logs once it is
    built."""

    __slots__ = ("model", "machine", "io", "memory", "sysvars", "program", "modules", "kss", "names", "notes")

    def message(self, text: str) -> None:
        """A message while no controller exists: kept in :attr:`notes`."""
        self.notes.append(text)


class ProgramModel:
    """The program of the run `spec` (interp/spec.py RunSpec, its robot given) loaded once and
    frozen (module docstring). ``machine``, ``io``, ``memory``, ``sysvars``, ``program``,
    ``modules``, ``kss``: the load's, only read; ``notes``: the messages the load gave (a type
    the backup does not declare, a system variable not simulated), a tuple. Raises what loading
    a program raises (program.Program: none for bad KRL, which is recorded and stops a run
    when it starts). `files`: (main path, project, extra files, checked workspace) when the
    caller found them (:func:`load_model`), else found here. Build one through
    :func:`load_model`; read it through :meth:`data`."""

    __slots__ = ("machine", "io", "memory", "sysvars", "program", "modules", "kss", "notes", "_frozen")

    def __init__(self, spec, files: tuple | None = None) -> None:
        notes: list[str] = []
        set_ = object.__setattr__
        set_(self, "_frozen", False)
        self.machine = spec.robot
        self.io = IOImage()
        self.memory = DataMemory()
        self.sysvars = SysVars(self.machine, self.io, notes.append)
        self.program = Program(spec.program, spec.workspace, [str(s) for s in spec.submit], spec.check,
                               self.sysvars, self.memory, notes.append, _system_ref(self.sysvars), files)
        self.kss = SystemSoftware(self.program, notes.append)
        self.modules = self.program.modules       # by Storage.owner / Callee.owner
        self.notes = tuple(notes)
        self._freeze()
        set_(self, "_frozen", True)

    def __setattr__(self, name, value) -> None:
        if self._frozen:
            raise AttributeError(f"a program model is only read: {name} cannot be set")
        object.__setattr__(self, name, value)

    def data(self, run=None, message=None, clock=None, spec=None) -> RunData:
        """A copy of this model for one owner (:class:`RunData`): `run` (interp/runtime/sysvars.py
        RunReads: the parts of the run being built; None for a tool) is what its computed system
        variables read,
        `message` (``message(text)``; None: the copy's ``notes``) where its parts' messages go,
        `clock` (scheduler.RunClock or None) whose running task VARSTATE's text is read in;
        `spec` (interp/spec.py RunSpec; None: the model's) names the program that runs, any of
        the model's files (:func:`load_model`), and whether it is checked."""
        d = RunData()
        d.model, d.machine = self, self.machine
        d.notes = list(self.notes)
        message = message or d.message
        d.io = IOImage()
        for name in _IO_STATE:
            value = getattr(self.io, name)
            setattr(d.io, name, bytearray(value) if isinstance(value, (bytes, bytearray)) else list(value))
        d.memory = DataMemory(self.memory.limit)
        d.memory.used = self.memory.used
        d.sysvars = self.sysvars.copy(d.io, message, run)
        main = check = None
        if spec is not None:
            main, check = spelled_within(spec.program, spec.workspace), spec.check
        d.program = self.program.copy(d.sysvars, d.memory, message, lambda st: d.names.sysref(st), main, check)
        d.sysvars.declared_as(self.sysvars, d.program.own_ref)
        d.modules = d.program.modules
        d.kss = self.kss.copy(d.program, message)
        d.names = Names(d.program, d.sysvars, d.kss, clock)
        return d

    def _freeze(self) -> None:
        """Make every value the model holds read-only (module docstring): the data lists'
        stores and the system variables' become tuples and read-only mappings, each value's
        components and elements too (frozen.py: each store kept with the copiers a run's copy
        takes, ``image``), the references re-pointed at them."""
        for m in self.program.modules:
            old = m.store
            m.image = StoreImage(old)
            m.store = m.image.values
            for ref in list(m.refs) + list(m.data.values()):
                if isinstance(ref, Slot) and ref.c is old:
                    ref.c = m.store
                elif isinstance(ref, Slot) and isinstance(ref.c, dict):     # a SIGNAL always FALSE
                    ref.c = MappingProxyType(ref.c)
            m.refs, m.errors, m.syntax_errors = tuple(m.refs), tuple(m.errors), tuple(m.syntax_errors)
            m.data = MappingProxyType(m.data)
        sv = self.sysvars
        sv.image = StoreImage(sv.store)
        sv.store = sv.image.values
        sv.refs, sv.declared = MappingProxyType(sv.refs), MappingProxyType(sv.declared)
        sv.noted = frozenset(sv.noted)
        kss = self.kss
        for ref in kss._refs.values():
            c = dict(ref.c)
            for v in c.values():
                freeze(v)
            ref.c = MappingProxyType(c)
        kss.uses, kss.standins = MappingProxyType(dict(kss.uses)), MappingProxyType(kss.standins)
        kss._refs = MappingProxyType(kss._refs)
        prog = self.program
        prog.stubs, prog.sysrefs = frozenset(prog.stubs), tuple(prog.sysrefs)
        prog.freeze_modules()
        for name in _IO_STATE:
            value = getattr(self.io, name)
            setattr(self.io, name, bytes(value) if isinstance(value, bytearray) else tuple(value))


def _system_ref(sysvars: SysVars):
    """The reference of a system variable a data list's initialiser names, while the model
    loads (program.Program ``system_ref``): the tables' or a system data list's; KrlRuntimeError
    "unknown name" else (the data list records it)."""
    def ref(st):
        r = sysvars.lookup(st.name)
        if r is None:
            raise KrlRuntimeError(f"unknown name {st.name}", name=st.name)
        return r
    return ref


def load_model(spec) -> ProgramModel:
    """The model of the program of `spec` (interp/spec.py RunSpec, its robot given): the one this
    process loaded for the same checked files and robot (module docstring), else loaded now.
    Safe to call from several threads (one loads at a time). Raises what
    :class:`ProgramModel` raises."""
    main, project, extra = program_files(spec.program, spec.workspace, [str(s) for s in spec.submit])
    with _LOCK:
        ws = checked_workspace(project, extra)
        models = ws.run_facts.setdefault(_MODELS, {})      # id(robot) -> model, least recent first
        model = models.pop(id(spec.robot), None)
        built = model is None or model.machine is not spec.robot
        if built:
            model = ProgramModel(spec, (main, project, extra, ws))
            LOADS[f"{getattr(project, 'root', project)} on {spec.robot.name}"] += 1
        models[id(spec.robot)] = model
        while len(models) > MODELS_PER_WORKSPACE:
            del models[next(iter(models))]
        if built:
            charge_models(ws, len(models))
        return model
