"""Text from untrusted input (KRL files, file names, stimuli) made safe for a terminal.

KRL text may hold any byte the lexer accepts in a comment or a string, and SWRITE or
MsgNotify can build any character at run time. Printed raw, an ESC (``\\x1b``) starts a
terminal control sequence: it can move the cursor, rewrite what was printed before, change
the window title or, on some terminals, answer back into the input. Every command that prints
text taken from input passes it through :func:`printable` first (docs/security.md).

What is replaced, by a visible escape in Python notation (``\\x1b``, ``\\x85``, ``\\u202e``):

* the C0 controls U+0000..U+001F except TAB (and, with ``keep_newlines``, LF), and DEL U+007F;
* the C1 controls U+0080..U+009F (U+009B is a one-character CSI on many terminals);
* the Unicode line and paragraph separators U+2028, U+2029 (one printed line stays one line);
* the bidirectional formatting characters U+200E, U+200F, U+202A..U+202E, U+2066..U+2069
  (they reorder what is shown, "Trojan source").

A backslash itself is left as it is: the result is for reading, not for parsing back.

:func:`progress_shown` is the one rule of whether a command shows progress (a bar, a status
line) on a stream: a terminal, and ``TERM`` not ``dumb``; piped or redirected, nothing.
"""

from __future__ import annotations

import os
import re
import sys

from krl.limits import MAX_MESSAGE_CHARS

__all__ = ["clip", "printable", "printable_path", "progress_shown"]

_UNSAFE = re.compile("[\x00-\x08\x0a-\x1f\x7f-\x9f\u2028\u2029\u200e\u200f\u202a-\u202e\u2066-\u2069]")
_UNSAFE_KEEP_NL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u2028\u2029\u200e\u200f\u202a-\u202e\u2066-\u2069]")


def _escape(m: re.Match[str]) -> str:
    cp = ord(m.group())
    return f"\\x{cp:02x}" if cp <= 0xFF else f"\\u{cp:04x}"


def printable(text: object, *, keep_newlines: bool = False) -> str:
    """``str(text)`` with every terminal control character shown as a visible escape.

    `keep_newlines` keeps LF (for multi-line blocks such as a source excerpt); CR is always
    replaced, since a bare CR returns to the start of the line and hides what was printed.
    Never raises; ``printable("a\\x1b[2Jb") == "a\\\\x1b[2Jb"``.
    """
    s = text if isinstance(text, str) else str(text)
    pattern = _UNSAFE_KEEP_NL if keep_newlines else _UNSAFE
    return pattern.sub(_escape, s)


def printable_path(path: object) -> str:
    """A file name for the terminal: :func:`printable`, and undecodable bytes (a Latin-1 name on
    a UTF-8 file system, held as surrogate escapes ``\\udcXX``) shown as ``\\xNN``."""
    s = str(path)
    if any("\udc80" <= ch <= "\udcff" for ch in s):
        s = "".join(f"\\x{ord(ch) - 0xDC00:02x}" if "\udc80" <= ch <= "\udcff" else ch for ch in s)
    return printable(s)


def clip(text: str, limit: int = MAX_MESSAGE_CHARS) -> str:
    """`text` cut to at most `limit` characters (default :data:`krl.limits.MAX_MESSAGE_CHARS`),
    the last one an ellipsis "…" when it was cut."""
    return text if len(text) <= limit else text[:limit - 1] + "…"


def progress_shown(stream=None) -> bool:
    """True when progress goes to `stream` (default stderr): it is a terminal and ``TERM`` is
    not ``dumb``; False for a pipe, a file, a closed or a missing stream."""
    stream = sys.stderr if stream is None else stream
    try:
        tty = stream.isatty()
    except (AttributeError, ValueError):
        return False
    return bool(tty) and os.environ.get("TERM", "") != "dumb"
