"""The one store of parse and check results (krl/store.py, krl/parsecache.py), shared by the
language server and krl run/debug: a program run from stored parses runs exactly as from files
parsed now (the trace is the oracle), a file parsed by `krl debug` is a hit for the language
server and the other way round, a corrupt entry or database is parsed again (never a crash),
and nothing read from the store is ever unpickled."""

from __future__ import annotations

import hashlib
import json
import os
import pickle
import shutil
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import msgpack
import pytest
from click.testing import CliRunner

import interp.runtime.program as program_mod
import krl.lsp.project as project_mod
import krl.parsecache as parsecache
import krl.store as store
from app import main as app_main
from interp.debug.client import DapClient
from interp.run import make_runtime, run_spec, RunSinks
from interp.runtime.sizedcache import SizedCache
from krl.lsp.paths import norm
from krl.limits import MODEL_CACHE_BYTES
from krl.lsp.project import Project
from krl.parsecache import load_files
from krl.pool import Outcome
from krl.project import project_of
from krl.semantics import builtins as B
from krl.workspace import load_batch
from robot.trace import TraceWriter
from tests import forkserver

REPO = Path(__file__).resolve().parents[2]
CASES = sorted(p for p in (REPO / "conformance" / "cases").iterdir() if (p / "program.src").is_file())
BACKUP = REPO / "tests" / "lsp" / "fixtures" / "backup"
CORPUS = REPO.parent / "shared" / "krl-corpus"
MILLING = CORPUS / "HugoDanielson__ChinaMilling" / "KRC"


@pytest.fixture
def cache(tmp_path, monkeypatch) -> Path:
    """A fresh user cache folder for this process and the processes it starts, and an empty
    cache of checked workspaces of the test's own (interp/runtime/program.py ``_CACHE``, which
    the tests empty again to read from the store): the process's, with the corpus backups
    other tests of this worker ask for again, is kept (before, emptying it here made each
    worker load them again after these tests: 2026-11-28, issue 87)."""
    d = tmp_path / "cache"
    monkeypatch.setenv("KRL_CACHE_DIR", str(d))
    monkeypatch.delenv("KRL_STORE", raising=False)
    monkeypatch.setattr(program_mod, "_CACHE", SizedCache(MODEL_CACHE_BYTES))
    return d


def _rows(db_path: Path) -> dict:
    """(kind, key) -> (rowid, used) of every entry of the database."""
    with sqlite3.connect(db_path) as db:
        return {(k, key): (rowid, used) for rowid, k, key, used in
                db.execute("SELECT rowid, kind, key, used FROM entries")}


def _database(cache: Path) -> Path:
    [db] = list((cache / "front-end").glob("*.sqlite"))
    return db


def _trace(program: Path, inputs=None) -> str:
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(program, mujoco=False, max_sim_time=60, inputs=inputs, max_steps=2_000_000),
                         RunSinks(trace=tw))
    res = rt.run()
    return res.reason + json.dumps(tw.events, default=str)


def test_a_sample_of_conformance_programs_runs_the_same_from_stored_parses(cache, monkeypatch):
    # every 25th case (motion, I/O, interrupts and submit cases among them): without the store,
    # then filling it, then from it (the per-process cache emptied each time)
    sample = CASES[::25]
    assert len(sample) >= 4
    for case in sample:
        inputs = case / "stimuli.yaml" if (case / "stimuli.yaml").is_file() else None
        runs = []
        for keep in ("0", "1", "1"):
            monkeypatch.setenv("KRL_STORE", keep)
            program_mod._CACHE.clear()
            s = store.shared_store()
            hits = s.hits
            before = _rows(_database(cache)) if (cache / "front-end").exists() else None
            runs.append((_trace(case / "program.src", inputs), s.hits - hits))
            if keep == "0":         # the database neither read (its rows' last use) nor written
                after = _rows(_database(cache)) if (cache / "front-end").exists() else None
                assert after == before, case.name
        (fresh, _h0), (first, _h1), (again, h2) = runs
        assert first == fresh and again == fresh, case.name
        assert h2 > 0, case.name                        # the third run read its files from the store


