"""Reading KRL source files: safe reading, encoding detection and bad-input classification.

KRL files are 8-bit text, Windows-1252 in practice, with CRLF line ends (reference 1.1); files
written on controllers set up for another language use that language's Windows code page
(the shared corpus holds cp1252 German, cp1250 Polish, UTF-8 with and without a BOM).
:func:`decode_bytes` is the one decoding function of every command: UTF-8 (a BOM is dropped),
else the most plausible of :data:`KRL_CODE_PAGES` by charset-normalizer; a byte that the chosen
page leaves undefined decodes as Latin-1, so no byte is ever lost.

:func:`read_source` never opens anything but a regular file (a FIFO, socket or device named
``x.src`` is classified ``not_regular`` without being opened for reading, so nothing hangs),
reads at most :data:`krl.limits.MAX_FILE_BYTES` + 1 bytes once, and hashes exactly the bytes it
decodes (``SourceText.sha``), so a cache keyed by that hash describes the text that was parsed.
"""

from __future__ import annotations

import codecs
import hashlib
import os
import re
import stat
from dataclasses import dataclass
from pathlib import Path

from krl.limits import MAX_FILE_BYTES

MAX_BYTES = MAX_FILE_BYTES   # krl/limits.py
KRL_SUFFIXES = (".src", ".dat", ".sub")
UTF8_BOM = b"\xef\xbb\xbf"

