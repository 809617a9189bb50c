"""Imports inside functions only where a benchmark measures what deferring them saves (issue 62).

Every Python file of the project (its packages, tests, tools and examples; not the generated
parser, a virtual environment or build output) is checked. An import inside a function carries,
on its own lines or in the comment lines directly above it (above the imports of its group),
one of:

* the benchmark that measures what it saves on a real command's start-up, with the command and
  the figure: ``# deferred: tools/startup_bench.py, krl run +384 ms at the top (2026-11-26)``.
  tools/startup_bench.py measures, for every import inside a function of the packages, what the
  same import at the top of its module would add to ``krl --help``, ``krl check FILE``, ``krl
  lsp`` (to its answer to ``initialize``), ``krl run FILE`` and ``krl check --reach FILE``; it
  lists those that save at least 3 ms, the figure this test requires;
* a reason that is no start-up cost: an ``optional`` dependency (which may not be installed),
  a tool that loads ``only for a build``, a module importable only ``once sys.path`` holds a
  checkout chosen at run time, or, in a test, the import being the ``subject of this test``.

No other text counts (a number of seconds in a nearby docstring does not). All of them together,
the packages', the tests' and the tools', are at most 60: an import at the top is the rule.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
#: folders that hold no source of the project: generated code, environments, build output
SKIPPED = {"generated", "build", "dist", "node_modules", "__pycache__", "venv", "krl_tools.egg-info"}
PACKAGES = ("app", "krl", "interp", "robot", "recovery", "conformance", "net", "pendant", "audit")
#: the benchmark, the command it measured and what the import at the top would add
MEASURED = re.compile(r"deferred: tools/startup_bench\.py, (krl --help|krl check --reach|krl check|krl lsp|krl run) "
                      r"\+(\d+(?:\.\d+)?) ms")
#: reasons that are no start-up cost
CATEGORY = re.compile(r"\b(optional|only for a build|once sys\.path|subject of this test)\b")
MIN_MS = 3.0
#: where an import statement can stand inside a function: after indentation, or after the colon
#: or semicolon of a one-line body (``def f(): import x``); a file without such a place holds no
#: import inside a function and is not parsed (a cheap first pass: 77 of 803 files are parsed, 2026-11-28)
MAYBE_NESTED = re.compile(r"(^[ \t]+|[:;][ \t]*)(import|from)[ \t]", re.M)
MAX_IMPORTS_INSIDE_FUNCTIONS = 60


def _files() -> list[Path]:
    out = []
    for p in sorted(REPO.rglob("*.py")):
        parts = p.relative_to(REPO).parts[:-1]
        if not any(part in SKIPPED or part.startswith(".") for part in parts):
            out.append(p)
    return out


def nested_imports(tree: ast.Module) -> list[ast.Import | ast.ImportFrom]:
    """Each import statement inside a function (once, however deeply the functions nest)."""
    found: dict[int, ast.Import | ast.ImportFrom] = {}
    for fn in ast.walk(tree):
        if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
            for node in ast.walk(fn):
                if isinstance(node, (ast.Import, ast.ImportFrom)):
                    found[id(node)] = node
    return sorted(found.values(), key=lambda n: (n.lineno, n.col_offset))


def reason(lines: list[str], node: ast.AST, group: set[int]) -> str:
    """The comments that justify `node`: those on its own lines, and the comment lines directly
    above it or above the import statements just before it (`group`: their line numbers)."""
    own = [ln.split("#", 1)[1] for ln in lines[node.lineno - 1:node.end_lineno] if "#" in ln]
    j = node.lineno - 2
    while j >= 0 and (j + 1) in group:
        j -= 1
    above = []
    while j >= 0 and lines[j].strip().startswith("#"):
        above.append(lines[j].strip())
        j -= 1
    return "\n".join(own + above[::-1])


def sites() -> list[tuple[str, str]]:
    """(file:line, its justification) of every import inside a function of the project."""
    out = []
    for path in _files():
        text = path.read_text(encoding="utf-8")
        if not MAYBE_NESTED.search(text):
            continue
        lines = text.splitlines()
        nodes = nested_imports(ast.parse(text))
        spans = {i for n in nodes for i in range(n.lineno, n.end_lineno + 1)}
        for node in nodes:
            group = {i for i in spans if i < node.lineno}
            out.append((f"{path.relative_to(REPO)}:{node.lineno}", reason(lines, node, group)))
    return out


def test_the_rule_reads_the_comments_next_to_an_import_and_nothing_else():
    src = ('def f():\n'
           '    """Costs 0.5 s, 2 s of CPU."""\n'
           '    # deferred: tools/startup_bench.py, krl check +12.5 ms at the top (2026-11-26)\n'
           '    import a\n'
           '    import b\n'
           '    x = 1\n'
           '    import c  # optional: pip install c\n'
           '    import d  # costs 0.3 s\n')
    lines = src.splitlines()
    nodes = nested_imports(ast.parse(src))
    spans = {i for n in nodes for i in range(n.lineno, n.end_lineno + 1)}
    got = {n.names[0].name: reason(lines, n, {i for i in spans if i < n.lineno}) for n in nodes}
    assert MEASURED.search(got["a"]) and MEASURED.search(got["b"])      # b: below a, the same group
    assert CATEGORY.search(got["c"]) and not MEASURED.search(got["c"])
    assert not MEASURED.search(got["d"]) and not CATEGORY.search(got["d"])  # a cost without the benchmark


def test_the_first_pass_keeps_every_file_with_an_import_inside_a_function():
    for src in ("def f():\n    import a\n", "def f(): import a\n", "def f(): x = 1; import a\n",
                "class C:\n\tdef m(self):\n\t\tfrom a import b\n", "async def f():\n  from . import a\n"):
        assert nested_imports(ast.parse(src)) and MAYBE_NESTED.search(src), src
    assert not MAYBE_NESTED.search("import a\nfrom b import c\n\ndef f():\n    return a\n")


def test_each_import_inside_a_function_names_its_benchmark_and_they_are_few():
    files = _files()
    assert len(files) > 500 and REPO / "app" / "__init__.py" in files, len(files)
    missing, unmeasured, outside = [], [], []
    found = sites()
    for site, why in found:
        m = MEASURED.search(why)
        if m is None and not CATEGORY.search(why):
            missing.append(site)
        elif m is not None and float(m.group(2)) < MIN_MS:
            unmeasured.append(f"{site}: {m.group(0)}")
        elif m is not None and not site.startswith(tuple(p + "/" for p in PACKAGES)):
            outside.append(site)           # the benchmark measures the packages' imports only
    assert not missing, f"no benchmark or reason named: {missing}"
    assert not unmeasured, f"saves less than {MIN_MS} ms: move it to the top: {unmeasured}"
    assert not outside, f"the benchmark does not measure these: {outside}"
    assert len(found) <= MAX_IMPORTS_INSIDE_FUNCTIONS, (len(found), [s for s, _ in found])
