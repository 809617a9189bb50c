"""The PLC side: the controller's I/O image and the Automatic External handshake as a Modbus
TCP server (pymodbus) and an OPC UA server (asyncua) (docs/network.md "The PLC side").

The address map (:class:`AddressMap`, derived from the cell by :func:`cell_map`): the
robot's inputs are what the PLC writes, its outputs what the PLC reads.

=====================  ==================  =======================================
robot                  Modbus TCP          OPC UA (namespace ``urn:krl-tools:plc``)
=====================  ==================  =======================================
``$IN[n]``             coil n-1 (rw)       ``Robot/Inputs/IN[n]`` Boolean (rw)
``$OUT[n]``            discrete input n-1  ``Robot/Outputs/OUT[n]`` Boolean (ro)
``$ANIN[n]``           holding reg. n-1    ``Robot/AnalogInputs/ANIN[n]`` Double (rw)
``$ANOUT[n]``          input reg. n-1      ``Robot/AnalogOutputs/ANOUT[n]`` Double (ro)
a SIGNAL of the cell   (its bits above)    ``Robot/Signals/NAME`` (rw on inputs)
=====================  ==================  =======================================

Modbus registers carry an analog value as a signed 16-bit integer, value x 32767 (-1.0 ..
+1.0). The map covers inputs and outputs 1..N, N the highest signal the cell file and the
program-number handshake name (its ``PGNO_*`` parameters, the SIGNALs of the rules), rounded
up to 64 (at least 64, at most 8192); analog 1..32. A PLC program or a plain client script
drives P00's handshake through these bits (``PGNO_FBIT``.., ``PGNO_PARITY``, ``PGNO_VALID``
in, ``PGNO_REQ`` out) as ``--pgno`` does (robot/cellpresets.py), and EXT start on its input.

The servers run in one thread with their own asyncio loop; once per IPO cycle
(:meth:`Plc.sync`, called by the hub) the loop copies, as one step between two requests, what
the PLC wrote since the last cycle into the inputs (traced as ``net`` events: a replay applies
them again) and the controller's outputs into the PLC's view. At most
:data:`~krl.limits.MAX_PLC_CLIENTS` clients per server; servers bind loopback unless the
cell file names another address.
"""

from __future__ import annotations

import functools
import threading
from dataclasses import dataclass, field
import logging
from pathlib import Path

from krl.ast import nodes as N
from krl.limits import MAX_PLC_CLIENTS

from .cellkey import SettingsError, inside, mapping, parse_address
from .netlog import clip, clip_library_logs
from .partner import Partner

PLC_KEYS = ("modbus", "opcua", "map")

N_ANALOG = 32
SCALE = 32767
#: OPC UA writes refused within one IPO cycle that get an event each (a flood gets these)
MAX_REFUSALS_TRACED = 64


@dataclass
class AddressMap:
    """Inputs/outputs 1..`digital`, analog 1..`analog`; `signals`: NAME -> ("$IN"/"$OUT", first, last)."""

    digital: int = 64
    analog: int = N_ANALOG
    signals: dict[str, tuple[str, int, int]] = field(default_factory=dict)

    def rows(self) -> list[tuple[str, str, str]]:
        """(robot, Modbus, OPC UA) rows of the map, for docs and `krl run`'s message."""
        out = [(f"$IN[1..{self.digital}]", f"coils 0..{self.digital - 1}", "Robot/Inputs/IN[n]"),
               (f"$OUT[1..{self.digital}]", f"discrete inputs 0..{self.digital - 1}", "Robot/Outputs/OUT[n]"),
               (f"$ANIN[1..{self.analog}]", f"holding registers 0..{self.analog - 1}", "Robot/AnalogInputs/ANIN[n]"),
               (f"$ANOUT[1..{self.analog}]", f"input registers 0..{self.analog - 1}", "Robot/AnalogOutputs/ANOUT[n]")]
        for name, (base, a, b) in sorted(self.signals.items()):
            out.append((f"{name} = {base}[{a}]" + (f"..[{b}]" if b != a else ""),
                        f"{'coil' if base == '$IN' else 'discrete input'} {a - 1}" + (f"..{b - 1}" if b != a else ""),
                        f"Robot/Signals/{name}"))
        return out


