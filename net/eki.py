"""EthernetKRL channels: the element memory, the EKI functions' semantics and EKI_STATUS
(KUKA.EthernetKRL 2.2/3.x manual, "Programming", "Messages"; docs/network.md "EthernetKRL").

A :class:`Channel` is created by ``EKI_Init`` from its :class:`~net.ekiconfig.EkiConfig`,
opened by ``EKI_Open`` (a server listens, a client connects; net/transport.py), closed by
``EKI_Close`` and deleted by ``EKI_Clear``. What arrives is split into messages (an XML
document, a fixed-length record or a record ending in the EOS string), checked, and its
configured elements are put into the element memory: per element a FIFO (or LIFO) of at most
BUFFERING Limit entries, each with the message counter (EKI_STATUS.Counter). ``EKI_Get*``
takes the oldest entry; ``EKI_CheckBuffer`` counts them; ``EKI_Set*`` fills the send
structure and ``EKI_Send`` sends the part under a path (or a literal XML string).

Every function returns a :class:`Status` (Buff, Read, Msg_No, Connected, Counter) and, for an
error of the call itself, an :class:`EkiError`: the runtime stops the program with it unless
the channel's ``MESSAGES Display="disabled"`` (then only Msg_No tells). Errors of reception
(malformed XML, a message too long, a full memory, a dropped connection) are messages of the
controller: traced, and given as Msg_No of the channel's next call, never a stop.

:class:`EkiPartner` is EthernetKRL as a network partner of the run (net/partner.py): the
channels, their sockets (one per channel the cell file names), their events at each IPO cycle
and in a replay. A client channel's ``EKI_Open`` waits for its connection up to TIMEOUT Connect
(:meth:`Channel.open`, docs/network.md "Which EKI functions wait").
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from pathlib import Path
import re
import xml.etree.ElementTree as ET

from krl.limits import MAX_EKI_CHANNELS, MAX_EKI_IDLE_S

from . import transport
from .cellkey import LOOPBACK, SettingsError, channel
from .ekiconfig import ConfigError, EkiConfig, Element, find_config, load_config
from .partner import Partner
from .xmlsafe import XmlFramer, XmlRefused, local, parse

# EKI's own message numbers (Msg_No; the controller shows "EKI000nn") with KUKA's texts, from
# KUKA's EthernetKRL message table (as generated from KUKA's sources into Intrinsic's
# kss_messages.h; docs/network.md "EthernetKRL", "Decisions"). 25 for a 17th channel is this
# project's choice: which message KUKA gives there is not public.
MESSAGES = {
    3: "File access failed",
    4: "Requested function not implemented",
    9: "Connection not available",
    10: "Ethernet is disconnected",
    14: "Ethernet connection to external system failed",
    15: "Access to empty element memory",
    16: "Element not found",
    19: "No data to send",
    20: "Mismatch in type of data",
    22: "Error while reading the configuration. XML not valid.",
    23: "Initialization already performed",
    24: "Link to internal parameters (Port, IP) failed",
    25: "Maximum number of channels reached",
    512: "Ethernet connection disrupted",
    768: "Ping reports no contact",
    1024: "Error while reading received XML data",
    1280: "Limit of element storage reached",
    1536: "Received string too long",
}


STRUCT_COMPONENTS = frozenset(("X", "Y", "Z", "A", "B", "C", "S", "T", "A1", "A2", "A3", "A4", "A5", "A6",
                               "E1", "E2", "E3", "E4", "E5", "E6"))
"""The components of a FRAME, POS, AXIS (and E6POS/E6AXIS) as EKI_SetFrame/GetFrame.. write them."""


@dataclass
class Status:
    """EKI_STATUS: Buff (entries left in memory), Read (entries read), Msg_No (0 or an EKI
    message number), Connected, Counter (the message counter of the data read)."""

    buff: int = 0
    read: int = 0
    msg_no: int = 0
    connected: bool = False
    counter: int = 0


class EkiError(Exception):
    """An EKI function's own error: number (Msg_No) and text; ``stops`` when the channel's
    messages are displayed (the controller's acknowledgement message stops the program)."""

    def __init__(self, number: int, detail: str = "", stops: bool = True) -> None:
        self.number = number
        self.stops = stops
        base = MESSAGES.get(number, "EthernetKRL error")
        super().__init__(f"EKI{number:05d} {base}" + (f": {detail}" if detail else ""))


def format_real(v: float) -> str:
    """A REAL as EKI writes it into a message: fixed point, at most 6 decimals."""
    s = f"{float(v):.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


class Channel:
    """One EKI channel (see the module docstring). `hub` is the run's :class:`EkiPartner` (or a
    network hub, net/hub.py, whose EKI partner is taken): it owns the sockets and the trace;
    `cfg` the configuration."""

    def __init__(self, hub, cfg: EkiConfig) -> None:
        self.hub = hub.partner("eki") if hasattr(hub, "partner") else hub
        self.cfg = cfg
        self.name = cfg.name
        self.opened = False
        self.connected = False
        self.endpoint = None
        self.counter = 0
        self.memory: dict[str, deque] = {}
        self.sendvals: dict[str, str | dict] = {}
        self.locked = False
        self.connecting = False     # a client's EKI_Open is waiting for its connection
        self.held: list[bytes] = []
        self.async_no = 0
        self.framer = XmlFramer(cfg.buffsize) if cfg.receive_kind != "raw" else None
        self.rawbuf = bytearray()

    # ------------------------------------------------------------------ status
    def status(self, **kw) -> Status:
        st = Status(connected=self.connected, **kw)
        if self.async_no and not st.msg_no:
            st.msg_no, self.async_no = self.async_no, 0
        return st

    def error(self, number: int, detail: str = "") -> EkiError:
        return EkiError(number, f"channel {self.name}" + (f", {detail}" if detail else ""), self.cfg.display)

    # ------------------------------------------------------------------ open / close
    def open(self, wait=None) -> tuple[Status, EkiError | None]:
        """EKI_Open. A server starts listening and returns at once; so does a UDP client (no
        connection to make). A TCP client connects and, as KUKA's EthernetKRL manual says
        ("EKI_Open() interrupts the program run until the connection to the external system
        is active"), returns when its connection is up or TIMEOUT Connect (default 2000 ms)
        has passed on the controller's clock: then EKI00014, the channel closed again.
        `wait()` gives one IPO cycle back while the caller is blocked (the runtime's
        ``block_cycle``: the controller, the main run and the other interpreters go on; the
        hub polls the socket at the cycle's start). A client opened again after its
        connection dropped connects again (the manual: "The connection can be re-opened via
        the EKI_OPEN() function"). docs/network.md "EthernetKRL"."""
        first = not self.opened
        self.opened = True
        if first or self.waits():
            self.hub.eki_opened(self)
        if not self.waits():
            return self.status(), None
        ctl = self.hub.ctl
        timeout_ms = self.cfg.connect_timeout_ms
        self.connecting = True
        try:
            if ctl is not None and wait is not None:
                deadline = ctl.cycle + max(1, ctl.cycles_for(timeout_ms / 1000.0))
                while not self.connected and ctl.cycle < deadline:
                    wait()
        finally:
            self.connecting = False
        if self.connected:
            return self.status(), None
        self.hub.eki_closed(self)
        self.opened = False
        where = self.hub.eki_target(self)
        detail = f"no connection{' to ' + where if where else ''} within TIMEOUT Connect {timeout_ms} ms"
        return self.status(msg_no=14), self.error(14, detail)

    def waits(self) -> bool:
        """True for a TCP client channel that is not connected: EKI_Open waits for it."""
        return not self.cfg.server and self.cfg.protocol == "TCP" and not self.connected

    def close(self) -> Status:
        if self.opened:
            self.hub.eki_closed(self)
            self.opened = False
        self.set_connected(False, "closed by the program")
        return self.status()

    def set_connected(self, on: bool, text: str = "") -> None:
        if on == self.connected:
            return
        self.connected = on
        cfg = self.cfg
        if cfg.alive_flag is not None:
            self.hub.sink.set_flag(cfg.alive_flag, on)
        if cfg.alive_out is not None:
            self.hub.sink.set_out(cfg.alive_out, on)
        if not on:
            if self.framer is not None:
                self.framer.buf.clear()
            self.rawbuf.clear()

    # ------------------------------------------------------------------ events
    def connected_event(self) -> None:
        self.set_connected(True)

    def disconnected_event(self, reason: str) -> None:
        if self.connected:
            self.async_error(512, reason)
        self.set_connected(False, reason)

    def async_error(self, number: int, detail: str) -> None:
        """A message of reception (see the module docstring): traced, given as the next Msg_No."""
        self.async_no = number
        self.hub.net_message(f"EKI{number:05d} {MESSAGES.get(number, '')}: channel {self.name}, {detail}", number)

    def data_event(self, data: bytes) -> list:
        """Split received bytes into messages; returns ``[(bytes | XmlRefused), ...]`` for
        the hub to trace and hand to :meth:`message` (so a replay feeds the same messages)."""
        if self.cfg.receive_kind == "raw":
            return self._raw_frames(data)
        if self.cfg.protocol == "UDP":      # one datagram, one message
            if len(data) > self.cfg.buffsize:
                return [XmlRefused(f"message of {len(data)} bytes, longer than {self.cfg.buffsize}")]
            return [bytes(data)]
        return self.framer.feed(data)

    def _raw_frames(self, data: bytes) -> list:
        el = self.cfg.receive[0]
        self.rawbuf += data
        out: list = []
        limit = min(el.size or self.cfg.buffsize, self.cfg.buffsize)
        if el.eos:
            while True:
                i = self.rawbuf.find(el.eos)
                if i < 0:
                    if len(self.rawbuf) > limit:
                        out.append(XmlRefused(f"record longer than {limit} bytes without its end string"))
                        self.rawbuf.clear()
                    return out
                rec = bytes(self.rawbuf[:i])
                del self.rawbuf[:i + len(el.eos)]
                out.append(rec if len(rec) <= limit else XmlRefused(f"record of {len(rec)} bytes, longer than {limit}"))
        size = el.size or limit
        while len(self.rawbuf) >= size:
            out.append(bytes(self.rawbuf[:size]))
            del self.rawbuf[:size]
        return out

    def message(self, msg: bytes) -> list[tuple[str, int]]:
        """Process one complete message: its elements go into memory (or wait while the
        channel is locked). Returns the (flag|out, n) the message sets."""
        if self.locked:
            self.held.append(msg)
            return []
        self.counter += 1
        if self.cfg.receive_kind == "raw":
            el = self.cfg.receive[0]
            return self._store(el, msg.decode("latin-1"))
        try:
            root = parse(msg, self.cfg.buffsize, f"message on channel {self.name}")
        except XmlRefused as exc:
            self.async_error(1024, str(exc))
            return []
        sets: list[tuple[str, int]] = []
        for el in self.cfg.receive:
            for v in _values(root, el):
                sets += self._store(el, v)
        return sets

    def refused(self, exc: XmlRefused) -> None:
        number = 1536 if "longer than" in str(exc) else 1024
        self.async_error(number, str(exc))

    def _store(self, el: Element, value) -> list[tuple[str, int]]:
        q = self.memory.setdefault(el.tag.upper(), deque())
        if len(q) >= self.cfg.buffering:
            self.async_error(1280, f"element {el.tag}: {self.cfg.buffering} entries")
            return []
        q.append((value, self.counter))
        out = []
        if el.set_flag is not None:
            out.append(("flag", el.set_flag))
        if el.set_out is not None:
            out.append(("out", el.set_out))
        return out

    # ------------------------------------------------------------------ functions
    def check(self, path: str) -> tuple[Status, EkiError | None]:
        """EKI_CheckBuffer: Buff = the entries of the element at `path`."""
        el = self._receive_element(path)
        if el is None:
            return self.status(msg_no=16), self.error(16, f"element {path[:60]}")
        q = self.memory.get(el.tag.upper()) or ()
        return self.status(buff=len(q), counter=q[0][1] if q else 0), None

    def get(self, path: str, n: int | None = None) -> tuple[list, Status, EkiError | None]:
        """EKI_Get*: the oldest entry (or up to `n` entries for an array getter) of the element
        at `path`; (values, status, error). An element whose components are configured as
        attributes (``P/@X`` .. ``P/@C``, no element ``P`` of its own) gives one entry of each
        component's memory as one structure (:meth:`_components`)."""
        el = self._receive_element(path)
        if el is None:
            parts = self._components(self.cfg.receive, path) if self.cfg.receive_kind == "xml" else {}
            if parts:
                return self._get_struct(parts, n)
            return [], self.status(msg_no=16), self.error(16, f"element {path[:60]}")
        q = self.memory.get(el.tag.upper())
        if not q:
            return [], self.status(msg_no=15), self.error(15, f"element {path[:60]}")
        take = 1 if n is None else max(0, min(n, len(q)))
        vals = []
        counter = 0
        for _ in range(take):
            v, counter = q.pop() if self.cfg.lifo else q.popleft()
            vals.append(v)
        return vals, self.status(buff=len(q), read=take, counter=counter), None

    def _get_struct(self, parts: dict[str, Element], n: int | None) -> tuple[list, Status, EkiError | None]:
        queues = {k: self.memory.get(el.tag.upper()) or deque() for k, el in parts.items()}
        have = min(len(q) for q in queues.values())
        if not have:
            name = next(iter(parts.values())).tag.rsplit("/", 1)[0]
            return [], self.status(msg_no=15), self.error(15, f"element {name[:60]}")
        take = 1 if n is None else max(0, min(n, have))
        vals = []
        counter = 0
        for _ in range(take):
            one = {}
            for k, q in queues.items():
                v, c = q.pop() if self.cfg.lifo else q.popleft()
                one[k] = v
                counter = counter or c
            vals.append(one)
        return vals, self.status(buff=have - take, read=take, counter=counter), None

    @staticmethod
    def _components(elements: list[Element], path: str) -> dict[str, Element]:
        """The attributes ``path/@K`` configured for a structure's components K (X, Y, Z, A, B,
        C, S, T, A1..A6, E1..E6): how a channel XML may describe a FRAME, POS or AXIS element
        (WeiminZhang's ConfigApp1.xml, used with EKI_SetFrame/EKI_GetFrame on the element;
        docs/network.md "Decisions")."""
        prefix = path.strip().strip("/").upper() + "/@"
        out = {}
        for e in elements:
            t = e.tag.upper()
            if t.startswith(prefix) and t[len(prefix):] in STRUCT_COMPONENTS:
                out[e.tag[len(prefix):].upper()] = e
        return out

    def clear_buffer(self, path: str) -> tuple[Status, EkiError | None]:
        """EKI_ClearBuffer: empty the memory of `path` and of every element under it (the root
        or ``""``: all)."""
        key = path.strip().upper().rstrip("/")
        for tag in list(self.memory):
            if not key or tag == key or tag.startswith(key + "/"):
                del self.memory[tag]
        return self.status(), None

    def set_value(self, path: str, value) -> tuple[Status, EkiError | None]:
        """EKI_Set*: the send structure's value at `path` (text, or a dict for a FRAME)."""
        if self.cfg.send_kind == "xml" and self.cfg.send_element(path) is None:
            parts = self._components(self.cfg.send, path) if isinstance(value, dict) else {}
            if not parts:
                return self.status(msg_no=16), self.error(16, f"send element {path[:60]}")
            for k, el in parts.items():
                if k in value:
                    self.sendvals[el.tag.upper()] = value[k]
            return self.status(), None
        self.sendvals[path.strip().upper()] = value
        return self.status(), None

    def send(self, data: str, length: int | None = None, raw: bytes | None = None) -> tuple[Status, EkiError | None]:
        """EKI_Send: `data` is a path of the send structure (its part is sent) or, beginning
        with ``<``, an XML string sent as it is; a RAW channel sends the record :meth:`record`
        makes of `raw` (every byte of the CHAR array, NULs included; default `data`'s bytes)."""
        if not self.connected:
            return self.status(msg_no=10), self.error(10, "nothing is connected")
        if self.cfg.send_kind == "raw" or (self.cfg.send_kind is None and self.cfg.receive_kind == "raw"):
            payload = self.record(raw if raw is not None else data.encode("latin-1", "replace"), length)
        elif data.lstrip().startswith("<"):
            payload = data.encode("utf-8")
        else:
            payload = self._build(data)
            if payload is None:
                return self.status(msg_no=16), self.error(16, f"send path {data[:60]}")
        if not payload:
            return self.status(msg_no=19), self.error(19)
        self.hub.eki_send(self, payload)
        return self.status(), None

    def record(self, data: bytes, length: int | None = None) -> bytes:
        """The binary record EKI_Send sends of `data` (a CHAR array's bytes) on a RAW channel
        (KUKA.EthernetKRL 2.2 manual 6.2.4, p. 32-33; 3.x, EKI_Send's LENGTH; docs/network.md
        "Binary records"): an element of fixed length (``Type="BYTE" Size="N"``) sends N bytes,
        NULs included, whatever LENGTH says (the array's first N, padded with NULs when it is
        shorter); an element with an end string (``Type="STREAM" EOS=".."``) sends LENGTH bytes
        of the array when LENGTH is given (NULs included), else the bytes up to its first NUL,
        then the end string."""
        el = (self.cfg.send or self.cfg.receive)[0]
        if el.eos is None and el.size:
            return data[:el.size].ljust(el.size, b"\0")
        if length is not None:
            body = data[:max(0, length)]
        else:
            nul = data.find(b"\0")
            body = data if nul < 0 else data[:nul]
        return body + (el.eos or b"") if body else b""

    def lock(self) -> Status:
        self.locked = True
        return self.status()

    def unlock(self) -> Status:
        self.locked = False
        held, self.held = self.held, []
        for msg in held:
            self.hub.sink.changed_outside()
            self.hub.eki_apply(self, self.message(msg))
        return self.status()

    # ------------------------------------------------------------------ helpers
    def _receive_element(self, path: str) -> Element | None:
        return self.cfg.receive_element(path) if self.cfg.receive_kind == "xml" else (
            self.cfg.receive[0] if self.cfg.receive and self.cfg.receive[0].tag.upper() == path.strip().upper() else None)

    def _build(self, path: str) -> bytes | None:
        """The XML text of the send elements under `path`, with the values set, inside the
        elements above `path` (the document's root down to it); None when nothing is
        configured under `path`."""
        key = path.strip().strip("/")
        keyu = key.upper()
        els = [e for e in self.cfg.send
               if e.tag.upper() == keyu or e.tag.upper().startswith(keyu + "/")]
        if not els or not key:
            return None

        root_name = els[0].tag.split("/")[0]
        root = ET.Element(root_name)
        for e in els:
            parts = e.tag.split("/")
            if parts[0].upper() != root_name.upper():
                continue
            node = root
            attr = None
            for p in parts[1:]:
                if p.startswith("@"):
                    attr = p[1:]
                    break
                found = None
                for c in node:
                    if c.tag.upper() == p.upper():
                        found = c
                        break
                node = found if found is not None else ET.SubElement(node, p)
            v = self.sendvals.get(e.tag.upper())
            if v is None:
                continue
            if isinstance(v, dict):
                for k, x in v.items():
                    node.set(k, x)
            elif attr is not None:
                node.set(attr, v)
            else:
                node.text = v
        # the part under `path` inside its ancestors, its siblings left out (KUKA.EthernetKRL
        # 2.2 manual, EKI_Send's example "Sending part of the XML structure":
        # EKI_Send(CH, "Robot/ActPos") sends <Robot><ActPos X=".."></ActPos></Robot>)
        return ET.tostring(root, encoding="unicode", short_empty_elements=True).encode("utf-8")


def _values(root, el: Element) -> list:
    """The values of configured element `el` in the message `root` (each occurrence)."""
    parts = el.tag.split("/")
    if local(root.tag).upper() != parts[0].upper():
        return []
    nodes = [root]
    attr = None
    for p in parts[1:]:
        if p.startswith("@"):
            attr = p[1:].upper()
            break
        nodes = [c for n in nodes for c in n if local(c.tag).upper() == p.upper()]
        if not nodes:
            return []
    out = []
    for n in nodes:
        if attr is not None:
            for k, v in n.attrib.items():
                if local(k).upper() == attr:
                    out.append(v)
        elif el.type == "FRAME":
            out.append({local(k).upper(): v for k, v in n.attrib.items()})
        else:
            out.append((n.text or "").strip())
    return out


_NAME = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]{0,63}\Z")
CLIENT_RETRY_CYCLES = 8
"""IPO cycles (96 ms) from a refused connection attempt of a client channel to the next one,
while its EKI_Open waits (up to TIMEOUT Connect)."""


