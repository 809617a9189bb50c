"""Imports inside functions only where a measured start-up cost needs them (issue 38).

In the packages listed here every import inside a function carries a comment on its line or
just above it that names why it is there: a measured cost (``python -X importtime``: "costs
0.87 s"), an optional dependency, a build-only tool, or a module importable only once
``sys.path`` holds its folder. The other packages of the project (krl/cli, krl/lsp, interp's
run-time, recovery, robot, pendant, krl/store.py and the tests of those) are not converted yet."""

from __future__ import annotations

import ast
import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
CHECKED = ["krl", "interp", "robot", "tests/robot", "recovery", "pendant", "tests/pendant", "audit", "tests/audit", "tests/interp", "tests/vm", "tests/debug", "robot", "tests/robot", "recovery", "pendant", "tests/pendant", "audit", "tests/audit", "robot", "tests/robot", "recovery", "pendant", "tests/pendant", "robot", "tests/robot", "robot/cellrules.py", "robot/datalist.py",
           "conformance", "net", "examples", "tools",
           "tests/frontend", "tests/recovery", "tests/conformance", "tests/syntax", "tests/programmap",
           "tests/report", "tests/fmt", "tests/net", "tests/diff", "tests/editors", "tests/conftest.py",
           "tests/test_json_schemas.py", "tests/test_layers.py", "tests/test_negative_corpus.py"]
REASON = re.compile(r"costs? \d|\d+(\.\d+)? s\b|optional|only for a build|loads only for a build|"
                    r"only while sys\.path|once sys\.path")


def _files():
    for entry in CHECKED:
        p = REPO / entry
        yield from (sorted(p.rglob("*.py")) if p.is_dir() else [p])


def _nested_imports(path: Path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for fn in ast.walk(tree):
        if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
            for node in ast.walk(fn):
                if isinstance(node, (ast.Import, ast.ImportFrom)):
                    yield node


def test_each_import_inside_a_function_names_its_cost():
    missing = []
    for path in _files():
        if "generated" in path.parts:
            continue
        lines = path.read_text(encoding="utf-8").splitlines()
        for node in _nested_imports(path):
            context = "\n".join(lines[max(0, node.lineno - 6):node.end_lineno])
            if not REASON.search(context):
                missing.append(f"{path.relative_to(REPO)}:{node.lineno}")
    assert not missing, missing
