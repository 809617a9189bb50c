"""The scan's own robustness (issue 12): dying and stuck workers, the result cache, atomic
reports and spreadsheet-safe CSV."""

from __future__ import annotations

import contextlib
import csv
import ctypes
import faulthandler
import hashlib
import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path
import random

import pytest

from krl import durable
from recovery import pipeline, report as report_mod
from recovery import scan as scan_mod
from recovery.cluster import Cluster
from recovery.report import ReportStream, SummaryBuilder, summarise, write_clusters_csv, write_report
from recovery.scan import FileResult, scan

REPO_ROOT = Path(__file__).resolve().parents[2]
KRL = [sys.executable, "-m", "app"]
VALID = "DEF t()\n  x = 1\nEND\n"
BROKEN = "DEF t()\n  IF x THEN\nEND\n"


def _stubborn() -> None:
    while True:
        try:
            time.sleep(3600)
        except BaseException:  # noqa: BLE001, S110 - a parse that swallows everything
            pass


@pytest.mark.wall_clock   # waits out a stuck worker's timeout (tests/conftest.py)
def test_dying_and_stuck_workers_give_rows_and_the_scan_goes_on(tmp_path: Path, monkeypatch) -> None:
    for name in ("exit.src", "kill.src", "segv.src", "oom.src", "stuck.src"):
        (tmp_path / name).write_text(BROKEN)      # would form a cluster if it were parsed
    (tmp_path / "good.src").write_text(VALID)
    (tmp_path / "bad.src").write_text(BROKEN)
    real = scan_mod.parse_row

    def parse_row(rel, data, sha):
        if rel == "exit.src":
            os._exit(3)
        if rel == "kill.src":
            os.kill(os.getpid(), signal.SIGKILL)
        if rel == "segv.src":
            faulthandler.disable()                 # the crash is the test: no stack dump in the log
            ctypes.string_at(0)                    # a segmentation fault
        if rel == "oom.src":
            raise MemoryError()
        if rel == "stuck.src":
            _stubborn()
        return real(rel, data, sha)

    monkeypatch.setattr(scan_mod, "parse_row", parse_row)
    # a generous timeout: the files that do parse take milliseconds, even on a loaded machine
    results = scan(tmp_path, "g", jobs=2, use_cache=False, progress=False, timeout=5)
    rows = {r.path: r for r in results}
    assert {p: r.status for p, r in rows.items()} == {
        "bad.src": "syntax_error", "exit.src": "internal_error", "good.src": "ok",
        "kill.src": "internal_error", "oom.src": "internal_error", "segv.src": "internal_error",
        "stuck.src": "timeout"}
    assert "exit status 3" in rows["exit.src"].detail
    assert "SIGKILL" in rows["kill.src"].detail
    assert "SIGSEGV" in rows["segv.src"].detail
    assert "MemoryError" in rows["oom.src"].detail
    # Internal failures and timeouts never form clusters: the one cluster is bad.src's.
    summary = summarise(results, "g", str(tmp_path), 0.0)
    assert [c.paths for c in summary.clusters] == [["bad.src"]]
    assert sorted(f["path"] for f in summary.internal_failures) == [
        "exit.src", "kill.src", "oom.src", "segv.src", "stuck.src"]


# ----------------------------------------------------------------------- the cache

def _facts(rows: dict) -> dict:
    return {p: (r.status, r.ok, r.sha, r.encoding, r.issues) for p, r in rows.items()}


def _cache_files(cache: Path) -> list[Path]:
    return sorted((cache / "results").glob("*.sqlite"))


def _cached_rows(cfile: Path) -> dict[str, dict]:
    with contextlib.closing(sqlite3.connect(cfile)) as db:
        return {sha: json.loads(row) for sha, row in db.execute("SELECT sha, row FROM results")}


