"""Hostile partners (issue 35, done-when 3): random bytes, an XML bomb, a flood, a drop in
the middle of a message, an oversized message and a slow sender each end cleanly within a
bounded time, and the program sees the EKI_STATUS the controller would give: EKI01024 for
XML that cannot be read, EKI01536 for a message past BUFFSIZE, EKI01280 when the element
memory is full, EKI00512 when the connection is destroyed; the good message after each is
read. The program (tests/net/programs/eki_guard.src) records every Msg_No it sees; the
channel's messages are not displayed (MESSAGES Display="disabled"), so nothing stops it."""

from __future__ import annotations

import random
import socket
import time

import pytest

from krl.semantics.values import KrlRuntimeError
from net.settings import Channel, NetworkSettings

from .helpers import PROGRAMS, run_with_partner

BOMB = b"""<?xml version="1.0"?>
<!DOCTYPE lolz [<!ENTITY lol "lol"><!ENTITY lol1 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
<!ENTITY lol2 "&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;">
<!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">]>
<Cmd Val="&lol3;"/>"""


def good(v: float) -> bytes:
    return f'<Cmd Val="{v}"/>'.encode()


def connect(net):
    return socket.create_connection(net.wait_address("eki:Guard"), timeout=10)


def wait_for(predicate, what: str, timeout: float = 90.0) -> None:
    """Poll `predicate` until it holds: the partner's next step waits on what the program
    has seen, never on a guess of how long the controller takes (the suite runs under load)."""
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"waited {timeout:g} s for {what}")
        time.sleep(0.02)


def seen(net) -> set[int]:
    """The Msg_No values the program has recorded (MSGS[1..min(NMSG, 16)]). The program counts
    NMSG one statement before it writes MSGS[NMSG]: read between the two (this thread runs beside
    the run), that element is still unset ("value invalid"), not seen yet."""
    sink = net.sink
    n = int(sink.read_var("NMSG"))
    out = set()
    for i in range(1, min(n, 16) + 1):
        try:
            out.add(int(sink.read_var(f"MSGS[{i}]")))
        except KrlRuntimeError:
            pass
    return out


def saw(net, msg_no: int) -> None:
    wait_for(lambda: msg_no in seen(net), f"EKI Msg_No {msg_no}")


def read_good(net) -> None:
    wait_for(lambda: float(net.sink.read_var("LASTVAL")) == 7.5, "the good message (LASTVAL = 7.5)")


def random_bytes(net, rt):
    s = connect(net)
    rng = random.Random(35)
    s.sendall(bytes(rng.randrange(256) for _ in range(20000)))
    s.close()                                   # whatever was pending is dropped with it
    saw(net, 512)
    s = connect(net)
    s.sendall(good(7.5))
    read_good(net)
    return s


def xml_bomb(net, rt):
    s = connect(net)
    s.sendall(BOMB)
    saw(net, 1024)
    s.sendall(good(7.5))
    read_good(net)
    return s


def flood(net, rt):
    s = connect(net)
    payload = b"".join(good(i) for i in range(3000))
    s.sendall(payload)
    saw(net, 1280)
    s.sendall(good(7.5))
    read_good(net)
    return s


def drop_mid_message(net, rt):
    s = connect(net)
    s.sendall(b'<Cmd Val="99')
    s.close()
    saw(net, 512)
    s = connect(net)
    s.sendall(good(7.5))
    read_good(net)
    return s


def oversized(net, rt):
    s = connect(net)
    s.sendall(b'<Cmd Val="1">' + b"x" * 5000 + b"</Cmd>")
    saw(net, 1536)
    s.sendall(good(7.5))
    read_good(net)
    return s


def slow_sender(net, rt):
    s = connect(net)
    for b in good(7.5):
        s.sendall(bytes([b]))
        time.sleep(0.005)
    read_good(net)
    return s


CASES = {
    # case: (partner, Msg_No the program must have seen, values it must never have read)
    "random_bytes": (random_bytes, {512}, ()),
    "xml_bomb": (xml_bomb, {1024}, ()),
    "flood": (flood, {1280}, ()),
    "drop_mid_message": (drop_mid_message, {512}, (99.0,)),
    "oversized": (oversized, {1536}, ()),
    "slow_sender": (slow_sender, set(), ()),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_hostile_partner(case):
    partner, expected, never = CASES[case]
    settings = NetworkSettings(PROGRAMS, eki={"GUARD": Channel(PROGRAMS / "Guard.xml", ("127.0.0.1", 0))})
    box: dict = {}
    started = time.monotonic()

    def run(net, rt):
        s = partner(net, rt)
        s.close()

    result, trace, _ = run_with_partner(PROGRAMS / "eki_guard.src", settings, run, box=box,
                                        max_sim_time=120.0)
    elapsed = time.monotonic() - started
    assert elapsed < 60, f"{case} took {elapsed:.1f} s"
    assert result.reason == "max_sim_time", (result.reason, result.text)   # never an error or a hang
    sink = box["rt"].controller.network.sink
    got = seen(box["rt"].controller.network)     # the run may end between NMSG's count and MSGS's write
    assert expected <= got, (case, got)
    assert got <= {512, 1024, 1280, 1536}, got
    assert float(sink.read_var("LASTVAL")) == 7.5
    assert int(sink.read_var("MAXBUFF")) < 16                    # BUFFERING Limit
    for v in never:
        assert not any(e.get("data", "").find(f'Val="{v:g}"') >= 0
                       for e in trace.events if e["kind"] == "net" and e["dir"] == "in")
    if case == "flood":
        # the flood was read at most MAX_NET_BYTES_PER_CYCLE a cycle, each message traced once
        assert int(sink.read_var("NREAD")) >= 16
    net = box["rt"].controller.network
    assert not net.endpoints                                         # closed at the run's end
