"""`krl run`: run a KRL program on the simulated controller (issue 6).

Exit codes: 0 completed; 3 stopped (HALT, --max-steps, --max-sim-time, deadlocked WAIT);
1 KRL run-time error; 2 usage or internal error (a --trace that cannot be written: a missing
folder, a read-only or full file system); 130 Ctrl-C (SIGINT), 143 SIGTERM: the trace then ends
with an ``end`` event of reason ``interrupted`` (krl/signals.py; docs/security.md "Faults").
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from interp.spec import Option, param_of, run_options
from krl.archive import ArchiveError, is_archive
from krl.backups import BackupsError, one_backup
from krl.kssarchive import ARCHIVE_MANIFESTS
from krl.project import backup_of
from krl.limits import MAX_CELL_ROBOTS
from krl.terminal import printable
from krl import signals
from krl.durable import write_text
from robot.trace import TraceWriteError, read_trace
from interp.run import program_in, run_setup, RunSetupError, RunSinks
from interp.summary import RunObserver, starvation_lines, summary_lines
from interp.progress import RunProgress
from robot.stimuli import StartError, StimulusError
from net.hub import NetError
from interp.scene import chosen
from interp.cellinit import cell_init, from_run as rules_from_run
from interp.cellwires import backup_root, robot_of, starter as robots_starter
from interp.robotcell import CellError, cell_result_path, cell_runs, is_robot_cell, load_robot_cell, run_cell
from interp.robotcell import summary_lines as robot_cell_summary
from interp.spec import RUN_SIM_TIME_S


def click_param(name: str, opt: Option):
    """The click decorator of krl run's parameter `name` (a RunSpec field, or a door option of
    interp/spec.py) from its :class:`~interp.spec.Option`: the argument PROGRAM, a flag, a
    choice, an integer range, a path, a number."""
    if not opt.flag:
        return click.argument(name, type=click.Path(path_type=Path))
    if opt.kind is bool:
        return click.option(opt.flag, param_of(name, opt), is_flag=True, help=opt.help)
    if opt.choices:
        kind = click.Choice(list(opt.choices), case_sensitive=opt.case_sensitive)
    elif opt.kind is int and (opt.minimum is not None or opt.maximum is not None):
        kind = click.IntRange(opt.minimum, opt.maximum)
    elif opt.kind is Path:
        kind = click.Path(path_type=Path)
    else:
        kind = {int: click.INT, float: click.FLOAT}.get(opt.kind)
    return click.option(opt.flag, param_of(name, opt), type=kind, default=None if opt.multiple else opt.default,
                        multiple=opt.multiple, show_default=opt.show_default, metavar=opt.metavar, help=opt.help)


def run_command(callback) -> click.Command:
    """krl run's click command: `callback` with every parameter of interp/spec.py
    ``run_options`` (RunSpec's fields and the door options, in krl run --help's order)."""
    for name, opt in reversed(run_options()):
        callback = click_param(name, opt)(callback)
    return click.command("run")(callback)


def _run_command(**options) -> None:
    """Run PROGRAM (.src) on the simulated KR C4; print where and why it ended.

    With --workspace BACKUP.zip (a KRC backup archive) PROGRAM is a path inside the archive
    (KRC/R1/Program/demo.src) or a module name (demo); the archive is checked and extracted
    to a temporary folder (krl/archive.py) that is removed after the run.
    """

    if options.get("program") is not None and is_robot_cell(Path(options["program"])):
        _run_cell(Path(options["program"]), options)
    try:
        with run_setup(options) as setup:
            _run(setup)
    except RunSetupError as exc:
        click.echo(f"error: {exc}", err=True)
        sys.exit(2)


run = run_command(_run_command)


def _run(setup) -> None:
    """Run `setup` (interp.run.RunSetup) and print the summary; exits with the run's code."""

    shown, machine, program = setup.shown, setup.machine, setup.program
    try:
        trace = setup.trace_writer()
    except OSError as exc:
        click.echo(f"error: the trace {shown(printable(setup.trace_path))} cannot be written: "
                   f"{printable(exc.strerror or exc)}", err=True)
        sys.exit(2)
    observer = RunObserver(inner=trace)
    rt = None
    try:
        rt, _ = setup.make_runtime(RunSinks(trace=trace, observer=observer))
        _announce_partners(rt)
        errors = rt.program.errors_of(rt.program.module_of(rt.program.main_path))
        if errors:
            # the checker rejects the program's own module: like the controller, it does not start
            for d in errors[:20]:
                click.echo(shown(printable(str(d))))
            click.echo(f"not started: {len(errors)} error(s) found by the checker (--no-check runs it anyway)")
            sys.exit(1)
        with progress_of(rt, observer, setup.spec.max_sim_time) as progress:
            res = rt.run()
    except (StimulusError, StartError, NetError) as exc:
        click.echo(f"error: {shown(printable(exc))}", err=True)
        sys.exit(2)
    except KeyboardInterrupt as exc:
        if rt is not None:       # the trace says how the run ended (the controller's one end event)
            rt.controller.log.finish("interrupted", text=signals.name(exc))
        elif trace is not None:  # stopped while the run was being set up
            trace.write("end", 0.0, reason="interrupted", text=signals.name(exc))
        raise                    # app's command group says "interrupted" and exits 130 / 143
    except TraceWriteError as exc:
        click.echo(f"error: {shown(printable(exc))}", err=True)
        sys.exit(2)
    except Exception as exc:  # noqa: BLE001
        click.echo(f"internal error: {type(exc).__name__}: {shown(printable(exc))}", err=True)
        sys.exit(2)
    finally:
        if trace is not None:
            _close(trace, shown)
    prog = rt.program
    ws_note = None
    if prog.backup:
        ws_note = f"{prog.workspace} (KRC backup{' found above the program' if setup.workspace is None else ''})"
    elif setup.workspace is not None:
        ws_note = str(prog.workspace)
    booted = setup.booted
    for line in summary_lines(res, observer, program=str(program), interp=setup.interp,
                              submits=[t for t in rt.scheduler.tasks if t.kind == "submit"],
                              workspace=ws_note, starving=starvation_lines(rt),
                              robot=f"{machine.name} ({machine.source}{_chosen(program, setup.workspace)})"
                              + (f"; {machine.named}" if machine.named else ""),
                              run=rt):
        click.echo(shown(line))
        if booted is not None and line.startswith("  workspace"):
            click.echo(shown(f"  submit     {booted} (the backup's, started as at boot; --no-submit: without)"))
    progress.done()
    sys.exit(res.exit_code)


