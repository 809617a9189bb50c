"""EthernetKRL client channels (issue 46): the robot connects (the channel XML's external system
is ``<TYPE>Server</TYPE>``), and ``EKI_Open`` returns when the connection is up, or after
``TIMEOUT Connect`` with EKI00014 (KUKA's EthernetKRL 2.2 manual, 6.2.3 "Client mode" and the
INTERNAL element TIMEOUT; docs/network.md "EthernetKRL").

The corpus's one client-role EKI program is WeiminZhang's Kuka_Robot_Control_through_LAN
(Kuka/app1b.src): it sends right after EKI_Init and EKI_Open, with no wait of its own. Its
partner here is a plain TCP server written from the channel's XML kept beside the program in
its repository (Kuka/ConfigApp1.xml; tests/net/configs/ConfigApp1.xml): it reads each
``<Robot>`` document the robot sends (``Data/LastPos`` X..C) and answers ``<Pc><Data><SetPos
X=".." .../></Data></Pc>``, which the program takes as the next relative motion. The
program's target XP2 is out of the KR 6 R900's reach: it runs on the library's KR 180 R3200 PA.
A probe written from the manual (tests/net/programs/eki_client.src) checks the timeout with
messages not displayed, interrupts while EKI_Open waits, and a partner that starts late."""

from __future__ import annotations

import re
import socket
import threading
import time
import xml.etree.ElementTree as ET

import pytest

from interp.run import make_runtime, run_spec, RunSinks
from net.settings import Channel, NetworkSettings
from robot.machine import library_robots
from robot.trace import TraceWriter

from .helpers import CONFIGS, PROGRAMS, free_port, net_events, run_with_partner

#: the EKI client waits out its connect and message timeouts: make test runs these on one worker (tests/conftest.py, ``wall_clock``)
pytestmark = pytest.mark.wall_clock

APP1B = "WeiminZhang__Kuka_Robot_Control_through_LAN/Kuka/app1b.src"
ROBOT = "kr180_r3200_pa"
DT = 0.012


def _documents(conn, root: bytes, deadline: float):
    """Each complete <root> document the partner receives on TCP `conn` (one after the other, a
    document ends where its root element closes: ``<root .../>`` or ``</root>``)."""
    parser = ET.XMLPullParser(events=("start", "end"))
    parser.feed(b"<stream>")            # the documents as children of one open element
    depth = 0
    while time.monotonic() < deadline:
        data = conn.recv(65536)
        if not data:
            return
        parser.feed(data)
        for event, el in parser.read_events():
            if event == "start":
                depth += 1
            else:
                depth -= 1
                if depth == 1 and el.tag == root.decode():
                    yield el


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_client_library_sends_right_after_eki_open(shared_corpus, interp):
    """app1b: EKI_Open waits for the connection, EKI_Send follows at once, and the answers of a
    plain TCP server move the robot: each LastPos is the one before plus the SetPos sent."""
    step = 10.0
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    settings = NetworkSettings(CONFIGS, eki={"CONFIGAPP1": Channel(CONFIGS / "ConfigApp1.xml", ("127.0.0.1", port))})

    def partner(net, rt):
        server.settimeout(60)
        conn, _ = server.accept()
        conn.settimeout(60)
        seen = []
        for doc in _documents(conn, b"Robot", time.monotonic() + 60):
            pos = doc.find("Data/LastPos")
            seen.append([float(pos.get(k)) for k in "XYZABC"])
            assert doc.findtext("Status") == "12345678"
            if len(seen) == 4:
                break
            answer = ET.Element("Pc")
            ET.SubElement(ET.SubElement(answer, "Data"), "SetPos", {"X": str(step), "Y": "0", "Z": "0",
                                                                    "A": "0", "B": "0", "C": "0"})
            conn.sendall(ET.tostring(answer))
        conn.close()
        server.close()
        return seen

    result, trace, seen = run_with_partner(shared_corpus / APP1B, settings, partner, interp=interp,
                                           robot=library_robots()[ROBOT])
    assert result.reason == "max_sim_time", result.text       # no EKI00010: stopped by the test
    assert len(seen) == 4
    for before, after in zip(seen, seen[1:]):                 # PTP_REL {X 10}: X moved, nothing else
        assert after[0] - before[0] == pytest.approx(step, abs=1e-3)
        assert after[1:] == pytest.approx(before[1:], abs=1e-3)
    events = trace.events
    opened = [e for e in events if e["kind"] == "stmt" and e["line"] == 43]
    after_open = [e for e in events if e["kind"] == "stmt" and e["line"] == 44]
    connect = net_events(trace, dir="connect", name="ConfigApp1")
    sent = net_events(trace, dir="out", name="ConfigApp1")
    assert len(opened) == 1 and len(connect) == 1
    # EKI_Open returned in the cycle its connection came up, and the first send went out then
    assert opened[0]["t"] < connect[0]["t"] == after_open[0]["t"] == sent[0]["t"]
    assert connect[0]["t"] - opened[0]["t"] < 1.0
    assert len(net_events(trace, dir="in", name="ConfigApp1")) == 3


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_client_without_its_server_stops_after_timeout_connect(shared_corpus, interp):
    """app1b with nothing listening: EKI_Open waits TIMEOUT Connect (2000 ms by default) of the
    controller's clock and stops the program with KUKA's EKI00014 at its line."""
    port = free_port()
    settings = NetworkSettings(CONFIGS, eki={"CONFIGAPP1": Channel(CONFIGS / "ConfigApp1.xml", ("127.0.0.1", port))})
    trace = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(shared_corpus / APP1B, network=settings, max_sim_time=20.0,
                         mujoco=False, interp=interp, robot=library_robots()[ROBOT]), RunSinks(trace=trace))
    result = rt.run()
    assert result.reason == "error" and result.error.number == 14 and result.line == 43
    assert result.text.startswith("EKI00014 Ethernet connection to external system failed")
    assert f"127.0.0.1:{port}" in result.text and "2000 ms" in result.text
    opened = [e for e in trace.events if e["kind"] == "stmt" and e["line"] == 43]
    end = trace.events[-1]
    assert end["kind"] == "end" and end["number"] == 14
    assert end["t"] - opened[0]["t"] == pytest.approx(167 * DT)      # ceil(2.0 s / 12 ms) cycles
    assert not net_events(trace, dir="connect")


