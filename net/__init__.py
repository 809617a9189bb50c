"""The controller on the network (issue 35, docs/network.md): the partners a PLC, a vision PC,
ROS and service tools connect to, on the simulated controller's one clock.

- :mod:`net.hub` — the run's network hub: polls every partner at each IPO cycle's start, paces
  the run to the wall clock while a partner is attached, replays a recorded trace;
- :mod:`net.partner` — the partner protocol (parse, attach, poll, replay, close), and
  :mod:`net.partners` — the registered partners, one line each;
- :mod:`net.settings` — the cell file's ``network:`` key, :mod:`net.cellkey` — what a
  partner's key is made of (addresses, paths, mappings);
- :mod:`net.xmlsafe` — XML parsed safely (defusedxml, size and depth limits), TCP stream framing;
- :mod:`net.transport` — non-blocking TCP/UDP endpoints, polled once per cycle;
- :mod:`net.ekiconfig`, :mod:`net.eki` — EthernetKRL channels and their element memory;
- :mod:`net.rsi` — RobotSensorInterface: the RSI context, the ETHERNET object, corrections;
- :mod:`net.varproxy` — KukaVarProxy's OpenShowVar protocol;
- :mod:`net.plc` — the PLC side: Modbus TCP (pymodbus) and OPC UA (asyncua) over the I/O image;
  :mod:`net.modbus` — Modbus TCP to the letter (exceptions, pipelined requests, the connection
  limit at accept) over pymodbus's PDUs;
- :mod:`net.netlog` — what a partner sent, clipped wherever it is shown but in its recording.

Every value a partner writes into the run goes through the controller's write rules
(interp/runtime/writerules.py), asked through the hub's sink (net/hub.py).
"""