def _lsp_analysis(root: Path, cache: Path) -> tuple[store.Store, list]:
    s = store.Store(cache)
    an = Project(store=s).analyze(norm(root / "R1" / "Program" / "main.src"), docs={})
    return s, an.ws.diagnostics


def _debug_launch(program: Path, cache: Path) -> None:
    # `krl debug` as a fork of the worker's fork server (tests/forkserver.py: the child takes this
    # environment, so its store is the one of KRL_CACHE_DIR, krl/store.py shared_store): its
    # start, the import of the project, is not what is tested (1.4 s of CPU a session, 2026-11-29)
    with DapClient(timeout=300, env={"KRL_CACHE_DIR": str(cache)}, python=str(forkserver.shared().launcher)) as c:
        c.initialize()
        c.request("launch", {"program": str(program), "stopOnEntry": True})
        c.request("configurationDone")
        c.wait_event("stopped")
        c.request("disconnect", {})


def test_a_file_parsed_by_krl_debug_is_a_hit_for_the_language_server(tmp_path, cache):
    root = tmp_path / "KRC"
    shutil.copytree(BACKUP, root)
    _debug_launch(root / "R1" / "Program" / "main.src", cache)
    before = _rows(_database(cache))
    assert sum(k == "parse" for k, _ in before) >= 5
    s, _diags = _lsp_analysis(root, cache)
    assert s.misses == 0 and s.hits >= 5               # every file of the workspace from debug's parses
    after = _rows(_database(cache))
    assert all(after[k][0] == v[0] for k, v in before.items() if k[0] == "parse")     # none parsed again


def test_a_file_parsed_by_the_language_server_is_a_hit_for_krl_debug(tmp_path, cache):
    root = tmp_path / "KRC"
    shutil.copytree(BACKUP, root)
    s, _diags = _lsp_analysis(root, cache)
    assert s.hits == 0 and s.misses == 5
    s.close()
    before = _rows(_database(cache))
    parses = {k: v for k, v in before.items() if k[0] == "parse"}
    assert len(parses) == 5
    with sqlite3.connect(_database(cache)) as db:     # last used two hours ago (the store keeps
        db.execute("UPDATE entries SET used = used - 7200 WHERE kind = 'parse'")   # it to the hour)
    _debug_launch(root / "R1" / "Program" / "main.src", cache)
    after = _rows(_database(cache))
    for k, (rowid, used) in parses.items():
        assert after[k][0] == rowid                     # not written again: not parsed again
        assert after[k][1] > used                       # read by the debugger (its last use moved)


def test_a_lookup_of_entries_used_within_the_hour_writes_nothing(tmp_path):
    """Store.get writes an entry's last use again only when it is older than
    USED_RESOLUTION_S (1 h): a second lookup right after the first changes no row."""
    s = store.Store(tmp_path)
    s.put("parse", {"a": b"x" * 10, "b": b"y" * 10})
    with sqlite3.connect(s.path) as db:
        db.execute("UPDATE entries SET used = used - 7200 WHERE key = 'a'")
        old = dict(db.execute("SELECT key, used FROM entries"))
    assert s.get("parse", ["a", "b"]) == {"a": b"x" * 10, "b": b"y" * 10}
    with sqlite3.connect(s.path) as db:
        new = dict(db.execute("SELECT key, used FROM entries"))
    assert new["b"] == old["b"] and new["a"] > old["a"] + 7000
    changes = s.db.total_changes
    s.get("parse", ["a", "b"])
    assert s.db.total_changes == changes


def _corrupt_every_parse(db_path: Path, data: bytes, good_digest: bool) -> int:
    digest = hashlib.sha256(data).digest() if good_digest else b"\0" * 32
    with sqlite3.connect(db_path) as db:
        return db.execute("UPDATE entries SET data = ?, digest = ? WHERE kind = 'parse'", (data, digest)).rowcount


