"""The CPU of a run's start on a model already loaded (issue 87, "a model shared by many runs":
a run's start should cost little once the program's model is loaded): this checkout against
another one (today's main), side by side, alternating.

What is timed, per run, in one process that has loaded the program before (its checked
workspace and its model cached: interp/runtime/model.py ``load_model``):

* ``krl run case``: ``krl run`` in process of a conformance case (conformance/harness.py
  ``run_case``, as tests/conformance/test_cases.py runs it: the trace written, the summary
  printed, the temporary folder removed), alternately on the tree interpreter and the VM;
* ``krl run /tmp``: the same of a four-line program in its own folder below the system's
  temporary folder, outside a backup (as the tests' ``tmp_path`` programs run: every parent
  folder is looked at for a KRC backup, the temporary folder among them);
* ``run /tmp``: the same program built and run through the API (interp/run.py ``make_runtime``
  and ``Runtime.run``, no trace), as most tests run their ``tmp_path`` programs: the harness's
  own temporary folder, made in the system's temporary folder at each run, is not made;
* ``start backup``: interp/run.py ``make_runtime`` alone (the runtime built, not run) of an
  entry point of a corpus backup with ``--inputs auto``, as tests/interp/test_outside_runs.py
  and the real-programs report start it (interp/realprograms.py ``report_run`` and
  ``run_one``: the robot chosen, the backup's SPS.SUB beside it, ``--no-check``);
* ``start mada``: the same of the first entry point of a backup with machine data of its own
  (``--mada-backup``, ChinaMilling's: its robot read from its ``$machine.dat``, whose kinematic
  family is found by solving sample poses of its chain: robot/machinememo.py).

Each side runs in a fresh child process importing only its checkout's files
(``krl.cbuild.measured_in``; the checkouts share this venv): each program is run
twice first (its model loaded, the parse store warm), then ``--repeat`` times ``--runs`` runs,
each repeat's CPU milliseconds per run (``time.process_time``) kept. The driver runs the two
sides ``--rounds`` times, alternating which goes first, and prints both sides' median and best
and their ratio per round.

Usage::

    python tools/run_start_bench.py --against /work/wt/base [--rounds 2] [--runs 40] [--repeat 3]
        [--backup ../shared/krl-corpus/ingeniado__KRC4-Robot-Palletizer]
        [--mada-backup ../shared/krl-corpus/HugoDanielson__ChinaMilling/KRC]

Exit status 0; 2 when a side fails.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

# the measuring child imports these from its checkout (the checkout first on sys.path:
# krl.cbuild.measured_in), the driver from this one
from conformance import harness as H
from interp import realprograms as rp
from interp.run import RunSinks, make_runtime, run_spec

try:
    from krl.cbuild import measured_in
except ImportError:  # the measuring child of a checkout older than it (only the driver calls it)
    measured_in = None

HERE = Path(__file__).resolve().parent.parent
CASE = "002_if_else"
BACKUP = HERE.parent / "shared" / "krl-corpus" / "ingeniado__KRC4-Robot-Palletizer"
MADA_BACKUP = HERE.parent / "shared" / "krl-corpus" / "HugoDanielson__ChinaMilling" / "KRC"
KINDS = ("krl run case", "krl run /tmp", "run /tmp", "start backup", "start mada")


def measure(runs: int, repeat: int, tmp_program: Path, backup: Path, mada: Path | None = None) -> dict:
    """In the child: CPU ms per run of each kind (module docstring), one list per kind."""
    case = next(c for c in H.load_cases() if c.name == CASE)
    entries = {"start backup": rp.entries_of(backup)[0] if backup.is_dir() else None,
               "start mada": rp.entries_of(mada)[0] if mada is not None and mada.is_dir() else None}

    def run_case(i: int) -> None:
        H.run_case(case, "tree" if i % 2 else "vm")

    def run_tmp(i: int) -> None:
        r = H.run_program(tmp_program, "tree" if i % 2 else "vm")
        assert r.crash is None, r.crash

    def run_api(i: int) -> None:
        rt, _ = make_runtime(run_spec(tmp_program, mujoco=False, interp="tree" if i % 2 else "vm"))
        assert rt.run().reason == "completed"

    def start(entry: Path):
        def start_backup(i: int) -> None:
            robot, submit, sim_time, limit = rp.report_run(entry, None, 20.0, 100_000, True, 20.0)
            make_runtime(run_spec(entry, mujoco=False, max_sim_time=sim_time, max_steps=limit, submit=submit,
                                  check=False, inputs="auto", robot=robot, interp="vm"),
                         RunSinks(observer=rp.RunEvents()))
        return start_backup

    out: dict = {}
    for kind, fn in zip(KINDS, (run_case, run_tmp, run_api, start(entries["start backup"]),
                                start(entries["start mada"]))):
        if kind in entries and entries[kind] is None:
            continue
        fn(0)
        fn(1)
        got = []
        for _ in range(repeat):
            t = time.process_time()
            for i in range(runs):
                fn(i)
            got.append((time.process_time() - t) * 1000 / runs)
        out[kind] = got
    return out


def _side(checkout: Path, runs: int, repeat: int, tmp_program: Path, backup: Path, mada: Path) -> dict:
    return measured_in(checkout, str(Path(__file__).resolve()), "measure", str(runs), str(repeat), str(tmp_program),
                       str(backup), str(mada))


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["measure"]:
        print(json.dumps(measure(int(argv[1]), int(argv[2]), Path(argv[3]), Path(argv[4]),
                                 Path(argv[5]) if len(argv) > 5 else None)))
        return 0
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--against", required=True, help="the other checkout (today's main)")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--runs", type=int, default=40)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--backup", type=Path, default=BACKUP)
    ap.add_argument("--mada-backup", type=Path, default=MADA_BACKUP)
    a = ap.parse_args(argv)
    sides = [("base", Path(a.against).resolve()), ("this", HERE)]
    with tempfile.TemporaryDirectory(prefix="run-start-bench-") as tmp:
        program = Path(tmp) / "prog" / "prog.src"
        program.parent.mkdir()
        program.write_text("DEF prog()\n  INT i\n  i = 1\n  $OUT[1] = TRUE\nEND\n", encoding="utf-8")
        print(f"CPU ms per run, {a.runs} runs x {a.repeat} per side and round (median / best of the repeats)")
        for rnd in range(a.rounds):
            order = sides if rnd % 2 == 0 else sides[::-1]
            got = {}
            for name, co in order:
                try:
                    got[name] = _side(co, a.runs, a.repeat, program, a.backup.resolve(), a.mada_backup.resolve())
                except RuntimeError as exc:
                    print(f"error: {exc}", file=sys.stderr)
                    return 2
            when = time.strftime("%H:%M:%S", time.gmtime())
            for kind in KINDS:
                if kind not in got["base"] or kind not in got["this"]:
                    continue
                b, t = got["base"][kind], got["this"][kind]
                print(f"round {rnd + 1} ({order[0][0]} first; {when} UTC) {kind:13s} base {statistics.median(b):6.2f} / "
                      f"{min(b):6.2f}   this {statistics.median(t):6.2f} / {min(t):6.2f}   "
                      f"base/this {statistics.median(b) / statistics.median(t):5.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
