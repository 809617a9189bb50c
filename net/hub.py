"""The network hub of one run: every partner on one clock (docs/network.md, "One clock").

The simulated controller calls :meth:`Network.cycle` at the start of every IPO cycle
(robot/controller.py ``Controller.step``). There the hub

1. paces the run to the wall clock while a partner is attached (:class:`Pacer`: cycle k
   starts no earlier than k·12 ms / pace after the first attached cycle; a run with no socket
   open never sleeps and stays as fast and as deterministic as without the network);
2. polls every socket once (net/transport.py) — or, replaying a recording, takes the events
   the recorded trace holds for this cycle — and hands each event to its interface: EKI
   channels (net/eki.py), the RSI object (net/rsi.py), KukaVarProxy (net/varproxy.py), the
   PLC's requests (net/plc.py);
3. writes a ``net`` trace event for every message that arrives or leaves, with its simulated
   time, so a trace is also a recording: ``network: {replay: trace.jsonl}`` feeds the same
   messages at the same cycles, with no socket, and both interpreters give the same trace.

The runtime talks to the hub through its EKI/RSI built-ins (interp/runtime/natives/eki.py, rsi.py)
and gives it a *sink*: ``set_flag(n, v)``, ``set_out(n, v)``, ``read_var(name) -> text``,
``write_var(name, text) -> text`` (interp/runtime/netvars.py).
"""

from __future__ import annotations

import threading
import time
from pathlib import Path
import json

from krl.limits import MAX_EKI_CHANNELS, MAX_NET_REPLAY_BYTES, MAX_NET_REPLAY_EVENTS

from . import transport
from .ekiconfig import ConfigError, find_config, load_config
from .eki import Channel, EkiError
from .settings import LOOPBACK, NetworkSettings
from .xmlsafe import XmlRefused
from .varproxy import VarProxy, replay_request


class Pacer:
    """Wall-clock pacing: :meth:`wait` returns when cycle `k` may start. A run that falls more
    than :data:`REANCHOR_S` behind (a debugger pause, an overloaded machine) is paced again
    from now on, instead of racing to catch up; `behind` keeps the largest lag seen (s)."""

    REANCHOR_S = 0.5

    def __init__(self, dt: float, pace: float = 1.0) -> None:
        self.dt = dt
        self.pace = pace
        self.k0: int | None = None
        self.t0 = 0.0
        self.behind = 0.0       # the largest lag behind the wall clock seen (s)

    def wait(self, k: int) -> None:
        now = time.monotonic()
        if self.k0 is None:
            self.k0, self.t0 = k, now
            return
        target = self.t0 + (k - self.k0) * self.dt / self.pace
        if target > now:
            time.sleep(target - now)
            return
        self.behind = max(self.behind, now - target)
        if now - target > self.REANCHOR_S:
            self.k0, self.t0 = k, now


class NullSink:
    """The sink of a hub without a runtime (tests of the protocols alone)."""

    def __init__(self) -> None:
        self.flags: dict[int, bool] = {}
        self.outs: dict[int, bool] = {}

    def set_flag(self, n: int, v: bool) -> None:
        self.flags[n] = v

    def set_out(self, n: int, v: bool) -> None:
        self.outs[n] = v

    def read_var(self, name: str) -> str:
        raise KeyError(name)

    def write_var(self, name: str, text: str) -> str:
        raise KeyError(name)


class NetError(Exception):
    """A partner that cannot be started (a port in use, a bad configuration): a clear error."""


