"""`krl recover`, `krl growth` and `krl validate`."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import click

from krl.limits import PARSE_TIMEOUT_S
from krl.terminal import printable, printable_path
from krl.archive import ArchiveError, is_archive
from krl.backups import BackupsError, one_folder
from recovery.pipeline import run_recovery
from recovery.scan import discover
from krl.syntax.engines import use_engine
from krl.cluster import SchedulerError
from recovery.report import ReportError
from recovery.grammar_versions import GrammarToolError
from recovery.growth import growth_rows, write_growth
from recovery.validate import DEFAULT_CORPUS, print_validation, validate_constructs
from recovery.construct import REPO_ROOT, ConstructError, new_construct


@click.command()
@click.argument("corpus", required=False, default="corpus", type=click.Path(path_type=Path))
@click.option("--out", default="reports/recovery", type=click.Path(path_type=Path),
              help="Report directory.")
@click.option("--jobs", type=int, default=None, help="Worker processes (default: the number of cores).")
@click.option("--no-cache", is_flag=True, help="Parse every file again (the cache folder is not touched).")
@click.option("--timeout", type=click.FloatRange(min=0, min_open=True), default=PARSE_TIMEOUT_S,
              show_default=True, help="Seconds one file may parse; past it its worker is killed (row `timeout`).")
@click.option("--engine", type=click.Choice(["auto", "python", "java"]), default=None,
              help="Parse engine: java (fast; needs a JDK), python (the reference), auto: java when available "
                   "(default: $KRL_ENGINE, else auto).")
@click.option("--scheduler", default=None, metavar="tcp://HOST:PORT",
              help="Parse the files on this Dask distributed scheduler's cluster (in batches); "
                   "default: local worker processes.")
def recover(corpus: Path, out: Path, jobs: int | None, no_cache: bool, timeout: float, engine: str | None,
            scheduler: str | None) -> None:
    """Parse every KRL file under CORPUS (a folder, a backup or archive .zip, or a folder of
    them), cluster the failures, write the report to --out.

    A controller archive is its KRC backup: its C and Log Files folders are not its programs.

    Exit code: 0 when every file parses, 1 when some do not, 2 when CORPUS holds no KRL file,
    on a usage or internal error
    (or an archive refused by the limits of krl/limits.py, or a report that cannot be
    written: a full disk, a read-only --out), 130 on Ctrl-C, 143 on SIGTERM.
    """

    use_engine(engine)
    if not corpus.is_dir() and not is_archive(corpus):
        click.echo(f"error: corpus folder or .zip archive not found: {printable_path(corpus)}", err=True)
        sys.exit(2)
    start = time.perf_counter()
    try:
        # a folder, a .zip, or a folder of controller archives, as one folder (krl/backups.py)
        with one_folder(corpus) as (folder, label, refused):
            for zipped, why in refused:
                click.echo(f"warning: {printable_path(zipped)}: not read: {printable(why)}", err=True)
            summary = run_recovery(folder, out, jobs=jobs, use_cache=not no_cache, timeout=timeout,
                                   label=label, scheduler=scheduler)
    except (ArchiveError, BackupsError, ReportError, SchedulerError) as exc:
        click.echo(f"error: {printable_path(exc)}", err=True)
        sys.exit(2)
    except OSError as exc:      # the report cannot be written: a full disk, a read-only --out
        click.echo(f"error: the report could not be written to {printable_path(out)}: "
                   f"{printable(exc.strerror or exc)} (the previous report, if any, is kept)", err=True)
        sys.exit(2)
    click.echo(f"{summary.files_ok}/{summary.files} files parse "
               f"({summary.bytes_ok}/{summary.bytes} bytes), {len(summary.clusters)} clusters, "
               f"{time.perf_counter() - start:.1f} s -> {printable_path(out)}/report.md")
    if summary.negative:
        click.echo(f"negative corpus: rejected {summary.negative['rejected']} of "
                   f"{summary.negative['programs']} invalid programs")
    if not summary.files:        # nothing read is no recovery passed (issue 85)
        click.echo(f"error: no KRL file in {printable_path(corpus)}", err=True)
        sys.exit(2)
    sys.exit(0 if summary.files_ok == summary.files else 1)


@click.command()
@click.argument("corpus", type=click.Path(path_type=Path))
@click.option("--out", default="reports/growth", type=click.Path(path_type=Path))
@click.option("--jobs", type=int, default=None, help="Grammar versions scanned at a time (default: the number of cores).")
@click.option("--no-cache", is_flag=True)
@click.option("--engine", type=click.Choice(["auto", "python", "java"]), default=None,
              help="Parse engine (java: fast, needs a JDK; python: the reference; default: $KRL_ENGINE, else auto).")
def growth(corpus: Path, out: Path, jobs: int | None, no_cache: bool, engine: str | None) -> None:
    """Replay every committed version of grammar/KRL.g4 over CORPUS: growth.csv and growth.png.

    CORPUS is read as `krl recover` reads it (a folder, a backup or archive .zip, or a folder of
    them); exit 2 when it holds no KRL file."""

    use_engine(engine)
    if not corpus.is_dir() and not is_archive(corpus):
        click.echo(f"error: corpus folder or .zip archive not found: {printable_path(corpus)}", err=True)
        sys.exit(2)
    try:
        # a folder, a .zip, or a folder of controller archives, as one folder (krl/backups.py)
        with one_folder(corpus) as (folder, _label, refused):
            for zipped, why in refused:
                click.echo(f"warning: {printable_path(zipped)}: not read: {printable(why)}", err=True)
            if not discover(folder):        # nothing to read is no growth measured (issue 85)
                click.echo(f"error: no KRL file in {printable_path(corpus)}", err=True)
                sys.exit(2)
            rows = growth_rows(folder, jobs=jobs, use_cache=not no_cache)
    except (GrammarToolError, ArchiveError, BackupsError) as exc:
        click.echo(f"error: {printable_path(exc)}", err=True)
        sys.exit(2)
    write_growth(out, rows)
    for i, r in enumerate(rows):
        click.echo(f"{i:3d} {r['commit']} {r['files_ok']:4d}/{r['files']} files "
                   f"{r['clusters']:4d} clusters  {r['subject']}")
    click.echo(f"-> {out}/growth.csv, {out}/growth.png")


@click.command()
@click.argument("names", nargs=-1)
@click.option("--corpus", type=click.Path(path_type=Path), default=None,
              help="Also report the corpus clusters each construct closed (default: "
                   "../shared/krl-corpus when present).")
@click.option("--no-corpus", is_flag=True, help="Only run the examples.")
@click.option("--jobs", type=int, default=None, help="Grammar versions scanned at a time (default: the number of cores).")
@click.option("--engine", type=click.Choice(["auto", "python", "java"]), default=None,
              help="Parse engine for the corpus scans (java: fast, needs a JDK; python: the reference; "
                   "default: $KRL_ENGINE, else auto).")
def validate(names: tuple[str, ...], corpus: Path | None, no_corpus: bool, jobs: int | None,
             engine: str | None) -> None:
    """Run every grammar construct's positive and negative examples (or only NAMES)."""

    use_engine(engine)
    if corpus is None and not no_corpus and DEFAULT_CORPUS.is_dir():
        corpus = DEFAULT_CORPUS
    try:
        reports = validate_constructs(list(names), corpus=None if no_corpus else corpus, jobs=jobs)
    except GrammarToolError as exc:
        click.echo(f"error: {exc}", err=True)
        sys.exit(2)
    ok = print_validation(reports)
    sys.exit(0 if ok else 1)


