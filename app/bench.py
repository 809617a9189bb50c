"""`krl bench`: benchmarks that print ratios and rates measured in the same run.

`krl bench` runs the compute benchmark (interp/bench) on the tree interpreter, on the
VM and as hand-written Python; `krl bench --json` prints one JSON line with every figure
(compute ratio and rates, simulator real-time factor, parser KB/s), measured in one process.

`krl bench parse [CORPUS]` measures each available parse engine (python, java) in KB/s over
the same corpus, rounds interleaved, best of N, one thread each, and prints the speedup of the
fast engine over the Python one, measured in the same run.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import click

from krl.files import SHARED_CORPUS as DEFAULT_CORPUS
from krl.fmt import format_text
from krl.source import read_source
from krl.syntax.parse import parse_source
from recovery.scan import discover
from interp.bench import Baseline, BaselineError, compute
from robot.bench import measure
from krl.syntax.engines import available, parse_sources, unavailable_reason


def parse_rate(corpus: Path, limit_bytes: int | None = None) -> dict:
    """Parse every KRL file under corpus twice in this process; returns KB/s cold and warm."""

    sources = []
    total = 0
    for p in discover(corpus):
        src = read_source(p)
        if src.status == "ok":
            sources.append(src)
            total += src.size
            if limit_bytes and total >= limit_bytes:
                break
    rates = {}
    for phase in ("cold", "warm"):
        start = time.perf_counter()
        for src in sources:
            parse_source(src, keep_tree=False)
        rates[phase] = total / 1024 / (time.perf_counter() - start)
    return {"files": len(sources), "kb": round(total / 1024, 1),
            "cold_kb_per_s": round(rates["cold"], 1), "warm_kb_per_s": round(rates["warm"], 1)}


def fmt_rate(corpus: Path, limit_bytes: int | None = None) -> dict:
    """Parse, then format, every KRL file under corpus that parses (a warm-up parse first);
    returns KB/s of both and the ratio of the times, all measured in this process."""

    sources = []
    total = 0
    for p in discover(corpus):
        src = read_source(p)
        if src.status == "ok" and parse_source(src, keep_tree=False).ok:   # also warms the parser
            sources.append(src)
            total += src.size
            if limit_bytes and total >= limit_bytes:
                break
    start = time.perf_counter()
    for src in sources:
        parse_source(src)
    parse_s = time.perf_counter() - start
    changed = 0
    start = time.perf_counter()
    for src in sources:
        changed += format_text(src.text) != src.text
    fmt_s = time.perf_counter() - start
    kb = total / 1024
    return {"files": len(sources), "changed": changed, "kb": round(kb, 1),
            "parse_kb_per_s": round(kb / parse_s, 1), "fmt_kb_per_s": round(kb / fmt_s, 1),
            "fmt_vs_parse": round(fmt_s / parse_s, 2)}


EMBEDDED_CORPUS = Path(__file__).resolve().parents[1] / "corpus"


def all_figures(repeat: int = 3, sim_seconds: float = 60.0, parse_kb: int = 512) -> dict:
    """Every figure of `krl bench --json`, measured in this process: the compute benchmark
    on both interpreters and in Python (interp/bench), the simulator's real-time factor and
    simulated s per CPU s as ``python -m robot.bench`` measures them (robot.bench ``measure``:
    after its warm-up run, so both commands give one figure) and the parser's warm rate over
    ``parse_kb`` KB of the shared corpus (the embedded corpus when the shared one is absent)."""

    c = compute(repeat)
    sim = measure(min_motion_s=sim_seconds)
    corpus = DEFAULT_CORPUS if DEFAULT_CORPUS.is_dir() else EMBEDDED_CORPUS
    parse = parse_rate(corpus, limit_bytes=parse_kb * 1024)
    return {
        "vm_vs_tree": round(c["vm_vs_tree"], 2),
        "vm_loop": c["vm_loop"],
        "tree_stmts_per_s": round(c["tree_stmts_per_s"]),
        "vm_stmts_per_s": round(c["vm_stmts_per_s"]),
        "sim_realtime_factor": sim["sim_realtime_factor"],
        "sim_cpu_factor": sim["sim_cpu_factor"],
        "parse_kb_per_s": parse["warm_kb_per_s"],
        "python_stmts_per_s": round(c["python_stmts_per_s"]),
    }


@click.group(invoke_without_command=True)
@click.option("--json", "as_json", is_flag=True, help="Print one JSON line with every figure.")
@click.option("--repeat", type=int, default=3, show_default=True, help="Runs of the compute benchmark (best counts).")
@click.option("--sim-seconds", type=float, default=60.0, show_default=True,
              help="Simulated seconds of the simulator benchmark (with --json).")
@click.option("--parse-kb", type=int, default=512, show_default=True,
              help="KB of the corpus for the parser rate (with --json).")
@click.pass_context
def bench(ctx: click.Context, as_json: bool, repeat: int, sim_seconds: float, parse_kb: int) -> None:
    """Benchmarks (ratios measured in one run). Without a subcommand: the compute benchmark
    (interp/bench/bench.src) on the tree interpreter, the VM and in Python."""
    if ctx.invoked_subcommand is not None:
        return
    if as_json:
        click.echo(json.dumps(all_figures(repeat, sim_seconds, parse_kb)))
        return
    _print_compute(repeat, None)


def _print_compute(repeat: int, baseline_rev: str | None, as_json: bool = False, cpu: bool = False) -> None:

    if baseline_rev:
        try:
            with Baseline(baseline_rev) as base:
                c = compute(repeat, base, cpu=cpu)
        except BaselineError as exc:
            raise click.UsageError(str(exc)) from None
    else:
        c = compute(repeat, cpu=cpu)
    if as_json:
        click.echo(json.dumps(c))
        return
    click.echo(f"compute benchmark, {c['steps']} statements and loop iterations, best of {repeat}"
               f"{' (CPU time of each process)' if cpu else ''}:")
    click.echo(f"  tree interpreter {c['tree_s']:.3f} s  {c['tree_stmts_per_s']:>12,.0f} stmts/s")
    click.echo(f"  VM               {c['vm_s']:.3f} s  {c['vm_stmts_per_s']:>12,.0f} stmts/s"
               f"  ({c['vm_vs_tree']:.2f}x the tree interpreter; {c['vm_loop']} loop)")
    click.echo(f"  Python           {c['python_s']:.4f} s  {c['python_stmts_per_s']:>12,.0f} stmts/s"
               f"  ({c['python_vs_vm']:.0f}x the VM)")
    if baseline_rev:
        click.echo(f"  tree at {c['baseline_rev']:7s} {c['baseline_tree_s']:.3f} s  "
                   f"{c['steps'] / c['baseline_tree_s']:>12,.0f} stmts/s  (this tree interpreter: "
                   f"{c['tree_vs_baseline']:.2f}x its speed)")
        click.echo(f"  VM at {c['baseline_rev']:7s}   {c['baseline_vm_s']:.3f} s  "
                   f"{c['steps'] / c['baseline_vm_s']:>12,.0f} stmts/s  (this VM: "
                   f"{c['vm_vs_baseline']:.2f}x its speed; {c['baseline_vm_loop']} loop)")


@bench.command("vm")
@click.option("--repeat", type=int, default=3, show_default=True, help="Runs of each (best counts).")
@click.option("--baseline", "baseline_rev", default=None, metavar="REV",
              help="Also run the tree interpreter and the VM of git revision REV (e.g. 8175047, the "
                   "starting commit of issue 38) side by side, from a temporary git worktree (its "
                   "VM loop compiled there).")
@click.option("--cpu", is_flag=True, help="Time each run by its process's CPU time instead of wall "
                                          "time (a shared machine's load disturbs it far less).")
@click.option("--json", "as_json", is_flag=True, help="One JSON object.")
def bench_vm(repeat: int, baseline_rev: str | None, as_json: bool, cpu: bool) -> None:
    """The compute benchmark (interp/bench/bench.src) on the tree interpreter, the VM and in
    Python, interleaved in this run; with --baseline, the tree interpreter and the VM of
    another revision too (this tree interpreter and this VM must stay at least as fast)."""
    _print_compute(repeat, baseline_rev, as_json, cpu)


def engine_rates(corpus: Path, repeat: int = 3, engines: list[str] | None = None) -> dict:
    """KB/s of each available parse engine (krl/syntax/engines) over the same files, rounds
    interleaved (python, java, python, java, ...), best of `repeat`; one thread each, results
    built in full (the java figure includes the Python side: pre-filters, records, fallbacks)."""

    sources = [s for s in (read_source(p) for p in discover(corpus)) if s.status == "ok"]
    kb = sum(s.size for s in sources) / 1024
    names = [e for e in available() if engines is None or e in engines]
    best = {name: float("inf") for name in names}
    for _ in range(max(1, repeat)):
        for name in names:
            start = time.perf_counter()
            for _res in parse_sources(sources, name, threads=1):
                pass
            best[name] = min(best[name], time.perf_counter() - start)
    out = {"engines": {name: {"kb_per_s": round(kb / best[name], 1)} for name in names}}
    fast = [n for n in names if n != "python"]
    out["speedup"] = (round(best["python"] / best[fast[0]], 2) if fast and "python" in best else None)
    return out


@bench.command("parse")
@click.argument("corpus", required=False, type=click.Path(path_type=Path))
@click.option("--json", "as_json", is_flag=True,
              help='Print {"engines": {"python": {"kb_per_s": ..}, "java": {..}}, "speedup": ..}.')
@click.option("--repeat", type=int, default=3, show_default=True, help="Rounds per engine (best counts).")
def bench_parse(corpus: Path | None, as_json: bool, repeat: int) -> None:
    """Parser speed in KB/s of each available engine over CORPUS (default ../shared/krl-corpus),
    measured side by side in this run: rounds interleaved, best of --repeat, one thread each."""

    corpus = corpus or DEFAULT_CORPUS
    if not corpus.is_dir():
        raise click.UsageError(f"corpus not found: {corpus}")
    res = engine_rates(corpus, repeat)
    if as_json:
        click.echo(json.dumps(res))
        return
    for name, fig in res["engines"].items():
        click.echo(f"{name:8s} {fig['kb_per_s']:>10.1f} KB/s")
    if res["speedup"] is not None:
        click.echo(f"speedup  {res['speedup']:.1f}x the python engine (best of {repeat}, interleaved)")
    else:
        click.echo(f"java engine unavailable: {unavailable_reason()}")


@bench.command("fmt")
@click.argument("corpus", required=False, type=click.Path(path_type=Path))
@click.option("--kb", type=int, default=1024, show_default=True, help="KB of the corpus to format.")
@click.option("--json", "as_json", is_flag=True)
def bench_fmt(corpus: Path | None, kb: int, as_json: bool) -> None:
    """Formatter speed over CORPUS (default ../shared/krl-corpus) against the parser, warm."""
    corpus = corpus or DEFAULT_CORPUS
    if not corpus.is_dir():
        raise click.UsageError(f"corpus not found: {corpus}")
    res = fmt_rate(corpus, limit_bytes=kb * 1024)
    if as_json:
        click.echo(json.dumps(res))
    else:
        click.echo(f"{res['files']} files, {res['kb']} KB ({res['changed']} would change): parse "
                   f"{res['parse_kb_per_s']} KB/s, format {res['fmt_kb_per_s']} KB/s; format takes "
                   f"{res['fmt_vs_parse']}x the parse time (one process)")


commands = [bench]
