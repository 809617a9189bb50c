"""The functions ``CWRITE($FCT_CALL, STATE, MODE, "NAME", ARG, ...)`` calls: the controller's
installed functions that KUKA's own KRL libraries reach through the function-call channel
(reference §4.7; KUKA's CREAD/CWRITE manual for KSS 8, "$FCT_CALL"; issue 59).

A backup may ship KUKA's KRL layer of an option: EthernetKRL's ``TP/EthernetKRL/EthernetKRL.src``
defines ``EKI_Init`` and the others as KRL functions that call the option's kernel through
``CWRITE($FCT_CALL, Stat, Mode, "EFC_eki_Init", ...)``. The backup's definitions win over the
natives (they are the program's routines), so the kernel function must do what the native does,
and a backup that ships the layer behaves as one that does not:

* ``EFC_<EKI function>`` (``EFC_eki_Init``, ``EFC_eki_Send``, ...: every EthernetKRL routine the
  natives implement, interp/runtime/natives/eki.py) runs that routine with the arguments after
  the name; a last argument that is an ``EKI_STATUS`` variable receives its result (the layer's
  return value). A kernel function the option does not have gives KUKA's EthernetKRL message 4,
  "Requested function not implemented" (EKI00004, number 4).
* ``krl_*``: the file functions of KUKA's CWRITE manual (``krl_fopen``, ``krl_fclose``,
  ``krl_fprintf``, ...; skilledAutomation's kuka_krl_wonderlibrary calls them). The simulator
  has no controller file system: the call answers ``STATE.RET1 = #CMD_ABORT``, ``MSG_NO = -2``
  ("Operation failed" in the manual's list of file-function errors), with one note per function.
* Any other name is no function of the controller: the run stops with KUKA's message 1309,
  "Object is not available" (KUKA's message table, CrossMeld 1309; docs/network.md "KUKA's EKI
  layer").

No KRL library of ../shared/krl-corpus or ../shared/krl-history calls ``$FCT_CALL`` (surveyed
2026-11-26: only kukaKRLmagic's ``operate.dat`` declares the channel); KUKA's EthernetKRL layer and
the file functions are the public callers found (docs/network.md).
"""

from __future__ import annotations

from krl.semantics.values import NOT_AVAILABLE

from ..errors import KrlRuntimeError
from ..values import EnumValue, Struct
from .eki import EKI
from net.eki import EkiError

#: the prefix of EthernetKRL's kernel functions behind its KRL layer
EKI_KERNEL = "EFC_"

#: KUKA's file functions of the $FCT_CALL channel (KSS 8 CREAD/CWRITE manual), not simulated
FILE_FUNCTIONS = frozenset({"KRL_MOUNT", "KRL_UNMOUNT", "KRL_FOPEN", "KRL_FCLOSE", "KRL_FCLOSE_ALL", "KRL_FEOF",
                            "KRL_FGETC", "KRL_FGETS", "KRL_FPUTC", "KRL_FPUTS", "KRL_FPRINTF", "KRL_FSCANF",
                            "KRL_FWRITELN", "KRL_FREADLN", "KRL_FREAD", "KRL_FWRITE", "KRL_FSEEK", "KRL_FFLUSH",
                            "KRL_FSIZEPOS"})


#: EthernetKRL's kernel functions: the EKI routine's UPPER name -> the native that implements it
KERNEL = {n.name: n.fn for n in EKI.entries if n.fn is not None}


def call(ctx, name: str, args: list, state) -> None:
    """The installed function `name` (the text of CWRITE's format argument) with CWRITE's
    argument references `args` after it; `state` the STATE_T value CWRITE writes RET1 and MSG_NO
    of (None: not a structure). See the module docstring."""
    name = name.strip()
    key = name.upper()
    if key.startswith(EKI_KERNEL):
        _eki_kernel(ctx, name, key[len(EKI_KERNEL):], args)
        _answer(state, "CMD_OK", 0)
        return
    if key in FILE_FUNCTIONS:
        note = f"not simulated: {key.lower()}"
        ctx.note_once(note, f"not simulated: CWRITE($FCT_CALL) {name[:40]}: the controller's file system "
                            "is not simulated; STATE.RET1 #CMD_ABORT, MSG_NO -2 (Operation failed)")
        _answer(state, "CMD_ABORT", -2)
        return
    raise KrlRuntimeError(f"CWRITE($FCT_CALL) {name[:40]}: Object is not available", NOT_AVAILABLE)


def _eki_kernel(ctx, name: str, function: str, args: list) -> None:
    """The EthernetKRL kernel function behind the layer's ``function`` (``EKI_INIT``)."""
    fn = KERNEL.get(function)
    if fn is None:

        err = EkiError(4, name[:40])
        raise KrlRuntimeError(str(err), err.number)
    out = args[-1] if args and args[-1] is not None and _is_eki_status(args[-1].peek()) else None
    result = fn(ctx, args[:-1] if out is not None else args)
    if out is not None and isinstance(result, Struct):
        out.set(result)


def _is_eki_status(v) -> bool:
    return isinstance(v, Struct) and getattr(v.type, "name", "").upper() == "EKI_STATUS"


def _answer(state, ret1: str, msg_no: int) -> None:
    """STATE_T of the call: RET1 and MSG_NO (the other components unchanged)."""
    if isinstance(state, Struct):
        if "RET1" in state.f:
            state.f["RET1"] = EnumValue(ret1)
        if "MSG_NO" in state.f:
            state.f["MSG_NO"] = msg_no
