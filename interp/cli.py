"""`krl run`: run a KRL program on the simulated controller (issue 6).

Exit codes: 0 completed; 3 stopped (HALT, --max-steps, --max-sim-time, deadlocked WAIT);
1 KRL run-time error; 2 usage or internal error (a --trace that cannot be written: a missing
folder, a read-only or full file system); 130 Ctrl-C (SIGINT), 143 SIGTERM: the trace then ends
with an ``end`` event of reason ``interrupted`` (krl/signals.py; docs/security.md "Faults").
"""

from __future__ import annotations

import sys
from pathlib import Path

import click

from interp.spec import INTERP, INTERPS, RUN_MODE, RUN_MODES, RUN_SIM_TIME_S
from krl.limits import MAX_HALT_CONTINUES
from krl.project import backup_of
from krl.terminal import printable
from krl import signals
from krl.durable import write_text
from robot.trace import TRACE_REPEATS, TraceWriteError, read_trace
from interp.run import program_in, run_setup, RunSetupError
from interp.summary import RunObserver, starvation_lines, summary_lines
from robot.stimuli import StartError, StimulusError
from net.hub import NetError
from interp.scene import chosen
from interp.cellinit import cell_init, from_run as rules_from_run


@click.command("run")
@click.argument("program", type=click.Path(path_type=Path))
@click.option("--interp", "interp_kind", type=click.Choice(list(INTERPS)), default=INTERP,
              show_default=True, help="Interpreter.")
@click.option("--workspace", type=click.Path(path_type=Path), default=None,
              help="Folder of the program's modules, or a KRC backup .zip (default: the program's folder; a KRC backup is detected).")
@click.option("--inputs", type=click.Path(path_type=Path), default=None,
              help="A cell file (stimuli, rules, presets: robot/stimuli.py), or `auto`: the automatic cell "
                   "sets the inputs the program starves for (interp/runtime/autocell.py; docs/robot.md).")
@click.option("--trace", "trace_path", type=click.Path(path_type=Path), default=None, help="Write the JSONL trace here.")
@click.option("--max-sim-time", type=float, default=RUN_SIM_TIME_S, show_default=True, help="Simulated-time limit (s).")
@click.option("--max-steps", type=int, default=None,
              help="Limit of the robot program's executed statements and loop iterations (its interrupt "
                   "routines and TRIGGER actions included; a submit program's are not counted). Default: "
                   "none, the time limit bounds the run (docs/architecture.md, \"The step limit\").")
@click.option("--submit", "submit", type=click.Path(path_type=Path), multiple=True,
              help="A submit program (.sub) to run beside the robot program (repeatable). Default: "
                   "in a KRC backup, its SPS.SUB, as the controller starts it at boot.")
@click.option("--no-submit", is_flag=True, help="Run without the backup's SPS.SUB.")
@click.option("--mode", "mode", type=click.Choice(["T1", "T2", "AUT", "EXT"], case_sensitive=False),
              default=None,
              help="Operating mode ($MODE_OP): T1 limits TCP and flange to 250 mm/s and PTP to "
                   "$RED_T1; AUT is the unattended virtual controller (docs/robot.md). Default AUT; EXT "
                   "for a cell program (&COMMENT HANDLER on external automatic, or a call of P00 (#INIT_EXT, "
                   "...)), with --inputs auto, or when the --inputs cell file has the autoext preset.")
@click.option("--run-mode", "run_mode", type=click.Choice(list(RUN_MODES), case_sensitive=False),
              default=RUN_MODE, show_default=True,
              help="Program run mode ($PRO_MODE): MSTEP stops after each motion, ISTEP after each "
                   "statement (no advance run, no approximation); BSTEP runs forward as MSTEP, then "
                   "retraces the motions backward (T1/T2 only). Each stop is a step_stop trace event "
                   "and the run goes on, as if Start were pressed again (docs/robot.md).")
@click.option("--pgno", "pgno", type=click.IntRange(1, 65535), default=None,
              help="Program number the cell's PLC answers in P00's handshake (PGNO_* of the "
                   "backup's $config.dat; robot/cellpresets.py, docs/robot.md).")
@click.option("--no-check", "no_check", is_flag=True,
              help="Start the program even when the front end's checker finds errors in its own "
                   "module (by default, like the controller, such a program does not start: exit 1). "
                   "A name nothing declares is then a run-time error where it is evaluated.")
@click.option("--robot", "robot", type=click.Path(path_type=Path), default=None,
              help="The robot to simulate: a robot YAML, a $machine.dat, a KRC backup folder or .zip "
                   "(default: the robot the --inputs cell file names, else the backup's own robot from its "
                   "R1/Mada/$machine.dat, else the KR 6 R900).")
@click.option("--start", "start", default=None, metavar="AXIS_OR_POINT",
              help="Where the robot stands at the start: an E6AXIS literal (\"{A1 0, A2 -90, A3 90, A4 0, A5 0, "
                   "A6 0}\") or a point of the program such as XHOME (default: the cell file's start:, for a "
                   "cell program or with --inputs auto XHOME, else $AXIS_HOME[1]).")
@click.option("--override", "override", type=click.IntRange(1, 100), default=None, metavar="PCT",
              help="The program override $OV_PRO (%) the operator set before the start (default 100): "
                   "every motion takes its time at 100 % divided by it, as on a KR C4 (docs/robot.md).")
