"""Results kept across processes (krl/store.py): a program run from a stored checked workspace
runs exactly as from one checked now (the trace is the oracle), across processes too, and a
stored file that is not this user's own, or not what it claims, is never read."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

import interp.runtime.program as program_mod
import krl.store as store
from interp.run import make_runtime
from robot.trace import TraceWriter

REPO = Path(__file__).resolve().parents[2]
CASES = sorted(p for p in (REPO / "conformance" / "cases").iterdir() if (p / "program.src").is_file())
CORPUS = REPO.parent / "shared" / "krl-corpus"
MILLING = CORPUS / "HugoDanielson__ChinaMilling" / "KRC"


def _through_store(tmp_path: Path, value, code=("krl",), fix_ids=True):
    """`value` written by the store and read back (as another process reads it)."""
    path = tmp_path / "stored" / "t" / "x.pickle"
    path.parent.mkdir(parents=True, exist_ok=True)
    store._write_now(path, "d" * 64, value, fix_ids, code)
    got = store._read(path, "d" * 64)
    assert got is not None, "a result just written is read back"
    return got[0]


def _trace(program: Path, inputs=None) -> tuple[str, str]:
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(program, trace=tw, mujoco=False, max_sim_time=60, inputs=inputs, max_steps=2_000_000)
    res = rt.run()
    return res.reason, json.dumps(tw.events, default=str)


def _same_from_the_store(cases, tmp_path, monkeypatch) -> list[str]:
    """The cases whose trace differs between a fresh checked workspace and a stored one."""
    monkeypatch.setenv("KRL_STORE", "0")
    fresh = program_mod.checked_workspace
    stored: dict = {}

    def from_store(project, extra=()):
        key = (str(project.root), tuple(map(str, project.files)), tuple(map(str, extra)))
        if key not in stored:
            stored[key] = _through_store(tmp_path, fresh(project, extra))
        return stored[key]

    differ = []
    for case in cases:
        inputs = case / "stimuli.yaml" if (case / "stimuli.yaml").is_file() else None
        monkeypatch.setattr(program_mod, "checked_workspace", fresh)
        program_mod._CACHE.clear()
        a = _trace(case / "program.src", inputs)
        monkeypatch.setattr(program_mod, "checked_workspace", from_store)
        b = _trace(case / "program.src", inputs)
        if a != b:
            differ.append(case.name)
    return differ


@pytest.mark.slow
def test_every_conformance_program_runs_the_same_from_a_stored_workspace(tmp_path, monkeypatch):
    assert len(CASES) > 100 and not _same_from_the_store(CASES, tmp_path, monkeypatch)


def test_a_sample_of_conformance_programs_runs_the_same_from_a_stored_workspace(tmp_path, monkeypatch):
    # every 25th case (motion, I/O, interrupts and submit cases among them); all of them nightly
    sample = CASES[::25]
    assert len(sample) >= 4 and not _same_from_the_store(sample, tmp_path, monkeypatch)


def test_shared_objects_keep_their_identity_and_id_tables_are_rekeyed(tmp_path, monkeypatch):
    from krl.project import project_of
    from krl.semantics import types as T

    monkeypatch.setenv("KRL_STORE", "0")
    prog = REPO / "conformance" / "cases" / "022_real_to_int" / "program.src"
    ws = program_mod.checked_workspace(project_of(prog.resolve()), sorted(program_mod.BASIS_DIR.iterdir()))
    back = _through_store(tmp_path, ws)
    assert back is not ws
    # id()-keyed tables: every routine finds its scope again
    routines = [r for u in back.units for r in u.routines]
    assert routines and all(back.routine_scope(r) is not None for r in routines)
    # the type singletons are the process's own, not copies (022 declares INT and REAL locals)
    simple = [s.type for r in routines for s in back.routine_scope(r).values.values()
              if isinstance(s.type, T.Simple)]
    assert {str(t) for t in simple} >= {"INT", "REAL"}
    assert all(t is T.SIMPLE[t.name] for t in simple)


@pytest.mark.slow       # three krl runs of a 150-file backup
@pytest.mark.skipif(not MILLING.is_dir(), reason="the shared corpus is beside the repository")
def test_krl_run_from_the_store_in_another_process_gives_the_same_trace(tmp_path):
    program = MILLING / "R1" / "Program" / "KukaMiling" / "Main.src"
    env = {**os.environ, "KRL_CACHE_DIR": str(tmp_path / "cache")}

    def run(trace: Path, **extra) -> None:
        subprocess.run([sys.executable, "-m", "krl.cli", "run", str(program), "--max-sim-time", "3",
                        "--trace", str(trace)], env={**env, **extra}, cwd=REPO, capture_output=True,
                       timeout=900, check=False)

    run(tmp_path / "fresh.jsonl", KRL_STORE="0")
    assert not (tmp_path / "cache" / "stored").exists()          # KRL_STORE=0 keeps nothing
    run(tmp_path / "first.jsonl")                                # checks and keeps
    kept = tmp_path / "cache" / "stored"
    for _ in range(1200):                                        # the writers are child processes
        if list(kept.glob("workspace/*.pickle")) and list(kept.glob("robot/*.pickle")):
            break
        time.sleep(0.5)
    assert len(list(kept.glob("workspace/*.pickle"))) == 1 and len(list(kept.glob("robot/*.pickle"))) == 1
    run(tmp_path / "stored.jsonl")                               # reads what was kept
    fresh = (tmp_path / "fresh.jsonl").read_bytes()
    assert fresh and (tmp_path / "first.jsonl").read_bytes() == fresh
    assert (tmp_path / "stored.jsonl").read_bytes() == fresh


def test_what_is_not_this_users_own_or_not_what_it_claims_is_never_read(tmp_path, monkeypatch):
    monkeypatch.setenv("KRL_CACHE_DIR", str(tmp_path))
    monkeypatch.delattr(os, "fork")                     # written at once, in this process
    made = []

    def make():
        made.append(1)
        return {"value": len(made)}

    assert store.stored("t", ("k",), make) == {"value": 1}
    files = list((tmp_path / "stored" / "t").glob("*.pickle"))
    assert len(files) == 1 and files[0].stat().st_mode & 0o777 == 0o600
    assert store.stored("t", ("k",), make) == {"value": 1} and len(made) == 1      # read back
    f = files[0]
    good = f.read_bytes()
    os.chmod(f, 0o620)                                  # writable by the group: not read
    assert store.stored("t", ("k",), make) == {"value": 2}
    for bad in (b"not a stored result\n" + good, good.replace(good.splitlines()[1], b"0" * 64, 1),
                good[:len(good) // 2]):
        f.write_bytes(bad)
        os.chmod(f, 0o600)
        n = len(made)
        assert store.stored("t", ("k",), make) == {"value": n + 1}
    assert store.stored("t", ("k",), make) == {"value": len(made)}     # the last one made is kept
    monkeypatch.setattr(store, "MAX_STORED_BYTES", 10)
    assert store._read(f, good.splitlines()[1].decode()) is None       # past the size limit
