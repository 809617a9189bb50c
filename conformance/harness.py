"""Conformance harness (issue 8): run hand-written cases on the interpreters and compare.

A case is a directory ``conformance/cases/NNN_name/`` with

* ``program.src`` (main routine ``DEF program()``), optionally ``program.dat`` and other
  ``.src``/``.sub`` modules;
* optionally ``stimuli.yaml`` (format of :mod:`robot.stimuli`);
* ``expect.yaml``: the expectations, written by hand from the reference (format:
  docs/architecture.md, "Conformance").

Each case is run through the ``krl run`` contract of issue 6 (``--interp tree|vm``,
``--trace OUT.jsonl``, ``--inputs``, ``--submit``, ``--max-sim-time``); the trace
(robot/trace.py ``SCHEMA``) is the only thing the harness looks at. Three comparisons:

* **control flow** - the executed *leaf* statements of the case's own files (source lines;
  control-structure lines such as ``IF``/``ENDFOR``/``CASE`` are not compared against the
  hand-written trace because whether they emit ``stmt`` events is an interpreter detail),
  calls and returns of the case's own routines, interrupt entries/exits;
* **I/O timing** - the output events (``$OUT``, ``$ANOUT``, ...) in order, each time
  within one IPO cycle (12 ms) of the expectation (absolute, or relative to a motion event);
* **paths** - properties of the TCP polyline (``pose`` events): straightness of LIN
  segments, circles, blend zone radius and where a blend starts and ends, exact stops,
  durations (trapezoid profile by hand), reached points; controller messages; the ``end``;
* **limits** - every case's trace keeps the motion limits (:func:`check_limits`, issue 15).

Between the tree interpreter and the VM the whole trace is compared: the statement/call/
interrupt sequence and the I/O events exactly (times included), and the TCP polylines by
their maximum deviation.
"""

from __future__ import annotations

import contextlib
import difflib
import fnmatch
import importlib
import importlib.util
import io
import json
import math
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
import traceback

import yaml
import numpy as np

from robot.limits import check_trace
from robot.trace import load_event

CASES_DIR = Path(__file__).parent / "cases"
REPO = Path(__file__).resolve().parent.parent
IPO = 0.012
TIME_TOL = IPO + 1e-6
INTERPRETERS = ("tree", "vm")


# ============================================================================ cases
@dataclass
class Case:
    name: str
    path: Path
    expect: dict[str, Any]

    @property
    def program(self) -> Path:
        return self.path / "program.src"

    @property
    def stimuli(self) -> Path | None:
        p = self.path / "stimuli.yaml"
        return p if p.exists() else None

    @property
    def submit(self) -> Path | None:
        name = self.expect.get("submit")
        return self.path / name if name else None

    @property
    def pending(self) -> str | None:
        """The reason if the case is marked ``status: pending`` (for any interpreter), else None."""
        if str(self.expect.get("status", "ok")).lower() == "pending":
            return str(self.expect.get("reason") or "pending (no reason given)")
        return None

    @property
    def pending_on(self) -> tuple[str, ...]:
        """The interpreters the pending mark applies to (``pending_on``, default both); the
        tree-vs-VM comparison counts as "vm"."""
        if self.pending is None:
            return ()
        on = self.expect.get("pending_on") or list(INTERPRETERS)
        return tuple(str(x).lower() for x in (on if isinstance(on, list) else [on]))

    def pending_for(self, interp: str) -> str | None:
        return self.pending if interp in self.pending_on else None

    @property
    def max_sim_time(self) -> float:
        return float(self.expect.get("max_sim_time", 10.0))

    def files(self) -> list[Path]:
        return sorted(p for p in self.path.iterdir() if p.suffix.lower() in (".src", ".sub", ".dat"))

    def routines(self, suffix: str | None = None) -> set[str]:
        """Upper-case names of the routines defined in the case's own files (only in files
        with the given suffix, if one is given)."""
        names: set[str] = set()
        for p in self.files():
            if suffix is not None and p.suffix.lower() != suffix:
                continue
            for m in re.finditer(r"^\s*(?:GLOBAL\s+)?DEF(?:FCT\s+\w+(?:\[\])?)?\s+(\w+)\s*\(",
                                 p.read_text(encoding="utf-8", errors="replace"), re.I | re.M):
                names.add(m.group(1).upper())
        return names


def load_case(path: Path) -> Case:
    with open(path / "expect.yaml", encoding="utf-8") as fh:
        # libyaml's safe loader where PyYAML has it (robot/machine.py's choice): the same documents,
        # the 111 cases, read at each collection of make test: 0.26 -> 0.04 s of CPU
        expect = yaml.load(fh, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader)) or {}
    return Case(path.name, path, expect)


def load_cases(root: Path = CASES_DIR) -> list[Case]:
    return [load_case(p) for p in sorted(root.iterdir()) if (p / "expect.yaml").exists()]


# ============================================================================ leaf lines
_CONTROL = re.compile(
    r"^(?:GLOBAL\s+)?(?:DEF|DEFFCT|END|ENDFCT|DEFDAT|ENDDAT|DECL|EXT|EXTFCT|EXTP|EXTFCTP|STRUC|ENUM|"
    r"SIGNAL|CONST|IF|ELSE|ENDIF|FOR|ENDFOR|WHILE|ENDWHILE|REPEAT|UNTIL|LOOP|ENDLOOP|SWITCH|"
    r"CASE|DEFAULT|ENDSWITCH|SPLINE|PTP_SPLINE|ENDSPLINE|SPL|SKIP|ENDSKIP|TIME_BLOCK)\b", re.I)
_SIMPLE_TYPES = {"INT", "REAL", "BOOL", "CHAR", "FRAME", "POS", "E6POS", "AXIS", "E6AXIS",
                 "LOAD", "ERROR_T"}
_LABEL = re.compile(r"^[A-Za-z_]\w*\s*:\s*$")


