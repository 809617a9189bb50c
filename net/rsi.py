"""KUKA.RobotSensorInterface: the RSI context, its ETHERNET object and the corrections
(docs/network.md "RobotSensorInterface").

``RSI_CREATE("NAME", CONTID, TRUE)`` reads the context (net/rsicontext.py: RSI 3
``NAME.rsi.xml`` or RSI 4/5 ``NAME.rsix``, in the backup's
``Config/User/Common/SensorInterface/``, beside the program, or the cell file's ``rsi:
{config: ...}``) and its ETHERNET configuration. Simulated objects:

* ``ETHERNET`` — ``ConfigFile`` (KUKA's ROOT document: ``CONFIG/IP_NUMBER``, ``PORT``,
  ``SENTYPE``, ``ONLYSEND``; ``SEND`` and ``RECEIVE`` elements with TAG, TYPE, INDX (a channel
  or INTERNAL), HOLDON), ``Timeout`` (late packets allowed in a row; past it the robot stops),
  ``Precision`` (decimals sent, at least 4);
* ``AXISCORR`` (inputs A1..A6; ``LowerLimAn``/``UpperLimAn``: the total correction is held
  within them, deg) and ``POSCORR`` (inputs X, Y, Z, A, B, C in $BASE; ``LowerLimX`` ..
  ``UpperLimC``, ``MaxTrans`` mm, ``MaxRotAngle`` deg);
* ``AXISCORRMON`` / ``POSCORRMON`` (``MaxAn`` / ``MaxTrans``, ``MaxRotAngle``: a total
  correction past them stops the robot; outputs 1..6 the total correction);
* the stateless blocks of RSI's toolbox (:data:`BLOCKS`: ``LIMIT`` (input 1 within
  ``LowerLimit``..``UpperLimit``), ``SUM``, ``SUB``, ``MULTI``, ``Division``, ``ABS``, ``NORM``,
  ``MinMax``, ``Equal``/``Greater``/``Less``, ``AND``/``OR``/``XOR``/``NOT``, ...);
* ``STOP`` (input 1 non-zero: ``RSI_MOVECORR`` ends).

Any other object is not simulated: one message says so, and its outputs read 0. RECEIVE's
``DEF_EStr`` (INTERNAL) is the sensor's text, shown as a message when it changes; the other
INTERNAL values of RECEIVE (``DEF_Tech.Tn``) are read and ignored, with one message.

Each sensor cycle (12 ms; ``RSI_ON(mode, #IPO_FAST)``: three of 4 ms in each IPO cycle) the
controller sends, over UDP to the sensor, KUKA's XML::

    <Rob Type="KUKA"><RIst X=".." Y=".." Z=".." A=".." B=".." C=".."/><RSol .../>
      <AIPos A1=".." .. A6=".."/><ASPos .../><Delay D="late packets"/><IPOC>ms</IPOC></Rob>

(the elements its SEND names) and expects the answer ``<Sen Type=".."><AK A1=".." ../>
<RKorr X=".." ../><Stop>0</Stop><IPOC>same</IPOC></Sen>`` before the next one. The answer's
RECEIVE elements are the ETHERNET object's outputs by INDX. ``#ABSOLUTE``: the correction is
the total offset from where RSI_ON found the robot; ``#RELATIVE``: each answer adds to it.
A cycle without its answer is *late*: counted (``Delay``; only an answer in time ends the
count). The sensor is the configured address and port (a datagram from elsewhere is an error
event, ignored: transport.Udp ``foreign``), one answer per IPOC: a second answer to a packet or
an answer to a packet already counted late is a *late answer*, counted (``late_answers``) and
never applied (docs/network.md, Decisions: "RSI"). In time is in simulated time: a
live sensor's answer is waited for until the next cycle starts (:data:`ANSWER_WAIT_S` of wall
time at most; a sensor silent that long is late at once from then on), so neither a slow
simulator nor a loaded machine makes a packet late. Past ``Timeout`` late packets
in a row the robot stops with the KSS message "RSI: maximum number of late packets
exceeded" and the program with it. The corrections superpose on the programmed motion
(robot/controller.py ``correction``); RSI_OFF keeps the corrected position. Everything that
arrives or leaves is a ``net`` event (iface ``rsi``), so a replay feeds the same answers.
"""

