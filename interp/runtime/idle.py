"""Idle time costs nothing (issue 34): :class:`IdleWatch`, one per run and the same for both
interpreters, finds a run idle (a window of quiet cycles with the same state, :func:`state_of`, at
both ends) and jumps its clock to the cycle before the next event (:meth:`IdleWatch.next_cycle`),
whole periods of a polling loop at once (:meth:`IdleWatch._period`); before a jump the automatic
cell may answer, and a robot program that starves beside a busy submit program is answered too
(:meth:`IdleWatch.robot_starves`). docs/robot.md "Idle time costs nothing" has the rules in full."""

from __future__ import annotations

import math

from krl.ast import nodes as N
from krl.semantics import types as T
from krl.semantics.inputflow import clock_slots

from .values import LEAVES, UNSET, Arr, EnumValue, Struct

#: cycles (12 ms) a run must be quiet before its state is compared (0.384 s)
WINDOW_CYCLES = 32
#: the longest window, after repeated changes of state without any I/O (6.1 s)
MAX_WINDOW_CYCLES = 512
#: phases of the tasks remembered while looking for the period of an idle run (IdleWatch._period)
MAX_PHASES = 64
#: "no bound" of :meth:`IdleWatch.span`
_FAR = 1 << 62

_SCALARS = (int, float, bool, str, type(None))
#: values imaged by :func:`freeze` and :func:`_store` so far (fields, elements, slots): the
#: cost of a state image, counted the same way by both interpreters (:func:`probe_state`)
_IMAGED = [0]
#: classes of the declared types whose values are immutable leaves (a simple or an enum type):
#: an array of such elements, a structure of only such components, holds leaves only
_LEAF_TYPES = frozenset({T.Simple, T.Enum})
#: id(structure type) -> (the type, its number of components, whether each is of a leaf type)
_LEAFY: dict = {}


def _leafy(t) -> int:
    """1 when every component of structure type `t` is of a leaf type (:data:`_LEAF_TYPES`),
    2 when every component is of a leaf type or a structure type of rank 1, else 0."""
    c = _LEAFY.get(id(t))
    if c is None or c[0] is not t or c[1] != len(t.fields):
        types = [ft for _, ft in t.fields.values()]
        rank = 1 if all(ft.__class__ in _LEAF_TYPES for ft in types) else \
            2 if all(ft.__class__ in _LEAF_TYPES or (ft.__class__ is T.Struc and ft is not t and _leafy(ft) == 1)
                     for ft in types) else 0
        c = _LEAFY[id(t)] = (t, len(t.fields), rank)
    return c[2]


def freeze(v):
    """A comparable, hashable image of a KRL value (:mod:`interp.runtime.values`): scalars as
    they are, structures and arrays as nested tuples, enum values by name. One whose elements are
    all immutable leaves (values.py ``LEAVES``) is a plain copy of them: equal to another image
    exactly when the element-wise images would be."""
    c = v.__class__
    if c in _SCALARS:
        return v
    if c is Struct:
        f = v.f
        _IMAGED[0] += len(f)
        if LEAVES.issuperset(map(type, f.values())):
            return (1, tuple(f.items()))
        return (1, tuple([(k, freeze(x)) for k, x in f.items()]))
    if c is Arr:
        d = v.data
        _IMAGED[0] += len(d)
        t = v.type
        e = t.elem if t.__class__ is T.Array else None
        if e.__class__ in _LEAF_TYPES or LEAVES.issuperset(map(type, d)):
            # (an array of a simple or enum type holds leaves only: no need to look)
            return (2, tuple(d))
        rank = _leafy(e) if e.__class__ is T.Struc else 0
        if rank:
            # an array of structures of leaf components (rank 1) or of leaf components and
            # structures of leaf components (rank 2): each imaged here as freeze images it
            out = []
            add = out.append
            n = 0
            for x in d:
                if x.__class__ is not Struct:
                    add(x if x.__class__ in _SCALARS else freeze(x))
                    continue
                f = x.f
                n += len(f)
                if rank == 1:
                    add((1, tuple(f.items())))
                    continue
                items = []
                for k, y in f.items():
                    if y.__class__ is Struct:
                        g = y.f
                        n += len(g)
                        items.append((k, (1, tuple(g.items()))))
                    else:
                        items.append((k, y if y.__class__ in _SCALARS else freeze(y)))
                add((1, tuple(items)))
            _IMAGED[0] += n
            return (2, tuple(out))
        return (2, tuple([x if x.__class__ in _SCALARS else freeze(x) for x in d]))
    if c is EnumValue:
        return (3, v.name)
    if v is UNSET:
        return (4,)
    return (5, id(v))


