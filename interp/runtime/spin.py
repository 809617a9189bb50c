"""The spin watch (issue 48; docs/architecture.md "Spins cost nothing"): a task whose loop runs the
same statements over the same state every pass is *parked* until something it reads can change.

:class:`SpinWatch` (one per run, both interpreters) *records* a task with the full hook (core.py
``Runtime.before_statement``, ``loop_tick``): a *pass* is what it executes between two iterations of
one loop in one frame. One pass that left the state as it found it (its frames' images within
:data:`IMAGE_BASE` values per step: ``SpinWatch._one_pass``), else two equal ones, make a spin when
every write that outlives the pass writes the value already there, nothing else changed (no I/O,
timer, message, clock or random read but a running timer compared with a constant it does not
cross within :data:`MIN_CROSSING` cycles, passes.py ``timer_compares``; no interrupt, no wait) and
every statement is one whose only effects are such writes (passes.py ``ALLOWED``).

**Parked**, the task is not resumed: each IPO cycle its time slice is counted
(:meth:`SpinWatch.count`) and the state stands as in the recorded passes. **Woken** before anything
that could change what it reads: another task proceeding, an input the controller's next step sets
(or sets on reaching a point: :meth:`SpinWatch.reaching`), a compared timer crossing, a state or
motion variable it reads changed (passes.py ``MOTION_NAMES``), an interrupt of its own due, the step
limit near. The wake *catches up*: the task runs from the pass's start the steps it took after its
last whole pass (checked against the recorded pass: ``diverged``), so it stands exactly where it
would; recorded again after it, or parked again at once (:meth:`SpinWatch._again`, period.py
``_replays``, :meth:`SpinWatch._restart`; docs/architecture.md).

The watch is off where statements are observed one by one (a trace, a debugger, run mode other
than GO, a network partner, ``ANIN ON``). A failed recording is tried again after twice as many
cycles (up to :data:`MAX_GAP`), one that may not park yet up to :data:`MAX_WAIT_GAP`. Periods are
period.py's; a pass's facts, passes.py's; its transients, transient.py's.
"""

from __future__ import annotations

from greenlet import getcurrent

from krl.ast import nodes as N
from krl.semantics.resolve import LOCAL, SYSTEM, UNRESOLVED

from .idle import _IMAGED, freeze, stack_image
from .memory import Slot
from .passes import (IO_NAMES, MAX_PASS_STEPS, Parked, StatementIndex, analyse, clock_reads, copy_with,
                     crosses, only_motion_changed, served, step_plan, stub_uses, touched)
from .passes import Pass as _Pass
from .period import MAX_STATE_CYCLES, Period, PeriodicSpins, set_timers, timers_image
from .scheduler import break_quiet
from .sysvars import CONSTANT_NAMES
from .transient import Transients

#: the longest wait between two recordings, in IPO cycles (after repeated failures)
MAX_GAP = 256
#: the longest wait, in IPO cycles, between recordings of a spin that could not park when recorded
MAX_WAIT_GAP = 16
#: pass recordings in a row that changed what they wrote before the next recording of a task looks
#: for a period (period.py), after a failed probe and when none failed (docs/architecture.md "Periods")
PASSES_AFTER_PROBE, PASSES_BEFORE_PERIOD = 3, 2
#: a first pass is imaged at its steps (one pass may then do) while its frames' images took at most
#: IMAGE_BASE + IMAGE_PER_STEP values per step recorded; past that, two passes are recorded
IMAGE_BASE, IMAGE_PER_STEP = 4096, 8
#: after a wake, the full hook looks for the loop only from this many steps before the predicted boundary
LOOK_MARGIN = 16
#: a pass comparing a running timer with a constant parks only if none changes in this many IPO cycles
MIN_CROSSING = 8


class _Recording:
    """A recording in progress (module docstring)."""

    __slots__ = ("task", "bound", "frame", "depth", "phase", "events", "infos", "at", "frames",
                 "images", "first", "pending", "world", "contexts", "last_at", "nodes", "looked", "seen",
                 "periodic", "probe", "written", "read", "timers", "grew", "keys", "ticks", "ends",
                 "starts", "clock", "cycle0", "states", "repeats", "foreign", "probed", "trans", "img", "one", "imaged",
                 "ahead", "plen", "c0", "creads", "after", "woken", "redo")

    def __init__(self, task, periodic: bool = False, probe=None) -> None:
        self.task = task
        self.periodic = periodic    # a periodic recording (period.py)
        self.probe = probe          # the known period it probes for
        self.written: dict = {}     # place (period.place_of) -> ref: what the statements wrote that outlives a pass
        self.read: dict = {}        # place -> ref: what they read that outlives a pass
        self.timers: set = set()    # the timers they name
        self.grew = False           # the written set or the timers grew since the last boundary
        self.keys: dict = {}        # key of a boundary -> its step index
        self.ticks: list = []       # (index, values, timers, own clock reads, key) per boundary
        self.ends: list = []        # (steps, images, values, timers, frames, clock reads) per cycle end
        self.starts: dict = {}      # index of the step a cycle starts at -> timers
        self.clock = 0              # the task's own clock reads (running timers)
        self.cycle0 = 0             # the IPO cycle it started in
        self.states: set = set()    # the keys seen, where in the time slice left out
        self.repeats = False        # one of them came again
        self.foreign: dict = {}     # a place or a timer -> the last step another task wrote it at
        self.probed: dict = {}      # the state variables the statements read -> their references
        self.bound = None           # (file, line) of the loop whose iteration ends a pass
        self.frame = None           # the frame of that loop
        self.depth = 0
        self.phase = 0              # 0: looking for the loop, 1: first pass, 2: second pass
        # per recorded step: its (file, line, tick, depth), StmtInfo, Task.at, frame, frames' image, clock reads
        self.events, self.infos, self.at, self.frames, self.images, self.creads = [], [], [], [], [], []
        self.first: list | None = None
        self.pending: list = []     # (depth, ref, image before, name) of the last statements' writes
        self.world = None
        self.contexts = len(task.contexts)
        self.last_at = task.at
        self.nodes: dict = {}       # id(node) -> node of the statements executed
        self.looked = 0             # steps taken while looking for a loop iteration
        self.seen: set = set()      # loops passed over while looking
        self.trans = Transients()   # what the pass changes and changes back (interp/runtime/transient.py)
        self.img, self.one = None, True     # (frame, its frames' image) while no local is written; one pass may do
        self.imaged = 0             # the values the first pass's images took (IMAGE_BASE, IMAGE_PER_STEP)
        self.c0 = 0                     # its clock reads at the pass's boundary
        self.ahead = self.plen = None   # own step LOOK_MARGIN before the predicted boundary, the pass's length
        self.after = 0                  # no pass starts at an iteration before this own step (SpinWatch._again)
        self.woken = None               # the pass the task was woken from: parked again if it stands (_replays)
        self.redo = 0                   # 1: the first pass changed what it found; 2: recorded again (_restart)


