"""KUKA's command channel ``$CMD`` and the program states it changes (issue 72): what
``CWRITE($CMD, STAT, MODE, "RUN /R1/CELL()")``, ``"STOP 1"``, ``"RESET 1"``, ``"CANCEL 1"`` do
to the robot interpreter (1) and the submit interpreter (0), and the states ``$PRO_STATE1``,
``$PRO_STATE0`` and ``$PRO_ACT`` read (interp/runtime/sysvars.py), on both interpreters.

The states (KUKA System Variables, ``$PRO_STATE``; the reference's ``PRO_STATE`` enum):
``#P_FREE`` no program selected, ``#P_RESET`` selected and reset (at its start),
``#P_ACTIVE`` running, ``#P_STOP`` stopped, ``#P_END`` at its END. The commands and the states
each is valid in follow KUKA's own SPS logic for the command channel
(https://industrialmonitordirect.com/blogs/knowledgebase/kuka-robot-program-abort-stopping-execution-like-fanuc-abort:
``CANCEL 1`` in #P_STOP, #P_END or #P_RESET, else ``STOP 1`` first; ``RESET 1`` in #P_STOP or
#P_END; ``RUN /R1/MAIN()`` when #P_FREE; "CWRITE commands for Cancel/Select only work between
interpreters ... An interpreter cannot cancel itself") and kroshu's external-control SDK for
KSS (program_handler.src: RUN, then the state leaves #P_FREE; STOP leaves #P_ACTIVE; CANCEL gives
#P_FREE; RESET gives #P_RESET):

* ``RUN path()``: selects the program in a free interpreter (#P_RESET); refused (``CMD_ABORT``)
  while one is selected. The robot interpreter's program then waits for its start (the start
  key, ``$EXT_START`` in EXT: "the CWRITE command with RUN only loads the program into the
  selected state", https://industrialmonitordirect.com/blogs/knowledgebase/kuka-cwrite-run-command-not-auto-starting-program-fix);
  the simulated cell gives no start, and the run executes only the program it was given: a
  program RUN selects is not executed (a note says so once) -- except after STOP 1 of the
  run's robot program in the same IPO cycle in Automatic External, where the PLC starts it
  (``$EXT_START``): the robot task runs it from its start (issue 85, :meth:`ProgramControl._reselect`).
* ``STOP n``: an active program stops (#P_STOP); a program that is not running stays as it is.
  The robot program the run executes then stays stopped, as no operator starts it again: the
  run ends (``halt``, the text naming the command, where it was written and the commands for
  the robot interpreter that followed it in that cycle), unless a RUN then selects a program
  that Automatic External's PLC starts (above).
* ``RESET n``: a stopped or ended program is reset (#P_RESET); refused while it runs or when
  none is selected.
* ``CANCEL n``: a program that does not run is deselected (#P_FREE); refused while it runs.
* a command on the interpreter that writes it is refused ("an interpreter cannot cancel
  itself"); one for the submit interpreter from the robot program changes its state only
  (the submit programs go on: not simulated, noted once).

A command the channel does not know, or one without its interpreter's number, is a syntax
error (``CMD_SYN``). Until a command changes it, an interpreter's state is that of the run's own
task: the robot program's #P_ACTIVE while it runs, then #P_END at its END or #P_STOP when an
error or a HALT stopped it (it stays selected; the run ends with it, so the submit programs see
it in the last IPO cycle), and #P_FREE for the robot interpreter of a run whose program is a
``.sub`` (it runs in the submit interpreter: ``krl run SPS.SUB``); the submit interpreter's is
#P_ACTIVE while a submit program runs, else #P_FREE."""

from __future__ import annotations

import re
from pathlib import Path

from .errors import ProgramSelected
from .values import EnumValue

FREE, RESET, ACTIVE, STOP, END = "P_FREE", "P_RESET", "P_ACTIVE", "P_STOP", "P_END"
#: the values $PRO_STATE* read, made once: an enum value is an immutable leaf, and an
#: interrupt's watch key compares the same object at each poll by identity (interp/runtime/watch.py)
STATE_VALUES = {s: EnumValue(s) for s in (FREE, RESET, ACTIVE, STOP, END)}

#: ``RUN /R1/NAME(...)`` (the path's /R1/ and the folders before the name optional, as the
#: KSS SDK's ``"RUN/" + name``), ``STOP n``, ``RESET n``, ``CANCEL n``
_RUN = re.compile(r"^\s*RUN(?:\s+|(?=/))(\S+?)\s*(\(.*\))?\s*$", re.I)
_OTHER = re.compile(r"^\s*(STOP|RESET|CANCEL)\s+([01])\s*$", re.I)

