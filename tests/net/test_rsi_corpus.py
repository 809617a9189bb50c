"""Every RSI program of the corpus with its own published context and configuration (RSI 3 or
4/5) and a sensor written from that configuration (tests/net/sensor.py), on both interpreters
(issue 50): datagrams at the program's cycle (12 ms, 4 ms with ``#IPO_FAST``), corrections
followed (axes for AK, the TCP for RKorr, absolute or relative as the program's RSI_ON, or RSI 2's
ST_SETPARAM, says),
and Stop honoured where the context has a STOP object (RSI_MOVECORR ends, the program goes on
to its end). Programs whose context has no STOP object never end RSI_MOVECORR themselves; the
run ends when the sensor has seen the correction.

RSI 2's program (KR C2) builds its objects itself; its published ETHERNET configuration is the
one file it needs. The contexts are tests/net/configs/published/ (derived from the programs' repositories, origins
in each file); the programs are read in place from the corpus. The expected values are the
sensor's own commands, compared with what the robot reports in its datagrams (AIPos, RIst)
and the trace's poses."""

from __future__ import annotations

import re
import shutil
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from interp.run import make_runtime, run_spec, RunSinks
from net.settings import Channel, NetworkSettings
from robot.trace import TraceWriter

from .helpers import CONFIGS, EXAMPLES, net_events, run_with_partner
from .sensor import ConfigSensor, axes_of, tcp_of

#: the RSI partner answers in real time (4/12 ms cycles): make test runs these on one worker (tests/conftest.py, ``wall_clock``)
pytestmark = pytest.mark.wall_clock

PUB = CONFIGS / "published"
KSS = "kroshu__kuka-external-control-sdk/kuka_external_control_sdk/krc_setup/kss/KRC/R1/Program/RSI/"

# program (corpus), context (published), ETHERNET configuration (None: the context's ConfigFile)
PROGRAMS = [
    ("ros-industrial__kuka_experimental/kuka_rsi_hw_interface/krl/KR_C4/ros_rsi.src",
     "ros_industrial_kr_c4/ros_rsi.rsi.xml", None),
    ("ros-industrial__kuka_experimental/kuka_rsi_hw_interface/krl/KR_C4/ros_rsi.src",
     "ros_industrial_kr_c4/ros_rsi.rsix", None),
    ("fzi-forschungszentrum-informatik__kuka_rsi_driver/kuka_rsi_driver/krl/KR_C4/kuka_rsi_driver.src",
     "fzi_kr_c4/ros_rsi.rsi.xml", None),
    ("fzi-forschungszentrum-informatik__kuka_rsi_driver/kuka_rsi_driver/krl/KR_C5/kuka_rsi_driver.src",
     "fzi_kr_c5/ros_rsi.rsix", None),
    ("wingljj__Kuka-RSI-real-time-control/krc/PoseTrack.src", "wingljj/PoseTrack.rsix", None),
    ("wingljj__Kuka-RSI-real-time-control/krc/PoseTrack.src", "wingljj_legacy/PoseTrack.rsi.xml", None),
    ("AlexeiOvcharov__kuka_rsi3_server/RSI/Painter_RSI.src", "alexeiovcharov/Painter_RSI.xml", None),
    ("adamleon__kuka/kuka_krl/src/RSI_AxisCorr/RSI_AxisCorr.src", "adamleon/RSIAxisCorrTest.rsi.xml", None),
    (KSS + "rsi_joint_pos_12ms.src", "kroshu_kss/rsi_joint_pos.rsix", None),
    (KSS + "rsi_joint_pos_4ms.src", "kroshu_kss/rsi_joint_pos.rsix", None),
    (KSS + "rsi_gpio_example.src", "kroshu_kss/rsi_gpio_joint_pos.rsix", None),
    # RSI 2 (KR C2): the program builds its objects with ST_ functions; the ETHERNET configuration
    # of its ST_ETHERNET is the published file (tests/net/test_rsi2.py for the rest)
    ("ros-industrial__kuka_experimental/kuka_rsi_hw_interface/krl/KR_C2/ros_rsi.src",
     "ros_industrial_kr_c2/ros_rsi_ethernet.xml", None),
]
AXIS_TARGET = np.array([2.0, -1.5, 1.0, 0.5, 3.0, -2.5])        # deg, within every context's limits
CART_TARGET = np.array([4.0, -3.0, 5.0, 0.0, 0.0, 0.0])         # mm
START = "{A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}"


def ethernet_of(context):
    for el in ET.parse(context).getroot().iter():
        if el.get("Name") == "ConfigFile":
            return context.parent / el.get("ParamValue")
    return context       # an ETHERNET configuration alone


