"""The language server checks the longest legal expression like `krl check` (krl/limits.py
MAX_EXPRESSION_TERMS): no E901 "routine nested too deeply to check", the value typed INT."""

from __future__ import annotations

from krl.ast import nodes as N
from krl.limits import MAX_EXPRESSION_TERMS, MAX_NESTING
from krl.lsp.project import Project
from krl.semantics import types as T


def test_longest_legal_expression_in_the_server(tmp_path):
    inner = " + ".join(["1"] * (MAX_EXPRESSION_TERMS - MAX_NESTING))
    expr = "1 - (" * MAX_NESTING + inner + ")" * MAX_NESTING       # 500 terms, 100 brackets
    path = str(tmp_path / "longest.src")
    text = f"DEF longest()\n  DECL INT x\n  x = {expr}\nEND\n"
    project = Project()
    project.open(path, text)
    an = project.analyze(path)
    assert [str(d) for d in an.ws.diagnostics] == []
    [assign] = an.ws.files[0].module.routines[0].body
    assert N.type_of(assign.value) == T.INT
