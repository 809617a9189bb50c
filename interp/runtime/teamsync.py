"""KUKA.RoboTeam's synchronised motions, the robot's side (issue 89 item 4; docs/cells.md
"RoboTeam synchronisation"): :class:`TeamSync` (``Runtime.motions.team``, interp/runtime/motions.py),
for both interpreters.

A spline motion whose WITH clause (or the program before it) gives ``$SYNC_ID`` a text and
``$SYNC_LIST`` the robots of the team is *synchronised*: ``SLIN X1 WITH ..., $Sync_Id[] =
"AutoSync", $Sync_List = 'B0011' C_Spl``, the form SatelliteApplicationsCatapult/
Automate-Synch-KUKA-RoboTeam ``MotionSynchSRC.py`` writes for both robots of a team (its inline
form: ``SyncLabel=AutoSync; CoopRobots=R1_R2``). The types are the controller's own
(rawpython__kukaKRLmagic ``R1/operate_r1.dat``: ``DECL CHAR $SYNC_ID[64]``, ``DECL INT
$SYNC_LIST``); bit k-1 of the list is robot k of the team.

* **Alone** (a single run, :attr:`TeamSync.number` None) or with no partner left (the list's
  other robots absent from the cell or marked simulated in ``$SIMULATED_COOP_ROBOTS``:
  :meth:`TeamSync.partners`): a synchronised motion runs as an ordinary one: no advance-run
  stop, its approximation kept (docs/cells.md: the decision and why).
* **In a cell** (interp/robotcell.py, the robot being robot ``number`` of the team, its place in
  the cell file) with partners: the advance run stops before the motion (the robot at rest at its start),
  the robot waits there (:attr:`TeamSync.at`: the :class:`SyncPoint`) until the cell releases
  it (interp/cellsync.py: every other robot of its list has reached a motion with the same
  ``$SYNC_ID``), then the motion is queued; the released robots start in the same IPO cycle.
  While it waits the robot program is in a wait like WAIT FOR (``Task.waiting``: ``SYNC
  "AutoSync" at file:line``), so the cell's deadlock test names it.
"""

from __future__ import annotations

from dataclasses import dataclass

from krl.semantics.advance import StmtInfo

from .values import UNSET

#: robots a $SYNC_LIST can name: the bits of an INT
MAX_TEAM = 32

#: the motions $SYNC_ID synchronises: spline motions (and SPLINE blocks, whose WITH clause is the
#: block's); "The POINTS NEED TO BE DEFINED AS SLIN ... for Synch to work"
#: (Automate-Synch-KUKA-RoboTeam README): a PTP, LIN or CIRC after an assignment to $SYNC_ID
#: outside a WITH clause stays an ordinary motion
SPLINE_MOTIONS = frozenset({"SPTP", "SLIN", "SCIRC", "SPTP_REL", "SLIN_REL", "SCIRC_REL"})


@dataclass(frozen=True)
class SyncPoint:
    """A synchronised motion reached: its ``$SYNC_ID`` text (compared as written, as KRL compares
    strings) and the team numbers its ``$SYNC_LIST`` names (bit k-1 set: robot k, 1..32)."""
    id: str
    robots: frozenset

    def __str__(self) -> str:
        return f'SYNC "{self.id}"'


def team_of(mask) -> frozenset:
    """The team numbers (1..32) of the set bits of the INT `mask` (an UNSET or non-INT: none)."""
    if not isinstance(mask, int) or isinstance(mask, bool):
        return frozenset()
    mask &= (1 << MAX_TEAM) - 1
    return frozenset(k + 1 for k in range(MAX_TEAM) if mask >> k & 1)


def text_of(value) -> str:
    """A CHAR array's text up to its first NUL or unset element ("" for anything else)."""
    out = []
    for c in getattr(value, "data", ()):
        if not isinstance(c, str) or c == "\0":
            break
        out.append(c)
    return "".join(out)


