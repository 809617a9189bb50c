"""An EthernetKRL channel's XML configuration, read as the controller reads it
(KUKA.EthernetKRL 2.2/3.x manual, "Configuration of an Ethernet connection").

The file ``Config/User/Common/EthernetKRL/NAME.xml`` of a backup (or a path the cell file
names, docs/network.md) holds::

    <ETHERNETKRL>
      <CONFIGURATION>
        <EXTERNAL> <TYPE>Client|Server</TYPE> <IP>..</IP> <PORT>..</PORT> </EXTERNAL>
        <INTERNAL> <ENVIRONMENT>Program|Submit|System</ENVIRONMENT>
                   <BUFFERING Mode="FIFO|LIFO" Limit="n"/> <BUFFSIZE Limit="bytes"/>
                   <TIMEOUT Connect="ms"/> <ALIVE Set_Out="n" Set_Flag="n" Ping="s"/>
                   <IP>..</IP> <PORT>..</PORT> <PROTOCOL>TCP|UDP</PROTOCOL>
                   <MESSAGES Logging=".." Display="enabled|disabled"/> </INTERNAL>
      </CONFIGURATION>
      <RECEIVE> <XML> <ELEMENT Tag="A/B/@C" Type="REAL" Set_Flag="n" Set_Out="n"/> .. </XML>
                | <RAW> <ELEMENT Tag="Buffer" Type="BYTE|STREAM" Size="n" EOS="13,10" Set_Flag="n"/> </RAW>
      </RECEIVE>
      <SEND> <XML> <ELEMENT Tag="A/B/@C"/> .. </XML> | <RAW> <ELEMENT Tag="Buffer" .. /> </RAW> </SEND>
    </ETHERNETKRL>

``EXTERNAL/TYPE`` names the partner's role: ``Client`` (the partner connects: the controller is
the server, on INTERNAL's port) or ``Server`` (the default: the controller connects to EXTERNAL's
IP and port). :func:`load_config` raises :class:`ConfigError` for a file that is missing,
too large, not well-formed or outside this schema.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from krl.limits import (EKI_BUFFSIZE_DEFAULT, MAX_EKI_BUFFERING, MAX_EKI_BUFFSIZE,
                        MAX_NET_CONFIG_BYTES)

from .xmlsafe import XmlRefused, local, parse

TYPES = ("REAL", "INT", "BOOL", "STRING", "FRAME", "BYTE", "STREAM")


class ConfigError(ValueError):
    """A channel configuration the controller would refuse (EKI00022, or EKI00003 when the file
    is missing: :attr:`missing`)."""

    def __init__(self, text: str, missing: bool = False) -> None:
        super().__init__(text)
        self.missing = missing


@dataclass(frozen=True)
class Element:
    """One configured element: ``tag`` its path (``A/B`` an element's text, ``A/B/@C`` an
    attribute), ``type`` (REAL, INT, BOOL, STRING, FRAME; BYTE/STREAM for raw), the flag and
    output it sets when a message carrying it arrives, and a raw element's size and end string."""

    tag: str
    type: str | None = None
    set_flag: int | None = None
    set_out: int | None = None
    size: int | None = None
    eos: bytes | None = None


@dataclass
class EkiConfig:
    """A channel: who connects to whom, the streams and their elements, the limits."""

    name: str
    server: bool                       # True: the controller listens (EXTERNAL TYPE Client)
    ip: str                            # the address of the XML (INTERNAL for a server, EXTERNAL for a client)
    port: int
    protocol: str = "TCP"              # TCP | UDP
    environment: str = "Program"
    buffering: int = 16                # entries kept per element (BUFFERING Limit)
    lifo: bool = False
    buffsize: int = EKI_BUFFSIZE_DEFAULT
    connect_timeout_ms: int = 2000
    alive_flag: int | None = None
    alive_out: int | None = None
    ping_s: float | None = None
    display: bool = True               # MESSAGES Display: an error stops the program
    receive_kind: str | None = None    # "xml" | "raw" | None
    receive: list[Element] = field(default_factory=list)
    send_kind: str | None = None
    send: list[Element] = field(default_factory=list)

    def receive_element(self, path: str) -> Element | None:
        return _find(self.receive, path)

    def send_element(self, path: str) -> Element | None:
        return _find(self.send, path)


