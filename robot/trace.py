"""The trace: JSON Lines, one event per line — the single source of truth for its schema.

Every event is a JSON object with ``t`` (simulated time in seconds, rounded to the µs) and
``kind``; the other fields depend on the kind and are listed in :data:`SCHEMA`. The
controller (``robot/controller.py``) writes ``motion``, ``io``, ``pose``, ``trigger``,
``message``, ``error`` and ``end``; the interpreters write ``stmt``, ``call``, ``return``
and ``interrupt`` through the same :class:`TraceWriter`.

Determinism: fields are written in the order of :data:`SCHEMA`, floats are rounded (time
to 1e-6 s, poses to 1e-6 mm/deg) and ``-0.0`` is written as ``0.0``, so the same program
gives the same bytes.
"""

from __future__ import annotations

import json
import sys
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import IO, Any

import numpy as np
import orjson
from .frames import matrix_to_frame

from . import poseline
from .kinematics.compiled import pure_module

#: robot/poseline.py, the pose lines' formatter: compiled where built and current, else as Python
_POSE = pure_module(poseline)

#: kind -> ordered list of (field, description). Fields marked "optional" may be absent.
SCHEMA: dict[str, list[tuple[str, str]]] = {
    "motion": [
        ("id", "int: motion id given by Controller.enqueue"),
        ("type", "str: PTP, LIN, CIRC, PTP_REL, LIN_REL, CIRC_REL, SPTP, SLIN, SCIRC, SPLINE"),
        ("target", "dict: programmed target components as given (name -> number)"),
        ("approximation", "str or null: C_PTP, C_DIS, C_VEL, C_ORI, C_SPL or null (exact stop)"),
        ("phase", "str: start | blend_start | blend_end | end"),
        ("point", "optional list[6] float: programmed end point, TCP X,Y,Z mm, A,B,C deg in $BASE"),
        ("line", "optional int: source line of the motion statement"),
        ("file", "optional str: source file of the motion statement"),
        ("reason", "optional str: on phase end: abort (the motion was abandoned: RESUME, "
                   "an error or a reset discarded it before its end point)"),
        ("limits", "optional dict on phase start: the limits the motion is planned within "
                   "(robot/limits.py): path (TCP mm/s or null), axes (6 deg/s), flange (mm/s "
                   "or null, T1), tool and base (X..C mm/deg); base_kin and base_root for a base "
                   "linked to a BASE kinematic (KSS EK)"),
        ("reached", "optional float on phase end of an exact stop: s, when the interpolation reached "
                    "the end point (KUKA Trace's ENDTIME under the program override); the end event, "
                    "the controller's END signal, follows 24-36 ms later (robot/exactstop.py)"),
    ],
    "io": [
        ("signal", "str: e.g. $OUT[3], $IN[5], $ANOUT[1], $ANIN[2]"),
        ("value", "bool or float: the new value"),
        ("source", "optional str: program | trigger | pulse | stimulus | cell (a rule of the cell file; a preset names itself: cell:pgno, cell:autoext) | auto (an answer of --inputs auto) | varproxy (a KukaVarProxy client's write of an output) | network (an EKI message's output)"),
    ],
    "pose": [
        ("axes", "list float: A1..An, the robot's axes (six; four on a SCARA), in deg (a linear axis in mm), then E1..En (mm or deg): the setpoint read back from MuJoCo"),
        ("tcp", "list[6] float: X, Y, Z mm and A, B, C deg of the TCP in $BASE (main-run $TOOL/$BASE)"),
        ("axes_act", "optional list float: A1..An (then E1..En, as axes) the drives reach behind the setpoint, "
                     "deg: robot/actualvalue.py's actual-value model (the setpoints averaged over "
                     "$machine's identified IPO cycles, less the drives' following error); written for "
                     "a robot that has such a model (the KR 3 R540), the same as krl trace compare's"),
        ("tcp_act", "optional list[6] float: X, Y, Z mm and A, B, C deg of the TCP those axes give, in $BASE "
                    "with the main-run $TOOL/$BASE of the cycle (with axes_act)"),
    ],
    "trigger": [
        ("id", "int: motion id the TRIGGER belongs to"),
        ("index", "int: position of the trigger among that motion's triggers (0-based)"),
        ("line", "optional int: source line of the TRIGGER statement"),
    ],
    "message": [
        ("text", "str: controller message, e.g. 'approximation not possible'"),
        ("id", "optional int: motion id the message refers to"),
        ("number", "optional int: KSS message number"),
    ],
    "error": [
        ("text", "str: error message"),
        ("number", "optional int: KSS message number"),
        ("id", "optional int: motion id"),
        ("line", "optional int: source line"),
        ("file", "optional str: source file"),
    ],
    "end": [
        ("reason", "str: e.g. program_end, error, reset, max_time; interpreters: completed, "
                   "halt, error, deadlock, max_steps, max_sim_time; interrupted (SIGINT or SIGTERM "
                   "stopped `krl run`: text names the signal)"),
        ("text", "optional str: detail (error message, the condition waited for)"),
        ("number", "optional int: KSS message number of an error"),
        ("file", "optional str: source file where the run ended"),
        ("line", "optional int: source line where the run ended"),
        ("context", "optional str: main | interrupt | trigger | submit"),
    ],
    "net": [
        ("iface", "str: eki | rsi | varproxy | plc (net/, docs/network.md)"),
        ("dir", "str: in (a message arrived) | out (sent) | connect | disconnect | refused | error | context (RSI_CREATE read one)"),
        ("name", "optional str: the EKI channel"),
        ("data", "optional str: the message (bytes as Latin-1; the replay feeds them back)"),
        ("number", "optional int: the EKI/RSI message number of an error"),
        ("text", "optional str: detail (why a connection ended, what was refused)"),
    ],
    "recording": [
        ("phase", "str: start | stop | trigger: a KUKA Trace recording started, stopped or was "
                  "triggered ($TRACE.MODE #T_START, #T_STOP, #T_TRIGGER: KUKA's TraceStart and TraceStop "
                  "of bas.src write it; robot/kukatrace reads a recording into these events too)"),
        ("name", "optional str: the recording's name ($TRACE.NAME)"),
        ("config", "optional str: the trace configuration ($TRACE.CONFIG, e.g. an .xml file)"),
    ],
    "robot": [
        ("name", "str: the simulated robot, e.g. 'KR210R2700_2 C4 FLR' (krl run's trace header, t=0)"),
        ("source", "str: where its data came from: a $machine.dat path or a robot YAML"),
        ("trafoname", "optional str: $TRAFONAME of the machine data"),
        ("axes", "optional list str: the E6AXIS component of each value of the pose events' axes "
                 "(robot/axismap.py), e.g. A1..A6, E1; given when they are not A1..A6 (external "
                 "axes, a SCARA's four)"),
    ],
    # written by the interpreters (same writer)
    "stmt": [
        ("file", "str: source file"),
        ("line", "int: source line"),
        ("text", "optional str: statement summary"),
        ("context", "optional str: main | interrupt | trigger | submit"),
    ],
    "step_stop": [
        ("mode", "str: the run mode that stops: MSTEP (a motion ended), ISTEP (before the next "
                 "statement), BSTEP (a backward motion ended, or was refused: then text); HALT "
                 "(krl run --on-halt continue: the operator presses Start again)"),
        ("file", "optional str: source file of the statement"),
        ("line", "optional int: source line of the statement (of the motion, for MSTEP and BSTEP)"),
        ("id", "optional int: motion id (MSTEP, BSTEP)"),
        ("text", "optional str: why backward motion was refused"),
    ],
    "call": [("name", "str: routine name"), ("line", "optional int")],
    "return": [("name", "str: routine name"), ("line", "optional int")],
    "idle": [
        ("until", "float: s, the clock jumped from t to here (interp/runtime/idle.py): nothing "
                  "changed and nothing happens before the next event, or the run repeats itself "
                  "(a polling loop with WAIT SEC: whole periods)"),
        ("since", "optional float: s, the state has stood still since"),
        ("cycles", "optional int: IPO cycles skipped (they execute no statement)"),
    ],
    "answer": [
        ("sets", "dict: what the automatic cell sets (krl run --inputs auto): $IN[n] -> bool, or a "
                 "SIGNAL group $IN[a..b] -> its INT value (bit 0 on $IN[a])"),
        ("names", "optional dict: signal -> the name the condition reads it by (a SIGNAL name)"),
        ("file", "str: source file of the statement the answer releases"),
        ("line", "int: its line"),
        ("statement", "str: WAIT FOR | UNTIL | WHILE | IF | SWITCH"),
        ("condition", "optional str: the source text of the condition's line"),
    ],
    "repeat": [
        ("count", "int: events left out since the last written one (a bounded trace, "
                  "TraceWriter repeats=N: a pass of events repeated with nothing changed but "
                  "time is written N times, then counted)"),
        ("since", "float: s, the first event left out"),
        ("kinds", "dict: kind -> events of that kind left out"),
        ("passes", "optional int: whole repetitions of the pass among them"),
        ("period", "optional int: events in one pass: each event left out repeats the one this "
                   "many events before it, counted over every event or over the events other than "
                   "poses (written also when no whole pass was left out)"),
    ],
    "interrupt": [
        ("prio", "int: interrupt number / priority"),
        ("name", "str: handler routine"),
        ("line", "optional int"),
        ("phase", "optional str: entry | exit"),
    ],
}

