"""`krl parse FILE...`: syntax-check files and print their syntax errors (registered by app/__init__.py).

Formats (``--format``): ``text`` (compiler style, krl/diagnostics/render.py: location, code, message,
source line, caret; a closing count line), ``json`` (one object per file: path, ok, encoding,
status, ``diagnostics`` in the shared model, the one truth; ``--antlr-errors`` adds ANTLR's raw
``antlr_errors``, debugging data for grammar work: the token where the parser stopped, which may
lie lines after the error the diagnostic names; schema: docs/schemas/parse.schema.json) and ``sarif`` (SARIF 2.1.0, krl/diagnostics/sarif.py). ``--outline`` prints the
symbols (routines, declarations) of each file that parses; ``--tree`` the grammar-rule outline.
Exit 0 when every file parses, 1 otherwise; never a traceback for bad input.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from krl.diagnostics import Diagnostic
from krl.diagnostics.codes import E001, E005
from krl.limits import PARSE_TIMEOUT_S
from krl.syntax.messages import file_diagnostics
from krl.syntax.parse import default_bundle
from krl.terminal import printable, printable_path
from krl.pool import run_tasks
from krl.diagnostics.render import Renderer, SourceLines, use_colour
from krl.syntax.engines import use_engine
from krl.diagnostics.sarif import to_sarif
from krl.syntax.outline import outline as tree_outline
from krl.ast.build import build_module
from krl.ast.outline import symbol_outline


def parse_job(path: str, outline: bool, tree: bool):
    """One file of `krl parse`, as a worker runs it: (ParseResult without its tree, text,
    diagnostics, outline lines). Everything returned is picklable."""
    result, text, diags = file_diagnostics(Path(path), keep_tree=outline or tree)
    entries: list[str] = []
    if result.ok and (outline or tree):
        if tree:
            entries = list(tree_outline(result.tree))
        else:
            entries = list(symbol_outline(build_module(result)))
    result.tree = None
    return result, text, diags, entries


def _jobs_in_order(files, outline: bool, tree: bool, timeout: float | None, jobs: int | None):
    """(path, job result or None, failure Diagnostic or None) per file, in the order of
    `files`. With `timeout`, each file is parsed in a worker process killed past it."""

    if timeout is None:
        for path in files:
            yield path, parse_job(str(path), outline, tree), None
        return
    default_bundle()   # imported once here, inherited by the forked workers
    waiting: dict[int, object] = {}
    nxt = 0
    tasks = ((i, (str(p), outline, tree)) for i, p in enumerate(files))
    for o in run_tasks(parse_job, tasks, jobs=jobs, timeout=timeout):
        waiting[o.key] = o
        while nxt in waiting:
            o = waiting.pop(nxt)
            path = files[nxt]
            nxt += 1
            if o.status == "done":
                yield path, o.value, None
            elif o.status == "timeout":
                yield path, None, Diagnostic(str(path), 1, 1, *E005(timeout=timeout))
            else:
                yield path, None, Diagnostic(str(path), 1, 1, *E001(why=o.detail))


def run_parse(files, fmt: str = "text", outline: bool = False, tree: bool = False, echo=print,
              colour: bool = False, timeout: float | None = None, jobs: int | None = None,
              antlr_errors: bool = False) -> int:
    """Parse `files` and print the result in `fmt`; returns the exit status (0 or 1).

    timeout: seconds per file; each file is then parsed in a worker process (krl/pool.py)
    that is killed past it, and the file gets error E005 while the others are still parsed
    (None: parse here, without a limit; the command passes krl.limits.PARSE_TIMEOUT_S).
    antlr_errors: with fmt "json", add the parser's raw errors as ``antlr_errors`` (1-based columns).
    """
    files = list(files)
    sources = SourceLines()
    renderer = Renderer(echo, colour, sources)
    all_diags: list[Diagnostic] = []
    all_ok = True
    for path, job, failure in _jobs_in_order(files, outline, tree, timeout, jobs):
        if job is None:
            all_ok = False
            all_diags.append(failure)
            if fmt == "json":
                obj = {"path": str(path), "ok": False, "encoding": "",
                       "status": "timeout" if failure.code == E005 else "internal_error",
                       "diagnostics": [failure.as_json()]}
                if antlr_errors:
                    obj["antlr_errors"] = []
                echo(json.dumps(obj))
            elif fmt == "text":
                renderer.emit([failure])
            continue
        result, text, diags, entries = job
        all_ok &= result.ok
        all_diags += diags
        if text or result.ok:
            sources.add(str(path), text)
        if fmt == "json":
            obj = {"path": str(path), "ok": result.ok, "encoding": result.encoding, "status": result.status,
                   "diagnostics": [d.as_json() for d in diags]}
            if antlr_errors:
                obj["antlr_errors"] = [dict(e.as_json(), column=e.column + 1) for e in result.errors]
            echo(json.dumps(obj))
            continue
        if fmt == "text":
            renderer.emit(diags)
        if result.ok and (outline or tree) and fmt == "text":
            for entry in entries:
                echo(f"{printable_path(path)}:{printable(entry)}")
    if fmt == "sarif":
        echo(json.dumps(to_sarif(all_diags), indent=2))
    elif fmt == "text":
        echo(renderer.summary(len(files)))
    return 0 if all_ok else 1


def main_status(files, fmt, as_json, outline, tree, timeout=None, jobs=None, engine: str | None = None,
                antlr_errors: bool = False) -> int:
    """The `parse` command's body (app/__init__.py keeps only the options)."""

    use_engine(engine)

    fmt = "json" if as_json else fmt
    return run_parse(files, fmt, outline, tree, click.echo, use_colour(sys.stdout) and fmt == "text",
                     timeout=timeout, jobs=jobs, antlr_errors=antlr_errors)


@click.command()
@click.argument("files", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--format", "fmt", type=click.Choice(["text", "json", "sarif"]), default="text",
              show_default=True, help="text: compiler style; json: one object per file; sarif: SARIF 2.1.0.")
@click.option("--json", "as_json", is_flag=True, help="Same as --format json.")
@click.option("--antlr-errors", is_flag=True,
              help="With --format json: add the parser's raw errors (antlr_errors), debugging data for grammar work.")
@click.option("--outline", is_flag=True, help="Print the routines and declarations of each file that parses.")
@click.option("--tree", is_flag=True, help="Print the grammar-rule outline of each file that parses.")
@click.option("--engine", type=click.Choice(["auto", "python", "java"]), default=None,
              help="Parse engine: java (fast; needs a JDK), python (the reference), auto: "
                   "java when available (default: $KRL_ENGINE, else auto).")
@click.option("--timeout", type=click.FloatRange(min=0, min_open=True), default=PARSE_TIMEOUT_S,
              show_default=True, help="Seconds one file may parse; past it the parse is stopped (error E005).")
@click.option("--jobs", type=click.IntRange(min=1), default=None,
              help="Worker processes (default: the number of cores).")
def parse(files: tuple[Path, ...], fmt: str, as_json: bool, outline: bool, tree: bool, timeout: float,
          jobs: int | None, engine: str | None, antlr_errors: bool) -> None:
    """Parse FILES; exit 0 when every file parses."""
    sys.exit(main_status(files, fmt, as_json, outline, tree, timeout, jobs, engine, antlr_errors))


commands = [parse]
