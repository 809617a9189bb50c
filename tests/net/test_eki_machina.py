"""Machina.NET's KUKA driver (a corpus EKI program: machina_kuka_driver.src, the robot the
server) run unmodified against a partner written from the channel XML kept beside it in its
repository (machina_kuka_server.xml, restated in tests/net/configs/machina) and Machina's action
list (issue 59). The driver sends the robot's state S once the partner connects, waits for a
DT document whose DT/Msg/Con sets $FLAG[2], reads its DT/DC actions from the repeated
DT/DR/A elements (EKI_GetIntArray, EKI_GetRealArray), executes them one by one and answers each
with R (@ID, @T). The action numbers are Machina.NET's ActionType (the driver lists the same in
its comments: Axes 04, Speed 07, IODigital 17). The partner sends one DT of four actions: a
speed, a digital output (the driver makes it a TRIGGER on the next motion), two axis moves."""

from __future__ import annotations

import time
import xml.etree.ElementTree as ET

import pytest

from net.settings import Channel, NetworkSettings

from .helpers import CONFIGS, connect, free_port, run_with_partner

PROGRAM = "RobotExMachina__Machina.NET/src/Machina/Resources/DriverModules/KUKA/machina_kuka_driver.src"
MACHINA = CONFIGS / "machina"
FIRST = (20.0, -80.0, 85.0, 0.0, 30.0, 10.0)
LAST = (-25.0, -95.0, 100.0, 15.0, 40.0, -5.0)


def _action(n: int, kind: int, *values: float) -> ET.Element:
    vs = list(values) + [0.0] * (7 - len(values))
    return ET.Element("A", {"ID": str(n), "T": str(kind), **{f"V{i + 1}": str(v) for i, v in enumerate(vs)}})


def _dt(actions: list) -> bytes:
    dt = ET.Element("DT")
    ET.SubElement(dt, "DC").text = str(len(actions))
    dr = ET.SubElement(dt, "DR")
    dr.extend(actions)
    msg = ET.SubElement(dt, "Msg")
    ET.SubElement(msg, "Str", {f"M{i:02d}": "" for i in range(1, 16)})
    ET.SubElement(msg, "Con").text = "1"         # sets $FLAG[2]: the actions are complete
    return ET.tostring(dt)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_machina_driver_runs_the_actions_of_a_partner_written_from_its_xml(shared_corpus, interp):
    port = free_port()
    settings = NetworkSettings(MACHINA, eki={
        "MACHINA_KUKA_SERVER": Channel(MACHINA / "machina_kuka_server.xml", ("127.0.0.1", port))})

    def bridge(net, rt):
        deadline = time.monotonic() + 60
        conn = connect(port, deadline)
        conn.settimeout(60)
        buf = bytearray()

        def document(end: bytes) -> ET.Element:
            while True:
                i = buf.find(end)
                if i >= 0:
                    doc, buf[:] = bytes(buf[:i + len(end)]), buf[i + len(end):]
                    return ET.fromstring(doc)
                buf.extend(conn.recv(4096))

        state = document(b"/>")
        conn.sendall(_dt([_action(1, 7, 0.25, 50), _action(2, 17, 5, 1), _action(3, 4, 0, *FIRST),
                          _action(4, 4, 0, *LAST)]))
        answers = [document(b"/>") for _ in range(4)]
        # the driver answers a motion when its advance run has passed it: the test ends once the
        # robot stands (the driver then waits for the next DT, WAIT FOR $FLAG[2])
        while rt.controller.is_moving() or len(rt.controller.queue):
            if time.monotonic() > deadline:
                raise TimeoutError("the robot did not come to rest")
            time.sleep(0.05)
        conn.close()
        return state, answers

    box: dict = {}
    res, trace, (state, answers) = run_with_partner(shared_corpus / PROGRAM, settings, bridge, interp=interp,
                                                    box=box, max_sim_time=60)
    assert state.tag == "S" and {k: float(state.get(k)) for k in ("A1", "A2", "A3")} == {
        "A1": 0.0, "A2": -90.0, "A3": 90.0}
    assert [(a.tag, a.get("ID"), a.get("T")) for a in answers] == [
        ("R", "1", "7"), ("R", "2", "17"), ("R", "3", "4"), ("R", "4", "4")]
    io = [(e["signal"], e["value"]) for e in trace.events if e["kind"] == "io"]
    assert ("$OUT[5]", True) in io                          # the TRIGGER of action 2, on action 3's motion
    # the first axis move is approximated (C_PTP) into the second, where the robot comes to rest
    assert list(box["rt"].controller.actual.axis_act()[:6]) == pytest.approx(LAST, abs=1e-3)
    assert res.reason == "max_sim_time"
