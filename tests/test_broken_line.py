"""Issue 63's broken-line test: one line the grammar does not accept never hides the rest of a file.

Every KRL file of ../shared/krl-corpus and ../shared/krl-history (each distinct content once)
that parses gets one line broken: a statement or declaration line chosen by the file's hash,
broken by a mutation of the negative corpus (tests/negative/generate.py ``MUTATIONS``: those that
turn one line into one line, replayed on the real line: the text they replace, or what they
append at the end), tried in an order the hash also picks, until one makes the file fail at that
line and only there. Then, the intact file against the broken one, each checked on its own:

* ``krl check``: every finding of the intact file is still found, and every new one is the
  broken line's (on it, or naming a name written on it);
* ``krl diff`` (the single-file form): the only changes are the broken line's: it is named as a
  line not understood (added, by its text), and what it held (its statement in its routine, its
  declaration or value) is what changed, at its line or by a name written on it;
* ``krl graph``: the same routines; every edge but those of the broken line (or to a name
  written on it), and no new one.

The expected values are the intact file's own results: nothing here is written by hand but the
rule that a change must be the broken line's. ``make test`` takes every 90th file of the sorted
list (or the next one under 48 KB that has a line to break: corpus and history files, .src,
.dat and .sub); ``make nightly`` takes them all (marked slow).
"""

from __future__ import annotations

import hashlib
import re
from pathlib import Path

import pytest

from krl.ast import nodes as N
from krl.ast.build import build_module
from krl.diff.core import diff_sides
from krl.diff.load import side
from krl.parsecache import through_store
from krl.programmap import build_map
from krl.syntax.engines import parse_file
from krl.workspace import load_workspace
from tests.conftest import SHARED_CORPUS, SHARED_HISTORY
from tests.test_negative_corpus import generator

SAMPLE_EVERY = 90
SAMPLE_MAX_BYTES = 48 * 1024        # make test's sample: smaller files (a 250 KB data list takes 30 s)
_WORD = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]*")
_QUOTED = re.compile(r"'([A-Za-z_$][A-Za-z0-9_$]*)'")
_COMPOUND = (N.If, N.Switch, N.For, N.While, N.Repeat, N.Loop, N.SplineBlock)


def _mutations() -> list[tuple[str, str, str, bool]]:
    """(slug, replaced text, replacement, appended) of every negative-corpus mutation that turns
    one line into one line: the text between the two lines' common prefix and suffix, widened
    to the token next to an insertion (``=`` -> ``:=``, ``=`` -> ``==``); `appended`: it adds
    text at the end of the line (``// reset the counter``)."""
    generate = generator()
    out = []
    for m in generate.MUTATIONS:
        if len(m.edits) != 1:
            continue
        old, new = m.edits[0]
        if old.count("\n") != 1 or new.count("\n") != 1 or not old.endswith("\n") or not new.endswith("\n"):
            continue
        p = 0
        while p < min(len(old), len(new)) and old[p] == new[p]:
            p += 1
        s = 0
        while s < min(len(old), len(new)) - p and old[-1 - s] == new[-1 - s]:
            s += 1
        x, y = old[p:len(old) - s], new[p:len(new) - s]
        if not x and s == 1:
            out.append((m.slug, "", y, True))
            continue
        if not x:
            after, before = re.match(r"\S+", old[p:]), re.search(r"\S+$", old[:p])
            if (old[p - 1:p].isspace() or before is None) and after is not None:
                x, y = after.group(0), y + after.group(0)      # widen to the token after the insertion
            elif before is not None:
                x, y = before.group(0), before.group(0) + y    # ... or before it
            else:
                continue
        if x.strip() and "\n" not in x + y:
            out.append((m.slug, x, y, False))
    return out


MUTATIONS = _mutations()


def _code_end(line: str) -> int:
    """Where the line's code ends: its comment's `;` outside a string, else its end."""
    quoted = False
    for i, ch in enumerate(line):
        if ch == '"':
            quoted = not quoted
        elif ch == ";" and not quoted:
            return i
    return len(line.rstrip("\r\n"))