from __future__ import annotations

import math
import re
import select
import time

import numpy as np

from krl.limits import MAX_RSI_DATAGRAM_BYTES

from . import transport
from .cellkey import LOOPBACK, channel
from .partner import Partner
from .rsi2 import CREATES, FRAMES, MAX_PARAM, RSI2, SignalFlow, find_ethernet, init_folders, param_name
from .rsicontext import (AXES, CART, MAX_CHANNELS, Context, RsiConfigError, RsiObject, find_context,
                         is_ethernet_config, load_context)
from .xmlsafe import XmlRefused, local, parse

RSIOK, RSIINVOBJID, RSIINVPARAM, RSINOMEM, RSIINVOBJTYPE, RSIINVCONN, RSIALREADYON, RSINOTON, RSIOBJUSED = range(9)
MSG_LATE = "RSI: maximum number of late packets exceeded"
MSG_MON = "RSI: correction monitoring exceeded"
SENSOR_CYCLE_MS = 12
FAST_CYCLE_MS = 4
LATE_NUMBER = 1
MON_NUMBER = 2
#: Wall-clock seconds the simulated controller waits for the live sensor's answer to a packet
#: before it counts the packet late (docs/network.md, Decisions: "an answer is in time in
#: simulated time"). The simulator is not a real-time controller: how fast it runs depends on
#: the machine and its load, so a packet's answer is in time when it is there when the next
#: sensor cycle starts, however long that took on the wall clock. A sensor that has not
#: answered for this long is silent: its packets are late from then on, at once, without
#: waiting, until it answers again (so Timeout + 1 silent cycles still stop the robot).
ANSWER_WAIT_S = 2.0
#: s of wall time between two looks at whether the sensor is known gone while waiting for it
WAIT_SLICE_S = 0.05
MIN_DECIMALS = 4        # values are sent with max(Precision, 4) decimals (docs/network.md, Decisions)
MAX_FLOW_DEPTH = 64     # links followed from an object back to its sources
def _first(ins: list, k: int = 0) -> float:
    return ins[k] if len(ins) > k else 0.0


def _compared(o, ins: list) -> float:
    """The second operand of Equal/Greater/Less: input 2 when linked, else ``CompVal``."""
    return ins[1] if len(ins) > 1 else o.param("CompVal", 0.0)


# The stateless blocks of RSI's toolbox (the "Math" and "Logic" subsets of the blueprint
# collection WorkVisual writes into every .rsix, e.g. FZI's published KR_C5 ros_rsi.rsix: their
# inputs and parameters): type -> fn(object, the linked inputs in index order, output index).
# A logic input is TRUE when non-zero; Greater/Less ignore their Hysteresis (no state).
BLOCKS = {
    "LIMIT": lambda o, i, k: min(max(_first(i), o.param("LowerLimit", -10.0)), o.param("UpperLimit", 10.0)),
    "ABS": lambda o, i, k: abs(_first(i)),
    "CEIL": lambda o, i, k: math.ceil(_first(i)),
    "FLOOR": lambda o, i, k: math.floor(_first(i)),
    "ROUND": lambda o, i, k: round(_first(i), int(o.param("nDig", 0))),
    "POW": lambda o, i, k: _first(i) ** o.param("Exp", 0.0),
    "NORM": lambda o, i, k: math.sqrt(sum(v * v for v in i)),
    "MULTI": lambda o, i, k: _first(i) * _first(i, 1),
    "SUM": lambda o, i, k: sum(i) + o.param("Value", 0.0),
    "SUB": lambda o, i, k: _first(i) - sum(i[1:]) - o.param("Value", 0.0),
    "DIVISION": lambda o, i, k: _first(i) / _first(i, 1),
    "MINMAX": lambda o, i, k: (min(i) if k == 1 else max(i)) if i else 0.0,
    "EQUAL": lambda o, i, k: float(abs(_first(i) - _compared(o, i)) <= o.param("Tolerance", 0.0)),
    "GREATER": lambda o, i, k: float(_first(i) > _compared(o, i)),
    "LESS": lambda o, i, k: float(_first(i) < _compared(o, i)),
    "AND": lambda o, i, k: float(bool(i) and all(v != 0.0 for v in i)),
    "OR": lambda o, i, k: float(any(v != 0.0 for v in i)),
    "XOR": lambda o, i, k: float(sum(v != 0.0 for v in i) % 2 == 1),
    "NOT": lambda o, i, k: float(_first(i) == 0.0),
}
# the objects this module simulates; any other reads 0 on its outputs (one message says so)
SIMULATED = ("ETHERNET", "AXISCORR", "POSCORR", "AXISCORRMON", "POSCORRMON", "STOP", *BLOCKS)
# the controller's internal values a SEND element DEF_... writes: element and its attributes
INTERNAL_SEND = {
    "DEF_RIST": ("RIst", CART), "DEF_RSOL": ("RSol", CART),
    "DEF_AIPOS": ("AIPos", AXES), "DEF_ASPOS": ("ASPos", AXES),
    "DEF_EIPOS": ("EIPos", ("E1", "E2", "E3", "E4", "E5", "E6")),
    "DEF_ESPOS": ("ESPos", ("E1", "E2", "E3", "E4", "E5", "E6")),
    "DEF_MACUR": ("MACur", AXES), "DEF_MECUR": ("MECur", ("E1", "E2", "E3", "E4", "E5", "E6")),
    "DEF_DELAY": ("Delay", ("D",)),
}


