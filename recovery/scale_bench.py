"""How `krl recover` scales with the corpus: one copy against N copies, in the same run.

``python -m recovery.scale_bench [CORPUS] [--copies 16] [--json]`` lays out ``copies/c01`` (one
copy of CORPUS, default ../shared/krl-corpus) and ``copies/c01..cNN`` (N copies, hard links
where the file system allows) in a temporary folder, runs ``krl recover DIR --no-cache`` on
each (one copy first, then N, then one again; the better of the two one-copy runs counts) and
samples the resident memory of the whole process tree every 50 ms (psutil): the main process,
the worker processes and the Java engine's workers. It prints the wall times, the peaks and
the ratios N-copies / one-copy (issue 17's targets: time at most 16.5x, peak memory at most
1.2x for 16 copies). Both layouts have the same depth, so every file's report path has the
same shape (a corpus's known-invalid list names paths of the original layout and matches
neither, in both runs alike).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import click
import psutil
from krl.files import SHARED_CORPUS as DEFAULT_CORPUS

def _link_tree(src: Path, dst: Path) -> None:
    try:
        shutil.copytree(src, dst, copy_function=os.link, symlinks=True)
    except OSError:
        shutil.rmtree(dst, ignore_errors=True)
        shutil.copytree(src, dst, symlinks=True)


def measure(argv: list[str], interval: float = 0.05) -> dict:
    """Run argv; wall time (s), exit status and peak resident memory (MB): of the whole process
    tree at any one moment (`total`) and of the largest process of each kind (`main`, `worker`,
    `java`)."""

    start = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    root = psutil.Process(proc.pid)
    peak = {"total": 0, "main": 0, "worker": 0, "java": 0}
    while proc.poll() is None:
        total = 0
        try:
            tree = [root] + root.children(recursive=True)
        except psutil.Error:
            break
        for p in tree:
            try:
                rss = p.memory_info().rss
                kind = "main" if p.pid == proc.pid else ("java" if "java" in p.name() else "worker")
            except psutil.Error:
                continue
            total += rss
            peak[kind] = max(peak[kind], rss)
        peak["total"] = max(peak["total"], total)
        time.sleep(interval)
    return {"seconds": round(time.perf_counter() - start, 2), "exit": proc.returncode,
            "peak_mb": {k: round(v / 2**20, 1) for k, v in peak.items()}}


def scale(corpus: Path, copies: int = 16) -> dict:
    """The figures of one copy and of `copies` copies of `corpus` (see the module docstring)."""
    krl = [sys.executable, "-m", "app", "recover"]
    with tempfile.TemporaryDirectory(prefix="krl-scale-") as tmp:
        one, many = Path(tmp) / "one", Path(tmp) / "many"
        _link_tree(corpus, one / "c01")
        for i in range(1, copies + 1):
            _link_tree(corpus, many / f"c{i:02d}")
        runs = [measure(krl + [str(one), "--no-cache", "--out", str(Path(tmp) / "r1")]),
                measure(krl + [str(many), "--no-cache", "--out", str(Path(tmp) / "rn")]),
                measure(krl + [str(one), "--no-cache", "--out", str(Path(tmp) / "r1")])]
    single = min((runs[0], runs[2]), key=lambda r: r["seconds"])
    single_peak = {k: min(runs[0]["peak_mb"][k], runs[2]["peak_mb"][k]) for k in runs[0]["peak_mb"]}
    n = runs[1]
    return {"corpus": str(corpus), "copies": copies, "one": {**single, "peak_mb": single_peak}, "many": n,
            "time_ratio": round(n["seconds"] / single["seconds"], 2),
            "memory_ratio": {k: round(n["peak_mb"][k] / single_peak[k], 2) if single_peak[k] else None
                             for k in single_peak}}


@click.command()
@click.argument("corpus", required=False, type=click.Path(exists=True, file_okay=False, path_type=Path))
@click.option("--copies", type=click.IntRange(2, 64), default=16, show_default=True)
@click.option("--json", "as_json", is_flag=True, help="One JSON object.")
def main(corpus: Path | None, copies: int, as_json: bool) -> None:

    if corpus is None and not DEFAULT_CORPUS.is_dir():
        raise click.UsageError(f"no corpus at {DEFAULT_CORPUS}; name one")
    figures = scale(corpus or DEFAULT_CORPUS, copies)
    if as_json:
        return click.echo(json.dumps(figures))
    one, many = figures["one"], figures["many"]
    click.echo(f"one copy: {one['seconds']} s, peak {one['peak_mb']}")
    click.echo(f"{copies} copies: {many['seconds']} s, peak {many['peak_mb']}")
    click.echo(f"time {figures['time_ratio']}x, peak memory {figures['memory_ratio']}")


if __name__ == "__main__":
    main()
