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
    python tools/trace_identity.py compare DIR_A DIR_B

``--network`` (both forms): instead of the backups' entry points, every code file of the corpus
that calls an EthernetKRL or RSI function (``EKI_*``, ``RSI_*``), each with its committed cell
file if it has one (none has today: its channels stay "not connected", docs/network.md).

``record`` skips what its OUTDIR holds already (a ``.json``) or what another ``record`` process of the
same OUTDIR has claimed (``NAME.INTERP.claim``; ``--workers N``: N processes per checkout and
interpreter share the programs; after an interrupted run, delete the claims without a ``.json``
and run again to finish). It writes, per program and interpreter, ``NAME.INTERP.jsonl.gz`` (the trace, gzip level
1, mtime 0) and ``NAME.INTERP.json`` (sha256 and size of the uncompressed trace, events, how the
run ended, CPU seconds). ``compare`` prints ``identical N, different M, missing K`` and, for each
difference, the first line where the traces part. Exit status: 0 all identical, 1 any
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
           reverse: bool = False, network: bool = False) -> int:
    """Run every entry point of `corpus` on each of `interps` with the code of `checkout` (which
    must come first on sys.path) and write its trace and summary to `out`. `network`: only the
    programs that use the network (:func:`network_programs`), each with its cell file if it has
    one, else none (every partner "not connected", docs/network.md)."""
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
    from interp.runtime.scheduler import SUBMIT_BUDGET  # noqa: PLC0415  (only once sys.path holds the checkout)
    from robot.trace import TraceWriter  # noqa: PLC0415  (only once sys.path holds the checkout)
    import interp  # noqa: PLC0415  (only once sys.path holds the checkout)

    if Path(interp.__file__).resolve().parent.parent != checkout:
        print(f"error: interp comes from {interp.__file__}, not {checkout}", file=sys.stderr)
        return 2
    out.mkdir(parents=True, exist_ok=True)
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
            try:
                cell = cell_of(p, corpus)   # a path: make_runtime and report_run read it (any version)
                robot, submit, t, steps = report_run(p, cell)
                tw = TraceWriter(sink)
                kw = dict(trace=tw, mujoco=False, max_sim_time=t, max_steps=steps, submit=submit, check=False,
                          inputs=cell, robot=robot, interp=it,
                          robot_budget=SUBMIT_BUDGET if p.suffix.lower() == ".sub" else None)
                rt, _ = make_runtime(run_spec(p, **kw)) if run_spec is not None else make_runtime(p, **kw)
                res = rt.run()
                tw.close()
                summary["end"] = [res.reason, res.text, res.file and str(res.file).replace(str(checkout), "<ROOT>"),
                                  res.line, round(res.sim_time, 6), res.steps]
            except Exception as exc:  # noqa: BLE001 - recorded: an internal error is a difference too
                summary["end"] = ["exception", f"{type(exc).__name__}: {exc}".replace(str(checkout), "<ROOT>")]
            sink.close()
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


def compare(a: Path, b: Path, out=sys.stdout) -> int:
    """Compare the records of two ``record`` runs; print the counts and each difference."""
    names = sorted({f.name for d in (a, b) for f in d.glob("*.json")})
    same, diff, missing = 0, [], []
    for n in names:
        fa, fb = a / n, b / n
        if not fa.exists() or not fb.exists():
            missing.append(n)
            continue
        sa, sb = json.loads(fa.read_text()), json.loads(fb.read_text())
        if sa["sha256"] == sb["sha256"] and sa["end"] == sb["end"]:
            same += 1
            continue
        diff.append(n)
        stem = n[:-len(".json")]
        line, la, lb = first_difference(a / f"{stem}.jsonl.gz", b / f"{stem}.jsonl.gz")
        print(f"DIFF {stem}: {sa['events']} vs {sb['events']} events; end {sa['end']} vs {sb['end']}", file=out)
        print(f"  first at line {line}:\n    {a.name}: {la[:300]}\n    {b.name}: {lb[:300]}", file=out)
    for n in missing:
        print(f"MISSING {n}", file=out)
    print(f"identical {same}, different {len(diff)}, missing {len(missing)}", file=out)
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
        a = ap.parse_args(argv)
        return record(Path(a.checkout), Path(a.out), a.interp.split(","), a.limit, Path(a.corpus), a.reverse,
                      a.network)
    if argv[:1] == ["compare"]:
        ap.add_argument("cmd")
        ap.add_argument("a")
        ap.add_argument("b")
        a = ap.parse_args(argv)
        return compare(Path(a.a), Path(a.b))
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
                                   *(["--network"] if a.network else [])), cwd=co, env=env, stdout=log, stderr=subprocess.STDOUT))
    for p in running:
        p.wait()
    return compare(out / "before", out / "after")


if __name__ == "__main__":
    sys.exit(main())