def sync_point(store) -> SyncPoint | None:
    """The :class:`SyncPoint` the motion system variables of `store` (the system variables as
    a motion statement's WITH clause leaves them) make, None when ``$SYNC_ID`` is empty or unset:
    an ordinary motion."""
    text = text_of(store.get("$SYNC_ID"))
    if not text.strip():
        return None
    return SyncPoint(text, team_of(store.get("$SYNC_LIST")))


class TeamSync:
    """The synchronised motions of one run's robot program (module docstring)."""

    __slots__ = ("clock", "wait_main_run", "wait_for", "declared", "number", "size", "at", "released")

    def __init__(self, clock, wait_main_run, wait_for, declared) -> None:
        """For the run whose `clock` (scheduler.py RunClock) says the running task;
        `wait_main_run(task)` (the advance-run stop) and `wait_for(cond, text)` (a wait like WAIT
        FOR, naming its text and the task's file:line) are the runtime's (core.py); `declared`:
        the system variables the backup's own system data lists declare (sysvars.py
        ``SysVars.declared``: name -> (reference, span)), where ``$SIMULATED_COOP_ROBOTS`` is."""
        self.clock = clock
        self.wait_main_run = wait_main_run
        self.wait_for = wait_for
        self.declared = declared
        self.number: int | None = None      # robot `number` of a cell's team; None: alone
        self.size = 1                       # the robots of the cell: robots 1..size
        self.at: SyncPoint | None = None    # the synchronised motion the robot waits at
        self.released = False

    def join(self, number: int, size: int) -> None:
        """The run is robot `number` of a cell of `size` robots (interp/robotcell.py), its team.
        Raises ValueError past the bits of a $SYNC_LIST (1..:data:`MAX_TEAM`)."""
        if not 1 <= number <= size <= MAX_TEAM:
            raise ValueError(f"robot {number} of {size}: a $SYNC_LIST names robots 1..{MAX_TEAM}")
        self.number, self.size = number, size

    def partners(self, point: SyncPoint) -> frozenset:
        """The robots the motion at `point` waits for: those its ``$SYNC_LIST`` names, but this
        robot, a robot the cell does not have (alone: every one) and the ones
        ``$SIMULATED_COOP_ROBOTS`` marks simulated (:meth:`simulated`)."""
        if self.number is None:
            return frozenset()
        return frozenset(n for n in point.robots if n <= self.size) - {self.number} - self.simulated()

    def simulated(self) -> frozenset:
        """The team numbers the robot's machine data marks as simulated (``$SIMULATED_COOP_ROBOTS``,
        ``;Simulierte Roboter im Roboteam-Verbund`` in a backup's ``R1/Mada/$machine.dat``; none
        when the backup does not declare it)."""
        ref = self.declared.get("$SIMULATED_COOP_ROBOTS")
        value = ref[0].peek() if ref is not None and hasattr(ref[0], "peek") else UNSET
        return team_of(value)

    def reach(self, point: SyncPoint | None, file: str | None = None, line: int | None = None) -> None:
        """Before a motion is queued: a synchronised one (`point`) with :meth:`partners` waits at
        rest until the cell releases it (:meth:`release`); alone, without partners, or for an
        ordinary motion, nothing: it runs as an ordinary motion. `file`:`line`: the motion
        statement's, where the robot program waits (the WITH clause's function calls ran
        since the statement began: the task's last statement is one of theirs)."""
        if point is None or not self.partners(point):
            return
        task = self.clock.current_task
        if file is not None and line is not None:
            task.at = StmtInfo(file, line)
        self.wait_main_run(task)
        self.at, self.released = point, False
        try:
            self.wait_for(lambda: self.released, str(point))
        finally:
            self.at, self.released = None, False

    def release(self) -> None:
        """The cell: every robot the motion waits for has reached it; the robot's next cycle
        queues it."""
        if self.at is not None:
            self.released = True
