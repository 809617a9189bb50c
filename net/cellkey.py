"""What a network partner's key of the cell file is made of (docs/network.md "The cell file"):
addresses, paths inside the cell file's folder, mappings with known keys, and an EKI channel's
or the RSI object's ``{config, address}``. Each partner (net/partner.py) parses its own key with
these; net/settings.py holds the whole ``network:`` mapping.

Paths are relative to the cell file's folder and stay inside it (the file is untrusted). An
address is ``HOST:PORT`` (``[V6]:PORT``), a bare port number meaning loopback; port 0 takes a
free port (the run says which).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

LOOPBACK = "127.0.0.1"
CHANNEL_KEYS = ("config", "address")
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


def parse_address(text, what: str, default_port: int | None = None) -> tuple[str, int]:
    """``HOST:PORT`` -> (host, port); a bare port number means loopback. Raises SettingsError."""
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


def inside(base: Path, text, what: str) -> Path:
    """`text`, a path relative to the cell file's folder `base` without ``..``, as a Path."""
    if not isinstance(text, str) or not text or len(text) > 1024:
        raise SettingsError(f"{what}: a path relative to the cell file")
    p = Path(text)
    if p.is_absolute() or ".." in p.parts:
        raise SettingsError(f"{what}: {text[:60]!r} must be relative to the cell file's folder, without '..'")
    return base / p


def mapping(doc, keys, what: str) -> dict:
    """`doc` when it is a mapping whose keys are among `keys`. Raises SettingsError."""
    if not isinstance(doc, dict):
        raise SettingsError(f"{what} must be a mapping")
    for k in doc:
        if k not in keys:
            raise SettingsError(f"{what}: unknown key {str(k)[:40]!r} (allowed: {', '.join(keys)})")
    return doc


def channel(doc, base: Path, what: str, keys=CHANNEL_KEYS) -> Channel:
    """``{config: PATH, address: HOST:PORT}`` (optional, None: the defaults), and ``ethernet:
    PATH`` where `keys` allow it (RSI)."""
    if doc is None:
        return Channel()
    doc = mapping(doc, keys, what)
    cfg = inside(base, doc["config"], f"{what}: config") if doc.get("config") is not None else None
    addr = parse_address(doc["address"], f"{what}: address") if doc.get("address") is not None else None
    eth = inside(base, doc["ethernet"], f"{what}: ethernet") if doc.get("ethernet") is not None else None
    return Channel(cfg, addr, eth)
