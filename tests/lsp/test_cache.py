"""The language server's use of the one store (krl/store.py, krl/parsecache.py): entries decode to
exactly what was parsed, a workspace opened again gets its files from the cache and its
diagnostics before its check, and a corrupt or hostile entry is ignored (parsed again), never
trusted."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

import msgpack
import pytest

import krl.parsecache as C
from krl.limits import PARSE_TIMEOUT_S
from krl.lsp.bench import corpus_backups
from krl.project import project_of
from krl.lsp.paths import norm
from krl.lsp.project import Project
from krl.source import decode_bytes
from krl.store import Store
from krl.workspace import Workspace, load_batch, load_file
from tests.conftest import SHARED
from tests.lsp.conftest import BACKUP


def rows(diags):
    return [(d.path, d.line, d.column, d.code, d.message, d.end_line, d.end_column, d.help,
             [(n.path, n.line, n.column, n.message) for n in d.notes]) for d in diags]


def spans(m):
    return [(type(n).__name__, n.span.file, n.span.line, n.span.column, getattr(n, "end_line", 0)) for n in m.walk()]


def reference_entry(lf) -> bytes:
    """The entry's bytes as the cache's schema describes them (krl/parsecache.py), written out
    plainly: the on-disk format must not change with the codec's implementation."""
    def enc(v):
        if isinstance(v, C.N.Node):
            fields = [f for f in dataclasses.fields(v) if f.name not in ("span", "ann")]
            fields = [f for f in fields if not f.kw_only] + [f for f in fields if f.kw_only]
            return [C._INDEX[type(v)], v.span.line, v.span.column, *[enc(getattr(v, f.name)) for f in fields]]
        if type(v) is list:
            return [C._LIST, *map(enc, v)]
        if type(v) is tuple:
            return [C._TUPLE, *map(enc, v)]
        assert v is None or type(v) in (int, float, str, bool), type(v)
        return v
    diags = [[d.line, d.column, d.code, d.message, d.severity, d.end_line, d.end_column, d.help,
              [[n.line, n.column, n.message] for n in d.notes]] for d in lf.diagnostics]
    return msgpack.packb([enc(lf.module), lf.ok, lf.status, diags, lf.unreadable, sorted(lf.failed_words),
                          *(sorted(map(list, lines.items())) for lines in lf.template)],
                         use_bin_type=True)


def test_entries_decode_to_what_was_parsed(shared_corpus: Path):
    """Every file of a real backup: AST (spans included), diagnostics, template folds, status."""
    backup = shared_corpus / "rawpython__kukaKRLmagic"
    files = sorted(p for p in backup.rglob("*") if p.suffix.lower() in (".src", ".dat", ".sub") and p.is_file())
    assert len(files) > 20
    for f in files:
        lf = load_file(f)
        data = C.encode_loaded(lf)
        assert data is not None, f
        assert data == reference_entry(lf), f
        back = C.decode_loaded(data, lf.path)
        assert back.module == lf.module and spans(back.module) == spans(lf.module), f
        assert rows(back.diagnostics) == rows(lf.diagnostics)
        assert (back.ok, back.status, back.unreadable, back.failed_words, back.template) == \
            (lf.ok, lf.status, lf.unreadable, lf.failed_words, lf.template)


@pytest.mark.parametrize("body", [
    [],                                             # too short
    [[999, 1, 1], True, "ok", [], False, [], [], [], []],          # no such node class
    [[C._INDEX[C.N.Module], 1, 1], True, "ok", [], False, [], [], [], []],     # a node of another shape
    [None, True, "ok", [], False, [], [], [], []],       # not a module
    [[C._INDEX[C.N.Module], 1, 1, [C._LIST], [C._LIST], None, "x"], True, "ok", [[1, 1, "E", "m"]], False, [], [], [], []],
    # a valid empty module ([C._INDEX[C.N.Module], 1, 1, "p", "src", [C._LIST], [C._LIST], None]) changed:
    [[C._INDEX[C.N.Module], 1, 1, "p", b"", [C._LIST], [C._LIST], None], True, "ok", [], False, [], [], [], []],  # bytes
    [[C._INDEX[C.N.Module], 1, 1, "p", "src", {}, [C._LIST], None], True, "ok", [], False, [], [], [], []],     # a map
    [[C._INDEX[C.N.Module], 1, 1, "p", "src", [C._LIST], [C._LIST, [7]], None], True, "ok", [], False, [], [], [], []],
    [[C._INDEX[C.N.Module], 1, 1, "p", "src", [C._LIST], [C._LIST], None], True, "ok", [], False, [], [], [], [], 0],
])
def test_a_hostile_entry_is_refused(body):
    with pytest.raises(C.CorruptEntry):
        C.decode_loaded(msgpack.packb(body, use_bin_type=True), "/w/x.src")


