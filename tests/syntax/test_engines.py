"""The parse engines agree (krl/syntax/engines, docs/architecture.md "Parse engines").

The Java engine runs ports of two pieces of krl/syntax/errors.py (LineErrorStrategy and the
line's tokens); everything else is shared Python code applied to its raw records. These tests
hold the ports to the originals on every file of ../shared/krl-corpus, tests/negative/ and
grammar/constructs/: the same status and the same error records (line, column, message,
offending token and its type, expected tokens, rule stack, line shape, line text, cascade
mark), hence the same clusters, and the same parse trees node by node (the Java engine's
rebuilt by krl/syntax/engines/tree.py). The Python side runs once per file. ``make test``
compares one file in twelve (:data:`SHARDS`), ``make nightly`` every file.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from antlr4.tree.Tree import ErrorNode, TerminalNode
from hypothesis import given, settings
from hypothesis import strategies as st
from antlr4 import CommonTokenStream, InputStream, ParserRuleContext

from krl.ast import nodes as N
from krl.ast.build import build_module
from krl.syntax import blocks
from krl.syntax.engines import EngineUnavailable, parse_file, parse_sources, resolve
from krl.syntax.engines import java as java_engine
from krl.syntax.engines.tree import RebuiltToken
from krl.syntax.parse import ParserBundle, default_bundle, prepare_text
from krl.source import SourceText, read_source
from recovery.scan import discover
from tests.budget import examples
from recovery.grammar_versions import _git, parser_dir_for

REPO = Path(__file__).resolve().parents[2]
#: the files are split into SHARDS by position (every SHARDS-th file, so each shard holds every
#: kind: corpus, negative examples, constructs); make test compares the engines on the first
#: shard (91 of the 1081 files: 50 of the corpus, 23 negative examples, 18 constructs, failing
#: ones among them; one in six, 181 files, until 2026-11-29), make nightly on all (the Python
#: engine parses at about 270 KB/s: the whole sweep is 75 s of CPU)
SHARDS = 12
SHARD_PARAMS = [pytest.param(k, marks=() if k == 0 else pytest.mark.slow) for k in range(SHARDS)]

needs_java = pytest.mark.may_skip("no JDK (java and javac) on this machine: the fast engine cannot run")


def _java_or_skip() -> None:
    """Skip only where there is no JDK; any other reason the engine cannot run (the ANTLR jar
    missing, KRL_NO_JAVA left set) is a failure, so the equivalence check is never dropped."""
    reason = java_engine.unavailable_reason()
    if reason is None:
        return
    if shutil.which("java") is None or shutil.which("javac") is None:
        pytest.skip(f"java engine unavailable: {reason}")
    pytest.fail(f"a JDK is here but the java engine cannot run: {reason}")


def _record(result) -> tuple:
    return (result.ok, result.status, [
        (i.line, i.column, i.kind, i.message, i.offending, i.offending_type, i.expected, i.rule_stack,
         i.line_shape, i.line_text, i.cascade) for i in result.errors])


def _token(t) -> tuple | None:
    return None if t is None else (t.tokenIndex, t.type, t.channel, t.start, t.stop, t.line, t.column, t.text)


def tree_shape(tree) -> list[tuple]:
    """Every node of a parse tree in preorder, with what a consumer can read of it: context
    class, start and stop tokens (all their fields), invoking state, whether the rule recorded
    an exception, children (count or None), label fields and the parent's class; terminals and
    error nodes with their token."""

    if tree is None:
        return []
    out, stack = [], [tree]
    while stack:
        n = stack.pop()
        parent = type(n.parentCtx).__name__
        if isinstance(n, TerminalNode):
            out.append(("error" if isinstance(n, ErrorNode) else "terminal", _token(n.symbol), parent))
            continue
        labels = sorted((k, _token(v) if not isinstance(v, (list, ParserRuleContext)) else
                         (n.children.index(v) if isinstance(v, ParserRuleContext) else
                          [_token(x) for x in v])) for k, v in getattr(n, "__dict__", {}).items())
        out.append((type(n).__name__, _token(n.start), _token(n.stop), n.invokingState, n.exception is not None,
                    None if n.children is None else len(n.children), labels, parent,
                    type(n.parser).__name__ if n.parser is not None else None))
        stack.extend(reversed(n.children or ()))
    return out


def _files(shared_corpus: Path) -> list[Path]:
    return (discover(shared_corpus) + discover(REPO / "tests" / "negative")
            + discover(REPO / "grammar" / "constructs"))


@needs_java
@pytest.mark.parametrize("shard", SHARD_PARAMS)
def test_engines_agree_on_every_file(shared_corpus, shard):
    _java_or_skip()
    paths = [p for i, p in enumerate(_files(shared_corpus)) if i % SHARDS == shard]
    sources = [read_source(p) for p in paths]
    py = list(parse_sources(sources, "python", keep_tree=True))
    jv = list(parse_sources(sources, "java", keep_tree=True))
    assert len(py) == len(jv) == len(paths)
    differ = [str(p) for p, a, b in zip(paths, py, jv) if _record(a) != _record(b)]
    assert differ == []
    # The parse trees too (krl/syntax/engines/tree.py rebuilds the Java engine's), node by node.
    differ = [str(p) for p, a, b in zip(paths, py, jv) if tree_shape(a.tree) != tree_shape(b.tree)]
    assert differ == []
    # Not vacuous: the Java worker really parsed files of this shard, failing ones among them,
    # and its trees were rebuilt (their tokens are RebuiltTokens).
    worker_parsed = [b for s, b in zip(sources, jv)
                     if s.status == "ok" and b.stage in ("sll", "ll") and isinstance(b.tree.start, RebuiltToken)]
    assert any(r.ok for r in worker_parsed)
    assert any(not r.ok and r.stage == "ll" for r in worker_parsed)
    assert any(any(isinstance(x, ErrorNode) for x in _nodes(r.tree)) for r in worker_parsed)
    assert all(not isinstance(r.tree.start, RebuiltToken) for r in py if r.tree is not None)


def _nodes(tree):
    stack = [tree]
    while stack:
        n = stack.pop()
        yield n
        stack.extend(getattr(n, "children", None) or ())


DEEP = "DEF deep()\n" + "IF a THEN\n" * 101 + "ENDIF\n" * 101 + "END\n"
LONG = "DEF long()\nx = " + " + ".join(["1"] * 600) + "\nEND\n"
CHECKED = "DEF t()\nTRIGGER WHEN DISTANCE=2 DELAY=0 DO x=1\nLIN_REL {x 1} #WORLD\nEND\n"


@needs_java
@pytest.mark.parametrize("text,status,code", [(DEEP, "too_deep", "E018"), (LONG, "too_long", "E019"),
                                              (CHECKED, "syntax_error", "")])
def test_java_engine_hands_python_only_checks_to_python(text, status, code):
    """Files past a limit of krl/limits.py, or failing a post-parse token check, give the same
    result through the java engine: it routes them to the Python engine."""
    _java_or_skip()
    py = parse_file(text, "t.src", engine="python")
    jv = parse_file(text, "t.src", engine="java")
    assert py.status == status
    if code:
        assert py.errors[0].offending_type == code
    else:  # DISTANCE=2 (5.18) and #WORLD (6.1) are rejected by the checks
        assert [(e.line, e.offending) for e in py.errors] == [(2, "2"), (3, "#WORLD")]
    assert _record(jv) == _record(py)


# ----------------------------------------------------------------------- the limit pre-filter

_PIECES = ["IF a THEN", "ENDIF", "FOR i=1 TO 2", "ENDFOR", "WHILE b", "ENDWHILE", "REPEAT", "UNTIL c",
           "LOOP", "ENDLOOP", "SWITCH s", "CASE 1", "ENDSWITCH", "SPLINE", "PTP_SPLINE", "ENDSPLINE",
           "DEF r()", "END", "DEFFCT INT f()", "ENDFCT", "DEFDAT d", "ENDDAT", "GLOBAL DEF g()", "END IF",
           "GLOBAL IF", "ELSE", "x = (a + (b", "NOT NOT x", "-(-(-y))", "a OR b AND c", "{x 1, y 2}",
           "; IF comment", "\"IF\"", "!IF x THEN", "\x0bIF y THEN", "&IF", "if z then", "EndIf", "x=[1,[2"]


@st.composite
def _krl_lines(draw):
    parts = draw(st.lists(st.sampled_from(_PIECES), min_size=1, max_size=40))
    ends = draw(st.lists(st.sampled_from(["\n", "\r\n", "\r"]), min_size=len(parts), max_size=len(parts)))
    return "".join(p + e for p, e in zip(parts, ends))


@settings(max_examples=examples(200), deadline=None)
@given(_krl_lines(), st.integers(1, 6), st.integers(2, 8))
def test_may_pass_limit_never_misses_a_limit(text, nesting, terms):
    """Whenever the token pass finds a file past a limit, the text pre-filter said it might be
    (with small limits, so that generated files reach them)."""

    saved = blocks.MAX_NESTING, blocks.MAX_EXPRESSION_TERMS
    blocks.MAX_NESTING, blocks.MAX_EXPRESSION_TERMS = nesting, terms
    try:
        bundle = default_bundle()
        lexer = bundle.lexer_cls(InputStream(prepare_text(text)))
        lexer.removeErrorListeners()
        stream = CommonTokenStream(lexer)
        stream.fill()
        found = blocks.first_past_limit(stream.tokens, bundle)
        if found is not None:
            assert blocks.may_pass_limit(prepare_text(text)), (found.code, found.line)
    finally:
        blocks.MAX_NESTING, blocks.MAX_EXPRESSION_TERMS = saved


def test_may_pass_limit_is_not_trivially_true():
    assert not blocks.may_pass_limit("DEF a()\n" + "IF x THEN\nENDIF\n" * 300 + "END\n")
    assert blocks.may_pass_limit(DEEP) and blocks.may_pass_limit(LONG)


# ----------------------------------------------------------------------- fallback and robustness

def test_without_java_auto_is_python_and_java_says_why(monkeypatch):
    monkeypatch.setenv("KRL_NO_JAVA", "1")
    monkeypatch.setattr(java_engine, "_REASON", [])
    assert resolve("auto") == "python"
    with pytest.raises(EngineUnavailable, match="unavailable: disabled by KRL_NO_JAVA"):
        resolve("java")
    res = parse_file("DEF a()\nEND\n", "a.src")   # auto: the Python engine, with a tree-free result
    assert res.ok and res.status == "ok"


def test_krl_parse_engine_java_without_java_is_a_message_not_a_traceback(tmp_path):
    f = tmp_path / "a.src"
    f.write_text("DEF a()\nEND\n")
    env = dict(os.environ, KRL_NO_JAVA="1")
    run = subprocess.run([sys.executable, "-m", "app", "parse", "--engine", "java", str(f)],
                         capture_output=True, text=True, env=env, cwd=REPO, check=False)
    assert run.returncode == 2
    assert "java parse engine is unavailable" in run.stderr
    assert "Traceback" not in run.stderr + run.stdout


@needs_java
def test_interrupted_batch_restarts_the_worker():
    """A batch abandoned mid-way (a parse timeout, a closed generator) kills the worker, and
    the next parse starts a fresh one: no late answer is read as another file's."""
    _java_or_skip()
    worker = java_engine.worker_for((REPO / "grammar" / "KRL.g4").read_text(encoding="utf-8"))
    texts = ["DEF a()\nEND\n", "DEF b()\nx = = 1\nEND\n"] * 10
    gen = worker.parse_raw(texts)
    next(gen)
    gen.close()
    assert worker.proc is None
    answers = dict(worker.parse_raw(["DEF c()\nEND\n", "DEF d()\ny = = 2\nEND\n"]))
    assert answers[0]["stage"] == "sll" and answers[1]["stage"] == "ll"
    assert answers[1]["syn"][0]["line"] == 2


