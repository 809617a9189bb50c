"""RSI 2 (KR C2, the ST_ functions; net/rsi2.py): ROS-Industrial's KR_C2 ``ros_rsi.src`` read
in place from the corpus, with its published ETHERNET configuration
(tests/net/configs/published/ros_industrial_kr_c2/) and a sensor written from that
configuration (tests/net/sensor.py). tests/net/test_rsi_corpus.py runs it as every other RSI
program of the corpus (12 ms, an absolute AK correction followed); here what is RSI 2's own:
the integration mode and the limits set by ST_SETPARAM number, the late-packet stop, and the
same run on both interpreters. Variants of the program are written to tmp_path with one line
changed; the expected values follow from that line and the sensor's commands."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from interp.run import make_runtime, run_spec, RunSinks
from net.settings import Channel, NetworkSettings
from robot.trace import TraceWriter

from ..interp.helpers import run_krl
from .helpers import CONFIGS, net_events, run_with_partner
from .sensor import ConfigSensor, axes_of

#: the RSI partner answers in real time (4/12 ms cycles): make test runs these on one worker (tests/conftest.py, ``wall_clock``)
pytestmark = pytest.mark.wall_clock

PROGRAM = "ros-industrial__kuka_experimental/kuka_rsi_hw_interface/krl/KR_C2/ros_rsi.src"
CONFIG = CONFIGS / "published" / "ros_industrial_kr_c2" / "ros_rsi_ethernet.xml"


def _program(shared_corpus, tmp_path, old: str = "", new: str = ""):
    """The corpus program, or a copy in tmp_path with `old` replaced by `new` (once)."""
    src = shared_corpus / PROGRAM
    if not old:
        return src
    text = src.read_text(encoding="latin-1")
    assert text.count(old) == 1, old
    out = tmp_path / "ros_rsi.src"
    out.write_text(text.replace(old, new), encoding="latin-1")
    return out


def _run(program, plan, interp="tree", settings_dir=None, config=CONFIG):
    sensor = ConfigSensor(config)
    settings = NetworkSettings(settings_dir or config.parent, rsi=Channel(config, sensor.address))
    return run_with_partner(program, settings, sensor.partner(plan), interp=interp)


def test_relative_integration_mode_by_st_setparam(shared_corpus, tmp_path):
    """ST_SETPARAM(hAxis,1,1): relative; each answer's AK adds to the correction (0.1 deg x 20
    answers = 2 deg on A1, 0.05 x 20 = -1 deg on A3), where the published 0 (absolute) would hold
    it at the last answer's value."""
    src = _program(shared_corpus, tmp_path, "err = ST_SETPARAM(hAxis,1,0)", "err = ST_SETPARAM(hAxis,1,1)")

    def plan(i, rob):
        if i >= 40:
            return "done"
        return {("AK", "A1"): 0.1 if i < 20 else 0.0, ("AK", "A3"): -0.05 if i < 20 else 0.0}, False

    result, trace, got = _run(src, plan)
    first, last = np.array(axes_of(got[0])), np.array(axes_of(got[-1]))
    assert np.allclose(last - first, [2.0, 0, -1.0, 0, 0, 0], atol=1e-4), last - first


def test_limits_by_st_setparam_number(shared_corpus, tmp_path):
    """ST_SETPARAM numbers 2..13 and 14..25 are the lower and upper limits of A1..A6, E1..E6:
    upperBound[1] = 1.5 (number 14) holds A1's absolute 4 deg at 1.5; lowerBound[2] = -0.5
    (number 3) holds A2's -3 deg at -0.5; A3's 2 deg is within its +-100."""
    src = _program(shared_corpus, tmp_path, "upperBound[1] =  100", "upperBound[1] =  1.5")
    text = src.read_text(encoding="latin-1").replace("lowerBound[2] = -100", "lowerBound[2] = -0.5")
    src.write_text(text, encoding="latin-1")

    def plan(i, rob):
        return "done" if i >= 40 else ({("AK", "A1"): 4.0, ("AK", "A2"): -3.0, ("AK", "A3"): 2.0}, False)

    result, trace, got = _run(src, plan)
    first, last = np.array(axes_of(got[0])), np.array(axes_of(got[-1]))
    assert np.allclose(last - first, [1.5, -0.5, 2.0, 0, 0, 0], atol=1e-4), last - first


def test_both_interpreters_send_the_same_datagrams(shared_corpus):
    """The tree interpreter and the VM: the same packets (IPOC, AIPos, RIst, Delay) for the same
    answers, cycle for cycle."""
    def plan(i, rob):
        return "done" if i >= 60 else ({("AK", "A1"): 0.05 * min(i, 30), ("AK", "A6"): -0.02 * min(i, 30)}, False)

    runs = {}
    for interp in ("tree", "vm"):
        result, trace, got = _run(shared_corpus / PROGRAM, plan, interp=interp)
        runs[interp] = [(r.findtext("IPOC"), tuple(sorted(r.find("AIPos").attrib.items())),
                         tuple(sorted(r.find("RIst").attrib.items())), r.find("Delay").get("D")) for r in got]
    assert len(runs["tree"]) == 61
    assert runs["tree"] == runs["vm"]
    a1 = [float(dict(p[1])["A1"]) for p in runs["tree"]]
    assert a1[-1] - a1[0] == pytest.approx(1.5, abs=1e-4)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_silent_sensor_stops_the_robot(shared_corpus, interp):
    """The sensor answers 10 packets and falls silent: after 100 late packets in a row (the RSI
    2 ETHERNET object's limit, as RSI 3's Timeout) the 101st stops the robot with RSI's message,
    and ST_SKIPSENS ends with the program."""
    def plan(i, rob):
        if i >= 200:
            return "done"
        return ({("AK", "A1"): 0.5}, False) if i < 10 else None

    result, trace, got = _run(shared_corpus / PROGRAM, plan, interp=interp)
    assert result.reason == "error" and "maximum number of late packets" in result.text, (result.reason, result.text)
    assert len(got) == 10 + 101, len(got)
    assert [r.find("Delay").get("D") for r in got[10:13]] == ["0", "1", "2"]
    assert axes_of(got[-1])[0] - axes_of(got[0])[0] == pytest.approx(0.5, abs=1e-4)


