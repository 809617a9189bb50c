"""`krl recover`, `krl growth` and `krl validate`."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import click



@click.command()
@click.argument("corpus", required=False, default="corpus", type=click.Path(path_type=Path))
@click.option("--out", default="reports/recovery", type=click.Path(path_type=Path),
              help="Report directory.")
@click.option("--jobs", type=int, default=None, help="Worker processes (default: the number of cores).")
@click.option("--no-cache", is_flag=True, help="Parse every file again.")
def recover(corpus: Path, out: Path, jobs: int | None, no_cache: bool) -> None:
    """Parse every KRL file under CORPUS, cluster the failures, write the report to --out.

    Exit code: 0 when every file parses, 1 when some do not, 2 on a usage or internal error.
    """
    from recovery.pipeline import run_recovery  # noqa: PLC0415

    if not corpus.is_dir():
        click.echo(f"error: corpus directory not found: {corpus}", err=True)
        sys.exit(2)
    start = time.perf_counter()
    summary = run_recovery(corpus, out, jobs=jobs, use_cache=not no_cache)
    click.echo(f"{summary.files_ok}/{summary.files} files parse "
               f"({summary.bytes_ok}/{summary.bytes} bytes), {len(summary.clusters)} clusters, "
               f"{time.perf_counter() - start:.1f} s -> {out}/report.md")
    if summary.negative:
        click.echo(f"negative corpus: rejected {summary.negative['rejected']} of "
                   f"{summary.negative['programs']} invalid programs")
    sys.exit(0 if summary.files_ok == summary.files else 1)


commands = [recover]
