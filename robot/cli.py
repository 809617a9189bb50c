"""``krl plot``: the robot package's subcommand (registered by krl/cli/__init__.py)."""

from __future__ import annotations

import sys
from pathlib import Path

import click


@click.command("plot")
@click.argument("trace", type=click.Path(path_type=Path, exists=True, dir_okay=False))
@click.option("-o", "--output", type=click.Path(path_type=Path), default=None,
              help="PNG file to write (default: TRACE with the suffix .png).")
def plot(trace: Path, output: Path | None) -> None:
    """Draw the TCP path of a JSON Lines TRACE (3D and top view, programmed points,
    approximation zones, I/O events) as a PNG."""
    from robot.plot import plot_trace  # noqa: PLC0415

    out = output or trace.with_suffix(".png")
    try:
        plot_trace(trace, out)
    except ValueError as exc:
        click.echo(f"error: {exc}", err=True)
        sys.exit(1)
    click.echo(str(out))


commands = [plot]
