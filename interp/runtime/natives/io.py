"""Inputs, outputs and the controller's channels (reference 5.12, 4.7): PULSE, COPEN, CWRITE,
CREAD, CCLOSE, CIOCTL, GET_SIG_INF.

PULSE sets an output for a time (``ctx.pulse``). COPEN(:SER_3, HANDLE) finds no device on any
channel: HANDLE 0, the channel not connected (:func:`_copen`). CWRITE writes to the $CMD
channel (a message; its commands RUN, STOP, RESET and CANCEL change the interpreters'
program states: interp/runtime/cmdchannel.py) and calls the controller's installed functions on the $FCT_CALL channel
(fctcall.py: EthernetKRL's kernel behind KUKA's KRL layer). Unsupported: CREAD, CCLOSE, CIOCTL,
GET_SIG_INF and other CWRITE channels stop the program with a clear "not supported" run-time
error.
"""

from __future__ import annotations

from krl.semantics.facts import ARGS, SIGNALS, WORLD
from ..convert import ref_text, to_bool
from ..errors import KrlRuntimeError
from ..values import Channel, EnumValue, Struct
from .args import int_arg, real_arg
from . import fctcall
from .registry import Family

IO = Family("I/O", reads=(ARGS, WORLD), writes=(ARGS, WORLD))     # the command channel's: the world's


@IO.native("PULSE(BOOL SIGNAL :OUT, BOOL LEVEL :IN, REAL DURATION :IN)", stops=True, reads=(ARGS,),
           writes=(SIGNALS,))
def _pulse(ctx, a):
    sig, level, dur = a[0], a[1], a[2]
    lvl = to_bool(level.get(), "PULSE level")
    d = real_arg(dur, "PULSE duration")
    ctx.pulse(sig, lvl, d)


@IO.native("COPEN(...)")
def _copen(ctx, a):
    """``COPEN(:SER_3, HANDLE)``: open a channel of the controller. No device answers on any
    channel in the simulation: the channel is *not connected*, HANDLE is 0 (KUKA: a handle > 0
    for an open channel, 0 when it could not be opened), and the run notes it once per channel."""
    if len(a) != 2 or a[0] is None or not isinstance(a[0].peek(), Channel):
        raise KrlRuntimeError("COPEN needs a channel name and a handle variable: COPEN(:SER_3, HANDLE)")
    ch = a[0].peek()
    a[1].set(0)
    key = f"COPEN {ch.name}"
    ctx.note_once(key, f"not simulated: channel :{ch.name} is not connected (no device on it): COPEN gives HANDLE 0")
    return None


@IO.native("CWRITE(INT CHANNEL :IN, STATE_T STATE :OUT, MODUS_T MODE :OUT, CHAR FORMAT[] :IN, ...)")
def _cwrite(ctx, a):
    ch = int_arg(a[0], "channel")
    store = ctx.sysvars.store
    fmt = ref_text(a[3], "CWRITE format") if len(a) > 3 else ""
    if ch == store.get("$FCT_CALL"):         # the controller's installed functions (fctcall.py)
        return fctcall.call(ctx, fmt, list(a[4:]), a[1].peek() if a[1] is not None else None)
    if ch != store.get("$CMD"):
        raise KrlRuntimeError("CWRITE: only the $CMD and $FCT_CALL channels are supported by this simulator")
    ctx.message(f"CWRITE $CMD: {fmt}")
    ret = ctx.programs.command(fmt)     # RUN, STOP n, RESET n, CANCEL n (cmdchannel.py)
    st = a[1].peek() if a[1] is not None else None
    if isinstance(st, Struct) and "RET1" in st.f:
        st.f["RET1"] = EnumValue(ret)


def _unsupported(name):
    def fn(ctx, a):
        raise KrlRuntimeError(f"{name} is not supported by this simulator")
    return fn


IO.add("CREAD(INT CHANNEL :IN, STATE_T STATE :OUT, MODUS_T MODE :OUT, ...)", _unsupported("CREAD"))
IO.add("CCLOSE(...)", _unsupported("CCLOSE"))
IO.add("CIOCTL(...)", _unsupported("CIOCTL"))
IO.add("INT GET_SIG_INF(CHAR SIGNAME[] :IN, ...)", _unsupported("GET_SIG_INF"))
