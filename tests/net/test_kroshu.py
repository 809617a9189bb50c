"""kroshu's external-control SDK (KSS variant) on the simulated controller (issue 35,
done-when 1), against partners written from its protocol:

* its EKI server (``driver.src``: SPS_Init/SPS_LoopCall in the submit interpreter) takes
  ``<External REQTYPE=".." ControlMode=".." CycleTime=".."/>`` commands over TCP and answers
  with ``<Robot>`` documents: ``Init`` (version, axes, model) after CMD_CON, ``Response`` with
  the event number, ``Status`` (control mode, cycle time, drives, operation mode, ...);
* its RSI program (``rsi_joint_pos_12ms.src``, the program CMD_START selects for joint
  position control at 12 ms) takes absolute axis corrections (``AK``) from the client over
  UDP, every packet carrying the robot's axes (``AIPos``), and ends when the client sends
  ``<Stop>1</Stop>``.

The command and event numbers are the SDK's own (mappings.dat: a command is its index in
COMMAND_TYPES less one, an event its index in EVENT_TYPES less one), read here, not from net/.

The corpus's KSS copy has no ``status.dat`` and no ``logging.src``; the test's backup takes
them from the same SDK's iiQKA copy (copied into a temporary folder, never into the repository;
the SDK repository's own KSS ``logging.src`` is the same code, docs/network.md "Decisions").
The robot program is the one CMD_START would select: ``CWRITE($CMD, .., "RUN/...")`` from the
submit interpreter is not simulated (docs/network.md, Decisions), so the run starts it.
``EKI_Send(CH, "Robot/Init")`` sends the part inside its root (``<Robot><Init .../></Robot>``),
as KUKA's EthernetKRL manual shows a partial send."""

from __future__ import annotations

import shutil
import socket
import threading
import time
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from net.settings import Channel, NetworkSettings

from .helpers import CONFIGS, PROGRAMS, net_events, run_with_partner
from .test_eki_partners import read_documents

SDK = "kroshu__kuka-external-control-sdk/kuka_external_control_sdk/krc_setup"
KROSHU = CONFIGS / "kroshu"
MSGLIB = "khrzysio__KRC4_test/R1/System/MsgLib.src"

# mappings.dat of the SDK: COMMAND_TYPES (CON, START, RESET, CANCEL, CHANGE, NONE, ...) and
# EVENT_TYPES (STARTED, STOPPED, CANCELLED, RESET_OK, ERROR, CONNECTED, SWITCH_OK, ...), less one
CMD_CON, CMD_CHANGE = 0, 4
EV_CONNECTED, EV_SWITCH_OK, EV_STATUS_UPDATED = 5, 6, 12
JOINT_POSITION = 1          # CONTROL_MODE_TUPLES: control_mode_int of #JOINT_POSITION


@pytest.fixture
def kroshu_backup(shared_corpus, tmp_path):
    """A KRC/R1 tree of the SDK's KSS programs (copied into the test's temporary folder: a
    backup's links are never followed), with the submit program its README asks for and the
    iiQKA copy's status.dat and logging.src/.dat."""
    sdk = shared_corpus / SDK
    eki = tmp_path / "KRC/R1/Program/EKIserver"
    rsi = tmp_path / "KRC/R1/Program/RSI"
    eki.mkdir(parents=True)
    rsi.mkdir(parents=True)
    for f in sorted((sdk / "kss/KRC/R1/Program/EKIserver").iterdir()):
        shutil.copyfile(f, eki / f.name)
    for name in ("status.dat", "logging.src", "logging.dat"):
        assert not (eki / name).exists()
        shutil.copyfile(sdk / "iiqka_os2/Program/EKIServer" / name, eki / name)
    # MsgNotify (logging.src) is KUKA's MsgLib, part of the controller's system software: a
    # real backup's own copy, as a controller has it
    shutil.copyfile(shared_corpus / MSGLIB, eki / "MsgLib.src")
    for name in ("rsi_joint_pos_12ms.src", "rsi_helper.src", "rsi_helper.dat"):
        shutil.copyfile(sdk / "kss/KRC/R1/Program/RSI" / name, rsi / name)
    sub = tmp_path / "KRC/R1/sps.sub"
    sub.write_text((PROGRAMS / "kroshu/sps.sub").read_text())
    return rsi / "rsi_joint_pos_12ms.src", sub     # the workspace: sub.parents[2] (tmp_path)


def command(sock, reqtype: int, control_mode: int = 0, cycle_time: int = 0) -> None:
    doc = ET.Element("External", {"REQTYPE": str(reqtype), "ControlMode": str(control_mode),
                                  "CycleTime": str(cycle_time)})
    sock.sendall(ET.tostring(doc))


