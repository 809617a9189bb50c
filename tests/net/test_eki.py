"""EthernetKRL without a partner (issue 35): the "not connected" state a run gets when the
cell file names no partner, the errors of EKI calls that stop the program as the controller
does (EKI's own message numbers, the line), and channel configurations read safely."""

from __future__ import annotations

import time

import pytest

from interp.run import make_runtime, run_spec, RunSinks
from net.ekiconfig import ConfigError, parse_config
from robot.trace import TraceWriter

from .helpers import CONFIGS, EXAMPLES, PROGRAMS

PROGRAM = PROGRAMS / "eki_errors.src"


def run_mode(mode: int, interp: str):
    trace = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(PROGRAM, max_sim_time=5.0, mujoco=False, interp=interp), RunSinks(trace=trace))
    sink = rt.controller.network.sink
    sink.write_var("MODE", str(mode))
    started = time.monotonic()
    result = rt.run()
    return result, sink, time.monotonic() - started, trace


@pytest.mark.parametrize("interp", ["tree", "vm"])
@pytest.mark.parametrize("mode, number, line", [(1, 16, 12), (2, 15, 14), (3, 23, 16), (4, 10, 18),
                                                (5, 9, 20), (6, 3, 22)])
def test_an_eki_error_stops_the_program(mode, number, line, interp):
    result, sink, _, trace = run_mode(mode, interp)
    assert result.reason == "error"
    assert result.error.number == number
    assert result.text.startswith(f"EKI{number:05d} ")
    assert result.line == line
    assert sink.read_var("OPENED") == "0"
    end = trace.events[-1]
    assert end["kind"] == "end" and end["number"] == number and end["line"] == line


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_without_a_partner_the_channel_is_not_connected(interp):
    """No `network:` key: EKI_Open succeeds, no socket opens, Connected stays FALSE, and a WAIT
    FOR the alive flag is a deadlock found at once (no wall-clock pacing)."""
    result, sink, elapsed, trace = run_mode(7, interp)
    assert sink.read_var("CONNECTED0") == "FALSE"
    assert sink.read_var("SETOK") == "TRUE"
    assert result.reason == "deadlock"
    assert result.line == 26
    assert elapsed < 5.0
    assert not [e for e in trace.events if e["kind"] == "net"]


def test_the_shipped_configurations_read():
    for folder, name in ((EXAMPLES, "EkiHwInterface"), (CONFIGS, "ros_eki_motion"), (CONFIGS, "ros_eki_state")):
        cfg = parse_config((folder / f"{name}.xml").read_bytes(), name)
        assert cfg.server and cfg.port in (54600, 54601)
    cfg = parse_config((EXAMPLES / "EkiHwInterface.xml").read_bytes(), "EkiHwInterface")
    assert cfg.protocol == "UDP" and cfg.alive_flag == 1 and cfg.buffering == 512
    assert [e.tag for e in cfg.receive][:2] == ["RobotCommand/Pos/@A1", "RobotCommand/Pos/@A2"]
    assert cfg.receive[0].type == "REAL" and cfg.send_kind == "xml"


@pytest.mark.parametrize("text, says", [
    (b'<!DOCTYPE x [<!ENTITY a "b">]><ETHERNETKRL/>', "refused"),
    (b"<ETHERNETKRL><CONFIGURATION>", "not well-formed"),
    (b"<OTHER/>", "not ETHERNETKRL"),
    (b"<ETHERNETKRL><CONFIGURATION><EXTERNAL><TYPE>Client</TYPE></EXTERNAL></CONFIGURATION></ETHERNETKRL>", "no PORT"),
    (b"<ETHERNETKRL><CONFIGURATION><EXTERNAL><IP>1.2.3.4</IP><PORT>99999</PORT></EXTERNAL></CONFIGURATION></ETHERNETKRL>", "outside"),
    (b"<a>" * 40 + b"</a>" * 40, "nested deeper"),
    (b"<ETHERNETKRL>" + b" " * (300 * 1024) + b"</ETHERNETKRL>", "more than the limit"),
])
def test_a_bad_configuration_is_refused(text, says):
    with pytest.raises(ConfigError, match=says):
        parse_config(text, "X")
