"""The controller's own rules for a value written into a variable (issue 61): one function,
:func:`check`, through which every write goes — a KRL assignment (both interpreters, through the
system variable's write hook, interp/runtime/sysvars.py), the pendant's and the debugger's
assignments (the same path), KukaVarProxy (interp/runtime/netvars.py ``write_var``), the PLC's
OPC UA and Modbus writes and EKI's ``Set_Flag``/``Set_Out`` (the network sink, ``admit`` and
``write_input``). docs/security.md "Values written into the controller" lists the rules.

The rules come from the system variable table, ``krl/semantics/data/sysvars.yaml`` (read by
:func:`krl.semantics.builtins.load_builtins`), where each range and each protection has its
source:

1. *write protection*: a variable marked ``safety`` (a signal of the safety controller or of the
   Automatic External interface that gates motion: ``$MOVE_ENABLE``, ``$DRIVES_ON``,
   ``$USER_SAF``, ``$ALARM_STOP``, ``$SAFETY_SW``, ...) is refused to every writer; another
   read-only one (``$POS_ACT``, ``$IN``, ...) to every writer but the I/O system for the inputs
   it drives (``fieldbus``: a PLC partner writes ``$IN``, ``$ANIN``). KSS message 1388, "variable
   write-protected" (KSS01388 as two field reports quote it: "$ORI_TYPE variable write
   protected", "M variable write-protected");
2. *type and shape*: an array or a structure never into a scalar, a scalar never into an array;
   a REAL that is not a finite number (NaN, an infinity) is refused;
3. *range*: the documented range of the variable (``$OV_PRO`` 0..100, ``$ADVANCE`` 0..5, each
   ``$ANIN`` -1.0..1.0). KSS message 1446, "value assignment inadmissible" (KUKA's KSS 8.3
   operating manual as errorlib.net quotes it: "an invalid or out-of-range value was assigned to
   a system variable"; the controller's own text "OV_PRO out of limits [0.0; 100.0]").

A refusal is a :class:`~krl.semantics.values.KrlRuntimeError` with that number: for a KRL
statement the run stops at its line with it, identically in the tree interpreter and the VM; a
partner gets its protocol's refusal (KukaVarProxy "not ok", an OPC UA bad status) and the run a
``net`` error event. Nothing is written.
"""

from __future__ import annotations

import math
import re

from krl.semantics.builtins import load_builtins
from net.netlog import clip

from .errors import KrlRuntimeError
from .values import Arr, Struct

WRITE_PROTECTED = 1388
VALUE_INADMISSIBLE = 1446

#: the writers of a value: KRL (a program's assignment; the pendant's and the debugger's
#: assignments take the same path), and the partners on the network (``plc``: its Modbus TCP
#: and OPC UA servers)
WRITERS = ("program", "varproxy", "plc", "eki")
#: the writers that are the I/O system: they drive the inputs marked ``fieldbus``
FIELDBUS_WRITERS = frozenset(("plc",))

_BASE = re.compile(r"\s*(\$?[A-Za-z_][\w$]*)")


def info_of(name: str):
    """The table's record (:class:`krl.semantics.builtins.SysVarInfo`) of the system variable
    `name` is part of (``$ANIN[2]`` -> ``$ANIN``), or None for a program's variable."""
    m = _BASE.match(name)
    if m is None or not m.group(1).startswith("$"):
        return None
    key = m.group(1).upper()
    b = load_builtins()
    return b.sysvars.get(key) or b.kss_variables.get(key)


def shown(value) -> str:
    """A value as a refusal shows it (clipped: it may come from a partner, net/netlog.py)."""
    if isinstance(value, float):
        text = repr(value) if math.isfinite(value) else ("nan" if math.isnan(value) else
                                                         ("inf" if value > 0 else "-inf"))
    elif isinstance(value, bool):
        text = "TRUE" if value else "FALSE"
    else:
        text = str(value)
    return clip(text)


_SAFETY = " (a signal of the safety controller)"


def write_protected(name: str, why: str = "") -> KrlRuntimeError:
    """KSS 1388: `name` may not be written (``rule`` "protected")."""
    err = KrlRuntimeError(f"{name} is write-protected{why}", WRITE_PROTECTED)
    err.rule = "protected"
    return err


