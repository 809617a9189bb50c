"""A fork server for the `krl` processes a test module starts many of (tests/debug: one `krl
debug` per test; tests/lsp: a language server per module): one process imports the project once, and each command is a fork of it.

Why: a `krl debug` session is a process whose start imports the runtime, the robot model,
NumPy, SciPy and MuJoCo; measured on 2026-11-27, a session that only answers `initialize` took
1.59 s of CPU, and tests/debug/test_dap.py's 20 sessions 31.4 s in all, nearly all of it that
start. A fork of a process that has imported them starts in milliseconds.

How: :class:`ForkServer` starts ``python -m tests.forkserver SOCKET MODULE...``, which imports
the modules, then listens on a Unix socket in a private temporary folder. A command is started
by :data:`LAUNCHER`, a small script run with ``python -IS`` (no site, no project import): it
sends its own stdin, stdout and stderr (``SCM_RIGHTS``) with its arguments, environment and
working folder; the server forks, the child puts those three descriptors in place of its own,
takes the environment and folder and runs ``-m MODULE ARGS...`` as ``python -m MODULE
ARGS...`` would (``runpy``). The launcher exits with the child's status, so the process a test holds (its pipes, its
exit code, closing its stdin) behaves as the command itself. If the launcher goes away (killed
by a test's time-out), the server kills the child.

What it does not stand for: what a command's start does before its module runs (Python's own
start, ``site``, the import of the packages). tests/debug/test_launch.py and the other suites still
start `krl debug` as a real process, and tests/lsp/test_cold_start.py the language server (the
other language-server tests fork it: tests/lsp/conftest.py ``ForkedServer``).
"""

from __future__ import annotations

import atexit
import importlib
import io
import json
import os
import runpy
import select
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import traceback
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

#: the launcher the test's process starts instead of ``python``: it is given ``-m MODULE ARGS``
#: (as interp/debug/client.py DapClient starts ``python -m app debug``); a command ended by a
#: signal ends the launcher by the same signal
LAUNCHER = """\
import json, os, signal, socket, sys
args = sys.argv[1:]
if args[:1] != ["-m"] or len(args) < 2:
    sys.exit("the fork server's launcher runs `-m MODULE ARGS...` only")
s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
s.connect({socket_path!r})
request = json.dumps({{"argv": args, "env": dict(os.environ), "cwd": os.getcwd()}}).encode()
socket.send_fds(s, [len(request).to_bytes(4, "big") + request], [0, 1, 2])
# SIGTERM and SIGINT (a test ending the command, Ctrl-C) go on to the command
signal.signal(signal.SIGTERM, lambda *_: s.send(b"T"))
signal.signal(signal.SIGINT, lambda *_: s.send(b"I"))
status = b""
while len(status) < 4:
    got = s.recv(4 - len(status))
    if not got:
        sys.exit(70)
    status += got
code = int.from_bytes(status, "big", signed=True)
if code < 0:
    signal.signal(-code, signal.SIG_DFL)
    os.kill(os.getpid(), -code)
sys.exit(code)
"""


def _child(request: dict, fds: list[int]) -> None:
    """In the forked child: take the launcher's descriptors, environment and folder, run the
    command; never returns."""
    code = 1
    try:
        for target, fd in enumerate(fds):
            os.dup2(fd, target)
            os.close(fd)
        os.environ.clear()
        os.environ.update(request["env"])
        os.chdir(request["cwd"])
        # Python's start reads PYTHONUNBUFFERED; here the streams are made again for it
        unbuffered = bool(os.environ.get("PYTHONUNBUFFERED"))
        # (sys.__stdout__ and its kin hold them too, as in any process: a command that puts
        # another stream in sys.stdout keeps the first one open, krl debug's protocol stream)
        sys.stdin = sys.__stdin__ = io.TextIOWrapper(io.BufferedReader(io.FileIO(0, "r", closefd=False)))
        for fd, name in ((1, "stdout"), (2, "stderr")):
            raw = io.FileIO(fd, "w", closefd=False)
            stream = io.TextIOWrapper(raw if unbuffered else io.BufferedWriter(raw), write_through=unbuffered,
                                      line_buffering=fd == 2 and not unbuffered,
                                      errors="backslashreplace" if fd == 2 else "strict")
            setattr(sys, name, stream)
            setattr(sys, f"__{name}__", stream)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        # `-m MODULE ARGS...`, as `python -m MODULE ARGS...` runs it
        module, args = request["argv"][1], request["argv"][2:]
        sys.argv = [module, *args]
        runpy.run_module(module, run_name="__main__", alter_sys=True)
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        if not isinstance(exc.code, int) and exc.code is not None:
            print(exc.code, file=sys.stderr)       # as Python prints sys.exit("message")
    except BaseException:  # noqa: BLE001  (reported as the command would: on its stderr)
        traceback.print_exc()
    finally:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(code)


#: what the launcher sends when it gets a signal: the signal the command gets
_SIGNALS = {b"T": signal.SIGTERM, b"I": signal.SIGINT}


def _watch(conn: socket.socket, pid: int) -> None:
    """Send the launcher the exit status of the child `pid`; kill the child if the launcher
    goes away first."""
    with conn:
        while True:
            done, status = os.waitpid(pid, os.WNOHANG)
            if done:
                try:
                    conn.sendall(os.waitstatus_to_exitcode(status).to_bytes(4, "big", signed=True))
                except OSError:
                    pass                # the launcher is gone: nobody waits for the status
                return
            readable, _, _ = select.select([conn], [], [], 0.05)
            if not readable:
                continue
            sent = conn.recv(1)
            if sent in _SIGNALS:
                os.kill(pid, _SIGNALS[sent])
            elif not sent:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
                return


