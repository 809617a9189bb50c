"""KukaVarProxy writes go through the controller's write rules (issue 61,
interp/runtime/writerules.py), tested with py-openshowvar, a client not written here, on both
interpreters: a value outside its documented range ($OV_PRO 1000 and -5 were taken, and A1 then
moved at 123 % of its maximum speed), a signal of the safety controller ($MOVE_ENABLE,
$DRIVES_ON, $USER_SAF were set; $ALARM_STOP, $SAFETY_SW refused), a value of the wrong shape,
a REAL that is no finite number: each answered "not ok", with an error event naming the KSS
message, and the variable keeps its value. And back-pressure as docs/security.md promises: 5,000
reads sent back to back are all answered, 16 per client and IPO cycle, none dropped (16 were
answered, then the connection closed without an error event)."""

from __future__ import annotations

import socket
import struct

import pytest
from py_openshowvar import openshowvar

from krl.limits import MAX_VARPROXY_REQUESTS_PER_CYCLE
from net.settings import NetworkSettings

from .helpers import PROGRAMS, net_events, run_with_partner

PROGRAM = PROGRAMS / "varproxy_rules.src"

WRITES = [
    # (name, value written, answered ok, the value read afterwards)
    ("$OV_PRO", "1000", False, b"40"),
    ("$OV_PRO", "-5", False, b"40"),
    ("$OV_PRO", "{E6POS: X 1}", False, b"40"),
    ("$OV_PRO", "55", True, b"55"),
    ("$MOVE_ENABLE", "FALSE", False, b"TRUE"),
    ("$DRIVES_ON", "TRUE", False, b"FALSE"),
    ("$USER_SAF", "FALSE", False, b"TRUE"),
    ("$ALARM_STOP", "FALSE", False, b"TRUE"),
    ("$SAFETY_SW", "#PRESSED", False, b"#RELEASED"),
    ("$POS_ACT", "{X 1}", False, None),
    ("SPEED", "1e999", False, b"0.5"),
    ("SPEED", "0.25", True, b"0.25"),
    ("COUNTS", "5", False, None),
    ("COUNTS[2]", "7", True, b"7"),
    ("PLACE", "3", False, None),
    ("PLACE.X", "5", True, b"5"),
]


def partner(net, rt):
    addr = net.wait_address("varproxy")
    client = openshowvar(*addr)
    got = []
    for name, value, _ok, _after in WRITES:
        written = client.write(name, value, debug=False)
        got.append((written, client.read(name, debug=False)))
    client.close()
    return got


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_writes_go_through_the_rules(interp):
    settings = NetworkSettings(PROGRAMS, varproxy=("127.0.0.1", 0), pace=10)
    result, trace, got = run_with_partner(PROGRAM, settings, partner, interp=interp)
    assert result.reason == "max_sim_time", (result.reason, result.text)
    for (name, value, ok, after), (written, read) in zip(WRITES, got):
        assert (written is not None) == ok, (name, value, written)
        if after is not None:
            assert read == after, (name, value, read)
    errors = [e["text"] for e in net_events(trace, iface="varproxy", dir="error")]
    assert any("$OV_PRO = 1000 out of limits [0; 100]" in t for t in errors), errors
    assert any("$MOVE_ENABLE is write-protected (a signal of the safety controller)" in t for t in errors)
    assert any("SPEED = inf is not a finite number" in t for t in errors)
    assert sum("write-protected" in t for t in errors) == 6


def request(msg_id: int, name: bytes) -> bytes:
    body = struct.pack("!BH", 0, len(name)) + name
    return struct.pack("!HH", msg_id, len(body)) + body


def test_back_to_back_reads_all_answered():
    """5,000 reads in one send: every one answered, in order, at most 16 per IPO cycle."""
    settings = NetworkSettings(PROGRAMS, varproxy=("127.0.0.1", 0), pace=10)
    n = 5000

    def flood(net, rt):
        s = socket.create_connection(net.wait_address("varproxy"), timeout=60)
        s.sendall(b"".join(request(i, b"$OV_PRO") for i in range(n)))
        buf = b""
        ids = []
        while len(ids) < n:
            data = s.recv(65536)
            if not data:
                break
            buf += data
            while len(buf) >= 4 and len(buf) >= 4 + struct.unpack_from("!H", buf, 2)[0]:
                msg_id, length = struct.unpack_from("!HH", buf)
                ids.append(msg_id)
                buf = buf[4 + length:]
        s.close()
        return ids

    result, trace, ids = run_with_partner(PROGRAM, settings, flood)
    assert ids == list(range(n))
    ins = [e for e in net_events(trace, iface="varproxy", dir="in")]
    per_cycle: dict = {}
    for e in ins:
        per_cycle[e["t"]] = per_cycle.get(e["t"], 0) + 1
    assert max(per_cycle.values()) == MAX_VARPROXY_REQUESTS_PER_CYCLE
    assert not net_events(trace, iface="varproxy", dir="error")