class Network:
    """The partners of one run. `settings` None: no partner (channels stay "not connected").
    `program`/`backup`: where EKI configurations are looked up. `sink`: see the module docstring."""

    def __init__(self, settings: NetworkSettings | None = None, *, program: Path | None = None,
                 backup: Path | None = None, sink=None) -> None:
        self.settings = settings
        self.program = Path(program) if program is not None else None
        self.backup = Path(backup) if backup is not None else None
        self.sink = sink if sink is not None else NullSink()
        self.ctl = None
        self.channels: dict[str, Channel] = {}
        self.endpoints: dict[tuple[str, str], object] = {}     # (iface, name) -> Endpoint
        self.pacer: Pacer | None = None
        self.replay: dict[int, list[dict]] | None = None
        self.varproxy = None
        self.rsi = None
        self.plc = None
        self.addresses: dict[str, tuple[str, int]] = {}        # "eki:NAME" / "varproxy" / ... -> bound
        self.ready = threading.Condition()
        self.listen_hook = None     # listen_hook(key, (host, port)) when a server starts (krl run says where)
        self.closed = False
        # the controller calls cycle() only while this is True: partners configured, a replay,
        # or RSI on; a run without any costs one attribute test per IPO cycle
        self.polling = settings is not None
        if settings is not None and settings.replay is not None:
            self.replay_events = load_replay(settings.replay)

    # ------------------------------------------------------------------ lifecycle
    def attach(self, ctl, plc_map=None) -> None:
        """Bind to the controller `ctl` and start the servers the settings name (KukaVarProxy,
        the PLC with the address map `plc_map`, net/plc.py). Raises OSError when one cannot
        start (a port in use)."""
        self.ctl = ctl
        ctl.network = self
        if getattr(self, "replay_events", None) is not None:
            self.replay = {}
            for t, ev in self.replay_events:
                self.replay.setdefault(int(round(t / ctl.dt)), []).append(ev)
        s = self.settings
        if s is None or not s.live:
            return
        if s.varproxy is not None:

            self.varproxy = VarProxy(self, s.varproxy)
            self.published("varproxy", self.varproxy.address)
        if s.modbus is not None or s.opcua is not None:
            from .plc import Plc  # noqa: PLC0415  (asyncio: costs 0.04 s at every krl run; only with a PLC)

            self.plc = Plc(self, s, plc_map)
            self.plc.start()

    @property
    def attached(self) -> bool:
        """True while a partner may be connected: a socket is open (the run is paced)."""
        return bool(self.endpoints) or self.varproxy is not None or self.plc is not None or \
            (self.rsi is not None and self.rsi.endpoint is not None)

    def may_change(self) -> bool:
        """True when something outside the program can still change its inputs (for the
        deadlock test of WAIT FOR): a partner attached, or a replay not yet over."""
        if self.attached:
            return True
        if self.replay and self.ctl is not None:
            return any(k >= self.ctl.cycle for k in self.replay)
        return False

    def next_event_cycle(self, k: int) -> int | None:
        """The first IPO cycle after cycle `k` in which a message can arrive (the idle
        fast-forward, interp/runtime/idle.py, never jumps past it): the next one while a
        partner is attached (it runs on the wall clock) or an RSI object is on (each cycle
        has its exchange, or its late packet), the next recorded cycle of a replay, None
        when nothing can arrive."""
        if self.attached or (self.rsi is not None and self.rsi.on):
            return k + 1
        later = [c for c in self.replay if c > k] if self.replay else []
        return min(later) if later else None

    def close(self) -> None:
        """Close every socket and stop the servers (the run ended; EKI channels of
        ENVIRONMENT Program are deleted at a program's end)."""
        if self.closed:
            return
        self.closed = True
        for ep in self.endpoints.values():
            ep.close()
        self.endpoints.clear()
        if self.varproxy is not None:
            self.varproxy.close()
        if self.rsi is not None:
            self.rsi.close()
        if self.plc is not None:
            self.plc.close()

    def published(self, key: str, address) -> None:
        """Record where a server listens (tests and the run's message read it)."""
        with self.ready:
            self.addresses[key] = tuple(address[:2])
            self.ready.notify_all()
        if self.listen_hook is not None:
            self.listen_hook(key, tuple(address[:2]))
        if self.ctl is not None:
            self.net_message(f"{key} listening on {address[0]}:{address[1]}")

    def wait_address(self, key: str, timeout: float = 300.0):
        """The address `key` listens on, waiting for it up to `timeout` s (another thread);
        None when it is not published by then. The default is generous: the OPC UA server
        builds its address space first (seconds of CPU), and on a loaded machine that took
        over 30 s (load 40 on 2 cores, 2026-11-24). Waiting longer costs nothing when it is up."""
        end = time.monotonic() + timeout
        with self.ready:
            while key not in self.addresses and not self.closed:
                left = end - time.monotonic()
                if left <= 0:
                    return None
                self.ready.wait(left)
            return self.addresses.get(key)

    # ------------------------------------------------------------------ the cycle
    def cycle(self, ctl) -> None:
        """Start of IPO cycle ``ctl.cycle`` (see the module docstring)."""
        if self.replay is not None:
            for ev in self.replay.pop(ctl.cycle, ()):
                self._replayed(ev)
            if self.rsi is not None:
                self.rsi.cycle(ctl, live=False)
            return
        if not self.attached:
            if self.rsi is not None and self.rsi.on:
                self.rsi.cycle(ctl, live=False)     # no sensor: every packet is late
            return
        if self.pacer is None:
            pace = self.settings.pace if self.settings is not None else 1.0
            self.pacer = Pacer(ctl.dt, pace)
        self.pacer.wait(ctl.cycle)
        for (iface, name), ep in list(self.endpoints.items()):
            for ev in ep.poll():
                self._event(iface, name, ev)
        if self.varproxy is not None:
            self.varproxy.poll()
        if self.plc is not None:
            self.plc.sync()
        if self.rsi is not None:
            self.rsi.cycle(ctl, live=True)

    def _event(self, iface: str, name: str, ev: tuple) -> None:
        kind = ev[0]
        if iface == "eki":
            ch = self.channels.get(name)
            if ch is None:
                return
            if kind == "connect":
                self.trace("eki", "connect", name=ch.name)
                ch.connected_event()
            elif kind == "refused":
                self.trace("eki", "refused", name=ch.name, text="a second partner: closed (one client per server)")
            elif kind == "disconnect":
                self.trace("eki", "disconnect", name=ch.name, text=ev[1])
                ch.disconnected_event(ev[1])
            elif kind == "data":
                for msg in ch.data_event(ev[1]):
                    self._eki_message(ch, msg)

    def _eki_message(self, ch: Channel, msg) -> None:
        if isinstance(msg, XmlRefused):
            number = 1536 if "longer than" in str(msg) else 1024
            self.trace("eki", "error", name=ch.name, number=number, text=str(msg))
            ch.async_error(number, str(msg))
            return
        self.trace("eki", "in", name=ch.name, data=msg.decode("latin-1"))
        self.eki_apply(ch, ch.message(msg))

    def _replayed(self, ev: dict) -> None:
        iface, d, name = ev.get("iface"), ev.get("dir"), ev.get("name")
        if iface == "eki":
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
                self._eki_message(ch, str(ev.get("data", "")).encode("latin-1", "replace"))
            elif d == "error":
                number = int(ev.get("number") or 1024)
                self.trace("eki", "error", name=ch.name, number=number, text=ev.get("text"))
                ch.async_error(number, str(ev.get("text") or ""))
        elif iface == "varproxy" and d == "in":

            replay_request(self, ev)
        elif iface == "plc" and d == "in":
            from .plc import replay_write  # noqa: PLC0415  (costs 0.04 s: asyncio, only on a PLC replay)

            replay_write(self, ev)
        elif iface == "rsi" and self.rsi is not None:
            self.rsi.replayed(ev)

    # ------------------------------------------------------------------ EKI
    def eki_init(self, name: str) -> Channel:
        """EKI_Init: the channel `name` from its configuration. Raises :class:`EkiError`."""
        key = name.strip().upper()
        if key in self.channels:
            raise EkiError(23, f"channel {name}", self.channels[key].cfg.display)
        if len(self.channels) >= MAX_EKI_CHANNELS:
            raise EkiError(25, f"{MAX_EKI_CHANNELS} channels")
        setting = self.settings.eki.get(key) if self.settings is not None else None
        path = setting.config if setting is not None and setting.config is not None else \
            find_config(name.strip(), self.program, self.backup)
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

    def eki_channel(self, name: str) -> Channel:
        ch = self.channels.get(name.strip().upper())
        if ch is None:
            raise EkiError(9, f"channel {name.strip()[:40]}")
        return ch

    def eki_clear(self, name: str) -> None:
        ch = self.eki_channel(name)
        ch.close()
        del self.channels[ch.name.upper()]

    def eki_opened(self, ch: Channel) -> None:
        """EKI_Open: the channel's socket, when the settings name the channel (else it stays
        "not connected")."""
        key = ch.name.upper()
        s = self.settings
        if s is None or key not in s.eki:
            return
        if not s.live:
            return
        cfg = ch.cfg
        addr = s.eki[key].address
        host, port = addr if addr is not None else (LOOPBACK, cfg.port)
        try:
            if cfg.protocol == "UDP":
                ep = transport.Udp(host, port) if cfg.server else transport.Udp(LOOPBACK, 0, (host, port))
            elif cfg.server:
                ep = transport.TcpServer(host, port)
            else:
                ep = transport.TcpClient(host, port)
        except OSError as exc:
            raise EkiError(24, f"channel {ch.name}: {host}:{port}: {exc.strerror or exc}", cfg.display) from None
        self.endpoints[("eki", key)] = ep
        if cfg.server:
            self.published("eki:" + ch.name, ep.address)
        if cfg.protocol == "UDP" and not cfg.server:
            ch.connected_event()

    def eki_closed(self, ch: Channel) -> None:
        ep = self.endpoints.pop(("eki", ch.name.upper()), None)
        if ep is not None:
            ep.close()

    def eki_send(self, ch: Channel, payload: bytes) -> None:
        self.trace("eki", "out", name=ch.name, data=payload.decode("latin-1"))
        ep = self.endpoints.get(("eki", ch.name.upper()))
        if ep is not None and not ep.send(payload):
            self.trace("eki", "disconnect", name=ch.name, text="send failed")
            ch.disconnected_event("send failed")

    def eki_apply(self, ch: Channel, sets: list) -> None:
        for what, n in sets:
            if what == "flag":
                self.sink.set_flag(n, True)
            else:
                self.sink.set_out(n, True)

    # ------------------------------------------------------------------ trace
    def trace(self, iface: str, direction: str, **fields) -> None:
        """A ``net`` trace event at the current simulated time."""
        ctl = self.ctl
        if ctl is not None and ctl.trace is not None:
            ctl.trace.write("net", ctl.time, iface=iface, dir=direction, **fields)

    def net_message(self, text: str, number: int | None = None) -> None:
        if self.ctl is not None:
            self.ctl.message(text, number=number)


