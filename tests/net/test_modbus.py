"""The PLC's Modbus TCP server to the letter (issue 61; net/modbus.py), probed as a hostile
neighbour and a faulty PLC would: raw frames for what a client library refuses to send, and
pymodbus's own client for the rest (neither written here). Expected answers are the *MODBUS
Application Protocol Specification V1.1b3*'s: an exception is the function code + 0x80 and its
code; 01 for a function the server does not serve, 03 for a quantity outside the function's
limits (coils 1..2000, registers 1..125, writes 1..1968 coils / 1..123 registers) or a byte count
that does not match it, 02 for addresses outside the map (64 coils and discrete inputs, 32
registers: net/plc.py's map of a cell without signals), 03 for a write-single-coil value other
than 0x0000/0xFF00; and of the *Modbus Messaging on TCP/IP Implementation Guide*: requests
pipelined in one TCP segment each answered, in order.

One run serves every case (a module fixture: the partner below talks to it while the program
waits; about 1 s of CPU); each test reads what the partner saw."""

from __future__ import annotations

import socket
import struct
import time

import pytest
from pymodbus.client import ModbusTcpClient

from krl.limits import MAX_PLC_CLIENTS
from net.modbus import SUPPORTED
from net.settings import NetworkSettings

from .helpers import PROGRAMS, net_events, run_with_partner

DIGITAL, ANALOG = 64, 32          # the map of a cell without signals (net/plc.py derive_map)


def request(tid: int, fc: int, body: bytes, unit: int = 1, pid: int = 0) -> bytes:
    pdu = bytes([fc]) + body
    return struct.pack(">HHHB", tid, pid, len(pdu) + 1, unit) + pdu


def answers(sock: socket.socket, n: int, timeout: float = 30.0) -> list[tuple[int, bytes]]:
    """`n` answers (transaction id, PDU) read from `sock`, framed by their MBAP length."""
    sock.settimeout(timeout)
    buf = b""
    out = []
    while len(out) < n:
        while len(buf) >= 6 and len(buf) >= 6 + struct.unpack_from(">H", buf, 4)[0]:
            tid, _pid, length = struct.unpack_from(">HHH", buf)
            out.append((tid, buf[7:6 + length]))
            buf = buf[6 + length:]
        if len(out) >= n:
            break
        data = sock.recv(65536)
        if not data:
            break
        buf += data
    return out


def silent(sock: socket.socket, wait: float = 0.5) -> bool:
    """True when nothing arrives on `sock` for `wait` seconds."""
    sock.settimeout(wait)
    try:
        return sock.recv(100) == b""
    except socket.timeout:
        return True


def read_coils(sock, tid, start, qty):
    sock.sendall(request(tid, 1, struct.pack(">HH", start, qty)))
    return answers(sock, 1)[0]


