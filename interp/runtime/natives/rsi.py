"""The RobotSensorInterface built-ins (KUKA.RobotSensorInterface manual; docs/network.md).
Each native converts its KRL arguments and hands them to the run's network hub (net/hub.py,
net/rsi.py); the behaviour lives there, once, for both interpreters.

RSI 3/4/5's functions return an RSIERR number as INT (``RSIOK`` = 0, :data:`RSI_CONSTANTS`);
RSI 2's ``ST_`` functions (KR C2; net/rsi2.py) return the enum RSIERR (``#RSIOK``), as the KR C2
programs declare their result.
"""

from __future__ import annotations

from krl.semantics.facts import ARGS, ROBOT, WORLD
from ..convert import num
from ..errors import KrlRuntimeError, value_invalid
from ..values import Arr, EnumValue
from .eki import NOT_SIMULATED, network
from .registry import Family
from net.rsi import RSIOK
from net.rsi2 import CREATES

# RSI's routines are declared on the controller (the option's EXTFCTP lines): known by name
# only, as functions.yaml's ``lenient: rsi``
RSI = Family("RSI", lenient="rsi", reads=(ARGS, WORLD, ROBOT), writes=(ARGS, WORLD, ROBOT))

# RSIERR's values as INT constants (types.yaml lists RSIERR; KUKA's numbering is not public:
# the order of the enum, RSIOK = 0, is the decision recorded in docs/network.md).
RSI_CONSTANTS = {name: i for i, name in enumerate(
    ("RSIOK", "RSIINVOBJID", "RSIINVPARAM", "RSINOMEM", "RSIINVOBJTYPE", "RSIINVCONN",
     "RSIALREADYON", "RSINOTON", "RSIOBJUSED"))}


def _rsi(method: str):
    def native(ctx, a):
        return rsi_call(network(ctx), ctx, method, a)
    return native


def _arg_text(a: list, i: int) -> str:
    v = a[i].get() if len(a) > i and a[i] is not None else ""
    return v.text() if isinstance(v, Arr) else str(v)


def _arg_enum(a: list, i: int, default: str) -> str:
    v = a[i].get() if len(a) > i and a[i] is not None else None
    return v.name.upper() if isinstance(v, EnumValue) else default


_RSIERR_NAMES = {v: k for k, v in RSI_CONSTANTS.items()}


def _st(func: str):
    def native(ctx, a):
        ret = st_call(network(ctx), ctx, func, a)
        # RSI 2's functions return the enum RSIERR (KR C2 programs declare DECL RSIERR err and
        # compare it with #RSIOK); RSI 3's return its number as INT
        return None if ret is None else EnumValue(_RSIERR_NAMES[ret])
    return native


def _arg_num(a: list, i: int, what: str) -> float:
    if len(a) <= i or a[i] is None:
        raise value_invalid(what)
    return float(num(a[i].get(), what))


def st_call(hub, ctx, func: str, a: list):
    """RSI 2's ST_ functions (KUKA.RobotSensorInterface 2.x; net/rsi2.py holds the model):
    ST_ETHERNET(h :OUT, container, CONFIG[]), ST_AXISCORR/ST_PATHCORR/ST_DIGIN/ST_MAP2DIGOUT/
    ST_COROB(h :OUT, container, ...), ST_NEWLINK(hOut, outIdx, hIn, inIdx), ST_SETPARAM(h, n,
    value), ST_DELOBJ(h), ST_RESET(), ST_ON(), ST_ON1(#frame, n), ST_OFF(), ST_SKIPSENS() (holds
    the program while the robot follows the sensor, until an error ends it). Returns the RSIERR
    number (:func:`_st` gives it as the enum RSIERR); ST_SKIPSENS nothing."""

    rsi = hub.partner("rsi").instance()
    ctl = ctx.controller
    if func in CREATES:
        ret, handle = rsi.st_create(func, _arg_text(a, 2) if func == "ST_ETHERNET" else "")
        if ret == RSIOK and a and a[0] is not None:
            a[0].set(handle)
        return ret
    if func == "ST_NEWLINK":
        return rsi.st_link(int(_arg_num(a, 0, "ST_NEWLINK object")), int(_arg_num(a, 1, "ST_NEWLINK output")),
                           int(_arg_num(a, 2, "ST_NEWLINK object")), int(_arg_num(a, 3, "ST_NEWLINK input")))
    if func == "ST_SETPARAM":
        return rsi.st_setparam(int(_arg_num(a, 0, "ST_SETPARAM object")), int(_arg_num(a, 1, "ST_SETPARAM number")),
                               _arg_num(a, 2, "ST_SETPARAM value"))
    if func == "ST_DELOBJ":
        return rsi.st_delete(int(_arg_num(a, 0, "ST_DELOBJ object")))
    if func == "ST_RESET":
        ctx.wait_main_run(ctx.current_task())
        return rsi.delete()
    if func in ("ST_ON", "ST_ON1"):
        ctx.wait_main_run(ctx.current_task())     # the sensor mode starts from the robot at rest
        return rsi.st_on(ctl, _arg_enum(a, 0, "BASE") if func == "ST_ON1" else None)
    if func == "ST_OFF":
        ctx.wait_main_run(ctx.current_task())
        return rsi.off(ctl)
    # ST_SKIPSENS: the sensor-guided motion; the program waits here as at RSI_MOVECORR
    return _follow(ctx, rsi, "ST_SKIPSENS without ST_ON")