def derive_map(indices: list[int], signals: dict[str, tuple[str, int, int]] | None = None) -> AddressMap:
    """The map covering digital `indices` (every $IN/$OUT number the cell uses) and `signals`."""
    top = max([64] + [abs(i) for i in indices] + [b for _, _, b in (signals or {}).values()])
    top = min(8192, (top + 63) // 64 * 64)
    return AddressMap(top, N_ANALOG, dict(signals or {}))


def cell_map(stimuli: list, rules: list, handshake: list[int],
             signals: dict[str, tuple[str, int, int]] | None = None) -> AddressMap:
    """The map of a run's cell (:func:`derive_map`): the digital inputs and outputs its
    `stimuli` set (robot/stimuli.py Stimulus ``set``: signal keys such as ``$IN[5]``, SIGNALs
    resolved), its `rules` set and read (robot/cellrules.py Rule ``set`` and the syntax tree of
    its condition ``when``: every ``$IN[n]``/``$OUT[n]`` with a literal index), the numbers of
    P00's program-number handshake (`handshake`: the ``PGNO_*`` bits of $config.dat) and the
    program's `signals` on ``$IN``/``$OUT``."""
    indices = list(handshake)
    for item in list(stimuli) + list(rules):
        for key in item.set:
            n = _digital(key)
            if n is not None:
                indices.append(n)
    for rule in rules:
        for e in rule.when.walk():
            if e.__class__ is N.Index and e.base.__class__ is N.Name and e.base.name.upper() in ("$IN", "$OUT") \
                    and len(e.indices) == 1 and e.indices[0].__class__ is N.IntLit:
                indices.append(int(e.indices[0].value))
    return derive_map(indices, signals)


def _digital(key) -> int | None:
    """n of a signal key ``$IN[n]``/``$OUT[n]`` (robot/io.py's spelling), else None."""
    k = str(key).upper().replace(" ", "")
    for base in ("$IN[", "$OUT["):
        if k.startswith(base) and k.endswith("]") and k[len(base):-1].isdigit():
            return int(k[len(base):-1])
    return None


def _to_reg(v: float) -> int:
    return int(round(max(-1.0, min(1.0, float(v))) * SCALE)) & 0xFFFF


def _from_reg(r: int) -> float:
    r = int(r) & 0xFFFF
    return (r - 0x10000 if r >= 0x8000 else r) / SCALE


class Plc:
    """The Modbus TCP and OPC UA servers of a run (see the module docstring)."""

    def __init__(self, hub, settings, amap: AddressMap | None = None) -> None:
        self.hub = hub
        self.settings = settings
        self.map = amap or AddressMap()
        self.loop = None                    # the servers' asyncio loop
        self.submit = None                  # asyncio.run_coroutine_threadsafe on that loop, once started
        self.ua = None                      # asyncua's `ua` types, once the OPC UA server runs
        self.thread: threading.Thread | None = None
        self.modbus = None
        self.device = None
        self.opcua = None
        self.nodes: dict[str, object] = {}
        self.seen_in: list[bool] = []
        self.seen_anin: list[float] = []
        self.seen_nodes: dict[str, object] = {}
        self.error: BaseException | None = None
        self.traced_refused = 0     # Modbus clients closed past MAX_PLC_CLIENTS (net.modbus.Server.refused)
        self.refusals: list[str] = []   # OPC UA writes the write rules refused (traced in sync)

    # ------------------------------------------------------------------ start / stop
    def start(self) -> None:
        """Start the servers; returns when they listen. Raises OSError (a port in use)."""
        # deferred: tools/startup_bench.py, krl check --reach +19 ms at the top (2026-11-26)
        import asyncio  # noqa: PLC0415

        ready = threading.Event()
        self.loop = asyncio.new_event_loop()
        self.submit = functools.partial(asyncio.run_coroutine_threadsafe, loop=self.loop)

        def main():
            asyncio.set_event_loop(self.loop)
            try:
                self.loop.run_until_complete(self._start())
            except BaseException as exc:  # noqa: BLE001 - reported to the starting thread
                self.error = exc
                ready.set()
                return
            ready.set()
            self.loop.run_forever()

        self.thread = threading.Thread(target=main, name="plc", daemon=True)
        self.thread.start()
        ready.wait(60)
        if self.error is not None:
            raise OSError(f"the PLC servers cannot start: {self.error}") from None

    async def _start(self) -> None:
        io = self.hub.ctl.io
        m = self.map
        self.seen_in = [io.get_in(n) for n in range(1, m.digital + 1)]
        self.seen_anin = [io.get_anin(n) for n in range(1, m.analog + 1)]
        if self.settings.modbus is not None:
            await self._start_modbus()
        if self.settings.opcua is not None:
            await self._start_opcua()

    async def _start_modbus(self) -> None:
        # deferred: tools/startup_bench.py, krl check --reach +33 ms at the top (2026-11-26)
        from pymodbus.datastore import (ModbusDeviceContext, ModbusSequentialDataBlock,  # noqa: PLC0415
                                        ModbusServerContext)

        # deferred: tools/startup_bench.py, krl check --reach +36 ms at the top (2026-11-26)
        from .modbus import Server  # noqa: PLC0415

        logging.getLogger("pymodbus").setLevel(logging.ERROR)   # its v4 deprecation notes are not the user's
        clip_library_logs("pymodbus")
        m = self.map
        io = self.hub.ctl.io
        # the blocks start at 1: pymodbus maps the PDU's address a to the block's a+1 (address 0 = $IN[1])
        self.device = ModbusDeviceContext(
            co=ModbusSequentialDataBlock(1, [io.get_in(n) for n in range(1, m.digital + 1)]),
            di=ModbusSequentialDataBlock(1, [io.get_out(n) for n in range(1, m.digital + 1)]),
            hr=ModbusSequentialDataBlock(1, [_to_reg(io.get_anin(n)) for n in range(1, m.analog + 1)]),
            ir=ModbusSequentialDataBlock(1, [_to_reg(io.get_anout(n)) for n in range(1, m.analog + 1)]))
        ctx = ModbusServerContext(devices=self.device, single=True)
        host, port = self.settings.modbus
        # the map's sizes bound every request's addresses; a client past the limit is closed at accept
        srv = Server(ctx, (host, port), m.digital, m.analog, MAX_PLC_CLIENTS)
        await srv.listen()
        self.modbus = srv
        socks = getattr(srv.transport, "sockets", None) or ()
        bound = socks[0].getsockname()[:2] if socks else (host, port)
        self.hub.published("modbus", bound)

    async def _start_opcua(self) -> None:
        # deferred: tools/startup_bench.py, krl run +282 ms at the top (2026-11-26)
        from asyncua import Server, ua  # noqa: PLC0415

        self.ua = ua
        clip_library_logs("asyncua")        # it logs a refused write with its whole value
        url = self.settings.opcua
        server = Server()
        await server.init()
        server.set_endpoint(url)
        server.set_server_name("krl-tools simulated KR C4")
        server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
        ns = await server.register_namespace("urn:krl-tools:plc")
        robot = await server.nodes.objects.add_object(ns, "Robot")
        m = self.map
        io = self.hub.ctl.io
        groups = {}
        for gname in ("Inputs", "Outputs", "AnalogInputs", "AnalogOutputs", "Signals"):
            groups[gname] = await robot.add_folder(ns, gname)
        for n in range(1, m.digital + 1):
            node = await groups["Inputs"].add_variable(ns, f"IN[{n}]", io.get_in(n), ua.VariantType.Boolean)
            await node.set_writable()
            self.nodes[f"$IN[{n}]"] = node
            self.nodes[f"$OUT[{n}]"] = await groups["Outputs"].add_variable(ns, f"OUT[{n}]", io.get_out(n), ua.VariantType.Boolean)
        for n in range(1, m.analog + 1):
            node = await groups["AnalogInputs"].add_variable(ns, f"ANIN[{n}]", io.get_anin(n), ua.VariantType.Double)
            await node.set_writable()
            self.nodes[f"$ANIN[{n}]"] = node
            self.nodes[f"$ANOUT[{n}]"] = await groups["AnalogOutputs"].add_variable(ns, f"ANOUT[{n}]", io.get_anout(n), ua.VariantType.Double)
        for name, (base, a, b) in m.signals.items():
            node = await groups["Signals"].add_variable(ns, name, self._signal_value(base, a, b),
                                                        ua.VariantType.Boolean if a == b else ua.VariantType.Int32)
            if base == "$IN":
                await node.set_writable()
            self.nodes["SIGNAL " + name] = node
        self._guard_writes(server, ua)
        await server.start()
        self.opcua = server
        socks = getattr(getattr(server.bserver, "_server", None), "sockets", None) or ()
        self.seen_nodes = {k: await n.read_value() for k, n in self.nodes.items()
                           if k.startswith(("$IN", "$ANIN", "SIGNAL"))}

        host, port = parse_address(url[len("opc.tcp://"):].split("/", 1)[0], "opcua")
        if socks:
            port = socks[0].getsockname()[1]
        self.hub.published("opcua", (host, port))

    def _guard_writes(self, server, ua) -> None:
        """A client's write of a node of the map goes through the controller's write rules
        first (the hub sink's ``admit``, interp/runtime/writerules.py): a value of another
        type or shape (an array into the scalar ``ANIN[2]``) is BadTypeMismatch, NaN, an
        infinity or a value outside the variable's range (``$ANIN`` -1.0..1.0) BadOutOfRange, a
        write-protected one BadNotWritable; nothing of it is taken, and the run gets a ``net``
        error event. asyncua itself checks only the variant's type (an array of Doubles passed
        into a Double node, and the run then stopped with "internal error: TypeError")."""
        expected = {}
        for key, node in self.nodes.items():
            if key.startswith(("$IN", "$ANIN", "SIGNAL")):
                expected[node.nodeid] = key
        service = server.iserver.attribute_service
        plain = service.write
        status = {"shape": ua.StatusCodes.BadTypeMismatch, "protected": ua.StatusCodes.BadNotWritable}

        async def write(params, *args, **kw):
            results = []
            for wv in params.NodesToWrite:
                key = expected.get(wv.NodeId)
                refusal = None
                if key is not None and wv.AttributeId == ua.AttributeIds.Value:
                    refusal = self._refusal(key, wv.Value, ua)
                if refusal is None:
                    results += await plain(ua.WriteParameters(NodesToWrite=[wv]), *args, **kw)
                    continue
                rule, text = refusal
                if len(self.refusals) < MAX_REFUSALS_TRACED:
                    self.refusals.append(text)
                results.append(ua.StatusCode(status.get(rule, ua.StatusCodes.BadOutOfRange)))
            return results

        service.write = write

    def _refusal(self, key: str, dv, ua) -> tuple[str, str] | None:
        """(rule, text) when the write rules refuse the OPC UA value `dv` for node `key`."""
        variant = dv.Value if dv is not None else None
        if variant is None or variant.Value is None:
            return ("shape", f"{key}: an empty value")
        value = variant.Value
        want = ua.VariantType.Double if key.startswith("$ANIN") else ua.VariantType.Boolean
        name = key
        if key.startswith("SIGNAL "):
            base, a, b = self.map.signals[key[7:]]
            want = ua.VariantType.Boolean if a == b else ua.VariantType.Int32
            name = f"{base}[{a}]"
            if a != b and isinstance(value, int) and not isinstance(value, bool) and not 0 <= value < 1 << (b - a + 1):
                return ("range", f"{key}: {clip(value)} outside 0..{(1 << (b - a + 1)) - 1}")
        if isinstance(value, (list, tuple)) or variant.is_array:
            refusal = self.hub.sink.admit(name, list(value) if isinstance(value, (list, tuple)) else value, "plc")
            return (getattr(refusal, "rule", "shape"), str(refusal) if refusal is not None else f"{key}: an array")
        if variant.VariantType != want:
            return ("shape", f"{key}: a {variant.VariantType.name}, the node a {want.name}")
        if key.startswith("SIGNAL ") and want == ua.VariantType.Int32:
            value = bool(value)         # each bit an input: the protection of the first names them all
        refusal = self.hub.sink.admit(name, value, "plc")
        return (refusal.rule, str(refusal)) if refusal is not None else None

    def _signal_value(self, base: str, a: int, b: int):
        io = self.hub.ctl.io
        get = io.get_in if base == "$IN" else io.get_out
        if a == b:
            return get(a)
        return sum(1 << i for i, n in enumerate(range(a, b + 1)) if get(n))

    def close(self) -> None:
        loop = self.loop
        if loop is None:
            return

        async def stop():
            if self.modbus is not None:
                await self.modbus.shutdown()
            if self.opcua is not None:
                await self.opcua.stop()

        if self.thread is not None and self.thread.is_alive():
            try:
                self.submit(stop()).result(30)
            except Exception:  # noqa: BLE001 - a server that does not stop cleanly is left to the thread's end
                pass
            loop.call_soon_threadsafe(loop.stop)
            self.thread.join(30)
        self.loop = None

    # ------------------------------------------------------------------ the cycle
    def sync(self) -> None:
        """Once per IPO cycle (see the module docstring)."""
        if self.loop is None or self.thread is None or not self.thread.is_alive():
            return
        writes, refusals, notes = self.submit(self._exchange()).result(30)
        refused = self.modbus.refused if self.modbus is not None else 0
        while self.traced_refused < refused:
            self.traced_refused += 1
            self.hub.trace("plc", "refused", text=f"more than {MAX_PLC_CLIENTS} Modbus clients: closed at accept")
        for text in refusals:
            self.hub.trace("plc", "error", text=f"OPC UA write refused: {text}")
        for text in notes:
            self.hub.trace("plc", "error", text=f"Modbus: {text}")
        for signal, value in writes:
            self.apply(signal, value)

    async def _exchange(self) -> tuple[list, list, list]:
        """In the servers' loop: what the PLC wrote (and the OPC UA writes refused, the Modbus
        connections closed, since the last cycle), then the robot's image published."""
        io = self.hub.ctl.io
        refusals, self.refusals = self.refusals, []
        notes = []
        if self.modbus is not None:
            notes, self.modbus.notes = self.modbus.notes, []
        m = self.map
        writes: list = []
        ctx = self.modbus.context if self.modbus is not None else None
        if ctx is not None:
            co = await ctx.async_getValues(0, 1, 0, m.digital)
            for i, v in enumerate(co):
                if bool(v) != self.seen_in[i]:
                    writes.append((f"$IN[{i + 1}]", bool(v)))
            hr = await ctx.async_getValues(0, 3, 0, m.analog)
            for i, r in enumerate(hr):
                v = _from_reg(r)
                if abs(v - self.seen_anin[i]) > 0.5 / SCALE:
                    writes.append((f"$ANIN[{i + 1}]", v))
        if self.opcua is not None:
            for key, node in self.nodes.items():
                if key in self.seen_nodes:
                    v = await node.read_value()
                    if v != self.seen_nodes[key]:
                        self.seen_nodes[key] = v
                        if key.startswith("SIGNAL "):
                            base, a, b = m.signals[key[7:]]
                            if a == b:
                                writes.append((f"$IN[{a}]", bool(v)))
                            else:
                                writes += [(f"$IN[{n}]", bool((int(v) >> i) & 1)) for i, n in enumerate(range(a, b + 1))]
                        else:
                            writes.append((key, bool(v) if key.startswith("$IN") else float(v)))
        # the image as it will be after these writes, published to both servers
        pending = dict(writes)
        ins = [pending.get(f"$IN[{n}]", io.get_in(n)) for n in range(1, m.digital + 1)]
        anins = [pending.get(f"$ANIN[{n}]", io.get_anin(n)) for n in range(1, m.analog + 1)]
        self.seen_in = [bool(x) for x in ins]
        self.seen_anin = [float(x) for x in anins]
        if ctx is not None:
            await ctx.async_setValues(0, 1, 0, ins)
            await ctx.async_setValues(0, 2, 0, [io.get_out(n) for n in range(1, m.digital + 1)])
            await ctx.async_setValues(0, 3, 0, [_to_reg(x) for x in anins])
            await ctx.async_setValues(0, 4, 0, [_to_reg(io.get_anout(n)) for n in range(1, m.analog + 1)])
        if self.opcua is not None:
            ua = self.ua
            for n in range(1, m.digital + 1):
                await self._publish(f"$IN[{n}]", ins[n - 1], ua.VariantType.Boolean)
                await self._publish(f"$OUT[{n}]", io.get_out(n), ua.VariantType.Boolean)
            for n in range(1, m.analog + 1):
                await self._publish(f"$ANIN[{n}]", anins[n - 1], ua.VariantType.Double)
                await self._publish(f"$ANOUT[{n}]", io.get_anout(n), ua.VariantType.Double)
        return writes, refusals, notes

    async def _publish(self, key: str, value, vtype) -> None:
        ua = self.ua
        cache = self.__dict__.setdefault("_published", {})
        if cache.get(key) == value:
            return
        cache[key] = value
        node = self.nodes[key]
        await self.opcua.write_attribute_value(node.nodeid, ua.DataValue(ua.Variant(value, vtype)))
        if key in self.seen_nodes:
            self.seen_nodes[key] = value

    def apply(self, signal: str, value) -> None:
        """A PLC write: the input changes now (traced, so a replay applies it again)."""
        self.hub.trace("plc", "in", data=f"{signal}={'TRUE' if value is True else 'FALSE' if value is False else value}")
        apply_write(self.hub, signal, value)


def apply_write(hub, signal: str, value) -> None:
    """The PLC's write of an input, through the controller's write rules (the sink's ``admit``:
    a refusal is an error event and nothing is written)."""
    refusal = hub.sink.admit(signal, value, "plc")
    if refusal is not None:
        hub.trace("plc", "error", text=f"write refused: {refusal}")
        return
    hub.sink.changed_outside()
    n = int(signal[signal.index("[") + 1:-1])
    hub.ctl.set_input(n, value, "plc", analog=not signal.startswith("$IN"))


def replay_write(hub, ev: dict) -> None:
    """A recorded PLC write, applied again."""
    text = str(ev.get("data", ""))
    if "=" not in text:
        return
    signal, value = text.split("=", 1)
    hub.trace("plc", "in", data=text)
    v = True if value == "TRUE" else False if value == "FALSE" else float(value)
    apply_write(hub, signal, v)


class PlcPartner(Partner):
    """The PLC side (net/partner.py): the Modbus TCP and OPC UA servers of ``network: {plc:
    {modbus, opcua, map}}`` over the I/O image (docs/network.md "The PLC side"). Its address map
    comes from the cell (``attach``'s ``plc_map``: a callable, interp/run.py)."""

    key = "plc"
    fields = {"modbus": None, "opcua": None, "plc_map": None}
    docs = "The PLC side"

    def __init__(self, hub) -> None:
        super().__init__(hub)
        self.plc: Plc | None = None

    @classmethod
    def parse(cls, doc, base: Path) -> dict:
        plc = mapping(doc, PLC_KEYS, "network: plc")
        out: dict = {}
        if plc.get("modbus") is not None:
            out["modbus"] = parse_address(plc["modbus"], "network: plc: modbus")
        if plc.get("opcua") is not None:
            url = plc["opcua"]
            if not isinstance(url, str) or not url.startswith("opc.tcp://"):
                raise SettingsError("network: plc: opcua is an opc.tcp://HOST:PORT address")
            parse_address(url[len("opc.tcp://"):].split("/", 1)[0], "network: plc: opcua")
            out["opcua"] = url
        if plc.get("map") is not None:
            out["plc_map"] = inside(base, plc["map"], "network: plc: map")
        return out

    def attach(self, ctl, **cell) -> None:
        s = self.hub.settings
        if s is None or (s.modbus is None and s.opcua is None):
            return
        amap = cell.get("plc_map")
        self.plc = Plc(self.hub, s, amap() if callable(amap) else amap)
        self.plc.start()

    @property
    def attached(self) -> bool:
        return self.plc is not None

    def poll(self, ctl, live: bool) -> None:
        if live and self.plc is not None:
            self.plc.sync()

    def replay(self, ev: dict) -> None:
        if ev.get("dir") == "in":
            replay_write(self.hub, ev)

    def close(self) -> None:
        if self.plc is not None:
            self.plc.close()
