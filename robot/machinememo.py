"""What is derived from one robot's machine data once per process: :func:`derived`.

A run builds its controller's robot model (robot/robotmodel.py ``RobotModel``, its
robot/kinematics ``Kinematics`` and ``JointChain``) anew, because those objects hold the run's
own state (the operating mode, the memo of recent forward results, the solvers' scratch rows,
the compiled forward's buffers: two runs at once never share them). What they derive from the
machine data alone does not change while the :class:`~robot.machine.MachineData` object lives
(it is frozen): the joints' geometry, the soft limits as arrays and lists, ``$ROBROOT`` as a
matrix, the kinematic family that takes the robot and its parameters (for machine data, found
by solving sample poses of the machine data's chain: 5-10 ms of CPU a build, at every run of a
backup's program). :func:`derived` computes each once per machine object and key and gives the
same value afterwards; the arrays in it are made read-only (a write raises instead of reaching
another run). Issue 87, "a run's start should cost little once the program's model is loaded".
"""

from __future__ import annotations

import threading
import weakref
from collections.abc import Callable
from typing import Any

import numpy as np

#: id(machine) -> (a weak reference to it, {key: value}); an entry goes with its machine
_MEMO: dict[int, tuple[weakref.ref, dict]] = {}
_LOCK = threading.Lock()


def derived(machine: Any, key: str, build: Callable[[], Any]) -> Any:
    """``build()`` for `machine` (a MachineData, or any object that supports weak references)
    and `key`: computed at the first call for this object and key, the same value afterwards
    while the object lives. `build` must give a value that depends on the machine data alone
    and is only read; the numpy arrays of a tuple or dict it gives (one level) are made
    read-only. An exception of `build` propagates and nothing is kept (the next call builds
    again); for an object without weak references nothing is kept either. Thread-safe: two threads may both build at once, one value is kept."""
    ident = id(machine)
    entry = _MEMO.get(ident)
    if entry is None or entry[0]() is not machine:
        try:
            ref = weakref.ref(machine, lambda ref, ident=ident: _forget(ident, ref))
        except TypeError:           # an object without weak references: built each time
            return _read_only(build())
        entry = (ref, {})
        with _LOCK:
            _MEMO[ident] = entry
    values = entry[1]
    if key in values:
        return values[key]
    value = _read_only(build())
    return values.setdefault(key, value)


def _forget(ident: int, ref: weakref.ref) -> None:
    """The machine of `ref` is gone: its entry goes (unless another object took its id)."""
    with _LOCK:
        entry = _MEMO.get(ident)
        if entry is not None and entry[0] is ref:
            del _MEMO[ident]


def _read_only(value: Any) -> Any:
    """`value` with its numpy arrays (itself, or the items of a tuple, a list or a dict's
    values) made read-only."""
    items = value.values() if isinstance(value, dict) else value if isinstance(value, (tuple, list)) else (value,)
    for v in items:
        if isinstance(v, np.ndarray):
            v.flags.writeable = False
    return value


__all__ = ["derived"]
