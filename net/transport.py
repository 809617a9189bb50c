"""Sockets of the network partners, polled once per IPO cycle (no threads).

Each endpoint is non-blocking and is read only in :meth:`Endpoint.poll`, which the network hub
(net/hub.py) calls at the start of an IPO cycle: what arrived since the last cycle arrives in
this one. A poll reads at most :data:`~krl.limits.MAX_NET_BYTES_PER_CYCLE` bytes per
connection (a flood waits in the kernel's buffer), and a connection whose partner does not read
what the controller sends is dropped once its send buffer passes its limit.

Each endpoint's ``poll(now)`` (`now`: the controller's time, for a server's idle partner) returns
events: ``("connect", peer)``, ``("data", bytes)``, ``("disconnect", reason)``,
``("refused", peer)`` (a second client of a one-client server: closed at once, as EthernetKRL
does), ``("foreign", peer)`` (a datagram to a UDP client from another address than its partner's:
not delivered). Servers bind where they are told; net/settings.py makes that loopback unless the cell
file names another address.
"""

from __future__ import annotations

import errno
import socket

from krl.limits import MAX_NET_BYTES_PER_CYCLE, MAX_RSI_DATAGRAM_BYTES, MAX_RSI_DATAGRAMS_PER_CYCLE

SEND_BUFFER_LIMIT = 1024 * 1024
"""Bytes the controller holds for a partner that does not read (then the connection drops)."""


def listen(host: str, port: int, backlog: int) -> socket.socket:
    """A non-blocking TCP socket listening on (host, port). Raises OSError (a port in use)."""
    s = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_STREAM)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        s.bind((host, port))
        s.listen(backlog)
    except OSError:
        s.close()
        raise
    s.setblocking(False)
    return s


class Endpoint:
    """The common part: ``address`` (host, port) bound or connected to, ``peer``, ``connected``."""

    def __init__(self) -> None:
        self.sock: socket.socket | None = None
        self.conn: socket.socket | None = None
        self.address: tuple[str, int] | None = None
        self.peer: tuple[str, int] | None = None
        self.out = bytearray()
        self.dropped: str | None = None     # why the connection was dropped last (a send may drop it)

    @property
    def connected(self) -> bool:
        return self.conn is not None

    def _drop(self, events: list, reason: str) -> None:
        if self.conn is not None:
            try:
                self.conn.close()
            except OSError:
                pass
            self.conn = None
            self.out.clear()
            self.dropped = reason
            events.append(("disconnect", reason))

    def _read(self, events: list) -> None:
        conn = self.conn
        got = 0
        while conn is not None and got < MAX_NET_BYTES_PER_CYCLE:
            try:
                data = conn.recv(min(65536, MAX_NET_BYTES_PER_CYCLE - got))
            except (BlockingIOError, InterruptedError):
                break
            except OSError as exc:
                self._drop(events, f"connection error ({exc.strerror or exc})")
                return
            if not data:
                self._drop(events, "closed by the partner")
                return
            got += len(data)
            events.append(("data", data))

    def _flush(self, events: list) -> None:
        while self.conn is not None and self.out:
            try:
                n = self.conn.send(self.out)
            except (BlockingIOError, InterruptedError):
                break
            except OSError as exc:
                self._drop(events, f"connection error ({exc.strerror or exc})")
                return
            del self.out[:n]
        if len(self.out) > SEND_BUFFER_LIMIT:
            self._drop(events, "the partner does not read what is sent")

    def send(self, data: bytes) -> bool:
        """Queue `data` for the partner and send what the socket takes now; False when not
        connected."""
        if self.conn is None:
            return False
        self.out += data
        events: list = []
        self._flush(events)
        return self.conn is not None

    def close(self) -> None:
        for s in (self.conn, self.sock):
            if s is not None:
                try:
                    s.close()
                except OSError:
                    pass
        self.conn = None
        self.sock = None


class TcpServer(Endpoint):
    """Listens on (host, port) and takes one partner at a time. A poll first reads the partner
    (so that its close is noticed before a new connection is looked at: a partner reconnecting
    right after a close is taken, not refused), then accepts. `idle_s` (None: never): a partner
    that has sent nothing for that long, on the clock of the `now` given to :meth:`poll`, gives
    its place to a new one that connects (``("disconnect", "idle ...")`` then ``connect``); any
    other second partner is refused."""

    def __init__(self, host: str, port: int, idle_s: float | None = None) -> None:
        super().__init__()
        self.sock = listen(host, port, 4)
        self.address = self.sock.getsockname()[:2]
        self.idle_s = idle_s
        self.heard = 0.0            # when the partner last sent something (or connected)

    def poll(self, now: float = 0.0) -> list:
        events: list = []
        self._flush(events)
        n = len(events)
        self._read(events)
        if any(e[0] == "data" for e in events[n:]):
            self.heard = now
        while self.sock is not None:
            try:
                c, peer = self.sock.accept()
            except (BlockingIOError, InterruptedError):
                break
            except OSError:
                break
            peer = peer[:2]
            if self.conn is not None:
                if self.idle_s is None or now - self.heard < self.idle_s:
                    c.close()
                    events.append(("refused", peer))
                    continue
                self._drop(events, f"idle for {now - self.heard:.1f} s: a new partner took the channel")
            c.setblocking(False)
            c.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self.conn, self.peer, self.heard = c, peer, now
            events.append(("connect", peer))
        return events