def _find(elements: list[Element], path: str) -> Element | None:
    key = path.strip().upper()
    for e in elements:
        if e.tag.upper() == key:
            return e
    return None


def _int(text: str | None, what: str, lo: int, hi: int) -> int | None:
    if text is None or not str(text).strip():
        return None
    t = str(text).strip()
    if not t.lstrip("-").isdigit() or len(t) > 10:
        raise ConfigError(f"{what}: {t[:20]!r} is not a number")
    v = int(t)
    if not lo <= v <= hi:
        raise ConfigError(f"{what}: {v} outside {lo}..{hi}")
    return v


def _attr(el, name: str):
    for k, v in el.attrib.items():
        if local(k).upper() == name.upper():
            return v
    return None


def _child(el, name: str):
    if el is None:
        return None
    for c in el:
        if local(c.tag).upper() == name.upper():
            return c
    return None


def _text(el, name: str) -> str | None:
    c = _child(el, name)
    return c.text.strip() if c is not None and c.text is not None else None


def _elements(section, where: str) -> tuple[str | None, list[Element]]:
    if section is None:
        return None, []
    kinds = [c for c in section if local(c.tag).upper() in ("XML", "RAW")]
    if not kinds:
        return None, []
    kind_el = kinds[0]
    kind = local(kind_el.tag).lower()
    out = []
    for c in kind_el:
        if local(c.tag).upper() != "ELEMENT":
            continue
        tag = _attr(c, "Tag")
        if not tag or len(tag) > 256:
            raise ConfigError(f"{where}: an ELEMENT without a Tag (or a Tag over 256 characters)")
        typ = _attr(c, "Type")
        if typ is not None:
            typ = typ.strip().upper()
            if typ not in TYPES:
                raise ConfigError(f"{where}: element {tag}: unknown Type {typ[:20]!r}")
        eos = _attr(c, "EOS")
        eos_b = None
        if eos:
            try:
                eos_b = bytes(int(x) for x in eos.split(","))
            except ValueError:
                raise ConfigError(f"{where}: element {tag}: EOS must be byte values (13,10)") from None
            if not 1 <= len(eos_b) <= 32:
                raise ConfigError(f"{where}: element {tag}: EOS of 1..32 bytes")
        out.append(Element(tag.strip(), typ, _int(_attr(c, "Set_Flag"), f"{tag} Set_Flag", 1, 1024),
                           _int(_attr(c, "Set_Out"), f"{tag} Set_Out", 1, 8192),
                           _int(_attr(c, "Size"), f"{tag} Size", 1, MAX_EKI_BUFFSIZE), eos_b))
    if kind == "raw" and len(out) != 1:
        raise ConfigError(f"{where}: a RAW stream has exactly one ELEMENT")
    return kind, out


