"""XML from a file or a socket, parsed safely (docs/security.md, "Network").

Every XML text this package reads (an EKI channel's configuration, an RSI configuration, a
message a partner sends) goes through :func:`parse`: defusedxml's ElementTree with DTDs,
entity declarations and external references forbidden (an XML bomb or an external entity is
refused, never expanded), the size bounded before the parse, and the tree bounded after it
(:data:`~krl.limits.MAX_NET_XML_DEPTH` levels, :data:`~krl.limits.MAX_NET_XML_NODES` elements
and attributes). The result is plain ElementTree elements; nothing is evaluated.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from xml.parsers.expat import ExpatError

from defusedxml import DefusedXmlException
from defusedxml.ElementTree import fromstring

from krl.limits import MAX_NET_XML_DEPTH, MAX_NET_XML_NODES


class XmlRefused(ValueError):
    """XML that is malformed, too large, too deep or uses DTDs/entities; the message says which."""


def parse(data: bytes | str, limit: int, what: str = "XML", max_nodes: int = MAX_NET_XML_NODES) -> ET.Element:
    """The root element of `data` (at most `limit` bytes, at most `max_nodes` elements and
    attributes: :data:`~krl.limits.MAX_NET_XML_NODES` unless a reader of larger documents says).

    Raises :class:`XmlRefused` for more than `limit` bytes, malformed XML, a DTD, an entity
    declaration or reference to an external resource, or a tree past the depth and node limits."""
    raw = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    if len(raw) > limit:
        raise XmlRefused(f"{what}: {len(raw)} bytes, more than the limit of {limit}")
    try:
        root = fromstring(raw, forbid_dtd=True, forbid_entities=True, forbid_external=True)
    except DefusedXmlException as exc:
        raise XmlRefused(f"{what}: refused ({type(exc).__name__}: DTDs, entities and external references are not read)") from None
    except (ET.ParseError, ExpatError, ValueError) as exc:
        raise XmlRefused(f"{what}: not well-formed XML ({str(exc)[:80]})") from None
    count = 0
    stack = [(root, 1)]
    while stack:
        el, depth = stack.pop()
        if depth > MAX_NET_XML_DEPTH:
            raise XmlRefused(f"{what}: nested deeper than {MAX_NET_XML_DEPTH} levels")
        count += 1 + len(el.attrib)
        if count > max_nodes:
            raise XmlRefused(f"{what}: more than {max_nodes} elements and attributes")
        stack.extend((c, depth + 1) for c in el)
    return root


def local(tag: str) -> str:
    """A tag without its namespace (``{ns}Name`` -> ``Name``)."""
    return tag.rsplit("}", 1)[-1]


_SKIPPED = ((b"<!--", b"-->"), (b"<?", b"?>"), (b"<![CDATA[", b"]]>"))


class XmlFramer:
    """Splits a TCP byte stream into complete XML documents (one EKI message each): a message
    ends where its root element closes. Comments, processing instructions and whitespace
    between messages are skipped; a ``<!`` other than a comment (a DTD) is kept in the message
    so that :func:`parse` refuses it. At most `limit` bytes are held: a message that grows past
    it is :class:`XmlRefused` (the caller drops it and resynchronises at the next ``<``)."""

    def __init__(self, limit: int) -> None:
        self.limit = limit
        self.buf = bytearray()

    def feed(self, data: bytes) -> list[bytes | XmlRefused]:
        """Add `data`; return the messages completed (bytes) and the refusals, in order."""
        self.buf += data
        out: list[bytes | XmlRefused] = []
        while True:
            start = self.buf.find(b"<")
            if start < 0:
                self.buf.clear()
                return out
            if start:
                del self.buf[:start]
            end = self._end()
            if end is None:
                if len(self.buf) > self.limit:
                    out.append(XmlRefused(f"message longer than {self.limit} bytes"))
                    self._resync()
                    continue
                return out
            if end > self.limit:
                out.append(XmlRefused(f"message of {end} bytes, longer than {self.limit}"))
                del self.buf[:end]
                continue
            msg = bytes(self.buf[:end])
            del self.buf[:end]
            out.append(msg)

    def _resync(self) -> None:
        nxt = self.buf.find(b"<", 1)
        if nxt < 0:
            self.buf.clear()
        else:
            del self.buf[:nxt]

    def pending(self) -> int:
        """Bytes of an incomplete message held."""
        return len(self.buf)

    def _end(self) -> int | None:
        """The end offset of the first complete document in the buffer, or None."""
        b = self.buf
        n = len(b)
        i = 0
        depth = 0
        opened = False
        while i < n:
            lt = b.find(b"<", i)
            if lt < 0:
                return None
            skip = next(((o, c) for o, c in _SKIPPED if b.startswith(o, lt)), None)
            if skip is not None:             # a comment, a processing instruction, CDATA
                e = b.find(skip[1], lt + len(skip[0]))
                if e < 0:
                    return None
                i = e + len(skip[1])
                continue
            # a tag: find its end outside quotes
            j = lt + 1
            quote = 0
            while j < n:
                c = b[j]
                if quote:
                    if c == quote:
                        quote = 0
                elif c in (0x22, 0x27):
                    quote = c
                elif c == 0x3E:     # '>'
                    break
                j += 1
            if j >= n:
                return None
            closing = b[lt + 1] == 0x2F          # '</'
            selfclose = b[j - 1] == 0x2F         # '/>'
            if b[lt + 1] == 0x21:                # '<!DOCTYPE ...>': part of the document
                i = j + 1
                continue
            if closing:
                depth -= 1
            elif not selfclose:
                depth += 1
                opened = True
            else:
                opened = True
            i = j + 1
            if opened and depth <= 0:
                return i
        return None