def _strip_comment(line: str) -> str:
    out, in_str = [], False
    for ch in line:
        if ch == '"':
            in_str = not in_str
        if ch == ";" and not in_str:
            break
        out.append(ch)
    return "".join(out).strip()


def leaf_lines(path: Path, types: set[str] | None = None) -> set[int]:
    """Source lines that hold an executable leaf statement (assignment, call, I/O, motion,
    WAIT, HALT, GOTO, EXIT, RETURN, CONTINUE, INTERRUPT, TRIGGER, BRAKE, ...).

    SPL/SLIN/SCIRC segments inside a SPLINE block are not leaves (the block is one motion)."""
    types = {t.upper() for t in (types or set())} | _SIMPLE_TYPES
    out: set[int] = set()
    in_spline = False
    for no, raw in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
        s = _strip_comment(raw)
        if not s or s.startswith("&"):
            continue
        u = s.upper()
        if re.match(r"^(SPLINE|PTP_SPLINE)\b", u):
            in_spline = True
        if in_spline:
            if u.startswith("ENDSPLINE"):
                in_spline = False
            continue
        if _CONTROL.match(s) or _LABEL.match(s):
            continue
        first = re.match(r"^(\w+)\s+\w", s)
        if first and first.group(1).upper() in types and "=" not in s.split("(")[0][:len(first.group(1)) + 1]:
            # a declaration without DECL: TYPE name[, ...]
            if not re.match(r"^\w+\s*=", s):
                continue
        out.add(no)
    return out


def _user_types(case: Case) -> set[str]:
    names: set[str] = set()
    for p in case.files():
        for m in re.finditer(r"^\s*(?:GLOBAL\s+)?(?:STRUC|ENUM)\s+(\w+)",
                             p.read_text(encoding="utf-8", errors="replace"), re.I | re.M):
            names.add(m.group(1).upper())
    return names


# ============================================================================ interpreters
def _interp_run_command():
    """The click ``run`` command of issue 6 (``interp.cli``), or None."""
    try:
        mod = importlib.import_module("interp.cli")
    except Exception:  # noqa: BLE001 - not built yet / broken: reported as not available
        return None
    for cmd in getattr(mod, "commands", []) or []:
        if getattr(cmd, "name", None) == "run":
            return cmd
    return None


_STATUS: dict[str, str | None] | None = None


def _probe(interp: str) -> str | None:
    """Run a two-line program with ``krl run --interp INTERP``; None if it works, else why not."""
    with tempfile.TemporaryDirectory(prefix="krl-probe-") as tmp:
        prog = Path(tmp) / "program.src"
        prog.write_text("DEF program()\n  $OUT[1] = TRUE\nEND\n", encoding="utf-8")
        res = run_program(prog, interp, max_sim_time=1.0, wall_timeout=60.0)
    if res.crash is None and res.exit_code == 0 and any(e.get("kind") == "end" for e in res.events):
        return None
    why = (res.crash or res.output or f"exit code {res.exit_code}").strip().splitlines()
    return "not available: " + (why[0] if why else "krl run failed")[:200]


def interpreter_status(refresh: bool = False) -> dict[str, str | None]:
    """name -> None if available, else the reason why not. An interpreter is available when
    ``krl run --interp NAME`` runs a trivial program to completion (probed once)."""
    global _STATUS
    if _STATUS is not None and not refresh:
        return dict(_STATUS)
    out: dict[str, str | None] = {}
    if _interp_run_command() is None:
        out["tree"] = "not available: interp.cli has no `run` command yet (issue 6)"
        out["vm"] = "not available: no `krl run`"
    else:
        out["tree"] = _probe("tree")
        out["vm"] = _probe("vm")
    _STATUS = out
    return dict(out)


def available_interpreters() -> list[str]:
    return [k for k, v in interpreter_status().items() if v is None]


@dataclass
class RunResult:
    interp: str
    events: list[dict[str, Any]]
    exit_code: int | None
    output: str = ""
    crash: str | None = None       # harness-level failure: exception, timeout, no trace
    wall_s: float = 0.0


class _Timeout(Exception):
    pass


@contextlib.contextmanager
def _wall_limit(seconds: float):
    if seconds <= 0 or not hasattr(signal, "SIGALRM"):
        yield
        return
    if signal.getsignal(signal.SIGALRM) not in (signal.SIG_DFL, signal.SIG_IGN, None):
        # someone else (pytest-timeout) owns SIGALRM: leave it to them
        yield
        return
    try:
        old = signal.signal(signal.SIGALRM, lambda *_: (_ for _ in ()).throw(_Timeout()))
    except ValueError:  # not in the main thread
        yield
        return
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def run_args(program: Path, interp: str, trace: Path, *, stimuli: Path | None = None,
             submit: Path | None = None, max_sim_time: float = 10.0,
             workspace: Path | None = None, max_steps: int | None = None, check: bool = True) -> list[str]:
    # the default bounded trace: a spin (a pass repeated with nothing changed but time) is
    # counted in `repeat` events the same way by both interpreters; every other event is there
    args = [str(program), "--interp", interp, "--trace", str(trace), "--max-sim-time", str(max_sim_time)]
    if not check:
        args.append("--no-check")
    if max_steps is not None:
        args += ["--max-steps", str(max_steps)]
    if workspace is not None:
        args += ["--workspace", str(workspace)]
    if stimuli is not None:
        args += ["--inputs", str(stimuli)]
    if submit is not None:
        args += ["--submit", str(submit)]
    return args


def _trace_path() -> Path:
    """A path in the temporary folder no file holds, for one run's trace (removed once read):
    a name made by ``mkstemp`` and given up at once, not a temporary folder per run (a 20 KB
    trace written, read and removed: 0.52-0.64 ms of CPU and 5.8-6.2 ms of wall per run in a
    folder of its own, 0.15-0.18 and 0.6-0.8 ms so; three alternations, 2026-11-29, load 21)."""
    fd, name = tempfile.mkstemp(prefix="krl-conf-", suffix=".jsonl")
    os.close(fd)
    os.unlink(name)
    return Path(name)


