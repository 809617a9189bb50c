"""Trace identity of the real programs between two checkouts (issue 38: "the traces of both back
ends are identical before and after").

Every entry point of the corpus backups (interp/realprograms.py ``entries_of``: module mains,
cell.src, each backup's SPS.SUB) runs with its committed cell file exactly as the real-programs
report runs it (``report_run``: the cell's robot, the backup's SPS.SUB beside it, the report's
time and step limits, ``--no-check``), on the tree interpreter and on the VM, once with the code
of each checkout, and writes its full trace (every event: ``TraceWriter(repeats=None)``). The two
traces of each program and interpreter are compared byte for byte, with the checkout's own root
written ``<ROOT>`` (a cell or a BASIS file of the repository named in an event).

Each checkout runs in a child process with ``PYTHONPATH=CHECKOUT`` on this interpreter, importing only
that checkout's files (``krl.cbuild.other_checkout_command``): the
checkouts must share this venv's dependencies, and each needs its generated parser
(krl/syntax/generated) and, for the VM at full speed, its compiled loop (``python -m
interp.vm.build`` run in it). ``KRL_BUILD_DIR`` (the Java parse engine) is passed through.

Usage::

    python tools/trace_identity.py BEFORE AFTER --out DIR [--interp tree,vm] [--limit N] [--jobs 2]
    python tools/trace_identity.py record CHECKOUT OUTDIR [--interp tree,vm] [--limit N]
        [--history --corpus ../shared/krl-history]
    python tools/trace_identity.py compare DIR_A DIR_B [--last-place]

``--cases`` (both forms): instead of the backups' entry points, the ``.src`` files of each folder of
``--corpus`` (``--corpus conformance/cases``: the conformance cases), each a program of its own
folder outside a backup, on the project's BASIS, with no cell file. Each record says how its
checked workspace was made (``basis``: "layer" when checked on the shared BASIS layer,
interp/runtime/program.py ``LAYER_USES``; "whole"; "cached"; absent for a checkout without the
layer).

``--network`` (both forms): instead of the backups' entry points, every code file of the corpus
that calls an EthernetKRL or RSI function (``EKI_*``, ``RSI_*``), each with its committed cell
file if it has one (none has today: its channels stay "not connected", docs/network.md).

``record`` skips what its OUTDIR holds already (a ``.json``) or what another ``record`` process of the
same OUTDIR has claimed (``NAME.INTERP.claim``; ``--workers N``: N processes per checkout and
interpreter share the programs; after an interrupted run, delete the claims without a ``.json``
and run again to finish). It writes, per program and interpreter, ``NAME.INTERP.jsonl.gz`` (the trace, gzip level
1, mtime 0) and ``NAME.INTERP.json`` (sha256 and size of the uncompressed trace, events, how the
run ended, CPU seconds). ``compare`` prints ``identical N, different M, missing K`` and, for each
difference, the first line where the traces part.

``compare --last-place`` also counts a trace **equivalent** when it has the end and the lines of the
other and each line that differs is the same event with the same fields, every differing number
one unit of the sixth decimal apart (the trace prints 6: two computations of the same value that
differ by 1e-12 round apart at a tie) or an orientation angle printed 180 on one side and -180 on
the other (A, B or C of a pose, ``tcp``/``point`` components 4-6: the same rotation at the cut of
KUKA's (-180, 180] range). Issue 62 asks for closed-form rotations "exact to the trace's 6
decimals": this is that bar, and the counts say how many numbers met it by the last place only.
It prints ``identical N, equivalent E (last place L numbers, +-180 P angles), different M, missing K``. Exit status: 0 all identical, 1 any
difference or missing trace, 2 bad usage.
"""

from __future__ import annotations

import argparse
import gzip
import hashlib
import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

try:
    from krl.cbuild import other_checkout_command
except ImportError:  # the record child of a checkout older than it (only the driver calls it)
    other_checkout_command = None

CORPUS = Path(__file__).resolve().parent.parent.parent / "shared" / "krl-corpus"


class _Sink:
    """A text sink for TraceWriter: hashes, counts and gzips what is written, with `root` (the
    checkout's path) written ``<ROOT>``."""

    def __init__(self, path: Path, root: str) -> None:
        self._raw = open(path, "wb")
        self._gz = gzip.GzipFile(fileobj=self._raw, mode="wb", compresslevel=1, mtime=0)
        self.sha = hashlib.sha256()
        self.size = 0
        self.lines = 0
        self.root = root

    def write(self, text: str) -> int:
        data = text.replace(self.root, "<ROOT>").encode("utf-8")
        self.sha.update(data)
        self._gz.write(data)
        self.size += len(data)
        self.lines += data.count(b"\n")
        return len(text)

    def flush(self) -> None:
        pass

    def close(self) -> None:
        self._gz.close()
        self._raw.close()


