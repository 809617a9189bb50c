"""The CPU of a warm load of small programs (issue 87, "one checked BASIS per process"): this
checkout against another one (today's main), side by side, alternating.

A *warm load* is what a run of a small program outside a backup pays when the process has loaded
programs before and the parse store holds its files: interp/runtime/program.py
``checked_workspace`` (the files from the store, checked and resolved with the BASIS) and
interp/runtime/model.py ``load_model`` (the checked workspace and the program model built on it),
the process's cache of checked workspaces emptied before each load. Programs: a one-line program
(``DEF prog()`` / ``$OUT[1] = TRUE`` / ``END`` in a temporary folder) and the first ``--cases``
conformance cases (conformance/cases of this checkout, for both sides).

Each side runs in a fresh child process importing only its checkout's files
(``krl.cbuild.measured_in``; the checkouts share this venv): it loads every program
once (the store, and on this checkout the shared BASIS layer, warm), then ``--loads`` times
each, and prints the CPU milliseconds per load (``time.process_time``; mean over the programs,
the best and the median of the repeats). The driver runs the two sides ``--rounds`` times,
alternating which goes first, and prints both and their ratio per round.

Usage::

    python tools/basis_bench.py --against /work/wt/base [--rounds 2] [--cases 40] [--loads 3]

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

try:
    from krl.cbuild import measured_in
except ImportError:  # the measuring child of a checkout older than it (only the driver calls it)
    measured_in = None

HERE = Path(__file__).resolve().parent.parent


def _programs(cases: int, tmp: Path) -> list[Path]:
    one = tmp / "one" / "prog.src"
    one.parent.mkdir(parents=True, exist_ok=True)
    one.write_text("DEF prog()\n  $OUT[1] = TRUE\nEND\n", encoding="utf-8")
    dirs = sorted(p for p in (HERE / "conformance" / "cases").iterdir() if p.is_dir())[:cases]
    return [one] + [next(d.glob("*.src")) for d in dirs]


def measure(programs: list[Path], loads: int) -> dict:
    """In the child: the CPU ms per warm load of `programs` (module docstring)."""
    from interp.run import robot_for, run_spec   # noqa: PLC0415  (the child's checkout, once sys.path holds it)
    from interp.runtime import model as M   # noqa: PLC0415  (once sys.path holds the checkout)
    from interp.runtime import program as P   # noqa: PLC0415  (once sys.path holds the checkout)

    robot = robot_for(str(programs[0]))     # the KR 6 R900: one robot for every program

    def drop() -> None:
        for k in P._CACHE.keys():
            P._CACHE.drop(k)

    specs = [run_spec(p, robot=robot) for p in programs]
    found = [P.program_files(str(p), None, []) for p in programs]
    for s in specs:
        drop()
        M.load_model(s)
    out: dict = {"checked_workspace": [], "load_model": []}
    for _ in range(loads):
        t = time.process_time()
        for _main, project, extra in found:
            drop()
            P.checked_workspace(project, extra)
        out["checked_workspace"].append((time.process_time() - t) * 1000 / len(found))
        t = time.process_time()
        for s in specs:
            drop()
            M.load_model(s)
        out["load_model"].append((time.process_time() - t) * 1000 / len(specs))
    out["layer"] = dict(getattr(P, "LAYER_USES", {}))
    return out


def _side(checkout: Path, programs: list[Path], loads: int) -> dict:
    return measured_in(checkout, str(Path(__file__).resolve()), "measure", str(loads), *map(str, programs))


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["measure"]:
        print(json.dumps(measure([Path(p) for p in argv[2:]], int(argv[1]))))
        return 0
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--against", required=True, help="the other checkout (today's main)")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--cases", type=int, default=40)
    ap.add_argument("--loads", type=int, default=3)
    a = ap.parse_args(argv)
    sides = [("base", Path(a.against).resolve()), ("this", HERE)]
    with tempfile.TemporaryDirectory() as tmp:
        programs = _programs(a.cases, Path(tmp))
        print(f"{len(programs)} programs, {a.loads} loads each per side and round; CPU ms per load "
              f"(best / median of the loads)")
        for rnd in range(a.rounds):
            order = sides if rnd % 2 == 0 else sides[::-1]
            got = {}
            for name, co in order:
                try:
                    got[name] = _side(co, programs, a.loads)
                except RuntimeError as exc:
                    print(f"error: {exc}", file=sys.stderr)
                    return 2
            when = time.strftime("%H:%M:%S", time.gmtime())
            for what in ("checked_workspace", "load_model"):
                b, t = got["base"][what], got["this"][what]
                print(f"round {rnd + 1} ({' first, '.join(n for n, _ in order)} second; {when} UTC) {what:17s} "
                      f"base {min(b):6.1f} / {statistics.median(b):6.1f}   this {min(t):6.1f} / "
                      f"{statistics.median(t):6.1f}   base/this {statistics.median(b) / statistics.median(t):5.2f}x")
            print(f"  on the layer: {got['this'].get('layer', {})}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
