"""`krl asm PROGRAM`: print the readable assembly of a program's routines (issue 7)."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from krl.files import same_file, spelled, spelled_within
from krl.project import project_of
from krl.terminal import printable
from interp.run import RunSetupError, located
from interp.runtime.program import basis_files, checked_workspace
from interp.vm.compiler import compile_module


#: what a module's line says when it has syntax errors (``krl asm`` then exits 1)
NOT_COMPILED = ": syntax errors, not compiled: "


def program_assembly(program: Path, workspace: Path | None = None, all_modules: bool = False) -> str:
    """The assembly text of :func:`assembly` (without its count of modules not compiled)."""
    return assembly(program, workspace, all_modules)[0]


def assembly(program: Path, workspace: Path | None = None, all_modules: bool = False) -> tuple[str, int]:
    """The assembly text of PROGRAM's module (with ``all_modules``: of every module of its
    program that has routines): the listings the VM links and runs, compiled from the
    checked, resolved program (krl/project.py, krl/semantics/resolve.py) with no runtime; and
    the number of those modules not compiled for their syntax errors (each a line saying so)."""

    main_path = spelled_within(program, workspace)         # the user's spelling, links kept
    project = project_of(main_path, spelled(workspace) if workspace else None)
    ws = checked_workspace(project, basis_files(project))
    units = [u for u in ws.units if any(f is not None and same_file(f.path, main_path) for f in (u.src, u.dat))]
    if all_modules:
        units += [u for u in ws.units if u not in units and u.routines]
    out, failed = [], 0
    for u in units:
        name = u.name.upper()
        bad = [f for f in (u.src, u.dat) if f is not None and not f.ok]
        if bad:
            first = next((d for d in ws.sink.sorted() if d.path == bad[0].path and d.is_error), None)
            why = f"{first.path}:{first.line}:{first.column}: {first.message}" if first else bad[0].status
            out.append(f"; module {printable(name)}{NOT_COMPILED}{printable(why)}\n")
            failed += 1
            continue
        out.append(f"; module {printable(name)}\n" + compile_module(u.routines))
    return "\n".join(out), failed


@click.command("asm")
@click.argument("program", type=click.Path(path_type=Path))
@click.option("--workspace", type=click.Path(path_type=Path), default=None, help="Folder of the program's modules.")
@click.option("--all", "all_modules", is_flag=True, help="Also the other modules of the workspace (BASIS, ...).")
def asm(program: Path, workspace, all_modules: bool) -> None:
    """Print the VM assembly of PROGRAM (one instruction per line, source lines as comments).
    PROGRAM is a .src, or a backup folder, controller archive (folder or .zip) or folder holding
    one archive, read as ``krl run`` reads it (its cell program). Exit 1 when a module has
    syntax errors (its line says so), 2 when PROGRAM cannot be found."""
    if not program.exists():
        click.echo(f"error: {printable(program)}: no such file", err=True)
        sys.exit(2)
    try:
        with located(program, workspace, "krl asm") as (found, folder, shown):
            text, failed = assembly(found, folder, all_modules)
            text = shown(text)
    except RunSetupError as exc:
        click.echo(f"error: {printable(exc)}", err=True)
        sys.exit(2)
    click.echo(text, nl=False)
    sys.exit(1 if failed else 0)
