"""A periodic spin (issue 62): a task whose loop runs over a state that repeats itself every few
IPO cycles (a clock generator: ``IF $TIMER[30] > 12 THEN ... gbClk = TRUE``), recorded from one
``LOOP`` iteration to the next until a boundary's key comes again (:class:`Period`), parked with
each cycle's end put in place, and woken to the boundary before its place: :class:`PeriodicSpins`,
a part of the spin watch (spin.py). Also the probe of a woken plain pass, parked again when what
decides it stands (:meth:`PeriodicSpins._replays`, issue 86 item 2). docs/architecture.md
"Periods" has the rules, the cases and how they are checked."""

from __future__ import annotations

from bisect import bisect_right
from collections import namedtuple

from krl.ast import nodes as N
from krl.semantics.advance import accesses
from krl.semantics.facts import BESIDE, REPEAT, TASKS
from krl.semantics.resolve import NATIVE, ROUTINE, SYSTEM, UNRESOLVED
from krl.semantics.statements import kinds_where

from .convert import assign_into
from .errors import KrlRuntimeError
from .idle import _SCALARS as SCALARS
from .idle import freeze, stack_image
from .memory import Slot
from .passes import (ALLOWED, CLOCK_NAMES, MAX_PASS_STEPS, PURE_NATIVES, STATE_NAMES, Pass, analyse, stub_uses,
                     written)
from .sysvars import _LIVE, live_reading
from .values import Arr, Struct, copy_value
from .watch import CONSTANT, IO

#: the longest period recorded, in IPO cycles (a pass of 44 steps in slices of 100 and a flag toggled
#: every other cycle make a period of 400 cycles, 4.8 s)
MAX_PERIOD_CYCLES = 1024
#: a recording ends when no state (its key but where it is in its slice) came again in this many cycles
MAX_STATE_CYCLES = 64
#: the timer arrays: a statement that names one of them names a timer of the period's state
TIMER_ARRAYS = frozenset({"$TIMER", "$TIMER_STOP", "$TIMER_FLAG"})
#: every timer (a timer named by a computed index)
ALL_TIMERS = tuple(range(1, 65))
#: failed replays of a woken pass in a row after which its next 1, 2, 4 ... MAX_REPLAY_SKIP parks are
#: not imaged (PeriodicSpins._to_image)
REPLAY_FAILS = 3
MAX_REPLAY_SKIP = 16


def timers_of(node) -> tuple[int, ...] | None:
    """The timers statement `node`'s own expressions name (``$TIMER[30]``, ``$TIMER_STOP[31]``),
    :data:`ALL_TIMERS` for one named by a computed index; None when it names none."""
    found: set[int] = set()
    for child in node.children():
        if not isinstance(child, N.Expr):
            continue
        for e in child.walk():
            if e.__class__ is N.Index and e.base.__class__ is N.Name and e.base.name.upper() in TIMER_ARRAYS:
                if len(e.indices) == 1 and e.indices[0].__class__ is N.IntLit:
                    found.add(int(e.indices[0].value))
                else:
                    return ALL_TIMERS
    return tuple(sorted(found)) if found else None


def timers_image(io, timers: tuple) -> tuple:
    ms, stop = io.timer_ms, io.timer_stop
    return tuple([(ms[i], stop[i]) for i in timers])


def set_timers(io, timers: tuple, image: tuple) -> None:
    """Put the timers `timers` to `image` (robot/io.py: a write of the value a timer has is none)."""
    for i, (ms, stop) in zip(timers, image):
        io.set_timer(i, ms)
        io.set_timer_stop(i, stop)


def put(ref, value) -> None:
    """Store `value` (a copy) into the written variable `ref` as the task's statement did: in place
    for a structure or an array, so that the references others hold stay valid."""
    cur = ref.c[ref.k]
    if cur.__class__ is Struct or cur.__class__ is Arr:
        assign_into(cur, value)
    else:
        ref.c[ref.k] = copy_value(value)


def place_of(ref) -> tuple:
    """Where the value of reference `ref` is kept: the same for every reference to it (a data
    list's slot, a frame's, a structure's component, an element; a live array's element)."""
    c = ref.__class__
    if c is Slot:
        return (id(ref.c), ref.k)
    proxy = getattr(ref, "proxy", None)
    if proxy is not None:
        return (id(proxy), getattr(ref, "index", None), getattr(ref, "a", None))
    return (id(ref),)