@pytest.mark.parametrize("data,good_digest", [
    (b"\x00\x11\x22\x33", False),                      # bytes that do not match their digest
    (msgpack.packb([[999, 1, 1], True, "ok", [], False, [], [], []]), True),      # no such node class
    (msgpack.packb({"a": 1}), True),                   # not an entry
    (b"\xc1\xc1\xc1", True),                           # not msgpack
])
def test_a_corrupt_entry_is_parsed_again_not_a_crash(cache, data, good_digest):
    case = CASES[0] / "program.src"
    fresh = _trace(case)
    db = _database(cache)
    assert _corrupt_every_parse(db, data, good_digest) > 0
    program_mod._CACHE.clear()
    s = store.shared_store()
    corrupt = s.corrupt
    assert _trace(case) == fresh
    assert s.corrupt > corrupt
    program_mod._CACHE.clear()
    hits = s.hits
    assert _trace(case) == fresh and s.hits > hits      # the entries were made anew


def test_a_database_that_is_not_sqlite_is_rebuilt_not_a_crash(cache, capsys):
    # issue 74, case 8: before, a garbage database switched the cache off for good (every
    # later command ran cold); now it is removed and made anew, said once on stderr
    case = CASES[0] / "program.src"
    fresh = _trace(case)
    db = _database(cache)
    store._SHARED.clear()
    db.write_bytes(b"this is not a database" * 100)
    program_mod._CACHE.clear()
    capsys.readouterr()
    assert _trace(case) == fresh
    s = store.shared_store()
    assert s.db is not None and s.rebuilt and s.hits == 0 and s.misses > 0
    assert capsys.readouterr().err.count("was damaged") == 1
    store._SHARED.clear()


@pytest.mark.parametrize("damage", ["garbage", "truncated"])
def test_a_damaged_database_is_rebuilt_once_with_one_warning(tmp_path, capsys, damage):
    # issue 74, case 8, at the store: the next store of the folder is warm and says nothing
    s = store.Store(tmp_path)
    s.put("parse", {f"k{i}": os.urandom(3000) for i in range(40)})
    s.close()
    db = s.path
    if damage == "garbage":
        db.write_bytes(b"this is not a database" * 100)
    else:                     # cut by a full disk or a crash: the header kept, the pages lost
        with open(db, "r+b") as fh:
            fh.truncate(db.stat().st_size // 3)
    capsys.readouterr()
    healed = store.Store(tmp_path)
    assert healed.db is not None and healed.rebuilt
    assert healed.get("parse", ["k1"]) == {}                 # the damaged entries are gone
    healed.put("parse", {"k1": b"anew"})
    healed.close()
    err = capsys.readouterr().err
    assert err.count("was damaged") == 1 and "it is rebuilt" in err
    warm = store.Store(tmp_path)
    assert warm.get("parse", ["k1"]) == {"k1": b"anew"} and not warm.rebuilt
    warm.close()
    assert capsys.readouterr().err == ""


def test_krl_check_no_cache_neither_reads_nor_keeps_parses(cache, tmp_path):
    # issue 74, case 8: a way around the store for one command (as krl recover --no-cache)
    prog = tmp_path / "nocache.src"
    prog.write_text("DEF nocache()\n  $OUT[1] = TRUE\nEND\n")
    store._SHARED.clear()
    res = CliRunner().invoke(app_main, ["check", "--no-cache", "--jobs", "1", str(prog)])
    assert res.exit_code == 0, res.output
    db = cache / "front-end"
    rows = 0
    for f in db.glob("*.sqlite"):
        with sqlite3.connect(f) as con:
            rows += con.execute("SELECT COUNT(*) FROM entries WHERE kind = 'parse'").fetchone()[0]
    assert rows == 0
    store._SHARED.clear()
    assert CliRunner().invoke(app_main, ["check", "--jobs", "1", str(prog)]).exit_code == 0
    with sqlite3.connect(_database(cache)) as con:
        assert con.execute("SELECT COUNT(*) FROM entries WHERE kind = 'parse'").fetchone()[0] == 1
    store._SHARED.clear()


def test_krl_cache_clear_removes_the_store_and_nothing_else(cache, tmp_path):
    s = store.Store(cache)
    s.put("parse", {"k": b"data"})
    s.close()
    elsewhere = tmp_path / "keep.sqlite"
    elsewhere.write_bytes(b"not ours")
    (cache / "front-end" / "link.sqlite").symlink_to(elsewhere)
    (cache / "front-end" / "notes.txt").write_text("kept")
    res = CliRunner().invoke(app_main, ["cache", "clear"])
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in (cache / "front-end").iterdir()) == ["link.sqlite", "notes.txt"]
    assert elsewhere.read_bytes() == b"not ours"
    assert res.output.startswith("removed 1 file(s)")
    assert CliRunner().invoke(app_main, ["cache", "path"]).output.strip() == str(cache)


