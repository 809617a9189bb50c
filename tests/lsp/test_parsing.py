"""The per-routine parse cache (krl/lsp/parsing.py) gives exactly the diagnostics and the AST of
`krl check`'s own pipeline (krl/workspace.py Workspace.add_text / add_file), on valid files and
after edits that break one routine, two routines, or a routine's END; and a whole backup analysed
by the server has exactly the diagnostics `krl check` gives it."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from krl.lsp.bench import generate
from krl.lsp.parsing import MIN_CHUNKED_LINES, ParseCache
from krl.lsp.project import Project, norm
from krl.source import read_source
from krl.workspace import Workspace, load_workspace
from krl.project import find_backups


def same(path: str, text: str, cache: ParseCache) -> None:
    ws = Workspace(path)
    a = ws.add_text(text, path)
    b = cache.parse(path, text)
    key = lambda d: (d.line, d.column, d.code, d.message)  # noqa: E731
    assert sorted((d.as_json() for d in b.diagnostics), key=lambda j: (j["line"], j["column"], j["code"], j["message"])) \
        == [d.as_json() for d in sorted(ws.sink.items, key=key)]
    assert (b.ok, b.status) == (a.ok, a.status)
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
    ws.check()
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


@pytest.mark.slow
def test_pieces_match_the_whole_file_on_the_corpus(shared_corpus: Path):
    rng = random.Random(7)
    mutations = [lambda s: s.replace("THEN", ""), lambda s: "", lambda s: s + " = = 1", lambda s: "IF x THEN",
                 lambda s: s.replace("(", ""), lambda s: "ENDFOR", lambda s: "END", lambda s: "DEF"]
    checked = 0
    for p in sorted(shared_corpus.rglob("*.src")):
        src = read_source(p)
        lines = src.text.split("\n")
        if src.status != "ok" or not MIN_CHUNKED_LINES <= len(lines) <= 3000:
            continue
        cache = ParseCache()
        for _ in range(2):
            ls = list(lines)
            i = rng.randrange(len(ls))
            ls[i] = rng.choice(mutations)(ls[i])
            same(str(p), "\n".join(ls), cache)
        checked += 1
    assert checked > 10


def test_links_and_fifos_in_a_backup_are_reported_as_krl_check_does(tmp_path: Path):
    import os
    import shutil

    from tests.lsp.conftest import BACKUP

    b = tmp_path / "KRC"
    shutil.copytree(BACKUP, b)
    (b / "R1" / "Program" / "link.src").symlink_to(b / "R1" / "Program" / "tools.src")
    os.mkfifo(b / "R1" / "Program" / "pipe.src")
    check_backup(b)           # W002 for both, in the same order, nothing read from them
    an = Project().analyze(norm(b / "R1" / "Program" / "main.src"))
    assert sorted(d.code for d in an.ws.diagnostics) == ["W002", "W002"]
