"""RobotSensorInterface over UDP on loopback (issue 35, done-when 1): a program streams
corrections from a sensor written here from KUKA's RSI protocol (the Rob/Sen XML documents,
IPOC echoed), and the TCP path shifts by the commanded amount within one cycle; the corpus's
ROS-Industrial RSI program follows axis corrections; a sensor that stops answering stops the
motion as KSS does (late packets past the ETHERNET object's Timeout)."""

from __future__ import annotations

import re
import socket
import time
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from net.settings import Channel, NetworkSettings
from interp.run import make_runtime, run_spec, RunSinks
from robot.trace import TraceWriter

from .helpers import CONFIGS, EXAMPLES, net_events, run_with_partner

#: the RSI partner answers in real time (4/12 ms cycles): make test runs these on one worker (tests/conftest.py, ``wall_clock``)
pytestmark = pytest.mark.wall_clock

ROS_RSI = "ros-industrial__kuka_experimental/kuka_rsi_hw_interface/krl/KR_C4/ros_rsi.src"


def sensor(answer, stop_after: float = 60.0, until_end: bool = True):
    """A partner: a UDP sensor that answers each Rob packet with ``answer(i, rob)`` (the
    children of <Sen> as text, None to stay silent, "done" when it has what it wanted); it
    returns the packets it got when the run ends (`until_end`) or when it is done."""
    box = {}

    def partner(net, rt):
        sock = box["sock"]
        sock.settimeout(0.5)
        got = []
        end = time.monotonic() + stop_after
        while time.monotonic() < end and not net.closed:
            try:
                data, peer = sock.recvfrom(65536)
            except TimeoutError:
                if got and box.get("done") and not until_end:
                    break
                continue
            rob = ET.fromstring(data)
            assert rob.tag == "Rob" and rob.get("Type") == "KUKA"
            ipoc = rob.find("IPOC").text
            got.append(rob)
            body = answer(len(got) - 1, rob)
            if body == "done":
                box["done"] = True
                continue
            if body is not None:
                sock.sendto(f'<Sen Type="ImFree">{body}<IPOC>{ipoc}</IPOC></Sen>'.encode(), peer)
        sock.close()
        return got

    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    box["sock"] = s
    return partner, s.getsockname()


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_rsi_corrections_shift_the_tcp_path(interp):
    def answer(i, rob):
        z = min(20.0, 0.5 * i)                    # a ramp to 20 mm, then held
        stop = 1 if i >= 70 else 0
        if i > 75:
            return "done"
        return f'<RKorr X="0" Y="0" Z="{z}" A="0" B="0" C="0"/><Stop>{stop}</Stop>'

    partner, addr = sensor(answer)
    settings = NetworkSettings(EXAMPLES, rsi=Channel(EXAMPLES / "rsi_path.rsi.xml", addr))
    result, trace, got = run_with_partner(EXAMPLES / "rsi_path.src", settings, partner, interp=interp)
    assert result.reason == "completed", (result.reason, result.text)
    events = trace.events
    first = ET.fromstring(net_events(trace, iface="rsi", dir="out")[0]["data"]).find("RIst")
    z0 = float(first.get("Z"))
    x0, y0 = float(first.get("X")), float(first.get("Y"))
    received = [(e["t"], float(re.search(r'Z="([-0-9.]+)"', e["data"]).group(1)))
                for e in net_events(trace, iface="rsi", dir="in")]
    assert len(received) >= 60
    poses = [e for e in events if e["kind"] == "pose" and received[0][0] <= e["t"] <= received[-1][0]]
    for p in poses:
        commanded = [z for t, z in received if t <= p["t"] + 1e-9][-1]
        assert p["tcp"][2] - z0 == pytest.approx(commanded, abs=1e-3)      # the commanded shift, this cycle
        assert p["tcp"][0] == pytest.approx(x0, abs=1e-3) and p["tcp"][1] == pytest.approx(y0, abs=1e-3)
    # every packet answered in time, whatever the machine's load: the controller waits for its
    # sensor's answer in simulated time (net/rsi.py ANSWER_WAIT_S). The last packet went out in
    # the cycle whose answer brought the Stop; RSI was off before its answer
    sent = len(net_events(trace, iface="rsi", dir="out"))
    late = sum(int(e["text"].split()[0]) for e in net_events(trace, iface="rsi", dir="error")
               if e.get("number") == 1)
    assert late == 0 and sent == len(received) + 1
    # RSI_OFF keeps the corrected position: the next motion starts from z0 + 20
    start = [e for e in events if e["kind"] == "motion" and e["phase"] == "start"][-1]
    at_start = [e for e in events if e["kind"] == "pose" and e["t"] <= start["t"]][-1]
    assert at_start["tcp"][2] - z0 == pytest.approx(20.0, abs=1e-3)


