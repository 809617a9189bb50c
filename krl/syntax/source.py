"""Reading KRL source files: encoding detection and bad-input classification.

KRL files are 8-bit text, Windows-1252 in practice, with CRLF line ends (reference 1.1).
We accept UTF-8 with or without a BOM, fall back to cp1252, and never lose a byte:
bytes that cp1252 leaves undefined decode as Latin-1.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
import codecs

from krl.limits import MAX_FILE_BYTES

MAX_BYTES = MAX_FILE_BYTES   # krl/limits.py
KRL_SUFFIXES = (".src", ".dat", ".sub")


def _latin1_fallback(err: UnicodeDecodeError) -> tuple[str, int]:
    return err.object[err.start:err.end].decode("latin-1"), err.end


codecs.register_error("krl-latin1", _latin1_fallback)


def _latin1_encode_fallback(err: UnicodeEncodeError) -> tuple[bytes, int]:
    chunk = err.object[err.start:err.end]
    if all(ord(ch) <= 0xFF for ch in chunk):
        return chunk.encode("latin-1"), err.end
    raise err


codecs.register_error("krl-latin1-encode", _latin1_encode_fallback)


@dataclass(slots=True)
class SourceText:
    """A decoded source file.

    status is "ok", or the classification of a file that is not parsed:
    "empty", "binary" (NUL bytes), "too_large" (over 10 MB), "unreadable".
    """

    path: str
    text: str
    encoding: str
    size: int
    status: str = "ok"
    detail: str = ""


def decode_bytes(data: bytes) -> tuple[str, str]:
    """Decode KRL bytes; returns (text, encoding name)."""
    if data.startswith(b"\xef\xbb\xbf"):
        try:
            return data[3:].decode("utf-8"), "utf-8-sig"
        except UnicodeDecodeError:
            pass
    try:
        text = data.decode("utf-8")
        return text, ("ascii" if text.isascii() else "utf-8")
    except UnicodeDecodeError:
        pass
    # cp1252 leaves 0x81, 0x8D, 0x8F, 0x90, 0x9D undefined; those decode as Latin-1.
    return data.decode("cp1252", errors="krl-latin1"), "cp1252"


def encode_text(text: str, encoding: str) -> bytes:
    """The inverse of :func:`decode_bytes` for the encoding it reported: ``encode_text(t, e)``
    gives back the original bytes for ``(t, e) = decode_bytes(data)`` ("utf-8-sig" restores the
    BOM; "cp1252" writes the five undefined bytes, decoded as Latin-1, back as themselves).
    Raises UnicodeEncodeError for a character the encoding cannot hold."""
    if encoding == "utf-8-sig":
        return b"\xef\xbb\xbf" + text.encode("utf-8")
    if encoding in ("ascii", "utf-8"):
        return text.encode("utf-8")
    return text.encode("cp1252", errors="krl-latin1-encode")


def read_source(path: str | Path, max_bytes: int = MAX_BYTES) -> SourceText:
    """Read and classify one file. Never raises for bad content; I/O errors give "unreadable"."""
    p = Path(path)
    try:
        size = p.stat().st_size
        if size > max_bytes:
            return SourceText(str(path), "", "", size, "too_large", f"{size} bytes > {max_bytes}")
        data = p.read_bytes()
    except OSError as exc:
        return SourceText(str(path), "", "", 0, "unreadable", str(exc))
    if not data.strip(b" \t\r\n\x1a"):
        return SourceText(str(path), "", "", len(data), "empty", "no content")
    if b"\x00" in data:
        return SourceText(str(path), "", "", len(data), "binary", "NUL bytes")
    text, encoding = decode_bytes(data)
    return SourceText(str(path), text, encoding, len(data))


def is_krl_file(path: Path) -> bool:
    """True for .src, .dat and .sub files, in any letter case."""
    return path.suffix.lower() in KRL_SUFFIXES