@click.option("--on-halt", "on_halt", default="stop", show_default=True, metavar="stop|continue[:N]",
              help="After a HALT: stop the run, or `continue`: the operator presses Start again (at most N "
                   "times, default 10; then the HALT ends the run).")
@click.option("--trace-repeats", "trace_repeats", type=click.IntRange(0, None), default=TRACE_REPEATS,
              show_default=True,
              help="A spin in the trace: a pass of events repeated with nothing changed but time (the same "
                   "events and values, the same state of the run) is written this many times, then counted "
                   "in a `repeat` event; a loop whose state changes keeps every event; 0 writes every event.")
def run(**options) -> None:
    """Run PROGRAM (.src) on the simulated KR C4; print where and why it ended.

    With --workspace BACKUP.zip (a KRC backup archive) PROGRAM is a path inside the archive
    (KRC/R1/Program/demo.src) or a module name (demo); the archive is checked and extracted
    to a temporary folder (krl/archive.py) that is removed after the run.
    """

    options["halt_continues"] = halt_option(options.pop("on_halt"))
    try:
        with run_setup(options) as setup:
            _run(setup)
    except RunSetupError as exc:
        click.echo(f"error: {exc}", err=True)
        sys.exit(2)


#: ``--on-halt continue`` without a count: the operator presses Start again at most this often
HALT_CONTINUES = 10


def halt_option(text: str) -> int:
    """The times the operator presses Start again after a HALT (``--on-halt``: ``stop`` 0,
    ``continue`` :data:`HALT_CONTINUES`, ``continue:N`` N, 1 <= N <= MAX_HALT_CONTINUES).
    Exits 2 for
    anything else."""
    t = (text or "stop").strip().lower()
    if t == "stop":
        return 0
    if t == "continue":
        return HALT_CONTINUES
    if t.startswith("continue:") and t[9:].isdigit() and 1 <= int(t[9:]) <= MAX_HALT_CONTINUES:
        return int(t[9:])
    click.echo(f"error: --on-halt {text!r}: stop, continue or continue:N (N 1..{MAX_HALT_CONTINUES})", err=True)
    sys.exit(2)


def _run(setup) -> None:
    """Run `setup` (interp.run.RunSetup) and print the summary; exits with the run's code."""

    shown, machine, program = setup.shown, setup.machine, setup.program
    try:
        trace = setup.trace_writer()
    except OSError as exc:
        click.echo(f"error: the trace {shown(printable(setup.trace_path))} cannot be written: "
                   f"{printable(exc.strerror or exc)}", err=True)
        sys.exit(2)
    observer = RunObserver()
    rt = None
    try:
        rt, _ = setup.make_runtime(trace=trace, observer=observer)
        _announce_partners(rt)
        errors = rt.program.errors_of(rt.program.module_of(rt.program.main_path))
        if errors:
            # the checker rejects the program's own module: like the controller, it does not start
            for d in errors[:20]:
                click.echo(shown(printable(str(d))))
            click.echo(f"not started: {len(errors)} error(s) found by the checker (--no-check runs it anyway)")
            sys.exit(1)
        res = rt.run()
    except (StimulusError, StartError, NetError) as exc:
        click.echo(f"error: {shown(printable(exc))}", err=True)
        sys.exit(2)
    except KeyboardInterrupt as exc:
        if rt is not None:       # the trace says how the run ended (the controller's one end event)
            rt.controller.log.finish("interrupted", text=signals.name(exc))
        elif trace is not None:  # stopped while the run was being set up
            trace.write("end", 0.0, reason="interrupted", text=signals.name(exc))
        click.echo(signals.MESSAGE, err=True)
        sys.exit(signals.exit_code(exc))
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
    sys.exit(res.exit_code)


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
@click.argument("backup", required=False, type=click.Path(path_type=Path))
@click.argument("program", required=False, type=click.Path(path_type=Path))
@click.option("-o", "--output", type=click.Path(path_type=Path), default=None,
              help="Write the starter file here (default: print it).")
@click.option("--from-run", "from_run", type=click.Path(path_type=Path), default=None, metavar="TRACE",
              help="Instead: the answers of a `krl run --inputs auto --trace TRACE` run as rules (commented).")
def cell_init_cmd(backup: Path | None, program: Path | None, output: Path | None, from_run: Path | None) -> None:
    """Write a starter cell file for PROGRAM (a path or a module name in BACKUP): each input it
    reads, with a rule to fill in; without PROGRAM for every program of BACKUP. With
    --from-run TRACE, the answers of an automatic cell's run as rules."""
    # deferred: tools/startup_bench.py, krl run +5 ms at the top (2026-11-26)
    from interp.realprograms import programs_of  # noqa: PLC0415
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
        if not backup.is_dir():
            click.echo(f"error: {printable(backup)}: not a folder", err=True)
            sys.exit(2)
        root = backup_of(backup.resolve()) or backup.resolve()
        if program is not None:
            found = program if program.is_file() else program_in(root, program)
            if found is None:
                click.echo(f"error: no program {printable(program)} in {printable(backup)}", err=True)
                sys.exit(2)
            programs = [found]
        else:
            programs = programs_of(root)
        try:
            text = cell_init(root, programs, whole=program is None)
        except Exception as exc:  # noqa: BLE001 - never a traceback for input
            click.echo(f"error: {printable(exc)}", err=True)
            sys.exit(2)
    if output is None:
        click.echo(text, nl=False)
    else:
        write_text(output, text)
        click.echo(f"wrote {printable(output)}")


from interp.asm import asm  # noqa: E402


commands = [run, asm, cell]
