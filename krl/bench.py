"""`krl bench`: benchmarks that print ratios and rates measured in the same run.

`krl bench parse [CORPUS]` measures the parser in KB/s over a corpus, cold (a fresh
parser whose ANTLR prediction cache is empty) and warm (the same files again in the same
process), single process, so the figure does not depend on the number of cores.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import click

DEFAULT_CORPUS = Path(__file__).resolve().parents[1].parent / "shared" / "krl-corpus"


def parse_rate(corpus: Path, limit_bytes: int | None = None) -> dict:
    """Parse every KRL file under corpus twice in this process; returns KB/s cold and warm."""
    from krl.syntax.parse import parse_source  # noqa: PLC0415
    from krl.syntax.source import read_source  # noqa: PLC0415
    from recovery.scan import discover  # noqa: PLC0415

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


@click.group(invoke_without_command=True)
@click.pass_context
def bench(ctx: click.Context) -> None:
    """Benchmarks (ratios measured in one run)."""
    if ctx.invoked_subcommand is None:
        click.echo(ctx.get_help())


@bench.command("parse")
@click.argument("corpus", required=False, type=click.Path(path_type=Path))
@click.option("--json", "as_json", is_flag=True)
def bench_parse(corpus: Path | None, as_json: bool) -> None:
    """Parser speed in KB/s over CORPUS (default ../shared/krl-corpus), cold and warm."""
    corpus = corpus or DEFAULT_CORPUS
    if not corpus.is_dir():
        raise click.UsageError(f"corpus not found: {corpus}")
    res = parse_rate(corpus)
    if as_json:
        click.echo(json.dumps(res))
    else:
        click.echo(f"{res['files']} files, {res['kb']} KB: cold {res['cold_kb_per_s']} KB/s, "
                   f"warm {res['warm_kb_per_s']} KB/s (one process)")


commands = [bench]
