"""`krl fmt [--check] [--diff] [--keyword-case upper|lower|keep] [--indent N|tab] PATHS...`
(registered by app/__init__.py).

PATHS are KRL files (.src, .dat, .sub) or folders, listed by the project model
(krl/project.py ``folder_entries``) as ``krl check`` walks them: a symbolic link, FIFO, socket
or device named like a KRL file and a folder more than ``MAX_FOLDER_DEPTH`` levels deep are
never read nor written; each is reported
on stderr as a W002 warning naming it (``path:1:1: warning[W002]: not read: a symbolic link
(never followed)``), as is a folder that cannot be listed. ``-`` alone formats standard input
to standard output (for editors and hooks). By default each file that would change is
rewritten in place, durably (krl/durable.py: a temporary file in the same folder, fsynced,
exchanged in by one rename, the folder fsynced; owner, group and mode kept; a read-only file
or one on a read-only file system refused, exit 2; a file another program saved while it was
formatted kept as that program saved it, exit 2), in the encoding it was read in (krl/source.py: UTF-8 with or without BOM, or Windows-1252,
byte for byte outside the changed whitespace and keyword case). ``--check`` and ``--diff``
write nothing: they print a unified diff of each file that would change (KRL text shown
through krl/terminal.py ``printable``); ``--check`` also exits 1 when any file would change.

A file that does not parse is never formatted: its syntax errors are printed in the compiler
form of ``krl parse`` (krl/diagnostics/render.py, ``file:line:col: error[E0xx]: ...``) on stderr,
the file is left untouched, and the exit status is 2. Exit status: 0 nothing to do or
everything formatted; 1 (``--check`` only) some file would change; 2 some file did not parse
or could not be read or written, or a folder could not be listed (this wins over 1). Links,
FIFOs and too deep folders met in a folder are skipped on purpose and do not change the exit
status. A count line closes the run on stderr.
"""

from __future__ import annotations

import difflib
import os
import re
import sys
from collections.abc import Iterator
from contextlib import ExitStack
from pathlib import Path

import click

from krl.diagnostics import Diagnostic
from krl.diagnostics.codes import E001, W002
from krl.durable import ChangedMeanwhile, write_bytes
from krl.files import Entry
from krl.fmt.core import FormatError, FormatOptions, FormatSyntaxError, format_text
from krl.limits import MAX_FILE_BYTES
from krl.archive import ArchiveError, is_archive
from krl.backups import BackupsError, archives_below, holds_archives, opened
from krl.project import folder_entries
from krl.source import SourceText, decode_bytes, encode_text, read_limited, read_source
from krl.syntax.messages import source_diagnostics
from krl.syntax.parse import parse_source
from krl.terminal import printable, printable_path
from krl.diagnostics.render import Renderer, SourceLines, use_colour

_LINE_END = re.compile(r"\r\n|\n|\r")


# entries of a walk that could not be read (exit status 2); the other kinds are skipped on purpose
_UNREADABLE = ("unreadable_folder", "unreadable")


def fmt_entries(paths, stack: ExitStack | None = None) -> Iterator[tuple[Entry, bool, str]]:
    """What `krl fmt PATHS` works on, in order: (krl/files.py entry, named, the path as the user
    sees it). A path that is not a folder is one ``file`` entry, named (a named link is
    followed; a missing path is reported unreadable when read). A folder (also one named through
    a link) is listed by the project model (krl/project.py ``folder_entries``, the walk ``krl
    check`` makes of it: krl/files.py, iterative, links inside never followed, every link,
    FIFO/socket/device, unreadable or too deep folder (past krl/limits.py ``MAX_FOLDER_DEPTH``)
    listed as an entry that is not read; a controller archive's C and Log Files left out).
    A ``.zip`` (named, or below a named folder) is a controller archive or backup: with `stack`
    (--check, --diff) it is extracted for the stack's life (krl/backups.py ``opened``, the
    limits of krl/limits.py) and its files are read under their names inside it
    (``cell.zip/KRC/R1/x.src``); without, it is one ``archive`` entry, never written (a zip is
    not formatted in place). A refused archive is one ``unreadable`` entry saying why."""
    for raw in paths:
        p = Path(raw)
        zips = is_archive(p) or (p.is_dir() and holds_archives(p))
        if not zips:
            if p.is_dir():
                for e in folder_entries(p):
                    yield e, False, str(e.path)
            else:
                yield Entry(p, str(p), "file"), True, str(p)
            continue
        if stack is None:
            if p.is_dir():
                for e in folder_entries(p):
                    yield e, False, str(e.path)
            for z in ([p] if is_archive(p) else archives_below(p)):
                yield Entry(z, str(z), "archive"), False, str(z)
            continue
        try:
            parts = stack.enter_context(opened(p))
        except (ArchiveError, BackupsError) as exc:
            yield Entry(p, str(p), "unreadable", str(exc).removeprefix(f"{p}: ")), True, str(p)
            continue
        for part in parts:
            if part.error:
                yield Entry(Path(part.source), part.source, "unreadable", part.error), True, part.source
                continue
            for e in folder_entries(part.folder):
                yield e, False, part.shown(str(e.path))


