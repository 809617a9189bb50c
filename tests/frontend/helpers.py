"""Helpers: build ASTs and check programs from text."""

from __future__ import annotations

from krl.ast.build import build_module
from krl.ast.nodes import Module
from krl.diagnostics import DiagnosticSink
from krl.syntax.parse import parse_text
from krl.workspace import Workspace, check_texts


def ast_of(text: str, path: str = "t.src") -> Module:
    result = parse_text(text, path)
    assert result.ok, [e.message for e in result.errors]
    sink = DiagnosticSink()
    module = build_module(result, sink)
    assert not sink.items, [str(d) for d in sink.items]
    return module


def body_of(text: str):
    """The statements of the first routine of a DEF wrapped around `text`."""
    return ast_of(f"DEF t()\n{text}\nEND\n").routines[0].body


def check(text: str, dat: str | None = None, extra: dict | None = None) -> Workspace:
    files = {"t.src": text}
    if dat is not None:
        files["t.dat"] = dat
    files.update(extra or {})
    return check_texts(files)


def codes(ws: Workspace, errors_only: bool = False) -> list[str]:
    return [d.code for d in ws.diagnostics if d.is_error or not errors_only]