def _probe(interp: str, settings, partner=None):
    box: dict = {}
    if partner is None:
        trace = TraceWriter(keep=True)
        rt, _ = make_runtime(run_spec(PROGRAMS / "eki_client.src", network=settings, max_sim_time=10.0,
                             mujoco=False, interp=interp), RunSinks(trace=trace))
        result = rt.run()
    else:
        result, trace, _ = run_with_partner(PROGRAMS / "eki_client.src", settings, partner, interp=interp,
                                            box=box, max_sim_time=10.0)
        rt = box["rt"]
    sink = rt.controller.network.sink
    return result, trace, {k: sink.read_var(k) for k in ("OPEN_NO", "SEEN_NO", "CONNECTED", "ANSWER")}


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_timeout_with_messages_not_displayed_and_an_interrupt_while_waiting(interp):
    """The probe's channel has TIMEOUT Connect 1000 ms and no message display: EKI_Open gives
    Msg_No 14, Connected FALSE, and the program goes on. The timer interrupt that came due
    100 ms into the wait ran after EKI_Open had returned (it saw Msg_No 14)."""
    port = free_port()
    settings = NetworkSettings(PROGRAMS, eki={"CLIENT": Channel(PROGRAMS / "Client.xml", ("127.0.0.1", port))})
    result, trace, v = _probe(interp, settings)
    assert result.reason == "completed", result.text
    assert (v["OPEN_NO"], v["SEEN_NO"], v["CONNECTED"], float(v["ANSWER"])) == ("14", "14", "FALSE", 0.0)
    opened = [e for e in trace.events if e["kind"] == "stmt" and e["line"] == 13]
    after = [e for e in trace.events if e["kind"] == "stmt" and e["line"] == 14]
    irq = [e for e in trace.events if e["kind"] == "interrupt" and e["phase"] == "entry"]
    assert after[0]["t"] - opened[0]["t"] == pytest.approx(84 * DT)          # ceil(1.0 s / 12 ms)
    assert irq and irq[0]["t"] == after[0]["t"]         # due at 0.1 s, run once EKI_Open returned


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_server_that_starts_late_is_connected_within_the_timeout(interp):
    """Nothing listens when EKI_Open starts: its first attempt is refused. The partner starts
    listening then, and the waiting EKI_Open connects at its next attempt, 8 IPO cycles later
    (a refused attempt is tried again while it waits, up to TIMEOUT Connect)."""
    port = free_port()
    settings = NetworkSettings(PROGRAMS, eki={"CLIENT": Channel(PROGRAMS / "Client.xml", ("127.0.0.1", port))})

    def partner(net, rt):
        eki = net.partner("eki")
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:      # EKI_Open waits and its attempt was refused
            ch, ep = eki.channels.get("CLIENT"), eki.endpoints.get("CLIENT")
            if ch is not None and ch.connecting and ep is not None and ep.failed:
                break
            time.sleep(0.002)
        server = socket.create_server(("127.0.0.1", port))
        server.settimeout(30)
        conn, _ = server.accept()
        conn.settimeout(30)
        for doc in _documents(conn, b"Ask", time.monotonic() + 30):
            conn.sendall(b'<Answer Val="%s"/>' % str(float(doc.get("Val")) * 2).encode())
            break
        # the robot clears the channel after reading the answer: its close ends the stream
        conn.recv(10)
        conn.close()
        server.close()

    result, trace, v = _probe(interp, settings, partner)
    assert result.reason == "completed", result.text
    assert (v["OPEN_NO"], v["CONNECTED"], float(v["ANSWER"])) == ("0", "TRUE", 5.0)
    connect = net_events(trace, dir="connect", name="Client")
    opened = [e for e in trace.events if e["kind"] == "stmt" and e["line"] == 13]
    assert len(connect) == 1 and 8 * DT <= connect[0]["t"] - opened[0]["t"] < 1.0
    assert re.match(r"<Ask Val=\"2.5\"\s*/>", net_events(trace, dir="out", name="Client")[0]["data"])


