"""The EthernetKRL built-ins (KUKA.EthernetKRL manual; docs/network.md). Each native converts
its KRL arguments and hands them to the run's network hub (net/hub.py, net/eki.py); the
behaviour lives there, once, for both interpreters. The RSI built-ins are in rsi.py.

EKI functions return EKI_STATUS (Buff, Read, Msg_No, Connected, Counter); an EKI error of the
call itself stops the program with its message (``EKI000nn ...``, number nn) unless the
channel's configuration sets ``MESSAGES Display="disabled"``: then only Msg_No tells.
"""

from __future__ import annotations

import math

from krl.semantics.facts import ARGS, WORLD
from ..convert import num, ref_bytes, ref_text
from ..errors import KrlRuntimeError, value_invalid
from ..memory import index_ref
from ..sysvars import struct_of
from ..values import UNSET, Arr, Struct, is_char_array
from .registry import Family
from net.eki import EkiError, format_real, Status

# EthernetKRL's routines are declared on the controller (the option's EXTFCTP lines): known by
# name only, as functions.yaml's ``lenient: ethernet_krl``
EKI = Family("EthernetKRL", lenient="ethernet_krl", reads=(ARGS, WORLD), writes=(ARGS, WORLD))

NOT_SIMULATED = ("not simulated: the run stops with \"routine NAME not found\" (a network partner's "
                 "routine is never stood in for: interp/runtime/kss.py)")
"""What a call of a network routine the simulator does not implement gives."""


def network(ctx):
    """The run's network hub (every run's controller has one: interp/runtime/core.py
    ``Runtime._controller``; without partners its channels stay "not connected")."""
    return ctx.controller.network


def _eki(ctx):
    """The run's EthernetKRL partner (net/eki.py EkiPartner)."""
    return network(ctx).partner("eki")


def _status(st) -> Struct:
    return struct_of("EKI_STATUS", {"BUFF": st.buff, "READ": st.read, "MSG_NO": st.msg_no,
                                    "CONNECTED": bool(st.connected), "COUNTER": st.counter})


def _result(st, err) -> Struct:
    if err is not None and err.stops:
        raise KrlRuntimeError(str(err), err.number)
    return _status(st)


def _eki_error(exc) -> Struct:

    if exc.stops:
        raise KrlRuntimeError(str(exc), exc.number)
    return _status(Status(msg_no=exc.number))


def _call(fn):
    """A native whose body may raise net.eki.EkiError (an unknown channel, a failed Init)."""
    def native(ctx, a):

        try:
            return fn(ctx, a)
        except EkiError as exc:
            return _eki_error(exc)
    return native


@_call
def eki_init(ctx, a):
    ch = _eki(ctx).init(ref_text(a[0], "EKI_Init channel"))
    return _status(ch.status())


@_call
def eki_open(ctx, a):
    ch = _eki(ctx).channel(ref_text(a[0], "EKI_Open channel"))
    task = ctx.current_task()
    return _result(*ch.open(lambda: ctx.block_cycle(task)))      # a client waits (net/eki.py)


@_call
def eki_close(ctx, a):
    return _status(_eki(ctx).channel(ref_text(a[0], "EKI_Close channel")).close())


@_call
def eki_clear(ctx, a):

    _eki(ctx).clear(ref_text(a[0], "EKI_Clear channel"))
    return _status(Status())


@_call
def eki_lock(ctx, a):
    return _status(_eki(ctx).channel(ref_text(a[0], "EKI_Lock channel")).lock())


@_call
def eki_unlock(ctx, a):
    return _status(_eki(ctx).channel(ref_text(a[0], "EKI_Unlock channel")).unlock())


@_call
def eki_send(ctx, a):
    """``EKI_Send(CHANNEL[], DATA[] [, LENGTH])``: DATA is a path of the send structure or an XML
    text (up to its first NUL), or, on a binary channel, the record: every byte of the CHAR array
    (net/eki.py ``Channel.send``; docs/network.md "Binary records")."""
    ch = _eki(ctx).channel(ref_text(a[0], "EKI_Send channel"))
    arg = a[1] if len(a) > 1 else None
    data = ref_text(arg, "EKI_Send data")
    length = None
    if len(a) > 2 and a[2] is not None:
        length = int(num(a[2].get(), "EKI_Send length"))
    return _result(*ch.send(data, length, ref_bytes(arg, "EKI_Send data")))


@_call
def eki_checkbuffer(ctx, a):
    ch = _eki(ctx).channel(ref_text(a[0], "EKI_CheckBuffer channel"))
    return _result(*ch.check(ref_text(a[1] if len(a) > 1 else None, "EKI_CheckBuffer element")))


@_call
def eki_clearbuffer(ctx, a):
    ch = _eki(ctx).channel(ref_text(a[0], "EKI_ClearBuffer channel"))
    return _result(*ch.clear_buffer(ref_text(a[1] if len(a) > 1 else None, "EKI_ClearBuffer element")))


def _setter(kind: str):
    @_call
    def native(ctx, a):

        ch = _eki(ctx).channel(ref_text(a[0], f"EKI_Set{kind} channel"))
        path = ref_text(a[1] if len(a) > 1 else None, f"EKI_Set{kind} element")
        if len(a) < 3 or a[2] is None:
            raise value_invalid(f"EKI_Set{kind} value")
        v = a[2].get()
        if kind == "Real":
            text = format_real(float(num(v, "EKI_SetReal value")))
        elif kind == "Int":
            n = num(v, "EKI_SetInt value")
            text = str(int(n))
        elif kind == "Bool":
            text = "TRUE" if bool(v) else "FALSE"
        elif kind == "String":
            text = ref_text(a[2], "EKI_SetString value")
        else:       # Frame, Pos, Axis: the components as attributes
            if not isinstance(v, Struct):
                raise KrlRuntimeError(f"EKI_Set{kind} needs a structure")
            text = {k: format_real(float(x)) if isinstance(x, float) else str(x)
                    for k, x in v.f.items() if x is not UNSET and isinstance(x, (int, float))}
        return _result(*ch.set_value(path, text))
    return native


