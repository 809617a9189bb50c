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

Paths are relative to the cell file's folder and stay inside it (the file is untrusted). An
address is ``HOST:PORT`` (``[V6]:PORT``); port 0 takes a free port (the run says which). Without
an address, every socket is on loopback: a server binds 127.0.0.1 at the XML's port, a client
connects to 127.0.0.1 at the XML's port; another host only where the cell file names it.
A channel the key does not name opens no socket: it stays "not connected", and the run stays
deterministic and unpaced.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from krl.limits import MAX_EKI_CHANNELS, MAX_NET_PACE

LOOPBACK = "127.0.0.1"
KEYS = ("eki", "rsi", "plc", "varproxy", "pace", "replay")
EKI_KEYS = ("config", "address")
RSI_KEYS = ("config", "address", "ethernet")
PLC_KEYS = ("modbus", "opcua", "map")
_NAME = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]{0,63}\Z")
_ADDR = re.compile(r"(?:\[([0-9A-Fa-f:.]+)\]|([A-Za-z0-9.\-]{1,253})):([0-9]{1,5})\Z")


class SettingsError(ValueError):
    """A ``network:`` key outside the schema; the message names the key."""


@dataclass(frozen=True)
class Channel:
    """An EKI channel or the RSI object the cell connects: its configuration file (None: where
    the controller keeps it) and the address that overrides the XML's."""

    config: Path | None = None
    address: tuple[str, int] | None = None
    ethernet: Path | None = None        # RSI only: the ETHERNET configuration (net/rsicontext.py)


@dataclass
class NetworkSettings:
    base: Path
    eki: dict[str, Channel] = field(default_factory=dict)       # CHANNEL (upper) -> Channel
    rsi: Channel | None = None
    modbus: tuple[str, int] | None = None
    opcua: str | None = None
    plc_map: Path | None = None
    varproxy: tuple[str, int] | None = None
    pace: float = 1.0
    replay: Path | None = None

    @property
    def live(self) -> bool:
        """True when the run opens sockets (not a replay)."""
        return self.replay is None


def parse_address(text, what: str, default_port: int | None = None) -> tuple[str, int]:
    """``HOST:PORT`` -> (host, port); a bare port number means loopback."""
    if isinstance(text, int) and not isinstance(text, bool):
        text = f"{LOOPBACK}:{text}"
    if not isinstance(text, str):
        raise SettingsError(f"{what}: an address is HOST:PORT")
    m = _ADDR.match(text.strip())
    if not m:
        raise SettingsError(f"{what}: {text[:60]!r} is not HOST:PORT")
    port = int(m.group(3))
    if port > 65535:
        raise SettingsError(f"{what}: port {port} outside 0..65535")
    return (m.group(1) or m.group(2)), port


def _inside(base: Path, text, what: str) -> Path:
    if not isinstance(text, str) or not text or len(text) > 1024:
        raise SettingsError(f"{what}: a path relative to the cell file")
    p = Path(text)
    if p.is_absolute() or ".." in p.parts:
        raise SettingsError(f"{what}: {text[:60]!r} must be relative to the cell file's folder, without '..'")
    return base / p


def _mapping(doc, keys, what: str) -> dict:
    if not isinstance(doc, dict):
        raise SettingsError(f"{what} must be a mapping")
    for k in doc:
        if k not in keys:
            raise SettingsError(f"{what}: unknown key {str(k)[:40]!r} (allowed: {', '.join(keys)})")
    return doc


def _channel(doc, base: Path, what: str, keys=EKI_KEYS) -> Channel:
    if doc is None:
        return Channel()
    doc = _mapping(doc, keys, what)
    cfg = _inside(base, doc["config"], f"{what}: config") if doc.get("config") is not None else None
    addr = parse_address(doc["address"], f"{what}: address") if doc.get("address") is not None else None
    eth = _inside(base, doc["ethernet"], f"{what}: ethernet") if doc.get("ethernet") is not None else None
    return Channel(cfg, addr, eth)


def parse_network(doc, base: Path) -> NetworkSettings:
    """The settings of a ``network:`` mapping; `base` the cell file's folder. Raises
    :class:`SettingsError`."""
    doc = _mapping(doc, KEYS, "network")
    s = NetworkSettings(base)
    eki = doc.get("eki")
    if eki is not None:
        if not isinstance(eki, dict):
            raise SettingsError("network: eki must map channel names to {config, address}")
        if len(eki) > MAX_EKI_CHANNELS:
            raise SettingsError(f"network: eki names {len(eki)} channels, more than {MAX_EKI_CHANNELS}")
        for name, ch in eki.items():
            if not isinstance(name, str) or not _NAME.match(name):
                raise SettingsError(f"network: eki: {str(name)[:40]!r} is not a channel name")
            s.eki[name.upper()] = _channel(ch, base, f"network: eki: {name}")
    if doc.get("rsi") is not None:
        s.rsi = _channel(doc["rsi"], base, "network: rsi", RSI_KEYS)
    if doc.get("plc") is not None:
        plc = _mapping(doc["plc"], PLC_KEYS, "network: plc")
        if plc.get("modbus") is not None:
            s.modbus = parse_address(plc["modbus"], "network: plc: modbus")
        if plc.get("opcua") is not None:
            url = plc["opcua"]
            if not isinstance(url, str) or not url.startswith("opc.tcp://"):
                raise SettingsError("network: plc: opcua is an opc.tcp://HOST:PORT address")
            parse_address(url[len("opc.tcp://"):].split("/", 1)[0], "network: plc: opcua")
            s.opcua = url
        if plc.get("map") is not None:
            s.plc_map = _inside(base, plc["map"], "network: plc: map")
    if doc.get("varproxy") is not None:
        s.varproxy = parse_address(doc["varproxy"], "network: varproxy")
    if doc.get("pace") is not None:
        pace = doc["pace"]
        if isinstance(pace, bool) or not isinstance(pace, (int, float)) or not 0 < pace <= MAX_NET_PACE:
            raise SettingsError(f"network: pace must be a number in (0, {MAX_NET_PACE:g}]")
        s.pace = float(pace)
        if s.rsi is not None and s.pace != 1.0:
            raise SettingsError("network: pace: RSI answers within its cycle in real time; pace must be 1 with rsi")
    if doc.get("replay") is not None:
        s.replay = _inside(base, doc["replay"], "network: replay")
    return s
