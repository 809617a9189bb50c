"""RSI with a sensor nobody here wrote: RSIPI (PyPI ``rsipi``, a Python library for the sensor
PC of KUKA RSI; a pinned test dependency) on both interpreters (issue 50):

* the project's example (examples/network/rsi_path.src, absolute RKorr, Stop): connection,
  the 12 ms cycle, the correction followed to 0.01 mm, ``Stop`` ending RSI_MOVECORR;
* RSIPI's own shipped context RSIPI_Stop (KUKA's ETHERNET template: DEF_EStr and DEF_Tech in
  RECEIVE, FREE, DiO, $SEN_PREA channels; a STOP object on MoveStop) with a relative program:
  each answer's RKorr added once, RSIPI's exit_movecorr() ending RSI_MOVECORR, its EStr text a
  message;
* corpus programs with their published configurations: wingljj's PoseTrack (RSI 4/5 .rsix,
  LIMIT objects, relative RKorr with HOLDON 0) and kroshu's rsi_joint_pos_4ms (RSI 4/5,
  ``#IPO_FAST``: 4 ms cycle, absolute AK, Stop);
* ROS-Industrial's KR_C2 ros_rsi.src (RSI 2, the ST_ functions) with its published
  ros_rsi_ethernet.xml: 12 ms, absolute AK;
* a late-answer stop: RSIPI stopped, the robot stops after Timeout + 1 late cycles;
* issue 64's KR 150 cell, rebuilt from its description (points at X 1800-2000, Z 1500-1840): the
  program runs on ``--robot "KR 150 R3100-2"`` and follows the correction; the KR 6 R900 stops at
  its first motion.

RSIPI binds the configuration's IP and PORT: each test hands it a copy of the published
configuration with IP 127.0.0.1 and a free port (nothing else changed), and the cell file's
``rsi: address`` sends the robot's packets there."""

from __future__ import annotations

import re
import shutil
import socket
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import psutil
import pytest
from RSIPI import RSIAPI, context

from net.settings import Channel, NetworkSettings

from tests.interp.helpers import run_krl

from .helpers import CONFIGS, EXAMPLES, PROGRAMS, net_events, run_with_partner

#: the RSI partner answers in real time (4/12 ms cycles): make test runs these on one worker (tests/conftest.py, ``wall_clock``)
pytestmark = pytest.mark.wall_clock

PUB = CONFIGS / "published"
KSS = "kroshu__kuka-external-control-sdk/kuka_external_control_sdk/krc_setup/kss/KRC/R1/Program/RSI/"
START = "{A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}"
INTERPS = ["tree", "vm"]


def local_copy(config: Path, tmp_path: Path) -> tuple[Path, int]:
    """The ETHERNET configuration with IP 127.0.0.1 and a free UDP port, for RSIPI to bind."""
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    text = config.read_text(encoding="utf-8-sig")
    text = re.sub(r"<IP_NUMBER>[^<]*</IP_NUMBER>", "<IP_NUMBER>127.0.0.1</IP_NUMBER>", text)
    text = re.sub(r"<PORT>[^<]*</PORT>", f"<PORT>{port}</PORT>", text)
    out = tmp_path / config.name
    out.write_text(text, encoding="utf-8")
    return out, port


def udp_bound(port: int) -> bool:
    """A socket of this machine is bound to UDP `port` (read from the kernel's table, without
    touching the port)."""
    return any(c.laddr and c.laddr.port == port for c in psutil.net_connections(kind="udp"))


@pytest.fixture
def rsipi():
    """A factory of partners for helpers.run_with_partner: ``rsipi(config, script, mode, cycle)``
    starts RSIPI on `config` at once and returns when it listens on the configuration's port,
    so that it is there before the robot's RSI_ON, as a sensor PC is (not racing the run); the
    partner then runs ``script(api, hold)`` once the robot's first packet arrived, and stops
    RSIPI after it. ``hold(s)`` returns when the controller has run `s` more seconds of
    simulated time (or the run ended): the script's pauses are the robot's cycles, not the
    wall clock's, whatever the machine's load. Every RSIPI started is stopped at teardown."""
    started = []

    def make(config: Path, script, mode: str = "absolute", cycle: float = 0.012):
        port = int(re.search(r"<PORT>\s*(\d+)\s*</PORT>", config.read_text(encoding="utf-8")).group(1))
        api = RSIAPI(str(config), rsi_mode=mode, cycle_time=cycle)
        api.start()
        started.append(api)
        assert until(lambda: udp_bound(port), 60.0), f"RSIPI did not bind UDP port {port}"

        def run(net, rt):
            def hold(seconds: float) -> None:
                t = rt.controller.time + seconds
                until(lambda: rt.controller.time >= t or net.closed, 60.0)

            try:
                assert api.wait_for_connection(60.0), "RSIPI saw no packet of the robot"
                return script(api, hold)
            finally:
                api.stop()
        return run

    yield make
    for api in started:
        api.stop()