@click.group()
def construct() -> None:
    """Grammar constructs: start a new one from a cluster of the recovery report."""


@construct.command("new")
@click.argument("name")
@click.option("--from", "cluster_id", required=True, metavar="CLUSTER", help="Cluster id of the report (e.g. C680b7aa).")
@click.option("--report", default="reports/recovery", type=click.Path(path_type=Path), show_default=True,
              help="The recovery report folder (krl recover --out).")
@click.option("--corpus", default=None, type=click.Path(path_type=Path),
              help="The corpus the report was made from (default: the one the report names).")
@click.option("--root", default=None, type=click.Path(path_type=Path),
              help="The project folder to write into (default: this checkout).")
def construct_new(name: str, cluster_id: str, report: Path, corpus: Path | None, root: Path | None) -> None:
    """Create grammar/constructs/NAME/ from CLUSTER: positive examples cut from the corpus (the
    smallest module that still shows the construct, each with its origin), a negative-example
    template, the grammar/CHANGES.md row and a conformance-case stub."""

    base = root or REPO_ROOT
    try:
        written = new_construct(name, cluster_id, report, corpus, base)
    except ConstructError as exc:
        click.echo(f"error: {printable(str(exc))}", err=True)
        sys.exit(2)
    for p in written:
        click.echo(f"wrote {printable(str(p.relative_to(base)))}")
    click.echo(f"next: write the rule in grammar/KRL.g4, fill in the .expect files and a bad_ example, "
               f"then krl validate {name}")


commands = [recover, growth, validate, construct]
