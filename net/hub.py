"""The network hub of one run: every partner on one clock (docs/network.md, "One clock").

The simulated controller calls :meth:`Network.cycle` at the start of every IPO cycle
(robot/controller.py ``Controller.step``). There the hub

1. paces the run to the wall clock while a partner is attached (:class:`Pacer`: cycle k
   starts no earlier than k·12 ms / pace after the first attached cycle; a run with no socket
   open never sleeps and stays as fast and as deterministic as without the network);
2. polls every partner once (net/partner.py ``Partner.poll``; the partners are registered in
   net/partners.py: EKI channels, KukaVarProxy, the PLC, the RSI object) — or, replaying a
   recording, hands each event the recorded trace holds for this cycle to the partner of its
   ``iface`` (``Partner.replay``);
3. the partners write a ``net`` trace event for every message that arrives or leaves, with its
   simulated time, so a trace is also a recording: ``network: {replay: trace.jsonl}`` feeds the
   same messages at the same cycles, with no socket, and both interpreters give the same trace.

The runtime talks to the partners through its EKI/RSI built-ins
(interp/runtime/natives/eki.py, rsi.py: ``hub.partner("eki")``, ``hub.partner("rsi")``) and gives
the hub a *sink*: ``set_flag(n, v)``, ``set_out(n, v)``, ``read_var(name) -> text``,
``write_var(name, text) -> text``, ``admit(name, value, writer) -> refusal or None`` (the
controller's write rules, interp/runtime/writerules.py; interp/runtime/netvars.py), and
``changed_outside()``, which
a partner calls at the moment it writes into the run otherwise (a message into an EKI channel's
memory, a PLC's input, an RSI answer; the sink's own writes call it themselves): the runtime's
watch keys move and parked spins catch up (interp/runtime/core.py ``Runtime.changed_outside``).
"""

from __future__ import annotations

import threading
import time
from pathlib import Path
import json

from krl.limits import MAX_NET_REPLAY_BYTES, MAX_NET_REPLAY_EVENTS