KINDS = tuple(SCHEMA)

#: ``krl run --trace``: each pass of a spin is written this many times, then counted
#: (TraceWriter ``repeats``; ``--trace-repeats 0`` writes every event)
TRACE_REPEATS = 10
#: the longest pass (events) the bounding recognises: a cycle of a robot program's time slice
#: (1000 steps) beside a submit program's (100) fits
MAX_PASS_EVENTS = 4096
#: the most events between two state probes after probes that found the state changed (a
#: probe costs what the idle watch's state_of costs: milliseconds on a large backup)
MAX_PROBE_GAP = 65536
#: the state probes of a bounded trace image at most this many values (fields, elements,
#: slots: the probe's second result) per event accounted, over the run: a probe of a large
#: backup's state (tens of thousands of values, milliseconds) waits until the events since
#: the start pay for it, so the probes cost a bounded share of the run whatever the state's size
PROBE_VALUES_PER_EVENT = 16
#: values the probes may image before the budget applies (a start credit: the first probes of a
#: run, when few events are accounted yet, confirm its first spins at once; about 0.1 s of probes)
PROBE_CREDIT_VALUES = 1 << 20
_REQUIRED = {k: tuple(f for f, d in v if not d.startswith("optional")) for k, v in SCHEMA.items()}
#: events whose text after the time TraceWriter.write keeps (its per-kind-and-fields cache)
MAX_CONTENT_CACHE = 4096
#: the field types whose events that cache takes (their JSON does not depend on the time) are
#: str and int, by exact type: a bool is left out, as True == 1 would find the line of an INT 1
#: the kinds that cache takes: every field a string, an integer or a boolean by the schema
#: (not a pose, a ``repeat``, nor a kind whose counters _content leaves out)
_PLAIN_KINDS = frozenset(k for k, v in SCHEMA.items() if k not in ("pose", "repeat", "motion", "trigger", "message",
                                                                    "error", "idle")
                         and all(d.removeprefix("optional ").startswith(("str", "int", "bool")) for _, d in v))
