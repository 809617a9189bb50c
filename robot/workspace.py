"""KUKA's workspace monitoring: ``$WORKSPACE[1..8]`` (cartesian boxes) and ``$AXWORKSPACE[1..8]``
(axis ranges), their state signals ``$WORKSTATE1..8`` / ``$AXWORKSTATE1..8``, and the STOP modes
(issue 64).

Sources: KUKA System Software 8.3, "Operating and Programming Instructions for System Integrators"
(KSS 8.3 SI V4, 14.01.2015), chapter "Configuring workspaces": cartesian workspaces
(``$WORKSPACE[n]`` in ``STEU/Mada/$custom.dat``, changeable by KRL) and axis-specific workspaces
(``$AXWORKSPACE[n]`` in ``R1/Mada/$machine.dat``), each with its signal ``$WORKSTATEn`` /
``$AXWORKSTATEn`` that is set while the workspace is violated (the copies of the manual the
project's stored pages hold give its table of contents only: studylib.net/doc/26132835); the
structures as KSS declares them (operate.dat: ``BOX`` = X, Y, Z, A, B, C, X1, Y1, Z1, X2, Y2, Z2,
``BOXMODE MODE``; ``AXBOX`` = A1_N, A1_P .. E6_N, E6_P, ``MODE``; ``BOXMODE`` #OFF, #INSIDE,
#OUTSIDE, #INSIDE_STOP, #OUTSIDE_STOP, #TCP_INSIDE, ...); the meaning of the modes and the
monitoring each IPO cycle as a secondary source describes them
(industrialmonitordirect.com, "KUKA $WORKSPACE $CYLWORKSPACE $AXWORKSPACE Configuration Guide" and
"KUKA KRC4 workspace pre-check": the monitor samples the actual position every IPO cycle and
stops the robot after it entered). Decisions, each marked in docs/robot.md "Workspaces":

* a cartesian box is the cuboid ``X1..X2 x Y1..Y2 x Z1..Z2`` (either order) in the frame
  ``{X, Y, Z, A, B, C}`` of ``$WORLD``; the point monitored is the TCP of the main run's
  ``$TOOL`` in ``$WORLD`` (the ``TCP_`` modes alike: the wrist point the non-``TCP_`` modes would
  add is from the secondary source only);
* an axis box holds the axes with ``An_N .. An_P`` (each E the robot has too); an axis whose
  ``_N`` and ``_P`` are both 0 is not monitored (the unconfigured value of every backup);
* the workspace is *violated* when the point (the axes) is inside for ``#INSIDE``/``_STOP`` and
  outside for ``#OUTSIDE``/``_STOP``: the signal is TRUE while it is violated; a ``_STOP`` mode
  also stops the robot at the IPO cycle that violates it, with :data:`MSG_STOP` naming the
  workspace (KUKA's message number is not known here: none is given);
* a boundary point is inside (a closed box);
* the structure's ``STATE`` component (``$WORKSPACE[n].STATE``, read by real code:
  itk-thrivaldi kuka_kvp_hw_interface toolchanger.src:26) holds the signal's value.

Units: mm and deg. This module reads numbers only: the runtime hands it the workspaces' current
values each cycle (interp/runtime/sysvars.py ``start_workspaces``), so a program that changes
``$WORKSPACE[n]`` takes effect at the next IPO cycle.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .frames import frame_to_matrix, inv_pos

#: the modes that stop the robot when the workspace is violated
STOP_MODES = frozenset({"INSIDE_STOP", "OUTSIDE_STOP", "TCP_INSIDE_STOP", "TCP_OUTSIDE_STOP"})
#: the modes whose workspace is violated while the point is inside
INSIDE_MODES = frozenset({"INSIDE", "INSIDE_STOP", "TCP_INSIDE", "TCP_INSIDE_STOP"})
#: the message of a STOP mode (its {kind} "workspace" or "axis workspace", {n} the number)
MSG_STOP = "{kind} {n} violated: the robot stopped ({mode})"


@dataclass(frozen=True)
class CartBox:
    """A cartesian workspace: the frame's inverse (4x4, ``$WORLD`` -> box), the box's corners in
    that frame (mm) and its mode (``"INSIDE"`` .. without ``#``)."""

    to_box: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    mode: str

    @classmethod
    def of(cls, c: dict, mode: str) -> "CartBox":
        """From a BOX's components (X, Y, Z, A, B, C, X1 .. Z2; a missing one is 0)."""
        g = {k: float(c.get(k, 0.0)) for k in ("X", "Y", "Z", "A", "B", "C", "X1", "Y1", "Z1", "X2", "Y2", "Z2")}
        a = np.array([g["X1"], g["Y1"], g["Z1"]])
        b = np.array([g["X2"], g["Y2"], g["Z2"]])
        return cls(inv_pos(frame_to_matrix(*(g[k] for k in "XYZABC"))), np.minimum(a, b), np.maximum(a, b), mode)

    def inside(self, p_world: np.ndarray) -> bool:
        """True when the point (mm, ``$WORLD``) lies in the box (boundary included)."""
        q = self.to_box[:3, :3] @ p_world + self.to_box[:3, 3]
        return bool(np.all(q >= self.lo - 1e-9) and np.all(q <= self.hi + 1e-9))


@dataclass(frozen=True)
class AxisBox:
    """An axis workspace: per monitored component (``"A1"`` .. ``"E6"``) its range, and the mode."""

    ranges: tuple[tuple[str, float, float], ...]
    mode: str

    @classmethod
    def of(cls, c: dict, mode: str, keys: Sequence[str]) -> "AxisBox":
        """From an AXBOX's components (``A1_N``, ``A1_P``, ..) for the axes `keys` the robot has."""
        out = []
        for k in keys:
            lo, hi = float(c.get(f"{k}_N", 0.0)), float(c.get(f"{k}_P", 0.0))
            if lo or hi:
                out.append((k, min(lo, hi), max(lo, hi)))
        return cls(tuple(out), mode)

    def inside(self, axes: dict[str, float]) -> bool:
        """True when every monitored axis lies in its range (an axis box monitoring none: False)."""
        return bool(self.ranges) and all(lo - 1e-9 <= axes[k] <= hi + 1e-9 for k, lo, hi in self.ranges)


def violated(mode: str, inside: bool) -> bool:
    """The workspace of `mode` is violated with the point (axes) `inside` or not."""
    return inside if mode in INSIDE_MODES else not inside


class WorkspaceMonitor:
    """The state of the 8 + 8 workspaces, updated each IPO cycle.

    Args:
        read: a callable returning the current definitions: two lists (cartesian, axis) of 8
            entries each, an entry ``None`` (mode #OFF or unset) or ``(mode, components)`` (the
            mode without ``#``, the structure's components as a dict).
        axis_keys: the E6AXIS components the robot has (robot/axismap.py ``model_keys``).
    """

    def __init__(self, read: Callable[[], tuple[list, list]], axis_keys: Sequence[str]) -> None:
        self.read = read
        self.axis_keys = tuple(axis_keys)
        #: called with (index 0..15, value) when a workspace's state changes (the runtime keeps
        #: the structure's STATE component: ``$WORKSPACE[n].STATE``), or None
        self.on_change: Callable[[int, bool], None] | None = None
        #: the signals' values: ``$WORKSTATE1..8`` then ``$AXWORKSTATE1..8``
        self.state = [False] * 16
        self._cache: dict = {}

    def _box(self, kind: str, n: int, entry):
        key = (kind, n)
        mode, comps = entry
        sig = (mode, tuple(sorted(comps.items())))
        got = self._cache.get(key)
        if got is None or got[0] != sig:
            box = CartBox.of(comps, mode) if kind == "cart" else AxisBox.of(comps, mode, self.axis_keys)
            got = self._cache[key] = (sig, box)
        return got[1]

    def cycle(self, tcp_world: np.ndarray, axes: dict[str, float]) -> tuple[list[tuple[str, bool]], str | None]:
        """One IPO cycle: the signals that changed (name, value) and the message of the first
        STOP workspace violated (None when none is)."""
        cart, axis = self.read()
        changes: list[tuple[str, bool]] = []
        stop = None
        for kind, entries, base, sig, label in (("cart", cart, 0, "$WORKSTATE", "workspace"),
                                                ("axis", axis, 8, "$AXWORKSTATE", "axis workspace")):
            for i, entry in enumerate(entries):
                v = False
                if entry is not None:
                    box = self._box(kind, i, entry)
                    v = violated(box.mode, box.inside(tcp_world) if kind == "cart" else box.inside(axes))
                    if v and stop is None and box.mode in STOP_MODES:
                        stop = MSG_STOP.format(kind=label, n=i + 1, mode="#" + box.mode)
                if v != self.state[base + i]:
                    self.state[base + i] = v
                    changes.append((f"{sig}{i + 1}", v))
                    if self.on_change is not None:
                        self.on_change(base + i, v)
        return changes, stop

    def occupied(self) -> list[tuple[int, CartBox]]:
        """The cartesian workspaces the TCP occupies now: ``[(n, box)]`` for each
        ``$WORKSPACE[n]`` of an inside mode (#INSIDE, #INSIDE_STOP, #TCP_INSIDE, ...) whose
        signal is set (after the last :meth:`cycle`). An #OUTSIDE box is the region the robot may
        stay in, not a place it occupies: never listed (interp/cellworkspaces.py)."""
        if not any(self.state[:8]):
            return []
        cart, _ = self.read()
        return [(i + 1, self._box("cart", i, e)) for i, e in enumerate(cart)
                if e is not None and self.state[i] and e[0] in INSIDE_MODES]

    def signal(self, name: str) -> bool:
        """The value of ``$WORKSTATEn`` / ``$AXWORKSTATEn``."""
        base = 8 if name.startswith("$AX") else 0
        return self.state[base + int(name[-1]) - 1]


__all__ = ["AxisBox", "CartBox", "INSIDE_MODES", "MSG_STOP", "STOP_MODES", "WorkspaceMonitor", "violated"]