def _run_cell(path: Path, options: dict) -> None:
    """Run the cell of several robots `path` (interp/robotcell.py) with krl run's `options`
    (--interp, --max-sim-time, --trace: one stream per robot and the cell's JSON result,
    ``run.cell.json``); print its summary; exit with the worst robot's code."""
    interp = options.get("interp_kind") or "vm"
    limit = options.get("max_sim_time") or RUN_SIM_TIME_S
    trace = options.get("trace_path")
    try:
        cell = load_robot_cell(path)
        with cell_runs(cell, interp, limit, Path(trace) if trace else None) as runs:
            res = run_cell(cell, runs)
        if trace:        # the cell's result beside the robots' streams (docs/cells.md)
            write_text(cell_result_path(Path(trace)), json.dumps(res.as_json(), indent=1) + "\n")
    except (CellError, StimulusError, StartError, NetError, TraceWriteError, OSError) as exc:
        click.echo(f"error: {printable(exc)}", err=True)
        sys.exit(2)
    for line in robot_cell_summary(res, path.parent):
        click.echo(printable(line))
    sys.exit(res.exit_code)


def progress_of(rt, observer: RunObserver, limit_s: float | None) -> RunProgress:
    """The run's progress on standard error when it is a terminal (interp/progress.py): the
    controller's simulated time and the motions the observer saw, read by the status line."""
    ctl = rt.controller
    return RunProgress(sys.stderr, lambda: (ctl.time, len(observer.motion_types)), limit_s)


def _close(trace, shown) -> None:
    """Close the trace; a trace that cannot be written to its end (a full disk) is exit 2."""
    try:
        trace.close()
    except TraceWriteError as exc:
        click.echo(f"error: {shown(printable(exc))}", err=True)
        sys.exit(2)


def _chosen(program: Path, workspace) -> str:
    """``; chosen by ...`` when --inputs auto chose the robot (interp/scene.py)."""

    c = chosen(program, workspace)
    return f"; {c.note}" if c is not None else ""


def _announce_partners(rt) -> None:
    """Say on stderr where the run's network partners connect, as each server starts (the cell
    file's `network:` key; a port 0 becomes the free port taken). The run is paced to the wall
    clock while a partner is attached (docs/network.md)."""
    net = getattr(rt.controller, "network", None)
    if net is None or net.settings is None:
        return

    def say(key, address):
        click.echo(f"network: {printable(key)} listening on {address[0]}:{address[1]}", err=True)

    for key, address in list(net.addresses.items()):
        say(key, address)
    net.listen_hook = say
    if net.settings.replay is not None:
        click.echo(f"network: replaying {printable(str(net.settings.replay))}", err=True)


@click.group("cell")
def cell() -> None:
    """The cell of a backup: the PLC's answers as reactive rules (robot/cellrules.py)."""


@cell.command("init")
@click.argument("paths", nargs=-1, type=click.Path(path_type=Path), metavar="BACKUP [PROGRAM | BACKUP...]")
@click.option("-o", "--output", type=click.Path(path_type=Path), default=None,
              help="Write the starter file here (default: print it).")