class SpinWatch(PeriodicSpins):
    """The spin watch of one run (module docstring). ``recordings``, ``parks``, ``wakes`` and
    ``skipped`` (steps not executed; ``moving``: those in IPO cycles the robot moved in) count what
    it did; ``diverged`` (a catch-up that left the recorded pass) and ``missed`` (a parked task's
    reads changed without a wake) count what must not happen."""

    def __init__(self, spec, controller, clock, tracing, stepping, program, names, sysvars, kss, messages,
                 yield_cycle, step_limit_left, part) -> None:
        """The spin watch of the run `spec` (RunSpec ``fast_forward``, ``spins``) with the parts it
        reads (fastforward.py says each); `part`: the FastForward, whose ``on`` it keeps."""
        self.part = part
        self.ctl, self.clock, self.tracing, self.stepping = controller, clock, tracing, stepping
        self.program, self.names, self.sysvars, self.kss, self.messages = program, names, sysvars, kss, messages
        self.yield_cycle, self.step_limit_left = yield_cycle, step_limit_left
        self.idle = self.scheduler = self.cyclic = self.cyclic_watch = None     # attach
        self.enabled = spec.fast_forward and spec.spins != "off"  # False: never park (RunSpec; tests compare)
        self.hooks_all = False      # a period is parked: every step takes the full hook (_harmless)
        self.rec: _Recording | None = None
        self.parked: list = []
        self.gap: dict = {}         # id(task) -> cycles between two recordings
        self.due: dict = {}         # id(task) -> the cycle of its next recording
        self.moved: dict = {}       # id(task) -> the gap after a wake by the robot's motion (resuming)
        self.bad: dict = {}         # id(task) -> loops ((file, line)) that did not give a spin
        self.passes: dict = {}      # signature of a recorded pass -> analysis (None: not a spin)
        self.woken: dict = {}       # id(task) -> the pass it was woken from, its reads imaged (_replays)
        self.unreplayed: dict = {}  # id(task) -> (replays in a row that failed, parks not imaged left, robot at rest: _to_image)
        self.replaying = 0          # catch-ups under way
        self._io_at = (None, False)     # (moment, _io_may_change's answer then)
        self._nodes: StatementIndex | None = None     # (file, line) -> the statements there
        self._targets: dict = {}    # id(statement) -> the names it writes
        self._rec_plans: dict = {}  # (file, line, tick) -> (nodes,) + passes.step_plan
        self._reads: dict = {}      # id(statement) -> the names it reads
        self._facts: dict = {}      # id(statement) -> passes.node_facts
        self._step_plans: dict = {}     # (file, line, tick) -> PeriodicSpins._step_plan
        self.parks = self.wakes = self.skipped = self.moving = self.diverged = self.missed = 0
        self.recordings = 0         # recordings started
        self.replays = 0            # of them, parked again at their first boundary: the pass stood (_replays)
        self.restarts = 0           # first passes that changed what they found, recorded again (_restart)
        self.seconds = 0            # second passes recorded (the first did not do: _one_pass)
        self.boundary: dict = {}    # id(task) -> (its own step (Task.steps) after a boundary, its pass's length)
        self.looked = 0             # steps the recordings took with the full hook looking for their loop
        self.why: dict = {}         # why recordings failed (a count per reason: tests, tuning)
        self.shadow = spec.spins == "shadow"    # True: a spin runs on, checked against parking (check_shadows)
        self.shadowed: list = []
        self.shadow_checks = self.shadow_errors = 0
        self.periodic: set = set()  # the tasks whose next recording looks for a period (period.py)
        self.probes: dict = {}      # id(task) -> the Period to probe for at its next boundary
        self.period_fails: dict = {}    # id(task) -> its periodic recordings that failed
        self.period_due: dict = {}      # id(task) -> the cycle before which none is tried again
        self.changed: dict = {}     # id(task) -> its pass recordings in a row that changed what they wrote
        self.needed: dict = {}      # id(task) -> how many before a period is looked for (PASSES_BEFORE_PERIOD if absent)
        self.periods = self.probe_parks = 0
        controller.signals.set_reach_hook(self.reaching)   # (robot/signals.py: a stimulus on reaching a point)
        kss.attach(self.parked_stub_uses)       # (kss.py summary: the calls of the steps counted)

    def attach(self, idle, scheduler, cyclic, cyclic_watch) -> None:
        """The parts built after the watch: the `idle` watch, the `scheduler` (a catch-up returns
        to it), `cyclic` (cyclic.py) and `cyclic_watch` (watch.py)."""
        self.idle, self.scheduler, self.cyclic, self.cyclic_watch = idle, scheduler, cyclic, cyclic_watch

    # ------------------------------------------------------------------ when
    def allowed(self) -> bool:
        """Nothing observes statements one by one, and nothing outside the tasks changes their
        variables (module docstring)."""
        ctl = self.ctl
        net = getattr(ctl, "network", None)
        return (self.enabled and self.tracing.writer is None and not self.stepping.watching
                and self.stepping.run_mode == "GO" and getattr(ctl, "correction", None) is None
                and not any(k[0] == "analog input" for k in self.cyclic.handles)
                and (net is None or not net.polling))     # (no partner attached or ticking else: net/hub.py)

    def _update(self) -> None:
        self.part.on = self.rec is not None or bool(self.parked) or self.replaying > 0 or bool(self.shadowed)
        self.hooks_all = any(t.parked.spin.periodic for t in self.parked) or \
            any(t.shadow.spin.periodic for t in self.shadowed)

    def resuming(self, task) -> bool:
        """The scheduler is about to give `task` its IPO cycle. True when it stays parked
        (this cycle is counted instead of run: :meth:`_hold`); else a recording may start."""
        if self.shadowed and task in self.shadowed:
            sh = task.shadow
            # (woken where a parked task would be: :meth:`_hold`)
            if self.limit_near(task, sh.spin) or self._step_may_change(sh.spin) or \
                    (sh.spin.probes and self._probed(sh.spin) != sh.probed) or \
                    (task.irqs.armed and self._interrupt_due(task)):
                self._unshadow(task)
            else:
                sh.expect += task.budget
                sh.seen = self.ctl.cycle
            return False
        if task.parked is not None:
            held, done = self._hold(task), task.parked.done
            if held:
                return True
            self.wake(task)
            if held is None and not self._again(task, done):
                # (the motion it reads changed, no room to park again in this slice: recorded later)
                key = id(task)
                gap = self.moved[key] = min(MAX_WAIT_GAP, 2 * self.moved.get(key, 1)) if done <= task.budget else 1
                self.due[key] = self.ctl.cycle + gap
            return False
        rec = self.rec
        if rec is None and task.replay is None and task.shadow is None and task.until is None:
            key = id(task)      # (task.until: not resumed while its test of the controller fails)
            probe = self.probes.pop(key, None)
            if probe is not None and self.allowed():
                self._start(task, probe=probe)
                return False
            cycle = self.ctl.cycle
            if cycle >= self.due.get(key, 0) and self.allowed():
                self._start(task, periodic=key in self.periodic and cycle >= self.period_due.get(key, 0))
        elif rec is not None and rec.periodic and rec.task is task and rec.phase:
            # a cycle starts: the timers as the controller left them, for the step that runs first
            self.rec.starts[len(rec.events) - 1] = timers_image(self.ctl.io, tuple(sorted(rec.timers)))
        return False

    def _again(self, task, done: int) -> bool:
        """Parked `task` (for `done` steps) was woken at its turn because the motion its pass reads
        changed; within the IPO cycle the values stand, so a recording starts whose pass begins at the
        second loop iteration from here (docs/architecture.md "Parked again in the cycle"). True when
        the rest of this pass and two whole ones fit in the time slice."""
        known = self.boundary.get(id(task))
        if known is None or self.rec is not None or not self.allowed() or task.until is not None:
            return False
        b0, steps = known               # (own step after the next iteration, the pass's length)
        if b0 - task.steps + 2 * steps + LOOK_MARGIN >= task.budget:
            return False
        self._start(task)
        self.rec.after = b0             # the iteration at b0 - 1 ends the pass that reads the new values
        self._predict(self.rec, task.steps, b0 + steps, steps)    # (b0 + steps > task.steps: the catch-up ran < steps)
        return True

    def _start(self, task, periodic: bool = False, probe=None) -> None:
        self.recordings += 1
        self.rec = _Recording(task, periodic, probe)
        known = self.boundary.get(id(task))
        if not periodic and probe is None:
            self.rec.woken = self.woken.pop(id(task), None)
            if known is not None:
                self._predict(self.rec, task.steps, *known)
        self.rec.cycle0 = self.ctl.cycle
        task.watched = True
        break_quiet(task)
        self._update()

    def _fail(self, why: str) -> None:
        self.why[why] = self.why.get(why, 0) + 1
        rec = self.rec
        if rec is not None and rec.probe is not None:
            # the state after a wake is none of the period's: passes are looked for first again
            self.periodic.discard(id(rec.task))
            self.changed.pop(id(rec.task), None)
            self.needed[id(rec.task)] = PASSES_AFTER_PROBE
        elif rec is not None:
            # a pass that changed what it wrote may be periodic (not the robot interpreter's loops:
            # no clock generators); after a failed periodic recording, passes again
            key = id(rec.task)
            if not rec.periodic and not rec.task.limited and \
                    (why in ("writes", "second") or why.startswith("wrote ")):
                n = self.changed[key] = self.changed.get(key, 0) + 1
                if n >= self.needed.get(key, PASSES_BEFORE_PERIOD):
                    self.periodic.add(key)
            elif rec.periodic:
                self.periodic.discard(key)
                if why in ("period: no state repeats", "period: none"):
                    # a state that does not come back (a counter): looked for ever more rarely
                    n = self.period_fails[key] = self.period_fails.get(key, 0) + 1
                    self.period_due[key] = self.ctl.cycle + MAX_STATE_CYCLES * 4 ** min(n, 8)
        self._stop(False)

    def _stop(self, ok: bool, parks: bool = True) -> None:
        """End the recording: `ok` it found a spin (which `parks` now or not: module docstring)."""
        rec = self.rec
        if rec is None:
            return
        task = rec.task
        self.rec = None
        task.watched = False
        self.looked += rec.looked
        key = id(task)
        if ok:
            self.changed.pop(key, None)
            gap = 1 if parks else min(MAX_WAIT_GAP, 2 * self.gap.get(key, 1))
        else:
            gap = min(MAX_GAP, 2 * self.gap.get(key, 1))
        self.gap[key] = gap
        self.due[key] = self.ctl.cycle + gap
        # (the loop of a failed recording is not the next one's boundary: it may find an outer one)
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
        if rec is not None:
            if rec.task is task:
                if rec.probe is not None:
                    self._probe(rec, task, info, tick)
                elif rec.periodic:
                    self._record_period(rec, task, info, tick)
                else:
                    self._record(rec, task, info, tick)
                return
            if rec.periodic and rec.phase:
                self._foreign(rec, task, info, tick)
        sh = task.shadow
        if sh is not None:
            j = (sh.pos0 + sh.done) % sh.spin.steps     # (a shadowed spin runs the recorded pass)
            sh.done += 1
            if sh.spin.events[j][:3] != (info.file, info.line, tick):
                self.shadow_errors += 1
                self.why[f"shadow left the pass at step {j}: {info.file}:{info.line}"] = 1
                self._unshadow(task)
            return
        if self.parked or self.shadowed:
            self.wake_all(lambda s: s.__class__ is not Period or not self._harmless(s, task, info, tick))

    def proceeding(self) -> None:
        """A task goes on after a wait, or runs a TRIGGER action or an interrupt routine
        (Runtime._proceed): the parked tasks but periods (:meth:`_harmless`) catch up first."""
        self.wake_all(lambda s: s.__class__ is not Period, but=self.clock.current_task)

    def ending(self, task) -> None:
        """`task` ends (Runtime.task_main): the state variables of the tasks ($PRO_STATE1,
        $PRO_ACT) change now, without a statement; a parked task that reads one catches up first."""
        self.wake_all(lambda s: s.probes, but=task)

    def clock_read(self, task, n: int = 1) -> None:
        """`task` read the clock `n` times (a running timer: Runtime.clock_read) while the watch is on."""
        rec = self.rec
        if rec is not None and rec.task is task:
            rec.clock += n

    def waiting(self, task) -> None:
        """`task` gives its IPO cycle back before its time slice ended (a wait): a recording of
        it fails."""
        rec = self.rec
        if rec is not None and rec.task is task and self.clock.steps < task.slice_end:
            self._fail("waits")

    def quiet_steps(self, task, lim: int) -> "int | None":
        """The fast-forward's part of the quiet-step limit (core.py ``Runtime.quiet_limit``): None
        while it watches every step of `task`, else `lim` or less."""
        if task.watched:
            q = self.quiet_until(task)
            if q <= self.clock.steps:
                return None
            lim = min(lim, q)
        auto = self.idle.auto
        return None if self.hooks_all or (auto is not None and auto.recording is not None) or \
            (task.replay is not None and len(task.replay) < 4) or task.shadow is not None else lim

    def quiet_until(self, task) -> int:
        """The clock's step count up to which the steps of `task`, whose recording looks for its
        loop's iteration, may be quiet: LOOK_MARGIN steps before the predicted boundary; 0: none."""
        rec = self.rec
        if rec is None or rec.ahead is None or rec.phase or rec.task is not task:
            return 0
        return rec.ahead - task.steps + task.slice_end - task.budget     # (the slice started at slice_end - budget)

    def _own(self, task) -> int:
        """The steps `task`, running its time slice, has taken in the run (as Task.steps counts)."""
        return task.steps + self.clock.steps - (task.slice_end - task.budget)

    @staticmethod
    def _predict(rec: _Recording, now: int, after: int, steps: int) -> None:
        """`rec` looks from LOOK_MARGIN steps before the first boundary after own step `now` of a
        pass of `steps` steps that had one after own step `after` (from now when that is nearer)."""
        x = now - after
        at = after + (x // steps + 1 if x >= 0 else 0) * steps - LOOK_MARGIN
        rec.ahead, rec.plen = (at if at > now else None), steps

    # ------------------------------------------------------------------ recording
    def statements(self, info):
        """The statements of the program at `info`'s file and line (passes.py ``StatementIndex``,
        one per checked workspace)."""
        index = self._nodes
        if index is None:
            index = self._nodes = self.program.derived("statement_index", StatementIndex)
        return index(info)

    def _record(self, rec: _Recording, task, info, tick: bool) -> None:
        frame = task.frame
        depth = frame.depth if frame is not None else 0
        if rec.pending and not self._writes_kept(rec, depth):
            if rec.phase != 1 or rec.redo or not rec.one:
                self._fail("writes")
                return
            rec.redo = 1        # (the pass after it may repeat: _restart)
        table = task.irqs.irqs
        if len(task.contexts) != rec.contexts or (table and any(i.pending for i in table.values())):
            self._fail("context")
            return
        if not tick:
            rec.last_at = info
        if rec.phase == 0:
            where = (info.file, info.line)
            if tick and (where not in self.bad.get(id(task), ()) or where in rec.seen) and \
                    (not rec.after or self._own(task) >= rec.after):
                if rec.woken is not None and self._replays(rec, task, where, frame):
                    return
                rec.bound, rec.frame, rec.depth, rec.phase = where, frame, depth, 1
                rec.last_at, rec.c0 = task.at, rec.clock    # (the statement before: quiet steps may have run it)
                rec.world = self._world(task)
            else:
                if tick:
                    rec.seen.add(where)     # a loop the last recording failed on: the next one, or it
                    if rec.plen is not None:    # (a pass later again, if it was the predicted one)
                        self._predict(rec, self._own(task) + 1, self._own(task) + 1, rec.plen)
                rec.looked += 1
                if rec.looked > MAX_PASS_STEPS:
                    self._fail("looking")
            return
        plan = self._rec_plans.get((info.file, info.line, tick))
        if plan is None:        # what a step at `info` needs (passes.py step_plan), made once
            nodes = self.statements(info)
            plan = self._rec_plans[(info.file, info.line, tick)] = (nodes,) + step_plan(nodes, tick, self._targets)
        nodes, ok, writers = plan
        if not ok:
            self._fail("statement")
            return
        if nodes is not None:
            for n in nodes:
                rec.nodes[id(n)] = n
        # (a step is known by its file and line: the VM's loop may tick with two StmtInfos)
        rec.events.append((info.file, info.line, tick, depth - rec.depth))
        rec.infos.append(info)
        rec.at.append(rec.last_at)
        rec.creads.append(rec.clock - rec.c0)
        if rec.phase == 2 or rec.phase and rec.one:
            img = rec.img
            if img is None or img[0] is not frame:     # (a local written since, another frame)
                before = _IMAGED[0]
                img = rec.img = (frame, stack_image(frame))
                if rec.phase == 1:      # (past its budget a first pass is no longer imaged: two passes)
                    rec.imaged += _IMAGED[0] - before
                    rec.one = rec.imaged <= IMAGE_BASE + IMAGE_PER_STEP * len(rec.events)
                    img = img if rec.one else None
            if img is not None:
                rec.frames.append(frame)
                rec.images.append(img[1])
        if len(rec.events) > MAX_PASS_STEPS:
            self._fail("long")
            return
        for n in writers:
            self._watch_writes(rec, task, n, frame, depth)
        if tick and (info.file, info.line) == rec.bound and frame is rec.frame:
            self.boundary[id(task)] = (self._own(task) + 1, len(rec.events))   # (its step is counted next)
            if rec.phase == 1:
                if self._one_pass(rec, task):
                    return
                rec.first = rec.events
                rec.events, rec.infos, rec.at, rec.frames, rec.images, rec.creads = [], [], [], [], [], []
                rec.phase, rec.c0 = 2, rec.clock
                self.seconds += 1
                return
            self._second_pass_done(rec, task)

    def _world(self, task) -> tuple:
        """What a pass must leave as it found it besides its writes: the I/O, the clock reads of
        others, and :meth:`_state`."""
        io = self.ctl.io
        return (io.version, len(io.log), self.idle.clock - self.rec.clock) + self._state(task)

    def _state(self, task) -> tuple:
        """The messages, `task`'s interrupts, error text and frames."""
        table = task.irqs.irqs
        irqs = tuple([(n, i.on, i.enabled, i.pending) for n, i in sorted(table.items())]) if table else ()
        return (self.messages.last_handle, len(self.messages.shown), self.messages.next_handle, irqs, task.err_text,
                stack_image(task.frame))

    def _watch_writes(self, rec: _Recording, task, node, frame, depth: int) -> None:
        """Note the values of what statement `node` writes that outlives the pass, before it
        runs (checked at the next step of the same or a shallower frame)."""
        names = self._written(node)
        if not names:
            return
        refs = []
        for name in names:
            place = getattr(name.ann, "place", None) if name.ann is not None else None
            if place is None or place.kind == LOCAL:
                rec.img = None          # the frames' image is made again at the next step
            ref = self._ref(name, frame, rec.depth)
            if ref is False:
                self._fail("name")
                return
            if ref is not None:
                refs.append((ref, freeze(ref.peek()), name))
                if rec.phase:
                    rec.trans.first_write(ref)
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
            if key in IO_NAMES or key in CONSTANT_NAMES:
                return None
        try:
            return self.names.storage_ref(place, frame)
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
                # (a value changed within the pass: a transient, if the pass puts it back)
                if freeze(ref.peek()) != before and \
                        not rec.trans.changed(ref, len(rec.events) if rec.phase else -1):
                    self.why["wrote " + name.name] = self.why.get("wrote " + name.name, 0) + 1
                    ok = False
        rec.pending = keep
        return ok

    def _one_pass(self, rec: _Recording, task) -> bool:
        """The first pass ended. True: it left the state as it found it (module docstring), taken as
        the spin; False: a second pass is recorded, with the first pass's transients only."""
        trans = rec.trans
        world = None        # (taken once: the checks below change none of it; the pass's end or the restart keeps it)
        if rec.one and rec.redo != 1 and not rec.pending:
            world = self._world(task)
            if world == rec.world and self._clock_ok(rec) and (not trans.refs or trans.seal(len(rec.events))):
                rec.first = rec.events
                self._second_pass_done(rec, task, world)
                return True
        if rec.redo < 2 and rec.one and self._clock_ok(rec):
            self._restart(rec, task, world)
            return True
        if rec.redo == 1:
            self._fail("writes")
            return True
        rec.trans = Transients()
        for key, ref in trans.refs.items():
            if ref is not None:
                rec.trans.refs[key] = ref       # (changed in the first pass: put back in the second)
        return False

    def _restart(self, rec: _Recording, task, world: "tuple | None" = None) -> None:
        """The first pass (its images within the budget) changed what it found: the pass after it,
        over what it left, may repeat it; recorded from here as the first pass, once (issue 86 item
        2). `world`: :meth:`_world` now, if taken."""
        rec.redo, rec.world, rec.c0 = 2, self._world(task) if world is None else world, rec.clock
        rec.events, rec.infos, rec.at, rec.frames, rec.images, rec.creads = [], [], [], [], [], []
        rec.nodes, rec.trans, rec.img, rec.imaged, rec.pending = {}, Transients(), None, 0, []
        self.restarts += 1

    def _second_pass_done(self, rec: _Recording, task, world: "tuple | None" = None) -> None:
        """The pass recorded last ended at its boundary (`world`: :meth:`_world` there, if taken):
        parked when it repeats the first (module docstring)."""
        events = rec.events
        if events != rec.first or rec.pending:
            self._fail("second")
            return
        world = self._world(task) if world is None else world
        if world != rec.world or not self._clock_ok(rec):
            self._fail("second")
            return
        if rec.trans.refs and not rec.trans.seal(len(events)):
            self._fail("transient")
            return
        spin = self._analysis(rec)
        if spin is None:
            self._fail("analysis")
            return
        spin = copy_with(spin, rec)     # (with the task's frames at each step, as recorded)
        ok = self._parks_now(spin, task) and \
            (not spin.motion or rec.cycle0 == self.ctl.cycle or self.ctl.is_idle())
        self._stop(True, ok)
        if ok:
            if spin.decides is not None and spin.trans is None and spin.reads is None and self._to_image(task):
                spin.seen = self._image(spin, task, world[3:])  # (a wake may park it again: _replays)
            task.park = spin

    def _analysis(self, rec: _Recording):
        """passes.py :func:`analyse` of the pass `rec` recorded last, made once per pass."""
        key = tuple(rec.events)
        spin = self.passes.get(key, False)
        if spin is False:
            spin = self.passes[key] = analyse(rec.nodes.values(), rec.events, self.statements, self._facts)
            if spin is not None and spin.compares == () and not spin.clocked and not spin.cyclic:
                spin.decides = touched(rec.nodes.values(), self._place_ref)
        return spin

    def _clock_ok(self, rec: _Recording) -> bool:
        """The pass `rec` recorded last read no clock, or a running timer only in comparisons with
        constants (passes.py ``timer_compares``: parked until the next step would change one)."""
        if rec.clock == rec.c0:
            return True
        spin = self._analysis(rec)
        ctl = self.ctl
        return spin is not None and bool(spin.compares) and not spin.clocked and \
            not crosses(spin, ctl.io, ctl._dt_ms, MIN_CROSSING)

    def _parks_now(self, spin: _Pass, task) -> bool:
        """`task` may park on `spin` now: the controller's next step changes nothing it reads
        and a step of its time slice is left."""
        return not self._step_may_change(spin) and self.clock.steps + 1 < task.slice_end

    def _step_may_change(self, spin: _Pass) -> bool:
        """The controller's next step may change what `spin` reads (module docstring)."""
        if spin.motion and spin.periodic and not self.ctl.is_idle():
            return True         # (a pass's reads of the robot's motion are probed: _hold)
        if self.reads_restless_flag(spin) or (spin.compares and crosses(spin, self.ctl.io, self.ctl._dt_ms)):
            return True
        # ($CYCFLAG, its expression settling, changes only after the I/O image: read as an input)
        return (spin.io or spin.cyclic) and \
            (self._io_may_change() or any(k[0] == "analog output" for k in self.cyclic.handles))

    def reads_restless_flag(self, spin: _Pass) -> bool:
        """`spin` reads ``$CYCFLAG`` while a cyclic flag whose expression does not settle is on:
        the flag may change at any IPO cycle."""
        return spin.cyclic and bool(self.cyclic.restless)

    def _io_may_change(self) -> bool:
        """The controller's next step may change an input (module docstring)."""
        ctl = self.ctl
        # the same cycle, no statement run since (a PULSE, an answer of the automatic cell)
        at = (ctl.cycle, len(ctl.signals.stimuli), self.clock.steps - self.skipped)
        if self._io_at[0] == at:
            return self._io_at[1]
        nxt = ctl.signals.next_event_cycle(ctl.cycle)
        may = nxt is not None and nxt <= ctl.cycle + 1
        self._io_at = (at, may)
        return may

    # ------------------------------------------------------------------ parked
    def park(self, task) -> None:
        """Called by Runtime.loop_tick at the boundary of the last recorded pass of `task` (after
        its step was counted), or at a boundary of its period (``task.park``: the period and the
        boundary's position): the task stops here."""
        spin, task.park = task.park, None
        pos0 = 0
        if spin.__class__ is tuple:
            spin, pos0 = spin
        if self.clock.steps >= task.slice_end or len(task.contexts) != 1 or not self.parked_ok(task):
            return
        left = task.slice_end - self.clock.steps        # the rest of this time slice: taken as passes
        if self.clock.steps + left + 2 * (task.budget + spin.steps) > self.clock.limit_at:
            return                              # the step limit is near: it ends at a statement
        if self.shadow:
            task.shadow = Parked(spin, 0, self.ctl.io.version, self._probed(spin), pos0)
            task.shadow.expect = left   # the steps parking would count by the end of this slice
            task.shadow.seen = self.ctl.cycle
            self.shadowed.append(task)
            self._update()
            return
        self.clock.count(left)
        self.skipped += left
        self.idle.clock += clock_reads(spin, left)     # (its reads of a running timer, as run)
        p = task.parked = Parked(spin, left, self.ctl.io.version, self._probed(spin), pos0)
        p.served = served(spin, spin.refs, p.probed)
        self.parked.append(task)
        self.parks += 1
        if spin.__class__ is Period:
            # the rest of this slice ran: its end's state, and its clock reads from the boundary
            tick = next(t for t in spin.ticks if t.pos == pos0)
            self._put_end(p, spin.end_at(pos0 + left), tick.clock, whole=True)
        if spin.trans is not None:
            spin.trans.put_at(p.step(), self.cyclic_watch)     # the state at the step it stands at
        task.at = spin.at[p.step()]     # the statement it would stand at
        self._update()
        self.yield_cycle(task)            # until the scheduler resumes it, or a catch-up

    def parked_stub_uses(self, into) -> None:
        """Add to the counter `into` the stand-in calls (passes.py ``stub_uses``) of the steps the
        parked tasks have been counted since they parked but the last (it runs when they resume)."""
        for task in self.parked:
            p = task.parked
            stub_uses(p.spin, p.pos0, p.done - 1, into)

    def parked_ok(self, task) -> bool:
        """Nothing pending for `task` (an interrupt, a TRIGGER, an error) and parking still allowed."""
        return (self.allowed() and not task.pending_triggers and task.pending_error is None
                and not any(i.pending for i in task.irqs.irqs.values()))

    def _probed(self, spin: _Pass) -> tuple:
        refs = spin.refs
        if refs is None:
            refs = spin.refs = tuple(self.sysvars.lookup(k) for k in spin.probes)
        return tuple([freeze(r.peek()) for r in refs])

    def _hold(self, task) -> bool:
        """The parked task's IPO cycle: counted, not run, unless it must wake (True: counted)."""
        p = task.parked
        spin = p.spin
        if self.limit_near(task, spin):
            return False
        if spin.io and self.ctl.io.version != p.io_version:
            self.missed += 1
            return False
        if spin.probes:
            now = self._probed(spin)
            if now != p.probed:
                if only_motion_changed(spin, now, p.probed) and not spin.periodic:
                    return None         # (its catch-up reads the motion it read: wake)
                self.missed += 1
                return False
        self.clock.epochs()                   # as Scheduler._resume: another task ran
        if task.irqs.armed and self._interrupt_due(task):
            return False                # an interrupt to run wakes it
        auto = self.idle.auto
        if auto is not None and auto.recording is not None:
            self._feed(task, auto)
        self.count(task, task.budget, self.ctl.is_moving())
        return True

    def count(self, task, k: int, moving: bool) -> None:
        """Count `k` steps of parked `task` (its turn's time slice, a steady cycle's, a clock
        jump's slices; `moving`: the robot moved in them): its steps, clock reads, position and
        the state there (a period's end, the pass's transients)."""
        p = task.parked
        spin = p.spin
        self.clock.count(k)
        task.steps += k
        if spin.reads is not None:
            self.idle.clock += clock_reads(spin, p.done + k) - clock_reads(spin, p.done)
        p.done += k
        self.skipped += k
        self.moving += k if moving else 0
        if spin.__class__ is Period:
            end = spin.end_at(p.pos0 + p.done)
            self._put_end(p, end, end.clock)
        elif spin.trans is not None:
            spin.trans.put_at(p.step(), self.cyclic_watch)      # (moves the cyclic watch's version if it changes)
        task.at = spin.at[p.step()]     # the statement it would stand at

    def limit_near(self, task, spin) -> bool:
        """The step limit comes near for `task`, parked (or shadowed) at `spin`: fewer steps are
        left than two time slices and a pass; woken, the task ends at a statement, as unparked."""
        return 2 * (task.budget + spin.steps) > self.step_limit_left(task)

    def _interrupt_due(self, task) -> bool:
        """The poll of `task`'s interrupts its resume would make (Runtime.service) finds one to run."""
        ctl = self.ctl
        return bool(task.irqs.poll(ctl.io.version, ctl.time, self.clock.state_epoch, self.cyclic_watch.written()))

    def _feed(self, task, auto) -> None:
        """The automatic cell's recording (autocell.py) gets the statements this time slice of the
        parked task would run, with their frames (one pass at most: a later pass's are the same)."""
        p = task.parked
        spin = p.spin
        n = spin.steps
        rec, fed = p.fed
        if rec is not auto.recording:
            fed = 0
        elif fed >= n:
            return      # every step of the pass is in this recording: a feed would add nothing
        # as run: the step that ended its last time slice, then this slice's steps but its last
        k = min(task.budget, n)
        for i in range(k):
            j = (p.pos0 + p.done - 1 + i) % n
            auto.record_frame(task, spin.infos[j], spin.frames[j])
        p.fed = (auto.recording, fed + k)

    def before_step(self) -> None:
        """The scheduler is about to step the controller: the end of a periodic recording's
        time slice; wake the parked tasks the step may change something for (module docstring)."""
        rec = self.rec
        if rec is not None and rec.periodic and rec.phase:
            self._period_end(rec, rec.task)
        self.wake_all(self._step_may_change)

    # ------------------------------------------------------------------ waking
    def reaching(self) -> None:
        """The step is about to set the inputs of a stimulus on reaching a point (robot/signals.py
        ``Signals.on_reach``): the passes that read I/O catch up first, over the inputs they saw."""
        self.wake_all(lambda spin: spin.io or spin.cyclic)

    def outside_change(self) -> None:
        """Something outside the tasks changed their state (core.py ``Runtime.changed_outside``):
        a recording fails, parked and shadowed spins run again."""
        if self.rec is not None:
            self._fail("outside")
        self.wake_all()

    def wake_all(self, which=None, but=None) -> None:
        """Wake the parked tasks and end the shadows but `but` whose spin `which` takes (None: all)."""
        for task in list(self.parked):
            if task is not but and (which is None or which(task.parked.spin)):
                self.wake(task)
        for task in list(self.shadowed):
            if task is not but and (which is None or which(task.shadow.spin)):
                self._unshadow(task)

    def _unshadow(self, task) -> None:
        if task.shadow.spin.__class__ is Period:
            self.probes[id(task)] = task.shadow.spin    # shadowed again at a boundary of its period
        elif task.shadow.spin.seen is not None:
            self.woken[id(task)] = task.shadow.spin     # (as a wake: _replays)
        task.shadow = None
        self.shadowed.remove(task)
        self.due[id(task)] = self.ctl.cycle
        self._update()

    def wake(self, task) -> None:
        """Catch up: `task` runs from the boundary the steps it took after its last whole pass, then
        stands where its last time slice ended (a period's task: period.py ``_wake_period``)."""
        p = task.parked
        task.parked = None
        self.parked.remove(task)
        self.wakes += 1
        self.due[id(task)] = self.ctl.cycle
        self.bad.pop(id(task), None)
        spin = p.spin
        if spin.__class__ is Period:
            self._wake_period(task, p)
        else:
            left = p.done % spin.steps
            if spin.trans is not None:
                spin.trans.put_at(0, self.cyclic_watch)        # the catch-up starts from the pass's start
            self.skipped -= left
            self.idle.clock -= clock_reads(spin, left)     # (the catch-up reads them again)
            stub_uses(spin, 0, p.done - left, self.kss.uses)     # the whole passes it skipped
            self.boundary[id(task)] = (task.steps + spin.steps - left, spin.steps)    # (its next one, if unchanged)
            if spin.seen is not None:
                self.woken[id(task)] = spin         # (parked again there if it stands: _replays)
            if left:    # (a pass's catch-up may take the VM's quiet steps: checked where hooked)
                self.sysvars.served = p.served        # (the robot's motion as its steps read it)
                try:
                    self._catch_up(task, [spin, 0, left, self.clock.steps], left)
                finally:
                    self.sysvars.served = None
        self._update()

    def _catch_up(self, task, replay: list, left: int) -> None:
        """Run `task` `left` steps (``replay``: the pass or period, the step it starts at, the
        step it must end at; :meth:`_replayed` checks each) now, before anything else goes on."""
        sched = self.scheduler
        before = self.clock.steps
        saved = self.clock.enter(task, before + left)     # replayed steps: counted while it was parked
        back = getcurrent()
        task.slice_end = before + left
        task.quiet = 0
        task.replay = replay
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
            if task.replay is not None and task.replay[1] != replay[2]:
                self.diverged += 1
                self.why[f"catch-up ran to step {task.replay[1]}, not {replay[2]}"] = 1
            task.replay = None
            self.replaying -= 1
            self.clock.restore(saved)       # these steps were counted while it was parked
            break_quiet(task)

    def _replayed(self, task, info, tick: bool) -> None:
        r = task.replay
        spin, i, end = r[0], r[1], r[2]
        if len(r) > 3:      # a pass's catch-up: the step is the steps taken since its start
            i = self.clock.steps - r[3]
        if i >= end or spin.events[i][:3] != (info.file, info.line, tick):
            self.diverged += 1
            self.why[f"catch-up left the pass at {i}: {info.file}:{info.line}"] = 1
        elif spin.__class__ is Period:
            timers = spin.starts.get(i)
            if timers is not None:          # this step ran first in a new IPO cycle
                set_timers(self.ctl.io, spin.timers, timers)
        task.replay[1] = i + 1


