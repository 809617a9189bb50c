"""`krl conformance`: run the conformance suites and write the report (issue 8)."""

from __future__ import annotations

import sys
from pathlib import Path

import click
from conformance.report import DEFAULT_CORPUS, run_all
from krl.cluster import SchedulerError
from krl.pool import default_jobs


@click.command("conformance")
@click.option("--out", "out", type=click.Path(path_type=Path), default=Path("reports/conformance"),
              show_default=True, help="Report directory.")
@click.option("--fuzz", "fuzz_n", type=int, default=200, show_default=True,
              help="Number of generated programs for the differential fuzzer (0: no fuzzing).")
@click.option("--no-real", is_flag=True, help="Skip the real programs of ../shared/krl-corpus.")
@click.option("--corpus", type=click.Path(path_type=Path), default=None,
              help="Corpus of KRC backups (default ../shared/krl-corpus).")
@click.option("--real-limit", type=int, default=None, help="Run at most N real programs.")
@click.option("--fuzz-random", is_flag=True,
              help="Fresh random programs (default: the same reproducible set every run).")
@click.option("--scheduler", default=None, metavar="tcp://HOST:PORT",
              help="Run the cases and the real programs on this Dask distributed scheduler's cluster "
                   "(its workers see the repository and the corpus at the same paths); the same report.")
@click.option("--jobs", type=click.IntRange(min=1), default=None, metavar="N",
              help="Worker processes of this machine for the cases, the fuzzer's programs and the real "
                   "programs (default: one per core; 1: all in this process); the same report.")
def conformance(out: Path, fuzz_n: int, no_real: bool, corpus: Path | None, real_limit: int | None,
                fuzz_random: bool, scheduler: str | None, jobs: int | None) -> None:
    """Run the hand-written cases on every available interpreter, the differential fuzzer and
    the corpus programs; write summary.json, report.md and report.html to --out.

    Exit code 0 when every case that is not marked pending passes and the interpreters agree,
    1 otherwise."""

    try:
        s = run_all(out, fuzz_n=fuzz_n, real=not no_real, corpus=corpus or DEFAULT_CORPUS,
                    real_limit=real_limit, fuzz_random=fuzz_random, echo=click.echo, scheduler=scheduler,
                    jobs=jobs if jobs is not None else default_jobs())
    except SchedulerError as exc:
        click.echo(f"error: {exc}", err=True)
        sys.exit(2)
    click.echo(f"cases {s['passed']}/{s['cases']} pass; pending: {len(s['pending'])}; "
               f"tree = vm: {s['tree_vm_agree'] if s['tree_vm_agree'] is not None else 'n/a (' + s['vm'] + ')'}")
    bad = bool(s["failed_not_pending"])
    if s.get("fuzz_tree_ok") is not None and s["fuzz_tree_ok"] < s["fuzz_programs"]:
        bad = True
    sys.exit(1 if bad else 0)


commands = [conformance]