def test_a_silent_sensor_stops_the_motion():
    """Past Timeout (100 here) late packets in a row the robot stops with RSI's message and the
    program ends with it."""
    def answer(i, rob):
        return '<RKorr X="0" Y="0" Z="1" A="0" B="0" C="0"/><Stop>0</Stop>' if i < 10 else None

    partner, addr = sensor(answer, stop_after=8.0)
    settings = NetworkSettings(EXAMPLES, rsi=Channel(EXAMPLES / "rsi_path.rsi.xml", addr))
    started = time.monotonic()
    result, trace, got = run_with_partner(EXAMPLES / "rsi_path.src", settings, partner)
    assert time.monotonic() - started < 60
    assert result.reason == "error"
    assert "maximum number of late packets exceeded" in result.text
    errors = [e for e in trace.events if e["kind"] == "error"]
    assert errors and "late packets" in errors[0]["text"]
    # the stop came 101 late cycles after the last answer, not earlier
    answers = net_events(trace, iface="rsi", dir="in")
    assert errors[0]["t"] - answers[-1]["t"] == pytest.approx(0.012 * 101, abs=0.012 * 2)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_ros_industrial_rsi_axis_corrections(shared_corpus, interp):
    """ROS-Industrial's ros_rsi.src (KR C4): RSI_ON(#ABSOLUTE), RSI_MOVECORR(): the axes
    follow AK (absolute, within the AXISCORR's limits). Its program never stops RSI itself: the
    test ends the run once the sensor has seen the axes there."""
    target = np.array([3.0, -2.0, 1.5, 0.0, 4.0, -6.0])
    state = {}

    def answer(i, rob):
        ai = rob.find("AIPos")
        axes = np.array([float(ai.get(f"A{k}")) for k in range(1, 7)])
        state.setdefault("start", axes)
        if np.allclose(axes - state["start"], target, atol=1e-4):
            state["reached"] = axes
            return "done"
        ramp = np.clip(target * (i + 1) / 50.0, -np.abs(target), np.abs(target))
        return "<AK " + " ".join(f'A{k + 1}="{v}"' for k, v in enumerate(ramp)) + "/>"

    partner, addr = sensor(answer, until_end=False)
    settings = NetworkSettings(CONFIGS, rsi=Channel(CONFIGS / "ros_rsi.rsi.xml", addr))
    result, trace, got = run_with_partner(shared_corpus / ROS_RSI, settings, partner, interp=interp)
    assert "reached" in state
    assert np.allclose(state["start"], [0, -90, 90, 0, 90, 0], atol=1e-6)   # its PTP before RSI_ON
    poses = [e["axes"] for e in trace.events if e["kind"] == "pose"]
    assert np.allclose(poses[-1], np.array([0, -90, 90, 0, 90, 0]) + target, atol=1e-4)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_without_a_sensor_every_packet_is_late(interp):
    """No `network:` key: no socket, no pacing; RSI_ON sends to nobody, so the robot stops after
    Timeout + 1 late cycles, deterministically, as KSS would without its sensor."""

    trace = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(EXAMPLES / "rsi_path.src", mujoco=False, interp=interp), RunSinks(trace=trace))
    started = time.monotonic()
    result = rt.run()
    assert time.monotonic() - started < 30
    assert result.reason == "error" and "late packets" in result.text
    on = next(e["t"] for e in trace.events if e["kind"] == "net" and e["dir"] == "out")
    err = next(e["t"] for e in trace.events if e["kind"] == "error")
    assert err - on == pytest.approx(0.012 * 101, abs=1e-6)
    assert rt.controller.network.pacer is None
