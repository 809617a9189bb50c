"""KukaVarProxy: the OpenShowVar protocol on TCP (docs/network.md "KukaVarProxy").

Service tools (py-openshowvar, JOpenShowVar, kukavarproxy clients) read and write the
controller's global variables by name through KukaVarProxy, a program on the controller that
listens on TCP port 7000. Every request and answer is one binary message, big-endian::

    request:  msg_id u16 | length u16 | mode u8 (0 read, 1 write) | name_len u16 | name
              [| value_len u16 | value]                                   (write only)
    answer:   msg_id u16 | length u16 | mode u8 | value_len u16 | value | 00 01 ok

``length`` counts the bytes after it; ``ok`` is 01 when the variable was read or written, 00
when it was not (an unknown name, a value that is not a literal, a read-only variable). The
value is the controller's text of the variable (interp/runtime/netvars.py): ``100`` for
``$OV_PRO``, ``{E6POS: X 1.5, ...}`` for ``$POS_ACT``. Requests are answered at the start of
the next IPO cycle (the variable as the program left it at the end of the last one); a write
is seen by the program's next statement.

Limits (krl/limits.py): :data:`~krl.limits.MAX_VARPROXY_CLIENTS` clients at once (more are
closed at once), :data:`~krl.limits.MAX_VARPROXY_REQUESTS_PER_CYCLE` requests answered per
client and cycle; the rest wait: a client's socket is read only while less than
:data:`BUFFERED` bytes of its requests wait to be answered, so a client sending faster than
that waits in the kernel's buffer (TCP's own back-pressure), and nothing it sent is dropped
(5,000 reads sent back to back were answered 16, then the connection dropped, issue 61). Names
and values are bounded; a request that breaks the format closes that client's connection, and
so does a client that does not read its answers (``transport.SEND_BUFFER_LIMIT``): each with a
``net`` error event saying why.
"""

from __future__ import annotations

from pathlib import Path
import struct

from krl.limits import (MAX_VARPROXY_CLIENTS, MAX_VARPROXY_NAME_CHARS, MAX_VARPROXY_REQUESTS_PER_CYCLE,
                        MAX_VARPROXY_VALUE_CHARS)

from .cellkey import parse_address
from .partner import Partner
from .transport import Endpoint, listen

OK = b"\x00\x01\x01"
FAILED = b"\x00\x01\x00"
#: the longest request (its header, a name and a value at their limits)
MAX_REQUEST = 9 + MAX_VARPROXY_NAME_CHARS + MAX_VARPROXY_VALUE_CHARS
#: a client's socket is read while fewer bytes than this of its requests wait to be answered
BUFFERED = 2 * MAX_REQUEST


class BadRequest(ValueError):
    pass


def parse_request(buf: bytearray):
    """(msg_id, mode, name, value or None, size) of the first complete request in `buf`, or None
    when it is incomplete. Raises :class:`BadRequest` for a request outside the format."""
    if len(buf) < 4:
        return None
    msg_id, length = struct.unpack_from("!HH", buf, 0)
    if length < 3 or length > 5 + MAX_VARPROXY_NAME_CHARS + MAX_VARPROXY_VALUE_CHARS:
        raise BadRequest(f"request length {length}")
    if len(buf) < 4 + length:
        return None
    body = bytes(buf[4:4 + length])
    mode = body[0]
    (nlen,) = struct.unpack_from("!H", body, 1)
    if mode not in (0, 1) or nlen == 0 or nlen > MAX_VARPROXY_NAME_CHARS or 3 + nlen > len(body):
        raise BadRequest(f"mode {mode}, name of {nlen} bytes")
    name = body[3:3 + nlen].decode("latin-1")
    value = None
    if mode == 1:
        rest = body[3 + nlen:]
        if len(rest) < 2:
            raise BadRequest("a write without its value")
        (vlen,) = struct.unpack_from("!H", rest, 0)
        if vlen > MAX_VARPROXY_VALUE_CHARS or 2 + vlen > len(rest):
            raise BadRequest(f"value of {vlen} bytes")
        value = rest[2:2 + vlen].decode("latin-1")
    return msg_id, mode, name, value, 4 + length


def answer(msg_id: int, mode: int, value: str, ok: bool) -> bytes:
    v = value.encode("latin-1", "replace")[:MAX_VARPROXY_VALUE_CHARS]
    body = struct.pack("!BH", mode, len(v)) + v + (OK if ok else FAILED)
    return struct.pack("!HH", msg_id, len(body)) + body


class _Client(Endpoint):
    def __init__(self, conn, peer) -> None:
        super().__init__()
        conn.setblocking(False)
        self.conn = conn
        self.peer = peer
        self.buf = bytearray()


