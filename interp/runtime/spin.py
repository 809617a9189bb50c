"""A spin costs nothing: a task whose loop runs the same statements over the same state every
pass is *parked* until something it reads can change (issue 48, "The submit interpreter at the
controller's pace"; docs/architecture.md "Spins").

The backup's ``SPS.SUB`` never ends: each pass of its ``LOOP`` polls inputs and flags and, most
of the time, finds nothing to do. At the controller's pace (interp/runtime/scheduler.py
:data:`~.scheduler.SUBMIT_BUDGET` steps per IPO cycle) it executes about 8 000 statements per
simulated second, also while the robot moves — when the idle fast-forward (interp/runtime/idle.py)
cannot skip anything. :class:`SpinWatch` (one per run, the same for both interpreters) finds such
passes and stops executing them, with the simulated time, every I/O event, the step count and
what every other part of the run observes exactly as if the task had run.

**A spin.** A task's *pass* is what it executes between two iterations of one loop (the
``loop_tick`` of the same loop statement in the same frame). While the watch *records* a task
(its statements take the full hook: interp/runtime/core.py ``Runtime.before_statement``,
``loop_tick``), it takes the first loop iteration it sees as the boundary and records two passes.
They are a spin when

* the two passes executed the same statements and loop iterations, in the same order, at the same
  call depths;
* every value a statement wrote that outlives the pass (a variable of a data list, a global, a
  system variable, a local of the loop's frame or of its callers, what an ``:OUT`` parameter is
  bound to) is the value it had before the statement (the locals of routines called within the
  pass come and go with them); no I/O changed, no timer was set, no message was written, no clock
  or random number was read, no interrupt was declared, switched, pending or run, and the task
  never waited (only its time slice ended);
* every statement is one whose only effects are such writes (assignments, IF, SWITCH, loops, calls
  of the program's routines and of the built-ins of :data:`PURE_NATIVES`, a WAIT FOR that holds,
  RETURN, EXIT, GOTO), so the next pass, over the same state, is the same pass again.

**Parked.** At the end of the second pass the task stops at the boundary. Each IPO cycle, at its
turn, the scheduler does not resume it but counts what it would have done: its time slice of
steps (``Runtime.steps``), its position in the pass (the statement it would stand at: ``Task.at``;
its frames as the idle watch images them: :meth:`frames_image`; the statements an automatic
cell's recording would see: :meth:`_feed`), and the poll of its interrupts that its resume would
make. The state stands still, as it did in the recorded passes, so whatever reads it (the other
tasks, the idle watch, the automatic cell) reads what it would have read.

**Woken.** A parked task is woken, *before* the change, by anything that could change what its
passes read:

* another task proceeds (a statement or loop iteration, the end of a wait, a TRIGGER action, an
  interrupt routine: ``Runtime._proceed``): it may write what the pass reads;
* the controller's next step can change an input it reads (``Controller.next_event_cycle``: a
  stimulus, a cell rule's answer, a PULSE's reset; a stimulus on reaching a point while the robot
  moves), or move the robot while the pass reads the robot's position or motion
  (:data:`MOTION_NAMES`); a pass that reads ``$CYCFLAG`` is an input's reader (a cyclic flag
  whose expression settles changes only after the I/O image did: interp/runtime/watch.py
  ``CyclicWatch``) and is not parked while a flag's expression does not settle;
* an interrupt of its own would run at its resume (the poll finds one pending);
* the step limit comes near.

Waking *catches up*: the task runs, from the boundary, the steps it would have executed after its
last whole pass (its interrupts not polled: nothing of theirs changed before), and stops where the
task would stand at the end of its last time slice; then it runs on as usual. The catch-up runs
before the change, over the state the parked passes saw, so it executes the same statements the
recorded pass did (``diverged`` counts a catch-up that did not: none on the corpus,
tests/interp/test_spin.py). Every step of a parked cycle is counted, so the step limit and
``RunResult.steps`` are those of the unparked run.

The watch works only where nothing observes statements one by one: no trace of the interpreters
(a trace has every statement), no debugger hook, run mode GO, no network partner, no ``ANIN ON``
(it writes a variable at every cycle). A failed recording is tried again after twice as many
cycles (1 to :data:`MAX_GAP`), at once after a wake; a spin that may not be parked yet (what it
reads may change at the next step: the robot moves, an input is due) after twice as many cycles
too, up to :data:`MAX_WAIT_GAP`. Until 2026-11-26 it was recorded again at every cycle: a
backup's SPS.SUB beside a cyclic flag (which kept it from parking) took 1.8 times the CPU of a
run without the watch, for recordings that could not end in a park.

An observer of the controller alone (the controller's ``trace`` while the runtime's is None:
interp/summary.py ``RunObserver`` behind ``krl run``'s summary, interp/outcomes.py and
interp/realprograms.py behind the change report, the audit and the real-programs report) does not
stop the watch: the controller's events (I/O changes, messages, motions, poses, errors) are the
same parked or not, since a parked pass changes nothing (robot/io.py logs changes only). Until
2026-11-25 it did, and ``krl run`` of a palletizer module took 19 s of CPU for 517 s simulated
where tools/whole_run_bench.py, which runs without an observer, reported 2.4 s.
"""

