"""`krl asm PROGRAM`: print the readable assembly of a program's routines (issue 7)."""

from __future__ import annotations

import sys
from pathlib import Path

import click


def program_assembly(program: Path, workspace: Path | None = None, all_modules: bool = False) -> str:
    """The assembly text of PROGRAM's module (with ``all_modules``: of every module of the
    workspace that has routines), compiled as the VM would compile it."""
    from interp.run import make_runtime  # noqa: PLC0415

    from krl.terminal import printable  # noqa: PLC0415

    from interp.vm.compiler import compile_module  # noqa: PLC0415

    rt, _ = make_runtime(program, workspace=workspace, mujoco=False, interp="vm", check=False)
    prog = rt.program
    main = prog.module_of(prog.main_path)
    mods = [main]
    if all_modules:
        mods += [m for m in prog.modules if m is not main and m.routines]
    out = []
    for m in mods:
        if m is None:
            continue
        if m.syntax_errors:
            out.append(f"; module {printable(m.name)}: syntax errors, not compiled: {printable(m.syntax_errors[0])}\n")
            continue
        out.append(f"; module {printable(m.name)}\n" + compile_module(rt, m))
    return "\n".join(out)


@click.command("asm")
@click.argument("program", type=click.Path(path_type=Path))
@click.option("--workspace", type=click.Path(path_type=Path), default=None, help="Folder of the program's modules.")
@click.option("--all", "all_modules", is_flag=True, help="Also the other modules of the workspace (BASIS, ...).")
def asm(program: Path, workspace, all_modules: bool) -> None:
    """Print the VM assembly of PROGRAM (one instruction per line, source lines as comments)."""
    if not program.exists():
        click.echo(f"error: {program}: no such file", err=True)
        sys.exit(2)
    click.echo(program_assembly(program, workspace, all_modules), nl=False)