def test_the_valid_entry_the_hostile_ones_change_decodes():
    body = [[C._INDEX[C.N.Module], 1, 1, "p", "src", [C._LIST], [C._LIST], None, [C._LIST], 0], True, "ok", [], False,
            [], [], [], []]
    lf = C.decode_loaded(msgpack.packb(body, use_bin_type=True), "/w/x.src")
    assert lf.module == C.N.Module("/w/x.src", "src", [], [], None) and lf.ok


def test_the_cache_serves_a_workspace_opened_again(tmp_path: Path):
    shutil.copytree(BACKUP, tmp_path / "KRC")
    main = norm(tmp_path / "KRC" / "R1" / "Program" / "main.src")
    store = Store(tmp_path / "cache")
    assert store.db is not None
    first = Project(store=store)
    an = first.analyze(main, docs={})
    assert store.hits == 0 and store.misses == 5
    cached: list = []
    again = Project(store=store)
    an2 = again.analyze(main, docs={}, on_cached=lambda root, diags: cached.append(diags))
    assert store.hits >= 5                              # every file from the cache
    assert rows(an2.ws.diagnostics) == rows(an.ws.diagnostics)
    assert cached and rows(cached[0]) == rows(an.ws.diagnostics)      # before the check: the same
    # a file changed on disk is parsed again, not taken from the cache
    tools = tmp_path / "KRC" / "R1" / "Program" / "tools.src"
    tools.write_text(tools.read_text() + "\n; changed\n")
    third = Project(store=store)
    misses = store.misses
    third.analyze(main, docs={})
    assert store.misses == misses + 1                   # tools.src


def test_a_corrupt_database_entry_is_parsed_again(tmp_path: Path):
    shutil.copytree(BACKUP, tmp_path / "KRC")
    main = norm(tmp_path / "KRC" / "R1" / "Program" / "main.src")
    store = Store(tmp_path / "cache")
    an = Project(store=store).analyze(main, docs={})
    store.db.execute("UPDATE entries SET data = X'00112233' WHERE kind = 'parse'")
    store.db.commit()
    corrupt = store.corrupt
    an2 = Project(store=store).analyze(main, docs={})
    assert store.corrupt == corrupt + 5
    assert rows(an2.ws.diagnostics) == rows(an.ws.diagnostics)


