"""The per-routine parse cache (krl/lsp/parsing.py) gives exactly the diagnostics and the AST of
`krl check`'s own pipeline (krl/workspace.py Workspace.add_text / add_file), on valid files and
after edits that break one routine, two routines, or a routine's END; and a whole backup analysed
by the server has exactly the diagnostics `krl check` gives it."""

from __future__ import annotations

import os
import random
import shutil
from pathlib import Path

import pytest

from krl.lsp.sample import generate
from krl.lsp.parsing import MIN_CHUNKED_LINES, ParseCache, parse_disk
from krl.lsp.project import Project, norm
from krl.source import read_source
from krl.workspace import Workspace, load_workspace
from krl.project import find_backups
from tests.lsp.conftest import BACKUP


def same(path: str, text: str, cache: ParseCache) -> None:
    """The cache's parse of `text` has the diagnostics of krl check's whole-file parse and, when
    the text parses, its AST, spans included. (A file with a syntax error keeps, by pieces, the
    routines the error does not touch; the whole file's error recovery may drop those after it.)"""
    ws = Workspace(path)
    a = ws.add_text(text, path)
    b = cache.parse(path, text)
    key = lambda d: (d.line, d.column, d.code, d.message)  # noqa: E731
    assert sorted((d.as_json() for d in b.diagnostics), key=lambda j: (j["line"], j["column"], j["code"], j["message"])) \
        == [d.as_json() for d in sorted(ws.sink.items, key=key)]
    assert (b.ok, b.status) == (a.ok, a.status)
    assert b.loaded.template == ws.template[path]
    if a.ok:
        assert b.module == a.module            # AST equality (spans and annotations aside)
        spans = lambda m: [(type(n).__name__, n.span.line, n.span.column, getattr(n, "end_line", 0)) for n in m.walk()]  # noqa: E731
        assert spans(b.module) == spans(a.module)


EDITS = [
    ("  WAIT SEC 0.3", "  WAIT SEC 0.7"),                 # valid edit
    ("  WAIT SEC 0.3", "  WAIT SEC"),                     # E0xx inside one routine
    ("    IF d > 10.0 THEN", "    IF d > 10.0"),          # IF without THEN
    ("    ENDIF", ""),                                    # a block left open
    ("END", ""),                                          # a routine without END
    ("  p = $POS_ACT", "  p = = $POS_ACT"),
]


