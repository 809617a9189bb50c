"""The EthernetKRL and RobotSensorInterface built-ins (KUKA.EthernetKRL and
KUKA.RobotSensorInterface manuals; docs/network.md). Each native converts its KRL arguments
and hands them to the run's network hub (net/hub.py, net/eki.py, net/rsi.py); the behaviour
lives there, once, for both interpreters.

EKI functions return EKI_STATUS (Buff, Read, Msg_No, Connected, Counter); an EKI error of the
call itself stops the program with its message (``EKI000nn ...``, number nn) unless the
channel's configuration sets ``MESSAGES Display="disabled"``: then only Msg_No tells. RSI
functions return an RSIERR number as INT (``RSIOK`` = 0, :data:`RSI_CONSTANTS`).
"""

from __future__ import annotations

from ..convert import ref_text
from ..errors import KrlRuntimeError, value_invalid
from ..values import UNSET, Arr, EnumValue, Struct, is_char_array

# RSIERR's values as INT constants (types.yaml lists RSIERR; KUKA's numbering is not public:
# the order of the enum, RSIOK = 0, is the decision recorded in docs/network.md).
RSI_CONSTANTS = {name: i for i, name in enumerate(
    ("RSIOK", "RSIINVOBJID", "RSIINVPARAM", "RSINOMEM", "RSIINVOBJTYPE", "RSIINVCONN",
     "RSIALREADYON", "RSINOTON", "RSIOBJUSED"))}


def network(rt):
    """The run's network hub; a run built without one gets a hub with no partner ("not
    connected": no socket, deterministic)."""
    ctl = rt.controller
    net = getattr(ctl, "network", None)
    if net is None:
        from net.hub import Network  # noqa: PLC0415

        from ..netvars import RuntimeSink  # noqa: PLC0415

        net = Network(program=rt.program.main_path, sink=RuntimeSink(rt))
        net.attach(ctl)
    return net


def _status(st) -> Struct:
    from ..sysvars import struct_of  # noqa: PLC0415

    return struct_of("EKI_STATUS", {"BUFF": st.buff, "READ": st.read, "MSG_NO": st.msg_no,
                                    "CONNECTED": bool(st.connected), "COUNTER": st.counter})


def _result(st, err) -> Struct:
    if err is not None and err.stops:
        raise KrlRuntimeError(str(err), err.number)
    return _status(st)


def _eki_error(exc) -> Struct:
    from net.eki import Status  # noqa: PLC0415

    if exc.stops:
        raise KrlRuntimeError(str(exc), exc.number)
    return _status(Status(msg_no=exc.number))


def _call(fn):
    """A native whose body may raise net.eki.EkiError (an unknown channel, a failed Init)."""
    def native(rt, a):
        from net.eki import EkiError  # noqa: PLC0415

        try:
            return fn(rt, a)
        except EkiError as exc:
            return _eki_error(exc)
    return native


@_call
def eki_init(rt, a):
    ch = network(rt).eki_init(ref_text(a[0], "EKI_Init channel"))
    return _status(ch.status())


@_call
def eki_open(rt, a):
    return _status(network(rt).eki_channel(ref_text(a[0], "EKI_Open channel")).open())


@_call
def eki_close(rt, a):
    return _status(network(rt).eki_channel(ref_text(a[0], "EKI_Close channel")).close())


@_call
def eki_clear(rt, a):
    from net.eki import Status  # noqa: PLC0415

    network(rt).eki_clear(ref_text(a[0], "EKI_Clear channel"))
    return _status(Status())


@_call
def eki_lock(rt, a):
    return _status(network(rt).eki_channel(ref_text(a[0], "EKI_Lock channel")).lock())


@_call
def eki_unlock(rt, a):
    return _status(network(rt).eki_channel(ref_text(a[0], "EKI_Unlock channel")).unlock())


@_call
def eki_send(rt, a):
    ch = network(rt).eki_channel(ref_text(a[0], "EKI_Send channel"))
    data = ref_text(a[1] if len(a) > 1 else None, "EKI_Send data")
    length = None
    if len(a) > 2 and a[2] is not None:
        from ..convert import num  # noqa: PLC0415

        length = int(num(a[2].get(), "EKI_Send length"))
    return _result(*ch.send(data, length))


@_call
def eki_checkbuffer(rt, a):
    ch = network(rt).eki_channel(ref_text(a[0], "EKI_CheckBuffer channel"))
    return _result(*ch.check(ref_text(a[1] if len(a) > 1 else None, "EKI_CheckBuffer element")))


@_call
def eki_clearbuffer(rt, a):
    ch = network(rt).eki_channel(ref_text(a[0], "EKI_ClearBuffer channel"))
    return _result(*ch.clear_buffer(ref_text(a[1] if len(a) > 1 else None, "EKI_ClearBuffer element")))


def _setter(kind: str):
    @_call
    def native(rt, a):
        from net.eki import format_real  # noqa: PLC0415

        from ..convert import num  # noqa: PLC0415

        ch = network(rt).eki_channel(ref_text(a[0], f"EKI_Set{kind} channel"))
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
        import math  # noqa: PLC0415

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
    def native(rt, a):
        from net.eki import EkiError  # noqa: PLC0415

        name = f"EKI_Get{kind}{'Array' if array else ''}"
        ch = network(rt).eki_channel(ref_text(a[0], f"{name} channel"))
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
                from ..memory import index_ref  # noqa: PLC0415

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


# ------------------------------------------------------------------ RSI

