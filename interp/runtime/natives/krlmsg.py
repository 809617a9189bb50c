"""KRL's messages and dialogs (KUKA System Software: "Programming messages"): SET_KRLMSG,
SET_KRLDLG, EXISTS_KRLMSG, CLEAR_KRLMSG, EXISTS_KRLDLG.

A message goes to the run's message list (interp/runtime/messages.py: the message window of
the pendant, the trace's ``message`` events) with its text, its parameters filled in
(``%1``..``%3``), module and number; its handle is the function's value. A dialog outside an
interactive run is answered with its first softkey.
"""

from __future__ import annotations

from krl.semantics.facts import ARGS, CLOCK, WORLD
from ..errors import KrlRuntimeError, StopRun
from ..messages import format_text
from ..values import UNSET, Arr, Struct
from .args import int_arg
from .registry import Family

MESSAGES = Family("messages")


def _krlmsg(a_msg, a_par) -> tuple[str, str, int, list[str]]:
    """(text, module, number, parameter texts) of a KrlMsg_T and its KrlMsgPar_T[] arguments."""
    msg = a_msg.peek() if a_msg is not None else None
    text, module, number = "", "", 0
    if isinstance(msg, Struct):
        for key in ("MSG_TXT", "MODUL"):
            v = msg.f.get(key)
            if isinstance(v, Arr):
                if key == "MSG_TXT":
                    text = v.text()
                else:
                    module = v.text()
        nr = msg.f.get("NR")
        number = nr if isinstance(nr, int) and not isinstance(nr, bool) else 0
    params = []
    pars = a_par.peek() if a_par is not None else None
    if isinstance(pars, Arr):
        for p in pars.data[:3]:
            if not isinstance(p, Struct):
                params.append("")
                continue
            kind = getattr(p.f.get("PAR_TYPE"), "name", "")
            t = p.f.get("PAR_TXT")
            if str(kind).upper() == "VALUE" and isinstance(t, Arr) and t.text() == "":
                v = next((p.f.get(k) for k in ("PAR_INT", "PAR_REAL", "PAR_BOOL") if p.f.get(k) is not UNSET), "")
                params.append("" if v is UNSET else str(v))
            else:
                params.append(t.text() if isinstance(t, Arr) else "")
    return text, module, number, params


@MESSAGES.native("INT SET_KRLMSG(EKRLMSGTYPE TYPE :IN, KRLMSG_T MSG :OUT, KRLMSGPAR_T PAR[] :OUT, KRLMSGOPT_T OPT :OUT)",
                 reads=(ARGS, CLOCK), writes=(ARGS, WORLD))     # (the message is stamped with the time)
def _set_krlmsg(ctx, a):
    kind = str(getattr(a[0].peek(), "name", a[0].peek()) if a and a[0] is not None else "NOTIFY").lstrip("#").upper()
    text, module, number, params = _krlmsg(a[1] if len(a) > 1 else None, a[2] if len(a) > 2 else None)
    ctx.controller.log.message(f"KRL message: {text}")
    m = ctx.messages.add(kind, format_text(text, params), module, number, time=ctx.controller.time)
    return m.handle


def _handle(a) -> int | None:
    """The message handle argument, None when it has no value (no message has it)."""
    try:
        return int_arg(a[0], "handle") if a else None
    except KrlRuntimeError:
        return None


@MESSAGES.native("BOOL EXISTS_KRLMSG(INT NHANDLE :IN)", pure=True)
def _exists_krlmsg(ctx, a):
    h = _handle(a)
    if h is None:
        return False
    shown = ctx.messages.exists(h, ctx.controller.queue.next_id)
    loop = ctx.messages.operator_loop() if not shown else None
    if loop is not None:
        raise StopRun("deadlock", loop)   # the operator's acknowledgement changes nothing (issue 85)
    return shown


@MESSAGES.native("BOOL CLEAR_KRLMSG(INT NHANDLE :IN)", reads=(ARGS, WORLD), writes=(WORLD,))
def _clear_krlmsg(ctx, a):
    h = _handle(a)
    return h is not None and ctx.messages.clear(h)


@MESSAGES.native("INT SET_KRLDLG(KRLMSG_T MSG :OUT, KRLMSGPAR_T PAR[] :OUT, KRLMSGDLGSK_T SK[] :OUT, KRLMSGOPT_T OPT :OUT)",
                 reads=(ARGS, CLOCK), writes=(ARGS, WORLD))     # (the message is stamped with the time)
def _set_krldlg(ctx, a):
    text, module, number, params = _krlmsg(a[0] if a else None, a[1] if len(a) > 1 else None)
    keys = []
    sk = a[2].peek() if len(a) > 2 and a[2] is not None else None
    if isinstance(sk, Arr):
        for k in sk.data:
            t = k.f.get("SK_TXT") if isinstance(k, Struct) else None
            keys.append(t.text() if isinstance(t, Arr) else "")
    while keys and not keys[-1].strip():
        keys.pop()
    if ctx.messages.interactive:
        ctx.controller.log.message(f"KRL dialog: {text}")
    else:
        ctx.controller.log.message("KRL dialog (answered with the first softkey)")
    m = ctx.messages.add("DIALOG", format_text(text, params), module, number, keys or ["OK"], ctx.controller.time)
    return m.handle


@MESSAGES.native("BOOL EXISTS_KRLDLG(INT NHANDLE :IN, INT ANSWER :OUT)", pure=True)
def _exists_krldlg(ctx, a):
    h = _handle(a)
    open_, answer = ctx.messages.dialog_answer(h) if h is not None else (False, None)
    if answer is not None and len(a) > 1 and a[1] is not None:
        a[1].set(answer)
    return open_
