"""An EKI server channel's one place for a partner (issue 61; net/transport.py ``TcpServer``):
a partner that closes and connects again at once is taken (the server used to accept the new
connection before it noticed the old one close, refuse it, and the program read 1 of the 5
messages sent); a partner that connects and stays silent gives its place, after
``MAX_EKI_IDLE_S`` of the controller's time, to a new one (it held the place forever), and the
program sees EKI00512 as for any dropped connection. The program (tests/net/programs/
eki_guard.src) counts what it reads; the partners are plain sockets."""

from __future__ import annotations

import socket
import time

import pytest

from krl.limits import MAX_EKI_IDLE_S
from net.settings import Channel, NetworkSettings

from .helpers import PROGRAMS, net_events, run_with_partner


def settings(pace: float = 1.0) -> NetworkSettings:
    return NetworkSettings(PROGRAMS, eki={"GUARD": Channel(PROGRAMS / "Guard.xml", ("127.0.0.1", 0))}, pace=pace)


def wait_for(predicate, what: str, timeout: float = 60.0) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"waited {timeout:g} s for {what}")
        time.sleep(0.01)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_partner_reconnecting_at_once_is_taken(interp):
    def partner(net, rt):
        addr = net.wait_address("eki:Guard")
        sink = net.sink
        first = socket.create_connection(addr, timeout=10)
        first.sendall(b'<Cmd Val="0.5"/>')
        wait_for(lambda: int(sink.read_var("NREAD")) == 1, "the first message read")
        first.close()
        again = socket.create_connection(addr, timeout=10)      # before the next IPO cycle's poll
        for v in range(1, 6):
            again.sendall(f'<Cmd Val="{v}"/>'.encode())
        wait_for(lambda: int(sink.read_var("NREAD")) >= 6, "the five messages of the new connection")
        again.close()
        return int(sink.read_var("NREAD")), float(sink.read_var("LASTVAL"))

    result, trace, (nread, last) = run_with_partner(PROGRAMS / "eki_guard.src", settings(), partner,
                                                    interp=interp, max_sim_time=120.0)
    assert (nread, last) == (6, 5.0)
    assert not net_events(trace, iface="eki", dir="refused")


def test_a_silent_partner_gives_its_place_after_the_idle_limit():
    def partner(net, rt):
        addr = net.wait_address("eki:Guard")
        sink = net.sink
        silent = socket.create_connection(addr, timeout=10)
        wait_for(lambda: sink.read_var("CONN") == "TRUE", "the silent partner connected")
        since = rt.controller.time
        early = socket.create_connection(addr, timeout=10)       # refused: the silent one is not idle yet
        early.settimeout(20)
        refused = early.recv(100) == b""
        early.close()
        wait_for(lambda: rt.controller.time > since + MAX_EKI_IDLE_S + 0.5, "the idle limit", timeout=120)
        late = socket.create_connection(addr, timeout=10)
        late.sendall(b'<Cmd Val="7.5"/>')
        wait_for(lambda: float(sink.read_var("LASTVAL")) == 7.5, "the new partner's message")
        silent.settimeout(20)
        dropped = silent.recv(100) == b""
        late.close()
        silent.close()
        return refused, dropped, [int(sink.read_var(f"MSGS[{i}]")) for i in range(1, int(sink.read_var("NMSG")) + 1)]

    result, trace, (refused, dropped, msgs) = run_with_partner(PROGRAMS / "eki_guard.src", settings(pace=10), partner,
                                                               max_sim_time=600.0)
    assert refused and dropped
    assert 512 in msgs                                   # the program saw the silent partner's drop
    drops = [e for e in net_events(trace, iface="eki", dir="disconnect") if "idle for" in (e.get("text") or "")]
    assert len(drops) == 1 and drops[0]["t"] >= MAX_EKI_IDLE_S
