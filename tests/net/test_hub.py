"""The network hub's clock (docs/network.md "One clock"): pacing to the wall clock, re-anchored
after a pause; the `network:` key's schema."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from net.hub import Pacer
from net.settings import SettingsError, parse_network


def test_the_pacer_never_runs_ahead_of_the_wall_clock():
    p = Pacer(0.012, pace=2.0)
    start = time.monotonic()
    for k in range(1, 26):
        p.wait(k)
    # 24 cycles of 12 ms at pace 2: at least 0.144 s of wall time (an upper bound would be timing)
    assert time.monotonic() - start >= 24 * 0.012 / 2.0 - 1e-3


def test_the_pacer_re_anchors_after_a_pause():
    p = Pacer(0.012)
    p.wait(1)
    p.t0 -= 2.0                      # as if the run had paused two seconds
    before = time.monotonic()
    p.wait(2)
    assert p.behind >= 1.5 and p.k0 == 2 and p.t0 >= before
    p.wait(3)                        # paced again from the new anchor: waits about one cycle
    assert time.monotonic() - before >= 0.012 - 1e-3


@pytest.mark.parametrize("doc, says", [
    ({"eki": {"X": {"config": "/etc/passwd"}}}, "relative to the cell file"),
    ({"eki": {"X": {"config": "../x.xml"}}}, "without '..'"),
    ({"eki": {"X": {"address": "127.0.0.1"}}}, "HOST:PORT"),
    ({"plc": {"opcua": "http://x:1"}}, "opc.tcp"),
    ({"pace": 50}, "pace"),
    ({"rsi": {}, "pace": 2}, "pace must be 1"),
    ({"telnet": 23}, "unknown key"),
    ({"eki": {f"C{i}": None for i in range(17)}}, "more than 16"),
])
def test_a_bad_network_key_is_refused(doc, says):
    with pytest.raises(SettingsError, match=says):
        parse_network(doc, Path("/cells"))


def test_addresses_default_to_loopback():
    s = parse_network({"eki": {"A": None, "B": {"address": "127.0.0.1:0"}}, "varproxy": 7000}, Path("/cells"))
    assert s.eki["A"].address is None and s.eki["B"].address == ("127.0.0.1", 0)
    assert s.varproxy == ("127.0.0.1", 7000)