def until(pred, timeout: float = 30.0) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if pred():
            return True
        time.sleep(0.01)
    return False


def pose(api) -> np.ndarray:
    p = api.motion.get_current_pose()
    return np.array([float(p[k]) for k in "XYZABC"])


def joints(api) -> np.ndarray:
    p = api.motion.get_current_joints()
    return np.array([float(p[f"A{i}"]) for i in range(1, 7)])


def follow_axes(api, target) -> tuple[np.ndarray, bool]:
    """RSIPI sends the absolute AK `target` (deg); (the joints before, whether the robot's
    joints reached it to 0.01 deg)."""
    q0 = joints(api)
    for i, v in enumerate(target):
        api.tools.update_variable(f"AK.A{i + 1}", float(v))
    return q0, until(lambda: np.allclose(joints(api) - q0, target, atol=0.01))


def last_axes(trace) -> np.ndarray:
    """A1..A6 of the robot's last packet (AIPos)."""
    pk = robot_packets(trace)[-1].find("AIPos")
    return np.array([float(pk.get(f"A{i}")) for i in range(1, 7)])


def robot_packets(trace):
    return [ET.fromstring(re.sub(r"(\s)([0-9][\w.-]*=)", r"\1_\2", e["data"])) for e in net_events(trace, iface="rsi", dir="out")]


def answers(trace):
    return [ET.fromstring(e["data"]) for e in net_events(trace, iface="rsi", dir="in")]


def ipoc_steps(trace) -> set[int]:
    ipocs = [int(r.findtext("IPOC")) for r in robot_packets(trace)]
    return set(np.diff(ipocs[:60]).tolist())


@pytest.mark.parametrize("interp", INTERPS)
def test_rsipi_on_the_example(rsipi, tmp_path, interp):
    cfg, port = local_copy(EXAMPLES / "rsi_path_ethernet.xml", tmp_path)

    def script(api, hold):
        z0 = pose(api)
        api.tools.update_variable("RKorr.Z", 5.0)
        reached = until(lambda: abs(pose(api)[2] - z0[2] - 5.0) < 0.01)
        hold(0.5)
        api.tools.update_variable("Stop", True)
        hold(0.3)
        return z0, reached

    settings = NetworkSettings(EXAMPLES, rsi=Channel(EXAMPLES / "rsi_path.rsi.xml", ("127.0.0.1", port)))
    result, trace, (z0, reached) = run_with_partner(EXAMPLES / "rsi_path.src", settings, rsipi(cfg, script), interp=interp)
    assert reached
    assert result.reason == "completed", (result.reason, result.text)        # Stop ended RSI_MOVECORR
    assert ipoc_steps(trace) == {12}
    assert len(answers(trace)) >= 40
    # each packet answered in time: the controller waits for its sensor in simulated time (net/rsi.py)
    assert not net_events(trace, iface="rsi", dir="error")
    # the TCP followed the 5 mm to 0.01 mm, in the robot's own packets
    last = robot_packets(trace)[-1].find("RIst")
    assert float(last.get("Z")) - z0[2] == pytest.approx(5.0, abs=0.01)
    assert float(last.get("X")) == pytest.approx(z0[0], abs=0.01)


@pytest.mark.parametrize("interp", INTERPS)
def test_rsipi_shipped_context_kuka_template(rsipi, tmp_path, interp):
    """RSIPI's own RSIPI_Stop context and its KUKA-template configuration, as RSIPI ships them."""
    shipped = Path(context("stop"))
    ctx = shipped.parent / "RSIPI_Stop.rsi.xml"
    cfg, port = local_copy(shipped, tmp_path)

    def script(api, hold):
        p0 = pose(api)
        api.motion.update_cartesian(X=0.1)
        until(lambda: pose(api)[0] - p0[0] > 3.0)
        api.motion.update_cartesian(X=0.0)
        hold(0.3)
        api.motion.exit_movecorr()
        hold(0.3)
        return p0

    settings = NetworkSettings(ctx.parent, rsi=Channel(ctx, ("127.0.0.1", port)))
    result, trace, p0 = run_with_partner(PROGRAMS / "rsipi_stop.src", settings, rsipi(cfg, script, "relative"),
                                         interp=interp)
    assert result.reason == "completed", (result.reason, result.text)
    assert ipoc_steps(trace) == {12}
    # relative: every answer's RKorr.X added once (the ones that arrived while RSI was on)
    sent = sum(float(a.find("RKorr").get("X")) for a in answers(trace))
    x_end = max(float(r.find("RIst").get("X")) for r in robot_packets(trace))
    assert sent > 3.0
    assert x_end - p0[0] == pytest.approx(sent, abs=0.01)
    # DEF_EStr: RSIPI's text is a message of the controller
    texts = [e.get("text", "") for e in trace.events if e["kind"] == "message"]
    assert any("RSIPI: Client started" in t for t in texts), texts[:5]


