"""`krl check PATH... [--json]`: the front end's command (registered by krl/cli.py).

PATH is a file (checked with the .src/.dat of its module), a KRC backup folder (one
workspace), or a folder holding backups (one workspace per backup) or plain files (one
workspace). Output: one ``path:line:col: error|warning CODE message`` line per diagnostic,
or with --json one JSON object per workspace. Exit 1 when there are errors, 0 otherwise,
2 for an internal failure; never a Python traceback for bad input.
"""

from __future__ import annotations

import json
import sys

import click


@click.command()
@click.argument("paths", nargs=-1, required=True)
@click.option("--json", "as_json", is_flag=True, help="One JSON object per workspace.")
@click.option("--no-warnings", is_flag=True, help="Print errors only.")
@click.option("--report", "report_dir", default=None,
              help="Instead: write check_report.md/.json for the KRC backups below PATH into this folder.")
def check(paths: tuple[str, ...], as_json: bool, no_warnings: bool, report_dir: str | None) -> None:
    """Type-check KRL files or KRC backups; exit 1 when there are errors."""
    if report_dir is not None:
        from krl.semantics.report import check_report  # noqa: PLC0415
        try:
            for path in paths:
                _data, md = check_report(path, report_dir)
                click.echo(md)
        except Exception as exc:  # noqa: BLE001
            click.echo(f"krl check: internal error: {type(exc).__name__}: {exc}")
            sys.exit(2)
        sys.exit(0)
    status = run_check(list(paths), as_json, no_warnings, click.echo)
    sys.exit(status)


def run_check(paths: list[str], as_json: bool = False, no_warnings: bool = False, echo=print) -> int:
    """Check `paths` and print the diagnostics; returns the exit status (0, 1 or 2)."""
    from krl.workspace import workspaces_for  # noqa: PLC0415

    any_error = False
    seen: set = set()      # files already checked: `krl check A.src A.dat` checks module A once
    try:
        for path in paths:
            if _resolved(path) in seen:
                continue
            for ws in workspaces_for(path):
                seen.update(_resolved(f.path) for f in ws.files)
                diags = ws.check()
                any_error |= any(d.is_error for d in diags)
                shown = [d for d in diags if d.is_error or not no_warnings]
                if as_json:
                    echo(json.dumps({
                        "workspace": ws.root,
                        "files": len(ws.files),
                        "errors": sum(d.is_error for d in diags),
                        "warnings": sum(not d.is_error for d in diags),
                        "diagnostics": [d.as_json() for d in shown],
                    }))
                else:
                    for d in shown:
                        echo(d.format())
    except Exception as exc:  # noqa: BLE001 - a last line of defence: no traceback
        echo(f"krl check: internal error: {type(exc).__name__}: {exc}")
        return 2
    return 1 if any_error else 0


def _resolved(path) -> str:
    from pathlib import Path  # noqa: PLC0415
    try:
        return str(Path(path).resolve())
    except OSError:
        return str(path)


commands = [check]