def run_program(program: Path, interp: str, *, stimuli: Path | None = None,
                submit: Path | None = None, max_sim_time: float = 10.0,
                workspace: Path | None = None, wall_timeout: float = 120.0,
                subprocess_mode: bool = False, max_steps: int | None = 1_000_000,
                check: bool = True) -> RunResult:
    """Run one program with ``krl run`` and read its trace back. ``check`` False: ``--no-check``
    (the real programs: the interpreters are compared on the code the checker rejects too)."""
    t0 = time.monotonic()
    trace = _trace_path()
    try:
        args = run_args(program, interp, trace, stimuli=stimuli, submit=submit,
                        max_sim_time=max_sim_time, workspace=workspace, max_steps=max_steps, check=check)
        code: int | None = None
        output = ""
        crash = None
        if subprocess_mode:
            try:
                p = subprocess.run([sys.executable, "-m", "app", "run", *args], cwd=REPO,
                                   capture_output=True, text=True, timeout=wall_timeout)
                code, output = p.returncode, (p.stdout + p.stderr)[-4000:]
            except subprocess.TimeoutExpired:
                crash = f"wall-clock timeout after {wall_timeout:.0f} s"
        else:
            cmd = _interp_run_command()
            if cmd is None:
                return RunResult(interp, [], None, crash="krl run not available")
            buf = io.StringIO()
            try:
                with _wall_limit(wall_timeout), contextlib.redirect_stdout(buf), \
                        contextlib.redirect_stderr(buf):
                    try:
                        rv = cmd.main(args=args, standalone_mode=False, prog_name="krl run")
                        code = rv if isinstance(rv, int) else 0
                    except SystemExit as exc:
                        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
            except _Timeout:
                crash = f"wall-clock timeout after {wall_timeout:.0f} s"
            except Exception as exc:  # noqa: BLE001 - an internal error of the interpreter
                crash = f"internal error: {type(exc).__name__}: {exc}\n" + traceback.format_exc()[-3000:]
            output = buf.getvalue()[-4000:]
        events: list[dict[str, Any]] = []
        if trace.exists():
            with open(trace, encoding="utf-8") as fh:
                for line in fh:
                    line = line.strip()
                    if line:
                        try:
                            events.append(load_event(line))
                        except ValueError:
                            crash = crash or f"trace line is not JSON: {line[:120]}"
        elif crash is None:
            crash = f"no trace written (exit code {code}): {output.strip()[-500:]}"
        if crash is None and code == 2:
            crash = f"exit code 2 (usage or internal error): {output.strip()[-1500:]}"
    finally:
        trace.unlink(missing_ok=True)
    return RunResult(interp, events, code, output, crash, time.monotonic() - t0)


def clean_run_problem(res: RunResult) -> str | None:
    """Why a run counts as an internal failure of the interpreter (crash, exit code 2, no
    ``end`` event), or None. Run-time errors of the KRL program (exit 1) and stops (exit 3)
    are clean outcomes."""
    if res.crash:
        return res.crash
    if res.exit_code not in (0, 1, 3):
        return f"exit code {res.exit_code}"
    if not any(e.get("kind") == "end" for e in res.events):
        return "no end event"
    return None


def run_case(case: Case, interp: str, **kw: Any) -> RunResult:
    return run_program(case.program, interp, stimuli=case.stimuli, submit=case.submit,
                       max_sim_time=case.max_sim_time, workspace=case.path, **kw)


# ============================================================================ trace views
def flow_tokens(events: list[dict[str, Any]], case: Case | None = None, *,
                submit: bool = False) -> list[str]:
    """The control-flow view of a trace.

    With a case: only leaf-statement lines of the case's files, calls/returns of the case's
    routines, interrupt events; ``submit=True`` selects the submit context instead of the
    robot program (main, interrupt). Trigger actions are checked through their I/O.
    Without a case (tree vs VM): every stmt/call/return/interrupt event."""
    out: list[str] = []
    leaves: dict[str, set[int]] = {}
    routines: set[str] = set()
    sub_routines: set[str] = set()
    if case is not None:
        types = _user_types(case)
        for p in case.files():
            if p.suffix.lower() != ".dat":
                leaves[p.name.lower()] = leaf_lines(p, types)
        routines = case.routines() - {"PROGRAM"}   # the run's own top-level call is implied
        sub_routines = case.routines(suffix=".sub")
    pending_handler: str | None = None
    names: dict[str, str] = {}      # a stmt event's file -> its name in lower case, made once
    for ev in events:
        k = ev.get("kind")
        if k == "stmt":
            pending_handler = None
            ctx = ev.get("context") or "main"
            file = str(ev.get("file", ""))
            fname = names.get(file)
            if fname is None:
                fname = names[file] = Path(file).name.lower()
            if case is not None:
                if ctx == "trigger":
                    continue
                is_sub = ctx == "submit" or fname.endswith(".sub")
                if is_sub != submit:
                    continue
                if fname not in leaves or ev.get("line") not in leaves[fname]:
                    continue
                out.append(str(ev["line"]) if fname == "program.src" else f"{fname}:{ev['line']}")
            else:
                out.append(f"{ctx}:{fname}:{ev.get('line')}")
        elif k in ("call", "return"):
            name = str(ev.get("name", "")).upper()
            if case is not None:
                # call events carry no context: a routine of a .sub file belongs to the submit side
                if name not in routines or (name in sub_routines) != submit:
                    continue
                # the handler call that an interrupt entry implies is not a separate token
                if k == "call" and pending_handler == name:
                    pending_handler = None
                    continue
            pending_handler = None
            out.append(f"{k} {name}")
        elif k == "interrupt":
            if case is not None and submit:
                continue
            phase = ev.get("phase") or "entry"
            name = str(ev.get("name", "")).upper()
            if case is not None:
                if phase == "entry":
                    pending_handler = name
                elif out and out[-1] == f"return {name}":
                    out.pop()
            out.append(f"interrupt {ev.get('prio')} {phase}")
    return out


