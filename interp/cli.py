"""`krl run`: run a KRL program on the simulated controller (issue 6).

Exit codes: 0 completed; 3 stopped (HALT, --max-steps, --max-sim-time, deadlocked WAIT);
1 KRL run-time error; 2 usage or internal error.
"""

from __future__ import annotations

import sys
from pathlib import Path

import click


@click.command("run")
@click.argument("program", type=click.Path(path_type=Path))
@click.option("--interp", "interp_kind", type=click.Choice(["tree", "vm"]), default="tree",
              show_default=True, help="Interpreter.")
@click.option("--workspace", type=click.Path(path_type=Path), default=None,
              help="Folder of the program's modules, or a KRC backup .zip (default: the program's folder; a KRC backup is detected).")
@click.option("--inputs", type=click.Path(path_type=Path), default=None, help="Stimuli YAML (robot/stimuli.py).")
@click.option("--trace", "trace_path", type=click.Path(path_type=Path), default=None, help="Write the JSONL trace here.")
@click.option("--max-sim-time", type=float, default=600.0, show_default=True, help="Simulated-time limit (s).")
@click.option("--max-steps", type=int, default=10_000_000, show_default=True,
              help="Limit of executed statements and loop iterations.")
@click.option("--submit", "submit", type=click.Path(path_type=Path), multiple=True,
              help="A submit program (.sub) to run beside the robot program (repeatable). Default: "
                   "in a KRC backup, its SPS.SUB, as the controller starts it at boot.")
@click.option("--no-submit", is_flag=True, help="Run without the backup's SPS.SUB.")
@click.option("--mode", "mode", type=click.Choice(["T1", "T2", "AUT", "EXT"], case_sensitive=False),
              default=None,
              help="Operating mode ($MODE_OP): T1 limits TCP and flange to 250 mm/s and PTP to "
                   "$RED_T1; AUT is the unattended virtual controller (docs/robot.md). Default AUT, "
                   "or EXT when the --inputs cell file has the autoext preset.")