class Rsi:
    """The RSI of one run (one context at a time, as the corpus's programs use it)."""

    def __init__(self, hub) -> None:
        self.hub = hub
        self.ctx: Context | None = None
        self.endpoint = None
        self.on = False
        self.mode = "ABSOLUTE"
        self.fast = False
        self.corr_axes = np.zeros(len(AXES))        # A1..A6 (KRL's components: robot/axismap.py)
        self.corr_cart = np.zeros(len(CART))
        self.outputs: dict[int, float] = {}
        self.expect: list[int] = []          # IPOCs sent and not answered yet
        self.recent: list[int] = []          # the last IPOCs sent (an answer to one not expected is late)
        self.late = 0
        self.late_total = 0
        self.late_answers = 0                # answers not applied: their IPOC already answered or counted late
        self.silent = False                  # no answer for ANSWER_WAIT_S: late without waiting
        self.stopped = False
        self.failed: str | None = None
        self.noted: set[str] = set()
        self.estr = ""
        self.q_on: np.ndarray | None = None
        self.flow: SignalFlow | None = None  # RSI 2: the objects the ST_ functions created

    # ------------------------------------------------------------------ functions
    def create(self, name: str) -> int:
        if self.ctx is not None:
            return RSIOBJUSED
        s = self.hub.settings
        chan = s.rsi if s is not None else None
        path = chan.config if chan is not None and chan.config is not None else \
            find_context(name, self.hub.program, self.hub.backup)
        if path is None:
            self.hub.net_message(f"RSI: context {name[:60]} not found (NAME.rsi.xml or NAME.rsix in "
                                 "Config/User/Common/SensorInterface or beside the program)")
            return RSIINVPARAM
        ethernet = getattr(chan, "ethernet", None) if chan is not None else None
        if chan is not None and chan.config is not None and ethernet is None and is_ethernet_config(chan.config):
            # the cell file names the ETHERNET configuration: the context RSI_CREATE names, where
            # the controller keeps it or beside that configuration, with it (else one implied)
            found = find_context(name, self.hub.program, self.hub.backup) or find_context(name, chan.config, None)
            if found is not None and not is_ethernet_config(found):
                path, ethernet = found, chan.config
        try:
            self.ctx = load_context(path, name, ethernet, self._folders())
        except RsiConfigError as exc:
            self.hub.net_message(f"RSI: {exc}")
            return RSIINVPARAM
        self.hub.trace("rsi", "context", name=name[:60],
                       text=f"{self.ctx.generation}: {len(self.ctx.objects)} objects from "
                            f"{self.ctx.path.name if self.ctx.path else '?'}, ETHERNET configuration "
                            f"{self.ctx.ethernet.path.name if self.ctx.ethernet.path else '?'}")
        for o in self.ctx.objects.values():
            if o.type not in SIMULATED and o.type not in self.noted:
                self.noted.add(o.type)
                self.hub.net_message(f"RSI: object {o.type} is not simulated (its outputs read 0)")
        for el in self.ctx.ethernet.send + self.ctx.ethernet.receive:
            key = el.tag.upper()
            if el.internal and key not in INTERNAL_SEND and key != "DEF_ESTR" and key not in self.noted:
                self.noted.add(key)
                self.hub.net_message(f"RSI: internal value {el.tag[:40]} is not simulated")
        return RSIOK

    def _folders(self) -> list:
        """Where else an ETHERNET configuration may be: beside the program, the backup's
        SensorInterface folders."""
        out = [self.hub.program.parent] if self.hub.program is not None else []
        b = self.hub.backup
        if b is not None:
            for top in (b, b / "KRC"):
                out += [top / "Config" / "User" / "Common" / "SensorInterface",
                        top / "Config" / "RobotSensorInterface" / "Ethernet configuration"]
        return out

    # ------------------------------------------------------------------ RSI 2 (ST_ functions)
    def st_create(self, func: str, config: str = "") -> tuple[int, int]:
        """An ST_ function that creates an object (net/rsi2.py): (RSIERR, handle)."""
        if self.ctx is not None and self.flow is None:
            return RSIOBJUSED, 0                 # an RSI 3+ context is loaded
        if self.flow is None:
            self.flow = SignalFlow()
            self.ctx = self.flow.ctx
        typ = CREATES[func]
        if typ == "ETHERNET" and self.flow.ctx.ethernet is not None:
            return RSIOBJUSED, 0
        obj = self.flow.create(typ)
        if obj is None:
            return RSINOMEM, 0
        if typ == "ETHERNET":
            path = self._st_config(config)
            if path is None:
                del self.flow.ctx.objects[obj.id]
                self.hub.net_message(f"RSI: {func}: ETHERNET configuration {config[:60]} not found (Roboter/Init "
                                     "of the backup, beside the program, or the cell file's rsi: {ethernet: PATH})")
                return RSIINVPARAM, 0
            try:
                self.flow.ethernet(obj, path)
            except RsiConfigError as exc:
                del self.flow.ctx.objects[obj.id]
                self.hub.net_message(f"RSI: {exc}")
                return RSIINVPARAM, 0
            self.hub.trace("rsi", "context", name=config[:60],
                           text=f"{RSI2}: ETHERNET object {obj.id} of {func}, ETHERNET configuration {path.name}")
            for el in self.ctx.ethernet.send + self.ctx.ethernet.receive:
                key = el.tag.upper()
                if el.internal and key not in INTERNAL_SEND and key != "DEF_ESTR" and key not in self.noted:
                    self.noted.add(key)
                    self.hub.net_message(f"RSI: internal value {el.tag[:40]} is not simulated")
        elif typ not in SIMULATED and typ not in self.noted:
            self.noted.add(typ)
            self.hub.net_message(f"RSI: object {func} is not simulated (its outputs read 0)")
        return RSIOK, int(obj.id)

    def _st_config(self, name: str):
        s = self.hub.settings
        chan = s.rsi if s is not None else None
        if chan is not None and getattr(chan, "ethernet", None) is not None:
            return chan.ethernet
        if chan is not None and chan.config is not None and is_ethernet_config(chan.config):
            return chan.config
        return find_ethernet(name, init_folders(self.hub.program, self.hub.backup))

    def st_link(self, h_out, out_idx: int, h_in, in_idx: int) -> int:
        """ST_NEWLINK: input `in_idx` of object `h_in` is output `out_idx` of `h_out`."""
        src = self.flow.obj(h_out) if self.flow is not None else None
        dst = self.flow.obj(h_in) if self.flow is not None else None
        if src is None or dst is None:
            return RSIINVOBJID
        if not (1 <= out_idx <= MAX_CHANNELS and 1 <= in_idx <= MAX_CHANNELS):
            return RSIINVPARAM
        dst.inputs[in_idx] = (src.id, out_idx)
        return RSIOK

    def st_setparam(self, handle, n: int, value: float) -> int:
        """ST_SETPARAM: parameter number `n` of the object (net/rsi2.py ``param_name``)."""
        obj = self.flow.obj(handle) if self.flow is not None else None
        if obj is None:
            return RSIINVOBJID
        if not 1 <= n <= MAX_PARAM:
            return RSIINVPARAM
        name = param_name(obj.type, n)
        if name is None:
            key = f"{obj.type}.{n}"
            if key not in self.noted:
                self.noted.add(key)
                self.hub.net_message(f"RSI: parameter {n} of {obj.type} is not simulated")
            name = f"P{n}"
        obj.params[name] = repr(float(value))
        return RSIOK

    def st_delete(self, handle) -> int:
        """ST_DELOBJ: the object and the links from it are gone."""
        obj = self.flow.obj(handle) if self.flow is not None else None
        if obj is None or self.on:
            return RSIINVOBJID if obj is None else RSIALREADYON
        del self.ctx.objects[obj.id]
        for o in self.ctx.objects.values():
            o.inputs = {k: v for k, v in o.inputs.items() if v[0] != obj.id}
        if obj.id == self.ctx.ethernet_id:
            self.ctx.ethernet_id, self.ctx.ethernet = "", None
        return RSIOK

    def st_on(self, ctl, frame: str | None = None) -> int:
        """ST_ON / ST_ON1: the sensor mode on, in the integration mode of the correction objects'
        parameter 1 (1 relative, 0 absolute; unset: relative, as RSI_ON's default)."""
        if self.flow is None or self.ctx.ethernet is None:
            self.hub.net_message("RSI: ST_ON without an ETHERNET object (ST_ETHERNET) is not simulated")
            return RSIINVOBJID
        if self.ctx.ethernet.protocol != "UDP":
            self.hub.net_message(f"RSI: PROTOCOL {self.ctx.ethernet.protocol} of "
                                 f"{self.ctx.ethernet.path.name} is not simulated (UDP is)")
            return RSIINVCONN
        modes = [o.param("IntegrationMode", 1.0) for o in self.ctx.objects.values()
                 if o.type in ("AXISCORR", "POSCORR") and o.param_name("IntegrationMode")]
        mode = "ABSOLUTE" if modes and modes[0] == 0.0 else "RELATIVE"
        if frame is not None:
            for o in self.ctx.of_type("POSCORR"):
                o.params["RefCorrSys"] = FRAMES.get(frame, "Base")
        return self.start(ctl, mode, False)

    def delete(self) -> int:
        if self.on:
            self.off()
        self.ctx = None
        self.flow = None
        return RSIOK

    def set_param(self, obj: str, name: str, value: float) -> int:
        """RSI_SETPUBLICPAR: object ids and parameter names compare without case."""
        if self.ctx is None:
            return RSIINVOBJID
        o = self.ctx.obj(obj)
        if o is None:
            return RSIINVOBJID
        o.params[o.param_name(name) or name] = repr(float(value))
        return RSIOK

    def get_param(self, obj: str, name: str) -> tuple[int, float]:
        if self.ctx is None:
            return RSIINVOBJID, 0.0
        o = self.ctx.obj(obj)
        if o is None:
            return RSIINVOBJID, 0.0
        k = o.param_name(name)
        if k is None:
            return RSIINVPARAM, 0.0
        try:
            return RSIOK, float(o.params[k])
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
        self.silent = False
        self.stopped = False
        self.failed = None
        self.q_on = np.array(ctl.actual.axis_act(), dtype=float)[:len(AXES)]
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
            self._await(self.expect)            # the last cycle's packets (ANSWER_WAIT_S)
            self._receive()
        self._count_late(ctl)
        if self.failed:
            return
        n = 3 if self.fast else 1
        base = int(round(ctl.time * 1000))
        for i in range(n):
            ipoc = base + i * FAST_CYCLE_MS
            msg = self.message(ctl, ipoc)
            self.hub.trace("rsi", "out", data=msg.decode("latin-1"))
            if not self.ctx.ethernet.onlysend:       # ONLYSEND TRUE: no answer is expected
                self.expect.append(ipoc)
            self.recent.append(ipoc)
            del self.recent[:-16]
            if live and self.endpoint is not None:
                self.endpoint.send(msg)
                if self.fast and i < n - 1:
                    if self.hub.pacer is not None:      # the sensor sees the 4 ms rhythm
                        time.sleep(FAST_CYCLE_MS / 1000.0 / self.hub.pacer.pace)
                    self._await([ipoc])                 # its answer before the next 4 ms packet
                    self._receive()

    def _receive(self) -> None:
        """What the sensor sent since the last look: each datagram from the sensor's address an
        answer; one from anywhere else an error event, ignored (transport.Udp: ``foreign``)."""
        for ev in self.endpoint.poll():
            if ev[0] == "data":
                self.hub.trace("rsi", "in", data=ev[1].decode("latin-1"))
                self.answer(ev[1])
            elif ev[0] == "foreign":
                sensor = self.endpoint.peer
                self.hub.trace("rsi", "error", text=f"a datagram from {ev[1][0]}:{ev[1][1]}, not the sensor's "
                                                    f"address {sensor[0]}:{sensor[1]}: ignored")

    def _await(self, ipocs: list[int]) -> None:
        """Live: wait until the packets `ipocs` are answered (each answer applied as it comes),
        at most :data:`ANSWER_WAIT_S` of wall time; past it the sensor is silent and is not
        waited for again until it answers."""
        sock = getattr(self.endpoint, "sock", None)
        if self.silent or sock is None:
            return
        pending = [i for i in ipocs if i in self.expect]
        end = time.monotonic() + ANSWER_WAIT_S
        while any(i in self.expect for i in pending) and not self.silent:
            left = end - time.monotonic()
            if left <= 0:
                self.silent = True
                return
            try:     # in slices, so that a sensor known gone (sensor_gone) is not waited for
                ready, _, _ = select.select([sock], [], [], min(left, WAIT_SLICE_S))
            except (OSError, ValueError):       # the socket was closed under us
                return
            if ready:
                self._receive()

    def sensor_gone(self) -> None:
        """The sensor has ended (its program or thread returned; another thread may say so): it
        is silent from now on, its packets late at once, and a wait for its answer ends at the
        next :data:`WAIT_SLICE_S` instead of after :data:`ANSWER_WAIT_S`."""
        self.silent = True

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
        return max(0, int(self.ctx.eth.param("Timeout", 100)))

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
            root = parse(_digit_names(data), MAX_RSI_DATAGRAM_BYTES, "RSI answer")
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
        elif ipoc in self.recent:
            # one answer per IPOC: a second answer to a packet, or one to a packet already counted
            # late, is a late answer: counted, never applied (docs/network.md, Decisions: "RSI")
            self.late_answers += 1
            self.silent = False
            self.hub.trace("rsi", "error", number=LATE_NUMBER,
                           text=f"a late answer with IPOC {ipoc} (already answered or counted late): not applied, "
                                f"{self.late_answers} so far")
            return
        else:
            self.hub.trace("rsi", "error", text=f"an answer with IPOC {ipoc} that no packet was sent with")
            return
        self.silent = False                     # the sensor answers: waited for again
        self.hub.sink.changed_outside()         # the outputs the program reads (RSI_GETPUBLICPAR, ...)
        for el in self.ctx.ethernet.receive:
            if el.internal:
                if el.tag.upper() == "DEF_ESTR":
                    self._sensor_text(root)
                continue
            v = _value(root, el.tag) if el.type != "STRING" else None
            if v is None:
                if not el.holdon:
                    self.outputs[el.indx] = 0.0
                continue
            self.outputs[el.indx] = v
        self._apply()

    def _sensor_text(self, root) -> None:
        """DEF_EStr: the sensor's text (``<EStr>``) is a message of the controller, once per
        change (the template: "Notification or error message"; not a stop)."""
        for el in root:
            if local(el.tag).upper() == "ESTR":
                text = (el.text or "").strip()[:200]
                if text and text != self.estr:
                    self.hub.net_message(f"RSI sensor: {text}")
                self.estr = text
                return

    def _input(self, obj: RsiObject, idx: int, depth: int = 0) -> float:
        """The value at input `idx` of `obj`: the output its link names (0 unlinked)."""
        src = obj.inputs.get(idx)
        if src is None or depth > MAX_FLOW_DEPTH:
            return 0.0
        o = self.ctx.obj(src[0])
        return self._output(o, src[1], depth + 1) if o is not None else 0.0

    def _output(self, o: RsiObject, idx: int, depth: int) -> float:
        """Output `idx` of object `o`: ETHERNET its RECEIVE channel, LIMIT its input clamped to
        LowerLimit..UpperLimit, the monitors the total correction; objects not simulated 0."""
        t = o.type
        if t == "ETHERNET":
            return float(self.outputs.get(idx, 0.0))
        if t == "AXISCORRMON" and 1 <= idx <= len(AXES):
            return float(self.corr_axes[idx - 1])
        if t == "POSCORRMON" and 1 <= idx <= len(CART):
            return float(self.corr_cart[idx - 1])
        fn = BLOCKS.get(t)
        if fn is None:
            return 0.0
        ins = [self._input(o, i, depth) for i in sorted(o.inputs)]
        try:
            v = float(fn(o, ins, idx))
        except (ValueError, ZeroDivisionError, OverflowError):
            return 0.0
        return v if np.isfinite(v) else 0.0

    def _apply(self) -> None:
        for obj in self.ctx.of_type("AXISCORR"):
            v = np.array([self._input(obj, i + 1) for i in range(len(AXES))])
            total = v if self.mode == "ABSOLUTE" else self.corr_axes + v
            lo = np.array([obj.param(f"LowerLim{k}", -1e9) for k in AXES])
            hi = np.array([obj.param(f"UpperLim{k}", 1e9) for k in AXES])
            self.corr_axes = np.clip(total, lo, hi)
        for obj in self.ctx.of_type("POSCORR"):
            v = np.array([self._input(obj, i + 1) for i in range(len(CART))])
            total = v if self.mode == "ABSOLUTE" else self.corr_cart + v
            lo = np.array([obj.param(f"LowerLim{k}", -1e9) for k in CART])
            hi = np.array([obj.param(f"UpperLim{k}", 1e9) for k in CART])
            total = np.clip(total, lo, hi)
            mt = obj.param("MaxTrans", 1e9)
            n = float(np.linalg.norm(total[:3]))
            if n > mt > 0:
                total[:3] *= mt / n
            mr = obj.param("MaxRotAngle", 1e9)
            total[3:] = np.clip(total[3:], -mr, mr)
            self.corr_cart = total
        for obj in self.ctx.of_type("STOP"):
            if self._input(obj, 1) != 0.0:
                self.stopped = True
        ctl = self.hub.ctl
        for obj in self.ctx.of_type("AXISCORRMON"):
            for i, k in enumerate(AXES):
                if abs(self.corr_axes[i]) > obj.param(f"Max{k}", 1e9):
                    self.fail(ctl, MSG_MON + f" ({k})", MON_NUMBER)
                    return
        for obj in self.ctx.of_type("POSCORRMON"):
            if float(np.linalg.norm(self.corr_cart[:3])) > obj.param("MaxTrans", 1e9):
                self.fail(ctl, MSG_MON + " (translation)", MON_NUMBER)
                return

    # ------------------------------------------------------------------ the correction
    @property
    def axes(self) -> np.ndarray:
        """The axis correction (deg, A1..A6) the controller superposes (robot/controller.py)."""
        return self.corr_axes

    @property
    def frame(self) -> str:
        """The frame of the Cartesian correction: the POSCORR's ``RefCorrSys`` (RSI 3 writes the
        name, RSI 4/5 the number of its enum: World 0, Base 1, RobRoot 2, Tool 3, TTS 4, as
        wingljj's published PoseTrack.rsix documents it); BASE when unset. RobRoot is taken as
        WORLD (the simulated robot stands at the world's origin) and TTS as TOOL."""
        for obj in self.ctx.of_type("POSCORR") if self.ctx is not None else ():
            k = obj.param_name("RefCorrSys")
            v = str(obj.params.get(k, "")).strip().upper() if k else ""
            return {"0": "WORLD", "WORLD": "WORLD", "2": "WORLD", "ROBROOT": "WORLD",
                    "3": "TOOL", "TOOL": "TOOL", "4": "TOOL", "TTS": "TOOL"}.get(v, "BASE")
        return "BASE"

    @property
    def cart(self) -> np.ndarray:
        """The Cartesian correction (X, Y, Z mm, A, B, C deg, in $BASE) the controller superposes."""
        return self.corr_cart

    def message(self, ctl, ipoc: int) -> bytes:
        """The robot's packet of one sensor cycle: the SEND elements in the configuration's
        order (internal values, and channels grouped by element: ``Tag.A1``.. as attributes of
        one ``<Tag>``), then IPOC."""
        q = np.array(ctl.actual.axis_act(), dtype=float)[:len(AXES)]
        fr = np.array(ctl.actual.tcp_frame(), dtype=float)
        eth = self.ctx.eth
        dec = max(MIN_DECIMALS, min(16, int(eth.param("Precision", MIN_DECIMALS))))
        groups: dict[str, list[tuple[str, str]]] = {}
        order: list[str] = []
        for el in self.ctx.ethernet.send:
            key = el.tag.upper()
            if el.internal:
                if key in INTERNAL_SEND:
                    name, comps = INTERNAL_SEND[key]
                    if name == "Delay":
                        vals = [str(self.late)]
                    elif name in ("RIst", "RSol"):
                        vals = [_f(v, dec) for v in fr[:len(CART)]]
                    elif name in ("AIPos", "ASPos"):
                        vals = [_f(v, dec) for v in q]
                    else:
                        vals = [_f(0.0, dec)] * len(comps)
                    if name not in groups:
                        order.append(name)
                        groups[name] = []
                    groups[name] += list(zip(comps, vals))
                continue
            head, _, attr = el.tag.partition(".")
            v = self._output_of_input(eth, el.indx)
            text = str(int(v)) if el.type in ("LONG", "BOOL") else ("" if el.type == "STRING" else _f(v, dec))
            if head not in groups:
                order.append(head)
                groups[head] = []
            groups[head].append((attr, text))
        parts = ['<Rob Type="KUKA">']
        for name in order:
            items = groups[name]
            attrs = [(k, v) for k, v in items if k]
            texts = [v for k, v in items if not k]
            if attrs:
                parts.append(f"<{name} " + " ".join(f'{k}="{v}"' for k, v in attrs) + "/>")
            if texts:
                parts.append(f"<{name}>{texts[-1]}</{name}>")
        parts.append(f"<IPOC>{ipoc}</IPOC></Rob>")
        return "".join(parts).encode()

    def _output_of_input(self, eth: RsiObject, indx: int) -> float:
        try:
            return self._input(eth, indx)
        except (TypeError, ValueError):
            return 0.0