def expand_flow(spec: list[Any]) -> list[str]:
    """Expected flow: ints are lines of program.src; strings are "file.src:N", "call X",
    "return X", "interrupt N entry|exit"; ``{repeat: [...], times: n}`` repeats."""
    out: list[str] = []
    for item in spec or []:
        if isinstance(item, dict) and "repeat" in item:
            inner = expand_flow(item["repeat"])
            out.extend(inner * int(item.get("times", 1)))
        elif isinstance(item, int):
            out.append(str(item))
        else:
            s = str(item).strip()
            m = re.match(r"^(call|return)\s+(\w+)$", s, re.I)
            if m:
                out.append(f"{m.group(1).lower()} {m.group(2).upper()}")
            elif re.match(r"^interrupt\s+\d+$", s, re.I):
                out.append(s.lower() + " entry")
            elif s.lower().startswith("interrupt"):
                out.append(s.lower())
            else:
                out.append(s.lower() if ":" in s else s)
    return out


def io_events(events: list[dict[str, Any]], signals: list[str] | None = None,
              sources: tuple[str, ...] = ("program", "trigger", "pulse", None)) -> list[dict[str, Any]]:
    out = []
    pat = [s.upper().replace(" ", "") for s in signals] if signals else None
    for ev in events:
        if ev.get("kind") != "io":
            continue
        sig = str(ev.get("signal", "")).upper().replace(" ", "")
        if pat is not None:
            if not any(sig == p or (p.endswith("*") and sig.startswith(p[:-1])) for p in pat):
                continue
        elif ev.get("source") not in sources:
            continue
        out.append(ev)
    return out


def motion_times(events: list[dict[str, Any]]) -> dict[int, dict[str, Any]]:
    """motion id -> {phase: t, 'point': [...], 'approximation': ..., 'line': ...}; an exact stop
    has the phase ``reached`` too: when its interpolation reached the point (the ``end`` event,
    the controller's END signal, comes 24-36 ms later: robot/exactstop.py)."""
    out: dict[int, dict[str, Any]] = {}
    for ev in events:
        if ev.get("kind") != "motion":
            continue
        d = out.setdefault(int(ev["id"]), {})
        d.setdefault(ev["phase"], ev["t"])
        if ev.get("reached") is not None:
            d.setdefault("reached", ev["reached"])
        for k in ("point", "approximation", "line", "type"):
            if k in ev:
                d[k] = ev[k]
    return out


def poses(events: list[dict[str, Any]]) -> list[tuple[float, list[float]]]:
    return [(ev["t"], ev["tcp"]) for ev in events if ev.get("kind") == "pose"]


# ============================================================================ geometry
def _sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def _dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def _norm(a):
    return math.sqrt(_dot(a, a))


def dist_point_segment(p, a, b) -> float:
    ab = _sub(b, a)
    L2 = _dot(ab, ab)
    if L2 < 1e-12:
        return _norm(_sub(p, a))
    u = max(0.0, min(1.0, _dot(_sub(p, a), ab) / L2))
    q = [a[i] + u * ab[i] for i in range(3)]
    return _norm(_sub(p, q))


def _dedupe(pts: list[list[float]]) -> list[list[float]]:
    out: list[list[float]] = []
    for p in pts:
        if not out or _norm(_sub(p, out[-1])) > 1e-9:
            out.append(list(p[:3]))
    return out


def _dist_to_polyline(src: list[list[float]], dst: list[list[float]]) -> float:
    P = np.asarray(src, dtype=float)
    D = np.asarray(dst, dtype=float)
    if len(D) == 1:
        return float(np.max(np.linalg.norm(P - D[0], axis=1)))
    S0, d = D[:-1], D[1:] - D[:-1]
    L2 = np.maximum(np.einsum("ij,ij->i", d, d), 1e-18)
    worst = 0.0
    for k in range(0, len(P), 256):
        Q = P[k:k + 256, None, :] - S0[None, :, :]
        u = np.clip(np.einsum("nmj,mj->nm", Q, d) / L2, 0.0, 1.0)
        R = Q - u[..., None] * d[None, :, :]
        worst = max(worst, float(np.max(np.min(np.linalg.norm(R, axis=2), axis=1))))
    return worst


def polyline_deviation(pa: list[list[float]], pb: list[list[float]]) -> float:
    """Symmetric maximum distance from the vertices of one polyline to the other polyline
    (the Hausdorff distance of the two paths; standing still adds no vertices)."""
    A, B = _dedupe(pa), _dedupe(pb)
    if not A or not B:
        return 0.0 if not A and not B else math.inf
    return max(_dist_to_polyline(A, B), _dist_to_polyline(B, A))


def path_deviation(ea: list[dict[str, Any]], eb: list[dict[str, Any]]) -> tuple[float, str]:
    """TCP path difference of two traces: pointwise by time when both have the same pose
    times (then a time shift counts too), else the polyline (Hausdorff) distance."""
    pa, pb = poses(ea), poses(eb)
    if [t for t, _ in pa] == [t for t, _ in pb]:
        dev = max((_norm(_sub(a[:3], b[:3])) for (_, a), (_, b) in zip(pa, pb)), default=0.0)
        return dev, "pointwise at equal times"
    return polyline_deviation([p for _, p in pa], [p for _, p in pb]), \
        f"polyline distance (pose counts {len(pa)} vs {len(pb)})"


# ============================================================================ checks
@dataclass
class Check:
    name: str
    ok: bool
    detail: str = ""


@dataclass
class CaseResult:
    case: str
    interp: str
    checks: list[Check] = field(default_factory=list)
    crash: str | None = None
    pending: str | None = None
    wall_s: float = 0.0

    @property
    def passed(self) -> bool:
        return self.crash is None and all(c.ok for c in self.checks)

    def failures(self) -> list[Check]:
        return [c for c in self.checks if not c.ok]

    def diff_text(self) -> str:
        parts = []
        if self.crash:
            parts.append(f"[run] {self.crash}")
        for c in self.failures():
            parts.append(f"[{c.name}] {c.detail}")
        return "\n".join(parts)