#: the states each command may leave (the others refuse it); None: every state, no change
#: for those not listed in _TO
_FROM = {"STOP": None, "RESET": {STOP, END, RESET}, "CANCEL": {STOP, END, RESET, FREE}}
_TO = {"STOP": {ACTIVE: STOP}, "RESET": RESET, "CANCEL": FREE}


class ProgramControl:
    """The program states of the run's interpreters as the ``$CMD`` commands set them
    (module docstring). ``state(robot)`` is the state's name; ``command(text, writer)``
    carries out one command and returns the ``CMD_STAT`` name CWRITE writes to RET1."""

    __slots__ = ("scheduler", "clock", "sub_main", "robot", "tasks_state_changed", "noted", "message",
                 "states", "selected", "stopped")

    def __init__(self, scheduler, main_path, robot, tasks_state_changed, noted: set, message) -> None:
        """For the run of `scheduler` (scheduler.py Scheduler: its tasks, its clock's running
        task, the stop a ``STOP 1`` sets), whose program is `main_path` (a ``.sub`` runs in the
        submit interpreter) and whose robot task `robot()` gives; `tasks_state_changed()`
        (core.py Runtime.tasks_state_changed) follows each change of a state, and a note is
        given once: kept in the run's `noted` set, then `message(text)`."""
        self.scheduler = scheduler
        self.clock = scheduler.clock
        #: the run's program is a .sub: its task is the submit interpreter's
        self.sub_main = str(main_path).lower().endswith(".sub")
        self.robot = robot
        self.tasks_state_changed = tasks_state_changed
        self.noted = noted
        self.message = message
        #: interpreter number (1 robot, 0 submit) -> the state a command set (absent: the
        #: run's own task's)
        self.states: dict[int, str] = {}
        #: interpreter number -> the program a RUN selected
        self.selected: dict[int, str] = {}
        #: the commands since STOP 1 stopped the robot program the run executes (the run's end
        #: says them), or None while no STOP did
        self.stopped: list[str] | None = None

    # ------------------------------------------------------------------ states
    def own_active(self, n: int) -> bool:
        """The run's own task of interpreter `n` runs (the robot program; the submit programs)."""
        robot = self.robot()
        if n == 1:
            return robot is not None and not robot.done and not self.sub_main
        if robot is not None and not robot.done and self.sub_main:
            return True
        return any(not t.done for t in self.scheduler.tasks[1:])

    def state(self, robot: bool) -> str:
        n = 1 if robot else 0
        s = self.states.get(n)
        if s is not None:
            return s
        if self.own_active(n):
            return ACTIVE
        robot_task = self.robot()
        if n == 1 and robot_task is not None and robot_task.done and not self.sub_main:
            # the robot program stays selected once it ended: at its END #P_END, stopped by an
            # error or a HALT #P_STOP (the submit programs see it in the run's last IPO cycle)
            return END if robot_task.outcome is not None and robot_task.outcome[0] == "completed" else STOP
        return FREE

    def value(self, robot: bool) -> EnumValue:
        """``$PRO_STATE1`` (`robot`) or ``$PRO_STATE0``: the enum value of :meth:`state`."""
        return STATE_VALUES[self.state(robot)]

    # ------------------------------------------------------------------ commands
    def writer(self) -> int:
        """The interpreter of the task that writes the command (1 robot, 0 submit)."""
        task = self.clock.current_task
        if task is None:
            return 1
        return 0 if task.kind != "robot" or self.sub_main else 1

    def command(self, text: str) -> str:
        """Carry out the $CMD command `text` (module docstring); returns the CMD_STAT name:
        ``CMD_OK``, ``CMD_ABORT`` (refused in this state) or ``CMD_SYN`` (not a command)."""
        m = _RUN.match(text)
        if m is not None:
            return self._run(m.group(1))
        m = _OTHER.match(text)
        if m is None:
            self._note(f"CWRITE $CMD: {text[:60]!r} is not a command of the channel (RUN, STOP n, RESET n, "
                       "CANCEL n): CMD_SYN")
            return "CMD_SYN"
        return self._change(m.group(1).upper(), int(m.group(2)), text.strip())

    def _run(self, path: str) -> str:
        path = path[:80]                # the program's text, shown in messages: clipped
        name = Path(path.replace("\\", "/")).name
        n = 0 if name.lower().endswith(".sub") else 1
        if self.writer() == n:
            return self._refuse(f"RUN {path}", n, "an interpreter cannot select a program for itself")
        if self.state(n == 1) != FREE:
            return self._refuse(f"RUN {path}", n, f"a program is selected ({self.state(n == 1)}); CANCEL it first")
        self._set(n, RESET)
        self.selected[n] = name
        if n == 1 and self.stopped is not None:
            self._after_stop(f"RUN {path}()" if "(" not in path else f"RUN {path}")
            if self._reselect(name.split("(", 1)[0]):
                return "CMD_OK"
        self._note(f"not simulated: RUN {path} selects {name} in the {_WHO[n]} (P_RESET); the run does not "
                   "start it: it executes only the program it was given")
        return "CMD_OK"

    def _after_stop(self, text: str) -> None:
        """A command for the robot interpreter after STOP 1 stopped the run's robot program:
        the run's end (the scheduler's stop, while it is STOP's) says it too."""
        self.stopped.append(text)
        stop = self.scheduler.stop
        if stop is not None and stop[0] == "halt" and stop[1].startswith(STOPPED):
            first = stop[1].split("; then ", 1)[0]
            self.scheduler.stop = ("halt", f"{first}; then {', '.join(self.stopped[1:])}", stop[2])

    def _reselect(self, module: str) -> bool:
        """RUN selected `module` in the robot interpreter after STOP 1 stopped the run's robot
        program in this IPO cycle: in Automatic External the PLC starts a selected program
        (``$EXT_START``: KUKA's Automatic External interface, the start of a program in
        #P_RESET), so the robot task runs it from its start at its next resume (errors.py
        ProgramSelected) and the run goes on; True then. In another mode the operator's start key
        would start it, which the run does not press: False, the run ends where STOP stopped it,
        its end saying the commands that followed."""
        sched = self.scheduler
        robot = self.robot()
        stop = sched.stop
        if sched.controller.mode_op != "EX" or robot is None or robot.done or stop is None or stop[2] is not robot:
            return False
        sched.stop = None
        robot.pending_error = ProgramSelected(
            module, f"{stop[1]}: the PLC of Automatic External starts {module} ($EXT_START)")
        self.stopped = None
        return True

    def started(self, n: int) -> None:
        """The program selected in interpreter `n` started (ProgramSelected): it is the run's
        own task's again (#P_ACTIVE while it runs)."""
        self.states.pop(n, None)
        self.selected.pop(n, None)
        self.tasks_state_changed()

    def _change(self, cmd: str, n: int, text: str) -> str:
        if self.writer() == n:
            return self._refuse(text, n, "an interpreter cannot stop, reset or cancel itself")
        now = self.state(n == 1)
        allowed = _FROM[cmd]
        if allowed is not None and now not in allowed:
            return self._refuse(text, n, f"its program is {now}" + ("; STOP it first" if now == ACTIVE else ""))
        to = _TO[cmd]
        new = to.get(now, now) if isinstance(to, dict) else to
        if new == now:
            return "CMD_OK"
        self._set(n, new)
        if new == FREE:
            self.selected.pop(n, None)
        if n == 1 and self.stopped is not None:
            self._after_stop(text)
        if cmd == "STOP" and n == 1 and self.own_active(1):
            self._stop_robot(text)
        elif n == 0 and self.own_active(0):
            self._note(f"not simulated: {text} changes $PRO_STATE0 only; the submit programs go on")
        return "CMD_OK"

    def _stop_robot(self, text: str) -> None:
        """STOP 1 stops the robot program the run executes: nothing starts it again, the run
        ends (the scheduler's stop: the end of this IPO cycle)."""
        task = self.clock.current_task
        where = f" at {Path(task.file).name}:{task.line}" if task is not None and task.file else ""
        sched = self.scheduler
        if sched.stop is None:
            sched.stop = ("halt", f"{STOPPED} {text!r} written to $CMD{where}", self.robot())
            self.stopped = [text]

    def _set(self, n: int, state: str) -> None:
        self.states[n] = state
        self.tasks_state_changed()

    def _refuse(self, text: str, n: int, why: str) -> str:
        self._note(f"CWRITE $CMD: {text[:60]!r} refused for the {_WHO[n]}: {why} (CMD_ABORT)")
        return "CMD_ABORT"

    def _note(self, text: str) -> None:
        if text not in self.noted:
            self.noted.add(text)
            self.message(text)


_WHO = {0: "submit interpreter", 1: "robot interpreter"}
#: the start of the run's end when STOP 1 stopped its robot program (interp/summary.py's
#: ending_of tells it from a HALT by it)
STOPPED = "the robot program was stopped by"