from __future__ import annotations

from greenlet import getcurrent

from krl.ast import nodes as N
from krl.semantics.advance import accesses
from krl.semantics.resolve import LOCAL, NATIVE, ROUTINE, SYSTEM, UNRESOLVED

from .idle import _frames, _store, freeze
from .memory import Slot
from .natives import REGISTRY
from .sysvars import CONSTANT_NAMES

#: built-ins whose only effects are on their arguments (the watch checks those as writes) and
#: that read nothing that changes by itself: declared ``pure`` in the natives registry
#: (interp/runtime/natives/registry.py). Not pure, so a pass that calls them is never parked:
#: FRAND (a random number), the message and dialog routines that write (SET_KRLMSG, CLEAR_KRLMSG,
#: SET_KRLDLG), CWRITE/COPEN/CREAD (the command channel), PULSE, ERR_RAISE/ERR_CLEAR ($ERR), the
#: network's (EKI_*, RSI_*), and every stand-in of KUKA's software (counted per call).
PURE_NATIVES = frozenset(name for name, native in REGISTRY.items() if native.pure)

#: system variables whose value the main run changes as the robot moves (interp/runtime/sysvars.py
#: ``_LIVE``): a pass that reads one is parked only while the main run is idle
MOTION_NAMES = frozenset({"$POS_ACT", "$POS_ACT_MES", "$AXIS_ACT", "$AXIS_ACT_MEAS", "$VEL_ACT",
                          "$VEL_AXIS_ACT", "$ACT_ADVANCE", "$PRO_MOVE", "$IN_HOME", "$IN_HOME1",
                          "$IN_HOME2", "$IN_HOME3", "$IN_HOME4", "$IN_HOME5"})
#: the I/O image's system variables: they change between steps only at the controller's events
IO_NAMES = frozenset({"$IN", "$OUT", "$ANIN", "$ANOUT", "$TIMER", "$TIMER_STOP", "$TIMER_FLAG"})
#: system variables the run's tasks change (the program's state: $PRO_STATE1 when the robot
#: program ends, $MODE_OP, ...) or that never change; the others are stored system variables,
#: which statements write. tests/interp/test_spin.py holds every computed variable of
#: interp/runtime/sysvars.py to one of these sets or MOTION_NAMES, IO_NAMES, the clock's.
#: ``$TRACE`` (KUKA Trace's state) changes only when a statement writes its MODE.
STATE_NAMES = frozenset({"$PRO_STATE", "$PRO_STATE0", "$PRO_STATE1", "$PRO_ACT", "$MODE_OP", "$T1",
                         "$T2", "$AUT", "$EXT", "$I_O_ACTCONF", "$INTERPRETER", "$COULD_START_MOTION",
                         "$ERR", "$NULLFRAME", "$POS_INT", "$AXIS_INT", "$TRACE", "$TORQUE_AXIS_ACT"})

#: the statements a spin may execute (module docstring)
ALLOWED = (N.Assign, N.CallStmt, N.If, N.Switch, N.For, N.While, N.Repeat, N.Loop, N.Exit, N.Goto,
           N.Label, N.WaitFor, N.Continue, N.Return)

#: the longest pass recorded, in steps
MAX_PASS_STEPS = 2048
#: the longest wait between two recordings, in IPO cycles (after repeated failures)
MAX_GAP = 256
#: the longest wait between two recordings of a spin that could not be parked when recorded
#: (what it reads was about to change), in IPO cycles: parked at most this late once it may be
MAX_WAIT_GAP = 16