def _diff(expected: list[str], actual: list[str], label: str) -> str:
    first = next((i for i, (a, b) in enumerate(zip(expected, actual)) if a != b),
                 min(len(expected), len(actual)))
    lines = list(difflib.unified_diff(expected, actual, f"expected {label}", f"actual {label}",
                                      lineterm="", n=3))
    if len(lines) > 80:
        lines = lines[:80] + [f"... ({len(lines) - 80} more diff lines)"]
    return (f"first difference at position {first} "
            f"(expected {expected[first] if first < len(expected) else '<end>'!r}, "
            f"got {actual[first] if first < len(actual) else '<end>'!r}); "
            f"lengths {len(expected)} vs {len(actual)}\n" + "\n".join(lines))


def _anchor_time(spec: dict[str, Any], mt: dict[int, dict[str, Any]]) -> float | None:
    after = spec.get("after")
    if after is None:
        return 0.0
    mid, phase = int(after["motion"]), after.get("phase", "end")
    return mt.get(mid, {}).get(phase)


def check_flow(case: Case, events: list[dict[str, Any]]) -> list[Check]:
    out = []
    for key, submit in (("flow", False), ("flow_submit", True)):
        if key not in case.expect:
            continue
        exp = expand_flow(case.expect[key])
        act = flow_tokens(events, case, submit=submit)
        ignore = [str(x).lower() for x in case.expect.get("flow_ignore", [])]
        if ignore:
            exp = [t for t in exp if not any(fnmatch.fnmatchcase(t.lower(), g) for g in ignore)]
            act = [t for t in act if not any(fnmatch.fnmatchcase(t.lower(), g) for g in ignore)]
        if key == "flow_submit" and case.expect.get("flow_submit_prefix", True):
            act = act[:len(exp)]  # the submit program loops until the robot program ends
        out.append(Check(key, exp == act, "" if exp == act else _diff(exp, act, key)))
    return out


def check_io(case: Case, events: list[dict[str, Any]]) -> list[Check]:
    if "io" not in case.expect:
        return []
    spec = case.expect["io"]
    # default: every output the program (or a trigger, a pulse) changes - an unexpected write fails
    signals = case.expect.get("io_signals") or ["$OUT*", "$ANOUT*"]
    act = io_events(events, signals)
    mt = motion_times(events)
    exp_tok = [f"{str(e['signal']).upper().replace(' ', '')}={_fmt(e['value'])}" for e in spec]
    act_tok = [f"{str(e['signal']).upper()}={_fmt(e['value'])}" for e in act]
    checks = []
    if exp_tok != act_tok:
        checks.append(Check("io.sequence", False, _diff(exp_tok, act_tok, "io")))
        return checks
    bad = []
    for i, (e, a) in enumerate(zip(spec, act)):
        if "between" in e:
            lo = _anchor_time({"after": e["between"][0]}, mt)
            hi = _anchor_time({"after": e["between"][1]}, mt)
            if lo is None or hi is None or not (lo - TIME_TOL <= a["t"] <= hi + TIME_TOL):
                bad.append(f"#{i} {exp_tok[i]}: expected between {e['between'][0]} ({lo}) and "
                           f"{e['between'][1]} ({hi}), got t={a['t']:.3f}")
            continue
        if "t" not in e and "dt" not in e:
            continue
        if isinstance(e.get("after"), dict) and "io" in e["after"]:
            k = int(e["after"]["io"])
            base = act[k]["t"] if 0 <= k < len(act) else None
        else:
            base = _anchor_time(e, mt)
        if base is None:
            bad.append(f"#{i} {exp_tok[i]}: anchor {e.get('after')} not in the trace")
            continue
        want = base + float(e.get("t", e.get("dt", 0.0)))
        tol = float(e.get("tol", TIME_TOL))
        if abs(a["t"] - want) > tol:
            anchor = f" (= {e['after']} at {base:.3f} + {e.get('t', e.get('dt'))})" if e.get("after") else ""
            bad.append(f"#{i} {exp_tok[i]}: expected t={want:.3f}{anchor} ±{tol:.3f}, got t={a['t']:.3f}")
    checks.append(Check("io.timing", not bad, "; ".join(bad)))
    return checks


def _fmt(v: Any) -> str:
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, (int, float)):
        return f"{float(v):.3f}"
    return str(v)


def check_end(case: Case, events: list[dict[str, Any]]) -> list[Check]:
    exp = case.expect.get("end")
    if exp is None:
        return []
    ends = [e for e in events if e.get("kind") == "end"]
    if not ends:
        return [Check("end", False, "no end event in the trace")]
    e = ends[-1]
    bad = []
    for k, v in exp.items():
        got = e.get(k)
        if k == "reason":
            ok = str(got).lower() in [str(x).lower() for x in (v if isinstance(v, list) else [v])]
        elif k == "t":
            ok = got is not None and abs(float(got) - float(v)) <= TIME_TOL
        elif k == "text_contains":
            ok = str(v).lower() in str(e.get("text", "")).lower()
        elif k == "file":
            ok = Path(str(got)).name.lower() == str(v).lower()
        else:
            ok = got == v
        if not ok:
            bad.append(f"{k}: expected {v!r}, got {got if k != 'text_contains' else e.get('text')!r}")
    return [Check("end", not bad, "; ".join(bad) + f"  (end event: {e})" if bad else "")]


def check_errors(case: Case, events: list[dict[str, Any]]) -> list[Check]:
    if "errors" not in case.expect:
        return []
    act = [e for e in events if e.get("kind") == "error"]
    exp = case.expect["errors"]
    bad = []
    if len(act) != len(exp):
        bad.append(f"expected {len(exp)} error event(s), got {len(act)}: {act}")
    for i, (e, a) in enumerate(zip(exp, act)):
        for k, v in e.items():
            if k == "text_contains":
                if str(v).lower() not in str(a.get("text", "")).lower():
                    bad.append(f"error #{i}: text {a.get('text')!r} lacks {v!r}")
            elif a.get(k) != v:
                bad.append(f"error #{i}: {k} expected {v!r}, got {a.get(k)!r}")
    return [Check("errors", not bad, "; ".join(bad))]