@pytest.mark.parametrize("interp", INTERPS)
def test_rsipi_on_posetrack_rsix(rsipi, shared_corpus, tmp_path, interp):
    """wingljj's PoseTrack.src with its published RSI 4/5 context (LIMIT objects of +-35 per
    answer, POSCORR within +-40, RELATIVE, HOLDON 0): no STOP object, so the test ends the run."""
    ctx = PUB / "wingljj" / "PoseTrack.rsix"
    cfg, port = local_copy(PUB / "wingljj" / "PoseTrack_ethernet.xml", tmp_path)

    def script(api, hold):
        p0 = pose(api)
        api.motion.update_cartesian(Y=-0.2, Z=0.1)
        until(lambda: pose(api)[1] - p0[1] < -4.0)
        api.motion.update_cartesian(Y=0.0, Z=0.0)
        hold(0.3)
        return p0

    settings = NetworkSettings(ctx.parent, rsi=Channel(ctx, ("127.0.0.1", port)))
    result, trace, p0 = run_with_partner(shared_corpus / "wingljj__Kuka-RSI-real-time-control/krc/PoseTrack.src",
                                         settings, rsipi(cfg, script, "relative"), interp=interp, start=START)
    assert ipoc_steps(trace) == {12}
    ys = sum(float(a.find("RKorr").get("Y")) for a in answers(trace))
    zs = sum(float(a.find("RKorr").get("Z")) for a in answers(trace))
    last = robot_packets(trace)[-1].find("RIst")
    assert ys < -4.0
    assert float(last.get("Y")) - p0[1] == pytest.approx(ys, abs=0.01)
    assert float(last.get("Z")) - p0[2] == pytest.approx(zs, abs=0.01)


@pytest.mark.parametrize("interp", INTERPS)
def test_rsipi_ipo_fast_kroshu(rsipi, shared_corpus, tmp_path, interp):
    """kroshu's rsi_joint_pos_4ms.src (RSI_ON(#ABSOLUTE, #IPO_FAST)) with its published RSI 4/5
    context: packets every 4 ms, absolute AK followed, Stop ends RSI_MOVECORR."""
    ctx = PUB / "kroshu_kss" / "rsi_joint_pos.rsix"
    cfg, port = local_copy(PUB / "kroshu_kss" / "rsi_ethernet.xml", tmp_path)
    target = np.array([1.5, -1.0, 0.5, 0.0, 2.0, -2.0])

    def script(api, hold):
        q0, reached = follow_axes(api, target)
        hold(0.2)
        api.tools.update_variable("Stop", True)
        hold(0.3)
        return q0, reached

    settings = NetworkSettings(ctx.parent, rsi=Channel(ctx, ("127.0.0.1", port)))
    result, trace, (q0, reached) = run_with_partner(shared_corpus / (KSS + "rsi_joint_pos_4ms.src"), settings,
                                                    rsipi(cfg, script, cycle=0.004), interp=interp, start=START)
    assert reached
    assert result.reason == "completed", (result.reason, result.text)
    assert ipoc_steps(trace) == {4}
    assert np.allclose(last_axes(trace) - q0, target, atol=0.01)


@pytest.mark.parametrize("interp", INTERPS)
def test_rsipi_on_the_kr_c2_rsi2_program(rsipi, shared_corpus, tmp_path, interp):
    """ROS-Industrial's KR_C2 ros_rsi.src (RSI 2: ST_ETHERNET, ST_AXISCORR absolute by
    ST_SETPARAM, ST_SKIPSENS) with its published ros_rsi_ethernet.xml (PROTOCOL UDP, UNIT
    attributes): 12 ms, RSIPI's absolute AK followed to 0.01 deg. No break object: the test
    ends the run."""
    cfg, port = local_copy(PUB / "ros_industrial_kr_c2" / "ros_rsi_ethernet.xml", tmp_path)
    target = np.array([2.0, -1.5, 1.0, 0.5, 3.0, -2.5])

    def script(api, hold):
        q0, reached = follow_axes(api, target)
        hold(0.2)
        return q0, reached

    settings = NetworkSettings(tmp_path, rsi=Channel(cfg, ("127.0.0.1", port)))
    result, trace, (q0, reached) = run_with_partner(
        shared_corpus / "ros-industrial__kuka_experimental/kuka_rsi_hw_interface/krl/KR_C2/ros_rsi.src",
        settings, rsipi(cfg, script), interp=interp)
    assert reached
    assert ipoc_steps(trace) == {12}
    # every packet answered in time until RSIPI was stopped (the run has no Stop: it goes on a
    # cycle or two after the script, and those packets are late)
    sent = [int(r.findtext("IPOC")) for r in robot_packets(trace)]
    answered = {int(a.findtext("IPOC")) for a in answers(trace)}
    assert len(answered) >= 15 and all(i > max(answered) for i in set(sent) - answered)
    assert np.allclose(last_axes(trace) - q0, target, atol=0.01)


