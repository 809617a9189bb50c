"""The clock jump: a run of IPO cycles in which no task runs is counted in one step, not cycle by
cycle (issue 76, item 4: "the run jumps to the next change of anything it reads";
docs/architecture.md "Spins cost nothing").

While the robot stands and every live task is parked by the spin watch (interp/runtime/spin.py:
its passes read what the previous pass read and write what it wrote) or, in a steady cycle
(interp/runtime/scheduler.py), waits on a test that only a change of the I/O image, a statement
or a running timer can end, an IPO cycle executes no statement: the scheduler counts it (a
parked task's time slice, ``SpinWatch._hold`` or ``Scheduler._steady_cycle``: its steps, the
step of its pass it stands at, the state epoch, the poll of its interrupts), the idle watch
counts it (interp/runtime/idle.py: its windows stay open), and the controller steps a robot at
rest. Such cycles follow each other unchanged until the earliest of

* the controller's next event (``Signals.next_event_cycle``: a timed stimulus, an answer of the
  automatic cell, a cell rule's pending answer, a PULSE's reset);
* the end of a window of the idle watch (its state comparison and the automatic cell's question)
  or of the robot program's window (``IdleWatch.robot_starves``);
* the end of a waiting task's ``WAIT SEC`` (``Task.wake_cycle``);
* the time limit, and for a parked task the step limit coming near (``SpinWatch.limit_near``).

:func:`span` finds how many cycles, from this one, are such cycles (0: fewer than
:data:`MIN_SPAN`, or a condition fails), and :func:`count` counts them at once: every parked
task's steps and position advance by whole time slices (its pass's transients, the values it
changes and changes back, put in place at the step it then stands at: interp/runtime/
transient.py), the state epoch by one per task and cycle, the idle watch's last cycle moves,
and the controller fast-forwards (``Controller.skip``: the clock, the path time and every
running ``$TIMER`` advance exactly as its steps would). The cycle after the jump is an ordinary
one: the window's end, the event, the wake, each meets the run at the cycle and in the state it
would have met it in without the jump, so the I/O, the automatic cell's answers, the steps and
the end are those of the unjumped run (RunSpec ``clock_jumps`` False; tests/interp/test_jump.py).

A jump is refused (when in doubt, no jump) when anything in those cycles could do more than
count: a debugger's cycle hook, a trace or a controller observer that takes the poses, a cyclic
hook but a cyclic flag whose expression settles (none beside a pass with transients), a workspace
monitor, a network partner, the main run not at rest or the robot
moving, a recording, a catch-up, a shadowed or periodic spin, an automatic cell recording, a
pending TRIGGER, error or interrupt, an armed interrupt whose condition may change without a
change of the I/O image (one that reads a variable, when a parked pass has transients: its
value could change with them), an input or state variable a parked pass reads that changed
(its wake is due), a parked pass that reads a running timer (interp/runtime/passes.py
``timer_compares``: the idle watch sees its clock reads at every cycle), a waiting task that reads a running timer or whose wait ends with the main
run, or beside a parked pass with transients.
"""

from __future__ import annotations

import math

from .idle import WINDOW_CYCLES
from .period import Period
from .watch import CONSTANT, IO, SETTLES, split_watch

#: the fewest cycles worth a jump (one cycle runs as before)
MIN_SPAN = 2
#: "no bound" of a span
_FAR = 1 << 62


def span(sched, steady: int) -> int:
    """The number of IPO cycles, from the current one, whose counting is all that happens in
    them (module docstring); 0 when fewer than :data:`MIN_SPAN`. `steady`: what
    ``Scheduler._steady`` returned for this cycle (2: a still steady cycle; 0: an ordinary one,
    tested here in full; 1, the robot moves: never)."""
    spin = sched.spin
    if steady == 1 or spin.rec is not None or spin.shadowed or spin.replaying:
        return 0
    for task in sched.tasks:        # (the quick tests first: this runs before every cycle)
        if not task.done and (task.parked.spin.__class__ is Period if task.parked is not None else steady != 2):
            return 0
    ctl = sched.controller
    c = ctl.cycle
    trans = any(t.parked is not None and t.parked.spin.trans is not None for t in sched.tasks if not t.done)
    if not _controller_plain(sched, ctl, trans):
        return 0
    n = _idle_span(sched.idle, c)
    nxt = ctl.signals.next_event_cycle(c)
    if nxt is not None:
        n = min(n, nxt - c - 1)                 # the step of cycle nxt processes the event
    if sched.max_sim_time is not None:
        n = min(n, int(math.ceil(sched.max_sim_time / ctl.dt - 1e-9)) - c)
    if n < MIN_SPAN or (sched.tasks[0].waiting and sched.deadlocked()):
        return 0
    if sched.idle.auto is not None and sched.idle.auto.recording is not None and \
            any(t.parked is None for t in sched.tasks if not t.done):
        return 0            # (the automatic cell's recording takes every statement a task runs)
    for task in sched.tasks:
        if task.done:
            continue
        n = min(n, _task_span(sched, task, c, steady, trans))
        if n < MIN_SPAN:
            return 0
    return n


