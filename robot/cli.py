"""``krl plot``, ``krl robot show|export`` and ``krl trace show|compare``: the robot package's
subcommands (registered by app/__init__.py)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from krl.archive import ArchiveError, is_archive
from krl.backups import BackupsError, archive_named
from krl.durable import write_text
from krl.kssarchive import info_lines, read_info
from krl.terminal import printable
from robot.machine import load_machine
from robot.plot import plot_trace
from robot.cellplot import plot_cell
from robot.mada import MachineDataError, load_robot
from robot.show import show_lines
from robot.catalogue import catalogue_lines
from robot.kukatrace.model import load_run
from robot.kukatrace.recording import RecordingError
from robot.kukatrace import compare as C, show as S
from robot.urdf import build_urdf
from robot.mjcf import build_mjcf
from robot.kukatrace.show import plot_compare


@click.command("plot")
@click.argument("trace", type=click.Path(path_type=Path, exists=True, dir_okay=False))
@click.option("-o", "--output", type=click.Path(path_type=Path), default=None,
              help="PNG file to write (default: TRACE with the suffix .png).")
def plot(trace: Path, output: Path | None) -> None:
    """Draw the TCP path of a JSON Lines TRACE (3D and top view, programmed points,
    approximation zones, I/O events) as a PNG; a cell's result run.cell.json (krl run CELL.yaml
    --trace run.jsonl): every robot's TCP path in the cell's world."""

    cell = trace.name.endswith(".cell.json")
    out = output or (trace.with_name(trace.name[:-len(".json")] + ".png") if cell else trace.with_suffix(".png"))
    try:
        if cell:
            plot_cell(trace, out)
        else:
            plot_trace(trace, out)
    except (ValueError, FileNotFoundError) as exc:
        click.echo(f"error: {printable(exc)}", err=True)
        sys.exit(1)
    click.echo(str(out))


@click.group("robot")
def robot_group() -> None:
    """The simulated robot: its model from a backup's machine data or a robot YAML (issue 22)."""


def _load(path: Path | None):
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
    that derived them), axis limits, speeds, accelerations, reach. A controller archive (a folder
    or .zip with am.ini or ArchiveInfo.xml) adds what it says of itself: the robot's name and
    serial, its type, the KSS version and the installed technology packages (krl/kssarchive.py)."""

    for line in show_lines(_load(robot)):
        click.echo(line)
    info = None
    if robot is not None and (robot.is_dir() or is_archive(robot)):
        try:
            info = read_info(archive_named(robot))   # a folder holding one archive .zip: its manifest
        except (ArchiveError, BackupsError):
            info = None                   # an archive _load read can still be refused here: not shown
    for line in info_lines(info) if info is not None else []:
        click.echo(printable(line))


@robot_group.command("list")
def list_models() -> None:
    """List the catalogue of KUKA robots by model name (robot/data/catalogue.yaml): each model's
    $MODEL_NAME spelling, reach, axis limits and speeds, and the public description every value
    comes from; `--robot NAME` and `krl robot show NAME` take either spelling."""

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

        text = build_urdf(m)
    else:

        text = build_mjcf(m)
    write_text(output, text)
    click.echo(str(output))


@click.group("trace")
def trace_group() -> None:
    """KUKA Trace recordings (a KR C4's KRCIpo CSV and PROG.TXT) and simulated runs' traces: show
    one, compare a run with a recording (issue 60; docs/trace.md)."""


def _view(path: Path, override: float | None):
    try:
        return load_run(path, override)
    except (RecordingError, ValueError, OSError) as exc:
        click.echo(f"error: {printable(str(exc))}", err=True)
        sys.exit(1)


_OVERRIDE_HELP = ("program override (%) a recording ran at (PROG.TXT does not record it); default: "
                  "the one its END signals allow (100 %, else a multiple of 5 %)")


@trace_group.command("show")
@click.argument("rec", type=click.Path(path_type=Path))
@click.option("--override", type=float, default=None, help=_OVERRIDE_HELP)
@click.option("--json", "as_json", is_flag=True, help="Print JSON (docs/schemas/trace-show.schema.json).")
@click.option("-o", "--output", type=click.Path(path_type=Path), default=None,
              help="PNG to write: axes, TCP speed with the motion boundaries, TCP path, per segment.")
def trace_show(rec: Path, override: float | None, as_json: bool, output: Path | None) -> None:
    """Show REC: a KUKA Trace recording (its _KRCIpo.csv or _PROG.TXT, or their common stem) or a
    run's JSON Lines trace (krl run --trace): its segments, motions (START, END, time, pause
    before, type, line, point) and samples."""

    view = _view(rec, override)
    if as_json:
        click.echo(json.dumps(S.as_json(view), indent=1))
    else:
        for line in S.show_lines(view):
            click.echo(printable(line))
    if output is not None:
        S.plot_view(view, output)
        click.echo(str(output), err=as_json)


@trace_group.command("compare")
@click.argument("run", type=click.Path(path_type=Path))
@click.argument("rec", type=click.Path(path_type=Path))
@click.option("--override", type=float, default=None, help=_OVERRIDE_HELP + " (REC)")
@click.option("--run-override", type=float, default=None, help="the same for RUN when it is a recording")
@click.option("--segment", default=None, help="RUN's segment to compare with REC: its name or number (1-based)")
@click.option("--setpoints", is_flag=True,
              help="measure a simulated RUN's path on its setpoints, not on the actual values they give "
                   "(the robot's identified averaging and following error; docs/trace.md)")
@click.option("--json", "as_json", is_flag=True, help="Print JSON (docs/schemas/trace-compare.schema.json).")
@click.option("-o", "--output", type=click.Path(path_type=Path), default=None,
              help="PNG to write: RUN (dashed) over REC per segment.")
def trace_compare(run: Path, rec: Path, override: float | None, run_override: float | None,
                  segment: str | None, setpoints: bool, as_json: bool, output: Path | None) -> None:
    """Compare RUN (a simulated run's trace, or a recording) with the recording REC, motion by
    motion within each TraceStart..TraceStop segment: motion time (END - START) and its error,
    the exact-stop pause, the path deviation of RUN's TCP from REC's (mm)."""

    a = _view(run, run_override)
    b = _view(rec, override)
    try:
        result = C.compare(a, b, segment, actual=not setpoints)
    except C.CompareError as exc:
        click.echo(f"error: {printable(str(exc))}", err=True)
        sys.exit(2)
    if as_json:
        click.echo(json.dumps(C.as_json(a, b, result), indent=1))
    else:
        for line in C.text_lines(a, b, result):
            click.echo(printable(line))
    if output is not None:

        plot_compare(a, b, result, output)
        click.echo(str(output), err=as_json)


commands = [plot, robot_group, trace_group]
