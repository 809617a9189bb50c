"""A partner of ROS-Industrial's kuka_eki_hw_interface (docs/network.md): sends one axis target
(A1..A6 in degrees) over UDP and prints the RobotState documents the controller sends back
until the robot is there. Usage: ``python eki_partner.py A1 A2 A3 A4 A5 A6 [PORT]``."""

from __future__ import annotations

import socket
import sys
import xml.etree.ElementTree as ET

AXES = ("A1", "A2", "A3", "A4", "A5", "A6")


def main(argv: list[str]) -> int:
    target = [float(x) for x in argv[1:7]]
    port = int(argv[7]) if len(argv) > 7 else 54600
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.settimeout(10)
    cmd = ET.Element("RobotCommand")
    ET.SubElement(cmd, "Pos", {a: str(v) for a, v in zip(AXES, target)})
    sock.sendto(ET.tostring(cmd), ("127.0.0.1", port))
    while True:
        data, _ = sock.recvfrom(65536)
        pos = ET.fromstring(data).find("Pos")
        axes = [float(pos.get(a)) for a in AXES]
        print(" ".join(f"{a}={v:9.4f}" for a, v in zip(AXES, axes)))
        if all(abs(a - b) < 1e-3 for a, b in zip(axes, target)):
            return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