def _controller_plain(sched, ctl, trans: bool) -> bool:
    """The controller's steps of a robot at rest do nothing but advance time (Controller.skip),
    and nothing watches the cycles one by one. A cyclic flag whose expression settles
    (interp/runtime/cyclic.py: evaluated again only when a statement ran or the I/O image or a
    flag changed) is evaluated at none of them, unless a parked pass's transients (`trans`)
    change a variable it may read."""
    if sched.stepping.cycle_hook is not None or sched.stepping.watching or sched.tracing.writer is not None:
        return False
    q, q0 = ctl._q, ctl._q_prev
    if not (q is q0 or q.tolist() == q0.tolist()) or not ctl.at_rest():
        return False
    tr = ctl.trace
    if (tr is not None and tr.takes_poses) or ctl.monitor.workspaces is not None:
        return False
    cyc = sched.cyclic
    if (ctl._cyclic or cyc.handles) and (trans or cyc.restless or len(ctl._cyclic) != len(cyc.handles)
                                         or any(k[0] != "cyclic flag" for k in cyc.handles)):
        return False
    net = getattr(ctl, "network", None)
    return net is None or not net.polling


def _idle_span(idle, c: int) -> int:
    """Cycles from `c` in which the idle watch only counts (IdleWatch.cycle): its quiet window is
    open and younger than its length, its marks unchanged, and, while the run is not idle yet,
    the robot program's window (``robot_starves``) open and younger than :data:`WINDOW_CYCLES` or
    not kept. (While the automatic cell watches a window before it answers, its recording must
    have every step of each parked pass already: :func:`_parked_span`; no other task runs.)"""
    if idle.start is None or not idle._quiet() or idle._marks() != idle.marks:
        return 0
    auto = idle.auto
    n = idle.start + idle.window - c
    if idle.since is not None:
        return n
    if auto is not None:
        marks = idle.robot_marks()
        if marks is not None:
            if idle._robot is None or idle._robot[1] != marks:
                return 0
            n = min(n, idle._robot[0] + WINDOW_CYCLES - c)
    return n


def _task_span(sched, task, c: int, steady: int, trans: bool) -> int:
    """Cycles from `c` that `task`'s turn only counts."""
    if task.pending_triggers or task.pending_error is not None or task.replay is not None:
        return 0
    if any(i.pending for i in task.irqs.irqs.values()):
        return 0
    p = task.parked
    if p is not None:
        return _parked_span(sched, task, p, trans)
    # a task that waits: in a steady cycle, on a test that stands while nothing changes
    if steady != 2 or trans or task.until is None or task.clock_reads:
        return 0
    if task.wake_cycle is not None:
        return task.wake_cycle - c              # its test holds from that cycle on
    return _FAR if sched.controller.is_idle() else 0


def _parked_span(sched, task, p, trans: bool) -> int:
    """Cycles for which parked `task` stays parked and only counts (SpinWatch._hold): nothing it
    reads changed, no interrupt to run, the step limit not near."""
    spin = sched.spin
    s = p.spin
    if s.__class__ is Period or s.motion or s.reads is not None or spin.reads_restless_flag(s) or \
            not spin.parked_ok(task):
        return 0        # (a pass that reads a running timer: its cycles are counted one by one)
    ctl = sched.controller
    if (s.io and ctl.io.version != p.io_version) or (s.probes and spin._probed(s) != p.probed):
        return 0
    auto = sched.idle.auto
    if auto is not None and auto.recording is not None and (p.fed[0] is not auto.recording or p.fed[1] < s.steps):
        return 0        # the automatic cell's recording has not every step of the pass yet (SpinWatch._feed)
    if task.irqs.armed:
        for i in task.irqs.irqs.values():
            if i.on and not _irq_stands(i, ctl, trans):
                return 0
        if spin._interrupt_due(task):
            return 0
    b = task.budget
    left = sched.step_limit_left(task) - 2 * (b + s.steps)
    return 1 + left // b if left >= 0 else 0


def _irq_stands(irq, ctl, trans: bool) -> bool:
    """The condition of armed interrupt `irq` keeps its value while nothing runs and the robot
    stands (interp/runtime/watch.py): class CONSTANT or IO (or SETTLES, a variable's value, when
    no parked pass has transients); a probe of a motion's state (``STEP_PROBED``: ``$PRO_MOVE``,
    ``$VEL_ACT``) only while the main run has no motion at all (``Controller.is_idle``)."""
    cls, _names = split_watch(irq.watch)
    if cls not in ((CONSTANT, IO) if trans else (CONSTANT, IO, SETTLES)):
        return False
    return irq.steady or ctl.is_idle()


def count(sched, n: int) -> None:
    """Count `n` cycles at once (module docstring), as ``SpinWatch._hold`` (or
    ``Scheduler._steady_cycle``), ``IdleWatch.cycle`` and the controller's steps would count them
    one by one."""
    spin = sched.spin
    ctl = sched.controller
    clock = sched.clock
    for task in sched.tasks:
        if task.done:
            continue
        clock.epochs(n)
        p = task.parked
        if p is not None:
            k = n * task.budget
            clock.count(k)
            task.steps += k
            p.done += k
            spin.skipped += k
            if p.spin.trans is not None:
                p.spin.trans.put_at(p.step(), sched.cyclic_watch)   # (moves the cyclic watch's version if it changes)
            spin._place(task)
    idle = sched.idle
    idle._last = (ctl.cycle + n - 1, idle.clock)
    if idle.auto is not None and idle.robot_marks() is None:
        idle._robot = None                      # as robot_starves would forget it at each cycle
    sched.jumped += n
    ctl.skip(n)