_ORDER = {k: tuple(f for f, _ in v) for k, v in SCHEMA.items()}


def round_time(t: float) -> float:
    """Simulated time rounded to the µs (s)."""
    r = round(float(t), 6)
    return 0.0 if r == 0.0 else r


def _round6(v: float) -> float:
    """A trace float: rounded to 6 decimals, -0.0 written as 0.0."""
    r = round(v, 6)
    return 0.0 if r == 0.0 else r


def _clean(v: Any) -> Any:
    if isinstance(v, bool) or v is None or isinstance(v, str) or isinstance(v, int):
        return v
    if isinstance(v, float):
        return _round6(v)
    if isinstance(v, dict):
        return {str(k): _clean(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_clean(x) for x in v]
    try:  # numpy scalars
        return _clean(v.item())
    except AttributeError:
        return str(v)


def make_event(kind: str, t: float, **fields: Any) -> dict[str, Any]:
    """Build a schema-checked event dict (fields ordered as in :data:`SCHEMA`).

    Raises ValueError for an unknown kind, a missing required field or an unknown field.
    """
    if kind not in SCHEMA:
        raise ValueError(f"unknown trace event kind {kind!r}")
    missing = [f for f in _REQUIRED[kind] if f not in fields]
    if missing:
        raise ValueError(f"trace event {kind!r} lacks {missing}")
    extra = [f for f in fields if f not in _ORDER[kind]]
    if extra:
        raise ValueError(f"trace event {kind!r} has unknown fields {extra}")
    ev: dict[str, Any] = {"t": round_time(t), "kind": kind}
    for f in _ORDER[kind]:
        if f in fields and fields[f] is not None or (f in fields and f in _REQUIRED[kind]):
            ev[f] = _clean(fields[f])
    return ev


class TraceWriteError(OSError):
    """The trace file could not be written (a full disk, a file system gone read-only): the
    lines written before stay whole, the last may be cut (:func:`trace_lines` drops it)."""

    def __init__(self, name: str, exc: OSError):
        super().__init__(exc.errno, f"the trace {name} could not be written: {exc.strerror or exc}")

    def __str__(self) -> str:
        return self.strerror


class TraceWriter:
    """Writes trace events as JSON Lines.

    ``TraceWriter(path)`` writes to a file, ``TraceWriter(stream)`` to an open text stream,
    ``TraceWriter()`` keeps the lines in memory only (see :attr:`lines`). With
    ``keep=True`` the events are also kept as dicts in :attr:`events`.
    ``pose_every`` > 1 thins the per-IPO-cycle pose events (1 = every cycle).

    ``repeats`` = N bounds a spin (issue 34): a *pass* — a sequence of events — that repeats
    with nothing changed but time is written N times, then left out and counted. Repeated means
    the same events with the same fields, time aside (:func:`_content`: values, outputs, motion
    targets; not the motion and message ids, which only count, nor an ``idle`` jump's times),
    back to back, for a whole pass (at most :data:`MAX_PASS_EVENTS` events), *and* the state of
    the run the same at the ends of two passes: :attr:`state_probe`, set by the runtime (the
    idle watch's ``state_of``: data lists, frames, system variables, I/O image, interrupts;
    it returns the image and the number of values imaged), is called at the end of pass N-1
    and N, so a counter loop (``N = N + 1``, whose statements repeat, whose state does not)
    keeps every event. While a spin is left out the state is compared again after 2N, 4N, ...
    passes; a change ends the spin. The probes keep to a budget of
    :data:`PROBE_VALUES_PER_EVENT` values imaged per event (after a start credit of
    :data:`PROBE_CREDIT_VALUES`): a probe over budget waits for a
    later end of pass (the capture, the comparison with it, or the recheck of a spin moves
    later, never earlier), so the bounding costs a bounded share of the run also on a backup
    with a large state; being counted, the budget is the same in every run and interpreter.
    Without a probe the events alone decide. A pose equal to the one before (the robot at rest) is an event
    of the pass like the others (a WAIT FOR at rest is a pass of one pose); a pose that differs
    (the robot moves) is progress: no event repeats one before it. Before the next written event a ``repeat`` event says how
    many events of each kind were left out, since when, how many whole passes and of how many
    events. None (the default) writes every event.

    ``takes_poses``: the controller passes its per-IPO-cycle pose to :meth:`write_pose` only
    for a trace whose ``takes_poses`` is true (an observer of the controller's events that has
    no use for poses says false: the TCP read back is then made only where the run asks for it,
    robot/readback.py ``ReadBack.tcp``). ``takes_motion_points``: likewise for the motion
    events' ``target``, ``point`` (the programmed end point, made by a forward kinematics) and
    ``limits``: an observer that says false gets the motion events without them.
    """

    takes_poses = True
    takes_motion_points = True

    def __init__(self, target: str | Path | IO[str] | None = None, *, keep: bool = False,
                 pose_every: int = 1, repeats: int | None = None) -> None:
        self._own = False
        if target is None:
            self._fh: IO[str] | None = None
        elif isinstance(target, (str, Path)):
            self._fh = open(target, "w", encoding="utf-8", newline="\n")
            self._own = True
        else:
            self._fh = target
        self._name = str(target) if isinstance(target, (str, Path)) else "the trace"
        self.keep = keep
        self._events: list[dict[str, Any]] = []
        self._lines: list[str] = []
        self._poses: list[tuple[float, Any, Any]] = []
        self._memory = target is None
        self.pose_every = max(1, int(pose_every))
        self._pose_count = 0
        self.closed = False
        self.repeats = repeats
        #: () -> (a comparable image of the run's state, values imaged), or None: the events
        #: alone decide a spin
        self.state_probe: Callable[[], tuple[Any, int]] | None = None
        self._spin = _Spin(repeats, self) if repeats is not None else None
        self._left: dict[str, int] = {}  # kind -> events left out since the last repeat event
        self._left_since: float | None = None
        self._left_last = 0.0
        self._left_passes = 0            # whole passes among the events left out
        self._left_period = 0            # events in their pass
        self._probe_after = 0            # no state probe before this many events (_Pass._end_of)
        self._probe_gap = 0
        self._probe_spent = 0            # values imaged by the state probes so far
        self._last_pose = None           # (axes) of the last pose queued
        #: robot/actualvalue.py ActualStream of the run's actual-value model (use_actual), and the
        #: forward kinematics (q, tool_T, base_inv_T) -> 4x4 of its TCP
        self.actual: Any = None
        self._actual_tcp: Callable[..., Any] | None = None
        self._act: dict[int, tuple[Any, Any]] = {}   # row -> (actual axes, 4x4 TCP), computed
        #: (kind, *fields' items) -> (the event's text after its time, its fields): write()
        self._content_cache: dict[tuple, tuple[str, dict[str, Any]]] = {}

    @property
    def events(self) -> list[dict[str, Any]]:
        """Events written so far (only with ``keep=True``)."""
        self.flush()
        return self._events

    @property
    def lines(self) -> list[str]:
        """JSON lines written so far (memory mode only)."""
        self.flush()
        return self._lines

    def write(self, kind: str, t: float, **fields: Any) -> dict[str, Any]:
        """Validate, serialise and write one event; returns the event dict.

        An event whose fields are all strings, integers or None (``stmt``, ``call``, ``return``:
        most of a busy run's events; a kind of :data:`_PLAIN_KINDS`) is the same text after its time whenever its
        kind and fields are: that text (:func:`_content`) and the event's fields are kept in
        :data:`MAX_CONTENT_CACHE` entries, so such an event is validated and serialised once,
        and its line is ``{"t":`` + the rounded time + that text (``json.dumps`` writes a float
        as its ``repr``: the same bytes)."""
        plain = kind in _PLAIN_KINDS
        if plain:
            for v in fields.values():
                if v is not None and type(v) is not str and type(v) is not int:
                    plain = False
                    break
        if plain:
            key = (kind, *fields.items())
            hit = self._content_cache.get(key)
            if hit is None:
                ev = make_event(kind, t, **fields)
                line = json.dumps(ev, separators=(",", ":"), ensure_ascii=True)
                if len(self._content_cache) >= MAX_CONTENT_CACHE:
                    self._content_cache.clear()
                hit = self._content_cache[key] = (line[line.index(",") + 1:], {k: v for k, v in ev.items() if k != "t"})
            if hit is not None:
                content, tail = hit
                tr = round(float(t), 6) or 0.0      # round_time: -0.0 written as 0.0
                ev = {"t": tr, **tail}
                self._write_plain(ev, '{"t":' + repr(tr) + "," + content, content)
                return ev
        ev = make_event(kind, t, **fields)
        self.write_event(ev)
        return ev

    def _write_plain(self, ev: dict[str, Any], line: str, content: str) -> None:
        """:meth:`write_event` of an event that is no pose, no ``repeat`` and no kind of
        :data:`_COUNTERS`, its JSON `line` and its `content` (:func:`_content`) known."""
        if self._spin is not None:
            if self._spin.left_out(content):
                self._leave_out(ev["kind"], ev["t"])
                return
            self._write_left(ev["t"])
        self._emit(ev, line)

    def use_actual(self, stream: Any, tcp: Callable[..., Any]) -> None:
        """Write each pose with the actual pose the drives reach (``axes_act``, ``tcp_act``):
        `stream` is the run's robot/actualvalue.py ``ActualStream`` (keeping its rows, the frames
        of each as its extra), to which the controller pushes every IPO cycle's axes before the
        pose; `tcp` (q, tool_T, base_inv_T) -> the 4x4 TCP. A pose waits in the queue until its
        actual axes are known (two cycles later; at :meth:`close` the stream finishes)."""
        self.actual, self._actual_tcp = stream, tcp

    def write_pose(self, t: float, axes: Any, tcp_T: Any) -> None:
        """Queue a ``pose`` event from axes (A1..An, E1..En; deg, mm) and a 4x4 TCP matrix (mm). Poses are
        converted to X, Y, Z, A, B, C in batches (vectorised, same numbers as
        :func:`robot.frames.matrix_to_frame`) and written before the next other event."""
        if self.actual is not None:
            tcp_T = (tcp_T, self.actual.pushed - 1)     # the stream's row of this cycle
        self._pose_count += 1
        if (self._pose_count - 1) % self.pose_every:
            return
        if self._spin is not None:
            key = tuple(_round6(float(v)) for v in (axes.tolist() if hasattr(axes, "tolist") else axes))
            if key != self._last_pose:
                self._last_pose = key
                self._spin.reset()          # the robot moves: progress
            if self._spin.left_out(f"pose{key}", pose=True):   # at rest: a pose is part of the pass
                self._leave_out("pose", t)
                return
            self._write_left(t)
        self._poses.append((t, axes, tcp_T))
        if len(self._poses) >= 512:
            self.flush()

    def flush(self) -> None:
        """Write the queued events: pose events and the events written after the first of
        them, in order (the poses' X, Y, Z, A, B, C are converted in one batch: the conversion's
        cost is mostly per call). A pose line is formatted by robot/poseline.py ``pose_line``:
        the same bytes as ``json.dumps`` of the event (``repr`` of each rounded float, ``-0.0``
        written as 0), without its generic encoder and :func:`_clean`'s recursion (a quarter of
        the benchmark's time went here); a number it leaves (not finite, 1e15 or more) takes
        ``json.dumps``."""
        if not self._poses:
            return
        if self.actual is not None:
            self._flush_actual()
            return
        poses, self._poses = self._poses, []
        frames = iter(_frames_of([T for t, _, T in poses if t is not None]))
        for t, axes, line in poses:
            if t is None:            # an event queued behind the poses (_emit)
                self._write(axes, line)
                continue
            fr = next(frames)
            vals = axes.tolist() if hasattr(axes, "tolist") else axes
            line = _POSE.pose_line(t, vals, fr)     # robot/poseline.py, compiled where built
            if line is not None and not self.keep:
                self._write(None, line)             # type: ignore[arg-type]  (not kept)
                continue
            ev = {"t": round_time(t), "kind": "pose", "axes": [_round6(float(v)) for v in vals],
                  "tcp": [_round6(v) for v in fr]}
            # json.dumps: the same bytes for a number pose_line writes; NaN / Infinity, a huge number
            self._write(ev, line if line is not None else json.dumps(ev, separators=(",", ":"), ensure_ascii=True))

    def _flush_actual(self, final: bool = False) -> None:
        """:meth:`flush` with the actual poses (:meth:`use_actual`): the queued poses whose actual
        axes the stream has computed, and the events behind them; the rest stay queued (all are
        written when `final`: the stream has finished)."""
        for row, frames, q in self.actual.take():
            self._act[row] = (q, frames)
        ready = 0
        for t, _, T in self._poses:
            if t is not None and T[1] not in self._act:
                break
            ready += 1
        poses, self._poses = self._poses[:ready], self._poses[ready:]
        if not poses:
            return
        want = [(t, axes, T[0], self._act.pop(T[1])) for t, axes, T in poses if t is not None]
        tcp = _frames_of([T for _, _, T, _ in want])
        act = _frames_of([self._actual_tcp(q, *fr) for _, _, _, (q, fr) in want])
        k = 0
        for t, axes, line in poses:
            if t is None:
                self._write(axes, line)
                continue
            q = want[k][3][0]
            vals = axes.tolist() if hasattr(axes, "tolist") else axes
            self._write_pose_line(t, vals, tcp[k], q.tolist(), act[k])
            k += 1
        self._act = {r: v for r, v in self._act.items() if r > self.actual.pushed - 4096}

    def _write_pose_line(self, t: float, vals: list, fr: list, qa: list, fa: list) -> None:
        """One pose event with its actual pose (:meth:`_flush_actual`): the bytes json.dumps gives."""
        ev = {"t": round_time(t), "kind": "pose", "axes": [_round6(float(v)) for v in vals],
              "tcp": [_round6(v) for v in fr], "axes_act": [_round6(float(v)) for v in qa],
              "tcp_act": [_round6(v) for v in fa]}
        self._write(ev, json.dumps(ev, separators=(",", ":"), ensure_ascii=True))

    def write_event(self, ev: dict[str, Any]) -> None:
        """Write an already built event dict (from :func:`make_event`)."""
        line = None
        if ev["kind"] == "pose":
            self._pose_count += 1
            if (self._pose_count - 1) % self.pose_every:
                return
        elif self._spin is not None and ev["kind"] != "repeat":
            line = json.dumps(ev, separators=(",", ":"), ensure_ascii=True)
            if self._spin.left_out(_content(ev, line)):
                self._leave_out(ev["kind"], ev["t"])
                return
            self._write_left(ev["t"])
        self._emit(ev, line)

    def _leave_out(self, kind: str, t: float) -> None:
        if self._left_since is None:
            self._left_since = t
        self._left[kind] = self._left.get(kind, 0) + 1
        self._left_last = t

    def _write_left(self, t: float | None = None) -> None:
        """Write the ``repeat`` event of the events left out, if any, at time `t` (the event
        written next; default: the last one left out)."""
        if not self._left:
            return
        left, self._left = self._left, {}
        since, self._left_since = self._left_since, None
        passes, self._left_passes = self._left_passes, 0
        self._emit(make_event("repeat", self._left_last if t is None else max(t, self._left_last),
                              count=sum(left.values()), since=since, kinds=dict(sorted(left.items())),
                              passes=passes or None, period=self._left_period or None))

    def _emit(self, ev: dict[str, Any], line: str | None = None) -> None:
        """Keep and/or write event `ev`; `line` is its JSON text when the caller formatted it.
        Behind queued poses the event waits in their queue (:meth:`flush` writes it in order)."""
        if line is None:
            line = json.dumps(ev, separators=(",", ":"), ensure_ascii=True)
        if self._poses:
            self._poses.append((None, ev, line))
        else:
            self._write(ev, line)

    def _write(self, ev: dict[str, Any], line: str) -> None:
        if self.keep:
            self._events.append(ev)
        if self._memory:
            self._lines.append(line)
        elif self._fh is not None:
            try:
                self._fh.write(line + "\n")     # one call: a signal never falls between line and end
            except OSError as exc:
                raise TraceWriteError(self._name, exc) from None

    def _probe(self) -> Any:
        """The state image of :attr:`state_probe`, or None while the probes are over their
        budget (:data:`PROBE_CREDIT_VALUES` plus :data:`PROBE_VALUES_PER_EVENT` values per
        event accounted so far)."""
        if self._probe_spent > PROBE_CREDIT_VALUES + PROBE_VALUES_PER_EVENT * self._spin.every.n:
            return None
        state, values = self.state_probe()
        self._probe_spent += values
        return state

    def text(self) -> str:
        """The in-memory trace as one string (memory mode only)."""
        return "".join(line + "\n" for line in self.lines)

    def close(self) -> None:
        """Write what is queued and close the file. Raises :class:`TraceWriteError`."""
        self._write_left()
        if self.actual is not None:
            self.actual.finish()           # the robot at rest after the run: every row computed
        self.flush()
        if self._own and self._fh is not None and not self.closed:
            self.closed = True
            try:
                self._fh.close()
            except OSError as exc:
                raise TraceWriteError(self._name, exc) from None
        self.closed = True

    def __enter__(self) -> "TraceWriter":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


#: fields that only count or give a time, left out of an event's content (:func:`_content`)
_COUNTERS = {"motion": ("id",), "trigger": ("id",), "message": ("id",), "error": ("id",),
             "idle": ("until", "since", "cycles")}


def _content(ev: dict[str, Any], line: str) -> str:
    """What event `ev` (written as JSON `line`) says, time aside: the line without its ``t``,
    and for the kinds of :data:`_COUNTERS` without the ids that only count motions and the
    times of an idle jump. Two events with the same content are repetitions."""
    drop = _COUNTERS.get(ev["kind"])
    if drop is None:
        return line[line.index(",") + 1:]
    return json.dumps({k: v for k, v in ev.items() if k != "t" and k not in drop},
                      separators=(",", ":"), ensure_ascii=True)


class _Spin:
    """The spin detector of a bounded :class:`TraceWriter` (its docstring): two
    :class:`_Pass` trackers, one over every event and one over the events of the programs
    (poses aside). The second sees a polling loop's passes run on from one IPO cycle into the
    next (the pose at rest between two time slices is not in its way); the first sees the cycle
    itself repeat, poses included (a robot program's time slice and a submit program's, with the
    pose between them). An event either leaves out is left out."""

    def __init__(self, repeats: int, writer: TraceWriter) -> None:
        self.writer = writer
        self.every = _Pass(repeats, writer)
        self.program = _Pass(repeats, writer)

    def reset(self) -> None:
        """Progress (the robot moves): no event repeats one before it."""
        self.every.reset()
        self.program.reset()

    def left_out(self, key: str, pose: bool = False) -> bool:
        """Account event `key` (:func:`_content`; `pose`: a pose event); True when it is to be
        left out."""
        done = self.every.step(key)
        if not pose:
            inner = self.program.step(key)  # always: its history must see every event
            done = done or inner
        if done is None:
            return False
        w = self.writer
        if w._left and w._left_period != done.period:
            w._write_left()                 # a spin of another pass: one `repeat` event each
        w._left_period, w._left_passes = done.period, w._left_passes + done.passes_ended
        return True


class _Pass:
    """One period tracker of :class:`_Spin`: the contents of its last :data:`MAX_PASS_EVENTS`
    events, the period of the pass, the matches in a row, and the state comparisons that
    confirm the spin (the :class:`TraceWriter` docstring). Each event is compared with the one
    a period back; a run of matches as long as the period is one more copy of the pass. When a
    match fails, the period is found again from the event's last occurrence."""

    def __init__(self, repeats: int, writer: TraceWriter) -> None:
        self.repeats = max(1, int(repeats))
        self.writer = writer
        self.hist: deque[str] = deque(maxlen=MAX_PASS_EVENTS)
        self.last: dict[str, int] = {}    # content -> index of its last occurrence
        self.n = 0                        # index of the next event
        self.unlock()

    def reset(self) -> None:
        self.hist.clear()
        self.last.clear()
        self.unlock()

    def unlock(self) -> None:
        self.period = 0                   # events in one pass (0: no repetition)
        self.match = 0                    # events that matched the one a period back, in a row
        self.confirmed = False            # the pass repeats with the same state: left out
        self.capture = max(2, self.repeats - 1)   # copy at whose end the state is captured
        self.gap = 1                      # passes before the next capture (doubles)
        self.ref = None                   # (copy, state) captured
        self.recheck = 0                  # copy at whose end a confirmed spin's state is compared
        self.passes_ended = 0             # 1 when the event left out ended a pass

    def step(self, key: str) -> "_Pass | None":
        """Account event `key`; returns self when it is to be left out."""
        i = self.n
        self.n += 1
        hist = self.hist
        p = self.period
        out = None
        if p and len(hist) >= p and hist[-p] == key:
            self.match += 1
            copy = (self.match - 1) // p + 2      # the original pass is copy 1
            out = self if self.confirmed else None
            end = self.match % p == 0
            if end:
                self._end_of(copy)
            self.passes_ended = 1 if end else 0
        else:
            self.unlock()
            j = self.last.get(key)
            if j is not None and 0 < i - j <= len(hist):
                self.period, self.match = i - j, 1
        self.last[key] = i
        hist.append(key)
        if len(self.last) > 4 * MAX_PASS_EVENTS:
            self.last = {k: v for k, v in self.last.items() if v > i - MAX_PASS_EVENTS}
        return out

    def _end_of(self, copy: int) -> None:
        """Copy `copy` of the pass ended: capture or compare the state."""
        w = self.writer
        if w.state_probe is None:
            self.confirmed = copy >= self.repeats
            return
        if self.confirmed:
            if copy >= self.recheck:
                state = w._probe()
                if state is None:
                    return                       # over budget: at a later end of pass
                if state != self.ref[1]:
                    self.confirmed = False       # the state changed: write again
                    self.ref, self.capture, self.gap = (copy, state), copy, 1
                else:
                    self.recheck = 2 * copy
            return
        if copy == self.capture:
            state = None if w._spin.every.n < w._probe_after else w._probe()
            if state is None:
                self.capture += 1            # the state changed lately, or over budget: not yet
            else:
                self.ref = (copy, state)
        elif self.ref is not None and copy > self.ref[0]:
            state = w._probe()
            if state is None:
                return                       # over budget: compare at a later end of pass
            if state == self.ref[1]:
                self.confirmed = True
                self.recheck = 2 * copy
                w._probe_gap = 0
            else:
                self.gap *= 2                # the state changes: compare again later
                self.capture = copy + self.gap
                self.ref = None
                # loops whose state changes cost a probe each: the next one, of any pass, after
                # twice as many events as the last (at most MAX_PROBE_GAP)
                w._probe_gap = min(max(2 * w._probe_gap, 64), MAX_PROBE_GAP)
                w._probe_after = w._spin.every.n + w._probe_gap


def _frames_of(Ts: list[Any]) -> list[list[float]]:
    """X, Y, Z, A, B, C of each 4x4 matrix of `Ts`: :func:`robot.frames.matrix_to_frame`, the one
    conversion (its closed form costs what scipy's batch did: 0.71 against 0.63 ms per 512
    poses, 2026-11-26; the batch differed from it in the last bit, 19.99999999999999 for 20)."""
    return [list(matrix_to_frame(T)) for T in Ts]


def read_trace(source: str | Path | IO[str], warn: Callable[[str], None] | None = None) -> Iterator[dict[str, Any]]:
    """Yield the events of a JSON Lines trace (a path, or a text stream; :func:`trace_lines`:
    a cut last line is dropped with a warning through `warn`, default: on stderr). Raises
    ValueError for a line that is no JSON."""
    if isinstance(source, (str, Path)):
        with open(source, encoding="utf-8") as fh:
            for _n, ev in trace_lines(fh, str(source), warn):
                yield ev
        return
    for _n, ev in trace_lines(source, getattr(source, "name", "<trace>"), warn):
        yield ev


def trace_lines(lines: Iterable[str], name: str,
                warn: Callable[[str], None] | None = None) -> Iterator[tuple[int, dict[str, Any]]]:
    """(line number, event) of each non-blank line. A last line cut short (no line end, no
    JSON: a full disk, a run killed while it wrote) is dropped, with a warning naming it through
    `warn` (default: printed on stderr): every whole line before it is kept (issue 74). Raises
    ValueError ``NAME:N: not a trace event (...)`` for any other line that is no JSON."""
    for n, line in enumerate(lines, 1):
        text = line.strip()
        if not text:
            continue
        try:
            ev = load_event(text)
        except ValueError as exc:
            if not line.endswith("\n"):
                (warn or _warn_stderr)(f"{name}:{n}: warning: the last line is cut short (a full disk, or "
                                        f"the run was killed while writing it): dropped")
                return
            raise ValueError(f"{name}:{n}: not a trace event ({exc})") from None
        yield n, ev


def _warn_stderr(text: str) -> None:
    print(text, file=sys.stderr)


def how_it_ended(events: Iterable[dict[str, Any]]) -> str:
    """How the run of a trace ended, in words: the last ``end`` event's reason (with its text,
    such as the signal of an ``interrupted`` run), or ``incomplete (no end event: the run was
    killed, or its trace cut)``."""
    last = None
    for ev in events:
        if ev.get("kind") == "end":
            last = ev
    return ending_words(last)


def ending_words(end: dict[str, Any] | None) -> str:
    """:func:`how_it_ended` of the last ``end`` event `end` (None: there was none)."""
    if end is None:
        return INCOMPLETE
    text = end.get("text")
    return f"{end.get('reason')}" + (f" ({text})" if text else "")


def unfinished(ended: str) -> bool:
    """True for a run that did not end by itself (:func:`how_it_ended`: no end event, or
    interrupted by a signal): ``krl trace show`` and the plots say so."""
    return ended.startswith(("incomplete", "interrupted"))


#: what :func:`how_it_ended` says of a trace without an ``end`` event
INCOMPLETE = "incomplete (no end event: the run was killed, or its trace cut)"


def load_event(line: str | bytes) -> dict[str, Any]:
    """One line of a trace as data: by orjson (a 110 744-line trace of a palletizer program in
    0.12 s of CPU against the json module's 0.27 s, 2026-11-25; reading the traces back was a
    tenth of ``krl conformance``'s CPU), by the json module where orjson refuses what json reads
    (NaN and Infinity, which :meth:`TraceWriter.write_event` writes as json.dumps does; a lone
    surrogate escape) or reads otherwise (an integer past 64 bits, which orjson reads as a float:
    a result holding a float of magnitude 2**63 or more is read again): the same data. Raises
    ValueError for a line that is no JSON."""
    try:
        data = orjson.loads(line)
    except orjson.JSONDecodeError:
        return json.loads(line)
    return json.loads(line) if _past_int64(data) else data


#: the smallest magnitude of a float orjson makes of an integer it cannot hold in 64 bits
_INT64 = float(2 ** 63)


def _past_int64(x) -> bool:
    """True when `x` (parsed JSON) holds a float of magnitude 2**63 or more (:func:`load_event`)."""
    t = type(x)
    if t is float:
        return not -_INT64 < x < _INT64
    if t is dict:
        x = x.values()
    elif t is not list:
        return False
    for v in x:
        tv = type(v)
        if tv is float:
            if not -_INT64 < v < _INT64:
                return True
        elif (tv is list or tv is dict) and _past_int64(v):
            return True
    return False


def validate_event(ev: dict[str, Any]) -> None:
    """Raise ValueError if ``ev`` does not follow :data:`SCHEMA`."""
    if "t" not in ev or "kind" not in ev:
        raise ValueError("event lacks t or kind")
    fields = {k: v for k, v in ev.items() if k not in ("t", "kind")}
    make_event(ev["kind"], ev["t"], **fields)


#: the leading words of a field description -> its JSON Schema type
_JSON_TYPES = (("list[6] float", {"type": "array", "items": {"type": "number"}, "minItems": 6, "maxItems": 6}),
               ("list float", {"type": "array", "items": {"type": "number"}, "minItems": 1}),
               ("bool or float", {"type": ["boolean", "number"]}), ("str or null", {"type": ["string", "null"]}),
               ("dict", {"type": "object"}), ("int", {"type": "integer"}), ("str", {"type": "string"}),
               ("float", {"type": "number"}), ("bool", {"type": "boolean"}), ("list", {"type": "array"}))


def _field_type(description: str) -> dict[str, Any]:
    words = description.removeprefix("optional").strip()
    for prefix, schema in _JSON_TYPES:
        if words.startswith(prefix):
            return dict(schema, description=description)
    return {"description": description}


def json_schema() -> dict[str, Any]:
    """The trace's JSON Schema (draft 2020-12), built from :data:`SCHEMA`: one event per line,
    one branch per kind with its required and optional fields. docs/schemas/trace.schema.json
    is this, written by ``python -m robot.trace --schema`` (a test keeps the file current)."""
    branches = []
    for kind, fields in SCHEMA.items():
        props: dict[str, Any] = {"t": {"type": "number", "minimum": 0, "description": "simulated time (s)"},
                                 "kind": {"const": kind}}
        props.update({name: _field_type(desc) for name, desc in fields})
        branches.append({"type": "object", "properties": props, "additionalProperties": False,
                         "required": ["t", "kind", *_REQUIRED[kind]]})
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "$id": "trace.schema.json",
            "title": "krl run --trace: one event per line (JSON Lines), robot/trace.py SCHEMA",
            "oneOf": branches}


__all__ = ["SCHEMA", "KINDS", "TraceWriter", "json_schema", "make_event", "read_trace", "trace_lines",
           "how_it_ended", "ending_words", "unfinished", "INCOMPLETE", "TraceWriteError", "validate_event",
           "round_time"]


if __name__ == "__main__":
    import sys

    if sys.argv[1:] != ["--schema"]:
        sys.exit("usage: python -m robot.trace --schema")
    print(json.dumps(json_schema(), indent=2))
