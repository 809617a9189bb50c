"""Modbus TCP to the letter (issue 61; docs/network.md "The PLC side", "Modbus TCP"): the
requests the PLC's server (net/plc.py) answers, as the *MODBUS Application Protocol
Specification V1.1b3* and the *MODBUS Messaging on TCP/IP Implementation Guide V1.0b* give them,
over pymodbus's data model and PDUs.

pymodbus (the pinned 3.16.1) is kept for what it does well — decoding a valid request, running
it against the device's data blocks, encoding the answer — and this module does what it does
not do by the specification:

* **every request of a TCP segment is answered, in order** (:class:`Connection`): pymodbus's
  server hands one frame of what arrived to its framer and keeps the rest until more bytes
  come (three requests in one segment got one answer), drops its whole receive buffer past 516
  bytes, and clears it whenever it sends (a pipelined request half arrived was lost). Its
  issues #1949 (fixed in 3.6.4 by PR #1965, for the client) and #2933 (``handleFrame`` decoding
  from offset 0 after a skipped frame; fixed in the pinned release, whose ``handleFrame``
  decodes ``data[used_len:]``) are about the framer; the server's one-frame-per-read is not.
  Here the connection keeps its own buffer, takes every complete frame of it, and answers
  them one after another; past :data:`MAX_PENDING` waiting requests it stops reading the
  socket (the client's further requests wait in the kernel's buffer) until they are answered;
* **exceptions** (:func:`check_request`, the specification's state diagram of each function:
  function code, then quantity and length, then address): an exception answer is the
  function code + 0x80 and the exception code; 01 ILLEGAL FUNCTION for a function code the
  server does not serve (pymodbus answered ``80 01`` for any code it did not know), 03 ILLEGAL
  DATA VALUE for a quantity outside the function's limits (2,001 coils: pymodbus answered
  ``80 01``), a byte count that does not match it, a length the function does not have, and a
  write-single-coil value other than 0x0000/0xFF00 (pymodbus switched the coil on), 02
  ILLEGAL DATA ADDRESS for a start and quantity outside the map;
* **the connection limit at accept** (:class:`Server`): a connection past
  :data:`~krl.limits.MAX_PLC_CLIENTS` is closed as it is accepted, unanswered (pymodbus counts
  connections only in its ``trace_connect`` callback, after the handler is made: 12
  connections at once were all served).

Served: 01 Read Coils, 02 Read Discrete Inputs, 03 Read Holding Registers, 04 Read Input
Registers, 05 Write Single Coil, 06 Write Single Register, 15 Write Multiple Coils, 16 Write
Multiple Registers, 22 Mask Write Register, 23 Read/Write Multiple Registers. Every other code
(the serial-line-only 07, 08, 11, 12, 17, the file and FIFO functions 20, 21, 24, the
encapsulated 43, the user-defined ones) is 01. MBAP header (implementation guide 3.1.3): the
length field frames the stream; a protocol identifier other than 0 is not MODBUS and a frame
without a function code cannot be answered: both are discarded unanswered (a ``net`` error
event); a PDU longer than 253 bytes is 03. A connection holds at most what it read before its
waiting requests passed :data:`MAX_PENDING` (one read of asyncio's, at most 256 KiB, past them).
"""

from __future__ import annotations

import asyncio
import struct
from collections import deque

from pymodbus.server import ModbusTcpServer
from pymodbus.server.requesthandler import ServerRequestHandler

ILLEGAL_FUNCTION = 0x01
ILLEGAL_DATA_ADDRESS = 0x02
ILLEGAL_DATA_VALUE = 0x03
SERVER_DEVICE_FAILURE = 0x04

