"""Motion statements of the robot program (reference §6.1-§6.3, §6.10, TRIGGER §6.11, STOP
WHEN PATH): :class:`MotionStatements` (``Runtime.motions``), for both interpreters.

It holds nothing of its own now: a statement's evaluated target, approximation and WITH clause
become a robot.motion.MotionRequest (interp/runtime/motion.py, with the motion system
variables at planning time: the advance run) queued on the run's controller, which waits
while the queue holds $ADVANCE motions; a TRIGGER or a conditional stop goes with the next
motion (``Task.next_triggers``); an executed motion is recorded for backward motion
(``Stepping.history``); a synchronised spline motion of a cell's robot waits for its partners
first (its part ``team``: interp/runtime/teamsync.py); a motion planned at ``$OV_PRO = 0`` holds
until the override rises (:meth:`MotionStatements.hold_at_zero_override`, issue 85 item 9c). Errors raised: KrlRuntimeError (a motion statement in the submit
interpreter or a TRIGGER action; a target the controller refuses, with its reason).
"""

from __future__ import annotations

from robot.errors import RobotError, SoftLimitError, WorkspaceError
from robot.motion import CondStop, MotionRequest, Trigger

from .convert import assign_into, num
from .errors import KrlRuntimeError
from .memory import Slot
from .motion import ParamsMemo, params_from, request, segment, target_of
from .runmode import STEP_MODES
from .scheduler import Task, break_quiet
from .teamsync import SPLINE_MOTIONS, TeamSync, sync_point
from .values import Arr, Struct, copy_value


#: appended to a workspace or software-limit error whose motion target itself is out of the
#: simulated robot's limits in every configuration (robot/controller.py target_outside_limits)
TARGET_OUTSIDE_NOTE = "the target itself: no axis configuration of this robot reaches it within its software limits"


def reach_message(ctl, req, err) -> str:
    """The message of a motion `req` the controller `ctl` refused with `err`: a workspace or
    software-limit error says so when the target itself is out of the robot's limits in
    every configuration (not only on the way there, or with the program's S/T)."""
    if isinstance(err, (SoftLimitError, WorkspaceError)) and ctl.queue.target_outside_limits(req):
        return f"{err.message} ({TARGET_OUTSIDE_NOTE})"
    return err.message


