"""The program map (`krl graph`, issue 26): routines, the calls, interrupts, triggers, RUN
commands and EKI channels between them, entry points and unreachable routines, read from the
checker's annotations (krl/programmap/graph.py); DOT, SVG, JSON and HTML forms
(krl/programmap/render.py). The language server's call hierarchy reads the same map."""

from krl.programmap.graph import Edge, Node, ProgramMap, build_map, routine_id

__all__ = ["Edge", "Node", "ProgramMap", "build_map", "routine_id"]