def protected(name: str) -> KrlRuntimeError:
    """KSS 1388 for a read-only `name` (memory.py: a read-only reference written), naming a
    signal of the safety controller as such."""
    info = info_of(name)
    return write_protected(name, _SAFETY if info is not None and info.safety else "")


def inadmissible(name: str, value, why: str, rule: str = "range") -> KrlRuntimeError:
    """KSS 1446: `value` may not be assigned to `name`; ``rule`` says which rule refused it:
    "shape" (an array into a scalar, ...), "finite" (NaN, an infinity) or "range"."""
    err = KrlRuntimeError(f"value assignment inadmissible: {name} = {shown(value)} {why}", VALUE_INADMISSIBLE)
    err.rule = rule
    return err


def _is_aggregate(v) -> bool:
    return isinstance(v, (Struct, Arr, dict, list, tuple)) or hasattr(v, "dims")


def check(name: str, value, writer: str = "program", target_is_scalar: bool | None = None):
    """Apply the rules (module docstring) to writing `value` (a KRL value, or what a partner
    sent: a Python bool/int/float/str, a list, a dict) into `name` (``$OV_PRO``, ``$ANIN[2]``,
    ``$VEL.CP``, or a program's variable) by `writer` (:data:`WRITERS`); `target_is_scalar`:
    whether the place written holds one value (None: from the table). Returns `value`; raises
    :class:`KrlRuntimeError` 1388 or 1446."""
    info = info_of(name)
    if info is not None:
        if info.safety:
            raise write_protected(name, _SAFETY)
        if info.access == "RO" and not (info.fieldbus and writer in FIELDBUS_WRITERS):
            raise write_protected(name)
        if target_is_scalar is None:
            whole = "[" not in name and "." not in name
            target_is_scalar = not (whole and info.dims)
    if target_is_scalar and _is_aggregate(value):
        n = len(value) if isinstance(value, (list, tuple, dict)) else None
        raise inadmissible(name, f"<{'an array' if not isinstance(value, (dict, Struct)) else 'a structure'}"
                                 f"{f' of {n} values' if n is not None else ''}>",
                           "is not a single value", "shape")
    if target_is_scalar is False and value is not None and not _is_aggregate(value) and not isinstance(value, str):
        raise inadmissible(name, value, "is a single value, the variable an array", "shape")
    if isinstance(value, float) and not math.isfinite(value):
        raise inadmissible(name, value, "is not a finite number", "finite")
    if info is not None and info.range is not None and target_is_scalar \
            and isinstance(value, (int, float)) and not isinstance(value, bool):
        lo, hi = info.range
        if not lo <= value <= hi:
            raise inadmissible(name, value, f"out of limits [{lo}; {hi}]")
    return value


def admit(name: str, value, writer: str, target_is_scalar: bool | None = None) -> KrlRuntimeError | None:
    """:func:`check` as an answer: None when the write is admitted, else the refusal (a partner's
    server thread asks before it takes a value, net/plc.py)."""
    try:
        check(name, value, writer, target_is_scalar)
    except KrlRuntimeError as exc:
        return exc
    return None


class WriteHook:
    """What writing a system variable's slot does besides storing the value (memory.py
    ``Slot.set``): :meth:`before` checks the value, converted to the slot's type (a REAL into an
    INT is checked as the INT it becomes), before anything is stored (:func:`check` for the
    slot's name); ``after`` runs once it is (``$PRO_MODE``: the new run mode applies from the
    next statement). The hook of an array or a structure goes with its elements and components
    (memory.py ``index_ref``, ``field_ref``): each element is checked as a scalar."""

    __slots__ = ("checked", "after")

    def __init__(self, checked: bool = True, after=None) -> None:
        self.checked = checked
        self.after = after

    def before(self, ref, value, scalar: bool) -> None:
        if self.checked:
            check(ref.name, value, "program", scalar)


__all__ = ["FIELDBUS_WRITERS", "VALUE_INADMISSIBLE", "WRITERS", "WRITE_PROTECTED", "WriteHook", "admit", "check",
           "info_of", "inadmissible", "protected", "shown", "write_protected"]
