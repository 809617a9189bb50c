"""KUKA.RobotSensorInterface: the RSI context, its ETHERNET object and the corrections
(docs/network.md "RobotSensorInterface").

``RSI_CREATE("NAME", CONTID, TRUE)`` reads the context's objects from ``NAME.rsi.xml`` (the
``RSIObjects`` file RSI Visual writes beside ``NAME.rsi``; the backup's
``Config/User/Common/SensorInterface/``, beside the program, or the cell file's ``rsi:
{config: ...}``). Simulated objects:

* ``ETHERNET`` — ``ConfigFile`` (the XML of the sensor: ``CONFIG/IP_NUMBER``, ``PORT``,
  ``SEND/ELEMENTS``, ``RECEIVE/ELEMENTS`` with TAG, TYPE, INDX, HOLDON), ``Timeout`` (late
  packets allowed in a row; past it the robot stops), ``Flag``;
* ``AXISCORR`` (inputs A1..A6; ``LowerLimAn``/``UpperLimAn``: the total correction is held
  within them, deg) and ``POSCORR`` (inputs X, Y, Z, A, B, C in $BASE; ``LowerLimX`` ..
  ``UpperLimC``, ``MaxTrans`` mm, ``MaxRotAngle`` deg);
* ``AXISCORRMON`` / ``POSCORRMON`` (``MaxAn`` / ``MaxTrans``, ``MaxRotAngle``: a total
  correction past them stops the robot);
* ``STOP`` (input 1 non-zero: ``RSI_MOVECORR`` ends).

Any other object is not simulated: one message says so, and its outputs read 0.

Each sensor cycle (12 ms; ``RSI_ON(mode, #IPO_FAST)``: three of 4 ms in each IPO cycle) the
controller sends, over UDP to the sensor, KUKA's XML::

    <Rob Type="KUKA"><RIst X=".." Y=".." Z=".." A=".." B=".." C=".."/><RSol .../>
      <AIPos A1=".." .. A6=".."/><ASPos .../><Delay D="late packets"/><IPOC>ms</IPOC></Rob>

(the elements its SEND names) and expects the answer ``<Sen Type=".."><AK A1=".." ../>
<RKorr X=".." ../><Stop>0</Stop><IPOC>same</IPOC></Sen>`` before the next one. The answer's
RECEIVE elements are the ETHERNET object's outputs by INDX. ``#ABSOLUTE``: the correction is
the total offset from where RSI_ON found the robot; ``#RELATIVE``: each answer adds to it.
A cycle without its answer is *late*: counted (``Delay``; a late answer still brings the
sensor's newest values, but only one in time ends the count), and past ``Timeout`` late packets
in a row the robot stops with the KSS message "RSI: maximum number of late packets
exceeded" and the program with it. The corrections superpose on the programmed motion
(robot/controller.py ``correction``); RSI_OFF keeps the corrected position. Everything that
arrives or leaves is a ``net`` event (iface ``rsi``), so a replay feeds the same answers.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
import time

import numpy as np

from krl.limits import MAX_NET_CONFIG_BYTES, MAX_RSI_DATAGRAM_BYTES

from . import transport
from .cellkey import LOOPBACK, channel
from .partner import Partner
from .xmlsafe import XmlRefused, local, parse

RSIOK, RSIINVOBJID, RSIINVPARAM, RSINOMEM, RSIINVOBJTYPE, RSIINVCONN, RSIALREADYON, RSINOTON, RSIOBJUSED = range(9)
MSG_LATE = "RSI: maximum number of late packets exceeded"
MSG_MON = "RSI: correction monitoring exceeded"
SENSOR_CYCLE_MS = 12
FAST_CYCLE_MS = 4
LATE_NUMBER = 1
MON_NUMBER = 2
AXES = ("A1", "A2", "A3", "A4", "A5", "A6")
CART = ("X", "Y", "Z", "A", "B", "C")


class RsiConfigError(ValueError):
    pass


@dataclass
class RsiObject:
    type: str
    id: str
    params: dict[str, str] = field(default_factory=dict)
    inputs: dict[int, tuple[str, int]] = field(default_factory=dict)   # InIdx -> (OutObjID, OutIdx)


@dataclass
class RecvElement:
    tag: str
    indx: int
    holdon: bool


@dataclass
class Context:
    """An RSI context read from its files."""

    name: str
    objects: dict[str, RsiObject]
    ip: str
    port: int
    send: list[str]
    receive: list[RecvElement]
    sentype: str = "ImFree"

    def of_type(self, t: str) -> list[RsiObject]:
        return [o for o in self.objects.values() if o.type == t]


def _read(path: Path, what: str) -> bytes:
    try:
        with open(path, "rb") as fh:
            return fh.read(MAX_NET_CONFIG_BYTES + 1)
    except OSError as exc:
        raise RsiConfigError(f"{what}: {path}: {exc.strerror or 'cannot read'}") from None


def load_context(path: Path, name: str) -> Context:
    """The context of ``NAME.rsi.xml`` at `path` and its ETHERNET object's configuration (in
    the same folder). Raises :class:`RsiConfigError`."""
    try:
        root = parse(_read(path, f"RSI context {name}"), MAX_NET_CONFIG_BYTES, f"RSI context {name}")
    except XmlRefused as exc:
        raise RsiConfigError(str(exc)) from None
    objects: dict[str, RsiObject] = {}
    for el in root.iter():
        if local(el.tag) != "RSIObject":
            continue
        obj = RsiObject(str(el.get("ObjType", "")).upper(), str(el.get("ObjID", "")))
        for p in el.iter():
            if local(p.tag) == "Parameter" and p.get("Name"):
                obj.params[p.get("Name")] = str(p.get("ParamValue", ""))
            elif local(p.tag) == "Input":
                try:
                    obj.inputs[int(p.get("InIdx", "0"))] = (str(p.get("OutObjID", "")), int(p.get("OutIdx", "0")))
                except ValueError:
                    raise RsiConfigError(f"RSI context {name}: object {obj.id}: an Input without numbers") from None
        objects[obj.id] = obj
    eth = [o for o in objects.values() if o.type == "ETHERNET"]
    if len(eth) != 1:
        raise RsiConfigError(f"RSI context {name}: {len(eth)} ETHERNET objects (one is simulated)")
    cfg_name = eth[0].params.get("ConfigFile", "")
    if not cfg_name or "/" in cfg_name or "\\" in cfg_name or ".." in cfg_name:
        raise RsiConfigError(f"RSI context {name}: ETHERNET ConfigFile {cfg_name[:60]!r} is not a file name")
    cfg_path = _beside(path.parent, cfg_name)
    try:
        eroot = parse(_read(cfg_path, "RSI ETHERNET configuration"), MAX_NET_CONFIG_BYTES, f"RSI {cfg_name}")
    except XmlRefused as exc:
        raise RsiConfigError(str(exc)) from None
    conf = _find(eroot, "CONFIG")
    ip = _text(conf, "IP_NUMBER") or LOOPBACK
    try:
        port = int(_text(conf, "PORT") or "")
    except ValueError:
        raise RsiConfigError(f"RSI {cfg_name}: CONFIG/PORT is not a number") from None
    send = [str(e.get("TAG", "")) for e in _elements(eroot, "SEND")]
    receive = []
    for e in _elements(eroot, "RECEIVE"):
        try:
            receive.append(RecvElement(str(e.get("TAG", "")), int(e.get("INDX", "0")), str(e.get("HOLDON", "0")) == "1"))
        except ValueError:
            raise RsiConfigError(f"RSI {cfg_name}: RECEIVE element {e.get('TAG')!r}: INDX is not a number") from None
    return Context(name, objects, ip, port, send, receive, _text(conf, "SENTYPE") or "ImFree")


def _beside(folder: Path, name: str) -> Path:
    p = folder / name
    if p.exists():
        return p
    for q in folder.iterdir() if folder.is_dir() else ():
        if q.name.lower() == name.lower():
            return q
    return p


def _find(el, name):
    for c in el.iter():
        if local(c.tag).upper() == name:
            return c
    return None


def _text(el, name):
    if el is None:
        return None
    c = _find(el, name)
    return c.text.strip() if c is not None and c.text else None


def _elements(root, section):
    s = _find(root, section)
    return [e for e in s.iter() if local(e.tag).upper() == "ELEMENT"] if s is not None else []


def find_context(name: str, program: Path | None, backup: Path | None) -> Path | None:
    """Where the controller keeps ``NAME.rsi.xml`` (or ``NAME.xml`` for a name ending in .rsi)."""
    stem = name[:-4] if name.lower().endswith(".rsi") else name
    want = {(stem + ".rsi.xml").upper(), (stem + ".xml").upper()} if not name.lower().endswith(".xml") else {name.upper()}
    folders = []
    if backup is not None:
        folders += [backup / "Config" / "User" / "Common" / "SensorInterface",
                    backup / "KRC" / "Config" / "User" / "Common" / "SensorInterface"]
    if program is not None:
        folders.append(program.parent)
    for f in folders:
        if f.is_dir():
            for p in sorted(f.iterdir()):
                if p.name.upper() in want and p.is_file():
                    return p
    return None


class Rsi:
    """The RSI of one run (one context at a time, as the corpus's programs use it)."""

    def __init__(self, hub) -> None:
        self.hub = hub
        self.ctx: Context | None = None
        self.endpoint = None
        self.on = False
        self.mode = "ABSOLUTE"
        self.fast = False
        self.corr_axes = np.zeros(6)
        self.corr_cart = np.zeros(6)
        self.outputs: dict[int, float] = {}
        self.expect: list[int] = []          # IPOCs sent and not answered yet
        self.recent: list[int] = []          # the last IPOCs sent (a late answer is still applied)
        self.late = 0
        self.late_total = 0
        self.stopped = False
        self.failed: str | None = None
        self.noted: set[str] = set()
        self.q_on: np.ndarray | None = None

    # ------------------------------------------------------------------ functions
    def create(self, name: str) -> int:
        if self.ctx is not None:
            return RSIOBJUSED
        s = self.hub.settings
        path = s.rsi.config if s is not None and s.rsi is not None and s.rsi.config is not None else \
            find_context(name, self.hub.program, self.hub.backup)
        if path is None:
            self.hub.net_message(f"RSI: context {name[:60]} not found (NAME.rsi.xml in Config/User/Common/SensorInterface or beside the program)")
            return RSIINVPARAM
        try:
            self.ctx = load_context(path, name)
        except RsiConfigError as exc:
            self.hub.net_message(f"RSI: {exc}")
            return RSIINVPARAM
        for o in self.ctx.objects.values():
            if o.type not in ("ETHERNET", "AXISCORR", "POSCORR", "AXISCORRMON", "POSCORRMON", "STOP") \
                    and o.type not in self.noted:
                self.noted.add(o.type)
                self.hub.net_message(f"RSI: object {o.type} is not simulated (its outputs read 0)")
        return RSIOK

    def delete(self) -> int:
        if self.on:
            self.off()
        self.ctx = None
        return RSIOK

    def set_param(self, obj: str, name: str, value: float) -> int:
        if self.ctx is None:
            return RSIINVOBJID
        o = self.ctx.objects.get(obj)
        if o is None:
            return RSIINVOBJID
        o.params[name] = repr(float(value))
        return RSIOK

    def get_param(self, obj: str, name: str) -> tuple[int, float]:
        if self.ctx is None or obj not in self.ctx.objects:
            return RSIINVOBJID, 0.0
        try:
            return RSIOK, float(self.ctx.objects[obj].params.get(name, "0"))
        except ValueError:
            return RSIINVPARAM, 0.0

    def start(self, ctl, mode: str, fast: bool) -> int:
        if self.ctx is None:
            return RSIINVOBJID
        if self.on:
            return RSIALREADYON
        self.on, self.mode, self.fast = True, mode, fast
        self.corr_axes[:] = 0
        self.corr_cart[:] = 0
        self.outputs = {}
        self.expect = []
        self.late = 0
        self.stopped = False
        self.failed = None
        self.q_on = np.array(ctl.axis_act(), dtype=float)[:6]
        s = self.hub.settings
        if s is not None and s.live and s.rsi is not None:
            host, port = s.rsi.address if s.rsi.address is not None else (LOOPBACK, self.ctx.port)
            try:
                self.endpoint = transport.Udp(LOOPBACK if host in (LOOPBACK, "localhost") else "0.0.0.0", 0,
                                              (host, port), MAX_RSI_DATAGRAM_BYTES)
            except OSError as exc:
                self.on = False
                self.hub.net_message(f"RSI: cannot open the ETHERNET object's socket: {exc.strerror or exc}")
                return RSIINVCONN
        ctl.set_correction(self)
        self.hub.polling = True
        return RSIOK

    def off(self, ctl=None) -> int:
        if not self.on:
            return RSINOTON
        self.on = False
        ctl = ctl or self.hub.ctl
        if ctl is not None and getattr(ctl, "correction", None) is not None:
            ctl.keep_correction()
        if self.endpoint is not None:
            self.endpoint.close()
            self.endpoint = None
        return RSIOK

    def close(self) -> None:
        if self.endpoint is not None:
            self.endpoint.close()
            self.endpoint = None

    # ------------------------------------------------------------------ the sensor cycle
    def cycle(self, ctl, live: bool) -> None:
        """At the start of IPO cycle ``ctl.cycle``: the answers to the last cycle's packets,
        the late count, then this cycle's packets."""
        if not self.on or self.failed:
            return
        if live and self.endpoint is not None:
            for ev in self.endpoint.poll():
                if ev[0] == "data":
                    self.hub.trace("rsi", "in", data=ev[1].decode("latin-1"))
                    self.answer(ev[1])
        self._count_late(ctl)
        if self.failed:
            return
        n = 3 if self.fast else 1
        base = int(round(ctl.time * 1000))
        for i in range(n):
            ipoc = base + i * FAST_CYCLE_MS
            msg = self.message(ctl, ipoc)
            self.hub.trace("rsi", "out", data=msg.decode("latin-1"))
            self.expect.append(ipoc)
            self.recent.append(ipoc)
            del self.recent[:-16]
            if live and self.endpoint is not None:
                self.endpoint.send(msg)
                if self.fast and i < n - 1 and self.hub.pacer is not None:

                    time.sleep(FAST_CYCLE_MS / 1000.0 / self.hub.pacer.pace)
                    for ev in self.endpoint.poll():
                        if ev[0] == "data":
                            self.hub.trace("rsi", "in", data=ev[1].decode("latin-1"))
                            self.answer(ev[1])

    def replayed(self, ev: dict) -> None:
        if ev.get("dir") == "in" and self.on and not self.failed:
            data = str(ev.get("data", "")).encode("latin-1", "replace")
            self.hub.trace("rsi", "in", data=data.decode("latin-1"))
            self.answer(data)

    def _count_late(self, ctl) -> None:
        if not self.expect:
            return
        # every packet sent before this cycle and not answered is late
        self.late += len(self.expect)
        self.late_total += len(self.expect)
        self.hub.trace("rsi", "error", number=LATE_NUMBER, text=f"{len(self.expect)} late packet(s), {self.late} in a row")
        self.expect = []
        limit = self._timeout()
        if self.late > limit:
            self.fail(ctl, MSG_LATE + f" ({self.late} in a row, Timeout {limit})", LATE_NUMBER)

    def _timeout(self) -> int:
        eth = self.ctx.of_type("ETHERNET")[0]
        try:
            return max(0, int(float(eth.params.get("Timeout", "100"))))
        except ValueError:
            return 100

    def fail(self, ctl, text: str, number: int) -> None:
        """Stop the robot as KSS does: the main run stops with the message, the program with it."""
        self.failed = text
        self.hub.trace("rsi", "error", number=number, text=text)
        self.off(ctl)
        ctl.stop_with(text, number)

    def answer(self, data: bytes) -> None:
        """One datagram of the sensor: its IPOC answers a packet; its values are the ETHERNET
        object's outputs."""
        try:
            root = parse(data, MAX_RSI_DATAGRAM_BYTES, "RSI answer")
        except XmlRefused as exc:
            self.hub.trace("rsi", "error", text=str(exc))
            return                              # unreadable: the packet stays late
        ipoc_el = None
        for c in root.iter():
            if local(c.tag).upper() == "IPOC":
                ipoc_el = c
        try:
            ipoc = int((ipoc_el.text or "").strip()) if ipoc_el is not None else None
        except ValueError:
            ipoc = None
        if ipoc in self.expect:
            self.expect.remove(ipoc)
            self.late = 0                       # in time: the late packets in a row end
        elif ipoc not in self.recent:
            self.hub.trace("rsi", "error", text=f"an answer with IPOC {ipoc} that no packet was sent with")
            return
        # a late answer (its packet already counted late) still carries the sensor's newest values
        for el in self.ctx.receive:
            v = _value(root, el.tag)
            if v is None:
                if not el.holdon:
                    self.outputs[el.indx] = 0.0
                continue
            self.outputs[el.indx] = v
        self._apply()

    def _input(self, obj: RsiObject, idx: int) -> float:
        src = obj.inputs.get(idx)
        if src is None:
            return 0.0
        o = self.ctx.objects.get(src[0])
        if o is None or o.type != "ETHERNET":
            return 0.0
        return float(self.outputs.get(src[1], 0.0))

    def _apply(self) -> None:
        for obj in self.ctx.of_type("AXISCORR"):
            v = np.array([self._input(obj, i) for i in range(1, 7)])
            total = v if self.mode == "ABSOLUTE" else self.corr_axes + v
            lo = np.array([_param(obj, f"LowerLimA{i}", -1e9) for i in range(1, 7)])
            hi = np.array([_param(obj, f"UpperLimA{i}", 1e9) for i in range(1, 7)])
            self.corr_axes = np.clip(total, lo, hi)
        for obj in self.ctx.of_type("POSCORR"):
            v = np.array([self._input(obj, i) for i in range(1, 7)])
            total = v if self.mode == "ABSOLUTE" else self.corr_cart + v
            lo = np.array([_param(obj, f"LowerLim{k}", -1e9) for k in CART])
            hi = np.array([_param(obj, f"UpperLim{k}", 1e9) for k in CART])
            total = np.clip(total, lo, hi)
            mt = _param(obj, "MaxTrans", 1e9)
            n = float(np.linalg.norm(total[:3]))
            if n > mt > 0:
                total[:3] *= mt / n
            mr = _param(obj, "MaxRotAngle", 1e9)
            total[3:] = np.clip(total[3:], -mr, mr)
            self.corr_cart = total
        for obj in self.ctx.of_type("STOP"):
            if self._input(obj, 1) != 0.0:
                self.stopped = True
        ctl = self.hub.ctl
        for obj in self.ctx.of_type("AXISCORRMON"):
            for i in range(6):
                if abs(self.corr_axes[i]) > _param(obj, f"MaxA{i + 1}", 1e9):
                    self.fail(ctl, MSG_MON + f" (A{i + 1})", MON_NUMBER)
                    return
        for obj in self.ctx.of_type("POSCORRMON"):
            if float(np.linalg.norm(self.corr_cart[:3])) > _param(obj, "MaxTrans", 1e9):
                self.fail(ctl, MSG_MON + " (translation)", MON_NUMBER)
                return

    # ------------------------------------------------------------------ the correction
    @property
    def axes(self) -> np.ndarray:
        """The axis correction (deg, A1..A6) the controller superposes (robot/controller.py)."""
        return self.corr_axes

    @property
    def cart(self) -> np.ndarray:
        """The Cartesian correction (X, Y, Z mm, A, B, C deg, in $BASE) the controller superposes."""
        return self.corr_cart

    def message(self, ctl, ipoc: int) -> bytes:
        """The robot's packet of one sensor cycle (the elements SEND names, and IPOC)."""
        q = np.array(ctl.axis_act(), dtype=float)[:6]
        parts = ['<Rob Type="KUKA">']
        tags = {t.upper() for t in self.ctx.send}
        fr = ctl.tcp_frame()
        if "DEF_RIST" in tags:
            parts.append("<RIst " + " ".join(f'{k}="{_f(v)}"' for k, v in zip(CART, fr)) + "/>")
        if "DEF_RSOL" in tags:
            parts.append("<RSol " + " ".join(f'{k}="{_f(v)}"' for k, v in zip(CART, fr)) + "/>")
        if "DEF_AIPOS" in tags:
            parts.append("<AIPos " + " ".join(f'{k}="{_f(v)}"' for k, v in zip(AXES, q)) + "/>")
        if "DEF_ASPOS" in tags:
            parts.append("<ASPos " + " ".join(f'{k}="{_f(v)}"' for k, v in zip(AXES, q)) + "/>")
        if "DEF_EIPOS" in tags:
            parts.append("<EIPos " + " ".join(f'E{i}="0.0"' for i in range(1, 7)) + "/>")
        if "DEF_DELAY" in tags:
            parts.append(f'<Delay D="{self.late}"/>')
        parts.append(f"<IPOC>{ipoc}</IPOC></Rob>")
        return "".join(parts).encode()


def _f(v: float) -> str:
    return f"{float(v):.4f}"


def _param(obj: RsiObject, name: str, default: float) -> float:
    try:
        return float(obj.params.get(name, default))
    except ValueError:
        return default


def _value(root, tag: str) -> float | None:
    """The value of RECEIVE tag ``EL.ATTR`` (an attribute) or ``EL`` (an element's text)."""
    el_name, _, attr = tag.partition(".")
    for el in root.iter():
        if local(el.tag).upper() == el_name.upper():
            text = None
            if attr:
                for k, v in el.attrib.items():
                    if local(k).upper() == attr.upper():
                        text = v
            else:
                text = el.text
            if text is None:
                return None
            try:
                v = float(text.strip())
            except ValueError:
                return None
            return v if np.isfinite(v) else None
    return None


class RsiPartner(Partner):
    """RobotSensorInterface (net/partner.py): the run's RSI object (:class:`Rsi`, created at the
    program's first RSI function) and its sensor's address, ``network: {rsi: {config,
    address}}`` (docs/network.md "RobotSensorInterface")."""

    key = "rsi"
    fields = {"rsi": None}
    docs = "RobotSensorInterface"
    max_pace = 1.0
    pace_reason = "RSI answers within its cycle in real time"
    opens = ("RSI_CREATE", "RSI_LOAD")

    def __init__(self, hub) -> None:
        super().__init__(hub)
        self.rsi: Rsi | None = None

    def instance(self) -> Rsi:
        """The run's RSI object, created at the first RSI function."""
        if self.rsi is None:
            self.rsi = Rsi(self.hub)
        return self.rsi

    @classmethod
    def parse(cls, doc, base: Path) -> dict:
        return {"rsi": channel(doc, base, "network: rsi")}

    def attach(self, ctl, **cell) -> None:
        """Nothing starts before the program's RSI_ON (its ETHERNET object's socket)."""

    @property
    def attached(self) -> bool:
        return self.rsi is not None and self.rsi.endpoint is not None

    def ticking(self) -> bool:
        return self.rsi is not None and self.rsi.on

    def poll(self, ctl, live: bool) -> None:
        if self.rsi is not None:
            self.rsi.cycle(ctl, live=live)

    def replay(self, ev: dict) -> None:
        if self.rsi is not None:
            self.rsi.replayed(ev)

    def close(self) -> None:
        if self.rsi is not None:
            self.rsi.close()

    def sockets(self) -> dict:
        return {"sensor": self.rsi.endpoint} if self.attached else {}

    @classmethod
    def starter(cls, opened: list[tuple[str, str]], root: Path) -> list[str]:
        out = []
        for name, where in opened:
            ctx = find_context(name, None, root)
            note = f"context {ctx.relative_to(root)}" if ctx is not None else \
                "no SensorInterface/" + name + ".rsi.xml in the backup: name one with config:"
            out.append(f"#   rsi: {{address: 127.0.0.1:49152}}   # the sensor; context {name} created at {where}; {note}")
        return out
