"""EthernetKRL's binary protocol types (issue 59; KUKA.EthernetKRL 2.2 manual 6.2.4 "Sending
data" and 6.2.5 "Reading out data", pages 32-33; docs/network.md "Binary records").

Case 2 of the issue, rebuilt from its description: a vision vendor's client library (the robot is
the client) exchanges fixed-length records (``<RAW><ELEMENT Tag=".." Type="BYTE" Size="80"/>``):
it builds its request with ``CAST_TO`` into ``CHAR Request[80]`` whose first bytes are 0 and
sends it with ``EKI_Send(channel, Request[])``; on main the array was read as a string, cut at its
first NUL, and the program stopped with EKI00019 "No data to send". The partner is written from
the record format alone: 80 bytes each way, little-endian INT (4 bytes), REAL (4 bytes IEEE
single), BOOL (1 byte) and CHAR (1 byte), as the manual's own example lays them out
(``CAST_TO(Bytes[],OFFSET,91984754,913434.2,TRUE,"X")`` into ``CHAR Bytes[10]`` sends
``"r?{ ? _I X"``: 4 + 4 + 1 + 1 bytes).
"""

from __future__ import annotations

import socket
import struct
import time

import pytest

from net.settings import Channel, NetworkSettings

from .helpers import HERE, net_events, run_with_partner

BINARY = HERE / "binary"


def _recv_exactly(conn, n: int, deadline: float) -> bytes:
    data = b""
    while len(data) < n and time.monotonic() < deadline:
        chunk = conn.recv(n - len(data))
        if not chunk:
            break
        data += chunk
    return data


def test_the_manuals_cast_example_lays_out_ten_bytes():
    """The byte layout the tests below rely on, from the manual's example (p. 33)."""
    sent = struct.pack("<if?c", 91984754, 913434.2, True, b"X")
    assert len(sent) == 10
    # the manual prints the bytes as text, "?" and blanks for the unprintable ones: "r?{ ? _I X"
    shown = "".join(chr(b) if 0x21 <= b < 0x7F else "?" if b >= 0x7F else " " for b in sent)
    assert shown == "r?{ ? _I X"


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_fixed_length_client_library_sends_its_record_nuls_included(interp):
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    settings = NetworkSettings(BINARY, eki={"VISIONBIN": Channel(BINARY / "VisionBin.xml", ("127.0.0.1", port))})
    box: dict = {}

    def partner(net, rt):
        server.settimeout(60)
        conn, _ = server.accept()
        conn.settimeout(60)
        request = _recv_exactly(conn, 80, time.monotonic() + 60)
        # the answer: counter, command echoed, status 1102, one target at (250.5, -40.25), valid, tag K
        answer = struct.pack("<iiiiff?c", 0, 101, 1102, 1, 250.5, -40.25, True, b"K").ljust(80, b"\0")
        conn.sendall(answer)
        # the program closes the channel when it has read the answer
        conn.settimeout(30)
        rest = conn.recv(100)
        conn.close()
        server.close()
        return request, rest

    res, trace, (request, rest) = run_with_partner(BINARY / "vislib.src", settings, partner, interp=interp,
                                                   box=box, max_sim_time=30)
    assert res.reason == "completed", res.text
    assert len(request) == 80
    assert struct.unpack_from("<iii", request) == (0, 101, 3)
    assert request[12:] == bytes(68)
    assert rest == b""
    data = box["rt"].program.module("vislib").data
    got = {k: data[k].get() for k in ("RESCMD", "RESSTATUS", "RESCOUNT", "RESVALID", "RESTAG", "RESREAD")}
    assert got == {"RESCMD": 101, "RESSTATUS": 1102, "RESCOUNT": 1, "RESVALID": True, "RESTAG": "K",
                   "RESREAD": 1}
    assert data["RESX"].get() == 250.5 and data["RESY"].get() == -40.25
    out = net_events(trace, dir="out", name="VisionBin")
    assert [len(e["data"]) for e in out] == [80]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_records_with_an_end_string_with_and_without_a_length(interp):
    """``Type="STREAM" EOS="65,66"``: the manual's example sends "Stream ends with:AB" (the CHAR
    array up to its first NUL, then the end string); with EthernetKRL 3's LENGTH the record is that
    many bytes of the array, NULs included (two INTs by CAST_TO: 8 bytes), then "AB"; a received
    record is read without its end string."""
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    settings = NetworkSettings(BINARY, eki={"STREAM": Channel(BINARY / "Stream.xml", ("127.0.0.1", port))})
    box: dict = {}
    want = b"Stream ends with:AB" + struct.pack("<ii", 0, 7) + b"AB"

    def partner(net, rt):
        server.settimeout(60)
        conn, _ = server.accept()
        conn.settimeout(60)
        got = _recv_exactly(conn, len(want), time.monotonic() + 60)
        conn.sendall(b"OK,42AB")
        conn.settimeout(30)
        rest = conn.recv(100)
        conn.close()
        server.close()
        return got, rest

    res, _trace, (got, rest) = run_with_partner(BINARY / "streams.src", settings, partner, interp=interp, box=box,
                                                max_sim_time=30)
    assert res.reason == "completed", res.text
    assert (got, rest) == (want, b"")
    data = box["rt"].program.module("streams").data
    assert data["ANSWER"].get().text() == "OK,42" and data["READ"].get() == 1


RVS = HERE / "rvs"


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_client_library_of_a_vision_vendors_published_hex_interface(interp):
    """A client library written from Percipio RVS 2.0's published TCP standard interface in HEX
    (64-byte commands of little-endian INT32 fields, padded with 0; 101 runs a project; status
    1102 "Successfully triggered project", 1011 "Project number does not exist": the vendor's
    status-code list) against a vision system written from the same description: each record is
    64 bytes both ways. The vendor publishes no answer layout for HEX beyond the status code; the
    partner answers in the commands' layout (the command, then the status). No vision vendor's
    KRL with binary records is stored in the search tool's corpora (docs/network.md)."""
    server = socket.create_server(("127.0.0.1", 0))
    settings = NetworkSettings(RVS, eki={"RVSHEX": Channel(RVS / "RvsHex.xml", ("127.0.0.1", server.getsockname()[1]))})
    box: dict = {}

    def vision(net, rt):
        server.settimeout(60)
        conn, _ = server.accept()
        conn.settimeout(60)
        seen = []
        for _ in range(2):
            cmd = _recv_exactly(conn, 64, time.monotonic() + 60)
            code, project, points, pose_type = struct.unpack_from("<iiii", cmd)
            seen.append((len(cmd), code, project, points, pose_type, cmd[16:] == bytes(48)))
            status = 1102 if project == 1 else 1011
            conn.sendall(struct.pack("<ii", code, status).ljust(64, b"\0"))
        conn.settimeout(30)
        seen.append(conn.recv(100))         # the run's end closes the connection
        conn.close()
        server.close()
        return seen

    res, _trace, seen = run_with_partner(RVS / "rvs_client.src", settings, vision, interp=interp, box=box,
                                         max_sim_time=30)
    assert res.reason == "completed", res.text
    assert seen == [(64, 101, 1, 0, 0, True), (64, 101, 99, 0, 0, True), b""]
    data = box["rt"].program.module("rvs_client").data
    assert (data["FIRSTSTATUS"].get(), data["SECONDSTATUS"].get()) == (1102, 1011)
