"""Real edits replayed in the editor: the changes between ``old/`` and ``new/`` of the history
pairs (../shared/krl-history, read in place: the edits go to the editor's buffers, nothing is
written), applied hunk by hunk to an open buffer as an editor sends them, each followed by the
language server's analysis (krl/lsp/project.py, which hands each new parse to the workspace's
re-check, krl/workspace.py ``Workspace.replace``). After every edit the diagnostics and the
never-read hints must be exactly those of a full check of the same texts made afresh: every
file parsed again, nothing shared with the editor's state; and, when the buffers parse, those
of ``krl check``'s own pipeline (each file parsed whole, krl/workspace.py)."""

from __future__ import annotations

import difflib
import shutil
from pathlib import Path

import pytest

from krl.lsp.analysis import build_analysis
from krl.lsp.parsing import ParseCache, Parsed
from krl.lsp.paths import norm
from krl.lsp.project import Project
from krl.lsp.unused import never_read
from krl.source import is_krl_file, read_source
from krl.limits import PARSE_TIMEOUT_S
from krl.workspace import Workspace, load_batch, load_file, load_text
from tests.conftest import SHARED
from tests.lsp.conftest import BACKUP

HISTORY = SHARED / "krl-history"


@pytest.fixture(scope="module")
def history() -> Path:
    if not (HISTORY / "MANIFEST.csv").exists():
        pytest.skip("../shared/krl-history is not present")
    return HISTORY


def rows(diags) -> list[tuple]:
    return [(d.path, d.line, d.column, d.code, d.message, d.severity, d.end_line, d.end_column, d.help,
             tuple((n.path, n.line, n.column, n.message) for n in d.notes)) for d in diags]


def hints(an, path) -> list[tuple]:
    return [(u.place.line, u.place.column, u.name, u.written) for u in never_read(an, path)]