def partner(net, rt):
    addr = net.wait_address("modbus")
    seen: dict = {}
    s = socket.create_connection(addr, timeout=20)
    # three requests in one segment (pymodbus's server answered the first only)
    s.sendall(request(1, 1, struct.pack(">HH", 0, 8)) + request(2, 2, struct.pack(">HH", 0, 8))
              + request(3, 3, struct.pack(">HH", 0, 2)))
    seen["pipelined"] = answers(s, 3)
    # every function code the server does not serve, one segment
    codes = [fc for fc in range(1, 128) if fc not in SUPPORTED]
    s.sendall(b"".join(request(1000 + fc, fc, b"\x00\x00\x00\x01") for fc in codes))
    seen["unsupported"] = dict(zip(codes, answers(s, len(codes))))
    # quantities at and past each function's limit (the spec checks the quantity before the address)
    limits = {
        "coils 0": request(20, 1, struct.pack(">HH", 0, 0)),
        "coils 2000": request(21, 1, struct.pack(">HH", 0, 2000)),
        "coils 2001": request(22, 1, struct.pack(">HH", 0, 2001)),
        "inputs 2001": request(23, 2, struct.pack(">HH", 0, 2001)),
        "registers 125": request(24, 3, struct.pack(">HH", 0, 125)),
        "registers 126": request(25, 3, struct.pack(">HH", 0, 126)),
        "input registers 126": request(26, 4, struct.pack(">HH", 0, 126)),
        "write coils 1969": request(27, 15, struct.pack(">HHB", 0, 1969, 247) + bytes(247)),
        "write coils byte count": request(28, 15, struct.pack(">HHB", 0, 8, 2) + b"\xff\x00"),
        "write registers 124": request(29, 16, struct.pack(">HHB", 0, 124, 248) + bytes(248)),
        "read/write 122": request(30, 23, struct.pack(">HHHHB", 0, 1, 0, 122, 244) + bytes(244)),
        "short read": request(31, 1, b"\x00\x00\x00"),
        "coils past the map": request(32, 1, struct.pack(">HH", DIGITAL - 4, 8)),
        "register past the map": request(33, 6, struct.pack(">HH", ANALOG, 1)),
    }
    s.sendall(b"".join(limits.values()))
    seen["limits"] = dict(zip(limits, answers(s, len(limits))))
    # write single coil: 0xFF00 on, 0x1234 refused (pymodbus switched the coil on), 0x0000 off
    s.sendall(request(40, 5, struct.pack(">HH", 5, 0x1234)))
    seen["coil 0x1234"] = answers(s, 1)[0]
    seen["coil 5 after 0x1234"] = read_coils(s, 41, 5, 1)
    time.sleep(0.1)
    seen["$IN[6] after 0x1234"] = rt.controller.io.get_in(6)
    s.sendall(request(42, 5, struct.pack(">HH", 5, 0xFF00)))
    seen["coil 0xFF00"] = answers(s, 1)[0]
    # malformed frames: another protocol identifier, no function code: discarded unanswered
    s.sendall(request(50, 1, struct.pack(">HH", 0, 1), pid=7))
    seen["protocol 7"] = silent(s)
    s.sendall(struct.pack(">HHHB", 51, 0, 1, 1))
    seen["no function code"] = silent(s)
    seen["after malformed"] = read_coils(s, 52, 0, 1)
    # a flood pipelined in one go: every request answered, in order, none lost
    s.sendall(b"".join(request(t, 3, struct.pack(">HH", 0, 1)) for t in range(5000)))
    flood = answers(s, 5000, timeout=120)
    seen["flood"] = (len(flood), all(t == i for i, (t, _) in enumerate(flood)))
    s.close()
    # pymodbus's client
    client = ModbusTcpClient(addr[0], port=addr[1], timeout=20)
    client.connect()
    seen["client write"] = client.write_coil(9, True).isError()
    seen["client read"] = client.read_coils(8, count=4).bits[:4]
    r = client.read_coils(DIGITAL - 2, count=4)
    seen["client address"] = (r.isError(), r.exception_code, r.function_code)
    r = client.write_registers(0, [1] * 124)
    seen["client 124 registers"] = (r.isError(), r.exception_code, r.function_code)
    client.close()
    # the connection limit, counted at accept: 12 at once, the first 8 served
    socks = [socket.create_connection(addr, timeout=20) for _ in range(MAX_PLC_CLIENTS + 4)]
    time.sleep(0.5)
    served = [i for i, c in enumerate(socks) if not closed_unanswered_quick(c)]
    seen["served"] = served
    for c in socks:
        c.close()
    seen["after the limit"] = read_when_served(addr, 60)
    return seen