def _lines(text: str) -> list[str]:
    return _LINE_END.split(text)


def unified_diff(path: str, before: str, after: str) -> list[str]:
    """A unified diff of two versions of a file, as printable lines (line ends are never changed
    by the formatter, so lines are compared without them; control characters escaped)."""

    name = printable_path(path)
    diff = difflib.unified_diff(_lines(before), _lines(after), f"{name} (original)", f"{name} (formatted)",
                                lineterm="")
    return [printable(line) for line in diff]


def write_atomically(path: Path, data: bytes, follow_symlinks: bool = True, expect: bytes | None = None) -> None:
    """Replace the file's content durably (krl/durable.py ``write_bytes``), keeping its mode,
    owner and group. A named file (`follow_symlinks`): the target of a symbolic link is
    replaced, the link kept; a file found in a folder: the path itself is replaced (a link
    swapped in meanwhile is replaced, its target never written). `expect`: the bytes read
    (an edit saved meanwhile is kept: krl.durable.ChangedMeanwhile). Raises OSError."""

    try:
        write_bytes(Path(os.path.realpath(path)) if follow_symlinks else Path(path), data, expect=expect)
    except ChangedMeanwhile as exc:
        raise ChangedMeanwhile(exc.errno, f"the file changed while it was formatted: {exc}") from None


def run_fmt(paths, check: bool = False, diff: bool = False, options: FormatOptions | None = None,
            out=None, err=None, colour: bool = False) -> int:
    """The command's body; `out`/`err` are line writers (diffs / diagnostics and the count line).
    Returns the exit status (0, 1 or 2). Never raises for bad input."""

    out = out or click.echo
    err = err or (lambda line: click.echo(line, err=True))
    options = options or FormatOptions()
    sources = SourceLines()
    renderer = Renderer(err, colour, sources)
    with ExitStack() as stack:
        counts = _fmt_all(fmt_entries(paths, stack if (check or diff) else None), check, diff, options,
                          out, err, sources, renderer)
    changed, unchanged, failed, skipped, archives = counts
    verb = "would be reformatted" if (check or diff) else "reformatted"
    summary = f"{changed} {'file' if changed == 1 else 'files'} {verb}, {unchanged} unchanged"
    if failed:
        summary += f", {failed} not formatted (syntax errors or unreadable)"
    if skipped:
        summary += f", {skipped} not read (links, FIFOs, devices, too deep folders)"
    if archives:
        summary += f", {archives} {'archive' if archives == 1 else 'archives'} (.zip) not formatted in place " \
                   "(--check and --diff read them)"
    err(summary)
    if failed or archives:
        return 2
    if not (changed or unchanged or skipped):     # nothing read is no format passed (issue 85)
        err(f"krl fmt: error: no KRL file in {', '.join(printable_path(p) for p in paths)}")
        return 2
    return 1 if (check and changed) else 0