def plain(ref) -> bool:
    """`ref` is a variable :func:`put` may store into: a slot with no write rules of its own."""
    return ref.__class__ is Slot and ref.on_write is None


class End:
    """The end of the task's time slice in one cycle of the period: the written values (their
    images and copies), the timers, the task's frames as the idle watch images them, and the clock
    reads of the slice (``clock``)."""

    __slots__ = ("pos", "images", "values", "timers", "frames", "clock", "delta")

    def __init__(self, pos, images, values, timers, frames, clock) -> None:
        self.pos, self.images, self.values, self.timers, self.frames = pos, images, values, timers, frames
        self.clock = clock
        self.delta: tuple = ()      # (index in the written set, value) that differ from the end before


#: a boundary of the loop within the period: its position (the period's steps counted through it),
#: the written values and timers then, the clock reads from it to the end of its time slice
Tick = namedtuple("Tick", "pos values timers clock")


class Period(Pass):
    """A recorded periodic spin: a :class:`~.passes.Pass` (``images`` None: the frames are the
    ends') with ``written`` (the written set's references), ``timers``, ``consts`` (the unwritten
    values read: references and images), ``probed_refs`` (the state variables in its key), ``ends``
    (by position), ``starts`` (timers at each cycle's first step, by step index), ``ticks`` (by
    position), ``keys`` (tick key -> Tick), ``bound`` and ``frame`` (the loop)."""

    periodic = True
    still = False       # no cycle's end puts anything: the state stands (SpinWatch._period_found)

    def __init__(self, events, infos, at, frames) -> None:
        super().__init__(events, infos, at, frames, None)
        self.written: tuple = ()
        self.timers: tuple = ()
        self.consts: tuple = ()
        self.touched: frozenset = frozenset()   # where what it reads or writes is (place_of)
        self.probed_refs: tuple = ()
        self.ends: dict = {}
        self.starts: dict = {}
        self.ticks: list = []
        self.keys: dict = {}
        self.bound = None
        self.frame = None

    def end_at(self, pos: int) -> End:
        return self.ends[pos % len(self.events)]

    def tick_before(self, pos: int) -> Tick:
        """The last boundary at or before position `pos` (0 <= pos < n; the first: none is)."""
        return self.ticks[max(bisect_right(self.ticks, pos, key=lambda t: t.pos) - 1, 0)]