def test_the_store_never_unpickles(cache, tmp_path, monkeypatch):
    """A pickle planted in an entry (with a matching digest) is a corrupt entry: it never
    runs, and no part of loading a program from the store calls the pickle module."""
    marker = tmp_path / "pwned"

    class Planted:
        def __reduce__(self):
            return (os.system, (f"touch {marker}",))

    case = CASES[0] / "program.src"
    fresh = _trace(case)
    payload = pickle.dumps(Planted())
    assert _corrupt_every_parse(_database(cache), payload, True) > 0

    def refuse(*_a, **_k):
        raise AssertionError("the store unpickled something")
    for name in ("load", "loads"):
        monkeypatch.setattr(pickle, name, refuse)
    monkeypatch.setattr(pickle, "Unpickler", refuse)
    program_mod._CACHE.clear()
    s = store.shared_store()
    corrupt = s.corrupt
    assert _trace(case) == fresh
    assert s.corrupt > corrupt and not marker.exists()
    for module in ("krl/store.py", "krl/parsecache.py"):
        text = (REPO / module).read_text()
        assert "pickle" not in text.replace("unpickled", "").replace("pickles", ""), module


@pytest.mark.parametrize("data", [msgpack.packb([1, 2]), msgpack.packb({"x": msgpack.ExtType(1, b"x")}),
                                  msgpack.packb({"types": 5, "functions": "x"})])
def test_a_corrupt_table_entry_is_read_from_the_yaml_again(cache, data):
    fresh = B._load_builtins(store.Store(enabled=False))
    B._load_builtins()                                  # fills the store
    digest = hashlib.sha256(data).digest()
    with sqlite3.connect(_database(cache)) as db:
        assert db.execute("UPDATE entries SET data = ?, digest = ? WHERE kind = 'table'", (data, digest)).rowcount == 4
    assert B._builtins() == fresh


def test_krl_store_0_keeps_nothing(cache, monkeypatch):
    monkeypatch.setenv("KRL_STORE", "0")
    load_files([BACKUP / "R1" / "Program" / "main.src"])
    assert not (cache / "front-end").exists()


def test_the_database_keeps_within_its_limit(tmp_path, monkeypatch):
    monkeypatch.setattr(store, "MAX_CACHE_BYTES", 4000)
    monkeypatch.setattr(store, "MAX_CACHE_ENTRY_BYTES", 300)
    s = store.Store(tmp_path)
    for k in range(40):
        s.put("parse", {f"k{k}": bytes(200)})
    s.put("parse", {"big": bytes(301)})                # past the entry limit: not kept
    size = s.db.execute("SELECT SUM(LENGTH(data)) FROM entries").fetchone()[0]
    assert size <= 4000 and s.get("parse", ["k39"]) and not s.get("parse", ["big"])


