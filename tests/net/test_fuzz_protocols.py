"""The longer fuzz of each protocol (issue 61; `make nightly`, marked slow): Modbus TCP (every
function code, quantities at, past and far past their limits, random bodies and malformed
frames), OPC UA (every writable node with every kind of value: each variant type, arrays, NaN,
infinities, huge strings), RSI (random datagrams, malformed answers, answers from other
ports, duplicates, stale and unknown IPOCs) and KukaVarProxy (random frames, names, values and
rates). Each run must end without an error or a traceback (stderr is read), every request must
get its protocol's answer or a clean close, and the process's memory must stay bounded
(ru_maxrss grows by less than 300 MB over each run). The draws are seeded: a failure is a case
to rebuild in the quick tests."""

from __future__ import annotations

import asyncio
import math
import random
import resource
import socket
import struct
import time
import xml.etree.ElementTree as ET

import pytest
from asyncua import Client, ua

from net import rsi as rsi_module
from net.modbus import SUPPORTED
from net.settings import Channel, NetworkSettings

from .helpers import EXAMPLES, PROGRAMS, run_with_partner
from .test_modbus import answers, read_when_served, request
from .test_rsi_sources import sensor_sockets

pytestmark = pytest.mark.slow

MAX_GROWTH_KB = 300 * 1024


def _rss_kb() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


def _clean(result, err: str) -> None:
    """The run ended as a controller's would (an RSI run may stop at its late packets: the
    controller's reaction), with nothing on stderr that is a traceback."""
    assert result.reason not in ("error", "internal") or "late packets" in (result.text or ""), \
        (result.reason, result.text)
    assert "Traceback" not in err and "internal error" not in err, err[-3000:]