@pytest.mark.parametrize("old,new", EDITS)
def test_pieces_match_the_whole_file(old, new):
    text = generate(350)
    lines = text.split("\r\n")
    cache = ParseCache()
    same("/w/bench.src", text, cache)
    before = cache.pieces_parsed
    hits = [i for i, ln in enumerate(lines) if ln == old]
    lines[hits[len(hits) // 2]] = new
    same("/w/bench.src", "\r\n".join(lines), cache)
    # a valid edit or an error inside one routine re-parses one piece only
    if new.startswith("  WAIT SEC 0.7"):
        assert cache.pieces_parsed == before + 1


def test_errors_in_two_routines_match_the_whole_file():
    lines = generate(350).split("\r\n")
    hits = [i for i, ln in enumerate(lines) if ln == "  WAIT SEC 0.3"]
    lines[hits[0]] = "  WAIT SEC"
    lines[hits[-1]] = "  x = = 1"
    same("/w/bench.src", "\r\n".join(lines), ParseCache())


def check_backup(backup: Path) -> None:
    files = sorted(f for f in backup.rglob("*")
                   if f.suffix.lower() in (".src", ".dat", ".sub") and f.is_file() and not f.is_symlink())
    an = Project().analyze(norm(files[0]))
    ws = load_workspace([backup], str(backup))
    ws.check(resolve=False)        # as krl check checks (app/check.py): no storage placed for a run
    shown = lambda d: (norm(d.path), d.line, d.column, d.code, d.message)  # noqa: E731
    assert sorted(map(shown, an.ws.diagnostics)) == sorted(map(shown, ws.diagnostics))
    assert len(an.files) == len(ws.files)


def test_a_backup_has_the_diagnostics_of_krl_check(shared_corpus: Path):
    backups = find_backups(shared_corpus)
    check_backup(min(backups, key=lambda b: sum(1 for _ in b.rglob("*"))))      # the smallest one


@pytest.mark.slow
def test_every_backup_has_the_diagnostics_of_krl_check(shared_corpus: Path):
    for b in find_backups(shared_corpus):
        check_backup(b)


MUTATIONS = [lambda s: s.replace("THEN", ""), lambda s: "", lambda s: s + " = = 1", lambda s: "IF x THEN",
             lambda s: s.replace("(", ""), lambda s: "ENDFOR", lambda s: "END", lambda s: "DEF",
             lambda s: s.replace("=", "= 1 +", 1), lambda s: s + "\n", lambda s: "\n" + s,
             lambda s: s.replace("1", "2"), lambda s: "DECL INT x", lambda s: "ENDDAT"]


def edited(path: Path, rng: random.Random, cache: ParseCache, edits: int = 3) -> None:
    """The file, then `edits` random line edits one after the other (lines inserted and
    removed among them), each parsed with one cache and compared with the whole-file parse."""
    src = read_source(path)
    lines = src.text.split("\n")
    same(str(path), src.text, cache)
    for _ in range(edits):
        i = rng.randrange(len(lines))
        lines = lines[:i] + rng.choice(MUTATIONS)(lines[i]).split("\n") + lines[i + 1:]
        same(str(path), "\n".join(lines), cache)


def corpus_files(corpus: Path, suffix: str) -> list[Path]:
    out = []
    for p in sorted(corpus.rglob("*")):
        if p.suffix.lower() == suffix and p.is_file() and not p.is_symlink():
            src = read_source(p)
            if src.status == "ok" and MIN_CHUNKED_LINES <= src.text.count("\n") <= 3000:
                out.append(p)
    return out


def test_data_list_pieces_match_the_whole_file(shared_corpus: Path):
    """A real $config.dat (1200 lines), parsed by pieces, edited: the AST, spans and
    diagnostics of the whole-file parse; a value edit re-parses one piece."""
    path = shared_corpus / "HugoDanielson__ChinaMilling" / "KRC" / "R1" / "System" / "$config.dat"
    src = read_source(path)
    cache = ParseCache()
    same(str(path), src.text, cache)
    lines = src.text.split("\n")
    k = next(i for i, ln in enumerate(lines) if ln.strip().upper().startswith("DECL INT") and "=" in ln)
    before = cache.pieces_parsed
    lines[k] = lines[k].split("=")[0] + "=12345"
    same(str(path), "\n".join(lines), cache)
    assert cache.pieces_parsed == before + 1
    edited(path, random.Random(3), cache, edits=6)


def test_moved_pieces_keep_their_ast():
    """Lines inserted above a routine: the routine's AST is the one parsed before, moved (its
    spans shifted), not parsed again."""
    text = generate(600)
    cache = ParseCache()
    first = cache.parse("/w/bench.src", text)
    last = first.module.routines[-1]
    line = last.span.line
    before = cache.pieces_parsed
    moved = text.replace("  n = 0\r\n", "  n = 0\r\n  n = 1\r\n  n = 2\r\n", 1)
    second = cache.parse("/w/bench.src", moved)
    assert second.module.routines[-1] is last and last.span.line == line + 2
    assert cache.pieces_parsed == before + 1
    same("/w/bench.src", moved, cache)


def test_a_seeded_cache_parses_one_piece_per_edit(shared_corpus: Path):
    path = shared_corpus / "khrzysio__KRC4_test" / "R1" / "System" / "bas.src"
    disk = parse_disk(str(path))
    cache = ParseCache()
    assert cache.seed(disk)
    lines = disk.text.split("\n")
    k = next(i for i, ln in enumerate(lines) if ln.strip().upper().startswith("WAIT SEC"))
    lines[k] = lines[k] + " ;x"
    got = cache.parse(str(path), "\n".join(lines))
    assert cache.pieces_parsed == 1
    assert sum(r is not s for r, s in zip(got.module.routines, disk.module.routines)) == 1
    same(str(path), "\n".join(lines), cache)


@pytest.mark.slow
def test_pieces_match_the_whole_file_on_the_corpus(shared_corpus: Path):
    rng = random.Random(7)
    files = corpus_files(shared_corpus, ".src") + corpus_files(shared_corpus, ".dat")
    for p in files:
        edited(p, rng, ParseCache())
    assert len(files) > 20


def test_links_and_fifos_in_a_backup_are_reported_as_krl_check_does(tmp_path: Path):
    b = tmp_path / "KRC"
    shutil.copytree(BACKUP, b)
    (b / "R1" / "Program" / "link.src").symlink_to(b / "R1" / "Program" / "tools.src")
    os.mkfifo(b / "R1" / "Program" / "pipe.src")
    check_backup(b)           # W002 for both, in the same order, nothing read from them
    an = Project().analyze(norm(b / "R1" / "Program" / "main.src"))
    assert sorted(d.code for d in an.ws.diagnostics) == ["W002", "W002"]