class PeriodicSpins:
    """The periodic part of the spin watch (spin.py ``SpinWatch`` is one): module docstring."""

    def _written(self, node) -> tuple:
        """The names statement `node` writes (passes.py ``written``), found once."""
        names = self._targets.get(id(node))
        if names is None:
            names = self._targets[id(node)] = written(node)
        return names

    def _record_period(self, rec, task, info, tick: bool) -> None:
        """A step of a periodic recording; the boundary is a LOOP's iteration."""
        frame = task.frame
        depth = frame.depth if frame is not None else 0
        if len(task.contexts) != rec.contexts or any(i.pending for i in task.irqs.irqs.values()):
            self._fail("context")
            return
        where = (info.file, info.line)
        nodes = self.statements(info)
        if rec.phase == 0:
            if tick and nodes and all(n.__class__ is N.Loop for n in nodes):
                rec.bound, rec.frame, rec.depth, rec.phase = where, frame, depth, 1
                rec.world = self._period_world(task)
                self._period_step(rec, info, frame, tick, depth)
                self._period_tick(rec, task)
                return
            if not tick:
                rec.last_at = info
            rec.looked += 1
            if rec.looked > MAX_PASS_STEPS:
                self._fail("looking")
            return
        if not tick:
            if nodes is None or not all(isinstance(n, ALLOWED) for n in nodes):
                self._fail("statement")
                return
            rec.last_at = info
        for n in nodes or ():
            if id(n) not in rec.nodes:
                rec.nodes[id(n)] = n
                named = timers_of(n)
                if named is not None and not rec.timers.issuperset(named):
                    rec.timers.update(named)
                    rec.grew = True
            if not self._period_names(rec, n, frame, tick):
                return
        self._period_step(rec, info, frame, tick, depth)
        if len(rec.events) > (MAX_PERIOD_CYCLES + 2) * task.budget + MAX_PASS_STEPS:
            self._fail("long")
            return
        if tick and where == rec.bound and frame is rec.frame:
            self._period_tick(rec, task)

    @staticmethod
    def _period_step(rec, info, frame, tick: bool, depth: int) -> None:
        rec.events.append((info.file, info.line, tick, depth - rec.depth))
        rec.infos.append(info)
        rec.at.append(rec.last_at)
        rec.frames.append(frame)

    def _period_names(self, rec, node, frame, tick: bool) -> bool:
        """Add what statement `node` (run in `frame`) writes and reads that outlives a pass to
        the recording's sets; False (the recording failed) for a name that cannot be placed."""
        for ref in self._writes_of(node, frame, rec.depth, tick):
            if ref is False:
                self._fail("name")
                return False
            k = place_of(ref)
            if k not in rec.written:
                rec.written[k] = ref
                rec.grew = True
        names = self._reads.get(id(node))
        if names is None:
            acc, cond = accesses(node)
            names = self._reads[id(node)] = tuple(x for mode, x in acc + cond if mode == "r")
        for name in names:
            place = getattr(name.ann, "place", None) if name.ann is not None else None
            if place is not None and place.kind in (SYSTEM, UNRESOLVED):
                key = place.name.upper()
                if key in STATE_NAMES:
                    if key not in rec.probed:
                        rec.probed[key] = self.sysvars.lookup(key)
                        rec.grew = True
                    continue
                if key in _LIVE:
                    continue        # computed: the analysis classes it (I/O, motion, clock)
            ref = self._ref(name, frame, rec.depth)
            if ref is False:
                self._fail("name")
                return False
            if ref is not None:
                rec.read[place_of(ref)] = ref
        return True

    def _writes_of(self, node, frame, base: int, tick: bool):
        """The references statement `node` (in `frame`) writes that outlive a pass (False for a
        name that cannot be placed; a loop iteration writes a FOR's counter only)."""
        if tick and not isinstance(node, N.For):
            return
        for name in self._written(node):
            ref = self._ref(name, frame, base)
            if ref is not None:
                yield ref

    def _foreign(self, rec, task, info, tick: bool) -> None:
        """Another task's step while a period is recorded: note what it writes and the timers it
        names (:meth:`_undisturbed`)."""
        idx = len(rec.events)
        frame = task.frame
        for node in self.statements(info) or ():
            for ref in self._writes_of(node, frame, -1, tick):
                rec.foreign[place_of(ref) if ref is not False else False] = idx
            for t in timers_of(node) or ():
                rec.foreign[("timer", t)] = idx

    def _harmless(self, spin: Period, task, info, tick: bool) -> bool:
        """Another task's step leaves a parked period as it is (else its task wakes first): it is
        of a kind :func:`_harmless_kind` lets run and writes nothing the period reads or writes
        (``spin.touched``: the names of :meth:`_step_plan`, placed in `task`'s frame each time)."""
        if not TASK_PROBES.issuperset(spin.probes):
            return False            # it reads state another task's step may change ($POS_INT, $ERR)
        plan = self._step_plans.get((info.file, info.line, tick))
        if plan is None:
            plan = self._step_plan(info, tick)
        if plan is False:
            return False
        frame = task.frame
        ref_of = self._ref
        touched = spin.touched
        for ok, names in plan:
            if not ok:
                return False
            for name in names:
                ref = ref_of(name, frame, -1)
                if ref is not None and (ref is False or place_of(ref) in touched):
                    return False
        return True

    def _step_plan(self, info, tick: bool):
        """For :meth:`_harmless`: ``(kind ok, names a step of it writes)`` per statement at
        `info`'s line (as :meth:`_writes_of`), False for none; kept per (file, line, tick)."""
        nodes = self.statements(info)
        plan = False
        if nodes is not None:
            plan = []
            for node in nodes:
                ok = _harmless_kind(node)
                plan.append((ok, self._written(node) if ok and (not tick or isinstance(node, N.For)) else ()))
            plan = tuple(plan)
        self._step_plans[(info.file, info.line, tick)] = plan
        return plan

    def _period_world(self, task) -> tuple:
        """What must not change at all while a period runs: the I/O log, the messages, the
        task's interrupt tables and error text."""
        irqs = tuple((n, i.on, i.enabled, i.pending, i.last) for n, i in sorted(task.irqs.irqs.items()))
        return (len(self.ctl.io.log), self.messages.last_handle, len(self.messages.shown), self.messages.next_handle,
                irqs, task.err_text)

    def _period_key(self, written, timers: tuple, probed, task) -> tuple:
        """The key of `task` at a boundary (module docstring)."""
        return (task.slice_end - self.clock.steps, values_image(written), timers_image(self.ctl.io, timers),
                stack_image(task.frame), values_image(probed), self._period_world(task))

    def _period_tick(self, rec, task) -> None:
        """A boundary of a periodic recording: its key seen before ends the recording."""
        cycle = self.ctl.cycle
        if cycle == rec.cycle0:
            return              # (a period starts after a cycle's end: its clock reads are known)
        if rec.grew:
            rec.keys, rec.states, rec.grew = {}, set(), False
        written = tuple(rec.written.values())
        key = self._period_key(written, tuple(sorted(rec.timers)), tuple(rec.probed.values()), task)
        if key[5] != rec.world:
            self._fail("period: I/O, a message or an interrupt")
            return
        state = key[1:]
        if state in rec.states:
            rec.repeats = True
        else:
            rec.states.add(state)
        if not rec.repeats and cycle - rec.cycle0 > MAX_STATE_CYCLES:
            self._fail("period: no state repeats")
            return
        idx = len(rec.events) - 1
        seen = rec.keys.get(key)
        if seen is not None and self._undisturbed(rec, seen):
            self._period_found(rec, task, seen)
            return
        rec.keys[key] = idx
        rec.ticks.append((idx, tuple([copy_value(r.peek()) for r in written]), key[2], rec.clock, key))
        if cycle - rec.cycle0 > MAX_PERIOD_CYCLES:
            self._fail("period: none")

    @staticmethod
    def _undisturbed(rec, ia: int) -> bool:
        """No other task wrote what the recorded statements read or write (or a timer they
        name) since step `ia`."""
        f = rec.foreign
        if f.get(False, -1) >= ia:
            return False            # a write nobody could place
        return all(f.get(k, -1) < ia for k in rec.read) and all(f.get(k, -1) < ia for k in rec.written) \
            and all(f.get(("timer", t), -1) < ia for t in rec.timers)

    def _period_end(self, rec, task) -> None:
        """The tasks of this IPO cycle ran (SpinWatch.before_step): the end of the recorded
        task's time slice."""
        written = tuple(rec.written.values())
        rec.ends.append((len(rec.events), values_image(written), tuple([copy_value(r.peek()) for r in written]),
                         timers_image(self.ctl.io, tuple(sorted(rec.timers))),
                         stack_image(task.frame), rec.clock))

    def _period_found(self, rec, task, ia: int) -> None:
        """The key of boundary `ia` came again at the present boundary: build the Period."""
        ib = len(rec.events) - 1
        n = ib - ia
        budget = task.budget
        if n <= 0 or n % budget:
            self._fail("period: steps")
            return
        cycles = n // budget
        spin = Period(tuple(rec.events[ia + 1:ib + 1]), tuple(rec.infos[ia + 1:ib + 1]),
                      tuple(rec.at[ia + 1:ib + 1]), tuple(rec.frames[ia + 1:ib + 1]))
        if not self._analyse_into(rec, spin) or not self._period_irqs(task):
            self._fail("analysis")
            return
        written = tuple(rec.written.values())
        spin.written, spin.timers = written, tuple(sorted(rec.timers))
        spin.bound, spin.frame = rec.bound, rec.frame
        # the ends of the time slices: those of the period, and the one before it (clock reads)
        ends = []
        prev_clock = None
        for steps, images, values, timers, frames, clock in rec.ends:
            pos = steps - ia - 1
            if pos < 0:
                prev_clock = clock
            elif pos < n:
                ends.append(End(pos, images, values, timers, frames, clock - prev_clock))
                prev_clock = clock
        if len(ends) != cycles or len({e.pos % budget for e in ends}) != 1:
            self._fail("period: ends")
            return
        for j, e in enumerate(ends):
            before = ends[j - 1]
            e.delta = tuple((i, v) for i, (v, img, old) in enumerate(zip(e.values, e.images, before.images))
                            if img != old)
            spin.ends[e.pos] = e
        for i, ref in enumerate(written):
            if not plain(ref) and any(e.images[i] != ends[0].images[i] for e in ends):
                self._fail("period: writes a system variable")
                return
        # nothing to put at any cycle: steady cycles may count it (interp/runtime/scheduler.py)
        spin.still = all(not e.delta and not e.clock for e in ends) and not spin.timers
        for idx, timers in rec.starts.items():
            k = idx - ia - 1
            if 0 <= k < n:
                spin.starts[k] = timers
            elif k == -1:
                spin.starts[n - 1] = timers     # the first boundary's: the last step's
        if len(spin.starts) != cycles:
            self._fail("period: starts")
            return
        # the boundaries: their state, and the clock reads from each to the end of its slice
        # (the reads of that slice less those before the boundary)
        ticks = []
        ends_raw = rec.ends
        for idx, values, timers, clock, key in rec.ticks:
            pos = idx - ia
            if not 0 <= pos < n:
                continue
            last = max((r for r in ends_raw if r[0] <= idx), key=lambda r: r[0])
            nxt = spin.end_at(last[0] - ia - 1 + budget)
            t = Tick(pos, values, timers, nxt.clock - (clock - last[5]))
            ticks.append(t)         # (by position: recorded in order)
            spin.keys[key] = t
        spin.ticks = ticks
        spin.consts = tuple((r, freeze(r.peek())) for k, r in rec.read.items() if k not in rec.written)
        spin.touched = frozenset(rec.read) | frozenset(rec.written)
        spin.probed_refs = tuple(rec.probed.values())
        self.periods += 1
        ok = self._parks_now(spin, task)
        self._stop(True, ok)
        if ok:
            task.park = (spin, 0)

    def _analyse_into(self, rec, spin) -> bool:
        """The plain analysis (passes.py :func:`analyse`) on the period's statements, and no clock read
        but a running timer's (:data:`CLOCK_NAMES`)."""
        for node in rec.nodes.values():
            acc, cond = accesses(node)
            for mode, x in acc + cond:
                place = getattr(x.ann, "place", None) if mode != "call" and x.ann is not None else None
                if place is not None and place.kind in (SYSTEM, UNRESOLVED) and place.name.upper() in CLOCK_NAMES:
                    return False
                sym = place.symbol if place is not None else None
                start = getattr(sym.decl, "start", None) if sym is not None and sym.kind == "signal" else None
                if start is not None and getattr(start, "sysvar", "").upper() in TIMER_ARRAYS:
                    return False        # a SIGNAL over a timer array
        found = analyse(rec.nodes.values(), rec.events, self.statements, self._facts)
        if found is None:
            return False
        spin.io, spin.motion, spin.cyclic, spin.probes = found.io, found.motion, found.cyclic, found.probes
        spin.stub_lines = found.stub_lines
        return True

    @staticmethod
    def _period_irqs(task) -> bool:
        """The task's interrupts read nothing a period writes: each one on is over inputs,
        outputs, constants and the probed state only (interp/runtime/watch.py classes)."""
        return all(i.watch.split(":")[0] in (CONSTANT, IO) for i in task.irqs.irqs.values() if i.on)

    def _probe(self, rec, task, info, tick: bool) -> None:
        """After a wake: the task's next boundary parks it again when its key is one of its
        period's and the unwritten values it reads are unchanged."""
        spin = rec.probe
        if len(task.contexts) != rec.contexts:
            self._fail("probe")
            return
        if tick and (info.file, info.line) == spin.bound and task.frame is spin.frame:
            t = spin.keys.get(self._period_key(spin.written, spin.timers, spin.probed_refs, task))
            if t is None or not all(freeze(r.peek()) == img for r, img in spin.consts) or \
                    not self._period_irqs(task):
                self._fail("probe")
                return
            if self._parks_now(spin, task):
                self.probe_parks += 1
                self._stop(True, True)
                task.park = (spin, t.pos)
                return
        rec.looked += 1
        if rec.looked > 2 * MAX_PASS_STEPS:
            self._fail("probe")

    def _image(self, spin: Pass, task, state: tuple) -> tuple:
        """What decides the pass `spin` from its boundary, where `task` stands: the values of
        what it names (passes.py ``touched``), the I/O image if it names it whole, its probes and
        `state` (:meth:`_state` there)."""
        refs, whole, _ = spin.decides
        return (values_image(refs), self.ctl.io.image() if whole else None,
                self._probed(spin) if spin.probes else ()) + state

    def _stands(self, spin: Pass, task) -> bool:
        """What decides `spin` is as :meth:`_image` took it where it parked (``spin.seen``): the
        same answer as comparing the whole images, value by value, the I/O it names first."""
        seen = spin.seen
        refs, whole, order = spin.decides
        vals = seen[0]
        for i in order:
            r = refs[i]
            v = r.c[r.k] if r.__class__ is Slot else r.peek()
            if v.__class__ not in SCALARS:
                v = freeze(v)
            if v is not vals[i] and v != vals[i]:       # (as tuples compare: a NaN is itself)
                return False
        if whole and self.ctl.io.image() != seen[1]:
            return False
        if spin.probes and self._probed(spin) != seen[2]:
            return False
        return self._state(task) == seen[3:]

    def _replays(self, rec: _Recording, task, where: tuple, frame) -> bool:
        """A recording after a wake reached its first boundary: parked again at once, not recorded,
        when it is the boundary of the pass the task was woken from (``rec.woken``) and what decides
        that pass stands (:meth:`_stands`); else its next parks are not imaged for a while."""
        spin, rec.woken = rec.woken, None
        if where != spin.events[-1][:2] or frame is not spin.frames[-1] or not self._stands(spin, task):
            self.why["not replayed: changed"] = self.why.get("not replayed: changed", 0) + 1
            rest = self.ctl.is_idle()
            got = self.unreplayed.get(id(task))
            n = got[0] + 1 if got is not None and got[2] == rest else 1
            self.unreplayed[id(task)] = (n, min(1 << (n - REPLAY_FAILS), MAX_REPLAY_SKIP) if n >= REPLAY_FAILS else 0,
                                         rest)
            return False
        self.unreplayed.pop(id(task), None)
        if not self._parks_now(spin, task):
            return False
        self.replays += 1
        self.boundary[id(task)] = (self._own(task) + 1, spin.steps)
        self._stop(True, True)
        task.park = spin
        return True

    def _to_image(self, task) -> bool:
        """`task` parks a recorded pass: image it for a replay after its wake (:meth:`_image`)? Not
        after :data:`REPLAY_FAILS` failed replays in a row (the robot moving at each, or at rest at
        each) for its next parks while that lasts. Changes no run, only what is recorded again."""
        got = self.unreplayed.get(id(task))
        if got is None or not got[1]:
            return True
        if got[2] != self.ctl.is_idle():
            del self.unreplayed[id(task)]       # (the robot started or stopped since: what changed may not)
            return True
        self.unreplayed[id(task)] = (got[0], got[1] - 1, got[2])
        self.why["not imaged: replays failed"] = self.why.get("not imaged: replays failed", 0) + 1
        return False

    def _place_ref(self, place, k):
        """The reference of a name's `place` (not a local's), element `k` of it when not None; None
        when names.py raises a run-time error for it (an unknown name, an index outside the array);
        any other error is the simulator's own and raised."""
        try:
            ref = self.names.storage_ref(place, None)
            return ref if k is None else self.names.index(ref, [k], place.name)
        except KrlRuntimeError:
            return None

    def _put_end(self, p, end, clock: int, whole: bool = False) -> None:
        """Put the state at the end `end` of a parked period's time slice in place: the written
        values that differ (`whole`: compared with each; else the end's delta from the end before,
        which is in place), the timers, `clock` reads of the clock; a change moves the watch keys."""
        spin = p.spin
        written = spin.written
        changed = False
        if whole:
            for i, ref in enumerate(written):
                if freeze(ref.peek()) != end.images[i]:
                    put(ref, end.values[i])
                    changed = True
        else:
            for i, v in end.delta:
                put(written[i], v)
                changed = True
        io = self.ctl.io
        set_timers(io, spin.timers, end.timers)
        p.io_version = io.version
        self.idle.clock += clock
        if changed:
            self.cyclic_watch.version += 1

    def _wake_period(self, task, p) -> None:
        spin = p.spin
        n = spin.steps
        target = (p.pos0 + p.done) % n
        tick = spin.tick_before(target)
        left = target - tick.pos
        self.skipped -= left
        stub_uses(spin, p.pos0, p.done - left, self.kss.uses)     # the steps it skipped
        io = self.ctl.io
        idle = self.idle
        now, clock = timers_image(io, spin.timers), idle.clock
        expect = values_image(spin.written)
        for ref, v in zip(spin.written, tick.values):
            if plain(ref):
                put(ref, v)
        set_timers(io, spin.timers, tick.timers)
        first = spin.starts.get((tick.pos - 1) % n)
        if first is not None:
            set_timers(io, spin.timers, first)      # the boundary ended a time slice
        if left:
            self._catch_up(task, [spin, tick.pos, target], left)
        set_timers(io, spin.timers, now)
        idle.clock = clock                          # the reads were counted while it was parked
        if values_image(spin.written) != expect:
            self.diverged += 1
            self.why[f"catch-up of a period left another state at step {target}"] = 1
        self.probes[id(task)] = spin

    def frames_image(self, task):
        """The image of a parked task's frames at the step it stands at (None: not parked; a
        period's task stands at the end of a time slice)."""
        p = task.parked
        if p is None:
            return None
        if p.spin.__class__ is Period:
            return p.spin.end_at(p.pos0 + p.done).frames
        return p.spin.images[p.step()]

    def check_shadows(self) -> None:
        """The end of an IPO cycle's tasks: each shadowed spin stands where parking says."""
        cycle = self.ctl.cycle
        for task in self.shadowed:
            p = task.shadow
            if p.seen != cycle:
                continue                # (not given this cycle: the run stopped before its turn)
            spin = p.spin
            j = p.step()
            self.shadow_checks += 1
            real = stack_image(task.frame)
            at = spin.at[j]
            if spin.__class__ is Period:
                end = spin.end_at(p.pos0 + p.done)
                ok = end.frames == real and end.images == values_image(spin.written) and \
                    end.timers == timers_image(self.ctl.io, spin.timers)
            else:
                ok = spin.images[j] == real
            if (at.file, at.line) != (task.at.file, task.at.line) or not ok or p.done != p.expect:
                self.shadow_errors += 1
                self.why[f"shadow at step {j}: {task.at.file}:{task.at.line}"] = 1


