"""`krl fmt [--check] [--diff] [--keyword-case upper|lower|keep] [--indent N|tab] PATHS...`
(registered by krl/cli.py).

PATHS are KRL files (.src, .dat, .sub) or folders (searched for KRL files, symbolic links not
followed); ``-`` alone formats standard input to standard output (for editors and hooks). By default each file that would change is rewritten in place, atomically (a
temporary file in the same folder, then a rename), in the encoding it was read in
(krl/syntax/source.py: UTF-8 with or without BOM, or Windows-1252, byte for byte outside the
changed whitespace and keyword case). ``--check`` and ``--diff`` write nothing: they print a
unified diff of each file that would change (KRL text shown through krl/terminal.py
``printable``); ``--check`` also exits 1 when any file would change.

A file that does not parse is never formatted: its syntax errors are printed in the compiler
form of ``krl parse`` (krl/semantics/render.py, ``file:line:col: error[E0xx]: ...``) on stderr,
the file is left untouched, and the exit status is 2. Exit status: 0 nothing to do or
everything formatted; 1 (``--check`` only) some file would change; 2 some file did not parse
or could not be read or written (this wins over 1). A count line closes the run on stderr.
"""

from __future__ import annotations

import difflib
import os
import re
import sys
from pathlib import Path

import click

from krl.fmt.core import FormatError, FormatOptions, FormatSyntaxError, format_text

_LINE_END = re.compile(r"\r\n|\n|\r")


def krl_files(paths) -> list[Path]:
    """The KRL files named by `paths`: files as given, folders walked iteratively (sorted,
    symbolic links inside folders not followed). A missing path is returned as is (and
    reported as unreadable)."""
    from krl.syntax.source import is_krl_file  # noqa: PLC0415

    out: list[Path] = []
    for raw in paths:
        p = Path(raw)
        if not p.is_dir():
            out.append(p)
            continue
        found: list[Path] = []
        stack = [p]
        while stack:
            d = stack.pop()
            try:
                entries = list(os.scandir(d))
            except OSError:
                continue
            for e in entries:
                try:
                    if e.is_symlink():
                        continue
                    if e.is_dir(follow_symlinks=False):
                        stack.append(Path(e.path))
                    elif e.is_file(follow_symlinks=False) and is_krl_file(Path(e.name)):
                        found.append(Path(e.path))
                except OSError:
                    continue
        out.extend(sorted(found))
    return out


def _lines(text: str) -> list[str]:
    return _LINE_END.split(text)


def unified_diff(path: str, before: str, after: str) -> list[str]:
    """A unified diff of two versions of a file, as printable lines (line ends are never changed
    by the formatter, so lines are compared without them; control characters escaped)."""
    from krl.terminal import printable, printable_path  # noqa: PLC0415

    name = printable_path(path)
    diff = difflib.unified_diff(_lines(before), _lines(after), f"{name} (original)", f"{name} (formatted)",
                                lineterm="")
    return [printable(line) for line in diff]


def write_atomically(path: Path, data: bytes) -> None:
    """Replace the file's content atomically (krl/files.py), keeping its mode; the target of a
    symbolic link is replaced, the link kept. Raises OSError."""
    from krl.files import write_bytes_atomic  # noqa: PLC0415

    write_bytes_atomic(Path(os.path.realpath(path)), data, mode=None)


def run_fmt(paths, check: bool = False, diff: bool = False, options: FormatOptions | None = None,
            out=None, err=None, colour: bool = False) -> int:
    """The command's body; `out`/`err` are line writers (diffs / diagnostics and the count line).
    Returns the exit status (0, 1 or 2). Never raises for bad input."""
    from krl.semantics.diagnostics import Diagnostic  # noqa: PLC0415
    from krl.semantics.render import Renderer, SourceLines  # noqa: PLC0415
    from krl.syntax.cli import file_diagnostics  # noqa: PLC0415
    from krl.syntax.source import encode_text, read_source  # noqa: PLC0415
    from krl.terminal import printable, printable_path  # noqa: PLC0415

    out = out or click.echo
    err = err or (lambda line: click.echo(line, err=True))
    options = options or FormatOptions()
    sources = SourceLines()
    renderer = Renderer(err, colour, sources)
    files = krl_files(paths)
    changed = unchanged = failed = 0
    for path in files:
        src = read_source(path)
        if src.status == "empty":
            unchanged += 1
            continue
        problem: list[Diagnostic] = []
        new = None
        if src.status == "ok":
            try:
                new = format_text(src.text, options)
            except FormatSyntaxError:
                _result, text, problem = file_diagnostics(path)
                sources.add(str(path), text)
            except FormatError as exc:
                err(f"{printable_path(path)}: not formatted: {printable(exc)}")
                failed += 1
                continue
        else:
            _result, text, problem = file_diagnostics(path)
        if new is None:
            renderer.emit(problem or [Diagnostic(str(path), 1, 1, "E001", f"file not parsed: {src.status}")])
            failed += 1
            continue
        if new == src.text:
            unchanged += 1
            continue
        changed += 1
        if check or diff:
            for line in unified_diff(str(path), src.text, new):
                out(line)
            continue
        try:
            original = encode_text(src.text, src.encoding)
            data = encode_text(new, src.encoding)
            if original != Path(path).read_bytes():
                raise OSError("the file changed while it was formatted, or its bytes do not round-trip")
            write_atomically(Path(path), data)
        except (OSError, UnicodeError) as exc:
            err(f"{printable_path(path)}: not written: {printable(exc)}")
            changed -= 1
            failed += 1
    verb = "would be reformatted" if (check or diff) else "reformatted"
    summary = f"{changed} {'file' if changed == 1 else 'files'} {verb}, {unchanged} unchanged"
    if failed:
        summary += f", {failed} not formatted (syntax errors or unreadable)"
    err(summary)
    if failed:
        return 2
    return 1 if (check and changed) else 0