def _rsi(method: str):
    def native(rt, a):
        return rsi_call(network(rt), rt, method, a)
    return native


def _arg_text(a: list, i: int) -> str:
    v = a[i].get() if len(a) > i and a[i] is not None else ""
    return v.text() if isinstance(v, Arr) else str(v)


def _arg_enum(a: list, i: int, default: str) -> str:
    v = a[i].get() if len(a) > i and a[i] is not None else None
    return v.name.upper() if isinstance(v, EnumValue) else default


def rsi_call(hub, rt, method: str, a: list):
    """RSI_CREATE(NAME, CONTID :OUT, BOOL), RSI_DELETE(CONTID), RSI_ON(#ABSOLUTE|#RELATIVE
    [, #IPO|#IPO_FAST]), RSI_OFF(), RSI_MOVECORR() (waits until the STOP object or an error
    ends it), RSI_SETPUBLICPAR(CONTID, OBJ, PARAM, VALUE), RSI_GETPUBLICPAR(CONTID, OBJ,
    PARAM, VALUE :OUT); RSI 5's RSI_LOAD(NAME), RSI_ACTIVATE(NAME), RSI_PROCESS_ON(mode),
    RSI_PROCESS_OFF(), RSI_DEACTIVATE, RSI_UNLOAD as the same. net/rsi.py holds the behaviour.
    Returns the RSIERR number (INT)."""
    from net.rsi import RSIOK, Rsi  # noqa: PLC0415

    from ..convert import num  # noqa: PLC0415

    if hub.rsi is None:
        hub.rsi = Rsi(hub)
    rsi = hub.rsi
    ctl = rt.controller
    if method == "create":
        ret = rsi.create(_arg_text(a, 0))
        if ret == RSIOK and len(a) > 1 and a[1] is not None:
            a[1].set(1)
        return ret
    if method == "delete":
        return rsi.delete()
    if method == "activate":
        return RSIOK if rsi.ctx is not None else RSI_CONSTANTS["RSIINVOBJID"]
    if method == "on":
        rt.wait_main_run(rt.current_task)     # RSI_ON stops the advance run: it corrects from the robot at rest
        return rsi.start(ctl, _arg_enum(a, 0, "RELATIVE"), _arg_enum(a, 1, "IPO") == "IPO_FAST")
    if method == "off":
        rt.wait_main_run(rt.current_task)
        return rsi.off(ctl)
    if method == "setpar":
        if len(a) < 4 or a[3] is None:
            raise value_invalid("RSI_SETPUBLICPAR value")
        return rsi.set_param(_arg_text(a, 1), _arg_text(a, 2), float(num(a[3].get(), "RSI_SETPUBLICPAR value")))
    if method == "getpar":
        ret, v = rsi.get_param(_arg_text(a, 1), _arg_text(a, 2))
        if len(a) > 3 and a[3] is not None:
            a[3].set(v)
        return ret
    # movecorr: the robot follows the corrections only, until the STOP object or an error
    if not rsi.on:
        raise KrlRuntimeError("RSI_MOVECORR without RSI_ON")
    task = rt.current_task
    rt.wait_main_run(task)
    while rsi.on and not rsi.stopped and not rsi.failed:
        rt.yield_cycle(task)
    return None


NATIVES = {
    "EKI_INIT": eki_init, "EKI_OPEN": eki_open, "EKI_CLOSE": eki_close, "EKI_CLEAR": eki_clear,
    "EKI_LOCK": eki_lock, "EKI_UNLOCK": eki_unlock, "EKI_SEND": eki_send,
    "EKI_CHECKBUFFER": eki_checkbuffer, "EKI_CLEARBUFFER": eki_clearbuffer,
    "EKI_SETREAL": _setter("Real"), "EKI_SETINT": _setter("Int"), "EKI_SETBOOL": _setter("Bool"),
    "EKI_SETSTRING": _setter("String"), "EKI_SETFRAME": _setter("Frame"),
    "EKI_SETPOS": _setter("Pos"), "EKI_SETAXIS": _setter("Axis"),
    "EKI_GETREAL": _getter("Real"), "EKI_GETINT": _getter("Int"), "EKI_GETBOOL": _getter("Bool"),
    "EKI_GETSTRING": _getter("String"), "EKI_GETFRAME": _getter("Frame"),
    "EKI_GETPOS": _getter("Pos"), "EKI_GETAXIS": _getter("Axis"),
    "EKI_GETREALARRAY": _getter("Real", True), "EKI_GETINTARRAY": _getter("Int", True),
    "EKI_GETBOOLARRAY": _getter("Bool", True), "EKI_GETFRAMEARRAY": _getter("Frame", True),
    "RSI_CREATE": _rsi("create"), "RSI_DELETE": _rsi("delete"), "RSI_ON": _rsi("on"),
    "RSI_OFF": _rsi("off"), "RSI_MOVECORR": _rsi("movecorr"),
    "RSI_SETPUBLICPAR": _rsi("setpar"), "RSI_GETPUBLICPAR": _rsi("getpar"),
    # RSI 5 (iiQKA): a context is loaded and activated by name, the process switched on and off
    "RSI_LOAD": _rsi("create"), "RSI_ACTIVATE": _rsi("activate"), "RSI_DEACTIVATE": _rsi("activate"),
    "RSI_UNLOAD": _rsi("delete"), "RSI_PROCESS_ON": _rsi("on"), "RSI_PROCESS_OFF": _rsi("off"),
}

__all__ = ["NATIVES", "RSI_CONSTANTS", "network"]