def _f(v: float, dec: int = MIN_DECIMALS) -> str:
    return f"{float(v):.{dec}f}"


_DIGIT_ATTR = re.compile(rb"(\s)([0-9][A-Za-z0-9_.-]*\s*=)")


def _digit_names(data: bytes) -> bytes:
    """The answer with attribute names that start with a digit (``<Out 01="1"/>``: RECEIVE tags
    ``Out.01`` of ROS-Industrial's and ``GPIO.01`` of kroshu's configurations, which RSI writes
    and reads as they stand) prefixed with ``_`` so that an XML parser reads them."""
    return _DIGIT_ATTR.sub(rb"\1_\2", data) if len(data) <= MAX_RSI_DATAGRAM_BYTES else data


def _value(root, tag: str) -> float | None:
    """The value of RECEIVE tag ``EL.ATTR`` (an attribute) or ``EL`` (an element's text)."""
    el_name, _, attr = tag.partition(".")
    if attr[:1].isdigit():
        attr = "_" + attr
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


RSI_KEYS = ("config", "address", "ethernet")
"""The keys of ``network: {rsi: ...}``: the context, the sensor's address, the ETHERNET object's
configuration when it is not beside the context (net/rsicontext.py)."""


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
        return {"rsi": channel(doc, base, "network: rsi", RSI_KEYS)}

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