def rsi_call(hub, ctx, method: str, a: list):
    """RSI_CREATE(NAME, CONTID :OUT, BOOL), RSI_DELETE(CONTID), RSI_ON(#ABSOLUTE|#RELATIVE
    [, #IPO|#IPO_FAST]), RSI_OFF(), RSI_MOVECORR() (waits until the STOP object or an error
    ends it), RSI_SETPUBLICPAR(CONTID, OBJ, PARAM, VALUE), RSI_GETPUBLICPAR(CONTID, OBJ,
    PARAM, VALUE :OUT); RSI 5's RSI_LOAD(NAME), RSI_ACTIVATE(NAME), RSI_PROCESS_ON(mode),
    RSI_PROCESS_OFF(), RSI_DEACTIVATE, RSI_UNLOAD as the same. net/rsi.py holds the behaviour.
    Returns the RSIERR number (INT)."""

    rsi = hub.partner("rsi").instance()
    ctl = ctx.controller
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
        ctx.wait_main_run(ctx.current_task())     # RSI_ON stops the advance run: it corrects from the robot at rest
        return rsi.start(ctl, _arg_enum(a, 0, "RELATIVE"), _arg_enum(a, 1, "IPO") == "IPO_FAST")
    if method == "off":
        ctx.wait_main_run(ctx.current_task())
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
    return _follow(ctx, rsi, "RSI_MOVECORR without RSI_ON")


def _follow(ctx, rsi, not_on: str) -> None:
    """RSI_MOVECORR, ST_SKIPSENS: the program waits (the main run done first) while the robot
    follows the sensor, until the STOP object or an error ends it; `not_on` is the error when
    the sensor mode is off."""
    if not rsi.on:
        raise KrlRuntimeError(not_on)
    task = ctx.current_task()
    ctx.wait_main_run(task)
    while rsi.on and not rsi.stopped and not rsi.failed:
        ctx.yield_cycle(task)


RSI.add("RSI_CREATE", _rsi("create"))
RSI.add("RSI_DELETE", _rsi("delete"))
RSI.add("RSI_LOAD", _rsi("create"))
RSI.add("RSI_ACTIVATE", _rsi("activate"))
RSI.add("RSI_ON", _rsi("on"))
RSI.add("RSI_OFF", _rsi("off"))
RSI.add("RSI_MOVECORR", _rsi("movecorr"))
RSI.add("RSI_SETPUBLICPAR", _rsi("setpar"))
RSI.add("RSI_GETPUBLICPAR", _rsi("getpar"))
RSI.stand_in("RSI_SETPARAMETER", NOT_SIMULATED)
RSI.add("RSI_PROCESS_ON", _rsi("on"))
RSI.add("RSI_PROCESS_OFF", _rsi("off"))
RSI.stand_in("RSI_RESET", NOT_SIMULATED)
RSI.stand_in("RSI_CHECKID", NOT_SIMULATED)
# RSI 5 (iiQKA): a context is loaded and activated by name, the process switched on and off
RSI.add("RSI_DEACTIVATE", _rsi("activate"))
RSI.add("RSI_UNLOAD", _rsi("delete"))
# RSI 2 (KR C2): the signal flow built object by object by the ST_ functions (net/rsi2.py)
for _name in ("ST_ON", "ST_ON1", "ST_OFF", "ST_SKIPSENS", "ST_SETPARAM", "ST_NEWLINK", "ST_ETHERNET",
              "ST_AXISCORR", "ST_PATHCORR", "ST_MAP2DIGOUT", "ST_DIGIN", "ST_COROB", "ST_DELOBJ", "ST_RESET"):
    RSI.add(_name, _st(_name))

__all__ = ["RSI", "RSI_CONSTANTS", "rsi_call", "st_call"]
