"""A plain client script that plays the PLC of the example cell (docs/network.md).

It writes the robot's inputs and reads its outputs over Modbus TCP, against the address map
of net/plc.py (``$IN[n]`` = coil n-1, ``$OUT[n]`` = discrete input n-1), with the signals of
R1/System/$config.dat: EXT start on $IN[17], the program number on $IN[33..40] (binary), its
parity on $IN[42], PGNO_VALID $IN[41], PGNO_REQ $OUT[20]. Then it reads the job's outputs over
OPC UA. Usage: ``python plc.py NUMBER [MODBUS_PORT [OPCUA_URL]]``.
"""

from __future__ import annotations

import asyncio
import sys
import time

from asyncua import Client
from pymodbus.client import ModbusTcpClient

EXT_START, PGNO_FBIT, PGNO_LENGTH, PGNO_PARITY, PGNO_VALID, PGNO_REQ = 17, 33, 8, 42, 41, 20
DONE = {1: 10, 2: 11}        # LOAD_DONE $OUT[10], UNLOAD_DONE $OUT[11]


def wait_output(client, n: int, value: bool, timeout: float) -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if client.read_discrete_inputs(n - 1, count=1).bits[0] == value:
            return
        time.sleep(0.02)
    raise TimeoutError(f"$OUT[{n}] did not become {value}")


def select_program(host: str, port: int, number: int, timeout: float = 60.0) -> None:
    """EXT start, then P00's handshake answering `number`, then wait for the job's output."""
    client = ModbusTcpClient(host, port=port, timeout=5)
    if not client.connect():
        raise ConnectionError(f"no Modbus server at {host}:{port}")
    try:
        client.write_coil(EXT_START - 1, True)
        wait_output(client, PGNO_REQ, True, timeout)           # the robot asks for a number
        bits = [bool((number >> i) & 1) for i in range(PGNO_LENGTH)]
        client.write_coils(PGNO_FBIT - 1, bits)
        client.write_coil(PGNO_PARITY - 1, sum(bits) % 2 == 1)  # odd parity: the EXOR of the bits
        client.write_coil(PGNO_VALID - 1, True)
        wait_output(client, PGNO_REQ, False, timeout)          # acknowledged
        client.write_coil(PGNO_VALID - 1, False)
        wait_output(client, DONE[number], True, timeout)       # the job ran
    finally:
        client.close()


async def read_outputs(url: str, numbers) -> dict[int, bool]:
    """The robot's outputs `numbers` over OPC UA (Robot/Outputs/OUT[n])."""

    async with Client(url) as client:
        ns = await client.get_namespace_index("urn:krl-tools:plc")
        out = {}
        for n in numbers:
            node = await client.nodes.objects.get_child([f"{ns}:Robot", f"{ns}:Outputs", f"{ns}:OUT[{n}]"])
            out[n] = await node.read_value()
        return out


def main(argv: list[str]) -> int:
    number = int(argv[1]) if len(argv) > 1 else 1
    port = int(argv[2]) if len(argv) > 2 else 5020
    url = argv[3] if len(argv) > 3 else "opc.tcp://127.0.0.1:4840"
    select_program("127.0.0.1", port, number)
    print(asyncio.run(read_outputs(url, [10, 11, 12])))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