def run_stdin(data: bytes, check: bool = False, diff: bool = False, options: FormatOptions | None = None,
              write=None, out=None, err=None, colour: bool = False, terminal: bool = False) -> int:
    """`krl fmt -`: format the bytes of standard input. The formatted file goes to `write`
    (bytes, in the input's encoding; through ``printable`` when `terminal`); with --check or
    --diff only the diff is printed. Exit status as :func:`run_fmt`; on a syntax error nothing
    is written to `write` (an editor keeps its buffer) and the diagnostics name ``<stdin>``."""
    from krl.limits import MAX_FILE_BYTES  # noqa: PLC0415
    from krl.semantics.diagnostics import Diagnostic  # noqa: PLC0415
    from krl.semantics.render import Renderer, SourceLines  # noqa: PLC0415
    from krl.syntax.messages import syntax_diagnostics  # noqa: PLC0415
    from krl.syntax.parse import parse_text  # noqa: PLC0415
    from krl.syntax.source import decode_bytes, encode_text  # noqa: PLC0415
    from krl.terminal import printable  # noqa: PLC0415

    out = out or click.echo
    err = err or (lambda line: click.echo(line, err=True))
    write = write or sys.stdout.buffer.write
    options = options or FormatOptions()
    name = "<stdin>"
    if len(data) > MAX_FILE_BYTES:
        Renderer(err, colour).emit([Diagnostic(name, 1, 1, "E001", f"file not parsed: too_large "
                                               f"({len(data)} bytes > {MAX_FILE_BYTES})")])
        return 2
    if b"\x00" in data:
        Renderer(err, colour).emit([Diagnostic(name, 1, 1, "E001", "file not parsed: binary (NUL bytes)")])
        return 2
    text, encoding = decode_bytes(data)
    try:
        new = format_text(text, options) if text.strip(" \t\r\n\x1a") else text
    except FormatSyntaxError:
        diags = syntax_diagnostics(parse_text(text, name), text)
        Renderer(err, colour, SourceLines({name: text})).emit(
            diags or [Diagnostic(name, 1, 1, "E001", "file not parsed")])
        return 2
    except FormatError as exc:
        err(f"{name}: not formatted: {printable(exc)}")
        return 2
    if check or diff:
        if new != text:
            for line in unified_diff(name, text, new):
                out(line)
        return 1 if (check and new != text) else 0
    if terminal:
        out(printable(new, keep_newlines=True))
    else:
        write(encode_text(new, encoding))
    return 0


@click.command("fmt")
@click.argument("paths", nargs=-1, required=True)
@click.option("--check", is_flag=True, help="Write nothing; print a diff and exit 1 when a file would change.")
@click.option("--diff", is_flag=True, help="Write nothing; print a unified diff of each file that would change.")
@click.option("--keyword-case", type=click.Choice(["upper", "lower", "keep"]), default="upper", show_default=True,
              help="Case of reserved words (names always keep theirs).")
@click.option("--indent", default="3", show_default=True, metavar="N|tab",
              help="One block level: N spaces (1-16) or a tab.")
def fmt(paths: tuple[str, ...], check: bool, diff: bool, keyword_case: str, indent: str) -> None:
    """Format KRL files in place (indentation, keyword case, spacing); comments, folds,
    inline forms, header lines and line ends are kept. Exit 1 with --check when a file would
    change, 2 when a file does not parse."""
    from krl.semantics.render import use_colour  # noqa: PLC0415

    if indent.lower() == "tab":
        unit = "\t"
    elif indent.isdigit() and 1 <= int(indent) <= 16:
        unit = " " * int(indent)
    else:
        raise click.BadParameter("N spaces (1-16) or tab", param_hint="--indent")
    options = FormatOptions(keyword_case=keyword_case, indent=unit)  # type: ignore[arg-type]
    try:
        if paths == ("-",):
            stdin = sys.stdin.buffer
            from krl.limits import MAX_FILE_BYTES  # noqa: PLC0415
            data = stdin.read(MAX_FILE_BYTES + 1)
            stdout = sys.stdout.buffer
            status = run_stdin(data, check, diff, options, write=stdout.write, colour=use_colour(sys.stderr),
                               terminal=stdout.isatty())
        else:
            status = run_fmt(paths, check, diff, options, colour=use_colour(sys.stderr))
    except Exception as exc:  # noqa: BLE001 - a last line of defence: no traceback
        from krl.terminal import printable  # noqa: PLC0415
        click.echo(f"krl fmt: internal error: {type(exc).__name__}: {printable(exc)}", err=True)
        status = 2
    sys.exit(status)


commands = [fmt]
