"""The PLC's OPC UA server against a faulty client (issue 61): asyncua's own client (not written
here) writes every kind of wrong value into the writable nodes. Expected (OPC UA Part 4, the
Write service's operation results, and the controller's write rules, interp/runtime/writerules.py):
a value of another type or shape is Bad_TypeMismatch (an array of 1,000 Doubles into the scalar
``ANIN[2]`` stopped the run with "internal error: TypeError ... 'list'"), NaN, an infinity or a
value outside ``$ANIN``'s -1.0..1.0 Bad_OutOfRange (NaN was taken and read full scale); nothing
refused reaches the robot's inputs, a good value does; the run goes on; no line on stderr and no
event text carries the client's value whole (a refused write of 100,000 characters put a
100,158-character line on stderr). One run serves every case (module fixture)."""

from __future__ import annotations

import asyncio
import io
import logging
import math
import time

import pytest
from asyncua import Client, ua

from krl.limits import MAX_NET_LOG_CHARS
from net import netlog
from net.settings import NetworkSettings

from .helpers import PROGRAMS, run_with_partner

NS = "urn:krl-tools:plc"


async def _writes(url: str, rt) -> dict:
    seen: dict = {}
    async with Client(url) as client:
        ns = await client.get_namespace_index(NS)
        objects = client.nodes.objects

        async def node(group: str, name: str):
            return await objects.get_child([f"{ns}:Robot", f"{ns}:{group}", f"{ns}:{name}"])

        anin = await node("AnalogInputs", "ANIN[2]")
        inp = await node("Inputs", "IN[3]")

        async def status(n, variant: ua.Variant) -> str:
            try:
                await n.write_value(ua.DataValue(variant))
            except ua.UaStatusCodeError as exc:
                return type(exc).__name__
            return "Good"

        seen["nan"] = await status(anin, ua.Variant(math.nan, ua.VariantType.Double))
        seen["inf"] = await status(anin, ua.Variant(-math.inf, ua.VariantType.Double))
        seen["2.0"] = await status(anin, ua.Variant(2.0, ua.VariantType.Double))
        seen["array"] = await status(anin, ua.Variant([0.25] * 1000, ua.VariantType.Double))
        seen["int into Double"] = await status(anin, ua.Variant(1, ua.VariantType.Int32))
        seen["huge string into Boolean"] = await status(inp, ua.Variant("x" * 100_000, ua.VariantType.String))
        seen["bool array"] = await status(inp, ua.Variant([True] * 50, ua.VariantType.Boolean))
        seen["after refusals: ANIN[2]"] = rt.controller.io.get_anin(2)
        seen["good"] = await status(anin, ua.Variant(0.5, ua.VariantType.Double))
        seen["good bool"] = await status(inp, ua.Variant(True, ua.VariantType.Boolean))
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and (rt.controller.io.get_anin(2) != pytest.approx(0.5)
                                               or not rt.controller.io.get_in(3)):
            await asyncio.sleep(0.02)
        seen["ANIN[2]"] = rt.controller.io.get_anin(2)
        seen["IN[3]"] = rt.controller.io.get_in(3)
        out = await node("Outputs", "OUT[1]")
        seen["output"] = await status(out, ua.Variant(True, ua.VariantType.Boolean))
    return seen


@pytest.fixture(scope="module")
def opcua_run():
    settings = NetworkSettings(PROGRAMS, opcua="opc.tcp://127.0.0.1:0")
    stderr = io.StringIO()

    def partner(net, rt):
        _, port = net.wait_address("opcua")
        # the clipping handler net/netlog.py put on asyncua's logger writes here for this run
        netlog.redirect(stderr)
        return asyncio.run(_writes(f"opc.tcp://127.0.0.1:{port}", rt))

    try:
        result, trace, seen = run_with_partner(PROGRAMS / "plc_watch.src", settings, partner, max_sim_time=600.0)
    finally:
        netlog.redirect(None)
    return result, trace, seen, stderr.getvalue()


@pytest.mark.parametrize("case, expected", [
    ("nan", "BadOutOfRange"), ("inf", "BadOutOfRange"), ("2.0", "BadOutOfRange"),
    ("array", "BadTypeMismatch"), ("int into Double", "BadTypeMismatch"),
    ("huge string into Boolean", "BadTypeMismatch"), ("bool array", "BadTypeMismatch"),
    ("good", "Good"), ("good bool", "Good"),
])
def test_each_write_gets_the_status_the_rules_give(opcua_run, case, expected):
    _result, _trace, seen, _ = opcua_run
    assert seen[case] == expected


def test_refused_values_never_reach_the_inputs_and_the_run_goes_on(opcua_run):
    result, trace, seen, _ = opcua_run
    assert result.reason == "max_sim_time", (result.reason, result.text)
    assert seen["after refusals: ANIN[2]"] == 0.0
    assert seen["ANIN[2]"] == pytest.approx(0.5) and seen["IN[3]"] is True
    assert seen["output"] != "Good"                    # an output is the robot's, not the PLC's
    refused = [e["text"] for e in trace.events if e["kind"] == "net" and e["dir"] == "error"]
    assert sum("OPC UA write refused" in t for t in refused) == 7
    assert any("$ANIN[2] = nan is not a finite number" in t for t in refused)
    assert any("$ANIN[2] = 2.0 out of limits [-1.0; 1.0]" in t for t in refused)


def test_nothing_of_the_client_is_logged_whole(opcua_run):
    _result, trace, _seen, stderr = opcua_run
    texts = [e.get("text", "") for e in trace.events if e["kind"] in ("net", "message", "error")]
    assert texts and max(len(str(t)) for t in texts) <= MAX_NET_LOG_CHARS
    assert all(len(line) <= MAX_NET_LOG_CHARS + 40 for line in stderr.splitlines())
    # asyncua's own record of a refused write (it logs the variant whole) goes through the clip
    logging.getLogger("asyncua.server.address_space").warning("Write refused: Variant: %s", "y" * 100_000)
    handler = netlog._installed["asyncua"]
    line = handler.format(logging.LogRecord("asyncua.server.address_space", logging.WARNING, __file__, 1,
                                            "Write refused: Variant: %s", ("y" * 100_000,), None))
    assert len(line) <= MAX_NET_LOG_CHARS + 40 and line.endswith("…")
