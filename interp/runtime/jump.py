"""The clock jump: a run of IPO cycles in which no task runs is counted in one step, not cycle by
cycle (issue 76, item 4; docs/architecture.md "Clock jumps": what it takes, what it refuses, how
it is checked). :func:`span` finds how many cycles from the current one follow each other
unchanged (0: fewer than :data:`MIN_SPAN`, or in doubt), :func:`count` counts them at once; the
cycle after is an ordinary one. The fast-forward is asked through its entries (fastforward.py).
"""

from __future__ import annotations

import math

from .watch import CONSTANT, IO, SETTLES, split_watch

#: the fewest cycles worth a jump (one cycle runs as before)
MIN_SPAN = 2
#: "no bound" of a span
_FAR = 1 << 62


def span(sched, steady: int) -> int:
    """The number of IPO cycles, from the current one, whose counting is all that happens in
    them; 0 when fewer than :data:`MIN_SPAN`. `steady`: ``Scheduler._steady``'s answer for this
    cycle (2: a still steady cycle; 0: an ordinary one, tested here in full; 1: never)."""
    ff = sched.ff
    trans = None if steady == 1 else ff.may_jump(steady)     # (whether a parked pass has transients)
    if trans is None:
        return 0
    ctl = sched.controller
    c = ctl.cycle
    if not _controller_plain(sched, ctl, trans):
        return 0
    # the clock reads of the tasks that wait on a test comparing running timers (Scheduler._waits)
    reads = sum(t.clock_reads for t in sched.tasks if not t.done and t.parked is None and t.until is not None)
    n = ff.idle_span(c, reads)
    nxt = ctl.signals.next_event_cycle(c)
    if nxt is not None:
        n = min(n, nxt - c - 1)                 # the step of cycle nxt processes the event
    if sched.max_sim_time is not None:
        n = min(n, int(math.ceil(sched.max_sim_time / ctl.dt - 1e-9)) - c)
    if n < MIN_SPAN or (sched.tasks[0].waiting and sched.deadlocked()):
        return 0
    for task in sched.tasks:
        if task.done:
            continue
        n = min(n, _task_span(sched, task, c, steady, trans))
        if n < MIN_SPAN:
            return 0
    return n


def _controller_plain(sched, ctl, trans: bool) -> bool:
    """The controller's steps of a robot at rest do nothing but advance time (Controller.skip),
    and nothing watches the cycles one by one. A cyclic flag whose expression settles is evaluated
    at none of them, unless a parked pass's transients (`trans`) change a variable it may read."""
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


def _task_span(sched, task, c: int, steady: int, trans: bool) -> int:
    """Cycles from `c` that `task`'s turn only counts."""
    if task.pending_triggers or task.pending_error is not None or task.replay is not None or \
            any(i.pending for i in task.irqs.irqs.values()):
        return 0
    if task.parked is not None:
        return sched.ff.parked_span(task, lambda i: _irq_stands(i, sched.controller, trans))
    # a task that waits, in a still steady cycle, on a test that stands while nothing changes (a
    # WAIT FOR comparing running timers with numbers: until a timer reaches its bound, watch.py)
    if steady != 2 or trans or task.until is None:
        return 0
    n = _FAR
    if task.clock_reads and task.timer_due is not None:
        n = task.timer_due - c                  # its test may hold from that cycle on
    if task.wake_cycle is not None:
        return min(n, task.wake_cycle - c)      # its test holds from that cycle on
    return n if sched.controller.is_idle() else 0


def _irq_stands(irq, ctl, trans: bool) -> bool:
    """The condition of armed interrupt `irq` keeps its value while nothing runs and the robot
    stands: class CONSTANT or IO (or SETTLES when no parked pass has transients); a probe of a
    motion's state (watch.py ``STEP_PROBED``) only while the main run has no motion at all."""
    return split_watch(irq.watch)[0] in ((CONSTANT, IO) if trans else (CONSTANT, IO, SETTLES)) and \
        (irq.steady or ctl.is_idle())


def count(sched, n: int) -> None:
    """Count `n` cycles at once, as the parked tasks' turns, the idle watch's cycles and the
    controller's steps would count them one by one."""
    ff = sched.ff
    clock = sched.clock
    for task in sched.tasks:
        if task.done:
            continue
        clock.epochs(n)
        if task.parked is not None:
            ff.count(task, n * task.budget, False)
        elif task.clock_reads:
            ff.clock_read(task, n * task.clock_reads)       # as Scheduler._waits at each cycle
    ff.jumped(n)
    sched.jumped += n
    sched.controller.skip(n)