@pytest.mark.slow       # three krl runs of a 150-file backup
@pytest.mark.skipif(not MILLING.is_dir(), reason="the shared corpus is beside the repository")
def test_krl_run_from_the_store_in_another_process_gives_the_same_trace(tmp_path):
    program = MILLING / "R1" / "Program" / "KukaMiling" / "Main.src"
    env = {**os.environ, "KRL_CACHE_DIR": str(tmp_path / "cache")}

    def run(trace: Path, **extra) -> None:
        subprocess.run([sys.executable, "-m", "app", "run", str(program), "--max-sim-time", "3",
                        "--trace", str(trace)], env={**env, **extra}, cwd=REPO, capture_output=True,
                       timeout=900, check=False)

    run(tmp_path / "fresh.jsonl", KRL_STORE="0")
    assert not (tmp_path / "cache" / "front-end").exists()         # KRL_STORE=0 keeps nothing
    run(tmp_path / "first.jsonl")                                # parses and keeps
    rows = _rows(_database(tmp_path / "cache"))
    assert sum(k == "parse" for k, _ in rows) >= len(project_of(program).files)
    run(tmp_path / "stored.jsonl")                               # reads what was kept
    fresh = (tmp_path / "fresh.jsonl").read_bytes()
    assert fresh and (tmp_path / "first.jsonl").read_bytes() == fresh
    assert (tmp_path / "stored.jsonl").read_bytes() == fresh
    assert {k: v[0] for k, v in _rows(_database(tmp_path / "cache")).items()} == {k: v[0] for k, v in rows.items()}


def test_a_stored_parse_gives_notes_at_the_files_own_path(tmp_path):
    """The same content at two paths is one parse entry (keyed by content): the second file's
    diagnostics, read from the store, point their notes at the second file, not the first."""
    text = "DEF x()\n;FOLD never closed\nx = 1\nEND\n"       # W021 at line 2, its note at the END (line 4)
    a, b = tmp_path / "a" / "x.src", tmp_path / "b" / "x.src"
    for f in (a, b):
        f.parent.mkdir()
        f.write_text(text)
    s = store.Store(tmp_path / "cache")
    [la] = load_files([a], store=s)
    [lb] = load_files([b], store=s)
    assert (s.misses, s.hits) == (1, 1)                 # b came from a's entry
    for lf, f in ((la, a), (lb, b)):
        [w] = [d for d in lf.diagnostics if d.code == "W021"]
        assert (w.path, w.line) == (str(f), 2)
        assert [(n.path, n.line) for n in w.notes] == [(str(f), 4)]


def _stopped(paths, timeout, jobs=None, threaded=False):
    """load_batch as when each file's worker was stopped: the first past its timeout, the others
    lost with their worker (krl.pool.Outcome)."""
    return [Outcome(p, "timeout" if i == 0 else "internal_error", None, "the worker process died (SIGKILL)")
            for i, p in enumerate(paths)]


@pytest.mark.parametrize("way", ["language server", "krl check"])
def test_a_stopped_parse_is_never_stored(tmp_path, monkeypatch, way):
    """A parse stopped past its timeout (E005) or lost with its worker (E001) is shown for what
    it is, and never kept: the next load of the same content parses it (docs/security.md)."""
    root = tmp_path / "KRC"
    shutil.copytree(BACKUP, root)
    files = sorted(norm(p) for p in root.rglob("*") if p.suffix.lower() in (".src", ".dat", ".sub"))
    assert len(files) >= 2
    s = store.Store(tmp_path / "cache")
    if way == "language server":        # its worker path (a big workspace parsed by the fast engine)
        monkeypatch.setattr(project_mod, "load_batch", _stopped)
        monkeypatch.setattr(project_mod, "_java", lambda: True)
        monkeypatch.setattr(project_mod, "PARALLEL_BYTES", 0)
        monkeypatch.setattr(project_mod, "default_jobs", lambda: project_mod.PARALLEL_MIN_JOBS)
        p = Project(store=s)
        p.load_files(files)
        got = [p._disk[f][1].loaded for f in files]
    else:
        monkeypatch.setattr(parsecache, "load_batch", _stopped)
        got = load_files(files, timeout=1.0, store=s)
    codes = [[d.code for d in lf.diagnostics] for lf in got]
    assert codes == [["E005"]] + [["E001"]] * (len(files) - 1)
    assert s.db.execute("SELECT COUNT(*) FROM entries WHERE kind = 'parse'").fetchone()[0] == 0
    monkeypatch.undo()
    again = store.Store(tmp_path / "cache")
    fresh = load_files(files, store=again)
    assert again.hits == 0 and again.misses == len(files)
    assert all(not any(d.code in ("E001", "E005") for d in lf.diagnostics) for lf in fresh)


