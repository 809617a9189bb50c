"""`krl pendant`: serve the virtual smartPAD on loopback and open it in the browser
(docs/pendant.md)."""

from __future__ import annotations

import contextlib
import socket
import sys
import threading
from pathlib import Path

import click

from krl.files import spelled
from krl.limits import MAX_WEB_MESSAGE_BYTES
from krl.project import backup_of
from krl.terminal import printable
from krl.archive import ArchiveError, backup_source, is_archive
from krl.logbook.record import ARCHIVE_FILES
import uvicorn
from .security import new_token
from .server import Pendant, create_app
from .cell import CellPendant
from interp.robotcell import CellError, is_robot_cell
import webbrowser


@click.command("pendant")
@click.argument("target", required=False, type=click.Path(path_type=Path))
@click.option("--port", type=click.IntRange(0, 65535), default=0, show_default=True,
              help="Port on 127.0.0.1 (0: a free port).")
@click.option("--no-browser", is_flag=True, help="Print the URL only; do not open a browser.")
@click.option("--inputs", type=click.Path(path_type=Path, exists=True, dir_okay=False), default=None,
              help="Cell file (stimuli and rules, as for krl run --inputs): its rules stay active beside "
                   "the inputs set by hand.")
@click.option("--mode", type=click.Choice(["T1", "T2", "AUT", "EXT"], case_sensitive=False), default="T1",
              show_default=True, help="Operating mode at the start.")
@click.option("--trace", "trace_path", type=click.Path(path_type=Path, dir_okay=False), default=None,
              help="Write the run's JSONL trace here (as krl run --trace; rewritten at each selection).")
@click.option("--no-realtime", is_flag=True,
              help="Run the simulation as fast as it goes instead of at real time.")
def pendant(target: Path | None, port: int, no_browser: bool, inputs: Path | None, mode: str,
            trace_path: Path | None, no_realtime: bool) -> None:
    """Serve a virtual smartPAD for TARGET (a KRC backup folder or .zip, a folder of KRL, a
    program .src: selected at the start, or a cell of several robots CELL.yaml: every robot in
    the 3D view; default the current folder) on 127.0.0.1 and open it in the browser. The first line printed is the page's URL with the session token."""
    target = target if target is not None else Path.cwd()
    if not target.exists():
        click.echo(f"error: {printable(target)}: no such file or folder", err=True)
        sys.exit(2)
    with contextlib.ExitStack() as stack:
        program = None
        readonly = False
        shown = str(target)
        if is_archive(target):
            try:
                # its event logs and manifest too: the Logbook tab (pendant/logbook.py)
                folder, _ = stack.enter_context(backup_source(target, ARCHIVE_FILES))
            except ArchiveError as exc:
                click.echo(f"error: {printable(exc)}", err=True)
                sys.exit(2)
            root, readonly = Path(folder), True
        elif is_robot_cell(target):
            sys.exit(serve_cell(target, port=port, open_browser=not no_browser, realtime=not no_realtime))
        elif target.is_file():
            if target.suffix.lower() != ".src":
                click.echo(f"error: {printable(target)}: a program is a .src file", err=True)
                sys.exit(2)
            # the user's spelling, links kept (krl/files.py spelled): the page shows the paths given
            where = spelled(target)
            root = backup_of(where) or where.parent
            program = str(where.relative_to(root))
            shown = str(root)
        else:
            root = backup_of(spelled(target)) or spelled(target)
        sys.exit(serve(root, port=port, open_browser=not no_browser, inputs=str(inputs) if inputs else None,
                       mode=mode.upper(), trace=str(trace_path) if trace_path else None, program=program,
                       readonly=readonly, realtime=not no_realtime, shown=shown))


def serve_cell(cell_file: Path, *, port: int = 0, open_browser: bool = True, realtime: bool = True) -> int:
    """Serve the cell of several robots `cell_file` (pendant/cell.py) as :func:`serve` serves a
    workspace; 2 for a cell file that makes no cell (its file:line) or a port it cannot take."""
    try:
        app = CellPendant(cell_file, realtime=realtime)
    except CellError as exc:
        click.echo(f"error: {printable(exc)}", err=True)
        return 2
    return serve(cell_file.parent, port=port, open_browser=open_browser, app=app)


def serve(root: Path, *, port: int = 0, open_browser: bool = True, inputs: str | None = None, mode: str = "T1",
          trace: str | None = None, program: str | None = None, readonly: bool = False, realtime: bool = True,
          shown: str | None = None, app: Pendant | None = None) -> int:
    """Bind 127.0.0.1:``port``, print the URL with the token, serve until interrupted (SIGINT
    or SIGTERM: the command exits 130 / 143, krl/signals.py); 2 when it cannot listen."""

    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind(("127.0.0.1", port))
    except OSError as exc:
        click.echo(f"error: cannot listen on 127.0.0.1:{port} ({exc.strerror})", err=True)
        return 2
    sock.listen(16)
    bound = sock.getsockname()[1]
    token = new_token()
    url = f"http://127.0.0.1:{bound}/?token={token}"
    click.echo(url)
    sys.stdout.flush()
    if app is None:
        app = Pendant(root, inputs=inputs, mode=mode, realtime=realtime, trace=trace, program=program,
                      readonly=readonly, shown_root=shown)
    config = uvicorn.Config(create_app(app, token, lambda: bound), log_level="warning", ws="websockets-sansio",
                            ws_max_size=MAX_WEB_MESSAGE_BYTES, lifespan="on", access_log=False,
                            # loopback: compressing each message (the pose at display rate, the
                            # state) cost the server more CPU than anything else it does for a page
                            # (py-spy, python -m pendant.bench)
                            ws_per_message_deflate=False)
    if open_browser:

        threading.Timer(0.5, lambda: webbrowser.open(url)).start()
    # Ctrl-C / SIGTERM: uvicorn shuts down gracefully, then raises the signal again; it ends
    # the command as every command ends on a signal (app/__init__.py: exit 130 / 143)
    uvicorn.Server(config).run(sockets=[sock])
    return 0


commands = [pendant]