def _mutate(line: str, mutation) -> str | None:
    """`line` with `mutation` applied to its code, or None where it does not apply."""
    _slug, x, y, appended = mutation
    end = _code_end(line)
    code, rest = line[:end], line[end:]
    if appended:
        return code.rstrip() + y.rstrip("\n") + " " + rest.lstrip() if code.strip() else None
    pat = re.escape(x)
    if x[:1].isalnum():
        pat = r"\b" + pat
    if x[-1:].isalnum():
        pat += r"\b"
    m = re.search(pat, code)
    if m is None or code.count('"', 0, m.start()) % 2:
        return None
    return code[:m.start()] + y + code[m.end():] + rest


def _candidates(module: N.Module) -> list[int]:
    """The lines of a simple statement or a declaration (not a block, not a header, not a
    label), each once, in order."""
    lines: dict[int, int] = {}
    for node in module.walk():
        if isinstance(node, (N.Routine, N.DataList, N.Module, *_COMPOUND)) or not isinstance(node, (N.Stmt, N.Decl)):
            continue
        if isinstance(node, (N.Label, N.Unparsed)):
            continue
        lines[node.span.line] = lines.get(node.span.line, 0) + 1
    return sorted(n for n, k in lines.items() if k == 1)


def _files() -> list[Path]:
    """Every KRL file of the corpus and the history, sorted, each file of the history's pairs
    once (its name and size: the sides of a pair and consecutive pairs share most files; read
    at collection by every worker, so no file is read here)."""
    out, seen = [], set()
    for root in (SHARED_CORPUS, SHARED_HISTORY):
        if not root.is_dir():
            continue
        for p in sorted(root.rglob("*")):
            if p.suffix.lower() in (".src", ".dat", ".sub") and p.is_file() and not p.is_symlink():
                key = (p.name.lower(), p.stat().st_size)
                if root is SHARED_CORPUS or key not in seen:
                    seen.add(key)
                    out.append(p)
    return out


FILES = _files()
#: make test: the files at every SAMPLE_EVERY-th place (the test takes the first from there on
#: that parses and has a line to break: the corpus's and the history's, .src, .dat and .sub)
SAMPLE = list(range(0, len(FILES), SAMPLE_EVERY))


def _text(p: Path) -> str | None:
    data = p.read_bytes()
    for enc in ("utf-8", "cp1252"):
        try:
            return data.decode(enc)
        except UnicodeDecodeError:
            continue
    return None