def test_an_entry_past_the_size_limit_is_not_read(tmp_path, monkeypatch):
    """A row larger than MAX_CACHE_ENTRY_BYTES (never written so: planted, with a matching
    digest) is a corrupt entry: left out, counted, and its data never returned."""
    monkeypatch.setattr(store, "MAX_CACHE_ENTRY_BYTES", 300)
    s = store.Store(tmp_path)
    s.put("parse", {"small": bytes(300)})
    big = bytes(301)
    s.db.execute("INSERT INTO entries VALUES ('parse', 'big', ?, ?, 0)", (hashlib.sha256(big).digest(), big))
    s.db.commit()
    assert s.get("parse", ["small", "big"]) == {"small": bytes(300)}
    assert (s.hits, s.misses, s.corrupt) == (1, 1, 1)


def test_opening_the_store_removes_old_versions_and_obsolete_folders_only(tmp_path, monkeypatch):
    """In a cache root of its own ($KRL_CACHE_DIR): other versions' databases unused for more
    than 7 days and the obsolete lsp/ and stored/ folders go; this version's database, another
    version's used within the week, other files, and anything behind a symbolic link stay."""
    root = tmp_path / "cache"
    monkeypatch.setenv("KRL_CACHE_DIR", str(root))
    monkeypatch.delenv("KRL_STORE", raising=False)
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "keep.sqlite").write_bytes(b"x")
    (outside / "inner").mkdir()
    (outside / "inner" / "keep").write_bytes(b"x")
    front = root / "front-end"
    front.mkdir(parents=True)
    eight_days, six_days = time.time() - 8 * 86400, time.time() - 6 * 86400

    def old(p: Path, when: float) -> Path:
        os.utime(p, (when, when), follow_symlinks=False)
        return p

    current = front / f"{store.front_end_version()[:24]}.sqlite"
    sqlite3.connect(current).close()
    for name in ("aaaa.sqlite", "aaaa.sqlite-journal", "bbbb.sqlite", "bbbb.sqlite-journal", "notes.txt"):
        (front / name).write_bytes(b"x")
    old(front / "aaaa.sqlite-journal", eight_days)
    old(current, eight_days)
    old(front / "aaaa.sqlite", eight_days)
    old(front / "bbbb.sqlite", eight_days)
    old(front / "bbbb.sqlite-journal", six_days)       # its journal was written within the week
    old(front / "notes.txt", eight_days)
    (front / "link.sqlite").symlink_to(outside / "keep.sqlite")
    old(front / "link.sqlite", eight_days)
    for name in ("lsp", "stored"):
        (root / name / "sub").mkdir(parents=True)
        (root / name / "sub" / "x.pickle").write_bytes(b"p" * 100)
    (root / "lsp" / "sub" / "out").symlink_to(outside / "inner")     # a link inside: removed, not followed
    (root / "other").mkdir()
    monkeypatch.setattr(store, "_TIDIED", set())
    s = store.Store()
    assert s.db is not None and s.path == current
    assert sorted(p.name for p in front.iterdir()) == sorted(
        [current.name, "bbbb.sqlite", "bbbb.sqlite-journal", "notes.txt", "link.sqlite"])
    assert not (root / "lsp").exists() and not (root / "stored").exists() and (root / "other").is_dir()
    assert (outside / "keep.sqlite").read_bytes() == b"x" and (outside / "inner" / "keep").read_bytes() == b"x"
    # once per process: a database that ages later is left for the next process
    old(front / "bbbb.sqlite-journal", eight_days)
    store.Store().close()
    assert (front / "bbbb.sqlite").exists()
    s.close()