def _convert(kind: str, text):
    """An element's text as the KRL type `kind`; ValueError when it does not convert."""
    if kind == "Real":
        v = float(text)
        if not math.isfinite(v):
            raise ValueError(text)
        return v
    if kind == "Int":
        t = str(text).strip()
        if not t.lstrip("+-").isdigit() or len(t) > 11:
            raise ValueError(text)
        v = int(t)
        if not -2 ** 31 <= v < 2 ** 31:
            raise ValueError(text)
        return v
    if kind == "Bool":
        u = str(text).strip().upper()
        if u in ("TRUE", "1"):
            return True
        if u in ("FALSE", "0"):
            return False
        raise ValueError(text)
    return text


def _store(ref, kind: str, value, what: str) -> None:
    if kind == "String":
        cur = ref.peek()
        if not is_char_array(cur):
            raise KrlRuntimeError(f"{what} needs a CHAR array")
        data = cur.data
        for i in range(len(data)):
            data[i] = value[i] if i < len(value) else "\0"
        return
    if kind in ("Frame", "Pos", "Axis"):
        if not isinstance(value, dict):
            raise ValueError(value)
        vals = {k: float(x) for k, x in value.items() if k in ("X", "Y", "Z", "A", "B", "C", "A1", "A2", "A3",
                                                                 "A4", "A5", "A6", "S", "T")}
        for k in ("S", "T"):
            if k in vals:
                vals[k] = int(vals[k])
        ref.set(Struct(None, vals))
        return
    ref.set(value)


def _getter(kind: str, array: bool = False):
    @_call
    def native(ctx, a):

        name = f"EKI_Get{kind}{'Array' if array else ''}"
        ch = _eki(ctx).channel(ref_text(a[0], f"{name} channel"))
        path = ref_text(a[1] if len(a) > 1 else None, f"{name} element")
        target = a[2] if len(a) > 2 else None
        if target is None:
            raise value_invalid(f"{name} variable")
        n = None
        if array:
            arr = target.peek()
            if not isinstance(arr, Arr):
                raise KrlRuntimeError(f"{name} needs an array")
            n = len(arr.data)
        vals, st, err = ch.get(path, n)
        if err is not None:
            return _result(st, err)
        try:
            conv = [_convert(kind, v) if kind not in ("Frame", "Pos", "Axis", "String") else v for v in vals]
        except ValueError:
            e = EkiError(20, f"channel {ch.name}, element {path[:60]}: {str(vals[0])[:30]!r} is not {kind.upper()}",
                         ch.cfg.display)
            st.msg_no = 20
            return _result(st, e)
        try:
            if array:
                for i, v in enumerate(conv, 1):
                    _store(index_ref(target, [i], name), kind, v, name)
            elif conv:
                _store(target, kind, conv[0], name)
        except ValueError:
            e = EkiError(20, f"channel {ch.name}, element {path[:60]}", ch.cfg.display)
            st.msg_no = 20
            return _result(st, e)
        return _status(st)
    return native


EKI.add("EKI_INIT", eki_init)
EKI.add("EKI_OPEN", eki_open)
EKI.add("EKI_CLOSE", eki_close)
EKI.add("EKI_CLEAR", eki_clear)
EKI.stand_in("EKI_LOAD", NOT_SIMULATED)
EKI.stand_in("EKI_UNLOAD", NOT_SIMULATED)
EKI.add("EKI_SEND", eki_send)
EKI.add("EKI_LOCK", eki_lock)
EKI.add("EKI_UNLOCK", eki_unlock)
EKI.stand_in("EKI_CHECK", NOT_SIMULATED)
EKI.add("EKI_CHECKBUFFER", eki_checkbuffer)
EKI.add("EKI_CLEARBUFFER", eki_clearbuffer)
EKI.stand_in("EKI_READNEXT", NOT_SIMULATED)
EKI.add("EKI_SETREAL", _setter("Real"))
EKI.add("EKI_SETINT", _setter("Int"))
EKI.add("EKI_SETBOOL", _setter("Bool"))
EKI.add("EKI_SETSTRING", _setter("String"))
EKI.add("EKI_SETFRAME", _setter("Frame"))
EKI.add("EKI_SETPOS", _setter("Pos"))
EKI.add("EKI_SETAXIS", _setter("Axis"))
EKI.add("EKI_GETREAL", _getter("Real"))
EKI.add("EKI_GETINT", _getter("Int"))
EKI.add("EKI_GETBOOL", _getter("Bool"))
EKI.add("EKI_GETSTRING", _getter("String"))
EKI.add("EKI_GETFRAME", _getter("Frame"))
EKI.add("EKI_GETPOS", _getter("Pos"))
EKI.add("EKI_GETAXIS", _getter("Axis"))
EKI.add("EKI_GETREALARRAY", _getter("Real", True))
EKI.add("EKI_GETINTARRAY", _getter("Int", True))
EKI.add("EKI_GETBOOLARRAY", _getter("Bool", True))
EKI.add("EKI_GETFRAMEARRAY", _getter("Frame", True))

__all__ = ["EKI", "NOT_SIMULATED", "network"]
