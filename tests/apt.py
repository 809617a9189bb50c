"""Installing a Debian package a test needs (chromium, neovim) as the test set-up does on a fresh
machine: `apt-get install`, then `apt-get update` and install again when the package lists are
stale. If a package cannot be installed (not root, no apt-get, no network), the caller skips with
a clear reason (tests marked may_skip), or fails under CI=true (tests/editors: node, code-server's
build headers)."""

from __future__ import annotations

import os
import shutil
import subprocess


def apt_install(package: str, binary: str) -> str | None:
    """The path of `binary`, installing `package` first when it is missing; None if it cannot be
    installed. Never raises."""
    found = shutil.which(binary)
    if found:
        return found
    _apt_get(lambda: [package], lambda: shutil.which(binary) is not None)
    return shutil.which(binary)


def apt_install_packages(packages: list[str]) -> bool:
    """Installs the Debian packages that dpkg does not list as installed (libraries and headers
    have no binary to look for), as apt_install does; True when all are installed. Never raises."""
    def missing() -> list[str]:
        try:
            out = subprocess.run(["dpkg-query", "-W", "-f=${Package} ${Status}\n", *packages],
                                 capture_output=True, text=True, timeout=60, check=False).stdout
        except (OSError, subprocess.TimeoutExpired):
            return list(packages)
        ok = {line.split()[0] for line in out.splitlines() if line.endswith(" installed")}
        return [p for p in packages if p not in ok]

    return not missing() or _apt_get(missing, lambda: not missing())


def _apt_get(packages, done) -> bool:
    """`apt-get install packages()`, then `apt-get update` and install again when the package lists
    are stale, until done(); False when not root, without apt-get, or on failure. Never raises."""
    if shutil.which("apt-get") is None or os.geteuid() != 0:
        return False
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    try:
        for step in (["install"], ["update"], ["install"]):
            args = ["apt-get", *step, "-y", "-q"] + (packages() if step == ["install"] else [])
            subprocess.run(args, env=env, capture_output=True, timeout=900, check=False)
            if done():
                return True
    except (OSError, subprocess.TimeoutExpired):
        return False
    return done()
