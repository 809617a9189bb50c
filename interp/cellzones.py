"""Shared zones of a cell of several robots (issue 89; docs/cells.md): where the robots stand in
the cell's world, and which two TCPs are in one zone at once.

Each robot of the cell file may have ``base: [X, Y, Z, A, B, C]`` (mm, deg): its robot root
(``$ROBROOT``, as KUKA.WorkVisual places a robot in a cell) in the cell's world; default the
identity. ``zones:`` names boxes of the cell's world, ``NAME: {min: [x, y, z], max: [x, y, z]}``
(mm, axis-parallel): a zone two robots may enter only one at a time (a workspace they share,
the place of a hand-off). After every IPO cycle the :class:`ZoneWatch` places each robot's TCP
(read back, ``$POS_ACT`` in its WORLD: robot/readback.py) in the cell's world and records a
:class:`Conflict` when two robots' TCPs are in one zone in the same cycle: the zone, both robots,
the time it began and the motion each robot's main run was executing (file:line). A conflict is
reported, not stopped: KUKA's workspace monitoring stops a robot only at a zone its own
``$WORKSPACE`` configures, and the cell's zones are the commissioning engineer's question "can
these two meet", which the summary answers.

Limits: :data:`krl.limits.MAX_CELL_ZONES` zones. Raises :class:`interp.robotcell.CellError`
through the reader for a malformed zone or base (file:line).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robot.frames import frame_to_matrix

#: $BASE = WORLD: a robot's TCP in its own world (its $ROBROOT's frame)
_WORLD = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Zone:
    """An axis-parallel box of the cell's world, ``lo``..``hi`` (mm)."""
    name: str
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]

    def holds(self, p) -> bool:
        return all(self.lo[i] <= p[i] <= self.hi[i] for i in range(3))


@dataclass(frozen=True)
class Conflict:
    """Two robots' TCPs in one zone at once, from ``time`` (s): each robot's name and the motion
    its main run executed then (``file:line``, or None at rest)."""
    zone: str
    time: float
    first: tuple[str, str | None]
    second: tuple[str, str | None]

    def __str__(self) -> str:
        def who(r):
            return f"{r[0]} ({r[1]})" if r[1] else f"{r[0]} (at rest)"
        return f"{self.zone}: {who(self.first)} and {who(self.second)} from {self.time:.3f} s"


def numbers(value, n: int, where: str, what: str, error) -> tuple[float, ...]:
    """`value` as `n` finite numbers, else `error` (an exception class) naming `where`."""
    if not isinstance(value, list) or len(value) != n or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value):
        raise error(f"{where}: {what} is a list of {n} numbers")
    return tuple(float(v) for v in value)


def parse_zones(doc: dict, at, limit: int, error) -> tuple[Zone, ...]:
    """The ``zones:`` of a cell file's document `doc` (`at(obj, key)`: file:line; at most
    `limit`; `error`: the exception class raised)."""
    items = doc.get("zones", {})
    if not isinstance(items, dict):
        raise error(f"{at(doc, 'zones')}: 'zones' maps a name to {{min: [x, y, z], max: [x, y, z]}}")
    if len(items) > limit:
        raise error(f"{at(doc, 'zones')}: {len(items)} zones, more than the limit of {limit}")
    zones = []
    for name, body in items.items():
        where = at(items, name)
        if not isinstance(body, dict) or set(body) != {"min", "max"}:
            raise error(f"{where}: zone {name}: {{min: [x, y, z], max: [x, y, z]}} (mm, the cell's world)")
        lo, hi = (numbers(body[k], 3, where, f"zone {name}'s {k}", error) for k in ("min", "max"))
        if any(a > b for a, b in zip(lo, hi)):
            raise error(f"{where}: zone {name}: min is above max")
        zones.append(Zone(str(name), lo, hi))
    return tuple(zones)


class ZoneWatch:
    """The zones of a cell and its robots' runs (interp/robotcell.py RobotRun, each with its
    ``base``), checked after each IPO cycle (:meth:`check`); :attr:`conflicts` in the order
    they began."""

    def __init__(self, zones: tuple[Zone, ...], runs: list, bases: dict[str, tuple]) -> None:
        self.zones = zones
        self.runs = runs
        self.bases = {name: frame_to_matrix(*b) for name, b in bases.items()}
        self.conflicts: list[Conflict] = []
        self._open: set[tuple[str, str, str]] = set()

    def check(self, t: float) -> None:
        """After the IPO cycle at `t` (s): a conflict begins for each zone and pair of robots whose
        TCPs are both in it and were not in the cycle before."""
        if not self.zones:
            return
        where = {}
        for r in self.runs:
            ctl = r.runtime.controller
            p = ctl.actual.pos_act(base=_WORLD)
            where[r.name] = (self.bases[r.name] @ np.array([p["X"], p["Y"], p["Z"], 1.0]))[:3]
        now = set()
        for z in self.zones:
            inside = [r for r in self.runs if z.holds(where[r.name])]
            for i, a in enumerate(inside):
                for b in inside[i + 1:]:
                    key = (z.name, a.name, b.name)
                    now.add(key)
                    if key not in self._open:
                        self.conflicts.append(Conflict(z.name, t, (a.name, motion_of(a)), (b.name, motion_of(b))))
        self._open = now


def motion_of(run) -> str | None:
    """The motion robot `run`'s main run is executing (``file:line``), or None at rest."""
    req = run.runtime.controller.current_request()
    if req is None or req.line is None:
        return None
    return f"{req.file}:{req.line}"