def rsi_client(target: np.ndarray, box: dict):
    """The SDK client's RSI side, from the protocol: answer every <Rob> packet (IPOC echoed)
    with AK = target - the axes of the first packet (#ABSOLUTE corrections), ramped over 25
    cycles; once the packet's AIPos is at the target, <Stop>1</Stop>."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    sock.settimeout(0.5)

    def serve(net):
        got = []
        end = time.monotonic() + 60
        while time.monotonic() < end and not net.closed:
            try:
                data, peer = sock.recvfrom(65536)
            except TimeoutError:
                continue
            rob = ET.fromstring(data)
            ipoc = rob.find("IPOC").text
            ai = rob.find("AIPos")
            axes = np.array([float(ai.get(f"A{k}")) for k in range(1, 7)])
            got.append(axes)
            start = got[0]
            ak = np.clip((target - start) * len(got) / 25.0, -np.abs(target - start), np.abs(target - start))
            stop = int(np.allclose(axes, target, atol=1e-4))
            if stop:
                box.setdefault("reached", axes)
            body = "<AK " + " ".join(f'A{k + 1}="{v:.6f}"' for k, v in enumerate(ak)) + "/>"
            sock.sendto(f'<Sen Type="KROSHU">{body}<Stop>{stop}</Stop><IPOC>{ipoc}</IPOC></Sen>'.encode(), peer)
        sock.close()
        box["packets"] = got

    return serve, sock.getsockname()


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_kroshu_external_control_sdk(kroshu_backup, interp):
    program, sub = kroshu_backup
    target = np.array([10.0, -80.0, 85.0, 5.0, 35.0, -20.0])
    rsi_box: dict = {}
    serve, rsi_addr = rsi_client(target, rsi_box)
    settings = NetworkSettings(KROSHU, eki={"EKIKSSINTERFACE": Channel(KROSHU / "EkiKSSinterface.xml", ("127.0.0.1", 0))},
                               rsi=Channel(KROSHU / "rsi_joint_pos.rsi.xml", rsi_addr))

    def partner(net, rt):
        rsi_thread = threading.Thread(target=serve, args=(net,), daemon=True)
        rsi_thread.start()
        eki = socket.create_connection(net.wait_address("eki:EkiKSSinterface"), timeout=20)
        buf = bytearray()
        docs = read_documents(eki, buf, "Robot", time.monotonic() + 30)
        seen = []

        def until(pred):
            for doc in docs:
                seen.append(doc)
                if pred(doc):
                    return doc
            raise AssertionError("no such document")

        command(eki, CMD_CON)
        init = until(lambda d: d.find("Init") is not None).find("Init")
        command(eki, CMD_CHANGE, JOINT_POSITION)
        switch = until(lambda d: d.find("Response") is not None
                       and d.find("Response").get("EventID") == str(EV_SWITCH_OK))
        rsi_thread.join(60)
        eki.close()
        return init, switch.find("Response"), seen

    result, trace, (init, switch, seen) = run_with_partner(program, settings, partner, interp=interp,
                                                           submit=[sub], workspace=sub.parents[2], max_sim_time=60.0)
    # the EKI server: Init after CMD_CON carries the SDK's version and this robot's axes
    assert init.get("VER") == "1.0.0"
    assert init.get("NumAxes") == "6" and init.get("NumExternalAxes") == "0"
    # CMD_CHANGE to joint position control: SWITCH_OK with the mode's name (mappings.dat)
    assert switch.text == "Joint Position Control"
    # a status went out on connection (first_update), in AUT with motion possible
    statuses = [d.find("Status") for d in seen if d.find("Status") is not None]
    assert statuses and statuses[0].get("OperationMode") == "3"
    assert statuses[0].get("DrivesPowered") in ("0", "1")
    # no EMERGENCY STOP ($ALARM_STOP, $ALARM_STOP_INTERN active-low: TRUE), operator safety
    # closed ($USER_SAF), and the robot program (started with the run) active with nothing
    # holding motion ($COULD_START_MOTION AND $PRO_ACT)
    assert statuses[0].get("EmergencyStop") == "0" and statuses[0].get("GuardStop") == "0"
    assert statuses[0].get("MotionPossible") == "1"
    # the RSI program: the axes reached the target the client commanded, every packet
    # carried the robot's axes, and the client's Stop ended RSI_MOVECORR: the program ran to
    # its end (RSI_OFF, PTP $AXIS_ACT_MEAS, RSI_DELETE)
    assert "reached" in rsi_box, rsi_box.get("packets", [])[-1:]
    assert result.reason == "completed", result.text
    poses = [e["axes"] for e in trace.events if e["kind"] == "pose"]
    assert np.allclose(poses[-1], target, atol=1e-4)
    sent = net_events(trace, iface="rsi", dir="out")
    assert len(sent) >= len(rsi_box["packets"]) > 25
    # EKI traffic traced with its simulated times
    assert net_events(trace, iface="eki", dir="connect")
    assert [e for e in net_events(trace, iface="eki", dir="in") if 'REQTYPE="4"' in e["data"]]