def broken_version(path: Path) -> tuple[str, str, int, str] | None:
    """(intact text, broken text, broken line, mutation's slug) of a file that parses, or None
    (it does not parse, or no mutation breaks a line of it on that line alone)."""
    text = _text(path)
    if text is None or "\x00" in text:
        return None
    intact = parse_file(text, str(path), keep_tree=True)      # the fast engine where it runs here
    if not intact.ok:
        return None
    lines = _candidates(build_module(intact))
    if not lines:
        return None
    h = int(hashlib.sha256(str(path.name).encode() + text.encode("utf-8", "surrogatepass")).hexdigest(), 16)
    rows = text.split("\n")
    for k in range(min(len(lines), 6)):
        n = lines[(h + k * 7919) % len(lines)]
        for j in range(len(MUTATIONS)):
            mutation = MUTATIONS[(h // 7 + j) % len(MUTATIONS)]
            changed = _mutate(rows[n - 1], mutation)
            if changed is None or changed == rows[n - 1]:
                continue
            broken = "\n".join(rows[:n - 1] + [changed] + rows[n:])
            got = parse_file(broken, str(path))
            if not got.ok and {e.line for e in got.errors} == {n}:
                return text, broken, n, mutation[0]
    return None


def _words(*texts: str) -> set[str]:
    return {w.upper() for t in texts for w in _WORD.findall(t)}


def _key(d, folder: Path) -> tuple:
    """A finding as the two files' findings are matched: its line, its code and its message with
    the file's folder left out (the intact and the broken file lie in two folders, and a message
    may name the file: E102's "first declared at FILE:LINE:COL") and numbers as N."""
    return d.line, d.code, re.sub(r"\d+", "N", d.message.replace(str(folder), "<folder>"))


def _named(message: str) -> set[str]:
    return {w.upper() for w in _QUOTED.findall(message)}


def _edges(pm) -> set[tuple]:
    return {(e.source, e.target, e.kind, e.line, e.column) for e in pm.edges}


def check_broken_line(path: Path, got, tmp_path: Path) -> None:
    """The test of one file (the module docstring); `got`: its :func:`broken_version`."""
    text, broken, n, slug = got
    original, mutated = text.split("\n")[n - 1], broken.split("\n")[n - 1]
    on_line = _words(original, mutated)
    where = f"{path}:{n} ({slug}: {mutated.strip()[:80]!r})"
    name = path.name
    for folder, t in (("a", text), ("b", broken)):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / name).write_text(t, encoding="utf-8")
    # each file on its own, as `krl check FILE` loads it (the store: the diff below parses neither again)
    with through_store():
        a, b = (load_workspace([tmp_path / f / name], str(tmp_path / f)) for f in ("a", "b"))
    a.check()
    b.check()
    name = str(tmp_path / "b" / name)       # the file as the broken side names it

    # check: every finding kept; a new one is the broken line's
    da = {_key(d, tmp_path / "a"): d for d in a.diagnostics}
    db = {_key(d, tmp_path / "b"): d for d in b.diagnostics}
    assert not any(d.is_error for d in b.diagnostics if d.code in ("E001", "E005")), where
    lost = [d for k, d in da.items() if k not in db and d.line != n and not (_named(d.message) & on_line)]
    assert not lost, f"{where}: findings of the intact file lost: {[str(d) for d in lost]}"
    new = [d for k, d in db.items() if k not in da and d.line != n and not (_named(d.message) & on_line)]
    assert not new, f"{where}: new findings not of the broken line: {[str(d) for d in new]}"
    assert any(d.line == n for d in b.diagnostics), where

    # graph: the same routines; the edges but the broken line's
    pa, pb = build_map(a), build_map(b)
    assert set(pa.nodes) == set(pb.nodes), where
    ea, eb = _edges(pa), _edges(pb)
    assert not eb - ea, f"{where}: new edges {sorted(eb - ea)}"
    gone = [e for e in ea - eb if e[3] != n and e[1].split(":")[-1] not in on_line]
    assert not gone, f"{where}: edges lost {sorted(gone)}"
    assert [x.path for x in pb.not_understood] == [name] and pb.not_understood[0].lines[0][0] == n

    # diff: the broken line's changes only
    with side(tmp_path / "a" / path.name, True, 900) as sa, side(tmp_path / "b" / path.name, True, 900) as sb:
        d = diff_sides(sa, sb)
    assert not d.not_compared, where
    assert [(e["line"], e["change"]) for e in d.unparsed] == [(n, "added")], f"{where}: {d.unparsed}"
    for e in d.routines:
        assert e["change"] == "changed" and {ln["line"] for ln in e["before"] + e["after"]} == {n}, f"{where}: {e}"
    for kind in ("points", "frames", "values", "declarations"):
        for e in getattr(d, kind):
            base = re.split(r"[\[.]", e["name"], maxsplit=1)[0].upper()
            assert e["line"] == n or base in on_line, f"{where}: {kind} {e}"
    routine_of_n = {r.name for r in b.files[0].module.routines if r.span.line <= n <= (r.end_line or n)}
    for e in d.motions:
        assert e["routine"] in routine_of_n, f"{where}: motion {e}"
    assert not d.duplicates or {x["line"] for x in d.duplicates} <= {x.span.line for x in a.declared_twice()}, where


@pytest.mark.corpus
@pytest.mark.parametrize("at", SAMPLE, ids=[FILES[i].name for i in SAMPLE])
def test_one_broken_line_hides_nothing_else(at, tmp_path, shared_corpus):
    for path in FILES[at:]:
        if path.stat().st_size > SAMPLE_MAX_BYTES:
            continue
        got = broken_version(path)
        if got is not None:
            check_broken_line(path, got, tmp_path)
            return
    raise AssertionError(f"no file from {FILES[at]} on has a line to break")


@pytest.mark.slow
@pytest.mark.may_skip("the file does not parse, or has no statement or declaration that a mutation "
                      "breaks on its own line (an empty module)")
@pytest.mark.parametrize("path", FILES, ids=[str(p.relative_to(p.parents[2])) for p in FILES])
def test_one_broken_line_hides_nothing_else_in_every_file(path, tmp_path):
    got = broken_version(path)
    if got is None:
        pytest.skip(f"{path.name}: does not parse, or no line breaks alone")
    check_broken_line(path, got, tmp_path)


def test_the_mutations_are_the_negative_corpus_s():
    """The line mutations come from tests/negative (generate.py): the operators and comments of
    C (`:=`, `==` as a statement, `//`), ... each applies to a line of the negative corpus's own
    base and makes it fail there."""
    slugs = {m[0] for m in MUTATIONS}
    assert {"colon_eq_assign", "eq_eq_statement", "slash_comment", "hex_c_style"} <= slugs
    assert len(MUTATIONS) >= 30
    assert _mutate("  nCount = 0\n", next(m for m in MUTATIONS if m[0] == "colon_eq_assign")) == "  nCount := 0\n"
    assert _mutate("  nCount = 0 ; note\n", next(m for m in MUTATIONS if m[0] == "slash_comment")) == \
        "  nCount = 0 // reset the counter ; note\n"


def test_lines_are_counted_as_the_lexer_counts_them(tmp_path):
    """A comment holding a character that Python's str.splitlines takes for a line end (the
    file separator \\x1c, as in a Paletizador backup) shifted every line after it: the line
    not understood was taken for the one before it, and its words and the next line's made names
    declared nowhere "maybe declared" (warnings) instead of errors (the broken-line sweep:
    setcamada_Prdt_M4207A.src lost its E101 findings)."""
    f = tmp_path / "p.src"
    f.write_text("DEF p()\n  ; a separator \x1c here\n  x = 1 ** 2\n  y = 2\nEND\n", encoding="utf-8")
    ws = load_workspace([f], str(tmp_path))
    ws.check()
    assert ws.files[0].module.unparsed == [3]
    assert ws.failed_words == {"X"}
    assert sorted((d.line, d.code) for d in ws.diagnostics) == [(3, "E002"), (4, "E101")]


def test_a_finding_that_names_its_file_is_matched_across_the_two_folders(tmp_path):
    """The intact and the broken file lie in two folders; a finding that names its file (E102's
    "first declared at FILE:LINE:COL") is the same finding on both sides (the sweep called it lost:
    TMatriz.dat, PlaceCaixaPallet1.dat), and a duplicate that goes away is still a loss."""
    intact = "DEFDAT d\nDECL INT a = 1\nDECL INT b = 2\nDECL INT a = 3\nENDDAT\n"
    broken = intact.replace("b = 2", "b = 2 ** 2")
    path = tmp_path / "src" / "d.dat"
    (tmp_path / "kept").mkdir()
    check_broken_line(path, (intact, broken, 3, "star_star_power"), tmp_path / "kept")
    (tmp_path / "lost").mkdir()
    with pytest.raises(AssertionError, match="findings of the intact file lost.*'a' is declared more than once"):
        check_broken_line(path, (intact, broken.replace("INT a = 3", "INT c = 3"), 3, "star_star_power"),
                          tmp_path / "lost")
