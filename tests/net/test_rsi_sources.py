"""RSI answers as the option takes them (issue 61; docs/network.md, Decisions: "RSI"): only
from the sensor's configured address and port, one answer per IPOC. A sensor written here from
the protocol (it echoes each packet's IPOC) answers every packet with a Z correction of 1 mm in
#RELATIVE; on the way it sends one answer twice, answers one packet only after the next has
come (a stale IPOC), and a second socket on another local port sends three answers of 3 mm with
the current IPOC. Before, the three foreign answers moved the robot 9 mm, the duplicate moved it
twice and the stale answer was applied; now every answer applied adds its millimetre, the
duplicate and the stale one are late answers (counted, not applied) and the foreign ones never
arrive, on both interpreters. (A packet after the stale one may be late too on a loaded machine:
once a packet is late the controller stops waiting for the sensor, docs/network.md; the test
counts what the controller counted, and requires the two late answers it made itself.)"""

from __future__ import annotations

import socket
import time
import xml.etree.ElementTree as ET

import pytest

from net.settings import Channel, NetworkSettings

from .helpers import EXAMPLES, PROGRAMS, net_events, run_with_partner

#: the RSI partner answers in real time (4/12 ms cycles): make test runs these on one worker (tests/conftest.py, ``wall_clock``)
pytestmark = pytest.mark.wall_clock

PACKETS = 30
DUPLICATE, STALE, FOREIGN = 5, 12, 18


def sen(ipoc: str, z: float, stop: int = 0) -> bytes:
    return (f'<Sen Type="ImFree"><RKorr X="0" Y="0" Z="{z}" A="0" B="0" C="0"/><Stop>{stop}</Stop>'
            f"<IPOC>{ipoc}</IPOC></Sen>").encode()


def sensor_sockets() -> tuple[socket.socket, socket.socket]:
    """(the sensor's UDP socket, another one on another local port), both on loopback."""
    out = []
    for _ in range(2):
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        s.bind(("127.0.0.1", 0))
        out.append(s)
    return out[0], out[1]


def make_sensor():
    sock, rogue = sensor_sockets()

    def partner(net, rt):
        sock.settimeout(0.5)
        late = []                                    # the IPOCs it answered twice or too late
        held = None
        i = 0
        end = time.monotonic() + 60
        while time.monotonic() < end and not net.closed and i <= PACKETS:
            try:
                data, peer = sock.recvfrom(65536)
            except TimeoutError:
                continue
            ipoc = ET.fromstring(data).find("IPOC").text
            if i == STALE:
                held = ipoc                          # answered only after the next packet came
            else:
                if held is not None:
                    sock.sendto(sen(held, 1.0), peer)
                    late.append(held)
                    held = None
                if i == FOREIGN:
                    for _ in range(3):
                        rogue.sendto(sen(ipoc, 3.0), peer)
                stop = 1 if i == PACKETS else 0
                sock.sendto(sen(ipoc, 0.0 if stop else 1.0, stop), peer)
                if i == DUPLICATE:
                    sock.sendto(sen(ipoc, 1.0), peer)
                    late.append(ipoc)
            i += 1
        sock.close()
        rogue.close()
        return late

    return partner, sock.getsockname()


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_only_the_sensor_and_one_answer_per_ipoc(interp):
    # the held packet is late once the controller has waited ANSWER_WAIT_S (2 s) of wall time for it
    partner, addr = make_sensor()
    settings = NetworkSettings(PROGRAMS, rsi=Channel(EXAMPLES / "rsi_path.rsi.xml", addr))
    box: dict = {}
    result, trace, late = run_with_partner(PROGRAMS / "rsi_relative.src", settings, partner,
                                           interp=interp, box=box)
    assert result.reason in ("completed", "max_sim_time"), (result.reason, result.text)   # the sensor's end stops the run
    rsi = box["rt"].controller.network.partner("rsi").rsi
    errors = [e["text"] for e in net_events(trace, iface="rsi", dir="error")]
    # the three answers from another port: ignored, never an answer (nor in the recording)
    assert sum("not the sensor's address" in t for t in errors) == 3
    answers = net_events(trace, iface="rsi", dir="in")
    assert not any('Z="3.0"' in e["data"] for e in answers)
    # the duplicate and the stale answer: late answers, counted, not applied (on a loaded machine
    # the first answer to the duplicated packet may come late too: then both are)
    assert len(late) == 2
    for ipoc in late:
        assert sum(f"a late answer with IPOC {ipoc} " in t for t in errors) >= 1, (ipoc, errors)
    assert rsi.late_answers == sum("a late answer with IPOC" in t for t in errors) >= 2
    # every other answer of 1 mm applied once: the correction is theirs and nothing else's
    ones = sum('Z="1.0"' in e["data"] for e in answers)
    assert ones >= PACKETS - 1
    assert rsi.corr_cart[2] == pytest.approx(1.0 * (ones - rsi.late_answers))