#: function code -> (table, the quantity's limit) of the functions served; table: the map's
#: "bits" (coils, discrete inputs: the digital signals) or "registers" (holding, input: analog)
READS = {1: ("bits", 2000), 2: ("bits", 2000), 3: ("registers", 125), 4: ("registers", 125)}
SUPPORTED = frozenset((1, 2, 3, 4, 5, 6, 15, 16, 22, 23))
MAX_WRITE_COILS = 1968      # 0x07B0
MAX_WRITE_REGISTERS = 123   # 0x007B
MAX_RW_WRITE = 121          # 0x0079 (function 23's write part)
MBAP = struct.Struct(">HHHB")
#: the MBAP header's bytes before the ones its length field counts (transaction, protocol, length)
MBAP_PREFIX = 6
#: function 22's request body (mask write register: address, AND mask, OR mask)
MASK_WRITE_BODY = 6
MAX_PDU = 253               # the largest PDU (Application Protocol 4.1: a 256-byte serial ADU less address and CRC)
#: requests of one connection waiting to be answered before it stops reading its socket
MAX_PENDING = 256


def check_request(pdu: bytes, bits: int, registers: int) -> int | None:
    """The exception code the specification gives for request `pdu` (function code and data)
    on a map of `bits` coils/discrete inputs and `registers` holding/input registers, or None
    when the request is to be carried out."""
    fc = pdu[0]
    body = pdu[1:]
    if fc not in SUPPORTED:
        return ILLEGAL_FUNCTION
    if len(pdu) > MAX_PDU:
        return ILLEGAL_DATA_VALUE       # longer than any request may be: the implied length is wrong
    size = {"bits": bits, "registers": registers}
    if fc in READS:
        table, limit = READS[fc]
        if len(body) != 4:
            return ILLEGAL_DATA_VALUE
        start, qty = struct.unpack(">HH", body)
        if not 1 <= qty <= limit:
            return ILLEGAL_DATA_VALUE
        return ILLEGAL_DATA_ADDRESS if start + qty > size[table] else None
    if fc in (5, 6):
        if len(body) != 4:
            return ILLEGAL_DATA_VALUE
        addr, value = struct.unpack(">HH", body)
        if fc == 5 and value not in (0x0000, 0xFF00):
            return ILLEGAL_DATA_VALUE
        return ILLEGAL_DATA_ADDRESS if addr >= size["bits" if fc == 5 else "registers"] else None
    if fc in (15, 16):
        if len(body) < 5:
            return ILLEGAL_DATA_VALUE
        start, qty, count = struct.unpack(">HHB", body[:5])
        limit, need = (MAX_WRITE_COILS, (qty + 7) // 8) if fc == 15 else (MAX_WRITE_REGISTERS, 2 * qty)
        if not 1 <= qty <= limit or count != need or len(body) != 5 + count:
            return ILLEGAL_DATA_VALUE
        return ILLEGAL_DATA_ADDRESS if start + qty > size["bits" if fc == 15 else "registers"] else None
    if fc == 22:
        if len(body) != MASK_WRITE_BODY:
            return ILLEGAL_DATA_VALUE
        (addr,) = struct.unpack(">H", body[:2])
        return ILLEGAL_DATA_ADDRESS if addr >= registers else None
    # 23: read/write multiple registers
    if len(body) < 9:
        return ILLEGAL_DATA_VALUE
    rstart, rqty, wstart, wqty, count = struct.unpack(">HHHHB", body[:9])
    if not 1 <= rqty <= 125 or not 1 <= wqty <= MAX_RW_WRITE or count != 2 * wqty or len(body) != 9 + count:
        return ILLEGAL_DATA_VALUE
    if rstart + rqty > registers or wstart + wqty > registers:
        return ILLEGAL_DATA_ADDRESS
    return None


def exception_frame(tid: int, unit: int, fc: int, code: int) -> bytes:
    """The ADU of an exception answer: the request's function code + 0x80, the exception code."""
    return MBAP.pack(tid, 0, 3, unit) + bytes(((fc | 0x80) & 0xFF, code))


class Connection(ServerRequestHandler):
    """One client's connection (see the module docstring): its own buffer, every complete frame
    checked (:func:`check_request`) and answered in order by one worker."""

    def __init__(self, owner, *args) -> None:
        super().__init__(owner, *args)
        self.buf = bytearray()
        self.pending: deque = deque()
        self.worker: asyncio.Task | None = None
        self.paused = False

    def datagram_received(self, data: bytes, addr: tuple | None) -> None:
        self.buf += data
        self._frames()

    def _frames(self) -> None:
        """Queue every complete frame of the buffer for the worker, which answers them in order
        (an exception in its turn, after the answers of the requests before it)."""
        buf = self.buf
        used = 0
        while len(buf) - used >= MBAP_PREFIX:
            tid, pid, length = struct.unpack_from(">HHH", buf, used)
            if len(buf) - used < MBAP_PREFIX + length:
                break
            unit = buf[used + MBAP_PREFIX] if length else 0
            pdu = bytes(buf[used + MBAP_PREFIX + 1:used + MBAP_PREFIX + length])
            used += MBAP_PREFIX + length
            if pid != 0 or not pdu:
                # not MODBUS (implementation guide 3.1.3), or no function code to answer: discarded
                self.server.note(f"a frame of protocol {pid}, {len(pdu)} PDU bytes: discarded unanswered")
                continue
            self.pending.append((tid, unit, pdu))
        del buf[:used]
        if self.pending and (self.worker is None or self.worker.done()):
            self.worker = asyncio.ensure_future(self._answer())
        if len(self.pending) >= MAX_PENDING and not self.paused and self.transport is not None:
            self.transport.pause_reading()
            self.paused = True

    async def _answer(self) -> None:
        while self.pending and self.transport is not None:
            tid, unit, pdu = self.pending.popleft()
            await self._one(tid, unit, pdu)
            if self.paused and len(self.pending) < MAX_PENDING // 2 and self.transport is not None:
                self.paused = False
                self.transport.resume_reading()

    async def _one(self, tid: int, unit: int, pdu: bytes) -> None:
        code = check_request(pdu, self.server.bits, self.server.registers)
        if code is None:
            request = self.server.decoder.decode(pdu)
            if request is None:
                code = ILLEGAL_DATA_VALUE       # a served function pymodbus cannot decode
            else:
                request.dev_id, request.transaction_id = unit, tid
                try:
                    response = await request.datastore_update(self.server.context, unit)
                except Exception:  # noqa: BLE001 - the device failed to carry it out: exception 04
                    code = SERVER_DEVICE_FAILURE
                else:
                    response.transaction_id, response.dev_id = tid, unit
                    self.server_send(response, None)
                    return
        self.server.exceptions += 1
        if self.transport is not None:
            self.transport.write(exception_frame(tid, unit, pdu[0], code))


class _Refused(ServerRequestHandler):
    """A connection past the limit: closed as it is made, never answered."""

    def connection_made(self, transport) -> None:
        transport.close()
        self.server.refused += 1
        if self.listener is not None:       # counted no more (pymodbus forgets only a handler it opened)
            self.listener.active_connections.pop(self.unique_id, None)

    def datagram_received(self, data: bytes, addr: tuple | None) -> None:
        """Nothing it sends is read."""


class Server(ModbusTcpServer):
    """pymodbus's TCP server with :class:`Connection` for each client and the connection limit
    counted at accept; ``bits`` and ``registers`` the map's sizes (net/plc.py ``AddressMap``),
    ``max_clients`` the limit. ``refused`` and ``exceptions`` count what the hub traces;
    ``notes`` keeps what closed a connection for the run's trace."""

    def __init__(self, context, address, bits: int, registers: int, max_clients: int) -> None:
        super().__init__(context, address=address)
        self.bits = bits
        self.registers = registers
        self.max_clients = max_clients
        self.refused = 0
        self.exceptions = 0
        self.notes: list[str] = []

    def callback_new_connection(self):
        if len(self.active_connections) >= self.max_clients:
            return _Refused(self, self.trace_packet, self.trace_pdu, self.trace_connect)
        return Connection(self, self.trace_packet, self.trace_pdu, self.trace_connect)

    def note(self, text: str) -> None:
        if len(self.notes) < 64:
            self.notes.append(text)


__all__ = ["ILLEGAL_DATA_ADDRESS", "ILLEGAL_DATA_VALUE", "ILLEGAL_FUNCTION", "MAX_PENDING", "SERVER_DEVICE_FAILURE",
           "SUPPORTED", "MAX_PDU", "Connection", "Server", "check_request", "exception_frame"]
