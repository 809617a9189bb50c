"""A sensor written from an RSI ETHERNET configuration (KUKA's ROOT document), for the tests
that run the corpus's RSI programs with their published contexts (issue 50).

It reads the configuration itself with ElementTree (not with net/): the port, SENTYPE, and
the RECEIVE tags. Each robot packet (``<Rob>``) is answered with a ``<Sen Type=SENTYPE>``
carrying every RECEIVE element: the correction tags (``AK.A1``.., ``AKorr.A1``..,
``RKorr.X``..) from ``plan(i, rob)``, ``Stop`` when the plan says so, ``DEF_EStr`` as ``<EStr>``,
anything else 0; IPOC echoed."""

from __future__ import annotations

import re
import socket
import time
import xml.etree.ElementTree as ET
from pathlib import Path

AXES = ("A1", "A2", "A3", "A4", "A5", "A6")
CART = ("X", "Y", "Z", "A", "B", "C")


class ConfigSensor:
    def __init__(self, config: Path):
        root = ET.parse(config).getroot()
        conf = root.find("CONFIG")
        self.sentype = (conf.findtext("SENTYPE") or "ImFree").strip()
        self.onlysend = (conf.findtext("ONLYSEND") or "FALSE").strip().upper() == "TRUE"
        self.receive = [e.get("TAG") for e in root.findall("RECEIVE/ELEMENTS/ELEMENT")]
        self.axis_tag = next((t.split(".")[0] for t in self.receive if t.split(".")[-1] == "A1"
                              and t.split(".")[0].upper() in ("AK", "AKORR")), None)
        self.cart_tag = next((t.split(".")[0] for t in self.receive if t.split(".")[-1] == "X"
                              and t.split(".")[0].upper() in ("RK", "RKORR")), None)
        self.has_stop = any(t.upper() == "STOP" for t in self.receive)
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.address = self.sock.getsockname()
        self.got: list[ET.Element] = []
        self.sent: list[dict] = []

    def body(self, values: dict, stop: bool) -> str:
        """The answer's elements: `values` maps "AK"/"RKorr" components to numbers."""
        groups: dict[str, list[str]] = {}
        texts = []
        for tag in self.receive:
            head, _, attr = tag.partition(".")
            if head.upper() == "DEF_ESTR":
                texts.append("<EStr>sensor of the test</EStr>")
                continue
            if head.upper().startswith("DEF_"):
                continue
            if not attr:
                texts.append(f"<{head}>{1 if (stop and head.upper() == 'STOP') else 0}</{head}>")
                continue
            v = values.get((head, attr), 0.0)
            groups.setdefault(head, []).append(f'{attr}="{v:.4f}"')
        return "".join(f"<{h} {' '.join(a)}/>" for h, a in groups.items()) + "".join(texts)

    def partner(self, plan, stop_after: float = 60.0):
        """The partner function of helpers.run_with_partner: `plan(i, rob)` returns (values,
        stop) for the i-th packet, None to stay silent, or "done" to end."""
        def run(net, rt):
            self.sock.settimeout(0.3)
            end = time.monotonic() + stop_after
            try:
                while time.monotonic() < end and not net.closed:
                    try:
                        data, peer = self.sock.recvfrom(65536)
                    except TimeoutError:
                        continue
                    # KUKA writes SEND tags such as GPIO.01 as attributes named 01, which an
                    # XML parser refuses; kroshu's SDK reads them by text search
                    rob = ET.fromstring(re.sub(rb"(\s)([0-9][\w.-]*=)", rb"\1_\2", data))
                    self.got.append(rob)
                    step = plan(len(self.got) - 1, rob)
                    if step == "done":
                        return self.got
                    if step is None or self.onlysend:
                        continue
                    values, stop = step
                    ipoc = rob.findtext("IPOC")
                    self.sent.append(dict(values))
                    self.sock.sendto(f'<Sen Type="{self.sentype}">{self.body(values, stop)}<IPOC>{ipoc}</IPOC></Sen>'
                                     .encode(), peer)
                # the run ended: the packets sent before it did are read too (on a loaded machine
                # the last one could still wait in the socket when the loop saw the end)
                self.sock.setblocking(False)
                while True:
                    try:
                        data, _peer = self.sock.recvfrom(65536)
                    except (BlockingIOError, OSError):
                        break
                    self.got.append(ET.fromstring(re.sub(rb"(\s)([0-9][\w.-]*=)", rb"\1_\2", data)))
            finally:
                self.sock.close()
            return self.got
        return run


def axes_of(rob) -> list[float] | None:
    el = rob.find("AIPos")
    return None if el is None else [float(el.get(a)) for a in AXES]


def tcp_of(rob) -> list[float] | None:
    el = rob.find("RIst")
    return None if el is None else [float(el.get(k)) for k in CART]