def check_messages(case: Case, events: list[dict[str, Any]]) -> list[Check]:
    if "messages" not in case.expect:
        return []
    act = [(e.get("text"), e.get("id")) for e in events if e.get("kind") == "message"]
    exp = [(m["text"], m.get("id")) for m in case.expect["messages"]]
    act_cmp = [(t, i if any(x[1] is not None for x in exp) else None) for t, i in act]
    ok = [f"{t}@{i}" for t, i in exp] == [f"{t}@{i}" for t, i in act_cmp]
    return [Check("messages", ok, "" if ok else _diff([f"{t}@{i}" for t, i in exp],
                                                       [f"{t}@{i}" for t, i in act_cmp], "messages"))]


def _window(mt, mid, which="body"):
    """Time window of motion ``mid`` outside its blends: (t0, t1)."""
    d = mt.get(mid, {})
    prev = mt.get(mid - 1, {})
    t0 = prev.get("blend_end", d.get("start"))
    if "blend_end" not in prev:
        t0 = d.get("start")
    t1 = d.get("blend_start", d.get("end"))
    if t1 is None:  # abandoned (RESUME) or cut by an error: up to the next motion / the trace end
        t1 = mt.get(mid + 1, {}).get("start", math.inf)
    return t0, t1


def _pts(ps, t0, t1):
    return [p[:3] for t, p in ps if t0 - 1e-9 <= t <= t1 + 1e-9]


def _pose_at(ps, t):
    best = min(ps, key=lambda tp: abs(tp[0] - t)) if ps else None
    return best[1][:3] if best else None


def _start_point(mt, ps, mid):
    prev = mt.get(mid - 1, {})
    if "point" in prev:
        return prev["point"][:3]
    t = mt.get(mid, {}).get("start")
    if t is None:
        return None
    before = [p for p in ps if p[0] < t - 1e-9]
    return (before[-1][1][:3] if before else _pose_at(ps, t))


def check_motion(case: Case, events: list[dict[str, Any]]) -> list[Check]:
    specs = case.expect.get("motion") or []
    if not specs:
        return []
    mt = motion_times(events)
    ps = poses(events)
    checks = []
    for spec in specs:
        kind = spec["check"]
        mid = int(spec.get("id", 0))
        name = f"motion.{kind}#{mid}"
        d = mt.get(mid)
        if d is None and kind != "count":
            checks.append(Check(name, False, f"motion {mid} not in the trace (motions: {sorted(mt)})"))
            continue
        try:
            ok, detail = _MOTION_CHECKS[kind](spec, mid, mt, ps)
        except Exception as exc:  # noqa: BLE001 - a malformed trace counts as a failure
            ok, detail = False, f"cannot evaluate: {type(exc).__name__}: {exc}"
        checks.append(Check(name, ok, detail))
    return checks


def _c_count(spec, mid, mt, ps):
    n = len(mt)
    return n == int(spec["n"]), f"expected {spec['n']} motions, got {n}"


def _c_straight(spec, mid, mt, ps):
    tol = float(spec.get("tol_mm", 0.01))
    a = _start_point(mt, ps, mid)
    b = mt[mid]["point"][:3]
    t0, t1 = _window(mt, mid)
    pts = _pts(ps, t0, t1)
    if not pts:
        return False, "no poses in the motion's window"
    dev = max(dist_point_segment(p, a, b) for p in pts)
    return dev <= tol, f"max distance from the line {a}->{b}: {dev:.4f} mm (tol {tol})"


def _c_circle(spec, mid, mt, ps):
    tol = float(spec.get("tol_mm", 0.01))
    c, r = spec["center"], float(spec["radius"])
    t0, t1 = _window(mt, mid)
    pts = _pts(ps, t0, t1)
    if not pts:
        return False, "no poses in the motion's window"
    dev = max(abs(_norm(_sub(p, c)) - r) for p in pts)
    ok = dev <= tol
    if "normal" in spec:
        n = spec["normal"]
        nn = _norm(n)
        pl = max(abs(_dot(_sub(p, c), n) / nn) for p in pts)
        ok = ok and pl <= tol
        return ok, f"radius deviation {dev:.4f} mm, off-plane {pl:.4f} mm (tol {tol})"
    return ok, f"max |dist to {c} - {r}|: {dev:.4f} mm (tol {tol})"


def _c_reaches(spec, mid, mt, ps):
    tol = float(spec.get("tol_mm", 0.1))
    t = mt[mid].get("end")
    p = _pose_at(ps, t)
    want = spec.get("point") or mt[mid]["point"][:3]
    dd = _norm(_sub(p, want[:3]))
    return dd <= tol, f"TCP at end of motion {mid}: {[round(x, 3) for x in p]}, expected {want[:3]}, distance {dd:.4f} mm"


def _c_exact(spec, mid, mt, ps):
    d = mt[mid]
    if "blend_start" in d:
        return False, f"motion {mid} was approximated (blend_start at {d['blend_start']}), expected an exact stop"
    tol = float(spec.get("tol_mm", 0.1))
    p = _pose_at(ps, d["end"])
    dd = _norm(_sub(p, d["point"][:3]))
    return dd <= tol, f"exact stop; TCP at the end {dd:.4f} mm from the point"