def _store(store) -> tuple:
    """The image of a frame's or a data list's slots (their values by :func:`freeze`)."""
    _IMAGED[0] += len(store)
    return tuple([x if x.__class__ in _SCALARS else freeze(x) for x in store])


def chain(frame):
    """`frame` and its callers, innermost first."""
    while frame is not None:
        yield frame
        frame = frame.caller


def stack_image(frame) -> tuple:
    """The image of `frame` and its callers' slots (:func:`_store`), innermost first."""
    return tuple([_store(f.store) for f in chain(frame)])


def frames_of(run, task) -> tuple:
    """The image of `task`'s frames (its innermost first): those it stands in, or for a parked
    spin those it would stand in (interp/runtime/spin.py)."""
    img = run.ff.spin.frames_image(task) if task.parked is not None else None
    return img if img is not None else stack_image(task.frame)


def starving_frames(run, task) -> tuple:
    """:func:`frames_of` `task` with the slots its routines assign from the clock (inputflow.py
    ``clock_slots``: ``t0 = $TIMER[1]``) as None: what :meth:`IdleWatch.robot_starves` compares
    (issue 85, item 7). A parked spin's image is :func:`frames_of`'s."""
    if task.parked is not None:
        return frames_of(run, task)
    clocks = run.program.derived("clock_slots", lambda pr: clock_slots(pr.ws))
    out = []
    for f in chain(task.frame):
        slots = clocks.get(id(f.routine)) if clocks else None
        img = _store(f.store)
        if slots:
            img = tuple([None if i in slots else x for i, x in enumerate(img)])
        out.append(img)
    return tuple(out)


def root(e):
    """The name an index or component expression selects from, or None."""
    while isinstance(e, (N.Index, N.Field)):
        e = e.base
    return e if isinstance(e, N.Name) else None


def routine_writes(program) -> dict:
    """id(routine) -> the data lists (module indices, ``Storage.owner``) the statements of that
    routine may write: an assignment's, a FOR's, an ``ANIN ON``'s or a WITH's target, a call's
    arguments (None: any, a name not placed); the statements outside a routine under the key None;
    once per checked workspace (``Program.derived``). Nothing else writes a data list."""
    return program.derived("routine_writes", _routine_writes)


def _routine_writes(program) -> dict:
    out: dict = {None: frozenset()}
    for unit in program.ws.units:
        src = unit.src
        if src is None or src.module is None:
            continue
        module = src.module
        for routine in module.routines:
            out[id(routine)] = _node_writes(routine)
        rest = [_node_writes(n) for n in module.children() if n.__class__ is not N.Routine]
        out[None] = None if out[None] is None or None in rest else out[None].union(*rest)
    return out


def _node_writes(top):
    """The data lists the statements under `top` may write (module indices), None: any."""
    out = set()
    for node in top.walk():
        c = node.__class__
        if c is N.Assign or c is N.AninOn or c is N.WithAssign:
            names = (root(node.target),)
        elif c is N.For:
            names = (root(node.var),)
        elif c is N.Call:
            names = tuple(root(a) for a in node.args)
        else:
            continue
        for name in names:
            place = getattr(name.ann, "place", None) if name is not None and name.ann is not None else None
            if place is not None and place.owner >= 0:
                out.add(place.owner)
            elif name is not None and place is None:
                return None
    return frozenset(out)


def state_of(run, constant: dict | None = None) -> tuple:
    """The state of the run `run` that its future depends on, besides the positions of its tasks
    in their loops: data lists, frames, system variables, I/O image but running timers, interrupt
    tables, contexts and waits. `constant`: module index -> the image of a data list no routine
    entered writes (:func:`routine_writes`), made once and used again."""
    constant = constant or {}
    mods = tuple([constant.get(m.index) or _store(m.slot_values()) for m in run.program.modules if m.loaded])
    tasks = []
    for t in run.scheduler.tasks:
        frames = frames_of(run, t)
        irqs = tuple((n, i.on, i.enabled, i.last, i.pending, id(i.frame))
                     for n, i in sorted(t.irqs.irqs.items()))
        tasks.append((t.done, t.waiting, len(t.contexts), frames, irqs, t.err_text, len(t.next_triggers)))
    sv = run.sysvars.store
    sysvars = tuple([(k, v if v.__class__ in _SCALARS else freeze(v)) for k, v in sv.items()])
    io = run.controller.io
    timers = tuple(ms if stop else None for ms, stop in zip(io.timer_ms, io.timer_stop))
    ioimg = (bytes(io._in), bytes(io._out), tuple(io._anin), tuple(io._anout),
             tuple(io.timer_stop), timers)
    return (mods, tuple(tasks), sysvars, ioimg, run.messages.last_handle)