def test_modbus_fuzz(capfd):
    rng = random.Random(61)
    before = _rss_kb()

    def partner(net, rt):
        addr = net.wait_address("modbus")
        answered = 0
        for round_ in range(40):
            s = socket.create_connection(addr, timeout=30)
            frames = []
            for _ in range(200):
                fc = rng.randrange(256)
                kind = rng.random()
                if kind < 0.5:
                    body = struct.pack(">HH", rng.choice([0, 1, 31, 63, 64, 65535]),
                                       rng.choice([0, 1, 8, 123, 125, 126, 1968, 2000, 2001, 65535]))
                elif kind < 0.8:
                    body = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 260)))
                else:
                    q = rng.choice([1, 8, 123, 124, 1968, 1969])
                    n = rng.choice([(q + 7) // 8, 2 * q, 0, 255]) & 0xFF
                    body = struct.pack(">HHB", 0, q, n) + bytes(n)
                frames.append(request(round_ * 1000 + len(frames), fc, body))
            s.sendall(b"".join(frames))
            got = answers(s, len(frames), timeout=60)
            assert len(got) == len(frames), (round_, len(got))
            for (tid, pdu), frame in zip(got, frames):
                fc = frame[7]
                assert tid == struct.unpack(">H", frame[:2])[0]
                assert pdu[0] in (fc, fc | 0x80), (fc, pdu.hex())
                if pdu[0] & 0x80:
                    assert len(pdu) == 2 and pdu[1] in (1, 2, 3, 4), pdu.hex()
                    assert fc in SUPPORTED or pdu[1] == 1
            answered += len(got)
            s.close()
        # malformed framing: random bytes, then a valid request on a new connection is answered
        for _ in range(20):
            s = socket.create_connection(addr, timeout=30)
            s.sendall(bytes(rng.randrange(256) for _ in range(rng.randrange(1, 2000))))
            s.close()
        served = read_when_served(addr, 1)
        assert served is not None and served[1][0] == 1
        return answered

    settings = NetworkSettings(PROGRAMS, modbus=("127.0.0.1", 0))
    result, trace, answered = run_with_partner(PROGRAMS / "plc_watch.src", settings, partner, max_sim_time=3600.0,
                                               wall_timeout=600)
    assert answered == 40 * 200
    _clean(result, capfd.readouterr().err)
    assert _rss_kb() - before < MAX_GROWTH_KB


def test_opcua_fuzz(capfd):
    rng = random.Random(62)
    before = _rss_kb()
    values = [ua.Variant(True, ua.VariantType.Boolean), ua.Variant(0.5, ua.VariantType.Double),
              ua.Variant(math.nan, ua.VariantType.Double), ua.Variant(math.inf, ua.VariantType.Double),
              ua.Variant(-1e308, ua.VariantType.Double), ua.Variant(7, ua.VariantType.Int32),
              ua.Variant("x" * 50_000, ua.VariantType.String), ua.Variant(b"\x00" * 1000, ua.VariantType.ByteString),
              ua.Variant([1.0] * 500, ua.VariantType.Double), ua.Variant([True, False], ua.VariantType.Boolean),
              ua.Variant(None, ua.VariantType.Null), ua.Variant(2 ** 31 - 1, ua.VariantType.Int32)]
    good = {"Good", "BadTypeMismatch", "BadOutOfRange", "BadNotWritable", "BadUserAccessDenied", "BadWriteNotSupported"}

    async def writes(url, rt):
        seen = set()
        async with Client(url) as client:
            ns = await client.get_namespace_index("urn:krl-tools:plc")
            nodes = []
            for group, name in [("Inputs", "IN[1]"), ("Inputs", "IN[64]"), ("AnalogInputs", "ANIN[1]"),
                                ("AnalogInputs", "ANIN[32]"), ("Outputs", "OUT[1]"), ("AnalogOutputs", "ANOUT[2]")]:
                nodes.append(await client.nodes.objects.get_child([f"{ns}:Robot", f"{ns}:{group}", f"{ns}:{name}"]))
            for _ in range(400):
                node = rng.choice(nodes)
                try:
                    await node.write_value(ua.DataValue(rng.choice(values)))
                    seen.add("Good")
                except ua.UaStatusCodeError as exc:
                    seen.add(type(exc).__name__)
            assert all(-1.0 <= rt.controller.io.get_anin(n) <= 1.0 for n in range(1, 33))
        return seen

    def partner(net, rt):
        _, port = net.wait_address("opcua")
        return asyncio.run(writes(f"opc.tcp://127.0.0.1:{port}", rt))

    settings = NetworkSettings(PROGRAMS, opcua="opc.tcp://127.0.0.1:0")
    result, trace, seen = run_with_partner(PROGRAMS / "plc_watch.src", settings, partner, max_sim_time=3600.0,
                                           wall_timeout=600)
    assert seen <= good and {"Good", "BadTypeMismatch", "BadOutOfRange"} <= seen, seen
    _clean(result, capfd.readouterr().err)
    assert _rss_kb() - before < MAX_GROWTH_KB


def test_rsi_fuzz(capfd, monkeypatch):
    rng = random.Random(63)
    monkeypatch.setattr(rsi_module, "ANSWER_WAIT_S", 0.1)     # a packet the fuzz leaves unanswered is late sooner
    before = _rss_kb()
    sock, rogue = sensor_sockets()

    def partner(net, rt):
        sock.settimeout(0.5)
        last = []
        end = time.monotonic() + 120
        n = 0
        while time.monotonic() < end and not net.closed and n < 1500:
            try:
                data, peer = sock.recvfrom(65536)
            except TimeoutError:
                continue
            n += 1
            ipoc = ET.fromstring(data).find("IPOC").text
            last = (last + [ipoc])[-5:]
            r = rng.random()
            if r < 0.5:
                body = f'<Sen Type="ImFree"><RKorr X="0" Y="0" Z="{rng.uniform(-1, 1):.3f}" A="0" B="0" C="0"/><Stop>0</Stop><IPOC>{ipoc}</IPOC></Sen>'
                sock.sendto(body.encode(), peer)
            elif r < 0.6:
                sock.sendto(bytes(rng.randrange(256) for _ in range(rng.randrange(1, 9000))), peer)
            elif r < 0.7:
                sock.sendto(f"<Sen><IPOC>{rng.choice(last)}</IPOC></Sen>".encode() * rng.randrange(1, 3), peer)
            elif r < 0.8:
                rogue.sendto(f"<Sen><IPOC>{ipoc}</IPOC></Sen>".encode(), peer)
                sock.sendto(f'<Sen><RKorr Z="nan"/><IPOC>{ipoc}</IPOC></Sen>'.encode(), peer)
            elif r < 0.9:
                sock.sendto(f"<Sen><IPOC>{'9' * rng.randrange(1, 4000)}</IPOC></Sen>".encode(), peer)
            else:
                sock.sendto(b"<Sen>" + b"<a>" * 100 + b"</Sen>", peer)
        return n

    settings = NetworkSettings(PROGRAMS, rsi=Channel(EXAMPLES / "rsi_path.rsi.xml", sock.getsockname()))
    result, trace, n = run_with_partner(PROGRAMS / "rsi_relative.src", settings, partner, max_sim_time=3600.0,
                                        wall_timeout=600)
    sock.close()
    rogue.close()
    assert n > 100
    texts = [e.get("text", "") for e in trace.events if e["kind"] == "net"]
    assert max(len(t) for t in texts) <= 200
    _clean(result, capfd.readouterr().err)
    assert _rss_kb() - before < MAX_GROWTH_KB


def test_varproxy_fuzz(capfd):
    rng = random.Random(64)
    before = _rss_kb()
    names = [b"$OV_PRO", b"$POS_ACT", b"SPEED", b"COUNTS[2]", b"PLACE.X", b"$MOVE_ENABLE", b"NOPE", b"$IN[1]",
             b"COUNTS[99]", b"$OUT[0]", b"x" * 300, b"\xff\xfe"]
    values = [b"1", b"-5", b"1000", b"1e999", b"TRUE", b"{X 1}", b'"text"', b"#PRESSED", b"", b"{" * 50, b"9" * 5000]

    def frame() -> bytes:
        r = rng.random()
        name = rng.choice(names)
        if r < 0.45:
            body = struct.pack("!BH", 0, len(name)) + name
        elif r < 0.9:
            v = rng.choice(values)
            body = struct.pack("!BH", 1, len(name)) + name + struct.pack("!H", len(v)) + v
        else:
            body = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 100)))
        return struct.pack("!HH", rng.randrange(65536), len(body) & 0xFFFF) + body

    def partner(net, rt):
        addr = net.wait_address("varproxy")
        closed = served = 0
        for _ in range(60):
            s = socket.create_connection(addr, timeout=30)
            s.sendall(b"".join(frame() for _ in range(rng.randrange(1, 200))))
            s.settimeout(1)
            try:
                while s.recv(65536):
                    served += 1
            except socket.timeout:
                pass
            except ConnectionResetError:
                closed += 1
            s.close()
        return served, closed

    settings = NetworkSettings(PROGRAMS, varproxy=("127.0.0.1", 0), pace=10)
    result, trace, (served, closed) = run_with_partner(PROGRAMS / "varproxy_rules.src", settings, partner,
                                                       max_sim_time=3600.0, wall_timeout=900)
    assert served > 0
    _clean(result, capfd.readouterr().err)
    assert _rss_kb() - before < MAX_GROWTH_KB