from . import partners as registry
from .netlog import clip
from .partner import Partner
from .settings import NetworkSettings


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

    def changed_outside(self) -> None:
        """A partner is about to write (no run to tell)."""

    def admit(self, name: str, value, writer: str, scalar: bool | None = True):
        """Every write admitted (no controller to apply its rules: a protocol tested alone)."""
        return None

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
    `program`/`backup`: where EKI configurations and RSI contexts are looked up. `sink`: see the
    module docstring. Each registered partner (net/partners.py) has one instance,
    :meth:`partner`."""

    def __init__(self, settings: NetworkSettings | None = None, *, program: Path | None = None,
                 backup: Path | None = None, sink=None) -> None:
        self.settings = settings
        self.program = Path(program) if program is not None else None
        self.backup = Path(backup) if backup is not None else None
        self.sink = sink if sink is not None else NullSink()
        self.ctl = None
        self.partners: dict[str, Partner] = {cls.key: cls(self) for cls in registry.PARTNERS}
        self.pacer: Pacer | None = None
        self.replay: dict[int, list[dict]] | None = None
        self.addresses: dict[str, tuple[str, int]] = {}        # "eki:NAME" / "varproxy" / ... -> bound
        self.ready = threading.Condition()
        self.listen_hook = None     # listen_hook(key, (host, port)) when a server starts (krl run says where)
        self.closed = False
        # the controller calls cycle() only while this is True: partners configured, a replay,
        # or RSI on; a run without any costs one attribute test per IPO cycle. False: no partner
        # is attached (attach starts partners only with settings) or ticks (RSI on sets it)
        self.polling = settings is not None
        if settings is not None and settings.replay is not None:
            self.replay_events = load_replay(settings.replay)

    def partner(self, key: str) -> Partner:
        """The run's partner of cell-file key `key` (``"eki"``, ``"rsi"``, ...). KeyError."""
        return self.partners[key]

    # ------------------------------------------------------------------ lifecycle
    def attach(self, ctl, **cell) -> None:
        """Bind to the controller `ctl` (which holds this hub: robot/controller.py ``Controller``
        attaches the hub it is built with) and start the servers the settings name (each
        partner's ``attach``; `cell`: facts of the cell they may need, ``plc_map``). Raises
        OSError when one cannot start (a port in use)."""
        self.ctl = ctl
        if getattr(self, "replay_events", None) is not None:
            self.replay = {}
            for t, ev in self.replay_events:
                self.replay.setdefault(int(round(t / ctl.dt)), []).append(ev)
        s = self.settings
        if s is None or not s.live:
            return
        for p in self.partners.values():
            p.attach(ctl, **cell)

    @property
    def attached(self) -> bool:
        """True while a partner may be connected: a socket is open (the run is paced)."""
        return any(p.attached for p in self.partners.values())

    @property
    def endpoints(self) -> dict:
        """Every open socket of the partners, by (key, name)."""
        return {(k, n): ep for k, p in self.partners.items() for n, ep in p.sockets().items()}

    def may_change(self) -> bool:
        """True when something outside the program can still change its inputs (for the
        deadlock test of WAIT FOR): a partner attached, or a replay not yet over."""
        if not self.polling:
            return False            # no partner configured, no replay, no RSI on (:attr:`polling`)
        if self.attached:
            return True
        if self.replay and self.ctl is not None:
            return any(k >= self.ctl.cycle for k in self.replay)
        return False

    def next_event_cycle(self, k: int) -> int | None:
        """The first IPO cycle after cycle `k` in which a message can arrive (the idle
        fast-forward, interp/runtime/idle.py, never jumps past it): the next one while a
        partner is attached (it runs on the wall clock) or ticks (an RSI object on: each cycle
        has its exchange, or its late packet), the next recorded cycle of a replay, None when
        nothing can arrive."""
        if not self.polling:
            return None             # no partner configured, no replay, no RSI on (:attr:`polling`)
        if self.attached or any(p.ticking() for p in self.partners.values()):
            return k + 1
        later = [c for c in self.replay if c > k] if self.replay else []
        return min(later) if later else None

    def close(self) -> None:
        """Close every socket and stop the servers (the run ended; EKI channels of
        ENVIRONMENT Program are deleted at a program's end)."""
        if self.closed:
            return
        self.closed = True
        for p in self.partners.values():
            p.close()

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
        partners = self.partners.values()
        if self.replay is not None:
            for ev in self.replay.pop(ctl.cycle, ()):
                p = self.partners.get(ev.get("iface"))
                if p is not None:
                    p.replay(ev)
            for p in partners:
                p.poll(ctl, live=False)
            return
        if not self.attached:
            for p in partners:
                p.poll(ctl, live=False)     # no socket: only a partner's own clock (RSI's late packets)
            return
        if self.pacer is None:
            pace = self.settings.pace if self.settings is not None else 1.0
            self.pacer = Pacer(ctl.dt, pace)
        self.pacer.wait(ctl.cycle)
        for p in partners:
            p.poll(ctl, live=True)

    # ------------------------------------------------------------------ trace
    def trace(self, iface: str, direction: str, **fields) -> None:
        """A ``net`` trace event at the current simulated time. Its ``text`` (an error, a
        refusal: it may quote what a partner sent) is clipped (net/netlog.py); its ``data`` is
        the recording of the message, which a replay feeds again."""
        ctl = self.ctl
        if ctl is not None and ctl.trace is not None:
            if isinstance(fields.get("text"), str):
                fields["text"] = clip(fields["text"])
            ctl.trace.write("net", ctl.time, iface=iface, dir=direction, **fields)

    def net_message(self, text: str, number: int | None = None) -> None:
        """A controller message of a partner's (clipped: it may quote what the partner sent)."""
        if self.ctl is not None:
            self.ctl.log.message(clip(text), number=number)


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