def read_when_served(addr, tid: int, timeout: float = 30.0):
    """A read of coil 0 on a new connection: (tid, PDU) once the server serves one. The server
    counts a closed connection out once it has seen the close; until then a new one past the
    limit is refused, so it is tried again for a bounded time (None when never served)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        c = socket.create_connection(addr, timeout=20)
        try:
            return read_coils(c, tid, 0, 1)
        except (OSError, IndexError):
            pass
        finally:
            c.close()
    return None


def closed_unanswered_quick(sock: socket.socket) -> bool:
    """True when a connection is closed by the server without an answer to one read."""
    try:
        sock.sendall(request(98, 1, struct.pack(">HH", 0, 1)))
        sock.settimeout(20)
        return sock.recv(100) == b""
    except (ConnectionResetError, BrokenPipeError):
        return True


@pytest.fixture(scope="module")
def modbus_run():
    settings = NetworkSettings(PROGRAMS, modbus=("127.0.0.1", 0))
    result, trace, seen = run_with_partner(PROGRAMS / "plc_watch.src", settings, partner, max_sim_time=600.0)
    assert result.reason == "max_sim_time", (result.reason, result.text)      # never an error, never a hang
    return seen, trace


def test_requests_pipelined_in_one_segment_are_each_answered_in_order(modbus_run):
    seen, _ = modbus_run
    assert [(t, pdu[0]) for t, pdu in seen["pipelined"]] == [(1, 1), (2, 2), (3, 3)]
    assert seen["flood"] == (5000, True)


def test_unsupported_function_codes_are_illegal_function(modbus_run):
    seen, _ = modbus_run
    got = seen["unsupported"]
    assert len(got) == 117
    assert all(t == 1000 + fc and pdu == bytes([fc | 0x80, 0x01]) for fc, (t, pdu) in got.items()), \
        {fc: pdu.hex() for fc, (t, pdu) in got.items() if pdu != bytes([fc | 0x80, 0x01])}


@pytest.mark.parametrize("case, answer", [
    ("coils 0", "8103"), ("coils 2000", "8102"), ("coils 2001", "8103"), ("inputs 2001", "8203"),
    ("registers 125", "8302"), ("registers 126", "8303"), ("input registers 126", "8403"),
    ("write coils 1969", "8f03"), ("write coils byte count", "8f03"), ("write registers 124", "9003"),
    ("read/write 122", "9703"), ("short read", "8103"), ("coils past the map", "8102"),
    ("register past the map", "8602"),
])
def test_quantities_lengths_and_addresses(modbus_run, case, answer):
    seen, _ = modbus_run
    assert seen["limits"][case][1].hex() == answer


def test_write_single_coil_takes_only_0000_and_ff00(modbus_run):
    seen, _ = modbus_run
    assert seen["coil 0x1234"][1].hex() == "8503"
    assert seen["coil 5 after 0x1234"][1].hex() == "010100"          # the coil is still off
    assert seen["$IN[6] after 0x1234"] is False                       # and so is the robot's input
    assert seen["coil 0xFF00"][1].hex() == "050005ff00"               # the echo


def test_malformed_frames_are_discarded_and_the_connection_goes_on(modbus_run):
    seen, trace = modbus_run
    assert seen["protocol 7"] and seen["no function code"]
    assert seen["after malformed"][0] == 52
    notes = [e["text"] for e in net_events(trace, iface="plc", dir="error")]
    assert any("protocol 7" in t for t in notes) and any("0 PDU bytes" in t for t in notes)


def test_pymodbus_client_reads_writes_and_decodes_the_exceptions(modbus_run):
    seen, _ = modbus_run
    assert seen["client write"] is False and seen["client read"] == [False, True, False, False]
    assert seen["client address"] == (True, 2, 0x81)
    assert seen["client 124 registers"] == (True, 3, 0x90)


def test_connection_limit_counted_at_accept(modbus_run):
    seen, trace = modbus_run
    assert seen["served"] == list(range(MAX_PLC_CLIENTS))
    assert seen["after the limit"] is not None and seen["after the limit"][0] == 60
    refused = net_events(trace, iface="plc", dir="refused")
    assert len(refused) >= 4 and "closed at accept" in refused[0]["text"]
