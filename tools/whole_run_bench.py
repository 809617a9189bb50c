"""Whole runs as the unit of speed (issue 48): every entry point of the corpus backups with
``--inputs auto`` for 600 s of simulated time, simulated seconds per CPU second for each and
for the total, side by side with a baseline checkout in one run.

Each entry point (interp/realprograms.py ``entries_of``: module mains, cell.src, each backup's
SPS.SUB) runs as the real-programs report's ``--inputs auto`` column runs it (``report_run``:
the robot of the backup or the library robot that reaches its points, the backup's SPS.SUB
beside it, ``--no-check``, the report's step limit for the time), except that every entry point,
an SPS.SUB too, gets the same simulated time (``--sim-time``, default 600 s). No trace is
written, and the controller is observed as ``krl run`` observes it for its summary
(interp/summary.py ``RunObserver``): the figure is what a user waits for when a whole cell runs.
(Until 2026-11-25 the bench ran without the observer, and the observer stopped the spin watch:
the bench measured a run no user got; docs/architecture.md, "Spins cost nothing".)

One worker process per checkout (``PYTHONPATH=CHECKOUT`` on this interpreter: the checkouts must
share this venv's dependencies and each needs its generated parser and compiled VM loop, as for
tools/trace_identity.py) runs the entry points one at a time when the driver asks, so imports are
paid once (each worker makes one short untimed run first: the process's one-time costs) and the
two checkouts alternate program by program (the first to run alternates too): both see the same
load. Each run measures, in its worker, the CPU time (``time.process_time``)
of making the runtime (reading the backup, and a cell file once, as ``krl run`` reads it: until
2026-11-29 the bench read it twice, for the report's robot and for the run; ``setup_s``) and of
the run (``run_s``); ``cpu_s`` is
their sum, the figure is ``sim_s / cpu_s``. Each run also gives a digest of every I/O change of
the run (time, signal, value, source: robot/io.py ``IOImage.log``), the end (reason, simulated
time, steps), the answers of the automatic cell and the idle time skipped, so two checkouts that
should agree can be seen to.

Usage::

    python tools/whole_run_bench.py [--baseline CHECKOUT] [--sim-time 600] [--interp vm|tree]
                                    [--only SUBSTRING] [--skip N] [--limit N] [--json OUT] [--corpus DIR]
                                    [--collision] [--cells [--trace-identity]]
                                    [--history --corpus ../shared/krl-history] [--baseline-spins off|shadow]

``--cells`` (issue 86) measures the cells whose robot moves, not every entry point: the corpus
palletizer's cell program (ingeniado__KRC4-Robot-Palletizer ``main.src``, ``DEF CELL``, with
``--inputs auto``, the corpus's one palletizing backup; its three other palletizing repositories
are loose hand-written files that stop at t=0, Bugaj32's main.src on E014, paulovictor237's
KUKA-Paletizador MainProgram.src and KUKA-Script My_Job.src each on a name no file declares:
:data:`CORPUS_STOPPED`, each run once and printed with its end below the table, not timed) and
the five-axis palletizer written from issue 86's description
(examples/palletizer5: ``R1/cell.src`` with its ``cell.yaml``: its robot, its PLC), each with
its SPS.SUB beside it, for ``--sim-time`` (default 120 s with ``--cells``). A row also gives the
motions the run started (the ``motion`` events, interp/summary.py ``RunObserver``); two checkouts
agree when the I/O digest, the end, the simulated time and the motions are the same.
``--trace-identity`` makes each worker run each program once more, untimed, with the trace
``krl run --trace`` writes (robot/trace.py ``TraceWriter``, its default spin bound), hashed with
the checkout's own path written ``<ROOT>``: where the ends agree, the traces must be identical.

``--history`` (issue 86): ``--corpus`` is ../shared/krl-history, and the programs are the entry
points of both sides of every pair (interp/realprograms.py ``history_entries``: each side's
backups' entry points, then its programs outside a backup), not only its backups'.
``--baseline-spins off`` (or ``shadow``) runs the baseline side with the spin watch off (or
shadowing: RunSpec ``spins``), the measured side parking as ``krl run`` does: with ``--baseline``
naming the same checkout, the evidence that parking (its replays too, which a traced run never
makes) changes no run's I/O, end or motions. Each row prints the measured side's I/O digest; the
JSON rows hold each side's ``parks`` (the spin watch's parks: 0 with it off).

``--collision`` makes the measured side check collisions at every IPO cycle (robot/collision.py: the
robot's links against each other: MuJoCo's contacts over the same geoms a cell adds to; with
``--baseline`` naming the same checkout the ratio is the cost of checking (issue 64).

Prints one row per entry point (CPU s and simulated s per CPU s of each checkout, the ratio,
whether the I/O digests and ends agree) and the totals; ``--json`` writes the rows and the
summary (date, commits, load average at the start and the end). ``make nightly`` runs it without
a baseline (``whole-runs.json``), and the nightly's history keeps the totals
(conformance/nightly/figures.py). Exit status 0, 2 on bad usage or when a worker dies.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent
CORPUS = HERE.parent / "shared" / "krl-corpus"
SIM_TIME_S = 600.0
#: ``--cells``: the simulated time of each run (s)
CELLS_SIM_TIME_S = 120.0
#: ``--cells``: the corpus's moving palletizer cells, relative to the corpus (``--inputs auto``)
CORPUS_CELLS = ("ingeniado__KRC4-Robot-Palletizer/main.src",)
#: ``--cells``: the corpus's other palletizing programs, which stop at t=0 (module docstring): run
#: once by the measured checkout and reported with their end, not timed
CORPUS_STOPPED = ("Bugaj32__KUKA-pick-and-place-palletizing/main.src",
                  "paulovictor237__KUKA-Paletizador/Script_Code/MainProgram.src",
                  "paulovictor237__KUKA-Script/file_in/My_Job.src")
#: ``--cells``: the cells of the repository, with their cell files (program, cell file)
EXAMPLE_CELLS = ((HERE / "examples" / "palletizer5" / "R1" / "cell.src", HERE / "examples" / "palletizer5" / "cell.yaml"),)


class _HashSink:
    """A text sink for TraceWriter: the sha256 and the lines of what is written, with `root`
    (the checkout's path) written ``<ROOT>`` (as tools/trace_identity.py does) and `cell` (the
    folder of the cell file, which may lie in either checkout) ``<CELL>``."""

    def __init__(self, root: str, cell: str | None = None) -> None:
        self.sha = hashlib.sha256()
        self.lines = 0
        self.root = root
        self.cell = cell

    def write(self, text: str) -> int:
        if self.cell:
            text = text.replace(self.cell, "<CELL>")
        data = text.replace(self.root, "<ROOT>").encode("utf-8")
        self.sha.update(data)
        self.lines += data.count(b"\n")
        return len(text)

    def flush(self) -> None:
        pass

    def close(self) -> None:
        pass


# ---------------------------------------------------------------------------- the worker
def _run_one(program: Path, sim_time: float, interp: str, collision: bool = False, cell: Path | None = None,
             trace: str | None = None, spins: str | None = None) -> dict:
    """One whole run of `program` with ``--inputs auto`` or with the cell file `cell` (module
    docstring), measured in this process (the checkout first on sys.path); `collision`: with the
    robot's collision check against itself (robot/collision.py: a cell file's ``floor: false``;
    the corpus cells' floors are not known, the palletizer works below its base); `trace` (the
    checkout's root): the run writes ``krl run``'s trace into a hash (``trace_sha``,
    ``trace_lines``); `spins`: the spin watch's mode (RunSpec ``spins``; None: the run's default,
    parking)."""
    from interp.realprograms import REPORT_STEPS, report_run, step_limit  # noqa: PLC0415  (once sys.path names the checkout measured)
    from interp.run import make_runtime  # noqa: PLC0415  (once sys.path names the checkout measured)
    try:
        from interp.run import run_spec  # noqa: PLC0415  (once sys.path names the checkout measured)
    except ImportError:     # a checkout before the run specification (issue 62): keywords
        run_spec = None
    try:
        from interp.run import RunSinks  # noqa: PLC0415  (once sys.path names the checkout measured)
    except ImportError:     # a checkout whose spec held the sinks (before issue 76): keywords of run_spec
        RunSinks = None
    from interp.runtime.scheduler import SUBMIT_BUDGET  # noqa: PLC0415  (once sys.path names the checkout measured)
    from interp.summary import RunObserver  # noqa: PLC0415  (once sys.path names the checkout measured)

    # the one loader of a cell file (a checkout before it: the path, read where used)
    cell_of = getattr(sys.modules["interp.run"], "cell_of", str)

    sub = program.suffix.lower() == ".sub"
    row: dict = {"program": str(program), "interp": interp}
    c0 = time.process_time()
    try:
        inputs = "auto" if cell is None else cell_of(str(cell))    # read once, as krl run reads it
        robot, submit, _t, _steps = report_run(program, None if cell is None else inputs, sim_time, REPORT_STEPS,
                                               auto=cell is None)
        steps = step_limit(REPORT_STEPS, sim_time, len(submit) + sub, robot.ipo_cycle_s)
        kw = dict(mujoco=False, max_sim_time=sim_time, max_steps=steps, submit=submit, check=False,
                  inputs=inputs, robot=robot, interp=interp,
                  robot_budget=SUBMIT_BUDGET if sub else None)
        if spins is not None:
            kw["spins"] = spins
        hashed = None
        if trace is not None:
            from robot.trace import TRACE_REPEATS, TraceWriter  # noqa: PLC0415  (once sys.path names the checkout measured)

            hashed = _HashSink(trace, cell and str(cell.resolve().parent))
            tw = TraceWriter(hashed, repeats=TRACE_REPEATS)
            sinks = dict(trace=tw, observer=RunObserver(inner=tw))
        else:
            sinks = dict(observer=RunObserver())
        geometry = None
        if collision:
            from robot.collision import CellGeometry, CollisionChecker  # noqa: PLC0415  (once sys.path names the checkout measured)

            geometry = CellGeometry(floor=None)
        if RunSinks is not None:
            rt, _ = make_runtime(run_spec(program, **kw, **({"geometry": geometry} if collision else {})),
                                 RunSinks(**sinks))
        elif run_spec is not None:
            rt, _ = make_runtime(run_spec(program, **kw, **sinks, **({"geometry": geometry} if collision else {})))
        else:
            rt, _ = make_runtime(program, **kw, **sinks)
            if collision:       # a checkout before the run specification: the checker set on its controller
                rt.controller.collision = CollisionChecker(robot, geometry)
        c1 = time.process_time()
        res = rt.run()
        c2 = time.process_time()
    except Exception as exc:  # noqa: BLE001 - the row says so; the other programs go on
        row.update(reason="exception", text=f"{type(exc).__name__}: {exc}",
                   setup_s=0.0, run_s=round(time.process_time() - c0, 3), cpu_s=round(time.process_time() - c0, 3),
                   sim_s=0.0, steps=0, io_events=0, io_sha="", answers=0, idle_s=0.0)
        return row
    io = rt.controller.io.log
    digest = hashlib.sha256()
    for t, name, value, source in io:
        digest.update(f"{t:.6f} {name} {value!r} {source}\n".encode())
    if hashed is not None:
        sinks["trace"].close()
        row.update(trace_sha=hashed.sha.hexdigest()[:16], trace_lines=hashed.lines)
    row.update(motions=len(sinks["observer"].motion_types), parks=getattr(rt.ff.spin, "parks", None))
    row.update(reason=res.reason, sim_s=round(res.sim_time, 6), steps=res.steps,
               setup_s=round(c1 - c0, 3), run_s=round(c2 - c1, 3), cpu_s=round(c2 - c0, 3),
               io_events=len(io), io_sha=digest.hexdigest()[:16],
               answers=len(rt.autocell.answers) if rt.autocell is not None else 0,
               idle_s=round(rt.ff.idle.skipped * rt.controller.dt, 3),
               end=[res.reason, res.file and Path(str(res.file)).name, res.line])
    return row


def worker(checkout: Path) -> int:
    """Serve runs for the driver: one JSON request per line on stdin (``{"program", "sim_time",
    "interp"}``), one JSON row per line on stdout."""
    checkout = checkout.resolve()
    sys.path.insert(0, str(checkout))
    import interp  # noqa: PLC0415  (once sys.path names the checkout measured)

    if Path(interp.__file__).resolve().parent.parent != checkout:
        print(json.dumps({"fatal": f"interp comes from {interp.__file__}, not {checkout}"}), flush=True)
        return 2
    out = sys.stdout
    sys.stdout = sys.stderr         # anything a run prints must not break the protocol
    print(json.dumps({"ready": str(checkout)}), file=out, flush=True)
    for line in sys.stdin:
        if not line.strip():
            continue
        req = json.loads(line)
        cell = Path(req["cell"]) if req.get("cell") else None
        row = _run_one(Path(req["program"]), float(req["sim_time"]), req["interp"], bool(req.get("collision")),
                       cell, str(checkout) if req.get("trace") else None, req.get("spins"))
        print(json.dumps(row), file=out, flush=True)
    return 0


# ---------------------------------------------------------------------------- the driver
class Worker:
    """A worker process of one checkout (module docstring)."""

    def __init__(self, checkout: Path, collision: bool = False, spins: str | None = None) -> None:
        self.checkout = checkout.resolve()
        self.collision = collision
        self.spins = spins
        env = dict(os.environ, PYTHONPATH=str(self.checkout))
        self.proc = subprocess.Popen([sys.executable, str(Path(__file__).resolve()), "worker", str(self.checkout)],
                                     cwd=self.checkout, env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     text=True)
        first = json.loads(self._line())
        if "ready" not in first:
            raise SystemExit(f"error: worker of {self.checkout}: {first.get('fatal', first)}")

    def _line(self) -> str:
        line = self.proc.stdout.readline()
        if not line:
            raise SystemExit(f"error: the worker of {self.checkout} ended (exit {self.proc.wait()})")
        return line

    def run(self, program: Path, sim_time: float, interp: str, cell: Path | None = None, trace: bool = False) -> dict:
        self.proc.stdin.write(json.dumps({"program": str(program), "sim_time": sim_time, "interp": interp,
                                          "collision": self.collision, "cell": cell and str(cell),
                                          "trace": trace, "spins": self.spins}) + "\n")
        self.proc.stdin.flush()
        return json.loads(self._line())

    def close(self) -> None:
        self.proc.stdin.close()
        self.proc.wait()


def commit_of(checkout: Path) -> str:
    res = subprocess.run(["git", "-C", str(checkout), "rev-parse", "--short", "HEAD"], capture_output=True,
                         text=True, check=False)
    dirty = subprocess.run(["git", "-C", str(checkout), "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True, check=False).stdout.strip()
    return (res.stdout.strip() or "?") + ("+" if dirty else "")


def entry_points(corpus: Path, history: bool = False, only: str | None = None) -> list[Path]:
    """The entry points of every backup under `corpus` (interp/realprograms.py ``entries_of``);
    `history` (``--history``): `corpus` is ../shared/krl-history, the entry points of both sides
    of every pair (``history_entries``). `only` (``--only``): of the corpus's backups, only those
    with a file whose path contains it are listed (an entry point is a file of its backup, so
    the entry points whose path contains it are all there; listing a backup's entry points
    parses its programs: the four backups of the corpus for the one of ``--only``, 2026-11-29)."""
    from interp.realprograms import entries_of, find_backups, history_entries  # noqa: PLC0415  (once sys.path names the checkout measured)

    if history:
        return history_entries(corpus, ("old", "new"))
    return [p for root in find_backups(corpus) if only is None or _holds(root, only) for p in entries_of(root)]


def _holds(root: Path, part: str) -> bool:
    """True when the path of `root` or of a file below it contains `part`."""
    return part in str(root) or any(part in str(f) for f in root.rglob("*"))


def cell_programs(corpus: Path) -> list[tuple[Path, Path | None]]:
    """``--cells``: (program, cell file or None for ``--inputs auto``) of the moving palletizer
    cells (module docstring): :data:`CORPUS_CELLS` found under `corpus`, then :data:`EXAMPLE_CELLS`."""
    return [(corpus / rel, None) for rel in CORPUS_CELLS if (corpus / rel).is_file()] + list(EXAMPLE_CELLS)


def display_name(program: Path, corpus: Path) -> str:
    """`program` relative to the corpus, or to the repository (an example cell)."""
    for root in (corpus, HERE):
        if program.is_relative_to(root):
            return str(program.relative_to(root))
    return str(program)


def factor(sim: float, cpu: float) -> float:
    return round(sim / cpu, 1) if cpu > 0 else float("inf")


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["worker"] and len(argv) == 2:
        return worker(Path(argv[1]))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--baseline", metavar="CHECKOUT", help="a checkout to measure side by side (e.g. main)")
    ap.add_argument("--checkout", default=str(HERE), help="the checkout measured (default: this one)")
    ap.add_argument("--sim-time", type=float, default=None,
                    help=f"simulated seconds of each run (default {SIM_TIME_S:g}; {CELLS_SIM_TIME_S:g} with --cells)")
    ap.add_argument("--interp", choices=("vm", "tree"), default="vm")
    ap.add_argument("--only", default=None, help="only entry points whose path contains this")
    ap.add_argument("--limit", type=int, default=0)
    ap.add_argument("--skip", type=int, default=0, help="leave out the first SKIP programs (a run interrupted)")
    ap.add_argument("--json", default=None, help="write the rows and the summary here")
    ap.add_argument("--corpus", default=str(CORPUS))
    ap.add_argument("--no-warm-up", action="store_true", help="time the first run of each worker too")
    ap.add_argument("--collision", action="store_true",
                    help="the measured checkout checks collisions (the robot against itself, robot/collision.py): "
                         "with --baseline the same checkout, the cost of checking")
    ap.add_argument("--cells", action="store_true",
                    help="the moving palletizer cells (CORPUS_CELLS, EXAMPLE_CELLS) instead of every entry point")
    ap.add_argument("--history", action="store_true",
                    help="--corpus is ../shared/krl-history: the entry points of both sides of every pair")
    ap.add_argument("--baseline-spins", choices=("off", "shadow"), default=None,
                    help="the baseline side's spin watch off or shadowing (with --baseline this checkout: "
                         "parking's evidence)")
    ap.add_argument("--trace-identity", action="store_true",
                    help="run each program once more, untimed, with krl run's trace, and compare the traces' hashes")
    a = ap.parse_args(argv)
    if a.sim_time is None:
        a.sim_time = CELLS_SIM_TIME_S if a.cells else SIM_TIME_S
    corpus = Path(a.corpus).resolve()
    if not corpus.is_dir():
        print(f"no corpus at {corpus}; nothing to do")
        return 0
    if a.sim_time <= 0:
        ap.error("--sim-time takes a positive number of seconds")
    sys.path.insert(0, str(Path(a.checkout).resolve()))
    if a.cells:
        programs = cell_programs(corpus)
    else:
        programs = [(p, None) for p in entry_points(corpus, a.history, a.only)]
    if a.only:
        programs = [(p, c) for p, c in programs if a.only in str(p)]
    programs = programs[a.skip:]
    if a.limit:
        programs = programs[:a.limit]
    sides = [("new", Path(a.checkout))] + ([("base", Path(a.baseline))] if a.baseline else [])
    load0 = os.getloadavg()
    started = datetime.now(timezone.utc)
    if a.baseline_spins and not a.baseline:
        ap.error("--baseline-spins needs --baseline")
    workers = {name: Worker(co, collision=a.collision and name == "new",
                            spins=a.baseline_spins if name == "base" else None) for name, co in sides}
    rows = []
    try:
        if programs and not a.no_warm_up:
            # the first run of a process pays its one-time costs (lazy imports, the first
            # compile of the VM's code, numpy's first calls): one short untimed run each
            for w in workers.values():
                w.run(programs[0][0], min(1.0, a.sim_time), a.interp, programs[0][1])
        names = [n for n, _ in sides]
        head = f"{'entry point':58s} " + " ".join(f"{n + ' cpu s':>10s} {n + ' sim/cpu':>12s}" for n in names)
        head += f" {'motions':>8s} {'I/O digest':16s}"
        if a.baseline:
            head += f" {'speedup':>8s}  same I/O+end" + (" trace" if a.trace_identity else "")
        print(head, flush=True)
        for i, (p, cell) in enumerate(programs):
            order = names if i % 2 == 0 else names[::-1]
            got = {n: workers[n].run(p, a.sim_time, a.interp, cell) for n in order}
            if a.trace_identity:
                for n in order:
                    traced = workers[n].run(p, a.sim_time, a.interp, cell, trace=True)
                    got[n].update(trace_sha=traced.get("trace_sha"), trace_lines=traced.get("trace_lines"))
            row = {"program": display_name(p, corpus), **{n: got[n] for n in names}}
            cells = " ".join(f"{got[n]['cpu_s']:10.2f} {factor(got[n]['sim_s'], got[n]['cpu_s']):12.1f}" for n in names)
            line = f"{row['program'][-58:]:58s} {cells} {got[names[0]].get('motions', 0):8d} {got[names[0]]['io_sha']:16s}"
            if a.baseline:
                new, base = got["new"], got["base"]
                same = new["io_sha"] == base["io_sha"] and new.get("end") == base.get("end") \
                    and new["sim_s"] == base["sim_s"] and new.get("motions") == base.get("motions")
                row["speedup"] = round(base["cpu_s"] / new["cpu_s"], 2) if new["cpu_s"] > 0 else None
                row["same"] = same
                line += f" {row['speedup'] or 0:8.2f}  {'yes' if same else 'NO':12s}"
                if a.trace_identity:
                    row["same_trace"] = new.get("trace_sha") == base.get("trace_sha") and bool(new.get("trace_sha"))
                    line += f" {'identical' if row['same_trace'] else 'DIFFERENT'}"
            print(line, flush=True)
            rows.append(row)
        if a.cells:
            for rel in CORPUS_STOPPED:
                if (corpus / rel).is_file():
                    got = workers["new"].run(corpus / rel, a.sim_time, a.interp)
                    end = got.get("end") or [got["reason"], None, None]
                    print(f"not measured: {rel} stops at t={got['sim_s']:g} s ({end[0]}"
                          + (f", {end[1]}:{end[2]}" if end[1] else "") + ")", flush=True)
    finally:
        for w in workers.values():
            w.close()
    load1 = os.getloadavg()
    summary: dict = {"date": started.strftime("%Y-%m-%d %H:%M UTC"), "sim_time_s": a.sim_time, "interp": a.interp,
                     "entry_points": len(rows), "load_start": [round(x, 2) for x in load0],
                     "load_end": [round(x, 2) for x in load1]}
    for n, co in sides:
        sim = sum(r[n]["sim_s"] for r in rows)
        cpu = sum(r[n]["cpu_s"] for r in rows)
        worst = max(rows, key=lambda r: r[n]["cpu_s"]) if rows else None
        summary[n] = {"checkout": str(co.resolve()), "commit": commit_of(co), "sim_s": round(sim, 3),
                      "spins": (a.baseline_spins if n == "base" else None) or "park",
                      "cpu_s": round(cpu, 3), "sim_per_cpu": factor(sim, cpu),
                      "worst": worst and {"program": worst["program"], "cpu_s": worst[n]["cpu_s"],
                                          "sim_per_cpu": factor(worst[n]["sim_s"], worst[n]["cpu_s"])},
                      "over_3s": sum(1 for r in rows if r[n]["cpu_s"] > 3.0 * a.sim_time / SIM_TIME_S)}
    if a.baseline:
        summary["speedup"] = round(summary["base"]["cpu_s"] / summary["new"]["cpu_s"], 2) \
            if summary["new"]["cpu_s"] > 0 else None
        summary["same"] = sum(1 for r in rows if r["same"])
        if a.trace_identity:
            summary["same_trace"] = sum(1 for r in rows if r["same_trace"])
    print()
    for n, _ in sides:
        s = summary[n]
        print(f"{n:5s} {s['commit']:10s} total {s['sim_s']:9.1f} simulated s in {s['cpu_s']:8.2f} CPU s: "
              f"{s['sim_per_cpu']}x; worst {s['worst']['program'] if s['worst'] else '-'} "
              f"{s['worst']['cpu_s'] if s['worst'] else 0} s; over {3.0 * a.sim_time / SIM_TIME_S:g} s CPU: {s['over_3s']}")
    if a.baseline:
        print(f"speedup of the total {summary['speedup']}x; the same I/O and end on {summary['same']} of {len(rows)}"
              + (f"; identical traces on {summary['same_trace']}" if a.trace_identity else ""))
    print(f"load average {summary['load_start'][0]} at the start, {summary['load_end'][0]} at the end "
          f"({summary['date']})")
    if a.json:
        Path(a.json).write_text(json.dumps({"summary": summary, "rows": rows}, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