def test_obsolete_folders_behind_a_symbolic_link_are_left(tmp_path, monkeypatch):
    root = tmp_path / "cache"
    root.mkdir()
    target = tmp_path / "elsewhere"
    (target / "sub").mkdir(parents=True)
    (target / "sub" / "x").write_bytes(b"x")
    (root / "stored").symlink_to(target)
    monkeypatch.setattr(store, "_TIDIED", set())
    monkeypatch.delenv("KRL_STORE", raising=False)
    store.Store(root).close()
    assert (root / "stored").is_symlink() and (target / "sub" / "x").exists()


def test_the_cache_root_is_created_0700(tmp_path, monkeypatch):
    monkeypatch.setenv("KRL_CACHE_DIR", str(tmp_path / "new" / "cache"))
    d = store.cache_dir()
    assert d.is_dir() and (d.stat().st_mode & 0o777) == 0o700 & ~_umask()


def _umask() -> int:
    m = os.umask(0)
    os.umask(m)
    return m


def test_a_file_changed_while_it_is_parsed_is_not_kept_under_its_old_hash(tmp_path, monkeypatch):
    """load_files hashes the files, and the worker processes read them again by path: when a
    file changes in between, the parse of the new content must not be kept under the old
    content's hash (a later load of the old content would get the new text's AST)."""
    src = tmp_path / "a.src"
    old_text = "DEF a()\n  $OUT[1] = TRUE\nEND\n"
    src.write_text(old_text, encoding="utf-8")

    def edit_then_parse(paths, timeout, jobs=None):
        src.write_text("DEF a()\n  $OUT[2] = TRUE\nEND\n", encoding="utf-8")
        return load_batch(paths, timeout, jobs)

    monkeypatch.setattr(parsecache, "load_batch", edit_then_parse)
    s = store.Store(tmp_path / "cache")
    load_files([norm(src)], timeout=60.0, store=s)
    assert s.db.execute("SELECT COUNT(*) FROM entries WHERE kind = 'parse'").fetchone()[0] == 0
    monkeypatch.undo()
    src.write_text(old_text, encoding="utf-8")
    again = store.Store(tmp_path / "cache")
    lf = load_files([norm(src)], store=again)[0]
    assert again.hits == 0
    assert lf.module.routines[0].body[0].target.indices[0].value == 1    # the old text's AST
    kept = store.Store(tmp_path / "cache")
    assert load_files([norm(src)], store=kept)[0] is not None and kept.hits == 1


def test_a_checked_workspace_whose_folder_is_gone_leaves_the_cache(cache, tmp_path):
    """A run's checked workspace is kept for the next run of the same files (the programs of a
    backup), but not once its folder is gone: the variants sweep runs each variant in a
    temporary folder, and eight dead workspaces made every collection of a Dask worker walk
    about 2 million objects (2026-11-27)."""
    folders = [tmp_path / "a", tmp_path / "b"]
    for d in folders:
        d.mkdir()
        (d / "p.src").write_text("DEF p()\nEND\n")
    make_runtime(run_spec(folders[0] / "p.src", mujoco=False))
    roots = lambda: {Path(k[0]).name for k in program_mod._CACHE.keys()}  # noqa: E731
    assert roots() == {"a"}
    make_runtime(run_spec(folders[1] / "p.src", mujoco=False))
    assert roots() == {"a", "b"}
    shutil.rmtree(folders[0])
    make_runtime(run_spec(folders[1] / "p.src", mujoco=False))
    assert roots() == {"b"}