@pytest.mark.parametrize("interp", INTERPS)
def test_rsipi_late_answers_stop_the_robot(rsipi, tmp_path, interp):
    """RSIPI stops answering: past the ETHERNET object's Timeout (100) late packets in a row
    the robot stops with RSI's message and the program ends with it."""
    cfg, port = local_copy(EXAMPLES / "rsi_path_ethernet.xml", tmp_path)

    def script(api, hold):
        api.tools.update_variable("RKorr.Z", 1.0)
        hold(0.5)
        return None                                # RSIPI stopped: no more answers

    settings = NetworkSettings(EXAMPLES, rsi=Channel(EXAMPLES / "rsi_path.rsi.xml", ("127.0.0.1", port)))
    box = {}
    partner = rsipi(cfg, script)

    def keep_running(net, rt):
        partner(net, rt)
        until(lambda: net.closed, 20.0)          # leave the run going until the robot stops
    result, trace, _ = run_with_partner(EXAMPLES / "rsi_path.src", settings, keep_running, interp=interp, box=box)
    assert result.reason == "error"
    assert "maximum number of late packets exceeded" in result.text
    errors = [e for e in trace.events if e["kind"] == "error"]
    last_answer = net_events(trace, iface="rsi", dir="in")[-1]["t"]
    assert errors[0]["t"] - last_answer == pytest.approx(0.012 * 101, abs=0.012 * 2)


#: the KR 150 cell of issue 64's unseen RSI programs: points at X 1800-2000 mm, Z 1500-1840 mm.
#: Rebuilt from that description (the programs are not among ../shared): the project's example
#: program taken to such a point; on the KR 6 R900 it stops at its first motion ("target not
#: reachable"), on `--robot "KR 150 R3100-2"` (robot/catalogue.py) it runs and follows the sensor.
KR150_PROGRAM = """&ACCESS RVP
DEF rsi_kr150()
  DECL INT ret
  DECL INT CONTID
  BAS(#INITMOV, 0)
  PTP {X 1900, Y 0, Z 1700, A 180, B 30, C 180, S 2, T 2}
  ret = RSI_CREATE("rsi_path", CONTID, TRUE)
  IF ret <> RSIOK THEN
    HALT
  ENDIF
  ret = RSI_ON(#ABSOLUTE)
  RSI_MOVECORR()
  ret = RSI_OFF()
  ret = RSI_DELETE(CONTID)
  LIN {X 1800, Y 100, Z 1840, A 180, B 30, C 180}
END
"""


@pytest.mark.parametrize("interp", ["vm", pytest.param("tree", marks=pytest.mark.slow)])
def test_rsipi_on_a_kr150_cell_program_by_model_name(rsipi, tmp_path, interp):
    shutil.copy(EXAMPLES / "rsi_path.rsi.xml", tmp_path / "rsi_path.rsi.xml")
    prog = tmp_path / "rsi_kr150.src"
    prog.write_text(KR150_PROGRAM, encoding="ascii")
    cfg, port = local_copy(EXAMPLES / "rsi_path_ethernet.xml", tmp_path)

    def script(api, hold):
        z0 = pose(api)
        api.tools.update_variable("RKorr.Z", -8.0)
        reached = until(lambda: abs(pose(api)[2] - z0[2] + 8.0) < 0.01)
        hold(0.5)
        api.tools.update_variable("Stop", True)
        hold(0.3)
        return z0, reached

    settings = NetworkSettings(tmp_path, rsi=Channel(tmp_path / "rsi_path.rsi.xml", ("127.0.0.1", port)))
    result, trace, (z0, reached) = run_with_partner(prog, settings, rsipi(cfg, script), interp=interp,
                                                    robot="KR 150 R3100-2")
    assert reached
    assert result.reason == "completed", (result.reason, result.text)
    assert z0[0] == pytest.approx(1900.0, abs=0.01) and z0[2] == pytest.approx(1700.0, abs=0.01)
    last = robot_packets(trace)[-1].find("RIst")
    assert float(last.get("Z")) - z0[2] == pytest.approx(-8.0, abs=0.01)
    # the stand-in KR 6 R900 cannot reach the cell's first point: the case the issue saw
    kr6 = run_krl(tmp_path, KR150_PROGRAM.split("  ret = RSI_CREATE")[0].replace("&ACCESS RVP\n", "") + "END\n",
                  name="rsi_kr150_kr6", interp=interp)
    assert "target not reachable" in str(kr6.result.error)
