"""``krl plot`` and ``krl robot show|export``: the robot package's subcommands (registered by
krl/cli/__init__.py)."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from krl.terminal import printable
from robot.machine import load_machine


@click.command("plot")
@click.argument("trace", type=click.Path(path_type=Path, exists=True, dir_okay=False))
@click.option("-o", "--output", type=click.Path(path_type=Path), default=None,
              help="PNG file to write (default: TRACE with the suffix .png).")
def plot(trace: Path, output: Path | None) -> None:
    """Draw the TCP path of a JSON Lines TRACE (3D and top view, programmed points,
    approximation zones, I/O events) as a PNG."""
    # costs 0.003 s at start-up (python -X importtime, 2026-11-25)
    from robot.plot import plot_trace  # noqa: PLC0415

    out = output or trace.with_suffix(".png")
    try:
        plot_trace(trace, out)
    except ValueError as exc:
        click.echo(f"error: {exc}", err=True)
        sys.exit(1)
    click.echo(str(out))


@click.group("robot")
def robot_group() -> None:
    """The simulated robot: its model from a backup's machine data or a robot YAML (issue 22)."""


def _load(path: Path | None):
    # costs 0.16 s at start-up (python -X importtime, 2026-11-25)
    from robot.mada import MachineDataError, load_robot  # noqa: PLC0415
    try:
        return load_robot(path) if path is not None else load_machine()
    except MachineDataError as exc:
        click.echo(f"error: {printable(exc)}", err=True)
        sys.exit(2)


@robot_group.command("show")
@click.argument("robot", type=click.Path(path_type=Path), required=False)
def show(robot: Path | None) -> None:
    """Print the robot model of ROBOT (a KRC backup folder or .zip, a $machine.dat, a robot
    YAML or a KUKA model's name from `krl robot list`; default the KR 6 R900): name, parameters with their source (file:line or the rule
    that derived them), axis limits, speeds, accelerations, reach."""
    # costs 0.0007 s at krl's start-up (python -X importtime, 2026-11-25)
    from robot.show import show_lines  # noqa: PLC0415

    for line in show_lines(_load(robot)):
        click.echo(line)


@robot_group.command("list")
def list_models() -> None:
    """List the catalogue of KUKA robots by model name (robot/data/catalogue.yaml): each model's
    $MODEL_NAME spelling, reach, axis limits and speeds, and the public description every value
    comes from; `--robot NAME` and `krl robot show NAME` take either spelling."""
    # costs 0.02 s at start-up (python -X importtime, 2026-11-26)
    from robot.catalogue import catalogue_lines  # noqa: PLC0415

    for line in catalogue_lines():
        click.echo(line)


@robot_group.command("export")
@click.argument("robot", type=click.Path(path_type=Path), required=False)
@click.option("--format", "fmt", type=click.Choice(["urdf", "mjcf"]), default="urdf", show_default=True)
@click.option("-o", "--output", type=click.Path(path_type=Path), required=True, help="File to write.")
def export(robot: Path | None, fmt: str, output: Path) -> None:
    """Write the robot model of ROBOT (as for `krl robot show`) as URDF or MJCF (MuJoCo)."""
    m = _load(robot)
    if fmt == "urdf":
        # costs 0.01 s at start-up (python -X importtime, 2026-11-25)
        from robot.urdf import build_urdf  # noqa: PLC0415

        text = build_urdf(m)
    else:
        # costs 0.02 s at start-up (python -X importtime, 2026-11-25)
        from robot.mjcf import build_mjcf  # noqa: PLC0415

        text = build_mjcf(m)
    output.write_text(text, encoding="utf-8")
    click.echo(str(output))


commands = [plot, robot_group]
