"""A sensor for examples/network/rsi_path.src (docs/network.md): answers each of the robot's
RSI packets within its cycle, ramping a Z correction up to the given millimetres, holding it,
then asking RSI to stop. Usage: ``python rsi_sensor.py [MM [PORT]]``."""

from __future__ import annotations

import socket
import sys
import xml.etree.ElementTree as ET


def main(argv: list[str]) -> int:
    mm = float(argv[1]) if len(argv) > 1 else 20.0
    port = int(argv[2]) if len(argv) > 2 else 49152
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", port))
    i = 0
    while True:
        data, robot = sock.recvfrom(65536)
        rob = ET.fromstring(data)
        z = min(mm, 0.5 * i)
        stop = 1 if z >= mm and i > 2 * mm + 20 else 0
        ipoc = rob.find("IPOC").text
        sock.sendto(f'<Sen Type="ImFree"><RKorr X="0" Y="0" Z="{z}" A="0" B="0" C="0"/>'
                    f"<Stop>{stop}</Stop><IPOC>{ipoc}</IPOC></Sen>".encode(), robot)
        if i % 25 == 0:
            print(f"IPOC {ipoc}: RIst Z {rob.find('RIst').get('Z')}, correction {z} mm")
        if stop:
            return 0
        i += 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