@pytest.mark.parametrize("interp", ["tree", "vm"])
@pytest.mark.parametrize("program,context,ethernet", PROGRAMS, ids=[f"{p[0].split('/')[-1]}-{p[1]}" for p in PROGRAMS])
def test_corpus_rsi_program(shared_corpus, program, context, ethernet, interp):
    src = shared_corpus / program
    text = src.read_text(encoding="latin-1").upper()
    relative = "#RELATIVE" in text
    fast = "#IPO_FAST" in text
    ctx_path = PUB / context
    sensor = ConfigSensor(ethernet_of(ctx_path))
    axes = sensor.axis_tag is not None
    target = AXIS_TARGET if axes else CART_TARGET
    ramp = 40                                   # answers to reach the target
    state = {"reached": None}

    def plan(i, rob):
        now = np.array(axes_of(rob) if axes else tcp_of(rob))
        state.setdefault("start", now)
        if state["reached"] is not None:
            done = i - state["reached"]
            if done >= 5:
                return "done" if not sensor.has_stop or done > 60 else ({}, True)
        elif np.allclose(now - state["start"], target, atol=0.01):
            state["reached"] = i
            state["at"] = now
        if relative:
            step = target / ramp if i < ramp else np.zeros(6)
        else:
            step = target * min(1.0, (i + 1) / ramp)
        tag = sensor.axis_tag if axes else sensor.cart_tag
        comps = ("A1", "A2", "A3", "A4", "A5", "A6") if axes else ("X", "Y", "Z", "A", "B", "C")
        return {(tag, c): float(v) for c, v in zip(comps, step)}, False

    settings = NetworkSettings(ctx_path.parent, rsi=Channel(ctx_path, sensor.address))
    # the robot stands off the wrist singularity (PoseTrack.src starts with PTP $POS_ACT)
    result, trace, got = run_with_partner(src, settings, sensor.partner(plan), interp=interp, start=START)
    assert got, "no datagram"
    # datagrams at the program's cycle
    ipocs = [int(r.findtext("IPOC")) for r in got]
    steps = set(np.diff(ipocs[:30]))
    assert steps == ({4} if fast else {12}), steps
    # the correction followed (to 0.01 mm / 0.01 deg), in the datagrams and the trace
    assert state["reached"] is not None, (result.reason, result.text, len(got))
    assert np.allclose(state["at"] - state["start"], target, atol=0.01)
    # Stop honoured: RSI_MOVECORR ends and the program runs to its end
    if sensor.has_stop:
        assert result.reason == "completed", (result.reason, result.text)
    created = net_events(trace, iface="rsi", dir="context")
    assert created and ("RSI 4/5" in created[0]["text"]) == context.endswith(".rsix")
    assert ("RSI 2:" in created[0]["text"]) == ("ST_ETHERNET" in text)


def test_the_cell_file_may_name_the_ethernet_configuration(shared_corpus, tmp_path):
    """A user who names the ETHERNET configuration in the cell file (``rsi: {config:
    PoseTrack_ethernet.xml}``) gets the context RSI_CREATE names from beside the program (here
    the RSI 4/5 PoseTrack.rsix, with its LIMIT objects), not one implied from the tags."""
    src = tmp_path / "PoseTrack.src"
    shutil.copyfile(shared_corpus / "wingljj__Kuka-RSI-real-time-control/krc/PoseTrack.src", src)
    shutil.copyfile(PUB / "wingljj" / "PoseTrack.rsix", tmp_path / "PoseTrack.rsix")
    cfg = tmp_path / "cfg" / "PoseTrack_ethernet.xml"
    cfg.parent.mkdir()
    shutil.copyfile(PUB / "wingljj" / "PoseTrack_ethernet.xml", cfg)
    sensor = ConfigSensor(cfg)

    def plan(i, rob):
        # 50 mm in one answer: the LIMIT objects let 35 through, POSCORR holds the total in 40
        return "done" if i > 20 else ({(sensor.cart_tag, "X"): 50.0 if i == 0 else 0.0}, False)

    settings = NetworkSettings(tmp_path, rsi=Channel(cfg, sensor.address))
    result, trace, got = run_with_partner(src, settings, sensor.partner(plan), start=START)
    created = net_events(trace, iface="rsi", dir="context")
    assert "RSI 4/5" in created[0]["text"] and "PoseTrack.rsix" in created[0]["text"]
    x = [tcp_of(r)[0] for r in got]
    assert x[-1] - x[0] == pytest.approx(35.0, abs=0.01)


def _rot(a, b, c):
    """KUKA's A, B, C (deg): rotations about Z, then Y, then X."""
    a, b, c = np.radians([a, b, c])
    rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
    rx = np.array([[1, 0, 0], [0, np.cos(c), -np.sin(c)], [0, np.sin(c), np.cos(c)]])
    return rz @ ry @ rx