def probe_state(run) -> tuple[tuple, int]:
    """``(state_of(run), values)``: the state and the number of values its image walked (fields,
    elements and slots), the cost a bounded trace's probes are kept within (robot/trace.py)."""
    before = _IMAGED[0]
    state = state_of(run)
    return state, _IMAGED[0] - before


class IdleWatch:
    """The idle detector of one run (module docstring). The scheduler calls :meth:`cycle`
    after the tasks of an IPO cycle ran and before the controller steps; it returns the
    number of cycles it skipped (0: none)."""

    def __init__(self, spec, controller, tracing, stepping, program, sysvars, messages, robot) -> None:
        """The idle watch of the run `spec` (RunSpec ``fast_forward``) on `controller`, tracing its
        jumps to `tracing`, none while `stepping` has a debugger watching; it images the run's
        `program`, `sysvars`, `messages` and the robot task `robot()`, and is itself a run for
        :func:`state_of` as the runtime is. The other parts: :meth:`attach`."""
        self.controller, self.tracing, self.stepping, self.program = controller, tracing, stepping, program
        self.sysvars, self.messages, self.robot = sysvars, messages, robot
        self.scheduler = self.ff = self.cyclic_watch = self.calls = None     # attach
        self.clock = 0               # clock and random reads (FastForward.clock_read): the quiet window starts again
        self.window = WINDOW_CYCLES
        self.start: int | None = None    # cycle at which the quiet window began
        self.marks: tuple | None = None  # (I/O changes, clock reads, planned axes, axes) at its start
        self.state = None
        self.since: float | None = None  # s: the run has been idle since (None: it is not)
        self.skipped = 0             # cycles skipped in the run
        self.jumps = 0               # fast-forwards in the run
        self.auto = None             # interp.runtime.autocell.AutoCell of --inputs auto
        self.enabled = spec.fast_forward  # False: never fast-forward (RunSpec.fast_forward; tests compare)
        self.held = False            # a robot of a cell of several: a jump is offered (:attr:`offer`), not made
        self.offer = 0               # held: the cycles the last cycle() would have skipped
        self._robot: tuple | None = None   # (cycle, marks, frames) of the robot program's quiet window
        # the automatic cell records the statements of the robot program's window (robot_starves):
        # the run's own quiet window, which a clock read restarts every cycle, does not drop them
        self._robot_watching = False
        self._phases: dict = {}      # phase of the tasks (:meth:`_phase`) -> cycle, while idle in one state
        self.shifted = 0             # cycles of the periodic jumps (each task's WAIT SEC moved with the clock)
        self._imaged = None          # _state_key() when the state was imaged last
        self._last = None            # (cycle, clock reads) at the end of the last cycle() call
        self._const = None           # images of the data lists no routine entered writes (_constant)
        self._entered = 0            # the routines entered when they were made (Calls.entered)
        self._plan_arr = self._plan_list = None     # the queue's plan_q array :meth:`moved` listed last, its list

    def attach(self, scheduler, ff, cyclic_watch, calls) -> None:
        """The parts built after the watch: the `scheduler`, the fast-forward `ff` (a parked task's
        frames), the `cyclic_watch` and `calls` (the routines entered)."""
        self.scheduler, self.ff, self.cyclic_watch, self.calls = scheduler, ff, cyclic_watch, calls

    def _marks(self) -> tuple:
        """What changes without being state, read every cycle of a quiet window: the count of
        I/O changes and of clock reads, the end point of the last planned motion and the
        robot's axes (deg)."""
        ctl = self.controller
        return (len(ctl.io.log), self.clock, ctl.queue.plan_q.tolist(), ctl._q.tolist())

    def outside_change(self) -> None:
        """Something outside the tasks changed the run's state (core.py ``Runtime.changed_outside``):
        it may have written a data list no statement writes, so its image is made again."""
        self._const = None
        self._imaged = None

    def _constant(self) -> dict:
        """The images of the data lists no statement of the routines the run has entered so far may
        write (module index -> image; :func:`routine_writes`, calls.py ``Calls.entered``), kept while
        no routine that may write one is entered (before any statement of it runs)."""
        c = self._const
        entered = self.calls.entered()
        if c is not None and len(entered) == self._entered:
            return c
        self._entered = len(entered)
        writes = routine_writes(self.program)
        written = set(writes[None] or ()) if writes[None] is not None else None
        for key in list(entered) if written is not None else ():
            w = writes.get(key)
            if w is None:
                written = None
                break
            written |= w
        old = c or {}
        c = self._const = {} if written is None else \
            {m.index: old.get(m.index) or _store(m.slot_values()) for m in self.program.modules
             if m.loaded and m.index not in written}
        return c

    def _state_key(self):
        """What :func:`state_of` images can change by: the statements executed and the cyclic
        flags' changes (watch.py ``CyclicWatch.written``), the I/O image's version, the message
        handle, the tasks' waits, contexts and interrupt tables, the step a parked spin stands at.
        Equal keys: the same state. None: image it (a debugger or an ``ANIN ON`` may write)."""
        written = self.cyclic_watch.written()
        if written is None:
            return None
        tasks = []
        for t in self.scheduler.tasks:
            irqs = tuple([(n, i.on, i.enabled, i.last, i.pending, id(i.frame)) for n, i in t.irqs.irqs.items()])
            p = t.parked
            tasks.append((t.done, t.waiting, len(t.contexts), t.err_text, irqs, len(t.next_triggers),
                          None if p is None else (id(p), p.step())))
        return (written, self.controller.io.version, self.messages.last_handle, tuple(tasks))

    def _quiet(self) -> bool:
        if self.stepping.watching:
            return False
        for t in self.scheduler.tasks:
            if t.done:
                continue
            # (a TRIGGER waiting for the task's next motion is not an event: it cannot fire
            # before the task plans that motion; it is part of the state, state_of)
            if t.pending_triggers or t.pending_error is not None or any(i.pending for i in t.irqs.irqs.values()):
                return False
        return True

    def reset(self) -> None:
        self._robot_watching = False
        self._restart(None, None)
        self.window = WINDOW_CYCLES

    def cycle(self, still: bool = False) -> int:
        """One IPO cycle ended (the tasks ran): check, and fast-forward when the run is idle; with
        the automatic cell, also answer a starving robot program (:meth:`robot_starves`). Returns
        the cycles skipped. `still`: a steady cycle of a robot that stands (scheduler.py: nothing
        changed since the last cycle); when the last call was the cycle before, no clock was read
        since and both windows are still counting, this one would only count too: it returns."""
        ctl = self.controller
        if still and self._last == (ctl.cycle - 1, self.clock) and self.start is not None \
                and self.since is None and ctl.cycle - self.start < self.window \
                and (self.auto is None or self._robot_counting(ctl.cycle)):
            self._last = (ctl.cycle, self.clock)
            return 0
        n = self._cycle()
        if n == 0 and self.auto is not None and self.since is None:
            self.robot_starves()
        self._last = (ctl.cycle, self.clock)
        return n

    def _robot_counting(self, cycle: int) -> bool:
        """:meth:`robot_starves` would only count IPO cycle `cycle` of a still steady cycle: its
        window is open, younger than :data:`WINDOW_CYCLES`, and nothing makes it forget it."""
        robot = self.robot()
        return (self._robot is not None and cycle - self._robot[0] < WINDOW_CYCLES and not self.auto.pending()
                and robot is not None and not robot.done and robot.wake_cycle is None)

    def moved(self, q: list | None = None) -> None:
        """:meth:`cycle` of a cycle in which the robot moved while the run is quiet and not idle
        (scheduler.py, "Steady cycles"): the quiet window and the robot program's start again here,
        without testing what is known. `q`: the robot's axes as a list (deg), when listed."""
        ctl = self.controller
        if q is None:
            q = ctl._q.tolist()
        # (as _marks and robot_marks read them; the queue replaces its plan_q array at each
        # change, robot/motionqueue.py, so the list of the same array is the same)
        pq = ctl.queue.plan_q
        if pq is self._plan_arr:
            planned = self._plan_list
        else:
            planned = self._plan_list = pq.tolist()
            self._plan_arr = pq
        self.start, self.marks, self.state, self.since = ctl.cycle, (len(ctl.io.log), self.clock, planned, q), \
            None, None
        if self._phases:
            self._phases = {}
        auto = self.auto
        if auto is None:
            return
        robot = self.robot()
        if robot is None or robot.done or robot.wake_cycle is not None or auto.pending():
            self._robot = None
        else:
            self._robot = (ctl.cycle, (self.scheduler.robot_io, robot.waiting, tuple(q), tuple(planned),
                                       len(robot.next_triggers)), None)

    def robot_starves(self) -> None:
        """The robot program starves while the run is not idle (a submit program blinks a lamp on
        a timer): for a whole window it stood in one WAIT FOR, or ran without moving the robot, an
        I/O change or a change of its own frames. Then the automatic cell answers (after one more
        window for a polling loop). A heuristic for answering only: nothing is fast-forwarded."""
        ctl = self.controller
        robot = self.robot()
        marks = self.robot_marks()
        if marks is None:
            self._robot = None
            self._drop_robot_watch()
            return
        if self._robot is None or self._robot[1] != marks:
            self._robot = (ctl.cycle, marks, None)
            self._drop_robot_watch()
            return
        start, _, frames = self._robot
        if ctl.cycle - start < WINDOW_CYCLES:
            return
        now = starving_frames(self, robot)
        if frames is None or frames != now:
            self._robot = (ctl.cycle, marks, now)
            self._drop_robot_watch()
            return
        got = self.auto.answer(self)
        self._robot_watching = got == "watching"
        self._robot = (ctl.cycle, marks, now if got == "watching" else None)

    def _drop_robot_watch(self) -> None:
        """The robot program's window ended: a recording it started is dropped."""
        if self._robot_watching:
            self._robot_watching = False
            self.auto.recording = None

    def robot_marks(self) -> tuple | None:
        """What :meth:`robot_starves` compares from cycle to cycle: the robot program's own I/O
        changes, its wait, the axes, the planned axes, its TRIGGERs waiting for a motion; None when
        it watches no window (no robot program or it ended, an answer pending, not quiet, a WAIT SEC)."""
        ctl = self.controller
        robot = self.robot()
        if robot is None or robot.done or self.auto.pending() or not self._quiet() or robot.wake_cycle is not None:
            return None
        return (self.scheduler.robot_io, robot.waiting, tuple(ctl._q.tolist()), tuple(ctl.queue.planned_axes().tolist()),
                len(robot.next_triggers))

    def span(self, c: int, reads: int = 0) -> int:
        """Cycles from `c` in which this watch only counts (jump.py): its quiet window open and
        younger than its length, its marks unchanged, and, while the run is not idle yet, the robot
        program's window open and younger than :data:`WINDOW_CYCLES` or not kept. `reads`: the
        clock reads each counted cycle makes; the quiet window then starts again at every one of
        them, so it bounds nothing."""
        if self.start is None or not self._quiet():
            return 0
        marks = self._marks()
        if reads:
            if self.since is not None or marks[0] != self.marks[0] or marks[2:] != self.marks[2:]:
                return 0
            n = _FAR
        elif marks != self.marks:
            return 0
        else:
            n = self.start + self.window - c
        if self.since is None and self.auto is not None:
            marks = self.robot_marks()
            if marks is not None:
                if self._robot is None or self._robot[1] != marks:
                    return 0
                n = min(n, self._robot[0] + WINDOW_CYCLES - c)
        return n

    def jumped(self, n: int) -> None:
        """The clock jump counted `n` cycles from this one, as :meth:`cycle` would at each (their
        clock reads counted first: then each started the quiet window again, :meth:`_cycle`)."""
        last = self.controller.cycle + n - 1
        if self.clock != self.marks[1]:
            self._restart(last, self._marks())
        self._last = (last, self.clock)
        if self.auto is not None and self.robot_marks() is None:
            self._robot = None                      # as robot_starves would forget it at each cycle

    def _cycle(self) -> int:
        ctl = self.controller
        if not self._quiet():
            self.reset()
            return 0
        marks = self._marks()
        if self.start is None or marks != self.marks:
            self._restart(ctl.cycle, marks)
            return 0
        if ctl.cycle - self.start < self.window:
            return 0
        # the state is imaged again only when something may have changed it since the last
        # image (:meth:`_state_key`); else it is that image
        key = self._state_key()
        state = self.state if key is not None and key == self._imaged else state_of(self, self._constant())
        self._imaged = key
        if self.state is None or state != self.state:
            if self.state is not None:
                self.window = min(2 * self.window, MAX_WINDOW_CYCLES)
                self._restart(ctl.cycle, marks)
            self.start, self.state, self.since, self._phases = ctl.cycle, state, None, {}
            return 0
        # idle: nothing changed for a whole window
        if self.since is None:
            self.since = self.start * ctl.dt
        if self.auto is not None and not self.auto.pending():
            got = self.auto.answer(self)
            if got == "watching":
                self.start = ctl.cycle      # the same state is compared again a window later
                return 0
        return self.jump()

    def _restart(self, start: int, marks: tuple) -> None:
        """The quiet window starts again at cycle `start` with `marks`; a recording the automatic
        cell made in it is dropped, unless the robot program's window (:meth:`robot_starves`) keeps it."""
        if self.auto is not None and not self._robot_watching:
            self.auto.recording = None
        self.start, self.marks, self.state, self.since, self._phases = start, marks, None, None, {}

    def next_cycle(self, wakes: bool = True) -> int | None:
        """The first cycle in which something can change (module docstring), or None: the
        controller's next event, the end of a task's WAIT SEC (unless `wakes` is False), the
        time limit."""
        ctl = self.controller
        cands = [ctl.signals.next_event_cycle(ctl.cycle)]
        if wakes:
            cands += [t.wake_cycle for t in self.scheduler.tasks if not t.done]
        lim = self.scheduler.max_sim_time
        if lim is not None:
            cands.append(int(math.ceil(lim / ctl.dt - 1e-9)))
        cands = [c for c in cands if c is not None]
        return min(cands) if cands else None

    def jump(self) -> int:
        """Skip to the cycle before the next event (its own cycle then runs as usual);
        returns the cycles skipped."""
        ctl = self.controller
        if not self.enabled:
            return 0
        nxt = self.next_cycle()
        if nxt is None or not ctl.at_rest():
            return 0
        n = nxt - 1 - ctl.cycle
        if self.held:
            # a robot of a cell (interp/robotcell.py): its robots skip together, so the cell
            # decides how far (Scheduler.cycles; no periodic extension, which moves the waits)
            self.offer = max(n, 0)
            return 0
        period = self._period()
        if period:
            # a WAIT SEC ends first, but the run repeats every `period` cycles: jump whole
            # periods to the last one before the next event, every task's wait moved with it
            ext = self.next_cycle(wakes=False)
            k = (ext - 1 - ctl.cycle) // period if ext is not None else 0
            if k >= 1 and k * period > n:
                n = k * period
                for t in self.scheduler.tasks:
                    if t.wake_cycle is not None:
                        t.wake_cycle += n
                self.shifted += n
                self._phases = {}
        if n <= 0:
            return 0
        return self.skip(n)

    def skip(self, n: int) -> int:
        """Skip `n` cycles now (:meth:`jump`'s, or a cell's grant of an :attr:`offer`); returns `n`."""
        ctl = self.controller
        t0 = ctl.time
        ctl.skip(n)
        self.skipped += n
        self.jumps += 1
        if self.tracing.writer is not None:
            self.tracing.writer.write("idle", t0, until=ctl.time, since=self.since, cycles=n)
        self.start = ctl.cycle
        if self._phases:
            self._phases[self._phase()] = ctl.cycle
        return n

    def _phase(self) -> tuple:
        """Where the tasks are, besides the state: each task's last statement, what it waits
        for, its contexts, and the cycles until its WAIT SEC ends."""
        cycle = self.controller.cycle
        return tuple((t.done, (t.at.file, t.at.line) if t.at is not None else None, t.waiting,
                      len(t.contexts), None if t.wake_cycle is None else t.wake_cycle - cycle)
                     for t in self.scheduler.tasks)

    def _period(self) -> int:
        """Cycles after which the idle run repeats itself exactly, or 0 (not known yet): the tasks'
        phase (:meth:`_phase`) is one they had at an earlier idle check in the same state, so each
        cycle after it repeats the cycle one period before, up to the next event (docs/robot.md)."""
        ph = self._phase()
        cycle = self.controller.cycle
        seen = self._phases.get(ph)
        if seen is not None and seen < cycle:
            return cycle - seen
        if len(self._phases) < MAX_PHASES:
            self._phases[ph] = cycle
        return 0