@click.option("--run-mode", "run_mode", type=click.Choice(["GO", "MSTEP", "ISTEP", "BSTEP"], case_sensitive=False),
              default="GO", show_default=True,
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
def run(program: Path, interp_kind: str, workspace, inputs, trace_path, max_sim_time, max_steps, submit,
        mode, run_mode, pgno, no_check, robot, no_submit) -> None:
    """Run PROGRAM (.src) on the simulated KR C4; print where and why it ended.

    With --workspace BACKUP.zip (a KRC backup archive) PROGRAM is a path inside the archive
    (KRC/R1/Program/demo.src) or a module name (demo); the archive is checked and extracted
    to a temporary folder (krl/archive.py) that is removed after the run.
    """
    from krl.archive import ArchiveError, backup_source, is_archive  # noqa: PLC0415
    from krl.terminal import printable  # noqa: PLC0415

    if is_archive(program):
        click.echo(f"error: {printable(program)} is a backup archive; name the program to run in it: "
                   f"krl run --workspace {printable(program)} PROGRAM", err=True)
        sys.exit(2)
    if workspace is not None and is_archive(workspace):
        try:
            with backup_source(workspace) as (folder, shown):
                found = program_in(folder, program)
                if found is None:
                    click.echo(f"error: no program {printable(program)} in {printable(workspace)}", err=True)
                    sys.exit(2)
                _run(found, folder, inputs, trace_path, max_sim_time, max_steps, submit, interp_kind,
                     mode=mode, shown=lambda text: text.replace(str(folder), str(workspace)), check=not no_check,
                     run_mode=run_mode, pgno=pgno, robot=robot, auto_submit=not no_submit)
        except ArchiveError as exc:
            click.echo(f"error: {printable(exc)}", err=True)
            sys.exit(2)
        return
    _run(program, workspace, inputs, trace_path, max_sim_time, max_steps, submit, interp_kind, mode=mode,
         check=not no_check, run_mode=run_mode, pgno=pgno, robot=robot, auto_submit=not no_submit)


def program_in(folder: Path, program: Path) -> Path | None:
    """PROGRAM inside an extracted archive: its relative path (any letter case of the file
    name), else the .src (then .sub) file whose stem is its name; None when there is none."""
    from krl.source import is_krl_file  # noqa: PLC0415

    direct = folder / program
    if not program.is_absolute() and ".." not in program.parts and direct.is_file():
        return direct
    stem = program.stem.lower()
    candidates = sorted(p for p in folder.rglob("*") if p.is_file() and is_krl_file(p) and p.stem.lower() == stem)
    for suffix in (".src", ".sub"):
        for p in candidates:
            if p.suffix.lower() == suffix:
                return p
    return None


def _run(program: Path, workspace, inputs, trace_path, max_sim_time, max_steps, submit, interp_kind,
         mode=None, shown=lambda text: text, check: bool = True, run_mode: str = "GO",
         pgno: int | None = None, robot=None, auto_submit: bool = False) -> None:
    if not program.exists():
        click.echo(f"error: {program}: no such file", err=True)
        sys.exit(2)
    for sub in submit:
        if not Path(sub).is_file():
            click.echo(f"error: {shown(str(sub))}: no such submit program", err=True)
            sys.exit(2)
    booted = None
    if not submit and auto_submit:
        from krl.project import boot_submit  # noqa: PLC0415

        booted = boot_submit(program, workspace)
        submit = (booted,) if booted is not None else ()
    from interp.run import cell_of, make_runtime, robot_for  # noqa: PLC0415
    from interp.summary import RunObserver, starvation_lines, summary_lines  # noqa: PLC0415
    from robot.mada import MachineDataError  # noqa: PLC0415
    from krl.terminal import printable  # noqa: PLC0415
    from robot.stimuli import StimulusError  # noqa: PLC0415
    from robot.trace import TraceWriter  # noqa: PLC0415
    from net.hub import NetError  # noqa: PLC0415

    try:
        inputs = cell_of(inputs)      # the cell file, read once: the robot and the run take it
        machine = robot_for(program, workspace, robot, inputs)
    except (MachineDataError, StimulusError) as exc:
        click.echo(f"error: {shown(printable(exc))}", err=True)
        sys.exit(2)
    trace = TraceWriter(trace_path) if trace_path else None
    if trace is not None:
        # the trace header: which robot the run simulates and where its data came from
        trace.write("robot", 0.0, name=machine.name, source=shown(machine.source),
                    trafoname=machine.trafoname or None)
    observer = RunObserver()
    try:
        rt, _ = make_runtime(program, workspace=workspace, inputs=inputs, trace=trace,
                             max_sim_time=max_sim_time, max_steps=max_steps, submit=list(submit),
                             interp=interp_kind, observer=observer, mode=mode, check=check,
                             run_mode=run_mode.upper(), pgno=pgno, robot=machine)
        _announce_partners(rt)
        errors = rt.program.errors_of(rt.program.module_of(rt.program.main_path))
        if errors:
            # the checker rejects the program's own module: like the controller, it does not start
            for d in errors[:20]:
                click.echo(shown(printable(str(d))))
            click.echo(f"not started: {len(errors)} error(s) found by the checker (--no-check runs it anyway)")
            sys.exit(1)
        res = rt.run()
    except (StimulusError, NetError) as exc:
        click.echo(f"error: {shown(printable(exc))}", err=True)
        sys.exit(2)
    except KeyboardInterrupt:
        click.echo("interrupted", err=True)
        sys.exit(130)
    except Exception as exc:  # noqa: BLE001
        click.echo(f"internal error: {type(exc).__name__}: {shown(printable(exc))}", err=True)
        sys.exit(2)
    finally:
        if trace is not None:
            trace.close()
    prog = rt.program
    ws_note = None
    if prog.backup:
        ws_note = f"{prog.workspace} (KRC backup{' found above the program' if workspace is None else ''})"
    elif workspace is not None:
        ws_note = str(prog.workspace)
    for line in summary_lines(res, observer, program=str(program), interp=interp_kind,
                              submits=[t for t in rt.scheduler.tasks if t.kind == "submit"],
                              workspace=ws_note, starving=starvation_lines(rt),
                              robot=f"{machine.name} ({machine.source})"):
        click.echo(shown(line))
        if booted is not None and line.startswith("  workspace"):
            click.echo(shown(f"  submit     {booted} (the backup's, started as at boot; --no-submit: without)"))
    sys.exit(res.exit_code)


def _announce_partners(rt) -> None:
    """Say on stderr where the run's network partners connect, as each server starts (the cell
    file's `network:` key; a port 0 becomes the free port taken). The run is paced to the wall
    clock while a partner is attached (docs/network.md)."""
    from krl.terminal import printable  # noqa: PLC0415

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
@click.argument("backup", type=click.Path(path_type=Path))
@click.argument("program", required=False, type=click.Path(path_type=Path))
@click.option("-o", "--output", type=click.Path(path_type=Path), default=None,
              help="Write the starter file here (default: print it).")
def cell_init_cmd(backup: Path, program: Path | None, output: Path | None) -> None:
    """Write a starter cell file for PROGRAM (a path or a module name in BACKUP), or for every
    program of BACKUP: each input the programs read, with a rule to fill in."""
    from interp.cellinit import cell_init  # noqa: PLC0415
    from interp.realprograms import programs_of  # noqa: PLC0415
    from krl.project import backup_of  # noqa: PLC0415
    from krl.terminal import printable  # noqa: PLC0415

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
        text = cell_init(root, programs)
    except Exception as exc:  # noqa: BLE001 - never a traceback for input
        click.echo(f"error: {printable(exc)}", err=True)
        sys.exit(2)
    if output is None:
        click.echo(text, nl=False)
    else:
        output.write_text(text, encoding="utf-8")
        click.echo(f"wrote {printable(output)}")


from interp.asm import asm  # noqa: E402


commands = [run, asm, cell]