class EkiPartner(Partner):
    """EthernetKRL (net/partner.py): the run's EKI channels (``EKI_Init`` creates them, the
    natives of interp/runtime/natives/eki.py call them) and their sockets, one per channel the
    cell file names (``network: {eki: {CHANNEL: {config, address}}}``); the others open none
    and stay "not connected" (docs/network.md "EthernetKRL")."""

    key = "eki"
    fields = {"eki": {}}
    docs = "EthernetKRL"
    opens = ("EKI_INIT", "EKI_LOAD")

    def __init__(self, hub) -> None:
        super().__init__(hub)
        self.channels: dict[str, Channel] = {}
        self.endpoints: dict[str, object] = {}      # CHANNEL (upper) -> net/transport.py endpoint

    # ------------------------------------------------------------------ the protocol
    @classmethod
    def parse(cls, doc, base: Path) -> dict:
        if not isinstance(doc, dict):
            raise SettingsError("network: eki must map channel names to {config, address}")
        if len(doc) > MAX_EKI_CHANNELS:
            raise SettingsError(f"network: eki names {len(doc)} channels, more than {MAX_EKI_CHANNELS}")
        out = {}
        for name, ch in doc.items():
            if not isinstance(name, str) or not _NAME.match(name):
                raise SettingsError(f"network: eki: {str(name)[:40]!r} is not a channel name")
            out[name.upper()] = channel(ch, base, f"network: eki: {name}")
        return {"eki": out}

    def attach(self, ctl, **cell) -> None:
        """Nothing starts before the program's EKI_Open."""

    @property
    def attached(self) -> bool:
        return bool(self.endpoints)

    def sockets(self) -> dict:
        return dict(self.endpoints)

    def poll(self, ctl, live: bool) -> None:
        if not live:
            return
        for name, ep in list(self.endpoints.items()):
            for ev in ep.poll(ctl.time):
                self._event(name, ev)
            if isinstance(ep, transport.TcpClient) and ep.failed:
                ch = self.channels.get(name)
                if ch is None or not ch.connecting:
                    continue
                if ep.retry_cycle is None:          # refused: tried again 8 cycles later while
                    ep.retry_cycle = ctl.cycle + CLIENT_RETRY_CYCLES   # EKI_Open waits (docs/network.md)
                elif ctl.cycle >= ep.retry_cycle:
                    ep.retry_cycle = None
                    ep.start()

    def replay(self, ev: dict) -> None:
        d, name = ev.get("dir"), ev.get("name")
        ch = self.channels.get(str(name).upper()) if name else None
        if ch is None:
            return
        if d == "connect":
            self.trace("eki", "connect", name=ch.name)
            ch.connected_event()
        elif d == "disconnect":
            self.trace("eki", "disconnect", name=ch.name, text=ev.get("text"))
            ch.disconnected_event(ev.get("text") or "closed by the partner")
        elif d == "in":
            self._message(ch, str(ev.get("data", "")).encode("latin-1", "replace"))
        elif d == "error":
            number = int(ev.get("number") or 1024)
            self.trace("eki", "error", name=ch.name, number=number, text=ev.get("text"))
            ch.async_error(number, str(ev.get("text") or ""))

    def close(self) -> None:
        for ep in self.endpoints.values():
            ep.close()
        self.endpoints.clear()

    @classmethod
    def starter(cls, opened: list[tuple[str, str]], root: Path) -> list[str]:
        if not opened:
            return []
        out = ["#   eki:"]
        for name, where in opened:
            path = find_config(name, None, root)
            port, role = 54600, ""
            if path is not None:
                try:
                    cfg = load_config(path, name)
                    port = cfg.port
                    role = "the robot listens; " if cfg.server else "the robot connects to its partner's server; "
                except ConfigError:
                    pass
            note = f"config {path.relative_to(root)}" if path is not None else \
                "no Config/User/Common/EthernetKRL/" + name + ".xml in the backup: name one with config:"
            out.append(f"#     {name}: {{address: 127.0.0.1:{port}}}   # {role}opened at {where}; {note}")
        return out

    # ------------------------------------------------------------------ the hub's services
    @property
    def sink(self):
        return self.hub.sink

    @property
    def ctl(self):
        return self.hub.ctl

    def trace(self, iface: str, direction: str, **fields) -> None:
        self.hub.trace(iface, direction, **fields)

    def net_message(self, text: str, number: int | None = None) -> None:
        self.hub.net_message(text, number)

    # ------------------------------------------------------------------ events
    def _event(self, name: str, ev: tuple) -> None:
        ch = self.channels.get(name)
        if ch is None:
            return
        kind = ev[0]
        if kind == "connect":
            self.trace("eki", "connect", name=ch.name)
            ch.connected_event()
        elif kind == "refused":
            self.trace("eki", "refused", name=ch.name, text="a second partner: closed (one client per server)")
        elif kind == "foreign":
            self.trace("eki", "error", name=ch.name,
                       text=f"a datagram from {ev[1][0]}:{ev[1][1]}, not the channel's partner: ignored")
        elif kind == "disconnect":
            self.trace("eki", "disconnect", name=ch.name, text=ev[1])
            ch.disconnected_event(ev[1])
        elif kind == "data":
            for msg in ch.data_event(ev[1]):
                self._message(ch, msg)

    def _message(self, ch: Channel, msg) -> None:
        if isinstance(msg, XmlRefused):
            number = 1536 if "longer than" in str(msg) else 1024
            self.trace("eki", "error", name=ch.name, number=number, text=str(msg))
            ch.async_error(number, str(msg))
            return
        self.trace("eki", "in", name=ch.name, data=msg.decode("latin-1"))
        self.sink.changed_outside()     # the channel's memory changes: EKI_CheckBuffer, EKI_Get*
        self.eki_apply(ch, ch.message(msg))

    # ------------------------------------------------------------------ the EKI functions
    def init(self, name: str) -> Channel:
        """EKI_Init: the channel `name` from its configuration. Raises :class:`EkiError`."""
        key = name.strip().upper()
        if key in self.channels:
            raise EkiError(23, f"channel {name}", self.channels[key].cfg.display)
        if len(self.channels) >= MAX_EKI_CHANNELS:
            raise EkiError(25, f"{MAX_EKI_CHANNELS} channels")
        settings = self.hub.settings
        setting = settings.eki.get(key) if settings is not None else None
        path = setting.config if setting is not None and setting.config is not None else \
            find_config(name.strip(), self.hub.program, self.hub.backup)
        if path is None:
            raise EkiError(3, f"channel {name}: no {name.strip()}.xml in the backup's "
                              "Config/User/Common/EthernetKRL nor beside the program")
        try:
            cfg = load_config(path, name.strip())
        except ConfigError as exc:
            raise EkiError(3 if exc.missing else 22, str(exc)) from None
        ch = Channel(self, cfg)
        self.channels[key] = ch
        return ch

    def channel(self, name: str) -> Channel:
        """The channel `name` (EKI_Open, EKI_Send, ...). Raises EkiError 9 for one never initialized."""
        ch = self.channels.get(name.strip().upper())
        if ch is None:
            raise EkiError(9, f"channel {name.strip()[:40]}")
        return ch

    def clear(self, name: str) -> None:
        """EKI_Clear: the channel closed and deleted."""
        ch = self.channel(name)
        ch.close()
        del self.channels[ch.name.upper()]

    def eki_opened(self, ch: Channel) -> None:
        """EKI_Open: the channel's socket, when the settings name the channel (else it stays
        "not connected"). A client channel opened again (its connection dropped, or its last
        attempt failed) gets a new connection attempt."""
        key = ch.name.upper()
        s = self.hub.settings
        if s is None or key not in s.eki:
            return
        if not s.live:
            return
        old = self.endpoints.pop(key, None)
        if old is not None:
            old.close()
        cfg = ch.cfg
        host, port = self.address(ch)
        try:
            if cfg.protocol == "UDP":
                ep = transport.Udp(host, port) if cfg.server else transport.Udp(LOOPBACK, 0, (host, port))
            elif cfg.server:
                ep = transport.TcpServer(host, port, MAX_EKI_IDLE_S)
            else:
                ep = transport.TcpClient(host, port)
        except OSError as exc:
            raise EkiError(24, f"channel {ch.name}: {host}:{port}: {exc.strerror or exc}", cfg.display) from None
        self.endpoints[key] = ep
        if cfg.server:
            self.hub.published("eki:" + ch.name, ep.address)
        if cfg.protocol == "UDP" and not cfg.server:
            ch.connected_event()

    def address(self, ch: Channel) -> tuple[str, int]:
        """Where channel `ch` listens (a server) or connects to (a client): the cell file's
        address, else loopback at the XML's port (docs/network.md "The cell file")."""
        s = self.hub.settings
        setting = s.eki.get(ch.name.upper()) if s is not None else None
        addr = setting.address if setting is not None else None
        return addr if addr is not None else (LOOPBACK, ch.cfg.port)

    def eki_target(self, ch: Channel) -> str:
        """``host:port`` a client channel connects to, "" when no socket is opened for it."""
        s = self.hub.settings
        if ch.name.upper() not in self.endpoints and (s is None or ch.name.upper() not in s.eki):
            return ""
        host, port = self.address(ch)
        return f"{host}:{port}"

    def eki_closed(self, ch: Channel) -> None:
        ep = self.endpoints.pop(ch.name.upper(), None)
        if ep is not None:
            ep.close()

    def eki_send(self, ch: Channel, payload: bytes) -> None:
        self.trace("eki", "out", name=ch.name, data=payload.decode("latin-1"))
        ep = self.endpoints.get(ch.name.upper())
        if ep is not None and not ep.send(payload):
            self.trace("eki", "disconnect", name=ch.name, text="send failed")
            ch.disconnected_event("send failed")

    def eki_apply(self, ch: Channel, sets: list) -> None:
        """A message's ``Set_Flag``/``Set_Out``: through the controller's write rules (the sink's
        set_flag/set_out, interp/runtime/writerules.py); a refusal is an error event."""
        for what, n in sets:
            try:
                if what == "flag":
                    self.sink.set_flag(n, True)
                else:
                    self.sink.set_out(n, True)
            except Exception as exc:  # noqa: BLE001 - the write rules' refusal (a KRL run-time error) of this one write
                self.trace("eki", "error", name=ch.name, text=f"{'$FLAG' if what == 'flag' else '$OUT'}[{n}]: {exc}")