def test_parse_file_takes_bytes_text_and_source():
    data = "DEF a()\r\n  x = 1\r\nEND\r\n".encode("cp1252")
    for value in (data, data.decode("cp1252"), SourceText("a.src", data.decode(), "ascii", len(data))):
        res = parse_file(value, "a.src", engine="python")
        assert res.ok and res.status == "ok"
    assert parse_file(b"", "e.src", engine="python").status == "empty"
    assert parse_file(b"DEF\x00", "b.src", engine="python").status == "binary"


def _names_a_predicate(source: SourceText) -> bool:
    """The text names what the old grammar's predicates check (DISTANCE, #WORLD)."""
    upper = source.text.upper()
    return "DISTANCE" in upper or "#WORLD" in upper


@needs_java
@pytest.mark.parametrize("every", [pytest.param(SHARDS, id="sample"), pytest.param(1, id="all", marks=pytest.mark.slow)])
def test_engines_agree_on_a_grammar_version_with_python_predicates(every):
    """Older grammar versions state two checks as Python predicates; the Java build removes
    them (java_grammar) and may_fail routes every file where one could fail to Python. The
    engines agree on tests/negative/ with such a version, and the files that exercise the
    predicates (DISTANCE, #WORLD) are among those parsed. ``make test`` parses those (23 of the
    274 today) and every :data:`SHARDS`-th file by position, 44 files (the Python engine's parse
    of all 274 is 3.7 s of the test's CPU); ``make nightly`` every file."""
    _java_or_skip()

    commits = _git("log", "--format=%H", "--", "grammar/KRL.g4").split()
    text = next((t for t in (_git("show", f"{c}:grammar/KRL.g4") for c in commits) if "}?<fail=" in t), None)
    assert text is not None, "no grammar version with predicates in the history"
    assert "}?" not in java_engine.java_grammar(text)
    bundle = ParserBundle.from_directory(parser_dir_for(text), tag="predicates")
    negative = [read_source(p) for p in discover(REPO / "tests" / "negative")]
    sources = [s for i, s in enumerate(negative) if _names_a_predicate(s) or i % every == 0]
    assert sum(map(_names_a_predicate, sources)) >= 20
    sources.append(SourceText("pred.src", CHECKED, "ascii", len(CHECKED)))
    py = list(parse_sources(sources, "python", bundle))
    jv = list(parse_sources(sources, "java", bundle))
    assert [_record(r) for r in jv] == [_record(r) for r in py]
    assert not py[-1].ok and [e.line for e in py[-1].errors if not e.cascade] == [2, 3]