@pytest.mark.parametrize("refcorrsys", ["Tool", "3", "Base", "1"])
def test_poscorr_in_the_tool_frame(tmp_path, refcorrsys):
    """POSCORR's RefCorrSys: Tool (RSI 3 "Tool", RSI 4/5 3) moves the TCP along its own axes,
    Base (the default, "Base" or 1) along $BASE's."""
    text = (EXAMPLES / "rsi_path.rsi.xml").read_text()
    text = text.replace('<Parameter Name="LowerLimX"', f'<Parameter Name="RefCorrSys" ParamValue="{refcorrsys}"/> '
                        '<Parameter Name="LowerLimX"', 1)
    (tmp_path / "rsi_path.rsi.xml").write_text(text)
    (tmp_path / "rsi_path_ethernet.xml").write_bytes((EXAMPLES / "rsi_path_ethernet.xml").read_bytes())
    sensor = ConfigSensor(tmp_path / "rsi_path_ethernet.xml")
    corr = np.array([6.0, -4.0, 3.0])

    def plan(i, rob):
        return {(sensor.cart_tag, k): float(v) * min(1.0, (i + 1) / 30) for k, v in zip("XYZ", corr)}, i > 60

    settings = NetworkSettings(tmp_path, rsi=Channel(tmp_path / "rsi_path.rsi.xml", sensor.address))
    result, trace, got = run_with_partner(EXAMPLES / "rsi_path.src", settings, sensor.partner(plan))
    assert result.reason == "completed", (result.reason, result.text)
    first, last = np.array(tcp_of(got[0])), np.array(tcp_of(got[-1]))
    frame = _rot(*first[3:]) if refcorrsys in ("Tool", "3") else np.eye(3)
    assert np.allclose(last[:3] - first[:3], frame @ corr, atol=0.01), (last[:3] - first[:3], frame @ corr)
    assert np.allclose(last[3:], first[3:], atol=0.01)


def test_onlysend_expects_no_answer(tmp_path):
    """ONLYSEND TRUE (KUKA's template: "the client don't expect answers"): the robot streams its
    packets and never counts one late, so a sensor that only listens does not stop it."""
    text = (EXAMPLES / "rsi_path_ethernet.xml").read_text().replace("<ONLYSEND>FALSE</ONLYSEND>", "<ONLYSEND>TRUE</ONLYSEND>")
    (tmp_path / "rsi_path_ethernet.xml").write_text(text)
    shutil.copyfile(EXAMPLES / "rsi_path.rsi.xml", tmp_path / "rsi_path.rsi.xml")
    sensor = ConfigSensor(tmp_path / "rsi_path_ethernet.xml")
    assert sensor.onlysend

    def plan(i, rob):
        return "done" if i >= 200 else ({}, False)        # never sent: the sensor only listens

    settings = NetworkSettings(tmp_path, rsi=Channel(tmp_path / "rsi_path.rsi.xml", sensor.address))
    result, trace, got = run_with_partner(EXAMPLES / "rsi_path.src", settings, sensor.partner(plan))
    assert len(got) >= 200 and result.reason != "error", (result.reason, result.text)
    assert not [e for e in net_events(trace, iface="rsi", dir="error") if e.get("number") == 1]
    assert all(r.find("Delay").get("D") == "0" for r in got)


AXIS_CORRECTION = "adamleon__kuka/kuka_rsi_hw_interface/krl/rsi_axis_correction/rsi_axis_correction.src"


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_rsi_axis_correction_has_no_published_ethernet_configuration(shared_corpus, tmp_path, interp):
    """The rsi_axis_correction.src copies are not run: their repository publishes the context as
    ``rsi_axis_corrrection.rsi.xml`` (three r's: RSI_CREATE("rsi_axis_correction.rsi") does not
    find it on the controller either) and its ETHERNET object's ConfigFile
    ``rsi_axis_correction_ethernet_config.xml`` nowhere. The run says so as the controller
    would: RSI_CREATE returns an error, the program's check HALTs, nothing is sent; with the
    published context named in the cell file, the message names the missing configuration."""
    src = tmp_path / "rsi_axis_correction.src"
    shutil.copyfile(shared_corpus / AXIS_CORRECTION, src)
    ctx = PUB / "ros_industrial_rsi_axis_correction" / "rsi_axis_corrrection.rsi.xml"
    shutil.copyfile(ctx, tmp_path / ctx.name)
    for channel, message in ((Channel(None, ("127.0.0.1", 9)), "RSI: context rsi_axis_correction.rsi not found"),
                             (Channel(tmp_path / ctx.name, ("127.0.0.1", 9)),
                              "ConfigFile rsi_axis_correction_ethernet_config.xml not found")):
        trace = TraceWriter(keep=True)
        rt, _ = make_runtime(run_spec(src, network=NetworkSettings(tmp_path, rsi=channel), max_sim_time=3.0,
                             mujoco=False, interp=interp), RunSinks(trace=trace))
        rt.run()
        texts = " ".join(str(e.get("text", "")) for e in trace.events)
        assert message in texts, texts[-1500:]
        assert not net_events(trace, iface="rsi", dir="out")