def test_corrupt_cache_entries_are_ignored_and_rebuilt_with_one_warning(tmp_path: Path, monkeypatch) -> None:
    cache = tmp_path / "cache"
    monkeypatch.setenv("KRL_CACHE_DIR", str(cache))
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    (corpus / "a.src").write_text(VALID)
    (corpus / "b.src").write_text(BROKEN)
    first = {r.path: r for r in scan(corpus, "g", jobs=1, progress=False)}
    [cfile] = _cache_files(cache)
    rows = _cached_rows(cfile)
    sha_a = hashlib.sha256(VALID.encode()).hexdigest()
    sha_b = hashlib.sha256(BROKEN.encode()).hexdigest()
    assert set(rows) == {sha_a, sha_b}
    # a poisoned entry: the broken file claimed to parse, with a field of the wrong type
    rows[sha_b]["ok"] = "yes"
    rows[sha_b]["status"] = "ok"
    with contextlib.closing(sqlite3.connect(cfile)) as db:
        db.execute("UPDATE results SET row = ? WHERE sha = ?", (json.dumps(rows[sha_b]), sha_b))
        db.execute("UPDATE results SET row = ? WHERE sha = ?", ("{not json", sha_a))
        db.commit()
    warnings: list[str] = []
    second = {r.path: r for r in scan(corpus, "g", jobs=1, progress=False, warn=warnings.append)}
    assert len(warnings) == 1 and "2 corrupt" in warnings[0]
    assert second["b.src"].status == "syntax_error" and _facts(second) == _facts(first)
    assert _cached_rows(cfile)[sha_b]["ok"] is False   # rebuilt
    # a file that is not a database at all: one warning, everything parsed again, file rewritten
    cfile.write_bytes(b"\x00garbage{" * 100)
    warnings.clear()
    third = {r.path: r for r in scan(corpus, "g", jobs=1, progress=False, warn=warnings.append)}
    assert len(warnings) == 1 and "corrupt" in warnings[0]
    assert _facts(third) == _facts(first)
    assert set(_cached_rows(cfile)) == {sha_a, sha_b}
    # a database of another version: the same
    with contextlib.closing(sqlite3.connect(cfile)) as db:
        db.execute("UPDATE meta SET value = 'old' WHERE key = 'version'")
        db.commit()
    warnings.clear()
    fourth = {r.path: r for r in scan(corpus, "g", jobs=1, progress=False, warn=warnings.append)}
    assert len(warnings) == 1 and "another version" in warnings[0]
    assert _facts(fourth) == _facts(first) and set(_cached_rows(cfile)) == {sha_a, sha_b}


