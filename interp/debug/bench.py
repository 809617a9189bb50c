"""How long ``krl debug`` takes to launch a program of a real backup (issue 37: "Launch on a
150-file backup <= 1 s"). A benchmark script, not a test: it prints figures measured in one run.

Each sample is a fresh ``krl debug`` process driven over stdio by the DAP client
(interp/debug/client.py), as an editor drives it, with the default launch (krl run's
defaults: the backup's SPS.SUB at boot, its robot):

* ``start`` — from starting the process to the ``initialize`` response: Python and the
  adapter's imports;
* ``launch`` — from the ``launch`` request to its response (the program loaded, checked and
  built; the robot loaded): what the issue's "launch" is;
* ``entry`` — from starting the process to the first stop (``stopOnEntry``) with the stack
  listed: until the editor shows the program pointer, all included;
* ``CPU`` — the processor time (user + system) of the ``krl debug`` process when the launch
  response came (Linux: /proc): on a loaded machine, what the start and launch cost without
  waiting for a processor;
* ``launchCPU`` — the processor time the process spent from the ``initialize`` response to the
  ``launch`` response: the launch's own cost (the imports of the run that the adapter starts in
  the background when it starts land mostly here, since an editor sends ``launch`` at once).

The program is the first robot program (interp.realprograms ``programs_of``) of the corpus
backup with the most KRL files. ``--against DIR`` times another checkout's ``krl debug``
(its ``.venv/bin/python``, e.g. a worktree of the round's baseline) in turn with this one
(A B A B ...), and prints the ratio of the medians. ``--cold`` also times runs with an empty
user cache (KRL_CACHE_DIR: nothing stored by an earlier run).

Usage: ``python -m interp.debug.bench [--runs N] [--against DIR] [--cold] [BACKUP [PROGRAM]]``
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from krl.cputime import tree_cpu_s

from .client import ROOT, DapClient
from krl.files import SHARED_CORPUS
from krl.project import find_backups
from krl.source import is_krl_file
from interp.realprograms import programs_of


def largest_backup() -> Path | None:
    """The corpus backup with the most KRL files (None without the shared corpus)."""

    if not SHARED_CORPUS.is_dir():
        return None
    sized = [(sum(1 for p in b.rglob("*") if p.is_file() and is_krl_file(p)), str(b)) for b in find_backups(SHARED_CORPUS)]
    return Path(max(sized)[1]) if sized else None


#: Python's compiled bytecode as an installed tool has it: written (an environment that sets
#: PYTHONDONTWRITEBYTECODE would compile every changed module of the checkout at each start),
#: under a directory of the benchmark's own (nothing written into the checkouts); the warm-up
#: run fills it
BYTECODE = {"PYTHONDONTWRITEBYTECODE": "",
            "PYTHONPYCACHEPREFIX": str(Path(tempfile.gettempdir()) / f"krl-debug-bench-pycache-{os.getuid()}")}


def sample(program: Path, workspace: Path, root: Path, python: str | None, env: dict | None) -> tuple:
    """(start s, launch s, entry s, CPU s, launch CPU s) of one fresh krl debug process."""
    env = {**BYTECODE, **(env or {})}
    t0 = time.perf_counter()
    with DapClient(timeout=600, root=root, python=python, env=env) as c:
        c.initialize()
        t_start = time.perf_counter()
        cpu_start = tree_cpu_s(c.proc.pid)
        c.request("launch", {"program": str(program), "workspace": str(workspace), "stopOnEntry": True})
        t_launch = time.perf_counter() - t_start
        cpu = tree_cpu_s(c.proc.pid)
        c.request("configurationDone")
        c.wait_event("stopped")
        c.stack()
        t_entry = time.perf_counter() - t0
        c.request("disconnect", {})
    return t_start - t0, t_launch, t_entry, cpu, cpu - cpu_start


def _fmt(xs: list[float]) -> str:
    return f"min {min(xs):6.2f}  median {statistics.median(xs):6.2f}  max {max(xs):6.2f} s"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m interp.debug.bench", description=__doc__.split("\n\n")[0])
    ap.add_argument("backup", nargs="?", type=Path)
    ap.add_argument("program", nargs="?", type=Path)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--against", type=Path, default=None, help="another checkout to time in turn")
    ap.add_argument("--cold", action="store_true", help="also time runs with an empty user cache")
    a = ap.parse_args(argv)
    backup = a.backup or largest_backup()
    if backup is None:
        print("no backup: the shared corpus is beside the repository", file=sys.stderr)
        return 2

    program = a.program or next(iter(programs_of(backup)), None)
    if program is None:
        print(f"no robot program in {backup}", file=sys.stderr)
        return 2
    files = sum(1 for p in backup.rglob("*") if p.is_file() and is_krl_file(p))
    print(f"krl debug launch on {backup} ({files} KRL files), program {program.relative_to(backup)}")
    print(f"{time.strftime('%Y-%m-%d %H:%M')}, load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}, "
          f"{os.cpu_count()} CPUs; {a.runs} runs each, interleaved, after one warm-up each")
    sides = [("this checkout", ROOT, None)]
    if a.against is not None:
        sides.append((str(a.against), a.against.resolve(), str(a.against.resolve() / ".venv" / "bin" / "python")))
    cold_dirs = []
    variants = []
    for name, root, python in sides:
        variants.append((name, root, python, None))
        if a.cold:
            d = tempfile.mkdtemp(prefix="krl-bench-cache-")
            cold_dirs.append(d)
            variants.append((f"{name}, empty cache", root, python, d))
    results: dict[str, list] = {v[0]: [] for v in variants}
    for name, root, python, cold in variants:          # warm-up (fills the cache of the warm runs)
        sample(program, backup, root, python, None if cold is None else {"KRL_CACHE_DIR": cold})
    for _ in range(a.runs):
        for name, root, python, cold in variants:
            env = None
            if cold is not None:
                env = {"KRL_CACHE_DIR": tempfile.mkdtemp(prefix="krl-bench-cache-", dir=cold)}
            results[name].append(sample(program, backup, root, python, env))
    what = ("start", "launch", "entry", "CPU", "launchCPU")
    for name, xs in results.items():
        print(f"{name}:")
        for i, w in enumerate(what):
            print(f"  {w:9s} {_fmt([x[i] for x in xs])}")
    if a.against is not None:
        base = results[sides[1][0]]
        here = results[sides[0][0]]
        for i, w in enumerate(what):
            r = statistics.median(b[i] for b in base) / statistics.median(h[i] for h in here)
            print(f"{w}: {r:.1f}x faster than {sides[1][0]} (ratio of medians)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
