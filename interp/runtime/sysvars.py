"""System variables wired to the simulated controller (reference §6.10, §7).

The table of names, types, access (RO/RW) and advance-run stop flags is the front end's
``krl/semantics/data/sysvars.yaml`` (read through :func:`krl.semantics.builtins.load_builtins`);
this module adds only *where the value lives*:

* live arrays on the controller's I/O image: ``$IN`` (RO), ``$OUT``, ``$ANIN`` (RO),
  ``$ANOUT``, ``$TIMER``, ``$TIMER_STOP``, ``$TIMER_FLAG`` (RO);
* computed values: ``$POS_ACT``, ``$AXIS_ACT`` (read back from the arm), ``$POS_INT`` /
  ``$AXIS_INT`` (captured when the running interrupt fired; "value invalid" elsewhere),
  ``$VEL_ACT``, ``$DATE``, ``$PRO_STATE*``, ``$PRO_MOVE``, ``$STOPMESS``, ``$MODE_OP``,
  ``$INTERPRETER``, ``$ERR`` (one per interpreter), ``$NULLFRAME``, ``$NUM_AX``, ...;
* everything else is stored (``store``), booting with the INITMOV values ("friendly mode",
  reference §7.3): the motion variables are read from there when a motion is planned;
* a system variable the table lacks: the value a KSS system data list of the program's files
  declares (``declare``), or, when only KSS's own files declare it (kss.yaml), its type with
  zero values; one ``message`` event per variable (:meth:`SysVars._unsimulated`). A ``$``
  name nothing declares is not created: the caller's run-time error "unknown name".
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import partial
from pathlib import Path

import numpy as np

from krl.semantics import types as T
from krl.semantics.builtins import load_builtins
from krl.semantics.facts import CLOCK, CONSTANT, ROBOT, SIGNALS, STATE, SYSVAR_READS, TASKS
from krl.semantics.symbols import make_array, system_scopes
from robot.axismap import CART_KEYS, E6AXIS_KEYS, EXT_KEYS, ROBOT_KEYS, AxisMap
from robot.motion import MotionParams

from .cmdchannel import STATE_VALUES
from .convert import frame_tuple
from .errors import KrlRuntimeError, value_invalid
from .memory import ComputedRef, LiveArray, Slot
from .values import UNSET, Arr, EnumValue, Struct, copy_value, make_value, struc_maker, zero_value
from .writerules import WriteHook, check
from robot.workspace import WorkspaceMonitor


def sys_type(name: str):
    system, basis = system_scopes()
    return basis.lookup_type(name)


#: system structure type name -> the maker of its fresh values (values.py ``struc_maker``; the
#: system scope is built once per process, krl/semantics/symbols.py ``system_scopes``)
_MAKERS: dict = {}
_N_AXIS_KEYS = len(E6AXIS_KEYS)
_AXIS_TAIL = [0.0] * _N_AXIS_KEYS
#: the E6AXIS type (:func:`axis_struct`), looked up once (its maker's)
_E6AXIS: list = [None]


def _maker(type_name: str):
    make = _MAKERS.get(type_name)
    if make is None:
        make = _MAKERS[type_name] = struc_maker(sys_type(type_name))
    return make


def struct_of(type_name: str, values: dict) -> Struct:
    """A fresh value of the system structure type `type_name` with the components of `values`
    (upper-cased keys) set, the others UNSET."""
    s = _maker(type_name)()
    f = s.f
    for k, v in values.items():
        f[k.upper()] = v
    return s


def axis_struct(values) -> Struct:
    """An E6AXIS of a KRL vector `values` (A1..A6, then E1..; robot/axismap.py ``to_krl``):
    every component given, 0 for the others. (INVERSE's result: a Find_Optimal_ST search makes
    one per call, issue 86.) The components in the type's order, as its fresh value has them:
    the dict is made in one pass (E6AXIS_KEYS is that order, :data:`_AXIS_TAIL` the zeros)."""
    # an array's tolist() gives the floats float() of each element gives, without a float64 each
    vals = values.tolist() if values.__class__ is np.ndarray else [float(v) for v in values]
    n = len(vals)
    if n < _N_AXIS_KEYS:
        vals += _AXIS_TAIL[n:]
    t = _E6AXIS[0]
    if t is None:
        t = _E6AXIS[0] = _maker("E6AXIS")().type
    return Struct(t, dict(zip(E6AXIS_KEYS, vals)))


def pos_struct(d: dict) -> Struct:
    """An E6POS of a dict {X, Y, Z, A, B, C, S, T, E1..E6} (the E components it lacks: 0)."""
    s = _maker("E6POS")()
    f = s.f
    for k in CART_KEYS:
        f[k] = float(d[k])
    f["S"] = int(d.get("S", 0))
    f["T"] = int(d.get("T", 0))
    for e in EXT_KEYS:
        f[e] = float(d.get(e, 0.0))
    return s


class RunReads:
    """What a run's computed system variables read of their run (issue 87 item 3: its parts, not
    the runtime; tests/interp/test_part_collaborators.py): the run's ``clock`` (scheduler.py
    RunClock: the running task and its context) from the start, and once the runtime (core.py)
    built them (:meth:`attach`) its ``program``, ``controller``, ``programs`` (cmdchannel.py: the
    interpreters' program states), ``errstate`` ($ERR), ``stepping`` (the run mode) and ``ff``
    (fastforward.py: a clock read). Before that a computed variable that reads one raises
    AttributeError (nothing is running)."""

    __slots__ = ("clock", "program", "controller", "programs", "errstate", "stepping", "ff")

    def __init__(self, clock) -> None:
        self.clock = clock
        self.program = self.controller = self.programs = self.errstate = self.stepping = self.ff = None

    def attach(self, program, controller, programs, errstate, stepping, ff) -> None:
        """The run's parts, once built (core.py ``Runtime.__init__``)."""
        self.program, self.controller, self.programs = program, controller, programs
        self.errstate, self.stepping, self.ff = errstate, stepping, ff

    @property
    def mode_op(self) -> str:
        """``$MODE_OP``'s name (T1, T2, AUT, EX): the controller's."""
        return self.controller.mode_op

    def interpreter_active(self, robot: bool) -> bool:
        """The robot interpreter's (`robot`) or the submit interpreter's program runs (#P_ACTIVE)."""
        return self.programs.state(robot) == "P_ACTIVE"

    def clock_read(self) -> None:
        """The running task read the clock ($DATE, a running $TIMER) or drew a random number: the
        run is not idle (fastforward.py ``FastForward.clock_read``)."""
        if self.ff is not None:
            self.ff.clock_read(self.clock.current_task)

    def current_task_kind(self) -> str:
        """'robot' or 'submit': the interpreter running now (the robot's between resumes)."""
        t = self.clock.current_task
        return t.kind if t is not None else "robot"

    def current_context(self):
        """The innermost interrupt context of the running task (contexts.py Context), or None."""
        t = self.clock.current_task
        return next((c for c in reversed(t.contexts) if c.kind == "interrupt"), None) if t is not None else None

    def io_source(self) -> str:
        """Who writes an output now: a network partner writing it (robot/io.py ``IOImage.writer``,
        set by interp/runtime/netvars.py around a KukaVarProxy write: 'varproxy'), 'trigger' (a
        TRIGGER action) or 'program'."""
        if self.controller.io.writer is not None:
            return self.controller.io.writer
        t = self.clock.current_task
        return "trigger" if t is not None and t.context.kind == "trigger" else "program"


class _RunDeclared(Mapping):
    """A run's system variables declared by a system data list (SysVars ``declared``, name ->
    (reference, Span)): its model's, each reference the run's own (``own_ref``), made when a
    name is first asked for (the data list holding it is copied then: program.py
    ``ModuleRT.copy``)."""

    __slots__ = ("_model", "_own_ref", "_got")

    def __init__(self, model, own_ref) -> None:
        self._model, self._own_ref, self._got = model, own_ref, {}

    def get(self, name, default=None):
        got = self._got.get(name)
        if got is None:
            d = self._model.get(name)
            if d is None:
                return default
            got = self._got[name] = (self._own_ref(d[0]), d[1])
        return got

    def __getitem__(self, name):
        got = self.get(name)
        if got is None:
            raise KeyError(name)
        return got

    def __contains__(self, name) -> bool:
        return name in self._model or name in self._got

    def __iter__(self):
        return iter({**self._model, **self._got})

    def __len__(self) -> int:
        return len({**self._model, **self._got})

    def setdefault(self, name, value):
        """A declaration the run's own loading adds (a data list the model could not load)."""
        got = self.get(name)
        if got is None:
            got = self._got[name] = value
        return got


class SysVars:
    """The system variables of one run, or of a program model's load (interp/runtime/model.py):
    ``machine`` (robot.machine.MachineData: the boot values), ``io`` (robot.io.IOImage: what
    ``$IN``, ``$OUT``, ``$TIMER`` ... view), ``message`` (``message(text)``: a controller
    message, kept as a note while no controller exists) and ``run``, the run's parts the
    computed variables read (:class:`RunReads`: its controller, the current task and context),
    None for a model's load and a tool's copy (reading one of those then is an AttributeError:
    nothing is running). A run's system variables are a copy of its model's
    (:meth:`copy`); nothing hands them to another owner.
    ``served``: while a parked pass catches up (interp/runtime/spin.py ``SpinWatch.wake``), the
    values of the robot's motion (the variables declared ``reads=ROBOT``) its steps read when
    they ran, name -> value; None otherwise."""

    served: dict | None = None

    def __init__(self, machine, io, message, run=None) -> None:
        self.machine = machine
        self.io = io
        self.message = message
        self.run = run
        self.info = load_builtins().sysvars
        self.store: dict = {}
        self.refs: dict = {}
        self.declared: dict = {}      # UPPER name -> (data-list reference, Span): declare()
        #: the variables not simulated whose note was given (:meth:`_unsimulated`, once per run)
        self.noted: set[str] = set()
        #: KUKA's workspace monitoring (robot/workspace.py WorkspaceMonitor) once a workspace can
        #: be active, else None: the controller is built with it or told of it (watch_workspaces)
        self.workspaces = None
        self._boot()

    def copy(self, io, message, run) -> "SysVars":
        """This load's system variables (a model's, frozen: interp/runtime/model.py
        ``ProgramModel``, its ``image``) as a run's own: every value copied (frozen.py
        ``StoreImage.copy``, a deep copy as values.copy_value makes), read on `io` with
        `message` for `run` (None: a tool's copy); the system data lists' declarations follow
        once the run's program is copied (:meth:`declared_as`). This object is only read."""
        sv = SysVars.__new__(SysVars)
        sv.machine, sv.io, sv.message, sv.run = self.machine, io, message, run
        sv.info = self.info
        sv.store = self.image.copy()
        sv.refs = {}
        sv.declared = {}
        sv.noted = set(self.noted)
        sv.workspaces = None
        _boot_trace(sv, reset=False)
        return sv

    def declared_as(self, model: "SysVars", own_ref) -> None:
        """A copy's declarations (:meth:`copy`): `model`'s, each data-list reference the run's
        own (``own_ref(model reference)``: program.Program ``own_ref``), found when first asked
        (:class:`_RunDeclared`); the workspaces the model watched are watched."""
        self.declared = _RunDeclared(model.declared, own_ref)
        for name in WORKSPACE_VARS:
            if name in model.refs:
                self._workspace_ref(name)

    def set_override(self, percent: int) -> None:
        """The operator sets the program override $OV_PRO (`percent`, 0..100 %: the
        controller's write rules, interp/runtime/writerules.py), as with the pendant's override
        keys: the motions planned from then on take it. Raises the rules' KrlRuntimeError."""
        check("$OV_PRO", percent, "program")
        self.store["$OV_PRO"] = percent

    # ------------------------------------------------------------------ boot values
    def _boot(self) -> None:
        m = self.machine
        p = MotionParams.initmov(m)
        boot = {
            "$VEL": {"CP": p.vel_cp, "ORI1": p.vel_ori1, "ORI2": p.vel_ori2},
            "$ACC": {"CP": p.acc_cp, "ORI1": p.acc_ori1, "ORI2": p.acc_ori2},
            "$APO": {"CPTP": int(p.apo_cptp), "CDIS": p.apo_cdis, "CVEL": int(p.apo_cvel), "CORI": p.apo_cori},
            "$BASE": dict.fromkeys(CART_KEYS, 0.0),
            "$TOOL": dict.fromkeys(CART_KEYS, 0.0),
            "$WORLD": dict.fromkeys(CART_KEYS, 0.0),
            "$ROBROOT": dict(zip("XYZABC", [float(x) for x in m.robroot_frame])),
            "$LOAD": {"M": -1.0},
        }
        for key, info in self.info.items():
            if key in _LIVE:
                continue
            t = make_array(sys_type(info.type_name) or T.UNKNOWN, info.dims)
            v = make_value(t)
            if key in boot and isinstance(v, Struct):
                for k, x in boot[key].items():
                    if k in v.f:
                        v.f[k] = x
            self.store[key] = v
        s = self.store
        for i, k in enumerate(E6AXIS_KEYS):          # A1..A6 the INITMOV values, E1..E6 100 %
            s["$VEL_AXIS"].data[i] = float(p.vel_axis[0]) if k in ROBOT_KEYS else 100.0
            s["$ACC_AXIS"].data[i] = float(p.acc_axis[0]) if k in ROBOT_KEYS else 100.0
        for key in ("$FLAG", "$CYCFLAG"):
            a = s[key]
            a.data[:] = [False] * len(a.data)
        s["$ADVANCE"] = m.def_advance
        s["$OV_PRO"] = 100
        s["$ORI_TYPE"] = EnumValue("VAR")
        s["$CIRC_TYPE"] = EnumValue("BASE")
        s["$IPO_MODE"] = EnumValue("BASE")
        s["$ACT_TOOL"] = -1
        s["$ACT_BASE"] = -1
        s["$ACT_EX_AX"] = -1
        s["$BWDSTART"] = False
        s["$TCP_IPO"] = False
        s["$ADAP_ACC"] = EnumValue("STEP2")
        s["$I_O_ACT"] = True
        s["$MOVE_ENABLE"] = True
        s["$USER_SAF"] = True
        s["$DRIVES_ON"] = False
        s["$DRIVES_OFF"] = False
        s["$CMD"] = 1
        s["$FCT_CALL"] = 2
        s["$FILTER"] = 0
        s["$KINCLASS"] = EnumValue("STANDARD")
        for k in ("$PRO_MODE", "$PRO_MODE0", "$PRO_MODE1"):
            s[k] = EnumValue("GO")
        s["$DEF_FLT_PTP"] = 16        # machine data (filter lengths), boot values
        s["$DEF_FLT_CP"] = 16
        s["$ACT_GROUP"] = 1
        s["$OV_PRO"] = 100
        s["$PAL_MODE"] = False
        s["$SINGUL_POS"].data[:] = [0, 0, 0]
        s["$ORI_CHECK"] = 0
        s["$CP_VEL_TYPE"] = 0
        s["$SPL_VEL_MODE"] = 0
        s["$TOOL_DIRECTION"] = 0
        s["$EMSTOP_TIME"] = 0
        s["$CONF_MESS"] = False
        s["$EXT_START"] = False
        s["$CHCK_MOVENA"] = False
        s["$EX_AX_IGNORE"] = 0
        home = AxisMap.of(m).to_krl(m.home_all)
        s["$H_POS"] = axis_struct(home)
        for i in range(5):
            s["$AXIS_HOME"].data[i] = axis_struct(home)
        # the home windows: 2 deg per axis, the value of every backup's $machine.dat
        # (shared/docs/robot-model.md "HOME"); a backup's Mada sets its own
        s["$H_POS_TOL"] = axis_struct([HOME_TOL_DEG] * 12)
        for i in range(5):
            s["$H_AXIS_TOL"].data[i] = axis_struct([HOME_TOL_DEG] * 12)
        _boot_trace(self)
        self.robot_values()

    #: The system variables that name the simulated robot (issue 22): they always hold the
    #: controller's machine data, also in a backup run with ``--robot`` (whose Mada says otherwise).
    ROBOT_SYSVARS = ("$TRAFONAME", "$SOFTN_END", "$SOFTP_END", "$ROBROOT", "$VEL_MA", "$ACC_MA")

    def robot_values(self) -> None:
        """Set :data:`ROBOT_SYSVARS` from the controller's robot (robot/machine.py
        MachineData): ``$TRAFONAME`` (when the robot has one), the soft limits of A1..An and of
        E1..Em (at 7..6+m; an endless axis has none),
        ``$ROBROOT``, ``$VEL_MA`` and ``$ACC_MA``. KRL code and the main run see one robot."""
        m = self.machine
        s = self.store
        name = getattr(m, "trafoname", "")
        if name and "$TRAFONAME" in s and hasattr(s["$TRAFONAME"], "data"):
            data = s["$TRAFONAME"].data
            text = list(name[:len(data)])
            data[:len(text)] = text
            data[len(text):] = [make_value(T.CHAR)] * (len(data) - len(text))
        index = AxisMap.of(m).krl_index          # each model axis's component (robot/axismap.py)
        limits = [(index[i], j.data_limits) for i, j in enumerate(m.joints)]   # the machine data's (issue 85)
        limits += [(index[len(m.joints) + k], e.limit) for k, e in enumerate(m.external_axes) if e.kind != "endless"]
        for i, (lo, hi) in limits:
            s["$SOFTN_END"].data[i] = float(lo)
            s["$SOFTP_END"].data[i] = float(hi)
        for key, values in (("$ROBROOT", dict(zip("XYZABC", (float(x) for x in m.robroot_frame)))),
                            ("$VEL_MA", {"CP": m.vel_ma.cp, "ORI1": m.vel_ma.ori1, "ORI2": m.vel_ma.ori2}),
                            ("$ACC_MA", {"CP": m.acc_ma.cp, "ORI1": m.acc_ma.ori1, "ORI2": m.acc_ma.ori2})):
            v = s.get(key)
            if isinstance(v, Struct):
                for k, x in values.items():
                    if k in v.f:
                        v.f[k] = float(x)
        self.drive_values()

    def drive_values(self) -> None:
        """``$VEL_AXIS_MA`` (rated motor speed, rpm) and ``$RAT_MOT_AX`` (gear ratio {N, D}) of
        each axis from the simulated robot's machine data (robot/data/kr6_r900.yaml
        ``machine_data_kinematics``, cited from a $machine.dat), where nothing set them: in a
        backup the Mada data list declares its own (the program reads those); a folder without
        one read "value invalid" although its robot has them (OsmanMarangoz's motion_eki.src
        computes its joints' top speed from them, issue 59)."""
        md = (getattr(self.machine, "raw", None) or {}).get("machine_data_kinematics") or {}
        rpm, ratios = md.get("vel_axis_ma_rpm") or (), md.get("rat_mot_ax_n_d") or ()
        vel, rat = self.store.get("$VEL_AXIS_MA"), self.store.get("$RAT_MOT_AX")
        for i, x in enumerate(rpm):
            if vel is not None and i < len(vel.data) and vel.data[i] is UNSET:
                vel.data[i] = float(x)
        for i, (n, d) in enumerate(ratios):
            if rat is not None and i < len(rat.data) and isinstance(rat.data[i], Struct):
                f = rat.data[i].f
                if f.get("N") is UNSET and f.get("D") is UNSET:
                    f["N"], f["D"] = int(n), int(d)

    # ------------------------------------------------------------------ lookup
    def lookup(self, name: str):
        """The reference of system variable ``name`` (upper-case), or None if unknown."""
        ref = self.refs.get(name)
        if ref is not None:
            return ref
        if name in WORKSPACE_VARS or name in WORKSTATE_SIGNALS:
            return self._workspace_ref(name)
        info = self.info.get(name)
        if info is None:
            return self._unsimulated(name)
        t = make_array(sys_type(info.type_name) or T.UNKNOWN, info.dims)
        live = _LIVE.get(name)
        if live is not None:
            ref = live(self, t, name)
        else:
            after = self._on_write.get(name)
            hook = None
            if after is not None or info.range is not None:
                # the write rules (writerules.py) for a documented range; a write's effect after it
                hook = WriteHook(info.range is not None, partial(after, self) if after is not None else None)
            ref = Slot(self.store, name, t, name, readonly=info.access == "RO", on_write=hook)
        self.refs[name] = ref
        return ref

    def declare(self, name: str, ref, span) -> None:
        """A KSS system data list of the program's files (``DEFDAT $MACHINE``, ``$ROBCOR``,
        ``$CUSTOM``, ``$OPTION``, ``$OPERATE``, ...; reference §2.5) declares system variable
        ``name`` (upper-case) as ``ref`` at ``span``: if the simulator does not model it, a
        read gives the value declared there (:meth:`lookup`). The first declaration holds."""
        if name not in self.info and name not in _LIVE:
            self.declared.setdefault(name, (ref, span))

    def _unsimulated(self, name: str):
        """The reference of a system variable the simulator does not model, or None if
        nothing declares it (the caller's run-time error "unknown name", as the controller
        gives for an undeclared ``$`` name). Declared by a system data list of the backup
        (:meth:`declare`): that variable, with its declared value. Declared only by KSS's own
        system files (krl/semantics/data/kss.yaml, e.g. ``$TORQMON`` of operate.dat in a flat
        export without them): a variable of the declared type whose numbers read 0, BOOLs
        FALSE, CHARs NUL (KSS's files give these no initial value; the simulated answer,
        docs/architecture.md "Environment"). Either way one ``message`` event per variable
        and run says so."""
        d = self.declared.get(name)
        if d is not None:
            ref, span = d
            if name not in self.noted:
                self.noted.add(name)
                where = _where(getattr(self.run, "program", None), span)
                self.message(f"not simulated: system variable {name} reads its value declared at {where}")
        else:
            kss = load_builtins().kss_variables.get(name)
            if kss is None:
                return None
            t = make_array(sys_type(kss.type_name) or T.UNKNOWN, kss.dims)
            if name not in self.store:        # (a copy holds its model's value)
                self.store[name] = zero_value(t)
            ref = Slot(self.store, name, t, name, readonly=kss.access == "RO")
            if name not in self.noted:
                self.noted.add(name)
                self.message(f"not simulated: system variable {name} (declared by KSS's system files, "
                             f"not by this program's): reads 0/FALSE")
        self.refs[name] = ref
        return ref

    # ------------------------------------------------------------------ a base on a BASE kinematic
    #: the last EK result (KSS ``EK(ROOT, MECH_TYPE, OFFSET)``, interp/runtime/natives/geometry.py):
    #: (system, root, offset, value); ``$BASE`` is linked while it holds that value
    ek: tuple | None = None

    def link_base(self, system: str, root: tuple, offset: tuple, value: tuple) -> None:
        """The EK call's result (natives/geometry.py): ``$BASE`` assigned the frame `value`
        (X, Y, Z, A, B, C mm/deg) is linked to the kinematic `system` at `root` and `offset`
        (:meth:`base_link`)."""
        self.ek = (system, root, offset, value)

    def base_link(self) -> tuple | None:
        """``(system, root, offset)`` while ``$BASE`` is the frame an ``EK`` call returned (KSS's
        bas.src: ``$BASE = EK(MACHINE_DEF[i].ROOT, MACHINE_DEF[i].MECH_TYPE, BASE_DATA[n])`` for a
        base that ``MACHINE_FRAME_DAT[n]`` measures on an external kinematic), else None."""
        ek = self.ek
        if ek is None:
            return None
        try:
            cur = frame_tuple(self.store["$BASE"], "$BASE")
        except KrlRuntimeError:
            return None
        if all(abs(a - b) <= 1e-9 for a, b in zip(cur, ek[3])):
            return ek[:3]
        return None

    # ------------------------------------------------------------------ workspace monitoring
    def _workspace_ref(self, name: str):
        """``$WORKSPACE``/``$AXWORKSPACE`` (simulated: robot/workspace.py): the variable the
        backup's system data list declares (``$custom.dat``, ``$machine.dat``), else one of KSS's
        type with zero values (mode #OFF); a program that names one may change it, so the
        monitor watches from then on. ``$WORKSTATEn``/``$AXWORKSTATEn``: the monitor's signal."""
        if name in WORKSTATE_SIGNALS:
            ref = ComputedRef(lambda: self._workstate(name), T.BOOL, name)
        else:
            d = self.declared.get(name)
            if d is not None:
                ref = d[0]
            else:
                kss = load_builtins().kss_variables[name]
                t = make_array(sys_type(kss.type_name) or T.UNKNOWN, kss.dims)
                self.store[name] = zero_value(t)
                ref = Slot(self.store, name, t, name)
            self.refs[name] = ref
            self._watch_workspaces()
        self.refs[name] = ref
        return ref

    def _workstate(self, name: str) -> bool:
        mon = self.workspaces
        return bool(mon is not None and mon.signal(name))

    def start_workspaces(self) -> None:
        """After the data lists are loaded: watch the workspaces when the backup's own
        declarations make one active (a mode other than #OFF)."""
        for name in WORKSPACE_VARS:
            d = self.declared.get(name)
            if d is not None and any(e is not None for e in _entries(d[0])):
                self._workspace_ref(name)

    def _watch_workspaces(self) -> None:
        if self.workspaces is not None:
            return

        refs = self.refs

        def read():
            cart = _entries(refs["$WORKSPACE"]) if "$WORKSPACE" in refs else ()
            axis = _entries(refs["$AXWORKSPACE"]) if "$AXWORKSPACE" in refs else ()
            return cart, axis
        def state(i: int, value: bool) -> None:      # $WORKSPACE[n].STATE, $AXWORKSPACE[n].STATE
            ref = refs.get(WORKSPACE_VARS[i // 8])
            try:
                st = ref.peek().data[i % 8] if ref is not None else None
            except KrlRuntimeError:
                return
            if isinstance(getattr(st, "f", None), dict) and "STATE" in st.f:
                st.f["STATE"] = value
        mon = WorkspaceMonitor(read, AxisMap.of(self.machine).model_keys)
        mon.on_change = state
        self.workspaces = mon
        ctl = getattr(self.run, "controller", None)
        if ctl is not None:      # a program naming one as it runs; else built with it
            ctl.monitor.watch_workspaces(mon)

    # ------------------------------------------------------------------ helpers for motion
    def value(self, name: str):
        return self.store[name]

    _on_write: dict = {}


#: the workspaces the simulator monitors (robot/workspace.py) and their state signals
WORKSPACE_VARS = ("$WORKSPACE", "$AXWORKSPACE")
WORKSTATE_SIGNALS = frozenset([f"$WORKSTATE{n}" for n in range(1, 9)] + [f"$AXWORKSTATE{n}" for n in range(1, 9)])


def _entries(ref) -> list:
    """The 8 workspaces of a ``$WORKSPACE``/``$AXWORKSPACE`` reference as robot/workspace.py reads
    them: None for one whose mode is #OFF or unset, else (mode, {component: number})."""
    try:
        arr = ref.peek()
    except KrlRuntimeError:
        return [None] * 8
    out = []
    for st in getattr(arr, "data", ())[:8]:
        f = getattr(st, "f", None)
        mode = f.get("MODE") if f is not None else None
        name = getattr(mode, "name", None)
        if not name or name == "OFF":
            out.append(None)
            continue
        out.append((name, {k: float(v) for k, v in f.items()
                           if k != "MODE" and isinstance(v, (int, float)) and not isinstance(v, bool)}))
    return out


def _where(program, span) -> str:
    """``file:line`` of a declaration, the file relative to the workspace of `program` (a run's
    interp/runtime/program.py Program, or None) when it lies inside it (traces do not depend
    on where the backup is unpacked)."""
    p = Path(span.file)
    root = getattr(program, "workspace", None)
    if root is not None:
        try:
            p = p.resolve().relative_to(Path(root).resolve())
        except ValueError:
            pass
    return f"{p.as_posix()}:{span.line}"


# ---------------------------------------------------------------------- live variables

def _io(kind: str):
    def make(sv: SysVars, t, name):
        io = sv.io              # the run's I/O image (the controller's, which may not be built yet)
        if kind == "$IN":
            arr = LiveArray(name, 8192, T.BOOL, io.get_in)
        elif kind == "$OUT":
            def set_out(i, v):
                # an output written with the value it has changes nothing and logs nothing
                # (robot/io.py IOImage.set_out): skip the controller's call for it
                if i.__class__ is int and 1 <= i <= 8192 and io._out[i] == (1 if v else 0):
                    return
                sv.run.controller.io.set_out(i, v, sv.run.io_source())
            arr = LiveArray(name, 8192, T.BOOL, io.get_out, set_out)
        elif kind == "$ANIN":
            arr = LiveArray(name, 32, T.REAL, io.get_anin)
        elif kind == "$ANOUT":
            arr = LiveArray(name, 32, T.REAL, io.get_anout,
                            lambda i, v: _set_anout(sv, i, v))
        elif kind == "$TIMER":
            arr = LiveArray(name, 64, T.INT, lambda i: _timer(sv, io.get_timer, i), io.set_timer)
        elif kind == "$TIMER_STOP":
            arr = LiveArray(name, 64, T.BOOL, io.get_timer_stop, io.set_timer_stop)
        else:  # $TIMER_FLAG
            arr = LiveArray(name, 64, T.BOOL, lambda i: _timer(sv, io.get_timer_flag, i))
        return ComputedRef(lambda: arr, t, name)
    make.reads = SIGNALS         # (a running timer's read is a clock read too: _timer)
    return make


def _timer(sv: SysVars, get, i: int):
    """``$TIMER[i]``/``$TIMER_FLAG[i]``: a running timer is the clock (interp/runtime/idle.py)."""
    io = sv.io
    if 1 <= i < len(io.timer_stop) and not io.timer_stop[i]:
        sv.run.clock_read()
    return get(i)


def _set_anout(sv: SysVars, i: int, v) -> None:
    io = sv.run.controller.io
    io.now = sv.run.controller.time
    io.set_anout(i, v, sv.run.io_source())


def _computed(fn, setter=None, *, reads: str):
    """A system variable computed by ``fn(sv)`` (written by ``setter``, None: read-only) whose read
    reads `reads` (krl/semantics/facts.py ``SYSVAR_READS``: what the fast-forward and the idle watch
    know of it; a CLOCK read is a clock read, interp/runtime/idle.py, made here and nowhere else).
    Raises ValueError for another class, or a constant's value declared otherwise."""
    if reads not in SYSVAR_READS or (getattr(fn, "constant", False) and setter is None) != (reads == CONSTANT):
        raise ValueError(f"a computed system variable reads one of {sorted(SYSVAR_READS)}, CONSTANT for a constant")
    if reads == CLOCK:
        def make(sv: SysVars, t, name):
            def read():
                sv.run.clock_read()
                return fn(sv)
            return ComputedRef(read, t, name, setter)
    elif reads == ROBOT:
        def make(sv: SysVars, t, name):
            def read():
                served = sv.served
                if served is not None and name in served:
                    return copy_value(served[name])     # (a catch-up's step reads what it read)
                return fn(sv)
            return ComputedRef(read, t, name, setter)
    else:
        def make(sv: SysVars, t, name):
            return ComputedRef(lambda: fn(sv), t, name, setter)
    make.reads = reads
    return make


def _pos_act(sv: SysVars):
    """``$POS_ACT``: the robot's pose in the current ``$TOOL``/``$BASE`` (reference §6.4,
    table §10: "current TCP pose in current $BASE/$TOOL"), the values the program set last,
    so that ``$TOOL = TOOL_DATA[2]`` then ``PTP $POS_ACT`` does not move the robot (the read
    stops the advance run: the robot stands still). ``$IPO_MODE = #TCP``: the fixed tool in
    the workpiece frame (robot/external_tcp.py)."""
    s = sv.store
    mode = s["$IPO_MODE"]
    return pos_struct(sv.run.controller.actual.pos_act(frame_tuple(s["$TOOL"], "$TOOL"), frame_tuple(s["$BASE"], "$BASE"),
                                               ipo_mode=mode.name if isinstance(mode, EnumValue) else "BASE"))


def _pos_int(sv: SysVars):
    ctx = sv.run.current_context()
    if ctx is None or ctx.pos_int is None:
        raise value_invalid("$POS_INT outside an interrupt routine")
    return pos_struct(ctx.pos_int)


def _axis_int(sv: SysVars):
    ctx = sv.run.current_context()
    if ctx is None or ctx.axis_int is None:
        raise value_invalid("$AXIS_INT outside an interrupt routine")
    return axis_struct(ctx.axis_int)


def _date(sv: SysVars):
    t = sv.run.controller.time
    cs = int(round(t * 100))
    s = cs // 100
    return struct_of("DATE", {"CSEC": cs % 100, "SEC": s % 60, "MIN": (s // 60) % 60,
                              "HOUR": (s // 3600) % 24, "DAY": 1, "MONTH": 1, "YEAR": 2026})


#: the values of $PRO_STATE*, made once (interp/runtime/cmdchannel.py): an enum value is an
#: immutable leaf (values.py LEAVES, which idle.py freeze copies), and an interrupt's watch key (watch.py)
#: compares the same object at each poll by identity
_P_ACTIVE = STATE_VALUES["P_ACTIVE"]


def _pro_state(robot: bool):
    """``$PRO_STATE1`` (`robot`) or ``$PRO_STATE0``: the interpreter's program state, as the
    run's tasks and the $CMD channel's commands set it (interp/runtime/cmdchannel.py)."""
    def fn(sv: SysVars):
        return sv.run.programs.value(robot)
    return fn


def _pro_state_self(sv: SysVars):
    return _P_ACTIVE


def _err(sv: SysVars):
    return sv.run.errstate.current_err()


def _nullframe(sv: SysVars):
    return struct_of("FRAME", dict.fromkeys(CART_KEYS, 0.0))


def _ro_const(v):
    def value(sv: SysVars):
        return v
    value.constant = True        # CONSTANT_NAMES
    return value


def _machine_const(fn):
    """A read-only value of the simulated robot's machine data (robot/machine.py), constant
    for the run: ``$NUM_AX`` (the robot's axes), ``$EX_AX_NUM`` (its external axes E1..Em)."""
    def value(sv: SysVars):
        return fn(sv.machine)
    value.constant = True        # CONSTANT_NAMES
    return value


def _vel_axis_act(sv: SysVars) -> Arr:
    """``$VEL_AXIS_ACT[1..12]``: each axis's velocity over the last IPO cycle in percent of its
    top speed, which the controller derives from ``$VEL_AXIS_MA`` and ``$RAT_MOT_AX`` (KUKA
    System Variables: "current axis speeds in %"; robot/machine.py ``max_speed_deg_s``), signed;
    0 for an axis the robot does not have."""
    ctl = sv.run.controller
    m = ctl.machine
    top = m.all_max_speed
    vel = ctl.actual.axis_vel_act()
    data = [0.0] * len(E6AXIS_KEYS)
    amap = ctl.model.axes
    # KRL order: A1..A6, E1..; each model axis at its component (robot/axismap.py)
    for i, (k, v) in enumerate(zip(amap.krl_index, amap.from_krl(vel))):
        if i < len(top) and top[i] > 0:
            data[k] = float(v) / top[i] * 100.0
    return Arr(T.Array(T.REAL, (len(data),)), (len(data),), data)


def _torque_axis_act(sv: SysVars) -> Arr:
    """``$TORQUE_AXIS_ACT[1..12]``: the simulator has no model of the drives, so every axis
    reads 0.0 (Nm), one "not simulated" note per run saying so (as for a variable only KSS's
    system files declare: :meth:`SysVars._unsimulated`). A program that streams it to a partner
    (OsmanMarangoz's motion_eki.src, issue 59) runs on instead of stopping on "value invalid"."""
    if name_noted(sv, "$TORQUE_AXIS_ACT"):
        sv.message("not simulated: system variable $TORQUE_AXIS_ACT (the simulator has no drive "
                      "model): reads 0.0")
    return Arr(T.Array(T.REAL, (12,)), (12,), [0.0] * 12)


def name_noted(sv: SysVars, name: str) -> bool:
    """True the first time `name` is asked about in the run (its note is due), False after."""
    noted = sv.__dict__.setdefault("_noted", set())
    if name in noted:
        return False
    noted.add(name)
    return True


#: the default window of ``$IN_HOME``/``$IN_HOME1..5`` (``$H_POS_TOL``, ``$H_AXIS_TOL[n]``), deg
HOME_TOL_DEG = 2.0


def _in_home(n: int):
    """``$IN_HOME`` (`n` = 0) or ``$IN_HOME1..5`` (`n` = 1..5): TRUE while every robot axis
    A1..A6 stands within the window of the home position — ``|$AXIS_ACT.Ai - $H_POS.Ai| <=
    $H_POS_TOL.Ai`` (deg), for ``$IN_HOMEn`` ``$AXIS_HOME[n]`` and ``$H_AXIS_TOL[n]`` (KUKA
    System Variables, KSS 8.x: "$IN_HOME: robot in the home position, the position window
    defined by $H_POS and $H_POS_TOL"), and each external axis E1..Em the robot has within its
    own window. A home position or window with an unset component gives FALSE."""
    def value(sv: SysVars) -> bool:
        s = sv.store
        if n == 0:
            home, tol = s["$H_POS"], s["$H_POS_TOL"]
        else:
            home, tol = s["$AXIS_HOME"].data[n - 1], s["$H_AXIS_TOL"].data[n - 1]
        q = sv.run.controller.actual.axis_act()
        try:
            return all(abs(float(q[i]) - float(home.f[k])) <= float(tol.f[k])
                       for i, k in enumerate(E6AXIS_KEYS[:len(q)]))
        except (TypeError, ValueError):     # an UNSET component
            return False
    return value


_LIVE = {
    "$IN": _io("$IN"), "$OUT": _io("$OUT"), "$ANIN": _io("$ANIN"), "$ANOUT": _io("$ANOUT"),
    "$TIMER": _io("$TIMER"), "$TIMER_STOP": _io("$TIMER_STOP"), "$TIMER_FLAG": _io("$TIMER_FLAG"),
    "$POS_ACT": _computed(lambda sv: _pos_act(sv), reads=ROBOT),
    "$POS_ACT_MES": _computed(lambda sv: _pos_act(sv), reads=ROBOT),
    "$AXIS_ACT": _computed(lambda sv: axis_struct(sv.run.controller.actual.axis_act()), reads=ROBOT),
    "$AXIS_ACT_MEAS": _computed(lambda sv: axis_struct(sv.run.controller.actual.axis_act()), reads=ROBOT),
    "$POS_INT": _computed(_pos_int, reads=STATE),
    "$AXIS_INT": _computed(_axis_int, reads=STATE),
    "$VEL_ACT": _computed(lambda sv: float(sv.run.controller.actual.vel_act()), reads=ROBOT),
    "$VEL_AXIS_ACT": _computed(lambda sv: _vel_axis_act(sv), reads=ROBOT),
    # the motions the advance run has planned that the main run has not begun (KUKA System
    # Variables: "$ACT_ADVANCE: number of motion blocks currently planned in the advance run",
    # 0..$ADVANCE); shenrq20's kuka_eki_hw_interface streams it to its partner (issue 59)
    "$ACT_ADVANCE": _computed(lambda sv: len(sv.run.controller.queue), reads=ROBOT),
    "$TORQUE_AXIS_ACT": _computed(lambda sv: _torque_axis_act(sv), reads=STATE),
    "$DATE": _computed(_date, reads=CLOCK),
    "$PRO_STATE": _computed(_pro_state_self, reads=TASKS),
    "$PRO_STATE0": _computed(_pro_state(False), reads=TASKS),
    "$PRO_STATE1": _computed(_pro_state(True), reads=TASKS),
    "$PRO_MOVE": _computed(lambda sv: bool(sv.run.controller.is_moving()), reads=ROBOT),
    "$STOPMESS": _computed(_ro_const(False), reads=CONSTANT),
    "$POWER_FAIL": _computed(_ro_const(False), reads=CONSTANT),
    # the EMERGENCY STOP signals are active-low, TRUE while no EMERGENCY STOP is pressed (KSS
    # 8.x System Integrators, Automatic External outputs: "ALARM_STOP: this output is reset
    # in the event of an EMERGENCY STOP"; $machine.dat: SIGNAL $ALARM_STOP ;NOT-STOP,
    # $ALARM_STOP_INTERN ;NOT-STOP INTERN): the simulated cell has no EMERGENCY STOP
    "$ALARM_STOP": _computed(_ro_const(True), reads=CONSTANT),
    "$ALARM_STOP_INTERN": _computed(_ro_const(True), reads=CONSTANT),
    # the other signals of the safety controller (sysvars.yaml ``safety``): the safety gate
    # closed, the drives enabled, the enabling switch released (a cell in AUT/EXT)
    "$SAFEGATE_OP": _computed(_ro_const(True), reads=CONSTANT),
    "$SAFETY_DRIVES_ENABLED": _computed(_ro_const(True), reads=CONSTANT),
    "$SAFETY_SW": _computed(_ro_const(EnumValue("RELEASED")), reads=CONSTANT),
    # every condition to start a motion holds (drives enabled, motion enable): what a KR C4
    # in AUT/EXT reads while nothing holds it ($MOVE_ENABLE, an input of the safety controller:
    # write-protected, sysvars.yaml ``safety``)
    "$COULD_START_MOTION": _computed(lambda sv: bool(sv.store.get("$MOVE_ENABLE", True)), reads=STATE),
    # a process is active at robot level: a robot program (or its interrupt) is being run
    # (KSS 8.x System Integrators, Automatic External outputs, PRO_ACT)
    "$PRO_ACT": _computed(lambda sv: bool(sv.run.interpreter_active(True)), reads=TASKS),
    "$ON_PATH": _computed(_ro_const(True), reads=CONSTANT),
    "$MODE_OP": _computed(lambda sv: EnumValue(sv.run.mode_op), reads=TASKS),
    "$T1": _computed(lambda sv: sv.run.mode_op == "T1", reads=TASKS),
    "$T2": _computed(lambda sv: sv.run.mode_op == "T2", reads=TASKS),
    "$AUT": _computed(lambda sv: sv.run.mode_op == "AUT", reads=TASKS),
    "$EXT": _computed(lambda sv: sv.run.mode_op == "EX", reads=TASKS),
    # Automatic External active: EXT selected and $I_O_ACT TRUE (KSS 8.x System Integrators,
    # Automatic External outputs; robot/cellpresets.py "autoext")
    "$I_O_ACTCONF": _computed(lambda sv: sv.run.mode_op == "EX" and bool(sv.store.get("$I_O_ACT", True)), reads=STATE),
    "$INTERPRETER": _computed(lambda sv: 1 if sv.run.current_task_kind() == "robot" else 0, reads=TASKS),
    "$ERR": _computed(_err, reads=STATE),
    "$NULLFRAME": _computed(_nullframe, reads=TASKS),
    "$NUM_AX": _computed(_machine_const(lambda m: m.n_axes), reads=CONSTANT),
    "$EX_AX_NUM": _computed(_machine_const(lambda m: m.n_ext), reads=CONSTANT),
    "$PERI_RDY": _computed(_ro_const(True), reads=CONSTANT),
    "$ROB_CAL": _computed(_ro_const(True), reads=CONSTANT),
    "$IN_HOME": _computed(_in_home(0), reads=ROBOT),
    "$IN_HOME1": _computed(_in_home(1), reads=ROBOT),
    "$IN_HOME2": _computed(_in_home(2), reads=ROBOT),
    "$IN_HOME3": _computed(_in_home(3), reads=ROBOT),
    "$IN_HOME4": _computed(_in_home(4), reads=ROBOT),
    "$IN_HOME5": _computed(_in_home(5), reads=ROBOT),
    "$NEAR_POSRET": _computed(_ro_const(False), reads=CONSTANT),
    "$ROBRUNTIME": _computed(lambda sv: int(sv.run.controller.time / 60), reads=CLOCK),
}




def live_reading(*classes: str) -> frozenset:
    """The computed system variables whose read reads one of `classes` (their ``reads=``)."""
    return frozenset(k for k, make in _LIVE.items() if make.reads in classes)


#: the system variables whose value never changes in a run (read-only constants of the
#: simulated cell: $STOPMESS FALSE, $ALARM_STOP TRUE, $NUM_AX 6, ...); interp/runtime/watch.py
CONSTANT_NAMES = live_reading(CONSTANT)

#: computed scalar system variables whose read has no effect and raises nothing: the state of
#: the run ($PRO_STATE1, $PRO_MOVE, $MODE_OP, ...). An interrupt condition over them keeps its
#: value while theirs are unchanged (interp/runtime/watch.py, "probed").
PROBED_NAMES = frozenset({"$PRO_STATE", "$PRO_STATE0", "$PRO_STATE1", "$PRO_MOVE", "$PRO_ACT",
                          "$MODE_OP", "$T1", "$T2", "$AUT", "$EXT", "$I_O_ACTCONF",
                          "$COULD_START_MOTION", "$VEL_ACT", "$INTERPRETER"}) - CONSTANT_NAMES
assert all(k in _LIVE and _LIVE[k].reads != CLOCK for k in PROBED_NAMES)
#: the probed names whose value changes only with the runtime's state epoch
#: (interp/runtime/scheduler.py ``RunClock.state_epoch``: the IPO cycle, RESUME, BRAKE, an interrupt
#: routine's end, the operating mode, a task's end): a poll reads them once per epoch. The others read variables a
#: statement may write ($MOVE_ENABLE, $I_O_ACT) and are read at every poll.
EPOCH_PROBED = PROBED_NAMES - {"$COULD_START_MOTION", "$I_O_ACTCONF"}


#: stored system variables whose components change beside a statement's write (``$TRACE``'s STATE
#: follows a write of its MODE: :class:`_TraceFields`): the fast-forward probes a read of them
#: (interp/runtime/passes.py ``STATE_NAMES``)
STORED_STATE = frozenset({"$TRACE"})


class _TraceFields(dict):
    """The components of ``$TRACE`` (STRUC TRACE CHAR NAME[64], CONFIG[64], TRACE_MODE MODE,
    TRACE_STATE STATE; KSS's $operate.dat). Writing ``MODE`` acts at once, as on a KR C4: ``#T_START``
    starts a recording named ``NAME`` with the configuration ``CONFIG``, ``#T_STOP`` stops it,
    ``#T_TRIGGER`` triggers it (a ``recording`` event of the run's trace, robot/trace.py, and the
    controller's trace segments that ``krl trace compare`` matches with a KUKA Trace recording);
    ``STATE`` follows: ``#TRIGGERED`` while recording (the configuration's own trigger is not
    simulated: it records from the start), ``#T_END`` when stopped. KUKA's TraceStart and TraceStop
    (every KSS 8 bas.src of the corpus; interp/basis/bas.src) write MODE and wait on STATE. A
    component write goes through this dict in both interpreters (interp/runtime/memory.py
    ``field_ref``: a Slot of the structure's components)."""

    __slots__ = ("sv",)

    def __setitem__(self, key, value) -> None:
        super().__setitem__(key, value)
        if key == "MODE" and isinstance(value, EnumValue):
            _trace_mode(self.sv.run, self, value.name.upper())


def _text(v) -> str:
    """A CHAR array's text up to its first NUL (or UNSET)."""
    data = getattr(v, "data", None)
    if data is None:
        return ""
    out = []
    for c in data:
        if not isinstance(c, str) or c == "\0":
            break
        out.append(c)
    return "".join(out).strip()


def _trace_mode(rt, fields: dict, mode: str) -> None:
    phase = {"T_START": "start", "T_STOP": "stop", "T_TRIGGER": "trigger"}.get(mode)
    if phase is None:
        return
    recording = fields.get("STATE") == EnumValue("TRIGGERED")
    if phase == "stop":
        dict.__setitem__(fields, "STATE", EnumValue("T_END"))
        if not recording:
            return
    else:
        if phase == "trigger" and not recording:
            return
        dict.__setitem__(fields, "STATE", EnumValue("TRIGGERED"))
    ctl = rt.controller
    if ctl.trace is not None:
        ctl.trace.write("recording", ctl.time, phase=phase, name=_text(fields.get("NAME")) or None,
                        config=_text(fields.get("CONFIG")) or None)


def _boot_trace(sv: SysVars, reset: bool = True) -> None:
    """``$TRACE`` at boot (`reset`: STATE #T_END, no recording; else the values it holds, a
    copy's): a structure whose MODE component acts when written (:class:`_TraceFields`)."""
    v = sv.store.get("$TRACE")
    if not isinstance(v, Struct):
        return
    fields = _TraceFields(v.f)
    fields.sv = sv          # its run: sv.run (None for a model's load: nothing acts)
    if reset:
        dict.__setitem__(fields, "STATE", EnumValue("T_END"))
        dict.__setitem__(fields, "MODE", EnumValue("T_STOP"))
    v.f = fields


def _pro_mode_written(sv: SysVars, ref) -> None:
    """``$PRO_MODE = #MSTEP`` (any run mode): the next statement takes the full hook, so the
    new mode applies from there in both interpreters (interp/runtime/runmode.py)."""
    sv.run.stepping.run_mode_changed()


#: what writing a system variable does once the value is stored (its range is checked before,
#: by the write rules: sysvars.yaml's ``range``, writerules.py)
SysVars._on_write = {"$PRO_MODE": _pro_mode_written}
