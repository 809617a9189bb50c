"""KUKA's EthernetKRL layer shipped in a backup (issue 59, case 3), rebuilt from the issue's
description: an unseen depalletizer backup carries ``TP/EthernetKRL/EthernetKRL.src``, KUKA's KRL
layer of the option, whose ``EKI_Init`` and the others call the installed kernel through
``CWRITE($FCT_CALL, Stat, Mode, "EFC_eki_Init", ...)``. The backup's own definitions win over the
project's natives, and on main the run stopped at once: "CWRITE: only the $CMD channel is
supported by this simulator". No public copy of KUKA's file was found (docs/network.md, "KUKA's
EKI layer"); tests/net/ekilayer/EthernetKRL.src is written from the description.

A backup that ships the layer must behave as one that does not: the same messages on the wire,
the same answer read, on both interpreters; a kernel function the option does not have gives
KUKA's EthernetKRL message 4, "Requested function not implemented"."""

from __future__ import annotations

import shutil
import socket
import time
import xml.etree.ElementTree as ET

import pytest

from interp.run import make_runtime, run_spec, RunSinks
from krl.workspace import workspaces_for
from net.settings import Channel, NetworkSettings
from robot.trace import TraceWriter

from .helpers import HERE, net_events, run_with_partner

LAYER = HERE / "ekilayer"


def _backup(tmp, with_layer: bool):
    root = tmp / ("with" if with_layer else "without")
    for d in ("R1/System", "R1/Program", "Config/User/Common/EthernetKRL"):
        (root / d).mkdir(parents=True)
    (root / "R1/System/$config.dat").write_text("DEFDAT $CONFIG\nENDDAT\n")
    if with_layer:
        (root / "R1/TP/EthernetKRL").mkdir(parents=True)
        shutil.copy(LAYER / "EthernetKRL.src", root / "R1/TP/EthernetKRL/EthernetKRL.src")
    for f in ("ask.src", "ask.dat"):
        shutil.copy(LAYER / f, root / "R1/Program" / f)
    shutil.copy(LAYER / "Layer.xml", root / "Config/User/Common/EthernetKRL/Layer.xml")
    return root


def _serve(server):
    def partner(net, rt):
        server.settimeout(60)
        conn, _ = server.accept()
        conn.settimeout(60)
        data = b""
        deadline = time.monotonic() + 60
        while b"</Robot>" not in data and time.monotonic() < deadline:
            data += conn.recv(4096)
        doc = ET.fromstring(data.decode())
        conn.sendall(b"<Pc><Answer>42</Answer></Pc>")
        conn.settimeout(30)
        rest = conn.recv(100)
        conn.close()
        server.close()
        return doc.findtext("Msg"), rest
    return partner


def _run(root, interp):
    server = socket.create_server(("127.0.0.1", 0))
    settings = NetworkSettings(root, eki={"LAYER": Channel(None, ("127.0.0.1", server.getsockname()[1]))})
    box: dict = {}
    res, trace, value = run_with_partner(root / "R1/Program/ask.src", settings, _serve(server), interp=interp,
                                         box=box, max_sim_time=30)
    data = box["rt"].program.module("ask").data
    wire = [(e["dir"], e.get("data")) for e in net_events(trace) if e["dir"] in ("in", "out", "connect")]
    return res, value, (data["RESULT"].get(), data["CONNECTED"].get()), wire


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_backup_shipping_kukas_eki_layer_runs_as_one_without_it(tmp_path, interp):
    runs = [_run(_backup(tmp_path, layer), interp) for layer in (True, False)]
    for res, value, got, _wire in runs:
        assert res.reason == "completed", res.text
        assert value == ("hello", b"")
        assert got == (42, True)
    assert runs[0][3] == runs[1][3]


def test_the_layer_checks_clean(tmp_path):
    [ws] = workspaces_for(_backup(tmp_path, True))
    assert [d for d in ws.check() if d.is_error] == []


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_kernel_function_the_option_lacks_is_kukas_message(tmp_path, interp):
    root = _backup(tmp_path, True)
    (root / "R1/Program/reset.src").write_text(
        'DEF reset( )\n  DECL EKI_STATUS RET\n  RET = EKI_Init("Layer")\n  RET = EKI_Reset("Layer")\nEND\n')
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(root / "R1/Program/reset.src", mujoco=False, check=False, interp=interp,
                                  max_sim_time=5), RunSinks(trace=tw))
    res = rt.run()
    assert res.reason == "error"
    assert res.text.startswith("EKI00004 Requested function not implemented: EFC_eki_Reset")
    assert (res.error.number, res.line, res.file.endswith("EthernetKRL.src")) == (4, 92, True)
