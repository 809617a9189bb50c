"""The background index of a closed file too large to read whole (issue 74).

A closed file of the workspace larger than :data:`krl.limits.MAX_LSP_INDEX_FILE_BYTES` is not
parsed whole (its AST would cost gigabytes: a 9.8 MB file made the first answer wait 96 s and
2.9 GB). What the other files may use of it are its declarations: the routines (their ``DEF`` /
``DEFFCT`` line, their ``END`` / ``ENDFCT``, the ``DECL`` lines of their parameters), and of a
data list its ``DEFDAT`` / ``ENDDAT`` and ``GLOBAL`` declarations (KUKA System Software 8.x,
Operating and Programming Instructions for System Integrators, "Subprograms and functions":
a routine is called from another module when it is the module's main routine or declared
``GLOBAL``; "Data lists": a ``PUBLIC`` data list's data is seen outside when declared
``GLOBAL``). :func:`index_text` keeps those lines (the *outline*), parses them alone, a few
hundred lines instead of hundreds of thousands, and moves every span of that AST to the line it
has in the file: names resolve and go to the right line, while the file's statements are never
parsed. :class:`Indexer` does this on its own thread, one file at a time, stoppable between
files and inside a file's scan.

Bounds: the outline of one file holds at most :data:`krl.limits.MAX_LSP_OUTLINE_BYTES` (a data
list of megabytes of ``GLOBAL`` declarations is past it: it stays not indexed, a W002 warning
says so); the file is read once (at most ``MAX_FILE_BYTES``, krl/source.py) and dropped when
its outline is made. The outline's diagnostics are not the file's and are dropped: the file's
own diagnostics come when the editor opens it.
"""

from __future__ import annotations

import logging
import queue
import re
import threading
from collections.abc import Callable
from dataclasses import dataclass

from krl.ast import nodes as N
from krl.limits import MAX_LSP_OUTLINE_BYTES
from krl.lsp.parsing import Parsed
from krl.source import SourceText, read_source
from krl.workspace import LoadedFile, load_parsed

log = logging.getLogger("krl.lsp")

# A line the outline keeps: a routine's or a data list's first or last line, a declaration.
_KEPT = re.compile(r"^[ \t]*(?:(?:GLOBAL[ \t]+)?(?:DEF|DEFFCT)\b|DEFDAT\b|ENDDAT\b|END\b|ENDFCT\b|DECL\b|GLOBAL\b)"
                   r"[^\r\n]*", re.I | re.M)
_IN_DATA_LIST = re.compile(r"[ \t]*(?:DECL[ \t]+)?GLOBAL\b", re.I)
_CHUNK = 1 << 20            # characters scanned between two looks at the stop flag


class OutlineTooLarge(ValueError):
    """The outline of a file is past MAX_LSP_OUTLINE_BYTES."""


class Stopped(Exception):
    """The index was stopped (the server shuts down, the file was opened)."""


@dataclass(frozen=True)
class Outline:
    """The lines of a file an index keeps: ``lines[i]`` is the 1-based line of the file that
    is line i + 1 of ``text``; ``count``: the file's number of line ends + 1 (``len(text.split("\\n"))``)."""
    text: str
    lines: list[int]
    count: int


def outline(text: str, stop: threading.Event | None = None) -> Outline:
    """The outline of a file's `text` (module docstring): of the routines seen from other
    modules (the first, the module's main routine, and the ``GLOBAL`` ones) the first and last
    lines and the ``DECL`` lines (their parameters' types), of a data list (``DEFDAT`` ..
    ``ENDDAT``) the ``GLOBAL`` declarations. Raises OutlineTooLarge, Stopped."""
    kept: list[str] = []
    lines: list[int] = []
    size, line, pos, look = 0, 1, 0, _CHUNK
    in_data, shown, routines = False, False, 0
    for m in _KEPT.finditer(text):
        if m.start() >= look:
            look = m.start() + _CHUNK
            if stop is not None and stop.is_set():
                raise Stopped()
        words = m.group(0).upper().split(None, 2)
        word = words[1] if words[0] == "GLOBAL" and len(words) > 1 else words[0]
        if word in ("DEF", "DEFFCT"):
            routines += 1
            shown = routines == 1 or words[0] == "GLOBAL"
            keep = shown
        elif word in ("END", "ENDFCT"):
            keep, shown = shown, False
        elif word in ("DEFDAT", "ENDDAT"):
            in_data, keep = word == "DEFDAT", True
        else:               # DECL or GLOBAL
            keep = bool(_IN_DATA_LIST.match(m.group(0))) if in_data else shown
        if not keep:
            continue
        line += text.count("\n", pos, m.start())
        pos = m.start()
        kept.append(m.group(0))
        lines.append(line)
        size += len(m.group(0)) + 1
        if size > MAX_LSP_OUTLINE_BYTES:
            raise OutlineTooLarge(f"its declarations are more than {MAX_LSP_OUTLINE_BYTES} bytes")
    return Outline("\n".join(kept) + "\n", lines, line + text.count("\n", pos))