def test_a_recorded_client_session_replays_identically_on_tree_and_vm(shared_corpus, tmp_path):
    """The live session of app1b (tree) is a recording: replayed with no socket, EKI_Open's
    wait ends at the recorded connection's cycle on both interpreters, and tree and VM give
    the same trace, whose arriving events are the live ones at the same simulated times."""
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    channel = {"CONFIGAPP1": Channel(CONFIGS / "ConfigApp1.xml", ("127.0.0.1", port))}

    def partner(net, rt):
        server.settimeout(60)
        conn, _ = server.accept()
        for n, _doc in enumerate(_documents(conn, b"Robot", time.monotonic() + 60)):
            if n == 2:
                break
            conn.sendall(b'<Pc><Data><SetPos X="0" Y="5" Z="0" A="0" B="0" C="0"/></Data></Pc>')
        conn.close()
        server.close()

    _, live, _ = run_with_partner(shared_corpus / APP1B, NetworkSettings(CONFIGS, eki=channel), partner,
                                  robot=library_robots()[ROBOT])
    recording = tmp_path / "app1b.jsonl"
    recording.write_text(live.text())
    arrived = [(e["t"], e["dir"], e.get("data")) for e in live.events
               if e["kind"] == "net" and e["dir"] in ("in", "connect")]
    assert [d for _, d, _ in arrived][:3] == ["connect", "in", "in"]
    traces = {}
    for it in ("tree", "vm"):
        trace = TraceWriter(keep=True)
        rt, _ = make_runtime(run_spec(shared_corpus / APP1B, network=NetworkSettings(CONFIGS, eki=channel, replay=recording),
                             max_sim_time=arrived[-1][0] + 0.5, mujoco=False, interp=it,
                             robot=library_robots()[ROBOT]), RunSinks(trace=trace))
        rt.run()
        assert not rt.controller.network.endpoints
        traces[it] = trace
        got = [(e["t"], e["dir"], e.get("data")) for e in trace.events
               if e["kind"] == "net" and e["dir"] in ("in", "connect")]
        assert got == arrived
        opened = [e for e in trace.events if e["kind"] == "stmt" and e["line"] == 43]
        after = [e for e in trace.events if e["kind"] == "stmt" and e["line"] == 44]
        assert opened[0]["t"] < after[0]["t"] == arrived[0][0]
    assert traces["tree"].lines == traces["vm"].lines
