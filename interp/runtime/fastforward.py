"""The fast-forward of one run as one part (issue 87 item 3; docs/architecture.md "The
fast-forward"): what repeats unchanged is not executed again, the run exact.

Its mechanisms, each in its module:

* the **clock jump** (interp/runtime/jump.py, the scheduler's): cycles in which nothing a task
  reads can change are counted, not stepped, up to the controller's next event;
* the **idle watch** (idle.py ``IdleWatch``): a run whose state repeats with no clock read is
  jumped to its next event, a periodic state by whole periods;
* the **spin watch** (spin.py ``SpinWatch``, period.py, passes.py, transient.py): a task whose
  loop runs the same statements over the same state is parked until something it reads can
  change, then caught up.

:class:`FastForward` builds the two watches with the run's parts they read (no runtime whole:
tests/interp/test_part_collaborators.py) and is what the runtime (core.py) calls: the entries
below, nothing of the watches' insides. The scheduler (scheduler.py) still drives the watches
at each IPO cycle through :attr:`spin` and :attr:`idle` (its steady cycles and clock jumps read
both): that is not yet one entry.
"""

from __future__ import annotations

from .idle import IdleWatch
from .spin import SpinWatch


class FastForward:
    """The fast-forward of one run (module docstring). ``on``: a recording, a parked task, a
    catch-up or a shadow is under way (the spin watch keeps it): while False no statement is
    reported to :attr:`statement`. ``statement(task, info, tick)``: a statement (`tick`: a loop
    iteration) of `task` is about to run (StmtInfo `info`); ``park(task)``: `task` stands at a
    recorded spin, parked until something it reads can change."""

    __slots__ = ("spin", "idle", "on", "statement", "park")

    def __init__(self, spec, controller, clock, tracing, stepping, program, names, sysvars, kss, messages,
                 robot, yield_cycle, step_limit_left) -> None:
        """For the run `spec` (interp/spec.py RunSpec: ``fast_forward``, ``spins``) on
        `controller`, whose counters `clock` (scheduler.py RunClock) it reads; `tracing`
        (tracing.py) and `stepping` (stepping.py: a debugger watching) turn it off; it reads the
        run's `program`, `names`, `sysvars`, `kss` (the stand-ins' uses), `messages` (the
        message window) and the robot task `robot()`; `yield_cycle(task)` and
        `step_limit_left(task)` are the runtime's. The parts built after it are given by
        :meth:`attach`."""
        self.on = False
        self.spin = SpinWatch(spec, controller, clock, tracing, stepping, program, names, sysvars, kss, messages,
                              yield_cycle, step_limit_left, self)
        self.idle = IdleWatch(spec, controller, tracing, stepping, program, sysvars, messages, robot)
        self.statement = self.spin.event
        self.park = self.spin.park

    def attach(self, scheduler, cyclic, cyclic_watch, calls, auto) -> None:
        """The run's parts built after it: the `scheduler` (scheduler.py: its tasks; a catch-up
        returns to it), `cyclic` (cyclic.py), `cyclic_watch` (watch.py), `calls` (calls.py: the
        routines entered) and the automatic cell `auto` (autocell.py; None without
        ``--inputs auto``)."""
        self.idle.auto = auto
        self.spin.attach(self.idle, scheduler, cyclic, cyclic_watch)
        self.idle.attach(scheduler, self.spin, cyclic_watch, calls)

    # ------------------------------------------------------------------ the runtime's entries
    def waiting(self, task) -> None:
        """`task` gives the rest of its IPO cycle back (a wait, a blocking statement)."""
        self.spin.waiting(task)

    def proceeding(self) -> None:
        """A task goes on after a wait, or runs a TRIGGER action or an interrupt routine: a
        parked spin that may read what it changes catches up first."""
        self.spin.proceeding()

    def ending(self, task) -> None:
        """`task` ends, or the tasks' program states changed ($CMD): a parked task that reads
        them catches up."""
        self.spin.ending(task)

    def outside_change(self) -> None:
        """Something outside the tasks (a debugger, a network partner) changed the run's
        variables: every parked task catches up, the idle window starts again."""
        self.spin.outside_change()
        self.idle.outside_change()

    def clock_read(self, task) -> None:
        """`task` read the clock ($DATE, a running $TIMER) or drew a random number: the run is
        not idle, and a recording of `task` reads the clock."""
        self.idle.clock_read()
        if self.on:
            self.spin.clock_read(task)

    def quiet_steps(self, task, lim: int) -> "int | None":
        """The last step (``RunClock.steps``) up to `lim` that `task` may take without the full
        hook as far as the fast-forward is concerned; None: none (spin.py ``quiet_steps``)."""
        return self.spin.quiet_steps(task, lim)

    def statements(self, at):
        """The statements at `at` (a StmtInfo or ``(file, line)``), as the spin watch indexes
        them (passes.py ``StatementIndex``)."""
        return self.spin.statements(at)

    @property
    def shifted(self) -> int:
        """IPO cycles the idle watch's periodic jumps moved every task's WAIT SEC by so far."""
        return self.idle.shifted
