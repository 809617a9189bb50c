"""KukaVarProxy over the OpenShowVar protocol, tested with py-openshowvar from PyPI, an
independent client (issue 35, done-when 1): it reads $POS_ACT and $OV_PRO, writes a global
that the program waits on, and an output, logged as the partner's write (source ``varproxy``,
issue 89: it was logged as the program's)."""

from __future__ import annotations

import re
import socket
import struct
import time

import pytest
from py_openshowvar import openshowvar

from krl.limits import MAX_VARPROXY_CLIENTS
from net.settings import NetworkSettings

from .helpers import EXAMPLES, run_with_partner

PROGRAM = EXAMPLES / "wait_global.src"


def read_until(client, name: str, want: bytes, deadline: float) -> bytes:
    while time.monotonic() < deadline:
        v = client.read(name, debug=False)
        if v == want:
            return v
        time.sleep(0.05)
    raise TimeoutError(f"{name} never became {want!r}")


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_py_openshowvar_reads_and_writes(interp):
    settings = NetworkSettings(EXAMPLES, varproxy=("127.0.0.1", 0))

    def partner(net, rt):
        host, port = net.wait_address("varproxy")
        client = openshowvar(host, port)
        deadline = time.monotonic() + 60
        read_until(client, "READY", b"TRUE", deadline)
        ov = client.read("$OV_PRO", debug=False)
        pos = client.read("$POS_ACT", debug=False)
        axis = client.read("$AXIS_ACT", debug=False)
        unknown = client.read("NO_SUCH_VARIABLE", debug=False)
        out = client.write("$OUT[7]", "TRUE", debug=False)
        written = client.write("GO_ON", "TRUE", debug=False)
        done = read_until(client, "DONE", b"1", deadline)
        client.close()
        return ov, pos, axis, unknown, out, written, done

    result, trace, got = run_with_partner(PROGRAM, settings, partner, interp=interp)
    ov, pos, axis, unknown, out, written, done = got
    assert ov == b"75"
    text = pos.decode()
    assert text.startswith("{E6POS: ") or text.startswith("{POS: ")
    comps = dict(re.findall(r"([A-Z]\w*) (-?[0-9.]+)", text))
    # the pose the robot stands at: the trace's last pose before the write
    writes = [e for e in trace.events if e["kind"] == "net" and e["dir"] == "in" and e["data"].startswith("write")]
    before = [e for e in trace.events if e["kind"] == "pose" and e["t"] <= writes[0]["t"]][-1]
    assert [float(comps[k]) for k in "XYZABC"] == pytest.approx(before["tcp"], abs=1e-4)
    ax = dict(re.findall(r"(A\d) (-?[0-9.]+)", axis.decode()))
    assert [float(ax[f"A{i}"]) for i in range(1, 7)] == pytest.approx([10, -80, 85, 0, 30, 0], abs=1e-6)
    assert unknown is None                        # the answer says "not ok"
    assert written == b"TRUE"
    assert done == b"1"
    # the client's $OUT write is the partner's, not the program's (which never writes $OUT[7])
    assert out == b"TRUE"
    assert [(e["value"], e.get("source")) for e in trace.events
            if e["kind"] == "io" and e["signal"] == "$OUT[7]"] == [(True, "varproxy")]
    # the program went on from the WAIT FOR because of the write: its second motion starts after it
    starts = [e["t"] for e in trace.events if e["kind"] == "motion" and e["phase"] == "start"]
    assert starts[-1] >= writes[0]["t"]


def test_bad_requests_close_only_that_client():
    settings = NetworkSettings(EXAMPLES, varproxy=("127.0.0.1", 0))

    def partner(net, rt):
        addr = net.wait_address("varproxy")
        bad = socket.create_connection(addr, timeout=10)
        bad.sendall(struct.pack("!HHBH", 1, 60000, 0, 5) + b"x" * 50)    # a length past the limit
        bad.settimeout(10)
        closed = bad.recv(100) == b""
        good = openshowvar(*addr)
        v = good.read("$OV_PRO", debug=False)
        good.close()
        return closed, v

    result, trace, (closed, v) = run_with_partner(PROGRAM, settings, partner)
    assert closed and v in (b"100", b"75")


def test_client_count_limit():
    """krl.limits.MAX_VARPROXY_CLIENTS clients at once: each is answered; one more is closed
    at once (a 'refused' net event) while the others go on; when one leaves, a new client is
    accepted again."""
    settings = NetworkSettings(EXAMPLES, varproxy=("127.0.0.1", 0))

    def partner(net, rt):
        addr = net.wait_address("varproxy")
        clients = [openshowvar(*addr) for _ in range(MAX_VARPROXY_CLIENTS)]
        # a read answers only once the server took the client: all of them are in
        first = [c.read("$OV_PRO", debug=False) for c in clients]
        extra = socket.create_connection(addr, timeout=20)
        extra.settimeout(20)
        try:
            extra_closed = extra.recv(100) == b""          # closed by the server, unanswered
        except ConnectionResetError:
            extra_closed = True
        extra.close()
        still = [c.read("$OV_PRO", debug=False) for c in clients]
        clients.pop().close()
        # the freed place: a new client is answered (the server sees the close first, in the
        # same or an earlier cycle than the new connection; retried until a bounded deadline)
        deadline = time.monotonic() + 20
        again = None
        while again is None and time.monotonic() < deadline:
            late = openshowvar(*addr)
            late.sock.settimeout(20)
            try:
                again = late.read("$OV_PRO", debug=False)
            except (ConnectionError, OSError, struct.error):   # closed unanswered: still full
                again = None
            late.close()
        for c in clients:
            c.close()
        return first, extra_closed, still, again

    result, trace, (first, extra_closed, still, again) = run_with_partner(PROGRAM, settings, partner)
    ov = (b"100", b"75")
    assert len(first) == MAX_VARPROXY_CLIENTS and all(v in ov for v in first)
    assert extra_closed
    assert all(v in ov for v in still)
    assert again in ov
    refused = [e for e in trace.events if e["kind"] == "net" and e["iface"] == "varproxy" and e["dir"] == "refused"]
    assert refused and f"more than {MAX_VARPROXY_CLIENTS} clients" in refused[0]["text"]