def test_no_cache_when_the_folder_cannot_be_made(tmp_path: Path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    store = Store(blocker / "cache")
    assert store.db is None
    assert store.get("parse", ["a"]) == {}
    store.put("parse", {"a": b"x"})                     # never raises


def test_the_cached_diagnostics_come_before_any_parse_is_decoded(tmp_path: Path, monkeypatch):
    """The check's key needs only the files' content hashes: the cached diagnostics of a
    workspace opened again are handed over before the first parse entry is decoded, with the
    opened file's buffer as it is on disk and with a buffer edited in a session before."""
    shutil.copytree(BACKUP, tmp_path / "KRC")
    main = norm(tmp_path / "KRC" / "R1" / "Program" / "main.src")
    text = Path(main).read_text()
    edited = text.replace("\nEND", "\n  no_such_name = 1\nEND", 1)      # an undeclared name: a finding
    assert edited != text
    store = Store(tmp_path / "cache")
    for docs in ({main: text}, {main: edited}):
        expected = Project(store=store).analyze(main, docs=docs).ws.diagnostics
        assert bool(expected) == (docs[main] is edited)
        events: list = []
        decode = C.decode_loaded
        monkeypatch.setattr(C, "decode_loaded", lambda data, path: events.append("decoded") or decode(data, path))
        an = Project(store=store).analyze(main, docs=docs, on_cached=lambda root, diags: events.append(rows(diags)))
        monkeypatch.undo()
        assert events[0] == rows(expected) == rows(an.ws.diagnostics)
        assert events.count("decoded") >= 4 and len([e for e in events if e != "decoded"]) == 1


def test_deferred_entries_are_written_after_the_check_open_files_encoded_at_once(tmp_path: Path):
    """The server's way (Project(defer_writes=True)): nothing is written before the check is
    published; the open file's entry (encoded before any edit) and the check's diagnostics are
    written by the first write_cache step, the other files' entries by write_cache, step by step;
    a file opened in between is left out."""
    shutil.copytree(BACKUP, tmp_path / "KRC")
    main = norm(tmp_path / "KRC" / "R1" / "Program" / "main.src")
    tools = norm(tmp_path / "KRC" / "R1" / "Program" / "tools.src")
    store = Store(tmp_path / "cache")
    first = Project(store=store, defer_writes=True)
    first.open(main, Path(main).read_text())
    an = first.analyze(main)
    count = lambda: store.db.execute("SELECT COUNT(*) FROM entries WHERE kind = 'parse'").fetchone()[0]  # noqa: E731
    checks = lambda: store.db.execute("SELECT COUNT(*) FROM entries WHERE kind = 'check'").fetchone()[0]  # noqa: E731
    assert count() == 0 and checks() == 0               # no commit before the publication
    assert [kind for kind, _items in first.unwritten_entries] == ["parse", "check"]
    assert sorted(p for _k, p, _lf, _status in first.unwritten) == sorted(set(an.files) - {main})
    first.open(tools, Path(tools).read_text())          # opened before its entry is written
    assert first.write_cache(1) == len(an.files) - 2
    assert count() == 2 and checks() == 1               # main.src, the open file, one more, the check
    assert not first.unwritten_entries
    assert first.write_cache() == 0 and not first.unwritten
    assert count() == len(an.files) - 1                 # all but tools.src
    again = Project(store=store)
    hits = store.hits
    an2 = again.analyze(main, docs={})
    assert store.hits - hits == len(an.files) - 1
    assert rows(an2.ws.diagnostics) == rows(an.ws.diagnostics)


def _backups():
    if not (SHARED / "krl-corpus").is_dir():
        return []
    # the backup of fewest KRL files in make test (rawpython__kukaKRLmagic: 35 files, where the
    # first by position, ChinaMilling, has 157: 4.7 -> 2.5 s of CPU, 2026-11-28), every backup in
    # make nightly (docs/architecture.md, "The test suite": a sweep over the corpus keeps a sample
    # in make test)
    backups = corpus_backups(SHARED / "krl-corpus")
    sample = min(backups, key=lambda b: (len(project_of(b[1]).files), b[0]), default=None)
    return [pytest.param(root, largest, id=label, marks=[] if (label, root, largest) == sample else [pytest.mark.slow])
            for label, root, largest in backups]


@pytest.mark.parametrize("root,largest", _backups())
def test_every_corpus_backup_gives_krl_checks_diagnostics_cold_and_from_the_cache(tmp_path: Path, root: Path,
                                                                                  largest: Path):
    """The server's way on each corpus backup as it is (its largest file open, as the bench
    does): cold (parse entries written after the check), from the cache, and the cached
    diagnostics shown before the check: all exactly those of ``krl check``'s pipeline on the
    same files (krl/workspace.py: each file loaded whole by its loader, then checked)."""
    store = Store(tmp_path / "cache")
    path = norm(largest)
    text = decode_bytes(largest.read_bytes())[0]
    expected = None
    for run in ("cold", "warm"):
        p = Project(store=store, defer_writes=True)
        p.open(path, text)
        cached: list = []
        an = p.analyze(path, on_cached=lambda _root, diags: cached.append(diags))
        if expected is None:
            ref = Workspace(an.root)
            for o in load_batch(list(an.files), PARSE_TIMEOUT_S):
                ref.add_loaded(o.value, notify=False)
            ref.add_unread(p.workspace_files(path)[2])
            ref.check(resolve=False)        # as krl check checks (app/check.py)
            expected = rows(ref.diagnostics)
            assert expected
        assert rows(an.ws.diagnostics) == expected, run
        if run == "cold":
            assert not cached and p.unwritten
            assert p.write_cache() == 0
        else:
            assert cached and sorted(rows(cached[0])) == sorted(expected)
            assert store.corrupt == 0 and store.hits >= len(an.files)
