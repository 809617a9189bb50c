"""A Java parser build runs once however many processes ask for it at the same time
(krl/syntax/engines/java.py ``_build_once``: a lock beside the target): the others wait and take
its result. Two callers here are two threads, each with its own open of the lock file (an
``flock`` holds per open file, so they exclude each other as two processes do); the build is a
stand-in that counts its calls, so no Java is needed."""

from __future__ import annotations

import threading
import time
from pathlib import Path

from krl.syntax.engines import java as J


def test_concurrent_builds_of_one_target_build_it_once(tmp_path: Path) -> None:
    target = tmp_path / "build" / "abc123"
    calls = []
    started = threading.Barrier(2)

    def make(tmp: Path) -> None:
        calls.append(tmp)
        time.sleep(0.5)        # a build long enough for the other caller to arrive meanwhile
        (tmp / "KRLParser.class").write_bytes(b"built")

    got = []

    def caller() -> None:
        started.wait()
        got.append(J._build_once(target, make))

    threads = [threading.Thread(target=caller) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    assert got == [target, target]
    assert len(calls) == 1
    assert (target / "KRLParser.class").read_bytes() == b"built"
    # nothing half-built is left beside it: only the target and its lock
    assert sorted(p.name for p in target.parent.iterdir()) == ["abc123", "abc123.lock"]


def test_a_failed_build_leaves_no_target_and_the_next_caller_builds(tmp_path: Path) -> None:
    target = tmp_path / "abc123"

    def broken(tmp: Path) -> None:
        raise RuntimeError("javac failed")

    try:
        J._build_once(target, broken)
    except RuntimeError as exc:
        assert str(exc) == "javac failed"
    else:
        raise AssertionError("the failed build returned")
    assert not target.exists()
    J._build_once(target, lambda tmp: (tmp / "ok").write_text("1"))
    assert (target / "ok").read_text() == "1"