def _run_alone(program, settings, max_sim_time=3.0):
    """The program with no sensor answering (the address a closed port): result and trace."""
    trace = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(program, network=settings, max_sim_time=max_sim_time, mujoco=False),
                         RunSinks(trace=trace))
    return rt.run(), trace


def _texts(trace) -> str:
    return " ".join(str(e.get("text", "")) for e in trace.events)


def test_the_configuration_is_found_in_roboter_init(shared_corpus, tmp_path):
    """ST_ETHERNET's file is looked up where the KR C2 keeps it (the program's comment: "Should
    be in c:/krc/roboter/init"): a backup whose archive holds ``KRC/R1/Program/ros_rsi.src`` and
    ``C/KRC/ROBOTER/INIT/ros_rsi_ethernet.xml``; the cell file names only the sensor's address."""
    root = tmp_path / "archive"
    prog = root / "KRC" / "R1" / "Program" / "ros_rsi.src"
    prog.parent.mkdir(parents=True)
    shutil.copyfile(shared_corpus / PROGRAM, prog)
    system = root / "KRC" / "R1" / "System"
    system.mkdir()
    (system / "$config.dat").write_text("DEFDAT  $CONFIG\nENDDAT\n")
    init = root / "C" / "KRC" / "ROBOTER" / "INIT"
    init.mkdir(parents=True)
    shutil.copyfile(CONFIG, init / "ros_rsi_ethernet.xml")
    result, trace = _run_alone(prog, NetworkSettings(tmp_path, rsi=Channel(None, ("127.0.0.1", 9))))
    created = net_events(trace, iface="rsi", dir="context")
    assert created and "ETHERNET configuration ros_rsi_ethernet.xml" in created[0]["text"], _texts(trace)[:2000]
    assert net_events(trace, iface="rsi", dir="out")


def test_a_missing_configuration_is_named(shared_corpus, tmp_path):
    """No ros_rsi_ethernet.xml anywhere: ST_ETHERNET returns an error RSIERR (the program's own
    check HALTs), the message names the file and where it was looked for; nothing is sent."""
    src = tmp_path / "ros_rsi.src"
    shutil.copyfile(shared_corpus / PROGRAM, src)
    result, trace = _run_alone(src, NetworkSettings(tmp_path, rsi=Channel(None, ("127.0.0.1", 9))))
    assert "RSI: ST_ETHERNET: ETHERNET configuration ros_rsi_ethernet.xml not found" in _texts(trace)
    assert not net_events(trace, iface="rsi", dir="out")


def test_tcp_protocol_is_refused_clearly(shared_corpus, tmp_path):
    """PROTOCOL TCP (Ethernet RSI XML allows it; the simulator's RSI speaks UDP): ST_ON returns
    an error RSIERR with a message naming the configuration; nothing is sent."""
    cfg = tmp_path / "ros_rsi_ethernet.xml"
    cfg.write_text(CONFIG.read_text().replace("<PROTOCOL>UDP</PROTOCOL>", "<PROTOCOL>TCP</PROTOCOL>"))
    result, trace = _run_alone(shared_corpus / PROGRAM, NetworkSettings(tmp_path, rsi=Channel(cfg, ("127.0.0.1", 9))))
    assert "RSI: PROTOCOL TCP of ros_rsi_ethernet.xml is not simulated (UDP is)" in _texts(trace)
    assert not net_events(trace, iface="rsi", dir="out")


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_st_functions_without_a_sensor(tmp_path, interp):
    """The ST_ functions as KRL sees them, no sensor needed: handles from 1, the enum RSIERR
    returned; a link to an unknown handle is #RSIINVOBJID; ST_ON without an ETHERNET object is
    not #RSIOK; ST_SKIPSENS before ST_ON stops the program with its line; object 257 of one flow
    is #RSINOMEM (docs/security.md)."""
    run = run_krl(tmp_path, """DEF prog()
  INT i
  err = ST_AXISCORR(h1, 0)
  err = ST_PATHCORR(h2, 0)
  link = ST_NEWLINK(99, 1, h1, 1)
  started = ST_ON()
  n = 2
  FOR i = 3 TO 300
    err = ST_AXISCORR(h2, 0)
    IF err == #RSIOK THEN
      n = n + 1
    ENDIF
  ENDFOR
  ST_SKIPSENS()
END
""", "DEFDAT prog\n  DECL RSIERR err, link, started\n  INT h1, h2, n\nENDDAT\n", interp=interp)
    assert run.result.line == 14, (run.result.reason, run.result.line, run.result.text)
    assert (run.var("prog", "h1"), run.var("prog", "n")) == (1, 256)
    assert run.var("prog", "link").name == "RSIINVOBJID"
    assert run.var("prog", "started").name != "RSIOK"
    assert run.var("prog", "err").name == "RSINOMEM"
    assert (run.result.reason, run.result.line, run.result.text) == ("error", 14, "ST_SKIPSENS without ST_ON")
