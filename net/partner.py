"""The network-partner protocol: what each kind of partner of a run (EthernetKRL, RSI,
KukaVarProxy, the PLC, ...) provides to the hub (net/hub.py), declared once
(docs/architecture.md "Network partners: where to add one").

A partner is a subclass of :class:`Partner` in its own module, registered once in
net/partners.py. It names its key of the cell file's ``network:`` mapping (which is also the
``iface`` of its ``net`` trace events) and implements every operation below;
tests/net/test_partners.py fails for a registered partner that lacks one, or its section in
docs/network.md. The hub creates one instance per run and calls, on the controller's clock:

- :meth:`parse` (class method) — its key of the cell file, to the :attr:`fields` it sets on
  net.settings.NetworkSettings;
- :meth:`attach` — the run starts with live sockets: start the servers the settings name;
- :attr:`attached` — a socket of it is open: the run is paced to the wall clock and the
  program's inputs may change from outside;
- :meth:`poll` — the start of every IPO cycle the hub polls (``live``: sockets, else a replay or
  no partner connected: only the partner's own clock work, RSI's late packets);
- :meth:`replay` — one recorded arriving ``net`` event of its iface, at its recorded cycle;
- :meth:`close` — the run ended: close every socket, stop every server.
"""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

from krl.limits import MAX_NET_PACE

#: the operations every partner implements (the completeness test checks each is its own)
OPERATIONS = ("parse", "attach", "attached", "poll", "replay", "close")


class Partner:
    """One kind of network partner (see the module docstring). `hub`: the run's network hub."""

    key: ClassVar[str] = ""
    """The cell file's key under ``network:`` and the ``iface`` of the partner's trace events."""
    fields: ClassVar[dict[str, object]] = {}
    """The attributes of NetworkSettings the key sets, with their values when it is absent."""
    docs: ClassVar[str] = ""
    """The heading of its section in docs/network.md."""
    max_pace: ClassVar[float] = MAX_NET_PACE
    """The largest ``pace`` the run may have while the key is set (RSI answers in real time: 1)."""
    pace_reason: ClassVar[str] = ""
    """Why, when :attr:`max_pace` is below the hub's limit (the message of a larger pace)."""
    opens: ClassVar[tuple[str, ...]] = ()
    """The KRL functions whose first argument names what a program opens of this partner (an
    EKI channel, an RSI context): ``krl cell init`` lists them (interp/cellinit.py)."""

    def __init__(self, hub) -> None:
        self.hub = hub

    @classmethod
    def parse(cls, doc, base: Path) -> dict:
        """The key's value `doc` (untrusted YAML), paths relative to the cell file's folder
        `base`, as {field: value}. Raises net.cellkey.SettingsError."""
        raise NotImplementedError

    def attach(self, ctl, **cell) -> None:
        """Start what the settings name for this partner (live runs only); `cell`: facts of
        the cell a partner may need (``plc_map``: a callable giving the PLC's address map).
        Raises OSError when a server cannot start (a port in use)."""
        raise NotImplementedError

    @property
    def attached(self) -> bool:
        """True while a socket of this partner is open."""
        raise NotImplementedError

    def ticking(self) -> bool:
        """True while the partner needs :meth:`poll` at every cycle even with no socket (an
        RSI object switched on: each cycle has its packet, late without a sensor)."""
        return False

    def poll(self, ctl, live: bool) -> None:
        """The start of IPO cycle ``ctl.cycle`` (see the module docstring)."""
        raise NotImplementedError

    def replay(self, ev: dict) -> None:
        """A recorded arriving event of this partner's iface (a ``net`` trace event)."""
        raise NotImplementedError

    def close(self) -> None:
        """The run ended: every socket closed, every server stopped. Called once."""
        raise NotImplementedError

    def sockets(self) -> dict:
        """The partner's open endpoints (net/transport.py) by a name of its own; none by default."""
        return {}

    @classmethod
    def starter(cls, opened: list[tuple[str, str]], root: Path) -> list[str]:
        """The commented lines of `krl cell init`'s ``network:`` section for what the backup
        `root` opens of this partner: `opened` = [(name, where), ...] in order of first use."""
        return []

    @classmethod
    def configured(cls, settings) -> bool:
        """True when `settings` set any of this partner's fields."""
        return settings is not None and any(getattr(settings, f) != d for f, d in cls.fields.items())