def test_a_locked_cache_means_no_cache_and_one_warning_never_a_lost_cache(tmp_path: Path, monkeypatch) -> None:
    """Another scan holding the database's write lock past the wait: this scan runs without
    the cache (one warning) and leaves the other's database alone."""
    monkeypatch.setenv("KRL_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(scan_mod.ResultCache, "LOCK_WAIT_S", 0.2)
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    (corpus / "a.src").write_text(VALID)
    first = scan(corpus, "g", jobs=1, progress=False)
    [cfile] = _cache_files(tmp_path / "cache")
    holder = sqlite3.connect(cfile)
    holder.execute("BEGIN EXCLUSIVE")
    try:
        warnings: list[str] = []
        again = scan(corpus, "g", jobs=1, progress=False, warn=warnings.append)
    finally:
        holder.rollback()
        holder.close()
    assert _facts({r.path: r for r in again}) == _facts({r.path: r for r in first})
    assert len(warnings) == 1 and "running without a cache" in warnings[0]
    assert set(_cached_rows(cfile)) == {hashlib.sha256(VALID.encode()).hexdigest()}


def test_unwritable_cache_folder_means_no_cache_and_one_warning(tmp_path: Path, monkeypatch) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("KRL_CACHE_DIR", str(blocker / "cache"))   # cannot be created, even by root
    (tmp_path / "a.src").write_text(VALID)
    warnings: list[str] = []
    rows = scan(tmp_path, "g", jobs=1, progress=False, warn=warnings.append)
    assert [(r.path, r.status) for r in rows] == [("a.src", "ok")]
    assert len(warnings) == 1 and "without a cache" in warnings[0]


def test_no_cache_never_touches_the_cache_folder(tmp_path: Path, monkeypatch, capsys) -> None:
    corpus = tmp_path / "corpus"
    (corpus / "KRC" / "R1" / "System").mkdir(parents=True)        # a backup: the static check runs
    (corpus / "KRC" / "R1" / "System" / "$config.dat").write_text("DEFDAT $CONFIG\nENDDAT\n")
    (corpus / "KRC" / "R1" / "a.src").write_text("DEF a()\nEND\n")
    monkeypatch.setattr(pipeline, "negative_figures", lambda *a: None)   # not what this test is about
    (tmp_path / "blocker").write_text("a file, not a folder")
    cache = tmp_path / "never"
    for env_cache in (cache, tmp_path / "blocker" / "cache"):
        monkeypatch.setenv("KRL_CACHE_DIR", str(env_cache))
        summary = pipeline.run_recovery(corpus, tmp_path / "out", jobs=1, use_cache=False)
        assert summary.files_ok == summary.files == 2 and summary.extra["check"]["files"] == 2
        assert not cache.exists()
        assert "warning" not in capsys.readouterr().err


def test_cache_holds_the_hash_of_the_bytes_parsed(tmp_path: Path, monkeypatch) -> None:
    # The file changes on disk right after the scan read it: the row (and the cache entry)
    # describe the bytes that were read and parsed, never the new content under the old hash.
    monkeypatch.setenv("KRL_CACHE_DIR", str(tmp_path / "cache"))
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    f = corpus / "a.src"
    f.write_text(VALID)
    real = scan_mod.read_limited

    def read_then_change(path, *a, **kw):
        got = real(path, *a, **kw)
        Path(path).write_text(BROKEN)
        return got

    monkeypatch.setattr(scan_mod, "read_limited", read_then_change)
    [row] = scan(corpus, "g", jobs=1, progress=False)
    assert row.sha == hashlib.sha256(VALID.encode()).hexdigest() and row.ok
    [cfile] = _cache_files(tmp_path / "cache")
    assert _cached_rows(cfile)[row.sha]["ok"] is True


# ----------------------------------------------------------------------- reports

def _results(corpus: Path) -> list[FileResult]:
    return scan(corpus, "g", jobs=1, use_cache=False, progress=False)


def test_report_is_replaced_atomically(tmp_path: Path, monkeypatch) -> None:
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    (corpus / "a.src").write_text(BROKEN)
    out = tmp_path / "reports" / "recovery"
    old_results = _results(corpus)
    write_report(out, summarise(old_results, "old", str(corpus), 0.0), old_results)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    assert {"summary.json", "files.csv", "clusters.csv", "report.md", "report.html"} <= set(before)

    (corpus / "b.src").write_text(VALID)
    new_results = _results(corpus)

    def fail(*_a, **_kw):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(report_mod, "write_clusters_csv", fail)   # after summary.json and files.csv
    with pytest.raises(OSError):
        write_report(out, summarise(new_results, "new", str(corpus), 0.0), new_results)
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert sorted(p.name for p in out.parent.iterdir()) == ["recovery"]   # no temporary folder left
    monkeypatch.undo()
    write_report(out, summarise(new_results, "new", str(corpus), 0.0), new_results)
    assert json.loads((out / "summary.json").read_text())["grammar_sha"] == "new"
    assert sorted(p.name for p in out.parent.iterdir()) == ["recovery"]


@pytest.mark.parametrize("exchange", ["atomic exchange", "two renames"])
def test_report_replacement_by_exchange_or_renames(tmp_path: Path, monkeypatch, exchange: str) -> None:
    # Both ways of putting the new report in place give the new report and leave nothing behind.
    if exchange == "two renames":
        monkeypatch.setattr(durable, "exchange", lambda a, b: False)
    (tmp_path / "a.src").write_text(BROKEN)
    out = tmp_path / "reports" / "recovery"
    results = _results(tmp_path)
    for gsha in ("old", "new"):
        write_report(out, summarise(results, gsha, str(tmp_path), 0.0), results)
    assert json.loads((out / "summary.json").read_text())["grammar_sha"] == "new"
    assert sorted(p.name for p in out.parent.iterdir()) == ["recovery"]


def test_report_never_replaces_a_folder_of_other_files(tmp_path: Path) -> None:
    (tmp_path / "a.src").write_text(VALID)
    out = tmp_path / "home"
    out.mkdir()
    (out / "thesis.tex").write_text("precious")
    results = _results(tmp_path)
    with pytest.raises(getattr(report_mod, "ReportError", "no ReportError")):
        write_report(out, summarise(results, "g", str(tmp_path), 0.0), results)
    assert [p.name for p in out.iterdir()] == ["thesis.tex"]


@pytest.mark.parametrize("text", ["=1+1", "+1", "-1", "@SUM(A1)", "\tx", "\rx", "=HYPERLINK(\"http://x\")"])
def test_csv_cell_neutralises_formulas(text: str) -> None:
    assert report_mod.csv_cell(text) == "'" + text


def test_csv_cell_keeps_plain_text_and_numbers() -> None:
    csv_cell = report_mod.csv_cell
    assert [csv_cell(v) for v in ("a.src", "x = -1", "", 12, -3)] == ["a.src", "x = -1", "", 12, -3]


def test_files_and_clusters_csv_hold_no_formula(tmp_path: Path) -> None:
    results = [FileResult("=cmd|' /C calc'!A0.src", 10, "s", "ascii", "ok", True),
               FileResult("@SUM(1).src", 10, "s", "ascii", "binary", False, detail="-NUL bytes")]
    cluster = Cluster(id="c1", signature="+x | y", files=1, occurrences=1, leading_keyword="=IF",
                      expected=["-a"], examples=[{"path": "=a.src", "line": 3, "text": "@x = 1"}])
    write_report(tmp_path, summarise(results, "g", "corpus", 0.0), results)    # files.csv among them
    write_clusters_csv(tmp_path / "clusters.csv", [cluster])
    for name in ("files.csv", "clusters.csv"):
        with (tmp_path / name).open(newline="", encoding="utf-8") as fh:
            cells = [c for row in list(csv.reader(fh))[1:] for c in row]
        assert cells and not [c for c in cells if c[:1] in ("=", "+", "-", "@", "\t", "\r")], (name, cells)
    with (tmp_path / "files.csv").open(newline="", encoding="utf-8") as fh:
        first = next(csv.DictReader(fh))
    assert first["path"] == "'=cmd|' /C calc'!A0.src" and first["bytes"] == "10"


# ----------------------------------------------------------------------- streaming (issue 17)

def test_streamed_report_equals_the_report_of_the_whole_list(tmp_path: Path) -> None:
    # Rows arrive in any order in a parallel scan; the streamed report (rows written as files
    # finish, only counts and clusters kept) must equal the report built from the full list.


    corpus = tmp_path / "corpus"
    (corpus / "sub").mkdir(parents=True)
    for i in range(6):
        (corpus / f"b{i}.src").write_text(BROKEN.replace("x", f"v{i}"))
        (corpus / "sub" / f"c{i}.src").write_text(f"DEF c{i}()\n  x = 1 ? 2\nEND\n")
        (corpus / f"ok{i}.src").write_text(VALID)
    (corpus / "empty.dat").write_text("")
    (corpus / "known.src").write_text("DEF k()\n  FOR\nEND\n")
    os.mkfifo(corpus / "fifo.src")
    results = scan(corpus, "g", jobs=1, use_cache=False, progress=False)
    known = ["known.src"]
    write_report(tmp_path / "list", summarise(results, "g", str(corpus), 1.0, known), results)

    order = list(range(len(results)))
    random.Random(4711).shuffle(order)
    builder = SummaryBuilder(known)
    with ReportStream(tmp_path / "stream") as stream:
        for index in order:
            builder.add(index, results[index])
            stream.add(index, results[index])
        stream.commit(builder.summary("g", str(corpus), 1.0), builder.bad_input)
    for name in ("files.csv", "clusters.csv", "summary.json", "report.md", "report.html"):
        assert (tmp_path / "stream" / name).read_bytes() == (tmp_path / "list" / name).read_bytes(), name
    summary = json.loads((tmp_path / "list" / "summary.json").read_text())
    assert summary["files"] == 21 and summary["statuses"]["not_regular"] == 1
    assert [c["files"] for c in summary["clusters"]] == [6, 6]


def test_scan_without_keeping_rows_reports_each_entry_once(tmp_path: Path) -> None:
    for i in range(5):
        (tmp_path / f"a{i}.src").write_text(VALID if i % 2 else BROKEN)
    (tmp_path / "link.src").symlink_to(tmp_path / "a0.src")
    seen: list[tuple[int, str]] = []
    got = scan(tmp_path, "g", jobs=2, use_cache=False, progress=False, keep=False,
               on_row=lambda index, row: seen.append((index, row.path)))
    assert got == []
    assert sorted(seen) == [(0, "a0.src"), (1, "a1.src"), (2, "a2.src"), (3, "a3.src"), (4, "a4.src"),
                            (5, "link.src")]