# The Windows code pages KUKA controllers write, in order of preference on a tie: Western
# (the default of reference 1.1), Central European, Cyrillic. Pages that decode every byte
# as a letter in the same places (cp1257, iso8859-x) are left out: they only add wrong guesses.
KRL_CODE_PAGES = ("cp1252", "cp1250", "cp1251")
_DETECT_SAMPLE = 16 * 1024   # bytes of non-ASCII lines given to charset-normalizer


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

    status is "ok", or the classification of a file that is not parsed: "empty", "binary"
    (NUL bytes), "too_large" (over :data:`krl.limits.MAX_FILE_BYTES`), "not_regular" (a FIFO,
    socket, device or folder: never opened), "unreadable" (an I/O error). ``sha`` is the
    SHA-256 of the bytes read ("" when nothing was read).
    """

    path: str
    text: str
    encoding: str
    size: int
    status: str = "ok"
    detail: str = ""
    sha: str = ""


_WORDS = re.compile(r"[^\W\d_]+(?:[^\w\s][^\W\d_]+)*")


def _suspicious(text: str) -> int:
    """How unlikely `text` is as a decoding: C1 controls (bytes the page leaves undefined),
    symbols inside a word (``Nieprawid³owy``: cp1252 for cp1250 text) and, counted twice,
    words mixing ASCII letters with Cyrillic or Greek ones (``cafй``: cp1251 for cp1252 text)."""
    score = sum(0x80 <= ord(ch) <= 0x9F for ch in text)
    for word in _WORDS.findall(text):
        if word.isascii():
            continue
        score += sum(1 for ch in word if ord(ch) > 0x7F and not ch.isalpha())
        if any(ch.isascii() and ch.isalpha() for ch in word) and any(0x370 <= ord(ch) <= 0x52F for ch in word):
            score += 2
    return score


def _code_page(body: bytes) -> str:
    """The most plausible of :data:`KRL_CODE_PAGES` for bytes that are not UTF-8.

    The candidates are the pages charset-normalizer finds plausible for the lines holding
    non-ASCII bytes (comments and strings, in KRL), in its order, and cp1252 (the default of
    reference 1.1) in any case; the candidate whose decoding is least :func:`_suspicious`
    wins, then charset-normalizer's order (its language model tells Cyrillic from Latin-1
    letters). When cp1252 gives the same text as the winner (German umlauts are the same bytes
    in cp1250), cp1252 is named.
    """
    # deferred: tools/startup_bench.py, krl lsp +12 ms at the top (2026-11-26)
    import charset_normalizer  # noqa: PLC0415

    sample = b"\n".join(line for line in body.splitlines() if not line.isascii())[:_DETECT_SAMPLE]
    try:
        matches = list(charset_normalizer.from_bytes(sample, cp_isolation=list(KRL_CODE_PAGES)))
    except Exception:  # noqa: BLE001 - detection is a guess; a failure means the default page
        matches = []
    names = [n for n in (codecs.lookup(m.encoding).name for m in matches) if n in KRL_CODE_PAGES]
    names = list(dict.fromkeys(names + ["cp1252"]))
    decoded = {n: sample.decode(n, errors="krl-latin1") for n in names}
    best = min(names, key=lambda n: (_suspicious(decoded[n]), names.index(n)))
    if best != "cp1252" and decoded["cp1252"] == decoded[best]:
        return "cp1252"
    return best


def decode_bytes(data: bytes) -> tuple[str, str]:
    """Decode KRL bytes; returns (text, encoding name).

    The encoding is "ascii", "utf-8", "utf-8-sig" (UTF-8 after a BOM), one of
    :data:`KRL_CODE_PAGES`, or one of them with "+bom" (a code page after a UTF-8 BOM). A UTF-8
    BOM is dropped whatever follows it: a BOM followed by cp1252 text decodes as cp1252 text
    ("cp1252+bom"; the BOM never becomes ``ï»¿`` at 1:1).
    """
    bom = data.startswith(UTF8_BOM)
    body = data[len(UTF8_BOM):] if bom else data
    try:
        text = body.decode("utf-8")
        return text, ("utf-8-sig" if bom else "ascii" if text.isascii() else "utf-8")
    except UnicodeDecodeError:
        pass
    page = _code_page(body)
    return body.decode(page, errors="krl-latin1"), page + ("+bom" if bom else "")


def encode_text(text: str, encoding: str) -> bytes:
    """The inverse of :func:`decode_bytes` for the encoding it reported: ``encode_text(t, e)``
    gives back the original bytes for ``(t, e) = decode_bytes(data)`` ("utf-8-sig" and "+bom"
    restore the BOM; a code page writes its undefined bytes, decoded as Latin-1, back as
    themselves). Raises UnicodeEncodeError for a character the encoding cannot hold."""
    if encoding == "utf-8-sig":
        return UTF8_BOM + text.encode("utf-8")
    if encoding in ("ascii", "utf-8"):
        return text.encode("utf-8")
    page, _, bom = encoding.partition("+")
    page = page if page in KRL_CODE_PAGES else "cp1252"
    return (UTF8_BOM if bom else b"") + text.encode(page, errors="krl-latin1-encode")


def source_from_bytes(path: str, data: bytes, sha: str | None = None) -> SourceText:
    """Classify and decode the bytes of one file (never raises): too_large past MAX_BYTES
    (krl/limits.py MAX_FILE_BYTES, whoever read the bytes: a file, an editor buffer), empty,
    binary, or ok with the decoded text."""
    sha = sha if sha is not None else hashlib.sha256(data).hexdigest()
    if len(data) > MAX_BYTES:
        return SourceText(path, "", "", len(data), "too_large", f"{len(data)} bytes > {MAX_BYTES}", sha)
    if not data.strip(b" \t\r\n\x1a"):
        return SourceText(path, "", "", len(data), "empty", "no content", sha)
    if b"\x00" in data:
        return SourceText(path, "", "", len(data), "binary", "NUL bytes", sha)
    text, encoding = decode_bytes(data)
    return SourceText(path, text, encoding, len(data), "ok", "", sha)


_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISSOCK, "a socket"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"))


def file_kind(mode: int) -> str:
    """What a non-regular file is, in words ("a FIFO", "a socket", ...)."""
    return next((word for test, word in _KINDS if test(mode)), "not a regular file")


def read_limited(path: str | Path, max_bytes: int = MAX_BYTES, follow_symlinks: bool = True
                 ) -> tuple[bytes | None, str, str, int]:
    """The bytes of a regular file, read once: ``(data, status, detail, size)``.

    data is None unless status is "ok". Nothing but a regular file is ever opened for
    reading: the path is stat'ed first (a FIFO, socket or device gives "not_regular"), opened
    non-blocking (a FIFO swapped in after the stat cannot block) and checked again on the open
    descriptor. With ``follow_symlinks=False`` a symbolic link is "not_regular" too (a scan
    has already listed it as a link). At most ``max_bytes + 1`` bytes are read: a larger file
    is "too_large", whatever its size said before.
    """
    try:
        st = os.stat(path) if follow_symlinks else os.lstat(path)
        if stat.S_ISLNK(st.st_mode):
            return None, "not_regular", "a symbolic link", 0
        if not stat.S_ISREG(st.st_mode):
            return None, "not_regular", file_kind(st.st_mode), 0
        if st.st_size > max_bytes:
            return None, "too_large", f"{st.st_size} bytes > {max_bytes}", st.st_size
        flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) \
            | getattr(os, "O_CLOEXEC", 0) | (0 if follow_symlinks else getattr(os, "O_NOFOLLOW", 0))
        fd = os.open(path, flags)
    except OSError as exc:
        return None, "unreadable", exc.strerror or str(exc), 0
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            return None, "not_regular", file_kind(st.st_mode), 0
        chunks, got = [], 0
        while got <= max_bytes:
            chunk = os.read(fd, min(1 << 20, max_bytes + 1 - got))
            if not chunk:
                break
            chunks.append(chunk)
            got += len(chunk)
        data = b"".join(chunks)
    except OSError as exc:
        return None, "unreadable", exc.strerror or str(exc), 0
    finally:
        os.close(fd)
    if len(data) > max_bytes:
        return None, "too_large", f"more than {max_bytes} bytes", len(data)
    return data, "ok", "", len(data)


def read_source(path: str | Path, max_bytes: int = MAX_BYTES, follow_symlinks: bool = True) -> SourceText:
    """Read and classify one file. Never raises for bad content; I/O errors give "unreadable",
    a FIFO/socket/device/folder "not_regular" (never opened, see :func:`read_limited`)."""
    data, status, detail, size = read_limited(path, max_bytes, follow_symlinks)
    if data is None:
        return SourceText(str(path), "", "", size, status, detail)
    return source_from_bytes(str(path), data)


def is_krl_file(path: Path) -> bool:
    """True for .src, .dat and .sub files, in any letter case."""
    return path.suffix.lower() in KRL_SUFFIXES