def index_text(path: str, text: str, stop: threading.Event | None = None) -> Parsed:
    """The index of the file `path` holding `text`: a Parsed whose AST is its outline's, every
    span on the file's own line, whose text has the file's lines with only the outline's
    lines kept (the others empty), and no diagnostics. Raises OutlineTooLarge, Stopped."""
    out = outline(text, stop)
    size = len(out.text.encode("utf-8", "surrogatepass"))
    lf = load_parsed(SourceText(path, out.text, "", size), None)     # a few hundred lines: the Python engine
    real = [0, *out.lines]
    for node in lf.module.walk():
        s = node.span
        if 0 < s.line < len(real):
            node.span = N.Span(s.file, real[s.line], s.column)
        if isinstance(node, N.Routine) and 0 < node.end_line < len(real):
            node.end_line = real[node.end_line]
    lf.module.unparsed = []
    loaded = LoadedFile(path, lf.module, True, "done", lf.parse_seconds, lf.build_seconds, [],
                        failed_words=set(lf.failed_words))
    return Parsed(path, _spread(out), loaded)


def _spread(out: Outline) -> str:
    """The outline's lines at the file's line numbers, the others empty."""
    parts, at = [], 1
    for text, line in zip(out.text.split("\n"), out.lines):
        parts.append("\n" * (line - at))
        parts.append(text)
        at = line
    parts.append("\n" * (out.count - at))
    return "".join(parts)


def index_file(path: str, stop: threading.Event | None = None) -> Parsed:
    """:func:`index_text` of the file at `path` as it is on disk. Raises OutlineTooLarge,
    Stopped, OSError (unreadable, undecodable: the reason of krl/source.py)."""
    src = read_source(path)
    if src.status != "ok":
        raise OSError(f"not read: {src.status} {src.detail}".rstrip())
    return index_text(path, src.text, stop)


class Indexer:
    """Indexes files on its own daemon thread, one at a time, in the order asked; each index
    made is handed to `done(path, stamp, parsed)`, each failure to `failed(path, stamp, why)`
    (from that thread). :meth:`stop` ends it (the file being indexed is left at its next
    chunk of 1 MiB); :meth:`forget` drops a file asked for and not indexed yet."""

    def __init__(self, done: Callable[[str, tuple, Parsed], None],
                 failed: Callable[[str, tuple, str], None]) -> None:
        self._done, self._failed = done, failed
        self._queue: queue.SimpleQueue = queue.SimpleQueue()
        self._asked: set[str] = set()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def ask(self, path: str, stamp: tuple) -> None:
        """Index the file `path` (as of its `stamp`) unless it is asked for already."""
        with self._lock:
            if self._stop.is_set() or path in self._asked:
                return
            self._asked.add(path)
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name="krl-index", daemon=True)
                self._thread.start()
        self._queue.put((path, stamp))

    def forget(self, path: str) -> None:
        with self._lock:
            self._asked.discard(path)

    def stop(self) -> None:
        self._stop.set()
        self._queue.put(None)

    def _run(self) -> None:
        while not self._stop.is_set():
            item = self._queue.get()
            if item is None:
                return
            path, stamp = item
            with self._lock:
                if path not in self._asked:
                    continue
            try:
                parsed = index_file(path, self._stop)
            except Stopped:
                return
            except (OutlineTooLarge, OSError, RecursionError) as exc:
                self._failed(path, stamp, str(exc))
            except Exception as exc:  # noqa: BLE001 - one file never ends the indexer
                log.error("indexing %s failed: %s: %s", path, type(exc).__name__, exc)
                self._failed(path, stamp, f"{type(exc).__name__}: {exc}")
            else:
                self._done(path, stamp, parsed)
            finally:
                with self._lock:
                    self._asked.discard(path)