def _claim(path: Path) -> bool:
    """True when this process made `path` (several ``record`` processes share one OUTDIR)."""
    try:
        os.close(os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
    except FileExistsError:
        return False
    return True


NETWORK_CALL = re.compile(rb"\b(?:EKI|RSI)_[A-Z_]+\s*\(", re.IGNORECASE)


def network_programs(corpus: Path) -> list[Path]:
    """The corpus's code files (.src/.sub) that call an EthernetKRL or RSI function (``EKI_*``,
    ``RSI_*``), inside a backup or not: the programs that use the network (``--network``)."""
    out = []
    for p in sorted(corpus.rglob("*")):
        if p.suffix.lower() in (".src", ".sub") and p.is_file() and not p.is_symlink():
            try:
                if NETWORK_CALL.search(p.read_bytes()[:1_000_000]):
                    out.append(p)
            except OSError:
                continue
    return out


def record(checkout: Path, out: Path, interps: list[str], limit: int = 0, corpus: Path = CORPUS,
           reverse: bool = False, network: bool = False, history: bool = False, cases: bool = False) -> int:
    """Run every entry point of `corpus` on each of `interps` with the code of `checkout` (which
    must come first on sys.path) and write its trace and summary to `out`. `network`: only the
    programs that use the network (:func:`network_programs`), each with its cell file if it has
    one, else none (every partner "not connected", docs/network.md). `history`: `corpus` is
    ../shared/krl-history and the programs are the entry points of both sides of every pair
    (interp/realprograms.py ``history_entries``). `cases`: the .src files of each folder of
    `corpus` (module docstring)."""
    checkout = checkout.resolve()
    sys.path.insert(0, str(checkout))
    # the checkout's code, importable only once sys.path holds it; loaded only for `record`
    # (optional for `compare` and the driver, which would pay its 0.3 s for nothing)
    from interp.realprograms import cell_of, entries_of, find_backups, report_run  # noqa: PLC0415
    from interp.run import make_runtime  # noqa: PLC0415
    try:
        from interp.run import run_spec  # noqa: PLC0415  (importable only once sys.path holds the checkout)
    except ImportError:     # a checkout before the run specification (issue 62): keywords
        run_spec = None
    try:
        from interp.run import RunSinks  # noqa: PLC0415  (importable only once sys.path holds the checkout)
    except ImportError:     # a checkout whose spec held the trace (before issue 76): a keyword of run_spec
        RunSinks = None
    from interp.runtime.scheduler import SUBMIT_BUDGET  # noqa: PLC0415  (only once sys.path holds the checkout)
    from robot.trace import TraceWriter  # noqa: PLC0415  (only once sys.path holds the checkout)
    import interp  # noqa: PLC0415  (only once sys.path holds the checkout)
    from interp.runtime import program as loading  # noqa: PLC0415  (only once sys.path holds the checkout)

    if not corpus.is_dir():       # a record of nothing would compare as "identical 0"
        print(f"error: no corpus at {corpus} (--corpus)", file=sys.stderr)
        return 2
    if Path(interp.__file__).resolve().parent.parent != checkout:
        print(f"error: interp comes from {interp.__file__}, not {checkout}", file=sys.stderr)
        return 2
    out.mkdir(parents=True, exist_ok=True)
    if history:
        from interp.realprograms import history_entries  # noqa: PLC0415  (only once sys.path holds the checkout)
        programs = history_entries(corpus, ("old", "new"))
    elif cases:
        programs = sorted(p for d in corpus.iterdir() if d.is_dir() for p in d.glob("*.src"))
    else:
        programs = network_programs(corpus) if network else \
            [p for root in find_backups(corpus) for p in entries_of(root)]
    if limit:
        programs = programs[:limit]
    if reverse:                 # a second worker from the other end: other backups recorded first
        programs = programs[::-1]
    for it in interps:
        for p in programs:
            name = str(p.relative_to(corpus)).replace("/", "__")
            if (out / f"{name}.{it}.json").exists() or not _claim(out / f"{name}.{it}.claim"):
                continue        # recorded, or another record process of the same OUTDIR has it
            sink = _Sink(out / f"{name}.{it}.jsonl.gz", str(checkout))
            summary: dict = {"program": str(p), "interp": it}
            c0 = time.process_time()
            uses = dict(getattr(loading, "LAYER_USES", {}))
            try:
                cell = cell_of(p, corpus)   # a path: make_runtime and report_run read it (any version)
                robot, submit, t, steps = report_run(p, cell)
                tw = TraceWriter(sink)
                kw = dict(mujoco=False, max_sim_time=t, max_steps=steps, submit=submit, check=False,
                          inputs=cell, robot=robot, interp=it,
                          robot_budget=SUBMIT_BUDGET if p.suffix.lower() == ".sub" else None)
                if RunSinks is not None:
                    rt, _ = make_runtime(run_spec(p, **kw), RunSinks(trace=tw))
                else:
                    rt, _ = make_runtime(run_spec(p, trace=tw, **kw)) if run_spec is not None else \
                        make_runtime(p, trace=tw, **kw)
                res = rt.run()
                tw.close()
                summary["end"] = [res.reason, (res.text or "").replace(str(checkout), "<ROOT>"),
                                  res.file and str(res.file).replace(str(checkout), "<ROOT>"),
                                  res.line, round(res.sim_time, 6), res.steps]
            except Exception as exc:  # noqa: BLE001 - recorded: an internal error is a difference too
                summary["end"] = ["exception", f"{type(exc).__name__}: {exc}".replace(str(checkout), "<ROOT>")]
            sink.close()
            if hasattr(loading, "LAYER_USES"):
                now = loading.LAYER_USES
                summary["basis"] = next((k for k in ("layer", "whole") if now.get(k, 0) > uses.get(k, 0)), "cached")
            summary.update(sha256=sink.sha.hexdigest(), bytes=sink.size, events=sink.lines,
                           cpu_s=round(time.process_time() - c0, 2))
            (out / f"{name}.{it}.json").write_text(json.dumps(summary) + "\n", encoding="utf-8")
            print(f"{it:4s} {summary['cpu_s']:8.1f}s {sink.lines:9d} events {summary['end'][0]:13s} {name}",
                  flush=True)
    return 0


def first_difference(a: Path, b: Path) -> tuple[int, str, str]:
    """(line number, line of `a`, line of `b`) where two gzipped traces part (``""`` past an end)."""
    with gzip.open(a, "rt", encoding="utf-8") as fa, gzip.open(b, "rt", encoding="utf-8") as fb:
        n = 0
        while True:
            n += 1
            la, lb = fa.readline(), fb.readline()
            if la != lb or not la:
                return n, la.rstrip("\n"), lb.rstrip("\n")


#: the fields whose components 4-6 are an orientation (A, B, C in degrees)
_ORIENTED = ("tcp", "point")


def _within_last_place(x, y, path: tuple, counts: dict) -> bool:
    """Whether two parsed trace values are the same up to :func:`compare`'s ``--last-place``
    rule; counts each number that needed it (``"last place"``, ``"180"``)."""
    if isinstance(x, dict) and isinstance(y, dict):
        return x.keys() == y.keys() and all(_within_last_place(x[k], y[k], path + (k,), counts) for k in x)
    if isinstance(x, list) and isinstance(y, list):
        return len(x) == len(y) and all(_within_last_place(u, v, path + (i,), counts) for i, (u, v) in enumerate(zip(x, y)))
    if type(x) is not type(y) or not isinstance(x, float) or x == y:
        return x == y
    if abs(round(x * 1e6) - round(y * 1e6)) <= 1:
        counts["last place"] += 1
        return True
    angle = (path[-1:] in (("A",), ("B",), ("C",))
             or (len(path) >= 2 and path[-2] in _ORIENTED and path[-1] in (3, 4, 5)))
    if angle and {x, y} == {180.0, -180.0}:
        counts["180"] += 1
        return True
    return False


def equivalent(a: Path, b: Path, counts: dict) -> bool:
    """Whether two gzipped traces have the same lines up to the ``--last-place`` rule."""
    with gzip.open(a, "rt", encoding="utf-8") as fa, gzip.open(b, "rt", encoding="utf-8") as fb:
        while True:
            la, lb = fa.readline(), fb.readline()
            if la == lb:
                if not la:
                    return True
                continue
            if not la or not lb:
                return False
            try:
                ea, eb = json.loads(la), json.loads(lb)
            except ValueError:
                return False
            if not _within_last_place(ea, eb, (), counts):
                return False


def compare(a: Path, b: Path, out=sys.stdout, last_place: bool = False) -> int:
    """Compare the records of two ``record`` runs; print the counts and each difference (with
    `last_place`, the equivalent ones are counted apart: module docstring)."""
    names = sorted({f.name for d in (a, b) for f in d.glob("*.json")})
    same, diff, missing = 0, [], []
    alike, counts = 0, {"last place": 0, "180": 0}
    for n in names:
        fa, fb = a / n, b / n
        if not fa.exists() or not fb.exists():
            missing.append(n)
            continue
        sa, sb = json.loads(fa.read_text()), json.loads(fb.read_text())
        if sa["sha256"] == sb["sha256"] and sa["end"] == sb["end"]:
            same += 1
            continue
        stem = n[:-len(".json")]
        mine = {"last place": 0, "180": 0}
        if last_place and sa["end"] == sb["end"] and equivalent(a / f"{stem}.jsonl.gz", b / f"{stem}.jsonl.gz", mine):
            alike += 1
            counts = {k: counts[k] + mine[k] for k in counts}
            continue
        diff.append(n)
        line, la, lb = first_difference(a / f"{stem}.jsonl.gz", b / f"{stem}.jsonl.gz")
        print(f"DIFF {stem}: {sa['events']} vs {sb['events']} events; end {sa['end']} vs {sb['end']}", file=out)
        print(f"  first at line {line}:\n    {a.name}: {la[:300]}\n    {b.name}: {lb[:300]}", file=out)
    for n in missing:
        print(f"MISSING {n}", file=out)
    shown = (f", equivalent {alike} (last place {counts['last place']} numbers, +-180 {counts['180']} angles)"
             if last_place else "")
    print(f"identical {same}{shown}, different {len(diff)}, missing {len(missing)}", file=out)
    return 0 if not diff and not missing else 1


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    if argv[:1] == ["record"]:
        ap.add_argument("cmd")
        ap.add_argument("checkout")
        ap.add_argument("out")
        ap.add_argument("--interp", default="tree,vm")
        ap.add_argument("--limit", type=int, default=0)
        ap.add_argument("--corpus", default=str(CORPUS))
        ap.add_argument("--reverse", action="store_true", help="the programs in reverse order")
        ap.add_argument("--network", action="store_true", help="the programs that call EKI_/RSI_ functions")
        ap.add_argument("--history", action="store_true",
                        help="--corpus is ../shared/krl-history: both sides of every pair")
        ap.add_argument("--cases", action="store_true", help="the .src files of each folder of --corpus")
        a = ap.parse_args(argv)
        return record(Path(a.checkout), Path(a.out), a.interp.split(","), a.limit, Path(a.corpus), a.reverse,
                      a.network, a.history, a.cases)
    if argv[:1] == ["compare"]:
        ap.add_argument("cmd")
        ap.add_argument("a")
        ap.add_argument("b")
        ap.add_argument("--last-place", action="store_true",
                        help="count traces equal up to the last printed decimal and +-180 angles apart")
        a = ap.parse_args(argv)
        return compare(Path(a.a), Path(a.b), last_place=a.last_place)
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--out", required=True)
    ap.add_argument("--interp", default="tree,vm")
    ap.add_argument("--limit", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--workers", type=int, default=1,
                    help="record processes per checkout and interpreter (they share the programs)")
    ap.add_argument("--corpus", default=str(CORPUS))
    ap.add_argument("--network", action="store_true",
                    help="instead of the backups' entry points: the programs that call EKI_/RSI_ functions")
    ap.add_argument("--cases", action="store_true",
                    help="instead of the backups' entry points: the .src files of each folder of --corpus "
                         "(conformance/cases), each on the project's BASIS")
    a = ap.parse_args(argv)
    if not Path(a.corpus).is_dir():
        print(f"no corpus at {a.corpus}; nothing to do")
        return 0
    out = Path(a.out)
    jobs = [(Path(co).resolve(), out / side, it) for it in a.interp.split(",")
            for co, side in ((a.before, "before"), (a.after, "after")) for _w in range(max(1, a.workers))]
    running: list[subprocess.Popen] = []
    for co, dest, it in jobs:
        while len(running) >= max(1, a.jobs):
            running = [p for p in running if p.poll() is None]
            if len(running) >= max(1, a.jobs):
                time.sleep(1.0)
        dest.mkdir(parents=True, exist_ok=True)
        env = dict(os.environ, PYTHONPATH=str(co))
        log = open(dest / f"record.{it}.log", "a", encoding="utf-8")
        running.append(subprocess.Popen(
            other_checkout_command(sys.executable, str(Path(__file__).resolve()), "record", str(co), str(dest),
                                   "--interp", it, "--limit", str(a.limit), "--corpus", a.corpus,
                                   *(["--network"] if a.network else []), *(["--cases"] if a.cases else [])), cwd=co, env=env, stdout=log, stderr=subprocess.STDOUT))
    for p in running:
        p.wait()
    return compare(out / "before", out / "after")


if __name__ == "__main__":
    sys.exit(main())