def parse_config(data: bytes, name: str) -> EkiConfig:
    """The channel `name` from the XML bytes `data`. Raises :class:`ConfigError`."""
    try:
        root = parse(data, MAX_NET_CONFIG_BYTES, f"EKI configuration {name}")
    except XmlRefused as exc:
        raise ConfigError(str(exc)) from None
    if local(root.tag).upper() != "ETHERNETKRL":
        raise ConfigError(f"EKI configuration {name}: the root element is {local(root.tag)[:40]!r}, not ETHERNETKRL")
    conf = _child(root, "CONFIGURATION")
    ext = _child(conf, "EXTERNAL")
    internal = _child(conf, "INTERNAL")
    role = (_text(ext, "TYPE") or "Server").strip().upper()
    if role not in ("CLIENT", "SERVER"):
        raise ConfigError(f"EKI configuration {name}: EXTERNAL TYPE must be Client or Server")
    server = role == "CLIENT"
    src = internal if server else ext
    ip = _text(src, "IP") or ""
    port = _int(_text(src, "PORT"), f"EKI configuration {name}: PORT", 0, 65535)
    if port is None:
        raise ConfigError(f"EKI configuration {name}: no PORT in {'INTERNAL' if server else 'EXTERNAL'}")
    cfg = EkiConfig(name, server, ip, port)
    proto = (_text(internal, "PROTOCOL") or "TCP").upper()
    if proto not in ("TCP", "UDP"):
        raise ConfigError(f"EKI configuration {name}: PROTOCOL must be TCP or UDP")
    cfg.protocol = proto
    env = _text(internal, "ENVIRONMENT")
    if env:
        if env.upper() not in ("PROGRAM", "SUBMIT", "SYSTEM"):
            raise ConfigError(f"EKI configuration {name}: ENVIRONMENT must be Program, Submit or System")
        cfg.environment = env.capitalize()
    buf = _child(internal, "BUFFERING")
    if buf is not None:
        lim = _int(_attr(buf, "Limit"), f"EKI configuration {name}: BUFFERING Limit", 1, MAX_EKI_BUFFERING)
        cfg.buffering = lim if lim is not None else cfg.buffering
        cfg.lifo = (_attr(buf, "Mode") or "FIFO").upper() == "LIFO"
    bs = _child(internal, "BUFFSIZE")
    if bs is not None:
        lim = _int(_attr(bs, "Limit"), f"EKI configuration {name}: BUFFSIZE Limit", 1, MAX_EKI_BUFFSIZE)
        cfg.buffsize = lim if lim is not None else cfg.buffsize
    to = _child(internal, "TIMEOUT")
    if to is not None:
        ms = _int(_attr(to, "Connect"), f"EKI configuration {name}: TIMEOUT Connect", 0, 65_534)  # the manual's range
        cfg.connect_timeout_ms = ms if ms is not None else cfg.connect_timeout_ms
    alive = _child(internal, "ALIVE")
    if alive is not None:
        cfg.alive_flag = _int(_attr(alive, "Set_Flag"), f"EKI configuration {name}: ALIVE Set_Flag", 1, 1024)
        cfg.alive_out = _int(_attr(alive, "Set_Out"), f"EKI configuration {name}: ALIVE Set_Out", 1, 8192)
        ping = _int(_attr(alive, "Ping"), f"EKI configuration {name}: ALIVE Ping", 1, 65534)
        cfg.ping_s = float(ping) if ping is not None else None
    msgs = _child(internal, "MESSAGES")
    if msgs is not None:
        cfg.display = (_attr(msgs, "Display") or "enabled").strip().lower() != "disabled"
    cfg.receive_kind, cfg.receive = _elements(_child(root, "RECEIVE"), f"EKI configuration {name}: RECEIVE")
    cfg.send_kind, cfg.send = _elements(_child(root, "SEND"), f"EKI configuration {name}: SEND")
    return cfg


def load_config(path: Path, name: str) -> EkiConfig:
    """Read and parse ``path`` (at most :data:`~krl.limits.MAX_NET_CONFIG_BYTES`). Raises
    :class:`ConfigError` (``missing`` when there is no such file)."""
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_NET_CONFIG_BYTES + 1)
    except FileNotFoundError:
        raise ConfigError(f"EKI configuration {name}: {path} not found", missing=True) from None
    except OSError as exc:
        raise ConfigError(f"EKI configuration {name}: {path}: {exc.strerror}", missing=True) from None
    return parse_config(data, name)


def find_config(name: str, program: Path | None, backup: Path | None) -> Path | None:
    """Where the controller keeps channel `name`'s XML: the backup's
    ``Config/User/Common/EthernetKRL/NAME.xml`` (any case), then beside the program."""
    folders = []
    if backup is not None:
        folders.append(backup / "Config" / "User" / "Common" / "EthernetKRL")
        folders.append(backup / "KRC" / "Config" / "User" / "Common" / "EthernetKRL")
    if program is not None:
        folders.append(program.parent)
    want = (name + ".xml").upper()
    for folder in folders:
        if not folder.is_dir():
            continue
        try:
            for p in folder.iterdir():
                if p.name.upper() == want and p.is_file():
                    return p
        except OSError:
            continue
    return None