class MotionStatements:
    """The motion statements of one run's robot program (module docstring)."""

    __slots__ = ("controller", "sysvars", "clock", "stepping", "wait", "proceed", "wait_main_run", "memo", "team",
                 "sync", "held")

    def __init__(self, controller, sysvars, clock, stepping, wait, proceed, wait_main_run, wait_for=None) -> None:
        """For the run of `controller` (robot/controller.py: its motion queue), `sysvars`
        (sysvars.SysVars: the motion system variables, $ADVANCE), `clock` (scheduler.py
        RunClock: the running task) and `stepping` (stepping.py: the run mode, the executed
        motions); `wait(task, until)` (the IPO cycles given back until ``until()`` holds),
        `proceed()` and `wait_main_run(task)` (the advance-run stop) are the runtime's (core.py
        Runtime._wait, _proceed, wait_main_run); with `wait_for(cond, text)` (core.py
        Runtime.wait_for, a wait like WAIT FOR) :attr:`team` (teamsync.py TeamSync) holds a
        synchronised motion of a cell's robot until its partners reach theirs (None: no
        synchronised motions)."""
        self.controller = controller
        self.sysvars = sysvars
        self.clock = clock
        self.stepping = stepping
        self.wait = wait
        self.proceed = proceed
        self.wait_main_run = wait_main_run
        self.memo = ParamsMemo()        # the last motion's snapshot (motion.py params_from)
        self.team = TeamSync(clock, wait_main_run, wait_for, sysvars.declared) if wait_for is not None else None
        self.sync = None                # the last snapshot's $SYNC_ID/$SYNC_LIST (teamsync.py)
        self.held: tuple | None = None  # (file, line, since s): the motion $OV_PRO = 0 holds now

    def _params(self, with_: list):
        store = self.sysvars.store
        saved = []
        for ref, value in with_:
            old = copy_value(ref.peek())
            saved.append((ref, old))
            ref.set(value)
        try:
            self.sync = sync_point(store) if self.team is not None and self.team.number is not None else None
            return params_from(store, self.sysvars.base_link(), self.memo)
        finally:
            for ref, old in reversed(saved):
                if isinstance(ref, Slot):
                    cur = ref.c[ref.k]
                    if isinstance(cur, (Struct, Arr)):
                        assign_into(cur, old)
                    else:
                        ref.c[ref.k] = old

    def motion(self, kind: str, target, approx: list, aux=None, ca=None, frame: str | None = None,
               with_: list = (), file: str | None = None, line: int | None = None, synced: bool = True) -> int:
        """Plan a motion statement and queue it (waits while the queue holds $ADVANCE
        motions). ``target``/``aux`` are evaluated values; ``with_`` (ref, value) pairs of a
        WITH clause, valid for this motion only; `synced` False: not a synchronised motion
        whatever $SYNC_ID says (a PTP_SPLINE block's later segments). Returns the motion id."""
        task = self._robot_only(kind)
        tgt = target_of(target)
        aux_d = target_of(aux, "auxiliary point") if aux is not None else None
        params = self._params(list(with_))
        if params.ov_pro <= 0:
            self.hold_at_zero_override(task, file, line)
            params = self._params(list(with_))
        trig, task.next_triggers = task.next_triggers, []
        if self.stepping.run_mode in STEP_MODES:
            approx = []     # no advance run: exact positioning (docs/robot.md, run modes)
        req = request(kind, tgt, params, list(approx), aux_d,
                      float(num(ca)) if ca is not None else None, frame, trig, file, line)
        return self._enqueue(task, req, self.sync if synced and kind.upper() in SPLINE_MOTIONS else None)

    def spline(self, kind: str, segments: list, approx: str | None, with_: list = (),
               file: str | None = None, line: int | None = None) -> int:
        """A SPLINE / PTP_SPLINE block. ``segments``: list of dicts with kind, target, aux,
        ca, with_ (ref, value pairs), triggers (robot.motion.Trigger list), line."""
        task = self._robot_only(kind)
        if self.stepping.run_mode in STEP_MODES:
            approx = None   # no advance run: the block ends exactly (docs/robot.md, run modes)
        if kind.upper() == "PTP_SPLINE":
            last = None
            for i, s in enumerate(segments):
                task.next_triggers = list(s.get("triggers", ()))
                ap = ["C_SPL"] if i < len(segments) - 1 else ([approx] if approx else [])
                last = self.motion("SPTP", s["target"], ap, with_=list(with_) + list(s.get("with_", ())),
                                   file=file, line=s.get("line"), synced=i == 0)   # the block starts together
            return last or 0
        block_params = self._params(list(with_))
        if block_params.ov_pro <= 0:
            self.hold_at_zero_override(task, file, line)
            block_params = self._params(list(with_))
        sync = self.sync
        segs = []
        for s in segments:
            p = self._params(list(with_) + list(s["with_"])) if s.get("with_") else None
            segs.append(segment(s["kind"], target_of(s["target"]),
                                target_of(s["aux"], "auxiliary point") if s.get("aux") is not None else None,
                                s.get("ca"), p, s.get("triggers", ()), s.get("line")))
        req = MotionRequest("SPLINE", segs[-1].target if segs else {}, block_params,
                            approx=approx, segments=tuple(segs), file=file, line=line)
        return self._enqueue(task, req, sync)

    def hold_at_zero_override(self, task: Task, file: str | None, line: int | None) -> None:
        """The motion statement at `file`:`line` meets ``$OV_PRO = 0``: the robot task waits,
        IPO cycle after IPO cycle, until the override is positive (the submit interpreter, the
        interrupts and the cell run on; the queued motions end and the robot stands), then plans
        the motion with the override it finds. KSS's program override is 0..100 % and at 0 %
        the robot stands while its program runs (KUKA's mxAutomation KRC_SetOverride, "Override
        0 ... 100 %", the robot takes a change as it comes:
        https://infosys.beckhoff.com/content/1033/tf5120/13081546379.html; a controller whose
        override a PLC holds at 0 % does not move: https://industrialmonitordirect.com/blogs/
        knowledgebase/resolving-kuka-krc4-program-override-stuck-at-0-in-external-mode). Here
        the override is read when the advance run plans a motion (docs/robot.md), so the advance
        run holds at the motion (on KSS it plans it and goes on to its next advance-run stop).
        :attr:`held` names the motion while it holds, and still when the run ends so
        (interp/summary.py); ``task.waiting`` says it (a hold nothing can end is a deadlock)."""
        store = self.sysvars.store
        self.held = (file, line, self.controller.time)
        task.waiting = f"$OV_PRO = 0 at {file}:{line} (the motion holds until the override rises)"
        try:
            self.wait(task, lambda: num(store["$OV_PRO"]) > 0)
        finally:
            task.waiting = None
        self.held = None
        self.proceed()

    def _robot_only(self, what: str) -> Task:
        task = self.clock.current_task
        if task.kind != "robot":
            raise KrlRuntimeError(f"{what}: motion statements are not allowed in the submit interpreter")
        if task.context.kind == "trigger":
            raise KrlRuntimeError(f"{what}: no motion statements in a TRIGGER action")
        return task

    def _enqueue(self, task: Task, req, sync=None) -> int:
        if sync is not None:
            self.team.reach(sync, req.file, req.line)   # a synchronised motion in a cell: its partners first
        ctl = self.controller
        adv = self.sysvars.store.get("$ADVANCE")
        ctl.queue.set_advance(int(adv) if isinstance(adv, int) else 3)
        if not ctl.can_enqueue():
            self.wait(task, ctl.can_enqueue)
            self.proceed()
        try:
            mid = ctl.queue.enqueue(req)
        except RobotError as e:
            raise KrlRuntimeError(reach_message(ctl, req, e), e.number) from None
        break_quiet(task)              # the main run is not idle now: advance-run stops wait
        stepping = self.stepping
        stepping.history.record(req, ctl.queue.last_planned())
        if stepping.run_mode in STEP_MODES:
            # the advance run does not pass the motion: the next statement is read when it ends
            self.wait_main_run(task)
            if stepping.run_mode != "ISTEP":
                stepping.step_stop(task, "MSTEP", motion=mid)
        return mid

    def trigger(self, action, *, distance: int | None = None, path: float | None = None,
                onstart: bool = False, delay_ms: float = 0.0, prio: int | None = None,
                line: int | None = None) -> None:
        """TRIGGER: ``action`` (a zero-argument callable; call arguments already
        evaluated) runs when the next motion's switching point is reached."""
        task = self._robot_only("TRIGGER")
        task.next_triggers.append(Trigger(distance=distance, path_mm=path, onstart=onstart,
                                          delay_ms=float(delay_ms), action=action, prio=prio, line=line))

    def conditional_stop(self, path, onstart: bool, condition, line: int | None = None) -> None:
        """STOP WHEN PATH = path [ONSTART] IF condition (KSS 8.3 and later): the next motion
        (spline segment) stops `path` mm from its end point (its start point) while
        ``condition()`` (a zero-argument callable, True: stop) holds there; the main run
        evaluates it (robot/controller.py ``Controller._conditional_stops``)."""
        task = self._robot_only("STOP WHEN PATH")
        task.next_triggers.append(CondStop(float(num(path)), bool(onstart), condition, line))