def _c_blend(spec, mid, mt, ps):
    d = mt[mid]
    if "blend_start" not in d:
        return False, f"motion {mid} was not approximated (phases {sorted(k for k in d if k in ('start', 'blend_start', 'blend_end', 'end'))})"
    corner = d["point"][:3]
    tol = float(spec.get("tol_mm", 0.5))
    msgs, ok = [], True
    ds = _norm(_sub(_pose_at(ps, d["blend_start"]), corner))
    de = _norm(_sub(_pose_at(ps, d["blend_end"]), corner))
    inside = _pts(ps, d["blend_start"], d["blend_end"])
    dmax = max((_norm(_sub(p, corner)) for p in inside), default=0.0)
    dmin = min((_norm(_sub(p, corner)) for p in inside), default=0.0)
    if "start_mm" in spec:
        good = abs(ds - float(spec["start_mm"])) <= tol
        ok &= good
        msgs.append(f"blend starts {ds:.3f} mm before the point (expected {spec['start_mm']} ±{tol})")
    if "end_mm" in spec:
        good = abs(de - float(spec["end_mm"])) <= tol
        ok &= good
        msgs.append(f"blend ends {de:.3f} mm after the point (expected {spec['end_mm']} ±{tol})")
    if "zone_mm" in spec:
        good = dmax <= float(spec["zone_mm"]) + tol
        ok &= good
        msgs.append(f"max distance from the point inside the blend {dmax:.3f} mm (zone {spec['zone_mm']})")
    if spec.get("cuts_corner", True):
        good = dmin > float(spec.get("min_cut_mm", 0.05))
        ok &= good
        msgs.append(f"closest approach to the point {dmin:.3f} mm")
    return ok, "; ".join(msgs)


def _c_duration(spec, mid, mt, ps):
    """The time of motion ``id`` from its start to when its interpolation reached the point (an
    exact stop), else to its end: the planned duration; ``from``/``to`` name other phases."""
    d = mt[mid]
    frm = spec.get("from", "start")
    to = spec.get("to", "reached" if "reached" in d else "end")
    if frm not in d or to not in d:
        return False, f"phases {frm}/{to} missing: {d}"
    dur = d[to] - d[frm]
    if "min_seconds" in spec:
        return dur >= float(spec["min_seconds"]) - TIME_TOL, \
            f"{frm}->{to} took {dur:.3f} s, expected at least {spec['min_seconds']}"
    tol = float(spec.get("tol", TIME_TOL))
    return abs(dur - float(spec["seconds"])) <= tol, \
        f"{frm}->{to} took {dur:.3f} s, expected {spec['seconds']} ±{tol:.3f}"


def _c_gap(spec, mid, mt, ps):
    """Time from the end of motion ``id`` to the start of motion ``id+1``."""
    a, b = mt[mid].get("end"), mt.get(mid + 1, {}).get("start")
    if a is None or b is None:
        return False, "missing end/start"
    gap = b - a
    tol = float(spec.get("tol", TIME_TOL))
    return abs(gap - float(spec["seconds"])) <= tol, f"gap {gap:.3f} s, expected {spec['seconds']} ±{tol:.3f}"


def _c_approx(spec, mid, mt, ps):
    got = mt[mid].get("approximation")
    return got == spec["value"], f"approximation {got!r}, expected {spec['value']!r}"


def _c_point(spec, mid, mt, ps):
    got = mt[mid].get("point")
    want = spec["point"]
    tol = float(spec.get("tol_mm", 0.01))
    dd = _norm(_sub(got[:3], want[:3]))
    return dd <= tol, f"programmed point {got}, expected {want}"


def _c_passes(spec, mid, mt, ps):
    """The TCP passes within tol of each given point during motion ``id``."""
    tol = float(spec.get("tol_mm", 0.5))
    d = mt[mid]
    pts = _pts(ps, d["start"], d["end"])
    worst = 0.0
    for q in spec["points"]:
        best = min((_norm(_sub(p, q)) for p in pts), default=math.inf)
        worst = max(worst, best)
    return worst <= tol, f"worst closest approach {worst:.3f} mm (tol {tol})"


def _c_stops_before(spec, mid, mt, ps):
    """The robot never gets closer than ``min_mm`` to the programmed point of motion ``id``
    (it was braked and the motion abandoned)."""
    target = mt[mid]["point"][:3]
    closest = min((_norm(_sub(p[:3], target)) for _, p in ps), default=math.inf)
    return closest >= float(spec.get("min_mm", 1.0)), \
        f"closest approach to the point of motion {mid}: {closest:.3f} mm (must stay >= {spec.get('min_mm', 1.0)})"


def _c_standstill(spec, mid, mt, ps):
    """The robot stands still during motion ``id`` (BRAKE without RESUME) at least
    ``min_mm`` away from both its start and its end point, and the motion then goes on."""
    d = mt[mid]
    a, b = _start_point(mt, ps, mid), d["point"][:3]
    t0, t1 = d["start"], d.get("end", math.inf)
    seg = [(t, p[:3]) for t, p in ps if t0 <= t <= t1]
    far = float(spec.get("min_mm", 5.0))
    still = [seg[k][0] for k in range(1, len(seg))
             if _norm(_sub(seg[k][1], seg[k - 1][1])) < 1e-6
             and _norm(_sub(seg[k][1], a)) > far and _norm(_sub(seg[k][1], b)) > far]
    return bool(still), (f"standing still at t={still[0]:.3f}..{still[-1]:.3f} s" if still
                         else f"no standstill inside motion {mid} (more than {far} mm from its ends)")


def _stands(ps, t0, t1, dt=IPO):
    """(from, to, position) of each stretch between t0 and t1 in which the TCP stands still:
    consecutive poses at one position, or a gap in the poses (a bounded trace writes a
    standstill as repeat events, robot/trace.py): there the TCP stood where the pose before the
    gap was until a cycle before the next pose."""
    seg = [(t, p[:3]) for t, p in ps if t0 - 1e-9 <= t <= t1 + 1e-9]
    spans = []
    for (ta, pa), (tb, pb) in zip(seg, seg[1:]):
        if _norm(_sub(pa, pb)) < 1e-6:
            spans.append((ta, tb, pa))
        elif tb - ta > 1.5 * dt:
            spans.append((ta, tb - dt, pa))
    out: list = []
    for a, b, p in spans:
        if out and abs(out[-1][1] - a) < 1e-9 and _norm(_sub(out[-1][2], p)) < 1e-6:
            out[-1] = (out[-1][0], b, p)
        else:
            out.append((a, b, p))
    return out


