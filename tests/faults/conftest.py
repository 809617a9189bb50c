"""Fixtures of the fault tests (issue 74): a real small or read-only file system (a tmpfs
mounted for the test and unmounted after it: the suite runs as root in CI and on the project's
machine; a user other than root skips these tests, see :data:`MAY_SKIP_MOUNT`), and a real
``krl`` process stopped inside its write (slow_fsync.py)."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SLOW_FSYNC = Path(__file__).with_name("slow_fsync.py")


#: the tests that take :func:`small_fs` or :func:`read_only_fs` carry this: they skip only for a
#: user other than root; as root a tmpfs that cannot be mounted is a failure
MAY_SKIP_MOUNT = pytest.mark.may_skip("run by a user other than root: mounting a tmpfs needs root "
                                      "(CI runs as root, its container --privileged)")


def _mount(where: Path, options: str) -> None:
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    where.mkdir(parents=True, exist_ok=True)
    res = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(where)],
                         capture_output=True, text=True)
    if res.returncode != 0:
        pytest.fail(f"root cannot mount a tmpfs here: {res.stderr.strip()} (a container needs --privileged "
                    "or CAP_SYS_ADMIN: .github/workflows/test.yml)")


@pytest.fixture
def small_fs(tmp_path: Path):
    """A tmpfs of 64 KiB (a full disk after 64 KiB); unmounted at the end."""
    where = tmp_path / "small"
    _mount(where, "size=64k,mode=0755")
    try:
        yield where
    finally:
        subprocess.run(["umount", "-l", str(where)], check=False)


@pytest.fixture
def read_only_fs(tmp_path: Path):
    """make(files) -> a folder on a tmpfs holding `files` (name -> bytes), remounted read-only."""
    where = tmp_path / "ro"
    _mount(where, "size=1m,mode=0755")

    def make(files: dict[str, bytes]) -> Path:
        for name, data in files.items():
            (where / name).write_bytes(data)
        subprocess.run(["mount", "-o", "remount,ro", str(where)], check=True)
        return where

    try:
        yield make
    finally:
        subprocess.run(["umount", "-l", str(where)], check=False)


def start_in_write(args: list[str], marker: Path, cwd: Path, seconds: float = 60.0,
                   env: dict | None = None) -> subprocess.Popen:
    """A real ``krl ARGS`` process, returned once it sits inside its first durable write (its
    first fsync done, the rename not yet: slow_fsync.py). Fails the test when it never gets
    there within 30 s."""
    proc = subprocess.Popen([sys.executable, str(SLOW_FSYNC), str(seconds), str(marker), *args], cwd=cwd,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, **(env or {})})
    deadline = time.monotonic() + 30
    while not marker.exists():
        if proc.poll() is not None:
            out, err = proc.communicate()
            pytest.fail(f"krl {' '.join(args)} ended ({proc.returncode}) before its write was slowed:\n{out}\n{err}")
        if time.monotonic() > deadline:
            proc.kill()
            pytest.fail(f"krl {' '.join(args)} never reached its write")
        time.sleep(0.02)
    return proc