def _end_with_parent(path: str) -> None:
    """Wait for the end of the server's stdin, a pipe its test process holds, and end the
    server with its folder: an xdist worker ends by ``os._exit`` (execnet), so neither its
    ``atexit`` nor :meth:`ForkServer.close` runs. It reads the descriptor, not ``sys.stdin``:
    a fork made while this thread holds the stream's lock would find it held for good."""
    while os.read(0, 4096):
        pass
    shutil.rmtree(Path(path).parent, ignore_errors=True)
    os._exit(0)


def serve(path: str, modules: list[str]) -> None:
    """The server's loop (``python -m tests.forkserver SOCKET MODULE...``); it ends when its
    stdin ends (:func:`_end_with_parent`)."""
    threading.Thread(target=_end_with_parent, args=(path,), daemon=True).start()
    for name in modules:
        importlib.import_module(name)
    server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    server.bind(path)
    server.listen(16)
    sys.stdout.write("ready\n")
    sys.stdout.flush()
    while True:
        conn, _ = server.accept()
        data, fds, _flags, _addr = socket.recv_fds(conn, 4, 3)
        size = int.from_bytes(data, "big")
        raw = b""
        while len(raw) < size:
            got = conn.recv(size - len(raw))
            if not got:
                break
            raw += got
        if len(fds) != 3 or len(raw) != size:
            for fd in fds:
                os.close(fd)
            conn.close()
            continue
        pid = os.fork()
        if pid == 0:
            server.close()
            conn.close()
            _child(json.loads(raw), fds)
        for fd in fds:
            os.close(fd)
        threading.Thread(target=_watch, args=(conn, pid), daemon=True).start()


class ForkServer:
    """The server process and its launcher (:data:`LAUNCHER`), in a private temporary folder;
    ``launcher`` is the path a test starts in place of ``python``. Raises RuntimeError when
    the server does not start."""

    def __init__(self, modules: tuple[str, ...]) -> None:
        self._dir = tempfile.TemporaryDirectory(prefix="krl-forkserver-")
        folder = Path(self._dir.name)
        sock = str(folder / "s")
        self.launcher = folder / "launch"
        self.launcher.write_text(f"#!{sys.executable} -IS\n" + LAUNCHER.format(socket_path=sock))
        self.launcher.chmod(0o700)
        env = {**os.environ, "PYTHONPATH": str(REPO) + (os.pathsep + os.environ["PYTHONPATH"]
                                                        if os.environ.get("PYTHONPATH") else "")}
        self.proc = subprocess.Popen([sys.executable, "-m", "tests.forkserver", sock, *modules], cwd=str(REPO),
                                     env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE)
        if self.proc.stdout.readline() != b"ready\n":
            self.close()
            raise RuntimeError("the fork server did not start")

    def close(self) -> None:
        self.proc.stdin.close()           # the server ends (_end_with_parent)
        try:
            self.proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        self.proc.stdout.close()
        self._dir.cleanup()


#: what a `krl` command the suite starts imports (interp/debug/session.py ``_prepare``, the
#: pendant's server, MuJoCo for the controller's arm, the docs' `krl diff`, `graph` and `report`:
#: tests/docs/conftest.py): imported once by the server
PRELOAD = ("app", "app.changes", "app.report", "interp.cli", "interp.debug.cli", "interp.debug.session", "interp.run",
           "robot.controller", "interp.tree", "interp.vm", "interp.debug.launch", "pendant.cli", "krl.lsp.server",
           "mujoco")
_SHARED: list[ForkServer] = []


def shared() -> ForkServer:
    """This process's fork server (:data:`PRELOAD`), started at the first call and ended when
    the process ends. MuJoCo's GL back end is not loaded (``MUJOCO_GL=disable``, as every `krl`
    command sets it, app/__init__.py)."""
    if not _SHARED:
        saved = os.environ.get("MUJOCO_GL")
        os.environ["MUJOCO_GL"] = "disable"
        try:
            _SHARED.append(ForkServer(PRELOAD))
        finally:
            if saved is None:
                del os.environ["MUJOCO_GL"]
            else:
                os.environ["MUJOCO_GL"] = saved
        atexit.register(_SHARED[0].close)
    return _SHARED[0]


def krl_command() -> list[str]:
    """The command line of `krl` as a fork of this process's server (``launcher -m app``): what
    ``[sys.executable, "-m", "app"]`` starts, without the import of the project at each start."""
    return [str(shared().launcher), "-m", "app"]


def krl_folder(folder: Path) -> Path:
    """`folder` (made if needed) holding an executable ``krl`` that runs :func:`krl_command`
    with its arguments: put first on ``PATH``, a shell's ``krl ARGS`` is a fork of the server."""
    folder.mkdir(parents=True, exist_ok=True)
    script = folder / "krl"
    script.write_text(f"#!/bin/sh\nexec {shlex.quote(str(shared().launcher))} -m app \"$@\"\n")
    script.chmod(0o700)
    return folder


if __name__ == "__main__":
    serve(sys.argv[1], sys.argv[2:])