def steps(old: str, new: str, most: int) -> list[str]:
    """The texts from `old` to `new`, one hunk of the line diff at a time (the last hunk first,
    so that each edit leaves the places of the others), at most `most` steps (hunks grouped)."""
    a, b = old.splitlines(keepends=True), new.splitlines(keepends=True)
    hunks = [op for op in difflib.SequenceMatcher(None, a, b, autojunk=False).get_opcodes() if op[0] != "equal"]
    size = max(1, -(-len(hunks) // most))
    groups = [hunks[i:i + size] for i in range(0, len(hunks), size)]
    out, lines = [], list(a)
    for group in reversed(groups):
        for _tag, i1, i2, j1, j2 in reversed(group):
            lines[i1:i2] = b[j1:j2]
        out.append("".join(lines))
    assert out[-1] == new
    return out


class Oracle:
    """Full checks made afresh: the files on disk loaded once by krl check's loader (objects of
    their own), each buffer's text parsed again by each pipeline when it changed (objects of
    their own, never the editor's: a buffer left as it was while another file is edited is the
    same text, and its parse by the same code the same; re-parsing the earlier files' buffers at
    each edit of the next: the module 25.6 -> 22.7 s of CPU, medians of three, a cgroup,
    2026-11-29)."""

    def __init__(self) -> None:
        self.disk: dict[str, object] = {}
        self.pieces: dict[str, tuple[str, Parsed]] = {}      # path -> (text, the editor's parse model of it)
        self.whole: dict[str, tuple[str, object]] = {}       # path -> (text, krl check's parse of it)

    def parsed(self, path: str, text: str) -> Parsed:
        """The editor's parse model of the buffer `text` of `path`, made afresh (a ParseCache
        of its own) unless this is the text it was made of last."""
        if path not in self.pieces or self.pieces[path][0] != text:
            self.pieces[path] = (text, ParseCache().parse(path, text))
        return self.pieces[path][1]

    def text(self, path: str, text: str):
        """krl check's parse of the buffer `text` of `path` (load_text: the file parsed whole),
        made afresh unless this is the text it was made of last."""
        if path not in self.whole or self.whole[path][0] != text:
            self.whole[path] = (text, load_text(text, path))
        return self.whole[path][1]

    def loaded(self, path: str):
        if path not in self.disk:
            self.disk[path] = load_file(path)
        return self.disk[path]

    def preload(self, paths: list[str]) -> None:
        todo = [p for p in paths if p not in self.disk]
        for path, o in zip(todo, load_batch(todo, PARSE_TIMEOUT_S) if len(todo) > 8 else ()):
            if o.status == "done":
                self.disk[path] = o.value

    def editor(self, an, docs: dict[str, str]):
        """The editor's own parse model (pieces for buffers), checked whole from fresh parses."""
        self.preload([p for p in an.files if p not in docs])
        parsed = []
        for path, fi in an.files.items():
            if path in docs:
                parsed.append(self.parsed(path, docs[path]))
            else:
                parsed.append(Parsed(path, fi.parsed.text, self.loaded(path)))
        return build_analysis(an.root, parsed)

    def krl_check(self, an, docs: dict[str, str]) -> Workspace:
        """krl check's pipeline: every file parsed whole (the buffers as texts), checked as krl
        check checks (app/check.py: the checker alone, no storage placed for a run; placing it
        was a third of these checks' CPU and adds no diagnostic)."""
        ws = Workspace(an.root)
        for path in an.files:
            ws.add_loaded(self.text(path, docs[path]) if path in docs else self.loaded(path), notify=False)
        ws.check(resolve=False)
        return ws


def agree(p: Project, oracle: Oracle, path: str, text: str) -> str:
    p.change(path, text)
    an = p.analyze(path)
    fresh = oracle.editor(an, p.docs)
    assert rows(an.ws.diagnostics) == rows(fresh.ws.diagnostics), path
    for doc in p.docs:
        if doc in an.files:
            assert hints(an, doc) == hints(fresh, doc), doc
    if all(an.files[d].parsed.ok for d in p.docs if d in an.files):
        assert rows(an.ws.diagnostics) == rows(oracle.krl_check(an, p.docs).diagnostics), path
    return an.how


def changed_files(pair: Path) -> list[Path]:
    old, new = pair / "old", pair / "new"
    out = []
    for f in sorted(new.rglob("*")):
        if f.is_file() and not f.is_symlink() and is_krl_file(f):
            o = old / f.relative_to(new)
            if o.is_file() and o.read_bytes() != f.read_bytes():
                out.append(f.relative_to(new))
    return out


def replay(pair: Path, most_files: int, most_steps: int) -> dict[str, int]:
    """Open each changed file of the pair's old side and edit it into its new text; returns how
    often each kind of re-check ran."""
    old, new = pair / "old", pair / "new"
    p = Project()
    p.folders = [Path(norm(old))]
    p.watched = True
    oracle = Oracle()
    kinds: dict[str, int] = {}
    for rel in changed_files(pair)[:most_files]:
        path = norm(old / rel)
        before, after = read_source(old / rel), read_source(new / rel)
        if before.status != "ok" or after.status != "ok":
            continue
        p.open(path, before.text)
        p.analyze(path)
        for text in steps(before.text, after.text, most_steps):
            how = agree(p, oracle, path, text)
            kinds[how] = kinds.get(how, 0) + 1
    return kinds


SMALL = ["AutodeskRoboticsLab__Mimic/01-9e0f9529", "BmadeRobots__KukaVarProxy/02-b04e507a",
         "CentroEPiaggio__kuka-lwr/03-215d3528", "OsmanMarangoz__2526ws_BH_KRL2Python/01-55a61b97",
         "kroshu__kuka-external-control-sdk/04-3f8f534c", "paulovictor237__KUKA-Paletizador/02-792705c8",
         "rawpython__kukaKRLmagic/03-e616379d", "Yassate__KRL_Parser/02-a218a745",
         "wingljj__Kuka-RSI-real-time-control/03-cb18f141"]


@pytest.mark.parametrize("pair", SMALL)
def test_history_edits_agree_with_a_full_check(history: Path, pair: str):
    kinds = replay(history / pair, most_files=3, most_steps=6)
    assert sum(kinds.values()) > 0


def test_history_edits_in_a_backup_re_check_routines_alone(history: Path):
    """The ChinaMilling backup (165 files): its real edits, hunk by hunk; most edits re-check
    only the routines or values they change."""
    kinds = replay(history / "HugoDanielson__ChinaMilling" / "03-05d627c7", most_files=3, most_steps=4)
    assert kinds.get("routines", 0) + kinds.get("values", 0) > 0, kinds


@pytest.mark.slow
def test_every_history_edit_agrees_with_a_full_check(history: Path):
    pairs = sorted(d for d in history.glob("*/*") if (d / "old").is_dir())
    assert len(pairs) >= 40
    for pair in pairs:
        replay(pair, most_files=1000, most_steps=1000)


def test_edits_that_change_what_an_unparsable_file_may_declare_agree_with_a_full_check(tmp_path: Path):
    """main.src assigns a name nobody declares (E101); tools.src is edited from parsing to not
    parsing (its broken line without, then with that name: the name may be declared there, so a
    warning, W101) and back. Each edit re-checks tools.src's routines alone, and the
    unresolved-name report must follow what the unparsable file may declare."""
    shutil.copytree(BACKUP, tmp_path / "KRC")
    main = norm(tmp_path / "KRC" / "R1" / "Program" / "main.src")
    tools = norm(tmp_path / "KRC" / "R1" / "Program" / "tools.src")
    text = Path(tools).read_text()
    assert "  shared = n\n" in text
    broken = lambda word: text.replace("  shared = n\n", f"  shared = n\n  {word} = = 2\n")  # noqa: E731
    p = Project()
    p.folders = [Path(norm(tmp_path / "KRC"))]
    p.open(main, Path(main).read_text().replace("  $OUT[2] = TRUE\n", "  $OUT[2] = TRUE\n  mystery_flag = 1\n"))
    p.open(tools, text)
    oracle = Oracle()
    codes, hows = [], []
    for t in (text, broken("other_word"), broken("mystery_flag"), broken("other_word"), text):
        hows.append(agree(p, oracle, tools, t))
        codes.append(sorted(d.code for d in p.analyses[p._root_of[tools]].ws.diagnostics
                            if d.path == main))
    assert codes == [["E101"], ["E101"], ["W101"], ["E101"], ["E101"]]
    assert hows[1:] == ["routines"] * 4                # the re-check of one routine, not a full check
