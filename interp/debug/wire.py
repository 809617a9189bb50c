"""The Debug Adapter Protocol's wire framing (DAP "Base protocol"): each message is a
header part of ``Name: value`` lines ended by CRLF, an empty CRLF line, then the body: a
UTF-8 JSON object of exactly ``Content-Length`` bytes.

Limits (krl/limits.py): a body longer than MAX_DAP_MESSAGE_BYTES, a header line longer than
1 KiB, more than 16 header lines, a missing or non-numeric Content-Length, a body that is not
a JSON object: :class:`ProtocolError` (the session ends; nothing is executed).
"""

from __future__ import annotations

import json
import os
from typing import BinaryIO

from krl.limits import MAX_DAP_MESSAGE_BYTES

MAX_HEADER_LINE = 1024
MAX_HEADER_LINES = 16


class ProtocolError(Exception):
    """A malformed DAP message (the text says what is wrong)."""


def read_message(stream: BinaryIO) -> dict | None:
    """The next message from ``stream`` as a dict, or None at the end of the stream (before
    any header byte). Raises :class:`ProtocolError` for a malformed message."""
    length = None
    lines = 0
    while True:
        line = stream.readline(MAX_HEADER_LINE + 1)
        if not line:
            if lines == 0:
                return None
            raise ProtocolError("end of stream inside a message header")
        if len(line) > MAX_HEADER_LINE:
            raise ProtocolError("header line too long")
        lines += 1
        if lines > MAX_HEADER_LINES:
            raise ProtocolError("too many header lines")
        text = line.decode("ascii", "replace").rstrip("\r\n")
        if text == "":
            if length is None:
                if lines == 1:      # tolerate blank lines between messages
                    lines = 0
                    continue
                raise ProtocolError("message without Content-Length")
            break
        name, sep, value = text.partition(":")
        if not sep:
            raise ProtocolError(f"malformed header line {text[:60]!r}")
        if name.strip().lower() == "content-length":
            value = value.strip()
            if not value.isdigit() or len(value) > 12:
                raise ProtocolError(f"bad Content-Length {value[:20]!r}")
            length = int(value)
            if length > MAX_DAP_MESSAGE_BYTES:
                raise ProtocolError(f"message of {length} bytes exceeds the limit of {MAX_DAP_MESSAGE_BYTES}")
    body = stream.read(length)
    if len(body) != length:
        raise ProtocolError("end of stream inside a message body")
    try:
        msg = json.loads(body.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as exc:
        raise ProtocolError(f"message body is not JSON: {exc}") from None
    if not isinstance(msg, dict):
        raise ProtocolError("message body is not a JSON object")
    return msg


def encode_message(msg: dict) -> bytes:
    """``msg`` framed for the wire (compact JSON, UTF-8)."""
    body = json.dumps(msg, separators=(",", ":"), ensure_ascii=False).encode("utf-8")
    return b"Content-Length: " + str(len(body)).encode("ascii") + b"\r\n\r\n" + body


def write_message(stream: BinaryIO, msg: dict) -> None:
    """Write one framed message and flush."""
    stream.write(encode_message(msg))
    stream.flush()


class FdReader:
    """The requests' byte stream read straight from a file descriptor (``krl debug``'s stdin),
    with a buffer of its own: ``readline(limit)`` and ``read(n)`` as :func:`read_message`
    uses them.

    Why not ``sys.stdin.buffer``: the reader thread blocks in a read of it while the session
    ends, and a buffered reader's lock held by a daemon thread aborts the interpreter's
    shutdown ("Fatal Python error: _enter_buffered_busy", exit -6). Nothing else touches this
    object, and it holds no lock."""

    CHUNK = 64 * 1024

    def __init__(self, fd: int) -> None:
        self.fd = fd
        self.buf = bytearray()
        self.eof = False

    def _fill(self) -> bool:
        if self.eof:
            return False
        chunk = os.read(self.fd, self.CHUNK)
        if not chunk:
            self.eof = True
            return False
        self.buf += chunk
        return True

    def _take(self, n: int) -> bytes:
        out = bytes(self.buf[:n])
        del self.buf[:n]
        return out

    def readline(self, limit: int = -1) -> bytes:
        """One line with its ``\n`` (at most ``limit`` bytes; at the end, what is left)."""
        while True:
            end = self.buf.find(b"\n")
            if end >= 0 and (limit < 0 or end < limit):
                return self._take(end + 1)
            if limit >= 0 and len(self.buf) >= limit:
                return self._take(limit)
            if not self._fill():
                return self._take(len(self.buf))

    def read(self, n: int) -> bytes:
        """``n`` bytes (fewer only at the end of the stream)."""
        while len(self.buf) < n and self._fill():
            pass
        return self._take(n)