class _Pass:
    """A recorded spin: ``events`` ((file, line, loop iteration?, depth below the loop's frame)
    per step, the loop iteration that ends the pass last), ``infos`` (the StmtInfo of each
    step), ``at`` (the statement the task stands at after each step), ``frames`` (its innermost
    frame at each step) and ``images`` (its frames as the idle watch images them at each step),
    ``io`` (it reads I/O), ``motion`` (it reads the robot's position or motion), ``cyclic`` (it
    reads ``$CYCFLAG``: a cyclic flag whose expression does not settle may set it at any IPO
    cycle, one that settles only after an input changed: interp/runtime/watch.py
    ``settles``), ``probes`` (the state variables it reads)."""

    __slots__ = ("events", "infos", "at", "frames", "images", "io", "motion", "cyclic", "probes", "refs")

    def __init__(self, events, infos, at, frames, images) -> None:
        self.events = events
        self.infos = infos
        self.at = at
        self.frames = frames
        self.images = images
        self.io = False
        self.motion = False
        self.cyclic = False
        self.probes: tuple = ()
        self.refs = None            # the references of the probes, found when first read

    @property
    def steps(self) -> int:
        return len(self.events)


class _Parked:
    """A parked task: its pass, the steps it has taken since the pass's boundary (``done``),
    the I/O version it saw and the values of the state variables its pass reads."""

    __slots__ = ("spin", "done", "io_version", "probed", "expect")

    def __init__(self, spin: _Pass, done: int, io_version: int, probed: tuple) -> None:
        self.spin = spin
        self.done = done
        self.io_version = io_version
        self.probed = probed
        self.expect = 0


class _Recording:
    """A recording in progress (module docstring)."""

    __slots__ = ("task", "bound", "frame", "depth", "phase", "events", "infos", "at", "frames",
                 "images", "first", "pending", "world", "contexts", "last_at", "nodes", "looked", "seen")

    def __init__(self, task) -> None:
        self.task = task
        self.bound = None           # (file, line) of the loop whose iteration ends a pass
        self.frame = None           # the frame of that loop
        self.depth = 0
        self.phase = 0              # 0: looking for the loop, 1: first pass, 2: second pass
        self.events: list = []
        self.infos: list = []
        self.at: list = []
        self.frames: list = []
        self.images: list = []
        self.first: list | None = None
        self.pending: list = []     # (depth, ref, image before, name) of the last statements' writes
        self.world = None
        self.contexts = len(task.contexts)
        self.last_at = task.at
        self.nodes: dict = {}       # id(node) -> node of the statements executed
        self.looked = 0             # steps taken while looking for a loop iteration
        self.seen: set = set()      # loops passed over while looking