@pytest.mark.parametrize("engine", ["python", pytest.param("java", marks=needs_java)])
def test_a_token_error_at_a_line_end_keeps_the_line_end(engine):
    """A character literal cut by the line end (``'B0120'``: ``'B012`` then ``0'``) is a lexer
    error on its own line: ANTLR's lexer skips one character past those it read, which would be
    the line end, and the next line would join the broken one (issue 63's broken-line sweep:
    ProfileHeight.dat, line 11 named not understood with line 10)."""
    if engine == "java":
        _java_or_skip()
    text = ("DEFDAT d\n"
            "DECL CONST REAL a = 51.'B0120'\n"
            "DECL CONST REAL b = 18.0\n"
            "DECL CONST REAL c = 7.'HFG'\r\n"
            "DECL CONST REAL e = 2.0\n"
            "ENDDAT\n")
    res = parse_file(text, "d.dat", engine=engine, keep_tree=True)
    assert not res.ok
    assert {e.line for e in res.errors} == {2, 4}
    items = build_module(res).data.items
    assert [(type(i).__name__, i.span.line) for i in items] == [
        ("Unparsed", 2), ("VarDecl", 3), ("Unparsed", 4), ("VarDecl", 5)]
    assert [i.names[0].name.upper() for i in items if isinstance(i, N.VarDecl)] == ["B", "E"]
