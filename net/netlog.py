"""What a partner sends, wherever it is shown but in the recording of the message itself, is
clipped to :data:`~krl.limits.MAX_NET_LOG_CHARS` (issue 61; docs/security.md "Network").

The recording — a ``net`` trace event's ``data``, which a replay feeds again — keeps the message
as it arrived, bounded by its protocol's own limit (EKI's BUFFSIZE, an RSI datagram, a
KukaVarProxy value, ...). Everything else a partner's bytes reach is clipped: an event's
``text`` and the controller's messages (the hub, net/hub.py, clips both for every partner), a
refusal, and the lines the protocol libraries log on stderr (asyncua logs a refused OPC UA write
with its whole value; :func:`clip_library_logs` puts one handler on their loggers).
"""

from __future__ import annotations

import logging
import sys

from krl.limits import MAX_NET_LOG_CHARS

ELLIPSIS = "…"


def clip(text, limit: int = MAX_NET_LOG_CHARS) -> str:
    """`text` (any object's ``str``) at most `limit` characters, ending in "…" when cut."""
    text = str(text)
    return text if len(text) <= limit else text[:limit - 1] + ELLIPSIS


class _Clipped(logging.Formatter):
    """A log record's message (its text with the arguments put in) clipped, its traceback left
    out: a library's record of a partner's request never carries the request whole."""

    def format(self, record: logging.LogRecord) -> str:
        try:
            msg = record.getMessage()
        except Exception:  # noqa: BLE001 - a record whose arguments do not format: its template
            msg = str(record.msg)
        return f"{record.name}: {record.levelname.lower()}: {clip(msg)}"


class _ClippedStderr(logging.Handler):
    """Writes each record, clipped (:class:`_Clipped`), to the process's stderr as it is when the
    record comes (as Python's last-resort handler does), or to the stream :meth:`setStream` set."""

    def __init__(self, level: int) -> None:
        super().__init__(level)
        self.setFormatter(_Clipped())
        self.stream = None

    def setStream(self, stream):
        """Write to `stream` from now on (None: stderr again); the stream written to before."""
        old, self.stream = self.stream, stream
        return old

    def emit(self, record: logging.LogRecord) -> None:
        try:
            stream = self.stream if self.stream is not None else sys.stderr
            stream.write(self.format(record) + "\n")
            stream.flush()
        except Exception:  # noqa: BLE001 - logging's own rule: a handler never raises
            self.handleError(record)


_installed: dict[str, _ClippedStderr] = {}


def redirect(stream) -> None:
    """Every clipping handler writes to `stream` from now on (None: stderr again)."""
    for handler in _installed.values():
        handler.setStream(stream)


def clip_library_logs(*names: str, level: int = logging.WARNING) -> None:
    """The loggers `names` (``asyncua``, ``pymodbus``, ...) and theirs below write through one
    stderr handler that clips each message (:class:`_Clipped`) at `level` and above, and no
    longer pass their records up (Python's last-resort handler would print them whole). Once
    per logger and process."""
    for name in names:
        if name in _installed:
            continue
        handler = _installed[name] = _ClippedStderr(level)
        log = logging.getLogger(name)
        log.addHandler(handler)
        log.propagate = False
        if log.level == logging.NOTSET or log.level < level:
            log.setLevel(level)


__all__ = ["ELLIPSIS", "clip", "clip_library_logs", "redirect"]
