"""`krl parse FILE...`: syntax-check files and print their syntax errors (registered by krl/cli.py).

Formats (``--format``): ``text`` (compiler style, krl/semantics/render.py: location, code, message,
source line, caret; a closing count line), ``json`` (one object per file: path, ok, encoding,
status, ``diagnostics`` in the shared model and the parser's raw ``errors`` with 1-based columns,
for grammar work) and ``sarif`` (SARIF 2.1.0, krl/semantics/sarif.py). ``--outline`` prints the
symbols (routines, declarations) of each file that parses; ``--tree`` the grammar-rule outline.
Exit 0 when every file parses, 1 otherwise; never a traceback for bad input.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from krl.semantics.diagnostics import Diagnostic


def file_diagnostics(path: Path, keep_tree: bool = True):
    """(ParseResult, decoded text, diagnostics) of one file; never raises for bad content.
    Without keep_tree the default parse engine (krl/syntax/engines) parses it, with no tree."""
    from krl.syntax.engines import parse_source  # noqa: PLC0415
    from krl.syntax.messages import syntax_diagnostics  # noqa: PLC0415
    from krl.syntax.source import read_source  # noqa: PLC0415

    src = read_source(path)
    result = parse_source(src, keep_tree=keep_tree)
    diags = syntax_diagnostics(result, src.text)
    if not result.ok and not diags:
        detail = f" ({src.detail})" if src.detail else ""
        diags = [Diagnostic(str(path), 1, 1, "E001", f"file not parsed: {result.status}{detail}")]
    return result, src.text, diags


def run_parse(files, fmt: str = "text", outline: bool = False, tree: bool = False, echo=print,
              colour: bool = False) -> int:
    """Parse `files` and print the result in `fmt`; returns the exit status (0 or 1)."""
    from krl.semantics.render import Renderer, SourceLines  # noqa: PLC0415
    from krl.terminal import printable, printable_path  # noqa: PLC0415

    sources = SourceLines()
    renderer = Renderer(echo, colour, sources)
    all_diags: list[Diagnostic] = []
    all_ok = True
    for path in files:
        result, text, diags = file_diagnostics(Path(path), keep_tree=(outline or tree) and fmt == "text")
        all_ok &= result.ok
        all_diags += diags
        sources.add(str(path), text)
        if fmt == "json":
            obj = {"path": str(path), "ok": result.ok, "encoding": result.encoding, "status": result.status,
                   "diagnostics": [d.as_json() for d in diags],
                   "errors": [dict(e.as_json(), column=e.column + 1) for e in result.errors]}
            echo(json.dumps(obj))
            continue
        if fmt == "text":
            renderer.emit(diags)
        if result.ok and (outline or tree) and fmt == "text":
            if tree:
                from krl.syntax.outline import outline as tree_outline  # noqa: PLC0415
                entries = tree_outline(result.tree)
            else:
                from krl.ast.build import build_module  # noqa: PLC0415
                from krl.syntax.outline import symbol_outline  # noqa: PLC0415
                entries = symbol_outline(build_module(result))
            for entry in entries:
                echo(f"{printable_path(path)}:{printable(entry)}")
    if fmt == "sarif":
        from krl.semantics.sarif import to_sarif  # noqa: PLC0415
        echo(json.dumps(to_sarif(all_diags), indent=2))
    elif fmt == "text":
        echo(renderer.summary(len(files)))
    return 0 if all_ok else 1


def main_status(files, fmt, as_json, outline, tree, engine: str | None = None) -> int:
    """The `parse` command's body (krl/cli.py keeps only the options)."""
    from krl.syntax.engines import use_engine  # noqa: PLC0415

    use_engine(engine)
    from krl.semantics.render import use_colour  # noqa: PLC0415

    import click  # noqa: PLC0415

    fmt = "json" if as_json else fmt
    return run_parse(files, fmt, outline, tree, click.echo, use_colour(sys.stdout) and fmt == "text")
