"""One KUKA event log (``KrcLog*.evt``, a Windows EVTX file) read with python-evtx.

python-evtx (PyPI ``python-evtx``, Willi Ballenthin) parses the file: its header, its 64 KiB
chunks, their records, and each record's binary XML (a template plus substitutions; Microsoft's
"Windows XML Event Log (EVTX)" format as libevtx documents it). Its own renderer
(``Record.xml()``) parses a record's template again for every record: 2.6 ms of CPU a record,
about 4.6 s for the archive's 1,761-record ``KrcLogU.evt``. :class:`_Renderer` gives the same
text (python-evtx's :func:`Evtx.Views.render_root_node_with_subs`, called once per template with
markers for the substitutions) and fills in each record's substitutions (python-evtx's
``RootNode.substitutions``, escaped by its ``escape_value``): 0.7 to 0.85 s of CPU for that log
(2026-11-27 on the shared 2-core machine: ``time.process_time`` around :func:`read_events` of
the whole log, three runs, and around ``Record.xml()`` of its first 300 records).

:func:`read_events` yields one :class:`Event` per record: the ``System`` part (TimeCreated,
EventRecordID, Channel, Level, EventID, Provider, Computer) and the ``LS`` document of its
``EventData`` (the KUKA record: krl/logbook/record.py). The file is untrusted
(docs/security.md): larger than ``MAX_LOG_BYTES`` it is not read; a file whose header is not an
EVTX header, a chunk past the file's end (a truncated copy), a chunk whose checksum fails, or a
record python-evtx cannot parse gives a :class:`LogError` naming the file and the record (the
last one read before it, and the byte offset), and the records before it stand. A *dirty*
header (the log was open when it was copied: its chunk count may lag) lets the chunks after
the counted ones be read as long as they verify.
"""

from __future__ import annotations

import datetime as dt
import logging
import struct
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from xml.etree.ElementTree import ParseError

from defusedxml import ElementTree as SafeET
from defusedxml.common import DefusedXmlException
from Evtx import Nodes as EvtxNodes
from Evtx import Views as EvtxViews
from Evtx.BinaryParser import BinaryParserException
from Evtx.Evtx import Evtx

from krl.limits import MAX_LOG_BYTES

__all__ = ["Event", "LogError", "read_events"]

# python-evtx logs a damaged template's "Unexpected token encountered" as a warning; without a
# handler Python prints it bare on standard error. What the damage costs is this module's
# LogError, naming the file and the record; the library's own line is not shown.
logging.getLogger("Evtx").addHandler(logging.NullHandler())

_EVENT_NS = "{http://schemas.microsoft.com/win/2004/08/events/event}"
#: what python-evtx raises on bytes that are not what the format says (its own exceptions, and
#: the struct/index/decoding errors of its field readers on a damaged buffer)
_DAMAGE = (BinaryParserException, struct.error, IndexError, KeyError, ValueError, UnicodeDecodeError,
           OverflowError, RuntimeError, EvtxViews.UnexpectedElementException, ParseError, DefusedXmlException)


class LogError(ValueError):
    """An event log that cannot be read (whole or from one record on): the message names the
    file and the record."""


@dataclass(frozen=True, slots=True)
class Event:
    """One record of an event log: ``time`` (TimeCreated, UTC, microseconds), ``record``
    (EventRecordID), ``channel``, ``level`` (1 critical .. 5 verbose), ``event_id``, ``provider``,
    ``computer``, ``ls`` (the text of ``EventData/Data[@Name="LS"]``, "" when absent)."""

    time: dt.datetime
    record: int
    channel: str
    level: int
    event_id: int
    provider: str
    computer: str
    ls: str


class _Mark:
    """A substitution stand-in: python-evtx's renderer writes its ``string()`` where the
    substitution goes (escape_value leaves NUL and the digits alone)."""

    __slots__ = ("text",)

    def __init__(self, index: int) -> None:
        self.text = f"\x00{index}\x00"

    def string(self) -> str:
        return self.text


class _Marks:
    """The substitutions of a template being rendered into a skeleton: a mark for any index."""

    def __getitem__(self, index: int) -> _Mark:
        return _Mark(index)