def _c_stops_at(spec, mid, mt, ps):
    """A conditional stop (STOP WHEN PATH): during motion ``id`` the TCP stands within
    ``tol_mm`` of ``point`` for at least ``min_seconds`` (its longest standstill), and stands
    nowhere else inside the motion (its end point aside); ``point: null``: it stands nowhere
    inside the motion (the condition did not hold at the braking point)."""
    d = mt[mid]
    t0, t1 = d["start"], d.get("end", math.inf)
    want = spec.get("point")
    tol = float(spec.get("tol_mm", 1.2))
    ends = [_start_point(mt, ps, mid), d["point"][:3]]
    # standing at the motion's own start or end point is no stop of its own, unless it is the one expected
    stands = [(a, b, p) for a, b, p in _stands(ps, t0, t1)
              if not any(e is not None and _norm(_sub(p, e)) < 1e-3 for e in ends)
              or (want is not None and _norm(_sub(p, want)) <= tol)]
    if want is None:
        return not stands, ("no standstill inside the motion" if not stands else
                            f"stands at {[round(float(x), 3) for x in stands[0][2]]} from t={stands[0][0]:.3f} s")
    elsewhere = [s for s in stands if _norm(_sub(s[2], want)) > tol]
    here = [s for s in stands if _norm(_sub(s[2], want)) <= tol]
    longest = max((b - a for a, b, _p in here), default=0.0)
    ok = not elsewhere and longest >= float(spec.get("min_seconds", 0.0)) - TIME_TOL
    where = ", ".join(f"{[round(float(x), 3) for x in p]} {a:.3f}..{b:.3f} s" for a, b, p in stands) or "none"
    return ok, f"standstills: {where}; expected at {want} (±{tol} mm) for at least {spec.get('min_seconds', 0)} s"


_MOTION_CHECKS = {
    "standstill": _c_standstill,
    "stops_at": _c_stops_at,
    "count": _c_count, "straight": _c_straight, "circle": _c_circle, "reaches": _c_reaches,
    "exact_stop": _c_exact, "blend": _c_blend, "duration": _c_duration, "gap": _c_gap,
    "approximation": _c_approx, "point": _c_point, "passes": _c_passes,
    "stops_before": _c_stops_before,
}


def check_limits(events: list[dict[str, Any]]) -> list[Check]:
    """The motion-limits property of issue 15 on a trace (robot/limits.py ``check_trace``):
    path speed <= $VEL.CP·$OV_PRO, axes <= their programmed/machine speed (3 %), axis
    accelerations <= machine data (10 %, finite differences), T1 250 mm/s."""
    if not any(e.get("kind") == "pose" for e in events):
        return []

    rep = check_trace(events)
    return [Check("limits", rep.ok, "" if rep.ok else rep.summary() + ": "
                  + "; ".join(str(v) for v in rep.violations[:5]))]


def check_case(case: Case, res: RunResult) -> CaseResult:
    cr = CaseResult(case.name, res.interp, crash=res.crash, pending=case.pending_for(res.interp),
                    wall_s=res.wall_s)
    if res.crash is not None:
        return cr
    ev = res.events
    if case.expect.get("fuzz"):
        # a program saved by the fuzzer: it must run without an internal error (tree == vm is
        # checked by compare_runs when both interpreters exist)
        prob = clean_run_problem(res)
        cr.checks.append(Check("runs_cleanly", prob is None, prob or ""))
    cr.checks += check_end(case, ev)
    cr.checks += check_flow(case, ev)
    cr.checks += check_io(case, ev)
    cr.checks += check_errors(case, ev)
    cr.checks += check_messages(case, ev)
    cr.checks += check_motion(case, ev)
    cr.checks += check_limits(ev)
    if "exit_code" in case.expect:
        want = case.expect["exit_code"]
        cr.checks.append(Check("exit_code", res.exit_code == want,
                               f"expected exit code {want}, got {res.exit_code}"))
    if not cr.checks:
        cr.checks.append(Check("expectations", False, "expect.yaml checks nothing"))
    return cr


# ============================================================================ tree vs vm
def compare_runs(a: RunResult, b: RunResult, path_tol_mm: float = 1e-6) -> list[Check]:
    """Tree vs VM: control flow and I/O exactly (with times), end event, TCP polylines."""
    checks = []
    if a.crash or b.crash:
        return [Check("run", False, f"{a.interp}: {a.crash or 'ok'}; {b.interp}: {b.crash or 'ok'}")]
    fa, fb = flow_tokens(a.events), flow_tokens(b.events)
    checks.append(Check("tree_vm.flow", fa == fb, "" if fa == fb else _diff(fa, fb, "flow")))

    def tio(evs):
        return [f"{e['t']:.6f} {e['signal']}={_fmt(e['value'])} ({e.get('source')})"
                for e in evs if e.get("kind") == "io"]
    ia, ib = tio(a.events), tio(b.events)
    checks.append(Check("tree_vm.io", ia == ib, "" if ia == ib else _diff(ia, ib, "io")))

    def other(evs):
        return [json.dumps({k: (Path(str(v)).name if k == "file" else v) for k, v in e.items()}, sort_keys=True)
                for e in evs if e.get("kind") in ("motion", "message", "error", "end", "trigger")]
    oa, ob = other(a.events), other(b.events)
    checks.append(Check("tree_vm.events", oa == ob, "" if oa == ob else _diff(oa, ob, "motion/message/error/end")))
    dev, how = path_deviation(a.events, b.events)
    checks.append(Check("tree_vm.path", dev <= path_tol_mm,
                        f"max TCP path deviation {dev:.6f} mm, {how} (tol {path_tol_mm})"))
    return checks


__all__ = ["Case", "CaseResult", "Check", "RunResult", "load_case", "load_cases", "run_case",
           "run_program", "check_case", "compare_runs", "interpreter_status",
           "available_interpreters", "flow_tokens", "expand_flow", "leaf_lines", "CASES_DIR"]
