"""An EKI program of the corpus run unmodified against a partner written from the channel XML its
repository keeps beside it (issue 59): LiorSkoury's Kuka_EthernetKrl_Python workshop
(KRL/ethernetkrl_workshop.src; its repository's Config/ITECH.xml, whose facts
tests/net/configs/ITECH.xml restates). The robot is the server; the program HALTs twice before
its loop (the operator presses Start again: ``halt_continues``), waits for its ALIVE flag, then for
each Sensor message answers Robot/DataRecived, and after the next one Robot with TaskDone and its
position. The partner knows only the XML: it sends Sensor/Action and Sensor/WaitForResponse.

The program empties its Sensor memory right after its ALIVE flag rises, so the partner sends its
first message a second after connecting (a message sent at once is emptied with the memory, and
the program then reads an empty memory: EKI00015, as on a controller).

The published XML does not configure Sensor/Key and Sensor/Frame, which the program reads for
actions 0 and 1: with it, the controller gives EKI00016 "Element not found" at that line, and so
does the run (the program's error with its published configuration, as on a controller)."""

from __future__ import annotations

import time
import xml.etree.ElementTree as ET

import pytest

from net.settings import Channel, NetworkSettings

from .helpers import CONFIGS, connect, free_port, run_with_partner

PROGRAM = "LiorSkoury-git__Kuka_EthernetKrl_Python/KRL/ethernetkrl_workshop.src"


def _document(conn, buf: bytearray, deadline: float) -> ET.Element:
    """The next <Robot> document the robot sends."""
    while time.monotonic() < deadline:
        end = buf.find(b"</Robot>")
        if end >= 0:
            doc, buf[:] = bytes(buf[:end + 8]), buf[end + 8:]
            return ET.fromstring(doc)
        buf += conn.recv(4096)
    raise TimeoutError("no <Robot> document")


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_workshop_answers_a_partner_written_from_its_xml(shared_corpus, interp):
    port = free_port()
    settings = NetworkSettings(CONFIGS, eki={"ITECH": Channel(CONFIGS / "ITECH.xml", ("127.0.0.1", port))})

    def sensor(net, rt):
        deadline = time.monotonic() + 60
        conn = connect(port, deadline)
        conn.settimeout(60)
        # the program empties the channel's memories right after its ALIVE flag rises (its
        # EKI_ClearBuffer of Sensor and Robot, lines 33-34): a message sent before would be
        # emptied with them; the workshop's operator sends from Grasshopper well after
        # connecting. The partner waits until the robot program has passed them, whatever the
        # machine's load (a fixed second of wall time was not enough at load 20)
        robot = next(t for t in rt.scheduler.tasks if t.kind == "robot")
        while (robot.line or 0) <= 34 and time.monotonic() < deadline:
            time.sleep(0.01)
        buf = bytearray()
        docs = []
        message = b"<Sensor><Action>2</Action><WaitForResponse>FALSE</WaitForResponse></Sensor>"
        conn.sendall(message)
        docs.append(_document(conn, buf, deadline))            # DataRecived
        conn.sendall(message)
        docs.append(_document(conn, buf, deadline))            # TaskDone and the position
        conn.sendall(b"<Sensor><Action>0</Action><WaitForResponse>FALSE</WaitForResponse></Sensor>")
        docs.append(_document(conn, buf, deadline))            # DataRecived, then Sensor/Key: EKI00016
        conn.settimeout(30)
        conn.recv(100)
        conn.close()
        return docs

    box: dict = {}
    res, _trace, docs = run_with_partner(shared_corpus / PROGRAM, settings, sensor, interp=interp, box=box,
                                         max_sim_time=60, halt_continues=2)
    assert [ET.tostring(d, encoding="unicode") for d in (docs[0], docs[2])] == \
        ["<Robot><DataRecived>TRUE</DataRecived></Robot>"] * 2
    second = docs[1]
    assert second.findtext("DataRecived") == "TRUE" and second.findtext("TaskDone") == "TRUE"
    pos = second.find("Data/ActPos")
    act = box["rt"].program.module("ethernetkrl_workshop").data["CURRENT_POSITION"].get()
    assert {k: float(v) for k, v in pos.attrib.items()} == pytest.approx(
        {k: act.f[k] for k in ("X", "Y", "Z", "A", "B", "C")}, abs=1e-5)
    assert res.reason == "error" and res.error.number == 16
    assert res.text.startswith("EKI00016 Element not found: channel ITECH, element Sensor/Key")
    assert res.file.endswith("ethernetkrl_workshop.src") and res.line == 53