def values_image(refs) -> tuple:
    """The images (idle.py ``freeze``) of the values of `refs`: a data list's slot read where it
    is kept, a scalar as it is (what ``freeze(ref.peek())`` gives, without the calls)."""
    vals = [r.c[r.k] if r.__class__ is Slot else r.peek() for r in refs]
    return tuple([v if v.__class__ in SCALARS else freeze(v) for v in vals])


#: the state variables a parked period may read while another task's steps leave it parked
#: (``reads=TASKS``: a task's end and an operator's change wake it first)
TASK_PROBES = live_reading(TASKS)

#: the kinds of statement another task may run beside a parked period (PeriodicSpins._harmless):
#: those whose facts say REPEAT or BESIDE (krl/semantics/statements.py ``KINDS``)
HARMLESS = kinds_where(lambda f: f.fast_forward in (REPEAT, BESIDE))


def _harmless_kind(node) -> bool:
    """Statement `node` is one of :data:`HARMLESS` that writes no computed system variable or
    SIGNAL, names no timer and calls no built-in but a pure one (passes.py ``PURE_NATIVES``)."""
    if not isinstance(node, HARMLESS) or timers_of(node) is not None:
        return False
    acc, cond = accesses(node)
    for mode, x in acc + cond:
        if mode == "call":
            callee = getattr(x.ann, "callee", None) if x.ann is not None else None
            if callee is None or callee.kind not in (NATIVE, ROUTINE) or \
                    (callee.kind == NATIVE and callee.name.upper() not in PURE_NATIVES):
                return False
        elif mode == "w":
            place = getattr(x.ann, "place", None) if x.ann is not None else None
            if place is None:
                return False
            sym = place.symbol
            if (sym is not None and sym.kind == "signal") or \
                    (place.kind in (SYSTEM, UNRESOLVED) and place.name.upper() in _LIVE):
                return False
    return True
