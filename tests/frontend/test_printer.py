"""Printer round trip: parse(print(ast)) == ast over generated ASTs and corpus files."""

from __future__ import annotations

import pytest
from hypothesis import given

from krl.ast import nodes as N
from krl.ast.build import build_module
from krl.ast.printer import expr, print_module
from krl.diagnostics import DiagnosticSink
from krl.syntax.parse import parse_text
from krl.source import is_krl_file, read_source
from krl.syntax.parse import parse_source

from .strategies import exprs, modules


def reparse(text: str, path: str = "gen.src") -> N.Module:
    result = parse_text(text, path)
    assert result.ok, (text, [f"{e.line}: {e.message}" for e in result.errors])
    sink = DiagnosticSink()
    module = build_module(result, sink)
    assert not sink.items, [str(d) for d in sink.items]
    return module


@given(modules)
def test_roundtrip_generated_modules(module):
    text = print_module(module)
    assert reparse(text) == module, text


@given(exprs)
def test_roundtrip_generated_expressions(e):
    text = f"DEF t()\n  x = {expr(e)}\nEND\n"
    assert reparse(text).routines[0].body[0].value == e, text


def test_precedence_parentheses():
    e = N.Binary("-", N.Name("a"), N.Binary("-", N.Name("b"), N.Name("c")))
    assert expr(e) == "a - (b - c)"
    e = N.Binary("==", N.Binary("AND", N.Name("a"), N.Name("b")), N.IntLit(1))
    assert expr(e) == "a AND b == 1"
    e = N.Binary("AND", N.Binary("==", N.Name("a"), N.IntLit(1)), N.Name("b"))
    assert expr(e) == "(a == 1) AND b"
    assert expr(N.Unary("-", N.Binary(":", N.Name("a"), N.Name("b")))) == "-(a : b)"


def test_roundtrip_data_list():
    text = ("DEFDAT t PUBLIC\n  DECL GLOBAL INT n = 3\n  E6AXIS xh = {A1 0, A2 -90.5}\n"
            "  DECL FRAME fr[4]\n  fr[2] = {X 1}\n  CHAR nm[8]\n  nm[] = \"ab\"\n"
            "  GLOBAL STRUC S INT a, b, REAL c[3]\n  ENUM E ON, OFF\n  SIGNAL go $OUT[3] TO $OUT[10]\n"
            "  SIGNAL $MODE_TEST FALSE\n  EXT Foo(INT :IN, REAL[] :OUT)\nENDDAT\n")
    m = reparse(text, "t.dat")
    assert reparse(print_module(m), "t.dat") == m


def _corpus_files(corpus, limit=None):
    files = sorted(p for p in corpus.rglob("*") if p.is_file() and is_krl_file(p))
    return files[:: max(1, len(files) // limit)] if limit else files


def _roundtrip_file(path):
    result = parse_source(read_source(path))
    if not result.ok:
        return None
    module = build_module(result)
    again = build_module(parse_text(print_module(module), str(path)))
    return again == module


@pytest.mark.corpus
def test_roundtrip_corpus_sample(corpus):
    """A sample of ~30 corpus files (all of them in the slow variant below)."""
    results = {str(p): _roundtrip_file(p) for p in _corpus_files(corpus, 30)}
    assert all(r is not False for r in results.values()), [p for p, r in results.items() if r is False]


@pytest.mark.corpus
@pytest.mark.slow
def test_roundtrip_corpus_all(corpus):
    results = {str(p): _roundtrip_file(p) for p in _corpus_files(corpus)}
    assert all(r is not False for r in results.values()), [p for p, r in results.items() if r is False]