class SpinWatch:
    """The spin watch of one run (module docstring). ``recordings``, ``parks``, ``wakes`` and
    ``skipped`` (steps not executed) count what it did; ``diverged`` (a catch-up that left the
    recorded pass) and ``missed`` (a parked task's reads changed without a wake) count what
    must not happen."""

    def __init__(self, rt) -> None:
        self.rt = rt
        self.enabled = True         # False: never park (tests compare with and without)
        self.on = False             # a recording, a parked task or a catch-up is under way
        self.rec: _Recording | None = None
        self.parked: list = []
        self.gap: dict = {}         # id(task) -> cycles between two recordings
        self.due: dict = {}         # id(task) -> the cycle of its next recording
        self.bad: dict = {}         # id(task) -> loops that did not give a spin (StmtInfo ids)
        self.passes: dict = {}      # signature of a recorded pass -> analysis (None: not a spin)
        self.replaying = 0          # catch-ups under way
        self._io_at = (None, False)     # (moment, _io_may_change's answer then)
        self._nodes: dict | None = None
        self._targets: dict = {}    # id(statement) -> the names it writes
        self.parks = self.wakes = self.skipped = self.diverged = self.missed = 0
        self.recordings = 0         # recordings started
        self.why: dict = {}         # why recordings failed (a count per reason: tests, tuning)
        #: True: a spin is not parked but *shadowed* — the task runs on, and at the end of each
        #: IPO cycle what parking would have given (the statement it stands at, its frames'
        #: image) is compared with what it is (:meth:`check_shadows`; tests/interp/test_spin.py)
        self.shadow = False
        self.shadowed: list = []
        self.shadow_checks = self.shadow_errors = 0

    # ------------------------------------------------------------------ when
    def allowed(self) -> bool:
        """Nothing observes statements one by one, and nothing outside the tasks changes their
        variables (module docstring)."""
        rt = self.rt
        ctl = rt.controller
        net = getattr(ctl, "network", None)
        return (self.enabled and rt.trace is None
                and rt.stmt_hook is None and rt.step_hook is None and rt.cycle_hook is None
                and rt.run_mode == "GO" and getattr(ctl, "correction", None) is None
                and not any(k[0] == "analog input" for k in rt._cyclic)
                and (net is None or not net.polling))     # (no partner attached or ticking else: net/hub.py)

    def _update(self) -> None:
        self.on = self.rec is not None or bool(self.parked) or self.replaying > 0 or bool(self.shadowed)

    def resuming(self, task) -> bool:
        """The scheduler is about to give `task` its IPO cycle. True when it stays parked
        (this cycle is counted instead of run: :meth:`_hold`); else a recording may start."""
        if self.shadowed and task in self.shadowed:
            sh = task.shadow
            if self._step_may_change(sh.spin) or (task.irqs.armed and any(i.pending for i in task.irqs.irqs.values())):
                self._unshadow(task)
            else:
                sh.expect += task.budget
            return False
        if task.parked is not None:
            if self._hold(task):
                return True
            self.wake(task)
            return False
        if self.rec is None and task.replay is None and task.shadow is None:
            cycle = self.rt.controller.cycle
            if cycle >= self.due.get(id(task), 0) and self.allowed():
                self._start(task)
        return False

    def _start(self, task) -> None:
        self.recordings += 1
        self.rec = _Recording(task)
        task.watched = True
        self.rt._break(task)
        self._update()

    def _fail(self, why: str) -> None:
        self.why[why] = self.why.get(why, 0) + 1
        self._stop(False)

    def _stop(self, ok: bool, parks: bool = True) -> None:
        """End the recording: `ok` it found a spin (which `parks` now or not: module docstring)."""
        rec = self.rec
        if rec is None:
            return
        task = rec.task
        self.rec = None
        task.watched = False
        key = id(task)
        if ok:
            gap = 1 if parks else min(MAX_WAIT_GAP, 2 * self.gap.get(key, 1))
        else:
            gap = min(MAX_GAP, 2 * self.gap.get(key, 1))
        self.gap[key] = gap
        self.due[key] = self.rt.controller.cycle + gap
        # the loop of a failed recording is not taken as the boundary by the next one (an inner
        # loop whose counter changes: the next recording may find the outer one)
        self.bad[key] = {rec.bound} if not ok and rec.bound is not None else set()
        self._update()

    # ------------------------------------------------------------------ the hooks
    def event(self, task, info, tick: bool) -> None:
        """A statement (``tick`` False) or a loop iteration of `task` (Runtime.before_statement,
        Runtime.loop_tick, before its step is counted)."""
        if task.replay is not None:
            self._replayed(task, info, tick)
            return
        rec = self.rec
        if rec is not None and rec.task is task:
            self._record(rec, task, info, tick)
            return
        sh = task.shadow
        if sh is not None:
            # a shadowed spin runs on: it must run the recorded pass, step after step
            n = sh.spin.steps
            j = sh.done % n
            sh.done += 1
            if sh.spin.events[j][:3] != (info.file, info.line, tick):
                self.shadow_errors += 1
                self.why[f"shadow left the pass at step {j}: {info.file}:{info.line}"] = 1
                self._unshadow(task)
            return
        if self.parked or self.shadowed:
            self.wake_all()

    def proceeding(self) -> None:
        """A task goes on after a wait, or runs a TRIGGER action or an interrupt routine
        (Runtime._proceed): the parked tasks catch up first."""
        if self.parked or self.shadowed:
            self.wake_all()

    def waiting(self, task) -> None:
        """`task` gives its IPO cycle back before its time slice ended (a wait): a recording of
        it fails."""
        rec = self.rec
        if rec is not None and rec.task is task and self.rt.steps < task.slice_end:
            self._fail("waits")

    # ------------------------------------------------------------------ recording
    def statements(self, info):
        """The statements of the program at `info`'s file and line (the VM has StmtInfos of its
        own: interp/vm/vm.py), as a tuple; None when there is none."""
        files = self._nodes
        if files is None:
            files = self._nodes = {}
            for unit in self.rt.program.ws.units:
                src = unit.src
                if src is not None and src.module is not None:
                    files.setdefault(str(src.path), []).append(src.module)
        nodes = files.get(info.file)
        if isinstance(nodes, list):         # the file's statements, indexed when first asked for
            modules, nodes = nodes, {}
            for module in modules:
                for node in module.walk():
                    ann = node.ann
                    i = getattr(ann, "info", None) if ann is not None else None
                    if i is not None:
                        key = (i.file, i.line)
                        nodes[key] = nodes.get(key, ()) + (node,)
            files[info.file] = nodes
        return nodes.get((info.file, info.line)) if nodes is not None else None

    def _record(self, rec: _Recording, task, info, tick: bool) -> None:
        frame = task.frame
        depth = frame.depth if frame is not None else 0
        if rec.pending and not self._writes_kept(rec, depth):
            self._fail("writes")
            return
        if len(task.contexts) != rec.contexts or any(i.pending for i in task.irqs.irqs.values()):
            self._fail("context")
            return
        if rec.phase == 0:
            where = (info.file, info.line)
            if tick and (where not in self.bad.get(id(task), ()) or where in rec.seen):
                rec.bound, rec.frame, rec.depth, rec.phase = where, frame, depth, 1
                rec.world = self._world(task) + (tuple([_store(f.store) for f in _chain(frame)]),)
            else:
                if tick:
                    rec.seen.add(where)     # a loop the last recording failed on: the next one, or it
                if not tick:
                    rec.last_at = info
                rec.looked += 1
                if rec.looked > MAX_PASS_STEPS:
                    self._fail("looking")
            return
        nodes = self.statements(info)
        if not tick:
            if nodes is None or not all(isinstance(n, ALLOWED) for n in nodes):
                self._fail("statement")
                return
            rec.last_at = info
        if nodes is not None:
            for n in nodes:
                rec.nodes[id(n)] = n
        # (the VM has a StmtInfo per instruction: a loop's iterations may tick with two; a step
        # is known by its file and line)
        rec.events.append((info.file, info.line, tick, depth - rec.depth))
        rec.infos.append(info)
        rec.at.append(rec.last_at)
        if rec.phase == 2:
            rec.frames.append(frame)
            rec.images.append(tuple([_store(f.store) for f in _chain(frame)]))
        if len(rec.events) > MAX_PASS_STEPS:
            self._fail("long")
            return
        if nodes is not None:
            for n in nodes:
                if not tick or isinstance(n, N.For):    # a FOR's iteration writes its counter
                    self._watch_writes(rec, task, n, frame, depth)
        if tick and (info.file, info.line) == rec.bound and frame is rec.frame:
            if rec.phase == 1:
                rec.first = rec.events
                rec.events, rec.infos, rec.at = [], [], []
                rec.phase = 2
                return
            self._second_pass_done(rec, task)

    def _world(self, task) -> tuple:
        rt = self.rt
        io = rt.controller.io
        irqs = tuple((n, i.on, i.enabled, i.pending) for n, i in sorted(task.irqs.irqs.items()))
        return (io.version, len(io.log), rt.scheduler.idle.clock, rt.msg_handle,
                len(rt.messages.shown), rt.messages.next_handle, irqs, task.err_text)

    def _watch_writes(self, rec: _Recording, task, node, frame, depth: int) -> None:
        """Note the values of what statement `node` writes that outlives the pass, before it
        runs (checked at the next step of the same or a shallower frame)."""
        names = self._targets.get(id(node))
        if names is None:
            names = self._targets[id(node)] = _written(node)
        if not names:
            return
        refs = []
        for name in names:
            ref = self._ref(name, frame, rec.depth)
            if ref is False:
                self._fail("name")
                return
            if ref is not None:
                refs.append((ref, freeze(ref.peek()), name))
        if refs:
            rec.pending.append((depth, refs))

    def _ref(self, name: N.Name, frame, base: int):
        """The reference `name` (written in `frame`) denotes, if its variable outlives the pass;
        None if it does not (a local of a routine the pass called), or an I/O system variable
        (its changes are in the I/O image's version); False when it cannot be told."""
        place = getattr(name.ann, "place", None) if name.ann is not None else None
        if place is None:
            return False
        kind = place.kind
        if kind == LOCAL:
            if frame is None:
                return False
            ref = frame.vars[place.slot]
            if frame.depth > base and (ref is None or (isinstance(ref, Slot) and ref.c is frame.store)):
                return None         # the routine's own variable: gone when it returns
            return ref if ref is not None else frame.var(place.slot)
        if kind == SYSTEM or kind == UNRESOLVED:
            key = place.name.upper()
            if key in IO_NAMES:
                return None
            if key in CONSTANT_NAMES:
                return None
        try:
            return self.rt.storage_ref(place, frame)
        except Exception:  # noqa: BLE001 - a name the run cannot place: not a spin
            return False

    def _writes_kept(self, rec: _Recording, depth: int) -> bool:
        """Check the writes of the statements that ended (those of frames at `depth` or deeper)."""
        keep = []
        ok = True
        for entry in rec.pending:
            d, refs = entry
            if d < depth:
                keep.append(entry)
                continue
            for ref, before, name in refs:
                if freeze(ref.peek()) != before:
                    self.why["wrote " + name.name] = self.why.get("wrote " + name.name, 0) + 1
                    ok = False
        rec.pending = keep
        return ok

    def _second_pass_done(self, rec: _Recording, task) -> None:
        first, events = rec.first, rec.events
        rt = self.rt
        if events != first or rec.pending or \
                self._world(task) + (tuple([_store(f.store) for f in _chain(task.frame)]),) != rec.world:
            self._fail("second")
            return
        key = tuple(events)
        spin = self.passes.get(key, False)
        if spin is False:
            spin = self.passes[key] = self._analyse(rec)
        if spin is None:
            self._fail("analysis")
            return
        # the task's frames at each step, as the idle watch images them (the recorded images
        # of the second pass), and its innermost frame (an automatic cell's recording)
        spin = _copy_with(spin, rec)
        ok = self._may_park(spin) and rt.steps + 1 < task.slice_end
        self._stop(True, ok)
        if ok:
            task.park = spin

    def _analyse(self, rec: _Recording) -> "_Pass | None":
        """What the recorded pass reads (module docstring), or None when it is not a spin."""
        io = motion = cyclic = False
        probes = []
        for node in rec.nodes.values():
            if node is None:
                continue
            acc, cond = accesses(node)
            if isinstance(node, N.For):
                acc = acc + [("w", node.var)]
            for mode, x in acc + cond:
                if mode == "call":
                    callee = getattr(x.ann, "callee", None) if x.ann is not None else None
                    if callee is None:
                        return None
                    if callee.kind == NATIVE:
                        if callee.name.upper() not in PURE_NATIVES:
                            return None
                    elif callee.kind != ROUTINE:
                        return None
                    continue
                place = getattr(x.ann, "place", None) if x.ann is not None else None
                sym = place.symbol if place is not None else None
                if sym is not None and sym.kind == "signal":
                    io = True
                    continue
                if place is None or place.kind not in (SYSTEM, UNRESOLVED):
                    continue
                key = place.name.upper()
                if key in IO_NAMES:
                    io = True
                elif key in MOTION_NAMES:
                    motion = True
                elif key == "$CYCFLAG":
                    cyclic = True
                elif key in STATE_NAMES and key not in probes:
                    probes.append(key)
        spin = _Pass(tuple(rec.events), None, None, None, None)
        spin.io, spin.motion, spin.cyclic, spin.probes = io, motion, cyclic, tuple(probes)
        return spin

    def _may_park(self, spin: _Pass) -> bool:
        return not self._step_may_change(spin)

    def _step_may_change(self, spin: _Pass) -> bool:
        """The controller's next step may change what `spin` reads (module docstring)."""
        rt = self.rt
        if spin.motion and not rt.controller.is_idle():
            return True
        if self.reads_restless_flag(spin):
            return True
        # a cyclic flag whose expression settles changes only after the I/O image did (a
        # statement or another task wakes the pass first): $CYCFLAG is read as an input is
        return (spin.io or spin.cyclic) and \
            (self._io_may_change() or any(k[0] == "analog output" for k in rt._cyclic))

    def reads_restless_flag(self, spin: _Pass) -> bool:
        """`spin` reads ``$CYCFLAG`` while a cyclic flag whose expression does not settle is on:
        the flag may change at any IPO cycle (the one test of it: here and the scheduler's
        steady cycles)."""
        return spin.cyclic and bool(self.rt.restless)

    def _io_may_change(self) -> bool:
        """The controller's next step may change an input (module docstring)."""
        rt = self.rt
        ctl = rt.controller
        # the same cycle, no statement run since (a PULSE, an answer of the automatic cell)
        at = (ctl.cycle, len(ctl.stimuli), rt.steps - self.skipped)
        if self._io_at[0] == at:
            return self._io_at[1]
        nxt = ctl.next_event_cycle()
        may = (nxt is not None and nxt <= ctl.cycle + 1) or (ctl.is_moving() and any(
            not st.fired and st.due is None and st.reached_mm is not None for st in ctl.stimuli))
        self._io_at = (at, may)
        return may

    # ------------------------------------------------------------------ parked
    def park(self, task) -> None:
        """Called by Runtime.loop_tick at the boundary of the second recorded pass of `task`
        (after its step was counted): the task stops here (module docstring)."""
        spin, task.park = task.park, None
        rt = self.rt
        if rt.steps >= task.slice_end or len(task.contexts) != 1 or not self.parked_ok(task):
            return
        left = task.slice_end - rt.steps        # the rest of this time slice: taken as passes
        if rt.steps + left + 2 * (task.budget + spin.steps) > rt.limit_at:
            return                              # the step limit is near: it ends at a statement
        if self.shadow:
            task.shadow = _Parked(spin, 0, rt.controller.io.version, self._probed(spin))
            task.shadow.expect = left   # the steps parking would count by the end of this slice
            self.shadowed.append(task)
            self._update()
            return
        rt.steps += left
        self.skipped += left
        task.parked = _Parked(spin, left, rt.controller.io.version, self._probed(spin))
        self.parked.append(task)
        self.parks += 1
        self._place(task)
        self._update()
        rt.yield_cycle(task)            # until the scheduler resumes it, or a catch-up

    def parked_ok(self, task) -> bool:
        """Nothing pending for `task` (an interrupt, a TRIGGER, an error) and parking still allowed."""
        return (self.allowed() and not task.pending_triggers and task.pending_error is None
                and not any(i.pending for i in task.irqs.irqs.values()))

    def _probed(self, spin: _Pass) -> tuple:
        refs = spin.refs
        if refs is None:
            sv = self.rt.sysvars
            refs = spin.refs = tuple(sv.lookup(k) for k in spin.probes)
        return tuple([freeze(r.peek()) for r in refs])

    def _place(self, task) -> None:
        """The statement the parked task would stand at (``Task.at``)."""
        p = task.parked
        task.at = p.spin.at[(p.done - 1) % p.spin.steps]

    def _hold(self, task) -> bool:
        """The parked task's IPO cycle: counted, not run, unless it must wake (True: counted)."""
        rt = self.rt
        p = task.parked
        spin = p.spin
        if 2 * (task.budget + spin.steps) > rt.step_limit_left(task):
            return False
        if (spin.io and rt.controller.io.version != p.io_version) or \
                (spin.probes and self._probed(spin) != p.probed):
            self.missed += 1
            return False
        rt.state_epoch += 1             # as Scheduler._resume: another task ran
        if task.irqs.armed:
            # the poll its resume would make (Runtime.service): an interrupt to run wakes it
            ctl = rt.controller
            if task.irqs.poll(ctl.io.version, ctl.time, rt.state_epoch, rt.cyclic_watch.written()):
                return False
        auto = rt.autocell
        if auto is not None and auto.recording is not None:
            self._feed(task, auto)
        rt.steps += task.budget
        p.done += task.budget
        self.skipped += task.budget
        self._place(task)
        return True

    def _feed(self, task, auto) -> None:
        """An automatic cell records what the tasks execute (interp/runtime/autocell.py): the
        statements this time slice of the parked task would run, with the frames they would run
        in (one pass at most: the keys of a later pass are the same)."""
        p = task.parked
        spin = p.spin
        n = spin.steps
        # as run: first the step that ended its last time slice (recorded when it resumes), then
        # the steps of this slice but its last one
        for i in range(min(task.budget, n)):
            j = (p.done - 1 + i) % n
            auto.record_frame(task, spin.infos[j], spin.frames[j])

    def frames_image(self, task):
        """The image of a parked task's frames at the step it stands at (None: not parked)."""
        p = task.parked
        if p is None:
            return None
        return p.spin.images[(p.done - 1) % p.spin.steps]

    def before_step(self) -> None:
        """The scheduler is about to step the controller: wake the parked tasks the step may
        change something for (module docstring)."""
        for task in list(self.parked):
            if self._step_may_change(task.parked.spin):
                self.wake(task)
        for task in list(self.shadowed):
            if self._step_may_change(task.shadow.spin):
                self._unshadow(task)

    # ------------------------------------------------------------------ waking
    def outside_change(self) -> None:
        """Something outside the tasks changed their state (an operator's edit: a variable set,
        a message acknowledged, the override; interp/runtime/core.py ``Runtime.changed_outside``):
        a recording fails, parked and shadowed spins run again."""
        if self.rec is not None:
            self._fail("outside")
        self.wake_all()

    def wake_all(self) -> None:
        for task in list(self.parked):
            self.wake(task)
        for task in list(self.shadowed):
            self._unshadow(task)

    def _unshadow(self, task) -> None:
        task.shadow = None
        self.shadowed.remove(task)
        self.due[id(task)] = self.rt.controller.cycle
        self._update()

    def check_shadows(self) -> None:
        """The end of an IPO cycle's tasks: each shadowed spin stands where parking says."""
        for task in self.shadowed:
            p = task.shadow
            j = (p.done - 1) % p.spin.steps
            self.shadow_checks += 1
            real = tuple([_store(f.store) for f in _frames(task)])
            at = p.spin.at[j]
            if (at.file, at.line) != (task.at.file, task.at.line) or p.spin.images[j] != real or p.done != p.expect:
                self.shadow_errors += 1
                self.why[f"shadow at step {j}: {task.at.file}:{task.at.line}"] = 1

    def wake(self, task) -> None:
        """Catch up: `task` runs from the boundary the steps it took after its last whole pass
        (module docstring), then stands where its last time slice ended."""
        rt = self.rt
        p = task.parked
        task.parked = None
        self.parked.remove(task)
        self.wakes += 1
        self.due[id(task)] = rt.controller.cycle
        self.bad.pop(id(task), None)
        left = p.done % p.spin.steps
        self.skipped -= left
        if left:
            sched = rt.scheduler
            saved, before, limit = rt.current_task, rt.steps, rt.limit_at
            rt.limit_at = before + left     # replayed steps: counted while it was parked
            back = getcurrent()
            rt.current_task = task
            task.slice_end = before + left
            task.quiet = 0
            task.replay = [p.spin, 0]
            self.replaying += 1
            task.in_poll = True         # its interrupts were polled where it parked: nothing changed
            task.glet.parent, parent = back, task.glet.parent
            sched.return_to, ret = back, sched.return_to
            self._update()
            try:
                task.glet.switch()
            finally:
                task.glet.parent = parent
                sched.return_to = ret
                task.in_poll = False
                if task.replay is not None and task.replay[1] != left:
                    self.diverged += 1
                    self.why[f"catch-up ran {task.replay[1]} of {left} steps"] = 1
                task.replay = None
                self.replaying -= 1
                rt.steps = before       # these steps were counted while it was parked
                rt.limit_at = limit
                rt.current_task = saved
                rt._break(task)
        self._update()

    def _replayed(self, task, info, tick: bool) -> None:
        spin, i = task.replay
        if i >= len(spin.events) or spin.events[i][:3] != (info.file, info.line, tick):
            self.diverged += 1
            self.why[f"catch-up left the pass at {i}: {info.file}:{info.line}"] = 1
        task.replay[1] = i + 1


def _chain(frame):
    while frame is not None:
        yield frame
        frame = frame.caller


def _copy_with(spin: _Pass, rec: _Recording) -> _Pass:
    out = _Pass(spin.events, rec.infos, rec.at, rec.frames, rec.images)
    out.io, out.motion, out.cyclic, out.probes = spin.io, spin.motion, spin.cyclic, spin.probes
    return out


def _root(e):
    while isinstance(e, (N.Index, N.Field)):
        e = e.base
    return e if isinstance(e, N.Name) else None


def _written(node) -> tuple:
    """The names statement `node` writes: its assignment target, a FOR's counter, and every
    variable passed to a built-in (its :OUT arguments; an :IN one is written by nothing, so
    counting it only costs a comparison)."""
    out = []
    acc, cond = accesses(node)
    for mode, x in acc + cond:
        if mode == "w":
            out.append(x)
        elif mode == "call":
            callee = getattr(x.ann, "callee", None) if x.ann is not None else None
            if callee is not None and callee.kind == NATIVE:
                for a in x.args:
                    r = _root(a)
                    if r is not None:
                        out.append(r)
    if isinstance(node, N.For):
        r = _root(node.var)
        if r is not None:
            out.append(r)
    return tuple(out)
