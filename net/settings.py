"""The cell file's ``network:`` key: which partners a run connects (docs/network.md)::

    network:
      eki:
        CHANNEL: {config: PATH.xml, address: 127.0.0.1:54600}  # address overrides the XML's IP and port
      rsi: {config: PATH, address: 127.0.0.1:49152, ethernet: PATH.xml}   # ethernet: the ETHERNET
                             # object's configuration when it is not beside the context
      plc: {modbus: 127.0.0.1:5020, opcua: opc.tcp://127.0.0.1:4840}
      varproxy: 127.0.0.1:7000
      pace: 1.0              # simulated s per wall s while a partner is attached (default 1: real time)
      replay: run.jsonl      # instead of sockets: the messages of a recorded trace, at their times

``pace`` and ``replay`` are the hub's; every other key is one partner's (net/partners.py), which
parses it (net/partner.py ``Partner.parse``) into the fields it sets here. Paths are relative to
the cell file's folder and stay inside it (the file is untrusted; net/cellkey.py). Without an
address, every socket is on loopback: a server binds 127.0.0.1 at the XML's port, a client
connects to 127.0.0.1 at the XML's port; another host only where the cell file names it. A
channel the key does not name opens no socket: it stays "not connected", and the run stays
deterministic and unpaced.
"""

from __future__ import annotations

from pathlib import Path

from krl.limits import MAX_NET_PACE

from .cellkey import LOOPBACK, Channel, SettingsError, inside, mapping, parse_address
from . import partners as registry  # noqa: I001  (after .cellkey: net/rsicontext.py imports LOOPBACK from here)

HUB_KEYS = ("pace", "replay")

__all__ = ["LOOPBACK", "Channel", "NetworkSettings", "SettingsError", "keys", "parse_address", "parse_network"]


def keys() -> tuple[str, ...]:
    """The keys of the ``network:`` mapping: each registered partner's, then the hub's."""
    return tuple(p.key for p in registry.PARTNERS) + HUB_KEYS


def _fields() -> dict[str, object]:
    return {f: d for p in registry.PARTNERS for f, d in p.fields.items()}


class NetworkSettings:
    """The ``network:`` mapping of a run: the cell file's folder `base`, `pace`, `replay` and
    each registered partner's fields (``eki``, ``rsi``, ``modbus``, ... net/partners.py), given
    by keyword or parsed by :func:`parse_network`; a field not given has its partner's default.
    Raises TypeError for a keyword no partner declares."""

    def __init__(self, base: Path, *, pace: float = 1.0, replay: Path | None = None, **fields) -> None:
        defaults = _fields()
        unknown = [k for k in fields if k not in defaults]
        if unknown:
            raise TypeError(f"NetworkSettings: no partner has the field(s) {', '.join(unknown)}")
        self.base = base
        self.pace = pace
        self.replay = replay
        self.fields = {f: _fresh(d) for f, d in defaults.items()}
        self.fields.update(fields)

    def __getattr__(self, name: str):
        fields = self.__dict__.get("fields")
        if fields is not None and name in fields:
            return fields[name]
        raise AttributeError(name)

    @property
    def live(self) -> bool:
        """True when the run opens sockets (not a replay)."""
        return self.replay is None

    def __repr__(self) -> str:
        return f"NetworkSettings({self.base!s}, pace={self.pace}, replay={self.replay}, {self.fields})"


def _fresh(default):
    """A partner's default value, a new one for a mutable default (``eki``: {})."""
    return type(default)() if isinstance(default, (dict, list)) else default


def parse_network(doc, base: Path) -> NetworkSettings:
    """The settings of a ``network:`` mapping; `base` the cell file's folder. Raises
    :class:`SettingsError`."""
    doc = mapping(doc, keys(), "network")
    s = NetworkSettings(base)
    for partner in registry.PARTNERS:
        if doc.get(partner.key) is not None:
            s.fields.update(partner.parse(doc[partner.key], base))
    if doc.get("pace") is not None:
        pace = doc["pace"]
        if isinstance(pace, bool) or not isinstance(pace, (int, float)) or not 0 < pace <= MAX_NET_PACE:
            raise SettingsError(f"network: pace must be a number in (0, {MAX_NET_PACE:g}]")
        s.pace = float(pace)
        for partner in registry.PARTNERS:
            if partner.configured(s) and s.pace > partner.max_pace:
                raise SettingsError(f"network: pace: {partner.pace_reason}; pace must be "
                                    f"{partner.max_pace:g} with {partner.key}")
    if doc.get("replay") is not None:
        s.replay = inside(base, doc["replay"], "network: replay")
    return s