class VarProxy:
    """The KukaVarProxy server of a run, on `address` (host, port)."""

    def __init__(self, hub, address: tuple[str, int]) -> None:
        self.hub = hub
        self.sock = listen(address[0], address[1], MAX_VARPROXY_CLIENTS)
        self.address = self.sock.getsockname()[:2]
        self.clients: list[_Client] = []

    def poll(self) -> None:
        while True:
            try:
                c, peer = self.sock.accept()
            except (BlockingIOError, InterruptedError, OSError):
                break
            if len(self.clients) >= MAX_VARPROXY_CLIENTS:
                c.close()
                self.hub.trace("varproxy", "refused", text=f"more than {MAX_VARPROXY_CLIENTS} clients")
                continue
            self.clients.append(_Client(c, peer[:2]))
            self.hub.trace("varproxy", "connect")
        for cl in list(self.clients):
            events: list = []
            if len(cl.buf) < BUFFERED:          # else the requests wait in the kernel's buffer
                cl._read(events)
            for ev in events:
                if ev[0] == "data":
                    cl.buf += ev[1]
            done = 0
            while done < MAX_VARPROXY_REQUESTS_PER_CYCLE and cl.conn is not None:
                try:
                    req = parse_request(cl.buf)
                except BadRequest as exc:
                    self.hub.trace("varproxy", "error", text=f"bad request ({exc}): connection closed")
                    cl._drop(events, "bad request")
                    break
                if req is None:
                    break
                msg_id, mode, name, value, size = req
                del cl.buf[:size]
                if not cl.send(self.handle(msg_id, mode, name, value)):
                    self.hub.trace("varproxy", "error", text=f"{cl.dropped}: connection closed")
                done += 1
            if cl.conn is None or any(e[0] == "disconnect" for e in events):
                self.hub.trace("varproxy", "disconnect", text=cl.dropped or "closed")
                cl.close()
                self.clients.remove(cl)

    def handle(self, msg_id: int, mode: int, name: str, value: str | None) -> bytes:
        """Answer one request (and trace it)."""
        text, ok = request(self.hub, mode, name, value)
        return answer(msg_id, mode, text, ok)

    def close(self) -> None:
        for cl in self.clients:
            cl.close()
        self.clients = []
        try:
            self.sock.close()
        except OSError:
            pass


def request(hub, mode: int, name: str, value: str | None) -> tuple[str, bool]:
    """Read (mode 0) or write (mode 1) a variable through the hub's sink; traced."""
    hub.trace("varproxy", "in", data=("read " + name) if mode == 0 else f"write {name} {value}")
    try:
        text = hub.sink.read_var(name) if mode == 0 else hub.sink.write_var(name, value or "")
        ok = True
    except Exception as exc:  # noqa: BLE001 - any refusal of the runtime is an answer "not ok"
        text, ok = "", False
        hub.trace("varproxy", "error", text=f"{name[:60]}: {str(exc)[:100]}")
    hub.trace("varproxy", "out", data=text)
    return text, ok


def replay_request(hub, ev: dict) -> None:
    """A recorded request, applied again (its answer goes nowhere but the trace)."""
    parts = str(ev.get("data", "")).split(" ", 2)
    if len(parts) >= 2 and parts[0] in ("read", "write"):
        request(hub, 0 if parts[0] == "read" else 1, parts[1], parts[2] if len(parts) > 2 else "")


class VarProxyPartner(Partner):
    """KukaVarProxy (net/partner.py): its server on the cell file's ``network: {varproxy:
    HOST:PORT}``, requests answered at each IPO cycle's start (docs/network.md "KukaVarProxy")."""

    key = "varproxy"
    fields = {"varproxy": None}
    docs = "KukaVarProxy"

    def __init__(self, hub) -> None:
        super().__init__(hub)
        self.server: VarProxy | None = None

    @classmethod
    def parse(cls, doc, base: Path) -> dict:
        return {"varproxy": parse_address(doc, "network: varproxy")}

    def attach(self, ctl, **cell) -> None:
        s = self.hub.settings
        if s is not None and s.varproxy is not None:
            self.server = VarProxy(self.hub, s.varproxy)
            self.hub.published("varproxy", self.server.address)

    @property
    def attached(self) -> bool:
        return self.server is not None

    def poll(self, ctl, live: bool) -> None:
        if live and self.server is not None:
            self.server.poll()

    def replay(self, ev: dict) -> None:
        if ev.get("dir") == "in":
            replay_request(self.hub, ev)

    def close(self) -> None:
        if self.server is not None:
            self.server.close()
