"""Imports inside functions only where a measured start-up cost needs them (issues 38, 47).

Every Python file of the project (its packages, tests, tools and examples; not the generated
parser, a virtual environment or build output) is checked: each import inside a function
carries a comment on its line or in the five lines above it that names why it is not at the
top of its module: a measured cost (``python -X importtime``: "costs 0.87 s"), an optional
dependency, a build-only tool, a module importable only once ``sys.path`` holds its folder, or,
in a test, the import being the subject of the test. Every other import is at the top."""

from __future__ import annotations

import ast
import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
#: folders that hold no source of the project: generated code, environments, build output
SKIPPED = {"generated", "build", "dist", "node_modules", "__pycache__", "venv", "krl_tools.egg-info"}
REASON = re.compile(r"costs? \d|\d+(\.\d+)? s\b|optional|only for a build|loads only for a build|"
                    r"only while sys\.path|once sys\.path|subject of this test")


def _files() -> list[Path]:
    out = []
    for p in sorted(REPO.rglob("*.py")):
        parts = p.relative_to(REPO).parts[:-1]
        if not any(part in SKIPPED or part.startswith(".") for part in parts):
            out.append(p)
    return out


def _nested_imports(path: Path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for fn in ast.walk(tree):
        if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
            for node in ast.walk(fn):
                if isinstance(node, (ast.Import, ast.ImportFrom)):
                    yield node


def test_each_import_inside_a_function_names_its_cost():
    missing = []
    files = _files()
    assert len(files) > 500 and REPO / "app" / "__init__.py" in files, len(files)
    for path in files:
        lines = path.read_text(encoding="utf-8").splitlines()
        for node in _nested_imports(path):
            context = "\n".join(lines[max(0, node.lineno - 6):node.end_lineno])
            if not REASON.search(context):
                missing.append(f"{path.relative_to(REPO)}:{node.lineno}")
    assert not missing, missing