class TcpClient(Endpoint):
    """Connects to (host, port) without blocking; the connection completes at a later poll."""

    def __init__(self, host: str, port: int) -> None:
        super().__init__()
        self.target = (host, port)
        self.address = self.target
        self.pending: socket.socket | None = None
        self.failed: str | None = None
        self.retry_cycle: int | None = None     # the next attempt after a refusal (net/eki.py)
        self.start()

    def start(self) -> None:
        """A (new) connection attempt; a refusal shows as :attr:`failed`."""
        if self.pending is not None:
            self.pending.close()
            self.pending = None
        s = socket.socket(socket.AF_INET6 if ":" in self.target[0] else socket.AF_INET, socket.SOCK_STREAM)
        s.setblocking(False)
        err = s.connect_ex(self.target)
        if err not in (0, errno.EINPROGRESS, errno.EWOULDBLOCK, errno.EALREADY):
            s.close()
            self.pending = None
            self.failed = f"connection refused ({errno.errorcode.get(err, err)})"
            return
        self.failed = None
        self.pending = s

    def poll(self, now: float = 0.0) -> list:
        events: list = []
        p = self.pending
        if p is not None:
            err = p.getsockopt(socket.SOL_SOCKET, socket.SO_ERROR)
            if err == 0:
                try:
                    p.getpeername()
                    ok = True
                except OSError:
                    ok = False
                if ok:
                    p.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                    self.conn, self.peer, self.pending = p, self.target, None
                    events.append(("connect", self.target))
            elif err not in (errno.EINPROGRESS, errno.EALREADY):
                p.close()
                self.pending = None
                self.failed = f"connection refused ({errno.errorcode.get(err, err)})"
        self._flush(events)
        self._read(events)
        return events

    def close(self) -> None:
        if self.pending is not None:
            self.pending.close()
            self.pending = None
        super().close()


class Udp(Endpoint):
    """A UDP socket bound to (host, port). As a server its partner is the last sender (the
    first datagram "connects"); as a client it sends to `target` and takes datagrams from that
    address only: one from anywhere else is a ``("foreign", peer)`` event, its bytes not
    delivered (issue 61: an RSI sensor is the configured address and port; three answers sent
    from another local port moved the robot)."""

    def __init__(self, host: str, port: int, target: tuple[str, int] | None = None,
                 limit: int = MAX_RSI_DATAGRAM_BYTES) -> None:
        super().__init__()
        s = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_DGRAM)
        try:
            s.bind((host, port))
        except OSError:
            s.close()
            raise
        s.setblocking(False)
        self.sock = s
        self.limit = limit
        self.address = s.getsockname()[:2]
        if target is not None:              # the address datagrams come from: numeric, as recvfrom gives it
            try:
                target = socket.getaddrinfo(target[0], target[1], s.family, socket.SOCK_DGRAM)[0][4][:2]
            except (OSError, UnicodeError):
                pass                        # sendto will fail as it would have: nothing arrives from it
        self.peer = target
        self.client = target is not None

    @property
    def connected(self) -> bool:
        return self.peer is not None

    def poll(self, now: float = 0.0) -> list:
        events: list = []
        for _ in range(MAX_RSI_DATAGRAMS_PER_CYCLE):
            try:
                data, peer = self.sock.recvfrom(self.limit + 1)
            except (BlockingIOError, InterruptedError):
                break
            except OSError:
                break           # e.g. ICMP port unreachable of an earlier send
            peer = peer[:2]
            if self.peer is None:
                self.peer = peer
                events.append(("connect", peer))
            elif peer != self.peer:
                if self.client:
                    events.append(("foreign", peer))
                    continue
                self.peer = peer
            events.append(("data", data))
        return events

    def send(self, data: bytes) -> bool:
        if self.peer is None or self.sock is None:
            return False
        try:
            self.sock.sendto(data, self.peer)
        except OSError:
            return False
        return True