def _fmt_all(entries, check: bool, diff: bool, options: FormatOptions, out, err, sources: SourceLines,
             renderer: Renderer) -> tuple[int, int, int, int, int]:
    """Format each of `entries` (:func:`fmt_entries`); (changed, unchanged, failed, skipped,
    archives not formatted in place)."""
    changed = unchanged = failed = skipped = archives = 0
    for entry, named, name in entries:
        path = entry.path
        if entry.kind == "archive":
            err(f"{printable_path(name)}: a .zip archive is not formatted in place (--check and --diff read it)")
            archives += 1
            continue
        if entry.kind != "file":
            # never read nor written: a W002 warning as `krl check` gives it
            renderer.emit([Diagnostic(name, 1, 1, *W002(why=entry.message))])
            if entry.kind in _UNREADABLE:
                failed += 1
            else:
                skipped += 1
            continue
        src = read_source(path, follow_symlinks=named)   # a link swapped in after the walk: not read
        src.path = name                                  # an archive's file as the user names it
        if src.status == "empty":
            unchanged += 1
            continue
        new = None
        if src.status == "ok":
            # one read, one parse: the formatter's parse result carries the syntax errors
            try:
                new = format_text(src.text, options, src.path)
            except FormatSyntaxError as exc:
                sources.add(src.path, src.text)
                renderer.emit(source_diagnostics(src, exc.result, exc.diagnostics))
                failed += 1
                continue
            except FormatError as exc:
                err(f"{printable_path(path)}: not formatted: {printable(exc)}")
                failed += 1
                continue
        else:
            renderer.emit(source_diagnostics(src, parse_source(src)))     # not parsed: E001 says why
            failed += 1
            continue
        if new == src.text:
            unchanged += 1
            continue
        changed += 1
        if check or diff:
            for line in unified_diff(name, src.text, new):
                out(line)
            continue
        try:
            original = encode_text(src.text, src.encoding)
            data = encode_text(new, src.encoding)
            now, status, detail, _size = read_limited(path, follow_symlinks=named)
            if status != "ok":
                raise OSError(f"the file changed while it was formatted ({status}{': ' + detail if detail else ''})")
            if original != now:
                raise OSError("the file changed while it was formatted, or its bytes do not round-trip")
            write_atomically(Path(path), data, follow_symlinks=named, expect=original)
        except (OSError, UnicodeError) as exc:
            err(f"{printable_path(path)}: not written: {printable(exc)}")
            changed -= 1
            failed += 1
    return changed, unchanged, failed, skipped, archives


def run_stdin(data: bytes, check: bool = False, diff: bool = False, options: FormatOptions | None = None,
              write=None, out=None, err=None, colour: bool = False, terminal: bool = False) -> int:
    """`krl fmt -`: format the bytes of standard input. The formatted file goes to `write`
    (bytes, in the input's encoding; through ``printable`` when `terminal`); with --check or
    --diff only the diff is printed. Exit status as :func:`run_fmt`; on a syntax error nothing
    is written to `write` (an editor keeps its buffer) and the diagnostics name ``<stdin>``."""

    out = out or click.echo
    err = err or (lambda line: click.echo(line, err=True))
    write = write or sys.stdout.buffer.write
    options = options or FormatOptions()
    name = "<stdin>"
    if len(data) > MAX_FILE_BYTES:
        Renderer(err, colour).emit([Diagnostic(name, 1, 1, *E001(why=f"too_large ({len(data)} bytes > {MAX_FILE_BYTES})"))])
        return 2
    if b"\x00" in data:
        Renderer(err, colour).emit([Diagnostic(name, 1, 1, *E001(why="binary (NUL bytes)"))])
        return 2
    text, encoding = decode_bytes(data)
    try:
        new = format_text(text, options, name) if text.strip(" \t\r\n\x1a") else text
    except FormatSyntaxError as exc:
        src = SourceText(name, text, encoding, len(data))
        Renderer(err, colour, SourceLines({name: text})).emit(source_diagnostics(src, exc.result, exc.diagnostics))
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
    inline forms, header lines and line ends are kept. Folders are searched; links, FIFOs and
    folders too deep met there are never read (a W002 warning each). Exit 1 with --check when
    a file would change, 2 when a file does not parse or cannot be read."""

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
            data = stdin.read(MAX_FILE_BYTES + 1)
            stdout = sys.stdout.buffer
            status = run_stdin(data, check, diff, options, write=stdout.write, colour=use_colour(sys.stderr),
                               terminal=stdout.isatty())
        else:
            status = run_fmt(paths, check, diff, options, colour=use_colour(sys.stderr))
    except Exception as exc:  # noqa: BLE001 - a last line of defence: no traceback
        click.echo(f"krl fmt: internal error: {type(exc).__name__}: {printable(exc)}", err=True)
        status = 2
    sys.exit(status)


commands = [fmt]