@click.option("--from-run", "from_run", type=click.Path(path_type=Path), default=None, metavar="TRACE",
              help="Instead: the answers of a `krl run --inputs auto --trace TRACE` run as rules (commented).")
def cell_init_cmd(paths: tuple[Path, ...], output: Path | None, from_run: Path | None) -> None:
    """Write a starter cell file for PROGRAM (a path or a module name in BACKUP): each input it
    reads, with a rule to fill in; without PROGRAM for every program of BACKUP. Given two or
    more backup folders, a cell of several robots: each backup's entry point and the wires its
    $config.dat makes evident (docs/cells.md). With --from-run TRACE, the answers of an
    automatic cell's run as rules."""
    if len(paths) >= 2 and all(p.is_dir() for p in paths) and from_run is None:
        _emit(_robots_init(paths, output), output)
        return
    if len(paths) > 2:
        click.echo("error: several backups are folders (extract an archive first); else BACKUP [PROGRAM]", err=True)
        sys.exit(2)
    backup = paths[0] if paths else None
    program = paths[1] if len(paths) > 1 else None
    if from_run is not None:
        try:
            text = rules_from_run(read_trace(from_run), str(from_run))
        except (OSError, ValueError, UnicodeDecodeError) as exc:
            click.echo(f"error: {printable(from_run)}: not a trace of krl run: {printable(exc)}", err=True)
            sys.exit(2)
    else:
        if backup is None:
            click.echo("error: name the BACKUP (or give --from-run TRACE)", err=True)
            sys.exit(2)
        if not backup.is_dir() and not is_archive(backup):
            click.echo(f"error: {printable(backup)}: not a folder nor a backup .zip", err=True)
            sys.exit(2)
        try:
            # a backup folder, a controller archive (folder or .zip), a folder holding one archive:
            # its one backup (krl/backups.py; several: name one of them)
            with one_backup(backup, ARCHIVE_MANIFESTS) as (part, root, _entries):
                text = _cell_init_of(part.folder if part.archive else backup, Path(root), program, backup)
                text = text.replace(str(part.folder), part.source) if part.archive else text
        except (BackupsError, ArchiveError) as exc:
            click.echo(f"error: {printable(exc)}", err=True)
            sys.exit(2)
    _emit(text, output)


def _emit(text: str, output: Path | None) -> None:
    """Print the starter `text`, or write it to `output` and say so."""
    if output is None:
        click.echo(text, nl=False)
    else:
        write_text(output, text)
        click.echo(f"wrote {printable(output)}")


def _robots_init(folders: tuple[Path, ...], output: Path | None) -> str:
    """The starter cell of several robots of the backup `folders` (interp/cellwires.py), its
    paths relative to `output`'s folder (the working folder when printed); exits 2 with a
    message for more robots than a cell takes or a backup that cannot be read."""
    # deferred: tools/startup_bench.py, krl run +5 ms at the top (2026-11-26; the import of _cell_init_of)
    from interp.realprograms import programs_of  # noqa: PLC0415
    if len(folders) > MAX_CELL_ROBOTS:
        click.echo(f"error: {len(folders)} backups, more than a cell's {MAX_CELL_ROBOTS} robots", err=True)
        sys.exit(2)
    try:
        robots = []
        for k, folder in enumerate(folders):
            root = backup_root(folder)
            robots.append(robot_of(f"R{k + 1}", root, programs_of(root)))
        start = (output.parent if output is not None else Path(".")).resolve()
        return robots_starter(robots, start)
    except Exception as exc:  # noqa: BLE001 - never a traceback for input
        click.echo(f"error: {printable(exc)}", err=True)
        sys.exit(2)


def _cell_init_of(folder: Path, root: Path, program: Path | None, named: Path) -> str:
    """The starter cell file of `program` (every program when None) of the backup or program
    folder `root` found in `folder` (krl.project: the backup holding it, else itself); exits 2
    with a message for a program that is not there or input that cannot be read."""
    # deferred: tools/startup_bench.py, krl run +5 ms at the top (2026-11-26)
    from interp.realprograms import programs_of  # noqa: PLC0415
    root = backup_of(root.resolve()) or root.resolve()
    if program is not None:
        found = program if program.is_file() else program_in(root, program)
        if found is None:
            click.echo(f"error: no program {printable(program)} in {printable(named)}", err=True)
            sys.exit(2)
        programs = [found]
    else:
        programs = programs_of(root)
    try:
        return cell_init(root, programs, whole=program is None)
    except Exception as exc:  # noqa: BLE001 - never a traceback for input
        click.echo(f"error: {printable(exc)}", err=True)
        sys.exit(2)


from interp.asm import asm  # noqa: E402


commands = [run, asm, cell]
