"""The PLC side over the network (issue 35, done-when 1): the example cell
(examples/plc_cell) is driven by its plain client script over Modbus TCP (pymodbus's client):
EXT start, P00's program-number handshake selecting a program, the job's output; an OPC UA
client (asyncua's) reads the outputs the cycle set."""

from __future__ import annotations

import asyncio
import importlib.util

import pytest

from interp.run import make_runtime, run_spec, RunSinks
from net.settings import NetworkSettings
from robot.trace import TraceWriter
from tests.conftest import REPO_ROOT

from .helpers import net_events, run_with_partner

CELL = REPO_ROOT / "examples" / "plc_cell"


def plc_script():
    spec = importlib.util.spec_from_file_location("example_plc", CELL / "plc.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("interp, number", [("tree", 2), ("vm", 1)])
def test_a_plc_selects_a_program_and_opcua_reads_its_outputs(interp, number, tmp_path):
    plc = plc_script()
    settings = NetworkSettings(CELL, modbus=("127.0.0.1", 0), opcua="opc.tcp://127.0.0.1:0")

    def partner(net, rt):
        host, port = net.wait_address("modbus")
        _, ua_port = net.wait_address("opcua")
        plc.select_program(host, port, number)
        return asyncio.run(plc.read_outputs(f"opc.tcp://127.0.0.1:{ua_port}", [10, 11, 12]))

    result, trace, outputs = run_with_partner(CELL / "R1" / "cell.src", settings, partner,
                                              interp=interp, max_sim_time=120.0)
    done = {1: 10, 2: 11}[number]
    other = {1: 11, 2: 10}[number]
    assert outputs[done] is True and outputs[other] is False
    assert outputs[12] is (number == 1)              # job 1 closes the gripper, job 2 opens it
    # the PLC's writes arrived as net events and changed the inputs P00 read
    writes = [e["data"] for e in net_events(trace, iface="plc", dir="in")]
    assert "$IN[17]=TRUE" in writes and "$IN[41]=TRUE" in writes and "$IN[41]=FALSE" in writes
    bits = {f"$IN[{33 + i}]=TRUE" for i in range(8) if (number >> i) & 1}
    assert bits <= set(writes)
    # the cycle: PGNO_REQ up, then down (acknowledged), then the job's motions and its output
    io = [(e["t"], e["signal"], e["value"]) for e in trace.events if e["kind"] == "io"]
    req = [t for t, s, v in io if s == "$OUT[20]"]
    assert len(req) >= 2
    done_t = [t for t, s, v in io if s == f"$OUT[{done}]" and v is True]
    assert done_t and done_t[0] > req[1]
    # the trace is a recording: replayed on the other interpreter, without sockets, the PLC's
    # writes arrive at the same cycles and the cycle sets the same outputs at the same times
    recording = tmp_path / "plc.jsonl"
    recording.write_text("\n".join(trace.lines) + "\n")
    other = "vm" if interp == "tree" else "tree"
    replayed = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(CELL / "R1" / "cell.src", network=NetworkSettings(tmp_path, replay=recording),
                         max_sim_time=result.sim_time, mujoco=False, interp=other), RunSinks(trace=replayed))
    rt.run()
    again = [(e["t"], e["signal"], e["value"]) for e in replayed.events if e["kind"] == "io"]
    assert again == io