class _Renderer:
    """Renders records as python-evtx's ``Record.xml()`` does, each template parsed once per
    chunk (the key: the chunk's offset and the template's)."""

    def __init__(self) -> None:
        self._skeletons: dict[tuple[int, int], list] = {}

    def _skeleton(self, chunk_ofs: int, root) -> list:
        key = (chunk_ofs, root.template_instance().template_offset())
        got = self._skeletons.get(key)
        if got is None:
            text = EvtxViews.render_root_node_with_subs(root, _Marks())
            parts = text.split("\x00")
            # even positions: literal text; odd positions: a substitution's index
            got = self._skeletons[key] = [p if k % 2 == 0 else int(p) for k, p in enumerate(parts)]
        return got

    def render(self, chunk_ofs: int, root) -> str:
        subs = root.substitutions()
        out = []
        for k, part in enumerate(self._skeleton(chunk_ofs, root)):
            if k % 2 == 0:
                out.append(part)
                continue
            sub = subs[part]
            if isinstance(sub, EvtxNodes.BXmlTypeNode):
                out.append(self.render(chunk_ofs, sub.root()))
            else:
                out.append(EvtxViews.escape_value(sub.string()))
        return "".join(out)


def _parse_time(text: str) -> dt.datetime:
    """python-evtx's ``2026-01-27 10:43:12.084162+00:00`` (UTC) as an aware datetime."""
    return dt.datetime.fromisoformat(text.strip()).astimezone(dt.timezone.utc)


def _event(xml: str) -> Event:
    root = SafeET.fromstring(xml)
    system = root.find(_EVENT_NS + "System")
    if system is None:
        raise ValueError("no System element")

    def text(name: str) -> str:
        node = system.find(_EVENT_NS + name)
        return (node.text or "").strip() if node is not None else ""

    created = system.find(_EVENT_NS + "TimeCreated")
    provider = system.find(_EVENT_NS + "Provider")
    ls = ""
    for data in root.iter(_EVENT_NS + "Data"):
        if data.get("Name") == "LS":
            ls = data.text or ""
            break
    return Event(time=_parse_time(created.get("SystemTime", "") if created is not None else ""),
                 record=int(text("EventRecordID") or 0), channel=text("Channel"),
                 level=int(text("Level") or 0), event_id=int(text("EventID") or 0),
                 provider=provider.get("Name", "") if provider is not None else "",
                 computer=text("Computer"), ls=ls)


def _check_file(path: Path, shown: str) -> int:
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise LogError(f"{shown}: cannot be read ({exc.strerror or exc})") from None
    if size > MAX_LOG_BYTES:
        raise LogError(f"{shown}: {size} bytes, larger than MAX_LOG_BYTES = {MAX_LOG_BYTES}; not read")
    if size < 0x1000:
        raise LogError(f"{shown}: {size} bytes, shorter than an EVTX file header (4096 bytes); not an event log")
    return size


def read_events(path: str | Path, shown: str | None = None) -> Iterator[Event]:
    """The records of the event log `path`, in file order (`shown`: its name in messages). Raises
    :class:`LogError` (after yielding the records before the damage) for a file that is not an
    EVTX event log, is truncated or damaged."""
    path = Path(path)
    shown = shown or str(path)
    size = _check_file(path, shown)
    renderer = _Renderer()
    last = "its start"
    try:
        log = Evtx(str(path)).__enter__()
    except (OSError, ValueError) as exc:
        raise LogError(f"{shown}: cannot be read ({exc})") from None
    try:
        header = log.get_file_header()
        if not header.check_magic():
            raise LogError(f"{shown}: not an EVTX event log (no 'ElfFile' header)")
        count = header.chunk_count()
        dirty = header.is_dirty()
        seen = 0
        # python-evtx stops at the file's end (counted below); a dirty header (the log was open
        # when copied) may lag behind chunks already written: those that verify are read too
        for chunk in header.chunks(include_inactive=dirty):
            if seen >= count and not (chunk.check_magic() and chunk.verify()):
                break
            seen += 1
            if not chunk.check_magic() or not chunk.verify():
                raise LogError(f"{shown}: chunk {seen} (byte {chunk.offset()}) is damaged (its checksum "
                               f"fails); the records after {last} are not read")
            for rec in chunk.records():
                where = f"the record at byte {rec.offset()} (after {last})"
                try:
                    if rec.magic() != 0x2A2A or not rec.verify():
                        raise LogError(f"{shown}: {where} is damaged (its header is not a record's)")
                    event = _event(renderer.render(chunk.offset(), rec.root()))
                except LogError:
                    raise
                except _DAMAGE as exc:
                    raise LogError(f"{shown}: {where} cannot be read ({type(exc).__name__}: {exc})") from None
                last = f"record {event.record}"
                yield event
        if seen < count:
            raise LogError(f"{shown}: truncated: the header names {count} chunks of records, the file ({size} "
                           f"bytes) holds {seen}; the records after {last} are missing")
    except LogError:
        raise
    except _DAMAGE as exc:
        raise LogError(f"{shown}: damaged after {last} ({type(exc).__name__}: {exc})") from None
    finally:
        log.__exit__(None, None, None)
