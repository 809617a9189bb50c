"""An EKI pair of the corpus run unmodified against partners written from the channel XMLs its
repository keeps beside its KRL, and from its README (issue 59): OsmanMarangoz's
2526ws_BH_KRL2Python drives a KR3 from Python over two TCP channels, the robot the server of both
(tests/net/configs/osman restates KRL/motion_eki.xml and KRL/meta_eki.xml): MOTION_EKI, served by
the robot program motion_eki.src, takes RobotCommand documents and streams RobotState (positions,
velocities, torques, the last command's ids) from a timer interrupt; META_EKI, served by the submit
program meta_eki.sub (the README: it replaces SPS in the controller's custom.dat), takes
MetaCommand/@VelocityOverride, which the robot program applies to $OV_PRO.

What the partner knows is the XMLs' elements and comments ("Type: 1=Move, 2=Gripper", "Mode:
1=Joint, 2=Cartesian-Ptp, 3=Cartesian-Lin, 6=Cartesian-Circ") and the README's ports and roles;
it does not read the KRL. It sends a velocity override of 40 %, then one joint move (Type 1, Mode
1), and reads the state stream until the robot stands at the target and reports the command
finished. (The KRL's own numbering differs from the XML's comment: its Type 1 grips, then moves —
the gripper's outputs change too, and the command is reported finished at the grip already; the
partner waits for the position as well.)"""

from __future__ import annotations

import time
import xml.etree.ElementTree as ET

import pytest

from net.settings import Channel, NetworkSettings

from .helpers import CONFIGS, connect, free_port, run_with_partner

REPO = "OsmanMarangoz__2526ws_BH_KRL2Python/KRL"
OSMAN = CONFIGS / "osman"
TARGET = {"A1": 20.0, "A2": -80.0, "A3": 75.0, "A4": 10.0, "A5": 30.0, "A6": -15.0}


def _states(conn, deadline: float):
    """The RobotState documents the robot streams."""
    buf = bytearray()
    while time.monotonic() < deadline:
        end = buf.find(b"</RobotState>")
        if end >= 0:
            doc, buf[:] = bytes(buf[:end + 13]), buf[end + 13:]
            yield ET.fromstring(doc[doc.find(b"<"):])
            continue
        data = conn.recv(65536)
        if not data:
            return
        buf += data
    raise TimeoutError("no RobotState")


def _command(**values) -> ET.Element:
    """A RobotCommand document with every element the channel's RECEIVE list declares (an
    attribute each: ``RobotCommand/Move/@Mode`` is Mode of RobotCommand's Move), 0 unless
    `values` gives it (keys relative to RobotCommand: ``Move/@Mode``, or ``Id``). The robot
    reads the whole of a command, so a partner written from the configuration sends it whole."""
    root = ET.Element("RobotCommand")
    config = ET.parse(OSMAN / "MOTION_EKI.xml").getroot()
    for el in config.iterfind("RECEIVE/XML/ELEMENT"):
        path, attr = el.get("Tag").split("/@")
        node = root
        for part in path.split("/")[1:]:
            node = node.find(part) if node.find(part) is not None else ET.SubElement(node, part)
        rel = "/".join(path.split("/")[1:] + ["@" + attr]) if "/" in path else attr
        node.set(attr, str(values.get(rel, 0)))
    return root


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_motion_and_meta_channels_answer_partners_written_from_their_xml(shared_corpus, interp):
    motion, meta = free_port(), free_port()
    settings = NetworkSettings(OSMAN, eki={
        "MOTION_EKI": Channel(OSMAN / "MOTION_EKI.xml", ("127.0.0.1", motion)),
        "META_EKI": Channel(OSMAN / "META_EKI.xml", ("127.0.0.1", meta))})

    def python_side(net, rt):
        deadline = time.monotonic() + 90
        m = connect(meta, deadline)
        m.sendall(b'<MetaCommand VelocityOverride="40" AbortCommands="FALSE"/>')
        conn = connect(motion, deadline)
        conn.settimeout(60)
        states = _states(conn, deadline)
        first = next(states)
        conn.sendall(ET.tostring(_command(Id=1, Type=1, **{"Move/@Mode": 1}, **{
            f"Move/Joint/@{a}": v for a, v in TARGET.items()})))
        seen = 0
        for state in states:
            seen += 1
            joint = state.find("Position/Joint")
            there = all(abs(float(joint.get(a)) - v) < 1e-3 for a, v in TARGET.items())
            if there and state.find("Command").get("Finished_Id") == "1":
                break
        conn.close()
        m.close()
        return first, state, seen

    box: dict = {}
    res, trace, (first, last, seen) = run_with_partner(
        shared_corpus / REPO / "motion_eki.src", settings, python_side, interp=interp, box=box,
        max_sim_time=60, submit=[shared_corpus / REPO / "meta_eki.sub"])
    assert first.find("Command").attrib == {"Id": "0", "Finished_Id": "0", "Stopped": "FALSE"}
    assert seen > 1 and last.find("Command").get("Finished_Id") == "1"
    joint = last.find("Position/Joint")
    assert {a: float(joint.get(a)) for a in TARGET} == pytest.approx(TARGET, abs=1e-3)
    rt = box["rt"]
    assert rt.sysvars.lookup("$OV_PRO").get() == 40            # the meta channel's override, applied
    io = {(e["signal"], e["value"]) for e in trace.events if e["kind"] == "io"}
    assert ("$OUT[8]", True) in io          # the KRL's Type 1: grip (close: $OUT[7] stays FALSE), then move
    assert res.reason in ("max_sim_time", "stopped"), res.text
