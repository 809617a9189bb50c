"""The VS Code extension's node packages (editors/vscode) for the tests: node and npm found or
installed (Debian packages `nodejs` and `npm`, as tests/apt.py installs chromium), then `npm ci`
from the committed package-lock.json, cached: it runs again only when the lock file changed
(the stamp node_modules/.installed holds the lock file's sha256, as `make vsix` writes it).

Under CI=true a missing node is a failure, not a skip (the extension's tests must run there)."""

from __future__ import annotations

import fcntl
import hashlib
import os
import shutil
import subprocess
from pathlib import Path

import pytest

from tests.apt import apt_install

EXTENSION = Path(__file__).resolve().parents[2] / "editors" / "vscode"
NPM_CI_TIMEOUT_S = 900     # a cold `npm ci` on the shared 2-core machine; cached runs take none
PACKAGE_TIMEOUT_S = 300


def _lock_sha(folder: Path) -> str:
    return hashlib.sha256((folder / "package-lock.json").read_bytes()).hexdigest()


def node_or_fail() -> tuple[str, str]:
    """(node, npm): found on PATH, else installed with apt-get. Missing: skip, or fail under CI."""
    node = shutil.which("node") or apt_install("nodejs", "node")
    npm = shutil.which("npm") or apt_install("npm", "npm")
    if node and npm:
        return node, npm
    why = ("node and npm are not installed and `apt-get install -y nodejs npm` was not possible "
           "(not root, no apt-get, or no package source)")
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(why)
    pytest.skip(why)


def npm_ci(folder: Path = EXTENSION, env: dict[str, str] | None = None, timeout: float = NPM_CI_TIMEOUT_S) -> Path:
    """folder (default: editors/vscode) with its node_modules installed from its package-lock.json,
    cached by the lock file's sha256 in node_modules/.installed; returns folder."""
    node_or_fail()
    sha = _lock_sha(folder)
    stamp = folder / "node_modules" / ".installed"
    # one installer at a time (make test runs the grammar and client tests in separate pytest workers)
    with open(folder / ".npm-ci.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (stamp.exists() and stamp.read_text().strip() == sha):
            run = subprocess.run(["npm", "ci", "--no-audit", "--no-fund"], cwd=folder, capture_output=True,
                                 text=True, timeout=timeout, check=False, env=env)
            assert run.returncode == 0, f"npm ci failed in {folder}:\n{run.stdout[-3000:]}\n{run.stderr[-3000:]}"
            stamp.write_text(sha + "\n")
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