def load_replay(path: Path) -> list[tuple[float, dict]]:
    """The arriving ``net`` events of a recorded trace (robot/trace.py JSONL) with their
    simulated times. Raises NetError for an unreadable or oversized file."""

    try:
        size = path.stat().st_size
    except OSError as exc:
        raise NetError(f"network replay {path}: {exc.strerror}") from None
    if size > MAX_NET_REPLAY_BYTES:
        raise NetError(f"network replay {path}: {size} bytes, more than {MAX_NET_REPLAY_BYTES}")
    out: list[tuple[float, dict]] = []
    n = 0
    with open(path, encoding="utf-8", errors="replace") as fh:
        for i, line in enumerate(fh, 1):
            if '"net"' not in line:
                continue
            try:
                ev = json.loads(line)
            except ValueError:
                raise NetError(f"network replay {path}:{i}: not a JSON line") from None
            if not isinstance(ev, dict) or ev.get("kind") != "net":
                continue
            if ev.get("dir") not in ("in", "connect", "disconnect", "error"):
                continue
            t = ev.get("t")
            if not isinstance(t, (int, float)):
                continue
            n += 1
            if n > MAX_NET_REPLAY_EVENTS:
                raise NetError(f"network replay {path}: more than {MAX_NET_REPLAY_EVENTS} events")
            out.append((float(t), ev))
    return out
